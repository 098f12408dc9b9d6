// A stable radix sort of records by a 64-bit unsigned key, for large arrays where std::sort's
// comparisons dominate (Seam Repair sorts a million vertex keys per million vertices).
#ifndef rgmcRadixSort_h
#define rgmcRadixSort_h

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace rgmc
{

/// Sorts `values` (a std::vector, with any allocator) by `keyOf(value)` (a std::uint64_t, compared
/// as unsigned), least significant byte first, skipping the bytes in which all keys agree. Stable:
/// values with equal keys keep their order. So records (key, index) whose indices increase in the
/// input come out exactly as std::sort on (key, index) gives them.
template <typename Vector, typename KeyOf>
void RadixSort(Vector& values, KeyOf&& keyOf)
{
  using T = typename Vector::value_type;
  const std::size_t n = values.size();
  if (n < 2)
  {
    return;
  }
  // Every byte's histogram in one pass.
  std::vector<std::array<std::size_t, 256>> counts(8);
  for (auto& c : counts)
  {
    c.fill(0);
  }
  for (const T& v : values)
  {
    const std::uint64_t key = keyOf(v);
    for (int b = 0; b < 8; ++b)
    {
      ++counts[b][(key >> (8 * b)) & 0xff];
    }
  }
  Vector buffer(n);
  Vector* from = &values;
  Vector* to = &buffer;
  for (int b = 0; b < 8; ++b)
  {
    std::array<std::size_t, 256>& count = counts[b];
    const std::uint64_t first = (keyOf((*from)[0]) >> (8 * b)) & 0xff;
    if (count[first] == n)
    {
      continue; // every key has this byte
    }
    std::size_t start = 0;
    for (std::size_t& c : count)
    {
      const std::size_t here = c;
      c = start;
      start += here;
    }
    for (const T& v : *from)
    {
      (*to)[count[(keyOf(v) >> (8 * b)) & 0xff]++] = v;
    }
    std::swap(from, to);
  }
  if (from != &values)
  {
    values.swap(buffer);
  }
}

} // namespace rgmc

#endif

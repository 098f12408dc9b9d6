// A stable radix sort of records by a 64-bit unsigned key, for large arrays where std::sort's
// comparisons dominate (Seam Repair sorts a million vertex keys per million vertices).
#ifndef rgmcRadixSort_h
#define rgmcRadixSort_h

#include "rgmcBuffer.h"

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

/// Sorts the pairs (keyAt(i), i), 0 <= i < n, by key and then index (std::sort's order on the
/// pairs), and calls put(rank, key, index) for each in that order, when every key fits above the
/// bits of the largest index in one 64-bit word: each pair is then sorted as that one word, half
/// the bytes a radix pass moves of 16-byte pairs. Returns false, having called nothing, when a
/// key does not fit (the caller sorts its pairs with RadixSort).
template <typename KeyAt, typename Put>
bool RadixSortPacked(std::size_t n, KeyAt&& keyAt, Put&& put)
{
  int indexBits = 0;
  while (indexBits < 64 && (std::uint64_t(1) << indexBits) < n)
  {
    ++indexBits;
  }
  if (indexBits == 64)
  {
    return false;
  }
  const std::uint64_t largestKey = ~std::uint64_t(0) >> indexBits;
  LargeVector<std::uint64_t> packed(n);
  for (std::size_t i = 0; i < n; ++i)
  {
    const std::uint64_t key = keyAt(i);
    if (key > largestKey)
    {
      return false;
    }
    packed[i] = key << indexBits | i;
  }
  // Only the key's bits are sorted on: the indices increase in the input, and the sort is stable.
  RadixSort(packed, [indexBits](std::uint64_t word) { return word >> indexBits; });
  const std::uint64_t indexMask = (std::uint64_t(1) << indexBits) - 1;
  for (std::size_t r = 0; r < n; ++r)
  {
    put(r, packed[r] >> indexBits, static_cast<std::size_t>(packed[r] & indexMask));
  }
  return true;
}

} // namespace rgmc

#endif

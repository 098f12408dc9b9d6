// A stable radix sort of records by a 64-bit unsigned key, for large arrays where std::sort's
// comparisons dominate (Seam Repair sorts a million vertex keys per million vertices).
#ifndef rgmcRadixSort_h
#define rgmcRadixSort_h

#include "rgmcBuffer.h"

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <type_traits>
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

/// Runs task(i) for each i in [0, count), in order, on this thread: the default of the sorts'
/// `parallel` argument.
struct SerialTasks
{
  template <typename Task>
  void operator()(std::int64_t count, Task&& task) const
  {
    for (std::int64_t i = 0; i < count; ++i)
    {
      task(i);
    }
  }
};

/// Values per task of the parallel sorts (fixed: the ranges never depend on the threads).
constexpr std::size_t RadixRange = 65536;

/// RadixSort on tasks: parallel(count, task) runs task(i) for every i in [0, count), in any
/// order, possibly at once. Per byte pass, each range of RadixRange values counts its digits,
/// then scatters them after the same digit of the ranges before it: stable, so the result is
/// exactly RadixSort's.
template <typename Vector, typename KeyOf, typename Parallel>
void RadixSort(Vector& values, KeyOf&& keyOf, Parallel&& parallel)
{
  using T = typename Vector::value_type;
  using Counts = std::array<std::size_t, 256>;
  const std::size_t n = values.size();
  const std::size_t ranges = (n + RadixRange - 1) / RadixRange;
  if (ranges < 2 || std::is_same<typename std::decay<Parallel>::type, SerialTasks>::value)
  {
    RadixSort(values, keyOf); // one range, or no threads: without the per-pass counts
    return;
  }
  auto range = [n, ranges](std::size_t r, std::size_t& begin, std::size_t& end)
  {
    begin = n * r / ranges;
    end = n * (r + 1) / ranges;
  };
  // Which bytes differ among the keys: every byte's histogram, per range, summed.
  std::vector<std::array<Counts, 8>> all(ranges);
  parallel(static_cast<std::int64_t>(ranges),
    [&](std::int64_t r)
    {
      std::array<Counts, 8>& c = all[r];
      for (Counts& byte : c)
      {
        byte.fill(0);
      }
      std::size_t begin, end;
      range(static_cast<std::size_t>(r), begin, end);
      for (std::size_t i = begin; i < end; ++i)
      {
        const std::uint64_t key = keyOf(values[i]);
        for (int b = 0; b < 8; ++b)
        {
          ++c[b][(key >> (8 * b)) & 0xff];
        }
      }
    });
  Vector buffer(n);
  Vector* from = &values;
  Vector* to = &buffer;
  std::vector<Counts> place(ranges);
  bool moved = false; // a pass has moved the values
  for (int b = 0; b < 8; ++b)
  {
    const std::uint64_t first = (keyOf(values[0]) >> (8 * b)) & 0xff;
    std::size_t same = 0;
    for (const std::array<Counts, 8>& c : all)
    {
      same += c[b][first];
    }
    if (same == n)
    {
      continue; // every key has this byte
    }
    // This pass's digits per range of the current order (the histograms' own before the first
    // pass moved anything), then each range's first place.
    parallel(static_cast<std::int64_t>(ranges),
      [&](std::int64_t r)
      {
        Counts& c = place[r];
        if (!moved)
        {
          c = all[r][b];
          return;
        }
        c.fill(0);
        std::size_t begin, end;
        range(static_cast<std::size_t>(r), begin, end);
        for (std::size_t i = begin; i < end; ++i)
        {
          ++c[(keyOf((*from)[i]) >> (8 * b)) & 0xff];
        }
      });
    std::size_t start = 0;
    for (int d = 0; d < 256; ++d)
    {
      for (Counts& c : place)
      {
        const std::size_t here = c[d];
        c[d] = start;
        start += here;
      }
    }
    parallel(static_cast<std::int64_t>(ranges),
      [&](std::int64_t r)
      {
        Counts& next = place[r];
        std::size_t begin, end;
        range(static_cast<std::size_t>(r), begin, end);
        for (std::size_t i = begin; i < end; ++i)
        {
          const T& v = (*from)[i];
          (*to)[next[(keyOf(v) >> (8 * b)) & 0xff]++] = v;
        }
      });
    std::swap(from, to);
    moved = true;
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
template <typename KeyAt, typename Put, typename Parallel = SerialTasks>
bool RadixSortPacked(std::size_t n, KeyAt&& keyAt, Put&& put, Parallel&& parallel = Parallel())
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
  const std::int64_t ranges = static_cast<std::int64_t>((n + RadixRange - 1) / RadixRange);
  std::vector<char> fits(static_cast<std::size_t>(ranges), 1);
  parallel(ranges,
    [&](std::int64_t r)
    {
      for (std::size_t i = static_cast<std::size_t>(r) * RadixRange;
           i < std::min(n, static_cast<std::size_t>(r + 1) * RadixRange); ++i)
      {
        const std::uint64_t key = keyAt(i);
        fits[r] = fits[r] && key <= largestKey;
        packed[i] = key << indexBits | i;
      }
    });
  if (std::find(fits.begin(), fits.end(), 0) != fits.end())
  {
    return false;
  }
  // Only the key's bits are sorted on: the indices increase in the input, and the sort is stable.
  RadixSort(
    packed, [indexBits](std::uint64_t word) { return word >> indexBits; }, parallel);
  const std::uint64_t indexMask = (std::uint64_t(1) << indexBits) - 1;
  parallel(ranges,
    [&](std::int64_t r)
    {
      for (std::size_t i = static_cast<std::size_t>(r) * RadixRange;
           i < std::min(n, static_cast<std::size_t>(r + 1) * RadixRange); ++i)
      {
        put(i, packed[i] >> indexBits, static_cast<std::size_t>(packed[i] & indexMask));
      }
    });
  return true;
}

} // namespace rgmc

#endif

// A stable radix sort of records by a 64-bit unsigned key, for large arrays where std::sort's
// comparisons dominate (Seam Repair sorts a million vertex keys per million vertices).
#ifndef rgmcRadixSort_h
#define rgmcRadixSort_h

#include "rgmcBuffer.h"
#include "rgmcTasks.h"

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

/// Values per task of the parallel sorts (fixed: the ranges never depend on the threads).
constexpr std::size_t RadixRange = 65536;

/// The ranges of the parallel radix sort's tasks over n values.
struct RadixRanges
{
  std::size_t N, Count;
  std::size_t Begin(std::size_t r) const { return this->N * r / this->Count; }
  std::size_t End(std::size_t r) const { return this->N * (r + 1) / this->Count; }
};

using RadixCounts = std::array<std::size_t, 256>;

/// Every byte's histogram of the keys of each range.
template <typename Vector, typename KeyOf, typename Parallel>
std::vector<std::array<RadixCounts, 8>> RadixHistograms(
  const Vector& values, KeyOf& keyOf, Parallel& parallel, const RadixRanges& ranges)
{
  std::vector<std::array<RadixCounts, 8>> all(ranges.Count);
  parallel(static_cast<std::int64_t>(ranges.Count),
    [&](std::int64_t r)
    {
      std::array<RadixCounts, 8>& c = all[r];
      for (RadixCounts& byte : c)
      {
        byte.fill(0);
      }
      for (std::size_t i = ranges.Begin(r); i < ranges.End(r); ++i)
      {
        const std::uint64_t key = keyOf(values[i]);
        for (int b = 0; b < 8; ++b)
        {
          ++c[b][(key >> (8 * b)) & 0xff];
        }
      }
    });
  return all;
}

/// One stable pass on byte b from `from` to `to`: each range's digits (`place`, counted already
/// when `counted`), then each range's first place for each digit, then the scatter.
template <typename Vector, typename KeyOf, typename Parallel>
void RadixPass(const Vector& from, Vector& to, int b, KeyOf& keyOf, Parallel& parallel,
  const RadixRanges& ranges, std::vector<RadixCounts>& place, bool counted)
{
  auto digit = [&keyOf, b](const typename Vector::value_type& v)
  { return (keyOf(v) >> (8 * b)) & 0xff; };
  if (!counted)
  {
    parallel(static_cast<std::int64_t>(ranges.Count),
      [&](std::int64_t r)
      {
        place[r].fill(0);
        for (std::size_t i = ranges.Begin(r); i < ranges.End(r); ++i)
        {
          ++place[r][digit(from[i])];
        }
      });
  }
  std::size_t start = 0;
  for (int d = 0; d < 256; ++d)
  {
    for (RadixCounts& c : place)
    {
      const std::size_t here = c[d];
      c[d] = start;
      start += here;
    }
  }
  parallel(static_cast<std::int64_t>(ranges.Count),
    [&](std::int64_t r)
    {
      RadixCounts& next = place[r];
      for (std::size_t i = ranges.Begin(r); i < ranges.End(r); ++i)
      {
        to[next[digit(from[i])]++] = from[i];
      }
    });
}

/// RadixSort on tasks: parallel(count, task) runs task(i) for every i in [0, count), in any
/// order, possibly at once. Per byte pass, each range of RadixRange values counts its digits
/// (the histograms' own before the first pass moved anything), then scatters them after the
/// same digit of the ranges before it: stable, so the result is exactly RadixSort's.
template <typename Vector, typename KeyOf, typename Parallel>
void RadixSort(Vector& values, KeyOf&& keyOf, Parallel&& parallel)
{
  const std::size_t n = values.size();
  const RadixRanges ranges{ n, (n + RadixRange - 1) / RadixRange };
  if (ranges.Count < 2 || std::is_same<typename std::decay<Parallel>::type, SerialTasks>::value)
  {
    RadixSort(values, keyOf); // one range, or no threads: without the per-pass counts
    return;
  }
  // Which bytes differ among the keys: the histograms, summed.
  const std::vector<std::array<RadixCounts, 8>> all =
    RadixHistograms(values, keyOf, parallel, ranges);
  Vector buffer(n);
  // An unset buffer (OverwriteVector) first touched range by range: a scatter's first range
  // writes into every digit's part of it, and so would fault in all its (huge) pages in one
  // task. Other vectors come zeroed, their pages touched already.
  if (LeavesValuesUnset<Vector>::value)
  {
    parallel(static_cast<std::int64_t>(ranges.Count),
      [&](std::int64_t r)
      {
        std::fill(buffer.begin() + ranges.Begin(r), buffer.begin() + ranges.End(r),
          typename Vector::value_type());
      });
  }
  Vector* from = &values;
  Vector* to = &buffer;
  std::vector<RadixCounts> place(ranges.Count);
  bool moved = false; // a pass has moved the values
  for (int b = 0; b < 8; ++b)
  {
    const std::uint64_t first = (keyOf(values[0]) >> (8 * b)) & 0xff;
    std::size_t same = 0;
    for (const std::array<RadixCounts, 8>& c : all)
    {
      same += c[b][first];
    }
    if (same == n)
    {
      continue; // every key has this byte
    }
    if (!moved)
    {
      for (std::size_t r = 0; r < ranges.Count; ++r)
      {
        place[r] = all[r][b];
      }
    }
    RadixPass(*from, *to, b, keyOf, parallel, ranges, place, !moved);
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
  OverwriteVector<std::uint64_t> packed(n); // written whole below
  const std::int64_t ranges = static_cast<std::int64_t>((n + RadixRange - 1) / RadixRange);
  std::vector<std::uint8_t> fits(static_cast<std::size_t>(ranges), 1);
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

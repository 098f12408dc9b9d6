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
#include <utility>
#include <vector>

namespace rgmc
{

/// The digits a radix sort passes over: only those in which two keys differ (known from the OR
/// and the AND of all keys), each `Bits` wide from its lowest bit `Shift[p]`. Bytes, or wider
/// digits (up to 11 bits: 2048 counts a digit) where they take fewer passes: keys of 20 bits are
/// sorted in two passes of 10 bits, not three of 8.
struct RadixDigits
{
  int Bits = 8;
  int Passes = 0; // 0: all keys are equal
  int Shift[8] = {};

  std::size_t Size() const { return std::size_t(1) << this->Bits; }
  std::size_t Of(std::uint64_t key, int p) const
  {
    return static_cast<std::size_t>(key >> this->Shift[p]) & (this->Size() - 1);
  }

  /// The fewest passes over digits of 8 to 11 bits, the narrowest digits among them, from the
  /// OR (`any`) and the AND (`every`) of the keys.
  static RadixDigits For(std::uint64_t any, std::uint64_t every)
  {
    const std::uint64_t differ = any & ~every;
    int low = 0;
    while (low < 64 && !((differ >> low) & 1))
    {
      ++low;
    }
    RadixDigits best;
    for (int bits = 8; bits <= 11; ++bits)
    {
      RadixDigits digits;
      digits.Bits = bits;
      for (int shift = low; shift < 64; shift += bits)
      {
        if ((differ >> shift) & ((std::uint64_t(1) << bits) - 1))
        {
          digits.Shift[digits.Passes++] = shift;
        }
      }
      if (bits == 8 || digits.Passes < best.Passes)
      {
        best = digits;
      }
    }
    return best;
  }
};

/// The OR and the AND of the keys of values[begin, end), folded into any and every.
template <typename Vector, typename KeyOf>
void RadixKeyBits(const Vector& values, KeyOf& keyOf, std::size_t begin, std::size_t end,
  std::uint64_t& any, std::uint64_t& every)
{
  for (std::size_t i = begin; i < end; ++i)
  {
    const std::uint64_t key = keyOf(values[i]);
    any |= key;
    every &= key;
  }
}

/// Sorts `values` (a std::vector, with any allocator) by `keyOf(value)` (a std::uint64_t, compared
/// as unsigned), least significant digit first, over the digits in which keys differ
/// (RadixDigits). Stable: values with equal keys keep their order. So records (key, index) whose
/// indices increase in the input come out exactly as std::sort on (key, index) gives them.
template <typename Vector, typename KeyOf>
void RadixSort(Vector& values, KeyOf&& keyOf)
{
  using T = typename Vector::value_type;
  const std::size_t n = values.size();
  if (n < 2)
  {
    return;
  }
  std::uint64_t any = 0, every = ~std::uint64_t(0);
  RadixKeyBits(values, keyOf, 0, n, any, every);
  const RadixDigits digits = RadixDigits::For(any, every);
  if (digits.Passes == 0)
  {
    return;
  }
  // Every digit's histogram in one pass.
  const std::size_t size = digits.Size();
  std::vector<std::size_t> counts(digits.Passes * size, 0);
  for (const T& v : values)
  {
    const std::uint64_t key = keyOf(v);
    for (int p = 0; p < digits.Passes; ++p)
    {
      ++counts[p * size + digits.Of(key, p)];
    }
  }
  Vector buffer(n);
  Vector* from = &values;
  Vector* to = &buffer;
  for (int p = 0; p < digits.Passes; ++p)
  {
    std::size_t* count = counts.data() + p * size;
    std::size_t start = 0;
    for (std::size_t d = 0; d < size; ++d)
    {
      const std::size_t here = count[d];
      count[d] = start;
      start += here;
    }
    for (const T& v : *from)
    {
      (*to)[count[digits.Of(keyOf(v), p)]++] = v;
    }
    std::swap(from, to);
  }
  if (from != &values)
  {
    values.swap(buffer);
  }
}

/// Values per task of the parallel sorts (fixed: the ranges never depend on the threads).
constexpr std::size_t RadixRange = 16384;

/// The ranges of the parallel radix sort's tasks over n values.
struct RadixRanges
{
  std::size_t N, Count;
  std::size_t Begin(std::size_t r) const { return this->N * r / this->Count; }
  std::size_t End(std::size_t r) const { return this->N * (r + 1) / this->Count; }
};

/// One stable pass on digit p from `from` to `to`: each range counts its digits, then each
/// range's first place for each digit value follows the same value's places in the ranges before
/// it, then each range scatters. `place` holds one count a digit value and range, digit-major
/// (digit d of range r at d * ranges + r), so that the serial sum walks it in memory order; a
/// range-major table put the ranges' entries of one digit 8-16 KiB apart, in one cache set
/// (with 62 ranges, the sums took 1.4 ms of the 512^3 skull's sort on one thread).
template <typename Vector, typename KeyOf, typename Parallel>
void RadixPass(const Vector& from, Vector& to, const RadixDigits& digits, int p, KeyOf& keyOf,
  Parallel& parallel, const RadixRanges& ranges, std::vector<std::size_t>& place)
{
  const std::size_t size = digits.Size();
  auto digit = [&](const typename Vector::value_type& v) { return digits.Of(keyOf(v), p); };
  parallel(static_cast<std::int64_t>(ranges.Count),
    [&](std::int64_t r)
    {
      std::vector<std::size_t> count(size, 0);
      for (std::size_t i = ranges.Begin(r); i < ranges.End(r); ++i)
      {
        ++count[digit(from[i])];
      }
      for (std::size_t d = 0; d < size; ++d)
      {
        place[d * ranges.Count + static_cast<std::size_t>(r)] = count[d];
      }
    });
  std::size_t start = 0;
  for (std::size_t& c : place)
  {
    start += std::exchange(c, start);
  }
  parallel(static_cast<std::int64_t>(ranges.Count),
    [&](std::int64_t r)
    {
      std::vector<std::size_t> next(size);
      for (std::size_t d = 0; d < size; ++d)
      {
        next[d] = place[d * ranges.Count + static_cast<std::size_t>(r)];
      }
      for (std::size_t i = ranges.Begin(r); i < ranges.End(r); ++i)
      {
        to[next[digit(from[i])]++] = from[i];
      }
    });
}

/// RadixSort on tasks: parallel(count, task) runs task(i) for every i in [0, count), in any
/// order, possibly at once. The keys' OR and AND range by range, then per digit pass each range
/// of RadixRange values counts its digits and scatters them after the same digit of the ranges
/// before it: stable, so the result is exactly RadixSort's.
template <typename Vector, typename KeyOf, typename Parallel>
void RadixSort(Vector& values, KeyOf&& keyOf, Parallel&& parallel)
{
  const std::size_t n = values.size();
  const RadixRanges ranges{ n, (n + RadixRange - 1) / RadixRange };
  if (ranges.Count < 2 || std::is_same<typename std::decay<Parallel>::type, SerialTasks>::value)
  {
    RadixSort(values, keyOf); // one range, or no threads: one histogram pass for every digit
    return;
  }
  std::vector<std::array<std::uint64_t, 2>> bits(ranges.Count, { 0, ~std::uint64_t(0) });
  parallel(static_cast<std::int64_t>(ranges.Count),
    [&](std::int64_t r)
    { RadixKeyBits(values, keyOf, ranges.Begin(r), ranges.End(r), bits[r][0], bits[r][1]); });
  std::uint64_t any = 0, every = ~std::uint64_t(0);
  for (const auto& b : bits)
  {
    any |= b[0];
    every &= b[1];
  }
  const RadixDigits digits = RadixDigits::For(any, every);
  if (digits.Passes == 0)
  {
    return;
  }
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
  std::vector<std::size_t> place(ranges.Count * digits.Size());
  for (int p = 0; p < digits.Passes; ++p)
  {
    RadixPass(*from, *to, digits, p, keyOf, parallel, ranges, place);
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

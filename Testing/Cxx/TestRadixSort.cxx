// Unit test of rgmc::RadixSort and rgmc::RadixSortPacked against std::sort: (key, index) records
// come out as std::sort on the pairs gives them, for keys that differ in few or many bytes, with
// many equal keys, and for keys whose top bits are set (unsigned order); the packed sort runs
// exactly when every key fits above the indices' bits; on tasks (ranges of 65 536 values) run
// in reverse order and on threads, the same, in a vector that leaves new values unset too; the
// digits the sorts pass over are those in which keys differ, bytes or wider where that saves a
// pass. And rgmc::GroupByKey (Seam Repair's corners by vertex on threads) against a counting pass
// in order.
#include "rgmcCheck.h"
#include "rgmcRadixSort.h"
#include "rgmcTaskOrders.h"

#include <algorithm>
#include <cstdint>
#include <random>
#include <utility>
#include <vector>

namespace
{

using Record = std::pair<std::uint64_t, std::int64_t>;

void Check(const std::vector<std::uint64_t>& keys, const char* what)
{
  std::vector<Record> sorted(keys.size()), expected(keys.size());
  for (std::size_t i = 0; i < keys.size(); ++i)
  {
    sorted[i] = expected[i] = Record(keys[i], static_cast<std::int64_t>(i));
  }
  std::sort(expected.begin(), expected.end());
  rgmc::RadixSort(sorted, [](const Record& r) { return r.first; });
  RGMC_CHECK(sorted == expected, what << ": " << keys.size() << " keys");
  // Packed with the indices when every key fits above them; refused otherwise.
  int indexBits = 0;
  while ((std::uint64_t(1) << indexBits) < keys.size())
  {
    ++indexBits;
  }
  const bool fits = std::all_of(keys.begin(), keys.end(),
    [indexBits](std::uint64_t k) { return k <= (~std::uint64_t(0) >> indexBits); });
  std::vector<Record> packed(keys.size(), Record(0, -1));
  const bool done = rgmc::RadixSortPacked(
    keys.size(), [&keys](std::size_t i) { return keys[i]; },
    [&packed](std::size_t r, std::uint64_t key, std::size_t i)
    { packed[r] = Record(key, static_cast<std::int64_t>(i)); });
  RGMC_CHECK(done == fits,
    what << ": " << keys.size() << " keys " << (fits ? "fit" : "do not fit") << " above "
         << indexBits << " index bits, but the packed sort " << (done ? "ran" : "refused"));
  RGMC_CHECK(!done || packed == expected, what << ": " << keys.size() << " keys, packed");

  // On tasks, run in reverse order and on 4 threads: the same records in the same order.
  for (int mode = 0; mode < 2; ++mode)
  {
    auto parallel = mode == 0 ? rgmc_test::TasksReversed : rgmc_test::TasksOnThreads;
    const char* how = mode == 0 ? "tasks reversed" : "tasks on threads";
    std::vector<Record> onTasks(keys.size());
    for (std::size_t i = 0; i < keys.size(); ++i)
    {
      onTasks[i] = Record(keys[i], static_cast<std::int64_t>(i));
    }
    rgmc::RadixSort(
      onTasks, [](const Record& r) { return r.first; }, parallel);
    RGMC_CHECK(onTasks == expected, what << ", " << how << ": " << keys.size() << " keys");
    // A vector that leaves its values unset (its buffer then first touched range by range).
    rgmc::OverwriteVector<Record> unset(onTasks.size());
    for (std::size_t i = 0; i < keys.size(); ++i)
    {
      unset[i] = Record(keys[i], static_cast<std::int64_t>(i));
    }
    rgmc::RadixSort(
      unset, [](const Record& r) { return r.first; }, parallel);
    RGMC_CHECK(std::equal(unset.begin(), unset.end(), expected.begin(), expected.end()),
      what << ", " << how << ", unset buffer: " << keys.size() << " keys");
    std::vector<Record> packedOnTasks(keys.size(), Record(0, -1));
    const bool doneOnTasks = rgmc::RadixSortPacked(
      keys.size(), [&keys](std::size_t i) { return keys[i]; },
      [&packedOnTasks](std::size_t r, std::uint64_t key, std::size_t i)
      { packedOnTasks[r] = Record(key, static_cast<std::int64_t>(i)); },
      parallel);
    RGMC_CHECK(doneOnTasks == fits && (!doneOnTasks || packedOnTasks == expected),
      what << ", " << how << ": " << keys.size() << " keys, packed");
  }
}

/// rgmc::GroupByKey against one counting pass in order: the same offsets and items, on tasks in
/// order, reversed and on threads; or a refusal, with nothing changed, exactly when the chunks'
/// ranges of keys (65 536 indices a chunk) add up to more than 2 (n + keys).
void CheckGroups(const std::vector<int>& keyOf, std::int64_t keys, const char* what)
{
  const std::int64_t n = static_cast<std::int64_t>(keyOf.size());
  std::vector<std::int64_t> offsets(static_cast<std::size_t>(keys) + 1, 0);
  for (int k : keyOf)
  {
    ++offsets[static_cast<std::size_t>(k) + 1];
  }
  for (std::int64_t k = 0; k < keys; ++k)
  {
    offsets[k + 1] += offsets[k];
  }
  std::vector<std::int64_t> place(offsets.begin(), offsets.end() - 1);
  std::vector<std::int32_t> items(keyOf.size());
  for (std::int64_t i = 0; i < n; ++i)
  {
    items[static_cast<std::size_t>(place[keyOf[i]]++)] = static_cast<std::int32_t>(i);
  }
  std::int64_t ranges = 0;
  for (std::int64_t c = 0; c < n; c += rgmc::GroupChunk)
  {
    const auto chunk =
      std::minmax_element(keyOf.begin() + c, keyOf.begin() + std::min(n, c + rgmc::GroupChunk));
    ranges += *chunk.second - *chunk.first + 1;
  }
  const bool local = ranges <= 2 * (n + keys);
  for (int mode = 0; mode < 3; ++mode)
  {
    auto parallel = mode == 0 ? rgmc_test::TasksInOrder
      : mode == 1             ? rgmc_test::TasksReversed
                              : rgmc_test::TasksOnThreads;
    std::vector<std::int64_t> gotOffsets{ -1 };
    rgmc::LargeVector<std::int32_t> gotItems(3, -1);
    const bool done = rgmc::GroupByKey(
      n, keys, [&keyOf](std::int64_t i) { return keyOf[static_cast<std::size_t>(i)]; }, gotOffsets,
      gotItems, parallel);
    RGMC_CHECK(done == local,
      what << ", mode " << mode << ": ranges " << ranges << " of " << 2 * (n + keys)
           << " allowed, but " << (done ? "grouped" : "refused"));
    if (done)
    {
      RGMC_CHECK(gotOffsets == offsets &&
          std::equal(gotItems.begin(), gotItems.end(), items.begin(), items.end()),
        what << ", mode " << mode << ": " << n << " indices, " << keys << " keys");
    }
    else
    {
      RGMC_CHECK(gotOffsets.size() == 1 && gotItems.size() == 3,
        what << ", mode " << mode << ": refused, yet the outputs changed");
    }
  }
  // Outputs that leave their values unset (as Seam Repair's corners are), here holding stale
  // values of the right sizes: every value is written.
  if (local)
  {
    rgmc::OverwriteVector<std::int64_t> gotOffsets(offsets.size(), 77);
    rgmc::OverwriteVector<std::int32_t> gotItems(items.size(), -5);
    rgmc::GroupByKey(
      n, keys, [&keyOf](std::int64_t i) { return keyOf[static_cast<std::size_t>(i)]; }, gotOffsets,
      gotItems, rgmc_test::TasksOnThreads);
    RGMC_CHECK(std::equal(gotOffsets.begin(), gotOffsets.end(), offsets.begin(), offsets.end()) &&
        std::equal(gotItems.begin(), gotItems.end(), items.begin(), items.end()),
      what << ": unset outputs with stale values, every value written");
  }
}

/// RadixDigits::For(any, every) against the expected digits: their width and lowest bits.
void CheckDigits(std::uint64_t any, std::uint64_t every, int bits, std::vector<int> shifts)
{
  const rgmc::RadixDigits digits = rgmc::RadixDigits::For(any, every);
  const std::vector<int> got(digits.Shift, digits.Shift + digits.Passes);
  RGMC_CHECK((shifts.empty() || digits.Bits == bits) && got == shifts,
    "keys ORed to " << std::hex << any << ", ANDed to " << every << std::dec << ": " << got.size()
                    << " passes of " << digits.Bits << " bits, expected " << shifts.size() << " of "
                    << bits);
}

static_assert(rgmc::LeavesValuesUnset<rgmc::OverwriteVector<Record>>::value &&
    rgmc::LeavesValuesUnset<rgmc::HeapOverwriteVector<Record>>::value &&
    !rgmc::LeavesValuesUnset<rgmc::LargeVector<Record>>::value &&
    !rgmc::LeavesValuesUnset<std::vector<Record>>::value,
  "only an OverwriteVector (of either allocator) leaves its values unset");

} // namespace

int main()
{
  std::mt19937_64 random(20261125);
  Check({}, "empty");
  Check({ 7 }, "one key");
  Check({ 5, 5, 5, 5 }, "all equal");
  // The digits: only where keys differ; the fewest passes of 8 to 11 bits, the narrowest of them.
  const std::uint64_t all = ~std::uint64_t(0);
  CheckDigits(5, 5, 8, {});
  CheckDigits(0x18, 0, 8, { 3 });                        // bits 3 and 4
  CheckDigits(0xffff, 0, 8, { 0, 8 });                   // 16 bits: two bytes
  CheckDigits(0xfffff, 0, 10, { 0, 10 });                // 20 bits: two passes of 10, not three
  CheckDigits(0xfffff << 7, 0, 10, { 7, 17 });           // the same from bit 7
  CheckDigits(0xffffffff, 0, 11, { 0, 11, 22 });         // 32 bits: three of 11, not four
  CheckDigits(all, 0, 11, { 0, 11, 22, 33, 44, 55 });    // 64 bits: six of 11, not eight
  CheckDigits(0xff000000000000ffULL, 0, 8, { 0, 56 });   // two bytes far apart: wider would take 3
  CheckDigits(all, 0x00ffffffffffff00ULL, 8, { 0, 56 }); // the same, the bytes between agreeing
  for (std::size_t n : { 2, 3, 255, 256, 257, 10000, 65536, 65537, 300000 })
  {
    std::vector<std::uint64_t> keys(n);
    // Vertex-key-like: 30 significant bits, the upper bytes the same.
    for (auto& k : keys)
    {
      k = random() & ((std::uint64_t(1) << 30) - 1);
    }
    Check(keys, "30-bit keys");
    // Bucket-key-like: 20 significant bits (two passes of 10 bits).
    for (auto& k : keys)
    {
      k = random() & ((std::uint64_t(1) << 20) - 1);
    }
    Check(keys, "20-bit keys");
    // Full 64-bit keys, the top bit set in half of them.
    for (auto& k : keys)
    {
      k = random();
    }
    Check(keys, "64-bit keys");
    // Many repeats (few distinct keys), spread over high and low bytes.
    for (auto& k : keys)
    {
      k = (random() % 7) << 56 | (random() % 3);
    }
    Check(keys, "repeated keys");
    // Already sorted and reversed.
    std::sort(keys.begin(), keys.end());
    Check(keys, "sorted keys");
    std::reverse(keys.begin(), keys.end());
    Check(keys, "reversed keys");
  }
  // Keys just below and just above the room the indices leave (300 000 indices: 19 bits).
  for (std::uint64_t top : { ~std::uint64_t(0) >> 19, (~std::uint64_t(0) >> 19) + 1 })
  {
    std::vector<std::uint64_t> keys(300000);
    for (auto& k : keys)
    {
      k = random() % (top + 1);
    }
    keys[12345] = top;
    Check(keys, "keys at the packed sort's limit");
  }
  // Keys equal in every byte but one, in each position.
  for (int b = 0; b < 8; ++b)
  {
    std::vector<std::uint64_t> keys(1000);
    for (auto& k : keys)
    {
      k = 0x0123456789abcdefULL ^ ((random() & 0xff) << (8 * b));
    }
    Check(keys, "one varying byte");
  }
  // Grouping by key: keys that follow the indices as a mesh's vertices follow its corners (some
  // keys without an index, chunk boundaries in every place), and keys scattered at random.
  const std::int64_t chunk = rgmc::GroupChunk;
  for (std::int64_t n : { std::int64_t(0), std::int64_t(1), std::int64_t(5), chunk - 1, chunk,
         chunk + 1, 4 * chunk - 1, 4 * chunk + 1, std::int64_t(400000) })
  {
    const std::int64_t keys = n / 6 + 50;
    std::vector<int> keyOf(static_cast<std::size_t>(n));
    for (std::int64_t i = 0; i < n; ++i)
    {
      const std::int64_t k = i / 6 + static_cast<std::int64_t>(random() % 2001) - 1000;
      keyOf[i] = static_cast<int>(std::max<std::int64_t>(0, std::min(keys - 1, k)));
    }
    CheckGroups(keyOf, keys, "keys that follow the indices");
    for (int& k : keyOf)
    {
      k = static_cast<int>(random() % static_cast<std::uint64_t>(keys));
    }
    CheckGroups(keyOf, keys, "scattered keys");
  }
  // As many keys as indices, scattered: refused (every chunk over nearly all 300 000 keys).
  std::vector<int> scattered(300000);
  for (int& k : scattered)
  {
    k = static_cast<int>(random() % 300000);
  }
  scattered[0] = 0;
  scattered[1] = 299999;
  CheckGroups(scattered, 300000, "as many keys as indices, scattered");
  // A few far keys among local ones: grouped while the ranges allow.
  std::vector<int> keyOf(300000);
  for (std::size_t i = 0; i < keyOf.size(); ++i)
  {
    keyOf[i] = static_cast<int>(i / 3);
  }
  keyOf[70000] = 99999;
  keyOf[200000] = 0;
  CheckGroups(keyOf, 100000, "a few far keys");
  return rgmc_test::Result("TestRadixSort");
}

// Unit test of rgmc::RadixSort and rgmc::RadixSortPacked against std::sort: (key, index) records
// come out as std::sort on the pairs gives them, for keys that differ in few or many bytes, with
// many equal keys, and for keys whose top bits are set (unsigned order); the packed sort runs
// exactly when every key fits above the indices' bits; on tasks (ranges of 65 536 values) run
// in reverse order and on threads, the same, in a vector that leaves new values unset too.
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

static_assert(rgmc::LeavesValuesUnset<rgmc::OverwriteVector<Record>>::value &&
    !rgmc::LeavesValuesUnset<rgmc::LargeVector<Record>>::value &&
    !rgmc::LeavesValuesUnset<std::vector<Record>>::value,
  "only an OverwriteVector leaves its values unset");

} // namespace

int main()
{
  std::mt19937_64 random(20261125);
  Check({}, "empty");
  Check({ 7 }, "one key");
  Check({ 5, 5, 5, 5 }, "all equal");
  for (std::size_t n : { 2, 3, 255, 256, 257, 10000, 65536, 65537, 300000 })
  {
    std::vector<std::uint64_t> keys(n);
    // Vertex-key-like: 30 significant bits, the upper bytes the same.
    for (auto& k : keys)
    {
      k = random() & ((std::uint64_t(1) << 30) - 1);
    }
    Check(keys, "30-bit keys");
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
  return rgmc_test::Result("TestRadixSort");
}

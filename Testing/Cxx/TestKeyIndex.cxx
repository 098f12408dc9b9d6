// Unit test of rgmc::KeyIndex: every key of a distinct set found at its place, and keys not in
// the set not found, whether its tasks run in order, in reverse or on threads (where each key
// lands then differs, what Find returns must not); sets with clustered keys (neighbours whose
// homes collide), spread 64-bit keys, key 0, one key, none.
#include "rgmcCheck.h"
#include "rgmcKeyIndex.h"
#include "rgmcTaskOrders.h"

#include <algorithm>
#include <cstdint>
#include <random>
#include <set>
#include <vector>

namespace
{

void Check(const std::vector<std::int64_t>& keys, const char* what, std::mt19937_64& random)
{
  const std::set<std::int64_t> in(keys.begin(), keys.end());
  for (int mode = 0; mode < 3; ++mode)
  {
    auto parallel = mode == 0 ? rgmc_test::TasksInOrder
                              : (mode == 1 ? rgmc_test::TasksReversed : rgmc_test::TasksOnThreads);
    const rgmc::KeyIndex index(
      keys.size(), [&keys](std::size_t i) { return keys[i]; }, parallel);
    std::size_t wrong = 0;
    for (std::size_t i = 0; i < keys.size(); ++i)
    {
      wrong += index.Find(keys[i]) != static_cast<std::int64_t>(i);
    }
    RGMC_CHECK(wrong == 0,
      what << ", tasks " << mode << ": " << wrong << " of " << keys.size()
           << " keys not found at their place");
    std::size_t found = 0;
    for (int k = 0; k < 20000; ++k)
    {
      const std::int64_t key = static_cast<std::int64_t>(random() >> (k % 2 ? 1 : 40));
      found += in.count(key) == 0 && index.Find(key) >= 0;
    }
    RGMC_CHECK(found == 0, what << ", tasks " << mode << ": " << found << " absent keys found");
  }
}

} // namespace

int main()
{
  std::mt19937_64 random(20261130);
  Check({}, "no keys", random);
  Check({ 0 }, "key 0", random);
  Check({ 12345 }, "one key", random);
  RGMC_CHECK(rgmc::KeyIndex().Find(7) == -1, "an empty index finds nothing");
  for (std::size_t n : { 3, 1000, 65536, 65537, 300000 })
  {
    // A surface's buckets: runs of neighbouring keys, in increasing order.
    std::vector<std::int64_t> keys;
    std::int64_t key = static_cast<std::int64_t>(random() % 1000);
    while (keys.size() < n)
    {
      key += 1 + static_cast<std::int64_t>(random() % 4 == 0 ? random() % 5000 : 0);
      keys.push_back(key);
    }
    Check(keys, "runs of neighbouring keys", random);
    // Spread keys, shuffled.
    std::set<std::int64_t> spread;
    while (spread.size() < n)
    {
      spread.insert(static_cast<std::int64_t>(random() >> 1));
    }
    keys.assign(spread.begin(), spread.end());
    std::shuffle(keys.begin(), keys.end(), random);
    Check(keys, "spread 63-bit keys", random);
  }
  return rgmc_test::Result("TestKeyIndex");
}

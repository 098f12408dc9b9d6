// Unit test of rgmc::MinHeap (the decimation's queue of candidate collapses) against
// std::priority_queue: the same values popped in the same order under a total order, through
// pushes and pops interleaved as the decimation makes them (many pushes after each pop), from
// one value to heaps of tens of thousands, with many equal keys; and under an order with
// equivalent values, every pop the least and the values popped those pushed. Both with 8-byte
// values and with 16-byte ones, which the heap lays out so that a node's children share a cache
// line.
#include "rgmcCheck.h"
#include "rgmcMinHeap.h"

#include <algorithm>
#include <cstdint>
#include <functional>
#include <queue>
#include <random>
#include <vector>

namespace
{

struct Entry
{
  int Key;
  int Tie;
  bool operator==(const Entry& other) const
  {
    return this->Key == other.Key && this->Tie == other.Tie;
  }
};

// 16 bytes, like the decimation's candidates: four fill a cache line.
struct WideEntry
{
  std::int64_t Key;
  std::int64_t Tie;
  bool operator==(const WideEntry& other) const
  {
    return this->Key == other.Key && this->Tie == other.Tie;
  }
};

struct ByKeyThenTie
{
  template <typename E>
  bool operator()(const E& x, const E& y) const
  {
    return x.Key != y.Key ? x.Key < y.Key : x.Tie < y.Tie;
  }
};

struct ByKey
{
  bool operator()(const Entry& x, const Entry& y) const { return x.Key < y.Key; }
};

// `rounds` rounds of one pop and up to `pushes` pushes, after `initial` pushes; keys below
// `keys`, so that many are equal. Ties are distinct: the order is total.
template <typename E>
void CheckAgainstPriorityQueue(int initial, int rounds, int pushes, int keys, unsigned seed)
{
  std::mt19937 random(seed);
  std::uniform_int_distribution<int> key(0, keys - 1), count(0, pushes);
  rgmc::MinHeap<E, ByKeyThenTie> heap;
  // std::priority_queue's top is the greatest: reverse the order.
  auto after = [](const E& x, const E& y) { return ByKeyThenTie()(y, x); };
  std::priority_queue<E, std::vector<E>, decltype(after)> expected(after);
  int tie = 0;
  auto push = [&]()
  {
    const E e{ key(random), tie++ };
    heap.Push(e);
    expected.push(e);
  };
  for (int i = 0; i < initial; ++i)
  {
    push();
  }
  for (int r = 0; r < rounds && !expected.empty(); ++r)
  {
    RGMC_CHECK(heap.Size() == expected.size(), "sizes agree before pop " << r);
    // The root sits three values before a cache line, where its children start.
    const auto address = reinterpret_cast<std::uintptr_t>(&heap.Top());
    RGMC_CHECK(sizeof(E) != 16 || address % 64 == 48,
      "a 16-byte root at " << address % 64 << " bytes into its cache line, not 48");
    RGMC_CHECK(heap.Top() == expected.top(),
      "seed " << seed << ", pop " << r << ": key " << heap.Top().Key << " tie " << heap.Top().Tie
              << " where " << expected.top().Key << " " << expected.top().Tie << " was expected");
    heap.Pop();
    expected.pop();
    for (int p = count(random); p > 0; --p)
    {
      push();
    }
  }
  while (!expected.empty())
  {
    RGMC_CHECK(heap.Top() == expected.top(), "seed " << seed << ": the drained order differs");
    heap.Pop();
    expected.pop();
  }
  RGMC_CHECK(heap.Empty(), "the heap is empty when the queue is");
}

// Under an order with equivalent values: non-decreasing keys, and the values pushed come out.
void CheckEquivalents(int n, unsigned seed)
{
  std::mt19937 random(seed);
  std::uniform_int_distribution<int> key(0, 9);
  rgmc::MinHeap<Entry, ByKey> heap;
  std::vector<Entry> pushed, popped;
  for (int i = 0; i < n; ++i)
  {
    pushed.push_back(Entry{ key(random), i });
    heap.Push(pushed.back());
  }
  while (!heap.Empty())
  {
    popped.push_back(heap.Top());
    heap.Pop();
    RGMC_CHECK(popped.size() < 2 || popped[popped.size() - 2].Key <= popped.back().Key,
      "pop " << popped.size() - 1 << " is not the least");
  }
  auto byTie = [](const Entry& x, const Entry& y) { return x.Tie < y.Tie; };
  std::sort(popped.begin(), popped.end(), byTie);
  RGMC_CHECK(popped == pushed, "the values popped are the values pushed");
}

} // namespace

int main()
{
  for (int wide : { 0, 1 })
  {
    auto check = wide ? CheckAgainstPriorityQueue<WideEntry> : CheckAgainstPriorityQueue<Entry>;
    check(1, 1, 0, 1, 1);
    check(2, 5, 1, 2, 2);
    for (unsigned seed = 3; seed < 13; ++seed)
    {
      check(static_cast<int>(seed * seed), 200, 3, 4, seed); // small, all tied
    }
    check(30000, 20000, 14, 1000, 21); // the decimation's shape
    check(0, 50000, 2, 1 << 30, 22);   // growing from empty, few ties
  }
  CheckEquivalents(5000, 31);
  return rgmc_test::Result("TestMinHeap");
}

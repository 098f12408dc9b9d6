// A priority queue whose nodes have four children: half the levels of a binary heap, and a
// node's children side by side in memory, so that a pop, which walks from the root to a leaf,
// misses the cache about half as often (the decimation's queues of candidate collapses hold
// tens of thousands of them, more than the core's nearest caches).
#ifndef rgmcMinHeap_h
#define rgmcMinHeap_h

#include <cstddef>
#include <utility>
#include <vector>

namespace rgmc
{

/// The least value first, by `Less` (a strict weak order). Values that `Less` finds equivalent
/// come out in an order of the heap's own; where that matters, make `Less` a total order.
template <typename Value, typename Less>
class MinHeap
{
public:
  explicit MinHeap(Less less = Less())
    : Before(std::move(less))
  {
  }

  bool Empty() const { return this->Values.empty(); }
  std::size_t Size() const { return this->Values.size(); }
  const Value& Top() const { return this->Values.front(); }

  void Push(Value value)
  {
    std::size_t hole = this->Values.size();
    this->Values.push_back(value);
    while (hole > 0)
    {
      const std::size_t parent = (hole - 1) / Arity;
      if (!this->Before(value, this->Values[parent]))
      {
        break;
      }
      this->Values[hole] = std::move(this->Values[parent]);
      hole = parent;
    }
    this->Values[hole] = std::move(value);
  }

  void Pop()
  {
    Value last = std::move(this->Values.back());
    this->Values.pop_back();
    const std::size_t n = this->Values.size();
    if (n == 0)
    {
      return;
    }
    // The hole left at the root goes down to the least child, while that is before the last
    // value, which then fills it.
    std::size_t hole = 0;
    for (;;)
    {
      const std::size_t first = Arity * hole + 1;
      if (first >= n)
      {
        break;
      }
      std::size_t least = first;
      const std::size_t end = first + Arity < n ? first + Arity : n;
      for (std::size_t c = first + 1; c < end; ++c)
      {
        least = this->Before(this->Values[c], this->Values[least]) ? c : least;
      }
      if (!this->Before(this->Values[least], last))
      {
        break;
      }
      this->Values[hole] = std::move(this->Values[least]);
      hole = least;
    }
    this->Values[hole] = std::move(last);
  }

private:
  static constexpr std::size_t Arity = 4;
  std::vector<Value> Values;
  Less Before;
};

} // namespace rgmc

#endif

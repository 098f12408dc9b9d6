// A priority queue whose nodes have four children: half the levels of a binary heap, and a
// node's children side by side in memory, so that a pop, which walks from the root to a leaf,
// misses the cache about half as often (the decimation's queues of candidate collapses hold
// tens of thousands of them, more than the core's nearest caches). Where four values fill a cache
// line (16-byte values), every node's children share one line: the values start three places into
// a line-aligned buffer.
#ifndef rgmcMinHeap_h
#define rgmcMinHeap_h

#include <cstddef>
#include <new>
#include <utility>
#include <vector>

namespace rgmc
{

/// Storage aligned to a 64-byte cache line.
template <typename T>
struct CacheLineAllocator
{
  using value_type = T;
  CacheLineAllocator() = default;
  template <typename U>
  CacheLineAllocator(const CacheLineAllocator<U>&)
  {
  }
  T* allocate(std::size_t n)
  {
    return static_cast<T*>(::operator new(n * sizeof(T), std::align_val_t(64)));
  }
  void deallocate(T* p, std::size_t) { ::operator delete(p, std::align_val_t(64)); }
  template <typename U>
  bool operator==(const CacheLineAllocator<U>&) const
  {
    return true;
  }
  template <typename U>
  bool operator!=(const CacheLineAllocator<U>&) const
  {
    return false;
  }
};

/// The least value first, by `Less` (a strict weak order). Values that `Less` finds equivalent
/// come out in an order of the heap's own; where that matters, make `Less` a total order. `Value`
/// is default-constructible (for the padding) and cheap to copy.
template <typename Value, typename Less>
class MinHeap
{
public:
  explicit MinHeap(Less less = Less())
    : Values(Pad)
    , Before(std::move(less))
  {
  }

  bool Empty() const { return this->Values.size() == Pad; }
  std::size_t Size() const { return this->Values.size() - Pad; }
  const Value& Top() const { return this->Values[Pad]; }

  void Push(Value value)
  {
    std::size_t hole = this->Size();
    this->Values.push_back(value);
    while (hole > 0)
    {
      const std::size_t parent = (hole - 1) / Arity;
      if (!this->Before(value, this->At(parent)))
      {
        break;
      }
      this->At(hole) = std::move(this->At(parent));
      hole = parent;
    }
    this->At(hole) = std::move(value);
  }

  void Pop()
  {
    Value last = std::move(this->Values.back());
    this->Values.pop_back();
    const std::size_t n = this->Size();
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
        least = this->Before(this->At(c), this->At(least)) ? c : least;
      }
      if (!this->Before(this->At(least), last))
      {
        break;
      }
      this->At(hole) = std::move(this->At(least));
      hole = least;
    }
    this->At(hole) = std::move(last);
  }

private:
  static constexpr std::size_t Arity = 4;
  // Node i is Values[Pad + i]; its children, 4i + 1 to 4i + 4, then start a cache line.
  static constexpr std::size_t Pad = Arity * sizeof(Value) == 64 ? Arity - 1 : 0;
  std::vector<Value, CacheLineAllocator<Value>> Values;

  Value& At(std::size_t i) { return this->Values[Pad + i]; }
  const Value& At(std::size_t i) const { return this->Values[Pad + i]; }

  Less Before;
};

} // namespace rgmc

#endif

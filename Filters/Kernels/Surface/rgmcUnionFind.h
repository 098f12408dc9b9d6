// The one union-find of the project: the triangles of a cube grouped by shared vertices, the
// components of one rank, the components of all ranks on rank 0. The smaller root always wins,
// so that the result does not depend on the order of the unions.
#ifndef rgmcUnionFind_h
#define rgmcUnionFind_h

#include <cstddef>
#include <type_traits>
#include <utility>
#include <vector>

namespace rgmc
{

/// Disjoint sets over the indices 0 .. n-1 of `Storage` (a std::vector, or a std::array for a
/// small fixed set on the stack).
template <typename Index, typename Storage = std::vector<Index>>
class UnionFind
{
public:
  /// n singletons (a std::array keeps its size; only its first n entries are used).
  void Reset(std::size_t n)
  {
    if constexpr (std::is_same<Storage, std::vector<Index>>::value)
    {
      this->Parent.resize(n);
    }
    for (std::size_t x = 0; x < n; ++x)
    {
      this->Parent[x] = static_cast<Index>(x);
    }
  }

  /// A new singleton; its index.
  Index Add()
  {
    this->Parent.push_back(static_cast<Index>(this->Parent.size()));
    return this->Parent.back();
  }

  /// Removes the last singleton (one that no union has touched).
  void RemoveLast() { this->Parent.pop_back(); }

  std::size_t Size() const { return this->Parent.size(); }

  /// The root of x's set (path halving).
  Index Find(Index x)
  {
    while (this->Parent[x] != x)
    {
      this->Parent[x] = this->Parent[this->Parent[x]];
      x = this->Parent[x];
    }
    return x;
  }

  /// Unites the sets of a and b. Returns {kept root, absorbed root}; equal when they were one.
  std::pair<Index, Index> Unite(Index a, Index b)
  {
    a = this->Find(a);
    b = this->Find(b);
    if (b < a)
    {
      std::swap(a, b);
    }
    this->Parent[b] = a;
    return { a, b };
  }

private:
  Storage Parent{};
};

} // namespace rgmc

#endif

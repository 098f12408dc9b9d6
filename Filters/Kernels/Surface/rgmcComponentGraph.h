// The components of all ranks as one graph, and the decision which of them the filter keeps.
// Each rank lists its root components and the edges to its neighbours' components (the ports
// both sides have); rank 0 joins the lists of all ranks and decides. VTK-free, so that the
// decision is unit-tested (TestComponentDecision); the VTK layer (vtkRGMarchingCubes) routes the
// ports to the neighbours, gathers the graph on rank 0 and scatters the decision.
#ifndef rgmcComponentGraph_h
#define rgmcComponentGraph_h

#include <algorithm>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

namespace rgmc
{

/// Which components the filter keeps (its ExtractionMode).
enum class Keep
{
  Seeded,  // those a seed grew: the components joined to one
  Largest, // the one of most triangles; of equal ones, that of the smallest vertex key
  All
};

/// A component of some rank in one number: the rank and its root's index there.
inline std::int64_t RankComponent(int rank, std::int64_t root)
{
  return (static_cast<std::int64_t>(rank) << 32) | root;
}

/// One rank's part of the component graph: its root components with their totals, and the
/// edges to the neighbours' components.
struct ComponentGraph
{
  std::vector<std::int64_t> Part; // 3 values per root (triangles, MinKey, seeded), then 2 per edge
  std::vector<std::pair<std::int64_t, std::int64_t>> Ports; // (key, root index), sorted for Join
  std::int64_t Roots = 0;
  std::int64_t Edges = 0;

  /// Lists a root component with its totals (before any edge); returns its index.
  std::int64_t AddRoot(std::int64_t triangles, std::int64_t minKey, bool seeded)
  {
    this->Part.push_back(triangles);
    this->Part.push_back(minKey);
    this->Part.push_back(seeded ? 1 : 0);
    return this->Roots++;
  }

  /// Appends the edges between this rank's components and the neighbours' that share a port
  /// (each pair of components once, whatever the number of ports between them), as pairs of
  /// RankComponent numbers. `incoming[r]`: the (key, root index) pairs of rank r's ports
  /// around cubes of this rank; `rank`'s own list is skipped.
  template <typename Id>
  void Join(const std::vector<std::vector<Id>>& incoming, int rank)
  {
    std::vector<std::pair<std::int64_t, std::int64_t>> edges;
    for (int from = 0; from < static_cast<int>(incoming.size()); ++from)
    {
      const std::vector<Id>& list = incoming[from];
      for (std::size_t n = 0; from != rank && n + 1 < list.size(); n += 2)
      {
        auto it = std::lower_bound(this->Ports.begin(), this->Ports.end(),
          std::make_pair(
            static_cast<std::int64_t>(list[n]), std::numeric_limits<std::int64_t>::min()));
        if (it != this->Ports.end() && it->first == list[n])
        {
          const std::int64_t mine = RankComponent(rank, it->second);
          const std::int64_t theirs = RankComponent(from, list[n + 1]);
          edges.emplace_back(std::min(mine, theirs), std::max(mine, theirs));
        }
      }
    }
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    for (const auto& e : edges)
    {
      this->Part.push_back(e.first);
      this->Part.push_back(e.second);
    }
    this->Edges = static_cast<std::int64_t>(edges.size());
  }
};

/// The decision as one rank receives it.
struct Decision
{
  std::vector<std::int64_t> FinalId; // per local root component (root index order), -1 = dropped
  std::int64_t Triangles = 0;        // kept, over all ranks
  std::int64_t Components = 0;       // kept, over all ranks
};

/// On rank 0: joins the components of all ranks (`parts`: the ComponentGraph::Part of each rank,
/// rank after rank, of `roots[r]` roots and `edges[r]` edges) and decides which to keep. The
/// kept components, never one of no triangles, are numbered 0, 1, ... in the order of their
/// smallest vertex keys. Writes at `out`, rank after rank, 3 + roots[r] values: the header (0,
/// the kept triangles, the kept components), then the final id of each of the rank's roots (-1:
/// dropped).
void Decide(Keep mode, const std::vector<std::int64_t>& parts,
  const std::vector<std::int64_t>& roots, const std::vector<std::int64_t>& edges,
  std::int64_t* out);

} // namespace rgmc

#endif

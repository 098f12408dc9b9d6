// Unit test of rank 0's decision which components to keep (rgmcComponentGraph.h), on graphs of
// a few components on a few simulated ranks: the edges each rank finds from its neighbours'
// ports, and the Largest, Seeded and All decisions with their tie rules and the ids they give.
#include "rgmcCheck.h"
#include "rgmcComponentGraph.h"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace
{

using Graphs = std::vector<rgmc::ComponentGraph>;

struct Root
{
  std::int64_t Triangles;
  std::int64_t MinKey;
  bool Seeded;
};

/// One graph per rank, of the roots given for it (no edges yet).
Graphs MakeGraphs(const std::vector<std::vector<Root>>& roots)
{
  Graphs graphs(roots.size());
  for (std::size_t r = 0; r < roots.size(); ++r)
  {
    for (const Root& root : roots[r])
    {
      graphs[r].AddRoot(root.Triangles, root.MinKey, root.Seeded);
    }
  }
  return graphs;
}

/// Each rank sends its ports to every other (the filter sends them to the owners of the cubes
/// around them only; Join ignores those it does not have) and joins what it received. The lists
/// are of vtkIdType's type, as the filter's exchange gives them.
void JoinAll(Graphs& graphs)
{
  std::vector<std::vector<long long>> sent(graphs.size());
  for (std::size_t r = 0; r < graphs.size(); ++r)
  {
    std::sort(graphs[r].Ports.begin(), graphs[r].Ports.end());
    for (const auto& port : graphs[r].Ports)
    {
      sent[r].push_back(port.first);
      sent[r].push_back(port.second);
    }
  }
  for (std::size_t r = 0; r < graphs.size(); ++r)
  {
    graphs[r].Join(sent, static_cast<int>(r));
  }
}

/// Rank 0's decision over the graphs, as each rank receives it: its header, then its roots' ids.
std::vector<std::vector<std::int64_t>> Decide(rgmc::Keep mode, const Graphs& graphs)
{
  std::vector<std::int64_t> parts, roots, edges;
  std::size_t length = 0;
  for (const rgmc::ComponentGraph& g : graphs)
  {
    parts.insert(parts.end(), g.Part.begin(), g.Part.end());
    roots.push_back(g.Roots);
    edges.push_back(g.Edges);
    length += static_cast<std::size_t>(3 + g.Roots);
  }
  std::vector<std::int64_t> out(length, -7);
  rgmc::Decide(mode, parts, roots, edges, out.data());
  std::vector<std::vector<std::int64_t>> received;
  auto at = out.begin();
  for (const rgmc::ComponentGraph& g : graphs)
  {
    received.emplace_back(at, at + 3 + g.Roots);
    at += 3 + g.Roots;
  }
  return received;
}

/// Whether every rank received the header (0, triangles, components) and then `ids`.
void CheckDecision(const std::vector<std::vector<std::int64_t>>& received, std::int64_t triangles,
  std::int64_t components, const std::vector<std::vector<std::int64_t>>& ids, const char* what)
{
  RGMC_CHECK(received.size() == ids.size(), what << ": " << received.size() << " ranks");
  for (std::size_t r = 0; r < received.size() && r < ids.size(); ++r)
  {
    std::vector<std::int64_t> expected = { 0, triangles, components };
    expected.insert(expected.end(), ids[r].begin(), ids[r].end());
    RGMC_CHECK(received[r] == expected, what << ": rank " << r << " received a wrong decision");
    for (std::size_t n = 0; n < received[r].size(); ++n)
    {
      RGMC_CHECK(n >= expected.size() || received[r][n] == expected[n],
        what << ": rank " << r << " value " << n << " is " << received[r][n] << ", expected "
             << expected[n]);
    }
  }
}

/// Join: an edge for each pair of components that share a port, each pair once however many
/// ports they share; a rank's own list and keys it has no port at are ignored.
void JoinFindsEachEdgeOnce()
{
  rgmc::ComponentGraph g;
  g.AddRoot(4, 100, false);
  g.AddRoot(5, 200, false);
  g.Ports = { { 5, 0 }, { 9, 0 }, { 12, 1 } };
  const std::vector<std::vector<long long>> incoming = {
    { 12, 1 },             // from rank 0 itself: ignored
    { 5, 0, 9, 0, 13, 1 }, // rank 1: two ports of its root 0 at our root 0; key 13 not ours
    { 12, 0 },             // rank 2: its root 0 at our root 1
  };
  g.Join(incoming, 0);
  RGMC_CHECK(g.Roots == 2, "roots " << g.Roots);
  RGMC_CHECK(g.Edges == 2, "edges " << g.Edges << ", expected 2 (two shared ports make one edge)");
  const std::vector<std::int64_t> expected = { 4, 100, 0, 5, 200, 0, rgmc::RankComponent(0, 0),
    rgmc::RankComponent(1, 0), rgmc::RankComponent(0, 1), rgmc::RankComponent(2, 0) };
  RGMC_CHECK(g.Part == expected, "the part lists the roots, then the edges sorted");
  RGMC_CHECK(rgmc::RankComponent(3, 5) == (std::int64_t(3) << 32) + 5, "a rank's component");
}

/// Largest: most triangles over the components joined across ranks; of equal ones, the smaller
/// MinKey, wherever the ranks list them.
void Largest()
{
  // One rank: two of 10 triangles, the smaller key listed second, then first.
  CheckDecision(Decide(rgmc::Keep::Largest,
                  MakeGraphs({ { { 10, 50, false }, { 10, 20, false }, { 5, 1, false } } })),
    10, 1, { { -1, 0, -1 } }, "largest, tie (smaller key second)");
  CheckDecision(Decide(rgmc::Keep::Largest,
                  MakeGraphs({ { { 10, 20, false }, { 10, 50, false }, { 5, 1, false } } })),
    10, 1, { { 0, -1, -1 } }, "largest, tie (smaller key first)");
  // A tie across ranks: rank 1's component has the smaller key.
  CheckDecision(Decide(rgmc::Keep::Largest,
                  MakeGraphs({ { { 7, 300, true } }, { { 7, 30, false }, { 6, 3, true } } })),
    7, 1, { { -1 }, { 0, -1 } }, "largest, tie across ranks");
  // Joined across ranks: 4 + 4 triangles beat 6, though each part alone is smaller; the two
  // shared ports make one edge on each side, and the triangles are counted once.
  Graphs graphs = MakeGraphs({ { { 4, 100, false } }, { { 4, 7, false } }, { { 6, 3, false } } });
  graphs[0].Ports = { { 11, 0 }, { 12, 0 } };
  graphs[1].Ports = { { 11, 0 }, { 12, 0 } };
  graphs[2].Ports = { { 40, 0 } };
  JoinAll(graphs);
  RGMC_CHECK(graphs[0].Edges == 1 && graphs[1].Edges == 1 && graphs[2].Edges == 0,
    "edges " << graphs[0].Edges << " " << graphs[1].Edges << " " << graphs[2].Edges);
  CheckDecision(Decide(rgmc::Keep::Largest, graphs), 8, 1, { { 0 }, { 0 }, { -1 } },
    "largest, joined across ranks");
  // Nothing with triangles: nothing kept.
  CheckDecision(Decide(rgmc::Keep::Largest, MakeGraphs({ { { 0, 5, true } }, {} })), 0, 0,
    { { -1 }, {} }, "largest of no triangles");
}

/// All: every component with triangles, numbered in the order of their smallest vertex keys
/// over all ranks; one of no triangles is dropped.
void All()
{
  Graphs graphs = MakeGraphs(
    { { { 3, 30, false }, { 0, 5, false } }, { { 2, 10, false } }, { { 4, 20, false } } });
  CheckDecision(Decide(rgmc::Keep::All, graphs), 9, 3, { { 2, -1 }, { 0 }, { 1 } }, "all");
  // Joined across ranks: one component, its id that of its smallest key.
  graphs = MakeGraphs(
    { { { 3, 30, false }, { 1, 25, false } }, { { 2, 10, false } }, { { 4, 20, false } } });
  graphs[0].Ports = { { 77, 0 } };
  graphs[2].Ports = { { 77, 0 } };
  JoinAll(graphs);
  CheckDecision(
    Decide(rgmc::Keep::All, graphs), 10, 3, { { 1, 2 }, { 0 }, { 1 } }, "all, joined across ranks");
}

/// Seeded: the union of the components a seed grew, each with those joined to it across ranks;
/// neither the largest nor one of no triangles unless seeded with triangles.
void Seeded()
{
  Graphs graphs = MakeGraphs({ { { 3, 40, true }, { 100, 1, false }, { 0, 2, true } },
    { { 2, 35, false }, { 1, 60, true } } });
  graphs[0].Ports = { { 8, 0 } };
  graphs[1].Ports = { { 8, 0 } };
  JoinAll(graphs);
  CheckDecision(Decide(rgmc::Keep::Seeded, graphs), 6, 2, { { 0, -1, -1 }, { 0, 1 } }, "seeded");
  // The same graph in the other modes.
  CheckDecision(Decide(rgmc::Keep::Largest, graphs), 100, 1, { { -1, 0, -1 }, { -1, -1 } },
    "largest of the seeded graph");
  CheckDecision(
    Decide(rgmc::Keep::All, graphs), 106, 3, { { 1, 0, -1 }, { 1, 2 } }, "all of the seeded graph");
  // No seeded component: nothing kept.
  CheckDecision(Decide(rgmc::Keep::Seeded, MakeGraphs({ { { 9, 1, false } } })), 0, 0, { { -1 } },
    "seeded without a seed");
}

} // namespace

int main()
{
  JoinFindsEachEdgeOnce();
  Largest();
  All();
  Seeded();
  return rgmc_test::Result("TestComponentDecision");
}

// Unit test of extraction's first pass (rgmcNodesBySlab.h): growth's nodes, in blocks of any
// size, sorted by slab in groups of blocks on tasks run in any order, against std::stable_sort
// on k of the whole list (growth's order kept within a slab): the same nodes in the same order,
// the box, each slab's first node and its triangles; for groups of one block, of a few nodes,
// and one group of everything; tasks in order, in reverse, and on threads.
#include "rgmcCheck.h"
#include "rgmcNodesBySlab.h"
#include "rgmcTaskOrders.h"

#include "vtkMarchingCubesTriangleCases.h"

#include <algorithm>
#include <cstring>
#include <random>
#include <vector>

namespace
{

const rgmc::CaseTable& Table()
{
  static const rgmc::CaseTable table(&vtkMarchingCubesTriangleCases::GetCases()[0].edges[0]);
  return table;
}

using rgmc_test::Task;

bool Same(const rgmc::SurfaceNode& a, const rgmc::SurfaceNode& b)
{
  return std::memcmp(&a, &b, sizeof(a)) == 0;
}

void Check(unsigned seed, int numBlocks, std::size_t nodesPerGroup,
  void (*parallel)(std::int64_t, const Task&), const char* how)
{
  std::mt19937 random(seed);
  rgmc::NodeList found;
  std::vector<rgmc::SurfaceNode> all;
  const int k0 = 5 + static_cast<int>(random() % 7), slabs = 1 + static_cast<int>(random() % 40);
  for (int b = 0; b < numBlocks; ++b)
  {
    std::vector<rgmc::SurfaceNode> block(random() % 300);
    for (rgmc::SurfaceNode& n : block)
    {
      std::memset(&n, 0, sizeof(n));
      n.I = static_cast<std::int32_t>(random() % 50) - 10;
      n.J = static_cast<std::int32_t>(random() % 60);
      n.K = k0 + static_cast<std::int32_t>(random() % slabs);
      n.Component = static_cast<std::int32_t>(all.size()); // its place in growth's order
      n.Case = static_cast<std::uint8_t>(1 + random() % 254);
      all.push_back(n);
    }
    found.Append(block);
  }
  if (all.empty())
  {
    return;
  }
  std::vector<rgmc::SurfaceNode> expected = all;
  std::stable_sort(expected.begin(), expected.end(),
    [](const rgmc::SurfaceNode& a, const rgmc::SurfaceNode& b) { return a.K < b.K; });
  rgmc::NodesBySlab sorted;
  rgmc::SortNodesBySlab(found, Table(), nodesPerGroup, parallel, sorted);

  bool same = sorted.Nodes.size() == expected.size();
  for (std::size_t i = 0; same && i < expected.size(); ++i)
  {
    same = Same(sorted.Nodes[i], expected[i]);
  }
  RGMC_CHECK(same, how << ", seed " << seed << ": the nodes in stable k order");
  rgmc::CellBox box;
  for (int a = 0; a < 3; ++a)
  {
    const auto c = [a](const rgmc::SurfaceNode& n) { return a == 0 ? n.I : a == 1 ? n.J : n.K; };
    const auto range = std::minmax_element(all.begin(), all.end(),
      [&c](const rgmc::SurfaceNode& x, const rgmc::SurfaceNode& y) { return c(x) < c(y); });
    RGMC_CHECK(sorted.Box.Lo[a] == c(*range.first) && sorted.Box.Hi[a] == c(*range.second),
      how << ": the box along axis " << a);
  }
  const int numSlabs = sorted.Box.Hi[2] - sorted.Box.Lo[2] + 1;
  RGMC_CHECK(static_cast<int>(sorted.Start.size()) == numSlabs + 1 &&
      sorted.SlabTriangles.size() == static_cast<std::size_t>(numSlabs),
    how << ": one entry a slab");
  for (int s = 0; s < numSlabs && static_cast<int>(sorted.Start.size()) == numSlabs + 1; ++s)
  {
    std::int64_t first = -1, count = 0, triangles = 0;
    for (std::size_t i = 0; i < expected.size(); ++i)
    {
      if (expected[i].K == sorted.Box.Lo[2] + s)
      {
        first = first < 0 ? static_cast<std::int64_t>(i) : first;
        ++count;
        triangles += Table()[expected[i].Case].NumTriangles;
      }
    }
    RGMC_CHECK(sorted.Start[s + 1] - sorted.Start[s] == count &&
        (count == 0 || sorted.Start[s] == first) && sorted.SlabTriangles[s] == triangles,
      how << ": slab " << s);
  }
}

} // namespace

int main()
{
  // Groups: one block each (nodesPerGroup 1), a few blocks, one group of all blocks.
  for (unsigned seed = 1; seed <= 12; ++seed)
  {
    for (std::size_t perGroup : { std::size_t(1), std::size_t(500), std::size_t(1) << 40 })
    {
      Check(
        seed, 1 + static_cast<int>(seed * 7 % 60), perGroup, rgmc_test::TasksInOrder, "in order");
      Check(
        seed, 1 + static_cast<int>(seed * 7 % 60), perGroup, rgmc_test::TasksReversed, "reversed");
      Check(
        seed, 1 + static_cast<int>(seed * 7 % 60), perGroup, rgmc_test::TasksOnThreads, "threads");
    }
  }
  // Groups about equal in nodes: for 1000-node groups of 100 blocks of about 150 nodes, 5 to
  // 8 blocks each.
  rgmc::NodeList found;
  for (int b = 0; b < 100; ++b)
  {
    std::vector<rgmc::SurfaceNode> block(100 + (b * 37) % 100);
    found.Append(block);
  }
  const std::vector<std::size_t> groups = rgmc::NodeGroups(found, 1000);
  RGMC_CHECK(groups.front() == 0 && groups.back() == 100, "groups cover the blocks");
  for (std::size_t g = 0; g + 1 < groups.size(); ++g)
  {
    const std::size_t blocks = groups[g + 1] - groups[g];
    RGMC_CHECK(blocks >= 4 && blocks <= 9, "group " << g << " has " << blocks << " blocks");
  }
  return rgmc_test::Result("TestNodesBySlab");
}

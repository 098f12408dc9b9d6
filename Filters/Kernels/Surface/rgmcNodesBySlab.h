// Extraction's first pass: growth's nodes sorted by slab of cubes along k, growth's order kept
// within a slab (a stable counting sort), on threads, the same for any number of them.
#ifndef rgmcNodesBySlab_h
#define rgmcNodesBySlab_h

#include "rgmcBuffer.h"
#include "rgmcCaseTable.h"
#include "rgmcCubeSurface.h"
#include "rgmcGrid.h"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

namespace rgmc
{

/// Nodes by slab: the box of their cubes (the slabs and the edge tables cover only it, so that a
/// small surface costs the same in any volume), the nodes, each slab's first node (and, last,
/// the count) and each slab's triangles.
struct NodesBySlab
{
  CellBox Box;
  Buffer<SurfaceNode> Nodes;
  std::vector<std::int64_t> Start;
  std::vector<std::int64_t> SlabTriangles;
};

/// The most groups of SortNodesBySlab: their counts per slab are 16 bytes a group and slab.
constexpr std::size_t MaxNodeGroups = 256;

/// Groups of consecutive blocks of `found`, about `nodesPerGroup` nodes each (at most
/// MaxNodeGroups groups): the tasks of SortNodesBySlab. They depend on the blocks only, never on
/// the threads. Returns each group's first block and, last, the number of blocks.
inline std::vector<std::size_t> NodeGroups(const NodeList& found, std::size_t nodesPerGroup)
{
  const std::size_t blocks = found.NumberOfBlocks();
  const std::size_t wanted = std::min<std::size_t>(MaxNodeGroups,
    std::max<std::size_t>(1, found.size() / std::max<std::size_t>(1, nodesPerGroup)));
  std::vector<std::size_t> first{ 0 };
  std::size_t seen = 0;
  for (std::size_t b = 0; b < blocks; ++b)
  {
    seen += found.Block(b).size();
    if (b + 1 < blocks && seen * wanted >= first.size() * found.size())
    {
      first.push_back(b + 1);
    }
  }
  first.push_back(blocks);
  return first;
}

/// Cuts slabs with `slabTriangles` triangles each into at most `wanted` chunks of consecutive
/// slabs (extraction's tasks), each holding about an equal share of the triangles: a chunk
/// ends before the slab that its share's end falls in, or after it, whichever is nearer. No
/// chunk is empty; each holds at most its share plus the largest slab's triangles. They depend
/// on the slabs only, never on the threads. Returns each chunk's first slab and, last, the
/// number of slabs.
inline std::vector<int> ChunkStarts(const std::vector<std::int64_t>& slabTriangles, int wanted)
{
  const int numSlabs = static_cast<int>(slabTriangles.size());
  std::int64_t total = 0;
  for (const std::int64_t t : slabTriangles)
  {
    total += t;
  }
  const std::int64_t chunks = std::max(1, std::min(wanted, numSlabs));
  std::vector<int> starts{ 0 };
  std::int64_t sofar = 0;
  for (int s = 0; s < numSlabs; ++s)
  {
    // Chunk n (from 0) closes before slab s once the slabs before s and half of s hold n + 1
    // shares of the triangles.
    const std::int64_t n = static_cast<std::int64_t>(starts.size()) - 1;
    if (s > starts.back() && n + 1 < chunks &&
      (2 * sofar + slabTriangles[s]) * chunks >= 2 * (n + 1) * total)
    {
      starts.push_back(s);
    }
    sofar += slabTriangles[s];
  }
  starts.push_back(numSlabs);
  return starts;
}

/// Sorts `found` (not empty) by slab into `out`: each group of blocks (NodeGroups) finds its box
/// and counts its nodes and triangles per slab, then each group's first place in each slab is
/// known and the groups scatter their nodes. parallel(count, task) runs task(i) for every i in
/// [0, count), in any order, possibly at once. The nodes' buffer is first touched by the tasks
/// that fill it (no zeroing).
template <typename Parallel>
void SortNodesBySlab(const NodeList& found, const CaseTable& table, std::size_t nodesPerGroup,
  Parallel&& parallel, NodesBySlab& out)
{
  const std::vector<std::size_t> groupFirst = NodeGroups(found, nodesPerGroup);
  const std::int64_t numGroups = static_cast<std::int64_t>(groupFirst.size()) - 1;
  auto forEachInGroup = [&](std::int64_t g, auto&& f)
  {
    for (std::size_t b = groupFirst[g]; b < groupFirst[g + 1]; ++b)
    {
      for (const SurfaceNode& n : found.Block(b))
      {
        f(n);
      }
    }
  };
  auto empty = []()
  {
    CellBox box;
    for (int a = 0; a < 3; ++a)
    {
      box.Lo[a] = std::numeric_limits<int>::max();
      box.Hi[a] = std::numeric_limits<int>::min();
    }
    return box;
  };
  std::vector<CellBox> boxes(static_cast<std::size_t>(numGroups), empty());
  parallel(numGroups,
    [&](std::int64_t g)
    {
      CellBox& gb = boxes[g];
      forEachInGroup(g,
        [&gb](const SurfaceNode& n)
        {
          const int c[3] = { n.I, n.J, n.K };
          for (int a = 0; a < 3; ++a)
          {
            gb.Lo[a] = std::min(gb.Lo[a], c[a]);
            gb.Hi[a] = std::max(gb.Hi[a], c[a]);
          }
        });
    });
  CellBox& box = out.Box;
  box = empty();
  for (const CellBox& gb : boxes)
  {
    for (int a = 0; a < 3; ++a)
    {
      box.Lo[a] = std::min(box.Lo[a], gb.Lo[a]);
      box.Hi[a] = std::max(box.Hi[a], gb.Hi[a]);
    }
  }
  const std::int64_t numSlabs = box.Hi[2] - box.Lo[2] + 1;
  const int k0 = box.Lo[2];
  // Each group's nodes and triangles per slab; then, in place of the counts, its first place.
  std::vector<std::int64_t> place(static_cast<std::size_t>(numGroups * numSlabs), 0);
  std::vector<std::int64_t> triangles(place.size(), 0);
  parallel(numGroups,
    [&](std::int64_t g)
    {
      std::int64_t* count = &place[g * numSlabs];
      std::int64_t* made = &triangles[g * numSlabs];
      forEachInGroup(g,
        [&](const SurfaceNode& n)
        {
          ++count[n.K - k0];
          made[n.K - k0] += table[n.Case].NumTriangles;
        });
    });
  out.Start.assign(static_cast<std::size_t>(numSlabs) + 1, 0);
  out.SlabTriangles.assign(static_cast<std::size_t>(numSlabs), 0);
  std::int64_t placed = 0;
  for (std::int64_t s = 0; s < numSlabs; ++s)
  {
    out.Start[s] = placed;
    for (std::int64_t g = 0; g < numGroups; ++g)
    {
      const std::int64_t count = place[g * numSlabs + s];
      place[g * numSlabs + s] = placed;
      placed += count;
      out.SlabTriangles[s] += triangles[g * numSlabs + s];
    }
  }
  out.Start[numSlabs] = placed;
  out.Nodes.resize_for_overwrite(found.size()); // huge pages: 16 B per node
  parallel(numGroups,
    [&](std::int64_t g)
    {
      std::int64_t* next = &place[g * numSlabs];
      forEachInGroup(g, [&](const SurfaceNode& n) { out.Nodes[next[n.K - k0]++] = n; });
    });
}

} // namespace rgmc

#endif

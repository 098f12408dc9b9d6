// Unit test of extraction's first pass (rgmcNodesBySlab.h): growth's nodes, in blocks of any
// size, sorted by slab in groups of blocks on tasks run in any order, against std::stable_sort
// on k of the whole list (growth's order kept within a slab): the same nodes in the same order,
// the box, each slab's first node and its triangles; for groups of one block, of a few nodes,
// and one group of everything; tasks in order, in reverse, and on threads. Then extraction's
// chunks of slabs (ChunkStarts) and the slices of triangles they fill (Buffer::Borrow).
#include "rgmcCheck.h"
#include "rgmcNodesBySlab.h"
#include "rgmcTaskOrders.h"

#include "vtkMarchingCubesTriangleCases.h"

#include <algorithm>
#include <cstdlib>
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

/// ChunkStarts on `slabs`, asked for `wanted` chunks: they cover the slabs in order, none
/// empty, at most `wanted`, each within a share of the triangles plus the largest slab (fewer
/// chunks where a slab holds several shares).
void CheckChunks(const std::vector<std::int64_t>& slabs, int wanted, const char* how)
{
  const std::vector<int> starts = rgmc::ChunkStarts(slabs, wanted);
  const int numSlabs = static_cast<int>(slabs.size());
  const int chunks = static_cast<int>(starts.size()) - 1;
  RGMC_CHECK(starts.front() == 0 && starts.back() == numSlabs, how << ": chunks cover the slabs");
  RGMC_CHECK(chunks >= 1 && chunks <= std::max(1, wanted), how << ": " << chunks << " chunks");
  std::int64_t total = 0, largest = 0;
  for (const std::int64_t t : slabs)
  {
    total += t;
    largest = std::max(largest, t);
  }
  for (int c = 0; c < chunks; ++c)
  {
    RGMC_CHECK(starts[c + 1] > starts[c], how << ": chunk " << c << " is empty");
    std::int64_t held = 0;
    for (int s = starts[c]; s < starts[c + 1]; ++s)
    {
      held += slabs[s];
    }
    RGMC_CHECK(held * wanted <= total + largest * wanted,
      how << ": chunk " << c << " holds " << held << " of " << total << " triangles");
  }
}

void CheckChunkStarts()
{
  std::mt19937 random(7);
  for (int trial = 0; trial < 200; ++trial)
  {
    std::vector<std::int64_t> slabs(1 + random() % 300);
    for (std::int64_t& t : slabs)
    {
      // Sparse, uniform, and a few slabs much larger than the rest.
      const unsigned kind = random() % 10;
      t = kind < 2 ? 0 : kind < 9 ? random() % 1000 : 20000 + random() % 50000;
    }
    for (int wanted : { 1, 2, 7, 32, 64, 1000 })
    {
      CheckChunks(slabs, wanted, "random slabs");
    }
  }
  // Equal slabs cut into equal chunks; one heavy slab gets a chunk of its own.
  const std::vector<int> even = rgmc::ChunkStarts(std::vector<std::int64_t>(64, 10), 16);
  RGMC_CHECK(even.size() == 17, "16 chunks of 64 equal slabs, not " << even.size() - 1);
  for (std::size_t c = 0; c + 1 < even.size(); ++c)
  {
    RGMC_CHECK(even[c + 1] - even[c] == 4, "equal slabs: chunk " << c << " of 4 slabs");
  }
  std::vector<std::int64_t> heavy(40, 1);
  heavy[20] = 1000;
  const std::vector<int> cut = rgmc::ChunkStarts(heavy, 4);
  RGMC_CHECK(std::find(cut.begin(), cut.end(), 20) != cut.end() &&
      std::find(cut.begin(), cut.end(), 21) != cut.end(),
    "the heavy slab alone in its chunk");
  CheckChunks(std::vector<std::int64_t>(5, 0), 3, "no triangles");
}

/// Buffer::Borrow, as extraction's chunks use it: a buffer fills its slice of a shared array in
/// place, never writes beyond it, and moves to storage of its own when it outgrows it; freeing
/// or handing it over never frees the shared array (AddressSanitizer's build would say).
void CheckBorrowedBuffer()
{
  std::vector<std::int32_t> shared(100, -7);
  {
    rgmc::Buffer<std::int32_t> slice;
    slice.push_back(99); // storage of its own first, freed by Borrow
    slice.Borrow(shared.data() + 10, 20);
    RGMC_CHECK(slice.empty(), "a borrowed buffer starts empty");
    for (int v = 0; v < 20; ++v)
    {
      slice.push_back(v);
    }
    RGMC_CHECK(slice.data() == shared.data() + 10 && shared[10] == 0 && shared[29] == 19,
      "values written in the slice");
    slice.push_back(20);
    RGMC_CHECK(slice.data() != shared.data() + 10 && slice.size() == 21 && slice[0] == 0 &&
        slice[19] == 19 && slice[20] == 20 && shared[30] == -7,
      "beyond its slice, the buffer moves its values to storage of its own");
  }
  rgmc::Buffer<std::int32_t> handed;
  handed.Borrow(shared.data() + 40, 10);
  handed.append(shared.data(), 3);
  std::int32_t* own = handed.Release();
  RGMC_CHECK(own != shared.data() + 40 && own[2] == -7, "a borrowed buffer hands over a copy");
  std::free(own);
  rgmc::Buffer<std::int32_t> freed;
  freed.Borrow(shared.data() + 60, 10);
  freed.push_back(1);
  freed.FreeNow();
  RGMC_CHECK(freed.empty() && shared[9] == -7 && shared[70] == -7, "FreeNow on a borrowed slice");
}

} // namespace

int main()
{
  CheckChunkStarts();
  CheckBorrowedBuffer();
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

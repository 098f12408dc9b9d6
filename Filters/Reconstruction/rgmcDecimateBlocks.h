// Decimate Surface's blocks on their rank: a block's mesh made from the triangles and vertex
// records it was sent, simplified, and its kept collapses replayed and copied out as the rank's
// part (vtkRGDecimate.cxx runs these in its passes; vtkRGDecimate.h says how the blocks are
// placed).
#ifndef rgmcDecimateBlocks_h
#define rgmcDecimateBlocks_h

#include "rgmcDecimateParts.h"
#include "rgmcDecimation.h"
#include "vtkRGParallel.h"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace rgmc
{
namespace decimate
{

/// The corners of the block's own triangles, then of its halo, as indices into `ids`, which
/// becomes their distinct global ids in increasing order: one sort of (id, corner) pairs, each
/// corner then numbered as its id is first met (a search of the ids for each corner costs
/// several times more).
inline std::vector<int> LocalCorners(const Block& block, std::vector<std::int64_t>& ids)
{
  const std::size_t ownCorners = 3 * block.Own.size();
  const std::size_t n = ownCorners + 3 * block.Halo.size();
  auto idAt = [&block, ownCorners](std::size_t c)
  { return c < ownCorners ? block.Own[c / 3][c % 3] : block.Halo[(c - ownCorners) / 3][c % 3]; };
  std::vector<int> local(n);
  ids.clear();
  std::uint64_t last = 0;
  auto put = [&](std::size_t, std::uint64_t key, std::size_t c)
  {
    if (ids.empty() || key != last)
    {
      ids.push_back(idAt(c));
      last = key;
    }
    local[c] = static_cast<int>(ids.size() - 1);
  };
  // Negative ids do not fit the packed sort: they are searched for.
  if (!rgmc::RadixSortPacked(
        n, [&idAt](std::size_t c) { return static_cast<std::uint64_t>(idAt(c)); }, put))
  {
    for (std::size_t c = 0; c < n; ++c)
    {
      ids.push_back(idAt(c));
    }
    SortDistinct(ids);
    for (std::size_t c = 0; c < n; ++c)
    {
      local[c] = static_cast<int>(std::lower_bound(ids.begin(), ids.end(), idAt(c)) - ids.begin());
    }
  }
  return local;
}

/// The block's mesh in local indices from its triangles (by global ids) and the records in
/// `seen`: a vertex of its own triangles that a halo triangle has too is shared with another
/// block, so fixed. Its quadrics are summed here in the first pass, and carried after.
inline void AssembleMesh(Block& block, const VertexTable& seen, bool areaWeighted)
{
  rgmc::DecimationBlock& mesh = block.Mesh;
  const std::vector<int> local = LocalCorners(block, mesh.Ids);
  const std::size_t n = mesh.Ids.size();
  mesh.Points.resize(3 * n);
  mesh.Quadrics.resize(n);
  std::ptrdiff_t at = 0;
  for (std::size_t v = 0; v < n; ++v)
  {
    at = seen.FindAfter(mesh.Ids[v], at); // the ids increase
    const Vertex& record = seen.Vertices[at];
    std::copy(record.Point, record.Point + 3, mesh.Points.begin() + 3 * v);
    if (seen.HasQuadrics)
    {
      mesh.Quadrics[v].Terms = seen.Quadrics[at];
    }
  }
  std::vector<std::uint8_t> inOwn(n, 0), inHalo(n, 0);
  const int* corner = local.data();
  for (auto* list : { &mesh.Triangles, &mesh.Halo })
  {
    const std::size_t count = list == &mesh.Triangles ? block.Own.size() : block.Halo.size();
    std::vector<std::uint8_t>& in = list == &mesh.Triangles ? inOwn : inHalo;
    list->resize(count);
    for (auto& t : *list)
    {
      t = { corner[0], corner[1], corner[2] };
      in[t[0]] = in[t[1]] = in[t[2]] = 1;
      corner += 3;
    }
  }
  mesh.Fixed.resize(n);
  for (std::size_t v = 0; v < n; ++v)
  {
    mesh.Fixed[v] = inOwn[v] & inHalo[v];
  }
  std::vector<Triangle>().swap(block.Own);
  std::vector<Triangle>().swap(block.Halo);
  mesh.SortTriangles();
  if (!seen.HasQuadrics)
  {
    mesh.AreaWeighted = areaWeighted;
    mesh.ComputeQuadrics();
  }
}

/// The block simplified: its collapses' levels and its vertices, fixed or not, counted; with
/// `dropMesh` (several waves) its mesh and collapses are freed, to be made again once the
/// threshold is known.
inline void SimplifyBlock(
  Block& block, double maximumError, std::size_t maximumCollapses, bool dropMesh)
{
  block.Log = rgmc::Simplify(block.Mesh, maximumError, maximumCollapses);
  block.Levels.resize(block.Log.size());
  for (std::size_t c = 0; c < block.Log.size(); ++c)
  {
    block.Levels[c] = block.Log[c].Level;
  }
  std::vector<std::uint8_t> used(block.Mesh.Ids.size(), 0);
  for (const auto& t : block.Mesh.Triangles)
  {
    used[t[0]] = used[t[1]] = used[t[2]] = 1;
  }
  for (std::size_t v = 0; v < used.size(); ++v)
  {
    block.Vertices += used[v];
    block.Fixed += used[v] && block.Mesh.Fixed[v];
  }
  if (dropMesh)
  {
    block.Mesh = rgmc::DecimationBlock();
    std::vector<rgmc::Collapse>().swap(block.Log);
  }
}

/// The blocks' collapses at or below `level` (below it when `strictly`).
inline vtkIdType CollapsesUpTo(const std::vector<Block>& blocks, double level, bool strictly)
{
  vtkIdType count = 0;
  for (const Block& block : blocks)
  {
    auto end = strictly ? std::lower_bound(block.Levels.begin(), block.Levels.end(), level)
                        : std::upper_bound(block.Levels.begin(), block.Levels.end(), level);
    count += static_cast<vtkIdType>(end - block.Levels.begin());
  }
  return count;
}

/// The blocks' triangles (by global ids) and vertices after their kept collapses, block after
/// block: what becomes the rank's part at the end of a pass.
class CollapsedBlocks
{
public:
  CollapsedBlocks() { this->Vertices.HasQuadrics = true; }

  /// Replays the kept collapses of the blocks from `first` to `last` in parallel (each block
  /// alone), simplifying them first when made `again`; then copies each block after those
  /// before it (places counted per block, in block order, so the lists are the same on any
  /// threads) and frees it, on threads.
  void Apply(std::vector<Block>::iterator first, std::vector<Block>::iterator last, bool again,
    double maximumError)
  {
    if (this->Surface.capacity() == 0)
    {
      this->Surface.reserve(this->Expected);
      this->Vertices.Reserve(this->Expected / 2 + this->Expected / 16);
    }
    const std::size_t blocks = static_cast<std::size_t>(last - first);
    std::vector<std::vector<std::uint8_t>> used(blocks);
    // Each block replayed (one a task), its triangles and used vertices counted; their places
    // after the lists' present ends, in block order.
    rgmc::ChunkPlaces places = rgmc::PlaceChunks(static_cast<vtkIdType>(blocks), 1,
      { this->Surface.size(), this->Vertices.Vertices.size() },
      [&](vtkIdType b, vtkIdType, vtkIdType, std::size_t* counts)
      {
        Block& block = *(first + b);
        if (again)
        {
          block.Log = rgmc::Simplify(block.Mesh, maximumError, block.Keep);
        }
        rgmc::ApplyCollapses(block.Mesh, block.Log, block.Keep);
        used[b].assign(block.Mesh.Ids.size(), 0);
        for (const auto& t : block.Mesh.Triangles)
        {
          used[b][t[0]] = used[b][t[1]] = used[b][t[2]] = 1;
        }
        counts[0] = block.Mesh.Triangles.size();
        counts[1] = static_cast<std::size_t>(std::count(used[b].begin(), used[b].end(), 1));
      });
    for (auto block = first; block != last; ++block)
    {
      this->Kept += static_cast<vtkIdType>(block->Keep);
      if (block->Keep > 0)
      {
        this->Level = std::max(this->Level, block->Levels[block->Keep - 1]);
      }
    }
    this->Surface.resize(places.End[0]);
    this->Vertices.Grow(places.End[1] - this->Vertices.Vertices.size());
    rgmc::ParallelFor(static_cast<vtkIdType>(blocks), 1,
      [&](vtkIdType from, vtkIdType to)
      {
        for (vtkIdType b = from; b < to; ++b)
        {
          Block& block = *(first + b);
          this->Copy(block, used[b], places.At(b, 0), places.At(b, 1));
          block = Block{ block.Id, block.Wave, {}, {}, {}, {}, {}, 0, 0, 0 };
          std::vector<std::uint8_t>().swap(used[b]);
        }
      });
  }

  rgmc::OverwriteVector<Triangle> Surface; // by global ids
  VertexTable Vertices;                    // of the triangles, as they come (Adopt sorts them)
  vtkIdType Kept = 0;                      // collapses
  double Level = 0;                        // the largest kept collapse's level
  std::size_t Expected = 0;                // triangles, to size the lists once

private:
  /// The block's triangles from place `triangle` on, its used vertices' records from `record`.
  void Copy(const Block& block, const std::vector<std::uint8_t>& used, std::size_t triangle,
    std::size_t record)
  {
    const rgmc::DecimationBlock& mesh = block.Mesh;
    for (const auto& t : mesh.Triangles)
    {
      this->Surface[triangle++] = { mesh.Ids[t[0]], mesh.Ids[t[1]], mesh.Ids[t[2]] };
    }
    for (std::size_t v = 0; v < used.size(); ++v)
    {
      if (used[v])
      {
        Vertex& out = this->Vertices.Vertices[record];
        out.Id = mesh.Ids[v];
        std::copy(&mesh.Points[3 * v], &mesh.Points[3 * v] + 3, out.Point);
        this->Vertices.Quadrics[record++] = mesh.Quadrics[v].Terms;
      }
    }
  }
};

} // namespace decimate
} // namespace rgmc

#endif

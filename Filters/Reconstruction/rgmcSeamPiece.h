// Seam Repair: one rank's piece of the mesh, as every pass family sees it.
#ifndef rgmcSeamPiece_h
#define rgmcSeamPiece_h

#include "rgmcBuffer.h"
#include "rgmcGrid.h"
#include "rgmcSeamNumbering.h"
#include "rgmcTasks.h"
#include "vtkRGCollective.h"
#include "vtkRGParallel.h"

#include "vtkAOSDataArrayTemplate.h"
#include "vtkCellArray.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <utility>
#include <vector>

namespace rgmc
{
namespace seam
{

/// Rows (vertices) per range when smoothing and normals run on threads: about 250 ranges a step
/// for a million vertices, so that 64 threads find work and no range holds a step back (the
/// work/span profile: the longest ranges of the 20 Laplacian steps 4.1 -> 1.3 ms). VTK's STDThread
/// backend queues one job per range under a lock; at 16384 rows (61 ranges) Seam Repair took
/// the same time on 2 threads, within this machine's spread.
constexpr vtkIdType RowGrain = 4096;

/// Which faces of the volume a vertex lies on (bits x-, x+, y-, y+, z-, z+): an edge whose two
/// vertices share a face runs along the volume's border.
struct BorderTest
{
  bool Keys = false;
  int Whole[6] = { 0, -1, 0, -1, 0, -1 };
  double Bounds[6] = { 0, 0, 0, 0, 0, 0 };
  double Tolerance = 0.0;

  int Mask(const rgmc::Grid& grid, vtkIdType key, const double x[3]) const
  {
    int mask = 0;
    if (this->Keys)
    {
      int p[3], axis;
      grid.Decode(key, p, axis);
      for (int b = 0; b < 3; ++b)
      {
        if (b != axis)
        {
          mask |= (p[b] == this->Whole[2 * b]) << (2 * b);
          mask |= (p[b] == this->Whole[2 * b + 1]) << (2 * b + 1);
        }
      }
      return mask;
    }
    for (int b = 0; b < 3; ++b)
    {
      mask |= (std::fabs(x[b] - this->Bounds[2 * b]) <= this->Tolerance) << (2 * b);
      mask |= (std::fabs(x[b] - this->Bounds[2 * b + 1]) <= this->Tolerance) << (2 * b + 1);
    }
    return mask;
  }
};

/// The positions and triangles of this rank's vertices: the input's own arrays when no points
/// are merged and they have the types asked for, otherwise copies (`copied`, `connectivity`).
/// Every cell is a triangle (checked before).
template <typename T, typename I>
const I* CopyInput(vtkPolyData* input, const LocalVertices& vertices, const T*& positions,
  std::vector<T>& copied, std::vector<vtkIdType>& connectivity)
{
  using PointArray = vtkAOSDataArrayTemplate<T>;
  PointArray* inputPoints =
    input->GetPoints() ? PointArray::FastDownCast(input->GetPoints()->GetData()) : nullptr;
  if (inputPoints && !vertices.Merged())
  {
    positions = inputPoints->GetPointer(0);
  }
  else
  {
    copied.resize(static_cast<std::size_t>(3 * vertices.Count));
    for (vtkIdType v = 0; v < vertices.Count; ++v)
    {
      double p[3];
      input->GetPoint(vertices.PointOf(v), p);
      for (int k = 0; k < 3; ++k)
      {
        copied[3 * v + k] = static_cast<T>(p[k]);
      }
    }
    positions = copied.data();
  }
  using IndexArray = vtkAOSDataArrayTemplate<I>;
  IndexArray* typed = IndexArray::FastDownCast(input->GetPolys()->GetConnectivityArray());
  if (typed && !vertices.Merged())
  {
    return typed->GetPointer(0);
  }
  if constexpr (std::is_same<I, vtkIdType>::value)
  {
    connectivity.reserve(static_cast<std::size_t>(3 * input->GetNumberOfPolys()));
    vtkCellArray* polys = input->GetPolys();
    vtkIdType npts;
    const vtkIdType* pts;
    for (polys->InitTraversal(); polys->GetNextCell(npts, pts);)
    {
      for (int k = 0; k < 3; ++k)
      {
        connectivity.push_back(vertices.VertexOf(pts[k]));
      }
    }
    return connectivity.data();
  }
  return nullptr;
}

/// One rank's piece, with points of type T and triangles over vertex indices of type I (the
/// input's own connectivity when its points need no merging): what every pass family reads, and
/// the triangle corners at each vertex. The families derive from it, one on top of the other
/// (SeamExchange, SeamAnalysis, SeamSmoothing, SeamNormals).
template <typename T, typename I>
struct SeamPiece
{
  SeamPiece(Ranks& ranks, const LocalVertices& vertices, const GlobalNumbering& numbering,
    const BorderTest& border, const vtkIdType* keys, const T* positions, const I* triangles,
    vtkIdType numTriangles)
    : AllRanks(ranks)
    , Vertices(vertices)
    , Numbering(numbering)
    , Border(border)
    , Grid(border.Whole, border.Whole)
    , Keys(keys)
    , Positions(positions)
    , Triangles(triangles)
    , NumTriangles(numTriangles)
    , NumVertices(vertices.Count)
  {
    this->Partners.assign(ranks.Size, false);
    for (int s : numbering.Sharers)
    {
      this->Partners[s] = true;
    }
  }

  /// One list per rank, empty.
  std::vector<std::vector<vtkIdType>> PerRank() const
  {
    return std::vector<std::vector<vtkIdType>>(this->AllRanks.Size);
  }

  /// The triangle corners (3 t + k, of type I as the connectivity's entries are) at each vertex,
  /// in compressed rows, each in increasing order: on threads where the vertices follow the
  /// triangles (rgmc::GroupByKey), else in one pass.
  void CornersAround(
    rgmc::OverwriteVector<vtkIdType>& offsets, rgmc::OverwriteVector<I>& corners) const
  {
    if (!rgmc::SingleThreaded() &&
      rgmc::GroupByKey(
        3 * this->NumTriangles, this->NumVertices,
        [this](std::int64_t c) { return this->Triangles[c]; }, offsets, corners, rgmc::Tasks()))
    {
      return;
    }
    offsets.assign(static_cast<std::size_t>(this->NumVertices) + 1, 0);
    for (vtkIdType c = 0; c < 3 * this->NumTriangles; ++c)
    {
      ++offsets[static_cast<vtkIdType>(this->Triangles[c]) + 1];
    }
    for (vtkIdType v = 0; v < this->NumVertices; ++v)
    {
      offsets[v + 1] += offsets[v];
    }
    corners.resize(static_cast<std::size_t>(3 * this->NumTriangles));
    std::vector<vtkIdType> fill(offsets.begin(), offsets.end() - 1);
    for (vtkIdType c = 0; c < 3 * this->NumTriangles; ++c)
    {
      corners[fill[static_cast<vtkIdType>(this->Triangles[c])]++] = static_cast<I>(c);
    }
  }

  /// The vertices after and before corner c (3 t + k) in triangle t's order: the ends of the
  /// triangle's two edges at that corner.
  std::pair<vtkIdType, vtkIdType> AroundCorner(I c) const
  {
    const vtkIdType t = static_cast<vtkIdType>(c) / 3, k = static_cast<vtkIdType>(c) % 3;
    return { static_cast<vtkIdType>(this->Triangles[3 * t + (k + 1) % 3]),
      static_cast<vtkIdType>(this->Triangles[3 * t + (k + 2) % 3]) };
  }

  /// The ends of this rank's edges at vertex v (once per triangle side), as (gid, vertex)
  /// sorted by gid, into `out`. Reads only: threads may call it at once.
  void EndsAt(vtkIdType v, std::vector<std::pair<vtkIdType, vtkIdType>>& out) const
  {
    out.clear();
    for (vtkIdType c = this->CornerOffsets[v]; c < this->CornerOffsets[v + 1]; ++c)
    {
      const std::pair<vtkIdType, vtkIdType> ends = this->AroundCorner(this->Corners[c]);
      for (const vtkIdType w : { ends.first, ends.second })
      {
        out.emplace_back(this->Numbering.Gid[w], w);
      }
    }
    std::sort(out.begin(), out.end());
  }

  int MaskOf(vtkIdType v) const
  {
    const T* x = this->Positions + 3 * v;
    const double p[3] = { static_cast<double>(x[0]), static_cast<double>(x[1]),
      static_cast<double>(x[2]) };
    return this->Border.Mask(
      this->Grid, this->Keys ? this->Keys[this->Vertices.PointOf(v)] : vtkIdType(0), p);
  }

  /// The vertex with global id `g` (this rank holds it): its vertices in identity order are in
  /// gid order.
  vtkIdType VertexOfGid(vtkIdType g) const
  {
    const auto& gid = this->Numbering.Gid;
    return *std::lower_bound(this->Vertices.Sorted.begin(), this->Vertices.Sorted.end(), g,
      [&gid](vtkIdType v, vtkIdType key) { return gid[v] < key; });
  }

  Ranks& AllRanks;
  const LocalVertices& Vertices;
  const GlobalNumbering& Numbering;
  const BorderTest Border;
  const rgmc::Grid Grid;
  const vtkIdType* Keys; // the input's vertex keys, or null
  const T* Positions;    // of this rank's vertices
  const I* Triangles;    // over this rank's vertices
  const vtkIdType NumTriangles;
  const vtkIdType NumVertices;
  std::vector<bool> Partners; // the ranks that share a vertex with this one

  // The triangle corners at each vertex: made for the seams' analysis, kept for the normals
  // when the surface is smoothed and I is 32-bit (else made again).
  rgmc::OverwriteVector<vtkIdType> CornerOffsets; // written whole by CornersAround
  rgmc::OverwriteVector<I> Corners;
};

} // namespace seam
} // namespace rgmc

#endif // rgmcSeamPiece_h

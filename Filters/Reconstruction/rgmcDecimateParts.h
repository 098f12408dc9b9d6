// The data of vtkRGDecimate's passes on one rank: the part of the surface it holds (vertex
// tables, read in place from the input in the first pass), the grid of blocks that cuts space,
// and the blocks it simplifies.
#ifndef rgmcDecimateParts_h
#define rgmcDecimateParts_h

#include "rgmcDecimation.h"
#include "rgmcRadixSort.h"
#include "vtkRGMessage.h"
#include "vtkRGParallel.h"

#include "vtkAOSDataArrayTemplate.h"
#include "vtkCellArray.h"
#include "vtkDataArray.h"
#include "vtkIdTypeArray.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <utility>
#include <vector>

namespace rgmc
{
namespace decimate
{

/// A triangle by its vertices' global ids.
using Triangle = std::array<vtkIdType, 3>;

/// A global id as a radix-sort key, in the ids' signed order.
inline std::uint64_t KeyOf(vtkIdType id)
{
  return static_cast<std::uint64_t>(id) ^ (std::uint64_t(1) << 63);
}

/// Sorted distinct ids.
template <typename Id>
void SortDistinct(std::vector<Id>& ids)
{
  rgmc::RadixSort(ids, [](Id id) { return KeyOf(static_cast<vtkIdType>(id)); });
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
}

/// A vertex's global id and position.
struct Vertex
{
  vtkIdType Id;
  double Point[3];
};

/// Vertices as they travel between passes: ids and positions and, from the second pass on, their
/// quadrics, kept apart (before the first pass has summed them there are none to carry, and the
/// records are then a quarter of the size).
class VertexTable
{
public:
  rgmc::OverwriteVector<Vertex> Vertices; // by increasing id once sorted
  // A quadric's terms, as plain arrays: grown by Grow, or gathered, without being zeroed first
  // on one thread (a million vertices' quadrics are 80 MB).
  rgmc::OverwriteVector<std::array<double, 10>> Quadrics;
  bool HasQuadrics = false;

  std::size_t Words() const { return this->HasQuadrics ? 14 : 4; }

  /// Message words of vertex `i` at `out` (Words() of them): id and position, then the
  /// quadric's 10 terms.
  void Write(std::size_t i, vtkIdType* out) const
  {
    const Vertex& v = this->Vertices[i];
    *out++ = v.Id;
    for (double x : v.Point)
    {
      *out++ = rgmc::WordOf(x);
    }
    for (std::size_t k = 0; this->HasQuadrics && k < 10; ++k)
    {
      *out++ = rgmc::WordOf(this->Quadrics[i][k]);
    }
  }

  /// Room for `more` records after the present ones, to be written by ReadAt.
  void Grow(std::size_t more)
  {
    this->Vertices.resize(this->Vertices.size() + more);
    this->Quadrics.resize(this->HasQuadrics ? this->Vertices.size() : 0);
  }

  /// Record i from the message words at `words` (as Write wrote them).
  void ReadAt(std::size_t i, const vtkIdType* words)
  {
    Vertex& v = this->Vertices[i];
    v.Id = words[0];
    for (int k = 0; k < 3; ++k)
    {
      v.Point[k] = rgmc::RealOf(words[1 + k]);
    }
    for (std::size_t k = 0; this->HasQuadrics && k < 10; ++k)
    {
      this->Quadrics[i][k] = rgmc::RealOf(words[4 + k]);
    }
  }

  void Reserve(std::size_t n)
  {
    this->Vertices.reserve(n);
    this->Quadrics.reserve(this->HasQuadrics ? n : 0);
  }

  void Add(const Vertex& v, const rgmc::Quadric* q)
  {
    this->Vertices.push_back(v);
    if (this->HasQuadrics)
    {
      this->Quadrics.push_back(q->Terms);
    }
  }

  /// The place of vertex `id`, or -1.
  std::ptrdiff_t Find(vtkIdType id) const
  {
    auto at = std::lower_bound(this->Vertices.begin(), this->Vertices.end(), id,
      [](const Vertex& v, vtkIdType key) { return v.Id < key; });
    return at != this->Vertices.end() && at->Id == id ? at - this->Vertices.begin() : -1;
  }

  /// Find for an id known to be at `from` or after it: steps of doubling length from there,
  /// then a binary search in the last step, so ids looked up in increasing order cost the log
  /// of the distance between them, in memory near the last.
  std::ptrdiff_t FindAfter(vtkIdType id, std::ptrdiff_t from) const
  {
    const std::ptrdiff_t n = static_cast<std::ptrdiff_t>(this->Vertices.size());
    std::ptrdiff_t lo = std::min(from, n), step = 1;
    while (lo + step < n && this->Vertices[lo + step].Id < id)
    {
      lo += step;
      step *= 2;
    }
    const auto begin = this->Vertices.begin() + lo;
    const auto end = this->Vertices.begin() + std::min(n, lo + step + 1);
    auto at =
      std::lower_bound(begin, end, id, [](const Vertex& v, vtkIdType key) { return v.Id < key; });
    return at != end && at->Id == id ? at - this->Vertices.begin() : this->Find(id);
  }

  /// Sorts by id and keeps one of each (copies of a vertex are equal: decimation never
  /// touches a vertex that more than one block has). In place: the records are not held twice.
  void SortDistinct()
  {
    const std::size_t n = this->Vertices.size();
    std::vector<std::pair<vtkIdType, std::size_t>> order(n);
    for (std::size_t i = 0; i < n; ++i)
    {
      order[i] = { this->Vertices[i].Id, i };
    }
    rgmc::RadixSort(
      order, [](const std::pair<vtkIdType, std::size_t>& p) { return KeyOf(p.first); },
      rgmc::Tasks());
    // Record i becomes record order[i].second: each cycle of the permutation walked once, its
    // places marked done by pointing them at themselves.
    for (std::size_t i = 0; i < n; ++i)
    {
      if (order[i].second == i)
      {
        continue;
      }
      const Vertex vertex = this->Vertices[i];
      const std::array<double, 10> quadric =
        this->HasQuadrics ? this->Quadrics[i] : std::array<double, 10>{};
      std::size_t at = i;
      while (order[at].second != i)
      {
        const std::size_t from = order[at].second;
        this->Vertices[at] = this->Vertices[from];
        if (this->HasQuadrics)
        {
          this->Quadrics[at] = this->Quadrics[from];
        }
        order[at].second = at;
        at = from;
      }
      this->Vertices[at] = vertex;
      if (this->HasQuadrics)
      {
        this->Quadrics[at] = quadric;
      }
      order[at].second = at;
    }
    std::vector<std::pair<vtkIdType, std::size_t>>().swap(order);
    std::size_t kept = 0;
    for (std::size_t i = 0; i < n; ++i)
    {
      if (kept == 0 || this->Vertices[i].Id != this->Vertices[kept - 1].Id)
      {
        this->Vertices[kept] = this->Vertices[i];
        if (this->HasQuadrics)
        {
          this->Quadrics[kept] = this->Quadrics[i];
        }
        ++kept;
      }
    }
    this->Vertices.resize(kept);
    this->Quadrics.resize(this->HasQuadrics ? kept : 0);
  }

  /// SortDistinct's result on threads, out of place: the records gathered in id order into
  /// new arrays, each id's first (so the records are held twice meanwhile: for a table whose
  /// moment is not the pass's peak, the part's at the end of a pass). Ids the packed sort
  /// cannot take (negative ones) are sorted in place by SortDistinct.
  void SortDistinctGathered()
  {
    const std::size_t n = this->Vertices.size();
    rgmc::OverwriteVector<std::size_t> from(n); // the record at each sorted place
    if (!rgmc::RadixSortPacked(
          n, [this](std::size_t i) { return static_cast<std::uint64_t>(this->Vertices[i].Id); },
          [&from](std::size_t at, std::uint64_t, std::size_t i) { from[at] = i; }, rgmc::Tasks()))
    {
      this->SortDistinct();
      return;
    }
    auto isFirst = [&](vtkIdType i)
    { return i == 0 || this->Vertices[from[i]].Id != this->Vertices[from[i - 1]].Id; };
    const std::vector<std::size_t> before =
      rgmc::CountBefore(static_cast<vtkIdType>(n), rgmc::ElementChunk, isFirst);
    decltype(this->Vertices) vertices(before.back());                         // written whole below
    decltype(this->Quadrics) quadrics(this->HasQuadrics ? before.back() : 0); // written whole
    rgmc::ForEachChunk(static_cast<vtkIdType>(n), rgmc::ElementChunk,
      [&](vtkIdType c, vtkIdType begin, vtkIdType end)
      {
        std::size_t at = before[static_cast<std::size_t>(c)];
        for (vtkIdType i = begin; i < end; ++i)
        {
          if (isFirst(i))
          {
            vertices[at] = this->Vertices[from[i]];
            if (this->HasQuadrics)
            {
              quadrics[at] = this->Quadrics[from[i]];
            }
            ++at;
          }
        }
      });
    this->Vertices.swap(vertices);
    this->Quadrics.swap(quadrics);
  }

  void Clear()
  {
    decltype(this->Vertices)().swap(this->Vertices);
    decltype(this->Quadrics)().swap(this->Quadrics);
  }
};

/// The blocks: cubes of edge Size from Origin, shifted by Offset blocks.
struct BlockGrid
{
  double Origin[3] = { 0, 0, 0 };
  double Size = 1;
  int Dims[3] = { 1, 1, 1 };
  double Offset = 0;

  vtkIdType Count() const { return vtkIdType(this->Dims[0]) * this->Dims[1] * this->Dims[2]; }
  vtkIdType BlockOf(const double p[3]) const
  {
    vtkIdType index[3];
    for (int a = 0; a < 3; ++a)
    {
      const double x = std::floor((p[a] - this->Origin[a]) / this->Size + this->Offset);
      index[a] = static_cast<vtkIdType>(std::min<double>(std::max(x, 0.0), this->Dims[a] - 1));
    }
    return index[0] + this->Dims[0] * (index[1] + vtkIdType(this->Dims[1]) * index[2]);
  }
};

/// This rank's part of the surface at the start of a pass: its triangles as indices of its
/// vertices, and the vertices' global ids, positions and (after the first pass) quadrics. The
/// first pass reads the input where it is (its connectivity, global ids and points): a copy
/// would hold the whole surface twice while the blocks are made. The input may hold copies of a
/// vertex (the same id and position at several points); the blocks see each id once.
class SurfacePart
{
public:
  /// The input's triangles (every cell is one: CheckInput) and points, in place.
  void Read(vtkPolyData* input)
  {
    this->Clear();
    this->Input = input;
    vtkCellArray* polys = input->GetPolys();
    this->InputTriangles = static_cast<std::size_t>(polys->GetNumberOfCells());
    vtkDataArray* connectivity = polys->GetConnectivityArray();
    if (auto* ids = vtkAOSDataArrayTemplate<vtkIdType>::FastDownCast(connectivity))
    {
      this->Corner64 = ids->GetPointer(0);
    }
    else if (auto* ids32 = vtkAOSDataArrayTemplate<std::int32_t>::FastDownCast(connectivity))
    {
      this->Corner32 = ids32->GetPointer(0);
    }
    else
    {
      this->CornerCopy.reserve(3 * this->InputTriangles);
      vtkIdType npts;
      const vtkIdType* pts;
      for (polys->InitTraversal(); polys->GetNextCell(npts, pts);)
      {
        this->CornerCopy.insert(this->CornerCopy.end(), pts, pts + 3);
      }
      this->Corner64 = this->CornerCopy.data();
    }
    // No global ids only where there are no points (CheckInput).
    auto* ids = vtkIdTypeArray::SafeDownCast(input->GetPointData()->GetGlobalIds());
    this->GlobalIds = ids ? ids->GetPointer(0) : nullptr;
    vtkDataArray* points = input->GetPoints() ? input->GetPoints()->GetData() : nullptr;
    if (auto* d = vtkAOSDataArrayTemplate<double>::FastDownCast(points))
    {
      this->PointsDouble = d->GetPointer(0);
    }
    else if (auto* f = vtkAOSDataArrayTemplate<float>::FastDownCast(points))
    {
      this->PointsFloat = f->GetPointer(0);
    }
  }

  /// Takes the triangles (by global ids) and their vertices' records as the part's own: the
  /// records sorted by id with copies merged, the triangles turned into indices of them.
  void Adopt(rgmc::OverwriteVector<Triangle>& byId, VertexTable& vertices)
  {
    this->Clear();
    std::swap(this->Vertices, vertices);
    this->Vertices.SortDistinctGathered();
    if (this->Vertices.Vertices.size() > static_cast<std::size_t>(VTK_INT_MAX))
    {
      throw std::runtime_error("a rank's part of the surface has more than 2^31 vertices");
    }
    this->Triangles.resize(byId.size()); // written whole below
    // Small tasks: each corner is a binary search, and a result never depends on the tasks.
    rgmc::ParallelFor(static_cast<vtkIdType>(byId.size()), 8192,
      [&](vtkIdType begin, vtkIdType end)
      {
        for (vtkIdType t = begin; t < end; ++t)
        {
          for (int k = 0; k < 3; ++k)
          {
            this->Triangles[t][k] = static_cast<std::int32_t>(this->Vertices.Find(byId[t][k]));
          }
        }
      });
    rgmc::OverwriteVector<Triangle>().swap(byId);
  }

  /// Makes an input part the part's own (as Adopt would have it).
  void OwnInput()
  {
    if (!this->Input)
    {
      return;
    }
    rgmc::OverwriteVector<Triangle> byId(this->NumberOfTriangles()); // written whole below
    VertexTable vertices;
    std::vector<std::uint8_t> used(this->NumberOfVertices(), 0);
    for (std::size_t t = 0; t < byId.size(); ++t)
    {
      vtkIdType c[3];
      this->Corners(t, c);
      for (int k = 0; k < 3; ++k)
      {
        byId[t][k] = this->Id(c[k]);
        used[c[k]] = 1;
      }
    }
    for (std::size_t v = 0; v < used.size(); ++v)
    {
      if (used[v])
      {
        Vertex record;
        record.Id = this->Id(static_cast<vtkIdType>(v));
        this->Point(static_cast<vtkIdType>(v), record.Point);
        vertices.Add(record, nullptr);
      }
    }
    this->Adopt(byId, vertices);
  }

  std::size_t NumberOfTriangles() const
  {
    return this->Input ? this->InputTriangles : this->Triangles.size();
  }
  std::size_t NumberOfVertices() const
  {
    return this->Input ? static_cast<std::size_t>(this->Input->GetNumberOfPoints())
                       : this->Vertices.Vertices.size();
  }
  bool HasQuadrics() const { return !this->Input && this->Vertices.HasQuadrics; }

  /// The vertices of triangle `t`, as indices of the part's vertices.
  void Corners(std::size_t t, vtkIdType c[3]) const
  {
    for (std::size_t k = 0; k < 3; ++k)
    {
      c[k] = !this->Input ? static_cast<vtkIdType>(this->Triangles[t][k])
        : this->Corner64  ? this->Corner64[3 * t + k]
                          : static_cast<vtkIdType>(this->Corner32[3 * t + k]);
    }
  }
  vtkIdType Id(vtkIdType v) const
  {
    return this->Input ? this->GlobalIds[v] : this->Vertices.Vertices[v].Id;
  }
  void Point(vtkIdType v, double p[3]) const
  {
    if (!this->Input)
    {
      std::copy(this->Vertices.Vertices[v].Point, this->Vertices.Vertices[v].Point + 3, p);
    }
    else if (this->PointsDouble)
    {
      std::copy(this->PointsDouble + 3 * v, this->PointsDouble + 3 * v + 3, p);
    }
    else if (this->PointsFloat)
    {
      std::copy(this->PointsFloat + 3 * v, this->PointsFloat + 3 * v + 3, p);
    }
    else
    {
      this->Input->GetPoint(v, p);
    }
  }
  /// How many message words Write gives a vertex.
  std::size_t WordsPerVertex() const { return this->HasQuadrics() ? 14 : 4; }
  /// Message words of vertex `v` at `out` (WordsPerVertex() of them): id and position, then
  /// its quadric's 10 terms if it has one.
  void Write(vtkIdType v, vtkIdType* out) const
  {
    if (!this->Input)
    {
      this->Vertices.Write(static_cast<std::size_t>(v), out);
      return;
    }
    double p[3];
    this->Point(v, p);
    *out++ = this->Id(v);
    for (double x : p)
    {
      *out++ = rgmc::WordOf(x);
    }
  }

  void Clear()
  {
    this->Input = nullptr;
    this->Corner64 = nullptr;
    this->Corner32 = nullptr;
    std::vector<vtkIdType>().swap(this->CornerCopy);
    this->PointsDouble = nullptr;
    this->PointsFloat = nullptr;
    decltype(this->Triangles)().swap(this->Triangles);
    this->Vertices.Clear();
  }

  rgmc::OverwriteVector<std::array<std::int32_t, 3>>
    Triangles;          // the part's own: indices of Vertices
  VertexTable Vertices; // the part's own: by increasing id

private:
  vtkPolyData* Input = nullptr; // the first pass: the input, in place
  std::size_t InputTriangles = 0;
  const vtkIdType* Corner64 = nullptr;
  const std::int32_t* Corner32 = nullptr;
  std::vector<vtkIdType> CornerCopy; // when the input's connectivity is of another type
  const vtkIdType* GlobalIds = nullptr;
  const double* PointsDouble = nullptr;
  const float* PointsFloat = nullptr;
};

/// One block on its rank during a pass.
struct Block
{
  vtkIdType Id;
  int Wave = 0;
  std::vector<Triangle> Own, Halo; // by global ids, as they came
  rgmc::DecimationBlock Mesh;
  std::vector<rgmc::Collapse> Log;
  std::vector<double> Levels; // of the collapses in Log (non-decreasing)
  std::size_t Vertices = 0;   // of its own triangles
  std::size_t Fixed = 0;      // of those, the ones it shares with other blocks
  std::size_t Keep = 0;
};

} // namespace decimate
} // namespace rgmc

#endif

// Decimate Surface's distance report, measured where the triangles are: the symmetric Hausdorff
// distance and the mean distance between the input surface and the decimated one, from every
// vertex of each (each global vertex once: the copies Seam Repair flags as duplicates are
// skipped) to the other surface (the nearest point of its nearest triangle, exactly).
//
// Nothing is gathered. Space is cut into cells, their layers along z given to the ranks in
// contiguous ranges balanced by the vertices to measure (so that the ranks' own parts, slabs
// along z, mostly stay where they are); each vertex goes to its cell's rank, with the other
// surface's triangles that come within a radius R of the cell (its halo). A vertex whose
// nearest triangle is within R has its exact distance; the few farther ones are measured again
// in a next round, R eight times larger, with the triangles sent again for their cells only,
// until none is left (R beyond the surfaces' extent sends every triangle). A vertex's distance
// to one triangle does not depend on the ranks (rgmcSurfaceDistance.h), the smallest over any
// superset of the triangles within R is the same value, the maximum is exact, and the mean's
// sum is an ExactSum: the figures are the same to the bit on any number of ranks and threads.
#ifndef rgmcDecimateDistance_h
#define rgmcDecimateDistance_h

#include "rgmcMeasure.h"
#include "rgmcSurfaceDistance.h"
#include "vtkRGCollective.h"
#include "vtkRGParallel.h"
#include "vtkRGSpan.h"

#include "vtkAOSDataArrayTemplate.h"
#include "vtkCellArray.h"
#include "vtkCellArrayIterator.h"
#include "vtkCommunicator.h"
#include "vtkDataSetAttributes.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace rgmc
{
constexpr int DistancePointsTag = 7411, DistanceTrianglesTag = 7413, DistanceCellsTag = 7415;

/// One surface's part on this rank: its owned vertices and its triangles (canonical corners, as
/// floats where the surface's points are floats: half the memory, the same values).
struct DistanceSurface
{
  OverwriteVector<double> Points;        // 3 a vertex, each global vertex on one rank only
  OverwriteVector<double> Triangles;     // 9 a triangle (sized, then filled on threads) or
  OverwriteVector<float> FloatTriangles; // these, where the points are floats
  double Lo[3] = { std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
    std::numeric_limits<double>::max() };
  double Hi[3] = { -std::numeric_limits<double>::max(), -std::numeric_limits<double>::max(),
    -std::numeric_limits<double>::max() };

  explicit DistanceSurface(vtkPolyData* pd)
  {
    vtkPoints* points = pd->GetPoints();
    vtkCellArray* polys = pd->GetPolys();
    if (!points || !polys)
    {
      return;
    }
    this->ReadPoints(pd, points);
    vtkDataArray* offsets = polys->GetOffsetsArray();
    vtkDataArray* connectivity = polys->GetConnectivityArray();
    auto* o32 = vtkAOSDataArrayTemplate<vtkTypeInt32>::FastDownCast(offsets);
    auto* c32 = vtkAOSDataArrayTemplate<vtkTypeInt32>::FastDownCast(connectivity);
    auto* o64 = vtkAOSDataArrayTemplate<vtkTypeInt64>::FastDownCast(offsets);
    auto* c64 = vtkAOSDataArrayTemplate<vtkTypeInt64>::FastDownCast(connectivity);
    const vtkIdType cells = polys->GetNumberOfCells();
    if (o32 && c32)
    {
      this->ReadTriangles(points, cells, o32->GetPointer(0), c32->GetPointer(0));
    }
    else if (o64 && c64)
    {
      this->ReadTriangles(points, cells, o64->GetPointer(0), c64->GetPointer(0));
    }
    else // another storage: a copy of the offsets and connectivity first
    {
      std::vector<vtkIdType> first(1, 0), ids;
      auto it = vtk::TakeSmartPointer(polys->NewIterator());
      for (it->GoToFirstCell(); !it->IsDoneWithTraversal(); it->GoToNextCell())
      {
        vtkIdType n;
        const vtkIdType* cell;
        it->GetCurrentCell(n, cell);
        ids.insert(ids.end(), cell, cell + n);
        first.push_back(static_cast<vtkIdType>(ids.size()));
      }
      this->ReadTriangles(points, cells, first.data(), ids.data());
    }
  }

  /// f(triangles): the triangles' container, whichever type holds them.
  template <typename F>
  void WithTriangles(F&& f) const
  {
    if (this->FloatTriangles.empty())
    {
      f(this->Triangles);
    }
    else
    {
      f(this->FloatTriangles);
    }
  }

  /// Whether the triangles are held as doubles (1) or as floats, or there are none (0).
  std::int64_t HasDoubleTriangles() const { return this->Triangles.empty() ? 0 : 1; }

  std::int64_t TriangleCount() const
  {
    return static_cast<std::int64_t>((this->Triangles.size() + this->FloatTriangles.size()) / 9);
  }

private:
  /// Points or cells a task reads (a fourth of ElementChunk: reading a triangle's corners costs
  /// more than most passes' elements; the results never depend on it).
  static constexpr vtkIdType ReadChunk = 16384;

  /// The points that are not Seam Repair's duplicate copies, in order (chunks on threads).
  void ReadPoints(vtkPolyData* pd, vtkPoints* points)
  {
    auto* ghosts = vtkUnsignedCharArray::SafeDownCast(
      pd->GetPointData()->GetArray(vtkDataSetAttributes::GhostArrayName()));
    const unsigned char* ghost = ghosts ? ghosts->GetPointer(0) : nullptr;
    auto kept = [ghost](vtkIdType i)
    { return !ghost || !(ghost[i] & vtkDataSetAttributes::DUPLICATEPOINT); };
    const vtkIdType n = points->GetNumberOfPoints();
    const std::vector<std::size_t> first = CountBefore(n, ReadChunk, kept);
    this->Points.resize(3 * first.back());
    ForEachChunk(n, ReadChunk,
      [&](vtkIdType c, vtkIdType begin, vtkIdType end)
      {
        double* out = this->Points.data() + 3 * first[static_cast<std::size_t>(c)];
        WithCoordinates(points,
          [&](auto&& point)
          {
            for (vtkIdType i = begin; i < end; ++i)
            {
              if (kept(i))
              {
                point(i, out);
                out += 3;
              }
            }
          });
      });
  }

  /// f(point), point(i, out) writing point i's coordinates as doubles: read straight from the
  /// array where it holds floats or doubles, through vtkPoints::GetPoint otherwise.
  template <typename F>
  static void WithCoordinates(vtkPoints* points, F&& f)
  {
    vtkDataArray* data = points->GetData();
    auto direct = [&f](const auto* x)
    {
      f(
        [x](vtkIdType i, double* out)
        {
          out[0] = static_cast<double>(x[3 * i]);
          out[1] = static_cast<double>(x[3 * i + 1]);
          out[2] = static_cast<double>(x[3 * i + 2]);
        });
    };
    if (auto* f32 = vtkAOSDataArrayTemplate<float>::FastDownCast(data))
    {
      direct(f32->GetPointer(0));
    }
    else if (auto* f64 = vtkAOSDataArrayTemplate<double>::FastDownCast(data))
    {
      direct(f64->GetPointer(0));
    }
    else
    {
      f([points](vtkIdType i, double* out) { points->GetPoint(i, out); });
    }
  }

  /// The cells of 3 points as canonical triangles, in order, and their box (chunks on threads).
  template <typename Offset, typename Id>
  void ReadTriangles(vtkPoints* points, vtkIdType cells, const Offset* offsets, const Id* ids)
  {
    if (vtkAOSDataArrayTemplate<float>::FastDownCast(points->GetData()))
    {
      this->ReadTriangles(points, cells, offsets, ids, this->FloatTriangles);
    }
    else
    {
      this->ReadTriangles(points, cells, offsets, ids, this->Triangles);
    }
  }

  template <typename Offset, typename Id, typename Out>
  void ReadTriangles(
    vtkPoints* points, vtkIdType cells, const Offset* offsets, const Id* ids, Out& triangles)
  {
    std::vector<std::array<double, 6>> boxes(static_cast<std::size_t>(ChunksOf(cells, ReadChunk)));
    auto isTriangle = [offsets](vtkIdType c) { return offsets[c + 1] - offsets[c] == 3; };
    const std::vector<std::size_t> first = CountBefore(cells, ReadChunk, isTriangle);
    triangles.resize(9 * first.back());
    ForEachChunk(cells, ReadChunk,
      [&](vtkIdType c, vtkIdType begin, vtkIdType end)
      {
        std::array<double, 6>& box = boxes[static_cast<std::size_t>(c)];
        std::copy(this->Lo, this->Lo + 3, box.begin());
        std::copy(this->Hi, this->Hi + 3, box.begin() + 3);
        auto* out = triangles.data() + 9 * first[static_cast<std::size_t>(c)];
        WithCoordinates(points,
          [&](auto&& point)
          {
            for (vtkIdType i = begin; i < end; ++i)
            {
              if (!isTriangle(i))
              {
                continue;
              }
              double t[9];
              for (int k = 0; k < 3; ++k)
              {
                point(static_cast<vtkIdType>(ids[offsets[i] + k]), t + 3 * k);
              }
              CanonicalTriangle(t);
              for (int k = 0; k < 9; ++k)
              {
                box[k % 3] = std::min(box[k % 3], t[k]);
                box[3 + k % 3] = std::max(box[3 + k % 3], t[k]);
                out[k] = static_cast<typename Out::value_type>(t[k]); // floats stay exact
              }
              out += 9;
            }
          });
      });
    for (const auto& box : boxes)
    {
      for (int a = 0; a < 3; ++a)
      {
        this->Lo[a] = std::min(this->Lo[a], box[a]);
        this->Hi[a] = std::max(this->Hi[a], box[3 + a]);
      }
    }
  }
};

/// The distances from one surface's vertices to the other's triangles, over all ranks.
struct DirectedDistance
{
  double Max = 0;
  ExactSum Sum;
  std::int64_t Count = 0;
};

/// The cells that own the vertices: a grid over the surfaces' global box, its layers along z in
/// contiguous ranges, one a rank (LayerRanks), so that the ranks' own parts, slabs along z as
/// the volume's pieces are, stay mostly where they are.
struct DistanceCells
{
  double Origin[3] = { 0, 0, 0 };
  double Size = 1;
  std::int64_t Dims[3] = { 1, 1, 1 };
  std::vector<int> LayerRank = { 0 }; // the rank of each layer along z

  std::int64_t CellOf(const double* p) const
  {
    std::int64_t c[3];
    for (int a = 0; a < 3; ++a)
    {
      c[a] = std::max<std::int64_t>(0,
        std::min<std::int64_t>(this->Dims[a] - 1,
          static_cast<std::int64_t>(std::floor((p[a] - this->Origin[a]) / this->Size))));
    }
    return c[0] + this->Dims[0] * (c[1] + this->Dims[1] * c[2]);
  }
  int RankOf(std::int64_t cell) const
  {
    return this->LayerRank[static_cast<std::size_t>(cell / (this->Dims[0] * this->Dims[1]))];
  }
  /// Gives the layers to the ranks in contiguous ranges balanced by the `points` (3 values a
  /// vertex) of all ranks in them: a layer goes to the rank whose share holds the layer's middle
  /// vertex (collective).
  bool BalanceLayers(Ranks& ranks, const double* points, std::size_t values, std::string& problem)
  {
    const std::size_t layers = static_cast<std::size_t>(this->Dims[2]);
    std::vector<std::int64_t> mine(layers, 0), all(layers, 0);
    for (std::size_t i = 0; i < values; i += 3)
    {
      ++mine[static_cast<std::size_t>(this->CellOf(points + i) / (this->Dims[0] * this->Dims[1]))];
    }
    ranks.AllReduce(mine.data(), all.data(), static_cast<vtkIdType>(layers),
      vtkCommunicator::SUM_OP, "the vertices in each layer of cells");
    std::int64_t total = 0;
    for (std::int64_t n : all)
    {
      total += n;
    }
    this->LayerRank.assign(layers, 0);
    std::int64_t before = 0;
    for (std::size_t l = 0; l < layers; ++l)
    {
      const double middle = static_cast<double>(before) + 0.5 * static_cast<double>(all[l]);
      this->LayerRank[l] = total == 0
        ? 0
        : std::min(
            ranks.Size - 1, static_cast<int>(middle * ranks.Size / static_cast<double>(total)));
      before += all[l];
    }
    return ranks.Agree(true, problem);
  }
  /// Calls f(cell) for every cell that a box grown by r overlaps.
  template <typename F>
  void ForCellsNear(const double* lo, const double* hi, double r, F&& f) const
  {
    std::int64_t a0[3], a1[3];
    for (int a = 0; a < 3; ++a)
    {
      auto at = [&](double x)
      {
        return std::max<std::int64_t>(0,
          std::min<std::int64_t>(this->Dims[a] - 1,
            static_cast<std::int64_t>(std::floor((x - this->Origin[a]) / this->Size))));
      };
      a0[a] = at(lo[a] - r);
      a1[a] = at(hi[a] + r);
    }
    for (std::int64_t z = a0[2]; z <= a1[2]; ++z)
    {
      for (std::int64_t y = a0[1]; y <= a1[1]; ++y)
      {
        for (std::int64_t x = a0[0]; x <= a1[0]; ++x)
        {
          f(x + this->Dims[0] * (y + this->Dims[1] * z));
        }
      }
    }
  }
};

/// Measures the vertices `points` (at their cell's rank already) against `triangles` and
/// `halo` (the rank's own triangles, in place, and those other ranks sent: a vertex's nearest
/// is the nearer of the two sets' nearest), within `limit`: adds the resolved ones to `into`,
/// returns the others' coordinates.
// Contiguous containers of doubles (or floats).
template <typename Points, typename Triangles, typename Halo>
std::vector<double> MeasureWithin(const Points& points, const Triangles& triangles,
  const Halo& halo, double bucket, double limit, DirectedDistance& into)
{
  SpanMark("distance: buckets");
  const TriangleBuckets buckets(triangles, bucket, Tasks());
  const TriangleBuckets haloBuckets(halo, bucket, Tasks());
  SpanMark("distance: nearest triangles");
  const vtkIdType n = static_cast<vtkIdType>(points.size() / 3);
  // The searches in the order of their home buckets (the results do not depend on the order:
  // the largest, an exact sum and a count).
  std::uint64_t indexMask = 0;
  const OverwriteVector<std::uint64_t> order =
    buckets.HomeOrder(points.data(), static_cast<std::size_t>(n), indexMask, Tasks());
  const vtkIdType grain = 4096; // searches cost more than reads: smaller chunks than ElementChunk
  const vtkIdType tasks = ChunksOf(n, grain);
  std::vector<DirectedDistance> parts(static_cast<std::size_t>(tasks));
  std::vector<std::vector<double>> far(static_cast<std::size_t>(tasks));
  ForEachChunk(n, grain,
    [&](vtkIdType task, vtkIdType begin, vtkIdType end)
    {
      DirectedDistance& part = parts[task];
      TriangleBucketsMemo memo, haloMemo;
      constexpr vtkIdType ahead = 8; // searches between a point's prefetch and its search
      for (vtkIdType i = begin; i < end; ++i)
      {
        if (i + ahead < end) // the points in the buckets' order are scattered in memory
        {
          __builtin_prefetch(
            points.data() + 3 * (order[static_cast<std::size_t>(i + ahead)] & indexMask));
        }
        const double* p = points.data() + 3 * (order[static_cast<std::size_t>(i)] & indexMask);
        const double d2 = halo.empty()
          ? buckets.Nearest2(p, limit, memo)
          : std::min(buckets.Nearest2(p, limit, memo), haloBuckets.Nearest2(p, limit, haloMemo));
        if (d2 > limit * limit)
        {
          far[task].insert(far[task].end(), p, p + 3);
          continue;
        }
        const double d = std::sqrt(d2);
        part.Max = std::max(part.Max, d);
        part.Sum.Add(d);
        ++part.Count;
      }
    });
  std::vector<double> unresolved;
  for (vtkIdType task = 0; task < tasks; ++task)
  {
    into.Max = std::max(into.Max, parts[task].Max);
    into.Sum.Add(parts[task].Sum);
    into.Count += parts[task].Count;
    unresolved.insert(unresolved.end(), far[task].begin(), far[task].end());
  }
  return unresolved;
}

/// The parts one after the other, the largest moved rather than copied (the order of the
/// values does not change the distances).
template <typename T>
std::vector<T> Concatenate(std::vector<std::vector<T>>&& parts)
{
  std::size_t largest = 0, total = 0;
  for (std::size_t i = 0; i < parts.size(); ++i)
  {
    largest = parts[i].size() > parts[largest].size() ? i : largest;
    total += parts[i].size();
  }
  std::vector<T> all;
  if (!parts.empty())
  {
    all.swap(parts[largest]);
  }
  all.reserve(total);
  for (auto& part : parts)
  {
    all.insert(all.end(), part.begin(), part.end());
    std::vector<T>().swap(part);
  }
  return all;
}

inline bool ReduceDirected(Ranks& ranks, DirectedDistance& result, std::string& problem);

/// The distances from `from`'s vertices to `to`'s triangles, over all ranks (collective).
/// `floats`: every rank's `to` holds its triangles as floats (or none).
inline bool MeasureDirected(Ranks& ranks, const DistanceSurface& from, const DistanceSurface& to,
  bool floats, const DistanceCells& layout, double radius, double bucket, double extent,
  DirectedDistance& result, std::string& problem)
{
  const int size = ranks.Size;
  if (size == 1) // every triangle is here: one search, without copies
  {
    TryLocally(problem, "measure the distances",
      [&]()
      {
        to.WithTriangles(
          [&](const auto& triangles)
          {
            MeasureWithin(from.Points, triangles, std::vector<float>(), bucket,
              std::numeric_limits<double>::infinity(), result);
          });
      });
    return ranks.Agree(problem.empty(), problem) && ReduceDirected(ranks, result, problem);
  }
  // The vertices' cells on their ranks, balanced for this direction's vertices.
  DistanceCells cells = layout;
  if (!cells.BalanceLayers(ranks, from.Points.data(), from.Points.size(), problem))
  {
    return false;
  }
  std::vector<bool> everyone(static_cast<std::size_t>(size), true);
  // Round 0: every vertex to its cell's rank; later rounds: the far ones stay where they are.
  std::vector<std::vector<double>> outgoing(static_cast<std::size_t>(size));
  for (auto& part : outgoing)
  {
    part.reserve(from.Points.size() / static_cast<std::size_t>(size) * 5 / 4);
  }
  for (std::size_t i = 0; i < from.Points.size(); i += 3)
  {
    const double* p = from.Points.data() + i;
    auto& to_ = outgoing[cells.RankOf(cells.CellOf(p))];
    to_.insert(to_.end(), p, p + 3);
  }
  std::vector<double> mine =
    Concatenate(ranks.Exchange(std::move(outgoing), everyone, DistancePointsTag));
  for (double r = radius;; r *= 8)
  {
    const bool all = r >= extent; // every triangle goes to every rank that still has vertices
    // The cells with vertices still to measure, known to every rank.
    std::vector<vtkIdType> wanted;
    wanted.reserve(mine.size() / 3);
    for (std::size_t i = 0; i < mine.size(); i += 3)
    {
      wanted.push_back(cells.CellOf(mine.data() + i));
    }
    std::sort(wanted.begin(), wanted.end());
    wanted.erase(std::unique(wanted.begin(), wanted.end()), wanted.end());
    std::vector<std::vector<vtkIdType>> told(static_cast<std::size_t>(size), wanted);
    const auto cellsOf = ranks.Exchange(told, everyone, DistanceCellsTag);
    // Whether another rank has vertices to measure in a cell: most triangles reach no such
    // cell, and stay here, measured in place.
    std::vector<bool> wantedElsewhere(
      static_cast<std::size_t>(cells.Dims[0] * cells.Dims[1] * cells.Dims[2]), false);
    for (int q = 0; q < size; ++q)
    {
      for (vtkIdType cell : q == ranks.Rank ? std::vector<vtkIdType>() : cellsOf[q])
      {
        wantedElsewhere[static_cast<std::size_t>(cell)] = true;
      }
    }
    // The triangles travel as floats where every rank's are floats (half the bytes, the same
    // values), as doubles otherwise: the ranks agree on the type (DecimationDistance).
    auto route = [&](const auto& corners, auto zero)
    {
      using Value = decltype(zero);
      std::vector<std::vector<Value>> triangles(static_cast<std::size_t>(size));
      std::vector<std::size_t> sentAt(static_cast<std::size_t>(size), corners.size());
      for (std::size_t t = 0; t < corners.size(); t += 9)
      {
        const auto* c = corners.data() + t;
        double lo[3], hi[3];
        TriangleBox(c, lo, hi);
        cells.ForCellsNear(lo, hi, all ? extent : r,
          [&](std::int64_t cell)
          {
            const int owner = cells.RankOf(cell);
            if (sentAt[owner] != t && wantedElsewhere[static_cast<std::size_t>(cell)])
            {
              sentAt[owner] = t;
              triangles[owner].insert(triangles[owner].end(), c, c + 9);
            }
          });
      }
      const std::vector<Value> halo =
        Concatenate(ranks.Exchange(std::move(triangles), everyone, DistanceTrianglesTag));
      TryLocally(problem, "measure the distances",
        [&]()
        {
          mine = MeasureWithin(
            mine, corners, halo, bucket, all ? std::numeric_limits<double>::infinity() : r, result);
        });
    };
    to.WithTriangles(
      [&](const auto& corners)
      {
        if (floats)
        {
          route(corners, 0.0f);
        }
        else
        {
          route(corners, 0.0);
        }
      });
    std::int64_t left = static_cast<std::int64_t>(mine.size() / 3), anyLeft = 0;
    ranks.AllReduce(&left, &anyLeft, 1, vtkCommunicator::SUM_OP, "counting the far vertices");
    if (!ranks.Agree(problem.empty(), problem))
    {
      return false;
    }
    if (anyLeft == 0 || all)
    {
      break;
    }
  }
  return ReduceDirected(ranks, result, problem);
}

/// The largest distance, the exact sum and the count over the ranks (collective).
inline bool ReduceDirected(Ranks& ranks, DirectedDistance& result, std::string& problem)
{
  double largest = 0;
  ranks.AllReduce(&result.Max, &largest, 1, vtkCommunicator::MAX_OP, "the largest distance");
  std::int64_t words[ExactSum::Words + 1], sums[ExactSum::Words + 1];
  result.Sum.ToWords(words);
  words[ExactSum::Words] = result.Count;
  ranks.AllReduce(words, sums, ExactSum::Words + 1, vtkCommunicator::SUM_OP, "the mean distance");
  result.Max = largest;
  result.Sum = ExactSum::FromWordSums(sums);
  result.Count = sums[ExactSum::Words];
  return ranks.Agree(true, problem);
}

/// The symmetric Hausdorff distance and the mean distance (the mean of the two directions'
/// means) between `input` and `output`, the same on every rank (collective).
inline bool DecimationDistance(Ranks& ranks, vtkPolyData* input, vtkPolyData* output,
  double& hausdorff, double& mean, std::string& problem)
{
  SpanMark("distance: collect");
  DistanceSurface* a = nullptr;
  DistanceSurface* b = nullptr;
  std::unique_ptr<DistanceSurface> ownA, ownB;
  TryLocally(problem, "collect the surfaces for the distance",
    [&]()
    {
      ownA.reset(new DistanceSurface(input));
      ownB.reset(new DistanceSurface(output));
    });
  if (!ranks.Agree(problem.empty(), problem))
  {
    return false;
  }
  a = ownA.get();
  b = ownB.get();
  // The global box, and the triangle counts (the search radius follows the triangles' size).
  double box[6], global[6];
  for (int k = 0; k < 3; ++k)
  {
    box[k] = std::min(a->Lo[k], b->Lo[k]);
    box[3 + k] = -std::max(a->Hi[k], b->Hi[k]);
  }
  ranks.AllReduce(box, global, 6, vtkCommunicator::MIN_OP, "the surfaces' box");
  // The triangle counts, and how many ranks hold each surface's triangles as doubles.
  std::int64_t counts[4] = { a->TriangleCount(), b->TriangleCount(), a->HasDoubleTriangles(),
    b->HasDoubleTriangles() },
               totals[4];
  ranks.AllReduce(counts, totals, 4, vtkCommunicator::SUM_OP, "the triangle counts");
  if (!ranks.Agree(true, problem))
  {
    return false;
  }
  double extent = 0;
  for (int k = 0; k < 3; ++k)
  {
    extent = std::max(extent, -global[3 + k] - global[k]);
  }
  if (totals[0] == 0 || totals[1] == 0 || !(extent > 0) || !std::isfinite(extent))
  {
    hausdorff = mean = std::numeric_limits<double>::quiet_NaN();
    return true;
  }
  DistanceCells cells;
  const double diagonal = extent * std::sqrt(3.0);
  auto radiusFor = [&](std::int64_t triangles)
  { return 2 * diagonal / std::sqrt(static_cast<double>(triangles)); };
  const double radius = std::max(radiusFor(totals[0]), radiusFor(totals[1]));
  cells.Size = std::max(8 * radius, extent / 64);
  for (int k = 0; k < 3; ++k)
  {
    cells.Origin[k] = global[k];
    cells.Dims[k] = static_cast<std::int64_t>((-global[3 + k] - global[k]) / cells.Size) + 1;
  }
  DirectedDistance there, back;
  // Buckets of about one vertex of the coarser surface each (a closed surface has half as many
  // vertices as triangles), for both directions: few triangles a bucket to test, few buckets a
  // triangle; smaller buckets for the finer surface's searches would cost more in building them
  // (a coarse triangle in many buckets) than they save in the searches (2026-11-30: the
  // report's work 1.04 s against 1.24 s on the 512^3 skull, one thread).
  const double bucket = 2 * diagonal /
    std::sqrt(std::max(1.0, 0.5 * static_cast<double>(std::min(totals[0], totals[1]))));
  if (!MeasureDirected(ranks, *a, *b, totals[3] == 0, cells, radiusFor(totals[1]), bucket,
        2 * diagonal, there, problem) ||
    !MeasureDirected(ranks, *b, *a, totals[2] == 0, cells, radiusFor(totals[0]), bucket,
      2 * diagonal, back, problem))
  {
    return false;
  }
  hausdorff = std::max(there.Max, back.Max);
  mean = there.Count > 0 && back.Count > 0
    ? 0.5 * (there.Sum.Get() / there.Count + back.Sum.Get() / back.Count)
    : std::numeric_limits<double>::quiet_NaN();
  return true;
}

/// DecimationDistance, added to `output`'s field data as DecimationHausdorffDistance and
/// DecimationMeanDistance (collective).
inline bool ReportDecimationDistance(
  Ranks& ranks, vtkPolyData* input, vtkPolyData* output, std::string& problem)
{
  double hausdorff = 0, mean = 0;
  if (!DecimationDistance(ranks, input, output, hausdorff, mean, problem))
  {
    return false;
  }
  for (const auto& value : { std::make_pair("DecimationHausdorffDistance", hausdorff),
         std::make_pair("DecimationMeanDistance", mean) })
  {
    vtkNew<vtkDoubleArray> a;
    a->SetName(value.first);
    a->InsertNextValue(value.second);
    output->GetFieldData()->AddArray(a);
  }
  return true;
}

} // namespace rgmc

#endif

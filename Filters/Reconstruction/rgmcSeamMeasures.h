// Seam Repair: the surface's area and enclosed volume, the same to the bit on any number of ranks.
#ifndef rgmcSeamMeasures_h
#define rgmcSeamMeasures_h

#include "rgmcMeasure.h"
#include "rgmcSeamPiece.h"
#include "vtkRGCollective.h"
#include "vtkRGParallel.h"

#include "vtkCommunicator.h"

#include <algorithm>
#include <cstdint>
#include <numeric>
#include <string>
#include <utility>
#include <vector>

namespace rgmc
{
namespace seam
{

/// The surface's area and the volume it encloses (closed by the volume's border planes where it
/// is cut by them: `capArea`), in world units; the volume is NaN when the surface has a hole.
struct Measures
{
  double Area = 0.0;
  double Volume = 0.0;
  double CapArea = 0.0;
  bool Closable = true;
};

/// Triangles a task of the measures: about 0.05 ms (16 384 took 0.2 ms, the longest task of two
/// steps of the work/span profile), 491 tasks on the 512^3 skull.
constexpr vtkIdType TriangleChunk = 4096;

/// This rank's triangles' sums of twice the area and six times the volume (rgmcMeasure.h),
/// at `positions`, on threads: exact sums, the same for any split of the triangles.
template <typename T, typename I>
rgmc::TriangleSums SumTriangles(
  const SeamPiece<T, I>& piece, const T* positions, const double centre[3], double scale)
{
  const vtkIdType n = piece.NumTriangles;
  std::vector<rgmc::TriangleSums> partial(
    static_cast<std::size_t>(rgmc::ChunksOf(n, TriangleChunk)));
  rgmc::ForEachChunk(n, TriangleChunk,
    [&](vtkIdType b, vtkIdType begin, vtkIdType end)
    {
      // Summed here, then stored: neighbouring blocks' sums share cache lines.
      rgmc::TriangleSums sum;
      sum.Add(positions, piece.Triangles, begin, end, centre, scale);
      partial[b] = sum;
    });
  rgmc::TriangleSums sums;
  for (const rgmc::TriangleSums& p : partial)
  {
    sums.Add(p);
  }
  return sums;
}

/// This rank's triangle edges whose two ends lie on a common face of the volume (the caps'
/// candidates, rgmc::BorderEdge), at `positions`, packed.
template <typename T, typename I>
std::vector<double> BorderEdges(
  const SeamPiece<T, I>& piece, const T* positions, const rgmc::VolumeBox& box)
{
  rgmc::HeapOverwriteVector<int> faces(static_cast<std::size_t>(piece.NumVertices)); // set below
  rgmc::ParallelFor(piece.NumVertices, RowGrain,
    [&](vtkIdType first, vtkIdType last)
    {
      for (vtkIdType v = first; v < last; ++v)
      {
        faces[v] = piece.MaskOf(v);
      }
    });
  // Blocks of triangles on threads, each packing its own edges, joined in triangle order.
  std::vector<std::vector<double>> parts(
    static_cast<std::size_t>(rgmc::ChunksOf(piece.NumTriangles, TriangleChunk)));
  rgmc::ForEachChunk(piece.NumTriangles, TriangleChunk,
    [&](vtkIdType block, vtkIdType begin, vtkIdType end)
    {
      std::vector<double> packed;
      for (vtkIdType t = begin; t < end; ++t)
      {
        for (int c = 0; c < 3; ++c)
        {
          const vtkIdType a = static_cast<vtkIdType>(piece.Triangles[3 * t + c]);
          const vtkIdType b = static_cast<vtkIdType>(piece.Triangles[3 * t + (c + 1) % 3]);
          if (!(faces[a] & faces[b]))
          {
            continue;
          }
          rgmc::BorderEdge e;
          e.From = piece.Numbering.Gid[a];
          e.To = piece.Numbering.Gid[b];
          e.FromFaces = faces[a];
          e.ToFaces = faces[b];
          double x[3];
          std::copy_n(positions + 3 * a, 3, x);
          box.ToIndex(x, e.FromIndex);
          std::copy_n(positions + 3 * b, 3, x);
          box.ToIndex(x, e.ToIndex);
          packed.resize(packed.size() + rgmc::BorderEdge::Words);
          e.Pack(packed.data() + packed.size() - rgmc::BorderEdge::Words);
        }
      }
      parts[block] = std::move(packed);
    });
  std::size_t size = 0;
  for (const std::vector<double>& part : parts)
  {
    size += part.size();
  }
  std::vector<double> packed;
  packed.reserve(size);
  for (const std::vector<double>& part : parts)
  {
    packed.insert(packed.end(), part.begin(), part.end());
  }
  return packed;
}

/// The measures of the whole surface from the exact sums reduced over the ranks (`totals`: twice
/// the area, then six times the volume, as word sums) and every rank's border edges (`all`,
/// packed): every rank closes the surface at the border in one order.
inline void CloseAtBorder(const std::vector<double>& all, const std::int64_t* totals,
  const rgmc::VolumeBox& box, double scale, Measures& measures)
{
  constexpr int n = rgmc::ExactSum::Words;
  std::vector<rgmc::BorderEdge> edges(all.size() / rgmc::BorderEdge::Words);
  for (std::size_t e = 0; e < edges.size(); ++e)
  {
    edges[e] = rgmc::BorderEdge::Unpack(all.data() + e * rgmc::BorderEdge::Words);
  }
  const rgmc::Caps caps = rgmc::BorderCaps(std::move(edges), box);
  const double twiceArea = rgmc::ExactSum::FromWordSums(totals).Get();
  const double sixVolume = rgmc::ExactSum::FromWordSums(totals + n).Get();
  measures.Area = 0.5 * twiceArea * scale * scale;
  // Counterclockwise in index space, as marching cubes orders triangles: a mirroring
  // direction turns them clockwise in the world.
  measures.Volume = (box.Handedness() * sixVolume * scale * scale * scale + caps.SixVolume) / 6.0;
  measures.CapArea = caps.Area;
  measures.Closable = caps.Closed;
}

/// The area and enclosed volume of the whole surface at `positions` (this rank's vertices),
/// the same to the bit on every rank for any number of ranks and threads: each rank's exact
/// sums (rgmc::ExactSum) are reduced as integers, and every rank closes the surface at the
/// border from all ranks' border edges, in one order. An agreement, an AllReduce, an AllGather,
/// an agreement, an AllGatherV, an agreement.
template <typename T, typename I>
bool MeasureSurface(Ranks& ranks, const SeamPiece<T, I>& piece, const T* positions,
  const rgmc::VolumeBox& box, Measures& measures, std::string& problem)
{
  double centre[3], scale;
  box.Frame(centre, scale);
  rgmc::TriangleSums sums;
  std::vector<double> mine;
  if (!ranks.Step("measure the surface", problem,
        [&]()
        {
          sums = SumTriangles(piece, positions, centre, scale);
          mine = BorderEdges(piece, positions, box);
        }))
  {
    return false;
  }
  constexpr int n = rgmc::ExactSum::Words;
  std::int64_t words[2 * n], totals[2 * n];
  sums.TwiceArea.ToWords(words);
  sums.SixVolume.ToWords(words + n);
  ranks.AllReduce(words, totals, 2 * n, vtkCommunicator::SUM_OP, "summing the measures");
  const vtkIdType count = static_cast<vtkIdType>(mine.size());
  std::vector<vtkIdType> lengths(ranks.Size), offsets(ranks.Size, 0);
  ranks.AllGather(&count, lengths.data(), 1, "counting the border edges");
  std::partial_sum(lengths.begin(), lengths.end() - 1, offsets.begin() + 1);
  std::vector<double> all;
  if (!ranks.Step("gather the border edges", problem,
        [&]() { all.resize(static_cast<std::size_t>(offsets.back() + lengths.back())); }))
  {
    return false;
  }
  ranks.AllGatherV(
    mine.data(), all.data(), count, lengths.data(), offsets.data(), "gathering the border edges");
  return ranks.Step("close the surface at the border", problem,
    [&]() { CloseAtBorder(all, totals, box, scale, measures); });
}

} // namespace seam
} // namespace rgmc

#endif // rgmcSeamMeasures_h

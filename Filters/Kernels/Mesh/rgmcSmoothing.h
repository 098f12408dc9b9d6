// Mesh smoothing that gives the same result on any number of ranks, without VTK: smoothing
// stencils, the windowed-sinc filter's coefficients, and the update steps of Jacobi Laplacian
// and windowed-sinc smoothing over a list of vertices.
//
// The stencils and the windowed-sinc steps follow vtkWindowedSincPolyDataFilter: boundary
// smoothing on, no feature-edge smoothing, coordinates not normalized, and a Nuttall window (VTK's
// default since 2024: its old Hamming window shrank surfaces by up to 1%) or a Hamming one.
// Neighbours are always visited in increasing global id, so the arithmetic of every vertex is
// fixed by the mesh alone, not by how it is distributed.
#ifndef rgmcSmoothing_h
#define rgmcSmoothing_h

#include "rgmcBuffer.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace rgmc
{

/// An edge of the whole mesh at one vertex: the other end and how many triangles use the edge.
struct IncidentEdge
{
  std::int64_t Neighbour;
  int Uses;
};

/// The neighbours a vertex is smoothed toward (empty: the vertex is fixed), by the rules of
/// vtkWindowedSincPolyDataFilter with boundary smoothing on, written into `stencil`. `incident`
/// holds the vertex's distinct edges sorted by neighbour. A vertex whose edges are all manifold
/// (used twice) uses all its neighbours; one with exactly two boundary edges (used once), or
/// exactly two non-manifold edges, is smoothed along them unless `exceedsEdgeAngle(a, b)` (the
/// path a, vertex, b turns by more than the edge angle); anything else is fixed.
template <typename ExceedsEdgeAngle>
void SmoothingStencil(const std::vector<IncidentEdge>& incident,
  ExceedsEdgeAngle&& exceedsEdgeAngle, std::vector<std::int64_t>& stencil)
{
  stencil.clear();
  int uses = 0;
  for (const IncidentEdge& e : incident)
  {
    uses += e.Uses;
  }
  // No edges, a dangling end, or more than VTK's 255 smoothing edges: fixed.
  if (uses <= 1 || uses >= 2 * 255)
  {
    return;
  }
  std::int64_t boundary[2], nonManifold[2];
  int numBoundary = 0, numNonManifold = 0;
  for (const IncidentEdge& e : incident)
  {
    if (e.Uses == 1)
    {
      if (numBoundary == 2)
      {
        return;
      }
      boundary[numBoundary++] = e.Neighbour;
    }
    else if (e.Uses > 2)
    {
      if (numNonManifold == 2)
      {
        return;
      }
      nonManifold[numNonManifold++] = e.Neighbour;
    }
  }
  if (numBoundary == 0 && numNonManifold == 0)
  {
    for (const IncidentEdge& e : incident)
    {
      stencil.push_back(e.Neighbour);
    }
    return;
  }
  const std::int64_t* pair = numBoundary == 2 && numNonManifold == 0 ? boundary
    : numNonManifold == 2 && numBoundary == 0                        ? nonManifold
                                                                     : nullptr;
  if (pair && !exceedsEdgeAngle(pair[0], pair[1]))
  {
    stencil.assign(pair, pair + 2);
  }
}

/// Whether the path p0 -> p1 -> p2 turns by more than the angle whose cosine is `cosAngle`
/// (vtkWindowedSincPolyDataFilter's edge-angle test at p1; differences taken in T as there).
template <typename T>
bool ExceedsEdgeAngle(const T* p0, const T* p1, const T* p2, double cosAngle)
{
  double l1[3], l2[3];
  for (int k = 0; k < 3; ++k)
  {
    l1[k] = static_cast<T>(p1[k] - p0[k]);
    l2[k] = static_cast<T>(p2[k] - p1[k]);
  }
  for (double* l : { l1, l2 })
  {
    const double norm = std::sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
    if (norm != 0.0)
    {
      l[0] /= norm;
      l[1] /= norm;
      l[2] /= norm;
    }
  }
  return l1[0] * l2[0] + l1[1] * l2[1] + l1[2] * l2[2] < cosAngle;
}

/// The window of the windowed-sinc filter. Nuttall is vtkWindowedSincPolyDataFilter's default
/// from VTK 9.4 (and ParaView 5.13's VTK 9.3.20240617); Hamming was VTK 9.2's only window.
enum class SincWindow
{
  Nuttall,
  Hamming
};

/// The Chebyshev coefficients c[0..iterations] of the windowed-sinc low-pass filter, as
/// vtkWindowedSincPolyDataFilter computes them (the window's weights, in VTK's order of
/// operations, and the pass band widened by a Newton-Raphson search so that the filter is 1 at
/// the pass band).
std::vector<double> SincCoefficients(int iterations, double passBand, SincWindow window);

/// Smoothing stencils of many vertices, in compressed rows: the neighbours of vertex row r are
/// Neighbours[Offsets[r] .. Offsets[r + 1]), indices into the point arrays, of type Index (32
/// bits where the points' count allows: the smoothing steps read every row each iteration).
/// Rows are appended, or room made for them and then filled (on threads: nothing is zeroed
/// first).
template <typename Index = std::int64_t>
struct Stencils
{
  OverwriteVector<std::int64_t> Offsets{ 0 };
  OverwriteVector<Index> Neighbours;
};

// Each step below updates the rows [first, last) of the vertices `points` (one per row); rows are
// independent, so ranges of rows may run on threads at once with the same result.

/// How many stencil entries ahead LaplacianStep prefetches a neighbour's position.
constexpr std::int64_t LaplacianPrefetch = 128;

/// One Jacobi Laplacian step for the vertices `points[r]` with stencil row r:
/// next = cur + relaxation * sum(cur[w] - cur) / n. Coordinates are 3 per point, of type T
/// (Seam Repair iterates in double and rounds to the points' type once, at the end).
template <typename T, typename Index>
void LaplacianStep(const Stencils<Index>& stencils, const Index* points, const T* cur, T* next,
  double relaxation, std::size_t first, std::size_t last)
{
  // The neighbours' positions are gathered from all over the mesh: the one LaplacianPrefetch
  // stencil entries ahead is asked for early (about 20 rows; measured: the step about 10% faster on
  // the 512^3 skull, where nearer or much farther gains less or loses).
  const std::int64_t total = static_cast<std::int64_t>(stencils.Neighbours.size());
  for (std::size_t r = first; r < last; ++r)
  {
    const std::int64_t v = points[r];
    const std::int64_t begin = stencils.Offsets[r], end = stencils.Offsets[r + 1];
    const double n = static_cast<double>(end - begin);
    const double x[3] = { static_cast<double>(cur[3 * v]), static_cast<double>(cur[3 * v + 1]),
      static_cast<double>(cur[3 * v + 2]) };
    // Each coordinate's sum in the stencil's order (the same additions as one coordinate at a
    // time), the neighbours read once.
    double delta[3] = { 0.0, 0.0, 0.0 };
    for (std::int64_t s = begin; s < end; ++s)
    {
      const T* w = cur + 3 * static_cast<std::int64_t>(stencils.Neighbours[s]);
      if (s + LaplacianPrefetch < total)
      {
        __builtin_prefetch(
          cur + 3 * static_cast<std::int64_t>(stencils.Neighbours[s + LaplacianPrefetch]));
      }
      for (int k = 0; k < 3; ++k)
      {
        delta[k] += static_cast<double>(w[k]) - x[k];
      }
    }
    for (int k = 0; k < 3; ++k)
    {
      next[3 * v + k] = static_cast<T>(end > begin ? x[k] + relaxation * delta[k] / n : x[k]);
    }
  }
}

// In the windowed-sinc steps, differences of two coordinates are taken in T, as VTK's loops
// do (they subtract two tuple values of the points' type), so that float meshes give VTK's
// result to the bit.

/// sum((x[v] - x[w]) / n) over the n neighbours w of vertex v (stencil row r), each difference
/// rounded to T first, as VTK's windowed sinc does.
template <typename T, typename Index>
void SincDelta(
  const Stencils<Index>& stencils, std::size_t r, std::int64_t v, const T* x, double delta[3])
{
  const std::int64_t begin = stencils.Offsets[r], end = stencils.Offsets[r + 1];
  const double n = static_cast<double>(end - begin);
  delta[0] = delta[1] = delta[2] = 0;
  for (std::int64_t s = begin; s < end; ++s)
  {
    const std::int64_t w = stencils.Neighbours[s];
    for (int k = 0; k < 3; ++k)
    {
      delta[k] += static_cast<double>(static_cast<T>(x[3 * v + k] - x[3 * w + k])) / n;
    }
  }
}

/// The first windowed-sinc step (Taubin): x1 = x0 - 0.5 * sum((x0 - y0) / n),
/// x3 = c0 x0 + c1 x1 (x1 before it is stored).
template <typename T, typename Index>
void SincFirstStep(const Stencils<Index>& stencils, const Index* points, const T* x0, T* x1, T* x3,
  const double* c, std::size_t first, std::size_t last)
{
  for (std::size_t r = first; r < last; ++r)
  {
    const std::int64_t v = points[r];
    double delta[3];
    SincDelta(stencils, r, v, x0, delta);
    for (int k = 0; k < 3; ++k)
    {
      const double x = static_cast<double>(x0[3 * v + k]);
      const double first = x - 0.5 * delta[k];
      x1[3 * v + k] = static_cast<T>(first);
      x3[3 * v + k] = static_cast<T>(c[0] * x + c[1] * first);
    }
  }
}

/// A later windowed-sinc step: x2 = x1 - x0 + x1 - sum((x1 - y1) / n), x3 += c x2 (x2 before it
/// is stored).
template <typename T, typename Index>
void SincStep(const Stencils<Index>& stencils, const Index* points, const T* x0, const T* x1, T* x2,
  T* x3, double c, std::size_t first, std::size_t last)
{
  for (std::size_t r = first; r < last; ++r)
  {
    const std::int64_t v = points[r];
    double delta[3];
    SincDelta(stencils, r, v, x1, delta);
    for (int k = 0; k < 3; ++k)
    {
      const T a = x1[3 * v + k];
      const double step =
        static_cast<double>(static_cast<T>(static_cast<T>(a - x0[3 * v + k]) + a)) - delta[k];
      x2[3 * v + k] = static_cast<T>(step);
      x3[3 * v + k] = static_cast<T>(static_cast<double>(x3[3 * v + k]) + c * step);
    }
  }
}

} // namespace rgmc

#endif

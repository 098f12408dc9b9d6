// Quadric-error edge collapse on one block of a surface (Garland and Heckbert, SIGGRAPH 1997),
// the VTK-free kernel of vtkRGDecimate. A block is a region of space: it owns some triangles of
// the surface and sees, as a halo, the other triangles around its vertices that lie in other
// blocks. Vertices with a triangle outside the block (and vertices on a boundary or a
// non-manifold edge) are fixed: they neither move nor go, so blocks can be simplified
// independently, in any order, on any rank or thread, and their results fit together.
//
// Everything here is a function of the block's content alone, in a canonical order (vertices in
// global-id order, triangles by their global ids), never of the order it arrived in: the same
// block gives the same collapses, to the bit, wherever it is simplified.
#ifndef rgmcDecimation_h
#define rgmcDecimation_h

#include <array>
#include <cstdint>
#include <vector>

namespace rgmc
{

/// A symmetric 4x4 error quadric: xx, xy, xz, xw, yy, yz, yw, zz, zw, ww. Its value at a point p
/// is the sum of the squared distances from p to the planes it was made of.
struct Quadric
{
  std::array<double, 10> Terms{};

  /// The quadric of the plane through `a`, `b`, `c` (counter-clockwise), times the triangle's
  /// area when `areaWeighted`; zero when degenerate.
  static Quadric OfTriangle(
    const double a[3], const double b[3], const double c[3], bool areaWeighted = false);
  Quadric operator+(const Quadric& other) const // inline: made for every candidate collapse
  {
    Quadric sum;
    for (int i = 0; i < 10; ++i)
    {
      sum.Terms[i] = this->Terms[i] + other.Terms[i];
    }
    return sum;
  }
  double Error(const double p[3]) const;
};

/// Where an edge collapse puts the merged vertex of the edge from `pa` to `pb`, whose ends'
/// quadrics sum to `q`, and the quadric's error there: the quadric's minimum when its matrix A
/// is not near singular (|det A| > 1e-10 trace(A)^3, vtkQuadricDecimation's test) and the
/// minimum lies within two edge lengths of the edge's midpoint; else the minimum on the edge
/// (a crease, a plane: A is singular); else (A flat along the edge) the best of the midpoint
/// and the two ends. HUGE_VAL when no error is finite.
double PlaceCollapse(const Quadric& q, const double pa[3], const double pb[3], double position[3]);

/// One block: its vertices (sorted global ids, positions, quadrics), its own triangles and the
/// halo triangles, as indices into the vertices.
struct DecimationBlock
{
  std::vector<std::int64_t> Ids;             // increasing
  std::vector<double> Points;                // 3 per vertex
  std::vector<Quadric> Quadrics;             // per vertex (see ComputeQuadrics)
  std::vector<std::uint8_t> Fixed;           // per vertex: has a triangle in another block
  std::vector<std::array<int, 3>> Triangles; // the block's own, in canonical order
  std::vector<std::array<int, 3>> Halo;      // other blocks' triangles around its vertices
  /// Whether ComputeQuadrics weights each plane by its triangle's area (Garland's thesis, and
  /// vtkQuadricDecimation): the error then follows the surface's shape, not how finely each of
  /// its parts is triangulated. Unweighted, a collapse's error is the root of the summed squared
  /// distances to the planes, a bound on each (what a maximum error limits).
  bool AreaWeighted = false;

  /// Puts the triangles in canonical order: each rotated to start at its lowest vertex
  /// (orientation kept), then sorted. Call before anything else.
  void SortTriangles();

  /// Each vertex of the block's own triangles gets the sum of the quadrics of every triangle
  /// around it (own and halo), added in canonical order.
  void ComputeQuadrics();
};

/// One edge collapse: `Removed` goes into `Kept`, which moves to `Position`. `Level` is the
/// largest quadric error of the collapses so far in the block (a non-decreasing sequence).
struct Collapse
{
  int Removed;
  int Kept;
  double Position[3];
  double Level;
};

/// Simplifies the block as far as it goes, cheapest collapse first (ties by the global ids of
/// the edge's ends), and returns the collapses in order. A collapse is made only when it keeps
/// the surface a manifold of the same topology (the link condition, and no vertex left with
/// fewer than three neighbours), turns no triangle over (against its normal before the collapse
/// or before the first), and moves no fixed vertex; and, when `maximumError` is positive, when
/// its quadric error is at most maximumError^2. Stops after `maximumCollapses`.
std::vector<Collapse> Simplify(
  const DecimationBlock& block, double maximumError, std::size_t maximumCollapses);

/// Applies the first `count` collapses of `log` to the block: positions and quadrics of the kept
/// vertices, and the triangles that remain (in their order); unused vertices are left as they
/// are.
void ApplyCollapses(DecimationBlock& block, const std::vector<Collapse>& log, std::size_t count);

} // namespace rgmc

#endif

// Unit test of the decimation's quadrics and collapse placement (rgmcDecimation.h), against
// positions and errors worked out by hand: an area-weighted plane quadric is the triangle's area
// times the plain one; a full-rank quadric puts the merged vertex at its minimum; a minimum
// farther than two edge lengths from the edge, a crease (two planes) and a plane are placed on
// the edge at the quadric's minimum there, which can lie between the midpoint and the ends (the
// best of those three would miss it); a quadric flat along the edge takes the midpoint.
#include "rgmcCheck.h"
#include "rgmcDecimation.h"

#include <cmath>

namespace
{

/// The plane through p with the normal axis `axis` (a unit vector along x, y or z), as the
/// quadric of a triangle in it (counter-clockwise around the normal).
rgmc::Quadric AxisPlane(int axis, double offset)
{
  double a[3] = { 0, 0, 0 }, b[3] = { 0, 0, 0 }, c[3] = { 0, 0, 0 };
  const int u = (axis + 1) % 3, v = (axis + 2) % 3;
  a[axis] = b[axis] = c[axis] = offset;
  b[u] = 1.0;
  c[v] = 1.0;
  return rgmc::Quadric::OfTriangle(a, b, c);
}

bool Near(const double* x, double x0, double y0, double z0)
{
  return std::abs(x[0] - x0) < 1e-12 && std::abs(x[1] - y0) < 1e-12 && std::abs(x[2] - z0) < 1e-12;
}

void CheckPlace(const rgmc::Quadric& q, const double pa[3], const double pb[3], double x0,
  double y0, double z0, double cost, const char* what)
{
  double position[3] = { NAN, NAN, NAN };
  const double found = rgmc::PlaceCollapse(q, pa, pb, position);
  RGMC_CHECK(Near(position, x0, y0, z0),
    what << ": placed at (" << position[0] << ", " << position[1] << ", " << position[2]
         << "), expected (" << x0 << ", " << y0 << ", " << z0 << ")");
  RGMC_CHECK(std::abs(found - cost) < 1e-12, what << ": error " << found << ", expected " << cost);
}

} // namespace

int main()
{
  // Area weighting: a right triangle of area 3 in the plane z = 0.5.
  {
    const double a[3] = { 0, 0, 0.5 }, b[3] = { 2, 0, 0.5 }, c[3] = { 0, 3, 0.5 };
    const rgmc::Quadric plain = rgmc::Quadric::OfTriangle(a, b, c);
    const rgmc::Quadric weighted = rgmc::Quadric::OfTriangle(a, b, c, true);
    for (int i = 0; i < 10; ++i)
    {
      RGMC_CHECK(std::abs(weighted.Terms[i] - 3.0 * plain.Terms[i]) < 1e-12,
        "area-weighted term " << i << ": " << weighted.Terms[i] << ", plain " << plain.Terms[i]);
    }
    const double p[3] = { 5, -7, 2.5 };
    RGMC_CHECK(std::abs(plain.Error(p) - 4.0) < 1e-12, "plain error " << plain.Error(p));
    RGMC_CHECK(std::abs(weighted.Error(p) - 12.0) < 1e-12, "weighted error " << weighted.Error(p));
  }
  const rgmc::Quadric corner = AxisPlane(0, 1.0) + AxisPlane(1, 2.0) + AxisPlane(2, 3.0);
  {
    // Full rank, the minimum (1, 2, 3) near the edge.
    const double pa[3] = { 0.5, 2, 3 }, pb[3] = { 1.5, 2, 3 };
    CheckPlace(corner, pa, pb, 1, 2, 3, 0.0, "a corner near the edge");
  }
  {
    // The same minimum 9.25 away from an edge of length 0.5: the edge's own minimum, its end.
    const double pa[3] = { 10, 2, 3 }, pb[3] = { 10.5, 2, 3 };
    CheckPlace(corner, pa, pb, 10, 2, 3, 81.0, "a corner far from the edge");
  }
  {
    // A crease x = 0, y = 0 crossed by the edge: Q(t) = (4t - 1)^2 + (2 - 2t)^2 is least at
    // t = 0.4 (1.8), below the midpoint's 2 and the ends' 5 and 9.
    const rgmc::Quadric crease = AxisPlane(0, 0.0) + AxisPlane(1, 0.0);
    const double pa[3] = { -1, 2, 0 }, pb[3] = { 3, 0, 0 };
    CheckPlace(crease, pa, pb, 0.6, 1.2, 0, 1.8, "a crease across the edge");
  }
  {
    // A plane z = 1 under a tilted edge: the end nearer the plane.
    const rgmc::Quadric plane = AxisPlane(2, 1.0);
    const double pa[3] = { 0, 0, 3 }, pb[3] = { 1, 0, 2 };
    CheckPlace(plane, pa, pb, 1, 0, 2, 1.0, "a plane below the edge");
  }
  {
    // A plane containing the edge: flat along it, the midpoint.
    const rgmc::Quadric plane = AxisPlane(2, 0.0);
    const double pa[3] = { 0, 0, 0 }, pb[3] = { 1, 1, 0 };
    CheckPlace(plane, pa, pb, 0.5, 0.5, 0, 0.0, "a plane along the edge");
  }
  {
    // No planes at all: the midpoint.
    const double pa[3] = { 1, 2, 3 }, pb[3] = { 3, 2, 1 };
    CheckPlace(rgmc::Quadric(), pa, pb, 2, 2, 2, 0.0, "no planes");
  }
  return rgmc_test::Result("TestQuadricPlacement");
}

// Unit test of rgmc::TriangleBuckets (the distance report's nearest-triangle search): for every
// query, the squared distance it finds is the brute-force minimum over all triangles of
// PointTriangleDistance2, to the bit, whatever the buckets' size, the order and threads of the
// build's tasks, and whether searches share a memo of their lookups (in the points' order or in
// the buckets' order, HomeOrder, as the distance report searches). The search skips buckets
// and triangles whose box is beyond the best distance so far; a skip that lost the nearest
// triangle would show here. Surfaces: random triangles, a fine surface against a coarse copy of
// itself (a decimation's case: distances far below the triangles' size, many near ties), points
// on the triangles (distance 0), degenerate and repeated triangles, chunks of the build whose
// triangles have more buckets than its sample made room for; searches within a limit; the
// corners kept as doubles and as floats.
#include "rgmcCheck.h"
#include "rgmcSurfaceDistance.h"
#include "rgmcTaskOrders.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace
{

/// A height field z = f(x, y) over [0, size)^2 sampled every `step`, two triangles a square, as
/// canonical triangles (9 coordinates each), shifted by `offset` (large coordinates).
std::vector<double> Terrain(double size, double step, double offset)
{
  auto f = [](double x, double y) { return 3 * std::sin(0.31 * x) * std::cos(0.23 * y) + 0.1 * x; };
  std::vector<double> corners;
  const int n = static_cast<int>(size / step);
  for (int i = 0; i < n; ++i)
  {
    for (int j = 0; j < n; ++j)
    {
      const double x0 = i * step, x1 = (i + 1) * step, y0 = j * step, y1 = (j + 1) * step;
      const double quad[4][3] = { { x0, y0, f(x0, y0) }, { x1, y0, f(x1, y0) },
        { x1, y1, f(x1, y1) }, { x0, y1, f(x0, y1) } };
      const int triangles[2][3] = { { 0, 1, 2 }, { 0, 2, 3 } };
      for (const auto& t : triangles)
      {
        double c[9];
        for (int k = 0; k < 3; ++k)
        {
          for (int a = 0; a < 3; ++a)
          {
            c[3 * k + a] = quad[t[k]][a] + offset;
          }
        }
        rgmc::CanonicalTriangle(c);
        corners.insert(corners.end(), c, c + 9);
      }
    }
  }
  return corners;
}

double BruteForce(const double* p, const std::vector<double>& triangles)
{
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t t = 0; t < triangles.size(); t += 9)
  {
    const double* c = triangles.data() + t;
    best = std::min(best, rgmc::PointTriangleDistance2(p, c, c + 3, c + 6));
  }
  return best;
}

bool SameBits(double x, double y)
{
  return std::memcmp(&x, &y, sizeof x) == 0;
}

/// The triangles rounded to floats (canonical again), as doubles: what buckets of floats hold.
std::vector<double> AsFloats(const std::vector<double>& triangles)
{
  std::vector<double> rounded(triangles.size());
  for (std::size_t t = 0; t < triangles.size(); t += 9)
  {
    for (int k = 0; k < 9; ++k)
    {
      rounded[t + k] = static_cast<float>(triangles[t + k]);
    }
    rgmc::CanonicalTriangle(rounded.data() + t);
  }
  return rounded;
}

/// Every query against the brute force, for buckets of each size and each order of tasks, the
/// corners kept as T (double, or float: `triangles` then hold floats' values).
template <typename T>
void Check(const std::vector<double>& triangles, const std::vector<double>& points,
  const std::vector<double>& sizes, const std::string& what)
{
  const std::vector<T> stored(triangles.begin(), triangles.end());
  std::vector<double> expected(points.size() / 3);
  for (std::size_t q = 0; q < expected.size(); ++q)
  {
    expected[q] = BruteForce(points.data() + 3 * q, triangles);
  }
  for (double size : sizes)
  {
    for (int mode = 0; mode < 3; ++mode)
    {
      auto parallel = mode == 0
        ? rgmc_test::TasksInOrder
        : (mode == 1 ? rgmc_test::TasksReversed : rgmc_test::TasksOnThreads);
      const rgmc::TriangleBuckets buckets(stored, size, parallel);
      rgmc::TriangleBucketsMemo memo;
      std::size_t wrong = 0, wrongAlone = 0, wrongLimited = 0;
      for (std::size_t q = 0; q < expected.size(); ++q)
      {
        const double* p = points.data() + 3 * q;
        const double inf = std::numeric_limits<double>::infinity();
        wrong += !SameBits(buckets.Nearest2(p, inf, memo), expected[q]);
        if (q % 7 == 0)
        {
          wrongAlone += !SameBits(buckets.Nearest2(p, inf), expected[q]);
          // Within a limit: exact when the nearest triangle is within it, above it otherwise.
          const double limit = 0.5 * size;
          const double within = buckets.Nearest2(p, limit, memo);
          wrongLimited += expected[q] <= limit * limit ? !SameBits(within, expected[q])
                                                       : !(within > limit * limit);
        }
      }
      // In the buckets' order (as the distance report searches), with one memo throughout:
      // every point once, each the brute force's.
      std::uint64_t mask = 0;
      const auto order = buckets.HomeOrder(points.data(), expected.size(), mask, parallel);
      std::vector<int> seen(expected.size(), 0);
      rgmc::TriangleBucketsMemo ordered;
      for (const std::uint64_t word : order)
      {
        const std::size_t q = static_cast<std::size_t>(word & mask);
        RGMC_CHECK(q < expected.size() && seen[q]++ == 0,
          what << ": point " << q << " twice or out of range in HomeOrder");
        const double inf = std::numeric_limits<double>::infinity();
        wrong += q < expected.size() &&
          !SameBits(buckets.Nearest2(points.data() + 3 * q, inf, ordered), expected[q]);
      }
      RGMC_CHECK(order.size() == expected.size(),
        what << ": HomeOrder has " << order.size() << " points, not " << expected.size());
      RGMC_CHECK(wrong == 0 && wrongAlone == 0 && wrongLimited == 0,
        what << (sizeof(T) == 4 ? " (floats)" : "") << ", buckets of " << size << ", tasks " << mode
             << ": " << wrong << " of " << expected.size() << " searches (" << wrongAlone
             << " without a memo, " << wrongLimited
             << " within a limit) not the brute force's to the bit");
    }
  }
}

/// `count` canonical triangles: triangle t's corners within reachOf(t) (a cube's edge) of a
/// centre drawn in [0, box)^3.
template <typename ReachOf>
std::vector<double> RandomTriangles(std::mt19937_64& random, int count, double box, ReachOf reachOf)
{
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<double> triangles;
  for (int t = 0; t < count; ++t)
  {
    const double centre[3] = { box * unit(random), box * unit(random), box * unit(random) };
    const double reach = reachOf(t);
    double c[9];
    for (int k = 0; k < 9; ++k)
    {
      c[k] = centre[k % 3] + reach * (unit(random) - 0.5);
    }
    rgmc::CanonicalTriangle(c);
    triangles.insert(triangles.end(), c, c + 9);
  }
  return triangles;
}

/// `count` points drawn in [low, low + span)^3.
std::vector<double> RandomPoints(std::mt19937_64& random, int count, double low, double span)
{
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<double> points;
  for (int k = 0; k < 3 * count; ++k)
  {
    points.push_back(span * unit(random) + low);
  }
  return points;
}

} // namespace

int main()
{
  std::mt19937_64 random(20261130);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  {
    // Random triangles of many sizes in a box, random points in and around it.
    const std::vector<double> triangles =
      RandomTriangles(random, 3000, 100, [](int t) { return t % 10 == 0 ? 20 : 2; });
    const std::vector<double> points = RandomPoints(random, 3000, -15, 130);
    Check<double>(triangles, points, { 0.5, 4, 40 }, "random triangles");
  }
  {
    // Three chunks of the build (16 384 triangles each) whose triangles are far larger than the
    // ones its sample (every 61st) sees: each chunk's pairs overflow its room in the scratch.
    const std::vector<double> triangles =
      RandomTriangles(random, 40000, 60, [](int t) { return t % 61 == 0 ? 0.01 : 3; });
    const std::vector<double> points = RandomPoints(random, 600, -5, 70);
    Check<double>(triangles, points, { 1, 6 }, "larger triangles than the sample's");
  }
  {
    // A fine surface and a coarse copy of it (a decimation), far from the origin, each
    // measured from the other's vertices, and from points just off them.
    const std::vector<double> fine = Terrain(40, 0.5, 1000), coarse = Terrain(40, 1.6, 1000);
    std::vector<double> fineCorners = fine, coarseCorners = coarse; // the corners as points
    for (std::size_t k = 2; k < fineCorners.size(); k += 3 * 5)
    {
      fineCorners[k] += 1e-3 * (unit(random) - 0.5);
    }
    Check<double>(coarse, fineCorners, { 0.4, 1.3, 5 }, "fine vertices to a coarse copy");
    Check<double>(fine, coarseCorners, { 0.4, 1.3, 5 }, "coarse vertices to the fine surface");
    // As floats (a float surface's triangles are kept so), far from the origin: ties and
    // roundings near the float's precision.
    Check<float>(AsFloats(coarse), fineCorners, { 0.4, 1.3, 5 }, "fine vertices to a coarse copy");
    Check<float>(
      AsFloats(fine), coarseCorners, { 0.4, 1.3, 5 }, "coarse vertices to the fine surface");
  }
  {
    // Degenerate triangles (a point, a segment) and a triangle repeated, points on them.
    std::vector<double> triangles = { 1, 1, 1, 1, 1, 1, 1, 1, 1, /* a point */
      0, 0, 0, 2, 0, 0, 4, 0, 0,                                 /* a segment */
      0, 0, 0, 0, 3, 0, 0, 0, 3, 0, 0, 0, 0, 3, 0, 0, 0, 3 };    /* twice */
    const std::vector<double> points = { 1, 1, 1, 3, 0, 0, 0, 1, 1, 0.5, 0.5, 0.5, -1, -1, -1, 5, 5,
      5 };
    Check<double>(triangles, points, { 0.25, 1, 10 }, "degenerate and repeated triangles");
  }
  return rgmc_test::Result("TestSurfaceDistance");
}

// Unit test of the growth kernel on tiny volumes checked by hand, on a volume split between
// owners (whose union must be the whole), and of its cost: seeded growth reads samples near the
// surface only, so the same surface in a larger volume costs exactly the same reads.
#include "rgmcCheck.h"
#include "rgmcSurfaceKernel.h"

#include "vtkMarchingCubesTriangleCases.h"

#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <set>
#include <vector>

namespace
{

const rgmc::CaseTable& Table()
{
  static const rgmc::CaseTable table(&vtkMarchingCubesTriangleCases::GetCases()[0].edges[0]);
  return table;
}

/// Samples that count how often they are read.
struct Counted
{
  const std::vector<float>* Data;
  mutable std::int64_t Reads = 0;
  float operator[](std::int64_t i) const
  {
    ++this->Reads;
    return (*this->Data)[static_cast<std::size_t>(i)];
  }
};

struct Volume
{
  int Extent[6];
  std::vector<float> Values;

  Volume(int nx, int ny, int nz)
    : Extent{ 0, nx - 1, 0, ny - 1, 0, nz - 1 }
    , Values(static_cast<std::size_t>(nx) * ny * nz, 0.0f)
  {
  }
  float& At(int i, int j, int k)
  {
    return this->Values[i + (this->Extent[1] + 1) * (j + (this->Extent[3] + 1) * k)];
  }
};

rgmc::Ownership OwnAll(const rgmc::Grid& grid)
{
  return rgmc::Ownership({ grid.WholeCells() }, 0);
}

using Triangle = std::array<std::int64_t, 3>;

std::set<Triangle> KeyTriangles(const rgmc::LocalMesh& mesh)
{
  std::set<Triangle> out;
  for (std::int64_t t = 0; t < mesh.NumberOfTriangles(); ++t)
  {
    Triangle tri;
    for (int v = 0; v < 3; ++v)
    {
      tri[v] = mesh.Keys[mesh.Triangles[3 * t + v]];
    }
    std::sort(tri.begin(), tri.end());
    out.insert(tri);
  }
  return out;
}

/// Every edge of a closed surface is used by exactly two triangles.
bool Closed(const std::set<Triangle>& tris)
{
  std::map<std::pair<std::int64_t, std::int64_t>, int> uses;
  for (const Triangle& t : tris)
  {
    ++uses[{ t[0], t[1] }];
    ++uses[{ t[1], t[2] }];
    ++uses[{ t[0], t[2] }];
  }
  for (const auto& u : uses)
  {
    if (u.second != 2)
    {
      return false;
    }
  }
  return !tris.empty();
}

void OneCorner()
{
  Volume vol(2, 2, 2);
  vol.At(0, 0, 0) = 1.0f;
  const rgmc::Grid grid(vol.Extent, vol.Extent);
  const rgmc::Ownership own = OwnAll(grid);
  rgmc::SurfaceOptions params;
  params.Isovalue = 0.5;
  const std::vector<float>& values = vol.Values;
  rgmc::SurfaceKernel<std::vector<float>> g(Table(), grid, own, values, params);
  const int comp = g.GrowFromKey(grid.EdgeKey(0, 0, 0, 0));
  g.Extract();
  RGMC_CHECK(comp == 0, "one component");
  RGMC_CHECK(g.Mesh().NumberOfTriangles() == 1 && g.Mesh().NumberOfPoints() == 3, "one triangle");
  RGMC_CHECK(g.Ports().empty(), "no ports on one rank");
  // The vertex on the x edge: t = 0.5, at (0.5, 0, 0). Its normal interpolates the negative
  // gradients (1, 1, 1) at (0,0,0) and (1, 0, 0) at (1,0,0) (one-sided at the border).
  for (std::int64_t p = 0; p < g.Mesh().NumberOfPoints(); ++p)
  {
    int q[3], axis;
    grid.Decode(g.Mesh().Keys[p], q, axis);
    RGMC_CHECK(q[0] == 0 && q[1] == 0 && q[2] == 0 && axis >= 0, "vertex on an edge of corner 0");
    double expected[3] = { 0, 0, 0 };
    expected[axis] = 0.5;
    for (int a = 0; a < 3; ++a)
    {
      RGMC_CHECK(g.Mesh().Points[3 * p + a] == expected[a], "position of vertex on axis " << axis);
    }
    double n[3] = { 0.5, 0.5, 0.5 };
    n[axis] = 1.0;
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int a = 0; a < 3; ++a)
    {
      RGMC_CHECK(
        std::fabs(g.Mesh().Normals[3 * p + a] - n[a] / len) < 1e-6, "normal on axis " << axis);
    }
  }
}

void TwoBlobs()
{
  // Two single-voxel blobs: each gives a closed octahedron of 8 triangles.
  Volume vol(7, 3, 3);
  vol.At(1, 1, 1) = 1.0f;
  vol.At(5, 1, 1) = 1.0f;
  const rgmc::Grid grid(vol.Extent, vol.Extent);
  const rgmc::Ownership own = OwnAll(grid);
  rgmc::SurfaceOptions params;
  params.Isovalue = 0.5;
  {
    rgmc::SurfaceKernel<std::vector<float>> g(Table(), grid, own, vol.Values, params);
    g.GrowFromKey(grid.EdgeKey(4, 1, 1, 0)); // the edge from (4,1,1) to (5,1,1): blob 2
    RGMC_CHECK(
      g.GrowFromKey(grid.EdgeKey(5, 1, 1, 1)) == -2, "a second seed on blob 2 finds it grown");
    RGMC_CHECK(g.GrowFromKey(grid.EdgeKey(0, 0, 0, 0)) == -1, "no surface at that key");
    g.Extract();
    const std::set<Triangle> tris = KeyTriangles(g.Mesh());
    RGMC_CHECK(
      tris.size() == 8 && Closed(tris), "seeded growth gives blob 2 only: " << tris.size());
    for (std::int64_t p = 0; p < g.Mesh().NumberOfPoints(); ++p)
    {
      RGMC_CHECK(g.Mesh().Points[3 * p] > 3.0, "a vertex of blob 1 was extracted");
    }
  }
  {
    rgmc::SurfaceKernel<std::vector<float>> g(Table(), grid, own, vol.Values, params);
    g.GrowAll();
    g.Extract();
    int roots = 0;
    for (int c = 0; c < g.Components().Size(); ++c)
    {
      if (g.Components().Root(c) == c)
      {
        ++roots;
        RGMC_CHECK(g.Components().TotalsOf(c).Triangles == 8, "each blob has 8 triangles");
      }
    }
    RGMC_CHECK(roots == 2, "two components, not " << roots);
  }
}

void SampleEqualsIsovalue()
{
  // A lone sample equal to the isovalue: every vertex collapses onto it, every triangle is
  // dropped (vtkMarchingCubes drops them too: their points merge).
  Volume vol(3, 3, 3);
  vol.At(1, 1, 1) = 0.5f;
  const rgmc::Grid grid(vol.Extent, vol.Extent);
  const rgmc::Ownership own = OwnAll(grid);
  rgmc::SurfaceOptions params;
  params.Isovalue = 0.5;
  rgmc::SurfaceKernel<std::vector<float>> g(Table(), grid, own, vol.Values, params);
  g.GrowAll();
  g.Extract();
  RGMC_CHECK(g.Mesh().NumberOfTriangles() == 0, "collapsed triangles must be dropped");

  // A blob whose neighbour sample equals the isovalue: the vertices on that sample's edges are
  // the grid point itself, shared by all its edges, and the surface stays closed.
  Volume pinch(5, 3, 3);
  pinch.At(1, 1, 1) = 1.0f;
  pinch.At(2, 1, 1) = 0.5f;
  const rgmc::Grid grid2(pinch.Extent, pinch.Extent);
  const rgmc::Ownership own2 = OwnAll(grid2);
  rgmc::SurfaceKernel<std::vector<float>> h(Table(), grid2, own2, pinch.Values, params);
  h.GrowAll();
  h.Extract();
  const std::set<Triangle> tris = KeyTriangles(h.Mesh());
  int pointKeys = 0;
  for (std::int64_t key : h.Mesh().Keys)
  {
    pointKeys += grid2.IsPointKey(key);
  }
  RGMC_CHECK(pointKeys == 1, "exactly one grid-point vertex, at (2,1,1): " << pointKeys);
  RGMC_CHECK(Closed(tris), "the pinched blob is closed");
}

/// A smooth field with several blobs, split between two owners along x.
void SplitOwnership()
{
  Volume vol(12, 9, 8);
  for (int k = 0; k <= 7; ++k)
  {
    for (int j = 0; j <= 8; ++j)
    {
      for (int i = 0; i <= 11; ++i)
      {
        vol.At(i, j, k) =
          static_cast<float>(std::sin(0.9 * i) * std::cos(0.7 * j) + 0.3 * std::sin(1.3 * k));
      }
    }
  }
  const rgmc::Grid grid(vol.Extent, vol.Extent);
  rgmc::SurfaceOptions params;
  params.Isovalue = 0.2;
  const rgmc::Ownership one = OwnAll(grid);
  rgmc::SurfaceKernel<std::vector<float>> whole(Table(), grid, one, vol.Values, params);
  whole.GrowAll();
  whole.Extract();
  const std::set<Triangle> expected = KeyTriangles(whole.Mesh());

  std::vector<rgmc::CellBox> boxes(2, grid.WholeCells());
  boxes[0].Hi[0] = 4;
  boxes[1].Lo[0] = 5;
  std::set<Triangle> united;
  std::map<std::int64_t, int> portSides;
  for (int r = 0; r < 2; ++r)
  {
    const rgmc::Ownership own(boxes, r);
    rgmc::SurfaceKernel<std::vector<float>> g(Table(), grid, own, vol.Values, params);
    g.GrowAll();
    g.Extract();
    for (const Triangle& t : KeyTriangles(g.Mesh()))
    {
      RGMC_CHECK(united.insert(t).second, "a triangle was extracted by both owners");
    }
    for (const rgmc::Port& p : g.Ports())
    {
      int q[3], axis;
      grid.Decode(p.Key, q, axis);
      RGMC_CHECK(q[0] == 5, "ports lie on the plane between the owners, not at x = " << q[0]);
      portSides[p.Key] |= 1 << r;
    }
  }
  RGMC_CHECK(united == expected,
    "the owners' union differs from the whole: " << united.size() << " vs " << expected.size());
  for (const auto& p : portSides)
  {
    RGMC_CHECK(p.second == 3, "port " << p.first << " seen by one owner only");
  }
  RGMC_CHECK(!portSides.empty(), "the surface crosses the plane, so there are ports");
}

/// Seeded growth between owners in rounds, as vtkRGMarchingCubes runs it between ranks (with a
/// tiny budget, so that growth pauses and goes on): the owners' union equals the component grown
/// by one owner, whatever the budget, and an owner the component never reaches reads nothing.
void RoundsBetweenOwners()
{
  Volume vol(16, 70, 8); // 69 cells along y: 3 tiles of 32, so growth pauses between them
  for (int k = 0; k <= 7; ++k)
  {
    for (int j = 0; j <= 69; ++j)
    {
      for (int i = 0; i <= 15; ++i)
      {
        // A tube of radius 1.5 along y inside owner 1's cells (x = 5) that bends into owner
        // 2's at its far end (x = 9 from y = 65): owners 0 and 3 hold no surface, and owner 2
        // is reached only after owner 1 grew the tube through its 3 tiles.
        const double x = i - 5.0 - std::min(4.0, 0.4 * std::max(0, j - 55)), z = k - 3.5;
        vol.At(i, j, k) = static_cast<float>(1.5 - std::sqrt(x * x + z * z));
      }
    }
  }
  const rgmc::Grid grid(vol.Extent, vol.Extent);
  rgmc::SurfaceOptions params;
  params.Isovalue = 0.2;
  // The seed: the first edge along x in owner 1's cells that the surface crosses.
  std::int64_t seed = -1;
  for (int k = 0; k <= 7 && seed < 0; ++k)
  {
    for (int j = 0; j <= 69 && seed < 0; ++j)
    {
      for (int i = 3; i < 6 && seed < 0; ++i)
      {
        if ((vol.At(i, j, k) >= 0.2f) != (vol.At(i + 1, j, k) >= 0.2f))
        {
          seed = grid.EdgeKey(i, j, k, 0);
        }
      }
    }
  }
  std::vector<rgmc::CellBox> boxes(4, grid.WholeCells());
  boxes[0].Hi[0] = 2;
  boxes[1].Lo[0] = 3;
  boxes[1].Hi[0] = 6;
  boxes[2].Lo[0] = 7;
  boxes[2].Hi[0] = 11;
  boxes[3].Lo[0] = 12;
  const rgmc::Ownership one = OwnAll(grid);
  rgmc::SurfaceKernel<std::vector<float>> whole(Table(), grid, one, vol.Values, params);
  RGMC_CHECK(whole.GrowFromKey(seed) >= 0, "the seed key is on the surface");
  whole.Extract();
  const std::set<Triangle> expected = KeyTriangles(whole.Mesh());
  for (const std::int64_t budget : { std::int64_t(1), std::int64_t(7), std::int64_t(1) << 40 })
  {
    std::vector<rgmc::Ownership> owners;
    std::vector<std::unique_ptr<rgmc::SurfaceKernel<std::vector<float>>>> kernels;
    for (int r = 0; r < 4; ++r)
    {
      owners.emplace_back(boxes, r);
    }
    for (int r = 0; r < 4; ++r)
    {
      kernels.emplace_back(
        new rgmc::SurfaceKernel<std::vector<float>>(Table(), grid, owners[r], vol.Values, params));
      kernels[r]->SetCrossRanks(true);
      kernels[r]->SetBudget(budget);
      kernels[r]->GrowFromKey(seed);
    }
    int rounds = 0;
    for (bool more = true; more && rounds < 10000; ++rounds)
    {
      // Departures to the owners of the other cubes around their vertices.
      std::vector<std::vector<rgmc::Arrival>> inbox(4);
      std::vector<int> labels(4, 0);
      more = false;
      for (int r = 0; r < 4; ++r)
      {
        more = more || kernels[r]->Busy();
        for (const rgmc::Departure& d : kernels[r]->TakeDepartures())
        {
          int p[3], axis;
          grid.Decode(d.Key, p, axis);
          std::set<int> to;
          rgmc::ForCubesAround(p, axis,
            [&](int i, int j, int k, int)
            {
              const int owner = owners[r].OwnerNear(i, j, k);
              if (grid.HasCell(i, j, k) && owner >= 0 && owner != r)
              {
                to.insert(owner);
              }
            });
          for (const int q : to)
          {
            inbox[q].push_back(rgmc::Arrival{ d.Key, labels[q]++ });
            more = true;
          }
        }
      }
      for (int r = 0; r < 4; ++r)
      {
        kernels[r]->GrowFromArrivals(inbox[r], labels[r]);
      }
    }
    std::set<Triangle> united;
    for (int r = 0; r < 4; ++r)
    {
      RGMC_CHECK(kernels[r]->CrossingsRead() == kernels[r]->CrossingsPosted(),
        "budget " << budget << ": owner " << r << "'s tiles read " << kernels[r]->CrossingsRead()
                  << " crossings of the " << kernels[r]->CrossingsPosted() << " sent them");
      kernels[r]->Extract();
      for (const Triangle& t : KeyTriangles(kernels[r]->Mesh()))
      {
        RGMC_CHECK(united.insert(t).second, "budget " << budget << ": a triangle made twice");
      }
    }
    RGMC_CHECK(united == expected,
      "budget " << budget << ": the owners' union differs from one "
                << "owner's: " << united.size() << " vs " << expected.size() << " triangles");
    RGMC_CHECK(
      rounds > 2, "budget " << budget << ": the surface crossed in " << rounds << " rounds");
    for (const int r : { 0, 3 })
    {
      RGMC_CHECK(kernels[r]->CubesExamined() == 0,
        "budget " << budget << ": owner " << r << ", without surface, examined "
                  << kernels[r]->CubesExamined() << " cubes");
    }
    RGMC_CHECK(kernels[2]->CubesExamined() > 0, "budget " << budget << ": owner 2 grew nothing");
  }
}

/// A sphere: radius - the distance to `centre` (index space), so inside is above 0.
void FillSphere(Volume& vol, const std::array<double, 3>& centre, double radius)
{
  for (int k = 0; k <= vol.Extent[5]; ++k)
  {
    for (int j = 0; j <= vol.Extent[3]; ++j)
    {
      for (int i = 0; i <= vol.Extent[1]; ++i)
      {
        const double d[3] = { i - centre[0], j - centre[1], k - centre[2] };
        vol.At(i, j, k) =
          static_cast<float>(radius - std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]));
      }
    }
  }
}

/// Seeded growth reads the same samples for the same surface, however large the volume.
void CostFollowsSurface()
{
  std::int64_t reads[2] = { 0, 0 };
  std::size_t triangles[2] = { 0, 0 };
  const int sizes[2] = { 24, 96 };
  for (int n = 0; n < 2; ++n)
  {
    const int size = sizes[n];
    Volume vol(size, size, size);
    FillSphere(vol, { 10.3, 10.7, 10.1 }, 6.0);
    const rgmc::Grid grid(vol.Extent, vol.Extent);
    const rgmc::Ownership own = OwnAll(grid);
    rgmc::SurfaceOptions params;
    Counted counted{ &vol.Values };
    rgmc::SurfaceKernel<Counted> g(Table(), grid, own, counted, params);
    const double seed[3] = { 16.5, 10.5, 10.5 };
    const rgmc::SeedHit hit = g.NearestVertex(seed, seed, 10.0, 1.0);
    RGMC_CHECK(hit.Found, "the sphere is within the radius");
    g.GrowFromKey(hit.Key);
    g.Extract();
    reads[n] = counted.Reads;
    triangles[n] = static_cast<std::size_t>(g.Mesh().NumberOfTriangles());
    RGMC_CHECK(Closed(KeyTriangles(g.Mesh())), "the sphere is closed");
  }
  RGMC_CHECK(triangles[0] == triangles[1] && triangles[0] > 0, "same sphere, same triangles");
  RGMC_CHECK(
    reads[0] == reads[1], "reads grew with the volume: " << reads[0] << " vs " << reads[1]);
  // 24^3 has 12167 cubes; the growth must stay well below one read per sample of the volume.
  RGMC_CHECK(reads[1] < 96LL * 96 * 96 / 20, "reads " << reads[1] << " look like a full scan");
}

/// Seeded growth makes the state of the tiles its nodes lie in and of no other: a small sphere
/// across tile corners in a volume of 4^3 tiles reaches the 8 tiles around the corner. The
/// oracle: every cube around an edge of a surface vertex has a node with that vertex (no sample
/// equals the isovalue here), so the nodes' tiles are those of the cubes around the vertices of
/// the surface. The full scan reaches every tile.
void TilesFollowSurface()
{
  const int size = 100; // 99 cubes along each axis: 4 tiles of 32 (the last of 3 cubes)
  Volume vol(size, size, size);
  FillSphere(vol, { 31.6, 32.3, 63.8 }, 5.0);
  const rgmc::Grid grid(vol.Extent, vol.Extent);
  const rgmc::Ownership own = OwnAll(grid);
  rgmc::SurfaceOptions params;
  rgmc::SurfaceKernel<std::vector<float>> seeded(Table(), grid, own, vol.Values, params);
  const double seed[3] = { 36.6, 32.3, 63.8 };
  const rgmc::SeedHit hit = seeded.NearestVertex(seed, seed, 10.0, 1.0);
  RGMC_CHECK(hit.Found, "the sphere is within the radius");
  seeded.GrowFromKey(hit.Key);
  seeded.Extract();
  const rgmc::LocalMesh& mesh = seeded.Mesh();
  std::set<std::array<int, 3>> tiles;
  for (std::int64_t v = 0; v < mesh.NumberOfPoints(); ++v)
  {
    int p[3], axis;
    grid.Decode(mesh.Keys[v], p, axis);
    RGMC_CHECK(axis >= 0, "a vertex on a grid point, where no sample equals the isovalue");
    const int u = (axis + 1) % 3, w = (axis + 2) % 3;
    for (int du = -1; du <= 0; ++du)
    {
      for (int dw = -1; dw <= 0; ++dw)
      {
        int c[3] = { p[0], p[1], p[2] };
        c[u] += du;
        c[w] += dw;
        if (c[u] >= 0 && c[u] < size - 1 && c[w] >= 0 && c[w] < size - 1)
        {
          tiles.insert({ c[0] / rgmc::GrowthTileCubes, c[1] / rgmc::GrowthTileCubes,
            c[2] / rgmc::GrowthTileCubes });
        }
      }
    }
  }
  RGMC_CHECK(tiles.size() == 8, "the sphere lies in " << tiles.size() << " tiles, not 8");
  RGMC_CHECK(seeded.TilesReached() == static_cast<std::int64_t>(tiles.size()),
    "seeded growth reached " << seeded.TilesReached() << " tiles; its nodes lie in "
                             << tiles.size());
  rgmc::SurfaceKernel<std::vector<float>> full(Table(), grid, own, vol.Values, params);
  full.GrowAll();
  RGMC_CHECK(
    full.TilesReached() == 64, "the full scan reached " << full.TilesReached() << " tiles of 64");
}

/// Uniform numbers in [0, 1) from a xorshift generator (the same on every platform).
struct Random
{
  std::uint64_t State;
  double operator()()
  {
    this->State ^= this->State << 13;
    this->State ^= this->State >> 7;
    this->State ^= this->State << 17;
    return static_cast<double>(this->State % 1000000) / 1000000.0;
  }
};

/// Samples 2 with probability pTwo, 1 (the tests' isovalue) with probability pOne, else 0.
void FillThreeLevels(Volume& vol, double pOne, double pTwo, Random& next)
{
  for (float& v : vol.Values)
  {
    const double r = next();
    v = r < pTwo ? 2.0f : (r < pTwo + pOne ? 1.0f : 0.0f);
  }
}

/// On one owner, growth follows every adjacency by itself: a component never meets a vertex
/// that another component created. Checked on many small volumes whose samples often equal
/// the isovalue (where vertices collapse and surfaces touch only at points).
void TraversalIsComplete()
{
  Random next{ 88172645463325252ull };
  std::int64_t joins = 0, triangles = 0;
  for (int trial = 0; trial < 400; ++trial)
  {
    const double pOne = 0.1 + 0.3 * next(), pTwo = 0.05 + 0.3 * next();
    Volume vol(7, 6, 7);
    FillThreeLevels(vol, pOne, pTwo, next);
    const rgmc::Grid grid(vol.Extent, vol.Extent);
    const rgmc::Ownership own = OwnAll(grid);
    rgmc::SurfaceOptions params;
    params.Isovalue = 1.0;
    rgmc::SurfaceKernel<std::vector<float>> g(Table(), grid, own, vol.Values, params);
    g.GrowAll();
    g.Extract();
    joins += g.Joins();
    triangles += g.Mesh().NumberOfTriangles();
  }
  RGMC_CHECK(triangles > 0, "the volumes have surfaces");
  RGMC_CHECK(joins == 0, "growth missed " << joins << " adjacencies that a later component met");
}

/// Seeded growth hands steps into other tiles to them as crossings, grouped by the neighbour
/// they go to (across a face, an edge or a corner of the tile). On random fields over 3 x 3 x 3
/// tiles, with samples equal to the isovalue (vertices on grid points), every crossing sent is
/// read once, and seeds from every vertex grow each component whole: no two seeded components
/// share a vertex (extraction would join them), the triangles are the full scan's, and the
/// largest component reaches all 27 tiles.
void CrossingsReachEveryNeighbourTile()
{
  Random next{ 0x9E3779B97F4A7C15ull };
  for (int trial = 0; trial < 3; ++trial)
  {
    const double pOne = 0.1 + 0.1 * trial, pTwo = 0.35 - 0.1 * trial;
    Volume vol(70, 70, 70); // 69 cubes along each axis: 3 tiles of 32
    FillThreeLevels(vol, pOne, pTwo, next);
    const rgmc::Grid grid(vol.Extent, vol.Extent);
    const rgmc::Ownership own = OwnAll(grid);
    rgmc::SurfaceOptions params;
    params.Isovalue = 1.0;
    rgmc::SurfaceKernel<std::vector<float>> seeded(Table(), grid, own, vol.Values, params);
    int components = 0;
    for (int k = 0; k < 70; ++k)
    {
      for (int j = 0; j < 70; ++j)
      {
        for (int i = 0; i < 70; ++i)
        {
          const float s = vol.At(i, j, k);
          std::vector<std::int64_t> keys;
          if (s == 1.0f)
          {
            keys.push_back(grid.PointKey(i, j, k));
          }
          const int p[3] = { i, j, k };
          for (int a = 0; a < 3; ++a)
          {
            int q[3] = { i, j, k };
            if (++q[a] < 70)
            {
              const float t = vol.At(q[0], q[1], q[2]);
              if ((s >= 1.0f) != (t >= 1.0f) && s != 1.0f && t != 1.0f)
              {
                keys.push_back(grid.EdgeKey(p[0], p[1], p[2], a));
              }
            }
          }
          for (const std::int64_t key : keys)
          {
            components += seeded.GrowFromKey(key) >= 0;
          }
        }
      }
    }
    RGMC_CHECK(seeded.CrossingsPosted() > 0 && seeded.CrossingsRead() == seeded.CrossingsPosted(),
      "trial " << trial << ": tiles read " << seeded.CrossingsRead() << " crossings of the "
               << seeded.CrossingsPosted() << " sent them");
    seeded.Extract();
    rgmc::SurfaceKernel<std::vector<float>> full(Table(), grid, own, vol.Values, params);
    full.GrowAll();
    full.Extract();
    RGMC_CHECK(seeded.Joins() == 0,
      "trial " << trial << ": " << seeded.Joins() << " seeded components met another");
    RGMC_CHECK(KeyTriangles(seeded.Mesh()) == KeyTriangles(full.Mesh()),
      "trial " << trial << ": seeds from every vertex do not give the full scan's triangles");
    // The tiles each component's vertices lie in (a grid point on a tile's upper face counts
    // for the tile above it).
    const rgmc::LocalMesh& mesh = seeded.Mesh();
    std::map<int, std::set<int>> tiles;
    for (std::int64_t v = 0; v < mesh.NumberOfPoints(); ++v)
    {
      int p[3], axis;
      grid.Decode(mesh.Keys[v], p, axis);
      tiles[mesh.VertexComponent[v]].insert(
        std::min(p[0] / 32, 2) + 3 * (std::min(p[1] / 32, 2) + 3 * std::min(p[2] / 32, 2)));
    }
    std::size_t most = 0;
    for (const auto& t : tiles)
    {
      most = std::max(most, t.second.size());
    }
    RGMC_CHECK(most == 27,
      "trial " << trial << ": the largest component reaches " << most << " tiles of 27");
    RGMC_CHECK(static_cast<int>(tiles.size()) <= components,
      "trial " << trial << ": " << tiles.size() << " components in the mesh, " << components
               << " seeded");
  }
}

} // namespace

int main()
{
  OneCorner();
  TwoBlobs();
  SampleEqualsIsovalue();
  SplitOwnership();
  RoundsBetweenOwners();
  CostFollowsSurface();
  TilesFollowSurface();
  TraversalIsComplete();
  CrossingsReachEveryNeighbourTile();
  return rgmc_test::Result("TestGrowth");
}

// The kernel's shortcuts against what they stand for, without VTK's filters:
//   - ClassifyRow (the full scan's classification of grid points) against Evaluate's case bits
//     and its NaN test, on every row, start and length of float and integer fields, at integer
//     and fractional isovalues, isovalues beyond the samples' type and NaN;
//   - EdgeNeighbourTable (growth's fixed steps to the cubes around an edge) against
//     ForCubesAround, in the same order, and the neighbour's edge being the same edge;
//   - TileStepTable (the same steps with their found-bit offsets and needed room) against the
//     steps themselves: for every cube of a box of several partial tiles, every step's neighbour
//     is taken inside the tile exactly when it lies in the cube's tile and in the box, at the
//     table's offset of the tile-local found-bit;
//   - the full scan (GrowAll) finding exactly the cubes that have surface nodes, counted by
//     brute force over every cube (Evaluate + Describe), on volumes cut into partial tiles, with
//     samples equal to the isovalue, and on a piece whose cubes overlap a lower rank's;
//   - a NaN sample away from the surface (in a region the scan classifies as empty) still
//     reported by the full scan, naming its grid point;
//   - PositionsAndNormals (extraction's vertices in batches) against PositionAndNormal, one
//     vertex at a time, to the bit: every edge that crosses the isovalue and some grid points,
//     in batches of every size, in a piece with and without a ghost layer's missing side, with
//     a rotated, anisotropic index-to-world map, normals on and off, and NaN samples (the same
//     error).
#include "rgmcCheck.h"
#include "rgmcSurfaceKernel.h"

#include "vtkMarchingCubesTriangleCases.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <iostream>
#include <limits>
#include <set>
#include <tuple>
#include <type_traits>
#include <vector>

namespace
{

const rgmc::CaseTable& Table()
{
  static const rgmc::CaseTable table(&vtkMarchingCubesTriangleCases::GetCases()[0].edges[0]);
  return table;
}

/// A fixed pseudo-random sequence.
struct Random
{
  std::uint64_t State = 12345;
  double Next()
  {
    this->State = this->State * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<double>(this->State >> 11) / 9007199254740992.0;
  }
};

/// Blobs rounded to integers (many samples equal the isovalue 3; raised by 16 for an unsigned
/// type), with a few NaN when asked.
template <typename T>
std::vector<T> Field(const int n[3], bool withNaN)
{
  std::vector<T> values(static_cast<std::size_t>(n[0]) * n[1] * n[2]);
  Random random;
  for (int k = 0; k < n[2]; ++k)
  {
    for (int j = 0; j < n[1]; ++j)
    {
      for (int i = 0; i < n[0]; ++i)
      {
        double v =
          5 * std::sin(0.31 * i) * std::cos(0.23 * j) + 4 * std::sin(0.19 * k) + 2 * random.Next();
        if (std::is_unsigned<T>::value)
        {
          v += 16; // no negative values for an unsigned type
        }
        values[i + n[0] * (j + n[1] * static_cast<std::size_t>(k))] = static_cast<T>(std::round(v));
      }
    }
  }
  if (withNaN)
  {
    for (int c = 0; c < 20; ++c)
    {
      values[static_cast<std::size_t>(random.Next() * values.size())] =
        std::numeric_limits<T>::quiet_NaN();
    }
  }
  return values;
}

/// A volume of n points per axis cut into `boxes` of cubes, seen by `owner`, at the isovalue 3.
struct Piece
{
  Piece(const int n[3], std::vector<rgmc::CellBox> boxes = {}, int owner = 0)
    : GridOf(Whole(n).data(), Whole(n).data())
    , Owned(boxes.empty() ? std::vector<rgmc::CellBox>{ this->GridOf.WholeCells() } : boxes, owner)
  {
    this->Options.Isovalue = 3.0;
  }
  static std::array<int, 6> Whole(const int n[3])
  {
    return { 0, n[0] - 1, 0, n[1] - 1, 0, n[2] - 1 };
  }
  rgmc::Grid GridOf;
  rgmc::Ownership Owned;
  rgmc::SurfaceOptions Options;
};

template <typename T>
void CheckClassifyRow(const char* what, bool withNaN, double isovalue = 3.0)
{
  const int n[3] = { 70, 9, 7 };
  const std::vector<T> values = Field<T>(n, withNaN);
  Piece piece(n);
  piece.Options.Isovalue = isovalue;
  const rgmc::Grid& grid = piece.GridOf;
  const rgmc::Ownership& own = piece.Owned;
  const rgmc::SurfaceOptions& options = piece.Options;
  rgmc::SampledVolume<std::vector<T>> volume(Table(), grid, own, values, options);
  int rows = 0;
  for (int k = 0; k < n[2]; ++k)
  {
    for (int j = 0; j < n[1]; ++j)
    {
      for (int i0 = 0; i0 < n[0]; ++i0)
      {
        for (int length = 1; length <= 64 && i0 + length <= n[0]; ++length)
        {
          std::uint64_t above = ~std::uint64_t(0), notNumber = ~std::uint64_t(0);
          volume.ClassifyRow(i0, length, j, k, above, notNumber);
          std::uint64_t wantAbove = 0, wantNaN = 0;
          for (int b = 0; b < length; ++b)
          {
            const double s = static_cast<double>(values[grid.LocalIndex(i0 + b, j, k)]);
            wantAbove |= static_cast<std::uint64_t>(s >= options.Isovalue) << b;
            wantNaN |= static_cast<std::uint64_t>(s != s) << b;
          }
          RGMC_CHECK(above == wantAbove && notNumber == wantNaN,
            what << ": row j " << j << " k " << k << " from i " << i0 << ", " << length
                 << " points: classified " << above << "/" << notNumber << ", expected "
                 << wantAbove << "/" << wantNaN);
          ++rows;
        }
      }
    }
  }
  // The case bits of every cube from its rows, as the scan combines them, against Evaluate.
  for (int k = 0; k + 1 < n[2]; ++k)
  {
    for (int j = 0; j + 1 < n[1]; ++j)
    {
      std::uint64_t a[4], x[4];
      for (int r = 0; r < 4; ++r)
      {
        volume.ClassifyRow(0, 64, j + (r & 1), k + (r >> 1), a[r], x[r]);
      }
      for (int i = 0; i < 63; ++i)
      {
        int code = 0;
        for (int v = 0; v < 8; ++v)
        {
          const int* o = rgmc::CornerOffset[v];
          code |= static_cast<int>((a[o[1] + 2 * o[2]] >> (i + o[0])) & 1) << v;
        }
        bool nan = false;
        for (int r = 0; r < 4; ++r)
        {
          nan = nan || ((x[r] >> i) & 3);
        }
        rgmc::CubeSamples st;
        rgmc::SampledVolume<std::vector<T>> fresh(Table(), grid, own, values, options);
        const bool read = fresh.Evaluate(i, j, k, st);
        RGMC_CHECK(read != nan,
          what << ": cube " << i << " " << j << " " << k << ": Evaluate "
               << (read ? "read it" : "met a NaN") << ", the rows say "
               << (nan ? "NaN" : "no NaN"));
        RGMC_CHECK(!read || code == st.Case,
          what << ": cube " << i << " " << j << " " << k << ": case " << st.Case
               << " from Evaluate, " << code << " from the rows");
      }
    }
  }
  std::cout << what << ": " << rows << " rows classified\n";
}

void CheckEdgeNeighbours()
{
  const int whole[6] = { 0, 20, 0, 20, 0, 20 };
  const rgmc::Grid grid(whole, whole);
  const int cube[3] = { 5, 6, 7 };
  for (int e = 0; e < 12; ++e)
  {
    const int* lo = rgmc::CornerOffset[rgmc::EdgeCorners[e][0]];
    const int p[3] = { cube[0] + lo[0], cube[1] + lo[1], cube[2] + lo[2] };
    const int axis = rgmc::CaseTable::EdgeAxis(e);
    std::vector<std::tuple<int, int, int, int>> around;
    rgmc::ForCubesAround(p, axis,
      [&](int i, int j, int k, int edge)
      {
        if (i != cube[0] || j != cube[1] || k != cube[2])
        {
          around.emplace_back(i, j, k, edge);
        }
      });
    RGMC_CHECK(around.size() == 3, "edge " << e << ": " << around.size() << " other cubes");
    for (std::size_t n = 0; n < around.size() && n < 3; ++n)
    {
      const rgmc::EdgeNeighbour& nb = rgmc::EdgeNeighbourTable[e][n];
      const int at[3] = { cube[0] + nb.Offset[0], cube[1] + nb.Offset[1], cube[2] + nb.Offset[2] };
      RGMC_CHECK(std::make_tuple(at[0], at[1], at[2], int(nb.Edge)) == around[n],
        "edge " << e << ", neighbour " << n << ": the table steps to " << at[0] << " " << at[1]
                << " " << at[2] << " edge " << int(nb.Edge) << ", ForCubesAround gives "
                << std::get<0>(around[n]) << " " << std::get<1>(around[n]) << " "
                << std::get<2>(around[n]) << " edge " << std::get<3>(around[n]));
      // The neighbour's edge is the same edge of the grid: the same key.
      const int* nlo = rgmc::CornerOffset[rgmc::EdgeCorners[nb.Edge][0]];
      RGMC_CHECK(grid.EdgeKey(at[0] + nlo[0], at[1] + nlo[1], at[2] + nlo[2],
                   rgmc::CaseTable::EdgeAxis(nb.Edge)) == grid.EdgeKey(p[0], p[1], p[2], axis),
        "edge " << e << ", neighbour " << n << ": not the same edge of the grid");
    }
  }
}

/// TileStepTable and TileRoom against the tiles and the box they stand for.
void CheckTileSteps()
{
  rgmc::CellBox box;
  const int lo[3] = { 3, -2, 5 }, size[3] = { 70, 40, 33 }; // partial tiles on every axis
  for (int a = 0; a < 3; ++a)
  {
    box.Lo[a] = lo[a];
    box.Hi[a] = lo[a] + size[a] - 1;
  }
  const int t = rgmc::GrowthTileCubes;
  auto tileOf = [&](const int c[3]) {
    return std::make_tuple((c[0] - box.Lo[0]) / t, (c[1] - box.Lo[1]) / t, (c[2] - box.Lo[2]) / t);
  };
  auto localBit = [&](const int c[3])
  {
    return ((c[0] - box.Lo[0]) % t) + t * (((c[1] - box.Lo[1]) % t) + t * ((c[2] - box.Lo[2]) % t));
  };
  std::int64_t inside = 0, outside = 0;
  int c[3];
  for (c[2] = box.Lo[2]; c[2] <= box.Hi[2]; ++c[2])
  {
    for (c[1] = box.Lo[1]; c[1] <= box.Hi[1]; ++c[1])
    {
      for (c[0] = box.Lo[0]; c[0] <= box.Hi[0]; ++c[0])
      {
        const unsigned room = rgmc::TileRoom(c, box);
        for (int e = 0; e < 12; ++e)
        {
          for (int n = 0; n < 3; ++n)
          {
            const rgmc::TileStep& step = rgmc::TileStepTable[e][n];
            const rgmc::EdgeNeighbour& nb = rgmc::EdgeNeighbourTable[e][n];
            const int to[3] = { c[0] + nb.Offset[0], c[1] + nb.Offset[1], c[2] + nb.Offset[2] };
            const bool expected = box.Contains(to[0], to[1], to[2]) && tileOf(to) == tileOf(c);
            const bool taken = (step.Needs & ~room) == 0;
            RGMC_CHECK(taken == expected,
              "cube " << c[0] << " " << c[1] << " " << c[2] << ", edge " << e << ", step " << n
                      << ": taken inside the tile " << taken << ", expected " << expected);
            RGMC_CHECK(step.Edge == nb.Edge && step.Offset[0] == nb.Offset[0] &&
                step.Offset[1] == nb.Offset[1] && step.Offset[2] == nb.Offset[2],
              "edge " << e << ", step " << n << ": not EdgeNeighbourTable's step");
            if (expected)
            {
              RGMC_CHECK(localBit(c) + step.BitOffset == localBit(to),
                "cube " << c[0] << " " << c[1] << " " << c[2] << ", edge " << e << ", step " << n
                        << ": found-bit offset " << step.BitOffset << ", expected "
                        << localBit(to) - localBit(c));
            }
            (expected ? inside : outside) += 1;
          }
        }
      }
    }
  }
  RGMC_CHECK(inside > 0 && outside > 0, "steps inside " << inside << ", outside " << outside);
}

/// The full scan on `owner` of `boxes`, against a brute-force count of the owned cubes that
/// have nodes.
void CheckScan(const char* what, const int n[3], const std::vector<rgmc::CellBox>& boxes, int owner)
{
  const std::vector<float> values = Field<float>(n, false);
  const Piece piece(n, boxes, owner);
  const rgmc::Ownership& own = piece.Owned;
  rgmc::SampledVolume<std::vector<float>> volume(Table(), piece.GridOf, own, values, piece.Options);
  rgmc::ComponentSet components;
  rgmc::SurfaceGrowth<std::vector<float>> growth(volume, components);
  growth.GrowAll();
  std::set<std::tuple<int, int, int, int>> found;
  std::size_t duplicates = 0;
  growth.Nodes().ForEach([&](const rgmc::SurfaceNode& node)
    { duplicates += !found.emplace(node.I, node.J, node.K, node.Node).second; });
  std::set<std::tuple<int, int, int, int>> expected;
  rgmc::CubeSamples st;
  rgmc::CubeSurface surface;
  std::size_t degenerate = 0;
  for (int k = 0; k + 1 < n[2]; ++k)
  {
    for (int j = 0; j + 1 < n[1]; ++j)
    {
      for (int i = 0; i + 1 < n[0]; ++i)
      {
        if (!own.Owns(i, j, k) || !volume.Evaluate(i, j, k, st))
        {
          continue;
        }
        volume.Describe(i, j, k, st, surface);
        degenerate += st.Degenerate;
        for (int node = 0; node < surface.NumberOfNodes(); ++node)
        {
          expected.emplace(i, j, k, node);
        }
      }
    }
  }
  RGMC_CHECK(duplicates == 0, what << ": " << duplicates << " nodes found twice");
  RGMC_CHECK(found == expected,
    what << ": the scan found " << found.size() << " nodes, " << expected.size() << " expected");
  RGMC_CHECK(degenerate > 0, what << ": no cube with a sample equal to the isovalue");
  std::cout << what << ": " << found.size() << " nodes, " << degenerate
            << " cubes with a sample on the isovalue\n";
}

void CheckNaNAwayFromSurface()
{
  const int n[3] = { 50, 40, 36 };
  for (const float level : { -5.0f, 10.0f }) // all below, all above the isovalue
  {
    std::vector<float> values(static_cast<std::size_t>(n[0]) * n[1] * n[2], level);
    // A small surface far from the NaN, so that the scan has work elsewhere.
    values[3 + n[0] * (3 + n[1] * 3)] = level < 0 ? 10.0f : -5.0f;
    values[40 + n[0] * (33 + n[1] * 30)] = std::numeric_limits<float>::quiet_NaN();
    const Piece piece(n);
    rgmc::SurfaceKernel<std::vector<float>> kernel(
      Table(), piece.GridOf, piece.Owned, values, piece.Options);
    kernel.GrowAll();
    const std::string error = kernel.Error();
    RGMC_CHECK(error.find("(40, 33, 30) is NaN") != std::string::npos,
      "a NaN in a region " << (level < 0 ? "below" : "above") << " the isovalue: the scan says '"
                           << error << "'");
  }
}

/// PositionsAndNormals against PositionAndNormal on a piece with the local extent `local` of a
/// 30 x 26 x 22 volume.
template <typename T>
void CheckBatchedPositions(const char* what, const int local[6], bool withNaN, bool normals)
{
  const int n[3] = { 30, 26, 22 };
  const int whole[6] = { 0, n[0] - 1, 0, n[1] - 1, 0, n[2] - 1 };
  const std::vector<T> all = Field<T>(n, withNaN);
  std::vector<T> values;
  for (int k = local[4]; k <= local[5]; ++k)
  {
    for (int j = local[2]; j <= local[3]; ++j)
    {
      for (int i = local[0]; i <= local[1]; ++i)
      {
        values.push_back(all[i + n[0] * (j + n[1] * static_cast<std::size_t>(k))]);
      }
    }
  }
  const rgmc::Grid grid(whole, local);
  const rgmc::Ownership own({ grid.WholeCells() }, 0);
  rgmc::SurfaceOptions options;
  options.Isovalue = std::is_integral<T>::value ? 3.0 : 2.75;
  options.ComputeNormals = normals;
  // A rotation about z by 30 degrees, spacings 0.7, 1.3 and 2.1, an origin off zero.
  const double c = std::cos(0.5235987755982988), s = std::sin(0.5235987755982988);
  const double spacing[3] = { 0.7, 1.3, 2.1 }, origin[3] = { -4.5, 2.25, 10.125 };
  const double rotation[3][3] = { { c, -s, 0 }, { s, c, 0 }, { 0, 0, 1 } };
  for (int r = 0; r < 3; ++r)
  {
    for (int a = 0; a < 3; ++a)
    {
      options.IndexToWorld[r][a] = rotation[r][a] * spacing[a];
      options.NormalToWorld[r][a] = rotation[r][a] / spacing[a];
    }
    options.IndexToWorld[r][3] = origin[r];
  }
  // The vertices: every edge of the piece that crosses the isovalue, and every fifth grid point.
  std::vector<std::array<int, 4>> vertices;
  for (int k = local[4]; k <= local[5]; ++k)
  {
    for (int j = local[2]; j <= local[3]; ++j)
    {
      for (int i = local[0]; i <= local[1]; ++i)
      {
        const int p[3] = { i, j, k };
        const double lo = static_cast<double>(values[grid.LocalIndex(i, j, k)]);
        for (int axis = 0; axis < 3; ++axis)
        {
          int q[3] = { i, j, k };
          ++q[axis];
          if (q[axis] > local[2 * axis + 1])
          {
            continue;
          }
          const double hi = static_cast<double>(values[grid.LocalIndex(q[0], q[1], q[2])]);
          if ((lo >= options.Isovalue) != (hi >= options.Isovalue) || lo != lo || hi != hi)
          {
            vertices.push_back({ p[0], p[1], p[2], axis });
          }
        }
        if ((i + 2 * j + 3 * k) % 5 == 0)
        {
          vertices.push_back({ p[0], p[1], p[2], -1 });
        }
      }
    }
  }
  // One at a time, as extraction placed them before.
  rgmc::SampledVolume<std::vector<T>> single(Table(), grid, own, values, options);
  std::vector<double> x1(3 * vertices.size());
  std::vector<float> n1(3 * vertices.size());
  for (std::size_t v = 0; v < vertices.size(); ++v)
  {
    const int* p = vertices[v].data();
    const int axis = vertices[v][3];
    double sLo = 0.0, sHi = 0.0;
    if (axis >= 0)
    {
      int q[3] = { p[0], p[1], p[2] };
      ++q[axis];
      sLo = single.Read(p[0], p[1], p[2]);
      sHi = single.Read(q[0], q[1], q[2]);
    }
    float normal[3] = { 0, 0, 0 };
    single.PositionAndNormal(p, axis, sLo, sHi, &x1[3 * v], normal);
    std::memcpy(&n1[3 * v], normal, sizeof(normal));
  }
  // In batches of 1, 2, ..., VertexBatch vertices, again and again.
  constexpr int B = rgmc::SampledVolume<std::vector<T>>::VertexBatch;
  rgmc::SampledVolume<std::vector<T>> batched(Table(), grid, own, values, options);
  std::vector<double> x2(3 * vertices.size());
  std::vector<float> n2(3 * vertices.size());
  int batches = 0;
  for (std::size_t first = 0; first < vertices.size(); ++batches)
  {
    const int count =
      static_cast<int>(std::min<std::size_t>(1 + batches % B, vertices.size() - first));
    int p[B][3], axis[B];
    double x[B][3];
    float normal[B][3];
    for (int b = 0; b < count; ++b)
    {
      for (int a = 0; a < 3; ++a)
      {
        p[b][a] = vertices[first + b][a];
      }
      axis[b] = vertices[first + b][3];
    }
    batched.PositionsAndNormals(p, axis, count, x, normal);
    std::memcpy(&x2[3 * first], x, sizeof(double) * 3 * count);
    std::memcpy(&n2[3 * first], normal, sizeof(float) * 3 * count);
    first += count;
  }
  std::size_t differ = 0, first = vertices.size();
  for (std::size_t v = 0; v < vertices.size(); ++v)
  {
    if (std::memcmp(&x1[3 * v], &x2[3 * v], 3 * sizeof(double)) != 0 ||
      std::memcmp(&n1[3 * v], &n2[3 * v], 3 * sizeof(float)) != 0)
    {
      first = std::min(first, v);
      ++differ;
    }
  }
  RGMC_CHECK(differ == 0,
    what << ": " << differ << " of " << vertices.size()
         << " vertices differ in batches; the first at (" << vertices[first][0] << ", "
         << vertices[first][1] << ", " << vertices[first][2] << ") axis " << vertices[first][3]
         << ": " << x2[3 * first] << " " << x2[3 * first + 1] << " " << x2[3 * first + 2] << " / "
         << n2[3 * first] << " " << n2[3 * first + 1] << " " << n2[3 * first + 2] << " against "
         << x1[3 * first] << " " << x1[3 * first + 1] << " " << x1[3 * first + 2] << " / "
         << n1[3 * first] << " " << n1[3 * first + 1] << " " << n1[3 * first + 2]);
  RGMC_CHECK(single.Error() == batched.Error(),
    what << ": one at a time '" << single.Error() << "', in batches '" << batched.Error() << "'");
  RGMC_CHECK(!withNaN || !batched.Error().empty(), what << ": no NaN reported");
  std::cout << what << ": " << vertices.size() << " vertices in " << batches
            << " batches, the same to the bit\n";
}

} // namespace

int main()
{
  CheckClassifyRow<float>("float samples with NaN", true);
  CheckClassifyRow<short>("int16 samples", false);
  // Integer samples are classified in their own type, against the isovalue rounded up: between
  // two integers, beyond the type's range at either end, and NaN (no sample is above it).
  CheckClassifyRow<short>("int16 samples, isovalue 2.5", false, 2.5);
  CheckClassifyRow<short>("int16 samples, isovalue -2.5", false, -2.5);
  CheckClassifyRow<short>("int16 samples, isovalue -40000", false, -40000.0);
  CheckClassifyRow<short>("int16 samples, isovalue 40000", false, 40000.0);
  CheckClassifyRow<short>(
    "int16 samples, isovalue NaN", false, std::numeric_limits<double>::quiet_NaN());
  CheckClassifyRow<unsigned char>("uint8 samples, isovalue 19.5", false, 19.5);
  CheckClassifyRow<int>("int32 samples, isovalue -0.5", false, -0.5);
  CheckClassifyRow<long long>("int64 samples (compared in double)", false, 2.5);
  CheckEdgeNeighbours();
  CheckTileSteps();
  // Partial tiles (70 = 2 x 32 + 6 points), more than one tile along each axis.
  const int n[3] = { 70, 45, 38 };
  const rgmc::CellBox all = Piece(n).GridOf.WholeCells();
  CheckScan("one owner", n, { all }, 0);
  // A piece whose box overlaps a lower rank's (the holes of a reader that ignores pieces):
  // rank 1 owns its box minus rank 0's.
  rgmc::CellBox lower = all, upper = all;
  lower.Hi[0] = 40;
  upper.Lo[0] = 20;
  upper.Lo[1] = 3;
  CheckScan("overlapping boxes, rank 0", n, { lower, upper }, 0);
  CheckScan("overlapping boxes, rank 1", n, { lower, upper }, 1);
  CheckNaNAwayFromSurface();
  const int wholePiece[6] = { 0, 29, 0, 25, 0, 21 };
  const int ghostPiece[6] = { 4, 22, 0, 17, 3, 21 }; // samples missing beyond it on 4 sides
  CheckBatchedPositions<short>("positions in batches, int16", wholePiece, false, true);
  CheckBatchedPositions<short>("positions in batches, int16, a piece", ghostPiece, false, true);
  CheckBatchedPositions<float>("positions in batches, float", wholePiece, false, true);
  CheckBatchedPositions<float>("positions in batches, float, no normals", ghostPiece, false, false);
  CheckBatchedPositions<float>("positions in batches, float with NaN", wholePiece, true, true);
  CheckBatchedPositions<double>("positions in batches, double, a piece", ghostPiece, false, true);
  return rgmc_test::Result("TestKernelShortcuts");
}

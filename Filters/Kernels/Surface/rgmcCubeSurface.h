// What seed search, growth and extraction share, below all three: the samples of one piece of
// the volume (read with NaN checks), the position and normal of a surface vertex, the surface
// nodes of one cube, the cubes around a vertex, and the components found on one rank.
//
// A surface node is one connected group of a cube's triangles: a sheet of the case table, or,
// in a cube with a sample equal to the isovalue, a group of the triangles that survive
// collapsing their vertices onto that grid point. Two nodes are adjacent when they share a
// vertex key; a vertex on an edge lies in the 4 cubes around the edge, a vertex on a grid point
// in the 8 cubes around the point.
#ifndef rgmcCubeSurface_h
#define rgmcCubeSurface_h

#include "rgmcCaseTable.h"
#include "rgmcGrid.h"
#include "rgmcUnionFind.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <exception>
#include <functional>
#include <limits>
#include <mutex>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#if defined(__SSE2__)
#include <emmintrin.h>
#elif defined(__aarch64__)
#include <arm_neon.h>
#endif

namespace rgmc
{

struct SurfaceOptions
{
  double Isovalue = 0.0;
  bool ComputeNormals = true;
  /// Store output points in double (LocalMesh::PointsDouble) instead of float (Points).
  bool DoublePoints = false;
  /// world = IndexToWorld * (i, j, k, 1): direction * spacing, then origin.
  double IndexToWorld[3][4] = { { 1, 0, 0, 0 }, { 0, 1, 0, 0 }, { 0, 0, 1, 0 } };
  /// Maps an index-space gradient to a world-space normal before normalizing:
  /// det(direction) * direction * diag(1 / spacing), as vtkImageTransform does.
  double NormalToWorld[3][3] = { { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };
  /// Called now and then, from the calling thread only, with the fraction done (growth fills
  /// the first half, extraction the second; never decreasing); returns true to abort.
  std::function<bool(double)> Progress;
  /// Runs body(begin, end) over ranges that cover [0, count) exactly once, possibly on several
  /// threads at once (the VTK layer passes vtkSMPTools::For). Empty: one range on this thread.
  /// The results never depend on how the ranges are cut or run.
  std::function<void(
    std::int64_t count, const std::function<void(std::int64_t begin, std::int64_t end)>& body)>
    ParallelFor;
};

/// The samples at the 8 corners of a cube (VTK's corner order) and its case.
struct CubeSamples
{
  int Case = 0;
  /// A corner's sample equals the isovalue: vertices may collapse onto grid points.
  bool Degenerate = false;
  double S[8];
};

/// A vertex of the surface as a cube sees it: its key, the grid point it lies on or leaves
/// from, its axis (-1 on a grid point) and the cube's edge that carries it.
struct SurfaceVertex
{
  std::int64_t Key;
  int Point[3];
  int Axis;
  int Edge;
};

/// A node found by growth: its cube, case, node within the cube and component.
struct SurfaceNode
{
  std::int32_t I, J, K;
  std::int32_t Component;
  std::uint8_t Case;
  std::uint8_t Node;
  bool Degenerate;
};

/// Surface nodes in blocks, in order: growth hands over each tile's queue of a round as it is,
/// instead of copying it onto the end of one growing list.
class NodeList
{
public:
  /// Appends the nodes of `block` (taken; left empty).
  void Append(std::vector<SurfaceNode>& block)
  {
    if (!block.empty())
    {
      this->Count += block.size();
      this->Blocks.emplace_back(std::move(block));
    }
    block = std::vector<SurfaceNode>();
  }
  std::size_t size() const { return this->Count; }
  bool empty() const { return this->Count == 0; }
  /// f(node) for every node, in order.
  template <typename F>
  void ForEach(F&& f) const
  {
    for (const std::vector<SurfaceNode>& block : this->Blocks)
    {
      for (const SurfaceNode& n : block)
      {
        f(n);
      }
    }
  }
  void Clear()
  {
    std::vector<std::vector<SurfaceNode>>().swap(this->Blocks);
    this->Count = 0;
  }

private:
  std::vector<std::vector<SurfaceNode>> Blocks;
  std::size_t Count = 0;
};

/// The cube edge that runs along `axis` with its lower corner offset by du, dv (0 or 1) along
/// the two other axes (in increasing axis order), from the corner and edge conventions.
constexpr int CubeEdgeAt(int axis, int du, int dv)
{
  const int u = axis == 0 ? 1 : 0, v = axis == 2 ? 1 : 2;
  for (int e = 0; e < 12; ++e)
  {
    const int* lo = CornerOffset[EdgeCorners[e][0]];
    const int* hi = CornerOffset[EdgeCorners[e][1]];
    if (hi[axis] != lo[axis] && lo[u] == du && lo[v] == dv)
    {
      return e;
    }
  }
  return -1;
}

/// CubeEdgeAt for every axis, du and dv.
constexpr std::array<std::array<std::array<int, 2>, 2>, 3> CubeEdgesAt()
{
  std::array<std::array<std::array<int, 2>, 2>, 3> edges{};
  for (int axis = 0; axis < 3; ++axis)
  {
    for (int du = 0; du < 2; ++du)
    {
      for (int dv = 0; dv < 2; ++dv)
      {
        edges[axis][du][dv] = CubeEdgeAt(axis, du, dv);
      }
    }
  }
  return edges;
}
constexpr std::array<std::array<std::array<int, 2>, 2>, 3> CubeEdgeAtTable = CubeEdgesAt();

/// The axis along which each cube edge runs, from the corner and edge conventions.
constexpr std::array<int, 12> CubeEdgeAxes()
{
  std::array<int, 12> axes{};
  for (int e = 0; e < 12; ++e)
  {
    for (int a = 0; a < 3; ++a)
    {
      if (CornerOffset[EdgeCorners[e][0]][a] != CornerOffset[EdgeCorners[e][1]][a])
      {
        axes[e] = a;
      }
    }
  }
  return axes;
}
constexpr std::array<int, 12> CubeEdgeAxis = CubeEdgeAxes();

/// One of the 3 other cubes around a cube's edge: its offset from the cube and its edge there.
struct EdgeNeighbour
{
  std::int8_t Offset[3];
  std::int8_t Edge;
};

/// For each cube edge, the 3 other cubes around it, in ForCubesAround's order (so that growth
/// visits them in the same order whichever way it steps).
constexpr std::array<std::array<EdgeNeighbour, 3>, 12> EdgeNeighbours()
{
  std::array<std::array<EdgeNeighbour, 3>, 12> table{};
  for (int e = 0; e < 12; ++e)
  {
    const int axis = CubeEdgeAxis[e];
    const int u = axis == 0 ? 1 : 0, v = axis == 2 ? 1 : 2;
    const int* p = CornerOffset[EdgeCorners[e][0]]; // the edge's lower end, from the cube
    int n = 0;
    for (int d = 0; d < 8; ++d)
    {
      const int o[3] = { d & 1, (d >> 1) & 1, (d >> 2) & 1 };
      const int offset[3] = { p[0] - o[0], p[1] - o[1], p[2] - o[2] };
      if (o[axis] != 0 || (offset[0] == 0 && offset[1] == 0 && offset[2] == 0))
      {
        continue;
      }
      EdgeNeighbour& nb = table[e][n++];
      for (int a = 0; a < 3; ++a)
      {
        nb.Offset[a] = static_cast<std::int8_t>(offset[a]);
      }
      nb.Edge = static_cast<std::int8_t>(CubeEdgeAtTable[axis][o[u]][o[v]]);
    }
  }
  return table;
}
constexpr std::array<std::array<EdgeNeighbour, 3>, 12> EdgeNeighbourTable = EdgeNeighbours();

/// Calls f(i, j, k, edge) for each cube that contains the vertex at grid point p: the 4 cubes
/// around the edge leaving p along `axis` (edge: that cube's edge carrying it), or the 8 cubes
/// around p when axis < 0 (edge -1). Cubes outside the volume are included: callers check.
template <typename F>
RGMC_INLINE void ForCubesAround(const int p[3], int axis, F&& f)
{
  for (int d = 0; d < 8; ++d)
  {
    const int o[3] = { d & 1, (d >> 1) & 1, (d >> 2) & 1 };
    if (axis >= 0 && o[axis] != 0)
    {
      continue; // an edge lies in the 4 cubes around it, not 8
    }
    int edge = -1;
    if (axis >= 0)
    {
      const int u = axis == 0 ? 1 : 0, v = axis == 2 ? 1 : 2;
      edge = CubeEdgeAtTable[axis][o[u]][o[v]];
    }
    f(p[0] - o[0], p[1] - o[1], p[2] - o[2], edge);
  }
}

/// The surface nodes of one cube: the case table's sheets, or, in a degenerate cube, the groups
/// of its surviving triangles (worked out when the cube is set).
class CubeSurface
{
public:
  RGMC_INLINE void Set(const CaseTable& table, const Grid& grid, double isovalue, int i, int j,
    int k, const CubeSamples& samples)
  {
    this->Entry = &table[samples.Case];
    this->GridOf = &grid;
    this->Cube[0] = i;
    this->Cube[1] = j;
    this->Cube[2] = k;
    this->IsDegenerate = samples.Degenerate;
    if (samples.Degenerate)
    {
      this->Collapse(isovalue, samples);
    }
  }

  bool Degenerate() const { return this->IsDegenerate; }

  int NumberOfNodes() const
  {
    return this->IsDegenerate ? this->NumGroups : this->Entry->NumSheets;
  }

  /// The nodes that have the vertex `key`, on the cube's edge `edge` (-1 for a grid-point
  /// key), as bits.
  RGMC_INLINE unsigned NodesWithVertex(std::int64_t key, int edge) const
  {
    if (!this->IsDegenerate)
    {
      const int sheet = edge >= 0 ? this->Entry->EdgeSheet[edge] : -1;
      return sheet >= 0 ? 1u << sheet : 0u;
    }
    unsigned nodes = 0;
    for (int t = 0; t < this->NumTriangles; ++t)
    {
      for (int v = 0; v < 3; ++v)
      {
        if (this->Triangles[t][v].Key == key)
        {
          nodes |= 1u << this->Group[t];
        }
      }
    }
    return nodes;
  }

  /// f(vertex) once for each vertex of `node`, or of every node when node < 0.
  template <typename F>
  RGMC_INLINE void ForEachVertex(int node, F&& f) const
  {
    if (!this->IsDegenerate)
    {
      unsigned edges = node >= 0 ? this->Entry->SheetEdges[node] : this->Entry->CutEdges;
      while (edges)
      {
        const int e = __builtin_ctz(edges);
        edges &= edges - 1;
        f(this->EdgeVertex(e));
      }
      return;
    }
    std::int64_t seen[3 * MaxTriangles];
    int numSeen = 0;
    for (int t = 0; t < this->NumTriangles; ++t)
    {
      for (int v = 0; v < 3 && (node < 0 || this->Group[t] == node); ++v)
      {
        const SurfaceVertex& x = this->Triangles[t][v];
        if (std::find(seen, seen + numSeen, x.Key) == seen + numSeen)
        {
          seen[numSeen++] = x.Key;
          f(x);
        }
      }
    }
  }

  /// f(triangle) for each triangle of `node` (3 vertices, the table's orientation).
  template <typename F>
  RGMC_INLINE void ForEachTriangle(int node, F&& f) const
  {
    if (!this->IsDegenerate)
    {
      for (int t = 0; t < this->Entry->NumTriangles; ++t)
      {
        if (this->Entry->TriangleSheet[t] == node)
        {
          const SurfaceVertex triangle[3] = { this->EdgeVertex(this->Entry->Triangles[t][0]),
            this->EdgeVertex(this->Entry->Triangles[t][1]),
            this->EdgeVertex(this->Entry->Triangles[t][2]) };
          f(triangle);
        }
      }
      return;
    }
    for (int t = 0; t < this->NumTriangles; ++t)
    {
      if (this->Group[t] == node)
      {
        f(this->Triangles[t].data());
      }
    }
  }

  /// The vertex on edge e of the cube (not collapsed).
  RGMC_INLINE SurfaceVertex EdgeVertex(int e) const
  {
    SurfaceVertex x;
    const int* o = CornerOffset[EdgeCorners[e][0]];
    for (int a = 0; a < 3; ++a)
    {
      x.Point[a] = this->Cube[a] + o[a];
    }
    x.Axis = CubeEdgeAxis[e];
    x.Edge = e;
    x.Key = this->GridOf->EdgeKey(x.Point[0], x.Point[1], x.Point[2], x.Axis);
    return x;
  }

private:
  /// The vertex on edge e, or the grid point it collapses onto when an end's sample equals the
  /// isovalue (the lower end first).
  SurfaceVertex CollapsedVertex(int e, double isovalue, const CubeSamples& s) const
  {
    for (const int corner : { EdgeCorners[e][0], EdgeCorners[e][1] })
    {
      if (s.S[corner] == isovalue)
      {
        SurfaceVertex x;
        for (int a = 0; a < 3; ++a)
        {
          x.Point[a] = this->Cube[a] + CornerOffset[corner][a];
        }
        x.Axis = -1;
        x.Edge = e;
        x.Key = this->GridOf->PointKey(x.Point[0], x.Point[1], x.Point[2]);
        return x;
      }
    }
    return this->EdgeVertex(e);
  }

  /// Collapses the vertices, drops the triangles that collapse (vtkMarchingCubes drops them
  /// too) and groups the others by shared keys, groups numbered by their first triangle.
  void Collapse(double isovalue, const CubeSamples& s)
  {
    this->NumTriangles = 0;
    for (int t = 0; t < this->Entry->NumTriangles; ++t)
    {
      std::array<SurfaceVertex, 3>& tri = this->Triangles[this->NumTriangles];
      for (int v = 0; v < 3; ++v)
      {
        tri[v] = this->CollapsedVertex(this->Entry->Triangles[t][v], isovalue, s);
      }
      if (tri[0].Key != tri[1].Key && tri[0].Key != tri[2].Key && tri[1].Key != tri[2].Key)
      {
        ++this->NumTriangles;
      }
    }
    UnionFind<int, std::array<int, MaxTriangles>> sets;
    sets.Reset(static_cast<std::size_t>(this->NumTriangles));
    for (int a = 0; a < this->NumTriangles; ++a)
    {
      for (int b = a + 1; b < this->NumTriangles; ++b)
      {
        for (int va = 0; va < 3; ++va)
        {
          for (int vb = 0; vb < 3; ++vb)
          {
            if (this->Triangles[a][va].Key == this->Triangles[b][vb].Key)
            {
              sets.Unite(a, b);
            }
          }
        }
      }
    }
    int groupOfRoot[MaxTriangles];
    std::fill(groupOfRoot, groupOfRoot + MaxTriangles, -1);
    this->NumGroups = 0;
    for (int t = 0; t < this->NumTriangles; ++t)
    {
      const int root = sets.Find(t);
      if (groupOfRoot[root] < 0)
      {
        groupOfRoot[root] = this->NumGroups++;
      }
      this->Group[t] = groupOfRoot[root];
    }
  }

  const CaseEntry* Entry = nullptr;
  const Grid* GridOf = nullptr;
  int Cube[3] = { 0, 0, 0 };
  bool IsDegenerate = false;
  // Degenerate cubes only: the surviving triangles and their groups.
  int NumTriangles = 0;
  int NumGroups = 0;
  std::array<SurfaceVertex, 3> Triangles[MaxTriangles];
  int Group[MaxTriangles];
};

/// The components found on one rank, as disjoint sets, with what the global decision needs.
class ComponentSet
{
public:
  struct Totals
  {
    bool Seeded = false;
    std::int64_t Triangles = 0;
    std::int64_t MinKey = std::numeric_limits<std::int64_t>::max();
  };

  int Add(bool seeded)
  {
    Totals totals;
    totals.Seeded = seeded;
    this->Of.push_back(totals);
    return this->Sets.Add();
  }
  /// Removes the component added last (nothing joined it).
  void RemoveLast()
  {
    this->Of.pop_back();
    this->Sets.RemoveLast();
  }
  int Size() const { return static_cast<int>(this->Of.size()); }
  int Root(int c) { return this->Sets.Find(c); }
  /// The totals of root component c.
  Totals& TotalsOf(int root) { return this->Of[root]; }
  /// Joins two components (the smaller root stays); true when they were apart.
  bool Join(int a, int b)
  {
    const std::pair<int, int> roots = this->Sets.Unite(a, b);
    if (roots.first == roots.second)
    {
      return false;
    }
    Totals& keep = this->Of[roots.first];
    const Totals& gone = this->Of[roots.second];
    keep.Seeded = keep.Seeded || gone.Seeded;
    keep.Triangles += gone.Triangles;
    keep.MinKey = std::min(keep.MinKey, gone.MinKey);
    return true;
  }

private:
  UnionFind<int> Sets;
  std::vector<Totals> Of;
};

/// x[v] = sqrt(x[v]) for v < N (N even), two at a time where the processor has them: the
/// compiler keeps std::sqrt scalar for errno's sake, and a square root is correctly rounded in
/// any width, so the values are std::sqrt's to the bit.
template <int N>
RGMC_INLINE void SquareRoots(double* x)
{
  static_assert(N % 2 == 0, "pairs");
#if defined(__SSE2__)
  for (int v = 0; v < N; v += 2)
  {
    _mm_storeu_pd(x + v, _mm_sqrt_pd(_mm_loadu_pd(x + v)));
  }
#elif defined(__aarch64__)
  for (int v = 0; v < N; v += 2)
  {
    vst1q_f64(x + v, vsqrtq_f64(vld1q_f64(x + v)));
  }
#else
  for (int v = 0; v < N; ++v)
  {
    x[v] = std::sqrt(x[v]);
  }
#endif
}

/// One rank's piece of the volume: its samples (NaN checked), the cubes it owns, and the
/// geometry of surface vertices (bitwise identical on every rank: computed from global indices
/// only).
template <typename Values>
class SampledVolume
{
public:
  using ValueType = typename std::decay<decltype(std::declval<const Values&>()[0])>::type;

  SampledVolume(const CaseTable& table, const Grid& grid, const Ownership& ownership,
    const Values& values, const SurfaceOptions& options)
    : Table(table)
    , GridOf(grid)
    , Owned(ownership)
    , Samples(values)
    , Options(options)
  {
    for (int v = 0; v < 8; ++v)
    {
      this->CornerStride[v] = CornerOffset[v][0] + this->GridOf.StrideY * CornerOffset[v][1] +
        this->GridOf.StrideZ * CornerOffset[v][2];
    }
    const CellBox& box = this->Owned.Mine();
    for (int a = 0; a < 3; ++a)
    {
      // Grid points where the gradient is central on every axis with samples at hand.
      this->CentralLo[a] = std::max(this->GridOf.WholeLo[a], this->GridOf.LocalLo[a]) + 1;
      this->CentralHi[a] = std::min(this->GridOf.WholeHi[a], this->GridOf.LocalHi[a]) - 1;
      // Grid points all of whose surrounding cubes this rank owns (no ports there).
      this->InnerLo[a] = box.Lo[a] + 1;
      this->InnerHi[a] = box.Hi[a];
    }
  }

  const CaseTable& Table;
  const Grid& GridOf;
  const Ownership& Owned;
  const Values& Samples;
  const SurfaceOptions Options; // the isovalue among them

  // ---- state shared by the passes ------------------------------------------------------------

  /// Empty unless a sample was not a number (the message names the grid point).
  std::string Error() const
  {
    std::lock_guard<std::mutex> lock(this->ErrorMutex);
    return this->ErrorText;
  }
  bool Aborted() const { return this->AbortFlag; }
  /// Whether the work should stop: aborted, a NaN met, or a task of Parallel failed.
  bool Stopped() const
  {
    return this->AbortFlag.load(std::memory_order_relaxed) ||
      this->Failed.load(std::memory_order_relaxed) ||
      this->Interrupted.load(std::memory_order_relaxed);
  }
  /// True when a gradient needed a sample beyond this piece that lies inside the volume (the
  /// input lacked its ghost layer); such normals are one-sided.
  bool MissingGhosts() const { return this->GhostsMissing; }

  /// Reports progress (never backwards) and notes an abort. From the calling thread only.
  void Report(double fraction)
  {
    this->Reported = std::max(this->Reported, fraction);
    if (this->Options.Progress && this->Options.Progress(this->Reported))
    {
      this->AbortFlag = true;
    }
  }

  /// Runs task(i) for every i in [0, count), through Options.ParallelFor. An exception thrown
  /// by a task stops the others and is thrown again here (the first one caught).
  template <typename Task>
  void Parallel(std::int64_t count, Task&& task)
  {
    std::exception_ptr failure;
    std::mutex failureMutex;
    auto range = [&](std::int64_t begin, std::int64_t end)
    {
      for (std::int64_t i = begin; i < end && !this->Stopped(); ++i)
      {
        try
        {
          task(i);
        }
        catch (...)
        {
          std::lock_guard<std::mutex> lock(failureMutex);
          if (!failure)
          {
            failure = std::current_exception();
          }
          this->Interrupted = true;
        }
      }
    };
    if (this->Options.ParallelFor && count > 1)
    {
      this->Options.ParallelFor(count, range);
    }
    else
    {
      range(0, count);
    }
    if (failure)
    {
      std::rethrow_exception(failure);
    }
  }

  // ---- samples -------------------------------------------------------------------------------

  /// The sample at grid point (i, j, k) of this piece; a NaN stops the work with an error.
  double Read(int i, int j, int k)
  {
    const double s = static_cast<double>(this->Samples[this->GridOf.LocalIndex(i, j, k)]);
    if (!std::is_integral<ValueType>::value && s != s)
    {
      this->Fail(i, j, k);
    }
    return s;
  }

  /// Reads the 8 corners of cube (i, j, k); false when a sample is NaN.
  RGMC_INLINE bool Evaluate(int i, int j, int k, CubeSamples& st)
  {
    const std::int64_t base = this->GridOf.LocalIndex(i, j, k);
    int code = 0;
    bool degenerate = false;
    for (int v = 0; v < 8; ++v)
    {
      const double s = static_cast<double>(this->Samples[base + this->CornerStride[v]]);
      if (!std::is_integral<ValueType>::value && s != s)
      {
        this->Fail(i + CornerOffset[v][0], j + CornerOffset[v][1], k + CornerOffset[v][2]);
        return false;
      }
      st.S[v] = s;
      code |= (s >= this->Options.Isovalue) << v;
      degenerate |= (s == this->Options.Isovalue);
    }
    st.Case = code;
    st.Degenerate = degenerate;
    return true;
  }

  /// What Describe needs of a surface node's cube: the case growth found and, for a cube with a
  /// degenerate sample, its samples read again (the others need only their case). False when a
  /// sample is NaN, as for Evaluate.
  RGMC_INLINE bool NodeSamples(const SurfaceNode& n, CubeSamples& st)
  {
    st.Case = n.Case;
    st.Degenerate = n.Degenerate;
    return !n.Degenerate || this->Evaluate(n.I, n.J, n.K, st);
  }

  /// Classifies the grid points (i0 + b, j, k), 0 <= b < n <= 64, as Evaluate would: bit b of
  /// `above` is set when the sample is at or above the isovalue, of `notNumber` when it is NaN
  /// (floating-point samples only). Reads each sample once, in memory order.
  RGMC_INLINE void ClassifyRow(
    int i0, int n, int j, int k, std::uint64_t& above, std::uint64_t& notNumber) const
  {
    const std::int64_t base = this->GridOf.LocalIndex(i0, j, k);
    const double c = this->Options.Isovalue;
    if constexpr (std::is_integral<ValueType>::value && sizeof(ValueType) <= 4 &&
      std::is_lvalue_reference<decltype(std::declval<const Values&>()[0])>::value)
    {
      // Integers of up to 32 bits are exact in double: s >= c exactly when s >= ceil(c), which
      // is compared in the samples' own type, a row at a time (the compiler vectorizes it).
      notNumber = 0;
      const double t = std::ceil(c);
      if (!(t <= static_cast<double>(std::numeric_limits<ValueType>::max())))
      {
        above = 0; // c above every sample, or NaN (nothing is >= NaN)
        return;
      }
      const std::uint64_t all = n == 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << n) - 1;
      if (t <= static_cast<double>(std::numeric_limits<ValueType>::min()))
      {
        above = all;
        return;
      }
      const ValueType threshold = static_cast<ValueType>(t);
      const ValueType* row = &this->Samples[base];
      unsigned char at[64];
      for (int b = 0; b < n; ++b)
      {
        at[b] = row[b] >= threshold;
      }
      std::uint64_t a = 0;
      for (int b = 0; b < n; ++b)
      {
        a |= static_cast<std::uint64_t>(at[b]) << b;
      }
      above = a;
      return;
    }
    std::uint64_t a = 0, x = 0;
    for (int b = 0; b < n; ++b)
    {
      const double s = static_cast<double>(this->Samples[base + b]);
      a |= static_cast<std::uint64_t>(s >= c) << b;
      if (!std::is_integral<ValueType>::value)
      {
        x |= static_cast<std::uint64_t>(s != s) << b;
      }
    }
    above = a;
    notNumber = x;
  }

  /// Asks the processor to fetch the samples that extraction reads for cube (i, j, k): its
  /// corners and their neighbours along each axis (the gradients' central differences), rows
  /// j - 1 to j + 2 of planes k and k + 1 and rows j, j + 1 of planes k - 1 and k + 2. Only
  /// where all of them lie in this piece; a hint, it changes no result.
  RGMC_INLINE void PrefetchAround(int i, int j, int k) const
  {
    if constexpr (std::is_lvalue_reference<decltype(std::declval<const Values&>()[0])>::value)
    {
      this->PrefetchSamples(i, j, k);
    }
  }

  /// The surface nodes of cube (i, j, k) with samples `st`.
  RGMC_INLINE void Describe(int i, int j, int k, const CubeSamples& st, CubeSurface& surface) const
  {
    surface.Set(this->Table, this->GridOf, this->Options.Isovalue, i, j, k, st);
  }

  // ---- vertex geometry -----------------------------------------------------------------------

  void ToWorld(const double idx[3], double x[3]) const
  {
    const auto& m = this->Options.IndexToWorld;
    for (int r = 0; r < 3; ++r)
    {
      x[r] = m[r][0] * idx[0] + m[r][1] * idx[1] + m[r][2] * idx[2] + m[r][3];
    }
  }

  /// The vertex on the edge leaving grid point p along `axis`, interpolated from the lower end
  /// as vtkMarchingCubes does (x = p_lo + t (p_hi - p_lo)); returns t.
  double EdgePosition(const int p[3], int axis, double sLo, double sHi, double x[3]) const
  {
    const double t = (this->Options.Isovalue - sLo) / (sHi - sLo);
    double idx[3] = { double(p[0]), double(p[1]), double(p[2]) };
    idx[axis] = idx[axis] + t * 1.0;
    this->ToWorld(idx, x);
    return t;
  }

  /// The world position of a vertex of a cube with samples `st`.
  void Position(const SurfaceVertex& v, const CubeSamples& st, double x[3]) const
  {
    if (v.Axis < 0)
    {
      const double idx[3] = { double(v.Point[0]), double(v.Point[1]), double(v.Point[2]) };
      this->ToWorld(idx, x);
    }
    else
    {
      this->EdgePosition(
        v.Point, v.Axis, st.S[EdgeCorners[v.Edge][0]], st.S[EdgeCorners[v.Edge][1]], x);
    }
  }

  /// Position and normal of a vertex: on a grid point (axis < 0) or on the edge leaving p
  /// along `axis` with end samples sLo, sHi. The normal interpolates the two grid points'
  /// gradients with the vertex's t.
  void PositionAndNormal(
    const int p[3], int axis, double sLo, double sHi, double x[3], float normal[3])
  {
    if (axis < 0)
    {
      const double idx[3] = { double(p[0]), double(p[1]), double(p[2]) };
      this->ToWorld(idx, x);
      if (this->Options.ComputeNormals)
      {
        double g[3];
        this->Gradient(p[0], p[1], p[2], g);
        this->FinishNormal(g, normal);
      }
      return;
    }
    const double t = this->EdgePosition(p, axis, sLo, sHi, x);
    if (this->Options.ComputeNormals)
    {
      double g0[3], g1[3], g[3];
      int q[3] = { p[0], p[1], p[2] };
      this->Gradient(q[0], q[1], q[2], g0);
      ++q[axis];
      this->Gradient(q[0], q[1], q[2], g1);
      for (int a = 0; a < 3; ++a)
      {
        g[a] = g0[a] + t * (g1[a] - g0[a]);
      }
      this->FinishNormal(g, normal);
    }
  }

  /// The most vertices PositionsAndNormals takes at once.
  static constexpr int VertexBatch = 16;

  /// PositionAndNormal of `n` (at most VertexBatch) vertices on the edges leaving p[v] along
  /// axis[v] (-1: on the grid point p[v]), to the bit: the same operations in the same order,
  /// each vertex's samples read first and the arithmetic then done over all of them in one loop,
  /// which the compiler vectorizes (square roots and divisions are correctly rounded in any
  /// width). Vertices on grid points, near the piece's border or next to a NaN sample take
  /// PositionAndNormal itself.
  void PositionsAndNormals(
    const int (*p)[3], const int* axis, int n, double (*x)[3], float (*normal)[3])
  {
    constexpr int B = VertexBatch;
    if (n <= 0)
    {
      return;
    }
    const Grid& g = this->GridOf;
    // The samples, by vertex: the edge's ends and the gradients' central differences at both.
    alignas(64) double lo[B], hi[B], idx[3][B], g0[3][B], g1[3][B];
    bool alone[B];
    int along[B]; // the lane's edge axis (-1: the lane is not computed here)
    for (int v = 0; v < B; ++v)
    {
      alone[v] = true;
      along[v] = -1;
      lo[v] = 0.0;
      hi[v] = 1.0;
      for (int a = 0; a < 3; ++a)
      {
        idx[a][v] = g0[a][v] = g1[a][v] = 0.0;
      }
      if (v >= n || axis[v] < 0)
      {
        continue;
      }
      int q[3] = { p[v][0], p[v][1], p[v][2] };
      ++q[axis[v]];
      if (!this->IsCentral(p[v][0], p[v][1], p[v][2]) || !this->IsCentral(q[0], q[1], q[2]))
      {
        continue;
      }
      const std::int64_t at = g.LocalIndex(p[v][0], p[v][1], p[v][2]);
      const std::int64_t at1 = at + (axis[v] == 0 ? 1 : (axis[v] == 1 ? g.StrideY : g.StrideZ));
      lo[v] = static_cast<double>(this->Samples[at]);
      hi[v] = static_cast<double>(this->Samples[at1]);
      double d0[3], d1[3];
      this->CentralDifferences(at, d0);
      this->CentralDifferences(at1, d1);
      for (int a = 0; a < 3; ++a)
      {
        g0[a][v] = d0[a];
        g1[a][v] = d1[a];
      }
      bool number = true;
      if (!std::is_integral<ValueType>::value)
      {
        number = lo[v] == lo[v] && hi[v] == hi[v];
        for (int a = 0; a < 3; ++a)
        {
          number = number && g0[a][v] == g0[a][v] && g1[a][v] == g1[a][v];
        }
      }
      if (!number)
      {
        continue; // PositionAndNormal names the NaN sample (this lane's arithmetic is dropped)
      }
      for (int a = 0; a < 3; ++a)
      {
        idx[a][v] = static_cast<double>(p[v][a]);
      }
      alone[v] = false;
      along[v] = axis[v];
    }
    // EdgePosition, Gradient's interpolation and FinishNormal, term by term as they compute.
    const double iso = this->Options.Isovalue;
    const auto& m = this->Options.IndexToWorld;
    const auto& r = this->Options.NormalToWorld;
    const bool normals = this->Options.ComputeNormals;
    alignas(64) double t[B], out[3][B], w[3][B];
    for (int v = 0; v < B; ++v)
    {
      t[v] = (iso - lo[v]) / (hi[v] - lo[v]);
    }
    for (int v = 0; v < B; ++v)
    {
      idx[0][v] = along[v] == 0 ? idx[0][v] + t[v] * 1.0 : idx[0][v];
      idx[1][v] = along[v] == 1 ? idx[1][v] + t[v] * 1.0 : idx[1][v];
      idx[2][v] = along[v] == 2 ? idx[2][v] + t[v] * 1.0 : idx[2][v];
    }
    for (int c = 0; c < 3; ++c)
    {
      for (int v = 0; v < B; ++v)
      {
        out[c][v] = m[c][0] * idx[0][v] + m[c][1] * idx[1][v] + m[c][2] * idx[2][v] + m[c][3];
      }
    }
    if (normals)
    {
      for (int a = 0; a < 3; ++a)
      {
        for (int v = 0; v < B; ++v)
        {
          g0[a][v] = g0[a][v] + t[v] * (g1[a][v] - g0[a][v]);
        }
      }
      for (int c = 0; c < 3; ++c)
      {
        for (int v = 0; v < B; ++v)
        {
          w[c][v] = r[c][0] * g0[0][v] + r[c][1] * g0[1][v] + r[c][2] * g0[2][v];
        }
      }
      alignas(64) double len[B];
      for (int v = 0; v < B; ++v)
      {
        len[v] = w[0][v] * w[0][v] + w[1][v] * w[1][v] + w[2][v] * w[2][v];
      }
      SquareRoots<B>(len);
      for (int v = 0; v < B; ++v)
      {
        // len > 0: w / len, as FinishNormal; else w / 1, which is w.
        const double by = len[v] > 0.0 ? len[v] : 1.0;
        w[0][v] = w[0][v] / by;
        w[1][v] = w[1][v] / by;
        w[2][v] = w[2][v] / by;
      }
    }
    for (int v = 0; v < n; ++v)
    {
      if (alone[v])
      {
        double sLo = 0.0, sHi = 0.0;
        if (axis[v] >= 0)
        {
          int q[3] = { p[v][0], p[v][1], p[v][2] };
          ++q[axis[v]];
          sLo = this->Read(p[v][0], p[v][1], p[v][2]);
          sHi = this->Read(q[0], q[1], q[2]);
        }
        normal[v][0] = normal[v][1] = normal[v][2] = 0.0f;
        this->PositionAndNormal(p[v], axis[v], sLo, sHi, x[v], normal[v]);
        continue;
      }
      for (int a = 0; a < 3; ++a)
      {
        x[v][a] = out[a][v];
        normal[v][a] = normals ? static_cast<float>(w[a][v]) : 0.0f;
      }
    }
  }

  /// Whether a cube that contains this vertex lies in the volume but not in this rank's cubes.
  RGMC_INLINE bool IsPort(const int p[3], int axis) const
  {
    if (this->Owned.Overlaps().empty() && p[0] >= this->InnerLo[0] && p[0] <= this->InnerHi[0] &&
      p[1] >= this->InnerLo[1] && p[1] <= this->InnerHi[1] && p[2] >= this->InnerLo[2] &&
      p[2] <= this->InnerHi[2])
    {
      return false; // the 8 cubes around p lie in this rank's box
    }
    bool port = false;
    ForCubesAround(p, axis,
      [&](int i, int j, int k, int)
      { port = port || (this->GridOf.HasCell(i, j, k) && !this->Owned.Owns(i, j, k)); });
    return port;
  }

private:
  RGMC_INLINE void PrefetchSamples(int i, int j, int k) const
  {
    if (i <= this->CentralLo[0] || i >= this->CentralHi[0] || j <= this->CentralLo[1] ||
      j >= this->CentralHi[1] || k <= this->CentralLo[2] || k >= this->CentralHi[2])
    {
      return;
    }
    const auto* at = &this->Samples[this->GridOf.LocalIndex(i, j, k)];
    const std::int64_t sy = this->GridOf.StrideY, sz = this->GridOf.StrideZ;
    for (const std::int64_t row : { -sz, -sz + sy, -sy, std::int64_t(0), sy, 2 * sy, sz - sy, sz,
           sz + sy, sz + 2 * sy, 2 * sz, 2 * sz + sy })
    {
      __builtin_prefetch(at + row - 1);
      __builtin_prefetch(at + row + 2);
    }
  }

  void Fail(int i, int j, int k)
  {
    std::lock_guard<std::mutex> lock(this->ErrorMutex);
    this->Failed = true;
    if (this->ErrorText.empty())
    {
      std::ostringstream msg;
      msg << "the scalar value at grid point (" << i << ", " << j << ", " << k
          << ") is NaN; replace NaN samples before extracting a surface (for example with "
             "the Python Calculator and numpy.nan_to_num)";
      this->ErrorText = msg.str();
    }
  }

  /// Whether the gradient at grid point (i, j, k) is central on every axis with samples at
  /// hand (CentralDifferences applies).
  RGMC_INLINE bool IsCentral(int i, int j, int k) const
  {
    return i >= this->CentralLo[0] && i <= this->CentralHi[0] && j >= this->CentralLo[1] &&
      j <= this->CentralHi[1] && k >= this->CentralLo[2] && k <= this->CentralHi[2];
  }

  /// Negative gradient by central differences at the sample with local index `at` (IsCentral).
  RGMC_INLINE void CentralDifferences(std::int64_t at, double n[3]) const
  {
    const std::int64_t sy = this->GridOf.StrideY, sz = this->GridOf.StrideZ;
    const Values& s = this->Samples;
    n[0] = 0.5 * (static_cast<double>(s[at - 1]) - static_cast<double>(s[at + 1]));
    n[1] = 0.5 * (static_cast<double>(s[at - sy]) - static_cast<double>(s[at + sy]));
    n[2] = 0.5 * (static_cast<double>(s[at - sz]) - static_cast<double>(s[at + sz]));
  }

  /// Negative gradient at a grid point by central differences, one-sided on the volume's
  /// border, as vtkMarchingCubes computes it.
  RGMC_INLINE void Gradient(int i, int j, int k, double n[3])
  {
    const Grid& g = this->GridOf;
    if (this->IsCentral(i, j, k))
    {
      // Central differences on all axes, the samples at hand: the common case.
      this->CentralDifferences(g.LocalIndex(i, j, k), n);
      if (std::is_integral<ValueType>::value || (n[0] == n[0] && n[1] == n[1] && n[2] == n[2]))
      {
        return;
      }
      // A NaN sample: the general path below names it.
    }
    const int p[3] = { i, j, k };
    const double s0 = this->Read(i, j, k);
    for (int a = 0; a < 3; ++a)
    {
      bool hasLow = p[a] > g.WholeLo[a];
      bool hasHigh = p[a] < g.WholeHi[a];
      if (hasLow && p[a] - 1 < g.LocalLo[a])
      {
        hasLow = false;
        this->GhostsMissing = true;
      }
      if (hasHigh && p[a] + 1 > g.LocalHi[a])
      {
        hasHigh = false;
        this->GhostsMissing = true;
      }
      int lo[3] = { i, j, k }, hi[3] = { i, j, k };
      --lo[a];
      ++hi[a];
      if (hasLow && hasHigh)
      {
        n[a] = 0.5 * (this->Read(lo[0], lo[1], lo[2]) - this->Read(hi[0], hi[1], hi[2]));
      }
      else if (hasHigh)
      {
        n[a] = s0 - this->Read(hi[0], hi[1], hi[2]);
      }
      else if (hasLow)
      {
        n[a] = this->Read(lo[0], lo[1], lo[2]) - s0;
      }
      else
      {
        n[a] = 0.0;
      }
    }
  }

  RGMC_INLINE void FinishNormal(const double n[3], float out[3]) const
  {
    const auto& m = this->Options.NormalToWorld;
    double w[3];
    for (int r = 0; r < 3; ++r)
    {
      w[r] = m[r][0] * n[0] + m[r][1] * n[1] + m[r][2] * n[2];
    }
    const double len = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    if (len > 0.0)
    {
      w[0] /= len;
      w[1] /= len;
      w[2] /= len;
    }
    out[0] = static_cast<float>(w[0]);
    out[1] = static_cast<float>(w[1]);
    out[2] = static_cast<float>(w[2]);
  }

  std::int64_t CornerStride[8];
  int CentralLo[3], CentralHi[3];
  int InnerLo[3], InnerHi[3];
  double Reported = 0.0;
  mutable std::mutex ErrorMutex;
  std::string ErrorText;
  std::atomic<bool> Failed{ false };
  std::atomic<bool> AbortFlag{ false };
  std::atomic<bool> Interrupted{ false };
  std::atomic<bool> GhostsMissing{ false };
};

} // namespace rgmc

#endif

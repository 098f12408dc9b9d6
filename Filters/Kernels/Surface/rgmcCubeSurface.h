// What seed search, growth and extraction share about cubes, below all three: the options of a
// surface, the surface nodes of one cube, the cubes around a vertex, and the components found
// on one rank (the samples themselves are rgmcSampledVolume.h's).
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
#include <cstdint>
#include <functional>
#include <limits>
#include <utility>
#include <vector>

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
  /// Called, from the calling thread, when a phase of the work starts (the VTK layer passes the
  /// work/span profile's marks). Empty: nothing.
  std::function<void(const char* phase)> Phase;
};

/// The samples at the 8 corners of a cube (VTK's corner order) and its case.
struct CubeSamples
{
  int Case = 0;
  /// A corner's sample equals the isovalue: vertices may collapse onto grid points.
  bool Degenerate = false;
  double Corners[8];
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
  /// The blocks appended, in order.
  std::size_t NumberOfBlocks() const { return this->Blocks.size(); }
  const std::vector<SurfaceNode>& Block(std::size_t b) const { return this->Blocks[b]; }
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
      if (s.Corners[corner] == isovalue)
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
    this->TotalsByComponent.push_back(totals);
    return this->Sets.Add();
  }
  /// Removes the component added last (nothing joined it).
  void RemoveLast()
  {
    this->TotalsByComponent.pop_back();
    this->Sets.RemoveLast();
  }
  int Size() const { return static_cast<int>(this->TotalsByComponent.size()); }
  int Root(int c) { return this->Sets.Find(c); }
  /// The totals of root component c.
  Totals& TotalsOf(int root) { return this->TotalsByComponent[root]; }
  /// Joins two components (the smaller root stays); true when they were apart.
  bool Join(int a, int b)
  {
    const std::pair<int, int> roots = this->Sets.Unite(a, b);
    if (roots.first == roots.second)
    {
      return false;
    }
    Totals& keep = this->TotalsByComponent[roots.first];
    const Totals& gone = this->TotalsByComponent[roots.second];
    keep.Seeded = keep.Seeded || gone.Seeded;
    keep.Triangles += gone.Triangles;
    keep.MinKey = std::min(keep.MinKey, gone.MinKey);
    return true;
  }

private:
  UnionFind<int> Sets;
  std::vector<Totals> TotalsByComponent; // by component; a root's covers its set
};

} // namespace rgmc

#endif

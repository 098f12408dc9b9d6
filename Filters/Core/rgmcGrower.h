// Region-growing marching cubes on one piece of a volume, without VTK.
//
// The surface graph: a node is one connected group of a cube's triangles (a sheet of the case
// table, or in a cube with a sample equal to the isovalue, a group of the triangles that survive
// collapsing); two nodes are adjacent when they share a vertex key. Growth visits, from a node,
// every other cube that contains one of its vertices (3 cubes around an edge, 7 around a grid
// point), so it reproduces exactly the connectivity of vtkMarchingCubes followed by
// vtkPolyDataConnectivityFilter while touching only cubes the surface passes through.
//
// Two phases. Growth (GrowFromKey, GrowAll, GrowBoundary) only finds the nodes: a breadth-first
// search over a bit per cube, appending each node and its component to a list that is also the
// queue. Extraction (Extract) then makes the triangles slab by slab along z, so that vertices
// shared by neighbouring cubes are found in small per-slab edge tables instead of a hash over
// the whole surface.
//
// Components that meet through a vertex this piece cannot see whole (a cube around it belongs to
// another rank) record that vertex as a port; the VTK layer matches ports across ranks and joins
// the components (vtkRGMarchingCubes).
#ifndef rgmcGrower_h
#define rgmcGrower_h

#include "rgmcBuffer.h"
#include "rgmcCaseTable.h"
#include "rgmcGrid.h"
#include "rgmcKeyMap.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace rgmc
{

struct GrowerParams
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
  /// Called now and then with the fraction done (growth fills the first half, extraction the
  /// second; never decreasing); returns true to abort.
  std::function<bool(double)> Progress;
};

/// One local component: a union-find node with the statistics the global resolution needs.
struct Component
{
  int Parent = 0;
  bool Seeded = false;
  std::int64_t Triangles = 0;
  std::int64_t MinKey = std::numeric_limits<std::int64_t>::max();
};

/// A vertex that other ranks may also have: its key and the component that owns it here.
struct Port
{
  std::int64_t Key;
  int Component;
};

/// The surface vertex a seed selected on one rank: its squared distance, key and position.
struct SeedHit
{
  bool Found = false;
  double Distance2 = std::numeric_limits<double>::infinity();
  std::int64_t Key = std::numeric_limits<std::int64_t>::max();
  double Point[3] = { 0, 0, 0 };
};

/// What one piece produced: vertices (positions, computed in double and stored in the
/// requested precision; normals; keys), triangles over them, and the local component of each
/// triangle. The buffers can be handed over to VTK arrays without copying.
struct LocalMesh
{
  Buffer<float> Points;
  Buffer<double> PointsDouble;
  Buffer<float> Normals;
  Buffer<long long> Keys;
  Buffer<std::int32_t> VertexComponent;
  Buffer<std::int32_t> Triangles;
  Buffer<std::int32_t> TriangleComponent;

  std::int64_t NumberOfPoints() const { return static_cast<std::int64_t>(this->Keys.size()); }
  std::int64_t NumberOfTriangles() const
  {
    return static_cast<std::int64_t>(this->TriangleComponent.size());
  }
  void GetPoint(std::int64_t p, double x[3]) const
  {
    for (int a = 0; a < 3; ++a)
    {
      x[a] = this->PointsDouble.empty() ? this->Points[3 * p + a] : this->PointsDouble[3 * p + a];
    }
  }

  /// Keeps the triangles whose component `keep(component)` accepts and the points they use,
  /// in their order, in place.
  template <typename Keep>
  void Compact(Keep&& keep)
  {
    const std::int64_t numPoints = this->NumberOfPoints();
    std::vector<std::int32_t> newId(static_cast<std::size_t>(numPoints), -1);
    std::size_t kept = 0;
    for (std::size_t t = 0; t < this->TriangleComponent.size(); ++t)
    {
      if (keep(this->TriangleComponent[t]))
      {
        for (int v = 0; v < 3; ++v)
        {
          this->Triangles[3 * kept + v] = this->Triangles[3 * t + v];
          newId[this->Triangles[3 * t + v]] = 0;
        }
        this->TriangleComponent[kept++] = this->TriangleComponent[t];
      }
    }
    this->Triangles.resize_down(3 * kept);
    this->TriangleComponent.resize_down(kept);
    std::int32_t next = 0;
    for (std::int64_t p = 0; p < numPoints; ++p)
    {
      if (newId[p] < 0)
      {
        continue;
      }
      newId[p] = next;
      for (int a = 0; a < 3; ++a)
      {
        if (!this->Points.empty())
        {
          this->Points[3 * next + a] = this->Points[3 * p + a];
        }
        if (!this->PointsDouble.empty())
        {
          this->PointsDouble[3 * next + a] = this->PointsDouble[3 * p + a];
        }
        if (!this->Normals.empty())
        {
          this->Normals[3 * next + a] = this->Normals[3 * p + a];
        }
      }
      this->Keys[next] = this->Keys[p];
      this->VertexComponent[next] = this->VertexComponent[p];
      ++next;
    }
    for (std::int32_t& id : this->Triangles)
    {
      id = newId[id];
    }
    for (auto* buffer : { &this->Points, &this->Normals })
    {
      buffer->resize_down(buffer->empty() ? 0 : 3 * static_cast<std::size_t>(next));
    }
    this->PointsDouble.resize_down(
      this->PointsDouble.empty() ? 0 : 3 * static_cast<std::size_t>(next));
    this->Keys.resize_down(next);
    this->VertexComponent.resize_down(next);
  }
};

template <typename Values>
class Grower
{
public:
  using ValueType = typename std::decay<decltype(std::declval<const Values&>()[0])>::type;

  Grower(const CaseTable& table, const Grid& grid, const Ownership& ownership, const Values& values,
    const GrowerParams& params)
    : Table(table)
    , G(grid)
    , Own(ownership)
    , Vals(values)
    , P(params)
    , C(params.Isovalue)
  {
    const CellBox& box = this->Own.Mine();
    if (!box.Empty())
    {
      // Visited bits in tiles of 32^3 cubes (4 KiB, one page), each tile in words of 4^3 cubes:
      // a small surface touches a few pages, whatever the size of the volume.
      std::int64_t tiles = 1;
      for (int a = 0; a < 3; ++a)
      {
        this->Tiles[a] = ((box.Hi[a] - box.Lo[a] + 1) + TileCubes - 1) / TileCubes;
        tiles *= this->Tiles[a];
      }
      this->Visited.Allocate(static_cast<std::size_t>(tiles * TileWords));
    }
    for (int v = 0; v < 8; ++v)
    {
      this->CornerStride[v] = CornerOffset[v][0] + this->G.StrideY * CornerOffset[v][1] +
        this->G.StrideZ * CornerOffset[v][2];
    }
    for (int e = 0; e < 12; ++e)
    {
      this->EdgeAxisOf[e] = CaseTable::EdgeAxis(e);
    }
    for (int a = 0; a < 3; ++a)
    {
      // Grid points where the gradient is central on every axis with samples at hand.
      this->CentralLo[a] = std::max(this->G.WholeLo[a], this->G.LocalLo[a]) + 1;
      this->CentralHi[a] = std::min(this->G.WholeHi[a], this->G.LocalHi[a]) - 1;
      // Grid points all of whose surrounding cubes this rank owns (no ports there).
      this->InnerLo[a] = box.Lo[a] + 1;
      this->InnerHi[a] = box.Hi[a];
    }
    for (int axis = 0; axis < 3; ++axis)
    {
      for (int du = 0; du < 2; ++du)
      {
        for (int dv = 0; dv < 2; ++dv)
        {
          this->EdgeAt[axis][du][dv] = CaseTable::EdgeAt(axis, du, dv);
        }
      }
    }
  }

  // ---- results -------------------------------------------------------------------------------
  LocalMesh Mesh;
  std::vector<Component> Components;
  std::vector<Port> Ports;

  /// Empty unless a sample was not a number (the message names the grid point).
  const std::string& Error() const { return this->ErrorText; }
  bool Aborted() const { return this->AbortFlag; }
  /// True when a gradient needed a sample beyond this piece that lies inside the volume (the
  /// input lacked its ghost layer); such normals are one-sided.
  bool MissingGhosts() const { return this->GhostsMissing; }
  bool Stopped() const { return this->AbortFlag || !this->ErrorText.empty(); }
  /// How often extraction met a vertex that another component had created. On a single owner
  /// growth follows every adjacency, so this stays 0; across owners it joins components that
  /// meet through cubes of another rank.
  std::int64_t Joins() const { return this->JoinCount; }
  /// Surface nodes found so far.
  std::int64_t NumberOfNodes() const { return static_cast<std::int64_t>(this->Nodes.size()); }

  int Root(int c)
  {
    while (this->Components[c].Parent != c)
    {
      const int grand = this->Components[this->Components[c].Parent].Parent;
      this->Components[c].Parent = grand;
      c = grand;
    }
    return c;
  }

  // ---- seed search ---------------------------------------------------------------------------

  /// The surface vertex nearest to a seed among the cubes this piece owns, ties broken by the
  /// smaller key. `seedIndex` is the seed in continuous index coordinates (inside the volume),
  /// `seedWorld` the same point in world coordinates. Only vertices within `radius` count.
  /// `minStep` is a lower bound of the world length of any index step of length 1 (the
  /// smallest singular value of direction * spacing); it bounds the search shells.
  SeedHit NearestVertex(
    const double seedIndex[3], const double seedWorld[3], double radius, double minStep)
  {
    SeedHit best;
    if (this->Own.OwnsNothing())
    {
      return best;
    }
    const CellBox& box = this->Own.Mine();
    int c[3];
    for (int a = 0; a < 3; ++a)
    {
      c[a] = static_cast<int>(std::floor(seedIndex[a]));
      c[a] = std::max(this->G.WholeLo[a], std::min(this->G.WholeHi[a] - 1, c[a]));
    }
    const double radius2 = radius * radius;
    auto consider = [&](std::int64_t key, const double x[3])
    {
      const double d2 = Distance2(x, seedWorld);
      if (d2 <= radius2 && (d2 < best.Distance2 || (d2 == best.Distance2 && key < best.Key)))
      {
        best.Found = true;
        best.Distance2 = d2;
        best.Key = key;
        std::copy(x, x + 3, best.Point);
      }
    };

    CubeState st;
    Groups groups;
    for (int r = 0;; ++r)
    {
      if (r >= 1)
      {
        // Every vertex of shell r or beyond is at least (r - 1) index steps away.
        const double bound = (r - 1) * minStep;
        if (bound > radius || (best.Found && std::sqrt(best.Distance2) < bound))
        {
          break;
        }
      }
      CellBox shell;
      for (int a = 0; a < 3; ++a)
      {
        shell.Lo[a] = c[a] - r;
        shell.Hi[a] = c[a] + r;
      }
      const CellBox clip = shell.Intersect(box);
      if (!clip.Empty())
      {
        this->ForShell(clip, c, r,
          [&](int i, int j, int k)
          {
            if (this->Stopped() || !this->Own.Owns(i, j, k) || !this->Evaluate(i, j, k, st) ||
              st.Case == 0 || st.Case == 255)
            {
              return;
            }
            double x[3];
            if (!st.Degenerate)
            {
              unsigned edges = this->Table[st.Case].CutEdges;
              while (edges)
              {
                const int e = __builtin_ctz(edges);
                edges &= edges - 1;
                int p[3];
                this->EdgeLowPoint(i, j, k, e, p);
                this->EdgePosition(
                  p, this->EdgeAxisOf[e], st.S[EdgeCorners[e][0]], st.S[EdgeCorners[e][1]], x);
                consider(this->G.EdgeKey(p[0], p[1], p[2], this->EdgeAxisOf[e]), x);
              }
              return;
            }
            this->ComputeGroups(i, j, k, st, groups);
            for (int t = 0; t < groups.NumTriangles; ++t)
            {
              for (int v = 0; v < 3; ++v)
              {
                this->KeyPosition(groups.Keys[t][v], groups.Edges[t][v], st, x);
                consider(groups.Keys[t][v], x);
              }
            }
          });
      }
      if (shell.ContainsBox(box) || this->Stopped())
      {
        break;
      }
    }
    return best;
  }

  // ---- phase 1: growth -----------------------------------------------------------------------

  /// Grows, as a new seeded component, the component that contains the vertex `key`, from the
  /// nodes of this piece that use it. Returns the new component; -1 when no cube this piece owns
  /// has the vertex; -2 when its nodes were already found (by an earlier seed: seeds must be
  /// grown before GrowBoundary).
  int GrowFromKey(std::int64_t key)
  {
    const int comp = this->AddComponent(true);
    const std::size_t before = this->Nodes.size();
    int p[3], axis;
    this->G.Decode(key, p, axis);
    bool seen = false;
    this->VisitAroundKey(key, p, axis, nullptr, comp, &seen);
    if (this->Nodes.size() == before)
    {
      this->Components.pop_back();
      return seen ? -2 : -1;
    }
    this->Drain(before);
    return comp;
  }

  /// Finds every component that has a node in an owned cube (a full scan: the "All" and
  /// "Largest" modes).
  void GrowAll()
  {
    if (!this->Own.OwnsNothing())
    {
      this->Scan(this->Own.Mine(), true);
    }
  }

  /// Grows every component that has a vertex on a face this rank shares with another rank: the
  /// other half of the distributed seeded growth, which lets every rank work at once. Only such
  /// vertices can be shared with another rank's cubes, and they lie on the face's plane of grid
  /// points: on an edge in the plane, or on a sample equal to the isovalue. So the plane is
  /// scanned, one sample per point, instead of the layer of cubes along it.
  void GrowBoundary()
  {
    if (this->Own.OwnsNothing())
    {
      return;
    }
    const CellBox& box = this->Own.Mine();
    const CellBox whole = this->G.WholeCells();
    for (int a = 0; a < 3 && !this->Stopped(); ++a)
    {
      for (int side = 0; side < 2 && !this->Stopped(); ++side)
      {
        const bool neighbourExists = side == 0 ? box.Lo[a] > whole.Lo[a] : box.Hi[a] < whole.Hi[a];
        if (neighbourExists)
        {
          this->GrowFromPlane(a, side == 0 ? box.Lo[a] : box.Hi[a] + 1);
        }
      }
    }
    for (const CellBox& lower : this->Own.Overlaps())
    {
      // Ownership with holes (a reader that ignored piece requests): every cube near them.
      this->Scan(lower.Grown(1).Intersect(box), false);
    }
  }

  // ---- phase 2: extraction -------------------------------------------------------------------

  /// Makes the triangles of every node found, slab by slab along z; fills Mesh, Ports and the
  /// components' triangle counts and smallest keys.
  void Extract()
  {
    if (this->Nodes.empty() || this->Stopped())
    {
      return;
    }
    // The box of the nodes' cubes: the slabs and the edge tables cover only it, so that a small
    // surface costs the same in any volume (no plane-sized tables to touch).
    CellBox& box = this->NodeBox;
    for (int a = 0; a < 3; ++a)
    {
      box.Lo[a] = std::numeric_limits<int>::max();
      box.Hi[a] = std::numeric_limits<int>::min();
    }
    for (const Node& n : this->Nodes)
    {
      const int c[3] = { n.I, n.J, n.K };
      for (int a = 0; a < 3; ++a)
      {
        box.Lo[a] = std::min(box.Lo[a], c[a]);
        box.Hi[a] = std::max(box.Hi[a], c[a]);
      }
    }
    const int numSlabs = box.Hi[2] - box.Lo[2] + 1;

    // Nodes by slab (a counting sort on k).
    std::vector<std::int64_t> start(static_cast<std::size_t>(numSlabs) + 1, 0);
    std::int64_t triangles = 0;
    for (const Node& n : this->Nodes)
    {
      ++start[n.K - box.Lo[2] + 1];
      triangles += this->Table[n.Case].NumTriangles;
    }
    for (int s = 0; s < numSlabs; ++s)
    {
      start[s + 1] += start[s];
    }
    {
      // Reorder the nodes by slab, so that extraction reads them in sequence.
      std::vector<std::int64_t> next(start.begin(), start.end() - 1);
      std::vector<Node> sorted(this->Nodes.size());
      for (const Node& n : this->Nodes)
      {
        sorted[next[n.K - box.Lo[2]]++] = n;
      }
      this->Nodes.swap(sorted);
    }
    // A node emits at most its case's triangles; a closed surface has about half as many
    // vertices as triangles.
    LocalMesh& m = this->Mesh;
    const std::size_t vertices = static_cast<std::size_t>(triangles / 2 + 64);
    m.Triangles.reserve(static_cast<std::size_t>(3 * triangles));
    m.TriangleComponent.reserve(static_cast<std::size_t>(triangles));
    m.Keys.reserve(vertices);
    m.VertexComponent.reserve(vertices);
    if (this->P.DoublePoints)
    {
      m.PointsDouble.reserve(3 * vertices);
    }
    else
    {
      m.Points.reserve(3 * vertices);
    }
    if (this->P.ComputeNormals)
    {
      m.Normals.reserve(3 * vertices);
    }

    // Vertex ids of the edges in the current slab: x and y edges on its bottom and top planes,
    // z edges inside it. The top plane becomes the next slab's bottom.
    this->LayerNx = box.Hi[0] - box.Lo[0] + 2;
    const std::size_t planeSize =
      static_cast<std::size_t>(this->LayerNx) * (box.Hi[1] - box.Lo[1] + 2);
    for (auto& layer : this->Layers)
    {
      layer.Ids.Allocate(planeSize);
      layer.Touched.clear();
    }
    Layer* bottom[2] = { &this->Layers[0], &this->Layers[1] }; // x, y edges at z = k
    Layer* top[2] = { &this->Layers[2], &this->Layers[3] };    // x, y edges at z = k + 1
    Layer* vertical = &this->Layers[4];                        // z edges
    for (int s = 0; s < numSlabs && !this->Stopped(); ++s)
    {
      const int k = box.Lo[2] + s;
      this->Slab[0][0] = bottom[0];
      this->Slab[0][1] = bottom[1];
      this->Slab[1][0] = top[0];
      this->Slab[1][1] = top[1];
      this->Vertical = vertical;
      this->SlabK = k;
      for (std::int64_t n = start[s]; n < start[s + 1] && !this->Stopped(); ++n)
      {
        this->Emit(this->Nodes[n]);
      }
      for (Layer* layer : { bottom[0], bottom[1], vertical })
      {
        layer->Reset();
      }
      std::swap(bottom[0], top[0]);
      std::swap(bottom[1], top[1]);
      if ((s & 15) == 0)
      {
        this->Report(0.5 + 0.5 * s / numSlabs);
      }
    }
  }

private:
  struct CubeState
  {
    int Case = 0;
    bool Degenerate = false;
    double S[8];
  };

  /// The triangles of a cube with a sample equal to the isovalue, after collapsing vertices
  /// onto grid points and dropping the triangles that collapse, grouped by shared keys.
  struct Groups
  {
    int NumTriangles = 0;
    int NumGroups = 0;
    std::int64_t Keys[MaxTriangles][3];
    std::int8_t Edges[MaxTriangles][3];
    int Group[MaxTriangles];
  };

  /// A node found by growth: its cube, case, group and component.
  struct Node
  {
    std::int32_t I, J, K;
    std::int32_t Component;
    std::uint8_t Case;
    std::uint8_t Group;
    bool Degenerate;
  };

  /// Vertex ids + 1 (0: none yet) of one plane of edges, with the entries written so far (to
  /// reset cheaply).
  struct Layer
  {
    ZeroedArray<std::int32_t> Ids;
    std::vector<std::int32_t> Touched;
    void Reset()
    {
      for (std::int32_t t : this->Touched)
      {
        this->Ids[t] = 0;
      }
      this->Touched.clear();
    }
  };

  static double Distance2(const double a[3], const double b[3])
  {
    const double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
    return dx * dx + dy * dy + dz * dz;
  }

  /// Reports progress (never backwards) and notes an abort.
  void Report(double fraction)
  {
    this->Reported = std::max(this->Reported, fraction);
    if (this->P.Progress && this->P.Progress(this->Reported))
    {
      this->AbortFlag = true;
    }
  }

  int AddComponent(bool seeded)
  {
    Component comp;
    comp.Parent = static_cast<int>(this->Components.size());
    comp.Seeded = seeded;
    this->Components.push_back(comp);
    return comp.Parent;
  }

  /// The sample at grid point (i, j, k) of this piece; a NaN stops the growth with an error.
  double Read(int i, int j, int k)
  {
    const double s = static_cast<double>(this->Vals[this->G.LocalIndex(i, j, k)]);
    if (!std::is_integral<ValueType>::value && s != s)
    {
      this->Fail(i, j, k);
    }
    return s;
  }

  void Fail(int i, int j, int k)
  {
    if (this->ErrorText.empty())
    {
      std::ostringstream msg;
      msg << "the scalar value at grid point (" << i << ", " << j << ", " << k
          << ") is NaN; replace NaN samples before extracting a surface (for example with "
             "the Python Calculator and numpy.nan_to_num)";
      this->ErrorText = msg.str();
    }
  }

  /// Reads the 8 corners of cube (i, j, k); false when a sample is NaN.
  bool Evaluate(int i, int j, int k, CubeState& st)
  {
    const std::int64_t base = this->G.LocalIndex(i, j, k);
    int code = 0;
    bool degenerate = false;
    for (int v = 0; v < 8; ++v)
    {
      const double s = static_cast<double>(this->Vals[base + this->CornerStride[v]]);
      if (!std::is_integral<ValueType>::value && s != s)
      {
        this->Fail(i + CornerOffset[v][0], j + CornerOffset[v][1], k + CornerOffset[v][2]);
        return false;
      }
      st.S[v] = s;
      code |= (s >= this->C) << v;
      degenerate |= (s == this->C);
    }
    st.Case = code;
    st.Degenerate = degenerate;
    return true;
  }

  void EdgeLowPoint(int i, int j, int k, int e, int p[3]) const
  {
    const int* o = CornerOffset[EdgeCorners[e][0]];
    p[0] = i + o[0];
    p[1] = j + o[1];
    p[2] = k + o[2];
  }

  /// The key of the vertex on edge e of cube (i, j, k): the grid point's own key when that
  /// end's sample equals the isovalue.
  std::int64_t VertexKeyOf(int i, int j, int k, int e, const CubeState& st) const
  {
    const int lo = EdgeCorners[e][0], hi = EdgeCorners[e][1];
    if (st.S[lo] == this->C)
    {
      return this->G.PointKey(
        i + CornerOffset[lo][0], j + CornerOffset[lo][1], k + CornerOffset[lo][2]);
    }
    if (st.S[hi] == this->C)
    {
      return this->G.PointKey(
        i + CornerOffset[hi][0], j + CornerOffset[hi][1], k + CornerOffset[hi][2]);
    }
    int p[3];
    this->EdgeLowPoint(i, j, k, e, p);
    return this->G.EdgeKey(p[0], p[1], p[2], this->EdgeAxisOf[e]);
  }

  void ComputeGroups(int i, int j, int k, const CubeState& st, Groups& g) const
  {
    const CaseEntry& ce = this->Table[st.Case];
    g.NumTriangles = 0;
    for (int t = 0; t < ce.NumTriangles; ++t)
    {
      std::int64_t keys[3];
      for (int v = 0; v < 3; ++v)
      {
        keys[v] = this->VertexKeyOf(i, j, k, ce.Triangles[t][v], st);
      }
      if (keys[0] == keys[1] || keys[0] == keys[2] || keys[1] == keys[2])
      {
        continue; // collapsed onto a grid point: vtkMarchingCubes drops it too
      }
      for (int v = 0; v < 3; ++v)
      {
        g.Keys[g.NumTriangles][v] = keys[v];
        g.Edges[g.NumTriangles][v] = ce.Triangles[t][v];
      }
      ++g.NumTriangles;
    }
    int parent[MaxTriangles];
    for (int t = 0; t < g.NumTriangles; ++t)
    {
      parent[t] = t;
    }
    auto find = [&parent](int x)
    {
      while (parent[x] != x)
      {
        x = parent[x];
      }
      return x;
    };
    for (int a = 0; a < g.NumTriangles; ++a)
    {
      for (int b = a + 1; b < g.NumTriangles; ++b)
      {
        for (int va = 0; va < 3; ++va)
        {
          for (int vb = 0; vb < 3; ++vb)
          {
            if (g.Keys[a][va] == g.Keys[b][vb])
            {
              parent[find(a)] = find(b);
            }
          }
        }
      }
    }
    int groupOfRoot[MaxTriangles];
    std::fill(groupOfRoot, groupOfRoot + MaxTriangles, -1);
    g.NumGroups = 0;
    for (int t = 0; t < g.NumTriangles; ++t)
    {
      const int root = find(t);
      if (groupOfRoot[root] < 0)
      {
        groupOfRoot[root] = g.NumGroups++;
      }
      g.Group[t] = groupOfRoot[root];
    }
  }

  static bool GroupHasKey(const Groups& g, int group, std::int64_t key)
  {
    for (int t = 0; t < g.NumTriangles; ++t)
    {
      if (g.Group[t] == group &&
        (g.Keys[t][0] == key || g.Keys[t][1] == key || g.Keys[t][2] == key))
      {
        return true;
      }
    }
    return false;
  }

  // ---- geometry (bitwise identical on every rank: computed from global indices only) --------

  void ToWorld(const double idx[3], double x[3]) const
  {
    const auto& m = this->P.IndexToWorld;
    for (int r = 0; r < 3; ++r)
    {
      x[r] = m[r][0] * idx[0] + m[r][1] * idx[1] + m[r][2] * idx[2] + m[r][3];
    }
  }

  /// The vertex on the edge leaving grid point p along `axis`, interpolated from the lower end
  /// as vtkMarchingCubes does (x = p_lo + t (p_hi - p_lo)).
  double EdgePosition(const int p[3], int axis, double sLo, double sHi, double x[3]) const
  {
    const double t = (this->C - sLo) / (sHi - sLo);
    double idx[3] = { double(p[0]), double(p[1]), double(p[2]) };
    idx[axis] = idx[axis] + t * 1.0;
    this->ToWorld(idx, x);
    return t;
  }

  void KeyPosition(std::int64_t key, int e, const CubeState& st, double x[3]) const
  {
    int p[3], axis;
    this->G.Decode(key, p, axis);
    if (axis < 0)
    {
      const double idx[3] = { double(p[0]), double(p[1]), double(p[2]) };
      this->ToWorld(idx, x);
    }
    else
    {
      this->EdgePosition(p, axis, st.S[EdgeCorners[e][0]], st.S[EdgeCorners[e][1]], x);
    }
  }

  /// Negative gradient at a grid point by central differences, one-sided on the volume's
  /// border, as vtkMarchingCubes computes it.
  void Gradient(int i, int j, int k, double n[3])
  {
    if (i >= this->CentralLo[0] && i <= this->CentralHi[0] && j >= this->CentralLo[1] &&
      j <= this->CentralHi[1] && k >= this->CentralLo[2] && k <= this->CentralHi[2])
    {
      // Central differences on all axes, the samples at hand: the common case.
      const std::int64_t at = this->G.LocalIndex(i, j, k);
      const std::int64_t sy = this->G.StrideY, sz = this->G.StrideZ;
      n[0] =
        0.5 * (static_cast<double>(this->Vals[at - 1]) - static_cast<double>(this->Vals[at + 1]));
      n[1] =
        0.5 * (static_cast<double>(this->Vals[at - sy]) - static_cast<double>(this->Vals[at + sy]));
      n[2] =
        0.5 * (static_cast<double>(this->Vals[at - sz]) - static_cast<double>(this->Vals[at + sz]));
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
      bool hasLow = p[a] > this->G.WholeLo[a];
      bool hasHigh = p[a] < this->G.WholeHi[a];
      if (hasLow && p[a] - 1 < this->G.LocalLo[a])
      {
        hasLow = false;
        this->GhostsMissing = true;
      }
      if (hasHigh && p[a] + 1 > this->G.LocalHi[a])
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

  void FinishNormal(const double n[3], float out[3]) const
  {
    const auto& m = this->P.NormalToWorld;
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

  // ---- phase 1 internals ---------------------------------------------------------------------

  /// The bit of an owned cube: tile (32^3 cubes), then word (4^3 cubes) in the tile, then cube.
  std::int64_t BoxIndex(int i, int j, int k) const
  {
    const CellBox& b = this->Own.Mine();
    const int x = i - b.Lo[0], y = j - b.Lo[1], z = k - b.Lo[2];
    const std::int64_t tile =
      (x >> 5) + this->Tiles[0] * ((y >> 5) + std::int64_t(this->Tiles[1]) * (z >> 5));
    const int word = ((x >> 2) & 7) + 8 * (((y >> 2) & 7) + 8 * ((z >> 2) & 7));
    const int bit = (x & 3) + 4 * ((y & 3) + 4 * (z & 3));
    return (tile * TileWords + word) * 64 + bit;
  }

  bool Done(std::int64_t bit) const { return (this->Visited[bit >> 6] >> (bit & 63)) & 1u; }
  void SetDone(std::int64_t bit) { this->Visited[bit >> 6] |= std::uint64_t(1) << (bit & 63); }

  bool GroupVisited(std::int64_t bit, int group, int numGroups) const
  {
    if (this->Done(bit))
    {
      return true;
    }
    if (numGroups == 1)
    {
      return false;
    }
    const std::int32_t* mask = this->MultiGroup.Find(bit);
    return mask && ((*mask >> group) & 1);
  }

  /// Marks node (cube, group) found and appends it to the node list (the queue). Cubes with one
  /// node use only the bit per cube; cubes with several remember which nodes were taken.
  void Mark(
    int i, int j, int k, std::int64_t bit, const CubeState& st, int group, int numGroups, int comp)
  {
    if (numGroups == 1)
    {
      this->SetDone(bit);
    }
    else
    {
      bool inserted;
      std::int32_t& mask = this->MultiGroup.FindOrInsert(bit, 0, inserted);
      if ((mask >> group) & 1)
      {
        return;
      }
      mask |= 1 << group;
      if (mask == (1 << numGroups) - 1)
      {
        this->SetDone(bit);
      }
    }
    this->Nodes.push_back(Node{ i, j, k, comp, static_cast<std::uint8_t>(st.Case),
      static_cast<std::uint8_t>(group), st.Degenerate });
  }

  /// Marks the nodes of cube (i, j, k) that use vertex `key`. `edge` is the cube's local edge
  /// carrying the vertex (ignored for a grid-point key). `seen` is set when such a node was
  /// found before.
  void Visit(int i, int j, int k, std::int64_t key, int edge, int comp, bool* seen)
  {
    if (!this->Own.Owns(i, j, k)) // owned cubes lie inside the volume
    {
      return;
    }
    const std::int64_t bit = this->BoxIndex(i, j, k);
    if (this->Done(bit) && !seen)
    {
      return;
    }
    CubeState st;
    if (!this->Evaluate(i, j, k, st))
    {
      return;
    }
    if (!st.Degenerate)
    {
      const CaseEntry& ce = this->Table[st.Case];
      const int sheet = edge >= 0 ? ce.EdgeSheet[edge] : -1;
      if (sheet >= 0)
      {
        if (this->GroupVisited(bit, sheet, ce.NumSheets))
        {
          if (seen)
          {
            *seen = true;
          }
          return;
        }
        this->Mark(i, j, k, bit, st, sheet, ce.NumSheets, comp);
      }
      return;
    }
    Groups g;
    this->ComputeGroups(i, j, k, st, g);
    for (int group = 0; group < g.NumGroups; ++group)
    {
      if (!GroupHasKey(g, group, key))
      {
        continue;
      }
      if (this->GroupVisited(bit, group, g.NumGroups))
      {
        if (seen)
        {
          *seen = true;
        }
        continue;
      }
      this->Mark(i, j, k, bit, st, group, g.NumGroups, comp);
    }
  }

  /// Visits every cube that contains the vertex `key` (at grid point p; `axis` < 0 for a
  /// grid-point vertex), except `from`.
  void VisitAroundKey(
    std::int64_t key, const int p[3], int axis, const int* from, int comp, bool* seen = nullptr)
  {
    for (int d = 0; d < 8; ++d)
    {
      const int o[3] = { d & 1, (d >> 1) & 1, (d >> 2) & 1 };
      if (axis >= 0 && o[axis] != 0)
      {
        continue; // an edge lies in the 4 cubes around it, not 8
      }
      const int i = p[0] - o[0], j = p[1] - o[1], k = p[2] - o[2];
      if (from && i == from[0] && j == from[1] && k == from[2])
      {
        continue;
      }
      int edge = -1;
      if (axis >= 0)
      {
        const int u = axis == 0 ? 1 : 0;
        const int v = axis == 2 ? 1 : 2;
        edge = this->EdgeAt[axis][o[u]][o[v]];
      }
      this->Visit(i, j, k, key, edge, comp, seen);
    }
  }

  /// Visits the neighbours of one node: every other cube that has one of its vertices.
  void Expand(const Node& n)
  {
    const int from[3] = { n.I, n.J, n.K };
    if (!n.Degenerate)
    {
      unsigned edges = this->Table[n.Case].SheetEdges[n.Group];
      while (edges)
      {
        const int e = __builtin_ctz(edges);
        edges &= edges - 1;
        int p[3];
        this->EdgeLowPoint(n.I, n.J, n.K, e, p);
        const int axis = this->EdgeAxisOf[e];
        this->VisitAroundKey(this->G.EdgeKey(p[0], p[1], p[2], axis), p, axis, from, n.Component);
      }
      return;
    }
    CubeState st;
    if (!this->Evaluate(n.I, n.J, n.K, st))
    {
      return;
    }
    Groups g;
    this->ComputeGroups(n.I, n.J, n.K, st, g);
    std::int64_t keys[3 * MaxTriangles];
    int numKeys = 0;
    for (int t = 0; t < g.NumTriangles; ++t)
    {
      for (int v = 0; v < 3 && g.Group[t] == n.Group; ++v)
      {
        if (std::find(keys, keys + numKeys, g.Keys[t][v]) == keys + numKeys)
        {
          keys[numKeys++] = g.Keys[t][v];
        }
      }
    }
    for (int s = 0; s < numKeys; ++s)
    {
      int p[3], axis;
      this->G.Decode(keys[s], p, axis);
      this->VisitAroundKey(keys[s], p, axis, from, n.Component);
    }
  }

  /// Expands the queued nodes from `head` on, until none is left.
  void Drain(std::size_t head)
  {
    for (; head < this->Nodes.size() && !this->Stopped(); ++head)
    {
      const Node n = this->Nodes[head];
      this->Expand(n);
      if ((++this->NodesExpanded & 0x3fff) == 0)
      {
        // The surface's size is unknown while it grows: an estimate that approaches 1.
        const double done = static_cast<double>(this->NodesExpanded);
        this->Report(0.5 * done / (done + 4.0 * (this->Nodes.size() - head) + (1 << 20)));
      }
    }
  }

  /// Grows a new component from the nodes that use vertex `key`, unless they were found.
  void GrowUnseeded(std::int64_t key, const int p[3], int axis)
  {
    const std::size_t head = this->Nodes.size();
    const int comp = this->AddComponent(false);
    this->VisitAroundKey(key, p, axis, nullptr, comp);
    if (this->Nodes.size() == head)
    {
      this->Components.pop_back();
      return;
    }
    this->Drain(head);
  }

  /// Grows from every vertex on the plane of grid points p[axis] = `plane` of this rank's box.
  void GrowFromPlane(int axis, int plane)
  {
    const CellBox& box = this->Own.Mine();
    const int u = axis == 0 ? 1 : 0, v = axis == 2 ? 1 : 2;
    int p[3];
    p[axis] = plane;
    for (p[v] = box.Lo[v]; p[v] <= box.Hi[v] + 1 && !this->Stopped(); ++p[v])
    {
      for (p[u] = box.Lo[u]; p[u] <= box.Hi[u] + 1 && !this->Stopped(); ++p[u])
      {
        const double s = this->Read(p[0], p[1], p[2]);
        if (s == this->C)
        {
          this->GrowUnseeded(this->G.PointKey(p[0], p[1], p[2]), p, -1);
        }
        for (const int along : { u, v })
        {
          if (p[along] > box.Hi[along])
          {
            continue;
          }
          int q[3] = { p[0], p[1], p[2] };
          ++q[along];
          const double t = this->Read(q[0], q[1], q[2]);
          if ((s >= this->C) != (t >= this->C) && s != this->C && t != this->C)
          {
            this->GrowUnseeded(this->G.EdgeKey(p[0], p[1], p[2], along), p, along);
          }
        }
      }
    }
  }

  /// Starts a new component from every unfound node of the owned cubes in `region`.
  void Scan(const CellBox& region, bool reportProgress)
  {
    CubeState st;
    Groups g;
    for (int k = region.Lo[2]; k <= region.Hi[2] && !this->Stopped(); ++k)
    {
      if (reportProgress)
      {
        this->Report(0.5 * (k - region.Lo[2]) / (region.Hi[2] - region.Lo[2] + 1));
      }
      for (int j = region.Lo[1]; j <= region.Hi[1]; ++j)
      {
        for (int i = region.Lo[0]; i <= region.Hi[0] && !this->Stopped(); ++i)
        {
          if (!this->Own.Owns(i, j, k))
          {
            continue;
          }
          const std::int64_t bit = this->BoxIndex(i, j, k);
          if (this->Done(bit) || !this->Evaluate(i, j, k, st) || st.Case == 0 || st.Case == 255)
          {
            continue;
          }
          int numGroups = this->Table[st.Case].NumSheets;
          if (st.Degenerate)
          {
            this->ComputeGroups(i, j, k, st, g);
            numGroups = g.NumGroups;
          }
          for (int group = 0; group < numGroups; ++group)
          {
            if (!this->GroupVisited(bit, group, numGroups))
            {
              const std::size_t head = this->Nodes.size();
              this->Mark(i, j, k, bit, st, group, numGroups, this->AddComponent(false));
              this->Drain(head);
            }
          }
        }
      }
    }
  }

  /// Calls f(i, j, k) for the cubes of `clip` at Chebyshev distance exactly r from cube c.
  template <typename F>
  void ForShell(const CellBox& clip, const int c[3], int r, F&& f)
  {
    for (int k = clip.Lo[2]; k <= clip.Hi[2]; ++k)
    {
      for (int j = clip.Lo[1]; j <= clip.Hi[1]; ++j)
      {
        if (std::abs(k - c[2]) == r || std::abs(j - c[1]) == r)
        {
          for (int i = clip.Lo[0]; i <= clip.Hi[0]; ++i)
          {
            f(i, j, k);
          }
        }
        else
        {
          if (c[0] - r >= clip.Lo[0])
          {
            f(c[0] - r, j, k);
          }
          if (r > 0 && c[0] + r <= clip.Hi[0])
          {
            f(c[0] + r, j, k);
          }
        }
      }
    }
  }

  // ---- phase 2 internals ---------------------------------------------------------------------

  /// Creates the output point of a vertex: position, normal, component, port check.
  std::int32_t NewVertex(
    std::int64_t key, const int p[3], int axis, double sLo, double sHi, int comp)
  {
    double x[3];
    float normal[3] = { 0, 0, 0 };
    if (axis < 0)
    {
      const double idx[3] = { double(p[0]), double(p[1]), double(p[2]) };
      this->ToWorld(idx, x);
      if (this->P.ComputeNormals)
      {
        double g[3];
        this->Gradient(p[0], p[1], p[2], g);
        this->FinishNormal(g, normal);
      }
    }
    else
    {
      const double t = this->EdgePosition(p, axis, sLo, sHi, x);
      if (this->P.ComputeNormals)
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
    LocalMesh& m = this->Mesh;
    // Vertex ids are 32-bit within a rank (slots hold id + 1).
    if (m.Keys.size() >= static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max() - 1))
    {
      throw std::length_error("more than 2147483646 surface vertices in one piece");
    }
    const std::int32_t id = static_cast<std::int32_t>(m.Keys.size());
    if (this->P.DoublePoints)
    {
      m.PointsDouble.append(x, 3);
    }
    else
    {
      const float xf[3] = { static_cast<float>(x[0]), static_cast<float>(x[1]),
        static_cast<float>(x[2]) };
      m.Points.append(xf, 3);
    }
    if (this->P.ComputeNormals)
    {
      m.Normals.append(normal, 3);
    }
    m.Keys.push_back(key);
    m.VertexComponent.push_back(comp);
    Component& c = this->Components[this->Root(comp)];
    c.MinKey = std::min(c.MinKey, key);
    if (this->IsPort(p, axis))
    {
      this->Ports.push_back(Port{ key, comp });
    }
    return id;
  }

  /// The output point of a vertex met by component `comp`, whose id + 1 is kept in `slot` (0:
  /// none yet): made on first use; met again by another component, it joins the two.
  std::int32_t UseVertex(std::int32_t& slot, std::int64_t key, const int p[3], int axis, double sLo,
    double sHi, int comp, Layer* layer, std::int32_t index)
  {
    if (slot > 0)
    {
      this->Join(this->Mesh.VertexComponent[slot - 1], comp);
      return slot - 1;
    }
    const std::int32_t id = this->NewVertex(key, p, axis, sLo, sHi, comp);
    slot = id + 1;
    if (layer)
    {
      layer->Touched.push_back(index);
    }
    return id;
  }

  /// The output point of the vertex on edge e of the current node's cube (not collapsed).
  std::int32_t EdgeVertex(const Node& n, int e, const CubeState& st)
  {
    int p[3];
    this->EdgeLowPoint(n.I, n.J, n.K, e, p);
    const int axis = this->EdgeAxisOf[e];
    const CellBox& box = this->NodeBox;
    const std::int32_t index =
      static_cast<std::int32_t>((p[0] - box.Lo[0]) + this->LayerNx * (p[1] - box.Lo[1]));
    Layer* layer = axis == 2 ? this->Vertical : this->Slab[p[2] - this->SlabK][axis];
    return this->UseVertex(layer->Ids[index], this->G.EdgeKey(p[0], p[1], p[2], axis), p, axis,
      st.S[EdgeCorners[e][0]], st.S[EdgeCorners[e][1]], n.Component, layer, index);
  }

  /// The output point of a vertex of a degenerate cube: an edge vertex, or a grid point.
  std::int32_t KeyVertex(const Node& n, std::int64_t key, int e, const CubeState& st)
  {
    if (!this->G.IsPointKey(key))
    {
      return this->EdgeVertex(n, e, st);
    }
    int p[3], axis;
    this->G.Decode(key, p, axis);
    bool inserted;
    std::int32_t& slot = this->PointVertices.FindOrInsert(key, 0, inserted);
    return this->UseVertex(slot, key, p, -1, 0.0, 0.0, n.Component, nullptr, 0);
  }

  /// Whether a cube that contains this vertex lies in the volume but not in this rank's cubes.
  bool IsPort(const int p[3], int axis) const
  {
    if (this->Own.Overlaps().empty() && p[0] >= this->InnerLo[0] && p[0] <= this->InnerHi[0] &&
      p[1] >= this->InnerLo[1] && p[1] <= this->InnerHi[1] && p[2] >= this->InnerLo[2] &&
      p[2] <= this->InnerHi[2])
    {
      return false; // the 8 cubes around p lie in this rank's box
    }
    for (int d = 0; d < 8; ++d)
    {
      const int o[3] = { d & 1, (d >> 1) & 1, (d >> 2) & 1 };
      if (axis >= 0 && o[axis] != 0)
      {
        continue;
      }
      const int i = p[0] - o[0], j = p[1] - o[1], k = p[2] - o[2];
      if (this->G.HasCell(i, j, k) && !this->Own.Owns(i, j, k))
      {
        return true;
      }
    }
    return false;
  }

  void Join(int a, int b)
  {
    a = this->Root(a);
    b = this->Root(b);
    if (a == b)
    {
      return;
    }
    ++this->JoinCount;
    if (b < a)
    {
      std::swap(a, b);
    }
    Component& keep = this->Components[a];
    const Component& gone = this->Components[b];
    keep.Seeded = keep.Seeded || gone.Seeded;
    keep.Triangles += gone.Triangles;
    keep.MinKey = std::min(keep.MinKey, gone.MinKey);
    this->Components[b].Parent = a;
  }

  void AddTriangle(const std::int32_t ids[3], int comp)
  {
    LocalMesh& m = this->Mesh;
    m.Triangles.append(ids, 3);
    m.TriangleComponent.push_back(comp);
    ++this->Components[this->Root(comp)].Triangles;
  }

  /// Emits the triangles of one node.
  void Emit(const Node& n)
  {
    CubeState st;
    if (!this->Evaluate(n.I, n.J, n.K, st))
    {
      return;
    }
    if (!n.Degenerate)
    {
      const CaseEntry& ce = this->Table[n.Case];
      for (int t = 0; t < ce.NumTriangles; ++t)
      {
        if (ce.TriangleSheet[t] == n.Group)
        {
          std::int32_t ids[3];
          for (int v = 0; v < 3; ++v)
          {
            ids[v] = this->EdgeVertex(n, ce.Triangles[t][v], st);
          }
          this->AddTriangle(ids, n.Component);
        }
      }
      return;
    }
    Groups g;
    this->ComputeGroups(n.I, n.J, n.K, st, g);
    for (int t = 0; t < g.NumTriangles; ++t)
    {
      if (g.Group[t] == n.Group)
      {
        std::int32_t ids[3];
        for (int v = 0; v < 3; ++v)
        {
          ids[v] = this->KeyVertex(n, g.Keys[t][v], g.Edges[t][v], st);
        }
        this->AddTriangle(ids, n.Component);
      }
    }
  }

  const CaseTable& Table;
  const Grid& G;
  const Ownership& Own;
  const Values& Vals;
  GrowerParams P;
  const double C;

  std::int64_t CornerStride[8];
  int EdgeAxisOf[12];
  int EdgeAt[3][2][2];
  int CentralLo[3], CentralHi[3];
  int InnerLo[3], InnerHi[3];

  static constexpr int TileCubes = 32;  // cubes along each axis of a tile of visited bits
  static constexpr int TileWords = 512; // 64-bit words in a tile
  std::int64_t Tiles[3] = { 0, 0, 0 };  // tiles along each axis of the owned box
  ZeroedArray<std::uint64_t> Visited;   // a bit per owned cube: its nodes were all found
  KeyMap MultiGroup{ 64 };
  std::vector<Node> Nodes;
  std::int64_t NodesExpanded = 0;

  Layer Layers[5];
  Layer* Slab[2][2] = { { nullptr, nullptr }, { nullptr, nullptr } };
  Layer* Vertical = nullptr;
  int SlabK = 0;
  std::int64_t LayerNx = 0;
  CellBox NodeBox; // the cubes of the nodes, during extraction
  KeyMap PointVertices{ 64 };

  std::int64_t JoinCount = 0;
  double Reported = 0.0;
  std::string ErrorText;
  bool AbortFlag = false;
  bool GhostsMissing = false;
};

} // namespace rgmc

#endif

// Growth: finds the surface nodes of the components that one rank extracts, without making any
// triangle. A breadth-first search over the surface graph from a node visits every other cube
// that contains one of the node's vertices (3 cubes around an edge, 7 around a grid point), so
// it reproduces exactly the connectivity of vtkMarchingCubes followed by
// vtkPolyDataConnectivityFilter while touching only cubes the surface passes through. A bit
// per owned cube (in pages of 32^3 cubes) says that its nodes were all found; the list of nodes
// found is also the search's queue.
#ifndef rgmcGrowth_h
#define rgmcGrowth_h

#include "rgmcBuffer.h"
#include "rgmcCubeSurface.h"
#include "rgmcKeyMap.h"

#include <cstdint>
#include <vector>

namespace rgmc
{

template <typename Values>
class SurfaceGrowth
{
public:
  SurfaceGrowth(SampledVolume<Values>& volume, ComponentSet& components)
    : Volume(volume)
    , Components(components)
  {
    const CellBox& box = this->Volume.Owned.Mine();
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
  }

  /// The nodes found, in the order found.
  std::vector<SurfaceNode>& Nodes() { return this->Found; }

  /// Grows, as a new seeded component, the component that contains the vertex `key`, from the
  /// nodes of this piece that use it. Returns the new component; -1 when no cube this piece owns
  /// has the vertex; -2 when its nodes were already found (by an earlier seed: seeds must be
  /// grown before GrowBoundary).
  int GrowFromKey(std::int64_t key)
  {
    const int comp = this->Components.Add(true);
    const std::size_t before = this->Found.size();
    int p[3], axis;
    this->Volume.GridOf.Decode(key, p, axis);
    bool seen = false;
    this->VisitAround(key, p, axis, nullptr, comp, &seen);
    if (this->Found.size() == before)
    {
      this->Components.RemoveLast();
      return seen ? -2 : -1;
    }
    this->ExpandFrom(before);
    return comp;
  }

  /// Finds every component that has a node in an owned cube (a full scan: the "All" and
  /// "Largest" modes).
  void GrowAll()
  {
    if (!this->Volume.Owned.OwnsNothing())
    {
      this->Scan(this->Volume.Owned.Mine(), true);
    }
  }

  /// Grows every component that has a vertex on a face this rank shares with another rank: the
  /// other half of the distributed seeded growth, which lets every rank work at once. Only such
  /// vertices can be shared with another rank's cubes, and they lie on the face's plane of grid
  /// points: on an edge in the plane, or on a sample equal to the isovalue. So the plane is
  /// scanned, one sample per point, instead of the layer of cubes along it.
  void GrowBoundary()
  {
    const Ownership& own = this->Volume.Owned;
    if (own.OwnsNothing())
    {
      return;
    }
    const CellBox& box = own.Mine();
    const CellBox whole = this->Volume.GridOf.WholeCells();
    for (int a = 0; a < 3 && !this->Volume.Stopped(); ++a)
    {
      for (int side = 0; side < 2 && !this->Volume.Stopped(); ++side)
      {
        const bool neighbourExists = side == 0 ? box.Lo[a] > whole.Lo[a] : box.Hi[a] < whole.Hi[a];
        if (neighbourExists)
        {
          this->GrowFromPlane(a, side == 0 ? box.Lo[a] : box.Hi[a] + 1);
        }
      }
    }
    for (const CellBox& lower : own.Overlaps())
    {
      // Ownership with holes (a reader that ignored piece requests): every cube near them.
      this->Scan(lower.Grown(1).Intersect(box), false);
    }
  }

private:
  /// The bit of an owned cube: tile (32^3 cubes), then word (4^3 cubes) in the tile, then cube.
  std::int64_t CubeBit(int i, int j, int k) const
  {
    const CellBox& b = this->Volume.Owned.Mine();
    const int x = i - b.Lo[0], y = j - b.Lo[1], z = k - b.Lo[2];
    const std::int64_t tile =
      (x >> 5) + this->Tiles[0] * ((y >> 5) + std::int64_t(this->Tiles[1]) * (z >> 5));
    const int word = ((x >> 2) & 7) + 8 * (((y >> 2) & 7) + 8 * ((z >> 2) & 7));
    const int bit = (x & 3) + 4 * ((y & 3) + 4 * (z & 3));
    return (tile * TileWords + word) * 64 + bit;
  }

  bool AllFound(std::int64_t bit) const { return (this->Visited[bit >> 6] >> (bit & 63)) & 1u; }
  void SetAllFound(std::int64_t bit) { this->Visited[bit >> 6] |= std::uint64_t(1) << (bit & 63); }

  bool NodeFound(std::int64_t bit, int node, int numNodes) const
  {
    if (this->AllFound(bit))
    {
      return true;
    }
    if (numNodes == 1)
    {
      return false;
    }
    const std::int32_t* mask = this->FoundNodesOfCube.Find(bit);
    return mask && ((*mask >> node) & 1);
  }

  /// Records node `node` of cube (i, j, k) found and appends it to the list (the queue). Cubes
  /// with one node use only the bit per cube; cubes with several remember which were found.
  void Record(
    int i, int j, int k, std::int64_t bit, const CubeSamples& st, int node, int numNodes, int comp)
  {
    if (numNodes == 1)
    {
      this->SetAllFound(bit);
    }
    else
    {
      bool inserted;
      std::int32_t& mask = this->FoundNodesOfCube.FindOrInsert(bit, 0, inserted);
      if ((mask >> node) & 1)
      {
        return;
      }
      mask |= 1 << node;
      if (mask == (1 << numNodes) - 1)
      {
        this->SetAllFound(bit);
      }
    }
    this->Found.push_back(SurfaceNode{ i, j, k, comp, static_cast<std::uint8_t>(st.Case),
      static_cast<std::uint8_t>(node), st.Degenerate });
  }

  /// Records the nodes of cube (i, j, k) that use vertex `key` (on the cube's edge `edge`; -1
  /// for a grid-point key). `seen` is set when such a node was found before.
  void Visit(int i, int j, int k, std::int64_t key, int edge, int comp, bool* seen)
  {
    if (!this->Volume.Owned.Owns(i, j, k)) // owned cubes lie inside the volume
    {
      return;
    }
    const std::int64_t bit = this->CubeBit(i, j, k);
    if (this->AllFound(bit) && !seen)
    {
      return;
    }
    CubeSamples st;
    if (!this->Volume.Evaluate(i, j, k, st))
    {
      return;
    }
    CubeSurface surface;
    this->Volume.Describe(i, j, k, st, surface);
    const int numNodes = surface.NumberOfNodes();
    unsigned nodes = surface.NodesWithVertex(key, edge);
    while (nodes)
    {
      const int node = __builtin_ctz(nodes);
      nodes &= nodes - 1;
      if (this->NodeFound(bit, node, numNodes))
      {
        if (seen)
        {
          *seen = true;
        }
        continue;
      }
      this->Record(i, j, k, bit, st, node, numNodes, comp);
    }
  }

  /// Visits every cube that contains the vertex `key` (at grid point p; `axis` < 0 for a
  /// grid-point vertex), except `from`.
  void VisitAround(
    std::int64_t key, const int p[3], int axis, const int* from, int comp, bool* seen = nullptr)
  {
    ForCubesAround(p, axis,
      [&](int i, int j, int k, int edge)
      {
        if (!from || i != from[0] || j != from[1] || k != from[2])
        {
          this->Visit(i, j, k, key, edge, comp, seen);
        }
      });
  }

  /// Visits the neighbours of one node: every other cube that has one of its vertices.
  void Expand(const SurfaceNode& n)
  {
    const int from[3] = { n.I, n.J, n.K };
    CubeSamples st;
    if (n.Degenerate && !this->Volume.Evaluate(n.I, n.J, n.K, st))
    {
      return;
    }
    // A cube without a degenerate sample needs only its case.
    st.Case = n.Case;
    st.Degenerate = n.Degenerate;
    CubeSurface surface;
    this->Volume.Describe(n.I, n.J, n.K, st, surface);
    surface.ForEachVertex(n.Node,
      [&](const SurfaceVertex& v)
      { this->VisitAround(v.Key, v.Point, v.Axis, from, n.Component); });
  }

  /// Expands the listed nodes from `head` on, until none is left.
  void ExpandFrom(std::size_t head)
  {
    for (; head < this->Found.size() && !this->Volume.Stopped(); ++head)
    {
      const SurfaceNode n = this->Found[head];
      this->Expand(n);
      if ((++this->NodesExpanded & 0x3fff) == 0)
      {
        // The surface's size is unknown while it grows: an estimate that approaches 1.
        const double done = static_cast<double>(this->NodesExpanded);
        this->Volume.Report(0.5 * done / (done + 4.0 * (this->Found.size() - head) + (1 << 20)));
      }
    }
  }

  /// Grows a new component from the nodes that use vertex `key`, unless they were found.
  void GrowUnseeded(std::int64_t key, const int p[3], int axis)
  {
    const std::size_t head = this->Found.size();
    const int comp = this->Components.Add(false);
    this->VisitAround(key, p, axis, nullptr, comp);
    if (this->Found.size() == head)
    {
      this->Components.RemoveLast();
      return;
    }
    this->ExpandFrom(head);
  }

  /// Grows from every vertex on the plane of grid points p[axis] = `plane` of this rank's box.
  void GrowFromPlane(int axis, int plane)
  {
    SampledVolume<Values>& volume = this->Volume;
    const CellBox& box = volume.Owned.Mine();
    const Grid& grid = volume.GridOf;
    const double c = volume.Isovalue;
    const int u = axis == 0 ? 1 : 0, v = axis == 2 ? 1 : 2;
    int p[3];
    p[axis] = plane;
    for (p[v] = box.Lo[v]; p[v] <= box.Hi[v] + 1 && !volume.Stopped(); ++p[v])
    {
      for (p[u] = box.Lo[u]; p[u] <= box.Hi[u] + 1 && !volume.Stopped(); ++p[u])
      {
        const double s = volume.Read(p[0], p[1], p[2]);
        if (s == c)
        {
          this->GrowUnseeded(grid.PointKey(p[0], p[1], p[2]), p, -1);
        }
        for (const int along : { u, v })
        {
          if (p[along] > box.Hi[along])
          {
            continue;
          }
          int q[3] = { p[0], p[1], p[2] };
          ++q[along];
          const double t = volume.Read(q[0], q[1], q[2]);
          if ((s >= c) != (t >= c) && s != c && t != c)
          {
            this->GrowUnseeded(grid.EdgeKey(p[0], p[1], p[2], along), p, along);
          }
        }
      }
    }
  }

  /// Starts a new component from every unfound node of the owned cubes in `region`.
  void Scan(const CellBox& region, bool reportProgress)
  {
    SampledVolume<Values>& volume = this->Volume;
    CubeSamples st;
    CubeSurface surface;
    for (int k = region.Lo[2]; k <= region.Hi[2] && !volume.Stopped(); ++k)
    {
      if (reportProgress)
      {
        volume.Report(0.5 * (k - region.Lo[2]) / (region.Hi[2] - region.Lo[2] + 1));
      }
      for (int j = region.Lo[1]; j <= region.Hi[1]; ++j)
      {
        for (int i = region.Lo[0]; i <= region.Hi[0] && !volume.Stopped(); ++i)
        {
          if (!volume.Owned.Owns(i, j, k))
          {
            continue;
          }
          const std::int64_t bit = this->CubeBit(i, j, k);
          if (this->AllFound(bit) || !volume.Evaluate(i, j, k, st) || st.Case == 0 ||
            st.Case == 255)
          {
            continue;
          }
          volume.Describe(i, j, k, st, surface);
          const int numNodes = surface.NumberOfNodes();
          for (int node = 0; node < numNodes; ++node)
          {
            if (!this->NodeFound(bit, node, numNodes))
            {
              const std::size_t head = this->Found.size();
              this->Record(i, j, k, bit, st, node, numNodes, this->Components.Add(false));
              this->ExpandFrom(head);
            }
          }
        }
      }
    }
  }

  static constexpr int TileCubes = 32;  // cubes along each axis of a tile of visited bits
  static constexpr int TileWords = 512; // 64-bit words in a tile

  SampledVolume<Values>& Volume;
  ComponentSet& Components;
  std::int64_t Tiles[3] = { 0, 0, 0 }; // tiles along each axis of the owned box
  ZeroedArray<std::uint64_t> Visited;  // a bit per owned cube: its nodes were all found
  KeyMap FoundNodesOfCube{ 64 };       // cubes of several nodes: the nodes found, as bits
  std::vector<SurfaceNode> Found;
  std::int64_t NodesExpanded = 0;
};

} // namespace rgmc

#endif

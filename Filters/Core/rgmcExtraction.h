// Extraction: makes the triangles of the surface nodes that growth found, slab by slab along z,
// so that vertices shared by neighbouring cubes are found in small per-slab edge tables instead
// of a hash over the whole surface. Components that meet through a vertex this piece cannot see
// whole (a cube around it belongs to another rank) record that vertex as a port; the VTK layer
// matches ports across ranks and joins the components (vtkRGMarchingCubes).
#ifndef rgmcExtraction_h
#define rgmcExtraction_h

#include "rgmcBuffer.h"
#include "rgmcCubeSurface.h"
#include "rgmcKeyMap.h"

#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

namespace rgmc
{

/// A vertex that other ranks may also have: its key and the component that owns it here.
struct Port
{
  std::int64_t Key;
  int Component;
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
class SurfaceExtraction
{
public:
  SurfaceExtraction(SampledVolume<Values>& volume, ComponentSet& components)
    : Volume(volume)
    , Components(components)
  {
  }

  LocalMesh Mesh;
  std::vector<Port> Ports;

  /// How often extraction met a vertex that another component had created. On a single owner
  /// growth follows every adjacency, so this stays 0; across owners it joins components that
  /// meet through cubes of another rank.
  std::int64_t Joins() const { return this->JoinCount; }

  /// Makes the triangles of `nodes` (reordered by slab); fills Mesh, Ports and the components'
  /// triangle counts and smallest keys.
  void Extract(std::vector<SurfaceNode>& nodes)
  {
    if (nodes.empty() || this->Volume.Stopped())
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
    for (const SurfaceNode& n : nodes)
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
    for (const SurfaceNode& n : nodes)
    {
      ++start[n.K - box.Lo[2] + 1];
      triangles += this->Volume.Table[n.Case].NumTriangles;
    }
    for (int s = 0; s < numSlabs; ++s)
    {
      start[s + 1] += start[s];
    }
    {
      // Reorder the nodes by slab, so that extraction reads them in sequence.
      std::vector<std::int64_t> next(start.begin(), start.end() - 1);
      std::vector<SurfaceNode> sorted(nodes.size());
      for (const SurfaceNode& n : nodes)
      {
        sorted[next[n.K - box.Lo[2]]++] = n;
      }
      nodes.swap(sorted);
    }
    // A node emits at most its case's triangles; a closed surface has about half as many
    // vertices as triangles.
    LocalMesh& m = this->Mesh;
    const std::size_t vertices = static_cast<std::size_t>(triangles / 2 + 64);
    m.Triangles.reserve(static_cast<std::size_t>(3 * triangles));
    m.TriangleComponent.reserve(static_cast<std::size_t>(triangles));
    m.Keys.reserve(vertices);
    m.VertexComponent.reserve(vertices);
    if (this->Volume.Options.DoublePoints)
    {
      m.PointsDouble.reserve(3 * vertices);
    }
    else
    {
      m.Points.reserve(3 * vertices);
    }
    if (this->Volume.Options.ComputeNormals)
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
    EdgeLayer* bottom[2] = { &this->Layers[0], &this->Layers[1] }; // x, y edges at z = k
    EdgeLayer* top[2] = { &this->Layers[2], &this->Layers[3] };    // x, y edges at z = k + 1
    EdgeLayer* vertical = &this->Layers[4];                        // z edges
    CubeSamples st;
    CubeSurface surface;
    for (int s = 0; s < numSlabs && !this->Volume.Stopped(); ++s)
    {
      const int k = box.Lo[2] + s;
      this->SlabLayers[0][0] = bottom[0];
      this->SlabLayers[0][1] = bottom[1];
      this->SlabLayers[1][0] = top[0];
      this->SlabLayers[1][1] = top[1];
      this->VerticalLayer = vertical;
      this->SlabK = k;
      for (std::int64_t n = start[s]; n < start[s + 1] && !this->Volume.Stopped(); ++n)
      {
        const SurfaceNode& node = nodes[n];
        if (this->Volume.Evaluate(node.I, node.J, node.K, st))
        {
          this->Volume.Describe(node.I, node.J, node.K, st, surface);
          this->Emit(node, st, surface);
        }
      }
      for (EdgeLayer* layer : { bottom[0], bottom[1], vertical })
      {
        layer->Reset();
      }
      std::swap(bottom[0], top[0]);
      std::swap(bottom[1], top[1]);
      if ((s & 15) == 0)
      {
        this->Volume.Report(0.5 + 0.5 * s / numSlabs);
      }
    }
  }

private:
  /// Vertex ids + 1 (0: none yet) of one plane of edges, with the entries written so far (to
  /// reset cheaply).
  struct EdgeLayer
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

  /// Creates the output point of a vertex: position, normal, component, port check.
  std::int32_t NewVertex(const SurfaceVertex& v, double sLo, double sHi, int comp)
  {
    double x[3];
    float normal[3] = { 0, 0, 0 };
    this->Volume.PositionAndNormal(v.Point, v.Axis, sLo, sHi, x, normal);
    LocalMesh& m = this->Mesh;
    // Vertex ids are 32-bit within a rank (slots hold id + 1).
    if (m.Keys.size() >= static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max() - 1))
    {
      throw std::length_error("more than 2147483646 surface vertices in one piece");
    }
    const std::int32_t id = static_cast<std::int32_t>(m.Keys.size());
    if (this->Volume.Options.DoublePoints)
    {
      m.PointsDouble.append(x, 3);
    }
    else
    {
      const float xf[3] = { static_cast<float>(x[0]), static_cast<float>(x[1]),
        static_cast<float>(x[2]) };
      m.Points.append(xf, 3);
    }
    if (this->Volume.Options.ComputeNormals)
    {
      m.Normals.append(normal, 3);
    }
    m.Keys.push_back(v.Key);
    m.VertexComponent.push_back(comp);
    ComponentSet::Totals& totals = this->Components.TotalsOf(this->Components.Root(comp));
    totals.MinKey = std::min(totals.MinKey, v.Key);
    if (this->Volume.IsPort(v.Point, v.Axis))
    {
      this->Ports.push_back(Port{ v.Key, comp });
    }
    return id;
  }

  /// The output point of a vertex met by component `comp`, whose id + 1 is kept in `slot` (0:
  /// none yet): made on first use; met again by another component, it joins the two.
  std::int32_t UseVertex(std::int32_t& slot, const SurfaceVertex& v, double sLo, double sHi,
    int comp, EdgeLayer* layer, std::int32_t index)
  {
    if (slot > 0)
    {
      this->JoinCount += this->Components.Join(this->Mesh.VertexComponent[slot - 1], comp);
      return slot - 1;
    }
    const std::int32_t id = this->NewVertex(v, sLo, sHi, comp);
    slot = id + 1;
    if (layer)
    {
      layer->Touched.push_back(index);
    }
    return id;
  }

  /// The output point of a vertex of the current node's cube: on an edge (kept in the slab's
  /// edge layers) or on a grid point (kept in a map).
  std::int32_t Vertex(const SurfaceNode& n, const SurfaceVertex& v, const CubeSamples& st)
  {
    if (v.Axis < 0)
    {
      bool inserted;
      std::int32_t& slot = this->PointVertices.FindOrInsert(v.Key, 0, inserted);
      return this->UseVertex(slot, v, 0.0, 0.0, n.Component, nullptr, 0);
    }
    const CellBox& box = this->NodeBox;
    const std::int32_t index = static_cast<std::int32_t>(
      (v.Point[0] - box.Lo[0]) + this->LayerNx * (v.Point[1] - box.Lo[1]));
    EdgeLayer* layer =
      v.Axis == 2 ? this->VerticalLayer : this->SlabLayers[v.Point[2] - this->SlabK][v.Axis];
    return this->UseVertex(layer->Ids[index], v, st.S[EdgeCorners[v.Edge][0]],
      st.S[EdgeCorners[v.Edge][1]], n.Component, layer, index);
  }

  /// Emits the triangles of one node.
  void Emit(const SurfaceNode& n, const CubeSamples& st, const CubeSurface& surface)
  {
    LocalMesh& m = this->Mesh;
    surface.ForEachTriangle(n.Node,
      [&](const SurfaceVertex* triangle)
      {
        const std::int32_t ids[3] = { this->Vertex(n, triangle[0], st),
          this->Vertex(n, triangle[1], st), this->Vertex(n, triangle[2], st) };
        m.Triangles.append(ids, 3);
        m.TriangleComponent.push_back(n.Component);
        ++this->Components.TotalsOf(this->Components.Root(n.Component)).Triangles;
      });
  }

  SampledVolume<Values>& Volume;
  ComponentSet& Components;
  EdgeLayer Layers[5];
  EdgeLayer* SlabLayers[2][2] = { { nullptr, nullptr }, { nullptr, nullptr } };
  EdgeLayer* VerticalLayer = nullptr;
  int SlabK = 0;
  std::int64_t LayerNx = 0;
  CellBox NodeBox; // the cubes of the nodes
  KeyMap PointVertices{ 64 };
  std::int64_t JoinCount = 0;
};

} // namespace rgmc

#endif

// Extraction: makes the triangles of the surface nodes that growth found, slab by slab along z,
// so that vertices shared by neighbouring cubes are found in small per-slab edge tables instead
// of a hash over the whole surface. Components that meet through a vertex this piece cannot see
// whole (a cube around it belongs to another rank) record that vertex as a port; the VTK layer
// matches ports across ranks and joins the components (vtkRGMarchingCubes).
#ifndef rgmcExtraction_h
#define rgmcExtraction_h

#include "rgmcBuffer.h"
#include "rgmcKeyMap.h"
#include "rgmcNodesBySlab.h"
#include "rgmcSampledVolume.h"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <limits>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <utility>
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

  /// Frees every array now, pages first (Buffer::FreeNow).
  void FreeNow()
  {
    this->Points.FreeNow();
    this->PointsDouble.FreeNow();
    this->Normals.FreeNow();
    this->Keys.FreeNow();
    this->VertexComponent.FreeNow();
    this->Triangles.FreeNow();
    this->TriangleComponent.FreeNow();
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

  /// How often extraction joined two components through a vertex both use: components of one
  /// surface that growth labelled apart (per tile in the full scan, and across owners, where
  /// components meet through cubes of another rank).
  std::int64_t Joins() const { return this->JoinCount; }

  /// Makes the triangles of `found` (taken: left empty); fills Mesh, Ports and the components'
  /// triangle counts and smallest keys. The nodes are sorted by slab, slabs are cut into chunks
  /// of a few slabs, extracted at once (on threads) and joined in chunk order, so that the
  /// result does not depend on the number of threads.
  void Extract(NodeList& found)
  {
    if (found.empty() || this->Volume.Stopped())
    {
      return;
    }
    this->Volume.Mark("extraction: nodes by slab");
    NodesBySlab sorted;
    SortNodesBySlab(
      found, this->Volume.Table, NodesPerGroup,
      [this](std::int64_t count, auto&& task) { this->Volume.Parallel(count, task); }, sorted);
    found.Clear();
    this->NodeBox = sorted.Box;
    const Buffer<SurfaceNode>& nodes = sorted.Nodes;
    const std::vector<std::int64_t>& start = sorted.Start;
    const std::vector<std::int64_t>& slabTriangles = sorted.SlabTriangles;
    const CellBox& box = this->NodeBox;
    const int numSlabs = box.Hi[2] - box.Lo[2] + 1;
    this->LayerNx = box.Hi[0] - box.Lo[0] + 2;
    for (int e = 0; e < 12; ++e)
    {
      const int* o = CornerOffset[EdgeCorners[e][0]];
      this->EdgeSlotOffset[e] = static_cast<std::int32_t>(o[0] + this->LayerNx * o[1]);
    }
    this->PlaneSize = static_cast<std::size_t>(this->LayerNx) * (box.Hi[1] - box.Lo[1] + 2);

    this->Volume.Mark("extraction: chunks");
    // Chunks of slabs, all extracted in one parallel step: enough of them for many threads,
    // few enough that the vertices made twice (on the planes between chunks) cost little; cut
    // where they hold equal shares of the triangles, so that the longest is short. The chunks
    // depend on the slabs only, never on the threads, and the joined mesh on neither.
    const int chunkSlabs = std::max(MinChunkSlabs, std::min(MaxChunkSlabs, numSlabs / 32));
    const std::vector<int> chunkStart =
      ChunkStarts(slabTriangles, (numSlabs + chunkSlabs - 1) / chunkSlabs);
    const int numChunks = static_cast<int>(chunkStart.size()) - 1;
    std::vector<Chunk> chunks(static_cast<std::size_t>(numChunks));
    // Each chunk's triangles (at most its slabs' count) and their components go in its slices
    // of one array shared by all chunks, in huge pages: 16 bytes a triangle that would
    // otherwise fault in 4 KiB at a time (a fault costs microseconds under a hypervisor).
    std::vector<std::int64_t> firstTriangle(static_cast<std::size_t>(numChunks) + 1, 0);
    for (int c = 0; c < numChunks; ++c)
    {
      firstTriangle[c + 1] = firstTriangle[c];
      for (int s = chunkStart[c]; s < chunkStart[c + 1]; ++s)
      {
        firstTriangle[c + 1] += slabTriangles[s];
      }
    }
    const std::size_t bound = static_cast<std::size_t>(firstTriangle.back());
    this->ChunkTriangles.resize_for_overwrite(4 * bound); // 3 ids a triangle, then components
    this->Volume.Parallel(numChunks,
      [&](std::int64_t c)
      {
        const std::int64_t t0 = firstTriangle[c], triangles = firstTriangle[c + 1] - t0;
        LocalMesh& m = chunks[c].Mesh;
        std::int32_t* store = this->ChunkTriangles.data();
        m.Triangles.Borrow(store + 3 * t0, 3 * static_cast<std::size_t>(triangles));
        m.TriangleComponent.Borrow(store + 3 * bound + t0, static_cast<std::size_t>(triangles));
        this->ExtractChunk(nodes, start, chunkStart[c], chunkStart[c + 1], triangles, chunks[c]);
      });
    this->Volume.Report(0.95);
    this->Pool.clear();
    if (!this->Volume.Stopped())
    {
      this->JoinChunks(chunks);
      this->Volume.Report(1.0);
    }
    chunks.clear(); // before the arrays they borrowed from
    this->ChunkTriangles.FreeNow();
  }

private:
  static constexpr std::size_t NodesPerGroup = 8192; // nodes by slab: nodes per task
  static constexpr std::int64_t TotalsRange = 65536; // component totals: triangles per task
  static constexpr int MinChunkSlabs = 4; // slabs of cubes per chunk, on average (not per thread)
  static constexpr int MaxChunkSlabs = 16;
  static constexpr int PrefetchAhead = 16;            // nodes between a prefetch and the node's use
  static constexpr std::int64_t PieceVertices = 8192; // copy chunks: at most vertices a piece
  static constexpr std::int64_t PieceTriangles = 16384; // and triangles a piece

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

  /// A vertex that other ranks may also have, by its id in a chunk.
  struct ChunkPort
  {
    std::int32_t Vertex;
    int Component;
  };

  /// What one chunk of slabs produced, with chunk-local vertex ids. Each on cache lines of its
  /// own: threads extract neighbouring chunks at once.
  struct alignas(64) Chunk
  {
    LocalMesh Mesh;
    std::vector<ChunkPort> Ports;
    /// Pairs of components that share a vertex in this chunk (or with the chunk below).
    std::vector<std::pair<int, int>> Joins;
    /// Vertices on the chunk's lowest plane of grid points and on the plane above its last
    /// slab (x and y edges, grid points): the ones the neighbouring chunks may have too.
    std::vector<std::int32_t> BottomPlane, TopPlane;
    int LowK = 0, TopK = 0;
    /// Per vertex: its id in the joined mesh.
    std::vector<std::int32_t> FinalId;
  };

  /// A task of CopyChunks: a chunk's vertices [V0, V1) and triangles [T0, T1).
  struct CopyPiece
  {
    int Chunk;
    std::int64_t V0, V1, T0, T1;
  };

  /// The state of one chunk's extraction (one task). Its edge layers are plane-sized: they are
  /// kept, all zero again, for the next chunk (a pool), rather than paged in anew every time.
  struct ChunkWork
  {
    Chunk* Out = nullptr;
    EdgeLayer Layers[5];
    EdgeLayer* EdgeLayerOf[12] = {}; // per cube edge: the layer of its slot in the current slab
    std::unique_ptr<KeyMap> PointVertices;
  };

  // The chunks' triangles, then their components, each chunk's in slices (Extract).
  Buffer<std::int32_t> ChunkTriangles;

  std::unique_ptr<ChunkWork> TakeWork()
  {
    {
      std::lock_guard<std::mutex> lock(this->PoolMutex);
      if (!this->Pool.empty())
      {
        std::unique_ptr<ChunkWork> work = std::move(this->Pool.back());
        this->Pool.pop_back();
        return work;
      }
    }
    std::unique_ptr<ChunkWork> work(new ChunkWork);
    for (auto& layer : work->Layers)
    {
      layer.Ids.Allocate(this->PlaneSize);
    }
    return work;
  }

  void GiveBack(std::unique_ptr<ChunkWork> work)
  {
    for (auto& layer : work->Layers)
    {
      layer.Reset();
    }
    work->PointVertices.reset();
    std::lock_guard<std::mutex> lock(this->PoolMutex);
    this->Pool.push_back(std::move(work));
  }

  void ExtractChunk(const Buffer<SurfaceNode>& nodes, const std::vector<std::int64_t>& start,
    int first, int last, std::int64_t triangles, Chunk& chunk)
  {
    const CellBox& box = this->NodeBox;
    std::unique_ptr<ChunkWork> taken = this->TakeWork();
    ChunkWork& work = *taken;
    work.Out = &chunk;
    work.PointVertices.reset(new KeyMap(64));
    chunk.LowK = box.Lo[2] + first;
    chunk.TopK = box.Lo[2] + last; // the plane above the last slab
    // A node emits at most its case's triangles (the room of the chunk's slices, Extract); a
    // closed surface has about half as many vertices as triangles. A chunk's vertices are keys
    // and components only: their positions and normals are computed from the keys into the
    // joined mesh (CopyChunks).
    LocalMesh& m = chunk.Mesh;
    const std::size_t vertices = static_cast<std::size_t>(triangles / 2 + 64);
    m.Keys.reserve(vertices);
    m.VertexComponent.reserve(vertices);
    // Vertex ids of the edges in the current slab: x and y edges on its bottom and top planes,
    // z edges inside it. The top plane becomes the next slab's bottom.
    EdgeLayer* bottom[2] = { &work.Layers[0], &work.Layers[1] }; // x, y edges at z = k
    EdgeLayer* top[2] = { &work.Layers[2], &work.Layers[3] };    // x, y edges at z = k + 1
    EdgeLayer* vertical = &work.Layers[4];                       // z edges
    CubeSamples st;
    CubeSurface surface;
    for (int s = first; s < last && !this->Volume.Stopped(); ++s)
    {
      for (int e = 0; e < 12; ++e)
      {
        const int axis = CubeEdgeAxis[e];
        EdgeLayer* const* plane = CornerOffset[EdgeCorners[e][0]][2] == 0 ? bottom : top;
        work.EdgeLayerOf[e] = axis == 2 ? vertical : plane[axis];
      }
      for (std::int64_t n = start[s]; n < start[s + 1]; ++n)
      {
        if (n + PrefetchAhead < start[s + 1])
        {
          // The vertices' slots of a node soon emitted: rows j and j + 1 of the slab's edge
          // layers.
          const SurfaceNode& ahead = nodes[n + PrefetchAhead];
          const std::int64_t at =
            (ahead.I - box.Lo[0]) + this->LayerNx * std::int64_t(ahead.J - box.Lo[1]);
          for (EdgeLayer* layer : { bottom[0], bottom[1], top[0], top[1], vertical })
          {
            __builtin_prefetch(&layer->Ids[at]);
            __builtin_prefetch(&layer->Ids[at + this->LayerNx]);
          }
        }
        const SurfaceNode& node = nodes[n];
        if (this->Volume.NodeSamples(node, st))
        {
          this->Volume.Describe(node.I, node.J, node.K, st, surface);
          this->Emit(work, node, surface);
        }
      }
      for (EdgeLayer* layer : { bottom[0], bottom[1], vertical })
      {
        layer->Reset();
      }
      std::swap(bottom[0], top[0]);
      std::swap(bottom[1], top[1]);
    }
    this->GiveBack(std::move(taken));
    std::sort(chunk.Joins.begin(), chunk.Joins.end());
    chunk.Joins.erase(std::unique(chunk.Joins.begin(), chunk.Joins.end()), chunk.Joins.end());
  }

  /// Creates the output point of a vertex in a chunk: key, component, port check (its position
  /// and normal come at the join).
  std::int32_t NewVertex(ChunkWork& work, const SurfaceVertex& v, int comp)
  {
    Chunk& chunk = *work.Out;
    LocalMesh& m = chunk.Mesh;
    // Vertex ids are 32-bit within a rank (slots hold id + 1).
    if (m.Keys.size() >= static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max() - 1))
    {
      throw std::length_error("more than 2147483646 surface vertices in one piece");
    }
    const std::int32_t id = static_cast<std::int32_t>(m.Keys.size());
    m.Keys.push_back(v.Key);
    m.VertexComponent.push_back(comp);
    if (v.Axis != 2 && v.Point[2] == chunk.LowK)
    {
      chunk.BottomPlane.push_back(id);
    }
    if (v.Axis != 2 && v.Point[2] == chunk.TopK)
    {
      chunk.TopPlane.push_back(id);
    }
    if (this->Volume.IsPort(v.Point, v.Axis))
    {
      chunk.Ports.push_back(ChunkPort{ id, comp });
    }
    return id;
  }

  /// The output point of a vertex met by component `comp`, whose id + 1 is kept in `slot` (0:
  /// none yet): made on first use; met again by another component, the two are to be joined.
  RGMC_INLINE std::int32_t UseVertex(ChunkWork& work, std::int32_t& slot, const SurfaceVertex& v,
    int comp, EdgeLayer* layer, std::int32_t index)
  {
    if (slot > 0)
    {
      const int other = work.Out->Mesh.VertexComponent[slot - 1];
      if (other != comp)
      {
        work.Out->Joins.emplace_back(std::min(other, comp), std::max(other, comp));
      }
      return slot - 1;
    }
    const std::int32_t id = this->NewVertex(work, v, comp);
    slot = id + 1;
    if (layer)
    {
      layer->Touched.push_back(index);
    }
    return id;
  }

  /// The output point of a vertex of the current node's cube: on an edge (kept in the slab's
  /// edge layers) or on a grid point (kept in a map).
  RGMC_INLINE std::int32_t Vertex(ChunkWork& work, const SurfaceNode& n, const SurfaceVertex& v)
  {
    if (v.Axis < 0)
    {
      bool inserted;
      std::int32_t& slot = work.PointVertices->FindOrInsert(v.Key, 0, inserted);
      return this->UseVertex(work, slot, v, n.Component, nullptr, 0);
    }
    const CellBox& box = this->NodeBox;
    const std::int32_t index = static_cast<std::int32_t>(
      (v.Point[0] - box.Lo[0]) + this->LayerNx * (v.Point[1] - box.Lo[1]));
    EdgeLayer* layer = work.EdgeLayerOf[v.Edge]; // the cube's edge that carries the vertex
    return this->UseVertex(work, layer->Ids[index], v, n.Component, layer, index);
  }

  /// The output point of the vertex on edge e of a cube without a degenerate sample: its slot
  /// found from the cube's place in the edge layers (`at`) and the edge, the vertex itself
  /// (its key) made only when it is new.
  RGMC_INLINE std::int32_t EdgeVertex(
    ChunkWork& work, const SurfaceNode& n, int e, std::int32_t at, const CubeSurface& surface)
  {
    EdgeLayer* layer = work.EdgeLayerOf[e];
    const std::int32_t index = at + this->EdgeSlotOffset[e];
    std::int32_t& slot = layer->Ids[index];
    if (slot > 0)
    {
      return this->UseVertex(work, slot, SurfaceVertex(), n.Component, layer, index);
    }
    return this->UseVertex(work, slot, surface.EdgeVertex(e), n.Component, layer, index);
  }

  /// Emits the triangles of one node.
  void Emit(ChunkWork& work, const SurfaceNode& n, const CubeSurface& surface)
  {
    LocalMesh& m = work.Out->Mesh;
    if (!surface.Degenerate())
    {
      // The common case: the case table's triangles of the node's sheet.
      const CaseEntry& entry = this->Volume.Table[n.Case];
      const std::int32_t at = static_cast<std::int32_t>(
        (n.I - this->NodeBox.Lo[0]) + this->LayerNx * (n.J - this->NodeBox.Lo[1]));
      for (int t = 0; t < entry.NumTriangles; ++t)
      {
        if (entry.TriangleSheet[t] == n.Node)
        {
          const std::int32_t ids[3] = { this->EdgeVertex(
                                          work, n, entry.Triangles[t][0], at, surface),
            this->EdgeVertex(work, n, entry.Triangles[t][1], at, surface),
            this->EdgeVertex(work, n, entry.Triangles[t][2], at, surface) };
          m.Triangles.append(ids, 3);
          m.TriangleComponent.push_back(n.Component);
        }
      }
      return;
    }
    surface.ForEachTriangle(n.Node,
      [&](const SurfaceVertex* triangle)
      {
        const std::int32_t ids[3] = { this->Vertex(work, n, triangle[0]),
          this->Vertex(work, n, triangle[1]), this->Vertex(work, n, triangle[2]) };
        m.Triangles.append(ids, 3);
        m.TriangleComponent.push_back(n.Component);
      });
  }

  /// Joins the chunks into Mesh and Ports, in chunk order: a vertex on the plane between two
  /// chunks, made by both, is the lower chunk's; components that share vertices are joined;
  /// then the components' totals.
  void JoinChunks(std::vector<Chunk>& chunks)
  {
    this->Volume.Mark("extraction: match planes");
    this->MatchChunkPlanes(chunks);
    std::vector<std::int64_t> vertexBase, triangleBase;
    std::int64_t vertices = 0, triangles = 0;
    this->Volume.Mark("extraction: number vertices");
    this->NumberJoinedVertices(chunks, vertexBase, triangleBase, vertices, triangles);
    this->CollectChunkPorts(chunks, vertexBase);
    this->Volume.Mark("extraction: copy chunks");
    this->CopyChunks(chunks, vertexBase, triangleBase, vertices, triangles);
    this->Volume.Mark("extraction: component totals");
    this->SumComponentTotals();
  }

  /// Each chunk's vertices on its bottom plane that the chunk below made too (FinalId -1 - the
  /// chunk below's vertex; 0 for the others), and the components they join.
  void MatchChunkPlanes(std::vector<Chunk>& chunks)
  {
    const std::int64_t numChunks = static_cast<std::int64_t>(chunks.size());
    this->Volume.Parallel(numChunks,
      [&](std::int64_t c)
      {
        Chunk& chunk = chunks[c];
        chunk.FinalId.assign(static_cast<std::size_t>(chunk.Mesh.NumberOfPoints()), 0);
        if (c == 0 || chunk.BottomPlane.empty())
        {
          return;
        }
        Chunk& below = chunks[c - 1];
        KeyMap theirs(below.TopPlane.size());
        for (std::int32_t id : below.TopPlane)
        {
          bool inserted;
          theirs.FindOrInsert(below.Mesh.Keys[id], id, inserted);
        }
        for (std::int32_t id : chunk.BottomPlane)
        {
          const std::int32_t* match = theirs.Find(chunk.Mesh.Keys[id]);
          if (match)
          {
            chunk.FinalId[id] = -1 - *match; // the chunk below's vertex
            const int a = below.Mesh.VertexComponent[*match];
            const int b = chunk.Mesh.VertexComponent[id];
            if (a != b)
            {
              chunk.Joins.emplace_back(std::min(a, b), std::max(a, b));
            }
          }
        }
      });
  }

  /// Joins the components, in chunk order; numbers the vertices of the joined mesh (a vertex
  /// the chunk below made gets that one's number) and gives each chunk its first vertex and
  /// triangle there.
  void NumberJoinedVertices(std::vector<Chunk>& chunks, std::vector<std::int64_t>& vertexBase,
    std::vector<std::int64_t>& triangleBase, std::int64_t& vertices, std::int64_t& triangles)
  {
    const std::int64_t numChunks = static_cast<std::int64_t>(chunks.size());
    vertexBase.assign(chunks.size(), 0);
    triangleBase.resize(chunks.size());
    for (Chunk& chunk : chunks)
    {
      for (const auto& pair : chunk.Joins)
      {
        this->JoinCount += this->Components.Join(pair.first, pair.second);
      }
      chunk.Joins = std::vector<std::pair<int, int>>();
    }
    // Each chunk's own vertices (FinalId 0) get the next numbers, chunk after chunk.
    this->Volume.Parallel(numChunks,
      [&](std::int64_t c)
      {
        const std::vector<std::int32_t>& ids = chunks[c].FinalId;
        vertexBase[c] = std::count(ids.begin(), ids.end(), 0);
      });
    for (std::int64_t c = 0; c < numChunks; ++c)
    {
      const std::int64_t own = vertexBase[c];
      vertexBase[c] = vertices;
      triangleBase[c] = triangles;
      vertices += own;
      triangles += chunks[c].Mesh.NumberOfTriangles();
    }
    // Vertex ids are 32-bit within a rank.
    if (vertices > std::numeric_limits<std::int32_t>::max() - 1)
    {
      throw std::length_error("more than 2147483646 surface vertices in one piece");
    }
    this->Volume.Parallel(numChunks,
      [&](std::int64_t c)
      {
        std::int32_t next = static_cast<std::int32_t>(vertexBase[c]);
        for (std::int32_t& id : chunks[c].FinalId)
        {
          if (id == 0)
          {
            id = next++;
          }
        }
      });
    // A vertex the chunk below made is one of that chunk's own (on its top plane, never on its
    // bottom one): numbered above, and not written here.
    this->Volume.Parallel(numChunks,
      [&](std::int64_t c)
      {
        if (c == 0)
        {
          return;
        }
        const std::vector<std::int32_t>& below = chunks[c - 1].FinalId;
        for (std::int32_t& id : chunks[c].FinalId)
        {
          if (id < 0)
          {
            id = below[-1 - id];
          }
        }
      });
  }

  /// The ports of the joined mesh: each chunk's, on its own vertices.
  void CollectChunkPorts(
    const std::vector<Chunk>& chunks, const std::vector<std::int64_t>& vertexBase)
  {
    for (const Chunk& chunk : chunks)
    {
      for (const ChunkPort& port : chunk.Ports)
      {
        const std::int32_t id = port.Vertex;
        const std::size_t c = static_cast<std::size_t>(&chunk - chunks.data());
        if (chunk.FinalId[id] >= vertexBase[c]) // not the chunk below's vertex
        {
          this->Ports.push_back(Port{ chunk.Mesh.Keys[id], port.Component });
        }
      }
    }
  }

  /// The joined mesh: each chunk's own vertices and all its triangles, copied in place, in
  /// pieces of a chunk (many more tasks than chunks: a chunk is several milliseconds of
  /// copying). Every piece writes its own places, so the mesh does not depend on the order; the
  /// last piece of a chunk to end releases the chunk.
  void CopyChunks(std::vector<Chunk>& chunks, const std::vector<std::int64_t>& vertexBase,
    const std::vector<std::int64_t>& triangleBase, std::int64_t vertices, std::int64_t triangles)
  {
    LocalMesh& m = this->Mesh;
    const std::size_t nv = static_cast<std::size_t>(vertices);
    const std::size_t nt = static_cast<std::size_t>(triangles);
    if (this->Volume.Options.DoublePoints)
    {
      m.PointsDouble.resize_for_overwrite(3 * nv);
    }
    else
    {
      m.Points.resize_for_overwrite(3 * nv);
    }
    if (this->Volume.Options.ComputeNormals)
    {
      m.Normals.resize_for_overwrite(3 * nv);
    }
    m.Keys.resize_for_overwrite(nv);
    m.VertexComponent.resize_for_overwrite(nv);
    m.Triangles.resize_for_overwrite(3 * nt);
    m.TriangleComponent.resize_for_overwrite(nt);
    std::vector<CopyPiece> pieces;
    std::vector<std::atomic<int>> left(chunks.size());
    for (std::size_t c = 0; c < chunks.size(); ++c)
    {
      const std::int64_t cv = chunks[c].Mesh.NumberOfPoints();
      const std::int64_t ct = chunks[c].Mesh.NumberOfTriangles();
      const std::int64_t k = std::max<std::int64_t>(1,
        std::max(
          (cv + PieceVertices - 1) / PieceVertices, (ct + PieceTriangles - 1) / PieceTriangles));
      left[c].store(static_cast<int>(k), std::memory_order_relaxed);
      for (std::int64_t i = 0; i < k; ++i)
      {
        pieces.push_back(CopyPiece{
          static_cast<int>(c), cv * i / k, cv * (i + 1) / k, ct * i / k, ct * (i + 1) / k });
      }
    }
    this->Volume.Parallel(static_cast<std::int64_t>(pieces.size()),
      [&](std::int64_t p)
      {
        const CopyPiece& piece = pieces[p];
        Chunk& chunk = chunks[piece.Chunk];
        this->CopyVertices(chunk, vertexBase[piece.Chunk], piece.V0, piece.V1);
        const std::int64_t t0 = triangleBase[piece.Chunk];
        const LocalMesh& from = chunk.Mesh;
        for (std::int64_t t = piece.T0; t < piece.T1; ++t)
        {
          for (int v = 0; v < 3; ++v)
          {
            m.Triangles[3 * (t0 + t) + v] = chunk.FinalId[from.Triangles[3 * t + v]];
          }
          m.TriangleComponent[t0 + t] = from.TriangleComponent[t];
        }
        // The chunk's memory back as the joined mesh fills, not after the last chunk.
        if (left[piece.Chunk].fetch_sub(1, std::memory_order_acq_rel) == 1)
        {
          chunk.Mesh.FreeNow();
          DiscardPages(chunk.FinalId.data(), chunk.FinalId.size() * sizeof(std::int32_t));
          chunk = Chunk();
        }
      });
  }

  /// A chunk's own vertices among its vertices [v0, v1), placed in the joined mesh in batches:
  /// each batch's keys decoded (and its samples prefetched) while the batch before is placed.
  void CopyVertices(const Chunk& chunk, std::int64_t base, std::int64_t v0, std::int64_t v1)
  {
    LocalMesh& m = this->Mesh;
    const LocalMesh& from = chunk.Mesh;
    constexpr int B = SampledVolume<Values>::VertexBatch;
    struct Batch
    {
      int Points[B][3];
      int Axis[B];
      std::int64_t To[B];
      int Count = 0;
    } batches[2];
    std::int64_t next = v0;
    auto fill = [&](Batch& b)
    {
      b.Count = 0;
      for (; next < v1 && b.Count < B; ++next)
      {
        const std::int64_t to = chunk.FinalId[next];
        if (to < base)
        {
          continue; // the chunk below's vertex
        }
        this->Volume.GridOf.Decode(from.Keys[next], b.Points[b.Count], b.Axis[b.Count]);
        this->Volume.PrefetchAround(
          b.Points[b.Count][0], b.Points[b.Count][1], b.Points[b.Count][2]);
        b.To[b.Count++] = to;
        m.Keys[to] = from.Keys[next];
        m.VertexComponent[to] = from.VertexComponent[next];
      }
    };
    fill(batches[0]);
    for (int current = 0; batches[current].Count > 0; current = 1 - current)
    {
      fill(batches[1 - current]);
      this->PlaceVertices(batches[current].Points, batches[current].Axis, batches[current].To,
        batches[current].Count, this->Volume.Options.DoublePoints,
        this->Volume.Options.ComputeNormals);
    }
  }

  /// The positions and normals of `n` vertices on the edges leaving p[v] along axis[v] (-1: on
  /// the grid point), stored as vertices to[v] of the joined mesh (SampledVolume's
  /// PositionsAndNormals: vtkMarchingCubes' interpolation from the edge's lower end, the
  /// gradients' central differences).
  void PlaceVertices(const int (*p)[3], const int* axis, const std::int64_t* to, int n,
    bool doublePoints, bool normals)
  {
    constexpr int B = SampledVolume<Values>::VertexBatch;
    double x[B][3];
    float normal[B][3];
    this->Volume.PositionsAndNormals(p, axis, n, x, normal);
    LocalMesh& m = this->Mesh;
    for (int v = 0; v < n; ++v)
    {
      for (int a = 0; a < 3; ++a)
      {
        if (doublePoints)
        {
          m.PointsDouble[3 * to[v] + a] = x[v][a];
        }
        else
        {
          m.Points[3 * to[v] + a] = static_cast<float>(x[v][a]);
        }
        if (normals)
        {
          m.Normals[3 * to[v] + a] = normal[v][a];
        }
      }
    }
  }

  /// The components' totals: triangles and smallest key, on their roots. Ranges of triangles
  /// and vertices on threads, each a list of runs of one root (few: neighbours mostly share a
  /// component), added up in range order (sums and minima: the same for any threads).
  void SumComponentTotals()
  {
    const LocalMesh& m = this->Mesh;
    const std::int64_t nt = m.NumberOfTriangles();
    const std::int64_t nv = m.NumberOfPoints();
    std::vector<int> roots(static_cast<std::size_t>(this->Components.Size()));
    for (std::size_t c = 0; c < roots.size(); ++c)
    {
      roots[c] = this->Components.Root(static_cast<int>(c));
    }
    struct Run
    {
      int Root;
      std::int64_t Triangles;
      std::int64_t MinKey;
    };
    const std::int64_t numRanges = std::max<std::int64_t>(1, (nt + TotalsRange - 1) / TotalsRange);
    std::vector<std::vector<Run>> runs(static_cast<std::size_t>(numRanges));
    this->Volume.Parallel(numRanges,
      [&](std::int64_t r)
      {
        std::vector<Run>& out = runs[r];
        auto runOf = [&out](int root) -> Run&
        {
          if (out.empty() || out.back().Root != root)
          {
            out.push_back(Run{ root, 0, std::numeric_limits<std::int64_t>::max() });
          }
          return out.back();
        };
        for (std::int64_t t = nt * r / numRanges; t < nt * (r + 1) / numRanges; ++t)
        {
          ++runOf(roots[m.TriangleComponent[t]]).Triangles;
        }
        for (std::int64_t v = nv * r / numRanges; v < nv * (r + 1) / numRanges; ++v)
        {
          Run& run = runOf(roots[m.VertexComponent[v]]);
          run.MinKey = std::min<std::int64_t>(run.MinKey, m.Keys[v]);
        }
      });
    for (const std::vector<Run>& list : runs)
    {
      for (const Run& run : list)
      {
        ComponentSet::Totals& totals = this->Components.TotalsOf(run.Root);
        totals.Triangles += run.Triangles;
        totals.MinKey = std::min(totals.MinKey, run.MinKey);
      }
    }
  }

  SampledVolume<Values>& Volume;
  ComponentSet& Components;
  std::int64_t LayerNx = 0;
  std::int32_t EdgeSlotOffset[12] = {}; // per cube edge: its slot, from the cube's in a layer
  std::size_t PlaneSize = 0;
  CellBox NodeBox; // the cubes of the nodes
  std::int64_t JoinCount = 0;
  std::mutex PoolMutex;
  std::vector<std::unique_ptr<ChunkWork>> Pool; // chunk states not in use
};

} // namespace rgmc

#endif

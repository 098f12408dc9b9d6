// Growth's node visits: the per-node step of growth's breadth-first search, inside one tile.
// Visiting a cube records its unfound nodes that use a vertex; expanding a node visits every
// other cube that has one of its vertices: now when the cube is in the node's tile, as a
// crossing for the tile it lies in, or as a departure when another rank owns it. Which tiles
// search when, and how crossings travel between them, is the scheduler's (rgmcGrowth.h).
#ifndef rgmcNodeVisits_h
#define rgmcNodeVisits_h

#include "rgmcBuffer.h"
#include "rgmcKeyMap.h"
#include "rgmcSampledVolume.h"

#include <array>
#include <cstdint>
#include <deque>
#include <memory>
#include <vector>

namespace rgmc
{

/// A vertex that growth reached in a cube of this rank whose other cubes around it include
/// one of another rank, with the component that reached it.
struct Departure
{
  std::int64_t Key;
  int Component;
};

/// A vertex that another rank's growth reached, to grow on from in this rank's cubes around
/// it; Label numbers the arrivals' components from 0 (arrivals of one component of one rank
/// share a label).
struct Arrival
{
  std::int64_t Key;
  int Label;
};

/// Growth's tiles: 32 cubes along each axis; a cube's found-bit in its tile is
/// i + 32 j + 1024 k (tile-local), so a step to a neighbour in the tile is a fixed offset.
/// (Measured 2026-11-29: tiles of 16^3 cut seeded growth's span by 40% but cost its work 25%
/// more on one thread, in more crossings between tiles.)
constexpr int GrowthTileBits = 5;
constexpr int GrowthTileCubes = 1 << GrowthTileBits;

/// A step of growth from a cube to one of the 3 other cubes around one of its edges
/// (EdgeNeighbourTable's), with what growth needs to take it inside a tile without arithmetic:
/// the neighbour's found-bit offset, and the room the step needs (bit 2a: one cube below along
/// axis a; bit 2a + 1: one cube above).
struct TileStep
{
  std::int16_t BitOffset;
  std::int8_t Offset[3];
  std::int8_t Edge; // the neighbour's edge that carries the vertex
  std::uint8_t Needs;
};

/// EdgeNeighbourTable as tile steps, in the same order.
constexpr std::array<std::array<TileStep, 3>, 12> TileSteps()
{
  std::array<std::array<TileStep, 3>, 12> table{};
  for (int e = 0; e < 12; ++e)
  {
    for (int n = 0; n < 3; ++n)
    {
      const EdgeNeighbour& nb = EdgeNeighbourTable[e][n];
      TileStep& step = table[e][n];
      int needs = 0;
      for (int a = 0; a < 3; ++a)
      {
        step.Offset[a] = nb.Offset[a];
        needs |= (nb.Offset[a] < 0 ? 1 : 0) << (2 * a);
        needs |= (nb.Offset[a] > 0 ? 1 : 0) << (2 * a + 1);
      }
      step.BitOffset = static_cast<std::int16_t>(
        nb.Offset[0] + GrowthTileCubes * (nb.Offset[1] + GrowthTileCubes * nb.Offset[2]));
      step.Edge = nb.Edge;
      step.Needs = static_cast<std::uint8_t>(needs);
    }
  }
  return table;
}
constexpr std::array<std::array<TileStep, 3>, 12> TileStepTable = TileSteps();

/// The room around cube c inside its tile of the box `owned` (tiles counted from owned.Lo), as
/// TileStep::Needs bits: a step whose Needs are all in the room lands in the same tile and in
/// the box.
RGMC_INLINE unsigned TileRoom(const int c[3], const CellBox& owned)
{
  unsigned room = 0;
  for (int a = 0; a < 3; ++a)
  {
    const int x = (c[a] - owned.Lo[a]) & (GrowthTileCubes - 1);
    room |= unsigned(x > 0) << (2 * a);
    room |= unsigned(x < GrowthTileCubes - 1 && c[a] < owned.Hi[a]) << (2 * a + 1);
  }
  return room;
}

/// The state of growth that its node visits share with its scheduler (SurfaceGrowth): the tiles,
/// their found-bits and search states, and the visits themselves.
template <typename Values>
class NodeVisits
{
public:
  /// Whether steps into cubes of other ranks are kept as departures (seeded growth on several
  /// ranks) instead of dropped.
  bool CrossRanks = false;

protected:
  NodeVisits(SampledVolume<Values>& volume, ComponentSet& components)
    : Volume(volume)
    , Components(components)
  {
    const CellBox& box = this->Volume.Owned.Mine();
    if (!box.Empty() && !this->Volume.Owned.OwnsNothing())
    {
      std::int64_t tiles = 1;
      for (int a = 0; a < 3; ++a)
      {
        this->Tiles[a] = ((box.Hi[a] - box.Lo[a] + 1) + TileCubes - 1) / TileCubes;
        tiles *= this->Tiles[a];
      }
      this->Visited.Allocate(static_cast<std::size_t>(tiles * TileWords));
      this->TileTable.Allocate(static_cast<std::size_t>(tiles));
      this->NumTiles = tiles;
    }
  }

  /// A step of the search into a tile: visit cube (I, J, K) for the vertex Key, on the cube's
  /// edge Edge (-1 for a grid-point key), for component Component.
  struct Crossing
  {
    std::int64_t Key;
    std::int32_t I, J, K;
    std::int32_t Component;
    std::int8_t Edge;
  };

  /// The crossings a tile sent in one round, grouped by the tile they go to: those for the
  /// neighbour in direction d (d = (di + 1) + 3 (dj + 1) + 9 (dk + 1), tile offsets di, dj, dk)
  /// are Items[Start[d], Start[d + 1]), in the order sent.
  struct Mail
  {
    Buffer<Crossing> Items;
    std::array<std::int32_t, 28> Start;
    std::int64_t Round = -1; // the round that sent them
  };

  /// A tile's search state: nodes found in the current round (the queue), crossings sent to
  /// other tiles in this round (the outbox, posted as mail at the round's end; the mail of the
  /// round before stays for its readers meanwhile), and which nodes of its cubes of several
  /// nodes were found. Each on cache lines of its own: threads grow neighbouring tiles at once.
  struct alignas(64) TileWork
  {
    std::vector<SurfaceNode> Queue;
    std::vector<Crossing> Outbox;
    std::vector<Departure> Departures;
    std::unique_ptr<KeyMap> FoundNodesOfCube;
    std::unique_ptr<Mail> Sent[2]; // by the parity of the round that sent it
    std::int64_t Examined = 0;     // cubes whose samples Visit read
    std::int64_t MailRound = -1;   // the last round that sent this tile crossings
    std::int64_t Posted = 0;       // crossings this tile sent
    std::int64_t Received = 0;     // crossings this tile was sent and read
  };

  /// The state of a tile that growth has reached.
  RGMC_INLINE TileWork& WorkOf(std::int64_t tile) { return *this->TileTable[tile]; }

  /// The state of tile `tile`, made when growth first reaches it. Tiles are made only between
  /// parallel steps (a step reads the table, never writes it), so that a surface costs the same
  /// in any volume: only the tiles it reaches are ever made, visited or freed. The states are
  /// kept in a deque, so making one moves none: references to others stay valid across it.
  TileWork& MakeWork(std::int64_t tile)
  {
    TileWork*& w = this->TileTable[tile];
    if (!w)
    {
      this->Reached.emplace_back();
      w = &this->Reached.back();
    }
    return *w;
  }

  static constexpr int TileCubes = GrowthTileCubes;
  static constexpr int PrefetchAhead = 8; // queued nodes between a prefetch and the expansion
  static constexpr int TileWords = TileCubes * TileCubes * TileCubes / 64; // found-bit words

  RGMC_INLINE std::int64_t TileOf(int i, int j, int k) const
  {
    const CellBox& b = this->Volume.Owned.Mine();
    constexpr int s = GrowthTileBits;
    return ((i - b.Lo[0]) >> s) +
      this->Tiles[0] * (((j - b.Lo[1]) >> s) + std::int64_t(this->Tiles[1]) * ((k - b.Lo[2]) >> s));
  }

  /// The found-bit of an owned cube: tile, then the cube in the tile in i, j, k order (so a
  /// step to a neighbour in the tile is a fixed offset: 1, 32, 1024).
  RGMC_INLINE std::int64_t CubeBit(int i, int j, int k) const
  {
    const CellBox& b = this->Volume.Owned.Mine();
    const int x = i - b.Lo[0], y = j - b.Lo[1], z = k - b.Lo[2];
    constexpr int m = TileCubes - 1;
    return this->TileOf(i, j, k) * (TileWords * 64) + (x & m) +
      TileCubes * ((y & m) + TileCubes * (z & m));
  }

  RGMC_INLINE bool AllFound(std::int64_t bit) const
  {
    return (this->Visited[bit >> 6] >> (bit & 63)) & 1u;
  }
  void SetAllFound(std::int64_t bit) { this->Visited[bit >> 6] |= std::uint64_t(1) << (bit & 63); }

  RGMC_INLINE bool NodeFound(TileWork& w, std::int64_t bit, int node, int numNodes) const
  {
    if (this->AllFound(bit))
    {
      return true;
    }
    if (numNodes == 1 || !w.FoundNodesOfCube)
    {
      return false;
    }
    const std::int32_t* mask = w.FoundNodesOfCube->Find(bit);
    return mask && ((*mask >> node) & 1);
  }

  /// Records node `node` of cube (i, j, k) found and queues it in its tile. Cubes with one node
  /// use only the bit per cube; cubes with several remember which were found.
  void Record(TileWork& w, int i, int j, int k, std::int64_t bit, const CubeSamples& st, int node,
    int numNodes, int comp)
  {
    if (numNodes == 1)
    {
      this->SetAllFound(bit);
    }
    else
    {
      if (!w.FoundNodesOfCube)
      {
        w.FoundNodesOfCube.reset(new KeyMap(64));
      }
      bool inserted;
      std::int32_t& mask = w.FoundNodesOfCube->FindOrInsert(bit, 0, inserted);
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
    w.Queue.push_back(SurfaceNode{ i, j, k, comp, static_cast<std::uint8_t>(st.Case),
      static_cast<std::uint8_t>(node), st.Degenerate });
  }

  /// Records the nodes of owned cube (i, j, k) that use vertex `key` (on the cube's edge
  /// `edge`; -1 for a grid-point key). `seen` is set when such a node was found before.
  RGMC_INLINE void Visit(
    TileWork& w, int i, int j, int k, std::int64_t key, int edge, int comp, bool* seen)
  {
    const std::int64_t bit = this->CubeBit(i, j, k);
    if (this->AllFound(bit) && !seen)
    {
      return;
    }
    this->VisitUnfound(w, i, j, k, bit, key, edge, comp, seen);
  }

  /// Visit, for a cube whose found-bit `bit` is known and was checked (unless `seen`).
  RGMC_NOINLINE void VisitUnfound(TileWork& w, int i, int j, int k, std::int64_t bit,
    std::int64_t key, int edge, int comp, bool* seen)
  {
    CubeSamples st;
    ++w.Examined;
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
      if (this->NodeFound(w, bit, node, numNodes))
      {
        if (seen)
        {
          *seen = true;
        }
        continue;
      }
      this->Record(w, i, j, k, bit, st, node, numNodes, comp);
    }
  }

  /// Visits the neighbours of one node of tile `tile`: every other cube that has one of its
  /// vertices. Cubes of the tile are visited now; owned cubes of other tiles get a crossing
  /// (unless `keepInTile`: then they are left to their own tile's scan).
  void Expand(std::int64_t tile, const SurfaceNode& n, bool keepInTile)
  {
    if (!n.Degenerate && this->Volume.Owned.Overlaps().empty())
    {
      this->ExpandByTable(tile, n, keepInTile);
      return;
    }
    TileWork& w = this->WorkOf(tile);
    CubeSamples st;
    if (!this->Volume.NodeSamples(n, st))
    {
      return;
    }
    CubeSurface surface;
    this->Volume.Describe(n.I, n.J, n.K, st, surface);
    const Ownership& own = this->Volume.Owned;
    surface.ForEachVertex(n.Node,
      [&](const SurfaceVertex& v)
      {
        ForCubesAround(v.Point, v.Axis,
          [&](int i, int j, int k, int edge)
          {
            if (i == n.I && j == n.J && k == n.K)
            {
              return;
            }
            const bool owned = own.Owns(i, j, k);
            if (owned && this->TileOf(i, j, k) == tile)
            {
              this->Visit(w, i, j, k, v.Key, edge, n.Component, nullptr);
            }
            else
            {
              this->StepOutOfTile(w, i, j, k, v.Key, edge, n.Component, owned, keepInTile);
            }
          });
      });
  }

  /// A step of component `comp` to cube (i, j, k) for vertex `key` (on the cube's edge `edge`)
  /// that leaves the expanding node's tile: to another tile of this rank (`owned`), a crossing
  /// (unless `keepInTile`); to another rank's cube, a departure (when CrossRanks); outside the
  /// volume, nothing.
  RGMC_INLINE void StepOutOfTile(TileWork& w, int i, int j, int k, std::int64_t key, int edge,
    int comp, bool owned, bool keepInTile)
  {
    if (!owned)
    {
      // Owned cubes lie inside the volume; one of another rank is a departure.
      if (this->CrossRanks && this->Volume.GridOf.HasCell(i, j, k))
      {
        w.Departures.push_back(Departure{ key, comp });
      }
    }
    else if (!keepInTile)
    {
      w.Outbox.push_back(Crossing{ key, i, j, k, comp, static_cast<std::int8_t>(edge) });
    }
  }

  /// Expand for a node of a cube without a degenerate sample, on a rank whose owned cubes are
  /// its box (the common case): the same steps in the same order, taken from the node's sheet
  /// edges and TileStepTable. A neighbour in the node's tile (the step's needs within the
  /// node's room) is found at a fixed offset of the node's found-bit, the vertex's key made only
  /// when the neighbour is visited; one outside it (another tile's, or no owned cube) is handled
  /// as Expand does.
  RGMC_INLINE void ExpandByTable(std::int64_t tile, const SurfaceNode& n, bool keepInTile)
  {
    TileWork& w = this->WorkOf(tile);
    const std::int64_t bit = this->CubeBit(n.I, n.J, n.K);
    const int c[3] = { n.I, n.J, n.K };
    const unsigned room = TileRoom(c, this->Volume.Owned.Mine());
    for (unsigned edges = this->Volume.Table[n.Case].SheetEdges[n.Node]; edges; edges &= edges - 1)
    {
      const int e = __builtin_ctz(edges);
      auto key = [&]()
      {
        const int* p = CornerOffset[EdgeCorners[e][0]];
        return this->Volume.GridOf.EdgeKey(n.I + p[0], n.J + p[1], n.K + p[2], CubeEdgeAxis[e]);
      };
      for (const TileStep& step : TileStepTable[e])
      {
        if ((step.Needs & ~room) == 0)
        {
          const std::int64_t to = bit + step.BitOffset;
          if (!this->AllFound(to))
          {
            this->VisitUnfound(w, n.I + step.Offset[0], n.J + step.Offset[1], n.K + step.Offset[2],
              to, key(), step.Edge, n.Component, nullptr);
          }
        }
        else
        {
          const int i = n.I + step.Offset[0], j = n.J + step.Offset[1], k = n.K + step.Offset[2];
          this->StepOutOfTile(w, i, j, k, key(), step.Edge, n.Component,
            this->Volume.Owned.Owns(i, j, k), keepInTile);
        }
      }
    }
  }

  /// Expands tile `tile`'s queue from `head` on, inside the tile.
  void ExpandQueue(std::int64_t tile, std::size_t head, bool keepInTile)
  {
    TileWork& w = this->WorkOf(tile);
    for (; head < w.Queue.size() && !this->Volume.Stopped(); ++head)
    {
      if (head + PrefetchAhead < w.Queue.size())
      {
        // The samples of the cubes around a node soon expanded (those its edges touch).
        const SurfaceNode& ahead = w.Queue[head + PrefetchAhead];
        this->Volume.PrefetchAround(ahead.I, ahead.J, ahead.K);
      }
      const SurfaceNode n = w.Queue[head];
      this->Expand(tile, n, keepInTile);
    }
  }

  /// Visits, for component `comp`, the owned cubes around vertex `key` (at grid point p; axis
  /// < 0 for a grid-point key); appends to `active` each tile whose queue grew (duplicates
  /// possible).
  void VisitAround(std::int64_t key, const int p[3], int axis, int comp, bool* seen,
    std::vector<std::int64_t>& active)
  {
    ForCubesAround(p, axis,
      [&](int i, int j, int k, int edge)
      {
        if (!this->Volume.Owned.Owns(i, j, k))
        {
          return;
        }
        const std::int64_t tile = this->TileOf(i, j, k);
        TileWork& w = this->MakeWork(tile);
        const std::size_t before = w.Queue.size();
        this->Visit(w, i, j, k, key, edge, comp, seen);
        if (w.Queue.size() > before)
        {
          active.push_back(tile);
        }
      });
  }

  SampledVolume<Values>& Volume;
  ComponentSet& Components;
  std::int64_t Tiles[3] = { 0, 0, 0 }; // tiles along each axis of the owned box
  ZeroedArray<std::uint64_t> Visited;  // a bit per owned cube: its nodes were all found
  std::int64_t NumTiles = 0;           // tiles of the owned box (Tiles' product)
  ZeroedArray<TileWork*> TileTable;    // per tile: its state, null until growth reaches it
  std::deque<TileWork> Reached;        // the states of the tiles growth reached, in that order
};

} // namespace rgmc

#endif

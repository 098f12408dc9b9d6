// Growth: finds the surface nodes of the components that one rank extracts, without making any
// triangle. A breadth-first search over the surface graph from a node visits every other cube
// that contains one of the node's vertices (3 cubes around an edge, 7 around a grid point), so
// it reproduces exactly the connectivity of vtkMarchingCubes followed by
// vtkPolyDataConnectivityFilter while touching only cubes the surface passes through.
//
// Threads. The owned cubes are cut into tiles of 32^3 (a tile's found-bits are one 4 KiB page).
// A tile is searched by one task at a time, which alone writes its bits, so tasks never share
// state. Growth goes in rounds: in a round every tile with work searches, inside itself, from
// the crossings it received (a vertex and the cube to visit), and hands each step into another
// tile to that tile as a crossing for the next round - the protocol ranks use between pieces,
// inside one rank. A tile's work in a round depends only on its crossings, taken in the order
// of the tiles that sent them, so the nodes found and their order are the same for any number
// of threads. A tile posts its crossings at the end of its round, grouped by the neighbour they
// go to, and each neighbour reads its group in the next round: the exchange between rounds is
// done by the tiles themselves, on threads. The full scan (All and Largest modes) searches each
// tile on its own, crossings dropped: a component that spans tiles gets one label per tile, and
// extraction joins them through their shared vertices, as it joins components across ranks.
//
// Ranks. With CrossRanks set, a step into a cube another rank owns is kept as a departure (the
// vertex and the component that reached it); the VTK layer sends departures to the cubes'
// owners, which grow on from them (GrowFromArrivals): the same protocol again, between ranks,
// in rounds until no rank has anything new.
#ifndef rgmcGrowth_h
#define rgmcGrowth_h

#include "rgmcBuffer.h"
#include "rgmcCubeSurface.h"
#include "rgmcKeyMap.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <deque>
#include <limits>
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
constexpr int GrowthTileCubes = 32;

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

template <typename Values>
class SurfaceGrowth
{
public:
  SurfaceGrowth(SampledVolume<Values>& volume, ComponentSet& components)
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

  /// The nodes found: by round, then by tile, then in the order each tile found them.
  NodeList& Nodes() { return this->Found; }

  /// Whether steps into cubes of other ranks are kept as departures (seeded growth on several
  /// ranks) instead of dropped.
  bool CrossRanks = false;

  /// The departures since the last call, in the order found (by round, then tile); duplicates
  /// are possible. Leaves the list empty.
  std::vector<Departure> TakeDepartures()
  {
    std::vector<Departure> taken;
    taken.swap(this->Departures);
    return taken;
  }

  /// Growth from seeds and arrivals stops after expanding about `budget` nodes (at the end of a
  /// round of tiles) and goes on at the next call of Continue: so a rank can hand departures
  /// to its neighbours while its part of a large structure is still growing. Unlimited by
  /// default.
  void SetBudget(std::int64_t budget) { this->Budget = budget; }
  /// Whether growth stopped on its budget with work left.
  bool Busy() const { return !this->Pending.empty(); }
  /// Goes on with the work left (another budget's worth).
  void Continue() { this->Rounds({}); }

  /// How many grid points of the faces shared with other ranks GrowBoundary read.
  std::int64_t PlanePointsRead() const { return this->PlanePoints; }

  /// How many cubes growth examined (read the samples of) on this rank so far.
  std::int64_t CubesExamined() const
  {
    std::int64_t total = this->ScannedCubes;
    for (const TileWork& w : this->Made)
    {
      total += w.Examined;
    }
    return total;
  }

  /// How many tiles growth has reached so far: those whose state was made (every tile of the
  /// piece after GrowAll; after seeded growth, the tiles of the nodes found).
  std::int64_t TilesReached() const { return static_cast<std::int64_t>(this->Made.size()); }

  /// How many crossings tiles sent each other, and how many the tiles they went to read (the
  /// same, once no growth is pending: each crossing is read once).
  std::int64_t CrossingsPosted() const
  {
    std::int64_t total = 0;
    for (const TileWork& w : this->Made)
    {
      total += w.Posted;
    }
    return total;
  }
  std::int64_t CrossingsRead() const
  {
    std::int64_t total = 0;
    for (const TileWork& w : this->Made)
    {
      total += w.Read;
    }
    return total;
  }

  /// Grows on from vertices that other ranks' growth reached: every arrival label becomes a new
  /// seeded component (reachable from a seed), grown from the nodes of this rank's cubes that
  /// use the arrival's vertex and were not found yet. Arrivals are taken in the order given.
  void GrowFromArrivals(const std::vector<Arrival>& arrivals, int numLabels)
  {
    if (this->NumTiles == 0)
    {
      return;
    }
    if (arrivals.empty())
    {
      this->Rounds({}); // the work left pending, if any
      return;
    }
    const int first = this->Components.Size();
    for (int l = 0; l < numLabels; ++l)
    {
      this->Components.Add(true);
    }
    std::vector<std::int64_t> active;
    for (const Arrival& a : arrivals)
    {
      int p[3], axis;
      this->Volume.GridOf.Decode(a.Key, p, axis);
      this->VisitAround(a.Key, p, axis, first + a.Label, nullptr, active);
    }
    std::sort(active.begin(), active.end());
    active.erase(std::unique(active.begin(), active.end()), active.end());
    this->Rounds(active);
  }

  /// Grows, as a new seeded component, the component that contains the vertex `key`, from the
  /// nodes of this piece that use it. Returns the new component; -1 when no cube this piece owns
  /// has the vertex; -2 when its nodes were already found (by an earlier seed: seeds must be
  /// grown before GrowBoundary).
  int GrowFromKey(std::int64_t key)
  {
    int p[3], axis;
    this->Volume.GridOf.Decode(key, p, axis);
    bool seen = false;
    const int comp = this->GrowFrom(key, p, axis, true, &seen);
    return comp >= 0 ? comp : (seen ? -2 : -1);
  }

  /// Finds every component that has a node in an owned cube (a full scan: the "All" and
  /// "Largest" modes). Each tile is scanned on its own; components are labelled per tile.
  void GrowAll()
  {
    if (this->NumTiles == 0)
    {
      return;
    }
    const std::int64_t numTiles = this->NumTiles;
    for (std::int64_t tile = 0; tile < numTiles; ++tile)
    {
      this->MakeWork(tile); // the scan reads every tile
    }
    std::vector<int> tileComponents(static_cast<std::size_t>(numTiles), 0);
    // Tiles in slabs of tiles along z, for the progress reported between them.
    const std::int64_t perSlab = this->Tiles[0] * this->Tiles[1];
    for (std::int64_t z = 0; z < this->Tiles[2] && !this->Volume.Stopped(); ++z)
    {
      this->Volume.Parallel(perSlab,
        [&](std::int64_t n)
        {
          const std::int64_t tile = z * perSlab + n;
          tileComponents[tile] = this->ScanTile(tile);
        });
      this->Volume.Report(0.5 * (z + 1) / this->Tiles[2]);
    }
    if (this->Volume.Stopped())
    {
      return;
    }
    // Tile-local component labels become this rank's: tile by tile, in tile order.
    for (std::int64_t tile = 0; tile < numTiles; ++tile)
    {
      const int first = this->Components.Size();
      for (int c = 0; c < tileComponents[tile]; ++c)
      {
        this->Components.Add(false);
      }
      TileWork& w = this->WorkOf(tile);
      for (SurfaceNode& n : w.Queue)
      {
        n.Component += first;
      }
      this->Found.Append(w.Queue);
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
    if (this->NumTiles == 0)
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
      this->ScanRegion(lower.Grown(1).Intersect(box));
    }
  }

private:
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
    std::int64_t Read = 0;         // crossings this tile was sent and read
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
      this->Made.emplace_back();
      w = &this->Made.back();
    }
    return *w;
  }

  static constexpr int TileCubes = GrowthTileCubes;
  static constexpr int PrefetchAhead = 8; // queued nodes between a prefetch and the expansion
  static constexpr int TileWords = 512;   // 64-bit words of found-bits in a tile (32^3 bits)

  RGMC_INLINE std::int64_t TileOf(int i, int j, int k) const
  {
    const CellBox& b = this->Volume.Owned.Mine();
    return ((i - b.Lo[0]) >> 5) +
      this->Tiles[0] * (((j - b.Lo[1]) >> 5) + std::int64_t(this->Tiles[1]) * ((k - b.Lo[2]) >> 5));
  }

  /// The found-bit of an owned cube: tile, then the cube in the tile in i, j, k order (so a
  /// step to a neighbour in the tile is a fixed offset: 1, 32, 1024).
  RGMC_INLINE std::int64_t CubeBit(int i, int j, int k) const
  {
    const CellBox& b = this->Volume.Owned.Mine();
    const int x = i - b.Lo[0], y = j - b.Lo[1], z = k - b.Lo[2];
    return this->TileOf(i, j, k) * (TileWords * 64) + (x & 31) + 32 * ((y & 31) + 32 * (z & 31));
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

  /// Grows, as a new component, from the nodes that use vertex `key` (at grid point p; axis < 0
  /// for a grid-point key) unless they were all found; rounds until no tile has work. Returns
  /// the component, or -1 when nothing new was found (`seen` says whether it was found before).
  int GrowFrom(std::int64_t key, const int p[3], int axis, bool seeded, bool* seen)
  {
    if (this->NumTiles == 0)
    {
      return -1;
    }
    const int comp = this->Components.Add(seeded);
    std::vector<std::int64_t> active;
    this->VisitAround(key, p, axis, comp, seen, active);
    const bool any = !active.empty();
    if (!any)
    {
      this->Components.RemoveLast();
      return -1;
    }
    std::sort(active.begin(), active.end());
    active.erase(std::unique(active.begin(), active.end()), active.end());
    this->Rounds(active);
    return comp;
  }

  /// Searches the active tiles (sorted; their queues hold the nodes found so far), with the
  /// tiles left pending by an earlier call, in rounds until no crossing is left or Budget nodes
  /// were expanded in this call (then the tiles with crossings stay pending), appending the
  /// nodes found to Found.
  void Rounds(std::vector<std::int64_t> active)
  {
    if (!this->Pending.empty())
    {
      active.insert(active.end(), this->Pending.begin(), this->Pending.end());
      std::sort(active.begin(), active.end());
      active.erase(std::unique(active.begin(), active.end()), active.end());
      this->Pending.clear();
    }
    const std::int64_t start = this->NodesExpanded;
    while (!active.empty() && !this->Volume.Stopped())
    {
      if (this->NodesExpanded - start >= this->Budget)
      {
        this->Pending.swap(active); // the rest in a later call
        return;
      }
      const std::int64_t round = ++this->Round;
      this->Volume.Parallel(static_cast<std::int64_t>(active.size()),
        [&](std::int64_t n)
        {
          const std::int64_t tile = active[n];
          this->ReadMail(tile, round - 1);
          this->ExpandQueue(tile, 0, false);
          this->PostMail(tile, round);
        });
      if (this->Volume.Stopped())
      {
        return;
      }
      // The round's nodes, tile by tile; the tiles its mail goes to.
      std::vector<std::int64_t> next;
      for (const std::int64_t tile : active)
      {
        TileWork& w = this->WorkOf(tile);
        this->NodesExpanded += static_cast<std::int64_t>(w.Queue.size());
        this->Found.Append(w.Queue); // the queue itself, not a copy
        this->Departures.insert(this->Departures.end(), w.Departures.begin(), w.Departures.end());
        w.Departures = std::vector<Departure>();
        const Mail* mail = w.Sent[round & 1].get();
        if (!mail || mail->Round != round)
        {
          continue;
        }
        for (int d = 0; d < 27; ++d)
        {
          const std::int64_t to = tile + this->TileOffset(d);
          if (mail->Start[d + 1] > mail->Start[d])
          {
            TileWork& receiver = this->MakeWork(to);
            if (receiver.MailRound != round)
            {
              receiver.MailRound = round;
              next.push_back(to);
            }
          }
        }
      }
      // The mail of the round before was read in this one.
      for (const std::int64_t tile : this->LastSenders)
      {
        this->WorkOf(tile).Sent[(round - 1) & 1].reset();
      }
      this->LastSenders = active;
      std::sort(next.begin(), next.end());
      active.swap(next);
      // The surface's size is unknown while it grows: an estimate that approaches 1.
      const double done = static_cast<double>(this->NodesExpanded);
      this->Volume.Report(0.5 * done / (done + (1 << 20)));
    }
  }

  /// The position of tile `tile` among the tiles, along each axis.
  void TileCoordinates(std::int64_t tile, std::int64_t t[3]) const
  {
    t[0] = tile % this->Tiles[0];
    t[1] = (tile / this->Tiles[0]) % this->Tiles[1];
    t[2] = tile / (this->Tiles[0] * this->Tiles[1]);
  }

  /// The offset of the neighbouring tile in direction d (see Mail).
  std::int64_t TileOffset(int d) const
  {
    return (d % 3 - 1) + this->Tiles[0] * ((d / 3 % 3 - 1) + this->Tiles[1] * (d / 9 - 1));
  }

  /// Visits the crossings tile `tile` was sent in round `round`: from its neighbours in tile
  /// order, each one's in the order sent.
  void ReadMail(std::int64_t tile, std::int64_t round)
  {
    TileWork& w = this->WorkOf(tile);
    std::int64_t t[3];
    this->TileCoordinates(tile, t);
    for (int d = 0; d < 27; ++d)
    {
      const int o[3] = { d % 3 - 1, d / 3 % 3 - 1, d / 9 - 1 };
      if (d == 13 || t[0] + o[0] < 0 || t[0] + o[0] >= this->Tiles[0] || t[1] + o[1] < 0 ||
        t[1] + o[1] >= this->Tiles[1] || t[2] + o[2] < 0 || t[2] + o[2] >= this->Tiles[2])
      {
        continue;
      }
      const TileWork* sender = this->TileTable[tile + this->TileOffset(d)];
      const Mail* mail = sender ? sender->Sent[round & 1].get() : nullptr;
      if (!mail || mail->Round != round)
      {
        continue;
      }
      const int back = 26 - d; // the direction from the sender to this tile
      w.Read += mail->Start[back + 1] - mail->Start[back];
      for (std::int32_t m = mail->Start[back]; m < mail->Start[back + 1]; ++m)
      {
        const Crossing& c = mail->Items[m];
        this->Visit(w, c.I, c.J, c.K, c.Key, c.Edge, c.Component, nullptr);
      }
    }
  }

  /// Posts the crossings tile `tile` sent in round `round` as its mail, grouped by the tile
  /// they go to (a stable counting sort).
  void PostMail(std::int64_t tile, std::int64_t round)
  {
    TileWork& w = this->WorkOf(tile);
    if (w.Outbox.empty())
    {
      return;
    }
    const CellBox& b = this->Volume.Owned.Mine();
    std::int64_t t[3];
    this->TileCoordinates(tile, t);
    auto direction = [&](const Crossing& c)
    {
      return static_cast<int>((((c.I - b.Lo[0]) >> 5) - t[0] + 1) +
        3 * (((c.J - b.Lo[1]) >> 5) - t[1] + 1) + 9 * (((c.K - b.Lo[2]) >> 5) - t[2] + 1));
    };
    w.Posted += static_cast<std::int64_t>(w.Outbox.size());
    std::unique_ptr<Mail>& slot = w.Sent[round & 1];
    if (!slot)
    {
      slot.reset(new Mail);
    }
    Mail& mail = *slot;
    mail.Round = round;
    std::array<std::int32_t, 28> next{};
    for (const Crossing& c : w.Outbox)
    {
      ++next[direction(c) + 1];
    }
    for (int d = 0; d < 27; ++d)
    {
      next[d + 1] += next[d];
    }
    mail.Start = next;
    mail.Items.resize_for_overwrite(w.Outbox.size());
    for (const Crossing& c : w.Outbox)
    {
      mail.Items[next[direction(c)]++] = c;
    }
    w.Outbox = std::vector<Crossing>();
  }

  /// Grows from every vertex on the plane of grid points p[axis] = `plane` of this rank's box.
  void GrowFromPlane(int axis, int plane)
  {
    SampledVolume<Values>& volume = this->Volume;
    const CellBox& box = volume.Owned.Mine();
    const Grid& grid = volume.GridOf;
    const double c = volume.Options.Isovalue;
    const int u = axis == 0 ? 1 : 0, v = axis == 2 ? 1 : 2;
    int p[3];
    p[axis] = plane;
    this->PlanePoints += std::int64_t(box.Hi[u] - box.Lo[u] + 2) * (box.Hi[v] - box.Lo[v] + 2);
    for (p[v] = box.Lo[v]; p[v] <= box.Hi[v] + 1 && !volume.Stopped(); ++p[v])
    {
      for (p[u] = box.Lo[u]; p[u] <= box.Hi[u] + 1 && !volume.Stopped(); ++p[u])
      {
        const double s = volume.Read(p[0], p[1], p[2]);
        if (s == c)
        {
          this->GrowFrom(grid.PointKey(p[0], p[1], p[2]), p, -1, false, nullptr);
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
            this->GrowFrom(grid.EdgeKey(p[0], p[1], p[2], along), p, along, false, nullptr);
          }
        }
      }
    }
  }

  /// The cubes of tile `tile` (within the owned box), in k, j, i order.
  CellBox TileBox(std::int64_t tile) const
  {
    const CellBox& b = this->Volume.Owned.Mine();
    std::int64_t t[3];
    this->TileCoordinates(tile, t);
    CellBox box;
    for (int a = 0; a < 3; ++a)
    {
      box.Lo[a] = b.Lo[a] + static_cast<int>(t[a]) * TileCubes;
      box.Hi[a] = std::min(b.Hi[a], box.Lo[a] + TileCubes - 1);
    }
    return box;
  }

  /// Finds every node of tile `tile`, each unfound one starting a new component (numbered from
  /// 0 in the tile) grown inside the tile only, in k, j, i order of the cubes. Returns the
  /// number of components.
  ///
  /// Most cubes of a volume have no surface: the tile's grid points are classified first, a row
  /// at a time (ClassifyRow: each sample read once), and only the cubes whose corners are not
  /// all on one side of the isovalue (cases other than 0 and 255), or that touch a NaN sample
  /// (for Evaluate to report it), are evaluated one by one.
  int ScanTile(std::int64_t tile)
  {
    SampledVolume<Values>& volume = this->Volume;
    TileWork& w = this->WorkOf(tile);
    const CellBox box = this->TileBox(tile);
    const bool holes = !volume.Owned.Overlaps().empty();
    const int cubesPerRow = box.Hi[0] - box.Lo[0] + 1; // at most TileCubes
    const int pointsPerRow = cubesPerRow + 1;
    const int rows = box.Hi[1] - box.Lo[1] + 2;
    const std::uint64_t rowCubes = (std::uint64_t(1) << cubesPerRow) - 1;
    // The classified rows of grid points of the planes below and above the current slab.
    std::uint64_t above[2][TileCubes + 1], notNumber[2][TileCubes + 1];
    auto classifyPlane = [&](int side, int k)
    {
      for (int r = 0; r < rows; ++r)
      {
        volume.ClassifyRow(
          box.Lo[0], pointsPerRow, box.Lo[1] + r, k, above[side][r], notNumber[side][r]);
      }
    };
    classifyPlane(0, box.Lo[2]);
    CubeSamples st;
    CubeSurface surface;
    int components = 0;
    for (int k = box.Lo[2], lower = 0; k <= box.Hi[2] && !volume.Stopped(); ++k, lower ^= 1)
    {
      const int upper = lower ^ 1;
      classifyPlane(upper, k + 1);
      for (int j = box.Lo[1]; j <= box.Hi[1] && !volume.Stopped(); ++j)
      {
        const int r = j - box.Lo[1];
        // A cube is cut when its 8 corners are neither all above nor all below; the 4 rows of
        // points around the row of cubes, then each cube's two ends along i.
        std::uint64_t all =
          above[lower][r] & above[lower][r + 1] & above[upper][r] & above[upper][r + 1];
        std::uint64_t any =
          above[lower][r] | above[lower][r + 1] | above[upper][r] | above[upper][r + 1];
        std::uint64_t nan = notNumber[lower][r] | notNumber[lower][r + 1] | notNumber[upper][r] |
          notNumber[upper][r + 1];
        all &= all >> 1;
        any |= any >> 1;
        nan |= nan >> 1;
        std::uint64_t candidates = ((any & ~all) | nan) & rowCubes;
        // The cubes skipped were read too (examined), as long as they are this rank's.
        if (!holes)
        {
          w.Examined += cubesPerRow - __builtin_popcountll(candidates);
        }
        else
        {
          for (std::uint64_t rest = rowCubes & ~candidates; rest; rest &= rest - 1)
          {
            w.Examined += volume.Owned.Owns(box.Lo[0] + __builtin_ctzll(rest), j, k);
          }
        }
        for (; candidates; candidates &= candidates - 1)
        {
          const int i = box.Lo[0] + __builtin_ctzll(candidates);
          if (!volume.Owned.Owns(i, j, k))
          {
            continue;
          }
          const std::int64_t bit = this->CubeBit(i, j, k);
          if (this->AllFound(bit))
          {
            continue;
          }
          ++w.Examined;
          if (!volume.Evaluate(i, j, k, st) || st.Case == 0 || st.Case == 255)
          {
            continue;
          }
          volume.Describe(i, j, k, st, surface);
          const int numNodes = surface.NumberOfNodes();
          for (int node = 0; node < numNodes; ++node)
          {
            if (!this->NodeFound(w, bit, node, numNodes))
            {
              const std::size_t head = w.Queue.size();
              this->Record(w, i, j, k, bit, st, node, numNodes, components++);
              this->ExpandQueue(tile, head, true);
            }
          }
        }
      }
    }
    return components;
  }

  /// Starts a new component, grown across tiles, from every unfound node of the owned cubes in
  /// `region` (one at a time, on this thread's schedule of rounds).
  void ScanRegion(const CellBox& region)
  {
    SampledVolume<Values>& volume = this->Volume;
    CubeSamples st;
    CubeSurface surface;
    for (int k = region.Lo[2]; k <= region.Hi[2] && !volume.Stopped(); ++k)
    {
      for (int j = region.Lo[1]; j <= region.Hi[1]; ++j)
      {
        for (int i = region.Lo[0]; i <= region.Hi[0] && !volume.Stopped(); ++i)
        {
          if (!volume.Owned.Owns(i, j, k))
          {
            continue;
          }
          const std::int64_t bit = this->CubeBit(i, j, k);
          if (this->AllFound(bit))
          {
            continue;
          }
          ++this->ScannedCubes;
          if (!volume.Evaluate(i, j, k, st) || st.Case == 0 || st.Case == 255)
          {
            continue;
          }
          volume.Describe(i, j, k, st, surface);
          const int numNodes = surface.NumberOfNodes();
          const std::int64_t tile = this->TileOf(i, j, k);
          TileWork& w = this->MakeWork(tile);
          for (int node = 0; node < numNodes; ++node)
          {
            if (!this->NodeFound(w, bit, node, numNodes))
            {
              this->Record(w, i, j, k, bit, st, node, numNodes, this->Components.Add(false));
              this->Rounds({ tile });
            }
          }
        }
      }
    }
  }

  SampledVolume<Values>& Volume;
  ComponentSet& Components;
  std::int64_t Tiles[3] = { 0, 0, 0 }; // tiles along each axis of the owned box
  ZeroedArray<std::uint64_t> Visited;  // a bit per owned cube: its nodes were all found
  std::int64_t NumTiles = 0;           // tiles of the owned box (Tiles' product)
  ZeroedArray<TileWork*> TileTable;    // per tile: its state, null until growth reaches it
  std::deque<TileWork> Made;           // the tiles' states, in the order made
  NodeList Found;
  std::vector<Departure> Departures;
  std::vector<std::int64_t> Pending;     // tiles with crossings left by the budget, sorted
  std::int64_t Round = 0;                // rounds of tiles searched so far
  std::vector<std::int64_t> LastSenders; // the tiles searched in the last round
  std::int64_t Budget = std::numeric_limits<std::int64_t>::max();
  std::int64_t NodesExpanded = 0;
  std::int64_t ScannedCubes = 0; // cubes read by ScanRegion
  std::int64_t PlanePoints = 0;  // grid points read by GrowFromPlane
};

} // namespace rgmc

#endif

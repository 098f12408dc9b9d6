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

#include "rgmcNodeVisits.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <deque>
#include <limits>
#include <memory>
#include <vector>

namespace rgmc
{

/// Growth's scheduler: the tiles that search in each round, on threads, and the crossings they
/// hand each other between rounds; the full scan of tiles and of the faces shared with other
/// ranks. The visits of nodes inside a tile are NodeVisits'.
template <typename Values>
class SurfaceGrowth : public NodeVisits<Values>
{
  using Base = NodeVisits<Values>;
  using Crossing = typename Base::Crossing;
  using Mail = typename Base::Mail;
  using TileWork = typename Base::TileWork;
  using Base::TileCubes;

public:
  SurfaceGrowth(SampledVolume<Values>& volume, ComponentSet& components)
    : Base(volume, components)
  {
  }

  /// The nodes found: by round, then by tile, then in the order each tile found them.
  NodeList& Nodes() { return this->Found; }

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
    for (const TileWork& w : this->Reached)
    {
      total += w.Examined;
    }
    return total;
  }

  /// How many tiles growth has reached so far: those whose state was made (every tile of the
  /// piece after GrowAll; after seeded growth, the tiles of the nodes found).
  std::int64_t TilesReached() const { return static_cast<std::int64_t>(this->Reached.size()); }

  /// How many crossings tiles sent each other, and how many the tiles they went to read (the
  /// same, once no growth is pending: each crossing is read once).
  std::int64_t CrossingsPosted() const
  {
    std::int64_t total = 0;
    for (const TileWork& w : this->Reached)
    {
      total += w.Posted;
    }
    return total;
  }
  std::int64_t CrossingsRead() const
  {
    std::int64_t total = 0;
    for (const TileWork& w : this->Reached)
    {
      total += w.Received;
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
    // Tiles in steps of whole slabs of tiles along z, at least ScanStepTiles a step: progress
    // between steps on large volumes, and on small ones few steps, each as long as its longest
    // tile (the tiles are independent: one step of them all would do, but report nothing).
    const std::int64_t perSlab = this->Tiles[0] * this->Tiles[1];
    const std::int64_t slabsPerStep = std::max<std::int64_t>(1, ScanStepTiles / perSlab);
    for (std::int64_t z = 0; z < this->Tiles[2] && !this->Volume.Stopped(); z += slabsPerStep)
    {
      const std::int64_t zEnd = std::min<std::int64_t>(this->Tiles[2], z + slabsPerStep);
      this->Volume.Parallel((zEnd - z) * perSlab,
        [&](std::int64_t n)
        {
          const std::int64_t tile = z * perSlab + n;
          tileComponents[tile] = this->ScanTile(tile);
        });
      this->Volume.Report(0.5 * zEnd / this->Tiles[2]);
    }
    if (this->Volume.Stopped())
    {
      return;
    }
    // Tile-local component labels become this rank's: tile by tile, in tile order (each tile's
    // first label counted here, its nodes relabelled on threads).
    std::vector<int> firstLabel(static_cast<std::size_t>(numTiles));
    for (std::int64_t tile = 0; tile < numTiles; ++tile)
    {
      firstLabel[tile] = this->Components.Size();
      for (int c = 0; c < tileComponents[tile]; ++c)
      {
        this->Components.Add(false);
      }
    }
    this->Volume.Parallel(numTiles,
      [&](std::int64_t tile)
      {
        for (SurfaceNode& n : this->WorkOf(tile).Queue)
        {
          n.Component += firstLabel[tile];
        }
      });
    for (std::int64_t tile = 0; tile < numTiles; ++tile)
    {
      this->Found.Append(this->WorkOf(tile).Queue);
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
  // The full scan: at least this many tiles a parallel step (4096: all of a 512^3 volume's).
  static constexpr std::int64_t ScanStepTiles = 4096;

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
      w.Received += mail->Start[back + 1] - mail->Start[back];
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
      constexpr int s = GrowthTileBits;
      return static_cast<int>((((c.I - b.Lo[0]) >> s) - t[0] + 1) +
        3 * (((c.J - b.Lo[1]) >> s) - t[1] + 1) + 9 * (((c.K - b.Lo[2]) >> s) - t[2] + 1));
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
        std::uint64_t candidates = CutCubes(above, notNumber, lower, upper, r) & rowCubes;
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
        this->ScanCandidates(tile, w, box.Lo[0], j, k, candidates, st, surface, components);
      }
    }
    return components;
  }

  /// The cubes of row r of a slab (bit b: the cube b along i) that the surface may cut: their 8
  /// corners (the 4 rows of points around the row of cubes, then each cube's two ends along i)
  /// neither all above nor all below the isovalue, or one of them NaN. Bits beyond the row's
  /// cubes are for the caller to drop.
  static RGMC_INLINE std::uint64_t CutCubes(const std::uint64_t (&above)[2][TileCubes + 1],
    const std::uint64_t (&notNumber)[2][TileCubes + 1], int lower, int upper, int r)
  {
    std::uint64_t all =
      above[lower][r] & above[lower][r + 1] & above[upper][r] & above[upper][r + 1];
    std::uint64_t any =
      above[lower][r] | above[lower][r + 1] | above[upper][r] | above[upper][r + 1];
    std::uint64_t nan =
      notNumber[lower][r] | notNumber[lower][r + 1] | notNumber[upper][r] | notNumber[upper][r + 1];
    all &= all >> 1;
    any |= any >> 1;
    nan |= nan >> 1;
    return (any & ~all) | nan;
  }

  /// ScanTile's search from the cubes `candidates` (bit b: cube (i0 + b, j, k)) of tile `tile`:
  /// each owned one not all found is evaluated, and each of its unfound nodes starts component
  /// `components` (then counted), grown inside the tile.
  RGMC_INLINE void ScanCandidates(std::int64_t tile, TileWork& w, int i0, int j, int k,
    std::uint64_t candidates, CubeSamples& st, CubeSurface& surface, int& components)
  {
    SampledVolume<Values>& volume = this->Volume;
    for (; candidates; candidates &= candidates - 1)
    {
      const int i = i0 + __builtin_ctzll(candidates);
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

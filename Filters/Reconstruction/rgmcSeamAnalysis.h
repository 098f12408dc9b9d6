// Seam Repair: the edges around seam vertices, the global checks, the smoothing stencils.
#ifndef rgmcSeamAnalysis_h
#define rgmcSeamAnalysis_h

#include "rgmcBuffer.h"
#include "rgmcSeamExchange.h"
#include "rgmcSmoothing.h"
#include "vtkRGMessage.h"
#include "vtkRGParallel.h"

#include "vtkMath.h"
#include "vtkSMPTools.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace rgmc
{
namespace seam
{

constexpr int EdgesTag = 48804, RequestTag = 48806;

/// A neighbour of a vertex, on the whole mesh: an edge at the vertex.
struct Neighbour
{
  vtkIdType Gid;
  int Uses;        // triangles on the edge
  vtkIdType Local; // index into this rank's vertices, or -1
  int Provider;    // a rank that holds it, when not local
  int Mask;        // when not local: the volume faces it lies on
  double X[3];     // when not local: its position
};

/// The global checks' counts: edges, boundary edges apart from those along the volume's
/// border, those, and non-manifold edges.
struct Checks
{
  vtkIdType Edges = 0, Boundary = 0, Border = 0, NonManifold = 0;
};

/// The seams analysed: the edges at each seam vertex gathered at its owner, the global checks'
/// counts, the smoothing stencils of owned vertices and the plan of the smoothing's exchanges.
template <typename T, typename I>
class SeamAnalysis : public SeamExchange<T, I>
{
public:
  using SeamExchange<T, I>::SeamExchange;

  /// The edges at each vertex (with repeats: once per triangle side), gathered at owners; the
  /// global checks' counts of this rank; smoothing stencils of owned vertices (when `stencils`)
  /// and the plan of the smoothing's exchanges. Two exchanges with the ranks that share
  /// vertices, three agreements.
  bool AnalyzeSeams(bool stencils, Checks& checks, std::string& problem)
  {
    std::vector<std::vector<vtkIdType>> toOwners(this->AllRanks.Size);
    if (!this->AllRanks.Step("list the edges at the seams", problem,
          [&]()
          {
            rgmc::SpanMark("seam analysis: corners");
            this->CornersAround(this->CornerOffsets, this->Corners);
            this->ListSeamEdges(toOwners);
          }))
    {
      return false;
    }
    const auto received = this->AllRanks.Exchange(toOwners, this->Partners, EdgesTag);
    std::vector<std::vector<vtkIdType>>().swap(toOwners);
    if (!this->AllRanks.Step("make the smoothing stencils", problem,
          [&]()
          {
            rgmc::SpanMark("seam analysis: stencils");
            this->AssembleNeighbourhoods(received, stencils, checks);
            this->NumberRemoteNeighbours();
            this->ListSharedVertices();
          }))
    {
      return false;
    }
    const auto asked = this->AllRanks.Exchange(this->RequestLists, this->Partners, RequestTag);
    std::vector<std::vector<vtkIdType>>().swap(this->RequestLists);
    return this->AllRanks.Step(
      "plan the smoothing's exchanges", problem, [&]() { this->ListProvided(asked); });
  }

protected:
  rgmc::HeapOverwriteVector<I> Owned; // the vertices this rank moves, one stencil row each
  rgmc::Stencils<I> Stencil;

  /// Per vertex, the order in which the normals sum its triangles when OrientedFanRow found
  /// them an oriented fan of at most MaxOrderedFan: 4 bits a place, each the corner's index in
  /// the vertex's corner list (SeamNormals' order, found here from the neighbours' ranks
  /// without looking the gids up again); NoFanOrder for any other vertex. Written by
  /// OrientedFanRow, each vertex by one thread; released with the normals.
  static constexpr int MaxOrderedFan = 8;
  static constexpr std::uint32_t NoFanOrder = ~std::uint32_t(0);
  mutable rgmc::OverwriteVector<std::uint32_t> FanOrder;

private:
  /// A neighbour held elsewhere, until the remote slots are numbered.
  struct Pending
  {
    vtkIdType Gid;
    int Provider;
    double X[3];
  };

  /// The edges that other ranks sent to this owner, read in order.
  struct ReceivedEdges
  {
    const std::vector<std::vector<vtkIdType>>& FromRank;
    std::vector<std::size_t> Cursor; // per rank
  };

  /// Edges at shared vertices go to their owners (shared vertices in gid order: each owner
  /// receives them in its own order): per vertex, its gid, its number of edges, and per edge
  /// the neighbour's gid, the edge's triangles here, the neighbour's volume faces and position.
  void ListSeamEdges(std::vector<std::vector<vtkIdType>>& toOwners)
  {
    for (std::size_t i = 0; i < this->Numbering.SharedVertex.size(); ++i)
    {
      const int owner = this->Numbering.SharedOwner[i];
      if (owner == this->AllRanks.Rank)
      {
        continue;
      }
      const vtkIdType v = this->Numbering.SharedVertex[i];
      this->Around.clear();
      this->LocalNeighbours(v, this->Around);
      rgmc::MessageWriter out(toOwners[owner]);
      out.Int(this->Numbering.Gid[v]).Int(static_cast<std::int64_t>(this->Around.size()));
      for (const Neighbour& nb : this->Around)
      {
        const T* x = this->Positions + 3 * nb.Local;
        out.Int(nb.Gid).Int(nb.Uses).Int(this->MaskOf(nb.Local));
        out.Real(static_cast<double>(x[0]))
          .Real(static_cast<double>(x[1]))
          .Real(static_cast<double>(x[2]));
      }
    }
  }

  /// Every vertex this rank owns, in gid order: its whole neighbourhood, its edges in the
  /// checks, its stencil row. Then the corner lists are released, unless the normals
  /// will need them (`stencils`: the surface is smoothed) and they are 32-bit.
  void AssembleNeighbourhoods(
    const std::vector<std::vector<vtkIdType>>& received, bool stencils, Checks& checks)
  {
    ReceivedEdges edges{ received, std::vector<std::size_t>(this->AllRanks.Size, 0) };
    this->CosEdgeAngle = std::cos(vtkMath::RadiansFromDegrees(15.0));
    if (stencils)
    {
      this->Owned.reserve(static_cast<std::size_t>(this->NumVertices));
      this->Stencil.Offsets.reserve(static_cast<std::size_t>(this->NumVertices) + 1);
      this->Stencil.Neighbours.reserve(static_cast<std::size_t>(3 * this->NumTriangles));
    }
    this->FanOrder.resize(static_cast<std::size_t>(this->NumVertices));
    rgmc::ParallelFor(this->NumVertices, RowGrain,
      [&](vtkIdType first, vtkIdType last)
      { std::fill(&this->FanOrder[first], &this->FanOrder[first] + (last - first), NoFanOrder); });
    this->AddUnsharedVertices(stencils, checks);
    // Shared vertices this rank owns, in gid order (the order of the received edges).
    for (std::size_t i = 0; i < this->Numbering.SharedVertex.size(); ++i)
    {
      if (this->Numbering.SharedOwner[i] == this->AllRanks.Rank)
      {
        this->AddVertex(this->Numbering.SharedVertex[i], i, &edges, stencils, checks);
      }
    }
    // Kept only when 32-bit: then they fit in the memory the 32-bit stencils save, so the
    // smoothing's peak is no higher than with 64-bit stencils and no corner lists.
    if (!stencils || sizeof(I) > 4)
    {
      rgmc::OverwriteVector<I>().swap(this->Corners);
      rgmc::OverwriteVector<vtkIdType>().swap(this->CornerOffsets);
    }
  }

  /// Vertices no other rank holds, in memory order: most are inside a closed manifold piece of
  /// the surface, where every edge has two triangles and the stencil is simply the neighbours
  /// in gid order. Those are found on threads, in blocks of vertices (each block's rows kept
  /// apart), then taken block by block in order: room is made for a block of manifold rows
  /// only, which threads then copy in; a block with other vertices is taken row by row, those
  /// going through AddVertex. The same rows, in the same order, for any number of threads.
  void AddUnsharedVertices(bool stencils, Checks& checks)
  {
    if (rgmc::SingleThreaded())
    {
      this->AddUnsharedVerticesInOrder(stencils, checks);
      return;
    }
    // Batches of blocks bound the rows held apart (memory), whatever the mesh's size.
    const vtkIdType numBlocks = (this->NumVertices + BlockSize - 1) / BlockSize;
    std::vector<Block> blocks;
    for (vtkIdType batch = 0; batch < numBlocks; batch += BatchBlocks)
    {
      blocks.assign(static_cast<std::size_t>(std::min(BatchBlocks, numBlocks - batch)), Block());
      this->FindManifoldRows(batch, stencils, blocks);
      const std::vector<Placement> placements = this->TakeBlocks(blocks, stencils, checks);
      this->PlaceBlocks(placements);
      blocks.clear();
    }
  }

  /// One thread: the unshared vertices straight into the stencils.
  void AddUnsharedVerticesInOrder(bool stencils, Checks& checks)
  {
    for (vtkIdType v = 0; v < this->NumVertices; ++v)
    {
      if (this->Numbering.Holding[v] != GlobalNumbering::Alone)
      {
        continue;
      }
      if (!this->ManifoldRow(v, stencils, this->Ends, this->Stencil.Neighbours, checks.Edges))
      {
        this->AddVertex(v, 0, nullptr, stencils, checks);
      }
      else if (stencils)
      {
        this->CloseRow(v);
      }
    }
  }

  /// A block of vertices, its manifold rows kept apart until they are placed.
  struct Block
  {
    std::vector<vtkIdType> Vertices; // in order; -1 - v for a vertex AddVertex takes
    std::vector<vtkIdType> Ends;     // row ends in Neighbours, per manifold vertex
    rgmc::OverwriteVector<I> Neighbours;
    vtkIdType Edges = 0;
  };

  /// Where a block of manifold rows goes in the stencils.
  struct Placement
  {
    const Block* From;
    std::size_t Row, Neighbour; // where its first row and its first neighbour go
  };

  /// A block is one task: 1024 vertices, about 0.15 ms here (4096 made each step of the
  /// work/span profile wait 0.63 ms for its longest task); a batch of blocks, 262 144 vertices.
  static constexpr vtkIdType BlockSize = 1024, BatchBlocks = 256;

  /// The manifold rows of the blocks of batch `batch`, on threads.
  void FindManifoldRows(vtkIdType batch, bool stencils, std::vector<Block>& blocks) const
  {
    rgmc::ParallelFor(static_cast<vtkIdType>(blocks.size()), 1,
      [&](vtkIdType first, vtkIdType last)
      {
        std::vector<std::pair<vtkIdType, vtkIdType>> blockEnds;
        for (vtkIdType b = first; b < last; ++b)
        {
          // Filled here and moved into place at the end: neighbouring blocks, on other
          // threads, share cache lines in `blocks`.
          Block block;
          const vtkIdType start = (batch + b) * BlockSize;
          const vtkIdType end = std::min(this->NumVertices, start + BlockSize);
          // A manifold row has one neighbour per corner: sized once, never grown.
          block.Vertices.reserve(static_cast<std::size_t>(end - start));
          block.Ends.reserve(static_cast<std::size_t>(end - start));
          if (stencils)
          {
            block.Neighbours.reserve(
              static_cast<std::size_t>(this->CornerOffsets[end] - this->CornerOffsets[start]));
          }
          for (vtkIdType v = start; v < end; ++v)
          {
            if (this->Numbering.Holding[v] != GlobalNumbering::Alone)
            {
              continue;
            }
            const bool manifold =
              this->ManifoldRow(v, stencils, blockEnds, block.Neighbours, block.Edges);
            block.Vertices.push_back(manifold ? v : -1 - v);
            if (manifold)
            {
              block.Ends.push_back(static_cast<vtkIdType>(block.Neighbours.size()));
            }
          }
          blocks[b] = std::move(block);
        }
      });
  }

  /// Takes the blocks in order: a block without a vertex for AddVertex (nearly all) is copied
  /// into place on threads after this walk (PlaceBlocks), which only makes room for it; the
  /// others are taken here, in order.
  std::vector<Placement> TakeBlocks(std::vector<Block>& blocks, bool stencils, Checks& checks)
  {
    std::vector<Placement> placements;
    for (Block& block : blocks)
    {
      checks.Edges += block.Edges;
      if (stencils && block.Ends.size() == block.Vertices.size())
      {
        placements.push_back(
          Placement{ &block, this->Owned.size(), this->Stencil.Neighbours.size() });
        this->Owned.resize(this->Owned.size() + block.Vertices.size());
        this->Stencil.Offsets.resize(this->Stencil.Offsets.size() + block.Ends.size());
        this->Stencil.Neighbours.resize(this->Stencil.Neighbours.size() + block.Neighbours.size());
        continue;
      }
      std::size_t row = 0;
      vtkIdType begin = 0;
      for (const vtkIdType entry : block.Vertices)
      {
        if (entry < 0)
        {
          this->AddVertex(-1 - entry, 0, nullptr, stencils, checks);
          continue;
        }
        const vtkIdType end = block.Ends[row++];
        if (stencils)
        {
          this->Stencil.Neighbours.insert(this->Stencil.Neighbours.end(),
            block.Neighbours.begin() + begin, block.Neighbours.begin() + end);
          this->CloseRow(entry);
        }
        begin = end;
      }
    }
    return placements;
  }

  /// Copies the placed blocks' rows into the stencils, on threads.
  void PlaceBlocks(const std::vector<Placement>& placements)
  {
    rgmc::ParallelFor(static_cast<vtkIdType>(placements.size()), 1,
      [&](vtkIdType first, vtkIdType last)
      {
        for (vtkIdType p = first; p < last; ++p)
        {
          const Placement& at = placements[p];
          const Block& block = *at.From;
          for (std::size_t r = 0; r < block.Vertices.size(); ++r)
          {
            this->Owned[at.Row + r] = static_cast<I>(block.Vertices[r]);
            this->Stencil.Offsets[at.Row + r + 1] =
              static_cast<std::int64_t>(at.Neighbour) + block.Ends[r];
          }
          std::copy(block.Neighbours.begin(), block.Neighbours.end(),
            this->Stencil.Neighbours.begin() + at.Neighbour);
        }
      });
  }

  /// Whether vertex v (no other rank holds it) is inside a manifold piece; if so, its edges are
  /// counted in `edges` and its row appended to `row` (when stencils are made). Reads only:
  /// threads may call it at once, each with its own `ends`.
  bool ManifoldRow(vtkIdType v, bool stencils, std::vector<std::pair<vtkIdType, vtkIdType>>& ends,
    rgmc::OverwriteVector<I>& row, vtkIdType& edges) const
  {
    if (this->OrientedFanRow(v, stencils, row, edges))
    {
      return true;
    }
    this->EndsAt(v, ends);
    bool manifold = !ends.empty() && ends.size() < 2 * 255;
    for (std::size_t e = 0; e < ends.size() && manifold; e += 2)
    {
      manifold = e + 1 < ends.size() && ends[e + 1].first == ends[e].first &&
        (e + 2 == ends.size() || ends[e + 2].first != ends[e].first);
    }
    if (!manifold)
    {
      return false;
    }
    for (std::size_t e = 0; e < ends.size(); e += 2)
    {
      edges += ends[e].first > this->Numbering.Gid[v];
      if (stencils)
      {
        row.push_back(static_cast<I>(ends[e].second));
      }
    }
    return true;
  }

  /// ManifoldRow's common case without its sort: vertex v's triangles all turn the same way
  /// around it, so each neighbour is the next corner of exactly one of them and the previous
  /// corner of exactly one. Then every neighbour is an end of exactly two edges (ManifoldRow's
  /// test), and the row is the next corners ranked by gid. Returns false, having changed
  /// nothing, when this does not hold (ManifoldRow then decides by sorting the ends). No
  /// branch on the gids' order: the ranks are counted.
  bool OrientedFanRow(
    vtkIdType v, bool stencils, rgmc::OverwriteVector<I>& row, vtkIdType& edges) const
  {
    constexpr int MaxFan = 12;
    const vtkIdType first = this->CornerOffsets[v];
    const int n = static_cast<int>(this->CornerOffsets[v + 1] - first);
    if (n == 0 || n > MaxFan)
    {
      return false;
    }
    const vtkIdType* gid = this->Numbering.Gid.data();
    vtkIdType next[MaxFan], nextGid[MaxFan], previousGid[MaxFan];
    for (int i = 0; i < n; ++i)
    {
      const std::pair<vtkIdType, vtkIdType> ends = this->AroundCorner(this->Corners[first + i]);
      next[i] = ends.first;
      nextGid[i] = gid[ends.first];
      previousGid[i] = gid[ends.second];
    }
    // rank[i]: how many next corners come before next[i]; distinct gids give distinct ranks.
    // matched: the next corners some previous corner equals.
    // previousOf[i]: the triangle whose previous corner is next[i] (the last one, if several).
    int rank[MaxFan], previousOf[MaxFan];
    unsigned ranks = 0, matched = 0;
    for (int i = 0; i < n; ++i)
    {
      int r = 0;
      bool found = false;
      previousOf[i] = 0;
      for (int j = 0; j < n; ++j)
      {
        r += nextGid[j] < nextGid[i];
        const bool closes = previousGid[j] == nextGid[i];
        found |= closes;
        previousOf[i] = closes ? j : previousOf[i];
      }
      rank[i] = r;
      ranks |= 1u << r;
      // Each previous corner equals at most one next corner (their gids are distinct when the
      // ranks are): n of them matching all n next corners is a permutation.
      matched |= static_cast<unsigned>(found) << i;
    }
    const unsigned all = (1u << n) - 1;
    if (ranks != all || matched != all)
    {
      return false;
    }
    const vtkIdType self = gid[v];
    for (int i = 0; i < n; ++i)
    {
      edges += nextGid[i] > self;
    }
    if (n <= MaxOrderedFan && !this->FanOrder.empty())
    {
      this->FanOrder[v] = FanOrderOf(n, rank, previousOf);
    }
    if (stencils)
    {
      const std::size_t at = row.size();
      row.resize(at + n);
      for (int i = 0; i < n; ++i)
      {
        row[at + rank[i]] = static_cast<I>(next[i]);
      }
    }
    return true;
  }

  /// The normals' order of an oriented fan of n <= MaxOrderedFan triangles (FanOrder): triangle
  /// i runs v, next i, previous i; the previous corner of triangle previousOf[j] is next j, so
  /// both ends of every triangle have a rank, and ranks compare as gids do. Triangles go by
  /// their ends' ranks, least first, equal pairs in corner order, as SeamNormals sorts them.
  static std::uint32_t FanOrderOf(int n, const int* rank, const int* previousOf)
  {
    int previousRank[MaxOrderedFan];
    for (int j = 0; j < n; ++j)
    {
      previousRank[previousOf[j]] = rank[j];
    }
    // Keys made distinct by the corner's index (ties in corner order), the unused ones last:
    // a fixed count of comparisons, no branch on n.
    int key[MaxOrderedFan];
    for (int i = 0; i < MaxOrderedFan; ++i)
    {
      key[i] = i < n
        ? (std::min(rank[i], previousRank[i]) * 16 + std::max(rank[i], previousRank[i])) * 16 + i
        : 0x7fffffff;
    }
    std::uint32_t order = 0;
    for (int i = 0; i < n; ++i)
    {
      int place = 0;
      for (int j = 0; j < MaxOrderedFan; ++j)
      {
        place += key[j] < key[i];
      }
      order |= static_cast<std::uint32_t>(i) << (4 * place);
    }
    return order;
  }

  /// Any vertex: its whole neighbourhood (with the edges other ranks sent, for a shared one:
  /// `received`, at shared index `sharedIndex`), its edges in the checks, its stencil.
  void AddVertex(
    vtkIdType v, std::size_t sharedIndex, ReceivedEdges* received, bool stencils, Checks& checks)
  {
    this->Around.clear();
    this->LocalNeighbours(v, this->Around);
    if (received)
    {
      this->AddReceivedEdges(v, sharedIndex, *received);
    }
    this->CountEdges(v, checks);
    if (stencils)
    {
      this->AddStencilRow(v);
    }
  }

  /// Adds the edges the other holders of shared vertex v sent to Around, and merges the ranks'
  /// counts of each edge (keeping the local copy of the neighbour).
  void AddReceivedEdges(vtkIdType v, std::size_t sharedIndex, ReceivedEdges& received)
  {
    const vtkIdType gid = this->Numbering.Gid[v];
    for (vtkIdType h = this->Numbering.SharerOffsets[sharedIndex];
         h < this->Numbering.SharerOffsets[sharedIndex + 1]; ++h)
    {
      const int s = this->Numbering.Sharers[h];
      const std::vector<vtkIdType>& in = received.FromRank[s];
      std::size_t& i = received.Cursor[s];
      if (i + 1 >= in.size() || in[i] != gid)
      {
        continue;
      }
      rgmc::MessageReader edges(in.data() + i, in.size() - i);
      edges.Int(); // the vertex's gid, checked above
      const std::int64_t count = edges.Int();
      for (std::int64_t j = 0; j < count; ++j)
      {
        Neighbour nb{ edges.Int(), 0, -1, s, 0, { 0, 0, 0 } };
        nb.Uses = static_cast<int>(edges.Int());
        nb.Mask = static_cast<int>(edges.Int());
        for (double& x : nb.X)
        {
          x = edges.Real();
        }
        this->Around.push_back(nb);
      }
      i += edges.Position();
    }
    std::stable_sort(this->Around.begin(), this->Around.end(),
      [](const Neighbour& a, const Neighbour& b) { return a.Gid < b.Gid; });
    std::vector<Neighbour>& all = this->Around;
    std::size_t kept = 0;
    for (std::size_t i = 0; i < all.size(); ++i)
    {
      if (kept > 0 && all[kept - 1].Gid == all[i].Gid)
      {
        all[kept - 1].Uses += all[i].Uses;
        if (all[kept - 1].Local < 0 && all[i].Local >= 0)
        {
          all[kept - 1] = Neighbour{ all[i].Gid, all[kept - 1].Uses, all[i].Local,
            this->AllRanks.Rank, 0, { 0, 0, 0 } };
        }
      }
      else
      {
        all[kept++] = all[i];
      }
    }
    this->Around.resize(kept);
  }

  /// The distinct edges of Around into Incident, each counted once in the checks (at its end
  /// of smaller gid): boundary edges (one triangle) apart from those along the volume's border,
  /// and non-manifold ones (more than two).
  void CountEdges(vtkIdType v, Checks& checks)
  {
    const int myMask = this->MaskOf(v);
    this->Incident.clear();
    for (const Neighbour& nb : this->Around)
    {
      this->Incident.push_back(rgmc::IncidentEdge{ nb.Gid, nb.Uses });
      if (nb.Gid > this->Numbering.Gid[v])
      {
        ++checks.Edges;
        if (nb.Uses == 1)
        {
          const int mask = nb.Local >= 0 ? this->MaskOf(nb.Local) : nb.Mask;
          ++((myMask & mask) ? checks.Border : checks.Boundary);
        }
        else if (nb.Uses > 2)
        {
          ++checks.NonManifold;
        }
      }
    }
  }

  /// Vertex v's stencil row, from Around and Incident; a neighbour held elsewhere is pending
  /// until the remote slots are numbered.
  void AddStencilRow(vtkIdType v)
  {
    auto find = [this](vtkIdType g) -> const Neighbour&
    {
      return *std::lower_bound(this->Around.begin(), this->Around.end(), g,
        [](const Neighbour& nb, vtkIdType key) { return nb.Gid < key; });
    };
    auto position = [this](const Neighbour& nb, T x[3])
    {
      for (int k = 0; k < 3; ++k)
      {
        x[k] = nb.Local >= 0 ? this->Positions[3 * nb.Local + k] : static_cast<T>(nb.X[k]);
      }
    };
    rgmc::SmoothingStencil(
      this->Incident,
      [&](std::int64_t a, std::int64_t b)
      {
        T pa[3], pb[3];
        position(find(a), pa);
        position(find(b), pb);
        return rgmc::ExceedsEdgeAngle(pa, this->Positions + 3 * v, pb, this->CosEdgeAngle);
      },
      this->Row);
    this->Owned.push_back(static_cast<I>(v));
    for (std::int64_t g : this->Row)
    {
      const Neighbour& nb = find(g);
      if (nb.Local >= 0)
      {
        this->Stencil.Neighbours.push_back(static_cast<I>(nb.Local));
        continue;
      }
      if (this->PendingRemote.size() >= static_cast<std::size_t>(std::numeric_limits<I>::max()))
      {
        throw std::length_error("more neighbours held elsewhere than the connectivity's index "
                                "type can number in one piece");
      }
      this->Stencil.Neighbours.push_back(
        static_cast<I>(-1 - static_cast<std::int64_t>(this->PendingRemote.size())));
      this->PendingRemote.push_back(Pending{ nb.Gid, nb.Provider, { nb.X[0], nb.X[1], nb.X[2] } });
    }
    this->Stencil.Offsets.push_back(static_cast<std::int64_t>(this->Stencil.Neighbours.size()));
  }

  /// Ends the stencil row of vertex v, whose neighbours are appended.
  void CloseRow(vtkIdType v)
  {
    this->Owned.push_back(static_cast<I>(v));
    this->Stencil.Offsets.push_back(static_cast<std::int64_t>(this->Stencil.Neighbours.size()));
  }

  /// The neighbours held elsewhere get slots NumVertices, NumVertices + 1, ... in gid order.
  void NumberRemoteNeighbours()
  {
    const std::vector<Pending>& pending = this->PendingRemote;
    std::vector<vtkIdType> order(pending.size()), slotOf(pending.size());
    std::iota(order.begin(), order.end(), vtkIdType(0));
    std::sort(order.begin(), order.end(),
      [&pending](vtkIdType a, vtkIdType b) { return pending[a].Gid < pending[b].Gid; });
    for (vtkIdType o : order)
    {
      const Pending& p = pending[o];
      if (this->RemoteGids.empty() || this->RemoteGids.back() != p.Gid)
      {
        this->RemoteGids.push_back(p.Gid);
        this->RemoteProviders.push_back(p.Provider);
        this->RemoteInitial.insert(this->RemoteInitial.end(), p.X, p.X + 3);
      }
      slotOf[o] = static_cast<vtkIdType>(this->RemoteGids.size()) - 1;
    }
    // The slots are indices of type I, as the vertices are.
    if (this->NumVertices + static_cast<vtkIdType>(this->RemoteGids.size()) >
      static_cast<vtkIdType>(std::numeric_limits<I>::max()))
    {
      throw std::length_error("more vertices and neighbours held elsewhere than the "
                              "connectivity's index type can number in one piece");
    }
    // The remote neighbours' entries (negative) become their slots, on threads; none when no
    // neighbour is held elsewhere.
    rgmc::OverwriteVector<I>& neighbours = this->Stencil.Neighbours;
    rgmc::ForEachChunk(pending.empty() ? 0 : static_cast<vtkIdType>(neighbours.size()),
      rgmc::ElementChunk,
      [&](vtkIdType, vtkIdType first, vtkIdType last)
      {
        for (vtkIdType i = first; i < last; ++i)
        {
          const I s = neighbours[i];
          neighbours[i] =
            s < 0 ? static_cast<I>(this->NumVertices + slotOf[-1 - static_cast<vtkIdType>(s)]) : s;
        }
      });
    std::vector<Pending>().swap(this->PendingRemote);
  }

  /// This rank's edges at vertex v, sorted by the neighbour's gid, appended to `out`.
  void LocalNeighbours(vtkIdType v, std::vector<Neighbour>& out)
  {
    this->EndsAt(v, this->Ends);
    const std::vector<std::pair<vtkIdType, vtkIdType>>& ends = this->Ends;
    for (std::size_t e = 0; e < ends.size();)
    {
      std::size_t end = e;
      while (end < ends.size() && ends[end].first == ends[e].first)
      {
        ++end;
      }
      out.push_back(Neighbour{ ends[e].first, static_cast<int>(end - e), ends[e].second,
        this->AllRanks.Rank, 0, { 0, 0, 0 } });
      e = end;
    }
  }

  // One vertex's neighbourhood while it is analysed (on the calling thread).
  std::vector<std::pair<vtkIdType, vtkIdType>> Ends;
  std::vector<Neighbour> Around;
  std::vector<rgmc::IncidentEdge> Incident;
  std::vector<std::int64_t> Row;
  double CosEdgeAngle = 1.0;
  std::vector<Pending> PendingRemote;
};

} // namespace seam
} // namespace rgmc

#endif // rgmcSeamAnalysis_h

// Seam repair: global vertex numbering across ranks, global mesh checks, and smoothing that is
// the same on any number of ranks.
#include "vtkRGSeamRepair.h"

#include "rgmcGrid.h"
#include "rgmcKeyMap.h"
#include "rgmcSmoothing.h"
#include "vtkRGArrays.h"
#include "vtkRGCollective.h"
#include "vtkRGParallel.h"

#include "vtkAOSDataArrayTemplate.h"
#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkDataSetAttributes.h"
#include "vtkDoubleArray.h"
#include "vtkDummyController.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkLogger.h"
#include "vtkMath.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkTypeInt32Array.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <functional>
#include <numeric>
#include <queue>
#include <sstream>
#include <type_traits>
#include <vector>

vtkStandardNewMacro(vtkRGSeamRepair);
vtkCxxSetObjectMacro(vtkRGSeamRepair, Controller, vtkMultiProcessController);

namespace
{

using rgmc::Ranks;
constexpr int NumberingTag = 48800, AnswerTag = 48802, EdgesTag = 48804, RequestTag = 48806,
              StateTag = 48808, UpdateTag = 48810, NormalTag = 48812, NormalBackTag = 48814;
/// Rows (vertices) per range when smoothing and normals run on threads.
constexpr vtkIdType RowGrain = 512;

// ---- vertex identities -----------------------------------------------------------------------

/// What makes copies of a vertex one vertex: its key (one word), or its exact coordinates (three).
template <int Words>
using Identity = std::array<std::uint64_t, Words>;

std::uint64_t Bits(double v)
{
  v = v == 0.0 ? 0.0 : v; // -0 and +0 are one coordinate
  std::uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

vtkIdType Word(std::uint64_t w)
{
  vtkIdType v;
  std::memcpy(&v, &w, sizeof v);
  return v;
}

std::uint64_t Unword(vtkIdType v)
{
  std::uint64_t w;
  std::memcpy(&w, &v, sizeof w);
  return w;
}

vtkIdType PackDouble(double v)
{
  vtkIdType b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

double UnpackDouble(vtkIdType b)
{
  double v;
  std::memcpy(&v, &b, sizeof v);
  return v;
}

/// This rank's distinct vertices. When every input point is a distinct vertex (the usual case:
/// the extraction emits each vertex once per rank), vertex v is input point v and the maps are
/// empty; otherwise the vertices are numbered in identity order and the maps say which points
/// they merge.
struct LocalVertices
{
  vtkIdType Count = 0;
  std::vector<vtkIdType> Sorted; // the vertices in identity order
  std::vector<vtkIdType> Of;     // input point -> vertex (empty: the same number)
  std::vector<vtkIdType> First;  // vertex -> its first input point (empty: the same number)

  bool Merged() const { return !this->Of.empty(); }
  vtkIdType PointOf(vtkIdType v) const { return this->First.empty() ? v : this->First[v]; }
  vtkIdType VertexOf(vtkIdType p) const { return this->Of.empty() ? p : this->Of[p]; }
};

/// Sorts the input points by identity into distinct vertices; `ids` gets the vertices'
/// identities in sorted order.
template <int Words>
LocalVertices MergeLocal(
  vtkPolyData* input, const vtkIdType* keys, std::vector<Identity<Words>>& ids)
{
  const vtkIdType n = input->GetNumberOfPoints();
  std::vector<std::pair<Identity<Words>, vtkIdType>> all(static_cast<std::size_t>(n));
  for (vtkIdType p = 0; p < n; ++p)
  {
    Identity<Words>& id = all[p].first;
    if (Words == 1)
    {
      id[0] = Unword(keys[p]);
    }
    else
    {
      double x[3];
      input->GetPoint(p, x);
      for (int k = 0; k < Words; ++k)
      {
        id[k] = Bits(x[k]);
      }
    }
    all[p].second = p;
  }
  rgmc::ParallelSort(all); // (identity, point) pairs are distinct
  LocalVertices local;
  bool duplicates = false;
  for (std::size_t i = 1; i < all.size() && !duplicates; ++i)
  {
    duplicates = all[i].first == all[i - 1].first;
  }
  ids.reserve(all.size());
  local.Sorted.reserve(all.size());
  if (duplicates)
  {
    local.Of.resize(static_cast<std::size_t>(n));
  }
  for (std::size_t i = 0; i < all.size(); ++i)
  {
    if (!duplicates)
    {
      ids.push_back(all[i].first);
      local.Sorted.push_back(all[i].second);
      continue;
    }
    if (i == 0 || all[i].first != all[i - 1].first)
    {
      local.Sorted.push_back(static_cast<vtkIdType>(ids.size()));
      local.First.push_back(all[i].second);
      ids.push_back(all[i].first);
    }
    local.Of[all[i].second] = static_cast<vtkIdType>(ids.size()) - 1;
  }
  local.Count = static_cast<vtkIdType>(ids.size());
  return local;
}

// ---- global numbering --------------------------------------------------------------------------

/// The global id and owner of each of this rank's vertices, and the other holders of the shared
/// ones.
struct Numbering
{
  std::vector<vtkIdType> Gid; // by vertex
  enum : unsigned char
  {
    Alone = 0,   // no other rank holds the vertex
    Shared = 1,  // other ranks hold it too
    Foreign = 2, // (with Shared) another rank owns it
  };
  std::vector<unsigned char> Holding; // by vertex
  // The shared vertices, in global-id order: the vertex, its owner, the other ranks that hold it.
  std::vector<vtkIdType> SharedVertex;
  std::vector<int> SharedOwner;
  std::vector<vtkIdType> SharerOffsets{ 0 };
  std::vector<int> Sharers;
  vtkIdType Total = 0;
};

/// Numbers the identities of all ranks in their sorted order: a sample sort. Each rank sends its
/// sorted identities to the ranks responsible for their ranges (from sampled identities); those
/// merge the sorted streams, number the distinct identities in order and answer each sender
/// with the global id of each identity it sent (in its order), and, for identities held by
/// several ranks, the holders (the lowest owns the vertex). Collective; false (on every rank,
/// with `problem`) on failure.
template <int Words>
bool Number(Ranks& ranks, const LocalVertices& local, std::vector<Identity<Words>>& ids,
  Numbering& numbering, std::string& problem)
{
  const int P = ranks.Size;
  const std::size_t n = ids.size();
  // Ranges of about equal size, from up to 64 sampled identities per rank.
  std::vector<vtkIdType> samples;
  for (std::size_t i = 0, k = std::min<std::size_t>(n, 64); i < k; ++i)
  {
    for (std::uint64_t w : ids[i * n / k])
    {
      samples.push_back(Word(w));
    }
  }
  vtkIdType count = static_cast<vtkIdType>(samples.size());
  std::vector<vtkIdType> counts(P), offsets(P + 1, 0);
  ranks.Check(ranks.C->AllGather(&count, counts.data(), 1), "gathering sample counts");
  for (int r = 0; r < P; ++r)
  {
    offsets[r + 1] = offsets[r] + counts[r];
  }
  std::vector<vtkIdType> allSamples(static_cast<std::size_t>(offsets[P]) + 1);
  ranks.Check(
    ranks.C->AllGatherV(samples.data(), allSamples.data(), count, counts.data(), offsets.data()),
    "gathering samples");
  std::vector<Identity<Words>> splitters;
  std::vector<std::size_t> sliceStart(P + 1, n);
  std::vector<std::vector<vtkIdType>> outgoing(P);
  if (!ranks.Step("send the vertex identities", problem,
        [&]()
        {
          std::vector<Identity<Words>> sorted(static_cast<std::size_t>(offsets[P] / Words));
          for (std::size_t s = 0; s < sorted.size(); ++s)
          {
            for (int k = 0; k < Words; ++k)
            {
              sorted[s][k] = Unword(allSamples[Words * s + k]);
            }
          }
          std::sort(sorted.begin(), sorted.end());
          for (int h = 1; h < P && !sorted.empty(); ++h)
          {
            splitters.push_back(sorted[h * sorted.size() / P]);
          }
          // The ranges follow the sorted identities: rank h gets one slice of them.
          sliceStart[0] = 0;
          for (int h = 1; h <= P; ++h)
          {
            sliceStart[h] = h - 1 < static_cast<int>(splitters.size())
              ? static_cast<std::size_t>(
                  std::upper_bound(ids.begin(), ids.end(), splitters[h - 1]) - ids.begin())
              : n;
          }
          for (int h = 0; h < P; ++h)
          {
            outgoing[h].reserve(Words * (sliceStart[h + 1] - sliceStart[h]));
            for (std::size_t i = sliceStart[h]; i < sliceStart[h + 1]; ++i)
            {
              for (std::uint64_t w : ids[i])
              {
                outgoing[h].push_back(Word(w));
              }
            }
          }
          std::vector<Identity<Words>>().swap(ids); // no longer needed
        }))
  {
    return false;
  }
  const std::vector<bool> everyone(P, true);
  auto incoming = ranks.Exchange(outgoing, everyone, NumberingTag);
  std::vector<std::vector<vtkIdType>>().swap(outgoing);

  // Merge the ranks' sorted streams; number the distinct identities in order. Each answer holds
  // the group number of every identity received (made a global id below), then, for the
  // identities held by several ranks, (position, number of holders, holders...).
  std::vector<std::vector<vtkIdType>> answers(P);
  vtkIdType groups = 0;
  if (!ranks.Step("number the vertex identities", problem,
        [&]()
        {
          using Head = std::pair<Identity<Words>, int>; // identity, source
          std::priority_queue<Head, std::vector<Head>, std::greater<Head>> heads;
          std::vector<std::size_t> next(P, 0);
          auto push = [&](int s)
          {
            const std::vector<vtkIdType>& in = incoming[s];
            if (next[s] + Words <= in.size())
            {
              Identity<Words> id;
              for (int k = 0; k < Words; ++k)
              {
                id[k] = Unword(in[next[s] + k]);
              }
              heads.emplace(id, s);
            }
          };
          for (int s = 0; s < P; ++s)
          {
            answers[s].reserve(incoming[s].size() / Words);
            push(s);
          }
          std::vector<std::vector<vtkIdType>> sharedRecords(P);
          std::vector<int> holders; // sources of the current group, in increasing order
          while (!heads.empty())
          {
            const Identity<Words> id = heads.top().first;
            holders.clear();
            while (!heads.empty() && heads.top().first == id)
            {
              const int s = heads.top().second;
              heads.pop();
              holders.push_back(s);
              answers[s].push_back(groups);
              next[s] += Words;
              push(s);
            }
            if (holders.size() > 1)
            {
              for (int s : holders)
              {
                std::vector<vtkIdType>& out = sharedRecords[s];
                out.insert(out.end(),
                  { static_cast<vtkIdType>(next[s] / Words - 1),
                    static_cast<vtkIdType>(holders.size()) });
                out.insert(out.end(), holders.begin(), holders.end());
              }
            }
            ++groups;
          }
          std::vector<std::vector<vtkIdType>>().swap(incoming);
          for (int s = 0; s < P; ++s)
          {
            answers[s].insert(answers[s].end(), sharedRecords[s].begin(), sharedRecords[s].end());
          }
        }))
  {
    return false;
  }
  std::vector<vtkIdType> groupCounts(P), first(P + 1, 0);
  ranks.Check(ranks.C->AllGather(&groups, groupCounts.data(), 1), "gathering vertex counts");
  for (int r = 0; r < P; ++r)
  {
    first[r + 1] = first[r] + groupCounts[r];
  }
  // The group numbers become global ids at the senders (an answer starts with one number per
  // identity the sender sent here).
  auto replies = ranks.Exchange(answers, everyone, AnswerTag);
  std::vector<std::vector<vtkIdType>>().swap(answers);
  return ranks.Step("number the vertices", problem,
    [&]()
    {
      numbering.Total = first[P];
      numbering.Gid.resize(static_cast<std::size_t>(local.Count));
      numbering.Holding.assign(static_cast<std::size_t>(local.Count), Numbering::Alone);
      for (int h = 0; h < P; ++h)
      {
        const std::vector<vtkIdType>& in = replies[h];
        const std::size_t sent = sliceStart[h + 1] - sliceStart[h];
        for (std::size_t i = 0; i < sent; ++i)
        {
          numbering.Gid[local.Sorted[sliceStart[h] + i]] = first[h] + in[i];
        }
        // Shared identities, in increasing position: the shared vertices come in gid order.
        for (std::size_t i = sent; i + 1 < in.size();)
        {
          const vtkIdType v = local.Sorted[sliceStart[h] + static_cast<std::size_t>(in[i])];
          const vtkIdType holders = in[i + 1];
          const int owner = static_cast<int>(in[i + 2]);
          numbering.SharedVertex.push_back(v);
          numbering.SharedOwner.push_back(owner);
          numbering.Holding[v] =
            owner != ranks.Rank ? Numbering::Shared | Numbering::Foreign : Numbering::Shared;
          for (vtkIdType j = 0; j < holders; ++j)
          {
            const int holder = static_cast<int>(in[i + 2 + j]);
            if (holder != ranks.Rank)
            {
              numbering.Sharers.push_back(holder);
            }
          }
          numbering.SharerOffsets.push_back(static_cast<vtkIdType>(numbering.Sharers.size()));
          i += 2 + static_cast<std::size_t>(holders);
        }
      }
    });
}

// ---- the mesh around each owned vertex ---------------------------------------------------------

/// Which faces of the volume a vertex lies on (bits x-, x+, y-, y+, z-, z+): an edge whose two
/// vertices share a face runs along the volume's border.
struct BorderTest
{
  bool Keys = false;
  int Whole[6] = { 0, -1, 0, -1, 0, -1 };
  double Bounds[6] = { 0, 0, 0, 0, 0, 0 };
  double Tolerance = 0.0;

  int Mask(const rgmc::Grid& grid, vtkIdType key, const double x[3]) const
  {
    int mask = 0;
    if (this->Keys)
    {
      int p[3], axis;
      grid.Decode(key, p, axis);
      for (int b = 0; b < 3; ++b)
      {
        if (b != axis)
        {
          mask |= (p[b] == this->Whole[2 * b]) << (2 * b);
          mask |= (p[b] == this->Whole[2 * b + 1]) << (2 * b + 1);
        }
      }
      return mask;
    }
    for (int b = 0; b < 3; ++b)
    {
      mask |= (std::fabs(x[b] - this->Bounds[2 * b]) <= this->Tolerance) << (2 * b);
      mask |= (std::fabs(x[b] - this->Bounds[2 * b + 1]) <= this->Tolerance) << (2 * b + 1);
    }
    return mask;
  }
};

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

struct Checks
{
  vtkIdType Edges = 0, Boundary = 0, Border = 0, NonManifold = 0;
};

/// The repair of one rank's piece, with points of type T and triangles over vertex indices of
/// type I (the input's own connectivity when its points need no merging).
template <typename T, typename I>
class Repair
{
public:
  Repair(Ranks& ranks, const LocalVertices& local, const Numbering& numbering,
    const BorderTest& border, const vtkIdType* keys, const T* x, const I* triangles,
    vtkIdType numTriangles)
    : R(ranks)
    , Local(local)
    , Num(numbering)
    , Border(border)
    , Grid(border.Whole, border.Whole)
    , Keys(keys)
    , X(x)
    , Triangles(triangles)
    , NumTriangles(numTriangles)
    , N(local.Count)
    , ToSharer(ranks.Size)
    , FromOwner(ranks.Size)
    , Provide(ranks.Size)
    , RemoteOrder(ranks.Size)
    , RequestLists(ranks.Size)
  {
    this->Partners.assign(ranks.Size, false);
    for (int s : numbering.Sharers)
    {
      this->Partners[s] = true;
    }
  }

  /// The edges at each vertex (with repeats: once per triangle side), gathered at owners;
  /// smoothing stencils of owned vertices; global checks. Collective; false (on every rank, with
  /// `problem`) on failure.
  bool Analyze(bool stencils, Checks& checks, std::string& problem)
  {
    const int P = this->R.Size, me = this->R.Rank;
    const std::vector<vtkIdType>& gid = this->Num.Gid;
    std::vector<Neighbour> all;
    std::vector<std::pair<vtkIdType, vtkIdType>> ends; // (gid, vertex) of edge ends
    // The corners of the triangles at each vertex, in compressed rows.
    std::vector<vtkIdType> cornerOffsets, corners;
    // The ends of this rank's edges at vertex v (once per triangle side), sorted by gid, into
    // `out` (reads only: threads may call it at once).
    auto endsAt = [&](vtkIdType v, std::vector<std::pair<vtkIdType, vtkIdType>>& out)
    {
      out.clear();
      for (vtkIdType c = cornerOffsets[v]; c < cornerOffsets[v + 1]; ++c)
      {
        const vtkIdType t = corners[c] / 3, k = corners[c] % 3;
        for (vtkIdType other : { (k + 1) % 3, (k + 2) % 3 })
        {
          const vtkIdType w = static_cast<vtkIdType>(this->Triangles[3 * t + other]);
          out.emplace_back(gid[w], w);
        }
      }
      std::sort(out.begin(), out.end());
    };
    auto localEnds = [&](vtkIdType v) { endsAt(v, ends); };
    // This rank's edges at vertex v, sorted by the neighbour's gid, into `out`.
    auto localNeighbours = [&](vtkIdType v, std::vector<Neighbour>& out)
    {
      localEnds(v);
      for (std::size_t e = 0; e < ends.size();)
      {
        std::size_t end = e;
        while (end < ends.size() && ends[end].first == ends[e].first)
        {
          ++end;
        }
        out.push_back(Neighbour{
          ends[e].first, static_cast<int>(end - e), ends[e].second, me, 0, { 0, 0, 0 } });
        e = end;
      }
    };

    // Edges at shared vertices go to their owners (shared vertices in gid order: each owner
    // receives them in its own order).
    std::vector<std::vector<vtkIdType>> outgoing(P);
    if (!this->R.Step("list the edges at the seams", problem,
          [&]()
          {
            this->CornersAround(cornerOffsets, corners);
            for (std::size_t i = 0; i < this->Num.SharedVertex.size(); ++i)
            {
              const int owner = this->Num.SharedOwner[i];
              if (owner == me)
              {
                continue;
              }
              const vtkIdType v = this->Num.SharedVertex[i];
              all.clear();
              localNeighbours(v, all);
              std::vector<vtkIdType>& out = outgoing[owner];
              out.push_back(gid[v]);
              out.push_back(static_cast<vtkIdType>(all.size()));
              for (const Neighbour& nb : all)
              {
                const T* x = this->X + 3 * nb.Local;
                out.insert(out.end(),
                  { nb.Gid, nb.Uses, this->MaskOf(nb.Local), PackDouble(static_cast<double>(x[0])),
                    PackDouble(static_cast<double>(x[1])), PackDouble(static_cast<double>(x[2])) });
              }
            }
          }))
    {
      return false;
    }
    const auto incoming = this->R.Exchange(outgoing, this->Partners, EdgesTag);
    std::vector<std::vector<vtkIdType>>().swap(outgoing);

    // Every owned vertex, in gid order: its whole neighbourhood, the checks, its stencil.
    struct Pending // a neighbour held elsewhere, until remote slots are numbered
    {
      vtkIdType Gid;
      int Provider;
      double X[3];
    };
    std::vector<Pending> pending;
    if (!this->R.Step("make the smoothing stencils", problem,
          [&]()
          {
            std::vector<std::size_t> cursor(P, 0);
            std::vector<rgmc::IncidentEdge> incident;
            std::vector<std::int64_t> stencil;
            const double cosEdgeAngle = std::cos(vtkMath::RadiansFromDegrees(15.0));
            if (stencils)
            {
              this->Owned.reserve(static_cast<std::size_t>(this->N));
              this->Stencil.Offsets.reserve(static_cast<std::size_t>(this->N) + 1);
              this->Stencil.Neighbours.reserve(static_cast<std::size_t>(3 * this->NumTriangles));
            }
            // Any vertex: its whole neighbourhood (with the edges other ranks sent, for a shared
            // one), the checks, its stencil.
            auto general = [&](vtkIdType v, bool isShared, std::size_t sharedIndex)
            {
              all.clear();
              localNeighbours(v, all);
              if (isShared)
              {
                for (vtkIdType h = this->Num.SharerOffsets[sharedIndex];
                     h < this->Num.SharerOffsets[sharedIndex + 1]; ++h)
                {
                  const int s = this->Num.Sharers[h];
                  const std::vector<vtkIdType>& in = incoming[s];
                  std::size_t& i = cursor[s];
                  if (i + 1 >= in.size() || in[i] != gid[v])
                  {
                    continue;
                  }
                  const vtkIdType count = in[i + 1];
                  i += 2;
                  for (vtkIdType j = 0; j < count; ++j, i += 6)
                  {
                    all.push_back(Neighbour{ in[i], static_cast<int>(in[i + 1]), -1, s,
                      static_cast<int>(in[i + 2]),
                      { UnpackDouble(in[i + 3]), UnpackDouble(in[i + 4]),
                        UnpackDouble(in[i + 5]) } });
                  }
                }
                std::stable_sort(all.begin(), all.end(),
                  [](const Neighbour& a, const Neighbour& b) { return a.Gid < b.Gid; });
                // Merge the ranks' counts of each edge; keep the local copy of the neighbour.
                std::size_t kept = 0;
                for (std::size_t i = 0; i < all.size(); ++i)
                {
                  if (kept > 0 && all[kept - 1].Gid == all[i].Gid)
                  {
                    all[kept - 1].Uses += all[i].Uses;
                    if (all[kept - 1].Local < 0 && all[i].Local >= 0)
                    {
                      all[kept - 1] = Neighbour{ all[i].Gid, all[kept - 1].Uses, all[i].Local, me,
                        0, { 0, 0, 0 } };
                    }
                  }
                  else
                  {
                    all[kept++] = all[i];
                  }
                }
                all.resize(kept);
              }
              const int myMask = this->MaskOf(v);
              incident.clear();
              for (const Neighbour& nb : all)
              {
                incident.push_back(rgmc::IncidentEdge{ nb.Gid, nb.Uses });
                if (nb.Gid > gid[v])
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
              if (!stencils)
              {
                return;
              }
              auto find = [&all](vtkIdType g) -> const Neighbour&
              {
                return *std::lower_bound(all.begin(), all.end(), g,
                  [](const Neighbour& nb, vtkIdType key) { return nb.Gid < key; });
              };
              auto position = [&](const Neighbour& nb, T x[3])
              {
                for (int k = 0; k < 3; ++k)
                {
                  x[k] = nb.Local >= 0 ? this->X[3 * nb.Local + k] : static_cast<T>(nb.X[k]);
                }
              };
              rgmc::SmoothingStencil(
                incident,
                [&](std::int64_t a, std::int64_t b)
                {
                  T pa[3], pb[3];
                  position(find(a), pa);
                  position(find(b), pb);
                  return rgmc::ExceedsEdgeAngle(pa, this->X + 3 * v, pb, cosEdgeAngle);
                },
                stencil);
              this->Owned.push_back(v);
              for (std::int64_t g : stencil)
              {
                const Neighbour& nb = find(g);
                if (nb.Local >= 0)
                {
                  this->Stencil.Neighbours.push_back(nb.Local);
                  continue;
                }
                this->Stencil.Neighbours.push_back(-1 - static_cast<std::int64_t>(pending.size()));
                pending.push_back(Pending{ nb.Gid, nb.Provider, { nb.X[0], nb.X[1], nb.X[2] } });
              }
              this->Stencil.Offsets.push_back(
                static_cast<std::int64_t>(this->Stencil.Neighbours.size()));
            };
            // Vertices no other rank holds, in memory order: most are inside a closed manifold
            // piece of the surface, where every edge has two triangles and the stencil is simply
            // the neighbours in gid order. Those are found on threads, in blocks of vertices
            // (each block's rows kept apart), then taken block by block in order, the others
            // going through the general path there: the same rows, in the same order, for any
            // number of threads.
            // Whether vertex v (no other rank holds it) is inside a manifold piece; if so, its
            // edges are counted in `edges` and its row appended to `row` (when stencils are
            // made). Reads only: threads may call it at once.
            auto manifoldRow = [&](vtkIdType v, std::vector<std::pair<vtkIdType, vtkIdType>>& at,
                                 std::vector<std::int64_t>& row, vtkIdType& edges)
            {
              endsAt(v, at);
              bool manifold = !at.empty() && at.size() < 2 * 255;
              for (std::size_t e = 0; e < at.size() && manifold; e += 2)
              {
                manifold = e + 1 < at.size() && at[e + 1].first == at[e].first &&
                  (e + 2 == at.size() || at[e + 2].first != at[e].first);
              }
              if (!manifold)
              {
                return false;
              }
              for (std::size_t e = 0; e < at.size(); e += 2)
              {
                edges += at[e].first > gid[v];
                if (stencils)
                {
                  row.push_back(at[e].second);
                }
              }
              return true;
            };
            auto ownRow = [&](vtkIdType v)
            {
              this->Owned.push_back(v);
              this->Stencil.Offsets.push_back(
                static_cast<std::int64_t>(this->Stencil.Neighbours.size()));
            };
            if (vtkSMPTools::GetEstimatedNumberOfThreads() <= 1)
            {
              // One thread: straight into the stencils.
              for (vtkIdType v = 0; v < this->N; ++v)
              {
                if (this->Num.Holding[v] != Numbering::Alone)
                {
                  continue;
                }
                if (!manifoldRow(v, ends, this->Stencil.Neighbours, checks.Edges))
                {
                  general(v, false, 0);
                }
                else if (stencils)
                {
                  ownRow(v);
                }
              }
            }
            struct Block
            {
              std::vector<vtkIdType> Vertices; // in order; -1 - v for a vertex of the general path
              std::vector<vtkIdType> Ends;     // row ends in Neighbours, per manifold vertex
              std::vector<std::int64_t> Neighbours;
              vtkIdType Edges = 0;
            };
            // Batches of blocks bound the rows held apart (memory), whatever the mesh's size.
            const vtkIdType blockSize = 4096, batchBlocks = 64;
            const vtkIdType numBlocks = vtkSMPTools::GetEstimatedNumberOfThreads() <= 1
              ? 0
              : (this->N + blockSize - 1) / blockSize;
            std::vector<Block> blocks;
            for (vtkIdType batch = 0; batch < numBlocks; batch += batchBlocks)
            {
              blocks.assign(
                static_cast<std::size_t>(std::min(batchBlocks, numBlocks - batch)), Block());
              rgmc::ParallelFor(static_cast<vtkIdType>(blocks.size()), 1,
                [&](vtkIdType first, vtkIdType last)
                {
                  std::vector<std::pair<vtkIdType, vtkIdType>> blockEnds;
                  for (vtkIdType b = first; b < last; ++b)
                  {
                    Block& block = blocks[b];
                    const vtkIdType start = (batch + b) * blockSize;
                    for (vtkIdType v = start; v < std::min(this->N, start + blockSize); ++v)
                    {
                      if (this->Num.Holding[v] != Numbering::Alone)
                      {
                        continue;
                      }
                      const bool manifold =
                        manifoldRow(v, blockEnds, block.Neighbours, block.Edges);
                      block.Vertices.push_back(manifold ? v : -1 - v);
                      if (manifold)
                      {
                        block.Ends.push_back(static_cast<vtkIdType>(block.Neighbours.size()));
                      }
                    }
                  }
                });
              for (Block& block : blocks)
              {
                checks.Edges += block.Edges;
                std::size_t row = 0;
                vtkIdType begin = 0;
                for (const vtkIdType entry : block.Vertices)
                {
                  if (entry < 0)
                  {
                    general(-1 - entry, false, 0);
                    continue;
                  }
                  const vtkIdType end = block.Ends[row++];
                  if (stencils)
                  {
                    this->Stencil.Neighbours.insert(this->Stencil.Neighbours.end(),
                      block.Neighbours.begin() + begin, block.Neighbours.begin() + end);
                    ownRow(entry);
                  }
                  begin = end;
                }
                block = Block();
              }
            }
            // Shared vertices this rank owns, in gid order (the order of the received edges).
            for (std::size_t i = 0; i < this->Num.SharedVertex.size(); ++i)
            {
              if (this->Num.SharedOwner[i] == me)
              {
                general(this->Num.SharedVertex[i], true, i);
              }
            }
            std::vector<vtkIdType>().swap(corners);
            std::vector<vtkIdType>().swap(cornerOffsets);

            // The neighbours held elsewhere get slots N, N + 1, ... in gid order.
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
            for (std::int64_t& s : this->Stencil.Neighbours)
            {
              s = s < 0 ? this->N + slotOf[-1 - s] : s;
            }
            // Who sends what each iteration: the neighbours owners lack, from ranks that hold
            // them; the owners' new positions, to the other holders (both sides list a pair's
            // vertices in gid order).
            for (std::size_t r = 0; r < this->RemoteGids.size(); ++r)
            {
              this->RequestLists[this->RemoteProviders[r]].push_back(this->RemoteGids[r]);
              this->RemoteOrder[this->RemoteProviders[r]].push_back(
                this->N + static_cast<vtkIdType>(r));
            }
            for (std::size_t i = 0; i < this->Num.SharedVertex.size(); ++i)
            {
              const vtkIdType v = this->Num.SharedVertex[i];
              if (this->Num.SharedOwner[i] == me)
              {
                for (vtkIdType h = this->Num.SharerOffsets[i]; h < this->Num.SharerOffsets[i + 1];
                     ++h)
                {
                  this->ToSharer[this->Num.Sharers[h]].push_back(v);
                }
              }
              else
              {
                this->FromOwner[this->Num.SharedOwner[i]].push_back(v);
              }
            }
          }))
    {
      return false;
    }
    const auto asked = this->R.Exchange(this->RequestLists, this->Partners, RequestTag);
    std::vector<std::vector<vtkIdType>>().swap(this->RequestLists);
    return this->R.Step("plan the smoothing's exchanges", problem,
      [&]()
      {
        for (int s = 0; s < P; ++s)
        {
          for (vtkIdType g : asked[s])
          {
            this->Provide[s].push_back(this->VertexOfGid(g));
          }
        }
      });
  }

  /// Smooths the positions into Smoothed. Returns false when aborted or failed (with
  /// `problem`). Collective.
  bool Smooth(int method, int iterations, double relaxation, double passBand,
    rgmc::SincWindow window, const std::function<bool(double)>& progress, std::string& problem)
  {
    const std::size_t size = 3 * (this->N + this->RemoteGids.size());
    std::vector<T> a, b, c, sum;       // windowed sinc: in the points' type, as VTK's filter
    std::vector<double> current, next; // Laplacian: in double, rounded once at the end
    std::vector<double> coefficients;
    const bool sinc = method == vtkRGSeamRepair::WINDOWED_SINC;
    if (!this->R.Step("smooth the surface", problem,
          [&]()
          {
            if (!sinc)
            {
              current.resize(size);
              next.resize(size);
              std::copy(this->X, this->X + 3 * this->N, current.begin());
              std::copy(this->RemoteInitial.begin(), this->RemoteInitial.end(),
                current.begin() + 3 * this->N);
              return;
            }
            a.resize(size);
            b.resize(size);
            std::copy(this->X, this->X + 3 * this->N, a.begin());
            for (std::size_t r = 0; r < this->RemoteGids.size(); ++r)
            {
              for (int k = 0; k < 3; ++k)
              {
                a[3 * (this->N + r) + k] = static_cast<T>(this->RemoteInitial[3 * r + k]);
              }
            }
            {
              c.resize(size);
              sum.resize(size);
              coefficients = rgmc::SincCoefficients(iterations, passBand, window);
            }
          }))
    {
      return false;
    }
    bool aborted = false;
    if (!sinc)
    {
      for (int it = 0; it < iterations && !aborted; ++it)
      {
        if (progress(double(it) / iterations))
        {
          aborted = true;
          break;
        }
        this->Fetch(current.data());
        rgmc::ParallelFor(static_cast<vtkIdType>(this->Owned.size()), RowGrain,
          [&](vtkIdType first, vtkIdType last)
          {
            rgmc::LaplacianStep(
              this->Stencil, this->Owned, current.data(), next.data(), relaxation, first, last);
          });
        this->Update(next.data());
        std::swap(current, next);
      }
      std::vector<double>().swap(next);
      if (!this->R.Step("smooth the surface", problem,
            [&]() { this->Smoothed.assign(current.begin(), current.begin() + 3 * this->N); }))
      {
        return false;
      }
    }
    else
    {
      // Windowed sinc: x0 = a, x1 = b, x2 = c, x3 = sum.
      T* x0 = a.data();
      T* x1 = b.data();
      T* x2 = c.data();
      this->Fetch(x0);
      rgmc::ParallelFor(static_cast<vtkIdType>(this->Owned.size()), RowGrain,
        [&](vtkIdType first, vtkIdType last)
        {
          rgmc::SincFirstStep(
            this->Stencil, this->Owned, x0, x1, sum.data(), coefficients.data(), first, last);
        });
      this->Update(x1);
      for (int it = 2; it <= iterations; ++it)
      {
        if (progress(double(it) / iterations))
        {
          aborted = true;
          break;
        }
        this->Fetch(x1);
        rgmc::ParallelFor(static_cast<vtkIdType>(this->Owned.size()), RowGrain,
          [&](vtkIdType first, vtkIdType last)
          {
            rgmc::SincStep(
              this->Stencil, this->Owned, x0, x1, x2, sum.data(), coefficients[it], first, last);
          });
        this->Update(x2);
        T* oldest = x0;
        x0 = x1;
        x1 = x2;
        x2 = oldest;
      }
      this->Update(sum.data());
      this->Smoothed.swap(sum);
    }
    // The stencils are done with: the normals need the memory.
    std::vector<std::int64_t>().swap(this->Stencil.Neighbours);
    std::vector<std::int64_t>().swap(this->Stencil.Offsets);
    std::vector<std::int64_t>().swap(this->Owned);
    if (!this->R.Agree(true, problem) || aborted)
    {
      return false;
    }
    this->Smoothed.resize(3 * this->N);
    return true;
  }

  /// Area-weighted vertex normals of the smoothed positions. Each vertex sums its triangles'
  /// area vectors in one order fixed by the mesh (by the triangles' sorted global ids), at its
  /// owner, so that the normals are the same to the bit for any number of ranks. Collective;
  /// empty on failure (on every rank, with `problem`).
  std::vector<float> Normals(std::string& problem)
  {
    const std::vector<vtkIdType>& gid = this->Num.Gid;
    const T* x = this->Smoothed.data();
    // A triangle: its sorted global ids, and its area vector taken from its corner of smallest
    // global id (orientation kept), so that every rank computes the same bits.
    struct Term
    {
      std::array<vtkIdType, 3> Key;
      double Cross[3];
      bool operator<(const Term& o) const { return this->Key < o.Key; }
    };
    auto term = [&](vtkIdType t)
    {
      vtkIdType c[3] = { static_cast<vtkIdType>(this->Triangles[3 * t]),
        static_cast<vtkIdType>(this->Triangles[3 * t + 1]),
        static_cast<vtkIdType>(this->Triangles[3 * t + 2]) };
      const int first =
        gid[c[0]] < gid[c[1]] ? (gid[c[0]] < gid[c[2]] ? 0 : 2) : (gid[c[1]] < gid[c[2]] ? 1 : 2);
      std::rotate(c, c + first, c + 3);
      Term out;
      double e1[3], e2[3];
      for (int k = 0; k < 3; ++k)
      {
        e1[k] = static_cast<double>(x[3 * c[1] + k]) - static_cast<double>(x[3 * c[0] + k]);
        e2[k] = static_cast<double>(x[3 * c[2] + k]) - static_cast<double>(x[3 * c[0] + k]);
      }
      vtkMath::Cross(e1, e2, out.Cross);
      out.Key = { gid[c[0]], gid[c[1]], gid[c[2]] };
      std::sort(out.Key.begin(), out.Key.end());
      return out;
    };
    std::vector<vtkIdType> cornerOffsets, corners;
    std::vector<Term> terms;
    auto localTerms = [&](vtkIdType v)
    {
      terms.clear();
      for (vtkIdType c = cornerOffsets[v]; c < cornerOffsets[v + 1]; ++c)
      {
        terms.push_back(term(corners[c] / 3));
      }
    };
    // The normal of a vertex: its terms summed in the order of their keys.
    auto SumTerms = [](std::vector<Term>& list, double n[3])
    {
      std::sort(list.begin(), list.end());
      n[0] = n[1] = n[2] = 0;
      for (const Term& t : list)
      {
        for (int k = 0; k < 3; ++k)
        {
          n[k] += t.Cross[k];
        }
      }
      vtkMath::Normalize(n);
    };
    auto sum = [&](double n[3]) { SumTerms(terms, n); };

    // The terms of shared vertices go to their owners (in gid order, as the owners list them).
    std::vector<double> n;
    std::vector<std::vector<vtkIdType>> outgoing(this->R.Size);
    if (!this->R.Step("compute normals", problem,
          [&]()
          {
            n.assign(3 * this->N, 0.0);
            this->CornersAround(cornerOffsets, corners);
            for (int o = 0; o < this->R.Size; ++o)
            {
              for (vtkIdType v : this->FromOwner[o])
              {
                localTerms(v);
                outgoing[o].push_back(static_cast<vtkIdType>(terms.size()));
                for (const Term& t : terms)
                {
                  outgoing[o].insert(outgoing[o].end(),
                    { t.Key[0], t.Key[1], t.Key[2], PackDouble(t.Cross[0]), PackDouble(t.Cross[1]),
                      PackDouble(t.Cross[2]) });
                }
              }
            }
          }))
    {
      return {};
    }
    const auto incoming = this->R.Exchange(outgoing, this->Partners, NormalTag);
    std::vector<float> normals;
    if (!this->R.Step("compute normals", problem,
          [&]()
          {
            // Each vertex's own terms, on threads (each range with its own list of terms).
            rgmc::ParallelFor(this->N, RowGrain,
              [&](vtkIdType first, vtkIdType last)
              {
                std::vector<Term> own;
                for (vtkIdType v = first; v < last; ++v)
                {
                  own.clear();
                  for (vtkIdType c = cornerOffsets[v]; c < cornerOffsets[v + 1]; ++c)
                  {
                    own.push_back(term(corners[c] / 3));
                  }
                  SumTerms(own, &n[3 * v]);
                }
              });
            // Owned shared vertices: their own terms and every holder's, in the same order.
            std::vector<std::size_t> cursor(this->R.Size, 0);
            std::vector<std::pair<vtkIdType, int>> order; // (gid, sharer) of owned shared vertices
            for (int s = 0; s < this->R.Size; ++s)
            {
              if (s != this->R.Rank)
              {
                for (vtkIdType v : this->ToSharer[s])
                {
                  order.emplace_back(gid[v], s);
                }
              }
            }
            std::sort(order.begin(), order.end());
            for (std::size_t i = 0; i < order.size();)
            {
              const vtkIdType v = this->VertexOfGid(order[i].first);
              localTerms(v);
              for (; i < order.size() && order[i].first == gid[v]; ++i)
              {
                const std::vector<vtkIdType>& in = incoming[order[i].second];
                std::size_t& at = cursor[order[i].second];
                const vtkIdType count = at < in.size() ? in[at++] : 0;
                for (vtkIdType j = 0; j < count && at + 5 < in.size(); ++j, at += 6)
                {
                  terms.push_back(Term{ { in[at], in[at + 1], in[at + 2] },
                    { UnpackDouble(in[at + 3]), UnpackDouble(in[at + 4]),
                      UnpackDouble(in[at + 5]) } });
                }
              }
              sum(&n[3 * v]);
            }
          }))
    {
      return {};
    }
    this->Update(n.data(), NormalBackTag);
    if (!this->R.Step("compute normals", problem, [&]() { normals.assign(n.begin(), n.end()); }))
    {
      return {};
    }
    return normals;
  }

  std::vector<T> Smoothed; // positions of this rank's vertices after smoothing

private:
  /// The triangle corners (3 t + k) at each vertex, in compressed rows.
  void CornersAround(std::vector<vtkIdType>& offsets, std::vector<vtkIdType>& corners) const
  {
    offsets.assign(static_cast<std::size_t>(this->N) + 1, 0);
    for (vtkIdType c = 0; c < 3 * this->NumTriangles; ++c)
    {
      ++offsets[static_cast<vtkIdType>(this->Triangles[c]) + 1];
    }
    for (vtkIdType v = 0; v < this->N; ++v)
    {
      offsets[v + 1] += offsets[v];
    }
    corners.resize(static_cast<std::size_t>(3 * this->NumTriangles));
    std::vector<vtkIdType> fill(offsets.begin(), offsets.end() - 1);
    for (vtkIdType c = 0; c < 3 * this->NumTriangles; ++c)
    {
      corners[fill[static_cast<vtkIdType>(this->Triangles[c])]++] = c;
    }
  }

  int MaskOf(vtkIdType v) const
  {
    const T* x = this->X + 3 * v;
    const double p[3] = { static_cast<double>(x[0]), static_cast<double>(x[1]),
      static_cast<double>(x[2]) };
    return this->Border.Mask(
      this->Grid, this->Keys ? this->Keys[this->Local.PointOf(v)] : vtkIdType(0), p);
  }

  /// The vertex with global id `g` (this rank holds it): its vertices in identity order are in
  /// gid order.
  vtkIdType VertexOfGid(vtkIdType g) const
  {
    const std::vector<vtkIdType>& gid = this->Num.Gid;
    return *std::lower_bound(this->Local.Sorted.begin(), this->Local.Sorted.end(), g,
      [&gid](vtkIdType v, vtkIdType key) { return gid[v] < key; });
  }

  /// Sends each rank r the triples of `state` at the vertices send[r], and stores the triples
  /// rank r sends at the vertices receive[r] (both sides list a pair's vertices in one order).
  template <typename S>
  void Share(const std::vector<std::vector<vtkIdType>>& send,
    const std::vector<std::vector<vtkIdType>>& receive, S* state, int tag)
  {
    std::vector<std::vector<double>> out(this->R.Size);
    for (int r = 0; r < this->R.Size; ++r)
    {
      for (vtkIdType v : send[r])
      {
        out[r].insert(out[r].end(), state + 3 * v, state + 3 * v + 3);
      }
    }
    const auto in = this->R.Exchange(out, this->Partners, tag);
    for (int r = 0; r < this->R.Size; ++r)
    {
      const std::vector<vtkIdType>& list = receive[r];
      for (std::size_t i = 0; i < list.size() && 3 * i + 2 < in[r].size(); ++i)
      {
        for (int k = 0; k < 3; ++k)
        {
          state[3 * list[i] + k] = static_cast<S>(in[r][3 * i + k]);
        }
      }
    }
  }

  /// Fills the remote slots of `state` with the neighbours' states from their holders.
  template <typename S>
  void Fetch(S* state)
  {
    this->Share(this->Provide, this->RemoteOrder, state, StateTag);
  }

  /// Sends the owned shared vertices' `state` to their other holders.
  template <typename S>
  void Update(S* state, int tag = UpdateTag)
  {
    this->Share(this->ToSharer, this->FromOwner, state, tag);
  }

  Ranks& R;
  const LocalVertices& Local;
  const Numbering& Num;
  const BorderTest Border;
  const rgmc::Grid Grid;
  const vtkIdType* Keys; // the input's vertex keys, or null
  const T* X;            // positions of this rank's vertices
  const I* Triangles;    // over this rank's vertices
  const vtkIdType NumTriangles;
  const vtkIdType N;
  std::vector<bool> Partners; // the ranks that share a vertex with this one

  std::vector<std::int64_t> Owned; // the vertices this rank moves, one stencil row each
  rgmc::Stencils Stencil;
  std::vector<vtkIdType> RemoteGids; // neighbours of owned vertices held elsewhere, by slot
  std::vector<int> RemoteProviders;
  std::vector<double> RemoteInitial;
  std::vector<std::vector<vtkIdType>> ToSharer;     // holder -> owned shared vertices
  std::vector<std::vector<vtkIdType>> FromOwner;    // owner -> vertices it updates here
  std::vector<std::vector<vtkIdType>> Provide;      // requester -> vertices to send
  std::vector<std::vector<vtkIdType>> RemoteOrder;  // provider -> slots, in request order
  std::vector<std::vector<vtkIdType>> RequestLists; // provider -> gids asked of it
};

} // namespace

//------------------------------------------------------------------------------
vtkRGSeamRepair::vtkRGSeamRepair()
{
  this->SetController(vtkMultiProcessController::GetGlobalController());
}

//------------------------------------------------------------------------------
vtkRGSeamRepair::~vtkRGSeamRepair()
{
  this->SetController(nullptr);
}

//------------------------------------------------------------------------------
int vtkRGSeamRepair::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPolyData* input = vtkPolyData::GetData(inputVector[0]);
  vtkPolyData* output = vtkPolyData::GetData(outputVector);
  vtkNew<vtkDummyController> single;
  Ranks ranks(this->Controller ? this->Controller : single.Get());
  // A new run: an abort of an earlier run does not carry over (VTK 9.2 cleared the flag itself;
  // VTK 9.3 and later keep it, so an aborted filter would stay empty). Set directly, as
  // SetAbortExecute would mark the filter modified and make it run again.
  this->AbortExecute = 0;

  // PASS 0: a triangle mesh, on every rank.
  std::string problem;
  {
    std::ostringstream msg;
    const vtkIdType verts = input->GetNumberOfVerts(), lines = input->GetNumberOfLines(),
                    strips = input->GetNumberOfStrips();
    vtkIdType other = 0;
    vtkCellArray* polys = input->GetPolys();
    vtkIdType npts;
    const vtkIdType* pts;
    for (polys->InitTraversal(); polys->GetNextCell(npts, pts);)
    {
      other += npts != 3;
    }
    if (verts || lines || strips || other)
    {
      msg << "the input is not a triangle mesh: it has " << verts << " vertex cells, " << lines
          << " lines, " << strips << " triangle strips and " << other
          << " polygons that are not triangles (apply Triangulate, or Extract Surface, first)";
    }
    problem = msg.str();
  }
  if (!ranks.Agree(problem.empty(), problem))
  {
    vtkErrorMacro(<< "Cannot repair the seams: " << problem << ".");
    return 0;
  }
  vtkIdType localTriangles = input->GetNumberOfPolys(), triangles = 0;
  ranks.Check(ranks.C->AllReduce(&localTriangles, &triangles, 1, vtkCommunicator::SUM_OP),
    "counting triangles");
  if (!ranks.Agree(triangles > 0, problem))
  {
    vtkErrorMacro(<< "Cannot repair the seams: "
                  << (problem.empty() ? std::string("the input has no triangles") : problem)
                  << ".");
    return 0;
  }
  this->UpdateProgress(0.05);

  // PASS 1: this rank's distinct vertices and their global numbering. Identities are global ids
  // when every rank with points has them, else exact coordinates.
  vtkIdTypeArray* keyArray = vtkIdTypeArray::SafeDownCast(input->GetPointData()->GetGlobalIds());
  int keyed = input->GetNumberOfPoints() == 0 || keyArray ? 1 : 0, allKeyed = 0;
  ranks.Check(ranks.C->AllReduce(&keyed, &allKeyed, 1, vtkCommunicator::MIN_OP),
    "agreeing on vertex identities");
  const vtkIdType* keys = allKeyed && keyArray ? keyArray->GetPointer(0) : nullptr;
  LocalVertices local;
  Numbering numbering;
  auto number = [&](auto words)
  {
    constexpr int Words = decltype(words)::value;
    std::vector<Identity<Words>> ids;
    return ranks.Step("sort the vertices", problem,
             [&]() { local = MergeLocal<Words>(input, keys, ids); }) &&
      Number<Words>(ranks, local, ids, numbering, problem);
  };
  if (!(allKeyed ? number(std::integral_constant<int, 1>())
                 : number(std::integral_constant<int, 3>())))
  {
    vtkErrorMacro(<< "Cannot repair the seams: " << problem << ".");
    return 0;
  }
  this->UpdateProgress(0.25);

  // How to tell edges on the volume's border: from keys and the whole extent when the input
  // came from vtkRGMarchingCubes, else from the global bounds.
  BorderTest border;
  {
    double b[6], lo[3], hi[3], glo[3], ghi[3];
    input->GetBounds(b);
    for (int a = 0; a < 3; ++a)
    {
      lo[a] = input->GetNumberOfPoints() ? b[2 * a] : VTK_DOUBLE_MAX;
      hi[a] = input->GetNumberOfPoints() ? b[2 * a + 1] : VTK_DOUBLE_MIN;
    }
    ranks.Check(ranks.C->AllReduce(lo, glo, 3, vtkCommunicator::MIN_OP), "reducing bounds");
    ranks.Check(ranks.C->AllReduce(hi, ghi, 3, vtkCommunicator::MAX_OP), "reducing bounds");
    double diagonal = 0;
    for (int a = 0; a < 3; ++a)
    {
      border.Bounds[2 * a] = glo[a];
      border.Bounds[2 * a + 1] = ghi[a];
      diagonal += (ghi[a] - glo[a]) * (ghi[a] - glo[a]);
    }
    border.Tolerance = 1e-6 * std::sqrt(diagonal);
    vtkIntArray* whole = vtkIntArray::SafeDownCast(input->GetFieldData()->GetArray("WholeExtent"));
    if (keys && whole && whole->GetNumberOfValues() == 6)
    {
      border.Keys = true;
      for (int i = 0; i < 6; ++i)
      {
        border.Whole[i] = whole->GetValue(i);
      }
    }
  }

  // PASS 2-4: edges at the seams, checks, smoothing, normals; in the input points' precision,
  // over the input's own connectivity when no points were merged.
  const bool smooth = this->SmoothingMethod != NO_SMOOTHING && this->NumberOfIterations > 0;
  const bool doublePoints = input->GetPoints() && input->GetPoints()->GetDataType() == VTK_DOUBLE;
  vtkDataArray* inputConnectivity = input->GetPolys()->GetConnectivityArray();
  std::vector<vtkIdType> connectivityCopy; // when the input's cannot be used as it is
  vtkNew<vtkPoints> points;
  std::vector<float> normals;
  Checks checks;
  bool aborted = false;
  auto progress = [this, &ranks](double fraction)
  {
    this->UpdateProgress(0.4 + 0.5 * fraction);
    return ranks.Any(this->CheckAbort());
  };
  auto run = [&](auto pointType, auto indexType) -> bool
  {
    using T = decltype(pointType);
    using I = decltype(indexType);
    const T* x = nullptr;
    std::vector<T> xCopy;
    const I* tris = nullptr;
    if (!ranks.Step("copy the input", problem,
          [&]()
          {
            using PointArray = vtkAOSDataArrayTemplate<T>;
            PointArray* inputPoints = input->GetPoints()
              ? PointArray::FastDownCast(input->GetPoints()->GetData())
              : nullptr;
            if (inputPoints && !local.Merged())
            {
              x = inputPoints->GetPointer(0);
            }
            else
            {
              xCopy.resize(static_cast<std::size_t>(3 * local.Count));
              for (vtkIdType v = 0; v < local.Count; ++v)
              {
                double p[3];
                input->GetPoint(local.PointOf(v), p);
                for (int k = 0; k < 3; ++k)
                {
                  xCopy[3 * v + k] = static_cast<T>(p[k]);
                }
              }
              x = xCopy.data();
            }
            using IndexArray = vtkAOSDataArrayTemplate<I>;
            IndexArray* typed = IndexArray::FastDownCast(inputConnectivity);
            if (typed && !local.Merged())
            {
              tris = typed->GetPointer(0); // every cell is a triangle (PASS 0)
            }
            else if constexpr (std::is_same<I, vtkIdType>::value)
            {
              connectivityCopy.reserve(static_cast<std::size_t>(3 * input->GetNumberOfPolys()));
              vtkCellArray* polys = input->GetPolys();
              vtkIdType npts;
              const vtkIdType* pts;
              for (polys->InitTraversal(); polys->GetNextCell(npts, pts);)
              {
                for (int k = 0; k < 3; ++k)
                {
                  connectivityCopy.push_back(local.VertexOf(pts[k]));
                }
              }
              tris = connectivityCopy.data();
            }
          }))
    {
      return false;
    }
    Repair<T, I> repair(ranks, local, numbering, border, keys, x, tris, input->GetNumberOfPolys());
    if (!repair.Analyze(smooth, checks, problem))
    {
      return false;
    }
    this->UpdateProgress(0.4);
    if (smooth)
    {
      if (!repair.Smooth(this->SmoothingMethod, this->NumberOfIterations, this->RelaxationFactor,
            this->PassBand,
            this->WindowFunction == HAMMING_WINDOW ? rgmc::SincWindow::Hamming
                                                   : rgmc::SincWindow::Nuttall,
            progress, problem))
      {
        aborted = problem.empty();
        return false;
      }
      normals = repair.Normals(problem);
      if (normals.empty() && local.Count > 0)
      {
        return false;
      }
    }
    // The output's points: the input's own when nothing moved and nothing was merged.
    return ranks.Step("store the output points", problem,
      [&]()
      {
        const std::vector<T>& moved = smooth ? repair.Smoothed : xCopy;
        if (!smooth && !local.Merged())
        {
          points->ShallowCopy(input->GetPoints());
          return;
        }
        vtkNew<vtkAOSDataArrayTemplate<T>> xyz;
        xyz->SetNumberOfComponents(3);
        std::copy(moved.begin(), moved.begin() + 3 * local.Count,
          rgmc::Allocate(xyz.Get(), 3 * local.Count));
        points->SetData(xyz);
      });
  };
  // A connectivity copy is always 64-bit; the input's own may be 32-bit.
  const bool int32 = !local.Merged() && vtkTypeInt32Array::FastDownCast(inputConnectivity);
  bool ok;
  if (doublePoints)
  {
    ok = int32 ? run(double(), std::int32_t()) : run(double(), vtkIdType());
  }
  else
  {
    ok = int32 ? run(float(), std::int32_t()) : run(float(), vtkIdType());
  }
  if (aborted)
  {
    output->Initialize();
    return 1;
  }
  if (!ok)
  {
    vtkErrorMacro(<< "Cannot repair the seams: " << problem << ".");
    output->Initialize();
    return 0;
  }

  // Global checks.
  vtkIdType counts[4] = { checks.Edges, checks.Boundary, checks.Border, checks.NonManifold },
            sums[4] = { 0, 0, 0, 0 };
  ranks.Check(ranks.C->AllReduce(counts, sums, 4, vtkCommunicator::SUM_OP), "summing the checks");
  const vtkIdType euler = numbering.Total - sums[0] + triangles;
  const bool closed = sums[1] == 0 && sums[3] == 0;

  // PASS 5: the output: the input's triangles and point data as they are (merged when points
  // were), global ids, duplicate flags, smoothed points and their normals.
  const vtkIdType n = local.Count;
  output->Initialize();
  if (!ranks.Step("build the output", problem,
        [&]()
        {
          output->SetPoints(points);
          vtkPointData* pd = output->GetPointData();
          pd->CopyGlobalIdsOff();
          if (smooth)
          {
            pd->CopyNormalsOff();
          }
          if (!local.Merged())
          {
            output->SetPolys(input->GetPolys());
            pd->PassData(input->GetPointData());
          }
          else
          {
            vtkNew<vtkIdTypeArray> offsets, conn;
            const vtkIdType numTris = static_cast<vtkIdType>(connectivityCopy.size() / 3);
            vtkIdType* o = rgmc::Allocate(offsets.Get(), numTris + 1);
            for (vtkIdType t = 0; t <= numTris; ++t)
            {
              o[t] = 3 * t;
            }
            std::copy(connectivityCopy.begin(), connectivityCopy.end(),
              rgmc::Allocate(conn.Get(), static_cast<vtkIdType>(connectivityCopy.size())));
            vtkNew<vtkCellArray> polys;
            polys->SetData(offsets, conn);
            output->SetPolys(polys);
            pd->CopyAllocate(input->GetPointData(), n);
            for (vtkIdType v = 0; v < n; ++v)
            {
              pd->CopyData(input->GetPointData(), local.PointOf(v), v);
            }
          }
          output->GetCellData()->PassData(input->GetCellData());
          vtkNew<vtkIdTypeArray> gids;
          gids->SetName("GlobalPointIds");
          vtkNew<vtkUnsignedCharArray> ghosts;
          ghosts->SetName(vtkDataSetAttributes::GhostArrayName());
          std::copy(numbering.Gid.begin(), numbering.Gid.end(), rgmc::Allocate(gids.Get(), n));
          unsigned char* ghost = rgmc::Allocate(ghosts.Get(), n);
          for (vtkIdType v = 0; v < n; ++v)
          {
            ghost[v] = (numbering.Holding[v] & Numbering::Foreign)
              ? vtkDataSetAttributes::DUPLICATEPOINT
              : 0;
          }
          pd->SetGlobalIds(gids);
          pd->AddArray(ghosts);
          if (smooth)
          {
            vtkNew<vtkFloatArray> normalArray;
            normalArray->SetName("Normals");
            normalArray->SetNumberOfComponents(3);
            std::copy(normals.begin(), normals.end(), rgmc::Allocate(normalArray.Get(), 3 * n));
            pd->SetNormals(normalArray);
          }
        }))
  {
    vtkErrorMacro(<< "Cannot repair the seams: " << problem << ".");
    output->Initialize();
    return 0;
  }

  vtkFieldData* fd = output->GetFieldData();
  fd->PassData(input->GetFieldData());
  auto add = [fd](const char* name, vtkIdType value)
  {
    vtkNew<vtkIdTypeArray> a;
    a->SetName(name);
    a->InsertNextValue(value);
    fd->AddArray(a);
  };
  add("UniquePoints", numbering.Total);
  add("Triangles", triangles);
  add("Edges", sums[0]);
  add("BoundaryEdges", sums[1]);
  add("VolumeBorderEdges", sums[2]);
  add("NonManifoldEdges", sums[3]);
  add("EulerCharacteristic", euler);
  add("Closed", closed ? 1 : 0);
  if (ranks.Rank == 0)
  {
    vtkLogF(INFO,
      "Seam repair: %lld unique points, %lld triangles, %lld edges, %lld boundary edges (%lld "
      "more on the volume's border), %lld non-manifold edges, Euler characteristic %lld: %s.",
      static_cast<long long>(numbering.Total), static_cast<long long>(triangles),
      static_cast<long long>(sums[0]), static_cast<long long>(sums[1]),
      static_cast<long long>(sums[2]), static_cast<long long>(sums[3]),
      static_cast<long long>(euler), closed ? "closed" : "not closed");
  }
  this->UpdateProgress(1.0);
  return 1;
}

//------------------------------------------------------------------------------
void vtkRGSeamRepair::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "SmoothingMethod: " << this->SmoothingMethod << "\n";
  os << indent << "NumberOfIterations: " << this->NumberOfIterations << "\n";
  os << indent << "RelaxationFactor: " << this->RelaxationFactor << "\n";
  os << indent << "PassBand: " << this->PassBand << "\n";
  os << indent
     << "WindowFunction: " << (this->WindowFunction == HAMMING_WINDOW ? "Hamming" : "Nuttall")
     << "\n";
  os << indent << "Controller: " << this->Controller << "\n";
}

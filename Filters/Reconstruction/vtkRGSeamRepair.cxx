// Seam repair: global vertex numbering across ranks, global mesh checks, and smoothing that is
// the same on any number of ranks.
#include "vtkRGSeamRepair.h"

#include "rgmcBuffer.h"
#include "rgmcGrid.h"
#include "rgmcKeyMap.h"
#include "rgmcMeasure.h"
#include "rgmcRadixSort.h"
#include "rgmcSmoothing.h"
#include "vtkRGArrays.h"
#include "vtkRGCollective.h"
#include "vtkRGCompatibility.h"
#include "vtkRGMessage.h"
#include "vtkRGParallel.h"
#include "vtkRGRunController.h"

#include "vtkAOSDataArrayTemplate.h"
#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkDataSetAttributes.h"
#include "vtkDoubleArray.h"
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
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <numeric>
#include <queue>
#include <sstream>
#include <stdexcept>
#include <type_traits>
#include <vector>

vtkStandardNewMacro(vtkRGSeamRepair);
vtkCxxSetObjectMacro(vtkRGSeamRepair, Controller, vtkMultiProcessController);

namespace
{

using rgmc::Ranks;
constexpr int NumberingTag = 48800, AnswerTag = 48802, EdgesTag = 48804, RequestTag = 48806,
              StateTag = 48808, UpdateTag = 48810, NormalTag = 48812, NormalBackTag = 48814;
/// Rows (vertices) per range when smoothing and normals run on threads. Large: VTK 9.2's
/// STDThread backend (ParaView 5.11) queues one job per range under a lock, and 512-row ranges
/// (2 000 jobs per Laplacian step on the 512^3 skull) cost a third of the step on two threads.
constexpr vtkIdType RowGrain = 16384;

// ---- vertex identities -----------------------------------------------------------------------

/// What makes copies of a vertex one vertex: its key (one word), or its exact coordinates (three).
template <int Words>
using Identity = std::array<std::uint64_t, Words>;

/// A coordinate as identity bits: -0 and +0 are one coordinate.
std::uint64_t Bits(double v)
{
  v = v == 0.0 ? 0.0 : v;
  std::uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

/// An identity's word in a message, and back.
vtkIdType WordOfBits(std::uint64_t bits)
{
  vtkIdType word;
  std::memcpy(&word, &bits, sizeof word);
  return word;
}

std::uint64_t BitsOfWord(vtkIdType word)
{
  std::uint64_t bits;
  std::memcpy(&bits, &word, sizeof bits);
  return bits;
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
  rgmc::LargeVector<std::pair<Identity<Words>, vtkIdType>> all(static_cast<std::size_t>(n));
  // One-word identities (the keys) are sorted packed with their points, one word each, where
  // both fit in 64 bits: a key takes log2 of 4 x the grid points (edge keys, then point keys), an
  // index log2 of the points (a 2048^3 volume leaves room for 500 million points).
  bool packed = false;
  if constexpr (Words == 1)
  {
    packed = rgmc::RadixSortPacked(
      static_cast<std::size_t>(n), [keys](std::size_t p) { return BitsOfWord(keys[p]); },
      [&all](std::size_t r, std::uint64_t key, std::size_t p)
      {
        all[r].first[0] = key;
        all[r].second = static_cast<vtkIdType>(p);
      });
  }
  for (vtkIdType p = 0; p < n && !packed; ++p)
  {
    Identity<Words>& id = all[p].first;
    if (Words == 1)
    {
      id[0] = BitsOfWord(keys[p]);
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
  // (identity, point) pairs are distinct. One-word identities (the keys) by a radix sort: the
  // points come in increasing order, so its stable order is the pairs' order.
  if constexpr (Words == 1)
  {
    if (!packed)
    {
      rgmc::RadixSort(
        all, [](const std::pair<Identity<Words>, vtkIdType>& entry) { return entry.first[0]; });
    }
  }
  else
  {
    rgmc::ParallelSort(all);
  }
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
struct GlobalNumbering
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
/// several ranks, the holders (the lowest owns the vertex).
template <int Words>
class IdentityNumbering
{
public:
  IdentityNumbering(Ranks& ranks, const LocalVertices& vertices, std::vector<Identity<Words>>& ids)
    : AllRanks(ranks)
    , Vertices(vertices)
    , Ids(ids)
    , SliceStart(ranks.Size + 1, ids.size())
  {
  }

  /// Collective: AllGather and AllGatherV (the samples), an agreement, an exchange with every
  /// rank (the identities), an agreement, an AllGather (the count each range numbered), an
  /// exchange (the answers), an agreement; on one rank, one agreement. False (on every rank,
  /// with `problem`) on failure.
  bool Number(GlobalNumbering& numbering, std::string& problem)
  {
    if (this->AllRanks.Size == 1)
    {
      // Alone: the distinct identities, sorted, are numbered in order (what the merge below
      // gives with one stream, without its heap).
      return this->AllRanks.Step("number the vertices", problem,
        [&]()
        {
          numbering.Total = this->Vertices.Count;
          numbering.Gid.resize(static_cast<std::size_t>(this->Vertices.Count));
          for (vtkIdType i = 0; i < this->Vertices.Count; ++i)
          {
            numbering.Gid[this->Vertices.Sorted[i]] = i;
          }
          numbering.Holding.assign(
            static_cast<std::size_t>(this->Vertices.Count), GlobalNumbering::Alone);
          std::vector<Identity<Words>>().swap(this->Ids);
        });
    }
    const std::vector<bool> everyone(this->AllRanks.Size, true);
    this->GatherSamples();
    std::vector<std::vector<vtkIdType>> toRanges(this->AllRanks.Size);
    if (!this->AllRanks.Step(
          "send the vertex identities", problem, [&]() { this->SliceByRange(toRanges); }))
    {
      return false;
    }
    auto received = this->AllRanks.Exchange(toRanges, everyone, NumberingTag);
    std::vector<std::vector<vtkIdType>>().swap(toRanges);
    std::vector<std::vector<vtkIdType>> answers(this->AllRanks.Size);
    if (!this->AllRanks.Step(
          "number the vertex identities", problem, [&]() { this->NumberRange(received, answers); }))
    {
      return false;
    }
    this->GatherRangeCounts();
    const auto replies = this->AllRanks.Exchange(answers, everyone, AnswerTag);
    std::vector<std::vector<vtkIdType>>().swap(answers);
    return this->AllRanks.Step(
      "number the vertices", problem, [&]() { this->StoreAnswers(replies, numbering); });
  }

private:
  /// Up to 64 identities sampled on each rank, given to every rank.
  void GatherSamples()
  {
    const int numRanks = this->AllRanks.Size;
    const std::size_t n = this->Ids.size();
    std::vector<vtkIdType> samples;
    for (std::size_t i = 0, k = std::min<std::size_t>(n, 64); i < k; ++i)
    {
      for (std::uint64_t w : this->Ids[i * n / k])
      {
        samples.push_back(WordOfBits(w));
      }
    }
    vtkIdType count = static_cast<vtkIdType>(samples.size());
    std::vector<vtkIdType> counts(numRanks);
    this->SampleOffsets.assign(numRanks + 1, 0);
    this->AllRanks.AllGather(&count, counts.data(), 1, "gathering sample counts");
    for (int r = 0; r < numRanks; ++r)
    {
      this->SampleOffsets[r + 1] = this->SampleOffsets[r] + counts[r];
    }
    this->AllSamples.resize(static_cast<std::size_t>(this->SampleOffsets[numRanks]) + 1);
    this->AllRanks.AllGatherV(samples.data(), this->AllSamples.data(), count, counts.data(),
      this->SampleOffsets.data(), "gathering samples");
  }

  /// Ranges of about equal size, from the sorted samples; rank h gets one slice of this rank's
  /// sorted identities. The identities are no longer needed here after that.
  void SliceByRange(std::vector<std::vector<vtkIdType>>& toRanges)
  {
    const int numRanks = this->AllRanks.Size;
    const std::size_t n = this->Ids.size();
    std::vector<Identity<Words>> sorted(
      static_cast<std::size_t>(this->SampleOffsets[numRanks] / Words));
    for (std::size_t s = 0; s < sorted.size(); ++s)
    {
      for (int k = 0; k < Words; ++k)
      {
        sorted[s][k] = BitsOfWord(this->AllSamples[Words * s + k]);
      }
    }
    std::sort(sorted.begin(), sorted.end());
    std::vector<Identity<Words>> splitters;
    for (int h = 1; h < numRanks && !sorted.empty(); ++h)
    {
      splitters.push_back(sorted[h * sorted.size() / numRanks]);
    }
    this->SliceStart[0] = 0;
    for (int h = 1; h <= numRanks; ++h)
    {
      this->SliceStart[h] = h - 1 < static_cast<int>(splitters.size())
        ? static_cast<std::size_t>(
            std::upper_bound(this->Ids.begin(), this->Ids.end(), splitters[h - 1]) -
            this->Ids.begin())
        : n;
    }
    for (int h = 0; h < numRanks; ++h)
    {
      toRanges[h].reserve(Words * (this->SliceStart[h + 1] - this->SliceStart[h]));
      for (std::size_t i = this->SliceStart[h]; i < this->SliceStart[h + 1]; ++i)
      {
        for (std::uint64_t w : this->Ids[i])
        {
          toRanges[h].push_back(WordOfBits(w));
        }
      }
    }
    std::vector<Identity<Words>>().swap(this->Ids);
  }

  /// Merges the ranks' sorted streams of this range and numbers the distinct identities in
  /// order. Each answer holds the range's number of every identity received (made a global id
  /// by the sender), then, for the identities held by several ranks, (position, number of
  /// holders, holders...).
  void NumberRange(
    std::vector<std::vector<vtkIdType>>& received, std::vector<std::vector<vtkIdType>>& answers)
  {
    const int numRanks = this->AllRanks.Size;
    using Head = std::pair<Identity<Words>, int>; // identity, source
    std::priority_queue<Head, std::vector<Head>, std::greater<Head>> heads;
    std::vector<std::size_t> next(numRanks, 0);
    auto push = [&](int s)
    {
      const std::vector<vtkIdType>& in = received[s];
      if (next[s] + Words <= in.size())
      {
        Identity<Words> id;
        for (int k = 0; k < Words; ++k)
        {
          id[k] = BitsOfWord(in[next[s] + k]);
        }
        heads.emplace(id, s);
      }
    };
    for (int s = 0; s < numRanks; ++s)
    {
      answers[s].reserve(received[s].size() / Words);
      push(s);
    }
    std::vector<std::vector<vtkIdType>> sharedRecords(numRanks);
    std::vector<int> holders; // sources of the current identity, in increasing order
    while (!heads.empty())
    {
      const Identity<Words> id = heads.top().first;
      holders.clear();
      while (!heads.empty() && heads.top().first == id)
      {
        const int s = heads.top().second;
        heads.pop();
        holders.push_back(s);
        answers[s].push_back(this->Numbered);
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
      ++this->Numbered;
    }
    std::vector<std::vector<vtkIdType>>().swap(received);
    for (int s = 0; s < numRanks; ++s)
    {
      answers[s].insert(answers[s].end(), sharedRecords[s].begin(), sharedRecords[s].end());
    }
  }

  /// The first global id of each range: the counts of the ranges before it.
  void GatherRangeCounts()
  {
    const int numRanks = this->AllRanks.Size;
    std::vector<vtkIdType> counts(numRanks);
    this->RangeFirst.assign(numRanks + 1, 0);
    this->AllRanks.AllGather(&this->Numbered, counts.data(), 1, "gathering vertex counts");
    for (int r = 0; r < numRanks; ++r)
    {
      this->RangeFirst[r + 1] = this->RangeFirst[r] + counts[r];
    }
  }

  /// The global id of each vertex, and the holders of the shared ones (in increasing position
  /// in each answer: the shared vertices come in global-id order).
  void StoreAnswers(
    const std::vector<std::vector<vtkIdType>>& replies, GlobalNumbering& numbering) const
  {
    const int numRanks = this->AllRanks.Size, me = this->AllRanks.Rank;
    numbering.Total = this->RangeFirst[numRanks];
    numbering.Gid.resize(static_cast<std::size_t>(this->Vertices.Count));
    numbering.Holding.assign(
      static_cast<std::size_t>(this->Vertices.Count), GlobalNumbering::Alone);
    for (int h = 0; h < numRanks; ++h)
    {
      const std::vector<vtkIdType>& in = replies[h];
      const std::size_t sent = this->SliceStart[h + 1] - this->SliceStart[h];
      for (std::size_t i = 0; i < sent; ++i)
      {
        numbering.Gid[this->Vertices.Sorted[this->SliceStart[h] + i]] = this->RangeFirst[h] + in[i];
      }
      for (std::size_t i = sent; i + 1 < in.size();)
      {
        const vtkIdType v =
          this->Vertices.Sorted[this->SliceStart[h] + static_cast<std::size_t>(in[i])];
        const vtkIdType holders = in[i + 1];
        const int owner = static_cast<int>(in[i + 2]);
        numbering.SharedVertex.push_back(v);
        numbering.SharedOwner.push_back(owner);
        numbering.Holding[v] = owner != me ? GlobalNumbering::Shared | GlobalNumbering::Foreign
                                           : GlobalNumbering::Shared;
        for (vtkIdType j = 0; j < holders; ++j)
        {
          const int holder = static_cast<int>(in[i + 2 + j]);
          if (holder != me)
          {
            numbering.Sharers.push_back(holder);
          }
        }
        numbering.SharerOffsets.push_back(static_cast<vtkIdType>(numbering.Sharers.size()));
        i += 2 + static_cast<std::size_t>(holders);
      }
    }
  }

  Ranks& AllRanks;
  const LocalVertices& Vertices;
  std::vector<Identity<Words>>& Ids;    // this rank's, sorted (released once sent)
  std::vector<vtkIdType> SampleOffsets; // per rank, into AllSamples (in words)
  std::vector<vtkIdType> AllSamples;
  std::vector<std::size_t> SliceStart; // per range: its first identity of this rank's
  vtkIdType Numbered = 0;              // distinct identities in this rank's range
  std::vector<vtkIdType> RangeFirst;   // per range: its first global id
};

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

// ---- the input and the output --------------------------------------------------------------

/// The positions and triangles of this rank's vertices: the input's own arrays when no points
/// are merged and they have the types asked for, otherwise copies (`copied`, `connectivity`).
/// Every cell is a triangle (checked before).
template <typename T, typename I>
const I* CopyInput(vtkPolyData* input, const LocalVertices& vertices, const T*& positions,
  std::vector<T>& copied, std::vector<vtkIdType>& connectivity)
{
  using PointArray = vtkAOSDataArrayTemplate<T>;
  PointArray* inputPoints =
    input->GetPoints() ? PointArray::FastDownCast(input->GetPoints()->GetData()) : nullptr;
  if (inputPoints && !vertices.Merged())
  {
    positions = inputPoints->GetPointer(0);
  }
  else
  {
    copied.resize(static_cast<std::size_t>(3 * vertices.Count));
    for (vtkIdType v = 0; v < vertices.Count; ++v)
    {
      double p[3];
      input->GetPoint(vertices.PointOf(v), p);
      for (int k = 0; k < 3; ++k)
      {
        copied[3 * v + k] = static_cast<T>(p[k]);
      }
    }
    positions = copied.data();
  }
  using IndexArray = vtkAOSDataArrayTemplate<I>;
  IndexArray* typed = IndexArray::FastDownCast(input->GetPolys()->GetConnectivityArray());
  if (typed && !vertices.Merged())
  {
    return typed->GetPointer(0);
  }
  if constexpr (std::is_same<I, vtkIdType>::value)
  {
    connectivity.reserve(static_cast<std::size_t>(3 * input->GetNumberOfPolys()));
    vtkCellArray* polys = input->GetPolys();
    vtkIdType npts;
    const vtkIdType* pts;
    for (polys->InitTraversal(); polys->GetNextCell(npts, pts);)
    {
      for (int k = 0; k < 3; ++k)
      {
        connectivity.push_back(vertices.VertexOf(pts[k]));
      }
    }
    return connectivity.data();
  }
  return nullptr;
}

/// What the smoothing is asked to do.
struct SmoothingSettings
{
  int Method = vtkRGSeamRepair::NO_SMOOTHING;
  int Iterations = 0;
  double Relaxation = 0.0;
  double PassBand = 0.0;
  rgmc::SincWindow Window = rgmc::SincWindow::Nuttall;
};

/// The surface's area and the volume it encloses (closed by the volume's border planes where it
/// is cut by them: `capArea`), in world units; the volume is NaN when the surface has a hole.
struct Measures
{
  double Area = 0.0;
  double Volume = 0.0;
  double CapArea = 0.0;
  bool Closable = true;
};

/// The repair of one rank's piece, with points of type T and triangles over vertex indices of
/// type I (the input's own connectivity when its points need no merging): the seams analysed,
/// the smoothing, the normals. Each public step is collective and returns false (on every rank,
/// with `problem`) on failure.
template <typename T, typename I>
class PieceRepair
{
public:
  PieceRepair(Ranks& ranks, const LocalVertices& vertices, const GlobalNumbering& numbering,
    const BorderTest& border, const vtkIdType* keys, const T* positions, const I* triangles,
    vtkIdType numTriangles)
    : AllRanks(ranks)
    , Vertices(vertices)
    , Numbering(numbering)
    , Border(border)
    , Grid(border.Whole, border.Whole)
    , Keys(keys)
    , Positions(positions)
    , Triangles(triangles)
    , NumTriangles(numTriangles)
    , NumVertices(vertices.Count)
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

  /// Smooths the positions into Smoothed. Returns false when aborted (`problem` empty) or
  /// failed. Per iteration: a reduction (abort) and two exchanges with the sharing ranks.
  bool Smooth(const SmoothingSettings& settings, const std::function<bool(double)>& progress,
    std::string& problem)
  {
    bool aborted = false;
    const bool done = settings.Method == vtkRGSeamRepair::WINDOWED_SINC
      ? this->SmoothWindowedSinc(settings, progress, aborted, problem)
      : this->SmoothLaplacian(settings, progress, aborted, problem);
    if (!done)
    {
      return false;
    }
    // The stencils are done with: the normals need the memory.
    rgmc::LargeVector<I>().swap(this->Stencil.Neighbours);
    std::vector<std::int64_t>().swap(this->Stencil.Offsets);
    std::vector<I>().swap(this->Owned);
    if (!this->AllRanks.Agree(true, problem) || aborted)
    {
      return false;
    }
    this->Smoothed.resize(3 * this->NumVertices);
    return true;
  }

  /// Area-weighted vertex normals of the smoothed positions. Each vertex sums its triangles'
  /// area vectors in one order fixed by the mesh (by the triangles' sorted global ids), at its
  /// owner, so that the normals are the same to the bit for any number of ranks. Two exchanges,
  /// three agreements; the output's array "Normals", or null on failure.
  vtkSmartPointer<vtkFloatArray> Normals(std::string& problem)
  {
    rgmc::LargeVector<double> sums;
    std::vector<std::vector<vtkIdType>> toOwners(this->AllRanks.Size);
    if (!this->AllRanks.Step("compute normals", problem,
          [&]()
          {
            sums.assign(3 * this->NumVertices, 0.0);
            if (this->CornerOffsets.empty())
            {
              this->CornersAround(this->CornerOffsets, this->Corners);
            }
            this->ComputeTriangleCrosses();
            this->ListSharedTerms(toOwners);
          }))
    {
      return nullptr;
    }
    const auto received = this->AllRanks.Exchange(toOwners, this->Partners, NormalTag);
    if (!this->AllRanks.Step("compute normals", problem,
          [&]()
          {
            this->SumOwnTerms(sums);
            this->SumSharedTerms(received, sums);
          }))
    {
      return nullptr;
    }
    rgmc::LargeVector<double>().swap(this->TriangleCross);
    this->Update(sums.data(), NormalBackTag);
    auto normals = vtkSmartPointer<vtkFloatArray>::New();
    if (!this->AllRanks.Step("compute normals", problem,
          [&]()
          {
            // Straight into the output's array, rounded to float on threads.
            normals->SetName("Normals");
            normals->SetNumberOfComponents(3);
            float* out = rgmc::Allocate(normals.Get(), 3 * this->NumVertices);
            rgmc::ParallelFor(3 * this->NumVertices, 3 * RowGrain,
              [&](vtkIdType first, vtkIdType last)
              {
                for (vtkIdType i = first; i < last; ++i)
                {
                  out[i] = static_cast<float>(sums[i]);
                }
              });
          }))
    {
      return nullptr;
    }
    return normals;
  }

  /// This rank's triangles' sums of twice the area and six times the volume (rgmcMeasure.h),
  /// at `positions`, on threads: exact sums, the same for any split of the triangles.
  rgmc::TriangleSums SumTriangles(const T* positions, const double centre[3], double scale) const
  {
    const vtkIdType grain = 65536;
    const vtkIdType blocks = (this->NumTriangles + grain - 1) / grain;
    std::vector<rgmc::TriangleSums> partial(static_cast<std::size_t>(blocks));
    rgmc::ParallelFor(blocks, 1,
      [&](vtkIdType first, vtkIdType last)
      {
        for (vtkIdType b = first; b < last; ++b)
        {
          // Summed here, then stored: neighbouring blocks' sums share cache lines.
          rgmc::TriangleSums sum;
          sum.Add(positions, this->Triangles, b * grain,
            std::min(this->NumTriangles, (b + 1) * grain), centre, scale);
          partial[b] = sum;
        }
      });
    rgmc::TriangleSums sums;
    for (const rgmc::TriangleSums& p : partial)
    {
      sums.Add(p);
    }
    return sums;
  }

  /// This rank's triangle edges whose two ends lie on a common face of the volume (the caps'
  /// candidates, rgmc::BorderEdge), at `positions`, packed.
  std::vector<double> BorderEdges(const T* positions, const rgmc::VolumeBox& box) const
  {
    std::vector<int> faces(static_cast<std::size_t>(this->NumVertices));
    rgmc::ParallelFor(this->NumVertices, RowGrain,
      [&](vtkIdType first, vtkIdType last)
      {
        for (vtkIdType v = first; v < last; ++v)
        {
          faces[v] = this->MaskOf(v);
        }
      });
    // Blocks of triangles on threads, each packing its own edges, joined in triangle order.
    const vtkIdType grain = 65536;
    std::vector<std::vector<double>> parts(
      static_cast<std::size_t>((this->NumTriangles + grain - 1) / grain));
    rgmc::ParallelFor(static_cast<vtkIdType>(parts.size()), 1,
      [&](vtkIdType firstBlock, vtkIdType lastBlock)
      {
        for (vtkIdType block = firstBlock; block < lastBlock; ++block)
        {
          std::vector<double> packed;
          for (vtkIdType t = block * grain; t < std::min(this->NumTriangles, (block + 1) * grain);
               ++t)
          {
            for (int c = 0; c < 3; ++c)
            {
              const vtkIdType a = static_cast<vtkIdType>(this->Triangles[3 * t + c]);
              const vtkIdType b = static_cast<vtkIdType>(this->Triangles[3 * t + (c + 1) % 3]);
              if (!(faces[a] & faces[b]))
              {
                continue;
              }
              rgmc::BorderEdge e;
              e.From = this->Numbering.Gid[a];
              e.To = this->Numbering.Gid[b];
              e.FromFaces = faces[a];
              e.ToFaces = faces[b];
              double x[3];
              std::copy_n(positions + 3 * a, 3, x);
              box.ToIndex(x, e.FromIndex);
              std::copy_n(positions + 3 * b, 3, x);
              box.ToIndex(x, e.ToIndex);
              packed.resize(packed.size() + rgmc::BorderEdge::Words);
              e.Pack(packed.data() + packed.size() - rgmc::BorderEdge::Words);
            }
          }
          parts[block] = std::move(packed);
        }
      });
    std::size_t size = 0;
    for (const std::vector<double>& part : parts)
    {
      size += part.size();
    }
    std::vector<double> packed;
    packed.reserve(size);
    for (const std::vector<double>& part : parts)
    {
      packed.insert(packed.end(), part.begin(), part.end());
    }
    return packed;
  }

  std::vector<T> Smoothed; // positions of this rank's vertices after smoothing

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

  /// A triangle's contribution to a vertex normal: its sorted global ids, and its area vector
  /// taken from its corner of smallest global id (orientation kept), so that every rank
  /// computes the same bits.
  struct NormalTerm
  {
    std::array<vtkIdType, 3> Key;
    double Cross[3];
    bool operator<(const NormalTerm& o) const { return this->Key < o.Key; }
  };

  // -- the seams ---------------------------------------------------------------------------

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
    this->AddUnsharedVertices(stencils, checks);
    // Shared vertices this rank owns, in gid order (the order of the received edges).
    for (std::size_t i = 0; i < this->Numbering.SharedVertex.size(); ++i)
    {
      if (this->Numbering.SharedOwner[i] == this->AllRanks.Rank)
      {
        this->AddVertex(this->Numbering.SharedVertex[i], i, &edges, stencils, checks);
      }
    }
    // Kept only when 32-bit: then they take the memory the 32-bit stencils saved, and the
    // smoothing's peak stays where it was with 64-bit stencils and no corner lists.
    if (!stencils || sizeof(I) > 4)
    {
      rgmc::LargeVector<I>().swap(this->Corners);
      std::vector<vtkIdType>().swap(this->CornerOffsets);
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
    if (vtkSMPTools::GetEstimatedNumberOfThreads() <= 1)
    {
      // One thread: straight into the stencils.
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
      return;
    }
    struct Block
    {
      std::vector<vtkIdType> Vertices; // in order; -1 - v for a vertex AddVertex takes
      std::vector<vtkIdType> Ends;     // row ends in Neighbours, per manifold vertex
      rgmc::LargeVector<I> Neighbours;
      vtkIdType Edges = 0;
    };
    // Batches of blocks bound the rows held apart (memory), whatever the mesh's size.
    const vtkIdType blockSize = 4096, batchBlocks = 64;
    const vtkIdType numBlocks = (this->NumVertices + blockSize - 1) / blockSize;
    std::vector<Block> blocks;
    for (vtkIdType batch = 0; batch < numBlocks; batch += batchBlocks)
    {
      blocks.assign(static_cast<std::size_t>(std::min(batchBlocks, numBlocks - batch)), Block());
      rgmc::ParallelFor(static_cast<vtkIdType>(blocks.size()), 1,
        [&](vtkIdType first, vtkIdType last)
        {
          std::vector<std::pair<vtkIdType, vtkIdType>> blockEnds;
          for (vtkIdType b = first; b < last; ++b)
          {
            // Filled here and moved into place at the end: neighbouring blocks, on other
            // threads, share cache lines in `blocks`.
            Block block;
            const vtkIdType start = (batch + b) * blockSize;
            const vtkIdType end = std::min(this->NumVertices, start + blockSize);
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
      // A block without a vertex for AddVertex (nearly all) is copied into place on threads
      // after this walk, which only makes room for it; the others are taken here, in order.
      struct Placement
      {
        const Block* From;
        std::size_t Row, Neighbour; // where its first row and its first neighbour go
      };
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
          this->Stencil.Neighbours.resize(
            this->Stencil.Neighbours.size() + block.Neighbours.size());
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
      blocks.clear();
    }
  }

  /// Whether vertex v (no other rank holds it) is inside a manifold piece; if so, its edges are
  /// counted in `edges` and its row appended to `row` (when stencils are made). Reads only:
  /// threads may call it at once, each with its own `ends`.
  bool ManifoldRow(vtkIdType v, bool stencils, std::vector<std::pair<vtkIdType, vtkIdType>>& ends,
    rgmc::LargeVector<I>& row, vtkIdType& edges) const
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
  bool OrientedFanRow(vtkIdType v, bool stencils, rgmc::LargeVector<I>& row, vtkIdType& edges) const
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
    int rank[MaxFan];
    unsigned ranks = 0, matched = 0;
    for (int i = 0; i < n; ++i)
    {
      int r = 0;
      bool found = false;
      for (int j = 0; j < n; ++j)
      {
        r += nextGid[j] < nextGid[i];
        found |= previousGid[j] == nextGid[i];
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
    for (I& s : this->Stencil.Neighbours)
    {
      s = s < 0 ? static_cast<I>(this->NumVertices + slotOf[-1 - static_cast<vtkIdType>(s)]) : s;
    }
    std::vector<Pending>().swap(this->PendingRemote);
  }

  /// Who sends what each iteration: the neighbours owners lack, from ranks that hold them; the
  /// owners' new positions, to the other holders (both sides list a pair's vertices in gid
  /// order).
  void ListSharedVertices()
  {
    for (std::size_t r = 0; r < this->RemoteGids.size(); ++r)
    {
      this->RequestLists[this->RemoteProviders[r]].push_back(this->RemoteGids[r]);
      this->RemoteOrder[this->RemoteProviders[r]].push_back(
        this->NumVertices + static_cast<vtkIdType>(r));
    }
    for (std::size_t i = 0; i < this->Numbering.SharedVertex.size(); ++i)
    {
      const vtkIdType v = this->Numbering.SharedVertex[i];
      if (this->Numbering.SharedOwner[i] == this->AllRanks.Rank)
      {
        for (vtkIdType h = this->Numbering.SharerOffsets[i];
             h < this->Numbering.SharerOffsets[i + 1]; ++h)
        {
          this->ToSharer[this->Numbering.Sharers[h]].push_back(v);
        }
      }
      else
      {
        this->FromOwner[this->Numbering.SharedOwner[i]].push_back(v);
      }
    }
  }

  /// The vertices each rank asked this one to send every iteration.
  void ListProvided(const std::vector<std::vector<vtkIdType>>& asked)
  {
    for (int s = 0; s < this->AllRanks.Size; ++s)
    {
      for (vtkIdType g : asked[s])
      {
        this->Provide[s].push_back(this->VertexOfGid(g));
      }
    }
  }

  // -- smoothing ---------------------------------------------------------------------------

  /// Jacobi Laplacian, in double, rounded once at the end.
  bool SmoothLaplacian(const SmoothingSettings& settings,
    const std::function<bool(double)>& progress, bool& aborted, std::string& problem)
  {
    const std::size_t size = 3 * (this->NumVertices + this->RemoteGids.size());
    rgmc::LargeVector<double> current, next;
    if (!this->AllRanks.Step("smooth the surface", problem,
          [&]()
          {
            current.resize(size);
            next.resize(size);
            std::copy(this->Positions, this->Positions + 3 * this->NumVertices, current.begin());
            std::copy(this->RemoteInitial.begin(), this->RemoteInitial.end(),
              current.begin() + 3 * this->NumVertices);
          }))
    {
      return false;
    }
    for (int it = 0; it < settings.Iterations && !aborted; ++it)
    {
      if (progress(double(it) / settings.Iterations))
      {
        aborted = true;
        break;
      }
      this->Fetch(current.data());
      rgmc::ParallelFor(static_cast<vtkIdType>(this->Owned.size()), RowGrain,
        [&](vtkIdType first, vtkIdType last)
        {
          rgmc::LaplacianStep(this->Stencil, this->Owned, current.data(), next.data(),
            settings.Relaxation, first, last);
        });
      this->Update(next.data());
      std::swap(current, next);
    }
    rgmc::LargeVector<double>().swap(next);
    return this->AllRanks.Step("smooth the surface", problem,
      [&]() { this->Smoothed.assign(current.begin(), current.begin() + 3 * this->NumVertices); });
  }

  /// Windowed sinc, in the points' type, as VTK's filter: x0, x1, x2 the last three states,
  /// `sum` the result.
  bool SmoothWindowedSinc(const SmoothingSettings& settings,
    const std::function<bool(double)>& progress, bool& aborted, std::string& problem)
  {
    const std::size_t size = 3 * (this->NumVertices + this->RemoteGids.size());
    std::vector<T> a, b, c, sum;
    std::vector<double> coefficients;
    if (!this->AllRanks.Step("smooth the surface", problem,
          [&]()
          {
            a.resize(size);
            b.resize(size);
            std::copy(this->Positions, this->Positions + 3 * this->NumVertices, a.begin());
            for (std::size_t r = 0; r < this->RemoteGids.size(); ++r)
            {
              for (int k = 0; k < 3; ++k)
              {
                a[3 * (this->NumVertices + r) + k] = static_cast<T>(this->RemoteInitial[3 * r + k]);
              }
            }
            c.resize(size);
            sum.resize(size);
            coefficients =
              rgmc::SincCoefficients(settings.Iterations, settings.PassBand, settings.Window);
          }))
    {
      return false;
    }
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
    for (int it = 2; it <= settings.Iterations; ++it)
    {
      if (progress(double(it) / settings.Iterations))
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
    return true;
  }

  // -- normals -----------------------------------------------------------------------------

  /// Each triangle's area vector at the smoothed positions, taken from its corner of smallest
  /// global id (orientation kept): the same bits whichever vertex or rank asks. Once per
  /// triangle, on threads (the stencils' memory, released, holds it).
  void ComputeTriangleCrosses()
  {
    this->TriangleCross.resize(static_cast<std::size_t>(3 * this->NumTriangles));
    const std::vector<vtkIdType>& gid = this->Numbering.Gid;
    const T* x = this->Smoothed.data();
    rgmc::ParallelFor(this->NumTriangles, 16384,
      [&](vtkIdType firstTriangle, vtkIdType lastTriangle)
      {
        for (vtkIdType t = firstTriangle; t < lastTriangle; ++t)
        {
          vtkIdType c[3] = { static_cast<vtkIdType>(this->Triangles[3 * t]),
            static_cast<vtkIdType>(this->Triangles[3 * t + 1]),
            static_cast<vtkIdType>(this->Triangles[3 * t + 2]) };
          const int first = gid[c[0]] < gid[c[1]] ? (gid[c[0]] < gid[c[2]] ? 0 : 2)
                                                  : (gid[c[1]] < gid[c[2]] ? 1 : 2);
          std::rotate(c, c + first, c + 3);
          double e1[3], e2[3];
          for (int k = 0; k < 3; ++k)
          {
            e1[k] = static_cast<double>(x[3 * c[1] + k]) - static_cast<double>(x[3 * c[0] + k]);
            e2[k] = static_cast<double>(x[3 * c[2] + k]) - static_cast<double>(x[3 * c[0] + k]);
          }
          vtkMath::Cross(e1, e2, &this->TriangleCross[3 * t]);
        }
      });
  }

  NormalTerm TermOf(vtkIdType t) const
  {
    const std::vector<vtkIdType>& gid = this->Numbering.Gid;
    NormalTerm out;
    out.Key = { gid[static_cast<vtkIdType>(this->Triangles[3 * t])],
      gid[static_cast<vtkIdType>(this->Triangles[3 * t + 1])],
      gid[static_cast<vtkIdType>(this->Triangles[3 * t + 2])] };
    std::sort(out.Key.begin(), out.Key.end());
    std::copy_n(&this->TriangleCross[3 * t], 3, out.Cross);
    return out;
  }

  /// The terms of this rank's triangles at vertex v, into `terms`.
  void LocalTerms(vtkIdType v, std::vector<NormalTerm>& terms) const
  {
    terms.clear();
    for (vtkIdType c = this->CornerOffsets[v]; c < this->CornerOffsets[v + 1]; ++c)
    {
      terms.push_back(this->TermOf(this->Corners[c] / 3));
    }
  }

  /// The normal of a vertex: its terms summed in the order of their keys.
  static void SumTerms(std::vector<NormalTerm>& terms, double n[3])
  {
    std::sort(terms.begin(), terms.end());
    n[0] = n[1] = n[2] = 0;
    for (const NormalTerm& t : terms)
    {
      for (int k = 0; k < 3; ++k)
      {
        n[k] += t.Cross[k];
      }
    }
    vtkMath::Normalize(n);
  }

  /// The terms of shared vertices go to their owners (in gid order, as the owners list them).
  void ListSharedTerms(std::vector<std::vector<vtkIdType>>& toOwners) const
  {
    std::vector<NormalTerm> terms;
    for (int o = 0; o < this->AllRanks.Size; ++o)
    {
      rgmc::MessageWriter out(toOwners[o]);
      for (vtkIdType v : this->FromOwner[o])
      {
        this->LocalTerms(v, terms);
        out.Int(static_cast<std::int64_t>(terms.size()));
        for (const NormalTerm& t : terms)
        {
          out.Int(t.Key[0]).Int(t.Key[1]).Int(t.Key[2]);
          out.Real(t.Cross[0]).Real(t.Cross[1]).Real(t.Cross[2]);
        }
      }
    }
  }

  /// A triangle at a vertex, by the global ids of its two other corners (sorted) and its index.
  /// Triangles that share the vertex compare by these pairs exactly as their NormalTerms compare
  /// by all three sorted ids (putting one common value into sorted pairs keeps their order,
  /// ties included), so sorting them with the same std::sort, from the same corner order, gives
  /// the terms' order without building the terms.
  struct TriangleAtVertex
  {
    vtkIdType A, B;
    vtkIdType Triangle;
    bool operator<(const TriangleAtVertex& o) const
    {
      return this->A < o.A || (this->A == o.A && this->B < o.B);
    }
  };

  /// Each vertex's sum of this rank's terms, on threads (each range with its own list), in
  /// SumTerms' order, from TriangleAtVertex. Owned shared vertices are summed again with every
  /// holder's terms (SumSharedTerms); the other shared ones get their owner's.
  void SumOwnTerms(rgmc::LargeVector<double>& sums) const
  {
    const std::vector<vtkIdType>& gid = this->Numbering.Gid;
    rgmc::ParallelFor(this->NumVertices, RowGrain,
      [&](vtkIdType first, vtkIdType last)
      {
        std::vector<TriangleAtVertex> around;
        for (vtkIdType v = first; v < last; ++v)
        {
          around.clear();
          for (vtkIdType c = this->CornerOffsets[v]; c < this->CornerOffsets[v + 1]; ++c)
          {
            const vtkIdType t = this->Corners[c] / 3;
            const std::pair<vtkIdType, vtkIdType> ends = this->AroundCorner(this->Corners[c]);
            vtkIdType a = gid[ends.first];
            vtkIdType b = gid[ends.second];
            if (b < a)
            {
              std::swap(a, b);
            }
            around.push_back(TriangleAtVertex{ a, b, t });
          }
          std::sort(around.begin(), around.end());
          double* n = &sums[3 * v];
          n[0] = n[1] = n[2] = 0;
          for (const TriangleAtVertex& at : around)
          {
            for (int k = 0; k < 3; ++k)
            {
              n[k] += this->TriangleCross[3 * at.Triangle + k];
            }
          }
          vtkMath::Normalize(n);
        }
      });
  }

  /// Owned shared vertices: their own terms and every holder's, in the same order.
  void SumSharedTerms(
    const std::vector<std::vector<vtkIdType>>& received, rgmc::LargeVector<double>& sums) const
  {
    const std::vector<vtkIdType>& gid = this->Numbering.Gid;
    std::vector<std::size_t> cursor(this->AllRanks.Size, 0);
    std::vector<std::pair<vtkIdType, int>> order; // (gid, sharer) of owned shared vertices
    for (int s = 0; s < this->AllRanks.Size; ++s)
    {
      if (s != this->AllRanks.Rank)
      {
        for (vtkIdType v : this->ToSharer[s])
        {
          order.emplace_back(gid[v], s);
        }
      }
    }
    std::sort(order.begin(), order.end());
    std::vector<NormalTerm> terms;
    for (std::size_t i = 0; i < order.size();)
    {
      const vtkIdType v = this->VertexOfGid(order[i].first);
      this->LocalTerms(v, terms);
      for (; i < order.size() && order[i].first == gid[v]; ++i)
      {
        const std::vector<vtkIdType>& in = received[order[i].second];
        std::size_t& at = cursor[order[i].second];
        const vtkIdType count = at < in.size() ? in[at++] : 0;
        for (vtkIdType j = 0; j < count && at + 5 < in.size(); ++j, at += 6)
        {
          rgmc::MessageReader term(in.data() + at, 6);
          NormalTerm t;
          t.Key = { term.Int(), term.Int(), term.Int() };
          t.Cross[0] = term.Real();
          t.Cross[1] = term.Real();
          t.Cross[2] = term.Real();
          terms.push_back(t);
        }
      }
      SumTerms(terms, &sums[3 * v]);
    }
  }

  // -- helpers -----------------------------------------------------------------------------

  /// The triangle corners (3 t + k, of type I as the connectivity's entries are) at each vertex,
  /// in compressed rows.
  void CornersAround(std::vector<vtkIdType>& offsets, rgmc::LargeVector<I>& corners) const
  {
    offsets.assign(static_cast<std::size_t>(this->NumVertices) + 1, 0);
    for (vtkIdType c = 0; c < 3 * this->NumTriangles; ++c)
    {
      ++offsets[static_cast<vtkIdType>(this->Triangles[c]) + 1];
    }
    for (vtkIdType v = 0; v < this->NumVertices; ++v)
    {
      offsets[v + 1] += offsets[v];
    }
    corners.resize(static_cast<std::size_t>(3 * this->NumTriangles));
    std::vector<vtkIdType> fill(offsets.begin(), offsets.end() - 1);
    for (vtkIdType c = 0; c < 3 * this->NumTriangles; ++c)
    {
      corners[fill[static_cast<vtkIdType>(this->Triangles[c])]++] = static_cast<I>(c);
    }
  }

  /// The vertices after and before corner c (3 t + k) in triangle t's order: the ends of the
  /// triangle's two edges at that corner.
  std::pair<vtkIdType, vtkIdType> AroundCorner(I c) const
  {
    const vtkIdType t = static_cast<vtkIdType>(c) / 3, k = static_cast<vtkIdType>(c) % 3;
    return { static_cast<vtkIdType>(this->Triangles[3 * t + (k + 1) % 3]),
      static_cast<vtkIdType>(this->Triangles[3 * t + (k + 2) % 3]) };
  }

  /// The ends of this rank's edges at vertex v (once per triangle side), as (gid, vertex)
  /// sorted by gid, into `out`. Reads only: threads may call it at once.
  void EndsAt(vtkIdType v, std::vector<std::pair<vtkIdType, vtkIdType>>& out) const
  {
    out.clear();
    for (vtkIdType c = this->CornerOffsets[v]; c < this->CornerOffsets[v + 1]; ++c)
    {
      const std::pair<vtkIdType, vtkIdType> ends = this->AroundCorner(this->Corners[c]);
      for (const vtkIdType w : { ends.first, ends.second })
      {
        out.emplace_back(this->Numbering.Gid[w], w);
      }
    }
    std::sort(out.begin(), out.end());
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

  int MaskOf(vtkIdType v) const
  {
    const T* x = this->Positions + 3 * v;
    const double p[3] = { static_cast<double>(x[0]), static_cast<double>(x[1]),
      static_cast<double>(x[2]) };
    return this->Border.Mask(
      this->Grid, this->Keys ? this->Keys[this->Vertices.PointOf(v)] : vtkIdType(0), p);
  }

  /// The vertex with global id `g` (this rank holds it): its vertices in identity order are in
  /// gid order.
  vtkIdType VertexOfGid(vtkIdType g) const
  {
    const std::vector<vtkIdType>& gid = this->Numbering.Gid;
    return *std::lower_bound(this->Vertices.Sorted.begin(), this->Vertices.Sorted.end(), g,
      [&gid](vtkIdType v, vtkIdType key) { return gid[v] < key; });
  }

  /// Sends each rank r the triples of `state` at the vertices send[r], and stores the triples
  /// rank r sends at the vertices receive[r] (both sides list a pair's vertices in one order).
  template <typename S>
  void Share(const std::vector<std::vector<vtkIdType>>& send,
    const std::vector<std::vector<vtkIdType>>& receive, S* state, int tag)
  {
    std::vector<std::vector<double>> out(this->AllRanks.Size);
    for (int r = 0; r < this->AllRanks.Size; ++r)
    {
      for (vtkIdType v : send[r])
      {
        out[r].insert(out[r].end(), state + 3 * v, state + 3 * v + 3);
      }
    }
    const auto in = this->AllRanks.Exchange(out, this->Partners, tag);
    for (int r = 0; r < this->AllRanks.Size; ++r)
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

  Ranks& AllRanks;
  const LocalVertices& Vertices;
  const GlobalNumbering& Numbering;
  const BorderTest Border;
  const rgmc::Grid Grid;
  const vtkIdType* Keys; // the input's vertex keys, or null
  const T* Positions;    // of this rank's vertices
  const I* Triangles;    // over this rank's vertices
  const vtkIdType NumTriangles;
  const vtkIdType NumVertices;
  std::vector<bool> Partners; // the ranks that share a vertex with this one

  // The triangle corners at each vertex: made for the seams' analysis, kept for the normals
  // when the surface is smoothed and I is 32-bit (else made again).
  std::vector<vtkIdType> CornerOffsets;
  rgmc::LargeVector<I> Corners;
  // One vertex's neighbourhood while it is analysed (on the calling thread).
  std::vector<std::pair<vtkIdType, vtkIdType>> Ends;
  std::vector<Neighbour> Around;
  std::vector<rgmc::IncidentEdge> Incident;
  std::vector<std::int64_t> Row;
  double CosEdgeAngle = 1.0;
  std::vector<Pending> PendingRemote;
  rgmc::LargeVector<double> TriangleCross; // per triangle, while the normals are summed

  std::vector<I> Owned; // the vertices this rank moves, one stencil row each
  rgmc::Stencils<I> Stencil;
  std::vector<vtkIdType> RemoteGids; // neighbours of owned vertices held elsewhere, by slot
  std::vector<int> RemoteProviders;
  std::vector<double> RemoteInitial;
  std::vector<std::vector<vtkIdType>> ToSharer;     // holder -> owned shared vertices
  std::vector<std::vector<vtkIdType>> FromOwner;    // owner -> vertices it updates here
  std::vector<std::vector<vtkIdType>> Provide;      // requester -> vertices to send
  std::vector<std::vector<vtkIdType>> RemoteOrder;  // provider -> slots, in request order
  std::vector<std::vector<vtkIdType>> RequestLists; // provider -> gids asked of it
};

/// The area and enclosed volume of the whole surface at `positions` (this rank's vertices),
/// the same to the bit on every rank for any number of ranks and threads: each rank's exact
/// sums (rgmc::ExactSum) are reduced as integers, and every rank closes the surface at the
/// border from all ranks' border edges, in one order. An agreement, an AllReduce, an AllGather,
/// an AllGatherV, an agreement.
template <typename T, typename I>
bool MeasureSurface(Ranks& ranks, const PieceRepair<T, I>& repair, const T* positions,
  const rgmc::VolumeBox& box, Measures& measures, std::string& problem)
{
  double centre[3], scale;
  box.Frame(centre, scale);
  rgmc::TriangleSums sums;
  std::vector<double> mine;
  if (!ranks.Step("measure the surface", problem,
        [&]()
        {
          sums = repair.SumTriangles(positions, centre, scale);
          mine = repair.BorderEdges(positions, box);
        }))
  {
    return false;
  }
  constexpr int n = rgmc::ExactSum::Words;
  std::int64_t words[2 * n], totals[2 * n];
  sums.TwiceArea.ToWords(words);
  sums.SixVolume.ToWords(words + n);
  ranks.AllReduce(words, totals, 2 * n, vtkCommunicator::SUM_OP, "summing the measures");
  const vtkIdType count = static_cast<vtkIdType>(mine.size());
  std::vector<vtkIdType> lengths(ranks.Size), offsets(ranks.Size, 0);
  ranks.AllGather(&count, lengths.data(), 1, "counting the border edges");
  std::partial_sum(lengths.begin(), lengths.end() - 1, offsets.begin() + 1);
  std::vector<double> all;
  if (!ranks.Step("gather the border edges", problem,
        [&]() { all.resize(static_cast<std::size_t>(offsets.back() + lengths.back())); }))
  {
    return false;
  }
  ranks.AllGatherV(
    mine.data(), all.data(), count, lengths.data(), offsets.data(), "gathering the border edges");
  return ranks.Step("close the surface at the border", problem,
    [&]()
    {
      std::vector<rgmc::BorderEdge> edges(all.size() / rgmc::BorderEdge::Words);
      for (std::size_t e = 0; e < edges.size(); ++e)
      {
        edges[e] = rgmc::BorderEdge::Unpack(all.data() + e * rgmc::BorderEdge::Words);
      }
      const rgmc::Caps caps = rgmc::BorderCaps(std::move(edges), box);
      const double twiceArea = rgmc::ExactSum::FromWordSums(totals).Get();
      const double sixVolume = rgmc::ExactSum::FromWordSums(totals + n).Get();
      measures.Area = 0.5 * twiceArea * scale * scale;
      // Counterclockwise in index space, as marching cubes orders triangles: a mirroring
      // direction turns them clockwise in the world.
      measures.Volume =
        (box.Handedness() * sixVolume * scale * scale * scale + caps.SixVolume) / 6.0;
      measures.CapArea = caps.Area;
      measures.Closable = caps.Closed;
    });
}

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
/// What one execution carries from pass to pass on this rank.
struct vtkRGSeamRepair::Run
{
  Run(vtkMultiProcessController* controller, vtkPolyData* input)
    : ranks(controller)
    , input(input)
  {
  }
  Ranks ranks;
  std::string problem; // the agreed error of a failed pass
  vtkPolyData* input;
  vtkIdType triangles = 0;         // over all ranks
  const vtkIdType* keys = nullptr; // the input's vertex keys, when every rank has them
  LocalVertices vertices;
  GlobalNumbering numbering;
  BorderTest border;
  rgmc::VolumeBox box;    // the volume's, or the mesh's bounds when the input does not say
  Measures before, after; // before and after smoothing
  bool smooth = false;
  std::vector<vtkIdType> connectivity;    // the triangles over the vertices, when merged or copied
  vtkNew<vtkPoints> points;               // the output's
  vtkSmartPointer<vtkFloatArray> normals; // after smoothing
  Checks checks;                          // this rank's counts, then the sums over all ranks
  bool aborted = false;
};

//------------------------------------------------------------------------------
// The collective schedule: every rank runs these passes in this order and makes the same
// collective calls in each (an agreement is one collective call on success, one or two
// broadcasts more on failure); a pass that fails returns on every rank at the same point.
// "Exchange" is Ranks::Exchange: with every rank in NumberVertices, else with the ranks that
// share a vertex with this one.
//
//  PASS 0 CheckInput      agreement (a triangle mesh), AllReduce (triangles), agreement
//  PASS 1 NumberVertices  AllReduce (whether every rank has vertex keys), agreement (the
//                         local sort); IdentityNumbering: AllGather, AllGatherV, agreement,
//                         exchange, agreement, AllGather, exchange, agreement (one rank: an
//                         agreement)
//  PASS 2 FindBorder      3 AllReduce (the bounds, whether every rank has the volume's box)
//  PASS 3 RepairSeams     agreement (the input copied); AnalyzeSeams: agreement, exchange,
//                         agreement, exchange, agreement
//  PASS 4                 smoothing only: per iteration an AllReduce (abort) and two
//                         exchanges, an agreement or two; Normals: agreement, exchange,
//                         agreement, exchange, agreement
//  PASS 5                 agreement (the output points)
//  PASS 6 StoreSurface    AllReduce (the checks), agreement (the output)
//         ReportChecks    none
int vtkRGSeamRepair::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPolyData* output = vtkPolyData::GetData(outputVector);
  rgmc::ForgetEarlierAbort(this->AbortExecute);
  rgmc::RunController controller(this->Controller);
  Run run(controller, vtkPolyData::GetData(inputVector[0]));
  // The count of this run's collective calls, however it ends.
  struct Accounting
  {
    vtkRGSeamRepair* Filter;
    Run& Counted;
    ~Accounting() { this->Filter->NumberOfCollectives = this->Counted.ranks.Collectives; }
  } accounting{ this, run };

  // PASS 0: a triangle mesh with triangles, on every rank.
  if (!this->CheckInput(run))
  {
    vtkErrorMacro(<< "Cannot repair the seams: " << run.problem << ".");
    return 0;
  }
  this->UpdateProgress(0.05);
  // PASS 1: this rank's distinct vertices and their global numbering.
  if (!this->NumberVertices(run))
  {
    vtkErrorMacro(<< "Cannot repair the seams: " << run.problem << ".");
    return 0;
  }
  this->UpdateProgress(0.25);
  // PASS 2: how to tell edges on the volume's border.
  this->FindBorder(run);
  // PASS 3-5: edges at the seams, checks, smoothing, normals, the output points.
  if (!this->RepairSeams(run))
  {
    output->Initialize();
    if (run.aborted)
    {
      return 1;
    }
    vtkErrorMacro(<< "Cannot repair the seams: " << run.problem << ".");
    return 0;
  }
  // PASS 6: the global checks and the output piece.
  if (!this->StoreSurface(run, output))
  {
    vtkErrorMacro(<< "Cannot repair the seams: " << run.problem << ".");
    output->Initialize();
    return 0;
  }
  this->ReportChecks(run, output);
  this->UpdateProgress(1.0);
  return 1;
}

//------------------------------------------------------------------------------
bool vtkRGSeamRepair::CheckInput(Run& run)
{
  Ranks& ranks = run.ranks;
  vtkPolyData* input = run.input;
  const vtkIdType verts = input->GetNumberOfVerts(), lines = input->GetNumberOfLines(),
                  strips = input->GetNumberOfStrips();
  vtkCellArray* polys = input->GetPolys();
  const vtkIdType other = rgmc::PolygonsNotTriangles(polys);
  if (verts || lines || strips || other)
  {
    std::ostringstream msg;
    msg << "the input is not a triangle mesh: it has " << verts << " vertex cells, " << lines
        << " lines, " << strips << " triangle strips and " << other
        << " polygons that are not triangles (apply Triangulate, or Extract Surface, first)";
    run.problem = msg.str();
  }
  if (!ranks.Agree(run.problem.empty(), run.problem))
  {
    return false;
  }
  const vtkIdType localTriangles = input->GetNumberOfPolys();
  ranks.AllReduce(
    &localTriangles, &run.triangles, 1, vtkCommunicator::SUM_OP, "counting triangles");
  if (!ranks.Agree(run.triangles > 0, run.problem))
  {
    run.problem = run.problem.empty() ? std::string("the input has no triangles") : run.problem;
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
// Identities are global ids when every rank with points has them, else exact coordinates.
bool vtkRGSeamRepair::NumberVertices(Run& run)
{
  Ranks& ranks = run.ranks;
  vtkIdTypeArray* keyArray =
    vtkIdTypeArray::SafeDownCast(run.input->GetPointData()->GetGlobalIds());
  int keyed = run.input->GetNumberOfPoints() == 0 || keyArray ? 1 : 0, allKeyed = 0;
  ranks.AllReduce(&keyed, &allKeyed, 1, vtkCommunicator::MIN_OP, "agreeing on vertex identities");
  run.keys = allKeyed && keyArray ? keyArray->GetPointer(0) : nullptr;
  auto number = [&run](auto words)
  {
    constexpr int Words = decltype(words)::value;
    std::vector<Identity<Words>> ids;
    return run.ranks.Step("sort the vertices", run.problem,
             [&]() { run.vertices = MergeLocal<Words>(run.input, run.keys, ids); }) &&
      IdentityNumbering<Words>(run.ranks, run.vertices, ids).Number(run.numbering, run.problem);
  };
  return allKeyed ? number(std::integral_constant<int, 1>())
                  : number(std::integral_constant<int, 3>());
}

//------------------------------------------------------------------------------
// From keys and the whole extent when the input came from vtkRGMarchingCubes, else from the
// global bounds.
void vtkRGSeamRepair::FindBorder(Run& run)
{
  vtkPolyData* input = run.input;
  BorderTest& border = run.border;
  double b[6], lo[3], hi[3], glo[3], ghi[3];
  input->GetBounds(b);
  for (int a = 0; a < 3; ++a)
  {
    lo[a] = input->GetNumberOfPoints() ? b[2 * a] : VTK_DOUBLE_MAX;
    hi[a] = input->GetNumberOfPoints() ? b[2 * a + 1] : VTK_DOUBLE_MIN;
  }
  run.ranks.AllReduce(lo, glo, 3, vtkCommunicator::MIN_OP, "reducing bounds");
  run.ranks.AllReduce(hi, ghi, 3, vtkCommunicator::MAX_OP, "reducing bounds");
  double diagonal = 0;
  for (int a = 0; a < 3; ++a)
  {
    border.Bounds[2 * a] = glo[a];
    border.Bounds[2 * a + 1] = ghi[a];
    diagonal += (ghi[a] - glo[a]) * (ghi[a] - glo[a]);
  }
  border.Tolerance = 1e-6 * std::sqrt(diagonal);
  vtkIntArray* whole = vtkIntArray::SafeDownCast(input->GetFieldData()->GetArray("WholeExtent"));
  // Only vtkRGMarchingCubes' keys say where a vertex is in the volume: global ids numbered
  // otherwise (Seam Repair's own, vtkRGDecimate's) do not, though the extent passes with them.
  vtkDataArray* keyArray = input->GetPointData()->GetGlobalIds();
  const bool extractionKeys =
    run.keys && keyArray && keyArray->GetName() && std::string(keyArray->GetName()) == "VertexKey";
  if (extractionKeys && whole && whole->GetNumberOfValues() == 6)
  {
    border.Keys = true;
    for (int i = 0; i < 6; ++i)
    {
      border.Whole[i] = whole->GetValue(i);
    }
  }
  // The box that closes a surface cut by the border: the volume's (vtkRGMarchingCubes says
  // where it is), else the bounds of the whole mesh.
  // Every rank must take the same box, ranks without points included.
  vtkDoubleArray* geometry =
    vtkDoubleArray::SafeDownCast(input->GetFieldData()->GetArray("VolumeGeometry"));
  const bool hasBox =
    whole && whole->GetNumberOfValues() == 6 && geometry && geometry->GetNumberOfValues() == 15;
  const int described = hasBox ? 1 : 0;
  int allDescribed = 0;
  run.ranks.AllReduce(
    &described, &allDescribed, 1, vtkCommunicator::MIN_OP, "agreeing on the volume's box");
  if (allDescribed)
  {
    const double* g = geometry->GetPointer(0);
    std::copy_n(g, 3, run.box.Origin);
    std::copy_n(g + 3, 3, run.box.Spacing);
    std::copy_n(g + 6, 9, run.box.Direction);
    for (int i = 0; i < 6; ++i)
    {
      run.box.Extent[i] = whole->GetValue(i);
    }
  }
  else
  {
    std::copy_n(border.Bounds, 6, run.box.Extent);
  }
}

//------------------------------------------------------------------------------
// In the input points' precision, over the input's own connectivity when no points were merged
// (a connectivity copy is always 64-bit; the input's own may be 32-bit).
bool vtkRGSeamRepair::RepairSeams(Run& run)
{
  run.smooth = this->SmoothingMethod != NO_SMOOTHING && this->NumberOfIterations > 0;
  vtkPoints* inputPoints = run.input->GetPoints();
  const bool doublePoints = inputPoints && inputPoints->GetDataType() == VTK_DOUBLE;
  const bool int32 = !run.vertices.Merged() &&
    vtkAOSDataArrayTemplate<std::int32_t>::FastDownCast(
      run.input->GetPolys()->GetConnectivityArray());
  if (doublePoints)
  {
    return int32 ? this->RepairSeamsIn<double, std::int32_t>(run)
                 : this->RepairSeamsIn<double, vtkIdType>(run);
  }
  return int32 ? this->RepairSeamsIn<float, std::int32_t>(run)
               : this->RepairSeamsIn<float, vtkIdType>(run);
}

//------------------------------------------------------------------------------
template <typename T, typename I>
bool vtkRGSeamRepair::RepairSeamsIn(Run& run)
{
  Ranks& ranks = run.ranks;
  const T* positions = nullptr;
  std::vector<T> copied; // the positions, when the input's cannot be used as they are
  const I* triangles = nullptr;
  if (!ranks.Step("copy the input", run.problem,
        [&]() {
          triangles = CopyInput<T, I>(run.input, run.vertices, positions, copied, run.connectivity);
        }))
  {
    return false;
  }
  PieceRepair<T, I> repair(ranks, run.vertices, run.numbering, run.border, run.keys, positions,
    triangles, run.input->GetNumberOfPolys());
  if (!repair.AnalyzeSeams(run.smooth, run.checks, run.problem) ||
    !MeasureSurface(ranks, repair, positions, run.box, run.before, run.problem))
  {
    return false;
  }
  run.after = run.before;
  this->UpdateProgress(0.4);
  if (run.smooth)
  {
    SmoothingSettings settings;
    settings.Method = this->SmoothingMethod;
    settings.Iterations = this->NumberOfIterations;
    settings.Relaxation = this->RelaxationFactor;
    settings.PassBand = this->PassBand;
    settings.Window = this->WindowFunction == HAMMING_WINDOW ? rgmc::SincWindow::Hamming
                                                             : rgmc::SincWindow::Nuttall;
    auto progress = [this, &ranks](double fraction)
    {
      this->UpdateProgress(0.4 + 0.5 * fraction);
      return ranks.Any(this->CheckAbort());
    };
    if (!repair.Smooth(settings, progress, run.problem))
    {
      run.aborted = run.problem.empty();
      return false;
    }
    run.normals = repair.Normals(run.problem);
    if (!run.normals ||
      !MeasureSurface(ranks, repair, repair.Smoothed.data(), run.box, run.after, run.problem))
    {
      return false;
    }
  }
  // The output's points: the input's own when nothing moved and nothing was merged.
  return ranks.Step("store the output points", run.problem,
    [&]()
    {
      if (!run.smooth && !run.vertices.Merged())
      {
        run.points->ShallowCopy(run.input->GetPoints());
        return;
      }
      const std::vector<T>& moved = run.smooth ? repair.Smoothed : copied;
      vtkNew<vtkAOSDataArrayTemplate<T>> xyz;
      xyz->SetNumberOfComponents(3);
      std::copy(moved.begin(), moved.begin() + 3 * run.vertices.Count,
        rgmc::Allocate(xyz.Get(), 3 * run.vertices.Count));
      run.points->SetData(xyz);
    });
}

//------------------------------------------------------------------------------
bool vtkRGSeamRepair::StoreSurface(Run& run, vtkPolyData* output)
{
  Ranks& ranks = run.ranks;
  Checks& checks = run.checks;
  vtkIdType counts[4] = { checks.Edges, checks.Boundary, checks.Border, checks.NonManifold },
            sums[4] = { 0, 0, 0, 0 };
  ranks.AllReduce(counts, sums, 4, vtkCommunicator::SUM_OP, "summing the checks");
  checks.Edges = sums[0];
  checks.Boundary = sums[1];
  checks.Border = sums[2];
  checks.NonManifold = sums[3];
  output->Initialize();
  return ranks.Step("build the output", run.problem, [&]() { this->BuildOutput(run, output); });
}

//------------------------------------------------------------------------------
// The input's triangles and point data as they are (merged when points were), global ids,
// duplicate flags, smoothed points and their normals.
void vtkRGSeamRepair::BuildOutput(Run& run, vtkPolyData* output)
{
  vtkPolyData* input = run.input;
  const LocalVertices& vertices = run.vertices;
  const vtkIdType n = vertices.Count;
  output->SetPoints(run.points);
  vtkPointData* pd = output->GetPointData();
  pd->CopyGlobalIdsOff();
  if (run.smooth)
  {
    pd->CopyNormalsOff();
  }
  if (!vertices.Merged())
  {
    output->SetPolys(input->GetPolys());
    pd->PassData(input->GetPointData());
  }
  else
  {
    vtkNew<vtkIdTypeArray> offsets, conn;
    const vtkIdType numTris = static_cast<vtkIdType>(run.connectivity.size() / 3);
    vtkIdType* o = rgmc::Allocate(offsets.Get(), numTris + 1);
    for (vtkIdType t = 0; t <= numTris; ++t)
    {
      o[t] = 3 * t;
    }
    std::copy(run.connectivity.begin(), run.connectivity.end(),
      rgmc::Allocate(conn.Get(), static_cast<vtkIdType>(run.connectivity.size())));
    vtkNew<vtkCellArray> polys;
    polys->SetData(offsets, conn);
    output->SetPolys(polys);
    pd->CopyAllocate(input->GetPointData(), n);
    for (vtkIdType v = 0; v < n; ++v)
    {
      pd->CopyData(input->GetPointData(), vertices.PointOf(v), v);
    }
  }
  output->GetCellData()->PassData(input->GetCellData());
  vtkNew<vtkIdTypeArray> gids;
  gids->SetName("GlobalPointIds");
  vtkNew<vtkUnsignedCharArray> ghosts;
  ghosts->SetName(vtkDataSetAttributes::GhostArrayName());
  std::copy(run.numbering.Gid.begin(), run.numbering.Gid.end(), rgmc::Allocate(gids.Get(), n));
  unsigned char* ghost = rgmc::Allocate(ghosts.Get(), n);
  for (vtkIdType v = 0; v < n; ++v)
  {
    ghost[v] = (run.numbering.Holding[v] & GlobalNumbering::Foreign)
      ? vtkDataSetAttributes::DUPLICATEPOINT
      : 0;
  }
  pd->SetGlobalIds(gids);
  pd->AddArray(ghosts);
  if (run.smooth)
  {
    pd->SetNormals(run.normals);
  }
}

//------------------------------------------------------------------------------
void vtkRGSeamRepair::ReportChecks(Run& run, vtkPolyData* output)
{
  const Checks& sums = run.checks;
  const vtkIdType unique = run.numbering.Total;
  const vtkIdType euler = unique - sums.Edges + run.triangles;
  const bool closed = sums.Boundary == 0 && sums.NonManifold == 0;
  vtkFieldData* fd = output->GetFieldData();
  fd->PassData(run.input->GetFieldData());
  auto add = [fd](const char* name, vtkIdType value)
  {
    vtkNew<vtkIdTypeArray> a;
    a->SetName(name);
    a->InsertNextValue(value);
    fd->AddArray(a);
  };
  add("UniquePoints", unique);
  add("Triangles", run.triangles);
  add("Edges", sums.Edges);
  add("BoundaryEdges", sums.Boundary);
  add("VolumeBorderEdges", sums.Border);
  add("NonManifoldEdges", sums.NonManifold);
  add("EulerCharacteristic", euler);
  add("Closed", closed ? 1 : 0);
  // The measures: the volume needs a surface without holes (closed, or cut by the border only).
  const bool enclosing = sums.Boundary == 0 && run.before.Closable && run.after.Closable;
  auto addMeasure = [fd](const char* name, double value)
  {
    vtkNew<vtkDoubleArray> a;
    a->SetName(name);
    a->InsertNextValue(value);
    fd->AddArray(a);
  };
  const double nan = vtkMath::Nan();
  addMeasure("SurfaceArea", run.after.Area);
  addMeasure("EnclosedVolume", enclosing ? run.after.Volume : nan);
  addMeasure("BorderCapArea", enclosing ? run.after.CapArea : nan);
  addMeasure("SurfaceAreaBeforeSmoothing", run.before.Area);
  addMeasure("EnclosedVolumeBeforeSmoothing", enclosing ? run.before.Volume : nan);
  if (run.ranks.Rank == 0)
  {
    vtkLogF(INFO,
      "Seam repair: %lld unique points, %lld triangles, %lld edges, %lld boundary edges (%lld "
      "more on the volume's border), %lld non-manifold edges, Euler characteristic %lld: %s.",
      static_cast<long long>(unique), static_cast<long long>(run.triangles),
      static_cast<long long>(sums.Edges), static_cast<long long>(sums.Boundary),
      static_cast<long long>(sums.Border), static_cast<long long>(sums.NonManifold),
      static_cast<long long>(euler), closed ? "closed" : "not closed");
    vtkLogF(INFO, "Seam repair: area %.10g, enclosed volume %.10g (before smoothing %.10g, %.10g).",
      run.after.Area, enclosing ? run.after.Volume : nan, run.before.Area,
      enclosing ? run.before.Volume : nan);
  }
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
  os << indent << "NumberOfCollectives: " << this->NumberOfCollectives << "\n";
}

// Seam Repair: the vertices of one rank, and their global numbering across ranks.
#ifndef rgmcSeamNumbering_h
#define rgmcSeamNumbering_h

#include "rgmcBuffer.h"
#include "rgmcRadixSort.h"
#include "vtkRGCollective.h"
#include "vtkRGParallel.h"

#include "vtkPolyData.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <cstring>
#include <functional>
#include <queue>
#include <string>
#include <utility>
#include <vector>

namespace rgmc
{
namespace seam
{

constexpr int NumberingTag = 48800, AnswerTag = 48802;

/// What makes copies of a vertex one vertex: its key (one word), or its exact coordinates (three).
template <int Words>
using Identity = std::array<std::uint64_t, Words>;

/// Identities in a vector sized, then written whole on threads (HeapOverwriteVector).
template <int Words>
using Identities = rgmc::HeapOverwriteVector<Identity<Words>>;

/// A coordinate as identity bits: -0 and +0 are one coordinate.
inline std::uint64_t Bits(double v)
{
  v = v == 0.0 ? 0.0 : v;
  std::uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}

/// An identity's word in a message, and back.
inline vtkIdType WordOfBits(std::uint64_t bits)
{
  vtkIdType word;
  std::memcpy(&word, &bits, sizeof word);
  return word;
}

inline std::uint64_t BitsOfWord(vtkIdType word)
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
  rgmc::HeapOverwriteVector<vtkIdType> Sorted; // the vertices in identity order
  std::vector<vtkIdType> VertexOfPoint;        // input point -> vertex (empty: the same number)
  std::vector<vtkIdType> First; // vertex -> its first input point (empty: the same number)

  bool Merged() const { return !this->VertexOfPoint.empty(); }
  vtkIdType PointOf(vtkIdType v) const { return this->First.empty() ? v : this->First[v]; }
  vtkIdType VertexOf(vtkIdType p) const
  {
    return this->VertexOfPoint.empty() ? p : this->VertexOfPoint[p];
  }
};

/// A point with its identity, ordered as a std::pair of the two; an aggregate, so that a vector
/// of them (IdentifiedPoints) is sized without being zeroed on one thread first.
template <int Words>
struct IdentifiedPoint
{
  Identity<Words> first;
  vtkIdType second;

  friend bool operator<(const IdentifiedPoint& a, const IdentifiedPoint& b)
  {
    return a.first < b.first || (a.first == b.first && a.second < b.second);
  }
};

/// Identified points, sized and then written whole (every place, by the sort or on threads).
template <int Words>
using IdentifiedPoints = rgmc::HeapOverwriteVector<IdentifiedPoint<Words>>;

/// The input points with their identities, sorted.
template <int Words>
IdentifiedPoints<Words> SortByIdentity(vtkPolyData* input, const vtkIdType* keys)
{
  const vtkIdType n = input->GetNumberOfPoints();
  IdentifiedPoints<Words> all(static_cast<std::size_t>(n));
  // One-word identities (the keys) are sorted packed with their points, one word each, where
  // both fit in 64 bits: a key takes log2 of 4 x the grid points (edge keys, then point keys), an
  // index log2 of the points (a 2048^3 volume leaves room for 500 million points).
  // The parallel sorts count each pass's digits per range before moving them: about 1.5 to 2
  // times the serial sorts' work, which pays from 4 threads (on 2, Seam Repair took 1-2% longer
  // with them). The result is the same either way; the work/span profile takes them.
  const bool threads =
    rgmc::SpanRecorder::Recording() || vtkSMPTools::GetEstimatedNumberOfThreads() >= 4;
  bool packed = false;
  if constexpr (Words == 1)
  {
    auto keyAt = [keys](std::size_t p) { return BitsOfWord(keys[p]); };
    auto put = [&all](std::size_t r, std::uint64_t key, std::size_t p)
    {
      all[r].first[0] = key;
      all[r].second = static_cast<vtkIdType>(p);
    };
    packed = threads ? rgmc::RadixSortPacked(static_cast<std::size_t>(n), keyAt, put, rgmc::Tasks())
                     : rgmc::RadixSortPacked(static_cast<std::size_t>(n), keyAt, put);
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
    auto keyOf = [](const IdentifiedPoint<Words>& entry) { return entry.first[0]; };
    if (!packed && threads)
    {
      rgmc::RadixSort(all, keyOf, rgmc::Tasks());
    }
    else if (!packed)
    {
      rgmc::RadixSort(all, keyOf);
    }
  }
  else
  {
    rgmc::ParallelSort(all);
  }
  return all;
}

/// The distinct vertices of the `n` sorted points `all`; `ids` gets their identities in order.
template <int Words>
LocalVertices DistinctVertices(
  const IdentifiedPoints<Words>& all, vtkIdType n, Identities<Words>& ids)
{
  LocalVertices local;
  // Copies of a vertex (sorted: side by side), looked for on threads, as are the vertices copied
  // when there are none (the common case: the points were merged before).
  const vtkIdType size = static_cast<vtkIdType>(all.size());
  std::atomic<bool> duplicates{ false };
  rgmc::ForEachChunk(size, rgmc::ElementChunk,
    [&](vtkIdType, vtkIdType first, vtkIdType last)
    {
      bool found = false;
      for (vtkIdType i = std::max<vtkIdType>(first, 1); i < last && !found; ++i)
      {
        found = all[i].first == all[i - 1].first;
      }
      if (found)
      {
        duplicates = true;
      }
    });
  if (!duplicates)
  {
    ids.resize(all.size());
    local.Sorted.resize(all.size());
    rgmc::ForEachChunk(size, rgmc::ElementChunk,
      [&](vtkIdType, vtkIdType first, vtkIdType last)
      {
        for (vtkIdType i = first; i < last; ++i)
        {
          ids[i] = all[i].first;
          local.Sorted[i] = all[i].second;
        }
      });
    local.Count = size;
    return local;
  }
  ids.reserve(all.size());
  local.Sorted.reserve(all.size());
  local.VertexOfPoint.resize(static_cast<std::size_t>(n));
  for (std::size_t i = 0; i < all.size(); ++i)
  {
    if (i == 0 || all[i].first != all[i - 1].first)
    {
      local.Sorted.push_back(static_cast<vtkIdType>(ids.size()));
      local.First.push_back(all[i].second);
      ids.push_back(all[i].first);
    }
    local.VertexOfPoint[all[i].second] = static_cast<vtkIdType>(ids.size()) - 1;
  }
  local.Count = static_cast<vtkIdType>(ids.size());
  return local;
}

/// Sorts the input points by identity into distinct vertices; `ids` gets the vertices'
/// identities in sorted order.
template <int Words>
LocalVertices MergeLocal(vtkPolyData* input, const vtkIdType* keys, Identities<Words>& ids)
{
  rgmc::SpanMark("numbering: sort");
  const IdentifiedPoints<Words> all = SortByIdentity<Words>(input, keys);
  rgmc::SpanMark("numbering: distinct vertices");
  LocalVertices local = DistinctVertices<Words>(all, input->GetNumberOfPoints(), ids);
  rgmc::SpanMark("numbering: global ids");
  return local;
}

/// The global id and owner of each of this rank's vertices, and the other holders of the shared
/// ones.
struct GlobalNumbering
{
  rgmc::HeapOverwriteVector<vtkIdType> Gid; // by vertex (written whole)
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
  IdentityNumbering(Ranks& ranks, const LocalVertices& vertices, Identities<Words>& ids)
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
          rgmc::ForEachChunk(this->Vertices.Count, rgmc::ElementChunk,
            [&](vtkIdType, vtkIdType first, vtkIdType last)
            {
              for (vtkIdType i = first; i < last; ++i)
              {
                numbering.Gid[this->Vertices.Sorted[i]] = i;
              }
            });
          numbering.Holding.assign(
            static_cast<std::size_t>(this->Vertices.Count), GlobalNumbering::Alone);
          Identities<Words>().swap(this->Ids);
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
    Identities<Words>().swap(this->Ids);
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
  Identities<Words>& Ids;               // this rank's, sorted (released once sent)
  std::vector<vtkIdType> SampleOffsets; // per rank, into AllSamples (in words)
  std::vector<vtkIdType> AllSamples;
  std::vector<std::size_t> SliceStart; // per range: its first identity of this rank's
  vtkIdType Numbered = 0;              // distinct identities in this rank's range
  std::vector<vtkIdType> RangeFirst;   // per range: its first global id
};

} // namespace seam
} // namespace rgmc

#endif // rgmcSeamNumbering_h

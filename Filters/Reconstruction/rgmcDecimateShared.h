// Decimate Surface's shared vertices, on threads: the part's vertices with their blocks, sent
// to each vertex's rank (its id modulo the ranks), and there the vertices in several blocks
// told back to the ranks that asked (vtkRGDecimate::FindSharedVertices runs these). What a
// rank sends or answers is a set: its order never reaches the result, which the receivers sort.
#ifndef rgmcDecimateShared_h
#define rgmcDecimateShared_h

#include "rgmcDecimateParts.h"
#include "rgmcRadixSort.h"
#include "vtkRGParallel.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

namespace rgmc
{
namespace decimate
{

using VertexBlocks = std::vector<std::vector<vtkIdType>>; // one message per rank

/// Each vertex's lowest block among its triangles' blocks (partBlock), NoBlock for a vertex
/// no triangle uses: a minimum, so the same whatever order the threads meet the triangles in.
class LowestBlocks
{
public:
  static constexpr std::int32_t NoBlock = std::numeric_limits<std::int32_t>::max();

  LowestBlocks(const SurfacePart& part, const std::vector<std::int32_t>& partBlock)
    : Lowest(part.NumberOfVertices())
  {
    const vtkIdType nv = static_cast<vtkIdType>(this->Lowest.size());
    ForEachChunk(nv, ElementChunk,
      [&](vtkIdType, vtkIdType begin, vtkIdType end)
      {
        for (vtkIdType v = begin; v < end; ++v)
        {
          this->Lowest[v].store(NoBlock, std::memory_order_relaxed);
        }
      });
    ForEachChunk(static_cast<vtkIdType>(part.NumberOfTriangles()), ElementChunk,
      [&](vtkIdType, vtkIdType begin, vtkIdType end)
      {
        for (vtkIdType t = begin; t < end; ++t)
        {
          vtkIdType c[3];
          part.Corners(static_cast<std::size_t>(t), c);
          for (vtkIdType v : c)
          {
            std::atomic<std::int32_t>& lowest = this->Lowest[v];
            std::int32_t now = lowest.load(std::memory_order_relaxed);
            while (partBlock[t] < now &&
              !lowest.compare_exchange_weak(now, partBlock[t], std::memory_order_relaxed))
            {
            }
          }
        }
      });
  }

  std::int32_t operator[](vtkIdType v) const
  {
    return this->Lowest[v].load(std::memory_order_relaxed);
  }

  vtkIdType Size() const { return static_cast<vtkIdType>(this->Lowest.size()); }

private:
  std::vector<std::atomic<std::int32_t>> Lowest;
};

/// The (vertex, block) pairs of the triangles' corners whose block is not the vertex's lowest,
/// sorted, each once (few vertices have any). On threads: each chunk of triangles lists its
/// pairs, copied to their places in chunk order, then radix-sorted as one word each (a vertex
/// index and a block both fit in 32 bits).
inline std::vector<std::pair<vtkIdType, vtkIdType>> OtherBlocks(
  const SurfacePart& part, const std::vector<std::int32_t>& partBlock, const LowestBlocks& lowest)
{
  const vtkIdType nt = static_cast<vtkIdType>(part.NumberOfTriangles());
  std::vector<std::vector<std::uint64_t>> found(
    static_cast<std::size_t>(ChunksOf(nt, ElementChunk)));
  ChunkPlaces places = PlaceChunks(nt, ElementChunk, { 0 },
    [&](vtkIdType chunk, vtkIdType begin, vtkIdType end, std::size_t* count)
    {
      for (vtkIdType t = begin; t < end; ++t)
      {
        vtkIdType c[3];
        part.Corners(static_cast<std::size_t>(t), c);
        for (vtkIdType v : c)
        {
          if (partBlock[t] != lowest[v])
          {
            found[chunk].push_back(
              static_cast<std::uint64_t>(v) << 32 | static_cast<std::uint32_t>(partBlock[t]));
          }
        }
      }
      *count = found[chunk].size();
    });
  OverwriteVector<std::uint64_t> words(places.End[0]); // written whole below
  ForEachChunk(nt, ElementChunk,
    [&](vtkIdType chunk, vtkIdType, vtkIdType)
    {
      std::copy(found[chunk].begin(), found[chunk].end(), words.begin() + places.At(chunk, 0));
      std::vector<std::uint64_t>().swap(found[chunk]);
    });
  RadixSort(
    words, [](std::uint64_t w) { return w; }, Tasks());
  words.erase(std::unique(words.begin(), words.end()), words.end());
  std::vector<std::pair<vtkIdType, vtkIdType>> more(words.size());
  for (std::size_t i = 0; i < words.size(); ++i)
  {
    more[i] = { static_cast<vtkIdType>(words[i] >> 32),
      static_cast<vtkIdType>(words[i] & 0xffffffffu) };
  }
  return more;
}

/// (vertex id, vertex, block) for the lowest block of every used vertex and for each of `more`,
/// to the vertex's rank: the lowest blocks written in fixed chunks of vertices on threads, each
/// chunk at its place in each rank's message (counted first), `more` after them.
inline void WriteVertexBlocks(const SurfacePart& part, const LowestBlocks& lowest,
  const std::vector<std::pair<vtkIdType, vtkIdType>>& more, VertexBlocks& outgoing)
{
  const std::size_t size = outgoing.size();
  const vtkIdType nv = lowest.Size();
  ChunkPlaces records = PlaceChunks(nv, ElementChunk, std::vector<std::size_t>(size, 0),
    [&](vtkIdType, vtkIdType begin, vtkIdType end, std::size_t* counts)
    {
      for (vtkIdType v = begin; v < end; ++v)
      {
        counts[static_cast<std::size_t>(part.Id(v)) % size] += lowest[v] != LowestBlocks::NoBlock;
      }
    });
  // `more` after the lowest blocks: each message sized once for both.
  std::vector<std::size_t> after = records.End;
  for (const auto& vb : more)
  {
    ++after[static_cast<std::size_t>(part.Id(vb.first)) % size];
  }
  for (std::size_t r = 0; r < size; ++r)
  {
    outgoing[r].resize(3 * after[r]);
  }
  ForEachChunk(nv, ElementChunk,
    [&](vtkIdType c, vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType v = begin; v < end; ++v)
      {
        if (lowest[v] != LowestBlocks::NoBlock)
        {
          const vtkIdType id = part.Id(v);
          const std::size_t r = static_cast<std::size_t>(id) % size;
          vtkIdType* out = outgoing[r].data() + 3 * records.At(c, r)++;
          out[0] = id;
          out[1] = v;
          out[2] = lowest[v];
        }
      }
    });
  for (const auto& vb : more)
  {
    const vtkIdType id = part.Id(vb.first);
    const std::size_t r = static_cast<std::size_t>(id) % size;
    vtkIdType* out = outgoing[r].data() + 3 * records.End[r]++;
    out[0] = id;
    out[1] = vb.first;
    out[2] = vb.second;
  }
}

using AskedRecord = std::array<vtkIdType, 4>; // (vertex id, block, asking rank, its index)

/// Every record asked (AskedRecord), by vertex id; `asked` is emptied.
inline OverwriteVector<AskedRecord> AskedRecords(VertexBlocks& asked)
{
  std::vector<std::size_t> first(asked.size() + 1, 0);
  for (std::size_t r = 0; r < asked.size(); ++r)
  {
    first[r + 1] = first[r] + asked[r].size() / 3;
  }
  OverwriteVector<AskedRecord> all(first.back());
  for (std::size_t r = 0; r < asked.size(); ++r)
  {
    const std::vector<vtkIdType>& words = asked[r];
    ForEachChunk(static_cast<vtkIdType>(first[r + 1] - first[r]), ElementChunk,
      [&](vtkIdType, vtkIdType begin, vtkIdType end)
      {
        for (vtkIdType i = begin; i < end; ++i)
        {
          all[first[r] + i] = { words[3 * i], words[3 * i + 2], static_cast<vtkIdType>(r),
            words[3 * i + 1] };
        }
      });
    std::vector<vtkIdType>().swap(asked[r]);
  }
  RadixSort(
    all, [](const AskedRecord& e) { return KeyOf(e[0]); }, Tasks());
  return all;
}

/// To each rank that asked about a vertex in several blocks, (its index of the vertex, block)
/// for each of them, in order of vertex id (`answers`: one empty message per rank). The records
/// (AskedRecords) are cut into fixed chunks, each taking the vertices that start in it, answered on
/// threads and joined in order.
inline void AnswerSharedVertices(const OverwriteVector<AskedRecord>& all, VertexBlocks& answers)
{
  const std::size_t size = answers.size();
  const vtkIdType n = static_cast<vtkIdType>(all.size());
  auto vertexStart = [&all, n](vtkIdType i) // the first record of a vertex at or after i
  {
    while (i > 0 && i < n && all[i][0] == all[i - 1][0])
    {
      ++i;
    }
    return i;
  };
  std::vector<VertexBlocks> parts(static_cast<std::size_t>(ChunksOf(n, ElementChunk)));
  // Each chunk's answers per rank, then their places (in chunk order) in the messages.
  ChunkPlaces places = PlaceChunks(n, ElementChunk, std::vector<std::size_t>(size, 0),
    [&](vtkIdType chunk, vtkIdType begin, vtkIdType end, std::size_t* counts)
    {
      VertexBlocks& part = parts[chunk];
      part.resize(size);
      std::vector<vtkIdType> blocks;
      std::vector<std::pair<vtkIdType, vtkIdType>> askers;
      for (vtkIdType first = vertexStart(begin), last, stop = vertexStart(end); first < stop;
           first = last)
      {
        blocks.clear();
        askers.clear();
        for (last = first; last < n && all[last][0] == all[first][0]; ++last)
        {
          blocks.push_back(all[last][1]);
          askers.emplace_back(all[last][2], all[last][3]);
        }
        SortDistinct(blocks);
        if (blocks.size() < 2)
        {
          continue;
        }
        std::sort(askers.begin(), askers.end());
        askers.erase(std::unique(askers.begin(), askers.end()), askers.end());
        for (const auto& asker : askers)
        {
          auto& words = part[static_cast<std::size_t>(asker.first)];
          for (vtkIdType block : blocks)
          {
            words.insert(words.end(), { asker.second, block });
          }
        }
      }
      for (std::size_t r = 0; r < size; ++r)
      {
        counts[r] = part[r].size();
      }
    });
  for (std::size_t r = 0; r < size; ++r)
  {
    answers[r].resize(places.End[r]);
  }
  ForEachChunk(n, ElementChunk,
    [&](vtkIdType chunk, vtkIdType, vtkIdType)
    {
      const std::size_t c = static_cast<std::size_t>(chunk);
      for (std::size_t r = 0; r < size; ++r)
      {
        std::copy(parts[c][r].begin(), parts[c][r].end(), answers[r].begin() + places.At(chunk, r));
        std::vector<vtkIdType>().swap(parts[c][r]);
      }
    });
}

} // namespace decimate
} // namespace rgmc

#endif

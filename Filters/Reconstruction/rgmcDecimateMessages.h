// The messages of vtkRGDecimate's exchanges: their tags, and the triangles (with their
// vertices' records) that a rank sends to the ranks of their blocks.
#ifndef rgmcDecimateMessages_h
#define rgmcDecimateMessages_h

#include "rgmcDecimateParts.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <utility>
#include <vector>

namespace rgmc
{
namespace decimate
{

/// Message tags of the passes' exchanges.
enum Tags
{
  TrianglesTag = 7401,
  SharedTag = 7402,
  AnswersTag = 7403
};

/// Every rank as a partner of an exchange.
inline std::vector<bool> Everyone(int size)
{
  return std::vector<bool>(static_cast<std::size_t>(size), true);
}

/// A triangle of this rank's part going to a block: (block, triangle, 1 if to its halo).
using Sending = std::array<vtkIdType, 3>;
/// The triangles going to one rank (sized, then written whole on threads).
using Sendings = rgmc::OverwriteVector<Sending>;

/// Where the part's triangles go: each one's block, each block's wave and rank, and the other
/// blocks of the part's vertices that are in several (those of vertex v are SharedBlocks[i],
/// SharedFirst[v] <= i < SharedFirst[v + 1]).
struct TriangleRoutes
{
  const std::int32_t* PartBlock;
  const int* WaveOf;
  const int* Owner;
  const std::uint32_t* SharedFirst;
  const std::int32_t* SharedBlocks;
};

/// The part's triangles for the blocks of `wave`, per rank of the block (one list for each of
/// `ranks`): to its own block if that is in the wave, and to the other blocks of
/// the wave that share one of its vertices, as their halo. Each rank's list holds the own ones
/// first, then the halos, each kind in order of triangle and, for a triangle's halos, of block.
/// On threads: each chunk of triangles lists its sendings per rank and kind; they are then
/// copied to their places (PlaceChunks).
inline std::vector<Sendings> ListSendings(
  const SurfacePart& part, const TriangleRoutes& routes, int wave, int ranks)
{
  const std::size_t size = static_cast<std::size_t>(ranks), kinds = 2 * size;
  const vtkIdType n = static_cast<vtkIdType>(part.NumberOfTriangles());
  std::vector<Sendings> found( // per chunk and kind: 2r own triangles of rank r, 2r + 1 halos
    static_cast<std::size_t>(rgmc::ChunksOf(n, rgmc::ElementChunk)) * kinds);
  rgmc::ChunkPlaces places =
    rgmc::PlaceChunks(n, rgmc::ElementChunk, std::vector<std::size_t>(kinds, 0),
      [&](vtkIdType chunk, vtkIdType begin, vtkIdType end, std::size_t* counts)
      {
        Sendings* lists = found.data() + static_cast<std::size_t>(chunk) * kinds;
        std::vector<vtkIdType> others;
        for (vtkIdType t = begin; t < end; ++t)
        {
          const vtkIdType block = routes.PartBlock[t];
          if (routes.WaveOf[block] == wave)
          {
            lists[2 * routes.Owner[block]].push_back({ block, t, 0 });
          }
          vtkIdType c[3];
          part.Corners(static_cast<std::size_t>(t), c);
          others.clear();
          for (vtkIdType v : c)
          {
            for (std::uint32_t i = routes.SharedFirst[v]; i < routes.SharedFirst[v + 1]; ++i)
            {
              const vtkIdType other = routes.SharedBlocks[i];
              if (other != block && routes.WaveOf[other] == wave)
              {
                others.push_back(other);
              }
            }
          }
          std::sort(others.begin(), others.end());
          others.erase(std::unique(others.begin(), others.end()), others.end());
          for (vtkIdType other : others)
          {
            lists[2 * routes.Owner[other] + 1].push_back({ other, t, 1 });
          }
        }
        for (std::size_t k = 0; k < kinds; ++k)
        {
          counts[k] = lists[k].size();
        }
      });
  std::vector<Sendings> going(size);
  for (std::size_t r = 0; r < size; ++r)
  {
    going[r].resize(places.End[2 * r] + places.End[2 * r + 1]);
  }
  rgmc::ForEachChunk(n, rgmc::ElementChunk,
    [&](vtkIdType chunk, vtkIdType, vtkIdType)
    {
      for (std::size_t k = 0; k < kinds; ++k)
      {
        Sendings& list = found[static_cast<std::size_t>(chunk) * kinds + k];
        const std::size_t at = places.At(chunk, k) + (k % 2 ? places.End[k - 1] : 0);
        std::copy(list.begin(), list.end(), going[k / 2].begin() + at);
        Sendings().swap(list);
      }
    });
  return going;
}

/// How many of `going` go to their own block: those come first (ListSendings lists them so).
inline vtkIdType OwnSendings(const Sendings& going)
{
  return std::partition_point(
           going.begin(), going.end(), [](const Sending& s) { return s[2] == 0; }) -
    going.begin();
}

/// A message of triangles for blocks: the counts of own and halo triangles, (block, three
/// vertex ids) for each (the own ones first, as in `going`), then the records of their
/// vertices, each once, by increasing id. Written in fixed chunks on threads (each part of the
/// message has its place).
inline void WriteTriangles(
  std::vector<vtkIdType>& words, const Sendings& going, const SurfacePart& part)
{
  const vtkIdType halos = static_cast<vtkIdType>(going.size()) - OwnSendings(going);
  const vtkIdType n = static_cast<vtkIdType>(going.size()), chunk = rgmc::ElementChunk;
  // The corners' vertices, by id (each written once), first: the message's size is then known.
  using IdAndIndex = std::array<vtkIdType, 2>; // (id, part index)
  rgmc::OverwriteVector<IdAndIndex> vertices(3 * going.size());
  rgmc::ForEachChunk(n, chunk,
    [&](vtkIdType, vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType i = begin; i < end; ++i)
      {
        vtkIdType c[3];
        part.Corners(static_cast<std::size_t>(going[i][1]), c);
        for (int k = 0; k < 3; ++k)
        {
          vertices[3 * i + k] = { part.Id(c[k]), c[k] };
        }
      }
    });
  rgmc::RadixSort(
    vertices, [](const IdAndIndex& p) { return KeyOf(p[0]); }, rgmc::Tasks());
  const vtkIdType corners = static_cast<vtkIdType>(vertices.size());
  auto isFirst = [&vertices](vtkIdType i)
  { return i == 0 || vertices[i][0] != vertices[i - 1][0]; };
  const std::vector<std::size_t> before = rgmc::CountBefore(corners, chunk, isFirst);
  const std::size_t start = words.size(), perVertex = part.WordsPerVertex();
  const std::size_t records = start + 2 + 4 * going.size();
  words.resize(records + perVertex * before.back());
  words[start] = n - halos;
  words[start + 1] = halos;
  rgmc::ForEachChunk(n, chunk,
    [&](vtkIdType, vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType i = begin; i < end; ++i)
      {
        vtkIdType c[3];
        part.Corners(static_cast<std::size_t>(going[i][1]), c);
        vtkIdType* out = words.data() + start + 2 + 4 * i;
        out[0] = going[i][0];
        for (int k = 0; k < 3; ++k)
        {
          out[1 + k] = part.Id(c[k]);
        }
      }
    });
  rgmc::ForEachChunk(corners, chunk,
    [&](vtkIdType c, vtkIdType begin, vtkIdType end)
    {
      vtkIdType* out = words.data() + records + perVertex * before[static_cast<std::size_t>(c)];
      for (vtkIdType i = begin; i < end; ++i)
      {
        if (isFirst(i))
        {
          part.Write(vertices[i][1], out);
          out += perVertex;
        }
      }
    });
}

/// Appends triangles [0, n) to their blocks' lists in order of t (`blocks`, this rank's, by
/// increasing id; a block this rank does not own is an error): the first `own` to the block's
/// own list, the others to its halo. blockOf(t) is triangle t's block id, cornersOf(t) its
/// vertices' ids. On threads: each chunk of triangles finds their blocks and counts them per
/// list, which gives each chunk its places in the lists (PlaceChunks); then they are filled.
template <typename BlockOf, typename CornersOf>
void AppendTriangles(
  vtkIdType n, vtkIdType own, BlockOf&& blockOf, CornersOf&& cornersOf, std::vector<Block>& blocks)
{
  // At most 64 chunks (any cut gives the same lists): counts per chunk and block list.
  const vtkIdType chunk = std::max(rgmc::ElementChunk, rgmc::ChunksOf(n, 64));
  auto list = [&blocks](std::size_t l) -> std::vector<Triangle>&
  { return l % 2 ? blocks[l / 2].Halo : blocks[l / 2].Own; };
  std::vector<std::size_t> sizes(2 * blocks.size());
  for (std::size_t l = 0; l < sizes.size(); ++l)
  {
    sizes[l] = list(l).size();
  }
  rgmc::OverwriteVector<std::int32_t> listOf(static_cast<std::size_t>(n));
  rgmc::ChunkPlaces places = rgmc::PlaceChunks(n, chunk, std::move(sizes),
    [&](vtkIdType, vtkIdType begin, vtkIdType end, std::size_t* counts)
    {
      for (vtkIdType t = begin; t < end; ++t)
      {
        const vtkIdType id = blockOf(t);
        const auto block = std::lower_bound(blocks.begin(), blocks.end(), id,
          [](const Block& b, vtkIdType key) { return b.Id < key; });
        if (block == blocks.end() || block->Id != id)
        {
          throw std::runtime_error("triangles came to a rank that does not own their block");
        }
        listOf[t] = static_cast<std::int32_t>(2 * (block - blocks.begin()) + (t < own ? 0 : 1));
        ++counts[listOf[t]];
      }
    });
  rgmc::ParallelFor(static_cast<vtkIdType>(places.Outputs), 1,
    [&](vtkIdType first, vtkIdType last)
    {
      for (std::size_t l = first; l < static_cast<std::size_t>(last); ++l)
      {
        list(l).resize(places.End[l]);
      }
    });
  rgmc::ForEachChunk(n, chunk,
    [&](vtkIdType c, vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType t = begin; t < end; ++t)
      {
        list(listOf[t])[places.At(c, listOf[t])++] = cornersOf(t);
      }
    });
}

/// Reads what WriteTriangles wrote: each triangle appended to its block's own or halo list
/// (AppendTriangles), the vertex records to `table`, on threads.
inline void ReadTriangles(
  const std::vector<vtkIdType>& words, std::vector<Block>& blocks, VertexTable& table)
{
  if (words.size() < 2)
  {
    return;
  }
  const vtkIdType own = words[0], n = words[0] + words[1];
  AppendTriangles(
    n, own, [&words](vtkIdType t) { return words[2 + 4 * t]; },
    [&words](vtkIdType t)
    {
      const vtkIdType* w = words.data() + 2 + 4 * t;
      return Triangle{ w[1], w[2], w[3] };
    },
    blocks);
  const std::size_t start = 2 + 4 * static_cast<std::size_t>(n), size = table.Words();
  const std::size_t first = table.Vertices.size(), records = (words.size() - start) / size;
  table.Grow(records);
  rgmc::ForEachChunk(static_cast<vtkIdType>(records), rgmc::ElementChunk,
    [&](vtkIdType, vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType i = begin; i < end; ++i)
      {
        table.ReadAt(first + i, words.data() + start + size * i);
      }
    });
}

/// What ReadTriangles reads from the message WriteTriangles writes of `staying` (this rank's
/// triangles for its own blocks, the own ones first), taken from the part with no message: the
/// same lists and the same records, on threads. The records are sorted by id as the message's
/// are (a packed radix sort of the used vertices), so that the table's sort, once every message
/// is read, finds them in place.
inline void KeepTriangles(
  const Sendings& staying, const SurfacePart& part, std::vector<Block>& blocks, VertexTable& table)
{
  const vtkIdType n = static_cast<vtkIdType>(staying.size());
  const vtkIdType own = OwnSendings(staying);
  auto corners = [&](vtkIdType t, vtkIdType c[3])
  { part.Corners(static_cast<std::size_t>(staying[t][1]), c); };
  AppendTriangles(
    n, own, [&staying](vtkIdType t) { return staying[t][0]; },
    [&](vtkIdType t)
    {
      vtkIdType c[3];
      corners(t, c);
      return Triangle{ part.Id(c[0]), part.Id(c[1]), part.Id(c[2]) };
    },
    blocks);
  const vtkIdType nv = static_cast<vtkIdType>(part.NumberOfVertices());
  std::vector<std::atomic<std::uint8_t>> used(static_cast<std::size_t>(nv));
  rgmc::ForEachChunk(n, rgmc::ElementChunk,
    [&](vtkIdType, vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType t = begin; t < end; ++t)
      {
        vtkIdType c[3];
        corners(t, c);
        for (vtkIdType v : c)
        {
          used[v].store(1, std::memory_order_relaxed);
        }
      }
    });
  auto isUsed = [&used](vtkIdType v) { return used[v].load(std::memory_order_relaxed) != 0; };
  const std::vector<std::size_t> before = rgmc::CountBefore(nv, rgmc::ElementChunk, isUsed);
  rgmc::OverwriteVector<vtkIdType> usedList(before.back()); // in the part's order
  rgmc::ForEachChunk(nv, rgmc::ElementChunk,
    [&](vtkIdType c, vtkIdType begin, vtkIdType end)
    {
      std::size_t at = before[static_cast<std::size_t>(c)];
      for (vtkIdType v = begin; v < end; ++v)
      {
        if (isUsed(v))
        {
          usedList[at++] = v;
        }
      }
    });
  const std::size_t first = table.Vertices.size(), records = usedList.size();
  table.Grow(records);
  auto put = [&](std::size_t at, vtkIdType v)
  {
    vtkIdType words[14]; // as the message would carry the vertex
    part.Write(v, words);
    table.ReadAt(first + at, words);
  };
  // By id, as in the message, so that the table's sort finds them in place (ids that do not
  // fit the packed sort, negative ones, stay in the part's order: the sort moves them).
  if (!rgmc::RadixSortPacked(
        records, [&](std::size_t i) { return static_cast<std::uint64_t>(part.Id(usedList[i])); },
        [&](std::size_t at, std::uint64_t, std::size_t i) { put(at, usedList[i]); }, rgmc::Tasks()))
  {
    rgmc::ForEachChunk(static_cast<vtkIdType>(records), rgmc::ElementChunk,
      [&](vtkIdType, vtkIdType begin, vtkIdType end)
      {
        for (vtkIdType i = begin; i < end; ++i)
        {
          put(static_cast<std::size_t>(i), usedList[i]);
        }
      });
  }
}

} // namespace decimate
} // namespace rgmc

#endif

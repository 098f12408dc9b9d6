// The messages of vtkRGDecimate's exchanges: their tags, and the triangles (with their
// vertices' records) that a rank sends to the ranks of their blocks.
#ifndef rgmcDecimateMessages_h
#define rgmcDecimateMessages_h

#include "rgmcDecimateParts.h"

#include <algorithm>
#include <array>
#include <cstddef>
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

/// A message of triangles for blocks: the counts of own and halo triangles, (block, three
/// vertex ids) for each (the own ones first), then the records of their vertices, each once, by
/// increasing id. Written in fixed chunks on threads (each part of the message has its place).
inline void WriteTriangles(
  std::vector<vtkIdType>& words, std::vector<Sending>& going, const SurfacePart& part)
{
  std::stable_partition(going.begin(), going.end(), [](const Sending& s) { return s[2] == 0; });
  const auto halos =
    std::count_if(going.begin(), going.end(), [](const Sending& s) { return s[2]; });
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

/// Reads what WriteTriangles wrote: each triangle appended to its block's own or halo list
/// (`blocks`, this rank's, by increasing id; a block this rank does not own is an error), the
/// vertex records to `table`. On threads: each chunk of triangles finds their blocks and counts
/// them per block, which gives each chunk its places in the blocks' lists (in message order, as
/// a serial read would append them); the records go to their places.
inline void ReadTriangles(
  const std::vector<vtkIdType>& words, std::vector<Block>& blocks, VertexTable& table)
{
  if (words.size() < 2)
  {
    return;
  }
  const vtkIdType own = words[0], n = words[0] + words[1];
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
        const vtkIdType id = words[2 + 4 * t];
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
        const vtkIdType* w = words.data() + 2 + 4 * t;
        list(listOf[t])[places.At(c, listOf[t])++] = { w[1], w[2], w[3] };
      }
    });
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

} // namespace decimate
} // namespace rgmc

#endif

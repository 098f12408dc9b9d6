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
  std::vector<std::pair<vtkIdType, vtkIdType>> vertices(3 * going.size()); // (id, part index)
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
    vertices, [](const std::pair<vtkIdType, vtkIdType>& p) { return KeyOf(p.first); },
    rgmc::Tasks());
  const vtkIdType corners = static_cast<vtkIdType>(vertices.size());
  auto isFirst = [&vertices](vtkIdType i)
  { return i == 0 || vertices[i].first != vertices[i - 1].first; };
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
          part.Write(vertices[i].second, out);
          out += perVertex;
        }
      }
    });
}

/// Reads what WriteTriangles wrote: each triangle into its block's own or halo list
/// (`blockWithId`; a block this rank does not own is an error), the vertex records into `table`.
template <typename BlockWithId>
void ReadTriangles(
  const std::vector<vtkIdType>& words, BlockWithId&& blockWithId, VertexTable& table)
{
  if (words.size() < 2)
  {
    return;
  }
  const vtkIdType own = words[0], n = words[0] + words[1];
  std::size_t at = 2;
  for (vtkIdType t = 0; t < n; ++t, at += 4)
  {
    Block* block = blockWithId(words[at]);
    if (!block)
    {
      throw std::runtime_error("triangles came to a rank that does not own their block");
    }
    (t < own ? block->Own : block->Halo).push_back({ words[at + 1], words[at + 2], words[at + 3] });
  }
  const std::size_t size = table.Words();
  for (; at + size <= words.size(); at += size)
  {
    table.Read(words.data() + at);
  }
}

} // namespace decimate
} // namespace rgmc

#endif

// The kernels' tasks: `parallel(count, task)` runs task(i) for every i in [0, count), in any
// order, possibly at once (the filters hand in vtkSMPTools' threads, rgmc::Tasks; SerialTasks
// runs them in order on this thread). And what several passes build on them: each chunk of a
// range counts what it puts into ordered outputs, the counts are summed in chunk order, and
// each chunk then writes at its places, so that the outputs are the same on any threads.
#ifndef rgmcTasks_h
#define rgmcTasks_h

#include "rgmcBuffer.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <utility>
#include <vector>

namespace rgmc
{

/// Runs task(i) for each i in [0, count), in order, on this thread: the default of the sorts'
/// `parallel` argument.
struct SerialTasks
{
  template <typename Task>
  void operator()(std::int64_t count, Task&& task) const
  {
    for (std::int64_t i = 0; i < count; ++i)
    {
      task(i);
    }
  }
};

/// How many chunks of `chunk` elements cover [0, n).
template <typename N, typename Chunk>
typename std::common_type<N, Chunk>::type ChunksOf(N n, Chunk chunk)
{
  return (n + chunk - 1) / chunk;
}

/// Where each chunk of [0, n) puts its elements in several outputs filled in chunk order (a
/// rank's message, a block's list), so that every output is the same on any number of threads.
/// At(c, d) is chunk c's first place in output d, End[d] the output's end once all are in.
struct ChunkPlaces
{
  std::size_t Outputs = 0;
  std::vector<std::size_t> Places; // Places[c * Outputs + d]
  std::vector<std::size_t> End;

  std::size_t& At(std::int64_t c, std::size_t d)
  {
    return this->Places[static_cast<std::size_t>(c) * this->Outputs + d];
  }
};

/// count(c, begin, end, counts) adds to counts[d] how many elements of chunk c = [begin, end)
/// go to output d (one chunk a task, counts zeroed); the counts are then summed in chunk order
/// from start[d], output d's first place, so chunk c's elements in output d follow those of
/// every chunk before it.
template <typename Count, typename Parallel>
ChunkPlaces PlaceChunks(std::int64_t n, std::int64_t chunk, std::vector<std::size_t> start,
  Count&& count, Parallel&& parallel)
{
  ChunkPlaces places;
  places.Outputs = start.size();
  places.Places.assign(static_cast<std::size_t>(ChunksOf(n, chunk)) * places.Outputs, 0);
  parallel(ChunksOf(n, chunk),
    [&](std::int64_t c) { count(c, c * chunk, std::min(n, (c + 1) * chunk), &places.At(c, 0)); });
  places.End = std::move(start);
  for (std::size_t i = 0; i < places.Places.size(); i += places.Outputs)
  {
    for (std::size_t d = 0; d < places.Outputs; ++d)
    {
      places.End[d] += std::exchange(places.Places[i + d], places.End[d]);
    }
  }
  return places;
}

/// before[c]: how many of the indices i < c * chunk, 0 <= i < n, have counted(i) true (a
/// count per chunk a task, then their sums in order); before has one entry per chunk and one
/// more, the total.
template <typename Counted, typename Parallel>
std::vector<std::size_t> CountBefore(
  std::int64_t n, std::int64_t chunk, Counted&& counted, Parallel&& parallel)
{
  ChunkPlaces places = PlaceChunks(
    n, chunk, { 0 },
    [&](std::int64_t, std::int64_t begin, std::int64_t end, std::size_t* counts)
    {
      for (std::int64_t i = begin; i < end; ++i)
      {
        counts[0] += counted(i);
      }
    },
    parallel);
  places.Places.push_back(places.End[0]);
  return std::move(places.Places);
}

/// Indices a task of GroupByKey (and keys a block): Seam Repair's 6 M corners of the 512^3 skull
/// in 368 tasks of about 0.07 ms (65 536 made three steps of the work/span profile wait 0.14 to
/// 0.28 ms for their longest task).
constexpr std::int64_t GroupChunk = 16384;

/// Groups the indices 0 <= i < n by their key keyAt(i), in [0, keys): on return, key k's indices
/// are items[offsets[k]] .. items[offsets[k + 1] - 1], in increasing order (offsets: keys + 1
/// values), exactly as one counting pass in order gives them, on any threads. For keys that
/// follow the indices (the corners of a mesh by vertex, its vertices numbered as its triangles
/// come): each chunk of indices counts its keys over the range of keys it meets, each key's
/// counts are then summed chunk after chunk (tasks over blocks of keys), and each chunk places
/// its indices after those of the chunks before it. Returns false, having changed nothing, when
/// the chunks' ranges of keys add up to more than 2 (n + keys) (scattered keys: the caller
/// takes one pass in order).
template <typename KeyAt, typename Offsets, typename Items, typename Parallel>
bool GroupByKey(std::int64_t n, std::int64_t keys, KeyAt&& keyAt, Offsets& offsets, Items& items,
  Parallel&& parallel)
{
  constexpr std::int64_t chunk = GroupChunk, keyBlock = GroupChunk;
  const std::int64_t chunks = ChunksOf(n, chunk), blocks = ChunksOf(keys, keyBlock);
  // Each chunk's keys [low, high), then its counts at base[c] .. base[c + 1].
  std::vector<std::int64_t> low(static_cast<std::size_t>(chunks), 0), high(low), base(low);
  parallel(chunks,
    [&](std::int64_t c)
    {
      std::int64_t lo = keys, hi = 0;
      for (std::int64_t i = c * chunk; i < std::min(n, (c + 1) * chunk); ++i)
      {
        const std::int64_t k = static_cast<std::int64_t>(keyAt(i));
        lo = std::min(lo, k);
        hi = std::max(hi, k + 1);
      }
      low[c] = lo;
      high[c] = std::max(lo, hi);
    });
  std::int64_t total = 0;
  for (std::int64_t c = 0; c < chunks; ++c)
  {
    base[c] = total;
    total += high[c] - low[c];
  }
  if (total > 2 * (n + keys))
  {
    return false;
  }
  OverwriteVector<std::int64_t> counts(static_cast<std::size_t>(total)); // zeroed by each chunk
  parallel(chunks,
    [&](std::int64_t c)
    {
      std::int64_t* count = counts.data() + base[c] - low[c];
      std::fill(count + low[c], count + high[c], std::int64_t(0));
      for (std::int64_t i = c * chunk; i < std::min(n, (c + 1) * chunk); ++i)
      {
        ++count[static_cast<std::int64_t>(keyAt(i))];
      }
    });
  // Per block of keys: each chunk's count becomes its first place among the key's indices, and
  // offsets[k + 1] the key's size; then the sizes summed, blocks first.
  // Offsets and items that leave their values unset (OverwriteVector) are first written, and
  // their pages faulted in, by the tasks below, not zeroed here on one thread.
  offsets.resize(static_cast<std::size_t>(keys) + 1);
  offsets[0] = 0;
  std::vector<std::int64_t> blockSize(static_cast<std::size_t>(blocks) + 1, 0);
  parallel(blocks,
    [&](std::int64_t b)
    {
      const std::int64_t first = b * keyBlock, last = std::min(keys, first + keyBlock);
      std::fill(offsets.begin() + (first + 1), offsets.begin() + (last + 1),
        typename Offsets::value_type(0));
      for (std::int64_t c = 0; c < chunks; ++c)
      {
        std::int64_t* count = counts.data() + base[c] - low[c];
        for (std::int64_t k = std::max(first, low[c]); k < std::min(last, high[c]); ++k)
        {
          offsets[k + 1] += std::exchange(count[k], offsets[k + 1]);
        }
      }
      for (std::int64_t k = first; k < last; ++k)
      {
        blockSize[b + 1] += offsets[k + 1];
      }
    });
  for (std::int64_t b = 0; b < blocks; ++b)
  {
    blockSize[b + 1] += blockSize[b];
  }
  parallel(blocks,
    [&](std::int64_t b)
    {
      const std::int64_t first = b * keyBlock, last = std::min(keys, first + keyBlock);
      std::int64_t at = blockSize[b];
      for (std::int64_t k = first; k < last; ++k)
      {
        at += offsets[k + 1];
        offsets[k + 1] = at;
      }
    });
  items.resize(static_cast<std::size_t>(n));
  parallel(chunks,
    [&](std::int64_t c)
    {
      std::int64_t* place = counts.data() + base[c] - low[c];
      for (std::int64_t k = low[c]; k < high[c]; ++k)
      {
        place[k] += offsets[k];
      }
      for (std::int64_t i = c * chunk; i < std::min(n, (c + 1) * chunk); ++i)
      {
        items[static_cast<std::size_t>(place[static_cast<std::int64_t>(keyAt(i))]++)] =
          static_cast<typename Items::value_type>(i);
      }
    });
  return true;
}

} // namespace rgmc

#endif

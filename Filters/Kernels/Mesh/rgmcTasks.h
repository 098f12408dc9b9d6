// The kernels' tasks: `parallel(count, task)` runs task(i) for every i in [0, count), in any
// order, possibly at once (the filters hand in vtkSMPTools' threads, rgmc::Tasks; SerialTasks
// runs them in order on this thread). And what several passes build on them: each chunk of a
// range counts what it puts into ordered outputs, the counts are summed in chunk order, and
// each chunk then writes at its places, so that the outputs are the same on any threads.
#ifndef rgmcTasks_h
#define rgmcTasks_h

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

} // namespace rgmc

#endif

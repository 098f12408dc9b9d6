// Threads within one rank for the plugin's VTK classes (private to the module): vtkSMPTools, so
// that ParaView's and VTK's settings govern them (VTK_SMP_BACKEND_IN_USE, VTK_SMP_MAX_THREADS),
// with an exception thrown on a worker thread (std::bad_alloc) carried back to the calling
// thread instead of terminating the process.
#ifndef vtkRGParallel_h
#define vtkRGParallel_h

#include "vtkRGSpan.h"
#include "vtkSMPTools.h"
#include "vtkType.h"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <exception>
#include <mutex>
#include <utility>
#include <vector>

namespace rgmc
{

/// True when one thread runs, so that a filter may take a serial path instead of a parallel
/// one with the same result; false while the work/span profile records the parallel paths.
inline bool SingleThreaded()
{
  return vtkSMPTools::GetEstimatedNumberOfThreads() <= 1 && !SpanRecorder::Recording();
}

/// Calls body(begin, end) over ranges covering [0, count) exactly once, on vtkSMPTools'
/// threads, `grain` indices or more at a time. The first exception a range throws stops the
/// ranges not yet started and is thrown again here. Results must not depend on the ranges.
/// While a work/span profile records, the ranges are the grains, timed one by one.
template <typename Body>
void ParallelFor(vtkIdType count, vtkIdType grain, Body&& body)
{
  if (SpanRecorder* recorder = SpanRecorder::Recording())
  {
    recorder->Step(count, grain, body);
    return;
  }
  std::exception_ptr failure;
  std::mutex failureMutex;
  std::atomic<bool> failed{ false };
  vtkSMPTools::For(vtkIdType(0), count, grain,
    [&](vtkIdType begin, vtkIdType end)
    {
      if (failed)
      {
        return;
      }
      try
      {
        body(begin, end);
      }
      catch (...)
      {
        std::lock_guard<std::mutex> lock(failureMutex);
        if (!failure)
        {
          failure = std::current_exception();
        }
        failed = true;
      }
    });
  if (failure)
  {
    std::rethrow_exception(failure);
  }
}

/// The elements a chunk holds in passes over many elements whose per-chunk results are put
/// together in chunk order (ForEachChunk, CountBefore): a fixed number, so that the results
/// are the same on any number of threads.
constexpr vtkIdType ElementChunk = 65536;

/// How many chunks of `chunk` elements cover [0, n).
inline vtkIdType ChunksOf(vtkIdType n, vtkIdType chunk)
{
  return (n + chunk - 1) / chunk;
}

/// body(c, begin, end) for every chunk c = [begin, end) of [0, n), `chunk` elements each but
/// the last, on threads through ParallelFor, one chunk a task.
template <typename Body>
void ForEachChunk(vtkIdType n, vtkIdType chunk, Body&& body)
{
  ParallelFor(ChunksOf(n, chunk), 1,
    [&](vtkIdType from, vtkIdType to)
    {
      for (vtkIdType c = from; c < to; ++c)
      {
        body(c, c * chunk, std::min(n, (c + 1) * chunk));
      }
    });
}

/// Where each chunk of [0, n) puts its elements in several outputs filled in chunk order (a
/// rank's message, a block's list), so that every output is the same on any number of threads.
/// At(c, d) is chunk c's first place in output d, End[d] the output's end once all are in.
struct ChunkPlaces
{
  std::size_t Outputs = 0;
  std::vector<std::size_t> Places; // Places[c * Outputs + d]
  std::vector<std::size_t> End;

  std::size_t& At(vtkIdType c, std::size_t d)
  {
    return this->Places[static_cast<std::size_t>(c) * this->Outputs + d];
  }
};

/// count(c, begin, end, counts) adds to counts[d] how many elements of chunk c = [begin, end)
/// go to output d (on threads, one chunk a task, counts zeroed); the counts are then summed in
/// chunk order from start[d], output d's first place, so chunk c's elements in output d follow
/// those of every chunk before it.
template <typename Count>
ChunkPlaces PlaceChunks(vtkIdType n, vtkIdType chunk, std::vector<std::size_t> start, Count&& count)
{
  ChunkPlaces places;
  places.Outputs = start.size();
  places.Places.assign(static_cast<std::size_t>(ChunksOf(n, chunk)) * places.Outputs, 0);
  ForEachChunk(n, chunk,
    [&](vtkIdType c, vtkIdType begin, vtkIdType end) { count(c, begin, end, &places.At(c, 0)); });
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
/// count per chunk on threads, then their sums in order); before has one entry per chunk and
/// one more, the total.
template <typename Counted>
std::vector<std::size_t> CountBefore(vtkIdType n, vtkIdType chunk, Counted&& counted)
{
  ChunkPlaces places = PlaceChunks(n, chunk, { 0 },
    [&](vtkIdType, vtkIdType begin, vtkIdType end, std::size_t* counts)
    {
      for (vtkIdType i = begin; i < end; ++i)
      {
        counts[0] += counted(i);
      }
    });
  places.Places.push_back(places.End[0]);
  return std::move(places.Places);
}

/// The kernels' parallel(count, task) (rgmc::RadixSort's, for one): task(i) for every i in
/// [0, count), one index a task, on vtkSMPTools' threads through ParallelFor.
struct Tasks
{
  template <typename Task>
  void operator()(std::int64_t count, Task&& task) const
  {
    ParallelFor(static_cast<vtkIdType>(count), 1,
      [&task](vtkIdType begin, vtkIdType end)
      {
        for (vtkIdType i = begin; i < end; ++i)
        {
          task(i);
        }
      });
  }
};

/// Sorts [begin, end) on threads: fixed slices (not one per thread) sorted at once, then merged
/// pairwise in rounds. The elements must be totally ordered (no two equal), so that the result
/// is the one std::sort gives, whatever the threads. Needs a buffer of the range's size.
template <typename Vector>
void ParallelSort(Vector& values)
{
  const std::size_t n = values.size();
  const std::size_t slice = std::max<std::size_t>(4096, (n + 63) / 64);
  // One thread: the merges would only add copies (the result is the same either way).
  if (n <= slice || SingleThreaded())
  {
    std::sort(values.begin(), values.end());
    return;
  }
  const vtkIdType slices = static_cast<vtkIdType>((n + slice - 1) / slice);
  ParallelFor(slices, 1,
    [&](vtkIdType first, vtkIdType last)
    {
      for (vtkIdType s = first; s < last; ++s)
      {
        const std::size_t a = static_cast<std::size_t>(s) * slice;
        std::sort(values.begin() + a, values.begin() + std::min(n, a + slice));
      }
    });
  Vector buffer(n);
  Vector* from = &values;
  Vector* to = &buffer;
  for (std::size_t run = slice; run < n; run *= 2)
  {
    const vtkIdType pairs = static_cast<vtkIdType>((n + 2 * run - 1) / (2 * run));
    ParallelFor(pairs, 1,
      [&](vtkIdType first, vtkIdType last)
      {
        for (vtkIdType p = first; p < last; ++p)
        {
          const std::size_t a = static_cast<std::size_t>(p) * 2 * run;
          const std::size_t b = std::min(n, a + run), c = std::min(n, a + 2 * run);
          std::merge(from->begin() + a, from->begin() + b, from->begin() + b, from->begin() + c,
            to->begin() + a);
        }
      });
    std::swap(from, to);
  }
  if (from != &values)
  {
    values.swap(buffer);
  }
}

} // namespace rgmc

#endif

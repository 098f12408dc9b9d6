// Threads within one rank for the plugin's VTK classes (private to the module): vtkSMPTools, so
// that ParaView's and VTK's settings govern them (VTK_SMP_BACKEND_IN_USE, VTK_SMP_MAX_THREADS),
// with an exception thrown on a worker thread (std::bad_alloc) carried back to the calling
// thread instead of terminating the process.
#ifndef vtkRGParallel_h
#define vtkRGParallel_h

#include "rgmcTasks.h"
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

/// rgmc::PlaceChunks (rgmcTasks.h) on vtkSMPTools' threads, one chunk a task.
template <typename Count>
ChunkPlaces PlaceChunks(vtkIdType n, vtkIdType chunk, std::vector<std::size_t> start, Count&& count)
{
  return PlaceChunks(n, chunk, std::move(start), count, Tasks());
}

/// rgmc::CountBefore (rgmcTasks.h) on vtkSMPTools' threads, one chunk a task.
template <typename Counted>
std::vector<std::size_t> CountBefore(vtkIdType n, vtkIdType chunk, Counted&& counted)
{
  return CountBefore(n, chunk, counted, Tasks());
}

/// How many of the first `d` elements std::merge takes from the sorted range `first` (of
/// `firstCount`) when merging it with the sorted range `second` (of `secondCount`): equal
/// elements come from `first` first. A merge path: a binary search over the d + 1 ways to split.
template <typename Iterator>
std::size_t MergedFromFirst(
  Iterator first, std::size_t firstCount, Iterator second, std::size_t secondCount, std::size_t d)
{
  std::size_t low = d > secondCount ? d - secondCount : 0, high = std::min(d, firstCount);
  while (low < high)
  {
    const std::size_t i = low + (high - low) / 2;
    // first[i] goes before second[d - i - 1] (ties to `first`): more than i from `first`.
    if (!(*(second + (d - i - 1)) < *(first + i)))
    {
      low = i + 1;
    }
    else
    {
      high = i;
    }
  }
  return low;
}

/// Sorts [begin, end) on threads: fixed slices (not one per thread) sorted at once, then merged
/// pairwise in rounds, each merge in pieces of a slice (MergedFromFirst). The elements must be
/// totally ordered (no two equal), so that the result is the one std::sort gives, whatever the
/// threads. Needs a buffer of the range's size.
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
    // Each pair of runs merged in pieces of `slice` outputs (merge paths), so that every round
    // has as many tasks as the first, not half as many as the round before.
    const std::size_t pieces = 2 * run / slice;
    const vtkIdType pairs = static_cast<vtkIdType>((n + 2 * run - 1) / (2 * run));
    ParallelFor(pairs * static_cast<vtkIdType>(pieces), 1,
      [&](vtkIdType first, vtkIdType last)
      {
        for (vtkIdType t = first; t < last; ++t)
        {
          const std::size_t a = static_cast<std::size_t>(t) / pieces * 2 * run;
          const std::size_t q = static_cast<std::size_t>(t) % pieces;
          const std::size_t b = std::min(n, a + run), c = std::min(n, a + 2 * run);
          const std::size_t d0 = std::min(c - a, q * slice), d1 = std::min(c - a, (q + 1) * slice);
          if (d0 < d1)
          {
            const auto in = from->begin();
            const std::size_t i0 = MergedFromFirst(in + a, b - a, in + b, c - b, d0);
            const std::size_t i1 = MergedFromFirst(in + a, b - a, in + b, c - b, d1);
            std::merge(in + a + i0, in + a + i1, in + b + (d0 - i0), in + b + (d1 - i1),
              to->begin() + a + d0);
          }
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

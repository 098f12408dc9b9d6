// Unit test of the work/span profile (vtkRGSpan.h) on a clock the test drives: rgmc::ParallelFor
// runs its grains in order, each once, each timed; a phase's work, span and predicted times are
// the sums the definitions give; a loop inside a task is part of the task; a mark inside a task,
// or with no recorder, does nothing; the prefix of a filter inside another; an exception leaves
// the recorder usable; ParallelSort takes its parallel path while recording, with std::sort's
// result; outside a recording, the loops run on vtkSMPTools as before; the chunked passes
// (ForEachChunk, CountBefore, PlaceChunks) give the serial results on any number of threads;
// runs combined task by task at their least times (LeastOver), and not when their steps differ;
// ParallelSort's merges in pieces (merge paths) with std::merge's result and order of ties.
#include "rgmcCheck.h"
#include "rgmcTaskOrders.h"
#include "vtkRGParallel.h"
#include "vtkRGSpan.h"

#include "vtkSMPTools.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace
{

bool Near(double a, double b)
{
  return std::abs(a - b) < 1e-9;
}

const rgmc::SpanPhase* Find(const rgmc::SpanRecorder& recorder, const std::string& name)
{
  for (const rgmc::SpanPhase& p : recorder.Phases())
  {
    if (p.Name == name)
    {
      return &p;
    }
  }
  return nullptr;
}

void TestAccounting()
{
  double now = 100;
  rgmc::SpanRecorder recorder([&now]() { return now; });
  RGMC_CHECK(!rgmc::SpanRecorder::Recording(), "no recorder before Start");
  recorder.Start("setup");
  RGMC_CHECK(rgmc::SpanRecorder::Recording() == &recorder, "recording after Start");
  now += 5; // a serial section
  // Grains of 3 over 10 indices, index i costing i + 1: grains cost 6, 15, 24 and 10.
  std::vector<std::pair<vtkIdType, vtkIdType>> ranges;
  std::vector<int> seen(10, 0);
  rgmc::ParallelFor(10, 3,
    [&](vtkIdType begin, vtkIdType end)
    {
      ranges.emplace_back(begin, end);
      rgmc::SpanMark("inside a task"); // ignored: the task is part of its phase
      for (vtkIdType i = begin; i < end; ++i)
      {
        ++seen[i];
        now += static_cast<double>(i + 1);
      }
    });
  const std::vector<std::pair<vtkIdType, vtkIdType>> grains = { { 0, 3 }, { 3, 6 }, { 6, 9 },
    { 9, 10 } };
  RGMC_CHECK(ranges == grains, "the grains, in order");
  RGMC_CHECK(
    std::all_of(seen.begin(), seen.end(), [](int n) { return n == 1; }), "every index once");
  rgmc::SpanMark("second");
  now += 2;
  // Four tasks, each a loop of three indices costing 1: the inner loops are the tasks' own.
  rgmc::ParallelFor(4, 1,
    [&](vtkIdType, vtkIdType)
    {
      RGMC_CHECK(!rgmc::SpanRecorder::Recording(), "no recording inside a task");
      rgmc::ParallelFor(3, 1, [&](vtkIdType b, vtkIdType e) { now += static_cast<double>(e - b); });
    });
  rgmc::SpanMark("setup"); // continued
  now += 1;
  recorder.Stop();
  RGMC_CHECK(!rgmc::SpanRecorder::Recording(), "no recording after Stop");
  rgmc::SpanMark("after the stop"); // no recorder: nothing

  RGMC_CHECK(recorder.Phases().size() == 2, recorder.Phases().size() << " phases, not 2");
  const rgmc::SpanPhase* setup = Find(recorder, "setup");
  const rgmc::SpanPhase* second = Find(recorder, "second");
  RGMC_CHECK(setup && second, "the phases by name");
  if (!setup || !second)
  {
    return;
  }
  RGMC_CHECK(Near(setup->Work, 61), "setup work " << setup->Work << ", not 5 + 55 + 1");
  RGMC_CHECK(Near(setup->ParallelWork, 55), "setup parallel work " << setup->ParallelWork);
  RGMC_CHECK(Near(setup->Span(), 30), "setup span " << setup->Span() << ", not 5 + 24 + 1");
  RGMC_CHECK(setup->Steps == 1 && setup->Tasks == 4, setup->Steps << " steps, " << setup->Tasks);
  RGMC_CHECK(Near(setup->Predicted(2), 30 + 31.0 / 2), "predicted " << setup->Predicted(2));
  RGMC_CHECK(Near(setup->Predicted(1), 61), "predicted on one thread: the work");
  RGMC_CHECK(Near(second->Work, 14), "second work " << second->Work << ", not 2 + 12");
  RGMC_CHECK(Near(second->Span(), 5), "second span " << second->Span() << ", not 2 + 3");
  RGMC_CHECK(second->Steps == 1 && second->Tasks == 4, "inner loops are not steps");
  const rgmc::SpanPhase total = recorder.Total("total");
  RGMC_CHECK(Near(total.Work, 75) && Near(total.Span(), 35),
    "total work " << total.Work << ", span " << total.Span());
}

void TestPrefixAndExceptions()
{
  double now = 0;
  rgmc::SpanRecorder recorder([&now]() { return now; });
  recorder.Start();
  {
    rgmc::SpanPrefix inner("numbering: ", "after");
    rgmc::SpanMark("sort");
    now += 3;
  }
  now += 1;
  bool thrown = false;
  try
  {
    rgmc::ParallelFor(5, 1,
      [&](vtkIdType begin, vtkIdType)
      {
        now += 1;
        if (begin == 2)
        {
          throw std::runtime_error("task 2");
        }
      });
  }
  catch (const std::runtime_error&)
  {
    thrown = true;
  }
  RGMC_CHECK(thrown, "a task's exception reaches the caller");
  RGMC_CHECK(rgmc::SpanRecorder::Recording() == &recorder, "recording again after the throw");
  rgmc::SpanMark("last");
  recorder.Stop();
  const rgmc::SpanPhase* sort = Find(recorder, "numbering: sort");
  const rgmc::SpanPhase* after = Find(recorder, "after");
  RGMC_CHECK(sort && Near(sort->Work, 3), "the prefixed phase");
  RGMC_CHECK(after && Near(after->Work, 4), "the phase after the prefix: 1 + three tasks");
  RGMC_CHECK(Find(recorder, "last") != nullptr, "a mark after the throw");

  rgmc::SpanRecorder first, second;
  first.Start();
  bool refused = false;
  try
  {
    second.Start();
  }
  catch (const std::logic_error&)
  {
    refused = true;
  }
  first.Stop();
  RGMC_CHECK(refused, "a second recorder at once is refused");
}

void TestSortAndThreads()
{
  std::mt19937_64 random(7);
  std::vector<std::uint64_t> values(100000);
  for (std::size_t i = 0; i < values.size(); ++i)
  {
    values[i] = (random() << 20) | i; // distinct
  }
  std::vector<std::uint64_t> expected = values;
  std::sort(expected.begin(), expected.end());
  vtkSMPTools::LocalScope(vtkSMPTools::Config{ 1, "STDThread", false },
    [&]()
    {
      RGMC_CHECK(rgmc::SingleThreaded(), "one thread, no recording");
      rgmc::SpanRecorder recorder;
      recorder.Start();
      RGMC_CHECK(!rgmc::SingleThreaded(), "recording takes the parallel paths");
      std::vector<std::uint64_t> sorted = values;
      rgmc::ParallelSort(sorted);
      recorder.Stop();
      RGMC_CHECK(sorted == expected, "ParallelSort while recording: std::sort's order");
      RGMC_CHECK(recorder.Total("").Steps > 1, "ParallelSort's slices and merges are steps");
    });
  // Outside a recording: vtkSMPTools on several threads, every index once.
  vtkSMPTools::LocalScope(vtkSMPTools::Config{ 4, "STDThread", false },
    [&]()
    {
      std::vector<int> seen(1000, 0);
      rgmc::ParallelFor(1000, 7,
        [&](vtkIdType b, vtkIdType e)
        {
          for (vtkIdType i = b; i < e; ++i)
          {
            ++seen[i];
          }
        });
      RGMC_CHECK(std::all_of(seen.begin(), seen.end(), [](int n) { return n == 1; }),
        "threads: every index once");
    });
}

/// CountBefore: chunk c's entry is the serial count of the indices before c * chunk, the last
/// the total, the same on 1, 2, 16 and 64 threads and while recording (chunks that end early,
/// a count that is not a multiple of the chunk, an empty range).
void TestCountBefore()
{
  std::mt19937_64 random(11);
  std::vector<std::uint8_t> flags(100003);
  for (auto& f : flags)
  {
    f = random() % 3 == 0;
  }
  auto counted = [&flags](vtkIdType i) { return flags[static_cast<std::size_t>(i)] != 0; };
  const vtkIdType n = static_cast<vtkIdType>(flags.size()), chunk = 4096;
  for (int threads : { 1, 2, 16, 64 })
  {
    vtkSMPTools::LocalScope(vtkSMPTools::Config{ threads, "STDThread", false },
      [&]()
      {
        const std::vector<std::size_t> before = rgmc::CountBefore(n, chunk, counted);
        RGMC_CHECK(before.size() == static_cast<std::size_t>((n + chunk - 1) / chunk) + 1,
          before.size() << " entries on " << threads << " threads");
        bool same = true;
        for (std::size_t c = 0; same && c < before.size(); ++c)
        {
          std::size_t serial = 0;
          for (vtkIdType i = 0; i < std::min(n, static_cast<vtkIdType>(c) * chunk); ++i)
          {
            serial += flags[static_cast<std::size_t>(i)];
          }
          same = before[c] == serial;
        }
        RGMC_CHECK(same, "CountBefore equals the serial counts on " << threads << " threads");
      });
  }
  rgmc::SpanRecorder recorder;
  recorder.Start();
  const std::vector<std::size_t> recorded = rgmc::CountBefore(n, chunk, counted);
  recorder.Stop();
  RGMC_CHECK(recorded.back() == static_cast<std::size_t>(std::count(flags.begin(), flags.end(), 1)),
    "CountBefore while recording: the total");
  const std::vector<std::size_t> none = rgmc::CountBefore(0, chunk, counted);
  RGMC_CHECK(none.size() == 1 && none[0] == 0, "no indices: one entry, 0");
}

/// PlaceChunks: outputs filled at the places it gives, each chunk's elements at At(c, d)
/// onwards, equal the serial appends in index order after each output's start (outputs that
/// start full, outputs nothing goes to), End the outputs' sizes; on 1, 2, 16 and 64 threads,
/// while recording, and the kernels' on tasks in reverse order; no elements: End the starts.
void TestPlaceChunks()
{
  std::mt19937_64 random(13);
  const std::size_t outputs = 7;
  std::vector<std::size_t> to(100003);
  for (auto& d : to)
  {
    d = random() % (outputs - 1); // the last output gets nothing
  }
  const std::vector<std::size_t> start = { 0, 5, 0, 0, 17, 0, 3 };
  std::vector<std::vector<vtkIdType>> serial(outputs);
  for (std::size_t d = 0; d < outputs; ++d)
  {
    serial[d].assign(start[d], -1);
  }
  for (std::size_t i = 0; i < to.size(); ++i)
  {
    serial[to[i]].push_back(static_cast<vtkIdType>(i));
  }
  const vtkIdType n = static_cast<vtkIdType>(to.size()), chunk = 4096;
  auto count = [&](vtkIdType, vtkIdType begin, vtkIdType end, std::size_t* counts)
  {
    for (vtkIdType i = begin; i < end; ++i)
    {
      ++counts[to[static_cast<std::size_t>(i)]];
    }
  };
  // The kernels' PlaceChunks on tasks run in reverse order, or vtkRGParallel's on threads.
  auto fill = [&](bool reversed = false)
  {
    rgmc::ChunkPlaces places = reversed
      ? rgmc::PlaceChunks(n, chunk, start, count, rgmc_test::TasksReversed)
      : rgmc::PlaceChunks(n, chunk, start, count);
    std::vector<std::vector<vtkIdType>> filled(outputs);
    for (std::size_t d = 0; d < outputs; ++d)
    {
      filled[d].assign(places.End[d], -1);
    }
    rgmc::ForEachChunk(n, chunk,
      [&](vtkIdType c, vtkIdType begin, vtkIdType end)
      {
        for (vtkIdType i = begin; i < end; ++i)
        {
          const std::size_t d = to[static_cast<std::size_t>(i)];
          filled[d][places.At(c, d)++] = i;
        }
      });
    return filled;
  };
  for (int threads : { 1, 2, 16, 64, 0, -1 })
  {
    std::vector<std::vector<vtkIdType>> filled;
    if (threads > 0)
    {
      vtkSMPTools::LocalScope(
        vtkSMPTools::Config{ threads, "STDThread", false }, [&]() { filled = fill(); });
    }
    else if (threads < 0)
    {
      filled = fill(true);
    }
    else
    {
      rgmc::SpanRecorder recorder;
      recorder.Start();
      filled = fill();
      recorder.Stop();
    }
    RGMC_CHECK(filled == serial,
      "PlaceChunks: the serial appends on " << threads
                                            << " threads (0: recording, -1: tasks reversed)");
  }
  const rgmc::ChunkPlaces none =
    rgmc::PlaceChunks(0, chunk, start, [](vtkIdType, vtkIdType, vtkIdType, std::size_t*) {});
  RGMC_CHECK(none.Places.empty() && none.End == start, "no elements: the outputs as they were");
}

/// ForEachChunk: every chunk once with c = begin / chunk, [begin, end) its own indices (the last
/// chunk short), every index in exactly one chunk, on 1, 2, 16 and 64 threads and while
/// recording; nothing for an empty range.
void TestForEachChunk()
{
  const vtkIdType n = 100003, chunk = 4096, chunks = rgmc::ChunksOf(n, chunk);
  RGMC_CHECK(chunks == 25 && rgmc::ChunksOf(0, chunk) == 0 && rgmc::ChunksOf(chunk, chunk) == 1,
    "ChunksOf rounds up: " << chunks);
  auto visit = [&](std::vector<std::atomic<int>>& seen, std::vector<std::atomic<int>>& calls)
  {
    rgmc::ForEachChunk(n, chunk,
      [&](vtkIdType c, vtkIdType begin, vtkIdType end)
      {
        const bool right =
          c >= 0 && c < chunks && begin == c * chunk && end == std::min(n, (c + 1) * chunk);
        calls[static_cast<std::size_t>(std::min(std::max(c, vtkIdType(0)), chunks - 1))] +=
          right ? 1 : 1000;
        for (vtkIdType i = begin; i < end; ++i)
        {
          ++seen[static_cast<std::size_t>(i)];
        }
      });
  };
  auto once = [](const std::vector<std::atomic<int>>& counts)
  {
    return std::all_of(
      counts.begin(), counts.end(), [](const std::atomic<int>& k) { return k == 1; });
  };
  for (int threads : { 1, 2, 16, 64, 0 })
  {
    std::vector<std::atomic<int>> seen(static_cast<std::size_t>(n));
    std::vector<std::atomic<int>> calls(static_cast<std::size_t>(chunks));
    if (threads > 0)
    {
      vtkSMPTools::LocalScope(
        vtkSMPTools::Config{ threads, "STDThread", false }, [&]() { visit(seen, calls); });
    }
    else
    {
      rgmc::SpanRecorder recorder;
      recorder.Start();
      visit(seen, calls);
      recorder.Stop();
    }
    RGMC_CHECK(
      once(calls), "each chunk once, with its bounds, on " << threads << " threads (0: recording)");
    RGMC_CHECK(once(seen), "each index once on " << threads << " threads (0: recording)");
  }
  int empty = 0;
  rgmc::ForEachChunk(0, chunk, [&](vtkIdType, vtkIdType, vtkIdType) { ++empty; });
  RGMC_CHECK(empty == 0, "no indices: no chunk");
}

} // namespace

/// One run of a stage on the test's clock: a serial section of `serial`, then a step of tasks
/// costing `tasks` (in order), then a second phase with one serial section of 1 and, when
/// `second` is positive, a step of `second` tasks of cost 1.
std::vector<rgmc::SpanPhase> Run(double serial, const std::vector<double>& tasks, int second = 0)
{
  double now = 0;
  rgmc::SpanRecorder recorder([&now]() { return now; });
  recorder.Start("first");
  now += serial;
  rgmc::ParallelFor(static_cast<vtkIdType>(tasks.size()), 1,
    [&](vtkIdType begin, vtkIdType) { now += tasks[static_cast<std::size_t>(begin)]; });
  rgmc::SpanMark("second");
  now += 1;
  if (second > 0)
  {
    rgmc::ParallelFor(second, 1, [&](vtkIdType, vtkIdType) { now += 1; });
  }
  recorder.Stop();
  return recorder.Phases();
}

void TestLeastOver()
{
  // Each run interrupted once (a task's time doubled, a serial section lengthened): the least
  // over the runs is the uninterrupted run, though no run was.
  const std::vector<std::vector<rgmc::SpanPhase>> runs = { Run(2, { 3, 8, 2 }), Run(5, { 6, 4, 2 }),
    Run(2, { 3, 4, 4 }) };
  std::vector<rgmc::SpanPhase> least;
  RGMC_CHECK(rgmc::LeastOver(runs, least), "the same steps in every run");
  RGMC_CHECK(least.size() == 2 && least[0].Name == "first" && least[1].Name == "second",
    "the phases, in order");
  const rgmc::SpanPhase& first = least[0];
  RGMC_CHECK(first.TaskTimes.size() == 1 && first.TaskTimes[0] == std::vector<double>({ 3, 4, 2 }),
    "each task at its least time");
  RGMC_CHECK(Near(first.Work, 2 + 9) && Near(first.ParallelWork, 9) &&
      Near(first.LongestTasks, 4) && Near(first.Span(), 6),
    "work 11, span 6 from the least serial section and tasks");
  for (const std::vector<rgmc::SpanPhase>& run : runs)
  {
    RGMC_CHECK(run[0].Work > first.Work + 1, "every run took longer");
  }
  RGMC_CHECK(Near(least[1].Work, 1) && Near(least[1].Span(), 1), "a serial phase");
  RGMC_CHECK(first.Steps == 1 && first.Tasks == 3, "steps and tasks kept");

  // Runs that took different steps are not combined: the run of least work is returned.
  const std::vector<std::vector<rgmc::SpanPhase>> differing = { Run(2, { 3, 8, 2 }),
    Run(2, { 1, 1 }), Run(2, { 3, 4, 4 }, 2) };
  RGMC_CHECK(!rgmc::LeastOver(differing, least), "different tasks are found");
  RGMC_CHECK(least.size() == 2 && Near(least[0].Work, 4) && Near(least[0].Span(), 3),
    "the run of least work");
  RGMC_CHECK(rgmc::LeastOver({}, least) && least.empty(), "no runs, no phases");
}

/// A key with a tag that the order ignores: equal keys tell which range an element came from.
struct Tagged
{
  int Key;
  int Tag;
  bool operator<(const Tagged& other) const { return this->Key < other.Key; }
  bool operator==(const Tagged& other) const
  {
    return this->Key == other.Key && this->Tag == other.Tag;
  }
};

/// ParallelSort's merges in pieces: split at any output position by MergedFromFirst, the two
/// pieces' merges are the whole merge, ties taken from the first range first (std::merge's
/// rule); ParallelSort on 1, 2, 16 and 64 threads and while recording gives std::sort's order
/// for sizes whose last runs are short, and every merge round has as many tasks as the first.
void TestMergePaths()
{
  std::mt19937 random(11);
  for (int trial = 0; trial < 200; ++trial)
  {
    std::vector<Tagged> first(random() % 12), second(random() % 12);
    for (std::size_t i = 0; i < first.size(); ++i)
    {
      first[i] = Tagged{ static_cast<int>(random() % 6), static_cast<int>(i) };
    }
    for (std::size_t i = 0; i < second.size(); ++i)
    {
      second[i] = Tagged{ static_cast<int>(random() % 6), 100 + static_cast<int>(i) };
    }
    // Sorted by key, equal keys in the order of their tags (as a stable sort by key leaves them).
    auto byKeyThenTag = [](const Tagged& a, const Tagged& b)
    { return a.Key < b.Key || (a.Key == b.Key && a.Tag < b.Tag); };
    std::sort(first.begin(), first.end(), byKeyThenTag);
    std::sort(second.begin(), second.end(), byKeyThenTag);
    std::vector<Tagged> whole(first.size() + second.size());
    std::merge(first.begin(), first.end(), second.begin(), second.end(), whole.begin());
    for (std::size_t d = 0; d <= whole.size(); ++d)
    {
      const std::size_t i =
        rgmc::MergedFromFirst(first.begin(), first.size(), second.begin(), second.size(), d);
      std::vector<Tagged> pieces(whole.size());
      std::merge(
        first.begin(), first.begin() + i, second.begin(), second.begin() + (d - i), pieces.begin());
      std::merge(
        first.begin() + i, first.end(), second.begin() + (d - i), second.end(), pieces.begin() + d);
      RGMC_CHECK(pieces == whole, "two pieces merged are the whole merge, ties first-first");
    }
  }
  for (std::size_t n : { std::size_t(4096 * 5 + 17), std::size_t(4096 * 64 + 4095) })
  {
    std::vector<std::uint64_t> values(n);
    for (std::size_t i = 0; i < n; ++i)
    {
      values[i] = (random() * 1000003ULL << 20) | i;
    }
    std::vector<std::uint64_t> expected = values;
    std::sort(expected.begin(), expected.end());
    for (int threads : { 1, 2, 16, 64 })
    {
      vtkSMPTools::LocalScope(vtkSMPTools::Config{ threads, "STDThread", false },
        [&]()
        {
          std::vector<std::uint64_t> sorted = values;
          rgmc::ParallelSort(sorted);
          RGMC_CHECK(sorted == expected, "ParallelSort on threads: std::sort's order");
        });
    }
    rgmc::SpanRecorder recorder;
    recorder.Start("sort");
    std::vector<std::uint64_t> sorted = values;
    rgmc::ParallelSort(sorted);
    recorder.Stop();
    RGMC_CHECK(sorted == expected, "ParallelSort while recording: std::sort's order");
    const std::vector<std::vector<double>>& steps = recorder.Phases()[0].TaskTimes;
    RGMC_CHECK(steps.size() > 1, "slices and merge rounds");
    for (std::size_t r = 1; r < steps.size(); ++r)
    {
      RGMC_CHECK(steps[r].size() >= steps[0].size(), "every merge round as many tasks as slices");
    }
  }
}

int main()
{
  TestAccounting();
  TestPrefixAndExceptions();
  TestSortAndThreads();
  TestCountBefore();
  TestPlaceChunks();
  TestForEachChunk();
  TestLeastOver();
  TestMergePaths();
  return rgmc_test::Result("TestSpanProfile");
}

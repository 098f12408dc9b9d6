// The work/span profile (./rgmc evaluate --span; never in a filter's normal run): while a
// SpanRecorder records, every rgmc::ParallelFor runs its tasks one after the other on the
// calling thread, each task (a grain of indices) timed, and the filters name their phases with
// rgmc::SpanMark. Per phase that gives the work W (its wall time), the parallel work, and the
// span S: the time outside parallel steps plus, for each step, its longest task. On p threads
// the phase takes about S + (W - S) / p (Brent's bound with perfect balance beyond the span).
//
// One recorder at a time, on the thread that runs the filter; a ParallelFor inside a task runs
// as part of that task. Parallel paths that a filter takes only when several threads run are
// taken while recording (rgmc::SingleThreaded), so the profile is that of the threaded run.
#ifndef vtkRGSpan_h
#define vtkRGSpan_h

#include "vtkType.h"

#include <algorithm>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace rgmc
{

/// One phase of a stage, as the recorder saw it (seconds).
struct SpanPhase
{
  std::string Name;
  double Work = 0;         // wall time of the phase, on one thread
  double ParallelWork = 0; // the sum of every parallel step's tasks
  double LongestTasks = 0; // the sum over parallel steps of each step's longest task
  long long Steps = 0;     // parallel steps (ParallelFor calls)
  long long Tasks = 0;     // tasks in those steps
  std::vector<std::vector<double>> TaskTimes; // each step's tasks, in order

  /// The serial sections plus each parallel step's longest task.
  double Span() const { return this->Work - this->ParallelWork + this->LongestTasks; }
  /// Predicted time on `threads` threads: S + (W - S) / p.
  double Predicted(int threads) const
  {
    return this->Span() + (this->Work - this->Span()) / std::max(1, threads);
  }
};

/// The phases as one phase: their sums (steps and tasks counted, task times not kept).
SpanPhase TotalOf(const std::vector<SpanPhase>& phases, const std::string& name);

/// Records one stage's phases. Start makes it the one recorder, Stop ends the last phase.
class SpanRecorder
{
public:
  /// `clock` returns seconds; the default is a steady clock (a test passes its own).
  explicit SpanRecorder(std::function<double()> clock = {});
  ~SpanRecorder();
  SpanRecorder(const SpanRecorder&) = delete;
  SpanRecorder& operator=(const SpanRecorder&) = delete;

  /// Starts recording, in a first phase named `first` (what runs before any mark).
  void Start(const std::string& first = "pipeline");
  /// Ends the current phase and stops recording.
  void Stop();
  /// Ends the current phase and opens `name` (a phase of that name already seen is continued),
  /// after the prefix of a SpanPrefix in force.
  void Mark(const std::string& name);
  /// What Mark puts before a name (SpanPrefix sets it).
  std::string Prefix;

  const std::vector<SpanPhase>& Phases() const { return this->Recorded; }
  /// The stage as one phase: the phases' sums.
  SpanPhase Total(const std::string& name) const;

  /// Runs body(begin, end) over [0, count) in grains of `grain`, in order, timing each.
  template <typename Body>
  void Step(vtkIdType count, vtkIdType grain, Body& body)
  {
    grain = std::max<vtkIdType>(1, grain);
    double total = 0, longest = 0;
    long long tasks = 0;
    std::vector<double> times;
    times.reserve(static_cast<std::size_t>((count + grain - 1) / grain));
    struct InTask
    {
      bool& Flag;
      explicit InTask(bool& flag)
        : Flag(flag)
      {
        this->Flag = true;
      }
      ~InTask() { this->Flag = false; }
    } inTask(this->Running);
    for (vtkIdType begin = 0; begin < count; begin += grain)
    {
      const double start = this->Clock();
      body(begin, std::min(count, begin + grain));
      const double took = this->Clock() - start;
      total += took;
      longest = std::max(longest, took);
      times.push_back(took);
      ++tasks;
    }
    SpanPhase& phase = this->Recorded[this->Current];
    phase.ParallelWork += total;
    phase.LongestTasks += longest;
    phase.Steps += 1;
    phase.Tasks += tasks;
    phase.TaskTimes.push_back(std::move(times));
  }

  /// The recorder recording now, outside any task; null otherwise (a filter's normal run).
  static SpanRecorder* Recording();

private:
  void EndPhase();

  std::function<double()> Clock;
  std::vector<SpanPhase> Recorded;
  std::size_t Current = 0;
  double PhaseStart = 0;
  bool Running = false; // inside a task: nested parallel loops are part of it
  bool Started = false;
};

/// The phases of several recorded runs of one stage, each serial section (a phase's time outside
/// its steps) and each task at its least time over the runs: the run without the machine's
/// interruptions, which land in one run's task and not in another's. A single interruption of a
/// task would otherwise count whole in its step's longest task. The runs must have taken the
/// same steps with the same tasks (a deterministic stage); false, with `least` the run of least
/// work, when they did not.
bool LeastOver(const std::vector<std::vector<SpanPhase>>& runs, std::vector<SpanPhase>& least);

/// Names the phase that starts here, when a recorder records; nothing otherwise.
inline void SpanMark(const char* name)
{
  if (SpanRecorder* recorder = SpanRecorder::Recording())
  {
    recorder->Mark(name);
  }
}

/// Marks the phases of a filter run inside another (Decimate's Seam Repair) with `prefix`,
/// for as long as it lives; at its end the phase `after` (of the outer filter) starts.
class SpanPrefix
{
public:
  SpanPrefix(const char* prefix, const char* after)
    : After(after)
  {
    if (SpanRecorder* recorder = SpanRecorder::Recording())
    {
      this->Outer = recorder->Prefix;
      recorder->Prefix += prefix;
    }
  }
  ~SpanPrefix()
  {
    if (SpanRecorder* recorder = SpanRecorder::Recording())
    {
      recorder->Prefix = this->Outer;
      recorder->Mark(this->After);
    }
  }
  SpanPrefix(const SpanPrefix&) = delete;
  SpanPrefix& operator=(const SpanPrefix&) = delete;

private:
  std::string Outer;
  const char* After;
};

} // namespace rgmc

#endif

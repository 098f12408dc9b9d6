// The work/span profile's recorder (see vtkRGSpan.h).
#include "vtkRGSpan.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>

namespace rgmc
{

namespace
{

SpanRecorder* TheRecorder = nullptr;

double SteadySeconds()
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

} // namespace

SpanRecorder::SpanRecorder(std::function<double()> clock)
  : Clock(clock ? std::move(clock) : std::function<double()>(SteadySeconds))
{
}

SpanRecorder::~SpanRecorder()
{
  if (TheRecorder == this)
  {
    TheRecorder = nullptr;
  }
}

SpanRecorder* SpanRecorder::Recording()
{
  return TheRecorder && !TheRecorder->Running ? TheRecorder : nullptr;
}

void SpanRecorder::Start(const std::string& first)
{
  if (TheRecorder && TheRecorder != this)
  {
    throw std::logic_error("a work/span recorder is recording already");
  }
  TheRecorder = this;
  this->Started = true;
  this->Recorded.clear();
  this->Prefix.clear();
  this->Recorded.push_back(SpanPhase{ first });
  this->Current = 0;
  this->PhaseStart = this->Clock();
}

void SpanRecorder::EndPhase()
{
  const double now = this->Clock();
  this->Recorded[this->Current].Work += now - this->PhaseStart;
  this->PhaseStart = now;
}

void SpanRecorder::Mark(const std::string& name)
{
  if (!this->Started)
  {
    return;
  }
  this->EndPhase();
  const std::string full = this->Prefix + name;
  for (std::size_t p = 0; p < this->Recorded.size(); ++p)
  {
    if (this->Recorded[p].Name == full)
    {
      this->Current = p;
      return;
    }
  }
  this->Recorded.push_back(SpanPhase{ full });
  this->Current = this->Recorded.size() - 1;
}

void SpanRecorder::Stop()
{
  if (!this->Started)
  {
    return;
  }
  this->EndPhase();
  this->Started = false;
  if (TheRecorder == this)
  {
    TheRecorder = nullptr;
  }
}

SpanPhase TotalOf(const std::vector<SpanPhase>& phases, const std::string& name)
{
  SpanPhase total{ name };
  for (const SpanPhase& phase : phases)
  {
    total.Work += phase.Work;
    total.ParallelWork += phase.ParallelWork;
    total.LongestTasks += phase.LongestTasks;
    total.Steps += phase.Steps;
    total.Tasks += phase.Tasks;
  }
  return total;
}

SpanPhase SpanRecorder::Total(const std::string& name) const
{
  return TotalOf(this->Recorded, name);
}

namespace
{

bool SameSteps(const std::vector<SpanPhase>& a, const std::vector<SpanPhase>& b)
{
  if (a.size() != b.size())
  {
    return false;
  }
  for (std::size_t p = 0; p < a.size(); ++p)
  {
    if (a[p].Name != b[p].Name || a[p].TaskTimes.size() != b[p].TaskTimes.size())
    {
      return false;
    }
    for (std::size_t s = 0; s < a[p].TaskTimes.size(); ++s)
    {
      if (a[p].TaskTimes[s].size() != b[p].TaskTimes[s].size())
      {
        return false;
      }
    }
  }
  return true;
}

} // namespace

bool LeastOver(const std::vector<std::vector<SpanPhase>>& runs, std::vector<SpanPhase>& least)
{
  least.clear();
  if (runs.empty())
  {
    return true;
  }
  for (const std::vector<SpanPhase>& run : runs)
  {
    if (!SameSteps(run, runs[0]))
    {
      least = *std::min_element(runs.begin(), runs.end(),
        [](const std::vector<SpanPhase>& a, const std::vector<SpanPhase>& b)
        { return TotalOf(a, "").Work < TotalOf(b, "").Work; });
      return false;
    }
  }
  least = runs[0];
  for (std::size_t p = 0; p < least.size(); ++p)
  {
    SpanPhase& phase = least[p];
    double serial = phase.Work - phase.ParallelWork;
    for (const std::vector<SpanPhase>& run : runs)
    {
      const SpanPhase& other = run[p];
      serial = std::min(serial, other.Work - other.ParallelWork);
      for (std::size_t s = 0; s < phase.TaskTimes.size(); ++s)
      {
        for (std::size_t t = 0; t < phase.TaskTimes[s].size(); ++t)
        {
          phase.TaskTimes[s][t] = std::min(phase.TaskTimes[s][t], other.TaskTimes[s][t]);
        }
      }
    }
    phase.ParallelWork = 0;
    phase.LongestTasks = 0;
    for (const std::vector<double>& step : phase.TaskTimes)
    {
      double longest = 0;
      for (double took : step)
      {
        phase.ParallelWork += took;
        longest = std::max(longest, took);
      }
      phase.LongestTasks += longest;
    }
    phase.Work = serial + phase.ParallelWork;
  }
  return true;
}

} // namespace rgmc

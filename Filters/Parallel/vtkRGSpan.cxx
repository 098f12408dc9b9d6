// The work/span profile's recorder (see vtkRGSpan.h).
#include "vtkRGSpan.h"

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

SpanPhase SpanRecorder::Total(const std::string& name) const
{
  SpanPhase total{ name };
  for (const SpanPhase& phase : this->Recorded)
  {
    total.Work += phase.Work;
    total.ParallelWork += phase.ParallelWork;
    total.LongestTasks += phase.LongestTasks;
    total.Steps += phase.Steps;
    total.Tasks += phase.Tasks;
  }
  return total;
}

} // namespace rgmc

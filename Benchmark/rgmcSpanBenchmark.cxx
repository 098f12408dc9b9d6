// The work/span benchmark (./rgmc evaluate --span; not a test): how the filters would scale on a
// machine with more cores than this one. Each stage runs on one thread under a
// rgmc::SpanRecorder, which times every serial section and every parallel task (vtkRGSpan.h):
// per stage and phase, the work W, the span S, the parallelism W / S and the predicted time on p
// threads, S + (W - S) / p, each serial section and task at its least time over the repeats
// (rgmc::LeastOver: an interruption of this machine lands in one run's task, not in every run's),
// with the run of least work as measured beside it. Beside them, the stage measured on 1 and 2
// threads (minimum of the repeats, re-run in one process as the GUI's slider does), the minor page
// faults of those runs with this machine's cost of one (what the model leaves out), and
// vtkFlyingEdges3D on 1 and 2 threads. Stages: Seeded, Largest and All on the CT phantom (skull), a
// noisy CT-like head and a dense gyroid; Seam Repair + 20 Laplacian and Decimate Surface (to 10%)
// on the phantom's skull. JSON on stdout, a summary on stderr.
//
//   rgmcSpanBenchmark [--size 512] [--ct-size 384] [--dense-size 256] [--repeats 5]
//                     [--decimate-repeats 3] [--only extraction|repair|decimate]
#include "rgmcBenchmark.h"
#include "rgmcBenchmarkVolumes.h"

#include "vtkDummyController.h"
#include "vtkFlyingEdges3D.h"
#include "vtkLogger.h"
#include "vtkPolyData.h"
#include "vtkRGDecimate.h"
#include "vtkRGMarchingCubes.h"
#include "vtkRGSeamRepair.h"
#include "vtkRGSpan.h"
#include "vtkSMPTools.h"

#include <sys/resource.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace
{

using rgmc_benchmark::Now;
using rgmc_benchmark::Volume;

long long MinorFaults()
{
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<long long>(usage.ru_minflt);
}

/// Seconds one minor page fault costs here: fresh memory touched once, over the faults it took.
double FaultCost()
{
  const std::size_t bytes = std::size_t(256) << 20;
  double best = 1e300;
  for (int r = 0; r < 3; ++r)
  {
    std::unique_ptr<unsigned char[]> fresh(new unsigned char[bytes]);
    const long long before = MinorFaults();
    const double start = Now();
    for (std::size_t b = 0; b < bytes; b += 4096)
    {
      fresh[b] = static_cast<unsigned char>(b);
    }
    const double took = Now() - start;
    const long long faults = MinorFaults() - before;
    if (faults > 0)
    {
      best = std::min(best, took / static_cast<double>(faults));
    }
  }
  return best < 1e300 ? best : 0.0;
}

/// A measured time: the minimum of the repeats on `threads` threads, and the minor page
/// faults of that run.
struct Timed
{
  double Seconds = 1e300;
  long long Faults = 0;
};

template <typename Algorithm>
Timed Measure(Algorithm* algorithm, int threads, int repeats)
{
  Timed best;
  vtkSMPTools::LocalScope(vtkSMPTools::Config{ threads, "STDThread", false },
    [&]()
    {
      for (int r = 0; r < repeats; ++r)
      {
        algorithm->Modified();
        const long long faults = MinorFaults();
        const double start = Now();
        algorithm->Update();
        const double took = Now() - start;
        if (took < best.Seconds)
        {
          best.Seconds = took;
          best.Faults = MinorFaults() - faults;
        }
      }
    });
  return best;
}

/// The stage's phases on one thread under a recorder, each serial section and task at its least
/// time over the repeats (rgmc::LeastOver), and their sum (`total`); `fastest` gets the sum of
/// the run of least work, as one run measured it (its span holds the machine's interruptions).
/// `matched` is false when the runs took different steps (then the phases are that run's).
template <typename Algorithm>
std::vector<rgmc::SpanPhase> Profile(Algorithm* algorithm, int repeats, rgmc::SpanPhase& total,
  rgmc::SpanPhase& fastest, bool& matched)
{
  std::vector<std::vector<rgmc::SpanPhase>> runs;
  fastest.Work = 1e300;
  vtkSMPTools::LocalScope(vtkSMPTools::Config{ 1, "STDThread", false },
    [&]()
    {
      for (int r = 0; r < repeats; ++r)
      {
        rgmc::SpanRecorder recorder;
        algorithm->Modified();
        recorder.Start();
        algorithm->Update();
        recorder.Stop();
        const rgmc::SpanPhase sum = recorder.Total("total");
        if (sum.Work < fastest.Work)
        {
          fastest = sum;
        }
        runs.push_back(recorder.Phases());
      }
    });
  std::vector<rgmc::SpanPhase> least;
  matched = rgmc::LeastOver(runs, least);
  total = rgmc::TotalOf(least, "total");
  return least;
}

void PhaseJson(std::ostream& os, const rgmc::SpanPhase& p)
{
  os << "{\"name\": \"" << p.Name << "\", \"work\": " << p.Work << ", \"span\": " << p.Span()
     << ", \"parallel_work\": " << p.ParallelWork << ", \"steps\": " << p.Steps
     << ", \"tasks\": " << p.Tasks << ", \"steps_longest\": [";
  for (std::size_t s = 0; s < p.TaskTimes.size(); ++s)
  {
    const std::vector<double>& step = p.TaskTimes[s];
    os << (s ? ", " : "") << "[" << step.size() << ", "
       << (step.empty() ? 0.0 : *std::max_element(step.begin(), step.end())) << "]";
  }
  os << "]}";
}

/// One stage's record: the profile, the measured times and Flying Edges' beside them.
template <typename Algorithm>
std::string Stage(const std::string& volume, const std::string& stage, Algorithm* algorithm,
  int repeats, const Timed* flying)
{
  const Timed one = Measure(algorithm, 1, repeats);
  const Timed two = Measure(algorithm, 2, repeats);
  const long long triangles = algorithm->GetOutput()->GetNumberOfCells();
  rgmc::SpanPhase total, fastest;
  bool matched = false;
  const std::vector<rgmc::SpanPhase> phases = Profile(algorithm, repeats, total, fastest, matched);
  std::ostringstream os;
  os << "{\"volume\": \"" << volume << "\", \"stage\": \"" << stage
     << "\", \"triangles\": " << triangles << ", \"work\": " << total.Work
     << ", \"span\": " << total.Span() << ", \"parallelism\": " << total.Work / total.Span()
     << ", \"least_per_task\": " << (matched ? "true" : "false")
     << ", \"fastest_run\": {\"work\": " << fastest.Work << ", \"span\": " << fastest.Span()
     << "}, \"predicted\": {";
  const int threads[] = { 1, 2, 4, 16, 64 };
  for (int t = 0; t < 5; ++t)
  {
    os << (t ? ", " : "") << "\"" << threads[t] << "\": " << total.Predicted(threads[t]);
  }
  os << "}, \"measured\": {\"1\": " << one.Seconds << ", \"2\": " << two.Seconds
     << "}, \"minor_faults\": {\"1\": " << one.Faults << ", \"2\": " << two.Faults << "}";
  if (flying)
  {
    os << ", \"flying_edges\": {\"1\": " << flying[0].Seconds << ", \"2\": " << flying[1].Seconds
       << "}";
  }
  os << ", \"phases\": [";
  for (std::size_t p = 0; p < phases.size(); ++p)
  {
    os << (p ? ", " : "");
    PhaseJson(os, phases[p]);
  }
  os << "]}";
  std::cerr << volume << ", " << stage << ": W " << total.Work << " s, S " << total.Span()
            << " s, W/S " << total.Work / total.Span() << " (fastest run: W " << fastest.Work
            << " s, S " << fastest.Span() << " s); T(2) predicted " << total.Predicted(2)
            << " s, measured " << two.Seconds << " s (1 thread " << one.Seconds << " s)\n";
  return os.str();
}

std::string Only(int argc, char* argv[])
{
  for (int a = 1; a + 1 < argc; a += 2)
  {
    if (std::strcmp(argv[a], "--only") == 0)
    {
      return argv[a + 1];
    }
  }
  return "";
}

int Option(int argc, char* argv[], const char* name, int value)
{
  for (int a = 1; a + 1 < argc; a += 2)
  {
    if (std::strcmp(argv[a], name) == 0)
    {
      return std::atoi(argv[a + 1]);
    }
  }
  return value;
}

} // namespace

int main(int argc, char* argv[])
{
  const char* known[] = { "--size", "--ct-size", "--dense-size", "--repeats", "--decimate-repeats",
    "--only" };
  for (int a = 1; a < argc; a += 2)
  {
    bool ok = a + 1 < argc;
    bool named = false;
    for (const char* k : known)
    {
      named = named || std::strcmp(argv[a], k) == 0;
    }
    if (!ok || !named)
    {
      std::cerr << "usage: rgmcSpanBenchmark [--size 512] [--ct-size 384] [--dense-size 256] "
                   "[--repeats 5] [--decimate-repeats 3]\n"
                   "                         [--only extraction|repair|decimate]\n";
      return 2;
    }
  }
  const int size = Option(argc, argv, "--size", 512);
  const int ctSize = Option(argc, argv, "--ct-size", 384);
  const int denseSize = Option(argc, argv, "--dense-size", 256);
  const int repeats = Option(argc, argv, "--repeats", 5);
  const int decimateRepeats = Option(argc, argv, "--decimate-repeats", 3);
  const std::string only = Only(argc, argv);
  vtkNew<vtkDummyController> single;
  vtkMultiProcessController::SetGlobalController(single);
  vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_WARNING); // not Seam Repair's summaries

  std::vector<std::string> stages;
  std::vector<Volume> volumes;
  volumes.push_back(rgmc_benchmark::Phantom(size));
  if (ctSize > 0)
  {
    volumes.push_back(rgmc_benchmark::NoisyHead(ctSize));
  }
  if (denseSize > 0)
  {
    volumes.push_back(rgmc_benchmark::Gyroid(denseSize, 16.0));
  }
  vtkSmartPointer<vtkPolyData> skull;
  for (std::size_t n = 0; n < volumes.size(); ++n)
  {
    const Volume& v = volumes[n];
    vtkNew<vtkFlyingEdges3D> flyingEdges;
    flyingEdges->SetInputData(v.Image);
    flyingEdges->SetValue(0, v.Isovalue);
    flyingEdges->ComputeNormalsOn();
    flyingEdges->ComputeScalarsOff();
    const bool extraction = only.empty() || only == "extraction";
    const Timed flying[2] = { extraction ? Measure(flyingEdges.Get(), 1, repeats) : Timed(),
      extraction ? Measure(flyingEdges.Get(), 2, repeats) : Timed() };
    vtkNew<vtkRGMarchingCubes> extract;
    extract->SetInputData(v.Image);
    extract->SetIsovalue(v.Isovalue);
    extract->AddSeedPoint(v.Seed[0], v.Seed[1], v.Seed[2]);
    const std::pair<int, const char*> modes[] = { { vtkRGMarchingCubes::SEEDED, "seeded" },
      { vtkRGMarchingCubes::LARGEST_COMPONENT, "largest" },
      { vtkRGMarchingCubes::ALL_COMPONENTS, "all components" } };
    for (const auto& mode : modes)
    {
      extract->SetExtractionMode(mode.first);
      if (extraction)
      {
        stages.push_back(Stage(v.Name, mode.second, extract.Get(), repeats, flying));
      }
      else
      {
        extract->Update();
      }
      if (n == 0 && mode.first == vtkRGMarchingCubes::SEEDED)
      {
        skull = vtkSmartPointer<vtkPolyData>::New();
        skull->DeepCopy(extract->GetOutput());
      }
    }
  }

  vtkNew<vtkRGSeamRepair> repair;
  repair->SetInputData(skull);
  repair->SetSmoothingMethod(vtkRGSeamRepair::LAPLACIAN);
  repair->SetNumberOfIterations(20);
  repair->SetRelaxationFactor(0.01);
  if (only.empty() || only == "repair")
  {
    stages.push_back(
      Stage(volumes[0].Name, "Seam Repair + 20 Laplacian", repair.Get(), repeats, nullptr));
  }
  // Decimate Surface as its benchmark runs it: the skull after Seam Repair's defaults, to 10%.
  vtkNew<vtkRGSeamRepair> defaults;
  defaults->SetInputData(skull);
  defaults->Update();
  vtkNew<vtkRGDecimate> decimate;
  decimate->SetInputConnection(defaults->GetOutputPort());
  decimate->SetTargetReduction(0.9);
  if (only.empty() || only == "decimate")
  {
    stages.push_back(
      Stage(volumes[0].Name, "Decimate Surface to 10%", decimate.Get(), decimateRepeats, nullptr));
  }

  std::cout << "{\n  \"repeats\": " << repeats << ",\n  \"decimate_repeats\": " << decimateRepeats
            << ",\n  \"fault_seconds\": " << FaultCost() << ",\n  \"stages\": [";
  for (std::size_t s = 0; s < stages.size(); ++s)
  {
    std::cout << (s ? "," : "") << "\n    " << stages[s];
  }
  std::cout << "\n  ]\n}\n";
  return 0;
}

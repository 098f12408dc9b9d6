// RGMC's scale benchmark (not a test; `./rgmc evaluate --scale` runs it): one large surface
// through the whole job, extract -> seam repair -> Laplacian smoothing [-> decimation] -> STL and
// PLY, with the seconds of each stage and the peak memory of each rank.
//
//   mpiexec -n 2 rgmcScale --size 512 --period 24 --iterations 5 --output /var/tmp/rgmc-scale
//                          [--decimate 0.9]
//
// The volume is a gyroid, sin x cos y + sin y cos z + sin z cos x = 0 with `period` voxels per
// cell: one connected surface through the whole volume, crossing every partition plane many
// times, the hardest case for the seams. Each rank computes only its piece (with one ghost layer,
// as ParaView gives it to vtkRGMarchingCubes), so the volume is never whole on one rank.
//
// A stage's time is the slowest rank's (barrier, stage, reduce max). Seam Repair's numbering and
// checks are told apart from its smoothing by its progress (it reports 0.4 when the smoothing
// starts). Peak memory is each rank's resident-set high-water mark (VmHWM), read after each
// stage; the stage's figure is the largest over ranks. Prints one JSON object per line on rank 0.
#include "rgmcBenchmark.h"       // Now, StatusMiB
#include "rgmcDistributedData.h" // GyroidPiece
#include "vtkRGDecimate.h"
#include "vtkRGMarchingCubes.h"
#include "vtkRGMergedSurfaceWriter.h"
#include "vtkRGSeamRepair.h"

#include "vtkCallbackCommand.h"
#include "vtkImageData.h"
#include "vtkMPIController.h"
#include "vtkNew.h"
#include "vtkPolyData.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

namespace
{

using rgmc_benchmark::Now;
using rgmc_benchmark::StatusMiB;

struct Options
{
  int Size = 512;
  double Period = 24;
  int Iterations = 5;
  double Decimate = 0; // the fraction of the triangles to remove, 0: no decimation
  std::string Output = "/var/tmp/rgmc-scale";
  bool Keep = false;
};

/// What rank 0 prints: the stage, its seconds, and each rank's peak memory after it.
void Report(vtkMultiProcessController* c, const char* stage, double seconds, long long triangles)
{
  const int ranks = c->GetNumberOfProcesses();
  double slowest = 0;
  c->AllReduce(&seconds, &slowest, 1, vtkCommunicator::MAX_OP);
  double peak = StatusMiB("VmHWM:");
  std::vector<double> peaks(ranks);
  c->Gather(&peak, peaks.data(), 1, 0);
  long long total = 0;
  c->Reduce(&triangles, &total, 1, vtkCommunicator::SUM_OP, 0);
  if (c->GetLocalProcessId() == 0)
  {
    std::printf("{\"stage\": \"%s\", \"ranks\": %d, \"seconds\": %.3f, \"triangles\": %lld, "
                "\"peak_rss_mib\": [",
      stage, ranks, slowest, total);
    for (int r = 0; r < ranks; ++r)
    {
      std::printf("%s%.0f", r ? ", " : "", peaks[r]);
    }
    std::printf("]}\n");
    std::fflush(stdout);
  }
}

} // namespace

int main(int argc, char* argv[])
{
  vtkNew<vtkMPIController> controller;
  controller->Initialize(&argc, &argv);
  vtkMultiProcessController::SetGlobalController(controller);
  const int rank = controller->GetLocalProcessId();
  const int ranks = controller->GetNumberOfProcesses();

  Options opt;
  bool usage = false;
  for (int a = 1; a < argc; ++a)
  {
    const std::string arg = argv[a];
    const bool value = a + 1 < argc;
    if (arg == "--size" && value)
    {
      opt.Size = std::atoi(argv[++a]);
    }
    else if (arg == "--period" && value)
    {
      opt.Period = std::atof(argv[++a]);
    }
    else if (arg == "--iterations" && value)
    {
      opt.Iterations = std::atoi(argv[++a]);
    }
    else if (arg == "--decimate" && value)
    {
      opt.Decimate = std::atof(argv[++a]);
    }
    else if (arg == "--output" && value)
    {
      opt.Output = argv[++a];
    }
    else if (arg == "--keep")
    {
      opt.Keep = true;
    }
    else
    {
      usage = true;
    }
  }
  if (usage || opt.Size < 8 || opt.Period <= 0 || opt.Iterations < 0)
  {
    if (rank == 0)
    {
      std::cerr << "usage: rgmcScale [--size N] [--period VOXELS] [--iterations N] "
                   "[--decimate FRACTION] [--output PREFIX] [--keep]\n";
    }
    controller->Finalize();
    return 2;
  }

  // This rank's piece of the gyroid, with one ghost layer.
  double t0 = Now();
  vtkSmartPointer<vtkImageData> volume = rgmc_test::GyroidPiece(opt.Size, opt.Period, rank, ranks);
  volume->SetSpacing(0.1, 0.1, 0.1);
  Report(controller, "make volume", Now() - t0, 0);

  vtkNew<vtkRGMarchingCubes> extract;
  extract->SetInputData(volume);
  extract->SetIsovalue(0.0);
  extract->SetExtractionMode(vtkRGMarchingCubes::ALL_COMPONENTS);
  controller->Barrier();
  t0 = Now();
  extract->Update();
  const long long triangles = extract->GetOutput()->GetNumberOfPolys();
  Report(controller, "extract", Now() - t0, triangles);
  volume = nullptr;
  extract->SetInputData(nullptr);

  // Seam Repair in two stages, split where its progress says the smoothing begins.
  vtkNew<vtkRGSeamRepair> repair;
  repair->SetInputData(extract->GetOutput());
  repair->SetSmoothingMethod(
    opt.Iterations ? vtkRGSeamRepair::LAPLACIAN : vtkRGSeamRepair::NO_SMOOTHING);
  repair->SetNumberOfIterations(opt.Iterations);
  repair->SetRelaxationFactor(0.01);
  struct Split
  {
    double Time = 0;
    double Peak = 0;
  } smoothing;
  vtkNew<vtkCallbackCommand> progress;
  progress->SetClientData(&smoothing);
  progress->SetCallback(
    [](vtkObject* caller, unsigned long, void* data, void*)
    {
      auto* s = static_cast<Split*>(data);
      if (s->Time == 0 && static_cast<vtkAlgorithm*>(caller)->GetProgress() >= 0.4)
      {
        s->Time = Now();
        s->Peak = StatusMiB("VmHWM:");
      }
    });
  repair->AddObserver(vtkCommand::ProgressEvent, progress);
  controller->Barrier();
  t0 = Now();
  repair->Update();
  const double t1 = Now();
  // Every rank reaches the split at a different time: report each part's slowest rank.
  Report(controller, "repair", (smoothing.Time ? smoothing.Time : t1) - t0, triangles);
  Report(controller, "smooth", smoothing.Time ? t1 - smoothing.Time : 0.0, triangles);
  // The writers take the repaired surface as data, so that freeing the extraction's output
  // does not make the pipeline run again.
  vtkNew<vtkPolyData> surface;
  surface->ShallowCopy(repair->GetOutput());
  repair->SetInputData(nullptr);
  extract->GetOutput()->Initialize();
  long long written = triangles;
  if (opt.Decimate > 0)
  {
    vtkNew<vtkRGDecimate> decimate;
    decimate->SetInputData(surface);
    decimate->SetTargetReduction(opt.Decimate);
    controller->Barrier();
    t0 = Now();
    decimate->Update();
    written = decimate->GetOutput()->GetNumberOfPolys();
    Report(controller, "decimate", Now() - t0, written);
    surface->ShallowCopy(decimate->GetOutput());
  }

  for (const char* format : { "stl", "ply" })
  {
    const std::string file = opt.Output + "." + format;
    vtkNew<vtkRGMergedSurfaceWriter> writer;
    writer->SetInputData(surface);
    writer->SetFileName(file.c_str());
    controller->Barrier();
    t0 = Now();
    const int ok = writer->Write();
    Report(controller, (std::string("write ") + format).c_str(), Now() - t0, written);
    if (!ok)
    {
      controller->Finalize();
      return 1;
    }
    controller->Barrier();
    if (rank == 0 && !opt.Keep)
    {
      std::remove(file.c_str());
    }
  }
  controller->Finalize();
  return 0;
}

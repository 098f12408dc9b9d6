// RGMC's timing program (not a test): run under mpiexec, every rank makes its piece of a volume
// once, then each method runs on the same pieces, several times; the time of a run is the
// slowest rank's (barrier, run, reduce max). Prints one JSON object per method on rank 0.
//
//   mpiexec -n 2 rgmcBenchmark --field phantom --size 512 --repeats 5 --methods seeded,fe,contour
//
// Methods: seeded (vtkRGMarchingCubes, one seed), all (vtkRGMarchingCubes, every component),
// fe (vtkFlyingEdges3D), mc (vtkMarchingCubes, 1 rank only), contour (ParaView's Contour,
// vtkPVContourFilter). Every method computes normals. vtkRGMarchingCubes gets the piece with
// its ghost layer (as it asks the pipeline for); the others get the piece without.
// On the seeded surface's pieces (extracted once, not timed): repair (vtkRGSeamRepair with 20
// Laplacian iterations, relaxation 0.01) and smooth (ParaView's Smooth: vtkSmoothPolyDataFilter
// with 20 iterations, relaxation 0.01, on each rank's piece alone).
#include "rgmcTestData.h" // pieces with ghost cells, as the pipeline makes them
#include "vtkRGMarchingCubes.h"
#include "vtkRGPhantomSource.h"
#include "vtkRGSeamRepair.h"
#include "vtkSmoothPolyDataFilter.h"

#include "vtkCellData.h"
#include "vtkDataSetAttributes.h"
#include "vtkExtentTranslator.h"
#include "vtkExtractVOI.h"
#include "vtkFloatArray.h"
#include "vtkFlyingEdges3D.h"
#include "vtkImageData.h"
#include "vtkMPIController.h"
#include "vtkMarchingCubes.h"
#include "vtkNew.h"
#include "vtkPVContourFilter.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"
#include "vtkUnsignedCharArray.h"

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

namespace
{

struct Options
{
  std::string Field = "phantom";
  int Size = 256;
  int Repeats = 3;
  std::vector<std::string> Methods = { "seeded", "fe", "contour" };
};

double Now()
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double PeakMemoryMiB()
{
  rusage usage;
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;
}

/// The field "sphere": one small sphere (radius 12 voxels) in empty space, float32,
/// f = 12 - distance to the centre (in voxels), isovalue 0.
vtkSmartPointer<vtkImageData> SpherePiece(const int whole[6], const int extent[6])
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetExtent(const_cast<int*>(extent));
  vtkNew<vtkFloatArray> f;
  f->SetName("f");
  f->SetNumberOfTuples(image->GetNumberOfPoints());
  const double c[3] = { 0.61 * whole[1], 0.43 * whole[3], 0.37 * whole[5] };
  float* out = f->GetPointer(0);
  for (int k = extent[4]; k <= extent[5]; ++k)
  {
    for (int j = extent[2]; j <= extent[3]; ++j)
    {
      for (int i = extent[0]; i <= extent[1]; ++i)
      {
        *out++ = static_cast<float>(
          12.0 - std::sqrt((i - c[0]) * (i - c[0]) + (j - c[1]) * (j - c[1]) + (k - c[2]) * (k - c[2])));
      }
    }
  }
  image->GetPointData()->SetScalars(f);
  return image;
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
  for (int a = 1; a < argc; ++a)
  {
    const std::string arg = argv[a];
    const bool hasValue = a + 1 < argc;
    if (arg == "--field" && hasValue)
    {
      opt.Field = argv[++a];
    }
    else if (arg == "--size" && hasValue)
    {
      opt.Size = std::atoi(argv[++a]);
    }
    else if (arg == "--repeats" && hasValue)
    {
      opt.Repeats = std::max(1, std::atoi(argv[++a]));
    }
    else if (arg == "--methods" && hasValue)
    {
      opt.Methods.clear();
      std::stringstream list(argv[++a]);
      for (std::string m; std::getline(list, m, ',');)
      {
        opt.Methods.push_back(m);
      }
    }
    else
    {
      if (rank == 0)
      {
        std::cerr << "usage: rgmcBenchmark [--field phantom|sphere] [--size N] [--repeats R] "
                     "[--methods seeded,all,fe,mc,contour,repair,smooth]\n";
      }
      controller->Finalize();
      return 2;
    }
  }
  if (opt.Size < 8 || (opt.Field != "phantom" && opt.Field != "sphere"))
  {
    if (rank == 0)
    {
      std::cerr << "rgmcBenchmark: --size must be at least 8 and --field phantom or sphere\n";
    }
    controller->Finalize();
    return 2;
  }

  // This rank's piece, split as ParaView splits images, with and without its ghost layer.
  const int n = opt.Size;
  const int whole[6] = { 0, n - 1, 0, n - 1, 0, n - 1 };
  int owned[6], withGhosts[6];
  vtkNew<vtkExtentTranslator> split;
  split->PieceToExtentThreadSafe(
    rank, ranks, 0, const_cast<int*>(whole), owned, vtkExtentTranslator::BLOCK_MODE, 0);
  split->PieceToExtentThreadSafe(
    rank, ranks, 1, const_cast<int*>(whole), withGhosts, vtkExtentTranslator::BLOCK_MODE, 0);
  const double started = Now();
  vtkSmartPointer<vtkImageData> ghosted;
  double isovalue = 0.0, seed[3] = { 0, 0, 0 };
  if (opt.Field == "phantom")
  {
    vtkNew<vtkRGPhantomSource> phantom;
    phantom->SetDimensions(n, n, n);
    phantom->UpdatePiece(rank, ranks, 1);
    ghosted = phantom->GetOutput();
    isovalue = 400;
    seed[2] = 105; // the top of the skull
  }
  else
  {
    ghosted = SpherePiece(whole, withGhosts);
    rgmc_test::MarkGhostCells(ghosted, owned);
    isovalue = 0;
    seed[0] = 0.61 * whole[1] + 12.0;
    seed[1] = 0.43 * whole[3];
    seed[2] = 0.37 * whole[5];
  }
  vtkNew<vtkExtractVOI> crop;
  crop->SetInputData(ghosted);
  crop->SetVOI(owned);
  crop->Update();
  vtkSmartPointer<vtkImageData> plain = crop->GetOutput();
  double generate = Now() - started, generateMax = 0;
  controller->AllReduce(&generate, &generateMax, 1, vtkCommunicator::MAX_OP);

  // The seeded surface's pieces, for the methods that work on a surface.
  vtkNew<vtkPolyData> surface;
  {
    vtkNew<vtkRGMarchingCubes> rg;
    rg->SetInputData(ghosted);
    rg->SetIsovalue(isovalue);
    rg->AddSeedPoint(seed[0], seed[1], seed[2]);
    rg->SetSeedSearchRadius(40);
    rg->Update();
    surface->ShallowCopy(rg->GetOutput());
  }

  for (const std::string& method : opt.Methods)
  {
    if (method == "mc" && ranks > 1)
    {
      continue; // vtkMarchingCubes misplaces pieces that do not start at the whole origin
    }
    std::vector<double> times;
    vtkIdType triangles = 0, busiest = 0;
    for (int r = 0; r < opt.Repeats; ++r)
    {
      vtkSmartPointer<vtkPolyDataAlgorithm> filter;
      if (method == "seeded" || method == "all")
      {
        auto rg = vtkSmartPointer<vtkRGMarchingCubes>::New();
        rg->SetInputData(ghosted);
        rg->SetIsovalue(isovalue);
        rg->AddSeedPoint(seed[0], seed[1], seed[2]);
        rg->SetSeedSearchRadius(40);
        if (method == "all")
        {
          rg->SetExtractionModeToAllComponents();
        }
        filter = rg;
      }
      else if (method == "fe")
      {
        auto fe = vtkSmartPointer<vtkFlyingEdges3D>::New();
        fe->SetInputData(plain);
        fe->SetValue(0, isovalue);
        fe->ComputeNormalsOn();
        fe->ComputeScalarsOff();
        filter = fe;
      }
      else if (method == "mc")
      {
        auto mc = vtkSmartPointer<vtkMarchingCubes>::New();
        mc->SetInputData(plain);
        mc->SetValue(0, isovalue);
        mc->ComputeNormalsOn();
        mc->ComputeScalarsOff();
        filter = mc;
      }
      else if (method == "repair")
      {
        auto repair = vtkSmartPointer<vtkRGSeamRepair>::New();
        repair->SetInputData(surface);
        repair->SetSmoothingMethod(vtkRGSeamRepair::LAPLACIAN);
        repair->SetNumberOfIterations(20);
        repair->SetRelaxationFactor(0.01);
        filter = repair;
      }
      else if (method == "smooth")
      {
        auto smooth = vtkSmartPointer<vtkSmoothPolyDataFilter>::New();
        smooth->SetInputData(surface);
        smooth->SetNumberOfIterations(20);
        smooth->SetRelaxationFactor(0.01);
        filter = smooth;
      }
      else if (method == "contour")
      {
        auto contour = vtkSmartPointer<vtkPVContourFilter>::New();
        contour->SetInputData(plain);
        contour->SetValue(0, isovalue);
        contour->ComputeNormalsOn();
        contour->ComputeScalarsOff();
        filter = contour;
      }
      else
      {
        if (rank == 0)
        {
          std::cerr << "rgmcBenchmark: unknown method " << method << "\n";
        }
        controller->Finalize();
        return 2;
      }
      controller->Barrier();
      const double t0 = Now();
      filter->Update();
      double t = Now() - t0, tMax = 0;
      controller->AllReduce(&t, &tMax, 1, vtkCommunicator::MAX_OP);
      times.push_back(tMax);
      vtkIdType local = filter->GetOutput()->GetNumberOfCells();
      controller->AllReduce(&local, &triangles, 1, vtkCommunicator::SUM_OP);
      controller->AllReduce(&local, &busiest, 1, vtkCommunicator::MAX_OP);
    }
    std::vector<double> sorted = times;
    std::sort(sorted.begin(), sorted.end());
    double memory = PeakMemoryMiB(), memoryMax = 0;
    controller->AllReduce(&memory, &memoryMax, 1, vtkCommunicator::MAX_OP);
    if (rank == 0)
    {
      std::printf("{\"field\": \"%s\", \"size\": %d, \"ranks\": %d, \"method\": \"%s\", "
                  "\"triangles\": %lld, \"busiest_rank_triangles\": %lld, "
                  "\"min_seconds\": %.5f, \"median_seconds\": %.5f, "
                  "\"repeats\": %d, \"input_seconds\": %.3f, \"peak_rss_mib\": %.1f}\n",
        opt.Field.c_str(), n, ranks, method.c_str(), static_cast<long long>(triangles),
        static_cast<long long>(busiest),
        sorted.front(), sorted[sorted.size() / 2], opt.Repeats, generateMax, memoryMax);
      std::fflush(stdout);
    }
  }
  controller->Finalize();
  return 0;
}

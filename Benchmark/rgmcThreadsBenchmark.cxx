// The threads benchmark (./rgmc evaluate --threads; not a test): the CT phantom on one rank,
// extracted by vtkFlyingEdges3D and by RGMC (seeded on the skull, and all components), then
// Seam Repair with 20 Laplacian iterations, at each thread count, through vtkSMPTools with the
// backend asked for (the one that ran is recorded). Minimum of the repeats; JSON on stdout.
//
//   rgmcThreadsBenchmark [--size 512] [--threads 1,2] [--repeats 3] [--backend STDThread]
//                        [--only repair]
// --only repair extracts the skull once and times Seam Repair alone (for a profiler: perf record).
#include "rgmcBenchmark.h"
#include "rgmcThreadCompare.h" // Difference

#include "vtkDummyController.h"
#include "vtkFlyingEdges3D.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkRGMarchingCubes.h"
#include "vtkRGPhantomSource.h"
#include "vtkRGSeamRepair.h"
#include "vtkSMPTools.h"
#include "vtkSmartPointer.h"

#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

namespace
{

using rgmc_benchmark::FastestUpdate;
using rgmc_benchmark::IntList;

} // namespace

int main(int argc, char* argv[])
{
  int size = 512, repeats = 3;
  std::vector<int> threadCounts = { 1, 2 };
  std::string backend = "STDThread";
  bool repairOnly = false;
  for (int a = 1; a + 1 < argc; a += 2)
  {
    const std::string arg = argv[a];
    if (arg == "--size")
    {
      size = std::atoi(argv[a + 1]);
    }
    else if (arg == "--repeats")
    {
      repeats = std::atoi(argv[a + 1]);
    }
    else if (arg == "--backend")
    {
      backend = argv[a + 1];
    }
    else if (arg == "--threads")
    {
      threadCounts = IntList(argv[a + 1]);
    }
    else if (arg == "--only" && std::string(argv[a + 1]) == "repair")
    {
      repairOnly = true;
    }
    else
    {
      std::cerr
        << "usage: rgmcThreadsBenchmark [--size N] [--threads 1,2] [--repeats N] [--backend B]\n"
           "                            [--only repair]\n";
      return 2;
    }
  }
  vtkNew<vtkDummyController> single;
  vtkMultiProcessController::SetGlobalController(single);

  vtkNew<vtkRGPhantomSource> phantom;
  phantom->SetDimensions(size, size, size);
  phantom->Update();
  vtkNew<vtkImageData> image;
  image->DeepCopy(phantom->GetOutput());
  image->GetPointData()->SetActiveScalars("HU");

  vtkSmartPointer<vtkPolyData> firstSeeded, firstAll, firstRepaired;
  std::ostringstream json;
  json << "{\n  \"size\": " << size << ",\n  \"repeats\": " << repeats << ",\n  \"runs\": [";
  for (std::size_t n = 0; n < threadCounts.size(); ++n)
  {
    const int threads = threadCounts[n];
    double fe = 0, seeded = 0, all = 0, repair = 0;
    long long feTriangles = 0, seededTriangles = 0, allTriangles = 0;
    std::string ran;
    int estimated = 0;
    bool identical = true;
    vtkSMPTools::LocalScope(vtkSMPTools::Config{ threads, backend, false },
      [&]()
      {
        ran = vtkSMPTools::GetBackend();
        estimated = vtkSMPTools::GetEstimatedNumberOfThreads();
        vtkNew<vtkFlyingEdges3D> flying;
        flying->SetInputData(image);
        flying->SetValue(0, 400);
        flying->ComputeNormalsOn();
        flying->ComputeScalarsOff();
        fe = repairOnly ? 0.0 : FastestUpdate(repeats, flying.Get());
        feTriangles = flying->GetOutput()->GetNumberOfCells();

        vtkNew<vtkRGMarchingCubes> rg;
        rg->SetInputData(image);
        rg->SetIsovalue(400);
        rg->AddSeedPoint(0, 0, 105);
        seeded = FastestUpdate(repairOnly ? 1 : repeats, rg.Get());
        seededTriangles = rg->GetOutput()->GetNumberOfCells();
        auto seededOut = vtkSmartPointer<vtkPolyData>::New();
        seededOut->DeepCopy(rg->GetOutput());

        vtkNew<vtkRGSeamRepair> repairFilter;
        repairFilter->SetInputData(seededOut);
        repairFilter->SetSmoothingMethod(vtkRGSeamRepair::LAPLACIAN);
        repairFilter->SetNumberOfIterations(20);
        repairFilter->SetRelaxationFactor(0.01);
        repair = FastestUpdate(repeats, repairFilter.Get());
        auto repaired = vtkSmartPointer<vtkPolyData>::New();
        repaired->DeepCopy(repairFilter->GetOutput());

        rg->SetExtractionMode(vtkRGMarchingCubes::ALL_COMPONENTS);
        all = repairOnly ? 0.0 : FastestUpdate(repeats, rg.Get());
        allTriangles = rg->GetOutput()->GetNumberOfCells();
        auto allOut = vtkSmartPointer<vtkPolyData>::New();
        allOut->DeepCopy(rg->GetOutput());

        if (n == 0)
        {
          firstSeeded = seededOut;
          firstAll = allOut;
          firstRepaired = repaired;
        }
        else
        {
          identical = rgmc_test::Difference(firstSeeded, seededOut).empty() &&
            rgmc_test::Difference(firstAll, allOut).empty() &&
            rgmc_test::Difference(firstRepaired, repaired).empty();
        }
      });
    json << (n ? "," : "") << "\n    {\"threads\": " << threads << ", \"backend\": \"" << ran
         << "\", \"estimated_threads\": " << estimated << ", \"flying_edges\": " << fe
         << ", \"seeded\": " << seeded << ", \"all_components\": " << all
         << ", \"seam_repair_laplacian20\": " << repair
         << ", \"flying_edges_triangles\": " << feTriangles
         << ", \"seeded_triangles\": " << seededTriangles << ", \"all_triangles\": " << allTriangles
         << ", \"identical_to_first\": " << (identical ? "true" : "false") << "}";
    std::cerr << threads << " threads (" << ran << "): flying edges " << fe << " s, seeded "
              << seeded << " s, all " << all << " s, Seam Repair + 20 Laplacian " << repair << " s"
              << (identical ? "" : "; OUTPUT DIFFERS FROM THE FIRST THREAD COUNT") << "\n";
  }
  json << "\n  ]\n}\n";
  std::cout << json.str();
  return 0;
}

// Decimate Surface's distance report on its own (rgmc::DecimationDistance), where its rounds
// matter: two surfaces farther apart than the first round's search radius, so that most
// vertices are measured again with a larger one. Against a cell locator's exact closest points
// over the whole surfaces (the oracle), and to the bit the same on 1-4 ranks (each rank holding
// an interleaved share of the triangles and of the vertices) and on 1 and 16 threads.
#include "rgmcCheck.h"
#include "rgmcDecimateDistance.h"
#include "rgmcNearestDistances.h"
#include "rgmcTestController.h"

#include "vtkDummyController.h"
#include "vtkIdList.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkSMPTools.h"
#include "vtkSmartPointer.h"
#include "vtkSphereSource.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <iostream>
#include <limits>
#include <string>

namespace
{

vtkSmartPointer<vtkPolyData> Sphere(double radius, const double centre[3], int resolution)
{
  vtkNew<vtkSphereSource> sphere;
  sphere->SetRadius(radius);
  sphere->SetCenter(centre[0], centre[1], centre[2]);
  sphere->SetThetaResolution(resolution);
  sphere->SetPhiResolution(resolution);
  sphere->Update();
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  pd->DeepCopy(sphere->GetOutput());
  return pd;
}

/// Rank `rank`'s share of `whole`: every point (those of other ranks flagged as duplicates, as
/// Seam Repair flags them), and every `ranks`-th triangle from `rank`.
vtkSmartPointer<vtkPolyData> Share(vtkPolyData* whole, int rank, int ranks)
{
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  pd->SetPoints(whole->GetPoints());
  vtkNew<vtkCellArray> polys;
  vtkNew<vtkIdList> ids;
  for (vtkIdType c = rank; c < whole->GetNumberOfCells(); c += ranks)
  {
    whole->GetCellPoints(c, ids);
    polys->InsertNextCell(ids);
  }
  pd->SetPolys(polys);
  vtkNew<vtkUnsignedCharArray> ghosts;
  ghosts->SetName(vtkDataSetAttributes::GhostArrayName());
  ghosts->SetNumberOfTuples(whole->GetNumberOfPoints());
  for (vtkIdType p = 0; p < whole->GetNumberOfPoints(); ++p)
  {
    ghosts->SetValue(p, p % ranks == rank ? 0 : vtkDataSetAttributes::DUPLICATEPOINT);
  }
  pd->GetPointData()->AddArray(ghosts);
  return pd;
}

bool Measure(vtkMultiProcessController* controller, vtkPolyData* a, vtkPolyData* b, int threads,
  double& hausdorff, double& mean)
{
  rgmc::Ranks ranks(controller);
  std::string problem;
  bool ok = false;
  vtkSMPTools::LocalScope(vtkSMPTools::Config{ threads, "STDThread", false },
    [&]() { ok = rgmc::DecimationDistance(ranks, a, b, hausdorff, mean, problem); });
  RGMC_CHECK(ok && problem.empty(), "the distance failed: " << problem);
  return ok;
}

bool SameBits(double x, double y)
{
  return std::memcmp(&x, &y, sizeof x) == 0;
}

} // namespace

int main(int argc, char* argv[])
{
  rgmc_test::AllowThreads(64);
  vtkSmartPointer<vtkMultiProcessController> controller = rgmc_test::StartController(argc, argv);
  const int rank = controller->GetLocalProcessId(), ranks = controller->GetNumberOfProcesses();
  vtkNew<vtkDummyController> single;
  const double origin[3] = { 0, 0, 0 }, shifted[3] = { 1.5, -0.5, 0.25 };
  struct Case
  {
    const char* Name;
    double RadiusA, RadiusB;
    const double* CentreB;
    int ResolutionA, ResolutionB;
  };
  // Concentric spheres 2 apart, an offset pair, and a sphere against a much coarser copy of
  // itself and the other way round (the decimation's own case: most vertices found in the
  // first round).
  const Case cases[] = { { "concentric", 10, 12, origin, 48, 96 },
    { "offset", 10, 11, shifted, 64, 40 }, { "coarse copy", 10, 10, origin, 120, 16 },
    { "fine copy", 10, 10, origin, 16, 120 } }; // the farthest vertices are the second's
  for (const Case& c : cases)
  {
    vtkSmartPointer<vtkPolyData> a = Sphere(c.RadiusA, origin, c.ResolutionA);
    vtkSmartPointer<vtkPolyData> b = Sphere(c.RadiusB, c.CentreB, c.ResolutionB);
    double oneHausdorff = 0, oneMean = 0;
    Measure(single, Share(a, 0, 1), Share(b, 0, 1), 1, oneHausdorff, oneMean);
    const rgmc_test::NearestDistances ab = rgmc_test::Nearest(a, b), ba = rgmc_test::Nearest(b, a);
    const double hausdorff = std::max(ab.Largest, ba.Largest), mean = 0.5 * (ab.Mean + ba.Mean);
    if (rank == 0)
    {
      std::cout << c.Name << ": Hausdorff " << oneHausdorff << " mean " << oneMean
                << "; the locator's " << hausdorff << ", " << mean << "\n";
    }
    RGMC_CHECK(std::abs(oneHausdorff - hausdorff) <= 1e-9 * (1 + hausdorff) &&
        std::abs(oneMean - mean) <= 1e-9 * (1 + mean),
      c.Name << ": (" << oneHausdorff << ", " << oneMean << ") is not the locator's (" << hausdorff
             << ", " << mean << ")");
    for (const int threads : { 1, 16 })
    {
      double h = 0, m = 0;
      Measure(controller, Share(a, rank, ranks), Share(b, rank, ranks), threads, h, m);
      RGMC_CHECK(SameBits(h, oneHausdorff) && SameBits(m, oneMean),
        c.Name << " on " << ranks << " ranks, " << threads << " threads: (" << h << ", " << m
               << ") is not 1 rank's (" << oneHausdorff << ", " << oneMean << ") to the bit");
    }
  }
  // Nothing to measure on some rank (all triangles and vertices elsewhere), and an empty
  // surface: no hang, NaN for no surface.
  {
    vtkSmartPointer<vtkPolyData> a = Sphere(10, origin, 24), b = Sphere(11, origin, 24);
    double h = 0, m = 0, oneH = 0, oneM = 0;
    Measure(single, Share(a, 0, 1), Share(b, 0, 1), 1, oneH, oneM);
    vtkNew<vtkPolyData> none;
    Measure(controller, rank == 0 ? Share(a, 0, 1).GetPointer() : none.GetPointer(),
      rank == 0 ? Share(b, 0, 1).GetPointer() : none.GetPointer(), 1, h, m);
    RGMC_CHECK(SameBits(h, oneH) && SameBits(m, oneM),
      "all on rank 0: (" << h << ", " << m << ") is not 1 rank's (" << oneH << ", " << oneM << ")");
    Measure(controller, Share(a, rank, ranks), none, 1, h, m);
    RGMC_CHECK(std::isnan(h) && std::isnan(m), "an empty surface: " << h << ", " << m);
  }
  return rgmc_test::Finish(controller, "TestDecimateDistance");
}

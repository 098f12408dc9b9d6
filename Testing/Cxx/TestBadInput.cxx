// Bad input to vtkRGMarchingCubes: each case gives a message that names the problem and an
// empty output, never a crash. Also progress reporting and abort.
#include "rgmcTestData.h"

#include "vtkCallbackCommand.h"
#include "vtkExecutive.h"
#include "vtkCellData.h"
#include "vtkRGMarchingCubes.h"
#include "vtkRGPhantomSource.h"

#include <limits>

using namespace rgmc_test;

namespace
{

struct Run
{
  std::string Errors, Warnings;
  vtkIdType Points = -1, Cells = -1;
};

Run Execute(vtkRGMarchingCubes* rg, vtkDataObject* input)
{
  vtkNew<MessageCatcher> catcher;
  catcher->Watch(rg);
  catcher->Watch(rg->GetExecutive());
  rg->SetInputData(input);
  rg->Update();
  Run r;
  r.Errors = catcher->Errors;
  r.Warnings = catcher->Warnings;
  r.Points = rg->GetOutput()->GetNumberOfPoints();
  r.Cells = rg->GetOutput()->GetNumberOfCells();
  return r;
}

void ExpectMessage(const std::string& what, const Run& r, const std::string& text, bool error)
{
  const std::string& where = error ? r.Errors : r.Warnings;
  RGMC_CHECK(where.find(text) != std::string::npos,
    what << ": expected " << (error ? "an error" : "a warning") << " with '" << text
         << "'; errors: [" << r.Errors << "] warnings: [" << r.Warnings << "]");
  RGMC_CHECK(r.Points == 0 && r.Cells == 0,
    what << ": the output should be empty, has " << r.Points << " points " << r.Cells << " cells");
  std::cout << what << ": " << (error ? r.Errors : r.Warnings);
}

const int Extent[6] = { 0, 15, 0, 15, 0, 15 };

double Sphere(int i, int j, int k)
{
  return 6.0 - std::sqrt((i - 7.5) * (i - 7.5) + (j - 7.5) * (j - 7.5) + (k - 7.5) * (k - 7.5));
}

vtkSmartPointer<vtkRGMarchingCubes> Filter(double isovalue = 0.0)
{
  auto rg = vtkSmartPointer<vtkRGMarchingCubes>::New();
  rg->SetIsovalue(isovalue);
  rg->AddSeedPoint(7.5, 7.5, 13.0);
  return rg;
}

} // namespace

int main()
{
  {
    vtkNew<vtkImageData> image;
    image->SetExtent(const_cast<int*>(Extent));
    ExpectMessage("no arrays", Execute(Filter(), image), "no point scalars", true);
  }
  {
    auto image = MakeImage(Extent, VTK_FLOAT, Sphere);
    vtkNew<vtkFloatArray> vectors;
    vectors->SetName("v");
    vectors->SetNumberOfComponents(3);
    vectors->SetNumberOfTuples(image->GetNumberOfPoints());
    vectors->Fill(1.0);
    image->GetPointData()->SetScalars(vectors);
    ExpectMessage("3-component array", Execute(Filter(), image), "has 3 components", true);
  }
  {
    vtkNew<vtkImageData> image;
    image->SetExtent(const_cast<int*>(Extent));
    vtkNew<vtkFloatArray> cells;
    cells->SetName("density");
    cells->SetNumberOfTuples(image->GetNumberOfCells());
    cells->Fill(1.0);
    image->GetCellData()->SetScalars(cells);
    auto rg = Filter();
    rg->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_CELLS, "density");
    ExpectMessage("cell data chosen", Execute(rg, image), "is cell data", true);
    auto byName = Filter();
    byName->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, "density");
    ExpectMessage("cell array asked as points", Execute(byName, image), "is cell data", true);
    ExpectMessage("cell data only", Execute(Filter(), image), "1 cell arrays", true);
  }
  {
    // A NaN next to the surface: an error naming its grid point.
    auto image = MakeImage(Extent, VTK_FLOAT, [](int i, int j, int k) {
      return (i == 7 && j == 7 && k == 13) ? std::numeric_limits<double>::quiet_NaN()
                                           : Sphere(i, j, k);
    });
    ExpectMessage("NaN on the surface", Execute(Filter(), image), "(7, 7, 13) is NaN", true);
    auto all = Filter();
    all->SetExtractionModeToAllComponents();
    ExpectMessage("NaN, all components", Execute(all, image), "is NaN", true);
    // A NaN far from the seeded surface does not touch it: the surface is extracted as usual.
    auto far = MakeImage(Extent, VTK_FLOAT, [](int i, int j, int k) {
      return (i == 0 && j == 0 && k == 0) ? std::numeric_limits<double>::quiet_NaN()
                                          : Sphere(i, j, k);
    });
    const Run r = Execute(Filter(), far);
    RGMC_CHECK(r.Errors.empty() && r.Cells > 0, "a NaN away from the surface is not read");
    auto allFar = Filter();
    allFar->SetExtractionModeToAllComponents();
    ExpectMessage("NaN far away, all components", Execute(allFar, far), "(0, 0, 0) is NaN", true);
  }
  {
    auto image = MakeImage(Extent, VTK_FLOAT, Sphere);
    ExpectMessage("isovalue above the range", Execute(Filter(100.0), image),
      "outside the data range", false);
    ExpectMessage("isovalue below the range", Execute(Filter(-100.0), image),
      "outside the data range", false);
    auto all = Filter(100.0);
    all->SetExtractionModeToAllComponents();
    ExpectMessage("isovalue above the range, all components", Execute(all, image),
      "gives no triangles", false);
  }
  {
    auto image = MakeImage(Extent, VTK_FLOAT, Sphere);
    auto rg = Filter();
    rg->AddSeedPoint(7.5, 7.5, 40.0);
    ExpectMessage("seed outside", Execute(rg, image), "seed point 1 (7.5, 7.5, 40) lies outside", false);
  }
  {
    auto image = MakeImage(Extent, VTK_FLOAT, Sphere);
    vtkNew<vtkRGMarchingCubes> rg;
    rg->AddSeedPoint(0.5, 0.5, 0.5);
    rg->SetSeedSearchRadius(2.0);
    ExpectMessage("no surface near the seed", Execute(rg, image), "passes within 2 of seed point 0",
      false);
    rg->SetSeedSearchRadius(20.0); // the same seed finds the sphere with a larger radius
    const Run r = Execute(rg, image);
    RGMC_CHECK(r.Cells > 0 && r.Warnings.empty(), "a larger radius reaches the sphere");
  }
  {
    const int flat[6] = { 0, 15, 0, 15, 3, 3 };
    auto image = MakeImage(flat, VTK_FLOAT, [](int i, int j, int) { return i + j; });
    ExpectMessage("2-D image", Execute(Filter(), image), "not a volume", true);
  }
  {
    vtkNew<vtkImageData> image;
    ExpectMessage("empty image", Execute(Filter(), image), "empty", true);
  }
  {
    auto image = MakeImage(Extent, VTK_FLOAT, Sphere);
    vtkNew<vtkRGMarchingCubes> rg;
    ExpectMessage("no seed", Execute(rg, image), "no seed point is set", true);
    auto nan = Filter(std::numeric_limits<double>::quiet_NaN());
    ExpectMessage("NaN isovalue", Execute(nan, image), "isovalue is NaN", true);
  }

  // Progress goes forward to 1; an abort from a progress observer stops with an empty output.
  {
    vtkNew<vtkRGPhantomSource> phantom;
    phantom->SetDimensions(96, 96, 96);
    vtkNew<vtkRGMarchingCubes> rg;
    rg->SetInputConnection(phantom->GetOutputPort());
    rg->SetIsovalue(400);
    rg->AddSeedPoint(0, 0, 105);
    std::vector<double> progress;
    vtkNew<vtkCallbackCommand> record;
    record->SetClientData(&progress);
    record->SetCallback([](vtkObject* caller, unsigned long, void* client, void*) {
      static_cast<std::vector<double>*>(client)->push_back(
        static_cast<vtkAlgorithm*>(caller)->GetProgress());
    });
    rg->AddObserver(vtkCommand::ProgressEvent, record);
    rg->Update();
    RGMC_CHECK(progress.size() > 5, "progress events: " << progress.size());
    RGMC_CHECK(std::is_sorted(progress.begin(), progress.end()), "progress goes forward");
    RGMC_CHECK(!progress.empty() && progress.back() == 1.0, "progress ends at 1");
    const vtkIdType full = rg->GetOutput()->GetNumberOfCells();
    RGMC_CHECK(full > 10000, "the skull has many triangles: " << full);

    vtkNew<vtkCallbackCommand> abort;
    abort->SetCallback([](vtkObject* caller, unsigned long, void*, void*) {
      auto* algorithm = static_cast<vtkAlgorithm*>(caller);
      if (algorithm->GetProgress() > 0.1)
      {
        algorithm->SetAbortExecute(1);
      }
    });
    rg->AddObserver(vtkCommand::ProgressEvent, abort);
    rg->SetIsovalue(401); // re-execute
    rg->Update();
    RGMC_CHECK(rg->GetOutput()->GetNumberOfCells() == 0,
      "an aborted run leaves an empty output, not " << rg->GetOutput()->GetNumberOfCells());
    // The next run, with nothing reset by the caller (as ParaView's next Apply; VTK 9.3+ keeps
    // an algorithm's abort flag between runs), extracts the whole surface again.
    rg->RemoveObserver(abort);
    rg->SetIsovalue(400);
    rg->Update();
    RGMC_CHECK(rg->GetOutput()->GetNumberOfCells() == full,
      "after an abort, the next run gives " << rg->GetOutput()->GetNumberOfCells()
                                            << " triangles, not " << full);
  }
  return rgmc_test::Result("TestBadInput");
}

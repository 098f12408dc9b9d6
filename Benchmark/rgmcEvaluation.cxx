// RGMC's evaluation program (not a test; Scripts/rgmc_evaluate.py runs it and writes the report).
//
// One process set, one run: started once under mpiexec on the largest rank count, it measures
// every case at every rank count by splitting the processes (the first r ranks work on a
// controller of their own; the others sleep until they are done, polling without spinning, so
// that they take no processor time from the ones measured). For each case and rank count, each
// rank makes its piece of the volume as ParaView splits images (not timed), then every method
// runs --repeats times on the same pieces; a run's time is the slowest rank's (barrier, run,
// reduce max). Peak memory is each rank's resident-set peak while the method runs (the kernel's
// high-water mark, reset before the method), the largest over ranks. Prints one JSON object per
// line on the first rank.
//
//   mpiexec -n 4 rgmcEvaluation --cases phantom256,phantom512,sphere512,blobs,mri --ranks 1,2,4
//
// Methods: mc (vtkMarchingCubes, the paper's MC; 1 rank, it misplaces other pieces), seeded
// (vtkRGMarchingCubes from one seed: the paper's RGMC at 1 rank, its parallel method at more),
// fe (vtkFlyingEdges3D), contour (ParaView's Contour, vtkPVContourFilter), contour+connectivity
// (Contour then ParaView's Connectivity, vtkPConnectivityFilter, closest point region: the
// pipeline that gives the seeded surface today), repair (vtkRGSeamRepair with 20 Laplacian
// iterations, relaxation 0.01, on the seeded surface), smooth (ParaView's Smooth,
// vtkSmoothPolyDataFilter with the same settings, on each rank's piece alone). Every extraction
// computes normals. vtkRGMarchingCubes gets its piece with one ghost layer (it asks the pipeline
// for it); the others get the piece without, as in ParaView.
//
// Distances: the symmetric Hausdorff distance (vtkHausdorffDistancePointSetFilter, point to
// point) between the seeded surface on r ranks and on 1 rank, and between the seam-repaired,
// Laplacian-smoothed surface on r ranks and VTK's smoothing (vtkSmoothPolyDataFilter) of the
// 1-rank surface; also the windowed-sinc smoothing against vtkWindowedSincPolyDataFilter's.
#include "rgmcBenchmark.h"       // Now, StatusMiB
#include "rgmcDistributedData.h" // BlockPiece, ghost marking
#include "vtkRGMarchingCubes.h"
#include "vtkRGPhantomSource.h"
#include "vtkRGPieces.h" // the phantom's pieces
#include "vtkRGSeamRepair.h"

#include "vtkAppendPolyData.h"
#include "vtkCellData.h"
#include "vtkDataSetAttributes.h"
#include "vtkExtractVOI.h"
#include "vtkFloatArray.h"
#include "vtkFlyingEdges3D.h"
#include "vtkHausdorffDistancePointSetFilter.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationIntegerRequestKey.h"
#include "vtkLogger.h"
#include "vtkMPICommunicator.h"
#include "vtkMPIController.h"
#include "vtkMarchingCubes.h"
#include "vtkMinimalStandardRandomSequence.h"
#include "vtkNIFTIImageReader.h"
#include "vtkNew.h"
#include "vtkPConnectivityFilter.h"
#include "vtkPVContourFilter.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkRGCompatibility.h"
#include "vtkSmartPointer.h"
#include "vtkSmoothPolyDataFilter.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkWindowedSincPolyDataFilter.h"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace
{

using rgmc_benchmark::Now;
using rgmc_benchmark::StatusMiB;

const int DoneTag = 7901;

/// Restarts the peak resident set from the current one (Linux: "5" into clear_refs).
bool ResetPeakMemory()
{
  std::ofstream clear("/proc/self/clear_refs");
  clear << "5";
  return static_cast<bool>(clear);
}

std::vector<std::string> Split(const std::string& text)
{
  std::vector<std::string> parts;
  std::stringstream list(text);
  for (std::string p; std::getline(list, p, ',');)
  {
    if (!p.empty())
    {
      parts.push_back(p);
    }
  }
  return parts;
}

/// What is measured: a field at a size, its isovalue and seed, the methods and rank counts.
struct Case
{
  std::string Name;  // as reported
  std::string Field; // phantom, sphere, blobs, mri
  int Dims[3] = { 0, 0, 0 };
  double Isovalue = 0.0;
  std::array<double, 3> Seed = { 0, 0, 0 };
  std::vector<std::string> Methods;
  std::vector<int> Ranks;
  int Repeats = 1;
  bool Distances = false; // compute the Hausdorff distances
};

struct Options
{
  std::vector<std::string> Cases = { "phantom256", "phantom512", "sphere512", "blobs", "mri" };
  std::vector<int> Ranks = { 1, 2, 4 };
  std::vector<int> Sweep = { 128, 256, 512, 1024 };
  int Repeats = 5;
  int SweepRepeats = 3;
  int BlobsSize = 256;
  std::string Mri = "/usr/share/mricron/templates/ch2.nii.gz";
  bool Quick = false; // small sizes, for the smoke test
};

// ---- fields ---------------------------------------------------------------------------------

/// The same small sphere (radius 12 voxels, centre fixed in index space) in any volume:
/// f = 12 - distance to the centre, float32, isovalue 0.
const double SphereCentre[3] = { 40.3, 50.7, 60.1 };

double SphereValue(int i, int j, int k)
{
  const double d[3] = { i - SphereCentre[0], j - SphereCentre[1], k - SphereCentre[2] };
  return 12.0 - std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
}

/// Many Gaussian blobs of both signs (as the tests' field, but each added only within four
/// widths of its centre, so that a large volume is quick to make), float32, isovalue 0.3.
struct Blob
{
  double C[3], Width, Height;
};

std::vector<Blob> MakeBlobs(const int dims[3], int count)
{
  vtkNew<vtkMinimalStandardRandomSequence> random;
  random->SetSeed(20171111);
  std::vector<Blob> blobs(count);
  for (Blob& b : blobs)
  {
    for (int a = 0; a < 3; ++a)
    {
      b.C[a] = random->GetNextRangeValue(0, dims[a] - 1);
    }
    b.Width = random->GetNextRangeValue(1.5, 5.0);
    b.Height = random->GetNextRangeValue(-0.6, 1.2);
  }
  return blobs;
}

vtkSmartPointer<vtkImageData> BlobsImage(const std::vector<Blob>& blobs, const int extent[6])
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetExtent(const_cast<int*>(extent));
  vtkNew<vtkFloatArray> f;
  f->SetName("f");
  f->SetNumberOfTuples(image->GetNumberOfPoints());
  f->FillValue(0.0f);
  float* v = f->GetPointer(0);
  const vtkIdType nx = extent[1] - extent[0] + 1, ny = extent[3] - extent[2] + 1;
  for (const Blob& b : blobs)
  {
    const double reach = 4.0 * b.Width;
    int lo[3], hi[3];
    for (int a = 0; a < 3; ++a)
    {
      lo[a] = std::max(extent[2 * a], static_cast<int>(std::ceil(b.C[a] - reach)));
      hi[a] = std::min(extent[2 * a + 1], static_cast<int>(std::floor(b.C[a] + reach)));
    }
    const double s = 1.0 / (2.0 * b.Width * b.Width);
    for (int k = lo[2]; k <= hi[2]; ++k)
    {
      for (int j = lo[1]; j <= hi[1]; ++j)
      {
        for (int i = lo[0]; i <= hi[0]; ++i)
        {
          const double d2 =
            (i - b.C[0]) * (i - b.C[0]) + (j - b.C[1]) * (j - b.C[1]) + (k - b.C[2]) * (k - b.C[2]);
          v[(k - extent[4]) * nx * ny + (j - extent[2]) * nx + (i - extent[0])] +=
            static_cast<float>(b.Height * std::exp(-d2 * s));
        }
      }
    }
  }
  image->GetPointData()->SetScalars(f);
  return image;
}

/// This rank's piece of the case's volume with one ghost layer (ghost cells marked), as the
/// pipeline gives it to vtkRGMarchingCubes.
vtkSmartPointer<vtkImageData> GhostedPiece(const Case& c, int rank, int ranks, vtkImageData* mri)
{
  const int whole[6] = { 0, c.Dims[0] - 1, 0, c.Dims[1] - 1, 0, c.Dims[2] - 1 };
  int owned[6], ghosted[6];
  rgmc_test::BlockPiece(whole, rank, ranks, owned, ghosted);
  vtkSmartPointer<vtkImageData> image;
  if (c.Field == "phantom")
  {
    vtkNew<vtkRGPhantomSource> phantom;
    phantom->SetDimensions(c.Dims[0], c.Dims[1], c.Dims[2]);
    phantom->UpdatePiece(rank, ranks, 1);
    image = phantom->GetOutput();
    return image; // the pipeline marks its ghost cells
  }
  if (c.Field == "sphere")
  {
    image = rgmc_test::MakeImage(ghosted, VTK_FLOAT, SphereValue);
  }
  else if (c.Field == "blobs")
  {
    image = BlobsImage(MakeBlobs(c.Dims, c.Dims[0] * 8), ghosted);
  }
  else
  {
    vtkNew<vtkExtractVOI> crop;
    crop->SetInputData(mri);
    crop->SetVOI(ghosted);
    crop->Update();
    image = crop->GetOutput();
  }
  if (ranks > 1)
  {
    rgmc_test::MarkGhostCells(image, owned);
  }
  return image;
}

/// The piece without its ghost layer, as ParaView's other filters get it.
vtkSmartPointer<vtkImageData> PlainPiece(vtkImageData* ghosted, const Case& c, int rank, int ranks)
{
  if (ranks == 1)
  {
    return ghosted;
  }
  const int whole[6] = { 0, c.Dims[0] - 1, 0, c.Dims[1] - 1, 0, c.Dims[2] - 1 };
  int owned[6], ghostedExtent[6];
  if (c.Field == "phantom")
  {
    // The phantom cuts its pieces itself, in slabs along z as the plugin's readers do.
    vtkNew<vtkInformation> request;
    request->Set(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER(), rank);
    request->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES(), ranks);
    rgmc::SlabPiece(request, whole, ghostedExtent, owned);
  }
  else
  {
    rgmc_test::BlockPiece(whole, rank, ranks, owned, ghostedExtent);
  }
  vtkNew<vtkExtractVOI> crop;
  crop->SetInputData(ghosted);
  crop->SetVOI(owned);
  crop->Update();
  vtkSmartPointer<vtkImageData> plain = crop->GetOutput();
  plain->GetPointData()->RemoveArray(vtkDataSetAttributes::GhostArrayName());
  plain->GetCellData()->RemoveArray(vtkDataSetAttributes::GhostArrayName());
  return plain;
}

// ---- methods --------------------------------------------------------------------------------

/// The filter of a method, ready to Update on this rank's pieces.
vtkSmartPointer<vtkAlgorithm> MakeMethod(const std::string& method, const Case& c,
  vtkImageData* ghosted, vtkImageData* plain, vtkPolyData* seededSurface,
  vtkMultiProcessController* controller)
{
  if (method == "seeded")
  {
    auto rg = vtkSmartPointer<vtkRGMarchingCubes>::New();
    rg->SetController(controller);
    rg->SetInputData(ghosted);
    rg->SetIsovalue(c.Isovalue);
    rg->AddSeedPoint(c.Seed[0], c.Seed[1], c.Seed[2]);
    rg->SetSeedSearchRadius(40);
    return rg;
  }
  if (method == "mc")
  {
    auto mc = vtkSmartPointer<vtkMarchingCubes>::New();
    mc->SetInputData(plain);
    mc->SetValue(0, c.Isovalue);
    mc->ComputeNormalsOn();
    mc->ComputeScalarsOff();
    return mc;
  }
  if (method == "fe")
  {
    auto fe = vtkSmartPointer<vtkFlyingEdges3D>::New();
    fe->SetInputData(plain);
    fe->SetValue(0, c.Isovalue);
    fe->ComputeNormalsOn();
    fe->ComputeScalarsOff();
    return fe;
  }
  if (method == "contour" || method == "contour+connectivity")
  {
    auto contour = vtkSmartPointer<vtkPVContourFilter>::New();
    contour->SetInputData(plain);
    contour->SetValue(0, c.Isovalue);
    contour->ComputeNormalsOn();
    contour->ComputeScalarsOff();
    if (method == "contour")
    {
      return contour;
    }
    auto connectivity = vtkSmartPointer<vtkPConnectivityFilter>::New();
    connectivity->SetInputConnection(contour->GetOutputPort());
    connectivity->SetExtractionModeToClosestPointRegion();
    connectivity->SetClosestPoint(c.Seed[0], c.Seed[1], c.Seed[2]);
    return connectivity;
  }
  if (method == "repair")
  {
    auto repair = vtkSmartPointer<vtkRGSeamRepair>::New();
    repair->SetController(controller);
    repair->SetInputData(seededSurface);
    repair->SetSmoothingMethod(vtkRGSeamRepair::LAPLACIAN);
    repair->SetNumberOfIterations(20);
    repair->SetRelaxationFactor(0.01);
    return repair;
  }
  if (method == "smooth")
  {
    auto smooth = vtkSmartPointer<vtkSmoothPolyDataFilter>::New();
    smooth->SetInputData(seededSurface);
    smooth->SetNumberOfIterations(20);
    smooth->SetRelaxationFactor(0.01);
    return smooth;
  }
  return nullptr;
}

vtkIdType Cells(vtkAlgorithm* filter)
{
  vtkDataSet* output = vtkDataSet::SafeDownCast(filter->GetOutputDataObject(0));
  return output ? output->GetNumberOfCells() : 0;
}

/// The pieces of `piece` gathered on rank 0 of `controller`, appended (rank 0 only).
vtkSmartPointer<vtkPolyData> GatherSurface(
  vtkMultiProcessController* controller, vtkPolyData* piece)
{
  std::vector<vtkSmartPointer<vtkDataObject>> pieces;
  vtkNew<vtkPolyData> mine;
  mine->SetPoints(piece->GetPoints());
  mine->SetPolys(piece->GetPolys());
  controller->Gather(mine, pieces, 0);
  auto all = vtkSmartPointer<vtkPolyData>::New();
  if (controller->GetLocalProcessId() != 0)
  {
    return all;
  }
  vtkNew<vtkAppendPolyData> append;
  for (auto& p : pieces)
  {
    if (auto pd = vtkPolyData::SafeDownCast(p))
    {
      append->AddInputData(pd);
    }
  }
  append->Update();
  all->ShallowCopy(append->GetOutput());
  return all;
}

/// The symmetric Hausdorff distance between the points of two surfaces.
double Hausdorff(vtkPolyData* a, vtkPolyData* b)
{
  if (a->GetNumberOfPoints() == 0 || b->GetNumberOfPoints() == 0)
  {
    return a->GetNumberOfPoints() == b->GetNumberOfPoints() ? 0.0 : -1.0;
  }
  vtkNew<vtkHausdorffDistancePointSetFilter> hausdorff;
  hausdorff->SetInputData(0, a);
  hausdorff->SetInputData(1, b);
  hausdorff->SetTargetDistanceMethodToPointToPoint();
  hausdorff->Update();
  return hausdorff->GetHausdorffDistance();
}

void PrintRow(const std::map<std::string, std::string>& fields)
{
  std::string line = "{";
  for (const auto& f : fields)
  {
    line += (line.size() > 1 ? ", \"" : "\"") + f.first + "\": " + f.second;
  }
  std::printf("%s}\n", line.c_str());
  std::fflush(stdout);
}

std::string Quote(const std::string& s)
{
  return "\"" + s + "\"";
}

std::string Number(double v)
{
  char text[64];
  std::snprintf(text, sizeof(text), "%.6g", v);
  return text;
}

// ---- one case at one rank count ----------------------------------------------------------------

/// What a case's 1-rank run leaves for the distances at other rank counts (world rank 0).
struct Serial
{
  vtkSmartPointer<vtkPolyData> Seeded, VTKLaplacian, VTKSinc;
};

void RunCase(const Case& c, vtkMultiProcessController* controller, int cores, vtkImageData* mri,
  Serial& serial)
{
  const int rank = controller->GetLocalProcessId();
  const int ranks = controller->GetNumberOfProcesses();
  vtkMultiProcessController::SetGlobalController(controller); // for ParaView's parallel filters

  double started = Now();
  vtkSmartPointer<vtkImageData> ghosted = GhostedPiece(c, rank, ranks, mri);
  vtkSmartPointer<vtkImageData> plain = PlainPiece(ghosted, c, rank, ranks);
  double make = Now() - started, makeMax = 0;
  controller->AllReduce(&make, &makeMax, 1, vtkCommunicator::MAX_OP);

  // The seeded surface once, for the methods that work on it (not timed).
  vtkNew<vtkPolyData> seeded;
  {
    auto rg = MakeMethod("seeded", c, ghosted, plain, nullptr, controller);
    rg->Update();
    seeded->ShallowCopy(rg->GetOutputDataObject(0));
  }
  const double spacing = ghosted->GetSpacing()[0];

  for (const std::string& method : c.Methods)
  {
    if (method == "mc" && ranks > 1)
    {
      continue;
    }
    std::vector<double> times;
    vtkIdType triangles = 0, busiest = 0;
    const double before = StatusMiB("VmRSS:");
    const bool peakKnown = ResetPeakMemory();
    // At least the asked repeats, and more of a short method (up to 0.5 s or 100 runs in all):
    // a millisecond timing taken 3 times is mostly noise. Every rank sees the same times, so all
    // stop together.
    double total = 0;
    for (int r = 0; r < c.Repeats || (total < 0.5 && r < 100); ++r)
    {
      vtkSmartPointer<vtkAlgorithm> filter =
        MakeMethod(method, c, ghosted, plain, seeded, controller);
      controller->Barrier();
      const double t0 = Now();
      filter->Update();
      double t = Now() - t0, tMax = 0;
      controller->AllReduce(&t, &tMax, 1, vtkCommunicator::MAX_OP);
      times.push_back(tMax);
      total += tMax;
      vtkIdType local = Cells(filter);
      controller->AllReduce(&local, &triangles, 1, vtkCommunicator::SUM_OP);
      controller->AllReduce(&local, &busiest, 1, vtkCommunicator::MAX_OP);
    }
    double memory[2] = { StatusMiB("VmHWM:"), StatusMiB("VmHWM:") - before }, memoryMax[2];
    controller->AllReduce(memory, memoryMax, 2, vtkCommunicator::MAX_OP);
    std::sort(times.begin(), times.end());
    if (rank == 0)
    {
      PrintRow({ { "case", Quote(c.Name) }, { "field", Quote(c.Field) },
        { "dims",
          "[" + std::to_string(c.Dims[0]) + ", " + std::to_string(c.Dims[1]) + ", " +
            std::to_string(c.Dims[2]) + "]" },
        { "ranks", std::to_string(ranks) }, { "oversubscribed", ranks > cores ? "true" : "false" },
        { "method", Quote(method) }, { "triangles", std::to_string(triangles) },
        { "busiest_rank_triangles", std::to_string(busiest) },
        { "min_seconds", Number(times.front()) },
        { "median_seconds", Number(times[times.size() / 2]) },
        { "repeats", std::to_string(times.size()) },
        { "peak_rss_mib", peakKnown ? Number(memoryMax[0]) : "null" },
        { "method_rss_mib", peakKnown ? Number(memoryMax[1]) : "null" },
        { "make_input_seconds", Number(makeMax) } });
    }
  }

  if (!c.Distances)
  {
    return;
  }
  // PASS: the distances, on rank 0 (not timed).
  vtkSmartPointer<vtkPolyData> surface = GatherSurface(controller, seeded);
  auto smoothed = [&](int method)
  {
    vtkNew<vtkRGSeamRepair> repair;
    repair->SetController(controller);
    repair->SetInputData(seeded);
    repair->SetSmoothingMethod(method);
    repair->SetNumberOfIterations(20);
    repair->SetRelaxationFactor(0.01);
#if !RGMC_VTK_SINC_HAS_WINDOW_FUNCTION
    repair->SetWindowFunction(vtkRGSeamRepair::HAMMING_WINDOW); // this VTK's only window
#endif
    repair->Update();
    return GatherSurface(controller, repair->GetOutput());
  };
  vtkSmartPointer<vtkPolyData> laplacian = smoothed(vtkRGSeamRepair::LAPLACIAN);
  vtkSmartPointer<vtkPolyData> sinc = smoothed(vtkRGSeamRepair::WINDOWED_SINC);
  if (rank != 0)
  {
    return;
  }
  if (ranks == 1)
  {
    serial.Seeded = surface;
    vtkNew<vtkSmoothPolyDataFilter> vtkLaplacian;
    vtkLaplacian->SetInputData(surface);
    vtkLaplacian->SetNumberOfIterations(20);
    vtkLaplacian->SetRelaxationFactor(0.01);
    vtkLaplacian->Update();
    serial.VTKLaplacian = vtkLaplacian->GetOutput();
    vtkNew<vtkWindowedSincPolyDataFilter> vtkSinc;
    vtkSinc->SetInputData(surface);
    vtkSinc->SetNumberOfIterations(20);
    vtkSinc->SetPassBand(0.1);
    vtkSinc->Update();
    serial.VTKSinc = vtkSinc->GetOutput();
  }
  if (!serial.Seeded)
  {
    return; // no 1-rank run to compare with
  }
  const std::pair<const char*, double> distances[] = {
    { "seeded surface vs 1 rank", Hausdorff(surface, serial.Seeded) },
    { "seam repair + Laplacian vs VTK's Laplacian of the 1-rank surface",
      Hausdorff(laplacian, serial.VTKLaplacian) },
    { "seam repair + windowed sinc vs VTK's windowed sinc of the 1-rank surface",
      Hausdorff(sinc, serial.VTKSinc) },
  };
  for (const auto& d : distances)
  {
    PrintRow({ { "case", Quote(c.Name) }, { "ranks", std::to_string(ranks) },
      { "distance", Quote(d.first) }, { "hausdorff", Number(d.second) },
      { "spacing", Number(spacing) } });
  }
}

/// Runs `work` on the first `ranks` processes of `world` with a controller of their own; the
/// others wait without using the processor until rank 0 says the work is done.
template <typename Work>
void OnFirstRanks(vtkMPIController* world, int ranks, Work&& work)
{
  const int rank = world->GetLocalProcessId();
  const bool working = rank < ranks;
  vtkSmartPointer<vtkMultiProcessController> group;
  group.TakeReference(world->PartitionController(working ? 0 : 1, rank));
  if (working)
  {
    work(group);
    if (rank == 0)
    {
      for (int other = ranks; other < world->GetNumberOfProcesses(); ++other)
      {
        int done = 1;
        world->Send(&done, 1, other, DoneTag);
      }
    }
  }
  else
  {
    auto* communicator = vtkMPICommunicator::SafeDownCast(world->GetCommunicator());
    vtkMPICommunicator::Request request;
    int done = 0;
    communicator->NoBlockReceive(&done, 1, 0, DoneTag, request);
    while (!request.Test())
    {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  }
  vtkMultiProcessController::SetGlobalController(world);
}

} // namespace

int main(int argc, char* argv[])
{
  vtkNew<vtkMPIController> world;
  world->Initialize(&argc, &argv);
  vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_WARNING); // no seam repair report lines
  vtkMultiProcessController::SetGlobalController(world);
  const int rank = world->GetLocalProcessId();
  const int size = world->GetNumberOfProcesses();

  Options opt;
  bool usage = false;
  for (int a = 1; a < argc; ++a)
  {
    const std::string arg = argv[a];
    const bool hasValue = a + 1 < argc;
    if (arg == "--cases" && hasValue)
    {
      opt.Cases = Split(argv[++a]);
    }
    else if (arg == "--ranks" && hasValue)
    {
      opt.Ranks.clear();
      for (const std::string& r : Split(argv[++a]))
      {
        opt.Ranks.push_back(std::atoi(r.c_str()));
      }
    }
    else if (arg == "--sweep" && hasValue)
    {
      opt.Sweep.clear();
      for (const std::string& n : Split(argv[++a]))
      {
        opt.Sweep.push_back(std::atoi(n.c_str()));
      }
    }
    else if (arg == "--repeats" && hasValue)
    {
      opt.Repeats = std::max(1, std::atoi(argv[++a]));
    }
    else if (arg == "--sweep-repeats" && hasValue)
    {
      opt.SweepRepeats = std::max(1, std::atoi(argv[++a]));
    }
    else if (arg == "--mri" && hasValue)
    {
      opt.Mri = argv[++a];
    }
    else if (arg == "--quick")
    {
      opt.Quick = true;
    }
    else
    {
      usage = true;
    }
  }
  for (int r : opt.Ranks)
  {
    usage = usage || r < 1 || r > size;
  }
  if (usage)
  {
    if (rank == 0)
    {
      std::cerr << "usage: mpiexec -n N rgmcEvaluation [--cases phantom256,phantom512,sphere512,"
                   "blobs,mri] [--ranks 1,2,4 (each at most N)] [--sweep 128,256,512,1024] "
                   "[--repeats R] [--sweep-repeats R] [--mri FILE.nii.gz] [--quick]\n";
    }
    world->Finalize();
    return 2;
  }
  const int cores = static_cast<int>(sysconf(_SC_NPROCESSORS_ONLN));
  const int scale = opt.Quick ? 4 : 1; // --quick: every size divided by 4

  const std::vector<std::string> table = { "mc", "seeded", "fe", "contour", "contour+connectivity",
    "repair", "smooth" };
  std::vector<Case> cases;
  for (const std::string& name : opt.Cases)
  {
    Case c;
    c.Name = name;
    c.Methods = table;
    c.Ranks = opt.Ranks;
    c.Repeats = opt.Repeats;
    c.Distances = true;
    if (name == "phantom256" || name == "phantom512")
    {
      const int n = (name == "phantom256" ? 256 : 512) / scale;
      c.Field = "phantom";
      c.Dims[0] = c.Dims[1] = c.Dims[2] = n;
      c.Isovalue = 400;
      c.Seed = { 0, 0, 105 }; // the top of the skull
    }
    else if (name == "sphere512")
    {
      const int n = 512 / scale;
      c.Field = "sphere";
      c.Dims[0] = c.Dims[1] = c.Dims[2] = n;
      c.Seed = { SphereCentre[0] + 12, SphereCentre[1], SphereCentre[2] };
    }
    else if (name == "blobs")
    {
      const int n = opt.BlobsSize / scale;
      c.Field = "blobs";
      c.Dims[0] = c.Dims[1] = c.Dims[2] = n;
      c.Isovalue = 0.3;
      // The seed: the centre of the highest blob (every rank draws the same blobs).
      std::vector<Blob> blobs = MakeBlobs(c.Dims, n * 8);
      const Blob& top = *std::max_element(blobs.begin(), blobs.end(),
        [](const Blob& a, const Blob& b) { return a.Height < b.Height; });
      c.Seed = { top.C[0], top.C[1], top.C[2] };
    }
    else if (name == "mri")
    {
      c.Field = "mri";
      // Between the scalp's intensity and the air's; not an integer, so that no sample of the
      // 8-bit data equals it (samples at the isovalue make non-manifold edges, as in any MC).
      c.Isovalue = 40.5;
      c.Seed = { 90, 108, 172 }; // above the vertex of the head, in the reader's index space
    }
    else
    {
      if (rank == 0)
      {
        std::cerr << "rgmcEvaluation: unknown case " << name << "\n";
      }
      world->Finalize();
      return 2;
    }
    cases.push_back(c);
  }
  // The sweep: the same sphere in ever larger empty volumes, on 1 rank.
  for (int n : opt.Sweep)
  {
    Case c;
    c.Name = "sphere-sweep-" + std::to_string(n);
    c.Field = "sphere";
    c.Dims[0] = c.Dims[1] = c.Dims[2] = n / scale < 80 ? 80 : n / scale;
    c.Seed = { SphereCentre[0] + 12, SphereCentre[1], SphereCentre[2] };
    c.Methods = { "seeded", "fe", "contour" };
    c.Ranks = { 1 };
    c.Repeats = opt.SweepRepeats;
    cases.push_back(c);
  }

  // The MRI, read by every rank (not timed; skipped when the file is missing).
  vtkSmartPointer<vtkImageData> mri;
  for (auto c = cases.begin(); c != cases.end();)
  {
    if (c->Field != "mri")
    {
      ++c;
      continue;
    }
    std::ifstream probe(opt.Mri);
    if (!probe)
    {
      if (rank == 0)
      {
        PrintRow({ { "skipped", Quote(c->Name) }, { "why", Quote("no file " + opt.Mri) } });
      }
      c = cases.erase(c);
      continue;
    }
    vtkNew<vtkNIFTIImageReader> reader;
    reader->SetFileName(opt.Mri.c_str());
    reader->Update();
    mri = reader->GetOutput();
    mri->GetPointData()->GetScalars()->SetName("MRI");
    int dims[3];
    mri->GetDimensions(dims);
    std::copy(dims, dims + 3, c->Dims);
    ++c;
  }

  if (rank == 0)
  {
    PrintRow({ { "processes", std::to_string(size) }, { "cores", std::to_string(cores) } });
  }
  for (const Case& c : cases)
  {
    Serial serial;
    for (int ranks : c.Ranks)
    {
      OnFirstRanks(world, ranks,
        [&](vtkMultiProcessController* group) { RunCase(c, group, cores, mri, serial); });
    }
  }
  world->Finalize();
  return 0;
}

// RGMC's decimation benchmark (not a test; `./rgmc evaluate --decimate` runs it):
//
//   mpiexec -n R rgmcDecimateBenchmark [--size 512] [--reduction 0.9] [--threads 1,2]
//                                      [--repeats 3] [--vtk 1] [--block 20000]
//                                      [--distance-repeats 0]
//
// The CT phantom's skull (`size`^3, seeded at 400 HU, Seam Repair with 20 Laplacian iterations)
// reduced by vtkRGDecimate on R ranks at each thread count, and, on one rank when --vtk is 1, by
// vtkQuadricDecimation, vtkDecimatePro (PreserveTopology on, so that it may not reach the
// target) and, where Debian's libmeshoptimizer-dev was found at configure time,
// meshopt_simplify (one thread, an error bound that never stops it before the target count) on
// the same merged mesh in the same run. For each: seconds (the slowest rank's, the fastest of
// `repeats`; vtkRGDecimate's with its distance report, and run in turn without it:
// seconds_without_distance, and the report's cost over the rest, distance_share), triangles, the
// symmetric Hausdorff and mean distances to the undecimated surface (sampled at the vertices of
// each surface, to the other surface, in voxels), the parts (sets of triangles joined through
// shared edges) and whether the output is closed (every edge in exactly two triangles, once each
// way). Each rank builds only its block of the volume. Prints one JSON object per line on rank 0.
// With --distance-repeats D > 0, also the distance report alone (rgmc::DecimationDistance on the
// last decimation's input and output, the fastest of D, at each thread count): a row to profile.
#include "rgmcBenchmark.h"        // Now, IntList
#include "rgmcDecimateDistance.h" // DecimationDistance
#include "rgmcDistributedData.h"  // BlockPiece, PhantomPiece, MarkGhostCells
#include "rgmcNearestDistances.h" // Nearest
#include "vtkRGDecimate.h"
#include "vtkRGMarchingCubes.h"
#include "vtkRGSeamRepair.h"

#include "vtkCellArray.h"
#include "vtkDecimatePro.h"
#include "vtkIdTypeArray.h"
#include "vtkImageData.h"
#include "vtkMPIController.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkQuadricDecimation.h"
#include "vtkSMPTools.h"

#ifdef RGMC_HAVE_MESHOPTIMIZER
#include <meshoptimizer.h>
#define RGMC_TEXT(x) #x
#define RGMC_VERSION_TEXT(v) RGMC_TEXT(v)
#define MESHOPT_VERSION_TEXT RGMC_VERSION_TEXT(MESHOPTIMIZER_VERSION)
#endif

#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

namespace
{

using rgmc_benchmark::Now;

/// The pieces of a distributed surface numbered as one mesh, merged on rank 0 (for measuring
/// only): points by global id.
vtkSmartPointer<vtkPolyData> Merge(vtkMultiProcessController* controller, vtkPolyData* piece)
{
  std::vector<vtkSmartPointer<vtkDataObject>> pieces;
  controller->Gather(piece, pieces, 0);
  auto merged = vtkSmartPointer<vtkPolyData>::New();
  if (controller->GetLocalProcessId() != 0)
  {
    return merged;
  }
  std::map<vtkIdType, std::array<double, 3>> points;
  std::vector<std::array<vtkIdType, 3>> triangles;
  for (auto& object : pieces)
  {
    vtkPolyData* pd = vtkPolyData::SafeDownCast(object);
    vtkIdTypeArray* ids = vtkIdTypeArray::SafeDownCast(pd->GetPointData()->GetGlobalIds());
    for (vtkIdType p = 0; p < pd->GetNumberOfPoints(); ++p)
    {
      std::array<double, 3> x;
      pd->GetPoint(p, x.data());
      points[ids->GetValue(p)] = x;
    }
    for (vtkIdType t = 0; t < pd->GetNumberOfCells(); ++t)
    {
      vtkIdType n;
      const vtkIdType* pts;
      pd->GetCellPoints(t, n, pts);
      triangles.push_back({ ids->GetValue(pts[0]), ids->GetValue(pts[1]), ids->GetValue(pts[2]) });
    }
  }
  vtkNew<vtkPoints> xyz;
  xyz->SetDataTypeToDouble();
  std::map<vtkIdType, vtkIdType> index;
  for (const auto& p : points)
  {
    index[p.first] = xyz->InsertNextPoint(p.second.data());
  }
  vtkNew<vtkCellArray> polys;
  for (const auto& t : triangles)
  {
    const vtkIdType ids[3] = { index[t[0]], index[t[1]], index[t[2]] };
    polys->InsertNextCell(3, ids);
  }
  merged->SetPoints(xyz);
  merged->SetPolys(polys);
  return merged;
}

/// The largest and mean distance from the vertices of `from` to the surface `to`.
void Distances(vtkPolyData* from, vtkPolyData* to, double& largest, double& mean)
{
  const rgmc_test::NearestDistances d = rgmc_test::Nearest(from, to);
  largest = d.Largest;
  mean = d.Mean;
}

/// Whether every edge is in exactly two triangles, once in each direction.
bool Closed(vtkPolyData* pd)
{
  std::vector<std::pair<vtkIdType, vtkIdType>> directed;
  for (vtkIdType t = 0; t < pd->GetNumberOfCells(); ++t)
  {
    vtkIdType n;
    const vtkIdType* pts;
    pd->GetCellPoints(t, n, pts);
    if (n != 3)
    {
      return false;
    }
    for (int k = 0; k < 3; ++k)
    {
      directed.emplace_back(pts[k], pts[(k + 1) % 3]);
    }
  }
  std::sort(directed.begin(), directed.end());
  for (std::size_t e = 0; e < directed.size(); ++e)
  {
    if (e > 0 && directed[e] == directed[e - 1])
    {
      return false;
    }
    const std::pair<vtkIdType, vtkIdType> back{ directed[e].second, directed[e].first };
    if (!std::binary_search(directed.begin(), directed.end(), back))
    {
      return false;
    }
  }
  return true;
}

/// How many parts `pd` falls into: triangles joined when they share an edge (admesh's count).
vtkIdType Parts(vtkPolyData* pd)
{
  const vtkIdType triangles = pd->GetNumberOfCells();
  std::vector<vtkIdType> parent(static_cast<std::size_t>(triangles));
  std::iota(parent.begin(), parent.end(), vtkIdType(0));
  auto root = [&parent](vtkIdType t)
  {
    while (parent[t] != t)
    {
      t = parent[t] = parent[parent[t]];
    }
    return t;
  };
  std::vector<std::array<vtkIdType, 3>> edges; // lower point, higher point, triangle
  for (vtkIdType t = 0; t < triangles; ++t)
  {
    vtkIdType n;
    const vtkIdType* pts;
    pd->GetCellPoints(t, n, pts);
    for (vtkIdType k = 0; k < n; ++k)
    {
      const vtkIdType a = pts[k], b = pts[(k + 1) % n];
      edges.push_back({ std::min(a, b), std::max(a, b), t });
    }
  }
  std::sort(edges.begin(), edges.end());
  for (std::size_t e = 1; e < edges.size(); ++e)
  {
    if (edges[e][0] == edges[e - 1][0] && edges[e][1] == edges[e - 1][1])
    {
      parent[root(edges[e][2])] = root(edges[e - 1][2]);
    }
  }
  vtkIdType parts = 0;
  for (vtkIdType t = 0; t < triangles; ++t)
  {
    parts += root(t) == t;
  }
  return parts;
}

#ifdef RGMC_HAVE_MESHOPTIMIZER
/// meshopt_simplify on `original` to (1 - reduction) of its triangles, the fastest of `repeats`
/// runs in `seconds`; the result with only the vertices its triangles use.
vtkSmartPointer<vtkPolyData> MeshoptSimplify(
  vtkPolyData* original, double reduction, int repeats, double& seconds)
{
  const vtkIdType points = original->GetNumberOfPoints(), cells = original->GetNumberOfCells();
  std::vector<float> xyz(static_cast<std::size_t>(3 * points));
  for (vtkIdType p = 0; p < points; ++p)
  {
    double x[3];
    original->GetPoint(p, x);
    for (int a = 0; a < 3; ++a)
    {
      xyz[3 * p + a] = static_cast<float>(x[a]);
    }
  }
  std::vector<unsigned int> indices;
  indices.reserve(static_cast<std::size_t>(3 * cells));
  for (vtkIdType t = 0; t < cells; ++t)
  {
    vtkIdType n;
    const vtkIdType* pts;
    original->GetCellPoints(t, n, pts);
    indices.insert(indices.end(),
      { static_cast<unsigned int>(pts[0]), static_cast<unsigned int>(pts[1]),
        static_cast<unsigned int>(pts[2]) });
  }
  const std::size_t target = 3 * static_cast<std::size_t>(std::llround((1 - reduction) * cells));
  std::vector<unsigned int> kept(indices.size());
  std::size_t count = 0;
  seconds = 1e300;
  for (int r = 0; r < std::max(1, repeats); ++r)
  {
    const double start = Now();
    count = meshopt_simplify(kept.data(), indices.data(), indices.size(), xyz.data(),
      static_cast<std::size_t>(points), 3 * sizeof(float), target, 1.0f, 0, nullptr);
    seconds = std::min(seconds, Now() - start);
  }
  std::map<unsigned int, vtkIdType> used;
  vtkNew<vtkPoints> out;
  out->SetDataTypeToDouble();
  vtkNew<vtkCellArray> polys;
  for (std::size_t i = 0; i < count; i += 3)
  {
    vtkIdType ids[3];
    for (int k = 0; k < 3; ++k)
    {
      auto at = used.find(kept[i + k]);
      if (at == used.end())
      {
        double x[3];
        original->GetPoint(kept[i + k], x);
        at = used.emplace(kept[i + k], out->InsertNextPoint(x)).first;
      }
      ids[k] = at->second;
    }
    polys->InsertNextCell(3, ids);
  }
  auto result = vtkSmartPointer<vtkPolyData>::New();
  result->SetPoints(out);
  result->SetPolys(polys);
  return result;
}
#endif

/// One JSON line for a decimated surface against the original.
std::string Row(const std::string& method, int ranks, int threads, double seconds,
  vtkPolyData* original, vtkPolyData* decimated, double voxel)
{
  double there, thereMean, back, backMean;
  Distances(decimated, original, there, thereMean);
  Distances(original, decimated, back, backMean);
  std::ostringstream os;
  os << "{\"method\": \"" << method << "\", \"ranks\": " << ranks << ", \"threads\": " << threads
     << ", \"seconds\": " << seconds << ", \"triangles_before\": " << original->GetNumberOfCells()
     << ", \"triangles\": " << decimated->GetNumberOfCells()
     << ", \"hausdorff_voxels\": " << std::max(there, back) / voxel
     << ", \"mean_voxels\": " << 0.5 * (thereMean + backMean) / voxel
     << ", \"parts\": " << Parts(decimated)
     << ", \"closed\": " << (Closed(decimated) ? "true" : "false") << "}";
  return os.str();
}

/// The distance report alone, the fastest of `repeats` on `threads` (a row on rank 0).
void TimeDistanceReport(vtkMultiProcessController* controller, vtkPolyData* input,
  vtkPolyData* output, int threads, int repeats)
{
  double best = 1e300, hausdorff = 0, mean = 0;
  vtkSMPTools::LocalScope(vtkSMPTools::Config{ threads, "STDThread", false },
    [&]()
    {
      rgmc::Ranks ranks(controller);
      for (int r = 0; r < repeats; ++r)
      {
        std::string problem;
        controller->Barrier();
        const double start = Now();
        rgmc::DecimationDistance(ranks, input, output, hausdorff, mean, problem);
        double mine = Now() - start, slowest = 0;
        controller->AllReduce(&mine, &slowest, 1, vtkCommunicator::MAX_OP);
        best = std::min(best, slowest);
      }
    });
  if (controller->GetLocalProcessId() == 0)
  {
    std::cout << "{\"method\": \"distance report\", \"ranks\": "
              << controller->GetNumberOfProcesses() << ", \"threads\": " << threads
              << ", \"seconds\": " << best << ", \"hausdorff\": " << hausdorff
              << ", \"mean\": " << mean << "}" << std::endl;
  }
}

} // namespace

int main(int argc, char* argv[])
{
  vtkNew<vtkMPIController> controller;
  controller->Initialize(&argc, &argv);
  vtkMultiProcessController::SetGlobalController(controller);
  const int rank = controller->GetLocalProcessId(), ranks = controller->GetNumberOfProcesses();
  int size = 512, repeats = 3, vtk = 1, distanceRepeats = 0;
  long long block = 20000;
  double reduction = 0.9;
  std::vector<int> threadCounts = { 1, 2 };
  for (int a = 1; a + 1 < argc; a += 2)
  {
    const std::string option = argv[a], value = argv[a + 1];
    if (option == "--size")
    {
      size = std::atoi(value.c_str());
    }
    else if (option == "--repeats")
    {
      repeats = std::atoi(value.c_str());
    }
    else if (option == "--reduction")
    {
      reduction = std::atof(value.c_str());
    }
    else if (option == "--threads")
    {
      threadCounts = rgmc_benchmark::IntList(value);
    }
    else if (option == "--block")
    {
      block = std::atoll(value.c_str());
    }
    else if (option == "--vtk")
    {
      vtk = std::atoi(value.c_str());
    }
    else if (option == "--distance-repeats")
    {
      distanceRepeats = std::atoi(value.c_str());
    }
  }

  // The skull, repaired and smoothed, on every rank's block.
  const int whole[6] = { 0, size - 1, 0, size - 1, 0, size - 1 };
  int owned[6], ghosted[6];
  rgmc_test::BlockPiece(whole, rank, ranks, owned, ghosted);
  vtkSmartPointer<vtkImageData> piece = rgmc_test::PhantomPiece(ghosted, size);
  if (ranks > 1)
  {
    rgmc_test::MarkGhostCells(piece, owned);
  }
  const double voxel = piece->GetSpacing()[0];
  vtkNew<vtkRGMarchingCubes> extract;
  extract->SetInputData(piece);
  extract->SetIsovalue(400);
  extract->AddSeedPoint(0, 0, 105);
  vtkNew<vtkRGSeamRepair> repair;
  repair->SetInputConnection(extract->GetOutputPort());
  repair->Update();
  auto repaired = vtkSmartPointer<vtkPolyData>::New();
  repaired->DeepCopy(repair->GetOutput());
  vtkSmartPointer<vtkPolyData> original = Merge(controller, repaired);

  vtkNew<vtkRGDecimate> decimate;
  decimate->SetInputData(repaired);
  decimate->SetTargetReduction(reduction);
  decimate->SetTrianglesPerBlock(block);
  for (int threads : threadCounts)
  {
    // With and without the distance report, in turn (the last run reports).
    double best[2] = { 1e300, 1e300 };
    vtkSMPTools::LocalScope(vtkSMPTools::Config{ threads, "STDThread", false },
      [&]()
      {
        for (int r = 0; r < repeats; ++r)
        {
          for (int report : { 0, 1 })
          {
            decimate->SetComputeDistance(report);
            controller->Barrier();
            const double start = Now();
            decimate->Update();
            double mine = Now() - start, slowest = 0;
            controller->AllReduce(&mine, &slowest, 1, vtkCommunicator::MAX_OP);
            best[report] = std::min(best[report], slowest);
          }
        }
      });
    vtkSmartPointer<vtkPolyData> result = Merge(controller, decimate->GetOutput());
    if (rank == 0)
    {
      std::string row = Row("RGDecimate", ranks, threads, best[1], original, result, voxel);
      std::ostringstream more;
      more << ", \"seconds_without_distance\": " << best[0]
           << ", \"distance_share\": " << (best[1] - best[0]) / best[0] << "}";
      std::cout << row.substr(0, row.size() - 1) << more.str() << std::endl;
    }
    if (distanceRepeats > 0)
    {
      TimeDistanceReport(controller, repaired, decimate->GetOutput(), threads, distanceRepeats);
    }
  }
  if (rank == 0 && ranks == 1 && vtk)
  {
    vtkNew<vtkQuadricDecimation> quadric;
    quadric->SetInputData(original);
    quadric->SetTargetReduction(reduction);
    const double quadricSeconds = rgmc_benchmark::FastestUpdate(1, quadric.Get());
    std::cout << Row("vtkQuadricDecimation", 1, 1, quadricSeconds, original, quadric->GetOutput(),
                   voxel)
              << std::endl;
    vtkNew<vtkDecimatePro> pro;
    pro->SetInputData(original);
    pro->SetTargetReduction(reduction);
    pro->PreserveTopologyOn();
    const double proSeconds = rgmc_benchmark::FastestUpdate(1, pro.Get());
    std::cout << Row("vtkDecimatePro", 1, 1, proSeconds, original, pro->GetOutput(), voxel)
              << std::endl;
#ifdef RGMC_HAVE_MESHOPTIMIZER
    double meshoptSeconds = 0;
    vtkSmartPointer<vtkPolyData> simplified =
      MeshoptSimplify(original, reduction, repeats, meshoptSeconds);
    std::cout << Row("meshopt_simplify " MESHOPT_VERSION_TEXT, 1, 1, meshoptSeconds, original,
                   simplified, voxel)
              << std::endl;
#endif
  }
  controller->Finalize();
  return 0;
}

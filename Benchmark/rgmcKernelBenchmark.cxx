// The kernel benchmark (./rgmc evaluate --kernel; not a test): where the time of one extraction
// goes, stage by stage, in ns per output triangle, against vtkFlyingEdges3D in the same run.
// Two volumes on one rank: the CT phantom (vtkRGPhantomSource, seeded on the skull) and a noisy
// CT-like head made here (int16: a skull shell with soft tissue, air, a separate head holder
// and Gaussian-like noise). For each thread count:
//   - the kernel alone (rgmc::SurfaceKernel over the image's samples): seed search, growth and
//     extraction, seeded and All Components;
//   - the filter (vtkRGMarchingCubes: input checks, ownership, the kernel, the decision and the
//     output arrays) in Seeded, Largest and All modes; "rest" is the filter's time minus the
//     kernel's stages (the checks, the decision, the output arrays): measured in separate runs,
//     it is a small difference of two minima and can come out slightly negative;
//   - vtkFlyingEdges3D with normals, the same isovalue, and again half a unit below the largest
//     sample (its scan of the volume; a surface only at the peaks): its time beyond the scan,
//     per triangle, is Flying Edges' own cost of a triangle, set against the seeded filter's.
// Then a dense surface (an int16 gyroid, --dense-size points per axis, 0 for none), where a
// triangle is all there is to pay for: the same comparison, seeded against Flying Edges' own.
// Minimum of the repeats; JSON on stdout, a summary on stderr.
//
//   rgmcKernelBenchmark [--size 512] [--ct-size 384] [--dense-size 256] [--threads 1,2]
//                       [--repeats 5] [--only seeded|all]
// --only runs the kernel's stages of one mode and nothing else (for a profiler: perf record).
#include "rgmcBenchmark.h"

#include "rgmcSurfaceKernel.h"

#include "vtkDataArrayRange.h"
#include "vtkDummyController.h"
#include "vtkFlyingEdges3D.h"
#include "vtkImageData.h"
#include "vtkMarchingCubesTriangleCases.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkRGMarchingCubes.h"
#include "vtkRGPhantomSource.h"
#include "vtkSMPTools.h"
#include "vtkShortArray.h"
#include "vtkSmartPointer.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

namespace
{

using rgmc_benchmark::FastestUpdate;
using rgmc_benchmark::IntList;
using rgmc_benchmark::Now;

/// A volume to extract from, with its isovalue and a seed on the structure (world).
struct Volume
{
  std::string Name;
  vtkSmartPointer<vtkImageData> Image;
  double Isovalue;
  double Seed[3];
};

Volume Phantom(int size)
{
  vtkNew<vtkRGPhantomSource> phantom;
  phantom->SetDimensions(size, size, size);
  phantom->Update();
  Volume v{ "phantom" + std::to_string(size), vtkSmartPointer<vtkImageData>::New(), 400.0,
    { 0, 0, 105 } };
  v.Image->DeepCopy(phantom->GetOutput());
  v.Image->GetPointData()->SetActiveScalars("HU");
  return v;
}

/// A noisy CT-like head, int16 HU, 1 mm voxels: air, an ellipsoidal head of soft tissue (40 HU)
/// inside a bone shell (about 1100 HU, 6 % of the radius thick, thinner at the top), and under
/// it a curved head holder (500 HU) apart from the head; noise of about 40 HU from a fixed
/// sequence (the same volume on every run). The structure at 300 HU: the skull shell.
Volume NoisyHead(int size)
{
  Volume v{ "noisy_head" + std::to_string(size), vtkSmartPointer<vtkImageData>::New(), 300.0,
    { 0, 0, 0 } };
  vtkImageData* image = v.Image;
  image->SetDimensions(size, size, size);
  image->SetSpacing(1, 1, 1);
  image->SetOrigin(-0.5 * (size - 1), -0.5 * (size - 1), -0.5 * (size - 1));
  vtkNew<vtkShortArray> hu;
  hu->SetName("HU");
  hu->SetNumberOfTuples(static_cast<vtkIdType>(size) * size * size);
  const double r = 0.40 * size; // the head's half-axes: r, 1.15 r, 0.95 r
  std::uint64_t state = 0x9E3779B97F4A7C15ull;
  auto noise = [&state]()
  {
    // The sum of 4 uniform numbers: roughly Gaussian, sd ~ 40 HU.
    double sum = 0;
    for (int n = 0; n < 4; ++n)
    {
      state = state * 6364136223846793005ull + 1442695040888963407ull;
      sum += static_cast<double>(state >> 11) / 9007199254740992.0 - 0.5;
    }
    return 138.0 * sum;
  };
  const double c = 0.5 * (size - 1);
  for (int k = 0; k < size; ++k)
  {
    for (int j = 0; j < size; ++j)
    {
      for (int i = 0; i < size; ++i)
      {
        const double x = (i - c) / r, y = (j - c) / (1.15 * r), z = (k - c) / (0.95 * r);
        const double d = std::sqrt(x * x + y * y + z * z);
        const double thickness = 0.06 * (1.0 - 0.3 * std::max(0.0, z));
        double value = -1000.0;
        if (d < 1.0 - thickness)
        {
          value = 40.0;
        }
        else if (d < 1.0)
        {
          value = 1100.0;
        }
        // The holder: a curved plate under the head's back (y), apart from the skull.
        const double h = std::sqrt(x * x + z * z * 0.8 + (y + 0.3) * (y + 0.3));
        if (y < -0.2 && h > 1.12 && h < 1.17 && std::abs(z) < 0.6)
        {
          value = 500.0;
        }
        const double s = value + noise();
        hu->SetValue(i + static_cast<vtkIdType>(size) * (j + static_cast<vtkIdType>(size) * k),
          static_cast<short>(std::lround(std::max(-1024.0, std::min(3000.0, s)))));
      }
    }
  }
  image->GetPointData()->SetScalars(hu);
  // The seed: on the top of the skull shell, inside the bone.
  v.Seed[2] = 0.95 * r * (1.0 - 0.5 * 0.06 * 0.7);
  return v;
}

/// A dense surface, to measure the cost of a triangle rather than of a scan: an int16 gyroid,
/// 1000 (sin x cos y + sin y cos z + sin z cos x) with `period` voxels per cell, at 0.5 (no
/// sample equals it). Its level set is one connected surface through the whole volume, about
/// 0.6 triangles a voxel at period 16, so a seed anywhere on it selects nearly every triangle
/// vtkFlyingEdges3D makes.
Volume Gyroid(int size, double period)
{
  Volume v{ "gyroid" + std::to_string(size), vtkSmartPointer<vtkImageData>::New(), 0.5,
    { 0, 0, 0 } };
  vtkImageData* image = v.Image;
  image->SetDimensions(size, size, size);
  vtkNew<vtkShortArray> values;
  values->SetName("Gyroid");
  values->SetNumberOfTuples(static_cast<vtkIdType>(size) * size * size);
  const double w = 2.0 * M_PI / period;
  for (int k = 0; k < size; ++k)
  {
    for (int j = 0; j < size; ++j)
    {
      for (int i = 0; i < size; ++i)
      {
        const double x = w * (i + 0.25), y = w * (j + 0.5), z = w * (k + 0.125);
        const double g =
          std::sin(x) * std::cos(y) + std::sin(y) * std::cos(z) + std::sin(z) * std::cos(x);
        values->SetValue(i + static_cast<vtkIdType>(size) * (j + static_cast<vtkIdType>(size) * k),
          static_cast<short>(std::lround(1000.0 * g)));
      }
    }
  }
  image->GetPointData()->SetScalars(values);
  for (int a = 0; a < 3; ++a)
  {
    v.Seed[a] = 0.5 * (size - 1); // the surface passes within period / 2 of any point
  }
  return v;
}

const rgmc::CaseTable& Table()
{
  static const rgmc::CaseTable table(&vtkMarchingCubesTriangleCases::GetCases()[0].edges[0]);
  return table;
}

/// The kernel's stages on the whole volume as one piece, as vtkRGMarchingCubes builds it.
struct Stages
{
  double Seed = 1e300, Growth = 1e300, Extraction = 1e300;
  long long Triangles = 0;
};

Stages KernelStages(const Volume& v, bool seeded, int repeats)
{
  vtkImageData* image = v.Image;
  int extent[6];
  image->GetExtent(extent);
  const rgmc::Grid grid(extent, extent);
  const rgmc::Ownership own({ grid.WholeCells() }, 0);
  rgmc::SurfaceOptions options;
  options.Isovalue = v.Isovalue;
  double origin[3], spacing[3];
  image->GetOrigin(origin);
  image->GetSpacing(spacing);
  for (int a = 0; a < 3; ++a)
  {
    options.IndexToWorld[a][a] = spacing[a];
    options.IndexToWorld[a][3] = origin[a];
    options.NormalToWorld[a][a] = 1.0 / spacing[a];
  }
  options.ParallelFor =
    [](std::int64_t count, const std::function<void(std::int64_t, std::int64_t)>& body)
  {
    vtkSMPTools::For(0, static_cast<vtkIdType>(count), 1,
      [&body](vtkIdType begin, vtkIdType end) { body(begin, end); });
  };
  double seedIndex[3];
  for (int a = 0; a < 3; ++a)
  {
    seedIndex[a] = (v.Seed[a] - origin[a]) / spacing[a];
  }
  auto* array = vtkShortArray::SafeDownCast(image->GetPointData()->GetScalars());
  const auto samples = vtk::DataArrayValueRange<1>(array);
  using Range = std::decay<decltype(samples)>::type;
  Stages best;
  for (int r = 0; r < repeats; ++r)
  {
    rgmc::SurfaceKernel<Range> kernel(Table(), grid, own, samples, options);
    double t0 = Now();
    std::int64_t key = -1;
    if (seeded)
    {
      const rgmc::SeedHit hit = kernel.NearestVertex(seedIndex, v.Seed, 10.0, spacing[0]);
      key = hit.Found ? hit.Key : -1;
    }
    const double t1 = Now();
    if (seeded && key >= 0)
    {
      kernel.GrowFromKey(key);
    }
    else if (!seeded)
    {
      kernel.GrowAll();
    }
    const double t2 = Now();
    kernel.Extract();
    const double t3 = Now();
    best.Seed = std::min(best.Seed, t1 - t0);
    best.Growth = std::min(best.Growth, t2 - t1);
    best.Extraction = std::min(best.Extraction, t3 - t2);
    best.Triangles = kernel.Mesh().NumberOfTriangles();
  }
  return best;
}

double FilterSeconds(const Volume& v, int mode, int repeats, long long& triangles)
{
  vtkNew<vtkRGMarchingCubes> rg;
  rg->SetInputData(v.Image);
  rg->SetIsovalue(v.Isovalue);
  rg->SetExtractionMode(mode);
  if (mode == vtkRGMarchingCubes::SEEDED)
  {
    rg->AddSeedPoint(v.Seed[0], v.Seed[1], v.Seed[2]);
  }
  const double seconds = FastestUpdate(repeats, rg.Get());
  triangles = rg->GetOutput()->GetNumberOfCells();
  return seconds;
}

double FlyingEdgesSeconds(const Volume& v, int repeats, long long& triangles)
{
  vtkNew<vtkFlyingEdges3D> flying;
  flying->SetInputData(v.Image);
  flying->SetValue(0, v.Isovalue);
  flying->ComputeNormalsOn();
  flying->ComputeScalarsOff();
  const double seconds = FastestUpdate(repeats, flying.Get());
  triangles = flying->GetOutput()->GetNumberOfCells();
  return seconds;
}

/// vtkFlyingEdges3D's time, about, for its scan of the volume alone: at half a unit below the
/// largest sample, within the data's range (it passes over every row) but with a surface only
/// in the few cubes at the peaks.
double FlyingEdgesScanSeconds(const Volume& v, int repeats, long long& triangles)
{
  Volume peaks = v;
  peaks.Isovalue = v.Image->GetPointData()->GetScalars()->GetRange()[1] - 0.5;
  return FlyingEdgesSeconds(peaks, repeats, triangles);
}

double Ns(double seconds, long long triangles)
{
  return triangles > 0 ? 1e9 * seconds / static_cast<double>(triangles) : 0.0;
}

/// The cost of a triangle on the dense surface, at the current thread count, as JSON: Flying
/// Edges' own (its time minus its time at an isovalue only the peaks' samples reach, which is
/// about its scan of the volume alone, per triangle more) against the seeded kernel's and
/// filter's (which read only the cubes the surface passes through: all their time counts).
std::string DenseRun(const Volume& v, int threads, int repeats)
{
  long long feTriangles = 0, noTriangles = 0, seededTriangles = 0;
  const double fe = FlyingEdgesSeconds(v, repeats, feTriangles);
  const double scan = FlyingEdgesScanSeconds(v, repeats, noTriangles);
  const Stages stages = KernelStages(v, true, repeats);
  const double seeded = FilterSeconds(v, vtkRGMarchingCubes::SEEDED, repeats, seededTriangles);
  const double feOwn = Ns(fe - scan, feTriangles - noTriangles);
  const double kernel = Ns(stages.Seed + stages.Growth + stages.Extraction, stages.Triangles);
  std::ostringstream json;
  json << "{\"volume\": \"" << v.Name << "\", \"threads\": " << threads
       << ", \"flying_edges\": " << fe << ", \"flying_edges_scan\": " << scan
       << ", \"flying_edges_triangles\": " << feTriangles
       << ", \"flying_edges_scan_triangles\": " << noTriangles
       << ", \"flying_edges_own_ns_per_triangle\": " << feOwn << ", \"seeded\": " << seeded
       << ", \"seeded_triangles\": " << seededTriangles
       << ", \"seeded_ns_per_triangle\": {\"growth\": " << Ns(stages.Growth, stages.Triangles)
       << ", \"extraction\": " << Ns(stages.Extraction, stages.Triangles)
       << ", \"kernel\": " << kernel << ", \"total\": " << Ns(seeded, seededTriangles)
       << "}, \"seeded_vs_flying_edges_own\": " << Ns(seeded, seededTriangles) / feOwn
       << ", \"seeded_kernel_vs_flying_edges_own\": " << kernel / feOwn << "}";
  std::cerr << v.Name << ", " << threads << " thread(s): flying edges " << fe << " s ("
            << feTriangles << " triangles), its scan alone " << scan << " s (" << noTriangles
            << " triangles): " << feOwn << " ns/triangle of its own; seeded " << seeded << " s ("
            << seededTriangles << " triangles, " << Ns(seeded, seededTriangles)
            << " ns/triangle; kernel " << kernel << ": growth "
            << Ns(stages.Growth, stages.Triangles) << ", extraction "
            << Ns(stages.Extraction, stages.Triangles) << ")\n";
  return json.str();
}

} // namespace

int main(int argc, char* argv[])
{
  int size = 512, ctSize = 384, denseSize = 256, repeats = 5;
  std::vector<int> threadCounts = { 1, 2 };
  std::string only;
  for (int a = 1; a + 1 < argc; a += 2)
  {
    const std::string arg = argv[a];
    if (arg == "--size")
    {
      size = std::atoi(argv[a + 1]);
    }
    else if (arg == "--ct-size")
    {
      ctSize = std::atoi(argv[a + 1]);
    }
    else if (arg == "--dense-size")
    {
      denseSize = std::atoi(argv[a + 1]);
    }
    else if (arg == "--repeats")
    {
      repeats = std::atoi(argv[a + 1]);
    }
    else if (arg == "--only" &&
      (std::string(argv[a + 1]) == "seeded" || std::string(argv[a + 1]) == "all"))
    {
      only = argv[a + 1];
    }
    else if (arg == "--threads")
    {
      threadCounts = IntList(argv[a + 1]);
    }
    else
    {
      std::cerr << "usage: rgmcKernelBenchmark [--size N] [--ct-size N] [--dense-size N] "
                   "[--threads 1,2] [--repeats N] [--only seeded|all]\n";
      return 2;
    }
  }
  if (argc % 2 == 0)
  {
    std::cerr << "rgmcKernelBenchmark: option " << argv[argc - 1] << " has no value\n";
    return 2;
  }
  vtkNew<vtkDummyController> single;
  vtkMultiProcessController::SetGlobalController(single);

  std::vector<Volume> volumes;
  if (size > 0)
  {
    volumes.push_back(Phantom(size));
  }
  if (ctSize > 0)
  {
    volumes.push_back(NoisyHead(ctSize));
  }
  std::ostringstream json;
  json << "{\n  \"repeats\": " << repeats << ",\n  \"runs\": [";
  bool firstRun = true;
  for (const Volume& v : volumes)
  {
    for (const int threads : threadCounts)
    {
      vtkSMPTools::LocalScope(vtkSMPTools::Config{ threads, "STDThread", false },
        [&]()
        {
          if (!only.empty())
          {
            const Stages stages = KernelStages(v, only == "seeded", repeats);
            std::cerr << v.Name << ", " << threads << " thread(s), " << only << ": seed "
                      << stages.Seed << " s, growth " << stages.Growth << " s, extraction "
                      << stages.Extraction << " s, " << stages.Triangles << " triangles\n";
            return;
          }
          long long feTriangles = 0, seededTriangles = 0, largestTriangles = 0, allTriangles = 0;
          long long peakTriangles = 0;
          const double fe = FlyingEdgesSeconds(v, repeats, feTriangles);
          const double scan = FlyingEdgesScanSeconds(v, repeats, peakTriangles);
          const double feOwn = Ns(fe - scan, feTriangles - peakTriangles);
          const Stages seededStages = KernelStages(v, true, repeats);
          const Stages allStages = KernelStages(v, false, repeats);
          const double seeded =
            FilterSeconds(v, vtkRGMarchingCubes::SEEDED, repeats, seededTriangles);
          const double largest =
            FilterSeconds(v, vtkRGMarchingCubes::LARGEST_COMPONENT, repeats, largestTriangles);
          const double all =
            FilterSeconds(v, vtkRGMarchingCubes::ALL_COMPONENTS, repeats, allTriangles);
          const double seededRest =
            seeded - seededStages.Seed - seededStages.Growth - seededStages.Extraction;
          const double allRest = all - allStages.Growth - allStages.Extraction;
          json << (firstRun ? "" : ",") << "\n    {\"volume\": \"" << v.Name
               << "\", \"threads\": " << threads << ", \"backend\": \"" << vtkSMPTools::GetBackend()
               << "\", \"flying_edges\": " << fe << ", \"flying_edges_triangles\": " << feTriangles
               << ", \"seeded\": " << seeded << ", \"seeded_triangles\": " << seededTriangles
               << ", \"seeded_ns_per_triangle\": {\"seed\": "
               << Ns(seededStages.Seed, seededTriangles)
               << ", \"growth\": " << Ns(seededStages.Growth, seededTriangles)
               << ", \"extraction\": " << Ns(seededStages.Extraction, seededTriangles)
               << ", \"rest\": " << Ns(seededRest, seededTriangles)
               << ", \"total\": " << Ns(seeded, seededTriangles) << "}, \"largest\": " << largest
               << ", \"largest_triangles\": " << largestTriangles << ", \"all\": " << all
               << ", \"all_triangles\": " << allTriangles
               << ", \"all_ns_per_triangle\": {\"growth\": " << Ns(allStages.Growth, allTriangles)
               << ", \"extraction\": " << Ns(allStages.Extraction, allTriangles)
               << ", \"rest\": " << Ns(allRest, allTriangles)
               << ", \"total\": " << Ns(all, allTriangles)
               << "}, \"flying_edges_ns_per_triangle\": " << Ns(fe, feTriangles)
               << ", \"flying_edges_scan\": " << scan
               << ", \"flying_edges_scan_triangles\": " << peakTriangles
               << ", \"flying_edges_own_ns_per_triangle\": " << feOwn
               << ", \"seeded_vs_flying_edges_own\": " << Ns(seeded, seededTriangles) / feOwn
               << ", \"seeded_vs_flying_edges\": " << seeded / fe
               << ", \"largest_vs_flying_edges\": " << largest / fe
               << ", \"all_vs_flying_edges\": " << all / fe << "}";
          firstRun = false;
          std::cerr << v.Name << ", " << threads << " thread(s): flying edges " << fe << " s ("
                    << feTriangles << " triangles, " << Ns(fe, feTriangles) << " ns/triangle, "
                    << feOwn << " of its own beyond its scan, " << scan << " s); seeded " << seeded
                    << " s (" << seededTriangles << " triangles, " << Ns(seeded, seededTriangles)
                    << " ns/triangle: seed " << Ns(seededStages.Seed, seededTriangles)
                    << ", growth " << Ns(seededStages.Growth, seededTriangles) << ", extraction "
                    << Ns(seededStages.Extraction, seededTriangles) << ", rest "
                    << Ns(seededRest, seededTriangles) << "), " << seeded / fe
                    << "x flying edges; largest " << largest << " s (" << largest / fe << "x); all "
                    << all << " s (" << all / fe << "x; growth "
                    << Ns(allStages.Growth, allTriangles) << ", extraction "
                    << Ns(allStages.Extraction, allTriangles) << ", rest "
                    << Ns(allRest, allTriangles) << " ns/triangle)\n";
        });
    }
  }
  json << "\n  ],\n  \"dense\": [";
  if (denseSize > 0 && only.empty())
  {
    const Volume dense = Gyroid(denseSize, 16.0);
    bool first = true;
    for (const int threads : threadCounts)
    {
      vtkSMPTools::LocalScope(vtkSMPTools::Config{ threads, "STDThread", false },
        [&]()
        {
          json << (first ? "" : ",") << "\n    " << DenseRun(dense, threads, repeats);
          first = false;
        });
    }
  }
  json << "\n  ]\n}\n";
  std::cout << json.str();
  return 0;
}

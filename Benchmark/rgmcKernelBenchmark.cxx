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
//                       [--repeats 5] [--only seeded|all|floor]
// --only runs the kernel's stages of one mode and nothing else (for a profiler: perf record).
// --only floor sets the seeded kernel's growth and extraction, on one thread, against the least
// that growth and extraction node by node can do on the same volume from the same seed vertex
// (GrowthFloor, ExtractionFloor): what the kernel's own machinery (tiles in rounds, chunks,
// keys, components, ports, degenerate cubes) costs beyond the work any such design must do.
#include "rgmcBenchmark.h"
#include "rgmcBenchmarkVolumes.h"

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
#include <unordered_map>
#include <vector>

namespace
{

using rgmc_benchmark::FastestUpdate;
using rgmc_benchmark::Gyroid;
using rgmc_benchmark::IntList;
using rgmc_benchmark::NoisyHead;
using rgmc_benchmark::Now;
using rgmc_benchmark::Phantom;
using rgmc_benchmark::Volume;

const rgmc::CaseTable& Table()
{
  static const rgmc::CaseTable table(&vtkMarchingCubesTriangleCases::GetCases()[0].edges[0]);
  return table;
}

/// The kernel's stages on the whole volume as one piece, as vtkRGMarchingCubes builds it.
struct Stages
{
  double Seed = 1e300, Growth = 1e300, Extraction = 1e300;
  long long Triangles = 0, Vertices = 0;
  std::int64_t SeedKey = -1; // the seed vertex (seeded), -1 when none was found
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
    best.SeedKey = key;
    best.Vertices = kernel.Mesh().NumberOfPoints();
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

/// The int16 samples of a volume, as the floors read them.
struct Int16Samples
{
  explicit Int16Samples(const Volume& v)
  {
    v.Image->GetDimensions(this->Dims);
    this->Values =
      vtkShortArray::SafeDownCast(v.Image->GetPointData()->GetScalars())->GetPointer(0);
    this->Sy = this->Dims[0];
    this->Sz = this->Sy * this->Dims[1];
  }
  std::int64_t Index(int i, int j, int k) const { return i + this->Sy * j + this->Sz * k; }

  int Dims[3];
  const short* Values;
  std::int64_t Sy, Sz; // strides of j and k
};

/// A node of the least growth: a cube and one of its case's sheets.
struct FloorNode
{
  int I, J, K;
  std::uint8_t Case, Sheet;
};

/// What the least growth node by node found, and how fast.
struct Floor
{
  double Seconds = 1e300;    // with each cube's case made from its 8 samples
  double CasesReady = 1e300; // with each cube's case looked up, made before the clock
  long long Triangles = 0;
  std::vector<FloorNode> Nodes; // in the order found
};

/// The least that growth node by node can do: a breadth-first search over the (cube, sheet)
/// nodes of the seeded component with growth's steps (the 3 other cubes around each of a
/// node's edges, EdgeNeighbourTable) and found-bits in 32^3 tiles, nothing else (no ranks,
/// tiles' rounds, components, keys or degenerate cubes: a sample equal to the isovalue counts
/// as above it, so the component can differ from the filter's where such samples join
/// surfaces). Its seed: the nodes that have the seeded filter's seed vertex (`seedKey`, on
/// an edge or a grid point). Int16 samples, one thread, memory paged in before the clock starts.
/// Twice: each cube's case made from its samples when visited, and looked up in a table of every
/// cube's case (tile by tile, as the bits) made beforehand, which is the least a node-by-node
/// design can pay however it gets its cases.
Floor GrowthFloor(const Volume& v, std::int64_t seedKey, int repeats)
{
  const Int16Samples volume(v);
  int extent[6], seedPoint[3], seedAxis;
  v.Image->GetExtent(extent);
  rgmc::Grid(extent, extent).Decode(seedKey, seedPoint, seedAxis);
  for (int a = 0; a < 3; ++a)
  {
    seedPoint[a] -= extent[2 * a];
  }
  const std::int64_t sy = volume.Sy, sz = volume.Sz;
  const int above = static_cast<int>(std::ceil(v.Isovalue)); // samples >= it are inside
  auto caseOf = [=](int i, int j, int k)
  {
    const short* s = volume.Values + volume.Index(i, j, k);
    return (s[0] >= above) | (s[1] >= above) << 1 | (s[sy + 1] >= above) << 2 |
      (s[sy] >= above) << 3 | (s[sz] >= above) << 4 | (s[sz + 1] >= above) << 5 |
      (s[sz + sy + 1] >= above) << 6 | (s[sz + sy] >= above) << 7;
  };
  // Cubes along each axis.
  const int nx = volume.Dims[0] - 1, ny = volume.Dims[1] - 1, nz = volume.Dims[2] - 1;
  auto inside = [=](int i, int j, int k)
  { return i >= 0 && j >= 0 && k >= 0 && i < nx && j < ny && k < nz; };
  const std::int64_t tx = (nx + 31) / 32, ty = (ny + 31) / 32, tz = (nz + 31) / 32;
  auto cubeOf = [=](int i, int j, int k) // a cube's place in tile order
  {
    return ((i >> 5) + tx * ((j >> 5) + ty * (k >> 5))) * 32768 + (i & 31) +
      32 * ((j & 31) + 32 * (k & 31));
  };
  const rgmc::CaseTable& table = Table();
  Floor result;
  std::vector<std::uint64_t> found(static_cast<std::size_t>(tx * ty * tz * 512), 0);
  std::vector<FloorNode> queue;
  auto search = [&](auto caseAt)
  {
    queue.clear();
    std::fill(found.begin(), found.end(), 0);
    std::unordered_map<std::int64_t, unsigned> sheetsFound; // cubes of several sheets
    auto record = [&](int i, int j, int k, int c, int sheet)
    {
      const std::int64_t bit = cubeOf(i, j, k);
      std::uint64_t& word = found[bit >> 6];
      if ((word >> (bit & 63)) & 1)
      {
        return;
      }
      bool allFound = true; // the cube's bit is set once all its sheets are found
      if (table[c].NumSheets > 1)
      {
        unsigned& mask = sheetsFound[bit];
        if ((mask >> sheet) & 1)
        {
          return;
        }
        mask |= 1u << sheet;
        allFound = mask == (1u << table[c].NumSheets) - 1;
      }
      if (allFound)
      {
        word |= std::uint64_t(1) << (bit & 63);
      }
      queue.push_back(FloorNode{ i, j, k, std::uint8_t(c), std::uint8_t(sheet) });
    };
    rgmc::ForCubesAround(seedPoint, seedAxis,
      [&](int i, int j, int k, int edge)
      {
        if (!inside(i, j, k))
        {
          return;
        }
        const int c = caseAt(i, j, k);
        for (int sheet = 0; sheet < table[c].NumSheets; ++sheet)
        {
          if (edge < 0 || table[c].EdgeSheet[edge] == sheet)
          {
            record(i, j, k, c, sheet);
          }
        }
      });
    long long made = 0;
    for (std::size_t head = 0; head < queue.size(); ++head)
    {
      const FloorNode n = queue[head];
      const rgmc::CaseEntry& entry = table[n.Case];
      for (int t = 0; t < entry.NumTriangles; ++t)
      {
        made += entry.TriangleSheet[t] == n.Sheet;
      }
      for (unsigned edges = entry.SheetEdges[n.Sheet]; edges; edges &= edges - 1)
      {
        for (const rgmc::EdgeNeighbour& step : rgmc::EdgeNeighbourTable[__builtin_ctz(edges)])
        {
          const int i = n.I + step.Offset[0], j = n.J + step.Offset[1], k = n.K + step.Offset[2];
          if (!inside(i, j, k))
          {
            continue;
          }
          const std::int64_t bit = cubeOf(i, j, k);
          if ((found[bit >> 6] >> (bit & 63)) & 1)
          {
            continue;
          }
          const int c = caseAt(i, j, k);
          record(i, j, k, c, table[c].EdgeSheet[step.Edge]);
        }
      }
    }
    result.Triangles = made;
  };
  auto fastest = [&](auto caseAt)
  {
    double best = 1e300;
    for (int r = 0; r <= repeats; ++r) // the first run only sizes the queue
    {
      const double t0 = Now();
      search(caseAt);
      if (r > 0)
      {
        best = std::min(best, Now() - t0);
      }
    }
    return best;
  };
  result.Seconds = fastest(caseOf);
  std::vector<std::uint8_t> cases(static_cast<std::size_t>(tx * ty * tz * 32768), 0);
  for (int k = 0; k < nz; ++k)
  {
    for (int j = 0; j < ny; ++j)
    {
      for (int i = 0; i < nx; ++i)
      {
        cases[cubeOf(i, j, k)] = static_cast<std::uint8_t>(caseOf(i, j, k));
      }
    }
  }
  const std::uint8_t* ready = cases.data();
  result.CasesReady = fastest([=](int i, int j, int k) { return int(ready[cubeOf(i, j, k)]); });
  result.Nodes = std::move(queue);
  return result;
}

/// The least that extraction can do with the nodes of GrowthFloor: the nodes sorted by slab;
/// each node's triangles, their vertices found or made through slots of the edges in two
/// planes of grid points and the slab between (cleared where used); each new vertex's position
/// and normal as vtkMarchingCubes computes them (from the lower end of its edge, the gradients'
/// central differences interpolated, in double) written to float arrays, the triangles to an
/// id array. Nothing else (no keys, components, ports, chunks, threads or joins). One thread;
/// all memory allocated and paged in before the clock starts. Returns the seconds (the minimum
/// of the repeats); `vertices` is how many it made.
double ExtractionFloor(const Volume& v, const Floor& growth, int repeats, long long& vertices)
{
  const Int16Samples volume(v);
  const int* dims = volume.Dims;
  const short* samples = volume.Values;
  double origin[3], spacing[3];
  v.Image->GetOrigin(origin);
  v.Image->GetSpacing(spacing);
  const std::vector<FloorNode>& found = growth.Nodes;
  auto gradient = [&](int i, int j, int k, double g[3])
  {
    // Central differences, one-sided on the volume's border (the index clamped).
    const int p[3] = { i, j, k };
    const std::int64_t stride[3] = { 1, volume.Sy, volume.Sz };
    const std::int64_t at = volume.Index(i, j, k);
    for (int a = 0; a < 3; ++a)
    {
      const std::int64_t lo = p[a] > 0 ? at - stride[a] : at;
      const std::int64_t hi = p[a] < dims[a] - 1 ? at + stride[a] : at;
      const double scale = (p[a] > 0 && p[a] < dims[a] - 1) ? 0.5 : 1.0;
      g[a] = scale * (static_cast<double>(samples[lo]) - static_cast<double>(samples[hi]));
    }
  };
  const rgmc::CaseTable& table = Table();
  const std::int64_t nx = dims[0], ny = dims[1];
  // Per cube edge: its slots' array (0: the lower plane's x and y edges, 1: the upper plane's,
  // 2: the slab's z edges) and its slot's offset from the cube's.
  int layerOf[12];
  std::int64_t slotOffset[12];
  for (int e = 0; e < 12; ++e)
  {
    const int axis = rgmc::CubeEdgeAxis[e];
    const int* p = rgmc::CornerOffset[rgmc::EdgeCorners[e][0]];
    layerOf[e] = axis == 2 ? 2 : p[2];
    slotOffset[e] = axis == 2 ? p[0] + nx * p[1] : 2 * (p[0] + nx * p[1]) + axis;
  }
  std::vector<std::int32_t> layers[3] = { std::vector<std::int32_t>(2 * nx * ny, -1),
    std::vector<std::int32_t>(2 * nx * ny, -1), std::vector<std::int32_t>(nx * ny, -1) };
  std::vector<std::int64_t> touched[3];
  for (auto& t : touched)
  {
    t.reserve(static_cast<std::size_t>(2 * nx * ny));
  }
  std::vector<FloorNode> sorted(found.size());
  std::vector<std::int64_t> start(static_cast<std::size_t>(dims[2]) + 1), next;
  const std::size_t numTriangles = static_cast<std::size_t>(growth.Triangles);
  // Each vertex belongs to at least one triangle that has 2 others: at most 3 per triangle.
  std::vector<float> points(9 * numTriangles, 1.0f), normals(9 * numTriangles, 1.0f);
  std::vector<std::int32_t> triangles(3 * numTriangles, 0);
  double best = 1e300;
  for (int r = 0; r < repeats; ++r)
  {
    const double t0 = Now();
    std::fill(start.begin(), start.end(), 0);
    for (const FloorNode& n : found)
    {
      ++start[n.K + 1];
    }
    for (int k = 0; k < dims[2]; ++k)
    {
      start[k + 1] += start[k];
    }
    next.assign(start.begin(), start.end() - 1);
    for (const FloorNode& n : found)
    {
      sorted[next[n.K]++] = n;
    }
    std::int32_t* slots[3] = { layers[0].data(), layers[1].data(), layers[2].data() };
    std::int32_t made = 0;
    std::int64_t t3 = 0;
    for (int k = 0; k + 1 < dims[2]; ++k)
    {
      for (std::int64_t s = start[k]; s < start[k + 1]; ++s)
      {
        const FloorNode& n = sorted[s];
        const rgmc::CaseEntry& entry = table[n.Case];
        const std::int64_t cube = n.I + nx * n.J;
        for (int t = 0; t < entry.NumTriangles; ++t)
        {
          if (entry.TriangleSheet[t] != n.Sheet)
          {
            continue;
          }
          for (int c = 0; c < 3; ++c)
          {
            const int e = entry.Triangles[t][c];
            const int layer = layerOf[e];
            const std::int64_t slot = (layer == 2 ? cube : 2 * cube) + slotOffset[e];
            std::int32_t id = slots[layer][slot];
            if (id < 0)
            {
              id = made++;
              slots[layer][slot] = id;
              touched[layer].push_back(slot);
              const int axis = rgmc::CubeEdgeAxis[e];
              const int* o = rgmc::CornerOffset[rgmc::EdgeCorners[e][0]];
              int p[3] = { n.I + o[0], n.J + o[1], n.K + o[2] };
              int q[3] = { p[0], p[1], p[2] };
              ++q[axis];
              const double sLo = samples[volume.Index(p[0], p[1], p[2])];
              const double sHi = samples[volume.Index(q[0], q[1], q[2])];
              const double along = (v.Isovalue - sLo) / (sHi - sLo);
              double g0[3], g1[3], w[3];
              gradient(p[0], p[1], p[2], g0);
              gradient(q[0], q[1], q[2], g1);
              for (int a = 0; a < 3; ++a)
              {
                const double index = p[a] + (a == axis ? along : 0.0);
                points[3 * id + a] = static_cast<float>(origin[a] + spacing[a] * index);
                w[a] = (g0[a] + along * (g1[a] - g0[a])) / spacing[a];
              }
              const double length = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
              for (int a = 0; a < 3; ++a)
              {
                normals[3 * id + a] = static_cast<float>(length > 0.0 ? w[a] / length : w[a]);
              }
            }
            triangles[t3++] = id;
          }
        }
      }
      // The upper plane becomes the lower one; the slab's z edges are done.
      for (const int layer : { 0, 2 })
      {
        for (const std::int64_t slot : touched[layer])
        {
          slots[layer][slot] = -1;
        }
        touched[layer].clear();
      }
      std::swap(slots[0], slots[1]);
      std::swap(touched[0], touched[1]);
    }
    for (const std::int64_t slot : touched[0])
    {
      slots[0][slot] = -1;
    }
    touched[0].clear();
    best = std::min(best, Now() - t0);
    vertices = made;
  }
  return best;
}

/// --only floor: the seeded kernel's growth and extraction against GrowthFloor and
/// ExtractionFloor on the same volume, one thread.
void FloorRun(const Volume& v, int repeats)
{
  if (!vtkShortArray::SafeDownCast(v.Image->GetPointData()->GetScalars()))
  {
    std::cerr << v.Name << ": the floors read int16 samples only\n";
    return;
  }
  const Stages stages = KernelStages(v, true, repeats);
  if (stages.SeedKey < 0)
  {
    std::cerr << v.Name << ": no surface near the seed\n";
    return;
  }
  const Floor floor = GrowthFloor(v, stages.SeedKey, repeats);
  long long floorVertices = 0;
  const double extraction = ExtractionFloor(v, floor, repeats, floorVertices);
  std::cerr << v.Name << ", 1 thread: growth " << stages.Growth << " s ("
            << Ns(stages.Growth, stages.Triangles) << " ns/triangle), extraction "
            << stages.Extraction << " s (" << Ns(stages.Extraction, stages.Triangles)
            << " ns/triangle), " << stages.Triangles << " triangles, " << stages.Vertices
            << " vertices; the least node by node: growth " << floor.Seconds << " s ("
            << Ns(floor.Seconds, floor.Triangles) << " ns/triangle; with every case ready "
            << floor.CasesReady << " s, " << Ns(floor.CasesReady, floor.Triangles)
            << " ns/triangle), extraction " << extraction << " s ("
            << Ns(extraction, floor.Triangles) << " ns/triangle), " << floor.Triangles
            << " triangles, " << floorVertices << " vertices, " << floor.Nodes.size()
            << " nodes; growth / least " << stages.Growth / floor.Seconds << ", extraction / least "
            << stages.Extraction / extraction << "\n";
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
      (std::string(argv[a + 1]) == "seeded" || std::string(argv[a + 1]) == "all" ||
        std::string(argv[a + 1]) == "floor"))
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
                   "[--threads 1,2] [--repeats N] [--only seeded|all|floor]\n";
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
    if (only == "floor")
    {
      vtkSMPTools::LocalScope(
        vtkSMPTools::Config{ 1, "STDThread", false }, [&]() { FloorRun(v, repeats); });
      continue;
    }
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

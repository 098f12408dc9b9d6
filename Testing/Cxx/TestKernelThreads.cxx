// The kernel on threads, under ThreadSanitizer (built with -fsanitize=thread where the compiler
// has it): seed search, growth and extraction over one piece with a ParallelFor of plain
// std::threads that take tasks in whatever order they come, at 1, 2, 3, 4, 16 and 64 threads. Every
// output buffer (points, normals, keys, triangles, components, ports, component totals) must be
// bitwise the same as on 1 thread. Volumes of several 32^3 tiles (growth crosses tiles) and
// more than one chunk of slabs (extraction joins chunks), with samples equal to the isovalue;
// one owner and two owners (the boundary growth of the distributed seeded mode).
// (vtkSMPTools is not used here: VTK's thread pool is not built with ThreadSanitizer, whose
// reports would then be about VTK's synchronisation, not this kernel's.)
#include "rgmcCheck.h"
#include "rgmcSurfaceKernel.h"

#include "vtkMarchingCubesTriangleCases.h"

#include <atomic>
#include <cmath>
#include <cstring>
#include <functional>
#include <iostream>
#include <thread>
#include <vector>

namespace
{

const rgmc::CaseTable& Table()
{
  static const rgmc::CaseTable table(&vtkMarchingCubesTriangleCases::GetCases()[0].edges[0]);
  return table;
}

/// A ParallelFor over `threads` std::threads taking one index at a time.
std::function<void(std::int64_t, const std::function<void(std::int64_t, std::int64_t)>&)>
ThreadsFor(int threads)
{
  return [threads](std::int64_t count, const std::function<void(std::int64_t, std::int64_t)>& body)
  {
    std::atomic<std::int64_t> next{ 0 };
    auto work = [&]()
    {
      for (std::int64_t i = next++; i < count; i = next++)
      {
        body(i, i + 1);
      }
    };
    std::vector<std::thread> pool;
    for (int t = 1; t < threads; ++t)
    {
      pool.emplace_back(work);
    }
    work();
    for (std::thread& t : pool)
    {
      t.join();
    }
  };
}

/// Everything one run produced, as bytes.
struct Result
{
  std::vector<unsigned char> Bytes;
  std::int64_t Triangles = 0;
  template <typename T>
  void Add(const T* data, std::size_t n)
  {
    const auto* p = reinterpret_cast<const unsigned char*>(data);
    this->Bytes.insert(this->Bytes.end(), p, p + n * sizeof(T));
  }
};

constexpr int N = 80; // points per axis: 3 tiles of cubes, 5 chunks of slabs

/// Wavy blobs, rounded to integers so that many samples equal the isovalue.
std::vector<float> Field()
{
  std::vector<float> values(static_cast<std::size_t>(N) * N * N);
  for (int k = 0; k < N; ++k)
  {
    for (int j = 0; j < N; ++j)
    {
      for (int i = 0; i < N; ++i)
      {
        const double v = 6 * std::sin(0.21 * i) * std::cos(0.17 * j) + 5 * std::sin(0.13 * k + 1) +
          2 * std::cos(0.05 * (i + j + k));
        values[i + N * (j + N * static_cast<std::size_t>(k))] = static_cast<float>(std::round(v));
      }
    }
  }
  return values;
}

enum Mode
{
  SEEDED,
  ALL
};

Result Run(const std::vector<float>& values, Mode mode, int owners, int owner, int threads)
{
  const int whole[6] = { 0, N - 1, 0, N - 1, 0, N - 1 };
  const rgmc::Grid grid(whole, whole);
  std::vector<rgmc::CellBox> boxes(owners, grid.WholeCells());
  if (owners == 2)
  {
    boxes[0].Hi[0] = 36;
    boxes[1].Lo[0] = 37;
  }
  const rgmc::Ownership own(boxes, owner);
  rgmc::SurfaceOptions options;
  options.Isovalue = 3.0;
  options.ParallelFor = ThreadsFor(threads);
  rgmc::SurfaceKernel<std::vector<float>> kernel(Table(), grid, own, values, options);
  if (mode == SEEDED)
  {
    const double seeds[2][3] = { { 10.5, 20.5, 30.5 }, { 60.2, 50.7, 12.1 } };
    for (const auto& seed : seeds)
    {
      const rgmc::SeedHit hit = kernel.NearestVertex(seed, seed, 100.0, 1.0);
      if (hit.Found)
      {
        kernel.GrowFromKey(hit.Key);
      }
    }
    if (owners > 1)
    {
      kernel.GrowBoundary();
    }
  }
  else
  {
    kernel.GrowAll();
  }
  kernel.Extract();
  RGMC_CHECK(kernel.Error().empty(), kernel.Error());
  const rgmc::LocalMesh& m = kernel.Mesh();
  Result r;
  r.Triangles = m.NumberOfTriangles();
  r.Add(m.Points.data(), m.Points.size());
  r.Add(m.Normals.data(), m.Normals.size());
  r.Add(m.Keys.data(), m.Keys.size());
  r.Add(m.VertexComponent.data(), m.VertexComponent.size());
  r.Add(m.Triangles.data(), m.Triangles.size());
  r.Add(m.TriangleComponent.data(), m.TriangleComponent.size());
  for (const rgmc::Port& p : kernel.Ports())
  {
    r.Add(&p.Key, 1);
    r.Add(&p.Component, 1);
  }
  for (int c = 0; c < kernel.Components().Size(); ++c)
  {
    const int root = kernel.Components().Root(c);
    const rgmc::ComponentSet::Totals& t = kernel.Components().TotalsOf(root);
    r.Add(&root, 1);
    r.Add(&t.Triangles, 1);
    r.Add(&t.MinKey, 1);
  }
  return r;
}

} // namespace

int main()
{
  const std::vector<float> values = Field();
  for (const Mode mode : { SEEDED, ALL })
  {
    for (const int owners : { 1, 2 })
    {
      for (int owner = 0; owner < owners; ++owner)
      {
        const Result one = Run(values, mode, owners, owner, 1);
        RGMC_CHECK(one.Triangles > 1000, "a surface of " << one.Triangles << " triangles");
        for (const int threads : { 2, 3, 4, 16, 64 })
        {
          const Result many = Run(values, mode, owners, owner, threads);
          RGMC_CHECK(many.Bytes == one.Bytes,
            (mode == SEEDED ? "seeded" : "all components")
              << ", owner " << owner << " of " << owners << ": " << threads
              << " threads differ from 1 (" << many.Triangles << " vs " << one.Triangles
              << " triangles)");
        }
        std::cout << (mode == SEEDED ? "seeded" : "all components") << ", owner " << owner << " of "
                  << owners << ": " << one.Triangles << " triangles\n";
      }
    }
  }
  return rgmc_test::Result("TestKernelThreads");
}

// RGMC's ranks benchmark (not a test; `./rgmc evaluate --ranks-benchmark` runs it): does seeded
// work on several ranks follow the chosen structure?
//
//   mpiexec -n 4 rgmcRanks [--size 256] [--phantom 512] [--repeats 4]
//
// Case 1, "sphere in a scaffold": a float volume of `size`^3 holding a small sphere that floats
// inside a 3-D scaffold of rods; the rods cross every partition plane. Seeded on the sphere
// against All Components, in the same run, and seeded on a rod (the scaffold itself as the
// chosen structure, held by every rank). Case 2: the CT phantom (`phantom`^3, int16 HU),
// seeded on the skull. Each rank computes its own block (with the ghost layer ParaView gives),
// so the volume is never whole on one rank. A time is the slowest rank's (barrier, update, max),
// the fastest of `repeats` runs. Also printed: the filter's counts of the seeded run (rounds of
// growth between ranks, collectives, messages), read only when the filter has them, so the same
// source measures older versions too. Prints one JSON object per line on rank 0.
#include "rgmcBenchmark.h"       // Now
#include "rgmcDistributedData.h" // BlockPiece, MakeImage, MarkGhostCells
#include "vtkRGMarchingCubes.h"

#include "vtkImageData.h"
#include "vtkMPIController.h"
#include "vtkNew.h"
#include "vtkPolyData.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <string>

namespace
{

using rgmc_benchmark::Now;

/// One of the filter's counts when this version has it (`get` names it), else -1 (older versions).
template <typename F, typename Get>
auto Count(F* f, Get get, int) -> decltype(static_cast<long long>(get(f)))
{
  return get(f);
}
template <typename F, typename Get>
long long Count(F*, Get, long)
{
  return -1;
}
#define RGMC_COUNT(filter, method)                                                                 \
  Count(                                                                                           \
    filter, [](auto* f) -> decltype(f->method()) { return f->method(); }, 0)

/// The sphere-in-a-scaffold field over `size`^3 points: rods of radius 2.5 along each axis on
/// a lattice of pitch size/8 (offset by a quarter pitch), and a sphere of radius 5 in the middle
/// of one lattice cell, away from every rod.
std::function<double(int, int, int)> Scaffold(int size, double sphere[3])
{
  const double pitch = size / 8.0, offset = pitch / 4.0;
  for (int a = 0; a < 3; ++a)
  {
    sphere[a] = offset + 2.5 * pitch; // between the rods at offset + 2 and + 3 pitches
  }
  const double c[3] = { sphere[0], sphere[1], sphere[2] };
  return [pitch, offset, c](int i, int j, int k)
  {
    const double p[3] = { i + 0.1, j + 0.2, k + 0.3 };
    double rods = 1e30;
    for (int axis = 0; axis < 3; ++axis)
    {
      double d2 = 0;
      for (int b = 1; b <= 2; ++b)
      {
        const double u = p[(axis + b) % 3] - offset;
        const double near = u - pitch * std::floor(u / pitch + 0.5);
        d2 += near * near;
      }
      rods = std::min(rods, std::sqrt(d2));
    }
    const double s =
      std::sqrt((i - c[0]) * (i - c[0]) + (j - c[1]) * (j - c[1]) + (k - c[2]) * (k - c[2]));
    return std::max(2.5 - rods, 5.0 - s);
  };
}

struct Timing
{
  double Seconds = 0;
  long long Triangles = 0, Rounds = -1, Collectives = -1, MostMessages = -1;
};

/// The fastest of `repeats` runs of the filter on this rank's piece (the slowest rank's time).
Timing Time(vtkMultiProcessController* c, vtkImageData* piece, double isovalue, int mode,
  const double seed[3], int repeats)
{
  Timing t;
  t.Seconds = 1e30;
  vtkNew<vtkRGMarchingCubes> rg;
  rg->SetController(c);
  rg->SetInputData(piece);
  rg->SetIsovalue(isovalue);
  rg->SetExtractionMode(mode);
  if (seed)
  {
    rg->AddSeedPoint(seed[0], seed[1], seed[2]);
  }
  for (int r = 0; r < repeats; ++r)
  {
    rg->Modified();
    c->Barrier();
    const double start = Now();
    rg->Update();
    double seconds = Now() - start, slowest = 0;
    c->AllReduce(&seconds, &slowest, 1, vtkCommunicator::MAX_OP);
    t.Seconds = std::min(t.Seconds, slowest);
  }
  long long mine = rg->GetOutput()->GetNumberOfCells(),
            messages = RGMC_COUNT(rg.Get(), GetNumberOfMessages);
  c->AllReduce(&mine, &t.Triangles, 1, vtkCommunicator::SUM_OP);
  c->AllReduce(&messages, &t.MostMessages, 1, vtkCommunicator::MAX_OP);
  t.Rounds = RGMC_COUNT(rg.Get(), GetNumberOfGrowthRounds);
  t.Collectives = RGMC_COUNT(rg.Get(), GetNumberOfCollectives);
  return t;
}

std::string Json(const char* name, const Timing& t)
{
  std::ostringstream os;
  os << "\"" << name << "\": " << t.Seconds << ", \"" << name << "_triangles\": " << t.Triangles
     << ", \"" << name << "_rounds\": " << t.Rounds << ", \"" << name
     << "_collectives\": " << t.Collectives << ", \"" << name
     << "_most_messages\": " << t.MostMessages;
  return os.str();
}

} // namespace

int main(int argc, char* argv[])
{
  vtkNew<vtkMPIController> controller;
  controller->Initialize(&argc, &argv);
  vtkMultiProcessController::SetGlobalController(controller);
  const int rank = controller->GetLocalProcessId(), ranks = controller->GetNumberOfProcesses();
  int size = 256, phantomSize = 512, repeats = 4;
  for (int a = 1; a + 1 < argc; a += 2)
  {
    const std::string option = argv[a];
    const int value = std::atoi(argv[a + 1]);
    if (option == "--size")
    {
      size = value;
    }
    else if (option == "--phantom")
    {
      phantomSize = value;
    }
    else if (option == "--repeats")
    {
      repeats = value;
    }
  }

  // Case 1: the sphere in the scaffold.
  {
    const int whole[6] = { 0, size - 1, 0, size - 1, 0, size - 1 };
    int owned[6], ghosted[6];
    rgmc_test::BlockPiece(whole, rank, ranks, owned, ghosted);
    double sphere[3];
    vtkSmartPointer<vtkImageData> piece =
      rgmc_test::MakeImage(ghosted, VTK_FLOAT, Scaffold(size, sphere));
    if (ranks > 1)
    {
      rgmc_test::MarkGhostCells(piece, owned);
    }
    const double seed[3] = { sphere[0] + 5.0, sphere[1], sphere[2] };
    const Timing seeded = Time(controller, piece, 0.0, vtkRGMarchingCubes::SEEDED, seed, repeats);
    const Timing all =
      Time(controller, piece, 0.0, vtkRGMarchingCubes::ALL_COMPONENTS, nullptr, repeats);
    // The scaffold itself as the chosen structure (seeded on a rod): growth in rounds over a
    // structure that every rank holds, against the full scan.
    const double pitch = size / 8.0, offset = pitch / 4.0;
    const double onRod[3] = { size / 2.0 + 0.3, offset + 2.5, offset };
    const Timing rods = Time(controller, piece, 0.0, vtkRGMarchingCubes::SEEDED, onRod, repeats);
    if (rank == 0)
    {
      std::cout << "{\"case\": \"scaffold\", \"ranks\": " << ranks << ", \"size\": " << size << ", "
                << Json("seeded", seeded) << ", " << Json("all", all) << ", "
                << Json("seeded_rods", rods)
                << ", \"seeded_over_all\": " << seeded.Seconds / all.Seconds << "}" << std::endl;
    }
  }
  // Case 2: the CT phantom, seeded on the skull.
  if (phantomSize > 0)
  {
    const int whole[6] = { 0, phantomSize - 1, 0, phantomSize - 1, 0, phantomSize - 1 };
    int owned[6], ghosted[6];
    rgmc_test::BlockPiece(whole, rank, ranks, owned, ghosted);
    vtkSmartPointer<vtkImageData> piece = rgmc_test::PhantomPiece(ghosted, phantomSize);
    if (ranks > 1)
    {
      rgmc_test::MarkGhostCells(piece, owned);
    }
    const double seed[3] = { 0, 0, 105 };
    const Timing seeded = Time(controller, piece, 400.0, vtkRGMarchingCubes::SEEDED, seed, repeats);
    if (rank == 0)
    {
      std::cout << "{\"case\": \"phantom\", \"ranks\": " << ranks << ", \"size\": " << phantomSize
                << ", " << Json("seeded", seeded) << "}" << std::endl;
    }
  }
  controller->Finalize();
  return 0;
}

// Seeded growth on many ranks follows the chosen structure. Run on 1 rank (the reference) and
// under mpiexec on up to 64 ranks, oversubscribed, on small data (correctness only, no timing).
//
// The volume holds a small sphere among a scaffold of rods that crosses every partition plane.
// With the seed on the sphere, the union of the pieces must equal the 1-rank output, and the
// filter's own counters must show that the work followed the sphere: a rank whose cubes do not
// touch the sphere's box examined no cube, read no face and made no triangle; no rank made a
// triangle it did not keep; every rank made the same collective calls. A helix that passes
// between the ranks again and again must give the 1-rank output too, in rounds and past
// MaximumGrowthRounds (the rest grown in one step). All Components on the scaffold must match.
// The counts are logged at TRACE verbosity.
#include "rgmcDistributedData.h"
#include "rgmcGrid.h"
#include "rgmcTestController.h"
#include "rgmcTestData.h"

#include "vtkDummyController.h"
#include "vtkLogger.h"
#include "vtkRGMarchingCubes.h"

#include <atomic>
#include <cmath>
#include <sstream>
#include <string>

using namespace rgmc_test;

namespace
{

constexpr int N = 49; // 48 cells per axis: 12 per rank in a 4 x 4 x 4 split
const int Whole[6] = { 0, N - 1, 0, N - 1, 0, N - 1 };
const double SphereCentre[3] = { 12.0, 12.0, 12.0 };
constexpr double SphereRadius = 3.2;

/// Distance from (x, y, z) to the nearest rod of the scaffold: rods along each axis through the
/// lines whose two other coordinates are in {4, 20, 28, 44}, away from the sphere.
double RodDistance(double x, double y, double z)
{
  const double at[4] = { 4, 20, 28, 44 };
  double best = 1e30;
  const double c[3] = { x, y, z };
  for (int axis = 0; axis < 3; ++axis)
  {
    const double u = c[(axis + 1) % 3], v = c[(axis + 2) % 3];
    for (double a : at)
    {
      for (double b : at)
      {
        best = std::min(best, std::hypot(u - a, v - b));
      }
    }
  }
  return best;
}

double Scaffold(int i, int j, int k)
{
  const double sphere = SphereRadius -
    std::sqrt((i - SphereCentre[0]) * (i - SphereCentre[0]) +
      (j - SphereCentre[1]) * (j - SphereCentre[1]) +
      (k - SphereCentre[2]) * (k - SphereCentre[2]));
  return std::max(sphere, 1.4 - RodDistance(i + 0.1, j + 0.2, k + 0.3));
}

/// A tube coiled around the line x = y = 24 (radius 12, pitch 5): it passes between the ranks
/// of any split many times.
double Helix(int i, int j, int k)
{
  const double pi = 3.14159265358979323846;
  const double x = i - 24.0, y = j - 24.0;
  const double rho = std::sqrt(x * x + y * y), theta = std::atan2(y, x);
  double dz = k - 5.0 * theta / (2 * pi);
  dz -= 5.0 * std::floor(dz / 5.0 + 0.5);
  return 1.8 - std::sqrt((rho - 12.0) * (rho - 12.0) + dz * dz);
}

std::atomic<int> TraceLines{ 0 };

void CountTrace(void*, const vtkLogger::Message& message)
{
  if (std::string(message.message).find("collectives") != std::string::npos)
  {
    ++TraceLines;
  }
}

} // namespace

int main(int argc, char* argv[])
{
  vtkSmartPointer<vtkMultiProcessController> controller = rgmc_test::StartController(argc, argv);
  const int rank = controller->GetLocalProcessId(), ranks = controller->GetNumberOfProcesses();
  vtkNew<vtkDummyController> single;
  vtkLogger::AddCallback("rgmc-trace", CountTrace, nullptr, vtkLogger::VERBOSITY_TRACE);

  struct Case
  {
    std::string Name;
    std::function<double(int, int, int)> Field;
    int Mode;
    Seeds Seed;
  };
  const std::vector<Case> cases = {
    { "sphere in the scaffold", Scaffold, vtkRGMarchingCubes::SEEDED, { { 12.0, 12.0, 16.0 } } },
    { "helix", Helix, vtkRGMarchingCubes::SEEDED, { { 36.0, 24.0, 0.5 } } },
    { "the whole scaffold", Scaffold, vtkRGMarchingCubes::ALL_COMPONENTS, {} },
  };
  const Piece piece = PieceOf("block", Whole, rank, ranks);
  // This rank's cubes, and the box of the cubes the sphere passes through.
  rgmc::CellBox mine, sphere;
  for (int a = 0; a < 3; ++a)
  {
    mine.Lo[a] = piece.Owned[2 * a];
    mine.Hi[a] = piece.Owned[2 * a + 1] - 1;
    sphere.Lo[a] = static_cast<int>(std::floor(SphereCentre[a] - SphereRadius)) - 1;
    sphere.Hi[a] = static_cast<int>(std::ceil(SphereCentre[a] + SphereRadius));
  }
  int untouched = 0, helixRounds = 0;
  long long sphereCollectives = 0, sphereMessages = 0, sphereRounds = 0;
  for (const Case& c : cases)
  {
    const FieldMaker make = [&c](const int extent[6])
    { return MakeImage(extent, VTK_FLOAT, c.Field); };
    Snapshot reference;
    if (rank == 0)
    {
      Run r = Extract(single, make(Whole), 0.0, c.Mode, c.Seed);
      RGMC_CHECK(r.Output->GetNumberOfCells() > 0 && r.Errors.empty(),
        c.Name << ": the reference is empty: " << r.Errors << r.Warnings);
      reference.Add(r.Output, 0);
    }
    vtkSmartPointer<vtkImageData> image = MakePiece(make, Whole, piece);
    const std::string what = c.Name + " on " + std::to_string(ranks) + " ranks";
    Run r = Extract(controller, image, 0.0, c.Mode, c.Seed);
    RGMC_CHECK(r.Errors.empty() && r.Warnings.empty(), what << ": " << r.Errors << r.Warnings);
    CompareUnion(controller, r.Output, rank == 0 ? &reference : nullptr, what);
    RGMC_CHECK(SameOnAllRanks(controller, std::to_string(r.Collectives)),
      what << ": the ranks made different numbers of collective calls");
    if (c.Mode != vtkRGMarchingCubes::SEEDED)
    {
      continue;
    }
    RGMC_CHECK(!r.OneStep || ranks == 1, what << ": grew in one step");
    RGMC_CHECK(r.TrianglesMade == r.Output->GetNumberOfCells(),
      what << ": rank " << rank << " made " << r.TrianglesMade << " triangles and kept "
           << r.Output->GetNumberOfCells());
    RGMC_CHECK(r.FacePointsRead == 0, what << ": rank " << rank << " read shared faces");
    if (c.Name == "helix")
    {
      helixRounds = r.Rounds;
      // Past MaximumGrowthRounds the rest grows in one step, with the same result.
      Run capped = Extract(controller, image, 0.0, c.Mode, c.Seed,
        [](vtkRGMarchingCubes* rg) { rg->SetMaximumGrowthRounds(2); });
      RGMC_CHECK(capped.Errors.empty(), what << ", 2 rounds at most: " << capped.Errors);
      CompareUnion(
        controller, capped.Output, rank == 0 ? &reference : nullptr, what + ", 2 rounds at most");
      RGMC_CHECK(capped.Rounds <= 2, what << ": " << capped.Rounds << " rounds, 2 allowed");
      RGMC_CHECK(capped.OneStep == (r.Rounds > 2),
        what << ": one step " << capped.OneStep << " after " << r.Rounds << " rounds");
    }
    else
    {
      sphereCollectives = r.Collectives;
      sphereRounds = r.Rounds;
      controller->AllReduce(&r.Messages, &sphereMessages, 1, vtkCommunicator::MAX_OP);
    }
    if (c.Name != "helix" && mine.Intersect(sphere).Empty() && ranks > 1)
    {
      ++untouched;
      RGMC_CHECK(r.CubesExamined == 0 && r.TrianglesMade == 0,
        what << ": rank " << rank << ", away from the sphere, examined " << r.CubesExamined
             << " cubes and made " << r.TrianglesMade << " triangles");
    }
  }
  // The helix passes between the ranks again and again: many rounds, on every rank the same.
  RGMC_CHECK(ranks < 4 || helixRounds > 4, "the helix took " << helixRounds << " rounds");
  RGMC_CHECK(
    SameOnAllRanks(controller, std::to_string(helixRounds)), "the ranks' round counts differ");
  RGMC_CHECK(TraceLines > 0, "rank " << rank << ": no TRACE line with the counts");
  long long away = untouched, total = 0;
  controller->AllReduce(&away, &total, 1, vtkCommunicator::SUM_OP);
  std::ostringstream detail;
  detail << "sphere in " << sphereRounds << " rounds, " << sphereCollectives
         << " collectives, at most " << sphereMessages << " messages sent by a rank; " << total
         << " ranks away from it idle; helix in " << helixRounds << " rounds; ";
  vtkLogger::RemoveCallback("rgmc-trace");
  return rgmc_test::Finish(controller, "TestManyRanks", detail.str());
}

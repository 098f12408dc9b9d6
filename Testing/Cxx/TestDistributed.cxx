// Distributed vtkRGMarchingCubes. Run on 1 rank (vtkDummyController) and under mpiexec on N
// ranks: for every field and decomposition, the union of the pieces must equal the 1-rank
// output in all modes: the same triangles over the same vertex keys, bitwise-identical
// coordinates and normals, identical ComponentIds, no triangle twice. Errors must be collective:
// a problem on one rank gives every rank the same message and an empty output.
//
// Decompositions: ParaView's block split (with a ghost layer), slabs along each axis, the whole
// volume on rank 0 and nothing elsewhere, a rank with no data, every rank holding the whole
// volume (a reader that ignored the piece requests), and slabs whose ghost arrays mark another
// split's cells as owned (VTK 9.2's executive does that to readers that split in slabs).
//
// Fields: random blobs (many components), a helical tube and a wavy sheet that cross the
// partition planes again and again, two blocks that meet only around the corner where 8 ranks
// meet, two bars that meet only along the edge where 4 ranks meet, and the CT phantom (with
// spacing and origin).
#include "rgmcDistributedData.h"
#include "rgmcTestController.h"
#include "rgmcTestData.h"

#include "vtkCallbackCommand.h"
#include "vtkDummyController.h"
#include "vtkExtentTranslator.h"
#include "vtkFieldData.h"
#include "vtkIdTypeArray.h"
#include "vtkIntArray.h"
#include "vtkRGMarchingCubes.h"
#include "vtkRGPhantomSource.h"

#include <cstring>
#include <functional>
#include <iostream>
#include <limits>
#include <sstream>

using namespace rgmc_test;

namespace
{

constexpr int N = 33; // 32 cells per axis: even splits for 2, 4 and 8 ranks
const int Whole[6] = { 0, N - 1, 0, N - 1, 0, N - 1 };
const double Pi = 3.14159265358979323846;

struct Field
{
  std::string Name;
  double Isovalue;
  std::vector<Seeds> SeedSets;
  /// The field's samples over a point extent (with its spacing and origin).
  FieldMaker Make;
};

Field IndexField(const std::string& name, int type, std::function<double(int, int, int)> f,
  double isovalue, std::vector<Seeds> seeds)
{
  return Field{ name, isovalue, std::move(seeds),
    [type, f](const int extent[6]) { return MakeImage(extent, type, f); } };
}

std::vector<Field> Fields()
{
  std::vector<Field> fields;
  fields.push_back(IndexField("blobs", VTK_FLOAT, Blobs(Whole, 40, 5), 0.3,
    { { { 10.2, 20.7, 5.1 } }, { { 3.3, 4.4, 5.5 }, { 28.1, 27.2, 26.3 }, { 16.4, 8.2, 30.1 } } }));

  // A tube of radius 2.2 coiled around the z axis (radius 10, pitch 6): it crosses every
  // partition plane again and again.
  fields.push_back(IndexField("helix", VTK_DOUBLE,
    [](int i, int j, int k)
    {
      const double x = i - 16.0, y = j - 16.0;
      const double rho = std::sqrt(x * x + y * y), theta = std::atan2(y, x);
      double dz = k - 6.0 * theta / (2 * Pi);
      dz -= 6.0 * std::floor(dz / 6.0 + 0.5);
      return 2.2 - std::sqrt((rho - 10.0) * (rho - 10.0) + dz * dz);
    },
    0.0, { { { 26.0, 16.0, 0.5 } } }));

  // A wavy sheet that winds back and forth across the planes x = 16, y = 16 and z = 16.
  fields.push_back(IndexField("comb", VTK_FLOAT,
    [](int i, int j, int k)
    {
      return (i - 16.0) - 6.0 * std::sin(2 * Pi * j / 7.3) * std::cos(2 * Pi * k / 9.1) -
        3.0 * std::sin(2 * Pi * k / 5.3);
    },
    0.0, { { { 16.0, 16.0, 16.0 } } }));

  // Two blocks of inside samples, one in the octant above the centre (16, 16, 16) and one
  // below it, sharing only the centre: where 8 ranks meet in a 2 x 2 x 2 split.
  fields.push_back(IndexField("corner", VTK_UNSIGNED_CHAR,
    [](int i, int j, int k)
    {
      const int d[3] = { i - 16, j - 16, k - 16 };
      const bool above = d[0] >= 0 && d[1] >= 0 && d[2] >= 0 && d[0] <= 5 && d[1] <= 5 && d[2] <= 5;
      const bool below =
        d[0] <= 0 && d[1] <= 0 && d[2] <= 0 && d[0] >= -5 && d[1] >= -5 && d[2] >= -5;
      return above || below ? 2.0 : 0.0;
    },
    1.0, { { { 20.0, 20.0, 20.0 } }, { { 16.0, 16.0, 16.0 } } }));

  // Two bars along z, one on each side of the line x = y = 16, sharing only that line: where
  // 4 ranks meet.
  fields.push_back(IndexField("edge", VTK_SHORT,
    [](int i, int j, int k)
    {
      const int x = i - 16, y = j - 16;
      const bool bar1 = x >= 0 && y >= 0 && x <= 4 && y <= 4;
      const bool bar2 = x <= 0 && y <= 0 && x >= -4 && y >= -4;
      return (bar1 || bar2) && k >= 3 && k <= 29 ? 100.0 : -100.0;
    },
    0.0, { { { 19.0, 19.0, 10.0 } } }));

  // The CT phantom (int16 HU, spacing and origin): skull, mandible and vertebrae.
  fields.push_back(
    Field{ "phantom", 400.0, { { { 0, 0, 105 } }, { { 0, 65, -75 }, { 0, -20, -96 } } },
      [](const int extent[6]) { return PhantomPiece(extent, N); } });
  return fields;
}

/// Strips what differs between ranks in a VTK message (the object's address and the source
/// line), leaving the text.
std::string Text(const std::string& message)
{
  const std::size_t at = message.find("): ");
  return at == std::string::npos ? message : message.substr(at + 3);
}

void CollectiveErrors(vtkMultiProcessController* controller)
{
  const int rank = controller->GetLocalProcessId(), ranks = controller->GetNumberOfProcesses();
  const Field field = Fields()[0];
  const Piece piece = PieceOf("block", Whole, rank, ranks);
  const Seeds seed = field.SeedSets[0];
  auto expect = [&](const std::string& what, const Run& r, const std::string& text, bool error)
  {
    const std::string message = Text(error ? r.Errors : r.Warnings);
    RGMC_CHECK(message.find(text) != std::string::npos,
      what << " (rank " << rank << "): expected '" << text << "', got [" << r.Errors << "]["
           << r.Warnings << "]");
    RGMC_CHECK(
      r.Output->GetNumberOfCells() == 0, what << " (rank " << rank << "): output not empty");
    RGMC_CHECK(SameOnAllRanks(controller, message), what << ": the ranks' messages differ");
  };

  // A 3-component array on one rank only.
  {
    vtkSmartPointer<vtkImageData> image = MakePiece(field.Make, Whole, piece);
    if (rank == ranks - 1)
    {
      vtkNew<vtkFloatArray> vectors;
      vectors->SetName("f");
      vectors->SetNumberOfComponents(3);
      vectors->SetNumberOfTuples(image->GetNumberOfPoints());
      vectors->Fill(0.5);
      image->GetPointData()->SetScalars(vectors);
    }
    expect("bad array on the last rank",
      Extract(controller, image, field.Isovalue, vtkRGMarchingCubes::ALL_COMPONENTS, {}),
      "has 3 components", true);
  }
  // NaN samples on the last rank's piece, where the surface passes.
  {
    vtkSmartPointer<vtkImageData> image = MakePiece(field.Make, Whole, piece);
    if (rank == ranks - 1)
    {
      vtkDataArray* f = image->GetPointData()->GetScalars();
      for (vtkIdType n = 0; n < f->GetNumberOfTuples(); n += 7)
      {
        f->SetComponent(n, 0, std::numeric_limits<double>::quiet_NaN());
      }
    }
    expect("NaN on the last rank",
      Extract(controller, image, field.Isovalue, vtkRGMarchingCubes::ALL_COMPONENTS, {}), "is NaN",
      true);
  }
  // A seed outside the volume.
  {
    vtkSmartPointer<vtkImageData> image = MakePiece(field.Make, Whole, piece);
    expect("seed outside",
      Extract(controller, image, field.Isovalue, vtkRGMarchingCubes::SEEDED, { { 16, 16, 90 } }),
      "lies outside the volume", false);
  }
  // An abort on the last rank only: every rank stops with an empty output, in the full scan
  // and in seeded growth, here of a small ball inside rank 0's block that the last rank never
  // reaches (so its kernel reports no progress).
  const Field ball = IndexField("ball", VTK_FLOAT,
    [](int i, int j, int k) {
      return 3.0 - std::sqrt((i - 5.0) * (i - 5.0) + (j - 5.0) * (j - 5.0) + (k - 5.0) * (k - 5.0));
    },
    0.0, { { { 5.0, 5.0, 8.0 } } });
  for (const int mode : { vtkRGMarchingCubes::ALL_COMPONENTS, vtkRGMarchingCubes::SEEDED })
  {
    vtkSmartPointer<vtkImageData> image = MakePiece(ball.Make, Whole, piece);
    vtkNew<vtkCallbackCommand> abort;
    abort->SetCallback([](vtkObject* caller, unsigned long, void*, void*)
      { static_cast<vtkAlgorithm*>(caller)->SetAbortExecute(1); });
    const Run r = Extract(controller, image, ball.Isovalue, mode,
      mode == vtkRGMarchingCubes::SEEDED ? ball.SeedSets[0] : Seeds(),
      [&](vtkRGMarchingCubes* rg)
      {
        if (rank == ranks - 1)
        {
          rg->AddObserver(vtkCommand::ProgressEvent, abort);
        }
      });
    RGMC_CHECK(r.Output->GetNumberOfCells() == 0,
      "abort on the last rank (rank " << rank << ", mode " << mode << "): output not empty");
  }
}

} // namespace

int main(int argc, char* argv[])
{
  vtkSmartPointer<vtkMultiProcessController> controller = rgmc_test::StartController(argc, argv);
  const int rank = controller->GetLocalProcessId(), ranks = controller->GetNumberOfProcesses();
  vtkNew<vtkDummyController> single;

  const int modes[] = { vtkRGMarchingCubes::SEEDED, vtkRGMarchingCubes::LARGEST_COMPONENT,
    vtkRGMarchingCubes::ALL_COMPONENTS };
  const char* modeNames[] = { "seeded", "largest", "all" };
  int runs = 0;
  long long mostRounds = 0; // of growth between ranks, in a seeded run
  for (const Field& field : Fields())
  {
    // The 1-rank reference, on rank 0.
    std::vector<Snapshot> references;
    vtkSmartPointer<vtkImageData> whole;
    if (rank == 0)
    {
      whole = field.Make(Whole);
      for (int mode : modes)
      {
        const std::size_t sets = mode == vtkRGMarchingCubes::SEEDED ? field.SeedSets.size() : 1;
        for (std::size_t s = 0; s < sets; ++s)
        {
          Run r = Extract(single, whole, field.Isovalue, mode,
            mode == vtkRGMarchingCubes::SEEDED ? field.SeedSets[s] : Seeds());
          RGMC_CHECK(r.Output->GetNumberOfCells() > 0 && r.Errors.empty() && r.Warnings.empty(),
            field.Name << " " << modeNames[mode] << ": the reference is empty: " << r.Errors
                       << r.Warnings);
          references.emplace_back();
          references.back().Add(r.Output, 0);
        }
      }
    }
    for (const std::string& how : Decompositions(ranks))
    {
      vtkSmartPointer<vtkImageData> image =
        MakePiece(field.Make, Whole, PieceOf(how, Whole, rank, ranks));
      std::size_t next = 0;
      for (int mode : modes)
      {
        const std::size_t sets = mode == vtkRGMarchingCubes::SEEDED ? field.SeedSets.size() : 1;
        for (std::size_t s = 0; s < sets; ++s, ++next)
        {
          std::ostringstream what;
          what << field.Name << ", " << how << " on " << ranks << " ranks, " << modeNames[mode];
          if (mode == vtkRGMarchingCubes::SEEDED)
          {
            what << " (seed set " << s << ")";
          }
          Run r = Extract(controller, image, field.Isovalue, mode,
            mode == vtkRGMarchingCubes::SEEDED ? field.SeedSets[s] : Seeds());
          if (how == "mismarked")
          {
            // The ownership is repaired by the extents, and said so once.
            const bool warned = r.Warnings.find("do not match the pieces") != std::string::npos &&
              r.Warnings.find("less one ghost layer") != std::string::npos;
            RGMC_CHECK(r.Errors.empty() && warned == (rank == 0) &&
                r.Warnings.find("one-sided") == std::string::npos,
              what.str() << ": " << r.Errors << r.Warnings);
          }
          else
          {
            RGMC_CHECK(
              r.Errors.empty() && r.Warnings.empty(), what.str() << ": " << r.Errors << r.Warnings);
          }
          CompareUnion(controller, r.Output, rank == 0 ? &references[next] : nullptr, what.str());
          ++runs;
          if (mode == vtkRGMarchingCubes::SEEDED && ranks > 1)
          {
            // Growth in rounds follows the structure: no rank makes a triangle that is not
            // kept, and no rank grows in one step; every rank made the same collective calls.
            RGMC_CHECK(!r.OneStep, what.str() << ": grew in one step");
            RGMC_CHECK(r.TrianglesMade == r.Output->GetNumberOfCells(),
              what.str() << ": rank " << rank << " made " << r.TrianglesMade
                         << " triangles and kept " << r.Output->GetNumberOfCells());
            RGMC_CHECK(r.FacePointsRead == 0, what.str() << ": face points read");
            RGMC_CHECK(SameOnAllRanks(controller, std::to_string(r.Collectives)),
              what.str() << ": the ranks made different numbers of collective calls");
            long long rounds = r.Rounds, most = 0;
            controller->AllReduce(&rounds, &most, 1, vtkCommunicator::MAX_OP);
            mostRounds = std::max(mostRounds, most);
            // The same in one step, as past MaximumGrowthRounds.
            Run once = Extract(controller, image, field.Isovalue, mode, field.SeedSets[s],
              [](vtkRGMarchingCubes* rg) { rg->SetMaximumGrowthRounds(0); });
            RGMC_CHECK(once.Errors.empty() && once.Rounds == 0, what.str() << ": " << once.Errors);
            CompareUnion(controller, once.Output, rank == 0 ? &references[next] : nullptr,
              what.str() + ", in one step");
          }
        }
      }
    }
  }
  if (ranks > 1)
  {
    CollectiveErrors(controller);
  }

  return rgmc_test::Finish(controller, "TestDistributed",
    std::to_string(runs) + " runs compared, at most " + std::to_string(mostRounds) +
      " rounds of seeded growth between ranks, ");
}

// vtkRGDecimate on 1 rank (vtkDummyController) and under mpiexec, after vtkRGMarchingCubes and
// vtkRGSeamRepair: the phantom's skull, a torus around the corner where 8 ranks meet, five
// spheres (many small components) and a sphere cut open by the volume's border. The decimated
// surface must be the 1-rank one to the bit, in the same order (positions, normals and the
// triangles rank after rank, as the Merged Surface Writer writes them), on 1 and N threads;
// closed with the input's Euler characteristic (checked by the project's edge counts and by
// counting the gathered mesh's edges here); the border's vertices where they were; the triangle
// count within 1% of the target; every vertex within the asked error of the original surface
// when an error bound is set; made in waves (TrianglesPerWave), the same surface to the bit.
// Bad input gives the same error on every rank.
#include "rgmcDistributedData.h"
#include "rgmcNearestDistances.h"
#include "rgmcTestController.h"
#include "rgmcTestData.h"
#include "rgmcUnitedMesh.h"

#include "vtkCellArray.h"
#include "vtkCellLocator.h"
#include "vtkDataSetAttributes.h"
#include "vtkDoubleArray.h"
#include "vtkDummyController.h"
#include "vtkExecutive.h"
#include "vtkFieldData.h"
#include "vtkGenericCell.h"
#include "vtkIdTypeArray.h"
#include "vtkMath.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkRGDecimate.h"
#include "vtkRGPhantomSource.h"
#include "vtkRGSeamRepair.h"
#include "vtkRGSpan.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <iostream>
#include <map>
#include <set>
#include <sstream>

using namespace rgmc_test;

namespace
{

const int Whole[6] = { 0, 64, 0, 64, 0, 64 }; // 64 cells: even splits for 2, 4 and 8 ranks

struct Surface
{
  std::string Name;
  FieldMaker Make;
  double Isovalue;
  int Mode;
  Seeds SeedPoints;
  bool Thick; // no two sheets of the surface closer than a voxel
};

double Ball(int i, int j, int k, const double c[3], double radius)
{
  return radius -
    std::sqrt((i - c[0]) * (i - c[0]) + (j - c[1]) * (j - c[1]) + (k - c[2]) * (k - c[2]));
}

std::vector<Surface> Surfaces()
{
  std::vector<Surface> surfaces;
  surfaces.push_back(Surface{ "skull", [](const int extent[6]) { return PhantomPiece(extent, 65); },
    400.0, vtkRGMarchingCubes::SEEDED, { { 0, 0, 105 } }, false });
  surfaces.push_back(Surface{ "torus",
    [](const int extent[6])
    {
      return MakeImage(extent, VTK_FLOAT,
        [](int i, int j, int k)
        {
          const double rho = std::sqrt((i - 32.0) * (i - 32.0) + (j - 32.3) * (j - 32.3));
          return 7.2 - std::sqrt((rho - 18.0) * (rho - 18.0) + (k - 32.4) * (k - 32.4));
        });
    },
    0.0, vtkRGMarchingCubes::SEEDED, { { 50.0, 32.0, 32.0 } }, true });
  surfaces.push_back(Surface{ "five spheres",
    [](const int extent[6])
    {
      return MakeImage(extent, VTK_DOUBLE,
        [](int i, int j, int k)
        {
          const double centres[5][3] = { { 32, 32, 32 }, { 32, 12, 12 }, { 12, 32, 50 },
            { 50, 50, 32 }, { 12, 12, 12 } };
          double f = -1e9;
          for (const auto& c : centres)
          {
            f = std::max(f, Ball(i, j, k, c, 7.3));
          }
          return f;
        });
    },
    0.0, vtkRGMarchingCubes::ALL_COMPONENTS, {}, true });
  // Centred on the volume's face x = 0: open there, along a circle on the border.
  surfaces.push_back(Surface{ "sphere cut by the border",
    [](const int extent[6])
    {
      return MakeImage(extent, VTK_DOUBLE,
        [](int i, int j, int k)
        {
          const double c[3] = { 0.0, 31.7, 32.2 };
          return Ball(i, j, k, c, 25.3);
        });
    },
    0.0, vtkRGMarchingCubes::ALL_COMPONENTS, {}, true });
  return surfaces;
}

long long Count(vtkPolyData* pd, const char* name)
{
  vtkDataArray* a = vtkDataArray::SafeDownCast(pd->GetFieldData()->GetAbstractArray(name));
  return a ? static_cast<long long>(a->GetTuple1(0)) : -1;
}

struct Decimated
{
  vtkSmartPointer<vtkPolyData> Output;
  std::string Errors;
};

// Small blocks: dozens of them on these surfaces, so that most vertices are near a block's face
// in one pass or another, and blocks are spread over every rank.
const vtkIdType TrianglesPerBlock = 500;

Decimated Decimate(vtkMultiProcessController* controller, vtkPolyData* input, double reduction,
  double maximumError = 0.0, vtkIdType trianglesPerBlock = TrianglesPerBlock,
  vtkIdType trianglesPerWave = 4000000, bool computeDistance = true)
{
  vtkNew<vtkRGDecimate> decimate;
  decimate->SetComputeDistance(computeDistance);
  vtkNew<MessageCatcher> catcher;
  catcher->Watch(decimate);
  decimate->SetController(controller);
  decimate->SetInputData(input);
  decimate->SetTargetReduction(reduction);
  decimate->SetMaximumError(maximumError);
  decimate->SetTrianglesPerBlock(trianglesPerBlock);
  decimate->SetTrianglesPerWave(trianglesPerWave);
  UpdateAtThreads(decimate, "Decimate",
    [&catcher]()
    {
      catcher->Errors.clear();
      catcher->Warnings.clear();
    });
  Decimated d;
  d.Output = vtkSmartPointer<vtkPolyData>::New();
  d.Output->ShallowCopy(decimate->GetOutput());
  d.Errors = catcher->Errors;
  const vtkIdType collectives = decimate->GetNumberOfCollectives();
  RGMC_CHECK(SameOnAllRanks(controller, std::to_string(collectives)) && collectives > 0,
    "Decimate: the ranks made different numbers of collective calls (" << collectives << " here)");
  return d;
}

vtkSmartPointer<vtkPolyData> Repair(vtkMultiProcessController* controller, vtkPolyData* input)
{
  vtkNew<vtkRGSeamRepair> repair;
  repair->SetController(controller);
  repair->SetInputData(input);
  repair->Update();
  auto out = vtkSmartPointer<vtkPolyData>::New();
  out->ShallowCopy(repair->GetOutput());
  return out;
}

/// The surface as the Merged Surface Writer writes it: vertices by global id (position and normal
/// bits), triangles rank after rank in their order, as global-id triples; and what the union
/// must satisfy.
struct Merged : rgmc_test::UnitedMesh<double>
{
  /// Edges used by one triangle, and edges not used exactly once in each direction.
  void CountEdges(long long& boundary, long long& bad, long long& edges) const
  {
    std::map<std::pair<long long, long long>, int> directed;
    for (const auto& t : this->Triangles)
    {
      for (int k = 0; k < 3; ++k)
      {
        ++directed[{ t[k], t[(k + 1) % 3] }];
      }
    }
    boundary = bad = edges = 0;
    for (const auto& e : directed)
    {
      const auto back = directed.find({ e.first.second, e.first.first });
      const int reverse = back == directed.end() ? 0 : back->second;
      if (e.first.first < e.first.second || reverse == 0)
      {
        ++edges;
      }
      if (reverse == 0)
      {
        ++boundary;
      }
      bad += e.second != 1 || reverse > 1;
    }
  }

  /// The positions of the vertices on boundary edges.
  std::set<std::array<std::uint64_t, 3>> BorderPositions() const
  {
    std::set<std::pair<long long, long long>> directed;
    for (const auto& t : this->Triangles)
    {
      for (int k = 0; k < 3; ++k)
      {
        directed.insert({ t[k], t[(k + 1) % 3] });
      }
    }
    std::set<std::array<std::uint64_t, 3>> border;
    for (const auto& e : directed)
    {
      if (!directed.count({ e.second, e.first }))
      {
        for (long long v : { e.first, e.second })
        {
          const auto& b = this->Points.at(v);
          border.insert({ b[0], b[1], b[2] });
        }
      }
    }
    return border;
  }
};

Merged Gather(vtkMultiProcessController* controller, vtkPolyData* piece)
{
  std::vector<vtkSmartPointer<vtkDataObject>> pieces;
  controller->Gather(piece, pieces, 0);
  Merged merged;
  for (auto& p : pieces)
  {
    merged.Add(vtkPolyData::SafeDownCast(p));
  }
  return merged;
}

/// The triangles as triples of their corners' positions (bits), each turned to start at its
/// least corner (orientation kept), sorted: the mesh whatever its numbering and order.
std::vector<std::array<std::array<std::uint64_t, 3>, 3>> TrianglesByPosition(const Merged& mesh)
{
  std::vector<std::array<std::array<std::uint64_t, 3>, 3>> out;
  for (const auto& t : mesh.Triangles)
  {
    std::array<std::array<std::uint64_t, 3>, 3> corners;
    for (int k = 0; k < 3; ++k)
    {
      const auto& bits = mesh.Points.at(t[k]);
      corners[k] = { bits[0], bits[1], bits[2] };
    }
    std::rotate(corners.begin(), std::min_element(corners.begin(), corners.end()), corners.end());
    out.push_back(corners);
  }
  std::sort(out.begin(), out.end());
  return out;
}

/// The largest distance from a vertex of `decimated` to the surface `original`.
double FarthestVertex(vtkPolyData* decimated, vtkPolyData* original)
{
  return rgmc_test::Nearest(decimated, original).Largest;
}

/// A field value of the output (NaN when missing).
double Field(vtkPolyData* pd, const char* name)
{
  vtkDataArray* a = vtkDataArray::SafeDownCast(pd->GetFieldData()->GetAbstractArray(name));
  return a && a->GetNumberOfTuples() == 1 ? a->GetTuple1(0) : std::nan("");
}

/// How many triangles of `decimated` face away from the triangle of `original` nearest to their
/// centre (a flipped triangle does).
long long FacingAway(vtkPolyData* decimated, vtkPolyData* original)
{
  vtkNew<vtkCellLocator> locator;
  locator->SetDataSet(original);
  locator->BuildLocator();
  vtkNew<vtkGenericCell> cell;
  long long away = 0;
  auto normal = [](vtkPolyData* pd, vtkIdType t, double n[3], double centre[3])
  {
    vtkIdType npts;
    const vtkIdType* pts;
    pd->GetCellPoints(t, npts, pts);
    double p[3][3];
    for (int k = 0; k < 3; ++k)
    {
      pd->GetPoint(pts[k], p[k]);
    }
    double u[3], v[3];
    for (int a = 0; a < 3; ++a)
    {
      u[a] = p[1][a] - p[0][a];
      v[a] = p[2][a] - p[0][a];
      centre[a] = (p[0][a] + p[1][a] + p[2][a]) / 3.0;
    }
    vtkMath::Cross(u, v, n);
  };
  for (vtkIdType t = 0; t < decimated->GetNumberOfCells(); ++t)
  {
    double n[3], centre[3], m[3], other[3], closest[3], d2;
    vtkIdType cellId;
    int subId;
    normal(decimated, t, n, centre);
    locator->FindClosestPoint(centre, closest, cell, cellId, subId, d2);
    normal(original, cellId, m, other);
    away += vtkMath::Dot(n, m) < 0;
  }
  return away;
}

/// The gathered mesh as a vtkPolyData with points in global-id order.
vtkSmartPointer<vtkPolyData> AsPolyData(const Merged& m)
{
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  std::map<long long, vtkIdType> index;
  for (const auto& p : m.Points)
  {
    double x[3];
    std::memcpy(x, p.second.data(), 24);
    index[p.first] = points->InsertNextPoint(x);
  }
  vtkNew<vtkCellArray> polys;
  for (const auto& t : m.Triangles)
  {
    const vtkIdType ids[3] = { index[t[0]], index[t[1]], index[t[2]] };
    polys->InsertNextCell(3, ids);
  }
  pd->SetPoints(points);
  pd->SetPolys(polys);
  return pd;
}

/// What every decimated surface must satisfy, checked on the gathered mesh (rank 0); the
/// triangle count within 1% of the target when `reduction` is not negative.
void CheckSurface(const Merged& input, const Merged& output, vtkPolyData* piece, double reduction,
  const std::string& what)
{
  long long inBoundary, inBad, inEdges, outBoundary, outBad, outEdges;
  input.CountEdges(inBoundary, inBad, inEdges);
  output.CountEdges(outBoundary, outBad, outEdges);
  const long long inEuler = static_cast<long long>(input.Points.size()) - inEdges +
    static_cast<long long>(input.Triangles.size());
  const long long outEuler = static_cast<long long>(output.Points.size()) - outEdges +
    static_cast<long long>(output.Triangles.size());
  RGMC_CHECK(outBad == 0 && inBad == 0,
    what << ": " << outBad << " edges not used once each way (input " << inBad << ")");
  RGMC_CHECK(outBoundary == inBoundary,
    what << ": " << outBoundary << " boundary edges, the input had " << inBoundary);
  RGMC_CHECK(
    outEuler == inEuler, what << ": Euler characteristic " << outEuler << ", input " << inEuler);
  RGMC_CHECK(Count(piece, "NonManifoldEdges") == 0 && Count(piece, "BoundaryEdges") == 0,
    what << ": Seam Repair's checks of the output: " << Count(piece, "BoundaryEdges")
         << " boundary and " << Count(piece, "NonManifoldEdges") << " non-manifold edges");
  RGMC_CHECK(input.BorderPositions() == output.BorderPositions(),
    what << ": the vertices on the volume's border moved or went");
  const double in = static_cast<double>(input.Triangles.size());
  const double kept = static_cast<double>(output.Triangles.size()) / in;
  RGMC_CHECK(reduction < 0 || std::abs(kept - (1.0 - reduction)) <= 0.01,
    what << ": kept " << output.Triangles.size() << " of " << input.Triangles.size()
         << " triangles (" << kept << "), asked " << 1.0 - reduction);
  long long badOwners = 0;
  for (const auto& o : output.Owners)
  {
    badOwners += o.second != 1;
  }
  RGMC_CHECK(badOwners == 0 && output.Inconsistent == 0,
    what << ": " << badOwners << " vertices without one owner, " << output.Inconsistent
         << " copies that differ");
  RGMC_CHECK(!output.Points.empty() &&
      output.Points.rbegin()->first == static_cast<long long>(output.Points.size()) - 1,
    what << ": global ids are not 0..N-1");
}

/// The phases of a work/span profile of a decimation with its distance report: the numbering's
/// own phases under "numbering: ", the report's under their own names (not the numbering's).
void SpanPhases(vtkMultiProcessController* controller, vtkPolyData* input)
{
  vtkNew<vtkRGDecimate> decimate; // updated once, here (Decimate's thread comparison records)
  decimate->SetController(controller);
  decimate->SetInputData(input);
  decimate->SetTargetReduction(0.9);
  decimate->SetTrianglesPerBlock(TrianglesPerBlock);
  rgmc::SpanRecorder recorder;
  recorder.Start();
  const int ok = decimate->GetExecutive()->Update();
  recorder.Stop();
  RGMC_CHECK(ok, "the profiled decimation failed");
  bool sort = false, collect = false, nested = false;
  for (const rgmc::SpanPhase& phase : recorder.Phases())
  {
    sort = sort || phase.Name == "numbering: numbering: sort";
    collect = collect || phase.Name == "distance: collect";
    nested = nested || phase.Name.rfind("numbering: distance", 0) == 0;
  }
  RGMC_CHECK(sort && collect && !nested,
    "the profile's phases: the numbering's sort " << sort << ", the report's collect " << collect
                                                  << ", the report under the numbering " << nested);
}

void BadInput(vtkMultiProcessController* controller, vtkPolyData* good)
{
  const int rank = controller->GetLocalProcessId(), ranks = controller->GetNumberOfProcesses();
  auto expect =
    [&](const std::string& what, vtkPolyData* input, double reduction, const std::string& text)
  {
    const Decimated d = Decimate(controller, input, reduction);
    RGMC_CHECK(d.Errors.find(text) != std::string::npos,
      what << " (rank " << rank << "): expected '" << text << "', got [" << d.Errors << "]");
    RGMC_CHECK(d.Output->GetNumberOfCells() == 0, what << ": output not empty");
    const std::size_t at = d.Errors.find("): ");
    const std::string message = at == std::string::npos ? d.Errors : d.Errors.substr(at + 3);
    RGMC_CHECK(SameOnAllRanks(controller, message), what << ": the ranks' messages differ");
    std::cout << (rank == 0 ? what + ": " + message : std::string());
  };
  expect("Target Reduction 0", good, 0.0, "Target Reduction is 0");
  expect("Target Reduction 1", good, 1.0, "Target Reduction is 1");
  expect("Target Reduction NaN", good, vtkMath::Nan(), "Target Reduction is nan");
  {
    auto unnumbered = vtkSmartPointer<vtkPolyData>::New();
    unnumbered->DeepCopy(good);
    if (rank == ranks - 1)
    {
      unnumbered->GetPointData()->SetGlobalIds(nullptr);
    }
    expect("no global ids on the last rank", unnumbered, 0.5, "without global point ids");
  }
  {
    auto nan = vtkSmartPointer<vtkPolyData>::New();
    nan->DeepCopy(good);
    if (rank == 0 && nan->GetNumberOfPoints() > 0)
    {
      nan->GetPoints()->SetPoint(0, vtkMath::Nan(), 0, 0);
    }
    long long points = nan->GetNumberOfPoints();
    controller->Broadcast(&points, 1, 0);
    if (points > 0)
    {
      expect("a NaN point on rank 0", nan, 0.5, "not a finite number");
    }
  }
  {
    auto quads = vtkSmartPointer<vtkPolyData>::New();
    quads->DeepCopy(good);
    if (rank == 0)
    {
      const vtkIdType q[4] = { 0, 1, 2, 3 };
      quads->GetPolys()->InsertNextCell(4, q);
    }
    expect("a quad on rank 0", quads, 0.5, "1 polygons that are not triangles");
  }
  {
    vtkNew<vtkPolyData> empty;
    expect("nothing on any rank", empty, 0.5, "no triangles");
  }
}

} // namespace

int main(int argc, char* argv[])
{
  vtkSmartPointer<vtkMultiProcessController> controller = rgmc_test::StartController(argc, argv);
  const int rank = controller->GetLocalProcessId(), ranks = controller->GetNumberOfProcesses();
  vtkNew<vtkDummyController> single;
  const double reduction = 0.9;
  vtkSmartPointer<vtkPolyData> firstRepaired;

  for (const Surface& surface : Surfaces())
  {
    // The 1-rank reference.
    Merged reference;
    double hausdorffOne = 0, meanOne = 0;
    if (rank == 0)
    {
      vtkSmartPointer<vtkImageData> whole = surface.Make(Whole);
      vtkSmartPointer<vtkPolyData> repaired = Repair(
        single, Extract(single, whole, surface.Isovalue, surface.Mode, surface.SeedPoints).Output);
      const Decimated d = Decimate(single, repaired, reduction);
      RGMC_CHECK(d.Errors.empty(), surface.Name << " on 1 rank: " << d.Errors);
      Merged input = Gather(single, repaired);
      reference = Gather(single, d.Output);
      CheckSurface(input, reference, d.Output, reduction, surface.Name + " on 1 rank");
      std::cout << surface.Name << ": " << input.Triangles.size() << " -> "
                << reference.Triangles.size() << " triangles, quadric error "
                << d.Output->GetFieldData()->GetArray("DecimationQuadricError")->GetTuple1(0)
                << ", farthest vertex "
                << FarthestVertex(AsPolyData(reference), AsPolyData(input).GetPointer()) << "\n";
      // Facing the same way: no triangle turned over. (Where two sheets of the surface are
      // closer than a voxel, as the phantom skull's thin bone at 64^3 is, the nearest original
      // triangle can be on the other sheet: not a test there.)
      if (surface.Thick)
      {
        const long long away = FacingAway(AsPolyData(reference), AsPolyData(input).GetPointer());
        RGMC_CHECK(away == 0,
          surface.Name << ": " << away << " triangles face away from the original surface");
      }
      // The distance report against the locator's: every vertex of each surface (once) to the
      // other surface, the largest and the mean of the two directions' means.
      {
        vtkSmartPointer<vtkPolyData> in = AsPolyData(input), out = AsPolyData(reference);
        const double hausdorff = std::max(FarthestVertex(out, in), FarthestVertex(in, out));
        const double mean =
          0.5 * (rgmc_test::Nearest(in, out).Mean + rgmc_test::Nearest(out, in).Mean);
        hausdorffOne = Field(d.Output, "DecimationHausdorffDistance");
        meanOne = Field(d.Output, "DecimationMeanDistance");
        std::cout << surface.Name << ": distance report Hausdorff " << hausdorffOne << " mean "
                  << meanOne << "; the locator's " << hausdorff << ", " << mean << "\n";
        RGMC_CHECK(std::abs(hausdorffOne - hausdorff) <= 1e-9 * (1 + hausdorff) &&
            std::abs(meanOne - mean) <= 1e-9 * (1 + mean),
          surface.Name << ": the distance report (" << hausdorffOne << ", " << meanOne
                       << ") is not the locator's (" << hausdorff << ", " << mean << ")");
        const Decimated off =
          Decimate(single, repaired, reduction, 0.0, TrianglesPerBlock, 1 << 30, false);
        RGMC_CHECK(std::isnan(Field(off.Output, "DecimationHausdorffDistance")),
          surface.Name << ": Compute Distance off, yet a distance is reported");
      }
      // In waves (the blocks made and simplified a few at a time, then made again to apply
      // what they keep): the same surface to the bit.
      {
        const Decimated waves = Decimate(single, repaired, reduction, 0.0, TrianglesPerBlock, 1000);
        const Merged wavesMesh = Gather(single, waves.Output);
        RGMC_CHECK(
          wavesMesh.Points == reference.Points && wavesMesh.Triangles == reference.Triangles,
          surface.Name << " in waves of 1000 triangles: not the surface made at once");
      }
      // Nothing to remove (a Target Reduction that rounds to no triangle: no pass runs): the
      // input surface itself, its points and triangles, numbered as the output is.
      {
        const Decimated none = Decimate(single, repaired, 1e-9);
        RGMC_CHECK(none.Errors.empty(), surface.Name << ", nothing to remove: " << none.Errors);
        const Merged noneMesh = Gather(single, none.Output);
        CheckSurface(input, noneMesh, none.Output, 0.0, surface.Name + ", nothing to remove");
        RGMC_CHECK(TrianglesByPosition(noneMesh) == TrianglesByPosition(input),
          surface.Name << ", nothing to remove: not the input's triangles");
      }
      // Tiny blocks (most vertices near a block's face in every pass): more passes, the same
      // guarantees, and still the target.
      {
        const Decimated tiny = Decimate(single, repaired, reduction, 0.0, 150);
        CheckSurface(input, Gather(single, tiny.Output), tiny.Output, reduction,
          surface.Name + " in blocks of 150 triangles");
      }
      // As far as it goes: still closed and of the same topology.
      {
        const Decimated most = Decimate(single, repaired, 0.9999);
        const Merged mostMesh = Gather(single, most.Output);
        CheckSurface(input, mostMesh, most.Output, -1, surface.Name + " decimated to the end");
        std::cout << surface.Name << ", as far as it goes: " << mostMesh.Triangles.size()
                  << " triangles\n";
        RGMC_CHECK(mostMesh.Triangles.size() * 20 < input.Triangles.size(),
          surface.Name << ": decimated to the end, " << mostMesh.Triangles.size() << " of "
                       << input.Triangles.size() << " triangles remain");
      }
      // With an error bound, every vertex stays within it of the original surface.
      const double bound = 0.25;
      const Decimated bounded = Decimate(single, repaired, 0.99, bound);
      const Merged boundedMesh = Gather(single, bounded.Output);
      // Both ways: the decimated vertices from the original surface, and the original vertices
      // from the decimated surface (the symmetric Hausdorff distance, sampled at the vertices).
      const double farthest =
        std::max(FarthestVertex(AsPolyData(boundedMesh), AsPolyData(input).GetPointer()),
          FarthestVertex(AsPolyData(input), AsPolyData(boundedMesh).GetPointer()));
      std::cout << surface.Name << ", Maximum Error " << bound << ": "
                << boundedMesh.Triangles.size() << " triangles, Hausdorff distance " << farthest
                << "\n";
      RGMC_CHECK(farthest <= bound,
        surface.Name << ": the surfaces are " << farthest << " apart, the bound is " << bound);
      RGMC_CHECK(boundedMesh.Triangles.size() < input.Triangles.size() &&
          boundedMesh.Triangles.size() > (1 - 0.99) * input.Triangles.size(),
        surface.Name << ": the error bound did not stop the decimation ("
                     << boundedMesh.Triangles.size() << " triangles)");
    }
    for (const std::string& how : Decompositions(ranks))
    {
      vtkSmartPointer<vtkImageData> image =
        MakePiece(surface.Make, Whole, PieceOf(how, Whole, rank, ranks));
      vtkSmartPointer<vtkPolyData> repaired = Repair(controller,
        Extract(controller, image, surface.Isovalue, surface.Mode, surface.SeedPoints).Output);
      if (!firstRepaired)
      {
        firstRepaired = repaired;
      }
      const Decimated d = Decimate(controller, repaired, reduction);
      const std::string what =
        surface.Name + ", " + how + " on " + std::to_string(ranks) + " ranks";
      RGMC_CHECK(d.Errors.empty(), what << ": " << d.Errors);
      const Merged input = Gather(controller, repaired);
      const Merged output = Gather(controller, d.Output);
      if (rank == 0)
      {
        CheckSurface(input, output, d.Output, reduction, what);
        RGMC_CHECK(output.Points == reference.Points,
          what << ": the vertices differ from 1 rank's (bitwise)");
        RGMC_CHECK(output.Triangles == reference.Triangles,
          what << ": the triangles differ from 1 rank's (" << output.Triangles.size() << " and "
               << reference.Triangles.size() << ", or in another order)");
        const double h = Field(d.Output, "DecimationHausdorffDistance");
        const double m = Field(d.Output, "DecimationMeanDistance");
        RGMC_CHECK(
          std::memcmp(&h, &hausdorffOne, sizeof h) == 0 && std::memcmp(&m, &meanOne, sizeof m) == 0,
          what << ": the distance report (" << h << ", " << m << ") is not 1 rank's ("
               << hausdorffOne << ", " << meanOne << ") to the bit");
      }
      RGMC_CHECK(
        SameOnAllRanks(controller, std::to_string(Field(d.Output, "DecimationMeanDistance"))),
        what << ": the ranks' distance reports differ");
      // In waves, on the first decomposition: each rank's blocks a few at a time.
      if (how == Decompositions(ranks).front())
      {
        const Decimated waves =
          Decimate(controller, repaired, reduction, 0.0, TrianglesPerBlock, 1000);
        const Merged wavesMesh = Gather(controller, waves.Output);
        if (rank == 0)
        {
          RGMC_CHECK(
            wavesMesh.Points == reference.Points && wavesMesh.Triangles == reference.Triangles,
            what << ", in waves of 1000 triangles: not 1 rank's surface");
        }
        // Nothing to remove: each rank's piece as it came.
        const Decimated none = Decimate(controller, repaired, 1e-9);
        const Merged noneMesh = Gather(controller, none.Output);
        if (rank == 0)
        {
          RGMC_CHECK(
            none.Errors.empty() && TrianglesByPosition(noneMesh) == TrianglesByPosition(input),
            what << ", nothing to remove: not the input's triangles " << none.Errors);
        }
      }
    }
  }
  BadInput(controller, firstRepaired);
  SpanPhases(controller, firstRepaired);
  return rgmc_test::Finish(controller, "TestDecimate");
}

// The oracle test of vtkRGMarchingCubes on one rank: its output equals vtkMarchingCubes followed
// by vtkPolyDataConnectivityFilter (closest point region) for every seed, and vtkMarchingCubes
// alone in the All mode: the same triangles over the same vertices, the same normals.
//
// Where the two can differ, and why:
// - vtkMarchingCubes merges vertices through a point locator on float coordinates, so two
//   distinct edge vertices that round to the same float become one point (and a triangle
//   between them is dropped). Ours never merges distinct edges. Compare() maps our vertices to
//   theirs by position and counts such merges ("float-merged"); the triangle sets are compared
//   after the same merge, and the test prints how often it happened.
// - vtkMarchingCubes keeps the points of triangles it drops (their vertices collapsed); the
//   connectivity filter can pick such an orphan as the closest point. The oracle removes them
//   first (vtkCleanPolyData without merging), since they are on no triangle.
// - With spacing, origin or direction, vtkMarchingCubes stores index-space points as float and
//   transforms them afterwards, so its points carry float rounding of the index coordinates.
//   Those cases are checked three ways: against vtkMarchingCubes on the index-space image
//   (exact), against our own index-space output transformed in double (1e-6 of the spacing),
//   and against vtkMarchingCubes with a tolerance of float precision at the coordinates' size.
#include "rgmcTestData.h"
#include "rgmcThreadCompare.h"

#include "vtkCellData.h"
#include "vtkFieldData.h"
#include "vtkIdTypeArray.h"
#include "vtkIntArray.h"
#include "vtkRGMarchingCubes.h"
#include "vtkRGPhantomSource.h"

#include <iostream>
#include <sstream>

using namespace rgmc_test;

namespace
{

vtkSmartPointer<vtkPolyData> Extract(vtkImageData* image, double isovalue,
  const std::vector<std::array<double, 3>>& seeds, int mode = vtkRGMarchingCubes::SEEDED,
  int precision = vtkAlgorithm::SINGLE_PRECISION)
{
  vtkNew<vtkRGMarchingCubes> rg;
  rg->SetInputData(image);
  rg->SetIsovalue(isovalue);
  rg->SetExtractionMode(mode);
  rg->SetSeedSearchRadius(1e30); // the oracle's closest point has no radius
  rg->SetOutputPointsPrecision(precision);
  for (const auto& s : seeds)
  {
    rg->AddSeedPoint(s[0], s[1], s[2]);
  }
  rgmc_test::UpdateAtThreads(rg, "extraction");
  auto out = vtkSmartPointer<vtkPolyData>::New();
  out->ShallowCopy(rg->GetOutput());
  return out;
}

int TotalMerged = 0;

void Expect(const std::string& what, const Comparison& c, double normalTolerance = 1e-5)
{
  std::cout << what << ": " << c << "\n";
  RGMC_CHECK(c.SameTriangles(), what << ": " << c);
  RGMC_CHECK(
    c.MaxNormalError <= normalTolerance, what << ": normals differ by " << c.MaxNormalError);
  TotalMerged += static_cast<int>(c.Merged);
}

/// The comparison itself counts triangles with multiplicity: a mesh with one triangle twice is
/// not the mesh with it once, either way round.
void ComparisonCountsMultiplicity(vtkImageData* image, double isovalue)
{
  vtkSmartPointer<vtkPolyData> mc = MarchingCubes(image, isovalue);
  auto twice = vtkSmartPointer<vtkPolyData>::New();
  twice->DeepCopy(mc);
  vtkIdType npts;
  const vtkIdType* pts;
  twice->GetPolys()->GetCellAtId(0, npts, pts);
  const std::vector<vtkIdType> first(pts, pts + npts);
  twice->GetPolys()->InsertNextCell(npts, first.data());
  const Comparison extra = Compare(twice, mc, 1e-6), missing = Compare(mc, twice, 1e-6);
  RGMC_CHECK(extra.ExtraOurs == 1 && extra.MissingTheirs == 0 && !extra.SameTriangles(),
    "a duplicated triangle of ours: " << extra);
  RGMC_CHECK(missing.MissingTheirs == 1 && missing.ExtraOurs == 0 && !missing.SameTriangles(),
    "a duplicated triangle of theirs: " << missing);
}

/// Seeded mode (each seed alone, then all together), All and Largest, against the oracle.
void CompareModes(const std::string& name, vtkImageData* image, double isovalue,
  const std::vector<std::array<double, 3>>& seeds, double tolerance)
{
  vtkSmartPointer<vtkPolyData> mc = MarchingCubes(image, isovalue);
  RGMC_CHECK(mc->GetNumberOfCells() > 0, name << ": the field has no surface");
  for (std::size_t s = 0; s < seeds.size(); ++s)
  {
    std::ostringstream what;
    what << name << " seed " << s << " (" << seeds[s][0] << ", " << seeds[s][1] << ", "
         << seeds[s][2] << ")";
    Expect(what.str(),
      Compare(Extract(image, isovalue, { seeds[s] }), ClosestRegions(mc, { seeds[s] }), tolerance));
  }
  Expect(name + " all seeds at once",
    Compare(Extract(image, isovalue, seeds), ClosestRegions(mc, seeds), tolerance));

  vtkSmartPointer<vtkPolyData> all =
    Extract(image, isovalue, {}, vtkRGMarchingCubes::ALL_COMPONENTS);
  Expect(name + " all components", Compare(all, mc, tolerance));

  vtkNew<vtkPolyDataConnectivityFilter> regions;
  regions->SetInputData(mc);
  regions->SetExtractionModeToAllRegions();
  regions->Update();
  const int numRegions = regions->GetNumberOfExtractedRegions();
  const vtkIdType components =
    vtkIdTypeArray::SafeDownCast(all->GetFieldData()->GetArray("NumberOfComponents"))->GetValue(0);
  RGMC_CHECK(components == numRegions,
    name << ": " << components << " components, VTK finds " << numRegions);
  std::cout << name << ": " << numRegions << " components\n";

  // ComponentId numbers the components by their smallest vertex key.
  vtkIntArray* ids = vtkIntArray::SafeDownCast(all->GetCellData()->GetArray("ComponentId"));
  vtkIdTypeArray* keys = vtkIdTypeArray::SafeDownCast(all->GetPointData()->GetGlobalIds());
  std::vector<vtkIdType> minKey(components, VTK_ID_MAX);
  for (vtkIdType t = 0; t < all->GetNumberOfCells(); ++t)
  {
    vtkIdType npts;
    const vtkIdType* pts;
    all->GetCellPoints(t, npts, pts);
    for (int v = 0; v < 3; ++v)
    {
      minKey[ids->GetValue(t)] = std::min(minKey[ids->GetValue(t)], keys->GetValue(pts[v]));
    }
  }
  RGMC_CHECK(std::is_sorted(minKey.begin(), minKey.end()), name << ": ComponentId order");

  vtkNew<vtkPolyDataConnectivityFilter> largest;
  largest->SetInputData(mc);
  largest->SetExtractionModeToLargestRegion();
  largest->Update();
  Expect(name + " largest component",
    Compare(Extract(image, isovalue, {}, vtkRGMarchingCubes::LARGEST_COMPONENT),
      largest->GetOutput(), tolerance));
}

/// Compares with the oracle. An image with spacing, origin or direction is compared three ways
/// (see the top of the file): in index space exactly, against our index-space output mapped in
/// double, and against vtkMarchingCubes within float precision of its coordinates.
void CheckField(const std::string& name, vtkImageData* image, double isovalue,
  const std::vector<std::array<double, 3>>& seeds)
{
  vtkMatrix4x4* m = image->GetIndexToPhysicalMatrix();
  if (m->IsIdentity())
  {
    CompareModes(name, image, isovalue, seeds, 1e-6);
    return;
  }

  // 1. The same samples in index space, exactly vtkMarchingCubes.
  vtkNew<vtkImageData> indexImage;
  indexImage->ShallowCopy(image);
  indexImage->SetSpacing(1, 1, 1);
  indexImage->SetOrigin(0, 0, 0);
  const double identity[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 1 };
  indexImage->SetDirectionMatrix(identity);
  std::vector<std::array<double, 3>> indexSeeds;
  for (const auto& x : seeds)
  {
    double q[3];
    image->TransformPhysicalPointToContinuousIndex(x.data(), q);
    indexSeeds.push_back({ q[0], q[1], q[2] });
  }
  CompareModes(name + " [index space]", indexImage, isovalue, indexSeeds, 1e-6);

  // 2. Our double output equals our index-space output mapped in double (1e-6 of the spacing).
  // The seeded mode is left out: the nearest vertex in world distance is not the nearest in
  // index distance once the spacing is anisotropic.
  double spacing[3];
  image->GetSpacing(spacing);
  const double* direction = image->GetDirectionMatrix()->GetData();
  const double det = image->GetDirectionMatrix()->Determinant();
  double normalMatrix[3][3];
  for (int r = 0; r < 3; ++r)
  {
    for (int k = 0; k < 3; ++k)
    {
      normalMatrix[r][k] = det * direction[3 * r + k] / spacing[k];
    }
  }
  for (int mode : { vtkRGMarchingCubes::LARGEST_COMPONENT, vtkRGMarchingCubes::ALL_COMPONENTS })
  {
    auto ours = Extract(image, isovalue, {}, mode, vtkAlgorithm::DOUBLE_PRECISION);
    auto base = Extract(indexImage, isovalue, {}, mode, vtkAlgorithm::DOUBLE_PRECISION);
    vtkNew<vtkPolyData> mapped;
    mapped->DeepCopy(base);
    vtkNew<vtkFloatArray> normals;
    normals->SetNumberOfComponents(3);
    normals->SetNumberOfTuples(mapped->GetNumberOfPoints());
    for (vtkIdType p = 0; p < mapped->GetNumberOfPoints(); ++p)
    {
      double x[4] = { 0, 0, 0, 1 }, y[4];
      mapped->GetPoint(p, x);
      m->MultiplyPoint(x, y);
      mapped->GetPoints()->SetPoint(p, y);
      double n[3], w[3];
      base->GetPointData()->GetNormals()->GetTuple(p, n);
      vtkMath::Multiply3x3(normalMatrix, n, w);
      vtkMath::Normalize(w);
      normals->SetTuple(p, w);
    }
    mapped->GetPointData()->SetNormals(normals);
    const double minSpacing = std::min(spacing[0], std::min(spacing[1], spacing[2]));
    Expect(name + " mode " + std::to_string(mode) + " vs index space mapped in double",
      Compare(ours, mapped, 1e-6 * minSpacing));
  }

  // 3. vtkMarchingCubes with the geometry, within float precision of the coordinates.
  double bounds[6], magnitude = 0;
  image->GetBounds(bounds);
  for (double b : bounds)
  {
    magnitude = std::max(magnitude, std::fabs(b));
  }
  CompareModes(name, image, isovalue, seeds, 8 * magnitude * 6e-8);
}

void Blobs()
{
  const int extent[6] = { 3, 42, -5, 38, 10, 45 }; // not starting at 0: global indices matter
  auto image = MakeImage(extent, VTK_FLOAT, rgmc_test::Blobs(extent, 40, 7));
  ComparisonCountsMultiplicity(image, 0.3);
  CheckField("blobs (float32)", image, 0.3, RandomSeeds(image, 6, 11));
}

void Phantom()
{
  vtkNew<vtkRGPhantomSource> phantom;
  phantom->SetDimensions(72, 72, 72);
  phantom->Update();
  vtkImageData* image = phantom->GetOutput();
  std::vector<std::array<double, 3>> bone = { { 0, 0, 105 }, { 0, 65, -75 }, { 0, -20, -96 } };
  for (const auto& s : RandomSeeds(image, 3, 5))
  {
    bone.push_back(s);
  }
  CheckField("phantom bone (int16, 400 HU)", image, 400, bone);
  CheckField("phantom skin (int16, -300 HU)", image, -300, RandomSeeds(image, 3, 6));
}

/// Integer samples, many exactly equal to the isovalue: vertices on grid points, collapsed
/// triangles dropped.
void EqualSamples()
{
  const int extent[6] = { 0, 35, 0, 31, 0, 33 };
  auto blobs = rgmc_test::Blobs(extent, 30, 3);
  auto quantized = [&](int i, int j, int k) { return std::round(100 + 60 * blobs(i, j, k)); };
  auto image = MakeImage(extent, VTK_UNSIGNED_CHAR, quantized);
  const double isovalue = 118;
  int equal = 0;
  vtkDataArray* f = image->GetPointData()->GetScalars();
  for (vtkIdType n = 0; n < f->GetNumberOfTuples(); ++n)
  {
    equal += f->GetComponent(n, 0) == isovalue;
  }
  RGMC_CHECK(equal > 50, "the field should have many samples equal to the isovalue: " << equal);
  auto all = Extract(image, isovalue, {}, vtkRGMarchingCubes::ALL_COMPONENTS);
  vtkIdTypeArray* keys = vtkIdTypeArray::SafeDownCast(all->GetPointData()->GetGlobalIds());
  const vtkIdType numGridPoints = 36 * 32 * 34;
  int onGridPoints = 0;
  for (vtkIdType p = 0; p < keys->GetNumberOfTuples(); ++p)
  {
    onGridPoints += keys->GetValue(p) >= 3 * numGridPoints;
  }
  RGMC_CHECK(onGridPoints > 0, "some vertices must sit on grid points");
  std::cout << "equal samples: " << equal << " samples equal the isovalue, " << onGridPoints
            << " vertices on grid points\n";
  CheckField(
    "quantized (uint8, samples equal to the isovalue)", image, isovalue, RandomSeeds(image, 5, 9));
}

/// Random samples in {0, 1, 2} with isovalue 1: a fifth of the samples equal the isovalue, so
/// vertices collapse everywhere and many surfaces touch only at a grid point or through a
/// vertex whose neighbouring cubes lost all their triangles there. Growth must still find
/// exactly what connectivity on vtkMarchingCubes' merged points finds.
void Degenerate()
{
  const int extent[6] = { 0, 17, 0, 15, 0, 16 };
  vtkNew<vtkMinimalStandardRandomSequence> random;
  random->SetSeed(1234);
  // Sparse enough to leave many small components that touch in degenerate ways.
  auto image = MakeImage(extent, VTK_UNSIGNED_CHAR,
    [&](int, int, int)
    {
      const double r = random->GetNextRangeValue(0.0, 1.0);
      return r < 0.62 ? 0.0 : (r < 0.84 ? 1.0 : 2.0);
    });
  CheckField("random {0,1,2} (uint8, a fifth equal to the isovalue)", image, 1.0,
    RandomSeeds(image, 40, 77));
}

/// Every numeric type gives the same surface for the same integer-valued field.
void ScalarTypes()
{
  const int extent[6] = { 0, 29, 0, 27, 0, 25 };
  auto blobs = rgmc_test::Blobs(extent, 25, 21);
  // Values in [0, 127] so that every type, signed char included, holds them exactly.
  auto field = [&](int i, int j, int k) { return std::round(40 + 30 * blobs(i, j, k)); };
  const int types[] = { VTK_UNSIGNED_CHAR, VTK_SHORT, VTK_UNSIGNED_SHORT, VTK_INT, VTK_FLOAT,
    VTK_DOUBLE, VTK_LONG_LONG, VTK_SIGNED_CHAR };
  auto reference = MakeImage(extent, VTK_DOUBLE, field);
  auto seeds = RandomSeeds(reference, 3, 4);
  vtkSmartPointer<vtkPolyData> expected = Extract(reference, 61.5, seeds);
  for (int type : types)
  {
    auto image = MakeImage(extent, type, field);
    auto out = Extract(image, 61.5, seeds);
    const std::string typeName = image->GetPointData()->GetScalars()->GetDataTypeAsString();
    Expect("type " + typeName + " vs double", Compare(out, expected, 0.0), 0.0);
    Expect("type " + typeName + " vs vtkMarchingCubes",
      Compare(out, ClosestRegions(MarchingCubes(image, 61.5), seeds), 1e-6));
  }
}

/// Spacing, origin and a rotated direction matrix.
void Geometry()
{
  const int extent[6] = { 0, 33, 0, 35, 0, 31 };
  auto image = MakeImage(extent, VTK_DOUBLE, rgmc_test::Blobs(extent, 30, 13));
  image->SetSpacing(0.7, 1.1, 1.9);
  image->SetOrigin(-12.0, 5.0, 30.0);
  const double c = std::cos(0.5), s = std::sin(0.5), c2 = std::cos(0.3), s2 = std::sin(0.3);
  // rotation about z by 0.5 rad, then about x by 0.3 rad
  const double direction[9] = { c, -s * c2, s * s2, s, c * c2, -c * s2, 0, s2, c2 };
  image->SetDirectionMatrix(direction);
  CheckField("rotated anisotropic (float64)", image, 0.3, RandomSeeds(image, 5, 17));
}

} // namespace

int main(int argc, char* argv[])
{
  rgmc_test::ParseThreads(argc, argv);
  Blobs();
  Phantom();
  EqualSamples();
  Degenerate();
  ScalarTypes();
  Geometry();
  std::cout << "vertices vtkMarchingCubes merged by float coincidence: " << TotalMerged << "\n";
  return rgmc_test::Result("TestOracle");
}

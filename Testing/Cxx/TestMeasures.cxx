// Seam Repair's area and enclosed volume, on 1 rank (vtkDummyController) and under mpiexec.
//
// Surfaces of known volume, closed or cut by the volume's border (by one face, at a corner of
// three, across four sides, reaching a whole face), on a volume with anisotropic spacing and a
// rotated or mirrored direction:
// - before smoothing, the area equals the sum of the output triangles' areas and the volume
//   equals the volume of the surface closed by the border planes, computed independently: the
//   signed volume of the triangles about a point on every cutting plane (the cones over the
//   caps from there are flat), the slab's exact volume where no such point exists, or, for
//   blobs cut by every face, the triangles' signed volume about the centre plus the cones over
//   caps found by marching squares on the faces;
// - every measure, before and after each smoothing, is the same to the bit on any number of
//   ranks and decompositions as on one rank (and on any number of threads: UpdateAtThreads);
// - Laplacian smoothing shrinks the volume, windowed sinc less;
// - a surface with a hole inside the volume has no volume (NaN), and still its area;
// - without vertex keys (border vertices told by their coordinates) the measures are the same;
// - a NaN point makes the area and the volume NaN.
#include "rgmcDistributedData.h"
#include "rgmcTestController.h"
#include "rgmcTestData.h"

#include "vtkCellArray.h"
#include "vtkDoubleArray.h"
#include "vtkDummyController.h"
#include "vtkFieldData.h"
#include "vtkMatrix3x3.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkRGSeamRepair.h"

#include <array>
#include <cmath>
#include <cstring>
#include <iostream>
#include <sstream>

using namespace rgmc_test;

namespace
{

const int Whole[6] = { 0, 32, 0, 32, 0, 32 };
const double Spacing[3] = { 0.75, 1.25, 1.5 };
const double Origin[3] = { -7.0, 3.5, 11.0 };
const char* Names[] = { "SurfaceArea", "EnclosedVolume", "BorderCapArea",
  "SurfaceAreaBeforeSmoothing", "EnclosedVolumeBeforeSmoothing" };

/// A direction matrix: identity, a rotation about z by 30 degrees, or that rotation mirrored.
void DirectionOf(int which, double d[9])
{
  const double c = std::cos(M_PI / 6), s = std::sin(M_PI / 6);
  const double identity[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 1 };
  const double rotated[9] = { c, -s, 0, s, c, 0, 0, 0, 1 };
  const double mirrored[9] = { c, -s, 0, s, c, 0, 0, 0, -1 };
  std::memcpy(d, which == 0 ? identity : which == 1 ? rotated : mirrored, sizeof(identity));
}

/// The world position of index point (i, j, k).
void World(int direction, const double index[3], double x[3])
{
  double d[9];
  DirectionOf(direction, d);
  for (int r = 0; r < 3; ++r)
  {
    x[r] = Origin[r];
    for (int c = 0; c < 3; ++c)
    {
      x[r] += d[3 * r + c] * Spacing[c] * index[c];
    }
  }
}

struct Case
{
  std::string Name;
  std::function<double(int, int, int)> Field; // inside where >= 0
  int Direction;
  bool HasApex;       // a point on every cutting plane: the oracle's apex
  double Apex[3];     // in index space
  double ExactVolume; // when !HasApex: the exact volume in index units (times the voxel's),
                      // or 0: the caps by marching squares on the faces (FaceCapsOracle)
};

std::vector<Case> Cases()
{
  auto sphere = [](double ci, double cj, double ck, double r)
  {
    return [=](int i, int j, int k)
    { return r - std::sqrt((i - ci) * (i - ci) + (j - cj) * (j - cj) + (k - ck) * (k - ck)); };
  };
  std::vector<Case> cases;
  cases.push_back(Case{ "closed sphere", sphere(15.3, 16.2, 16.9, 10.4), 0, true, { 0, 0, 0 }, 0 });
  cases.push_back(
    Case{ "sphere cut by face z-", sphere(15.3, 16.2, 0.0, 10.4), 1, true, { 0, 0, 0 }, 0 });
  cases.push_back(
    Case{ "sphere at corner x- y- z-", sphere(0, 0, 0, 13.6), 0, true, { 0, 0, 0 }, 0 });
  cases.push_back(Case{ "sphere at corner x+ y+ z+ (mirrored direction)", sphere(32, 32, 32, 13.6),
    2, true, { 32, 32, 32 }, 0 });
  cases.push_back(Case{ "box cut by face x+",
    [](int i, int j, int k)
    {
      return std::min(
        { 10.0 - std::abs(i - 28.3), 7.2 - std::abs(j - 15.6), 9.3 - std::abs(k - 14.1) });
    },
    1, true, { 32, 0, 0 }, 0 });
  // A slab across the whole volume in x and y: caps on four sides, none meeting at a point.
  // The field is linear along k where it crosses 0: the faces are planes at k = 10.85, 21.35.
  cases.push_back(
    Case{ "slab across four sides", [](int, int, int k) { return 5.25 - std::abs(k - 16.1); }, 1,
      false, { 0, 0, 0 }, 32.0 * 32.0 * 10.5 });
  // Everything above k = 10.3: its cap on face z+ has no edge of the mesh on it.
  cases.push_back(Case{ "half space reaching face z+", [](int, int, int k) { return k - 10.3; }, 2,
    false, { 0, 0, 0 }, 32.0 * 32.0 * 21.7 });
  // Many blobs, cut by every face, with caps meeting at the volume's edges and corners.
  for (int seed : { 5, 17 })
  {
    const std::function<double(int, int, int)> blobs = Blobs(Whole, 40, seed);
    cases.push_back(Case{ "blobs cut by every face, seed " + std::to_string(seed),
      [blobs](int i, int j, int k) { return blobs(i, j, k) - 0.3; }, 0, false, { 0, 0, 0 }, 0 });
  }
  return cases;
}

/// The caps of an All Components surface on the six faces of the volume, by marching squares:
/// on each face cell, the polygon of its corners inside (field >= 0) and the crossings on its
/// edges (linear, as marching cubes places them), in index units. Returns the volume the caps
/// add (their cones from the volume's centre) in world units, and in `slack` a bound on the
/// part that saddle cells (two opposite corners inside) leave open: marching cubes joins or
/// separates their corners by its case table, this oracle takes the smaller polygon.
double FaceCapsOracle(const Case& c, double& capArea, double& slack, double& areaSlack, int& faces)
{
  double volume = 0.0;
  capArea = 0.0;
  slack = 0.0;
  areaSlack = 0.0;
  faces = 0;
  for (int face = 0; face < 6; ++face)
  {
    const int axis = face / 2, u = (axis + 1) % 3, v = (axis + 2) % 3;
    const int fixed = Whole[face];
    double area = 0.0, saddles = 0.0;
    for (int a = Whole[2 * u]; a < Whole[2 * u + 1]; ++a)
    {
      for (int b = Whole[2 * v]; b < Whole[2 * v + 1]; ++b)
      {
        double corner[4][2] = { { 0, 0 }, { 1, 0 }, { 1, 1 }, { 0, 1 } }, f[4];
        for (int q = 0; q < 4; ++q)
        {
          int index[3];
          index[axis] = fixed;
          index[u] = a + static_cast<int>(corner[q][0]);
          index[v] = b + static_cast<int>(corner[q][1]);
          f[q] = c.Field(index[0], index[1], index[2]);
        }
        std::vector<std::array<double, 2>> polygon;
        for (int q = 0; q < 4; ++q)
        {
          const int r = (q + 1) % 4;
          if (f[q] >= 0)
          {
            polygon.push_back({ corner[q][0], corner[q][1] });
          }
          if ((f[q] >= 0) != (f[r] >= 0))
          {
            const double t = f[q] / (f[q] - f[r]);
            polygon.push_back({ corner[q][0] + t * (corner[r][0] - corner[q][0]),
              corner[q][1] + t * (corner[r][1] - corner[q][1]) });
          }
        }
        double twice = 0.0;
        for (std::size_t p = 0; p < polygon.size(); ++p)
        {
          const auto& x = polygon[p];
          const auto& y = polygon[(p + 1) % polygon.size()];
          twice += x[0] * y[1] - x[1] * y[0];
        }
        const bool saddle =
          (f[0] >= 0) == (f[2] >= 0) && (f[1] >= 0) == (f[3] >= 0) && (f[0] >= 0) != (f[1] >= 0);
        if (saddle)
        {
          saddles += 1.0; // at most the whole cell is in doubt
          // The hexagon joins the two inside corners; the separated reading is two triangles,
          // whose area the hexagon's exceeds: take the triangles, the difference is slack.
          double triangles = 0.0;
          for (int q = 0; q < 4; ++q)
          {
            if (f[q] >= 0)
            {
              const int prev = (q + 3) % 4, next = (q + 1) % 4;
              const double s = f[q] / (f[q] - f[next]), w = f[q] / (f[q] - f[prev]);
              triangles += s * w; // a right triangle in the unit cell: legs s and w
            }
          }
          twice = triangles;
        }
        area += 0.5 * twice;
      }
    }
    const double cell = Spacing[u] * Spacing[v];
    const double distance = 0.5 * (Whole[2 * axis + 1] - Whole[2 * axis]) * Spacing[axis];
    volume += distance * area * cell / 3.0;
    capArea += area * cell;
    slack += distance * saddles * cell / 3.0;
    areaSlack += saddles * cell;
    faces += area > 0;
  }
  return volume;
}

FieldMaker Maker(const Case& c)
{
  return [c](const int extent[6])
  {
    vtkSmartPointer<vtkImageData> image = MakeImage(extent, VTK_DOUBLE, c.Field);
    image->SetSpacing(Spacing[0], Spacing[1], Spacing[2]);
    image->SetOrigin(Origin[0], Origin[1], Origin[2]);
    double d[9];
    DirectionOf(c.Direction, d);
    image->SetDirectionMatrix(d);
    return image;
  };
}

struct Measured
{
  double Values[5];
};

Measured Read(vtkPolyData* pd)
{
  Measured m;
  for (int n = 0; n < 5; ++n)
  {
    vtkDoubleArray* a = vtkDoubleArray::SafeDownCast(pd->GetFieldData()->GetArray(Names[n]));
    m.Values[n] = a && a->GetNumberOfValues() == 1 ? a->GetValue(0) : -1.0;
  }
  return m;
}

bool SameBits(const Measured& a, const Measured& b)
{
  return std::memcmp(a.Values, b.Values, sizeof(a.Values)) == 0;
}

std::string Text(const Measured& m)
{
  std::ostringstream os;
  os.precision(17);
  for (int n = 0; n < 5; ++n)
  {
    os << (n ? ", " : "") << Names[n] << " " << m.Values[n];
  }
  return os.str();
}

vtkSmartPointer<vtkPolyData> Repair(
  vtkMultiProcessController* controller, vtkPolyData* input, int method, const std::string& what)
{
  vtkNew<vtkRGSeamRepair> repair;
  vtkNew<MessageCatcher> catcher;
  catcher->Watch(repair);
  repair->SetController(controller);
  repair->SetInputData(input);
  repair->SetSmoothingMethod(method);
  UpdateAtThreads(repair, what, [&catcher]() { catcher->Errors.clear(); });
  RGMC_CHECK(catcher->Errors.empty(), what << ": " << catcher->Errors);
  auto out = vtkSmartPointer<vtkPolyData>::New();
  out->ShallowCopy(repair->GetOutput());
  return out;
}

/// The area of a (merged, one-rank) mesh's triangles and their signed volume about `apex`.
void Oracle(vtkPolyData* mesh, const double apex[3], double& area, double& volume)
{
  long double a = 0, v = 0;
  vtkCellArray* polys = mesh->GetPolys();
  vtkIdType n;
  const vtkIdType* ids;
  for (polys->InitTraversal(); polys->GetNextCell(n, ids);)
  {
    double p[3][3];
    for (int c = 0; c < 3; ++c)
    {
      mesh->GetPoint(ids[c], p[c]);
      for (int k = 0; k < 3; ++k)
      {
        p[c][k] -= apex[k];
      }
    }
    const long double u[3] = { p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2] };
    const long double w[3] = { p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2] };
    const long double cross[3] = { u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2],
      u[0] * w[1] - u[1] * w[0] };
    a += std::sqrt(cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]) / 2;
    v += (p[0][0] * cross[0] + p[0][1] * cross[1] + p[0][2] * cross[2]) / 6;
  }
  area = static_cast<double>(a);
  volume = static_cast<double>(v);
}

void Check(vtkMultiProcessController* controller, const Case& c)
{
  const int rank = controller->GetLocalProcessId(), ranks = controller->GetNumberOfProcesses();
  vtkNew<vtkDummyController> single;
  Measured reference[3];
  if (rank == 0)
  {
    vtkSmartPointer<vtkImageData> whole = Maker(c)(Whole);
    vtkSmartPointer<vtkPolyData> extracted =
      Extract(single, whole, 0.0, vtkRGMarchingCubes::ALL_COMPONENTS, {}).Output;
    for (int method = 0; method < 3; ++method)
    {
      vtkSmartPointer<vtkPolyData> out =
        Repair(single, extracted, method, c.Name + ", 1 rank, method " + std::to_string(method));
      reference[method] = Read(out);
      if (method == 0 && c.Direction == 0)
      {
        // Without vertex keys Seam Repair tells border vertices by their coordinates: the same
        // measures (to rounding: the caps' edges come in another order).
        auto unkeyed = vtkSmartPointer<vtkPolyData>::New();
        unkeyed->ShallowCopy(extracted);
        unkeyed->GetPointData()->SetGlobalIds(nullptr);
        const Measured m = Read(Repair(single, unkeyed, 0, c.Name + ", by coordinates"));
        for (int n = 0; n < 5; ++n)
        {
          const double a = m.Values[n], b = reference[0].Values[n];
          RGMC_CHECK(std::abs(a - b) <= 1e-9 * std::abs(b),
            c.Name << ", by coordinates: " << Names[n] << " " << a << ", with keys " << b);
        }
      }
      if (method == 0)
      {
        // Unsmoothed: the measures against an independent computation on the same mesh.
        double apex[3], area, volume, caps = 0.0, capArea = 0.0, slack = 0.0, areaSlack = 0.0;
        int capped = 0;
        const bool faces = !c.HasApex && c.ExactVolume == 0.0;
        if (faces)
        {
          // About the volume's centre: the caps add their cones from there.
          const double centre[3] = { 16, 16, 16 };
          World(c.Direction, centre, apex);
          caps = FaceCapsOracle(c, capArea, slack, areaSlack, capped);
          RGMC_CHECK(capped == 6, c.Name << ": caps on " << capped << " faces, not all six");
        }
        else
        {
          World(c.Direction, c.Apex, apex);
        }
        Oracle(out, apex, area, volume);
        const double voxel = Spacing[0] * Spacing[1] * Spacing[2];
        // A mirroring direction turns marching cubes' triangles clockwise in the world.
        const double expected = faces ? volume + caps
          : c.HasApex                 ? (c.Direction == 2 ? -volume : volume)
                                      : c.ExactVolume * voxel;
        // Sums of about 10^4 float points' terms in double: 1e-9 relative. The points are
        // float: on a rotated plane a vertex lies up to half an ulp of its coordinates off it,
        // which tilts the oracle's cones over the caps by as much (a third of the caps' area
        // times that, at most). The slab's exact volume has the float rounding of its planes'
        // positions (about 1e-7 relative).
        const Measured& m = reference[0];
        double largest = 0;
        for (int corner = 0; corner < 8; ++corner)
        {
          const double index[3] = { corner & 1 ? 32.0 : 0.0, corner & 2 ? 32.0 : 0.0,
            corner & 4 ? 32.0 : 0.0 };
          double x[3];
          World(c.Direction, index, x);
          largest = std::max({ largest, std::abs(x[0]), std::abs(x[1]), std::abs(x[2]) });
        }
        const double offPlane = c.Direction ? std::ldexp(largest, -24) : 0.0;
        // The marching squares caps: computed in double from the field, where marching
        // cubes' vertices are float (1e-6 of the caps' cones), and the saddle cells' slack.
        const double tolerance = faces ? 1e-9 * std::abs(expected) + 1e-6 * caps + slack
          : c.HasApex                  ? 1e-9 * std::abs(expected) + m.Values[2] * offPlane / 3.0
                                       : 1e-6 * std::abs(expected);
        RGMC_CHECK(std::abs(m.Values[0] - area) <= 1e-9 * area,
          c.Name << ": area " << m.Values[0] << ", the triangles' " << area);
        RGMC_CHECK(m.Values[0] == m.Values[3], c.Name << ": unsmoothed area before and after");
        RGMC_CHECK(std::abs(m.Values[1] - expected) <= tolerance,
          c.Name << ": enclosed volume " << m.Values[1] << ", expected " << expected);
        RGMC_CHECK((m.Values[2] > 0) == (c.Name != "closed sphere"),
          c.Name << ": border cap area " << m.Values[2]);
        if (faces)
        {
          RGMC_CHECK(std::abs(m.Values[2] - capArea) <= 1e-6 * capArea + areaSlack,
            c.Name << ": border cap area " << m.Values[2] << ", by marching squares " << capArea
                   << " (saddle cells: " << areaSlack << ")");
        }
        std::cout.precision(15);
        std::cout << c.Name << ": area " << m.Values[0] << ", volume " << m.Values[1]
                  << " (expected " << expected << "), caps " << m.Values[2] << "\n";
      }
    }
    // Laplacian shrinks a curved surface; windowed sinc much less.
    const double before = reference[0].Values[1];
    const double laplacian = reference[1].Values[1] - before,
                 sinc = reference[2].Values[1] - before;
    RGMC_CHECK(c.Name.find("sphere") == std::string::npos ||
        (laplacian < 0 && std::abs(sinc) < std::abs(laplacian)),
      c.Name << ": volume change " << laplacian << " (Laplacian), " << sinc << " (windowed sinc)");
  }
  for (const std::string& how : Decompositions(ranks))
  {
    vtkSmartPointer<vtkImageData> image =
      MakePiece(Maker(c), Whole, PieceOf(how, Whole, rank, ranks));
    vtkSmartPointer<vtkPolyData> extracted =
      Extract(controller, image, 0.0, vtkRGMarchingCubes::ALL_COMPONENTS, {}).Output;
    for (int method = 0; method < 3; ++method)
    {
      std::ostringstream what;
      what << c.Name << ", " << how << " on " << ranks << " ranks, method " << method;
      Measured m = Read(Repair(controller, extracted, method, what.str()));
      // Every rank holds the same measures, the 1-rank ones.
      RGMC_CHECK(SameOnAllRanks(controller, Text(m)), what.str() << ": ranks differ");
      if (rank == 0)
      {
        RGMC_CHECK(SameBits(m, reference[method]),
          what.str() << ": " << Text(m) << "; on 1 rank: " << Text(reference[method]));
      }
    }
  }
}

/// This rank's piece of the closed sphere (the first case), extracted in blocks.
vtkSmartPointer<vtkPolyData> ClosedSphere(vtkMultiProcessController* controller)
{
  const int rank = controller->GetLocalProcessId(), ranks = controller->GetNumberOfProcesses();
  vtkSmartPointer<vtkImageData> image =
    MakePiece(Maker(Cases()[0]), Whole, PieceOf("block", Whole, rank, ranks));
  return Extract(controller, image, 0.0, vtkRGMarchingCubes::ALL_COMPONENTS, {}).Output;
}

/// A hole inside the volume: no enclosed volume, the area still reported.
void Hole(vtkMultiProcessController* controller)
{
  const int rank = controller->GetLocalProcessId(), ranks = controller->GetNumberOfProcesses();
  vtkSmartPointer<vtkPolyData> extracted = ClosedSphere(controller);
  if (rank == 0 && extracted->GetNumberOfPolys() > 0)
  {
    vtkNew<vtkCellArray> fewer;
    vtkIdType n;
    const vtkIdType* ids;
    vtkCellArray* polys = extracted->GetPolys();
    polys->InitTraversal();
    polys->GetNextCell(n, ids); // the first triangle left out
    while (polys->GetNextCell(n, ids))
    {
      fewer->InsertNextCell(n, ids);
    }
    auto holed = vtkSmartPointer<vtkPolyData>::New();
    holed->ShallowCopy(extracted);
    holed->SetPolys(fewer);
    extracted = holed;
  }
  const Measured m = Read(Repair(controller, extracted, 0, "a sphere with a hole"));
  RGMC_CHECK(std::isnan(m.Values[1]) && std::isnan(m.Values[4]) && m.Values[0] > 0,
    "a sphere with a hole on " << ranks << " ranks: " << Text(m));
}

/// A point that is not a number: no area and no volume (NaN), on every rank, and no undefined
/// conversion on the way (the sanitizers run this too).
void NotANumber(vtkMultiProcessController* controller)
{
  const int rank = controller->GetLocalProcessId(), ranks = controller->GetNumberOfProcesses();
  vtkSmartPointer<vtkPolyData> extracted = ClosedSphere(controller);
  if (rank == 0 && extracted->GetNumberOfPoints() > 0)
  {
    auto broken = vtkSmartPointer<vtkPolyData>::New();
    broken->DeepCopy(extracted);
    broken->GetPoints()->SetPoint(0, std::nan(""), 0.0, 0.0);
    extracted = broken;
  }
  const Measured m = Read(Repair(controller, extracted, 0, "a sphere with a NaN point"));
  RGMC_CHECK(std::isnan(m.Values[0]) && std::isnan(m.Values[1]) && std::isnan(m.Values[3]),
    "a sphere with a NaN point on " << ranks << " ranks: " << Text(m));
}

} // namespace

int main(int argc, char* argv[])
{
  vtkSmartPointer<vtkMultiProcessController> controller = rgmc_test::StartController(argc, argv);
  for (const Case& c : Cases())
  {
    Check(controller, c);
  }
  Hole(controller);
  NotANumber(controller);
  return Finish(controller, "TestMeasures");
}

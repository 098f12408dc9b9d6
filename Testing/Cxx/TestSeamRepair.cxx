// vtkRGSeamRepair on 1 rank (vtkDummyController) and under mpiexec. Closed surfaces cut by the
// partition planes (spheres, one centred where 8 ranks meet; a torus around that corner; the
// phantom's skull with its holes) must come out closed (no boundary or non-manifold edge) with
// the expected Euler characteristic, with contiguous global point ids, one owner per vertex,
// and positions after smoothing identical, to the bit, to the 1-rank result. Windowed sinc must
// equal vtkWindowedSincPolyDataFilter on the merged mesh. Surfaces without vertex keys (the
// coordinates fallback, and vtkFlyingEdges3D pieces) must close too. Bad input gives the same
// error on every rank.
#include "rgmcDistributedData.h"
#include "rgmcTestController.h"
#include "rgmcTestData.h"
#include "rgmcUnitedMesh.h"

#include "vtkCallbackCommand.h"
#include "vtkCellArray.h"
#include "vtkDummyController.h"
#include "vtkExtractVOI.h"
#include "vtkFieldData.h"
#include "vtkFlyingEdges3D.h"
#include "vtkIdTypeArray.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkRGCompatibility.h"
#include "vtkRGPhantomSource.h"
#include "vtkRGSeamRepair.h"
#include "vtkWindowedSincPolyDataFilter.h"

#include <cstring>
#include <iostream>
#include <map>
#include <sstream>

using namespace rgmc_test;

namespace
{

const int Whole[6] = { 0, 64, 0, 64, 0, 64 }; // 64 cells: even splits for 2, 4 and 8 ranks
const char* MethodNames[] = { "no smoothing", "Laplacian", "windowed sinc" };

struct Surface
{
  std::string Name;
  FieldMaker Make;
  double Isovalue;
  int Mode;
  Seeds SeedPoints;
  long long Euler;
};

std::vector<Surface> Surfaces()
{
  std::vector<Surface> surfaces;
  // Five spheres: at the corner where 8 ranks meet, on the middle planes, and inside an octant.
  const double centres[5][3] = { { 32, 32, 32 }, { 32, 12, 12 }, { 12, 32, 50 }, { 50, 50, 32 },
    { 12, 12, 12 } };
  surfaces.push_back(Surface{ "five spheres",
    [centres](const int extent[6])
    {
      return MakeImage(extent, VTK_DOUBLE,
        [centres](int i, int j, int k)
        {
          double f = -1e9;
          for (const auto& c : centres)
          {
            f = std::max(f,
              7.3 -
                std::sqrt(
                  (i - c[0]) * (i - c[0]) + (j - c[1]) * (j - c[1]) + (k - c[2]) * (k - c[2])));
          }
          return f;
        });
    },
    0.0, vtkRGMarchingCubes::ALL_COMPONENTS, {}, 10 });
  // A torus around the corner where 8 ranks meet.
  surfaces.push_back(Surface{ "torus",
    [](const int extent[6])
    {
      return MakeImage(extent, VTK_FLOAT,
        [](int i, int j, int k)
        {
          const double rho = std::sqrt((i - 32.0) * (i - 32.0) + (j - 32.3) * (j - 32.3));
          return 5.2 - std::sqrt((rho - 14.0) * (rho - 14.0) + (k - 32.4) * (k - 32.4));
        });
    },
    0.0, vtkRGMarchingCubes::SEEDED, { { 46.0, 32.0, 32.0 } }, 0 });
  // The phantom's skull: a shell with 5 holes (Euler characteristic 4 - 2 * 5).
  surfaces.push_back(Surface{ "skull", [](const int extent[6]) { return PhantomPiece(extent, 65); },
    400.0, vtkRGMarchingCubes::SEEDED, { { 0, 0, 105 } }, -6 });
  return surfaces;
}

struct Repaired
{
  vtkSmartPointer<vtkPolyData> Output;
  std::string Errors;
};

Repaired Repair(vtkMultiProcessController* controller, vtkPolyData* input, int method,
  int window = vtkRGSeamRepair::NUTTALL_WINDOW)
{
  vtkNew<vtkRGSeamRepair> repair;
  vtkNew<MessageCatcher> catcher;
  catcher->Watch(repair);
  repair->SetController(controller);
  repair->SetInputData(input);
  repair->SetSmoothingMethod(method);
  repair->SetWindowFunction(window);
  UpdateAtThreads(repair,
    "Seam Repair, method " + std::to_string(method) +
      (input->GetPointData()->GetGlobalIds() ? " keyed" : " unkeyed"),
    [&catcher]()
    {
      catcher->Errors.clear();
      catcher->Warnings.clear();
    });
  Repaired r;
  r.Output = vtkSmartPointer<vtkPolyData>::New();
  r.Output->ShallowCopy(repair->GetOutput());
  r.Errors = catcher->Errors;
  // Every rank made the same collective calls (a rank that skipped one would hang or mismatch
  // in a later run; counted by the filter itself).
  const vtkIdType collectives = repair->GetNumberOfCollectives();
  const bool same = SameOnAllRanks(controller, std::to_string(collectives));
  RGMC_CHECK(same && collectives > 0,
    "Seam Repair, method " << method << ": the ranks made different numbers of collective calls ("
                           << collectives << " here)");
  return r;
}

/// The same surface without its vertex keys (the repair then matches points by coordinates).
vtkSmartPointer<vtkPolyData> WithoutKeys(vtkPolyData* pd)
{
  auto unkeyed = vtkSmartPointer<vtkPolyData>::New();
  unkeyed->ShallowCopy(pd);
  unkeyed->GetPointData()->SetGlobalIds(nullptr);
  return unkeyed;
}

long long Field(vtkPolyData* pd, const char* name)
{
  vtkIdTypeArray* a = vtkIdTypeArray::SafeDownCast(pd->GetFieldData()->GetArray(name));
  return a ? a->GetValue(0) : -1;
}

/// A repaired surface by global point id, positions and normals as float bits.
using Mesh = rgmc_test::UnitedMesh<float>;

/// Checks on every rank, then the gathered union against the 1-rank mesh.
void Compare(vtkMultiProcessController* controller, vtkPolyData* piece, const Mesh* reference,
  long long referenceEuler, const std::string& what)
{
  const long long closed = Field(piece, "Closed"), euler = Field(piece, "EulerCharacteristic");
  RGMC_CHECK(closed == 1,
    what << ": not closed (" << Field(piece, "BoundaryEdges") << " boundary, "
         << Field(piece, "NonManifoldEdges") << " non-manifold edges)");
  RGMC_CHECK(euler == referenceEuler,
    what << ": Euler characteristic " << euler << ", expected " << referenceEuler);
  std::vector<vtkSmartPointer<vtkDataObject>> pieces;
  controller->Gather(piece, pieces, 0);
  if (controller->GetLocalProcessId() != 0)
  {
    return;
  }
  Mesh united;
  for (auto& p : pieces)
  {
    united.Add(vtkPolyData::SafeDownCast(p));
  }
  const long long unique = Field(piece, "UniquePoints");
  RGMC_CHECK(static_cast<long long>(united.Points.size()) == unique &&
      (united.Points.empty() || united.Points.rbegin()->first == unique - 1),
    what << ": global ids are not 0.." << unique - 1);
  const long long badOwners = united.BadOwners();
  RGMC_CHECK(badOwners == 0, what << ": " << badOwners << " vertices without exactly one owner");
  RGMC_CHECK(united.Inconsistent == 0, what << ": " << united.Inconsistent << " copies differ");
  long long duplicated = 0, referenceDuplicated = 0;
  const auto triangles = united.SortedTriangles(duplicated);
  RGMC_CHECK(duplicated == 0, what << ": triangles on two ranks");
  if (reference)
  {
    RGMC_CHECK(triangles == reference->SortedTriangles(referenceDuplicated),
      what << ": triangles differ from 1 rank");
    long long differ = 0;
    for (const auto& p : united.Points)
    {
      auto r = reference->Points.find(p.first);
      differ += r == reference->Points.end() || r->second != p.second;
    }
    RGMC_CHECK(differ == 0 && united.Points.size() == reference->Points.size(),
      what << ": " << differ << " vertices differ from 1 rank (bitwise)");
  }
}

/// Windowed sinc on 1 rank against VTK's filter on the merged mesh, its points put in global-id
/// order (VTK visits neighbours in point order; ours in global-id order),
/// with each window this VTK has: Hamming everywhere, Nuttall (VTK's default from 9.4) where VTK
/// has a window setting.
void CompareWithVTK(vtkMultiProcessController* single, vtkPolyData* extracted, double spacing,
  const std::string& name)
{
  vtkSmartPointer<vtkPolyData> merged =
    Repair(single, extracted, vtkRGSeamRepair::NO_SMOOTHING).Output;
  vtkIdTypeArray* ids = vtkIdTypeArray::SafeDownCast(merged->GetPointData()->GetGlobalIds());
  const vtkIdType n = merged->GetNumberOfPoints();
  std::vector<bool> seen(n, false);
  for (vtkIdType p = 0; p < n; ++p)
  {
    const vtkIdType g = ids->GetValue(p);
    RGMC_CHECK(g >= 0 && g < n && !seen[g], name << ": one rank's global ids are 0..N-1");
    seen[g] = true;
  }
  vtkNew<vtkPolyData> mesh;
  {
    vtkNew<vtkPoints> ordered;
    ordered->SetDataType(merged->GetPoints()->GetDataType());
    ordered->SetNumberOfPoints(n);
    for (vtkIdType p = 0; p < n; ++p)
    {
      ordered->SetPoint(ids->GetValue(p), merged->GetPoint(p));
    }
    vtkNew<vtkCellArray> polys;
    vtkIdType npts;
    const vtkIdType* pts;
    vtkCellArray* in = merged->GetPolys();
    for (in->InitTraversal(); in->GetNextCell(npts, pts);)
    {
      const vtkIdType tri[3] = { ids->GetValue(pts[0]), ids->GetValue(pts[1]),
        ids->GetValue(pts[2]) };
      polys->InsertNextCell(3, tri);
    }
    mesh->SetPoints(ordered);
    mesh->SetPolys(polys);
  }
  std::vector<int> windows = { vtkRGSeamRepair::HAMMING_WINDOW };
#if RGMC_VTK_SINC_HAS_WINDOW_FUNCTION
  windows.push_back(vtkRGSeamRepair::NUTTALL_WINDOW);
#endif
  for (int window : windows)
  {
    const char* windowName = window == vtkRGSeamRepair::HAMMING_WINDOW ? "Hamming" : "Nuttall";
    vtkNew<vtkWindowedSincPolyDataFilter> vtk;
    vtk->SetInputData(mesh);
#if RGMC_VTK_SINC_HAS_WINDOW_FUNCTION
    if (window == vtkRGSeamRepair::HAMMING_WINDOW)
    {
      vtk->SetWindowFunctionToHamming();
    }
    else
    {
      vtk->SetWindowFunctionToNuttall();
    }
#endif
    vtk->Update();
    vtkSmartPointer<vtkPolyData> ours =
      Repair(single, extracted, vtkRGSeamRepair::WINDOWED_SINC, window).Output;
    double worst = 0, moved = 0;
    long long bitwise = 0;
    for (vtkIdType p = 0; p < ours->GetNumberOfPoints(); ++p)
    {
      double a[3], b[3], before[3];
      ours->GetPoint(p, a);
      const vtkIdType g =
        vtkIdTypeArray::SafeDownCast(ours->GetPointData()->GetGlobalIds())->GetValue(p);
      vtk->GetOutput()->GetPoint(g, b);
      mesh->GetPoint(g, before);
      worst = std::max(worst, std::sqrt(vtkMath::Distance2BetweenPoints(a, b)));
      moved = std::max(moved, std::sqrt(vtkMath::Distance2BetweenPoints(a, before)));
      bitwise += a[0] == b[0] && a[1] == b[1] && a[2] == b[2];
    }
    std::cout << name << ": windowed sinc (" << windowName
              << " window) vs vtkWindowedSincPolyDataFilter: max distance " << worst / spacing
              << " spacings; " << bitwise << " of " << ours->GetNumberOfPoints()
              << " points identical to the bit; points moved up to " << moved / spacing
              << " spacings\n";
    RGMC_CHECK(worst <= 1e-5 * spacing,
      name << ": windowed sinc (" << windowName << " window) is " << worst / spacing
           << " spacings from VTK's");
    // A smoother that did nothing would also equal an input that VTK did not move.
    RGMC_CHECK(moved > 1e-3 * spacing, name << ": windowed sinc moved no point");
  }
}

/// The smoothing does not depend on the triangles' orientation. A vertex whose triangles all
/// turn one way around it gets its stencil row by a shortcut (the ends ranked, not sorted); a
/// vertex with a reversed triangle takes the general path. With every third triangle reversed,
/// nearly every vertex takes the general path, and the Laplacian must still move every point
/// to the same bits. In double: a row in another order would change some float sums' last bits
/// and the points' rounding to float would hide most of them.
void OrientationDoesNotMatter(
  vtkMultiProcessController* single, vtkPolyData* surface, const std::string& name)
{
  auto extracted = vtkSmartPointer<vtkPolyData>::New();
  extracted->ShallowCopy(surface);
  vtkNew<vtkPoints> doubles;
  doubles->SetDataTypeToDouble();
  doubles->SetNumberOfPoints(surface->GetNumberOfPoints());
  for (vtkIdType p = 0; p < surface->GetNumberOfPoints(); ++p)
  {
    doubles->SetPoint(p, surface->GetPoint(p));
  }
  extracted->SetPoints(doubles);
  auto flipped = vtkSmartPointer<vtkPolyData>::New();
  flipped->ShallowCopy(extracted);
  vtkNew<vtkCellArray> polys;
  vtkIdType npts, t = 0;
  const vtkIdType* pts;
  vtkCellArray* in = extracted->GetPolys();
  for (in->InitTraversal(); in->GetNextCell(npts, pts); ++t)
  {
    const bool reverse = t % 3 == 0;
    const vtkIdType tri[3] = { pts[0], pts[reverse ? 2 : 1], pts[reverse ? 1 : 2] };
    polys->InsertNextCell(3, tri);
  }
  flipped->SetPolys(polys);
  vtkSmartPointer<vtkPolyData> a = Repair(single, extracted, vtkRGSeamRepair::LAPLACIAN).Output;
  RGMC_CHECK(a->GetPoints()->GetDataType() == VTK_DOUBLE,
    name << ": double points came out as "
         << "type " << a->GetPoints()->GetDataType());
  vtkSmartPointer<vtkPolyData> b = Repair(single, flipped, vtkRGSeamRepair::LAPLACIAN).Output;
  RGMC_CHECK(a->GetNumberOfPoints() == b->GetNumberOfPoints() && a->GetNumberOfPoints() > 0,
    name << ": reversing triangles changed the number of points");
  vtkIdTypeArray* idsA = vtkIdTypeArray::SafeDownCast(a->GetPointData()->GetGlobalIds());
  vtkIdTypeArray* idsB = vtkIdTypeArray::SafeDownCast(b->GetPointData()->GetGlobalIds());
  std::vector<vtkIdType> pointOfGid(a->GetNumberOfPoints());
  for (vtkIdType p = 0; p < b->GetNumberOfPoints(); ++p)
  {
    pointOfGid[idsB->GetValue(p)] = p;
  }
  vtkIdType differ = 0;
  for (vtkIdType p = 0; p < a->GetNumberOfPoints(); ++p)
  {
    double x[3], y[3];
    a->GetPoint(p, x);
    b->GetPoint(pointOfGid[idsA->GetValue(p)], y);
    differ += x[0] != y[0] || x[1] != y[1] || x[2] != y[2];
  }
  std::cout << name << ": Laplacian with every third triangle reversed: " << differ << " of "
            << a->GetNumberOfPoints() << " points differ\n";
  RGMC_CHECK(
    differ == 0, name << ": reversing every third triangle moved " << differ << " smoothed points");
}

/// A mesh of the given triangles (`which`, indices into `triangles`, whose corners index `xyz`
/// and are the points' keys), in double.
vtkSmartPointer<vtkPolyData> KeyedMesh(
  const double (*xyz)[3], const vtkIdType (*triangles)[3], const std::vector<int>& which)
{
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  vtkNew<vtkIdTypeArray> keys;
  keys->SetName("VertexKey");
  vtkNew<vtkCellArray> polys;
  std::map<vtkIdType, vtkIdType> local;
  for (int t : which)
  {
    vtkIdType ids[3];
    for (int k = 0; k < 3; ++k)
    {
      const vtkIdType key = triangles[t][k];
      auto found = local.find(key);
      if (found == local.end())
      {
        found = local.emplace(key, points->InsertNextPoint(xyz[key])).first;
        keys->InsertNextValue(key);
      }
      ids[k] = found->second;
    }
    polys->InsertNextCell(3, ids);
  }
  pd->SetPoints(points);
  pd->SetPolys(polys);
  pd->GetPointData()->SetGlobalIds(keys);
  return pd;
}

/// The normal of the point of key 0, if this piece holds it.
bool NormalOfKey0(vtkPolyData* pd, double n[3])
{
  vtkIdTypeArray* ids = vtkIdTypeArray::SafeDownCast(pd->GetPointData()->GetGlobalIds());
  for (vtkIdType p = 0; ids && p < pd->GetNumberOfPoints(); ++p)
  {
    if (ids->GetValue(p) == 0 && pd->GetPointData()->GetNormals())
    {
      pd->GetPointData()->GetNormals()->GetTuple(p, n);
      return true;
    }
  }
  return false;
}

/// Seam Repair with Laplacian smoothing that moves nothing: the normals are computed.
vtkSmartPointer<vtkPolyData> RepairInPlace(vtkMultiProcessController* c, vtkPolyData* input)
{
  vtkNew<vtkRGSeamRepair> r;
  r->SetController(c);
  r->SetInputData(input);
  r->SetSmoothingMethod(vtkRGSeamRepair::LAPLACIAN);
  r->SetRelaxationFactor(0.0);
  r->Update();
  auto out = vtkSmartPointer<vtkPolyData>::New();
  out->ShallowCopy(r->GetOutput());
  return out;
}

/// Normals after smoothing are summed in an order fixed by the mesh, not by the ranks. A fan of
/// three triangles around vertex 0 whose area vectors are +1e16, -1e16 and +1 along z: summed in
/// the 1-rank order (A, B, C) that gives (0, 0, 1); summed per rank with rank 0 holding A and C
/// and rank 1 holding B, it would give (A + C) + B = 0. The normal must be the same, to the bit,
/// on any number of ranks. (Relaxation 0: the smoothing moves nothing, the normals are computed.)
void NormalsInCanonicalOrder(vtkMultiProcessController* controller)
{
  const int rank = controller->GetLocalProcessId(), ranks = controller->GetNumberOfProcesses();
  const double big = 1e8;
  const double xyz[7][3] = { { 0, 0, 0 }, { big, 0, 0 }, { 0, big, 0 }, { 0, -big, 0 },
    { -big, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 } };
  const vtkIdType fan[3][3] = { { 0, 1, 2 }, { 0, 3, 4 }, { 0, 5, 6 } }; // A, B, C
  auto mesh = [&](const std::vector<int>& triangles) { return KeyedMesh(xyz, fan, triangles); };
  vtkNew<vtkDummyController> single;
  double expected[3] = { 0, 0, 0 }, got[3] = { 0, 0, 0 };
  const bool found = NormalOfKey0(RepairInPlace(single, mesh({ 0, 1, 2 })), expected);
  RGMC_CHECK(found && expected[2] == 1.0, "the fan's normal on 1 rank: " << expected[2]);
  const std::vector<int> mine = ranks == 1 ? std::vector<int>{ 0, 2, 1 }
    : rank == 0                            ? std::vector<int>{ 0, 2 }
    : rank == 1                            ? std::vector<int>{ 1 }
                                           : std::vector<int>{};
  vtkSmartPointer<vtkPolyData> out = RepairInPlace(controller, mesh(mine));
  double mineNormal[4] = { 0, 0, 0, 0 }, all[4] = { 0, 0, 0, 0 };
  if (NormalOfKey0(out, got) && rank == 0)
  {
    mineNormal[0] = got[0], mineNormal[1] = got[1], mineNormal[2] = got[2], mineNormal[3] = 1;
  }
  controller->AllReduce(mineNormal, all, 4, vtkCommunicator::SUM_OP);
  RGMC_CHECK(all[3] == 1 && all[0] == expected[0] && all[1] == expected[1] && all[2] == expected[2],
    "the fan's normal on " << ranks << " ranks (triangles in another order): (" << all[0] << ", "
                           << all[1] << ", " << all[2] << "), on 1 rank (" << expected[0] << ", "
                           << expected[1] << ", " << expected[2] << ")");
}

/// The same for a vertex inside an oriented fan, whose order the stencils' pass finds from its
/// neighbours' ranks (no sort): triangles T1..T4 around vertex 0, closed, with area vectors
/// +1e16, -1e16, -1 and 0 along z, given in the order T3, T4, T1, T2. By the keys of their other
/// corners, T1 (1, 2), T4 (1, 4), T2 (2, 3), T3 (3, 4): 1e16 + 0 - 1e16 - 1 = -1, so the normal
/// is (0, 0, -1). Summed in the given order, or in reverse, -1 meets 1e16 first and is lost.
void NormalsOfAnOrientedFan()
{
  const double big = 1e8;
  const double xyz[5][3] = { { 0, 0, 0 }, { big, 0, 0 }, { 0, big, 0 }, { big, 1, 0 },
    { 1, 0, 0 } };
  const vtkIdType fan[4][3] = { { 0, 1, 2 }, { 0, 2, 3 }, { 0, 3, 4 }, { 0, 4, 1 } };
  vtkNew<vtkDummyController> single;
  double n[3] = { 0, 0, 0 };
  const bool found = NormalOfKey0(RepairInPlace(single, KeyedMesh(xyz, fan, { 2, 3, 0, 1 })), n);
  RGMC_CHECK(found && n[0] == 0.0 && n[1] == 0.0 && n[2] == -1.0,
    "the oriented fan's normal: (" << n[0] << ", " << n[1] << ", " << n[2] << "), not (0, 0, -1)");
}

void BadInput(vtkMultiProcessController* controller)
{
  const int rank = controller->GetLocalProcessId(), ranks = controller->GetNumberOfProcesses();
  auto expect = [&](const std::string& what, vtkPolyData* input, const std::string& text)
  {
    const Repaired r = Repair(controller, input, vtkRGSeamRepair::LAPLACIAN);
    const std::size_t at = r.Errors.find("): ");
    const std::string message = at == std::string::npos ? r.Errors : r.Errors.substr(at + 3);
    RGMC_CHECK(message.find(text) != std::string::npos,
      what << " (rank " << rank << "): expected '" << text << "', got [" << r.Errors << "]");
    RGMC_CHECK(r.Output->GetNumberOfCells() == 0, what << ": output not empty");
    long long h = static_cast<long long>(std::hash<std::string>()(message) >> 1), lo, hi;
    controller->AllReduce(&h, &lo, 1, vtkCommunicator::MIN_OP);
    controller->AllReduce(&h, &hi, 1, vtkCommunicator::MAX_OP);
    RGMC_CHECK(lo == hi, what << ": the ranks' messages differ");
    std::cout << (rank == 0 ? what + ": " + message : std::string());
  };
  auto triangle = [](vtkPolyData* pd)
  {
    vtkNew<vtkPoints> pts;
    pts->InsertNextPoint(0, 0, 0);
    pts->InsertNextPoint(1, 0, 0);
    pts->InsertNextPoint(0, 1, 0);
    pts->InsertNextPoint(1, 1, 0);
    pd->SetPoints(pts);
    vtkNew<vtkCellArray> polys;
    const vtkIdType tri[3] = { 0, 1, 2 };
    polys->InsertNextCell(3, tri);
    pd->SetPolys(polys);
  };
  {
    vtkNew<vtkPolyData> lines;
    triangle(lines);
    lines->SetPolys(nullptr);
    vtkNew<vtkCellArray> cells;
    const vtkIdType line[3] = { 0, 1, 2 };
    cells->InsertNextCell(3, line);
    lines->SetLines(cells);
    expect("lines only", lines, "not a triangle mesh");
  }
  {
    vtkNew<vtkPolyData> mixed;
    triangle(mixed);
    if (rank == ranks - 1)
    {
      vtkNew<vtkCellArray> cells;
      const vtkIdType line[2] = { 0, 3 };
      cells->InsertNextCell(2, line);
      mixed->SetLines(cells);
    }
    expect("a line among the triangles of the last rank", mixed, "1 lines");
  }
  {
    vtkNew<vtkPolyData> quad;
    triangle(quad);
    if (rank == 0)
    {
      const vtkIdType q[4] = { 0, 1, 3, 2 };
      quad->GetPolys()->InsertNextCell(4, q);
    }
    expect("a quad on rank 0", quad, "1 polygons that are not triangles");
  }
  {
    vtkNew<vtkPolyData> empty;
    expect("nothing on any rank", empty, "no triangles");
  }
}

/// An abort on the last rank during smoothing: every rank stops, with an empty output, and
/// nothing hangs.
void Abort(vtkMultiProcessController* controller)
{
  const int rank = controller->GetLocalProcessId(), ranks = controller->GetNumberOfProcesses();
  const Surface surface = Surfaces().front();
  vtkSmartPointer<vtkImageData> image =
    MakePiece(surface.Make, Whole, PieceOf("block", Whole, rank, ranks));
  vtkSmartPointer<vtkPolyData> extracted =
    Extract(controller, image, surface.Isovalue, surface.Mode, surface.SeedPoints).Output;
  vtkNew<vtkRGSeamRepair> repair;
  repair->SetController(controller);
  repair->SetInputData(extracted);
  repair->SetNumberOfIterations(200);
  vtkNew<vtkCallbackCommand> abort;
  abort->SetCallback(
    [](vtkObject* caller, unsigned long, void*, void*)
    {
      vtkAlgorithm* algorithm = static_cast<vtkAlgorithm*>(caller);
      if (algorithm->GetProgress() > 0.5)
      {
        algorithm->SetAbortExecute(1);
      }
    });
  if (rank == ranks - 1)
  {
    repair->AddObserver(vtkCommand::ProgressEvent, abort);
  }
  repair->Update();
  long long cells = repair->GetOutput()->GetNumberOfCells(), total = 0;
  controller->AllReduce(&cells, &total, 1, vtkCommunicator::SUM_OP);
  RGMC_CHECK(total == 0, "an abort on the last rank left " << total << " triangles");
  if (rank == 0 && total == 0)
  {
    std::cout << "abort on rank " << ranks - 1 << " during smoothing: every rank stopped\n";
  }

  // The same filter repairs again at its next update, with nothing reset by the caller (as
  // ParaView's next Apply does; VTK 9.3+ keeps an algorithm's abort flag between runs).
  repair->RemoveAllObservers();
  repair->SetNumberOfIterations(100); // a changed property re-executes
  repair->Update();
  cells = repair->GetOutput()->GetNumberOfCells();
  controller->AllReduce(&cells, &total, 1, vtkCommunicator::SUM_OP);
  RGMC_CHECK(total > 0 && Field(repair->GetOutput(), "Closed") == 1,
    "after an abort, the next update gives " << total << " triangles");
}

} // namespace

int main(int argc, char* argv[])
{
  vtkSmartPointer<vtkMultiProcessController> controller = rgmc_test::StartController(argc, argv);
  const int rank = controller->GetLocalProcessId(), ranks = controller->GetNumberOfProcesses();
  vtkNew<vtkDummyController> single;

  for (const Surface& surface : Surfaces())
  {
    // 1-rank references, each smoothing method, with vertex keys and without.
    std::vector<Mesh> references(6);
    double spacing = 1.0;
    if (rank == 0)
    {
      vtkSmartPointer<vtkImageData> whole = surface.Make(Whole);
      spacing = whole->GetSpacing()[0];
      vtkSmartPointer<vtkPolyData> extracted =
        Extract(single, whole, surface.Isovalue, surface.Mode, surface.SeedPoints).Output;
      vtkSmartPointer<vtkPolyData> unkeyed = WithoutKeys(extracted);
      for (int method = 0; method < 3; ++method)
      {
        for (int keyed = 0; keyed < 2; ++keyed)
        {
          Repaired r = Repair(single, keyed ? extracted.Get() : unkeyed.Get(), method);
          RGMC_CHECK(r.Errors.empty(), surface.Name << ": " << r.Errors);
          RGMC_CHECK(Field(r.Output, "Closed") == 1, surface.Name << " on 1 rank is not closed");
          RGMC_CHECK(Field(r.Output, "EulerCharacteristic") == surface.Euler,
            surface.Name << " on 1 rank: Euler characteristic "
                         << Field(r.Output, "EulerCharacteristic"));
          references[2 * method + keyed].Add(r.Output);
        }
      }
      CompareWithVTK(single, extracted, spacing, surface.Name);
      OrientationDoesNotMatter(single, extracted, surface.Name);
    }

    for (const std::string& how : Decompositions(ranks))
    {
      vtkSmartPointer<vtkImageData> image =
        MakePiece(surface.Make, Whole, PieceOf(how, Whole, rank, ranks));
      vtkSmartPointer<vtkPolyData> extracted =
        Extract(controller, image, surface.Isovalue, surface.Mode, surface.SeedPoints).Output;
      vtkSmartPointer<vtkPolyData> unkeyed = WithoutKeys(extracted);
      for (int method = 0; method < 3; ++method)
      {
        for (int keyed = 0; keyed < 2; ++keyed)
        {
          std::ostringstream what;
          what << surface.Name << ", " << how << " on " << ranks << " ranks, "
               << MethodNames[method] << (keyed ? "" : ", by coordinates");
          Repaired r = Repair(controller, keyed ? extracted.Get() : unkeyed.Get(), method);
          RGMC_CHECK(r.Errors.empty(), what.str() << ": " << r.Errors);
          Compare(controller, r.Output, rank == 0 ? &references[2 * method + keyed] : nullptr,
            surface.Euler, what.str());
        }
      }
    }

    // Any distributed surface: vtkFlyingEdges3D on each rank's own cells, matched by
    // coordinates (its seam vertices are computed alike on both sides).
    {
      const Piece piece = PieceOf("block", Whole, rank, ranks);
      vtkSmartPointer<vtkImageData> image = MakePiece(surface.Make, Whole, piece);
      vtkNew<vtkPolyData> surfacePiece;
      if (!piece.Empty())
      {
        vtkNew<vtkExtractVOI> own;
        own->SetInputData(image);
        own->SetVOI(const_cast<int*>(piece.Owned));
        vtkNew<vtkFlyingEdges3D> fe;
        fe->SetInputConnection(own->GetOutputPort());
        fe->SetValue(0, surface.Isovalue);
        fe->Update();
        surfacePiece->ShallowCopy(fe->GetOutput());
      }
      // VTK 9.6's vtkFlyingEdges3D stores its triangles in fixed-size cell arrays, which have no
      // offsets array: the repair must read them all the same.
      long long feTriangles = surfacePiece->GetNumberOfPolys(), allFeTriangles = 0;
      controller->AllReduce(&feTriangles, &allFeTriangles, 1, vtkCommunicator::SUM_OP);
      Repaired r = Repair(controller, surfacePiece, vtkRGSeamRepair::LAPLACIAN);
      RGMC_CHECK(r.Errors.empty(), surface.Name << ", vtkFlyingEdges3D pieces: " << r.Errors);
      RGMC_CHECK(Field(r.Output, "Triangles") == allFeTriangles,
        surface.Name << ", vtkFlyingEdges3D pieces: the repair counts "
                     << Field(r.Output, "Triangles") << " triangles, Flying Edges made "
                     << allFeTriangles);
      const long long border = Field(r.Output, "VolumeBorderEdges");
      const long long boundary = Field(r.Output, "BoundaryEdges");
      const long long nonManifold = Field(r.Output, "NonManifoldEdges");
      // vtkFlyingEdges3D keeps every component and zero-area triangles; what matters here is
      // that the seams close: no boundary edge.
      RGMC_CHECK(boundary == 0,
        surface.Name << ", vtkFlyingEdges3D pieces on " << ranks << " ranks: " << boundary
                     << " boundary edges");
      if (rank == 0)
      {
        std::cout << surface.Name << ", vtkFlyingEdges3D pieces: " << boundary << " boundary, "
                  << border << " border, " << nonManifold << " non-manifold edges\n";
      }
    }
  }
  NormalsInCanonicalOrder(controller);
  NormalsOfAnOrientedFan();
  BadInput(controller);
  Abort(controller);

  return rgmc_test::Finish(controller, "TestSeamRepair");
}

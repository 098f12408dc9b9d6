// Seam Repair: the filter and its collective schedule; each pass family is in an rgmcSeam*.h.
#include "vtkRGSeamRepair.h"

#include "rgmcMeasure.h"
#include "rgmcSeamMeasures.h"
#include "rgmcSeamNormals.h"
#include "rgmcSeamNumbering.h"
#include "rgmcSeamPiece.h"
#include "rgmcSeamSmoothing.h"
#include "vtkRGArrays.h"
#include "vtkRGCollective.h"
#include "vtkRGCompatibility.h"
#include "vtkRGRunController.h"
#include "vtkRGSpan.h"

#include "vtkAOSDataArrayTemplate.h"
#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkDataSetAttributes.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkLogger.h"
#include "vtkMath.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

vtkStandardNewMacro(vtkRGSeamRepair);
vtkCxxSetObjectMacro(vtkRGSeamRepair, Controller, vtkMultiProcessController);

using rgmc::Ranks;
using rgmc::seam::BorderTest;
using rgmc::seam::Checks;
using rgmc::seam::GlobalNumbering;
using rgmc::seam::Identities;
using rgmc::seam::Identity;
using rgmc::seam::IdentityNumbering;
using rgmc::seam::LocalVertices;
using rgmc::seam::Measures;
using rgmc::seam::SmoothingSettings;

namespace
{
/// One rank's repair of its piece: every pass family, each built on the one before it.
template <typename T, typename I>
using PieceRepair = rgmc::seam::SeamNormals<T, I>;
} // namespace

//------------------------------------------------------------------------------
vtkRGSeamRepair::vtkRGSeamRepair()
{
  this->SetController(vtkMultiProcessController::GetGlobalController());
}

//------------------------------------------------------------------------------
vtkRGSeamRepair::~vtkRGSeamRepair()
{
  this->SetController(nullptr);
}

//------------------------------------------------------------------------------
/// What one execution carries from pass to pass on this rank.
struct vtkRGSeamRepair::Run
{
  Run(vtkMultiProcessController* controller, vtkPolyData* input)
    : Ranks(controller)
    , Input(input)
  {
  }
  rgmc::Ranks Ranks;
  std::string Problem; // the agreed error of a failed pass
  vtkPolyData* Input;
  vtkIdType Triangles = 0;         // over all ranks
  const vtkIdType* Keys = nullptr; // the input's vertex keys, when every rank has them
  LocalVertices Vertices;
  GlobalNumbering Numbering;
  BorderTest Border;
  rgmc::VolumeBox Box;    // the volume's, or the mesh's bounds when the input does not say
  Measures Before, After; // before and after smoothing
  bool Smooth = false;
  std::vector<vtkIdType> Connectivity;    // the triangles over the vertices, when merged or copied
  vtkNew<vtkPoints> Points;               // the output's
  vtkSmartPointer<vtkFloatArray> Normals; // after smoothing
  rgmc::seam::Checks Checks;              // this rank's counts, then the sums over all ranks
  bool Aborted = false;
};

//------------------------------------------------------------------------------
// The collective schedule: every rank runs these passes in this order and makes the same
// collective calls in each (an agreement is one collective call on success, one or two
// broadcasts more on failure); a pass that fails returns on every rank at the same point.
// "Exchange" is Ranks::Exchange: with every rank in NumberVertices, else with the ranks that
// share a vertex with this one.
//
//  PASS 0 CheckInput      agreement (a triangle mesh), AllReduce (triangles), agreement
//  PASS 1 NumberVertices  AllReduce (whether every rank has vertex keys), agreement (the
//                         local sort); IdentityNumbering: AllGather, AllGatherV, agreement,
//                         exchange, agreement, AllGather, exchange, agreement (one rank: an
//                         agreement)
//  PASS 2 FindBorder      3 AllReduce (the bounds, whether every rank has the volume's box)
//  PASS 3 RepairSeams     agreement (the input copied); AnalyzeSeams: agreement, exchange,
//                         agreement, exchange, agreement; MeasureSurface: agreement,
//                         AllReduce, AllGather, agreement, AllGatherV, agreement
//  PASS 4 SmoothSurface   smoothing only: per iteration an AllReduce (abort) and two
//                         exchanges, an agreement or two; Normals: agreement, exchange,
//                         agreement, exchange, agreement; MeasureSurface as in PASS 3
//  PASS 5                 agreement (the output points)
//  PASS 6 StoreSurface    AllReduce (the checks), agreement (the output)
//         ReportChecks    none
int vtkRGSeamRepair::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPolyData* output = vtkPolyData::GetData(outputVector);
  rgmc::ForgetEarlierAbort(this->AbortExecute);
  rgmc::RunController controller(this->Controller);
  Run run(controller, vtkPolyData::GetData(inputVector[0]));
  // The count of this run's collective calls, however it ends.
  struct Accounting
  {
    vtkRGSeamRepair* Filter;
    Run& Counted;
    ~Accounting() { this->Filter->NumberOfCollectives = this->Counted.Ranks.Collectives; }
  } accounting{ this, run };

  // PASS 0: a triangle mesh with triangles, on every rank.
  rgmc::SpanMark("check input");
  if (!this->CheckInput(run))
  {
    vtkErrorMacro(<< "Cannot repair the seams: " << run.Problem << ".");
    return 0;
  }
  this->UpdateProgress(0.05);
  // PASS 1: this rank's distinct vertices and their global numbering.
  rgmc::SpanMark("numbering");
  if (!this->NumberVertices(run))
  {
    vtkErrorMacro(<< "Cannot repair the seams: " << run.Problem << ".");
    return 0;
  }
  this->UpdateProgress(0.25);
  // PASS 2: how to tell edges on the volume's border.
  rgmc::SpanMark("border");
  this->FindBorder(run);
  // PASS 3-5: edges at the seams, checks, smoothing, normals, the output points.
  if (!this->RepairSeams(run))
  {
    output->Initialize();
    if (run.Aborted)
    {
      return 1;
    }
    vtkErrorMacro(<< "Cannot repair the seams: " << run.Problem << ".");
    return 0;
  }
  // PASS 6: the global checks and the output piece.
  rgmc::SpanMark("output");
  if (!this->StoreSurface(run, output))
  {
    vtkErrorMacro(<< "Cannot repair the seams: " << run.Problem << ".");
    output->Initialize();
    return 0;
  }
  this->ReportChecks(run, output);
  this->UpdateProgress(1.0);
  return 1;
}

//------------------------------------------------------------------------------
bool vtkRGSeamRepair::CheckInput(Run& run)
{
  Ranks& ranks = run.Ranks;
  vtkPolyData* input = run.Input;
  const vtkIdType verts = input->GetNumberOfVerts(), lines = input->GetNumberOfLines(),
                  strips = input->GetNumberOfStrips();
  vtkCellArray* polys = input->GetPolys();
  const vtkIdType other = rgmc::PolygonsNotTriangles(polys);
  if (verts || lines || strips || other)
  {
    std::ostringstream msg;
    msg << "the input is not a triangle mesh: it has " << verts << " vertex cells, " << lines
        << " lines, " << strips << " triangle strips and " << other
        << " polygons that are not triangles (apply Triangulate, or Extract Surface, first)";
    run.Problem = msg.str();
  }
  if (!ranks.Agree(run.Problem.empty(), run.Problem))
  {
    return false;
  }
  const vtkIdType localTriangles = input->GetNumberOfPolys();
  ranks.AllReduce(
    &localTriangles, &run.Triangles, 1, vtkCommunicator::SUM_OP, "counting triangles");
  if (!ranks.Agree(run.Triangles > 0, run.Problem))
  {
    run.Problem = run.Problem.empty() ? std::string("the input has no triangles") : run.Problem;
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
// Identities are global ids when every rank with points has them, else exact coordinates.
bool vtkRGSeamRepair::NumberVertices(Run& run)
{
  Ranks& ranks = run.Ranks;
  vtkIdTypeArray* keyArray =
    vtkIdTypeArray::SafeDownCast(run.Input->GetPointData()->GetGlobalIds());
  int keyed = run.Input->GetNumberOfPoints() == 0 || keyArray ? 1 : 0, allKeyed = 0;
  ranks.AllReduce(&keyed, &allKeyed, 1, vtkCommunicator::MIN_OP, "agreeing on vertex identities");
  run.Keys = allKeyed && keyArray ? keyArray->GetPointer(0) : nullptr;
  auto number = [&run](auto words)
  {
    constexpr int Words = decltype(words)::value;
    Identities<Words> ids;
    return run.Ranks.Step("sort the vertices", run.Problem,
             [&]() { run.Vertices = rgmc::seam::MergeLocal<Words>(run.Input, run.Keys, ids); }) &&
      IdentityNumbering<Words>(run.Ranks, run.Vertices, ids).Number(run.Numbering, run.Problem);
  };
  return allKeyed ? number(std::integral_constant<int, 1>())
                  : number(std::integral_constant<int, 3>());
}

//------------------------------------------------------------------------------
// From keys and the whole extent when the input came from vtkRGMarchingCubes, else from the
// global bounds.
void vtkRGSeamRepair::FindBorder(Run& run)
{
  vtkPolyData* input = run.Input;
  BorderTest& border = run.Border;
  double b[6], lo[3], hi[3], glo[3], ghi[3];
  input->GetBounds(b);
  for (int a = 0; a < 3; ++a)
  {
    lo[a] = input->GetNumberOfPoints() ? b[2 * a] : VTK_DOUBLE_MAX;
    hi[a] = input->GetNumberOfPoints() ? b[2 * a + 1] : VTK_DOUBLE_MIN;
  }
  run.Ranks.AllReduce(lo, glo, 3, vtkCommunicator::MIN_OP, "reducing bounds");
  run.Ranks.AllReduce(hi, ghi, 3, vtkCommunicator::MAX_OP, "reducing bounds");
  double diagonal = 0;
  for (int a = 0; a < 3; ++a)
  {
    border.Bounds[2 * a] = glo[a];
    border.Bounds[2 * a + 1] = ghi[a];
    diagonal += (ghi[a] - glo[a]) * (ghi[a] - glo[a]);
  }
  border.Tolerance = 1e-6 * std::sqrt(diagonal);
  vtkIntArray* whole = vtkIntArray::SafeDownCast(input->GetFieldData()->GetArray("WholeExtent"));
  // Only vtkRGMarchingCubes' keys say where a vertex is in the volume: global ids numbered
  // otherwise (Seam Repair's own, vtkRGDecimate's) do not, though the extent passes with them.
  vtkDataArray* keyArray = input->GetPointData()->GetGlobalIds();
  const bool extractionKeys =
    run.Keys && keyArray && keyArray->GetName() && std::string(keyArray->GetName()) == "VertexKey";
  if (extractionKeys && whole && whole->GetNumberOfValues() == 6)
  {
    border.Keys = true;
    for (int i = 0; i < 6; ++i)
    {
      border.Whole[i] = whole->GetValue(i);
    }
  }
  // The box that closes a surface cut by the border: the volume's (vtkRGMarchingCubes says
  // where it is), else the bounds of the whole mesh.
  // Every rank must take the same box, ranks without points included.
  vtkDoubleArray* geometry =
    vtkDoubleArray::SafeDownCast(input->GetFieldData()->GetArray("VolumeGeometry"));
  const bool hasBox =
    whole && whole->GetNumberOfValues() == 6 && geometry && geometry->GetNumberOfValues() == 15;
  const int described = hasBox ? 1 : 0;
  int allDescribed = 0;
  run.Ranks.AllReduce(
    &described, &allDescribed, 1, vtkCommunicator::MIN_OP, "agreeing on the volume's box");
  if (allDescribed)
  {
    const double* g = geometry->GetPointer(0);
    std::copy_n(g, 3, run.Box.Origin);
    std::copy_n(g + 3, 3, run.Box.Spacing);
    std::copy_n(g + 6, 9, run.Box.Direction);
    for (int i = 0; i < 6; ++i)
    {
      run.Box.Extent[i] = whole->GetValue(i);
    }
  }
  else
  {
    std::copy_n(border.Bounds, 6, run.Box.Extent);
  }
}

//------------------------------------------------------------------------------
// In the input points' precision, over the input's own connectivity when no points were merged
// (a connectivity copy is always 64-bit; the input's own may be 32-bit).
bool vtkRGSeamRepair::RepairSeams(Run& run)
{
  run.Smooth = this->SmoothingMethod != NO_SMOOTHING && this->NumberOfIterations > 0;
  vtkPoints* inputPoints = run.Input->GetPoints();
  const bool doublePoints = inputPoints && inputPoints->GetDataType() == VTK_DOUBLE;
  const bool int32 = !run.Vertices.Merged() &&
    vtkAOSDataArrayTemplate<std::int32_t>::FastDownCast(
      run.Input->GetPolys()->GetConnectivityArray());
  if (doublePoints)
  {
    return int32 ? this->RepairSeamsIn<double, std::int32_t>(run)
                 : this->RepairSeamsIn<double, vtkIdType>(run);
  }
  return int32 ? this->RepairSeamsIn<float, std::int32_t>(run)
               : this->RepairSeamsIn<float, vtkIdType>(run);
}

//------------------------------------------------------------------------------
// Per iteration an abort decided over the ranks, so that every rank stops at the same one.
template <typename Repair>
bool vtkRGSeamRepair::SmoothSurface(Run& run, Repair& repair)
{
  Ranks& ranks = run.Ranks;
  SmoothingSettings settings;
  settings.Method = this->SmoothingMethod;
  settings.Iterations = this->NumberOfIterations;
  settings.Relaxation = this->RelaxationFactor;
  settings.PassBand = this->PassBand;
  settings.Window =
    this->WindowFunction == HAMMING_WINDOW ? rgmc::SincWindow::Hamming : rgmc::SincWindow::Nuttall;
  auto progress = [this, &ranks](double fraction)
  {
    this->UpdateProgress(0.4 + 0.5 * fraction);
    return ranks.Any(this->CheckAbort());
  };
  rgmc::SpanMark("smoothing");
  if (!repair.Smooth(settings, progress, run.Problem))
  {
    run.Aborted = run.Problem.empty();
    return false;
  }
  rgmc::SpanMark("normals");
  run.Normals = repair.Normals(run.Problem);
  rgmc::SpanMark("measures");
  return run.Normals &&
    rgmc::seam::MeasureSurface(
      ranks, repair, repair.Smoothed.data(), run.Box, run.After, run.Problem);
}

//------------------------------------------------------------------------------
template <typename T, typename I>
bool vtkRGSeamRepair::RepairSeamsIn(Run& run)
{
  Ranks& ranks = run.Ranks;
  const T* positions = nullptr;
  std::vector<T> copied; // the positions, when the input's cannot be used as they are
  const I* triangles = nullptr;
  // PASS 3: the input copied, the seams analysed (checks, stencils), the surface measured.
  rgmc::SpanMark("copy input");
  if (!ranks.Step("copy the input", run.Problem,
        [&]()
        {
          triangles = rgmc::seam::CopyInput<T, I>(
            run.Input, run.Vertices, positions, copied, run.Connectivity);
        }))
  {
    return false;
  }
  PieceRepair<T, I> repair(ranks, run.Vertices, run.Numbering, run.Border, run.Keys, positions,
    triangles, run.Input->GetNumberOfPolys());
  rgmc::SpanMark("seam analysis");
  if (!repair.AnalyzeSeams(run.Smooth, run.Checks, run.Problem))
  {
    return false;
  }
  rgmc::SpanMark("measures");
  if (!rgmc::seam::MeasureSurface(ranks, repair, positions, run.Box, run.Before, run.Problem))
  {
    return false;
  }
  run.After = run.Before;
  this->UpdateProgress(0.4);
  // PASS 4: smoothing, then the normals and the measures of the smoothed surface.
  if (run.Smooth && !this->SmoothSurface(run, repair))
  {
    return false;
  }
  // PASS 5: the output's points: the input's own when nothing moved and nothing was merged.
  rgmc::SpanMark("output points");
  return ranks.Step("store the output points", run.Problem,
    [&]()
    {
      if (!run.Smooth && !run.Vertices.Merged())
      {
        run.Points->ShallowCopy(run.Input->GetPoints());
        return;
      }
      const T* moved = run.Smooth ? repair.Smoothed.data() : copied.data();
      vtkNew<vtkAOSDataArrayTemplate<T>> xyz;
      xyz->SetNumberOfComponents(3);
      T* to = rgmc::Allocate(xyz.Get(), 3 * run.Vertices.Count);
      rgmc::ForEachChunk(3 * run.Vertices.Count, rgmc::ElementChunk,
        [&](vtkIdType, vtkIdType first, vtkIdType last)
        { std::copy(moved + first, moved + last, to + first); });
      run.Points->SetData(xyz);
    });
}

//------------------------------------------------------------------------------
bool vtkRGSeamRepair::StoreSurface(Run& run, vtkPolyData* output)
{
  Ranks& ranks = run.Ranks;
  Checks& checks = run.Checks;
  vtkIdType counts[4] = { checks.Edges, checks.Boundary, checks.Border, checks.NonManifold },
            sums[4] = { 0, 0, 0, 0 };
  ranks.AllReduce(counts, sums, 4, vtkCommunicator::SUM_OP, "summing the checks");
  checks.Edges = sums[0];
  checks.Boundary = sums[1];
  checks.Border = sums[2];
  checks.NonManifold = sums[3];
  output->Initialize();
  return ranks.Step("build the output", run.Problem, [&]() { this->BuildOutput(run, output); });
}

//------------------------------------------------------------------------------
// The input's triangles and point data as they are (merged when points were), global ids,
// duplicate flags, smoothed points and their normals.
void vtkRGSeamRepair::BuildOutput(Run& run, vtkPolyData* output)
{
  vtkPolyData* input = run.Input;
  const LocalVertices& vertices = run.Vertices;
  const vtkIdType n = vertices.Count;
  output->SetPoints(run.Points);
  vtkPointData* pd = output->GetPointData();
  pd->CopyGlobalIdsOff();
  if (run.Smooth)
  {
    pd->CopyNormalsOff();
  }
  if (!vertices.Merged())
  {
    output->SetPolys(input->GetPolys());
    pd->PassData(input->GetPointData());
  }
  else
  {
    vtkNew<vtkIdTypeArray> offsets, conn;
    const vtkIdType numTris = static_cast<vtkIdType>(run.Connectivity.size() / 3);
    vtkIdType* o = rgmc::Allocate(offsets.Get(), numTris + 1);
    for (vtkIdType t = 0; t <= numTris; ++t)
    {
      o[t] = 3 * t;
    }
    std::copy(run.Connectivity.begin(), run.Connectivity.end(),
      rgmc::Allocate(conn.Get(), static_cast<vtkIdType>(run.Connectivity.size())));
    vtkNew<vtkCellArray> polys;
    polys->SetData(offsets, conn);
    output->SetPolys(polys);
    pd->CopyAllocate(input->GetPointData(), n);
    for (vtkIdType v = 0; v < n; ++v)
    {
      pd->CopyData(input->GetPointData(), vertices.PointOf(v), v);
    }
  }
  output->GetCellData()->PassData(input->GetCellData());
  vtkNew<vtkIdTypeArray> gids;
  gids->SetName("GlobalPointIds");
  vtkNew<vtkUnsignedCharArray> ghosts;
  ghosts->SetName(vtkDataSetAttributes::GhostArrayName());
  vtkIdType* gid = rgmc::Allocate(gids.Get(), n);
  unsigned char* ghost = rgmc::Allocate(ghosts.Get(), n);
  rgmc::ForEachChunk(n, rgmc::ElementChunk,
    [&](vtkIdType, vtkIdType first, vtkIdType last)
    {
      for (vtkIdType v = first; v < last; ++v)
      {
        gid[v] = run.Numbering.Gid[v];
        ghost[v] = (run.Numbering.Holding[v] & GlobalNumbering::Foreign)
          ? vtkDataSetAttributes::DUPLICATEPOINT
          : 0;
      }
    });
  pd->SetGlobalIds(gids);
  pd->AddArray(ghosts);
  if (run.Smooth)
  {
    pd->SetNormals(run.Normals);
  }
}

//------------------------------------------------------------------------------
void vtkRGSeamRepair::ReportChecks(Run& run, vtkPolyData* output)
{
  const Checks& sums = run.Checks;
  const vtkIdType unique = run.Numbering.Total;
  const vtkIdType euler = unique - sums.Edges + run.Triangles;
  const bool closed = sums.Boundary == 0 && sums.NonManifold == 0;
  vtkFieldData* fd = output->GetFieldData();
  fd->PassData(run.Input->GetFieldData());
  auto add = [fd](const char* name, vtkIdType value)
  {
    vtkNew<vtkIdTypeArray> a;
    a->SetName(name);
    a->InsertNextValue(value);
    fd->AddArray(a);
  };
  add("UniquePoints", unique);
  add("Triangles", run.Triangles);
  add("Edges", sums.Edges);
  add("BoundaryEdges", sums.Boundary);
  add("VolumeBorderEdges", sums.Border);
  add("NonManifoldEdges", sums.NonManifold);
  add("EulerCharacteristic", euler);
  add("Closed", closed ? 1 : 0);
  // The measures: the volume needs a surface without holes (closed, or cut by the border only).
  const bool enclosing = sums.Boundary == 0 && run.Before.Closable && run.After.Closable;
  auto addMeasure = [fd](const char* name, double value)
  {
    vtkNew<vtkDoubleArray> a;
    a->SetName(name);
    a->InsertNextValue(value);
    fd->AddArray(a);
  };
  const double nan = vtkMath::Nan();
  addMeasure("SurfaceArea", run.After.Area);
  addMeasure("EnclosedVolume", enclosing ? run.After.Volume : nan);
  addMeasure("BorderCapArea", enclosing ? run.After.CapArea : nan);
  addMeasure("SurfaceAreaBeforeSmoothing", run.Before.Area);
  addMeasure("EnclosedVolumeBeforeSmoothing", enclosing ? run.Before.Volume : nan);
  if (run.Ranks.Rank == 0)
  {
    vtkLogF(INFO,
      "Seam repair: %lld unique points, %lld triangles, %lld edges, %lld boundary edges (%lld "
      "more on the volume's border), %lld non-manifold edges, Euler characteristic %lld: %s.",
      static_cast<long long>(unique), static_cast<long long>(run.Triangles),
      static_cast<long long>(sums.Edges), static_cast<long long>(sums.Boundary),
      static_cast<long long>(sums.Border), static_cast<long long>(sums.NonManifold),
      static_cast<long long>(euler), closed ? "closed" : "not closed");
    vtkLogF(INFO, "Seam repair: area %.10g, enclosed volume %.10g (before smoothing %.10g, %.10g).",
      run.After.Area, enclosing ? run.After.Volume : nan, run.Before.Area,
      enclosing ? run.Before.Volume : nan);
  }
}

//------------------------------------------------------------------------------
void vtkRGSeamRepair::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "SmoothingMethod: " << this->SmoothingMethod << "\n";
  os << indent << "NumberOfIterations: " << this->NumberOfIterations << "\n";
  os << indent << "RelaxationFactor: " << this->RelaxationFactor << "\n";
  os << indent << "PassBand: " << this->PassBand << "\n";
  os << indent
     << "WindowFunction: " << (this->WindowFunction == HAMMING_WINDOW ? "Hamming" : "Nuttall")
     << "\n";
  os << indent << "Controller: " << this->Controller << "\n";
  os << indent << "NumberOfCollectives: " << this->NumberOfCollectives << "\n";
}

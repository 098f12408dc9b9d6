// The VTK adapter of the region-growing kernels: input checks, ownership of cubes across ranks,
// seeds, the distributed resolution of components, and the output polydata.
#include "vtkRGMarchingCubes.h"

#include "rgmcExtractComponents.h"
#include "rgmcExtractInput.h"
#include "rgmcExtractOutput.h"
#include "vtkRGArrays.h"
#include "vtkRGCollective.h"
#include "vtkRGCompatibility.h"
#include "vtkRGMessage.h"
#include "vtkRGParallel.h"
#include "vtkRGRunController.h"
#include "vtkRGSpan.h"

#include "vtkArrayDispatch.h"
#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkCommunicator.h"
#include "vtkDataSetAttributes.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkLogger.h"
#include "vtkMath.h"
#include "vtkMatrix3x3.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>
#include <chrono>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkRGMarchingCubes);
vtkCxxSetObjectMacro(vtkRGMarchingCubes, Controller, vtkMultiProcessController);

namespace
{

using rgmc::Ranks;
using rgmc::extract::AdoptNormals;
using rgmc::extract::AdoptPoints;
using rgmc::extract::AdoptTriangles;
using rgmc::extract::AdoptVertexKeys;
using rgmc::extract::ForOtherOwners;
using rgmc::extract::Geometry;
using rgmc::extract::GlobalRange;
using rgmc::extract::KeepDecidedComponents;
using rgmc::extract::KernelBuilder;
using rgmc::extract::KernelOnSamples;
using rgmc::extract::NoValues;
using rgmc::extract::OwnedCells;
using rgmc::extract::RankGraph;
using rgmc::extract::Resolve;
constexpr int PortTag = 48731;
constexpr int DepartureTag = 48741;
// Seeded growth on several ranks pauses after expanding this many surface nodes to hand what
// reached the neighbours' parts on to them: so that the ranks a large structure passes through
// grow it at the same time rather than one after the other.
constexpr std::int64_t GrowthBudget = std::int64_t(1) << 16;

/// The filter's ExtractionMode in the kernel's words.
rgmc::Keep Kept(int mode)
{
  return mode == vtkRGMarchingCubes::SEEDED         ? rgmc::Keep::Seeded
    : mode == vtkRGMarchingCubes::LARGEST_COMPONENT ? rgmc::Keep::Largest
                                                    : rgmc::Keep::All;
}

// ---- seeds ---------------------------------------------------------------------------------

/// The global nearest vertex to each seed among every rank's hits (five values per rank and
/// seed, rank by rank): smallest distance, then smallest key, so the same point on every rank
/// that has it. A seed no rank found keeps the largest key.
void PickNearestVertices(const std::vector<vtkIdType>& all, int numRanks, int numSeeds,
  std::vector<vtkIdType>& bestKeys, std::vector<double>& bestPoints)
{
  bestKeys.assign(numSeeds, std::numeric_limits<vtkIdType>::max());
  bestPoints.assign(3 * numSeeds, 0.0);
  for (int s = 0; s < numSeeds; ++s)
  {
    double bestD2 = VTK_DOUBLE_MAX;
    for (int r = 0; r < numRanks; ++r)
    {
      rgmc::MessageReader hit(&all[5 * (numSeeds * r + s)], 5);
      const double d2 = hit.Real();
      const vtkIdType key = hit.Int();
      if (key >= 0 && (d2 < bestD2 || (d2 == bestD2 && key < bestKeys[s])))
      {
        bestD2 = d2;
        bestKeys[s] = key;
        for (int a = 0; a < 3; ++a)
        {
          bestPoints[3 * s + a] = hit.Real();
        }
      }
    }
  }
}

} // namespace

//------------------------------------------------------------------------------
vtkRGMarchingCubes::vtkRGMarchingCubes()
{
  this->SetController(vtkMultiProcessController::GetGlobalController());
  this->SetInputArrayToProcess(
    0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
}

//------------------------------------------------------------------------------
vtkRGMarchingCubes::~vtkRGMarchingCubes()
{
  this->SetController(nullptr);
}

//------------------------------------------------------------------------------
void vtkRGMarchingCubes::AddSeedPoint(double x, double y, double z)
{
  this->SeedPoints.insert(this->SeedPoints.end(), { x, y, z });
  this->Modified();
}

//------------------------------------------------------------------------------
void vtkRGMarchingCubes::RemoveAllSeedPoints()
{
  if (!this->SeedPoints.empty())
  {
    this->SeedPoints.clear();
    this->Modified();
  }
}

//------------------------------------------------------------------------------
int vtkRGMarchingCubes::GetNumberOfSeedPoints() const
{
  return static_cast<int>(this->SeedPoints.size() / 3);
}

//------------------------------------------------------------------------------
void vtkRGMarchingCubes::GetSeedPoint(int i, double x[3]) const
{
  std::copy_n(this->SeedPoints.begin() + 3 * i, 3, x);
}

//------------------------------------------------------------------------------
int vtkRGMarchingCubes::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkImageData");
  return 1;
}

//------------------------------------------------------------------------------
int vtkRGMarchingCubes::RequestUpdateExtent(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkInformation* inInfo = inputVector[0]->GetInformationObject(0);
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  using SDDP = vtkStreamingDemandDrivenPipeline;
  inInfo->Set(SDDP::UPDATE_PIECE_NUMBER(), outInfo->Get(SDDP::UPDATE_PIECE_NUMBER()));
  inInfo->Set(SDDP::UPDATE_NUMBER_OF_PIECES(), outInfo->Get(SDDP::UPDATE_NUMBER_OF_PIECES()));
  // One ghost layer: central differences at the seams need the neighbour's samples.
  inInfo->Set(SDDP::UPDATE_NUMBER_OF_GHOST_LEVELS(), 1);
  return 1;
}

//------------------------------------------------------------------------------
/// What one execution carries from pass to pass on this rank.
struct vtkRGMarchingCubes::Run
{
  explicit Run(vtkMultiProcessController* controller)
    : Ranks(controller)
  {
  }
  rgmc::Ranks Ranks;
  std::string Problem; // the agreed error of a failed pass
  int WholeExtent[6] = { 0, -1, 0, -1, 0, -1 };
  bool HasPoints = false;
  vtkDataArray* Scalars = nullptr;
  rgmc::extract::Geometry Geometry;
  int LocalExtent[6] = { 0, -1, 0, -1, 0, -1 };
  std::unique_ptr<rgmc::Ownership> Ownership;
  std::unique_ptr<rgmc::Grid> Grid;
  std::unique_ptr<rgmc::Kernel> Kernel;
  std::vector<rgmc::CellBox> CellBoxes;   // per rank: its cells not marked ghost
  std::vector<rgmc::CellBox> ExtentBoxes; // per rank: all the cells of its extent
  std::vector<vtkIdType> SeedVertexKeys;
  std::vector<double> SeedVertexPoints;
  rgmc::extract::RankGraph Graph;
  std::vector<std::int64_t> Roots, Edges; // per rank: the sizes of its part of the graph
  rgmc::Decision Decision;
  int GrowthRounds = 0;       // rounds of growth between ranks
  bool GrewInOneStep = false; // the rest grown in one step (GrowBoundary) or a full scan
  vtkIdType TrianglesMade = 0;
};

//------------------------------------------------------------------------------
// The collective schedule: every rank runs these passes in this order and makes the same
// collective calls in each (an agreement is one collective call on success, one or two
// broadcasts more on failure); a pass that fails returns on every rank at the same point.
// Seeded on N ranks with R rounds of growth with messages between ranks and G rounds without
// (a rank still growing past its budget): 9 + R + G collective calls on success and R + 1
// exchanges with the neighbours (on one rank: 8 calls); Largest and All: 7 and 1.
//
//  PASS 0 CheckInput
//           AgreeOnWholeExtent      AllReduce (whole extent)
//           GatherPieces            agreement gathering every rank's boxes of cells, whether it
//                                   has points, and its geometry
//  PASS 1 AssignCubes               none (ownership and neighbours from the gathered boxes)
//         BuildKernel               none
//  PASS 2 FindSeeds                 Seeded mode only:
//           GatherNearestVertices   agreement gathering each rank's nearest vertex to each seed
//           WarnNoSurfaceNearSeed   GlobalRange (2 AllReduce) when a seed has none
//  PASS 3 GrowAndExtract
//           GrowInRounds            Seeded on several ranks: per round an agreement (status,
//                                   anything sent: AddressDepartures) and, if something was, an
//                                   exchange with the neighbours (then GrowFromNeighbours; past
//                                   MaximumGrowthRounds GrowComponentsAtSharedFaces instead)
//           GrowAndExtractLocally   none
//           JoinComponentsAtPorts   an exchange of ports with the neighbours
//           AgreeOnGraphSizes       agreement gathering the status, abort, missing ghosts and
//                                   graph sizes
//  PASS 4 Resolve                   agreement (memory for the graph), GatherV (the graph to
//                                   rank 0), ScatterV (the decision, with rank 0's verdict)
//  PASS 5 StoreSurface              agreement (also on what Resolve found) around AdoptSurface
//         DescribeSurface           GlobalRange when the surface is empty (2 AllReduce)
int vtkRGMarchingCubes::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkImageData* input = vtkImageData::GetData(inputVector[0]);
  vtkPolyData* output = vtkPolyData::GetData(outputVector);
  rgmc::ForgetEarlierAbort(this->AbortExecute);
  rgmc::RunController controller(this->Controller);
  Run run(controller);
  // The counts and the time of this run, however it ends.
  struct Accounting
  {
    vtkRGMarchingCubes* Filter;
    Run& Counted;
    std::chrono::steady_clock::time_point Started = std::chrono::steady_clock::now();
    ~Accounting()
    {
      this->Filter->ExtractionSeconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - this->Started).count();
      this->Filter->Account(this->Counted);
    }
  } accounting{ this, run };

  // PASS 0: check the input on every rank and agree on the verdict.
  rgmc::SpanMark("check input");
  if (!this->CheckInput(run, input, inputVector))
  {
    vtkErrorMacro(<< "Cannot extract a surface: " << run.Problem << ".");
    return 0;
  }
  this->UpdateProgress(0.05);
  // PASS 1: ownership of cubes; the kernel over this rank's samples.
  rgmc::SpanMark("cubes and kernel");
  this->AssignCubes(run);
  this->BuildKernel(run);
  // PASS 2: seeds, each to its nearest surface vertex over all ranks.
  if (this->ExtractionMode == SEEDED)
  {
    rgmc::SpanMark("seed search");
    const int found = this->FindSeeds(run);
    if (found <= 0)
    {
      return found == 0 ? 1 : 0; // no surface near a seed (a warning), or an error
    }
  }
  this->UpdateProgress(0.1);
  // PASS 3: local growth and extraction, on every rank at once.
  const int grown = this->GrowAndExtract(run);
  if (grown <= 0)
  {
    output->Initialize();
    return grown == 0 ? 1 : 0; // aborted, or an error
  }
  this->UpdateProgress(0.8);
  // PASS 4: join components across ranks; decide what to keep (agreed in pass 5).
  rgmc::SpanMark("component decision");
  Resolve(run.Ranks, Kept(this->ExtractionMode), run.Graph, run.Roots, run.Edges, run.Decision,
    run.Problem);
  this->UpdateProgress(0.9);
  // PASS 5: the output piece.
  rgmc::SpanMark("output arrays");
  if (!this->StoreSurface(run, output))
  {
    vtkErrorMacro(<< "Cannot extract a surface: " << run.Problem << ".");
    output->Initialize();
    return 0;
  }
  this->DescribeSurface(run, output);
  this->UpdateProgress(1.0);
  return 1;
}

//------------------------------------------------------------------------------
bool vtkRGMarchingCubes::CheckInput(
  Run& run, vtkImageData* input, vtkInformationVector** inputVector)
{
  run.HasPoints = input && input->GetNumberOfPoints() > 0;
  this->AgreeOnWholeExtent(run, input, inputVector[0]->GetInformationObject(0));
  run.Problem = this->DescribeInputProblem(run, input, inputVector);
  return this->GatherPieces(run, input);
}

//------------------------------------------------------------------------------
// The whole extent, agreed by all ranks: the union of what each rank was told and what it holds
// (pieces handed over without a pipeline know only their own extent). One MIN reduction of the
// lows and the negated highs.
void vtkRGMarchingCubes::AgreeOnWholeExtent(Run& run, vtkImageData* input, vtkInformation* inInfo)
{
  int told[6] = { 0, -1, 0, -1, 0, -1 }, held[6] = { 0, -1, 0, -1, 0, -1 };
  if (inInfo->Has(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()))
  {
    inInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), told);
  }
  if (run.HasPoints)
  {
    input->GetExtent(held);
  }
  int mine[6], agreed[6];
  for (int a = 0; a < 3; ++a)
  {
    mine[a] = VTK_INT_MAX;
    mine[3 + a] = VTK_INT_MAX; // -high
    for (const int* e : { told, held })
    {
      if (e[1] >= e[0] && e[3] >= e[2] && e[5] >= e[4])
      {
        mine[a] = std::min(mine[a], e[2 * a]);
        mine[3 + a] = std::min(mine[3 + a], -e[2 * a + 1]);
      }
    }
  }
  run.Ranks.AllReduce(mine, agreed, 6, vtkCommunicator::MIN_OP, "a reduction");
  if (agreed[0] <= -agreed[3])
  {
    for (int a = 0; a < 3; ++a)
    {
      run.WholeExtent[2 * a] = agreed[a];
      run.WholeExtent[2 * a + 1] = -agreed[3 + a];
    }
  }
}

//------------------------------------------------------------------------------
// What is wrong with this rank's input (empty: nothing); the scalars to contour, when found.
std::string vtkRGMarchingCubes::DescribeInputProblem(
  Run& run, vtkImageData* input, vtkInformationVector** inputVector)
{
  const int* whole = run.WholeExtent;
  std::ostringstream msg;
  if (whole[1] < whole[0] || whole[3] < whole[2] || whole[5] < whole[4])
  {
    msg << "the input image is empty (whole extent " << whole[0] << " " << whole[1] << " "
        << whole[2] << " " << whole[3] << " " << whole[4] << " " << whole[5] << ")";
  }
  else if (whole[1] == whole[0] || whole[3] == whole[2] || whole[5] == whole[4])
  {
    msg << "the input image is not a volume: its dimensions are " << whole[1] - whole[0] + 1
        << " x " << whole[3] - whole[2] + 1 << " x " << whole[5] - whole[4] + 1
        << "; marching cubes needs at least 2 samples along each axis";
  }
  else if (vtkMath::IsNan(this->Isovalue))
  {
    msg << "the isovalue is NaN";
  }
  else if (this->ExtractionMode == SEEDED && this->SeedPoints.empty())
  {
    msg << "no seed point is set: add one (SeedPoints = [x, y, z] in world coordinates) or "
           "choose the Largest Component or All Components mode";
  }
  else if (run.HasPoints)
  {
    this->CheckScalars(run, input, inputVector, msg);
  }
  return msg.str();
}

//------------------------------------------------------------------------------
void vtkRGMarchingCubes::CheckScalars(
  Run& run, vtkImageData* input, vtkInformationVector** inputVector, std::ostream& msg)
{
  int association = vtkDataObject::FIELD_ASSOCIATION_POINTS;
  vtkDataArray* scalars = this->GetInputArrayToProcess(0, inputVector, association);
  vtkInformation* arrayInfo = this->GetInputArrayInformation(0);
  const char* name = arrayInfo && arrayInfo->Has(vtkDataObject::FIELD_NAME())
    ? arrayInfo->Get(vtkDataObject::FIELD_NAME())
    : nullptr;
  if (scalars && association != vtkDataObject::FIELD_ASSOCIATION_POINTS)
  {
    msg << "the array '" << (scalars->GetName() ? scalars->GetName() : "")
        << "' is cell data; contouring needs point data (apply Cell Data to Point Data "
           "first)";
  }
  else if (!scalars)
  {
    if (name && input->GetCellData()->GetArray(name))
    {
      msg << "the array '" << name
          << "' is cell data; contouring needs point data (apply Cell Data to Point Data "
             "first)";
    }
    else if (name)
    {
      msg << "the input has no point array named '" << name << "'";
    }
    else
    {
      msg << "the input has no point scalars to contour (it has "
          << input->GetPointData()->GetNumberOfArrays() << " point arrays and "
          << input->GetCellData()->GetNumberOfArrays()
          << " cell arrays, none of them active point scalars)";
    }
  }
  else if (scalars->GetNumberOfComponents() != 1)
  {
    msg << "the array '" << (scalars->GetName() ? scalars->GetName() : "") << "' has "
        << scalars->GetNumberOfComponents()
        << " components; contour one component (extract it first, e.g. with Calculator)";
  }
  else
  {
    run.Scalars = scalars;
  }
}

//------------------------------------------------------------------------------
// One agreement that also gathers each rank's cells (those not marked ghost, and all of its
// extent), whether it has points, and its geometry: the lowest rank with points gives everybody
// its geometry (a rank without data may carry default geometry).
bool vtkRGMarchingCubes::GatherPieces(Run& run, vtkImageData* input)
{
  Ranks& ranks = run.Ranks;
  rgmc::CellBox myCells, allMine;
  if (run.Problem.empty() && run.HasPoints && run.Scalars)
  {
    input->GetExtent(run.LocalExtent);
    myCells = OwnedCells(input);
  }
  for (int a = 0; a < 3; ++a)
  {
    allMine.Lo[a] = run.LocalExtent[2 * a];
    allMine.Hi[a] = run.LocalExtent[2 * a + 1] - 1;
  }
  // Per rank: whether it has points, its two boxes, origin, spacing, direction.
  constexpr std::size_t PerRank = 1 + 12 + 15;
  double geometry[15] = { 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0 };
  if (run.HasPoints)
  {
    input->GetOrigin(geometry);
    input->GetSpacing(geometry + 3);
    std::copy_n(input->GetDirectionMatrix()->GetData(), 9, geometry + 6);
  }
  std::vector<vtkIdType> mine, all;
  rgmc::MessageWriter piece(mine);
  piece.Int(run.HasPoints ? 1 : 0);
  for (const rgmc::CellBox* box : { &myCells, &allMine })
  {
    piece.Int(box->Lo[0]).Int(box->Lo[1]).Int(box->Lo[2]);
    piece.Int(box->Hi[0]).Int(box->Hi[1]).Int(box->Hi[2]);
  }
  for (double g : geometry)
  {
    piece.Real(g);
  }
  if (!ranks.AgreeGather(run.Problem.empty(), run.Problem, mine, all))
  {
    return false;
  }
  int source = -1;
  run.CellBoxes.resize(ranks.Size);
  run.ExtentBoxes.resize(ranks.Size);
  for (int r = ranks.Size - 1; r >= 0; --r)
  {
    rgmc::MessageReader theirs(&all[PerRank * r], PerRank);
    source = theirs.Int() != 0 ? r : source;
    for (rgmc::CellBox* box : { &run.CellBoxes[r], &run.ExtentBoxes[r] })
    {
      for (int* bound : { box->Lo, box->Hi })
      {
        for (int a = 0; a < 3; ++a)
        {
          bound[a] = static_cast<int>(theirs.Int());
        }
      }
    }
    if (r == source)
    {
      for (double& g : geometry)
      {
        g = theirs.Real();
      }
    }
  }
  if (source < 0)
  {
    run.Problem = "the input image has no points"; // the same verdict on every rank
    return false;
  }
  std::copy_n(geometry, 3, run.Geometry.Origin);
  std::copy_n(geometry + 3, 3, run.Geometry.Spacing);
  std::copy_n(geometry + 6, 9, run.Geometry.Direction);
  return true;
}

//------------------------------------------------------------------------------
void vtkRGMarchingCubes::AssignCubes(Run& run)
{
  Ranks& ranks = run.Ranks;
  const int* whole = run.WholeExtent;
  std::vector<rgmc::CellBox>& cellBoxes = run.CellBoxes;
  const std::vector<rgmc::CellBox>& extentBoxes = run.ExtentBoxes;
  // Ghost markings that leave cells of a piece owned by no rank (a reader whose ghost arrays do
  // not match its pieces) would silently lose the surface there. Then own by the extents: first
  // without the one ghost layer asked for at faces inside the volume (the pipeline's
  // convention), else whole, the lowest rank holding a cell owning it. Every rank knows every
  // box, so every rank finds the same.
  bool holes = false;
  for (const rgmc::CellBox& b : extentBoxes)
  {
    holes = holes || !rgmc::Covers(cellBoxes, b);
  }
  if (holes)
  {
    std::vector<rgmc::CellBox> trimmed = extentBoxes;
    for (rgmc::CellBox& b : trimmed)
    {
      for (int a = 0; a < 3 && !b.Empty(); ++a)
      {
        b.Lo[a] += b.Lo[a] > whole[2 * a] ? 1 : 0;
        b.Hi[a] -= b.Hi[a] < whole[2 * a + 1] - 1 ? 1 : 0;
      }
    }
    bool trimmedCovers = true;
    for (const rgmc::CellBox& b : extentBoxes)
    {
      trimmedCovers = trimmedCovers && rgmc::Covers(trimmed, b);
    }
    cellBoxes = trimmedCovers ? trimmed : extentBoxes;
    if (ranks.Rank == 0)
    {
      vtkWarningMacro(<< "The input's ghost arrays mark cells that no rank owns (they do not match "
                         "the pieces); cells are owned by the pieces' extents instead"
                      << (trimmedCovers ? " less one ghost layer."
                                        : ". Normals at the partition seams may be one-sided."));
    }
  }
  run.Ownership.reset(new rgmc::Ownership(cellBoxes, ranks.Rank));
  run.Grid.reset(new rgmc::Grid(whole, run.LocalExtent));
}

//------------------------------------------------------------------------------
// The kernel over this rank's samples (of any array type; a rank without samples owns no cube
// and reads none), with the isovalue, the options and the geometry.
void vtkRGMarchingCubes::BuildKernel(Run& run)
{
  rgmc::SurfaceOptions options;
  options.Isovalue = this->Isovalue;
  options.ComputeNormals = this->ComputeNormals;
  options.DoublePoints = this->OutputPointsPrecision == DOUBLE_PRECISION;
  run.Geometry.IndexToWorldMatrix(options.IndexToWorld);
  run.Geometry.NormalMatrix(options.NormalToWorld);
  options.Progress = [this](double fraction)
  {
    this->UpdateProgress(0.1 + 0.7 * fraction);
    return this->CheckAbort();
  };
  // Threads within the rank: vtkSMPTools, so ParaView's and VTK's settings govern them
  // (VTK_SMP_BACKEND_IN_USE, VTK_SMP_MAX_THREADS). Each index is a large task (a tile, a chunk).
  options.ParallelFor =
    [](std::int64_t count, const std::function<void(std::int64_t, std::int64_t)>& body)
  {
    rgmc::ParallelFor(static_cast<vtkIdType>(count), vtkIdType(1),
      [&body](vtkIdType begin, vtkIdType end) { body(begin, end); });
  };
  options.Phase = [](const char* phase) { rgmc::SpanMark(phase); };
  KernelBuilder builder{ run.Grid.get(), run.Ownership.get(), &options, nullptr };
  if (run.Scalars)
  {
    if (!vtkArrayDispatch::Dispatch::Execute(run.Scalars, builder))
    {
      builder(run.Scalars); // any other array layout, through the generic API
    }
  }
  else
  {
    builder.Result.reset(
      new KernelOnSamples<NoValues>(NoValues(), *run.Grid, *run.Ownership, options));
  }
  run.Kernel = std::move(builder.Result);
}

//------------------------------------------------------------------------------
// Each seed to its nearest surface vertex over all ranks: each rank's nearest vertices, gathered
// in one agreement, and the global nearest picked alike on every rank.
int vtkRGMarchingCubes::FindSeeds(Run& run)
{
  std::vector<double> seedIndex;
  const std::string outside = this->DescribeSeedOutsideVolume(run, seedIndex);
  // A seed outside the volume: the same verdict on every rank (the geometry is agreed).
  if (!outside.empty())
  {
    vtkWarningMacro(<< "No surface extracted: " << outside << ".");
    return 0;
  }
  std::vector<vtkIdType> hits;
  if (!this->GatherNearestVertices(run, seedIndex, hits))
  {
    vtkErrorMacro(<< "Cannot extract a surface: " << run.Problem << ".");
    return -1;
  }
  const int numSeeds = this->GetNumberOfSeedPoints();
  std::vector<vtkIdType> bestKeys;
  std::vector<double> bestPoints;
  PickNearestVertices(hits, run.Ranks.Size, numSeeds, bestKeys, bestPoints);
  for (int s = 0; s < numSeeds; ++s)
  {
    if (bestKeys[s] == std::numeric_limits<vtkIdType>::max())
    {
      this->WarnNoSurfaceNearSeed(run, s);
      return 0;
    }
  }
  run.SeedVertexKeys = std::move(bestKeys);
  run.SeedVertexPoints = std::move(bestPoints);
  return 1;
}

//------------------------------------------------------------------------------
// The seeds in continuous index coordinates; what is wrong when one lies outside the volume
// (empty: nothing), the same on every rank since the geometry is agreed.
std::string vtkRGMarchingCubes::DescribeSeedOutsideVolume(Run& run, std::vector<double>& seedIndex)
{
  const int* whole = run.WholeExtent;
  const Geometry& geom = run.Geometry;
  const int numSeeds = this->GetNumberOfSeedPoints();
  std::ostringstream outside;
  seedIndex.resize(3 * numSeeds);
  for (int s = 0; s < numSeeds && outside.str().empty(); ++s)
  {
    double* q = &seedIndex[3 * s];
    geom.WorldToIndex(&this->SeedPoints[3 * s], q);
    for (int a = 0; a < 3; ++a)
    {
      const double tolerance = 1e-6 * (1.0 + std::fabs(whole[2 * a + 1]));
      if (!(q[a] >= whole[2 * a] - tolerance && q[a] <= whole[2 * a + 1] + tolerance))
      {
        double bounds[6];
        geom.Bounds(whole, bounds);
        outside << "seed point " << s << " (" << this->SeedPoints[3 * s] << ", "
                << this->SeedPoints[3 * s + 1] << ", " << this->SeedPoints[3 * s + 2]
                << ") lies outside the volume, whose bounds are [" << bounds[0] << ", " << bounds[1]
                << "] x [" << bounds[2] << ", " << bounds[3] << "] x [" << bounds[4] << ", "
                << bounds[5] << "]";
        break;
      }
    }
  }
  return outside.str();
}

//------------------------------------------------------------------------------
// Each rank's nearest vertex to each seed (a NaN met on the way is an error), gathered in the
// agreement: per rank and seed, the squared distance, the key (-1: none found), the position.
bool vtkRGMarchingCubes::GatherNearestVertices(
  Run& run, const std::vector<double>& seedIndex, std::vector<vtkIdType>& all)
{
  const double minStep = run.Geometry.MinStep();
  std::vector<vtkIdType> mine;
  rgmc::MessageWriter hits(mine);
  for (int s = 0; s < this->GetNumberOfSeedPoints(); ++s)
  {
    const rgmc::SeedHit hit = run.Kernel->NearestVertex(
      &seedIndex[3 * s], &this->SeedPoints[3 * s], this->SeedSearchRadius, minStep);
    hits.Real(hit.Found ? hit.Distance2 : VTK_DOUBLE_MAX).Int(hit.Found ? hit.Key : -1);
    hits.Real(hit.Point[0]).Real(hit.Point[1]).Real(hit.Point[2]);
  }
  run.Problem = run.Kernel->Error();
  return run.Ranks.AgreeGather(run.Problem.empty(), run.Problem, mine, all);
}

//------------------------------------------------------------------------------
// Warns, on a seed whose search found no vertex on any rank, whether there is no surface at all
// or only none near the seed. Collective (GlobalRange).
void vtkRGMarchingCubes::WarnNoSurfaceNearSeed(Run& run, int seed)
{
  double range[2];
  GlobalRange(run.Ranks, run.Scalars, range);
  std::ostringstream why;
  if (this->Isovalue > range[1] || this->Isovalue <= range[0])
  {
    why << "the isovalue " << this->Isovalue << " is outside the data range [" << range[0] << ", "
        << range[1] << "], so there is no surface at all";
  }
  else
  {
    why << "no surface at isovalue " << this->Isovalue << " passes within "
        << this->SeedSearchRadius << " of seed point " << seed << " (" << this->SeedPoints[3 * seed]
        << ", " << this->SeedPoints[3 * seed + 1] << ", " << this->SeedPoints[3 * seed + 2]
        << "); move the seed onto the structure or raise SeedSearchRadius";
  }
  vtkWarningMacro(<< "No surface extracted: " << why.str() << ".");
}

//------------------------------------------------------------------------------
int vtkRGMarchingCubes::GrowAndExtract(Run& run)
{
  const bool rounds = this->ExtractionMode == SEEDED && run.Ranks.Size > 1;
  bool aborted = false;
  if (rounds && !this->GrowInRounds(run, aborted))
  {
    vtkErrorMacro(<< "Cannot extract a surface: " << run.Problem << ".");
    return -1;
  }
  this->GrowAndExtractLocally(run, rounds, aborted);
  aborted = aborted || run.Kernel->Aborted();
  this->JoinComponentsAtPorts(run, aborted);
  return this->AgreeOnGraphSizes(run, aborted);
}

//------------------------------------------------------------------------------
// The growth left after GrowInRounds (all of it without rounds), the extraction and this rank's
// part of the component graph. A failure of the last round's growth skips the extraction.
void vtkRGMarchingCubes::GrowAndExtractLocally(Run& run, bool rounds, bool aborted)
{
  rgmc::Kernel& kernel = *run.Kernel;
  std::string outOfMemory = run.Problem;
  rgmc::TryLocally(
    outOfMemory, "grow and extract the surface", run.Ranks.Rank,
    [&]()
    {
      rgmc::SpanMark("growth");
      if (!rounds && this->ExtractionMode == SEEDED)
      {
        for (vtkIdType key : run.SeedVertexKeys)
        {
          kernel.GrowFromKey(key);
        }
      }
      else if (!rounds)
      {
        run.GrewInOneStep = true;
        kernel.GrowAll();
      }
      if (!aborted)
      {
        rgmc::SpanMark("extraction: nodes by slab");
        kernel.Extract();
        run.TrianglesMade = kernel.Mesh().NumberOfTriangles();
        rgmc::SpanMark("component graph");
        run.Graph.Prepare(kernel, *run.Grid, *run.Ownership, run.Ranks.Rank, run.Ranks.Size);
      }
    },
    [&]()
    { return " (" + std::to_string(kernel.Mesh().NumberOfTriangles()) + " triangles so far)"; });
  run.Problem = outOfMemory.empty() ? kernel.Error() : outOfMemory;
}

//------------------------------------------------------------------------------
// Ports go to the neighbours that own the other cubes around them (nothing after a failure
// here: the exchange still runs, so that the ranks stay in step); the edges of the component
// graph are the ports both sides have.
void vtkRGMarchingCubes::JoinComponentsAtPorts(Run& run, bool aborted)
{
  Ranks& ranks = run.Ranks;
  std::vector<std::vector<vtkIdType>> nothing(ranks.Size);
  const bool sendPorts = run.Problem.empty() && !aborted;
  const std::vector<std::vector<vtkIdType>> incoming = ranks.ExchangeInOrder(
    sendPorts ? run.Graph.PortsTo : nothing, run.Ownership->MeetingOrder(), PortTag);
  if (sendPorts)
  {
    rgmc::TryLocally(run.Problem, "join the components", ranks.Rank,
      [&]() { run.Graph.Join(incoming, ranks.Rank); });
  }
}

//------------------------------------------------------------------------------
// One agreement, which also tells every rank the sizes of every rank's part of the graph, and
// whether any rank aborted or misses ghosts. 1: go on; 0: aborted; -1: an error.
int vtkRGMarchingCubes::AgreeOnGraphSizes(Run& run, bool aborted)
{
  Ranks& ranks = run.Ranks;
  std::vector<vtkIdType> mine = { run.Graph.Roots, run.Graph.Edges, aborted ? 1 : 0,
    run.Kernel->MissingGhosts() ? 1 : 0 },
                         all;
  if (!ranks.AgreeGather(run.Problem.empty(), run.Problem, mine, all))
  {
    vtkErrorMacro(<< "Cannot extract a surface: " << run.Problem << ".");
    return -1;
  }
  bool missingGhosts = false;
  run.Roots.resize(ranks.Size);
  run.Edges.resize(ranks.Size);
  for (int r = 0; r < ranks.Size; ++r)
  {
    run.Roots[r] = all[4 * r];
    run.Edges[r] = all[4 * r + 1];
    aborted = aborted || all[4 * r + 2] != 0;
    missingGhosts = missingGhosts || all[4 * r + 3] != 0;
  }
  if (aborted)
  {
    return 0;
  }
  if (missingGhosts && ranks.Rank == 0)
  {
    vtkWarningMacro(<< "The input pieces have no ghost layer: normals at the partition seams "
                       "are one-sided there and differ from a 1-rank run.");
  }
  return 1;
}

//------------------------------------------------------------------------------
// Seeded growth on several ranks. Round 0 grows from the seed vertices on the ranks that own
// cubes around them. Each round then: the departures (vertices where growth stepped into
// another rank's cubes) go to those cubes' owners, once per vertex and owner, except back to
// the rank a vertex just came from; one reduction agrees on the status and on whether anybody
// sent anything (or has growth left); if so, the neighbours exchange departures and each rank
// grows on from what it received (one new component per sending rank's component), for at most
// GrowthBudget nodes. A rank the structure never reaches examines no cube. Past
// MaximumGrowthRounds rounds with messages every rank grows the rest in one step.
bool vtkRGMarchingCubes::GrowInRounds(Run& run, bool& aborted)
{
  Ranks& ranks = run.Ranks;
  rgmc::Kernel& kernel = *run.Kernel;
  std::string problem;
  auto local = [&](const char* what, const std::function<void()>& work)
  { rgmc::TryLocally(problem, what, ranks.Rank, work); };
  kernel.SetCrossRanks(true);
  kernel.SetBudget(GrowthBudget);
  local("grow from the seeds",
    [&]()
    {
      for (vtkIdType key : run.SeedVertexKeys)
      {
        kernel.GrowFromKey(key);
      }
    });
  // The vertices received last, by rank: not sent back there.
  std::vector<std::pair<std::int64_t, int>> received;
  for (;;)
  {
    std::vector<std::vector<vtkIdType>> outgoing(ranks.Size);
    bool sending = false;
    local("send the growing surface to the neighbours",
      [&]() { this->AddressDepartures(run, received, outgoing, sending); });
    if (problem.empty())
    {
      problem = kernel.Error();
    }
    // An abort is noticed by the kernel's progress reports, which a rank without work makes
    // none of: ask the filter too.
    aborted = kernel.Aborted() || this->CheckAbort();
    bool busy = kernel.Busy();
    if (!ranks.Agree(problem.empty(), problem, { &sending, &aborted, &busy }))
    {
      run.Problem = problem;
      return false;
    }
    if (aborted || (!sending && !busy))
    {
      return true;
    }
    if (!sending)
    {
      // Some rank still grows a large part of the structure: a round without messages.
      local("grow the surface", [&]() { kernel.Continue(); });
      continue;
    }
    if (run.GrowthRounds >= this->MaximumGrowthRounds)
    {
      this->GrowComponentsAtSharedFaces(run, problem);
      run.Problem = problem; // GrowAndExtract agrees on the status
      return true;
    }
    const std::vector<std::vector<vtkIdType>> incoming =
      ranks.ExchangeInOrder(outgoing, run.Ownership->MeetingOrder(), DepartureTag);
    ++run.GrowthRounds;
    local("grow from the neighbours' surface",
      [&]() { this->GrowFromNeighbours(run, incoming, received); });
  }
}

//------------------------------------------------------------------------------
// Past MaximumGrowthRounds, the rest in one step: every component next to another rank's cubes;
// Resolve keeps those joined to a seed. The departures not sent are among them.
void vtkRGMarchingCubes::GrowComponentsAtSharedFaces(Run& run, std::string& problem)
{
  rgmc::Kernel& kernel = *run.Kernel;
  run.GrewInOneStep = true;
  kernel.SetCrossRanks(false);
  kernel.SetBudget(std::numeric_limits<std::int64_t>::max());
  rgmc::TryLocally(problem, "grow the components at the shared faces", run.Ranks.Rank,
    [&]()
    {
      kernel.Continue();
      kernel.GrowBoundary();
    });
}

//------------------------------------------------------------------------------
// The work of "send the growing surface to the neighbours": the departures the kernel made,
// each vertex once, addressed to the other owners of the cubes around it, except the rank it
// was just received from. `sending` is set when anything is addressed.
void vtkRGMarchingCubes::AddressDepartures(Run& run,
  const std::vector<std::pair<std::int64_t, int>>& received,
  std::vector<std::vector<vtkIdType>>& outgoing, bool& sending)
{
  std::vector<rgmc::Departure> departures = run.Kernel->TakeDepartures();
  std::sort(departures.begin(), departures.end(),
    [](const rgmc::Departure& a, const rgmc::Departure& b)
    { return a.Key < b.Key || (a.Key == b.Key && a.Component < b.Component); });
  std::int64_t last = -1;
  for (const rgmc::Departure& d : departures)
  {
    if (d.Key == last)
    {
      continue;
    }
    last = d.Key;
    ForOtherOwners(*run.Grid, *run.Ownership, run.Ranks.Rank, d.Key,
      [&](int owner)
      {
        if (!std::binary_search(received.begin(), received.end(), std::make_pair(d.Key, owner)))
        {
          outgoing[owner].push_back(d.Key);
          outgoing[owner].push_back(d.Component);
          sending = true;
        }
      });
  }
}

//------------------------------------------------------------------------------
// The work of "grow from the neighbours' surface": the vertices received become arrivals, with
// one label per component of a sending rank, in the order of the ranks; `received` lists them
// by rank for the next round.
void vtkRGMarchingCubes::GrowFromNeighbours(Run& run,
  const std::vector<std::vector<vtkIdType>>& incoming,
  std::vector<std::pair<std::int64_t, int>>& received)
{
  std::vector<rgmc::Arrival> arrivals;
  std::map<vtkIdType, int> labelOf; // of the sending rank's components
  int numLabels = 0;
  received.clear();
  for (const int from : run.Ownership->Neighbours())
  {
    labelOf.clear();
    const std::vector<vtkIdType>& list = incoming[from];
    for (std::size_t n = 0; n + 1 < list.size(); n += 2)
    {
      auto label = labelOf.emplace(list[n + 1], numLabels);
      numLabels += label.second ? 1 : 0;
      arrivals.push_back(rgmc::Arrival{ list[n], label.first->second });
      received.emplace_back(list[n], from);
    }
  }
  std::sort(received.begin(), received.end());
  run.Kernel->GrowFromArrivals(arrivals, numLabels);
}

//------------------------------------------------------------------------------
bool vtkRGMarchingCubes::StoreSurface(Run& run, vtkPolyData* output)
{
  output->Initialize();
  return run.Ranks.Step(
    "store the surface", run.Problem, [&]() { this->AdoptSurface(run, output); });
}

//------------------------------------------------------------------------------
// The work of "store the surface": the kept components, renumbered, become the output piece.
// The kernel's buffers become the output arrays without copies.
void vtkRGMarchingCubes::AdoptSurface(Run& run, vtkPolyData* output)
{
  rgmc::LocalMesh& mesh = run.Kernel->Mesh();
  KeepDecidedComponents(run.Decision, run.Graph.RootIndex, mesh);
  const vtkIdType numPoints = mesh.NumberOfPoints();
  const vtkIdType numKept = mesh.NumberOfTriangles();
  vtkSmartPointer<vtkPoints> points =
    AdoptPoints(mesh, numPoints, this->OutputPointsPrecision == DOUBLE_PRECISION);
  vtkSmartPointer<vtkFloatArray> normals = AdoptNormals(mesh, numPoints, this->ComputeNormals);
  vtkSmartPointer<vtkIdTypeArray> keys = AdoptVertexKeys(mesh, numPoints);
  vtkSmartPointer<vtkCellArray> polys = AdoptTriangles(mesh, numKept);
  vtkNew<vtkIntArray> componentIds;
  componentIds->SetName("ComponentId");
  static_assert(sizeof(int) == sizeof(std::int32_t), "component ids are 32-bit");
  componentIds->SetArray(reinterpret_cast<int*>(mesh.TriangleComponent.Release()), numKept, 0,
    vtkAbstractArray::VTK_DATA_ARRAY_FREE);
  vtkNew<vtkIntArray> rankIds;
  rankIds->SetName("RankId");
  rgmc::extract::Fill(rgmc::Allocate(rankIds.Get(), numKept), numKept, run.Ranks.Rank);

  output->SetPoints(points);
  output->SetPolys(polys);
  if (this->ComputeNormals)
  {
    output->GetPointData()->SetNormals(normals);
  }
  output->GetPointData()->SetGlobalIds(keys);
  output->GetCellData()->AddArray(rankIds);
  // No active scalars: ParaView shows the surface in one colour, as Contour's; colouring by
  // RankId (the decomposition) or ComponentId is the user's choice.
  output->GetCellData()->AddArray(componentIds);
}

//------------------------------------------------------------------------------
void vtkRGMarchingCubes::DescribeSurface(Run& run, vtkPolyData* output)
{
  vtkNew<vtkIdTypeArray> seedKeyArray;
  seedKeyArray->SetName("SeedVertexKeys");
  vtkNew<vtkDoubleArray> seedPointArray;
  seedPointArray->SetName("SeedVertexPoints");
  seedPointArray->SetNumberOfComponents(3);
  for (std::size_t s = 0; s < run.SeedVertexKeys.size(); ++s)
  {
    seedKeyArray->InsertNextValue(run.SeedVertexKeys[s]);
    seedPointArray->InsertNextTuple(&run.SeedVertexPoints[3 * s]);
  }
  vtkNew<vtkIdTypeArray> triangleCount;
  triangleCount->SetName("NumberOfTriangles");
  triangleCount->InsertNextValue(run.Decision.Triangles);
  vtkNew<vtkIdTypeArray> componentCount;
  componentCount->SetName("NumberOfComponents");
  componentCount->InsertNextValue(run.Decision.Components);
  if (!run.SeedVertexKeys
         .empty()) // empty arrays would hide the field data from ParaView's information
  {
    output->GetFieldData()->AddArray(seedKeyArray);
    output->GetFieldData()->AddArray(seedPointArray);
  }
  output->GetFieldData()->AddArray(triangleCount);
  vtkNew<vtkIntArray> wholeExtent; // lets Seam Repair tell edges on the volume's border
  wholeExtent->SetName("WholeExtent");
  wholeExtent->SetNumberOfValues(6);
  for (int i = 0; i < 6; ++i)
  {
    wholeExtent->SetValue(i, run.WholeExtent[i]);
  }
  output->GetFieldData()->AddArray(wholeExtent);
  // With WholeExtent, the volume's box in the world: Seam Repair closes a surface cut by it.
  vtkNew<vtkDoubleArray> geometry;
  geometry->SetName("VolumeGeometry");
  geometry->SetNumberOfValues(15);
  std::copy_n(run.Geometry.Origin, 3, geometry->GetPointer(0));
  std::copy_n(run.Geometry.Spacing, 3, geometry->GetPointer(3));
  std::copy_n(run.Geometry.Direction, 9, geometry->GetPointer(6));
  output->GetFieldData()->AddArray(geometry);
  output->GetFieldData()->AddArray(componentCount);

  if (run.Decision.Triangles == 0)
  {
    double range[2];
    GlobalRange(run.Ranks, run.Scalars, range);
    if (run.Ranks.Rank == 0)
    {
      vtkWarningMacro(<< "No surface extracted: the isovalue " << this->Isovalue
                      << " gives no triangles (data range [" << range[0] << ", " << range[1]
                      << "]).");
    }
  }
}

//------------------------------------------------------------------------------
void vtkRGMarchingCubes::Account(Run& run)
{
  this->NumberOfGrowthRounds = run.GrowthRounds;
  this->GrewInOneStep = run.GrewInOneStep;
  this->NumberOfCollectives = static_cast<vtkIdType>(run.Ranks.Collectives);
  this->NumberOfMessages = static_cast<vtkIdType>(run.Ranks.Messages);
  this->NumberOfValuesSent = static_cast<vtkIdType>(run.Ranks.ValuesSent);
  this->NumberOfCubesExamined = run.Kernel ? run.Kernel->CubesExamined() : 0;
  this->NumberOfFacePointsRead = run.Kernel ? run.Kernel->PlanePointsRead() : 0;
  this->NumberOfTrianglesMade = run.TrianglesMade;
  vtkLogF(TRACE,
    "vtkRGMarchingCubes on rank %d of %d: %d rounds of growth between ranks%s, %lld collectives, "
    "%lld messages sent (%lld values), %lld cubes examined, %lld face points read, %lld "
    "triangles made",
    run.Ranks.Rank, run.Ranks.Size, run.GrowthRounds, run.GrewInOneStep ? " then one step" : "",
    static_cast<long long>(this->NumberOfCollectives),
    static_cast<long long>(this->NumberOfMessages),
    static_cast<long long>(this->NumberOfValuesSent),
    static_cast<long long>(this->NumberOfCubesExamined),
    static_cast<long long>(this->NumberOfFacePointsRead),
    static_cast<long long>(this->NumberOfTrianglesMade));
}

//------------------------------------------------------------------------------
void vtkRGMarchingCubes::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Isovalue: " << this->Isovalue << "\n";
  os << indent << "SeedPoints: " << this->GetNumberOfSeedPoints() << "\n";
  for (int s = 0; s < this->GetNumberOfSeedPoints(); ++s)
  {
    os << indent.GetNextIndent() << "(" << this->SeedPoints[3 * s] << ", "
       << this->SeedPoints[3 * s + 1] << ", " << this->SeedPoints[3 * s + 2] << ")\n";
  }
  os << indent << "SeedSearchRadius: " << this->SeedSearchRadius << "\n";
  os << indent << "ExtractionMode: " << this->ExtractionMode << "\n";
  os << indent << "ComputeNormals: " << (this->ComputeNormals ? "On" : "Off") << "\n";
  os << indent << "OutputPointsPrecision: " << this->OutputPointsPrecision << "\n";
  os << indent << "MaximumGrowthRounds: " << this->MaximumGrowthRounds << "\n";
  os << indent << "Controller: " << this->Controller << "\n";
}

// The VTK adapter of the region-growing kernels: input checks, ownership of cubes across ranks,
// seeds, the distributed resolution of components, and the output polydata.
#include "vtkRGMarchingCubes.h"

#include "rgmcCaseTable.h"
#include "rgmcComponentGraph.h"
#include "rgmcSurfaceKernel.h"
#include "vtkRGArrays.h"
#include "vtkRGCollective.h"
#include "vtkRGCompatibility.h"
#include "vtkRGMessage.h"
#include "vtkRGParallel.h"
#include "vtkRGRunController.h"

#include "vtkArrayDispatch.h"
#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkCommunicator.h"
#include "vtkDataArrayRange.h"
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
#include "vtkMarchingCubesTriangleCases.h"
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
#include "vtkTypeInt32Array.h"
#include "vtkTypeInt64Array.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <array>
#include <cstdlib>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkRGMarchingCubes);
vtkCxxSetObjectMacro(vtkRGMarchingCubes, Controller, vtkMultiProcessController);

namespace
{

using rgmc::Ranks;
constexpr int PortTag = 48731;
constexpr int DepartureTag = 48741;
// Seeded growth on several ranks pauses after expanding this many surface nodes (about 10 ms
// of work) to hand what reached the neighbours' parts on to them: so that the ranks a large
// structure passes through grow it at the same time rather than one after the other.
constexpr std::int64_t GrowthBudget = std::int64_t(1) << 16;

const rgmc::CaseTable& Cases()
{
  static const rgmc::CaseTable table(&vtkMarchingCubesTriangleCases::GetCases()[0].edges[0]);
  return table;
}

// ---- geometry ------------------------------------------------------------------------------

/// Origin, spacing and direction of the volume, agreed on by all ranks (a rank without data
/// may carry default geometry).
struct Geometry
{
  double Origin[3] = { 0, 0, 0 };
  double Spacing[3] = { 1, 1, 1 };
  double Direction[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 1 };

  void IndexToWorldMatrix(double m[3][4]) const
  {
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 3; ++c)
      {
        m[r][c] = this->Direction[3 * r + c] * this->Spacing[c];
      }
      m[r][3] = this->Origin[r];
    }
  }

  void NormalMatrix(double m[3][3]) const
  {
    double d[3][3];
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 3; ++c)
      {
        d[r][c] = this->Direction[3 * r + c];
      }
    }
    const double det = vtkMath::Determinant3x3(d);
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 3; ++c)
      {
        m[r][c] = det * d[r][c] / this->Spacing[c];
      }
    }
  }

  /// Continuous index coordinates of a world point.
  void WorldToIndex(const double x[3], double idx[3]) const
  {
    double m[3][4], a[3][3], inv[3][3];
    this->IndexToWorldMatrix(m);
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 3; ++c)
      {
        a[r][c] = m[r][c];
      }
    }
    vtkMath::Invert3x3(a, inv);
    const double d[3] = { x[0] - m[0][3], x[1] - m[1][3], x[2] - m[2][3] };
    vtkMath::Multiply3x3(inv, d, idx);
  }

  /// World bounds of the volume of point extent `whole`.
  void Bounds(const int whole[6], double bounds[6]) const
  {
    double m[3][4];
    this->IndexToWorldMatrix(m);
    for (int a = 0; a < 3; ++a)
    {
      bounds[2 * a] = VTK_DOUBLE_MAX;
      bounds[2 * a + 1] = VTK_DOUBLE_MIN;
    }
    for (int c = 0; c < 8; ++c)
    {
      const double idx[3] = { double(whole[(c & 1) ? 1 : 0]), double(whole[(c & 2) ? 3 : 2]),
        double(whole[(c & 4) ? 5 : 4]) };
      for (int a = 0; a < 3; ++a)
      {
        const double x = m[a][0] * idx[0] + m[a][1] * idx[1] + m[a][2] * idx[2] + m[a][3];
        bounds[2 * a] = std::min(bounds[2 * a], x);
        bounds[2 * a + 1] = std::max(bounds[2 * a + 1], x);
      }
    }
  }

  /// The smallest world length of a unit index step (smallest singular value).
  double MinStep() const
  {
    double m[3][4], a[3][3], u[3][3], w[3], vt[3][3];
    this->IndexToWorldMatrix(m);
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 3; ++c)
      {
        a[r][c] = m[r][c];
      }
    }
    vtkMath::SingularValueDecomposition3x3(a, u, w, vt);
    return std::min(std::fabs(w[0]), std::min(std::fabs(w[1]), std::fabs(w[2])));
  }
};

// ---- ownership -----------------------------------------------------------------------------

/// The box of this piece's cells that are not ghosts. Ghost layers of image data are shells at
/// the extent's faces, so probing the lines through the centre finds the box; an unusual
/// pattern falls back to scanning the ghost array.
rgmc::CellBox OwnedCells(vtkImageData* input)
{
  rgmc::CellBox box;
  int ext[6];
  input->GetExtent(ext);
  for (int a = 0; a < 3; ++a)
  {
    box.Lo[a] = ext[2 * a];
    box.Hi[a] = ext[2 * a + 1] - 1;
  }
  vtkUnsignedCharArray* ghosts = input->GetCellGhostArray();
  if (!ghosts || box.Empty())
  {
    return box;
  }
  const vtkIdType nx = ext[1] - ext[0], nxy = nx * (ext[3] - ext[2]);
  auto ghost = [&](int i, int j, int k)
  {
    const vtkIdType id = (i - ext[0]) + nx * (j - ext[2]) + nxy * (k - ext[4]);
    return (ghosts->GetValue(id) & vtkDataSetAttributes::DUPLICATECELL) != 0;
  };
  const rgmc::CellBox all = box;
  int centre[3];
  for (int a = 0; a < 3; ++a)
  {
    centre[a] = (all.Lo[a] + all.Hi[a]) / 2;
  }
  bool probed = !ghost(centre[0], centre[1], centre[2]);
  for (int a = 0; a < 3 && probed; ++a)
  {
    int p[3] = { centre[0], centre[1], centre[2] };
    for (p[a] = all.Lo[a]; p[a] < centre[a] && ghost(p[0], p[1], p[2]); ++p[a])
    {
    }
    box.Lo[a] = p[a];
    for (p[a] = all.Hi[a]; p[a] > centre[a] && ghost(p[0], p[1], p[2]); --p[a])
    {
    }
    box.Hi[a] = p[a];
  }
  for (int c = 0; c < 8 && probed; ++c)
  {
    const int i = (c & 1) ? box.Hi[0] : box.Lo[0];
    const int j = (c & 2) ? box.Hi[1] : box.Lo[1];
    const int k = (c & 4) ? box.Hi[2] : box.Lo[2];
    probed = !ghost(i, j, k);
  }
  if (probed)
  {
    return box;
  }
  rgmc::CellBox found; // bounding box of all non-ghost cells
  for (int a = 0; a < 3; ++a)
  {
    found.Lo[a] = all.Hi[a] + 1;
    found.Hi[a] = all.Lo[a] - 1;
  }
  for (int k = all.Lo[2]; k <= all.Hi[2]; ++k)
  {
    for (int j = all.Lo[1]; j <= all.Hi[1]; ++j)
    {
      for (int i = all.Lo[0]; i <= all.Hi[0]; ++i)
      {
        if (!ghost(i, j, k))
        {
          const int p[3] = { i, j, k };
          for (int a = 0; a < 3; ++a)
          {
            found.Lo[a] = std::min(found.Lo[a], p[a]);
            found.Hi[a] = std::max(found.Hi[a], p[a]);
          }
        }
      }
    }
  }
  return found;
}

// ---- the kernel over the input's samples, whatever the array type ---------------------------

/// The samples' range, constructed before the kernel that keeps a reference to it.
template <typename Range>
struct SamplesHolder
{
  Range Samples;
};

/// The kernel (rgmc::Kernel's implementation) with the samples it reads.
template <typename Range>
struct KernelOnSamples
  : SamplesHolder<Range>
  , rgmc::SurfaceKernel<Range>
{
  KernelOnSamples(const Range& samples, const rgmc::Grid& grid, const rgmc::Ownership& own,
    const rgmc::SurfaceOptions& options)
    : SamplesHolder<Range>{ samples }
    , rgmc::SurfaceKernel<Range>(Cases(), grid, own, this->Samples, options)
  {
  }
};

/// Stands in for the samples on a rank that has none (it owns no cube, so nothing is read).
struct NoValues
{
  float operator[](std::int64_t) const { return 0.0f; }
};

struct MakeKernel
{
  const rgmc::Grid* Grid;
  const rgmc::Ownership* Own;
  const rgmc::SurfaceOptions* Options;
  std::unique_ptr<rgmc::Kernel> Result;

  template <typename ArrayT>
  void operator()(ArrayT* array)
  {
    using Range = decltype(vtk::DataArrayValueRange<1>(array));
    this->Result.reset(new KernelOnSamples<Range>(
      vtk::DataArrayValueRange<1>(array), *this->Grid, *this->Own, *this->Options));
  }
};

// ---- routing between neighbours ------------------------------------------------------------

/// Calls `to(owner)` once for each other rank that owns a cube around vertex `key` (one of this
/// rank's vertices: such cubes touch this rank's, so their owners are among its neighbours).
template <typename To>
void ForOtherOwners(
  const rgmc::Grid& grid, const rgmc::Ownership& own, int rank, std::int64_t key, To&& to)
{
  int p[3], axis;
  grid.Decode(key, p, axis);
  int sentTo[8], numSent = 0;
  rgmc::ForCubesAround(p, axis,
    [&](int i, int j, int k, int)
    {
      if (!grid.HasCell(i, j, k) || own.Owns(i, j, k))
      {
        return;
      }
      const int owner = own.OwnerNear(i, j, k);
      if (owner < 0 || owner == rank || std::count(sentTo, sentTo + numSent, owner))
      {
        return;
      }
      sentTo[numSent++] = owner;
      to(owner);
    });
}

// ---- the global decision: which components to keep, and their ids --------------------------

/// This rank's part of the component graph (rgmc::ComponentGraph), made after extraction, with
/// what routes it: the root of each local component, and the ports to send to each neighbour.
struct RankGraph : rgmc::ComponentGraph
{
  std::vector<int> RootIndex;                  // per local component: its root's index
  std::vector<std::vector<vtkIdType>> PortsTo; // per rank: (key, root index) pairs

  /// Numbers the roots, lists their totals, and sorts the ports by the ranks that own the other
  /// cubes around them. Local work.
  void Prepare(rgmc::Kernel& kernel, const rgmc::Grid& grid, const rgmc::Ownership& own, int rank,
    int numRanks)
  {
    rgmc::ComponentSet& comps = kernel.Components();
    this->RootIndex.assign(comps.Size(), -1);
    for (int c = 0; c < comps.Size(); ++c)
    {
      if (comps.Root(c) == c)
      {
        const rgmc::ComponentSet::Totals& totals = comps.TotalsOf(c);
        this->RootIndex[c] =
          static_cast<int>(this->AddRoot(totals.Triangles, totals.MinKey, totals.Seeded));
      }
    }
    for (int c = 0; c < comps.Size(); ++c)
    {
      this->RootIndex[c] = this->RootIndex[comps.Root(c)];
    }
    this->PortsTo.resize(static_cast<std::size_t>(numRanks));
    for (const rgmc::Port& port : kernel.Ports())
    {
      const vtkIdType root = this->RootIndex[port.Component];
      this->Ports.emplace_back(port.Key, root);
      ForOtherOwners(grid, own, rank, port.Key,
        [&](int owner)
        {
          this->PortsTo[owner].push_back(port.Key);
          this->PortsTo[owner].push_back(root);
        });
    }
    std::sort(this->Ports.begin(), this->Ports.end());
  }
};

/// The filter's ExtractionMode in the kernel's words.
rgmc::Keep Kept(int mode)
{
  return mode == vtkRGMarchingCubes::SEEDED         ? rgmc::Keep::Seeded
    : mode == vtkRGMarchingCubes::LARGEST_COMPONENT ? rgmc::Keep::Largest
                                                    : rgmc::Keep::All;
}

/// Gathers the component graph (each rank's part, sizes known to all from `roots` and
/// `edges`) on rank 0, which decides, and gives each rank its decision. Collective; false (with
/// `problem`) when it failed, on every rank alike (rank 0's verdict comes with the decision),
/// but not yet agreed: the caller's next agreement does that.
bool Resolve(Ranks& ranks, rgmc::Keep mode, const rgmc::ComponentGraph& graph,
  const std::vector<std::int64_t>& roots, const std::vector<std::int64_t>& edges,
  rgmc::Decision& decision, std::string& problem)
{
  const int size = ranks.Size;
  std::vector<vtkIdType> gatherLengths(size), gatherOffsets(size + 1, 0);
  std::vector<vtkIdType> scatterLengths(size), scatterOffsets(size + 1, 0);
  for (int r = 0; r < size; ++r)
  {
    gatherLengths[r] = 3 * roots[r] + 2 * edges[r];
    gatherOffsets[r + 1] = gatherOffsets[r] + gatherLengths[r];
    scatterLengths[r] = 3 + roots[r]; // the header, then the roots' final ids
    scatterOffsets[r + 1] = scatterOffsets[r] + scatterLengths[r];
  }
  std::vector<std::int64_t> parts, decided, mine;
  if (!ranks.Step("join the components", problem,
        [&]()
        {
          parts.resize(ranks.Rank == 0 ? gatherOffsets[size] + 1 : 1);
          decided.resize(ranks.Rank == 0 ? scatterOffsets[size] : 1);
          mine.resize(static_cast<std::size_t>(scatterLengths[ranks.Rank]));
        }))
  {
    return false;
  }
  ranks.GatherV(graph.Part.data(), parts.data(), gatherLengths[ranks.Rank], gatherLengths.data(),
    gatherOffsets.data(), 0, "gathering the components");
  std::string noMemory; // on rank 0, told to every rank below
  if (ranks.Rank == 0 &&
    !rgmc::TryLocally(noMemory, "decide which components to keep",
      [&]() { rgmc::Decide(mode, parts, roots, edges, decided.data()); }))
  {
    for (int r = 0; r < size; ++r)
    {
      decided[scatterOffsets[r]] = 1; // the verdict every rank reads
    }
  }
  ranks.ScatterV(decided.data(), mine.data(), scatterLengths.data(), scatterOffsets.data(),
    scatterLengths[ranks.Rank], 0, "scattering the decision");
  if (mine[0] == 1)
  {
    problem = "not enough memory on rank 0 to decide which components to keep";
    return false;
  }
  decision.Triangles = mine[1];
  decision.Components = mine[2];
  decision.FinalId.assign(mine.begin() + 3, mine.end());
  // Component ids are 32-bit in the output (ComponentId, like vtkConnectivityFilter's RegionId).
  if (decision.Components > VTK_INT_MAX)
  {
    problem = "the surface has " + std::to_string(decision.Components) +
      " components, more than ComponentId can number (" + std::to_string(VTK_INT_MAX) + ")";
    return false;
  }
  // A failed gather or scatter is reported at the next agreement (StoreSurface's).
  return true;
}

/// Global range of the scalars (only on failure paths, to explain an empty result).
void GlobalRange(Ranks& ranks, vtkDataArray* scalars, double range[2])
{
  double lo = VTK_DOUBLE_MAX, hi = VTK_DOUBLE_MIN;
  if (scalars && scalars->GetNumberOfTuples() > 0)
  {
    double r[2];
    scalars->GetRange(r, 0);
    lo = r[0];
    hi = r[1];
  }
  ranks.AllReduce(&lo, &range[0], 1, vtkCommunicator::MIN_OP, "a reduction");
  ranks.AllReduce(&hi, &range[1], 1, vtkCommunicator::MAX_OP, "a reduction");
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
    : ranks(controller)
  {
  }
  Ranks ranks;
  std::string problem; // the agreed error of a failed pass
  int whole[6] = { 0, -1, 0, -1, 0, -1 };
  bool hasPoints = false;
  vtkDataArray* scalars = nullptr;
  Geometry geometry;
  int local[6] = { 0, -1, 0, -1, 0, -1 };
  std::unique_ptr<rgmc::Ownership> own;
  std::unique_ptr<rgmc::Grid> grid;
  std::unique_ptr<rgmc::Kernel> kernel;
  std::vector<rgmc::CellBox> cellBoxes;   // per rank: its cells not marked ghost
  std::vector<rgmc::CellBox> extentBoxes; // per rank: all the cells of its extent
  std::vector<vtkIdType> seedKeys;
  std::vector<double> seedPoints;
  RankGraph graph;
  std::vector<std::int64_t> roots, edges; // per rank: the sizes of its part of the graph
  rgmc::Decision decision;
  int rounds = 0;       // rounds of growth between ranks
  bool oneStep = false; // the rest grown in one step (GrowBoundary) or a full scan
  vtkIdType trianglesMade = 0;
};

//------------------------------------------------------------------------------
// The collective schedule: every rank runs these passes in this order and makes the same
// collective calls in each (an agreement is one collective call on success, one or two
// broadcasts more on failure); a pass that fails returns on every rank at the same point.
// Seeded on N ranks with R rounds of growth with messages between ranks and G rounds without
// (a rank still growing past its budget): 9 + R + G collective calls on success and R + 1
// exchanges with the neighbours (on one rank: 8 calls); Largest and All: 7 and 1.
//
//  PASS 0 CheckInput       AllReduce (whole extent), agreement gathering every rank's boxes
//                          of cells, whether it has points, and its geometry
//  PASS 1 AssignCubes      none (ownership and neighbours from the gathered boxes)
//         BuildKernel      none
//  PASS 2 FindSeeds        Seeded mode only: agreement gathering each rank's nearest vertex
//                          to each seed; GlobalRange (2 AllReduce) when there is none
//  PASS 3 GrowAndExtract   Seeded on several ranks: per round an agreement (status, anything
//                          sent) and, if something was, an exchange with the neighbours. Then
//                          an exchange of ports with the neighbours, and an agreement
//                          gathering the status, abort, missing ghosts and graph sizes
//  PASS 4 Resolve          agreement (memory for the graph), GatherV (the graph to rank 0),
//                          ScatterV (the decision, with rank 0's verdict)
//  PASS 5 StoreSurface     agreement (also on what Resolve found)
//         DescribeSurface  GlobalRange when the surface is empty (2 AllReduce)
int vtkRGMarchingCubes::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkImageData* input = vtkImageData::GetData(inputVector[0]);
  vtkPolyData* output = vtkPolyData::GetData(outputVector);
  rgmc::ForgetEarlierAbort(this->AbortExecute);
  rgmc::RunController controller(this->Controller);
  Run run(controller);
  // The counts of this run, however it ends.
  struct Accounting
  {
    vtkRGMarchingCubes* Filter;
    Run& Counted;
    ~Accounting() { this->Filter->Account(this->Counted); }
  } accounting{ this, run };

  // PASS 0: check the input on every rank and agree on the verdict.
  if (!this->CheckInput(run, input, inputVector))
  {
    vtkErrorMacro(<< "Cannot extract a surface: " << run.problem << ".");
    return 0;
  }
  this->UpdateProgress(0.05);
  // PASS 1: ownership of cubes; the kernel over this rank's samples.
  this->AssignCubes(run);
  this->BuildKernel(run);
  // PASS 2: seeds, each to its nearest surface vertex over all ranks.
  if (this->ExtractionMode == SEEDED)
  {
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
  Resolve(run.ranks, Kept(this->ExtractionMode), run.graph, run.roots, run.edges, run.decision,
    run.problem);
  this->UpdateProgress(0.9);
  // PASS 5: the output piece.
  if (!this->StoreSurface(run, output))
  {
    vtkErrorMacro(<< "Cannot extract a surface: " << run.problem << ".");
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
  run.hasPoints = input && input->GetNumberOfPoints() > 0;
  this->AgreeOnWholeExtent(run, input, inputVector[0]->GetInformationObject(0));
  run.problem = this->DescribeInputProblem(run, input, inputVector);
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
  if (run.hasPoints)
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
  run.ranks.AllReduce(mine, agreed, 6, vtkCommunicator::MIN_OP, "a reduction");
  if (agreed[0] <= -agreed[3])
  {
    for (int a = 0; a < 3; ++a)
    {
      run.whole[2 * a] = agreed[a];
      run.whole[2 * a + 1] = -agreed[3 + a];
    }
  }
}

//------------------------------------------------------------------------------
// What is wrong with this rank's input (empty: nothing); the scalars to contour, when found.
std::string vtkRGMarchingCubes::DescribeInputProblem(
  Run& run, vtkImageData* input, vtkInformationVector** inputVector)
{
  const int* whole = run.whole;
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
  else if (run.hasPoints)
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
    run.scalars = scalars;
  }
}

//------------------------------------------------------------------------------
// One agreement that also gathers each rank's cells (those not marked ghost, and all of its
// extent), whether it has points, and its geometry: the lowest rank with points gives everybody
// its geometry (a rank without data may carry default geometry).
bool vtkRGMarchingCubes::GatherPieces(Run& run, vtkImageData* input)
{
  Ranks& ranks = run.ranks;
  rgmc::CellBox myCells, allMine;
  if (run.problem.empty() && run.hasPoints && run.scalars)
  {
    input->GetExtent(run.local);
    myCells = OwnedCells(input);
  }
  for (int a = 0; a < 3; ++a)
  {
    allMine.Lo[a] = run.local[2 * a];
    allMine.Hi[a] = run.local[2 * a + 1] - 1;
  }
  // Per rank: whether it has points, its two boxes, origin, spacing, direction.
  constexpr std::size_t PerRank = 1 + 12 + 15;
  double geometry[15] = { 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0 };
  if (run.hasPoints)
  {
    input->GetOrigin(geometry);
    input->GetSpacing(geometry + 3);
    std::copy_n(input->GetDirectionMatrix()->GetData(), 9, geometry + 6);
  }
  std::vector<vtkIdType> mine, all;
  rgmc::MessageWriter piece(mine);
  piece.Int(run.hasPoints ? 1 : 0);
  for (const rgmc::CellBox* box : { &myCells, &allMine })
  {
    piece.Int(box->Lo[0]).Int(box->Lo[1]).Int(box->Lo[2]);
    piece.Int(box->Hi[0]).Int(box->Hi[1]).Int(box->Hi[2]);
  }
  for (double g : geometry)
  {
    piece.Real(g);
  }
  if (!ranks.AgreeGather(run.problem.empty(), run.problem, mine, all))
  {
    return false;
  }
  int source = -1;
  run.cellBoxes.resize(ranks.Size);
  run.extentBoxes.resize(ranks.Size);
  for (int r = ranks.Size - 1; r >= 0; --r)
  {
    rgmc::MessageReader theirs(&all[PerRank * r], PerRank);
    source = theirs.Int() != 0 ? r : source;
    for (rgmc::CellBox* box : { &run.cellBoxes[r], &run.extentBoxes[r] })
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
    run.problem = "the input image has no points"; // the same verdict on every rank
    return false;
  }
  std::copy_n(geometry, 3, run.geometry.Origin);
  std::copy_n(geometry + 3, 3, run.geometry.Spacing);
  std::copy_n(geometry + 6, 9, run.geometry.Direction);
  return true;
}

//------------------------------------------------------------------------------
void vtkRGMarchingCubes::AssignCubes(Run& run)
{
  Ranks& ranks = run.ranks;
  const int* whole = run.whole;
  std::vector<rgmc::CellBox>& cellBoxes = run.cellBoxes;
  const std::vector<rgmc::CellBox>& extentBoxes = run.extentBoxes;
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
  run.own.reset(new rgmc::Ownership(cellBoxes, ranks.Rank));
  run.grid.reset(new rgmc::Grid(whole, run.local));
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
  run.geometry.IndexToWorldMatrix(options.IndexToWorld);
  run.geometry.NormalMatrix(options.NormalToWorld);
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
  MakeKernel make{ run.grid.get(), run.own.get(), &options, nullptr };
  if (run.scalars)
  {
    if (!vtkArrayDispatch::Dispatch::Execute(run.scalars, make))
    {
      make(run.scalars); // any other array layout, through the generic API
    }
  }
  else
  {
    make.Result.reset(new KernelOnSamples<NoValues>(NoValues(), *run.grid, *run.own, options));
  }
  run.kernel = std::move(make.Result);
}

//------------------------------------------------------------------------------
int vtkRGMarchingCubes::FindSeeds(Run& run)
{
  Ranks& ranks = run.ranks;
  const int* whole = run.whole;
  const Geometry& geom = run.geometry;
  const int numSeeds = this->GetNumberOfSeedPoints();
  // Every seed must lie in the volume (the same verdict on every rank: the geometry is agreed).
  std::ostringstream outside;
  std::vector<double> seedIndex(3 * numSeeds);
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
  // A seed outside the volume: the same verdict on every rank (the geometry is agreed).
  if (!outside.str().empty())
  {
    vtkWarningMacro(<< "No surface extracted: " << outside.str() << ".");
    return 0;
  }
  // Each rank's nearest vertex to each seed (a NaN met on the way is an error), gathered in the
  // agreement: per seed, the squared distance, the key (-1: none found), the position.
  const double minStep = geom.MinStep();
  std::vector<vtkIdType> mine, all;
  rgmc::MessageWriter hits(mine);
  for (int s = 0; s < numSeeds; ++s)
  {
    const rgmc::SeedHit hit = run.kernel->NearestVertex(
      &seedIndex[3 * s], &this->SeedPoints[3 * s], this->SeedSearchRadius, minStep);
    hits.Real(hit.Found ? hit.Distance2 : VTK_DOUBLE_MAX).Int(hit.Found ? hit.Key : -1);
    hits.Real(hit.Point[0]).Real(hit.Point[1]).Real(hit.Point[2]);
  }
  run.problem = run.kernel->Error();
  if (!ranks.AgreeGather(run.problem.empty(), run.problem, mine, all))
  {
    vtkErrorMacro(<< "Cannot extract a surface: " << run.problem << ".");
    return -1;
  }
  // The global nearest: smallest distance, then smallest key (the same point on every rank
  // that has it).
  std::vector<vtkIdType> bestKeys(numSeeds, std::numeric_limits<vtkIdType>::max());
  std::vector<double> bestPoints(3 * numSeeds, 0.0);
  for (int s = 0; s < numSeeds; ++s)
  {
    double bestD2 = VTK_DOUBLE_MAX;
    for (int r = 0; r < ranks.Size; ++r)
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
  for (int s = 0; s < numSeeds; ++s)
  {
    if (bestKeys[s] == std::numeric_limits<vtkIdType>::max())
    {
      double range[2];
      GlobalRange(ranks, run.scalars, range);
      std::ostringstream why;
      if (this->Isovalue > range[1] || this->Isovalue <= range[0])
      {
        why << "the isovalue " << this->Isovalue << " is outside the data range [" << range[0]
            << ", " << range[1] << "], so there is no surface at all";
      }
      else
      {
        why << "no surface at isovalue " << this->Isovalue << " passes within "
            << this->SeedSearchRadius << " of seed point " << s << " (" << this->SeedPoints[3 * s]
            << ", " << this->SeedPoints[3 * s + 1] << ", " << this->SeedPoints[3 * s + 2]
            << "); move the seed onto the structure or raise SeedSearchRadius";
      }
      vtkWarningMacro(<< "No surface extracted: " << why.str() << ".");
      return 0;
    }
  }
  run.seedKeys = bestKeys;
  run.seedPoints = bestPoints;
  return 1;
}

//------------------------------------------------------------------------------
int vtkRGMarchingCubes::GrowAndExtract(Run& run)
{
  Ranks& ranks = run.ranks;
  rgmc::Kernel& kernel = *run.kernel;
  const bool rounds = this->ExtractionMode == SEEDED && ranks.Size > 1;
  bool aborted = false;
  if (rounds)
  {
    if (!this->GrowInRounds(run, aborted))
    {
      vtkErrorMacro(<< "Cannot extract a surface: " << run.problem << ".");
      return -1;
    }
  }
  // A failure of the last round's growth (GrowInRounds) skips the extraction.
  std::string outOfMemory = run.problem;
  rgmc::TryLocally(
    outOfMemory, "grow and extract the surface", ranks.Rank,
    [&]()
    {
      if (!rounds && this->ExtractionMode == SEEDED)
      {
        for (vtkIdType key : run.seedKeys)
        {
          kernel.GrowFromKey(key);
        }
      }
      else if (!rounds)
      {
        run.oneStep = true;
        kernel.GrowAll();
      }
      if (!aborted)
      {
        kernel.Extract();
        run.trianglesMade = kernel.Mesh().NumberOfTriangles();
        run.graph.Prepare(kernel, *run.grid, *run.own, ranks.Rank, ranks.Size);
      }
    },
    [&]()
    { return " (" + std::to_string(kernel.Mesh().NumberOfTriangles()) + " triangles so far)"; });
  run.problem = outOfMemory.empty() ? kernel.Error() : outOfMemory;
  aborted = aborted || kernel.Aborted();
  // Ports go to the neighbours that own the other cubes around them (nothing after a failure
  // here: the exchange still runs, so that the ranks stay in step); the edges of the component
  // graph are the ports both sides have.
  std::vector<std::vector<vtkIdType>> nothing(ranks.Size);
  const bool sendPorts = run.problem.empty() && !aborted;
  const std::vector<std::vector<vtkIdType>> incoming = ranks.ExchangeInOrder(
    sendPorts ? run.graph.PortsTo : nothing, run.own->MeetingOrder(), PortTag);
  if (sendPorts)
  {
    rgmc::TryLocally(run.problem, "join the components", ranks.Rank,
      [&]() { run.graph.Join(incoming, ranks.Rank); });
  }
  // One agreement, which also tells every rank the sizes of every rank's part of the graph.
  std::vector<vtkIdType> mine = { run.graph.Roots, run.graph.Edges, aborted ? 1 : 0,
    kernel.MissingGhosts() ? 1 : 0 },
                         all;
  if (!ranks.AgreeGather(run.problem.empty(), run.problem, mine, all))
  {
    vtkErrorMacro(<< "Cannot extract a surface: " << run.problem << ".");
    return -1;
  }
  bool missingGhosts = false;
  run.roots.resize(ranks.Size);
  run.edges.resize(ranks.Size);
  for (int r = 0; r < ranks.Size; ++r)
  {
    run.roots[r] = all[4 * r];
    run.edges[r] = all[4 * r + 1];
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
  Ranks& ranks = run.ranks;
  rgmc::Kernel& kernel = *run.kernel;
  const rgmc::Grid& grid = *run.grid;
  const rgmc::Ownership& own = *run.own;
  std::string problem;
  auto local = [&](const char* what, const std::function<void()>& work)
  { rgmc::TryLocally(problem, what, ranks.Rank, work); };
  kernel.SetCrossRanks(true);
  kernel.SetBudget(GrowthBudget);
  local("grow from the seeds",
    [&]()
    {
      for (vtkIdType key : run.seedKeys)
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
      [&]()
      {
        std::vector<rgmc::Departure> departures = kernel.TakeDepartures();
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
          ForOtherOwners(grid, own, ranks.Rank, d.Key,
            [&](int owner)
            {
              if (!std::binary_search(
                    received.begin(), received.end(), std::make_pair(d.Key, owner)))
              {
                outgoing[owner].push_back(d.Key);
                outgoing[owner].push_back(d.Component);
                sending = true;
              }
            });
        }
      });
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
      run.problem = problem;
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
    if (run.rounds >= this->MaximumGrowthRounds)
    {
      // The rest in one step: every component next to another rank's cubes; Resolve keeps
      // those joined to a seed. The departures not sent are among them.
      run.oneStep = true;
      kernel.SetCrossRanks(false);
      kernel.SetBudget(std::numeric_limits<std::int64_t>::max());
      local("grow the components at the shared faces",
        [&]()
        {
          kernel.Continue();
          kernel.GrowBoundary();
        });
      run.problem = problem; // GrowAndExtract agrees on the status
      return true;
    }
    const std::vector<std::vector<vtkIdType>> incoming =
      ranks.ExchangeInOrder(outgoing, own.MeetingOrder(), DepartureTag);
    ++run.rounds;
    local("grow from the neighbours' surface",
      [&]()
      {
        // One label per component of a sending rank, in the order of the ranks.
        std::vector<rgmc::Arrival> arrivals;
        std::map<vtkIdType, int> labelOf; // of the sending rank's components
        int numLabels = 0;
        received.clear();
        for (const int from : own.Neighbours())
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
        kernel.GrowFromArrivals(arrivals, numLabels);
      });
  }
}

//------------------------------------------------------------------------------
bool vtkRGMarchingCubes::StoreSurface(Run& run, vtkPolyData* output)
{
  output->Initialize();
  // The kernel's buffers become the output arrays without copies.
  return run.ranks.Step("store the surface", run.problem,
    [&]()
    {
      const rgmc::Decision& decision = run.decision;
      const std::vector<int>& rootIndex = run.graph.RootIndex;
      rgmc::LocalMesh& mesh = run.kernel->Mesh();
      // Where this rank keeps every component it has (All Components; Seeded, which grows only
      // what the seeds reach unless MaximumGrowthRounds was passed), there is nothing to compact:
      // every point is a corner of a triangle, and Compact would rewrite the same arrays.
      auto kept = [&](int comp) { return decision.FinalId[rootIndex[comp]] >= 0; };
      bool dropsAny = false;
      for (int comp = 0; comp < static_cast<int>(rootIndex.size()) && !dropsAny; ++comp)
      {
        dropsAny = !kept(comp);
      }
      if (dropsAny)
      {
        mesh.Compact(kept);
      }
      const vtkIdType numPoints = mesh.NumberOfPoints();
      const vtkIdType numKept = mesh.NumberOfTriangles();
      for (std::int32_t& comp : mesh.TriangleComponent)
      {
        comp = static_cast<std::int32_t>(decision.FinalId[rootIndex[comp]]);
      }

      vtkNew<vtkPoints> points;
      if (this->OutputPointsPrecision == DOUBLE_PRECISION)
      {
        vtkNew<vtkDoubleArray> xyz;
        xyz->SetNumberOfComponents(3);
        xyz->SetArray(
          mesh.PointsDouble.Release(), 3 * numPoints, 0, vtkAbstractArray::VTK_DATA_ARRAY_FREE);
        points->SetData(xyz);
      }
      else
      {
        vtkNew<vtkFloatArray> xyz;
        xyz->SetNumberOfComponents(3);
        xyz->SetArray(
          mesh.Points.Release(), 3 * numPoints, 0, vtkAbstractArray::VTK_DATA_ARRAY_FREE);
        points->SetData(xyz);
      }
      vtkNew<vtkFloatArray> normals;
      normals->SetName("Normals");
      normals->SetNumberOfComponents(3);
      if (this->ComputeNormals)
      {
        normals->SetArray(
          mesh.Normals.Release(), 3 * numPoints, 0, vtkAbstractArray::VTK_DATA_ARRAY_FREE);
      }
      vtkNew<vtkIdTypeArray> keys;
      keys->SetName("VertexKey");
      static_assert(sizeof(vtkIdType) == sizeof(long long), "vertex keys are 64-bit ids");
      keys->SetArray(reinterpret_cast<vtkIdType*>(mesh.Keys.Release()), numPoints, 0,
        vtkAbstractArray::VTK_DATA_ARRAY_FREE);

      // Triangles: the kernel's 32-bit connectivity, adopted as is; 64-bit when a rank has more
      // than 2^31 - 1 corners, where 32-bit offsets would overflow.
      vtkNew<vtkCellArray> polys;
      if (3 * numKept <= VTK_TYPE_INT32_MAX)
      {
        vtkNew<vtkTypeInt32Array> offsets, connectivity;
        std::int32_t* o = rgmc::Allocate(offsets.Get(), numKept + 1);
        for (vtkIdType n = 0; n <= numKept; ++n)
        {
          o[n] = static_cast<std::int32_t>(3 * n);
        }
        connectivity->SetArray(
          mesh.Triangles.Release(), 3 * numKept, 0, vtkAbstractArray::VTK_DATA_ARRAY_FREE);
        polys->SetData(offsets, connectivity);
      }
      else
      {
        vtkNew<vtkTypeInt64Array> offsets, connectivity;
        vtkTypeInt64* o = rgmc::Allocate(offsets.Get(), numKept + 1);
        for (vtkIdType n = 0; n <= numKept; ++n)
        {
          o[n] = 3 * n;
        }
        std::copy(mesh.Triangles.begin(), mesh.Triangles.begin() + 3 * numKept,
          rgmc::Allocate(connectivity.Get(), 3 * numKept));
        std::free(mesh.Triangles.Release());
        polys->SetData(offsets, connectivity);
      }
      vtkNew<vtkIntArray> componentIds;
      componentIds->SetName("ComponentId");
      static_assert(sizeof(int) == sizeof(std::int32_t), "component ids are 32-bit");
      componentIds->SetArray(reinterpret_cast<int*>(mesh.TriangleComponent.Release()), numKept, 0,
        vtkAbstractArray::VTK_DATA_ARRAY_FREE);
      vtkNew<vtkIntArray> rankIds;
      rankIds->SetName("RankId");
      std::fill_n(rgmc::Allocate(rankIds.Get(), numKept), numKept, run.ranks.Rank);

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
    });
}

//------------------------------------------------------------------------------
void vtkRGMarchingCubes::DescribeSurface(Run& run, vtkPolyData* output)
{
  vtkNew<vtkIdTypeArray> seedKeyArray;
  seedKeyArray->SetName("SeedVertexKeys");
  vtkNew<vtkDoubleArray> seedPointArray;
  seedPointArray->SetName("SeedVertexPoints");
  seedPointArray->SetNumberOfComponents(3);
  for (std::size_t s = 0; s < run.seedKeys.size(); ++s)
  {
    seedKeyArray->InsertNextValue(run.seedKeys[s]);
    seedPointArray->InsertNextTuple(&run.seedPoints[3 * s]);
  }
  vtkNew<vtkIdTypeArray> triangleCount;
  triangleCount->SetName("NumberOfTriangles");
  triangleCount->InsertNextValue(run.decision.Triangles);
  vtkNew<vtkIdTypeArray> componentCount;
  componentCount->SetName("NumberOfComponents");
  componentCount->InsertNextValue(run.decision.Components);
  if (!run.seedKeys.empty()) // empty arrays would hide the field data from ParaView's information
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
    wholeExtent->SetValue(i, run.whole[i]);
  }
  output->GetFieldData()->AddArray(wholeExtent);
  // With WholeExtent, the volume's box in the world: Seam Repair closes a surface cut by it.
  vtkNew<vtkDoubleArray> geometry;
  geometry->SetName("VolumeGeometry");
  geometry->SetNumberOfValues(15);
  std::copy_n(run.geometry.Origin, 3, geometry->GetPointer(0));
  std::copy_n(run.geometry.Spacing, 3, geometry->GetPointer(3));
  std::copy_n(run.geometry.Direction, 9, geometry->GetPointer(6));
  output->GetFieldData()->AddArray(geometry);
  output->GetFieldData()->AddArray(componentCount);

  if (run.decision.Triangles == 0)
  {
    double range[2];
    GlobalRange(run.ranks, run.scalars, range);
    if (run.ranks.Rank == 0)
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
  this->NumberOfGrowthRounds = run.rounds;
  this->GrewInOneStep = run.oneStep;
  this->NumberOfCollectives = static_cast<vtkIdType>(run.ranks.Collectives);
  this->NumberOfMessages = static_cast<vtkIdType>(run.ranks.Messages);
  this->NumberOfValuesSent = static_cast<vtkIdType>(run.ranks.ValuesSent);
  this->NumberOfCubesExamined = run.kernel ? run.kernel->CubesExamined() : 0;
  this->NumberOfFacePointsRead = run.kernel ? run.kernel->PlanePointsRead() : 0;
  this->NumberOfTrianglesMade = run.trianglesMade;
  vtkLogF(TRACE,
    "vtkRGMarchingCubes on rank %d of %d: %d rounds of growth between ranks%s, %lld collectives, "
    "%lld messages sent (%lld values), %lld cubes examined, %lld face points read, %lld "
    "triangles made",
    run.ranks.Rank, run.ranks.Size, run.rounds, run.oneStep ? " then one step" : "",
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

// The VTK adapter of the region-growing kernels: input checks, ownership of cubes across ranks,
// seeds, the distributed resolution of components, and the output polydata.
#include "vtkRGMarchingCubes.h"

#include "rgmcCaseTable.h"
#include "rgmcGrower.h"
#include "vtkRGArrays.h"
#include "vtkRGCollective.h"

#include "vtkArrayDispatch.h"
#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkCommunicator.h"
#include "vtkDataArrayRange.h"
#include "vtkDataSetAttributes.h"
#include "vtkDoubleArray.h"
#include "vtkDummyController.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
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
#include <limits>
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

// ---- the kernel behind one interface, whatever the array type ------------------------------

class AnyGrower
{
public:
  virtual ~AnyGrower() = default;
  virtual rgmc::SeedHit NearestVertex(
    const double idx[3], const double x[3], double radius, double minStep) = 0;
  virtual int GrowFromKey(std::int64_t key) = 0;
  virtual void GrowAll() = 0;
  virtual void GrowBoundary() = 0;
  virtual void Extract() = 0;
  virtual int Root(int c) = 0;
  virtual rgmc::LocalMesh& Mesh() = 0;
  virtual std::vector<rgmc::Component>& Components() = 0;
  virtual std::vector<rgmc::Port>& Ports() = 0;
  virtual std::string Error() const = 0;
  virtual bool Aborted() const = 0;
  virtual bool MissingGhosts() const = 0;
};

template <typename Range>
class GrowerOf : public AnyGrower
{
public:
  GrowerOf(const Range& values, const rgmc::Grid& grid, const rgmc::Ownership& own,
    const rgmc::GrowerParams& params)
    : Values(values)
    , G(Cases(), grid, own, this->Values, params)
  {
  }
  rgmc::SeedHit NearestVertex(
    const double idx[3], const double x[3], double radius, double minStep) override
  {
    return this->G.NearestVertex(idx, x, radius, minStep);
  }
  int GrowFromKey(std::int64_t key) override { return this->G.GrowFromKey(key); }
  void GrowAll() override { this->G.GrowAll(); }
  void GrowBoundary() override { this->G.GrowBoundary(); }
  void Extract() override { this->G.Extract(); }
  int Root(int c) override { return this->G.Root(c); }
  rgmc::LocalMesh& Mesh() override { return this->G.Mesh; }
  std::vector<rgmc::Component>& Components() override { return this->G.Components; }
  std::vector<rgmc::Port>& Ports() override { return this->G.Ports; }
  std::string Error() const override { return this->G.Error(); }
  bool Aborted() const override { return this->G.Aborted(); }
  bool MissingGhosts() const override { return this->G.MissingGhosts(); }

private:
  Range Values;
  rgmc::Grower<Range> G;
};

/// Stands in for the samples on a rank that has none (it owns no cube, so nothing is read).
struct NoValues
{
  float operator[](std::int64_t) const { return 0.0f; }
};

struct MakeGrower
{
  const rgmc::Grid* Grid;
  const rgmc::Ownership* Own;
  const rgmc::GrowerParams* Params;
  std::unique_ptr<AnyGrower> Result;

  template <typename ArrayT>
  void operator()(ArrayT* array)
  {
    using Range = decltype(vtk::DataArrayValueRange<1>(array));
    this->Result.reset(new GrowerOf<Range>(
      vtk::DataArrayValueRange<1>(array), *this->Grid, *this->Own, *this->Params));
  }
};

// ---- the global decision: which components to keep, and their ids --------------------------

struct Decision
{
  std::vector<vtkIdType> FinalId; // per local root component (rootIndex order), -1 = dropped
  vtkIdType Triangles = 0;
  vtkIdType Components = 0;
};

/// Joins the local components of all ranks through their ports and decides, on rank 0, which
/// to keep. Collective; false on every rank (with `problem`) when it failed on one.
bool Resolve(Ranks& ranks, AnyGrower& grower, const rgmc::Grid& grid, const rgmc::Ownership& own,
  int mode, std::vector<int>& rootIndex, Decision& decision, std::string& problem)
{
  std::vector<rgmc::Component>& comps = grower.Components();
  std::vector<int> roots;
  if (!ranks.Step("join the components", problem,
        [&]()
        {
          rootIndex.assign(comps.size(), -1);
          for (int c = 0; c < static_cast<int>(comps.size()); ++c)
          {
            if (grower.Root(c) == c)
            {
              rootIndex[c] = static_cast<int>(roots.size());
              roots.push_back(c);
            }
          }
          for (int c = 0; c < static_cast<int>(comps.size()); ++c)
          {
            rootIndex[c] = rootIndex[grower.Root(c)];
          }
        }))
  {
    return false;
  }

  vtkIdType localCount = static_cast<vtkIdType>(roots.size());
  std::vector<vtkIdType> counts(ranks.Size), offsets(ranks.Size + 1, 0);
  ranks.Check(ranks.C->AllGather(&localCount, counts.data(), 1), "gathering component counts");
  for (int r = 0; r < ranks.Size; ++r)
  {
    offsets[r + 1] = offsets[r] + counts[r];
  }
  const vtkIdType myOffset = offsets[ranks.Rank];

  // Ports go to the ranks that own the other cubes around them.
  std::vector<std::vector<vtkIdType>> outgoing(ranks.Size);
  std::vector<std::pair<std::int64_t, vtkIdType>> mine;
  if (!ranks.Step("list the components' crossings", problem,
        [&]()
        {
          for (const rgmc::Port& port : grower.Ports())
          {
            const vtkIdType gid = myOffset + rootIndex[port.Component];
            mine.emplace_back(port.Key, gid);
            int p[3], axis;
            grid.Decode(port.Key, p, axis);
            int sentTo[8], numSent = 0;
            for (int d = 0; d < 8; ++d)
            {
              const int o[3] = { d & 1, (d >> 1) & 1, (d >> 2) & 1 };
              if (axis >= 0 && o[axis] != 0)
              {
                continue;
              }
              const int i = p[0] - o[0], j = p[1] - o[1], k = p[2] - o[2];
              if (!grid.HasCell(i, j, k) || own.Owns(i, j, k))
              {
                continue;
              }
              const int owner = own.Owner(i, j, k);
              if (owner < 0 || owner == ranks.Rank || std::count(sentTo, sentTo + numSent, owner))
              {
                continue;
              }
              sentTo[numSent++] = owner;
              outgoing[owner].push_back(port.Key);
              outgoing[owner].push_back(gid);
            }
          }
        }))
  {
    return false;
  }
  std::vector<bool> partners(ranks.Size, false);
  const rgmc::CellBox near = own.Mine().Grown(1);
  for (int r = 0; r < ranks.Size; ++r)
  {
    partners[r] = r != ranks.Rank && !own.Mine().Empty() && !own.BoxOf(r).Empty() &&
      !near.Intersect(own.BoxOf(r)).Empty();
  }
  const std::vector<std::vector<vtkIdType>> incoming = ranks.Exchange(outgoing, partners, PortTag);

  // Edges of the component graph: my component and theirs share a vertex.
  const vtkIdType total = offsets[ranks.Size];
  std::vector<vtkIdType> info, flatEdges, allInfo;
  std::vector<vtkIdType> infoLengths(ranks.Size), infoOffsets(ranks.Size);
  if (!ranks.Step("join the components", problem,
        [&]()
        {
          std::sort(mine.begin(), mine.end());
          std::vector<std::pair<vtkIdType, vtkIdType>> edges;
          for (const std::vector<vtkIdType>& list : incoming)
          {
            for (std::size_t n = 0; n + 1 < list.size(); n += 2)
            {
              auto it = std::lower_bound(mine.begin(), mine.end(),
                std::make_pair(
                  static_cast<std::int64_t>(list[n]), std::numeric_limits<vtkIdType>::min()));
              if (it != mine.end() && it->first == list[n])
              {
                edges.emplace_back(
                  std::min(it->second, list[n + 1]), std::max(it->second, list[n + 1]));
              }
            }
          }
          std::sort(edges.begin(), edges.end());
          edges.erase(std::unique(edges.begin(), edges.end()), edges.end());

          // Gather the small component graph on rank 0.
          info.reserve(3 * roots.size());
          for (int c : roots)
          {
            info.push_back(comps[c].Triangles);
            info.push_back(comps[c].MinKey);
            info.push_back(comps[c].Seeded ? 1 : 0);
          }
          for (const auto& e : edges)
          {
            flatEdges.push_back(e.first);
            flatEdges.push_back(e.second);
          }
          for (int r = 0; r < ranks.Size; ++r)
          {
            infoLengths[r] = 3 * counts[r];
            infoOffsets[r] = 3 * offsets[r];
          }
          allInfo.resize(ranks.Rank == 0 ? 3 * total + 1 : 1);
        }))
  {
    return false;
  }
  ranks.Check(ranks.C->GatherV(info.data(), allInfo.data(), static_cast<vtkIdType>(info.size()),
                infoLengths.data(), infoOffsets.data(), 0),
    "gathering the components");
  vtkIdType edgeLength = static_cast<vtkIdType>(flatEdges.size());
  std::vector<vtkIdType> edgeLengths(ranks.Size), edgeOffsets(ranks.Size + 1, 0);
  // Every rank learns every length: VTK 9.5's GatherV reads the lengths and offsets on all ranks.
  ranks.Check(ranks.C->AllGather(&edgeLength, edgeLengths.data(), 1), "gathering edge counts");
  for (int r = 0; r < ranks.Size; ++r)
  {
    edgeOffsets[r + 1] = edgeOffsets[r] + edgeLengths[r];
  }
  std::vector<vtkIdType> allEdges, finalIds;
  if (!ranks.Step("join the components", problem,
        [&]() { allEdges.resize(ranks.Rank == 0 ? edgeOffsets[ranks.Size] + 1 : 1); }))
  {
    return false;
  }
  ranks.Check(ranks.C->GatherV(flatEdges.data(), allEdges.data(), edgeLength, edgeLengths.data(),
                edgeOffsets.data(), 0),
    "gathering the component graph");

  vtkIdType totals[2] = { 0, 0 };
  if (!ranks.Step("decide which components to keep", problem,
        [&]()
        {
          finalIds.assign(ranks.Rank == 0 ? total + 1 : 1, -1);
          if (ranks.Rank == 0)
          {
            std::vector<vtkIdType> parent(total);
            std::iota(parent.begin(), parent.end(), 0);
            auto find = [&parent](vtkIdType x)
            {
              while (parent[x] != x)
              {
                x = parent[x] = parent[parent[x]];
              }
              return x;
            };
            for (vtkIdType n = 0; n + 1 < edgeOffsets[ranks.Size]; n += 2)
            {
              const vtkIdType a = find(allEdges[n]), b = find(allEdges[n + 1]);
              if (a != b)
              {
                parent[std::max(a, b)] = std::min(a, b);
              }
            }
            struct Class
            {
              vtkIdType Triangles = 0;
              vtkIdType MinKey = std::numeric_limits<vtkIdType>::max();
              bool Seeded = false;
            };
            std::vector<Class> classes(total);
            for (vtkIdType c = 0; c < total; ++c)
            {
              Class& k = classes[find(c)];
              k.Triangles += allInfo[3 * c];
              k.MinKey = std::min(k.MinKey, allInfo[3 * c + 1]);
              k.Seeded = k.Seeded || allInfo[3 * c + 2] != 0;
            }
            std::vector<vtkIdType> selected;
            vtkIdType largest = -1;
            for (vtkIdType c = 0; c < total; ++c)
            {
              if (find(c) != c || classes[c].Triangles == 0)
              {
                continue;
              }
              if (mode == vtkRGMarchingCubes::ALL_COMPONENTS ||
                (mode == vtkRGMarchingCubes::SEEDED && classes[c].Seeded))
              {
                selected.push_back(c);
              }
              if (largest < 0 || classes[c].Triangles > classes[largest].Triangles ||
                (classes[c].Triangles == classes[largest].Triangles &&
                  classes[c].MinKey < classes[largest].MinKey))
              {
                largest = c;
              }
            }
            if (mode == vtkRGMarchingCubes::LARGEST_COMPONENT && largest >= 0)
            {
              selected.push_back(largest);
            }
            std::sort(selected.begin(), selected.end(),
              [&classes](vtkIdType a, vtkIdType b)
              { return classes[a].MinKey < classes[b].MinKey; });
            std::vector<vtkIdType> idOfClass(total, -1);
            for (std::size_t n = 0; n < selected.size(); ++n)
            {
              idOfClass[selected[n]] = static_cast<vtkIdType>(n);
              totals[0] += classes[selected[n]].Triangles;
            }
            totals[1] = static_cast<vtkIdType>(selected.size());
            for (vtkIdType c = 0; c < total; ++c)
            {
              finalIds[c] = idOfClass[find(c)];
            }
          }
          decision.FinalId.assign(static_cast<std::size_t>(localCount) + 1, -1);
        }))
  {
    return false;
  }
  ranks.Check(ranks.C->ScatterV(finalIds.data(), decision.FinalId.data(), counts.data(),
                offsets.data(), localCount, 0),
    "scattering the decision");
  decision.FinalId.resize(static_cast<std::size_t>(localCount));
  ranks.Check(ranks.C->Broadcast(totals, 2, 0), "broadcasting the totals");
  decision.Triangles = totals[0];
  decision.Components = totals[1];
  // Component ids are 32-bit in the output (ComponentId, like vtkConnectivityFilter's RegionId).
  if (decision.Components > VTK_INT_MAX)
  {
    problem = "the surface has " + std::to_string(decision.Components) +
      " components, more than ComponentId can number (" + std::to_string(VTK_INT_MAX) + ")";
  }
  return ranks.Agree(problem.empty(), problem);
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
  ranks.Check(ranks.C->AllReduce(&lo, &range[0], 1, vtkCommunicator::MIN_OP), "a reduction");
  ranks.Check(ranks.C->AllReduce(&hi, &range[1], 1, vtkCommunicator::MAX_OP), "a reduction");
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
int vtkRGMarchingCubes::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkImageData* input = vtkImageData::GetData(inputVector[0]);
  vtkPolyData* output = vtkPolyData::GetData(outputVector);
  vtkInformation* inInfo = inputVector[0]->GetInformationObject(0);
  // A new run: an abort of an earlier run does not carry over (VTK 9.2 cleared the flag itself;
  // VTK 9.3 and later keep it, so an aborted filter would stay empty). Set directly, as
  // SetAbortExecute would mark the filter modified and make it run again.
  this->AbortExecute = 0;

  vtkNew<vtkDummyController> single;
  Ranks ranks(this->Controller ? this->Controller : single.Get());

  // PASS 0: check the input on every rank and agree on the verdict.
  std::string problem;
  const bool hasPoints = input && input->GetNumberOfPoints() > 0;
  // The whole extent, agreed by all ranks: the union of what each rank was told and what it
  // holds (pieces handed over without a pipeline know only their own extent).
  int whole[6] = { 0, -1, 0, -1, 0, -1 };
  {
    int told[6] = { 0, -1, 0, -1, 0, -1 }, held[6] = { 0, -1, 0, -1, 0, -1 };
    if (inInfo->Has(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT()))
    {
      inInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), told);
    }
    if (hasPoints)
    {
      input->GetExtent(held);
    }
    int lows[3], highs[3];
    for (int a = 0; a < 3; ++a)
    {
      lows[a] = VTK_INT_MAX;
      highs[a] = VTK_INT_MIN;
      for (const int* e : { told, held })
      {
        if (e[1] >= e[0] && e[3] >= e[2] && e[5] >= e[4])
        {
          lows[a] = std::min(lows[a], e[2 * a]);
          highs[a] = std::max(highs[a], e[2 * a + 1]);
        }
      }
    }
    int agreedLows[3], agreedHighs[3];
    ranks.Check(ranks.C->AllReduce(lows, agreedLows, 3, vtkCommunicator::MIN_OP), "a reduction");
    ranks.Check(ranks.C->AllReduce(highs, agreedHighs, 3, vtkCommunicator::MAX_OP), "a reduction");
    if (agreedLows[0] <= agreedHighs[0])
    {
      for (int a = 0; a < 3; ++a)
      {
        whole[2 * a] = agreedLows[a];
        whole[2 * a + 1] = agreedHighs[a];
      }
    }
  }
  vtkDataArray* scalars = nullptr;
  {
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
    else if (hasPoints)
    {
      int association = vtkDataObject::FIELD_ASSOCIATION_POINTS;
      scalars = this->GetInputArrayToProcess(0, inputVector, association);
      vtkInformation* arrayInfo = this->GetInputArrayInformation(0);
      const char* name = arrayInfo && arrayInfo->Has(vtkDataObject::FIELD_NAME())
        ? arrayInfo->Get(vtkDataObject::FIELD_NAME())
        : nullptr;
      if (scalars && association != vtkDataObject::FIELD_ASSOCIATION_POINTS)
      {
        msg << "the array '" << (scalars->GetName() ? scalars->GetName() : "")
            << "' is cell data; contouring needs point data (apply Cell Data to Point Data "
               "first)";
        scalars = nullptr;
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
        scalars = nullptr;
      }
    }
    problem = msg.str();
  }
  if (!ranks.Agree(problem.empty(), problem))
  {
    vtkErrorMacro(<< "Cannot extract a surface: " << problem << ".");
    return 0;
  }
  {
    // An empty image on every rank (each rank's piece is empty).
    std::string empty = "the input image has no points";
    if (!ranks.Agree(!ranks.Any(hasPoints) ? false : true, empty))
    {
      vtkErrorMacro(<< "Cannot extract a surface: " << empty << ".");
      return 0;
    }
  }
  this->UpdateProgress(0.05);

  // Geometry, from the lowest rank that has data.
  Geometry geom;
  {
    int mine = hasPoints ? ranks.Rank : ranks.Size, source = ranks.Size;
    ranks.Check(ranks.C->AllReduce(&mine, &source, 1, vtkCommunicator::MIN_OP), "a reduction");
    double g[15];
    if (ranks.Rank == source)
    {
      input->GetOrigin(g);
      input->GetSpacing(g + 3);
      const double* d = input->GetDirectionMatrix()->GetData();
      std::copy_n(d, 9, g + 6);
    }
    ranks.Check(ranks.C->Broadcast(g, 15, source), "a broadcast");
    std::copy_n(g, 3, geom.Origin);
    std::copy_n(g + 3, 3, geom.Spacing);
    std::copy_n(g + 6, 9, geom.Direction);
  }

  // PASS 1: ownership of cubes.
  int local[6] = { 0, -1, 0, -1, 0, -1 };
  rgmc::CellBox myCells;
  if (hasPoints && scalars)
  {
    input->GetExtent(local);
    myCells = OwnedCells(input);
  }
  // Each rank's owned cells (from its ghost array) and all its cells (its extent).
  rgmc::CellBox allMine;
  for (int a = 0; a < 3; ++a)
  {
    allMine.Lo[a] = local[2 * a];
    allMine.Hi[a] = local[2 * a + 1] - 1;
  }
  std::vector<int> boxes(12 * ranks.Size);
  {
    const int mine[12] = { myCells.Lo[0], myCells.Lo[1], myCells.Lo[2], myCells.Hi[0],
      myCells.Hi[1], myCells.Hi[2], allMine.Lo[0], allMine.Lo[1], allMine.Lo[2], allMine.Hi[0],
      allMine.Hi[1], allMine.Hi[2] };
    ranks.Check(ranks.C->AllGather(mine, boxes.data(), 12), "a gather");
  }
  std::vector<rgmc::CellBox> cellBoxes(ranks.Size), extentBoxes(ranks.Size);
  for (int r = 0; r < ranks.Size; ++r)
  {
    for (int a = 0; a < 3; ++a)
    {
      cellBoxes[r].Lo[a] = boxes[12 * r + a];
      cellBoxes[r].Hi[a] = boxes[12 * r + 3 + a];
      extentBoxes[r].Lo[a] = boxes[12 * r + 6 + a];
      extentBoxes[r].Hi[a] = boxes[12 * r + 9 + a];
    }
  }
  // Ghost markings that leave cells of a piece owned by no rank (a reader whose ghost arrays do
  // not match its pieces) would silently lose the surface there. Then own by the extents: first
  // without the one ghost layer asked for at faces inside the volume (the pipeline's
  // convention), else whole, the lowest rank holding a cell owning it.
  if (ranks.Any(!rgmc::Covers(cellBoxes, allMine)))
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
    const bool trimmedCovers = !ranks.Any(!rgmc::Covers(trimmed, allMine));
    cellBoxes = trimmedCovers ? trimmed : extentBoxes;
    if (ranks.Rank == 0)
    {
      vtkWarningMacro(<< "The input's ghost arrays mark cells that no rank owns (they do not match "
                         "the pieces); cells are owned by the pieces' extents instead"
                      << (trimmedCovers ? " less one ghost layer."
                                        : ". Normals at the partition seams may be one-sided."));
    }
  }
  const rgmc::Ownership own(cellBoxes, ranks.Rank);
  const rgmc::Grid grid(whole, local);

  rgmc::GrowerParams params;
  params.Isovalue = this->Isovalue;
  params.ComputeNormals = this->ComputeNormals;
  params.DoublePoints = this->OutputPointsPrecision == DOUBLE_PRECISION;
  geom.IndexToWorldMatrix(params.IndexToWorld);
  geom.NormalMatrix(params.NormalToWorld);
  params.Progress = [this](double fraction)
  {
    this->UpdateProgress(0.1 + 0.7 * fraction);
    return this->CheckAbort();
  };
  MakeGrower make{ &grid, &own, &params, nullptr };
  if (scalars)
  {
    if (!vtkArrayDispatch::Dispatch::Execute(scalars, make))
    {
      make(scalars); // any other array layout, through the generic API
    }
  }
  else
  {
    make.Result.reset(new GrowerOf<NoValues>(NoValues(), grid, own, params));
  }
  AnyGrower& grower = *make.Result;

  // PASS 2: seeds, each to its nearest surface vertex over all ranks.
  const int numSeeds = this->GetNumberOfSeedPoints();
  std::vector<vtkIdType> seedKeys;
  std::vector<double> seedPoints;
  if (this->ExtractionMode == SEEDED)
  {
    std::ostringstream msg;
    double bounds[6];
    for (int a = 0; a < 3; ++a)
    {
      bounds[2 * a] = VTK_DOUBLE_MAX;
      bounds[2 * a + 1] = VTK_DOUBLE_MIN;
    }
    double m[3][4];
    geom.IndexToWorldMatrix(m);
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
    std::vector<double> seedIndex(3 * numSeeds);
    for (int s = 0; s < numSeeds && msg.str().empty(); ++s)
    {
      double* q = &seedIndex[3 * s];
      geom.WorldToIndex(&this->SeedPoints[3 * s], q);
      for (int a = 0; a < 3; ++a)
      {
        const double tolerance = 1e-6 * (1.0 + std::fabs(whole[2 * a + 1]));
        if (!(q[a] >= whole[2 * a] - tolerance && q[a] <= whole[2 * a + 1] + tolerance))
        {
          msg << "seed point " << s << " (" << this->SeedPoints[3 * s] << ", "
              << this->SeedPoints[3 * s + 1] << ", " << this->SeedPoints[3 * s + 2]
              << ") lies outside the volume, whose bounds are [" << bounds[0] << ", " << bounds[1]
              << "] x [" << bounds[2] << ", " << bounds[3] << "] x [" << bounds[4] << ", "
              << bounds[5] << "]";
          break;
        }
      }
    }
    std::string outside = msg.str();
    if (!ranks.Agree(outside.empty(), outside))
    {
      vtkWarningMacro(<< "No surface extracted: " << outside << ".");
      return 1;
    }

    std::vector<double> d2(numSeeds), bestD2(numSeeds);
    std::vector<rgmc::SeedHit> hits(numSeeds);
    const double minStep = geom.MinStep();
    for (int s = 0; s < numSeeds; ++s)
    {
      hits[s] = grower.NearestVertex(
        &seedIndex[3 * s], &this->SeedPoints[3 * s], this->SeedSearchRadius, minStep);
      d2[s] = hits[s].Distance2;
    }
    std::string error = grower.Error();
    if (!ranks.Agree(error.empty(), error))
    {
      vtkErrorMacro(<< "Cannot extract a surface: " << error << ".");
      return 0;
    }
    ranks.Check(ranks.C->AllReduce(d2.data(), bestD2.data(), numSeeds, vtkCommunicator::MIN_OP),
      "a reduction");
    std::vector<vtkIdType> keys(numSeeds), bestKeys(numSeeds);
    for (int s = 0; s < numSeeds; ++s)
    {
      keys[s] = hits[s].Found && hits[s].Distance2 == bestD2[s]
        ? hits[s].Key
        : std::numeric_limits<vtkIdType>::max();
    }
    ranks.Check(ranks.C->AllReduce(keys.data(), bestKeys.data(), numSeeds, vtkCommunicator::MIN_OP),
      "a reduction");
    std::vector<double> points(3 * numSeeds), bestPoints(3 * numSeeds);
    for (int s = 0; s < numSeeds; ++s)
    {
      for (int a = 0; a < 3; ++a)
      {
        points[3 * s + a] =
          hits[s].Found && hits[s].Key == bestKeys[s] ? hits[s].Point[a] : VTK_DOUBLE_MAX;
      }
    }
    ranks.Check(
      ranks.C->AllReduce(points.data(), bestPoints.data(), 3 * numSeeds, vtkCommunicator::MIN_OP),
      "a reduction");
    for (int s = 0; s < numSeeds; ++s)
    {
      if (bestKeys[s] == std::numeric_limits<vtkIdType>::max())
      {
        double range[2];
        GlobalRange(ranks, scalars, range);
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
        return 1;
      }
    }
    seedKeys = bestKeys;
    seedPoints = bestPoints;
  }
  this->UpdateProgress(0.1);

  // PASS 3: local growth, on every rank at once.
  std::string outOfMemory;
  try
  {
    if (this->ExtractionMode == SEEDED)
    {
      for (vtkIdType key : seedKeys)
      {
        grower.GrowFromKey(key); // seeded components; before the boundary growth
      }
      if (ranks.Size > 1)
      {
        grower.GrowBoundary();
      }
    }
    else
    {
      grower.GrowAll();
    }
    grower.Extract();
  }
  catch (const std::length_error& tooMany)
  {
    outOfMemory = std::string(tooMany.what()) + " on rank " + std::to_string(ranks.Rank) +
      ": run on more ranks";
  }
  catch (const std::bad_alloc&)
  {
    outOfMemory = "not enough memory to grow and extract the surface on rank " +
      std::to_string(ranks.Rank) + " (" + std::to_string(grower.Mesh().NumberOfTriangles()) +
      " triangles so far)";
  }
  {
    std::string error = outOfMemory.empty() ? grower.Error() : outOfMemory;
    if (!ranks.Agree(error.empty(), error))
    {
      vtkErrorMacro(<< "Cannot extract a surface: " << error << ".");
      return 0;
    }
    if (ranks.Any(grower.Aborted()))
    {
      output->Initialize();
      return 1;
    }
    if (ranks.Any(grower.MissingGhosts()) && ranks.Rank == 0)
    {
      vtkWarningMacro(<< "The input pieces have no ghost layer: normals at the partition seams "
                         "are one-sided there and differ from a 1-rank run.");
    }
  }
  this->UpdateProgress(0.8);

  // PASS 4: join components across ranks; decide what to keep.
  std::vector<int> rootIndex;
  Decision decision;
  if (!Resolve(ranks, grower, grid, own, this->ExtractionMode, rootIndex, decision, problem))
  {
    vtkErrorMacro(<< "Cannot extract a surface: " << problem << ".");
    output->Initialize();
    return 0;
  }
  this->UpdateProgress(0.9);

  // PASS 5: the output piece. The kernel's buffers become the output arrays without copies.
  output->Initialize();
  if (!ranks.Step("store the surface", problem,
        [&]()
        {
          rgmc::LocalMesh& mesh = grower.Mesh();
          mesh.Compact([&](int comp) { return decision.FinalId[rootIndex[comp]] >= 0; });
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
          componentIds->SetArray(reinterpret_cast<int*>(mesh.TriangleComponent.Release()), numKept,
            0, vtkAbstractArray::VTK_DATA_ARRAY_FREE);
          vtkNew<vtkIntArray> rankIds;
          rankIds->SetName("RankId");
          std::fill_n(rgmc::Allocate(rankIds.Get(), numKept), numKept, ranks.Rank);

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
        }))
  {
    vtkErrorMacro(<< "Cannot extract a surface: " << problem << ".");
    output->Initialize();
    return 0;
  }

  vtkNew<vtkIdTypeArray> seedKeyArray;
  seedKeyArray->SetName("SeedVertexKeys");
  vtkNew<vtkDoubleArray> seedPointArray;
  seedPointArray->SetName("SeedVertexPoints");
  seedPointArray->SetNumberOfComponents(3);
  for (std::size_t s = 0; s < seedKeys.size(); ++s)
  {
    seedKeyArray->InsertNextValue(seedKeys[s]);
    seedPointArray->InsertNextTuple(&seedPoints[3 * s]);
  }
  vtkNew<vtkIdTypeArray> triangleCount;
  triangleCount->SetName("NumberOfTriangles");
  triangleCount->InsertNextValue(decision.Triangles);
  vtkNew<vtkIdTypeArray> componentCount;
  componentCount->SetName("NumberOfComponents");
  componentCount->InsertNextValue(decision.Components);
  if (!seedKeys.empty()) // empty arrays would hide the field data from ParaView's information
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
    wholeExtent->SetValue(i, whole[i]);
  }
  output->GetFieldData()->AddArray(wholeExtent);
  output->GetFieldData()->AddArray(componentCount);

  if (decision.Triangles == 0 && ranks.Rank == 0)
  {
    double range[2];
    GlobalRange(ranks, scalars, range);
    vtkWarningMacro(<< "No surface extracted: the isovalue " << this->Isovalue
                    << " gives no triangles (data range [" << range[0] << ", " << range[1]
                    << "]).");
  }
  else if (decision.Triangles == 0)
  {
    double range[2];
    GlobalRange(ranks, scalars, range);
  }
  this->UpdateProgress(1.0);
  return 1;
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
  os << indent << "Controller: " << this->Controller << "\n";
}

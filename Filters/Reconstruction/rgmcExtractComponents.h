// The component graph of vtkRGMarchingCubes across ranks: which neighbours a vertex's ports go
// to, this rank's part of the graph, and its gathering on rank 0, which decides which components
// to keep and numbers them.
#ifndef rgmcExtractComponents_h
#define rgmcExtractComponents_h

#include "rgmcComponentGraph.h"
#include "rgmcSurfaceKernel.h"
#include "vtkRGCollective.h"
#include "vtkRGOutOfMemory.h"

#include "vtkCommunicator.h"
#include "vtkDataArray.h"

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

namespace rgmc
{
namespace extract
{

// ---- routing between neighbours ------------------------------------------------------------

/// Calls `to(owner)` once for each other rank that owns a cube around vertex `key` (one of this
/// rank's vertices: such cubes touch this rank's, so their owners are among its neighbours).
template <typename To>
void ForOtherOwners(
  const rgmc::Grid& grid, const rgmc::Ownership& ownership, int rank, std::int64_t key, To&& to)
{
  int p[3], axis;
  grid.Decode(key, p, axis);
  int sentTo[8], numSent = 0;
  rgmc::ForCubesAround(p, axis,
    [&](int i, int j, int k, int)
    {
      if (!grid.HasCell(i, j, k) || ownership.Owns(i, j, k))
      {
        return;
      }
      const int owner = ownership.OwnerNear(i, j, k);
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
  void Prepare(rgmc::Kernel& kernel, const rgmc::Grid& grid, const rgmc::Ownership& ownership,
    int rank, int numRanks)
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
      ForOtherOwners(grid, ownership, rank, port.Key,
        [&](int owner)
        {
          this->PortsTo[owner].push_back(port.Key);
          this->PortsTo[owner].push_back(root);
        });
    }
    std::sort(this->Ports.begin(), this->Ports.end());
  }
};

/// Gathers the component graph (each rank's part, sizes known to all from `roots` and
/// `edges`) on rank 0, which decides, and gives each rank its decision. Collective; false (with
/// `problem`) when it failed, on every rank alike (rank 0's verdict comes with the decision),
/// but not yet agreed: the caller's next agreement does that.
inline bool Resolve(Ranks& ranks, rgmc::Keep mode, const rgmc::ComponentGraph& graph,
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
inline void GlobalRange(Ranks& ranks, vtkDataArray* scalars, double range[2])
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

} // namespace extract
} // namespace rgmc

#endif

// Region-growing marching cubes on one piece of a volume, without VTK: the seed search, the
// growth and the extraction over one piece's samples, as the VTK layer (vtkRGMarchingCubes)
// and the kernel's unit tests drive them.
//
// Layers, each file including only those below it:
//   rgmcSurfaceKernel.h   this file: the three passes over one piece
//   rgmcSeedSearch.h, rgmcGrowth.h, rgmcExtraction.h
//   rgmcCubeSurface.h     samples, vertex geometry, a cube's surface nodes, components
//   rgmcCaseTable.h, rgmcGrid.h, rgmcUnionFind.h, rgmcKeyMap.h, rgmcBuffer.h
#ifndef rgmcSurfaceKernel_h
#define rgmcSurfaceKernel_h

#include "rgmcExtraction.h"
#include "rgmcGrowth.h"
#include "rgmcSeedSearch.h"

#include <string>
#include <vector>

namespace rgmc
{

template <typename Values>
class SurfaceKernel
{
public:
  SurfaceKernel(const CaseTable& table, const Grid& grid, const Ownership& ownership,
    const Values& values, const SurfaceOptions& options)
    : Volume(table, grid, ownership, values, options)
    , Growth(this->Volume, this->Components)
    , Extraction(this->Volume, this->Components)
  {
  }

  /// See rgmc::NearestVertex.
  SeedHit NearestVertex(
    const double seedIndex[3], const double seedWorld[3], double radius, double minStep)
  {
    return rgmc::NearestVertex(this->Volume, seedIndex, seedWorld, radius, minStep);
  }
  /// See SurfaceGrowth.
  int GrowFromKey(std::int64_t key) { return this->Growth.GrowFromKey(key); }
  void GrowAll() { this->Growth.GrowAll(); }
  void GrowBoundary() { this->Growth.GrowBoundary(); }
  void SetCrossRanks(bool cross) { this->Growth.CrossRanks = cross; }
  void SetBudget(std::int64_t budget) { this->Growth.SetBudget(budget); }
  bool Busy() const { return this->Growth.Busy(); }
  void Continue() { this->Growth.Continue(); }
  std::vector<Departure> TakeDepartures() { return this->Growth.TakeDepartures(); }
  void GrowFromArrivals(const std::vector<Arrival>& arrivals, int numLabels)
  {
    this->Growth.GrowFromArrivals(arrivals, numLabels);
  }
  std::int64_t CubesExamined() const { return this->Growth.CubesExamined(); }
  std::int64_t PlanePointsRead() const { return this->Growth.PlanePointsRead(); }
  /// Makes the triangles of every node found (SurfaceExtraction).
  void Extract() { this->Extraction.Extract(this->Growth.Nodes()); }

  LocalMesh& Mesh() { return this->Extraction.Mesh; }
  std::vector<Port>& Ports() { return this->Extraction.Ports; }
  ComponentSet Components;
  std::int64_t Joins() const { return this->Extraction.Joins(); }
  std::int64_t NumberOfNodes() { return static_cast<std::int64_t>(this->Growth.Nodes().size()); }

  std::string Error() const { return this->Volume.Error(); }
  bool Aborted() const { return this->Volume.Aborted(); }
  bool MissingGhosts() const { return this->Volume.MissingGhosts(); }

private:
  SampledVolume<Values> Volume;
  SurfaceGrowth<Values> Growth;
  SurfaceExtraction<Values> Extraction;
};

} // namespace rgmc

#endif

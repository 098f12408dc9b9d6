// Region-growing marching cubes on one piece of a volume, without VTK: the seed search, the
// growth and the extraction over one piece's samples, as the VTK layer (vtkRGMarchingCubes)
// and the kernel's unit tests drive them.
//
// Layers, each file including only those below it:
//   rgmcSurfaceKernel.h   this file: the kernel's interface (Kernel), and the three passes over
//                         one piece behind it (SurfaceKernel)
//   rgmcSeedSearch.h, rgmcGrowth.h (growth's scheduler: tiles, rounds, threads),
//   rgmcExtraction.h
//   rgmcNodeVisits.h      growth's per-node step of the breadth-first search
//   rgmcSampledVolume.h   one piece's samples, the passes' shared state, vertex geometry
//   rgmcCubeSurface.h     options, a cube's surface nodes, the cubes around a vertex, components
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

/// What the VTK layer drives, whatever the type of the samples: declared once, implemented by
/// SurfaceKernel.
class Kernel
{
public:
  virtual ~Kernel() = default;

  /// See rgmc::NearestVertex.
  virtual SeedHit NearestVertex(
    const double seedIndex[3], const double seedWorld[3], double radius, double minStep) = 0;
  /// See SurfaceGrowth.
  virtual int GrowFromKey(std::int64_t key) = 0;
  virtual void GrowAll() = 0;
  virtual void GrowBoundary() = 0;
  virtual void SetCrossRanks(bool cross) = 0;
  virtual void SetBudget(std::int64_t budget) = 0;
  virtual bool Busy() const = 0;
  virtual void Continue() = 0;
  virtual std::vector<Departure> TakeDepartures() = 0;
  virtual void GrowFromArrivals(const std::vector<Arrival>& arrivals, int numLabels) = 0;
  virtual std::int64_t CubesExamined() const = 0;
  virtual std::int64_t PlanePointsRead() const = 0;
  /// Makes the triangles of every node found (SurfaceExtraction).
  virtual void Extract() = 0;

  virtual LocalMesh& Mesh() = 0;
  virtual std::vector<Port>& Ports() = 0;
  virtual ComponentSet& Components() = 0;

  virtual std::string Error() const = 0;
  virtual bool Aborted() const = 0;
  virtual bool MissingGhosts() const = 0;
};

template <typename Values>
class SurfaceKernel : public Kernel
{
public:
  SurfaceKernel(const CaseTable& table, const Grid& grid, const Ownership& ownership,
    const Values& values, const SurfaceOptions& options)
    : Volume(table, grid, ownership, values, options)
    , Growth(this->Volume, this->Found)
    , Extraction(this->Volume, this->Found)
  {
  }

  SeedHit NearestVertex(
    const double seedIndex[3], const double seedWorld[3], double radius, double minStep) override
  {
    return rgmc::NearestVertex(this->Volume, seedIndex, seedWorld, radius, minStep);
  }
  int GrowFromKey(std::int64_t key) override { return this->Growth.GrowFromKey(key); }
  void GrowAll() override { this->Growth.GrowAll(); }
  void GrowBoundary() override { this->Growth.GrowBoundary(); }
  void SetCrossRanks(bool cross) override { this->Growth.CrossRanks = cross; }
  void SetBudget(std::int64_t budget) override { this->Growth.SetBudget(budget); }
  bool Busy() const override { return this->Growth.Busy(); }
  void Continue() override { this->Growth.Continue(); }
  std::vector<Departure> TakeDepartures() override { return this->Growth.TakeDepartures(); }
  void GrowFromArrivals(const std::vector<Arrival>& arrivals, int numLabels) override
  {
    this->Growth.GrowFromArrivals(arrivals, numLabels);
  }
  std::int64_t CubesExamined() const override { return this->Growth.CubesExamined(); }
  std::int64_t PlanePointsRead() const override { return this->Growth.PlanePointsRead(); }
  void Extract() override { this->Extraction.Extract(this->Growth.Nodes()); }

  LocalMesh& Mesh() override { return this->Extraction.Mesh; }
  std::vector<Port>& Ports() override { return this->Extraction.Ports; }
  ComponentSet& Components() override { return this->Found; }
  std::int64_t Joins() const { return this->Extraction.Joins(); }
  std::int64_t CrossingsPosted() const { return this->Growth.CrossingsPosted(); }
  std::int64_t CrossingsRead() const { return this->Growth.CrossingsRead(); }
  std::int64_t TilesReached() const { return this->Growth.TilesReached(); }

  std::string Error() const override { return this->Volume.Error(); }
  bool Aborted() const override { return this->Volume.Aborted(); }
  bool MissingGhosts() const override { return this->Volume.MissingGhosts(); }

private:
  ComponentSet Found; // the components of the surface found (before the passes that fill it)
  SampledVolume<Values> Volume;
  SurfaceGrowth<Values> Growth;
  SurfaceExtraction<Values> Extraction;
};

} // namespace rgmc

#endif

// The output piece of vtkRGMarchingCubes: the kept components, numbered with their final ids,
// and the kernel's buffers adopted as the output's arrays without copies.
#ifndef rgmcExtractOutput_h
#define rgmcExtractOutput_h

#include "rgmcComponentGraph.h"
#include "rgmcSurfaceKernel.h"
#include "vtkRGArrays.h"
#include "vtkRGParallel.h"

#include "vtkCellArray.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkNew.h"
#include "vtkPoints.h"
#include "vtkSmartPointer.h"
#include "vtkTypeInt32Array.h"
#include "vtkTypeInt64Array.h"

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <vector>

namespace rgmc
{
namespace extract
{

/// Values per task of the output's fills, on threads that so first touch their pages.
constexpr vtkIdType FillGrain = 65536;

/// offsets[n] = 3 n for n in [0, numTriangles].
template <typename T>
void FillOffsets(T* offsets, vtkIdType numTriangles)
{
  rgmc::ParallelFor(numTriangles + 1, FillGrain,
    [offsets](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType n = begin; n < end; ++n)
      {
        offsets[n] = static_cast<T>(3 * n);
      }
    });
}

/// value in every one of n places, on threads.
template <typename T>
void Fill(T* values, vtkIdType n, T value)
{
  rgmc::ParallelFor(n, FillGrain,
    [values, value](vtkIdType begin, vtkIdType end)
    { std::fill(values + begin, values + end, value); });
}

/// Drops the triangles of the components not kept and numbers the rest with their final ids.
/// Where this rank keeps every component it has (All Components; Seeded, which grows only what
/// the seeds reach unless MaximumGrowthRounds was passed), there is nothing to compact: every
/// point is a corner of a triangle, and Compact would rewrite the same arrays.
inline void KeepDecidedComponents(
  const rgmc::Decision& decision, const std::vector<int>& rootIndex, rgmc::LocalMesh& mesh)
{
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
  std::int32_t* comps = mesh.TriangleComponent.data();
  rgmc::ParallelFor(static_cast<vtkIdType>(mesh.TriangleComponent.size()), FillGrain,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType t = begin; t < end; ++t)
      {
        comps[t] = static_cast<std::int32_t>(decision.FinalId[rootIndex[comps[t]]]);
      }
    });
}

inline vtkSmartPointer<vtkPoints> AdoptPoints(
  rgmc::LocalMesh& mesh, vtkIdType numPoints, bool doublePoints)
{
  vtkNew<vtkPoints> points;
  if (doublePoints)
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
    xyz->SetArray(mesh.Points.Release(), 3 * numPoints, 0, vtkAbstractArray::VTK_DATA_ARRAY_FREE);
    points->SetData(xyz);
  }
  return vtkSmartPointer<vtkPoints>(points.Get());
}

/// Empty (and not to be attached) when no normals were computed.
inline vtkSmartPointer<vtkFloatArray> AdoptNormals(
  rgmc::LocalMesh& mesh, vtkIdType numPoints, bool computed)
{
  vtkNew<vtkFloatArray> normals;
  normals->SetName("Normals");
  normals->SetNumberOfComponents(3);
  if (computed)
  {
    normals->SetArray(
      mesh.Normals.Release(), 3 * numPoints, 0, vtkAbstractArray::VTK_DATA_ARRAY_FREE);
  }
  return vtkSmartPointer<vtkFloatArray>(normals.Get());
}

inline vtkSmartPointer<vtkIdTypeArray> AdoptVertexKeys(rgmc::LocalMesh& mesh, vtkIdType numPoints)
{
  vtkNew<vtkIdTypeArray> keys;
  keys->SetName("VertexKey");
  static_assert(sizeof(vtkIdType) == sizeof(long long), "vertex keys are 64-bit ids");
  keys->SetArray(reinterpret_cast<vtkIdType*>(mesh.Keys.Release()), numPoints, 0,
    vtkAbstractArray::VTK_DATA_ARRAY_FREE);
  return vtkSmartPointer<vtkIdTypeArray>(keys.Get());
}

/// The kernel's 32-bit connectivity, adopted as is; 64-bit when a rank has more than 2^31 - 1
/// corners, where 32-bit offsets would overflow.
inline vtkSmartPointer<vtkCellArray> AdoptTriangles(rgmc::LocalMesh& mesh, vtkIdType numKept)
{
  vtkNew<vtkCellArray> polys;
  if (3 * numKept <= VTK_TYPE_INT32_MAX)
  {
    vtkNew<vtkTypeInt32Array> offsets, connectivity;
    std::int32_t* o = rgmc::Allocate(offsets.Get(), numKept + 1);
    FillOffsets(o, numKept);
    connectivity->SetArray(
      mesh.Triangles.Release(), 3 * numKept, 0, vtkAbstractArray::VTK_DATA_ARRAY_FREE);
    polys->SetData(offsets, connectivity);
  }
  else
  {
    vtkNew<vtkTypeInt64Array> offsets, connectivity;
    vtkTypeInt64* o = rgmc::Allocate(offsets.Get(), numKept + 1);
    FillOffsets(o, numKept);
    std::copy(mesh.Triangles.begin(), mesh.Triangles.begin() + 3 * numKept,
      rgmc::Allocate(connectivity.Get(), 3 * numKept));
    std::free(mesh.Triangles.Release());
    polys->SetData(offsets, connectivity);
  }
  return vtkSmartPointer<vtkCellArray>(polys.Get());
}

} // namespace extract
} // namespace rgmc

#endif

// The union of a distributed surface's pieces, keyed by global point id, as the tests of Seam
// Repair and Decimate Surface compare it: each vertex's position and normal as bits (of float or
// double), the triangles rank after rank as global-id triples, and what a union must satisfy
// (one owner per vertex, copies of a vertex that agree to the bit).
#ifndef rgmcUnitedMesh_h
#define rgmcUnitedMesh_h

#include "vtkDataArray.h"
#include "vtkDataSetAttributes.h"
#include "vtkIdTypeArray.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <map>
#include <set>
#include <type_traits>
#include <vector>

namespace rgmc_test
{

template <typename Real>
struct UnitedMesh
{
  using Bits = std::conditional_t<sizeof(Real) == 4, std::uint32_t, std::uint64_t>;
  static_assert(sizeof(Bits) == sizeof(Real), "Real is float or double");

  std::map<long long, std::array<Bits, 6>> Points; // position and normal bits by global id
  std::vector<std::array<long long, 3>> Triangles; // global ids, in the pieces' order
  std::map<long long, int> Owners;                 // copies not flagged as duplicates
  long long Inconsistent = 0;                      // copies of a vertex that differ

  /// Adds one piece: its points by global id (GlobalIds), its triangles.
  void Add(vtkPolyData* pd)
  {
    if (pd->GetNumberOfPoints() == 0)
    {
      return;
    }
    vtkIdTypeArray* ids = vtkIdTypeArray::SafeDownCast(pd->GetPointData()->GetGlobalIds());
    vtkDataArray* ghosts = pd->GetPointData()->GetArray(vtkDataSetAttributes::GhostArrayName());
    vtkDataArray* normals = pd->GetPointData()->GetNormals();
    for (vtkIdType p = 0; p < pd->GetNumberOfPoints(); ++p)
    {
      double x[3], n[3] = { 0, 0, 0 };
      pd->GetPoint(p, x);
      if (normals)
      {
        normals->GetTuple(p, n);
      }
      std::array<Bits, 6> bits;
      for (int k = 0; k < 3; ++k)
      {
        const Real xr = static_cast<Real>(x[k]), nr = static_cast<Real>(n[k]);
        std::memcpy(&bits[k], &xr, sizeof(Real));
        std::memcpy(&bits[3 + k], &nr, sizeof(Real));
      }
      const long long gid = ids->GetValue(p);
      auto inserted = this->Points.emplace(gid, bits);
      this->Inconsistent += !inserted.second && inserted.first->second != bits;
      this->Owners[gid] += ghosts && ghosts->GetComponent(p, 0) != 0 ? 0 : 1;
    }
    for (vtkIdType t = 0; t < pd->GetNumberOfCells(); ++t)
    {
      vtkIdType npts;
      const vtkIdType* pts;
      pd->GetCellPoints(t, npts, pts);
      this->Triangles.push_back(
        { ids->GetValue(pts[0]), ids->GetValue(pts[1]), ids->GetValue(pts[2]) });
    }
  }

  /// The triangles as sorted id triples, whatever their order and orientation; `duplicated`
  /// counts those that appear more than once.
  std::set<std::array<long long, 3>> SortedTriangles(long long& duplicated) const
  {
    std::set<std::array<long long, 3>> sorted;
    duplicated = 0;
    for (std::array<long long, 3> t : this->Triangles)
    {
      std::sort(t.begin(), t.end());
      duplicated += !sorted.insert(t).second;
    }
    return sorted;
  }

  /// Vertices whose copies are not owned exactly once.
  long long BadOwners() const
  {
    long long bad = 0;
    for (const auto& o : this->Owners)
    {
      bad += o.second != 1;
    }
    return bad;
  }
};

} // namespace rgmc_test

#endif

// Helpers for VTK arrays shared by the filters (private to the module): storage that fails with
// std::bad_alloc, as the rest of the filters' allocations do (VTK's own path reports a failed
// allocation through its error output, which needs memory too: with the memory exhausted it
// aborted the process, measured in TestOutOfMemory), the count of a cell array's cells that
// are not triangles, an array's first value that is not finite, and an array's value ranges
// computed once where it is made.
#ifndef vtkRGArrays_h
#define vtkRGArrays_h

#include "vtkAOSDataArrayTemplate.h"
#include "vtkAbstractArray.h"
#include "vtkCellArray.h"
#include "vtkDataArray.h"
#include "vtkRGParallel.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <new>
#include <vector>

namespace rgmc
{

/// Gives `array` (a vtkAOSDataArrayTemplate, its number of components set) storage for `values`
/// values, uninitialized, and returns it.
template <typename ArrayT>
typename ArrayT::ValueType* Allocate(ArrayT* array, vtkIdType values)
{
  using Value = typename ArrayT::ValueType;
  void* memory =
    std::malloc(std::max<std::size_t>(1, static_cast<std::size_t>(values)) * sizeof(Value));
  if (!memory)
  {
    throw std::bad_alloc();
  }
  array->SetArray(static_cast<Value*>(memory), values, 0, vtkAbstractArray::VTK_DATA_ARRAY_FREE);
  return static_cast<Value*>(memory);
}

/// As Allocate, with every value zero: from calloc, whose large blocks are fresh pages the
/// kernel gives zeroed when first touched, so that values left zero cost no write.
template <typename ArrayT>
typename ArrayT::ValueType* AllocateZeroed(ArrayT* array, vtkIdType values)
{
  using Value = typename ArrayT::ValueType;
  void* memory =
    std::calloc(std::max<std::size_t>(1, static_cast<std::size_t>(values)), sizeof(Value));
  if (!memory)
  {
    throw std::bad_alloc();
  }
  array->SetArray(static_cast<Value*>(memory), values, 0, vtkAbstractArray::VTK_DATA_ARRAY_FREE);
  return static_cast<Value*>(memory);
}

/// How many cells of `polys` do not have 3 points: from the offsets, read straight when they are
/// 32- or 64-bit arrays (as VTK's cell arrays keep them), else cell by cell.
inline vtkIdType PolygonsNotTriangles(vtkCellArray* polys)
{
  const vtkIdType cells = polys->GetNumberOfCells();
  auto count = [cells](const auto* offsets)
  {
    vtkIdType other = 0;
    for (vtkIdType c = 0; c < cells; ++c)
    {
      other += offsets[c + 1] - offsets[c] != 3;
    }
    return other;
  };
  vtkDataArray* offsets = polys->GetOffsetsArray();
  // The AOS templates, not vtkTypeInt32Array and vtkTypeInt64Array: VTK 9.6's cell arrays keep
  // their offsets in vtkAOSDataArrayTemplate<vtkTypeInt64>, which is not a vtkTypeInt64Array.
  if (auto* o32 = vtkAOSDataArrayTemplate<vtkTypeInt32>::FastDownCast(offsets))
  {
    return count(o32->GetPointer(0));
  }
  if (auto* o64 = vtkAOSDataArrayTemplate<vtkTypeInt64>::FastDownCast(offsets))
  {
    return count(o64->GetPointer(0));
  }
  vtkIdType other = 0;
  for (vtkIdType c = 0; c < cells; ++c)
  {
    other += polys->GetCellSize(c) != 3;
  }
  return other;
}

/// The first value of `array` that is not a finite number, or -1: float and double arrays read
/// straight in chunks on threads, any other type value by value.
inline vtkIdType FirstNotFinite(vtkDataArray* array)
{
  const vtkIdType n = array->GetNumberOfValues();
  auto scan = [n](const auto* values)
  {
    const vtkIdType chunk = 4 * ElementChunk; // a test a value: larger chunks
    std::vector<vtkIdType> first(static_cast<std::size_t>(ChunksOf(n, chunk)), -1);
    ForEachChunk(n, chunk,
      [&](vtkIdType c, vtkIdType begin, vtkIdType end)
      {
        for (vtkIdType i = begin; i < end; ++i)
        {
          if (!std::isfinite(values[i]))
          {
            first[c] = i;
            break;
          }
        }
      });
    for (vtkIdType at : first)
    {
      if (at >= 0)
      {
        return at;
      }
    }
    return vtkIdType(-1);
  };
  if (auto* d = vtkAOSDataArrayTemplate<double>::FastDownCast(array))
  {
    return scan(d->GetPointer(0));
  }
  if (auto* f = vtkAOSDataArrayTemplate<float>::FastDownCast(array))
  {
    return scan(f->GetPointer(0));
  }
  const int components = std::max(1, array->GetNumberOfComponents());
  for (vtkIdType i = 0; i < n; ++i)
  {
    if (!std::isfinite(array->GetComponent(i / components, static_cast<int>(i % components))))
    {
      return i;
    }
  }
  return -1;
}

/// Stores `array`'s range and finite range, per component, where VTK keeps them once computed
/// (vtkAbstractArray::PER_COMPONENT and PER_FINITE_COMPONENT), so that GetRange,
/// GetFiniteRange and ParaView's data information find them instead of scanning the array again
/// (about 30 ns a value for each of them in Debian's VTK 9.2: 1.7 s for each of the two scans of
/// a 384^3 volume). The same values VTK computes: for every component the smallest and largest
/// value, NaN skipped, and the finite ones; for an array that is not one contiguous block, of no
/// values, of plain char (whose sign is the platform's), or with a component without a value,
/// nothing is stored and VTK computes as before. Call it once the values are final: VTK drops
/// the ranges when the array is modified.
void CacheRanges(vtkDataArray* array);

/// Stores `range` as the range and finite range of `array`, of one component, whose values its
/// maker knows without a scan (the keys CacheRanges sets: the caller answers for them).
void StoreRange(vtkDataArray* array, const double range[2]);

} // namespace rgmc

#endif

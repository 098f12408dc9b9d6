// Storage for VTK arrays that fails with std::bad_alloc, as the rest of the filters' allocations
// do. (VTK's own path reports a failed allocation through its error output, which needs memory
// too: with the memory exhausted it aborted the process, measured in TestOutOfMemory.) Private to
// the module.
#ifndef vtkRGArrays_h
#define vtkRGArrays_h

#include "vtkAbstractArray.h"

#include <algorithm>
#include <cstdlib>
#include <new>

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

} // namespace rgmc

#endif

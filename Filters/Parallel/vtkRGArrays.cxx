// An array's ranges computed once, in parallel, where the array is made (vtkRGArrays.h).
#include "vtkRGArrays.h"

#include "vtkRGParallel.h"

#include "vtkDataArray.h"
#include "vtkInformation.h"
#include "vtkInformationDoubleVectorKey.h"
#include "vtkInformationInformationVectorKey.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"

#include <cmath>
#include <limits>
#include <type_traits>
#include <vector>

namespace
{

/// The smallest and largest value of one component, NaN skipped (All), and of its finite values
/// (Finite), in the array's own type until the end.
template <typename T>
struct Extremes
{
  // Floating types start from the infinities, so that an infinite value is its own extreme.
  static constexpr T Highest = std::numeric_limits<T>::has_infinity
    ? std::numeric_limits<T>::infinity()
    : std::numeric_limits<T>::max();
  static constexpr T Lowest = std::numeric_limits<T>::has_infinity
    ? -std::numeric_limits<T>::infinity()
    : std::numeric_limits<T>::lowest();
  T AllLow = Highest, AllHigh = Lowest, FiniteLow = Highest, FiniteHigh = Lowest;
  bool AnyValue = false, AnyFinite = false;

  void Add(T v)
  {
    if constexpr (std::is_floating_point<T>::value)
    {
      if (std::isnan(v))
      {
        return;
      }
      if (std::isfinite(v))
      {
        this->AddFinite(v);
      }
    }
    else
    {
      this->AddFinite(v);
    }
    this->AllLow = std::min(this->AllLow, v);
    this->AllHigh = std::max(this->AllHigh, v);
    this->AnyValue = true;
  }

  void AddFinite(T v)
  {
    this->FiniteLow = std::min(this->FiniteLow, v);
    this->FiniteHigh = std::max(this->FiniteHigh, v);
    this->AnyFinite = true;
  }

  void Merge(const Extremes& o)
  {
    this->AllLow = std::min(this->AllLow, o.AllLow);
    this->AllHigh = std::max(this->AllHigh, o.AllHigh);
    this->FiniteLow = std::min(this->FiniteLow, o.FiniteLow);
    this->FiniteHigh = std::max(this->FiniteHigh, o.FiniteHigh);
    this->AnyValue = this->AnyValue || o.AnyValue;
    this->AnyFinite = this->AnyFinite || o.AnyFinite;
  }
};

/// Every component's extremes; the minimum and maximum do not depend on how the tuples are cut
/// into chunks, so neither do the results on the threads.
template <typename T>
std::vector<Extremes<T>> ComponentExtremes(const T* values, vtkIdType tuples, int components)
{
  const vtkIdType chunk = 4 * rgmc::ElementChunk; // a comparison or two a value: larger chunks
  const vtkIdType chunks = rgmc::ChunksOf(tuples, chunk);
  std::vector<Extremes<T>> partial(static_cast<std::size_t>(chunks * components));
  rgmc::ForEachChunk(tuples, chunk,
    [&](vtkIdType c, vtkIdType begin, vtkIdType end)
    {
      Extremes<T>* e = partial.data() + c * components;
      const T* v = values + begin * components;
      if constexpr (std::is_floating_point<T>::value)
      {
        for (vtkIdType t = begin; t < end; ++t)
        {
          for (int k = 0; k < components; ++k)
          {
            e[k].Add(*v++);
          }
        }
      }
      else
      {
        // Integers are all finite: a plain minimum and maximum, which the compiler vectorizes.
        const vtkIdType n = end - begin;
        for (int k = 0; k < components; ++k)
        {
          T low = e[k].AllLow, high = e[k].AllHigh;
          for (vtkIdType t = 0; t < n; ++t)
          {
            low = std::min(low, v[t * components + k]);
            high = std::max(high, v[t * components + k]);
          }
          e[k].AllLow = e[k].FiniteLow = low;
          e[k].AllHigh = e[k].FiniteHigh = high;
          e[k].AnyValue = e[k].AnyFinite = n > 0;
        }
      }
    });
  std::vector<Extremes<T>> result(static_cast<std::size_t>(components));
  for (vtkIdType c = 0; c < chunks; ++c)
  {
    for (int k = 0; k < components; ++k)
    {
      result[k].Merge(partial[c * components + k]);
    }
  }
  return result;
}

/// Stores the ranges (`all`) and finite ranges (`finite`), low and high for each of
/// `components`, where VTK keeps them.
void SetRanges(vtkDataArray* array, const double* all, const double* finite, int components)
{
  vtkNew<vtkInformationVector> allRanges, finiteRanges;
  allRanges->SetNumberOfInformationObjects(components);
  finiteRanges->SetNumberOfInformationObjects(components);
  for (int k = 0; k < components; ++k)
  {
    allRanges->GetInformationObject(k)->Set(vtkDataArray::COMPONENT_RANGE(), all + 2 * k, 2);
    finiteRanges->GetInformationObject(k)->Set(vtkDataArray::COMPONENT_RANGE(), finite + 2 * k, 2);
  }
  vtkInformation* info = array->GetInformation();
  info->Set(vtkAbstractArray::PER_COMPONENT(), allRanges);
  info->Set(vtkAbstractArray::PER_FINITE_COMPONENT(), finiteRanges);
}

template <typename T>
void StoreRanges(vtkDataArray* array, const T* values)
{
  const int components = array->GetNumberOfComponents();
  const auto extremes = ComponentExtremes(values, array->GetNumberOfTuples(), components);
  for (const auto& e : extremes)
  {
    if (!e.AnyValue || !e.AnyFinite)
    {
      return; // VTK's own scan decides what such a component's range is
    }
  }
  std::vector<double> all, finite; // low, high a component
  for (const auto& e : extremes)
  {
    all.insert(all.end(), { double(e.AllLow), double(e.AllHigh) });
    finite.insert(finite.end(), { double(e.FiniteLow), double(e.FiniteHigh) });
  }
  SetRanges(array, all.data(), finite.data(), components);
}

} // namespace

namespace rgmc
{

void CacheRanges(vtkDataArray* array)
{
  // Plain char is left to VTK: its sign is the platform's, and a build of this code with another
  // sign than VTK's (the -funsigned-char check of ./rgmc test) would store other ranges.
  if (!array || array->GetNumberOfTuples() == 0 || array->GetNumberOfComponents() < 1 ||
    !array->HasStandardMemoryLayout() || array->GetDataType() == VTK_BIT ||
    array->GetDataType() == VTK_CHAR)
  {
    return;
  }
  switch (array->GetDataType())
  {
    vtkTemplateMacro(StoreRanges(array, static_cast<const VTK_TT*>(array->GetVoidPointer(0))));
    default:
      break;
  }
}

void StoreRange(vtkDataArray* array, const double range[2])
{
  SetRanges(array, range, range, 1);
}

} // namespace rgmc

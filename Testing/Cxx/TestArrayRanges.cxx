// The ranges the readers and the phantom store with their arrays (rgmc::CacheRanges), against
// the ranges VTK itself computes on a copy that has none stored: per component, with NaN and
// infinities, for every value type, on 1, 2, 16 and 64 threads; and present on the outputs of
// the NIfTI reader (real volumes of Debian's mricron-data) and of the phantom.
#include "rgmcCheck.h"
#include "rgmcThreadCompare.h"
#include "vtkRGArrays.h"
#include "vtkRGNIfTIReader.h"
#include "vtkRGPhantomSource.h"

#include "vtkCharArray.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationInformationVectorKey.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkSMPTools.h"
#include "vtkShortArray.h"
#include "vtkSignedCharArray.h"
#include "vtkSmartPointer.h"
#include "vtkUnsignedLongLongArray.h"

#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <random>
#include <string>

namespace
{

bool Stored(vtkDataArray* a)
{
  return a->GetInformation()->Has(vtkAbstractArray::PER_COMPONENT()) &&
    a->GetInformation()->Has(vtkAbstractArray::PER_FINITE_COMPONENT());
}

/// `a`'s ranges as it answers them (stored or not) against VTK's scan of a copy with nothing
/// stored, every component, plain and finite.
void ExpectVTKRanges(vtkDataArray* a, const std::string& what)
{
  vtkSmartPointer<vtkDataArray> fresh = vtkSmartPointer<vtkDataArray>::Take(a->NewInstance());
  fresh->DeepCopy(a);
  fresh->GetInformation()->Clear();
  for (int k = 0; k < a->GetNumberOfComponents(); ++k)
  {
    double got[2], want[2], gotFinite[2], wantFinite[2];
    a->GetRange(got, k);
    fresh->GetRange(want, k);
    a->GetFiniteRange(gotFinite, k);
    fresh->GetFiniteRange(wantFinite, k);
    RGMC_CHECK(got[0] == want[0] && got[1] == want[1],
      what << ", component " << k << ": range " << got[0] << " " << got[1] << ", VTK's " << want[0]
           << " " << want[1]);
    RGMC_CHECK(gotFinite[0] == wantFinite[0] && gotFinite[1] == wantFinite[1],
      what << ", component " << k << ": finite range " << gotFinite[0] << " " << gotFinite[1]
           << ", VTK's " << wantFinite[0] << " " << wantFinite[1]);
  }
}

template <typename ArrayT, typename Fill>
void CheckArray(const char* name, vtkIdType tuples, int components, bool expectStored, Fill fill)
{
  for (int threads : { 1, 2, 16, 64 })
  {
    vtkNew<ArrayT> a;
    a->SetNumberOfComponents(components);
    a->SetNumberOfTuples(tuples);
    std::mt19937_64 random(7);
    for (vtkIdType i = 0; i < tuples * components; ++i)
    {
      a->SetValue(i, fill(random, i));
    }
    vtkSMPTools::LocalScope(
      vtkSMPTools::Config{ threads, "STDThread", false }, [&]() { rgmc::CacheRanges(a); });
    const std::string what = std::string(name) + " on " + std::to_string(threads) + " threads";
    RGMC_CHECK(Stored(a) == expectStored, what << ": ranges stored " << Stored(a));
    ExpectVTKRanges(a, what);
  }
}

void CheckValueTypes()
{
  // More tuples than one chunk of the parallel scan (2^18), so the chunks' extremes merge.
  const vtkIdType many = 700001;
  CheckArray<vtkShortArray>("int16", many, 1, true,
    [](std::mt19937_64& r, vtkIdType) { return static_cast<short>(r() % 5000) - 2000; });
  // Plain char is left to VTK (its sign is the platform's): nothing stored, VTK's own ranges.
  CheckArray<vtkCharArray>("char", many, 2, false,
    [](std::mt19937_64& r, vtkIdType) { return static_cast<char>(r() % 256); });
  // Each component in a range of its own (-100..-51, -40..9, 20..69), so that mixing them up
  // shows.
  CheckArray<vtkSignedCharArray>("signed char, 3 components", many, 3, true,
    [](std::mt19937_64& r, vtkIdType i)
    { return static_cast<signed char>(static_cast<int>(r() % 50) + 60 * (i % 3) - 100); });
  CheckArray<vtkUnsignedLongLongArray>("uint64 beyond 2^53", 1000, 1, true,
    [](std::mt19937_64& r, vtkIdType)
    { return std::numeric_limits<std::uint64_t>::max() - r() % 7; });
  const float inf = std::numeric_limits<float>::infinity(), nan = std::nanf("");
  CheckArray<vtkFloatArray>("float32 with NaN and infinities, 3 components", many, 3, true,
    [=](std::mt19937_64& r, vtkIdType i)
    {
      const auto u = r() % 1000;
      if (i % 3 == 1 && u < 5)
      {
        return u % 2 ? inf : -inf; // component 1: infinities beside finite values
      }
      return u < 10 ? nan : static_cast<float>(u) * 0.25f - 100.0f;
    });
  // A component of only NaN, one of only infinities: VTK decides those ranges, nothing stored.
  CheckArray<vtkDoubleArray>("float64, a component of NaN only", 1000, 2, false,
    [](std::mt19937_64&, vtkIdType i) { return i % 2 ? std::nan("") : double(i); });
  CheckArray<vtkDoubleArray>("float64, a component of infinities only", 1000, 2, false,
    [](std::mt19937_64&, vtkIdType i)
    { return i % 2 ? std::numeric_limits<double>::infinity() : double(i); });
  CheckArray<vtkFloatArray>(
    "one value", 1, 1, true, [](std::mt19937_64&, vtkIdType) { return -3.5f; });
  vtkNew<vtkFloatArray> empty;
  rgmc::CacheRanges(empty);
  RGMC_CHECK(!Stored(empty), "an empty array got ranges");
}

void CheckPhantom()
{
  for (int threads : { 1, 16 })
  {
    vtkSMPTools::LocalScope(vtkSMPTools::Config{ threads, "STDThread", false },
      [&]()
      {
        vtkNew<vtkRGPhantomSource> phantom;
        phantom->SetDimensions(48, 40, 36);
        phantom->Update();
        vtkDataArray* hu = phantom->GetOutput()->GetPointData()->GetScalars();
        RGMC_CHECK(hu && Stored(hu), "the phantom's HU array has no stored ranges");
        if (hu)
        {
          ExpectVTKRanges(hu, "the phantom on " + std::to_string(threads) + " threads");
        }
      });
  }
}

void CheckNIfTI()
{
  int read = 0;
  for (const char* name : { "ch2better.nii.gz", "inia19-t1-brain.nii.gz", "aal.nii.gz" })
  {
    const std::string path = std::string("/usr/share/mricron/templates/") + name;
    if (!std::ifstream(path))
    {
      continue;
    }
    vtkNew<vtkRGNIfTIReader> reader;
    reader->SetFileName(path.c_str());
    reader->Update();
    vtkDataArray* scalars = reader->GetOutput()->GetPointData()->GetScalars();
    RGMC_CHECK(scalars && Stored(scalars), path << ": no stored ranges");
    if (scalars)
    {
      ExpectVTKRanges(scalars, path);
      ++read;
    }
  }
  RGMC_CHECK(read > 0, "no mricron-data volume found (the package is a test dependency)");
}

} // namespace

int main()
{
  rgmc_test::AllowThreads(64);
  CheckValueTypes();
  CheckPhantom();
  CheckNIfTI();
  return rgmc_test::Result("TestArrayRanges");
}

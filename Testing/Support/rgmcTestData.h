// Shared by the VTK-level tests: volumes with known structure, the oracle pipeline
// (vtkMarchingCubes + vtkPolyDataConnectivityFilter), and comparisons of triangle meshes.
#ifndef rgmcTestData_h
#define rgmcTestData_h

#include "rgmcCheck.h"

#include "vtkAppendPolyData.h"
#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkCleanPolyData.h"
#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkDataSetAttributes.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkIdList.h"
#include "vtkImageData.h"
#include "vtkMarchingCubes.h"
#include "vtkMath.h"
#include "vtkMatrix3x3.h"
#include "vtkMatrix4x4.h"
#include "vtkMinimalStandardRandomSequence.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkPolyDataConnectivityFilter.h"
#include "vtkSmartPointer.h"
#include "vtkStaticPointLocator.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace rgmc_test
{

/// An image of the given extent whose point array "f" (of VTK type `type`) holds f(i, j, k).
inline vtkSmartPointer<vtkImageData> MakeImage(
  const int extent[6], int type, const std::function<double(int, int, int)>& f)
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetExtent(const_cast<int*>(extent));
  vtkSmartPointer<vtkDataArray> array;
  array.TakeReference(vtkDataArray::CreateDataArray(type));
  array->SetName("f");
  array->SetNumberOfTuples(image->GetNumberOfPoints());
  vtkIdType id = 0;
  for (int k = extent[4]; k <= extent[5]; ++k)
  {
    for (int j = extent[2]; j <= extent[3]; ++j)
    {
      for (int i = extent[0]; i <= extent[1]; ++i)
      {
        array->SetComponent(id++, 0, f(i, j, k));
      }
    }
  }
  image->GetPointData()->SetScalars(array);
  return image;
}

/// A smooth field: a sum of `count` Gaussian bumps of both signs at random places, so that an
/// isovalue near 0.3 cuts it into many separate components.
inline std::function<double(int, int, int)> Blobs(const int extent[6], int count, int seed)
{
  vtkNew<vtkMinimalStandardRandomSequence> random;
  random->SetSeed(seed);
  struct Bump
  {
    double C[3], Width, Height;
  };
  std::vector<Bump> bumps(count);
  for (Bump& b : bumps)
  {
    for (int a = 0; a < 3; ++a)
    {
      b.C[a] = random->GetNextRangeValue(extent[2 * a], extent[2 * a + 1]);
    }
    b.Width = random->GetNextRangeValue(1.5, 5.0);
    b.Height = random->GetNextRangeValue(-0.6, 1.2);
  }
  return [bumps](int i, int j, int k)
  {
    double v = 0.0;
    for (const Bump& b : bumps)
    {
      const double d2 =
        (i - b.C[0]) * (i - b.C[0]) + (j - b.C[1]) * (j - b.C[1]) + (k - b.C[2]) * (k - b.C[2]);
      v += b.Height * std::exp(-d2 / (2 * b.Width * b.Width));
    }
    return v;
  };
}

/// Random points inside the image's bounds.
inline std::vector<std::array<double, 3>> RandomSeeds(vtkImageData* image, int count, int seed)
{
  vtkNew<vtkMinimalStandardRandomSequence> random;
  random->SetSeed(seed);
  int ext[6];
  image->GetExtent(ext);
  std::vector<std::array<double, 3>> seeds(count);
  for (auto& s : seeds)
  {
    double idx[3], x[3];
    for (int a = 0; a < 3; ++a)
    {
      idx[a] = random->GetNextRangeValue(ext[2 * a], ext[2 * a + 1]);
    }
    image->TransformContinuousIndexToPhysicalPoint(idx, x);
    s = { x[0], x[1], x[2] };
  }
  return seeds;
}

/// vtkMarchingCubes with normals, without the points that only collapsed triangles used (the
/// locator inserts them before the triangle is dropped; they belong to no triangle).
inline vtkSmartPointer<vtkPolyData> MarchingCubes(vtkImageData* image, double isovalue)
{
  vtkNew<vtkMarchingCubes> mc;
  mc->SetInputData(image);
  mc->SetValue(0, isovalue);
  mc->ComputeNormalsOn();
  mc->ComputeScalarsOff();
  vtkNew<vtkCleanPolyData> clean;
  clean->SetInputConnection(mc->GetOutputPort());
  clean->PointMergingOff();
  clean->Update();
  return clean->GetOutput();
}

/// The oracle of the seeded mode: for each seed, the connected region of marching cubes that
/// holds the point closest to it; their union, each region once (two seeds on one region select
/// it once, as the filter does; regions share no point, so a region whose first point is already
/// in the union is one chosen before).
inline vtkSmartPointer<vtkPolyData> ClosestRegions(
  vtkPolyData* mc, const std::vector<std::array<double, 3>>& seeds)
{
  vtkNew<vtkAppendPolyData> append;
  std::set<std::array<double, 3>> chosen;
  for (const auto& s : seeds)
  {
    vtkNew<vtkPolyDataConnectivityFilter> conn;
    conn->SetInputData(mc);
    conn->SetExtractionModeToClosestPointRegion();
    conn->SetClosestPoint(s[0], s[1], s[2]);
    conn->Update();
    auto region = vtkSmartPointer<vtkPolyData>::New();
    region->ShallowCopy(conn->GetOutput());
    std::array<double, 3> first;
    if (region->GetNumberOfPoints() > 0)
    {
      region->GetPoint(0, first.data());
      if (chosen.count(first))
      {
        continue;
      }
    }
    for (vtkIdType p = 0; p < region->GetNumberOfPoints(); ++p)
    {
      std::array<double, 3> x;
      region->GetPoint(p, x.data());
      chosen.insert(x);
    }
    append->AddInputData(region);
  }
  append->Update();
  return append->GetOutput();
}

/// How two meshes differ, vertex by vertex and triangle by triangle.
struct Comparison
{
  vtkIdType OursTriangles = 0;
  vtkIdType TheirTriangles = 0;
  vtkIdType Unmatched = 0;     // our vertices with no counterpart within the tolerance
  vtkIdType Merged = 0;        // our vertices that share a counterpart with another (float merge)
  vtkIdType MissingTheirs = 0; // their triangles we lack
  vtkIdType ExtraOurs = 0;     // our triangles they lack
  double MaxDistance = 0;
  double MaxNormalError = 0;

  bool SameTriangles() const
  {
    return this->Unmatched == 0 && this->MissingTheirs == 0 && this->ExtraOurs == 0;
  }
};

/// Matches each of our points to the nearest of theirs (within `tolerance`) and compares the
/// triangles as multisets of matched vertex triples (a triangle emitted twice is one too many),
/// and the normals of matched vertices. Their vertices are identified by exact coordinates.
inline Comparison Compare(vtkPolyData* ours, vtkPolyData* theirs, double tolerance)
{
  Comparison c;
  c.OursTriangles = ours->GetNumberOfCells();
  c.TheirTriangles = theirs->GetNumberOfCells();

  std::vector<vtkIdType> canon(theirs->GetNumberOfPoints());
  {
    std::map<std::array<double, 3>, vtkIdType> first;
    for (vtkIdType q = 0; q < theirs->GetNumberOfPoints(); ++q)
    {
      std::array<double, 3> x;
      theirs->GetPoint(q, x.data());
      canon[q] = first.emplace(x, q).first->second;
    }
  }

  std::vector<vtkIdType> match(ours->GetNumberOfPoints(), -1);
  vtkNew<vtkStaticPointLocator> locator;
  if (theirs->GetNumberOfPoints() > 0)
  {
    locator->SetDataSet(theirs);
    locator->BuildLocator();
  }
  std::map<vtkIdType, int> uses;
  for (vtkIdType p = 0; p < ours->GetNumberOfPoints(); ++p)
  {
    if (theirs->GetNumberOfPoints() == 0)
    {
      ++c.Unmatched;
      continue;
    }
    double x[3], y[3];
    ours->GetPoint(p, x);
    const vtkIdType q = locator->FindClosestPoint(x);
    theirs->GetPoint(q, y);
    const double d = std::sqrt(vtkMath::Distance2BetweenPoints(x, y));
    c.MaxDistance = std::max(c.MaxDistance, d);
    if (d <= tolerance)
    {
      match[p] = canon[q];
      ++uses[canon[q]];
    }
    else
    {
      ++c.Unmatched;
    }
  }
  for (const auto& u : uses)
  {
    c.Merged += u.second - 1;
  }

  vtkDataArray* n1 = ours->GetPointData()->GetNormals();
  vtkDataArray* n2 = theirs->GetPointData()->GetNormals();
  if (n1 && n2)
  {
    for (vtkIdType p = 0; p < ours->GetNumberOfPoints(); ++p)
    {
      if (match[p] >= 0 && uses[match[p]] == 1)
      {
        double a[3], b[3];
        n1->GetTuple(p, a);
        n2->GetTuple(match[p], b);
        for (int k = 0; k < 3; ++k)
        {
          c.MaxNormalError = std::max(c.MaxNormalError, std::fabs(a[k] - b[k]));
        }
      }
    }
  }

  auto triangles = [](vtkPolyData* pd, const std::vector<vtkIdType>& map)
  {
    std::map<std::array<vtkIdType, 3>, vtkIdType> counts;
    vtkIdType npts;
    const vtkIdType* pts;
    vtkCellArray* cells = pd->GetPolys();
    for (cells->InitTraversal(); cells->GetNextCell(npts, pts);)
    {
      std::array<vtkIdType, 3> t = { map[pts[0]], map[pts[1]], map[pts[2]] };
      std::sort(t.begin(), t.end());
      if (t[0] != t[1] && t[1] != t[2]) // a triangle that a float merge collapses is dropped
      {
        ++counts[t];
      }
    }
    return counts;
  };
  const auto a = triangles(ours, match);
  const auto b = triangles(theirs, canon);
  auto excess = [](const std::map<std::array<vtkIdType, 3>, vtkIdType>& x,
                  const std::map<std::array<vtkIdType, 3>, vtkIdType>& y)
  {
    vtkIdType n = 0;
    for (const auto& t : x)
    {
      auto other = y.find(t.first);
      n += std::max<vtkIdType>(0, t.second - (other == y.end() ? 0 : other->second));
    }
    return n;
  };
  c.ExtraOurs = excess(a, b);
  c.MissingTheirs = excess(b, a);
  return c;
}

inline std::ostream& operator<<(std::ostream& os, const Comparison& c)
{
  return os << "ours " << c.OursTriangles << " triangles, theirs " << c.TheirTriangles
            << ", unmatched vertices " << c.Unmatched << ", float-merged " << c.Merged << ", extra "
            << c.ExtraOurs << ", missing " << c.MissingTheirs << ", max distance " << c.MaxDistance
            << ", max normal error " << c.MaxNormalError;
}

/// Marks the cells of `image` outside the cells of `owned` (a point extent) as ghost cells
/// (DUPLICATECELL), as the pipeline does for a ghost level.
inline void MarkGhostCells(vtkImageData* image, const int owned[6])
{
  int ext[6];
  image->GetExtent(ext);
  vtkNew<vtkUnsignedCharArray> ghosts;
  ghosts->SetName(vtkDataSetAttributes::GhostArrayName());
  ghosts->SetNumberOfTuples(image->GetNumberOfCells());
  vtkIdType id = 0;
  for (int k = ext[4]; k < ext[5]; ++k)
  {
    for (int j = ext[2]; j < ext[3]; ++j)
    {
      for (int i = ext[0]; i < ext[1]; ++i)
      {
        const bool inside = i >= owned[0] && i < owned[1] && j >= owned[2] && j < owned[3] &&
          k >= owned[4] && k < owned[5];
        ghosts->SetValue(id++, inside ? 0 : vtkDataSetAttributes::DUPLICATECELL);
      }
    }
  }
  image->GetCellData()->AddArray(ghosts);
}

/// The point extent of `owned` (a point extent) widened by `levels` ghost layers, within
/// `whole`.
inline void WithGhostLayers(const int owned[6], const int whole[6], int levels, int out[6])
{
  for (int a = 0; a < 3; ++a)
  {
    out[2 * a] = std::max(whole[2 * a], owned[2 * a] - levels);
    out[2 * a + 1] = std::min(whole[2 * a + 1], owned[2 * a + 1] + levels);
  }
}

/// A "Vm..." line of /proc/self/status in KiB (VmSize: the address space in use, VmPeak its
/// peak; VmRSS: the resident set, VmHWM its peak), or 0.
inline long long ProcessStatusKiB(const char* field)
{
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
  {
    if (line.rfind(field, 0) == 0)
    {
      return std::atoll(line.c_str() + std::strlen(field) + 1);
    }
  }
  return 0;
}

/// Collects the error and warning messages a VTK object emits.
class MessageCatcher : public vtkCommand
{
public:
  static MessageCatcher* New() { return new MessageCatcher; }
  void Execute(vtkObject*, unsigned long event, void* data) override
  {
    const std::string text = data ? static_cast<const char*>(data) : "";
    (event == vtkCommand::ErrorEvent ? this->Errors : this->Warnings) += text + "\n";
  }
  void Watch(vtkObject* o)
  {
    o->AddObserver(vtkCommand::ErrorEvent, this);
    o->AddObserver(vtkCommand::WarningEvent, this);
  }
  void Clear()
  {
    this->Errors.clear();
    this->Warnings.clear();
  }
  std::string Errors, Warnings;
};

} // namespace rgmc_test

#endif

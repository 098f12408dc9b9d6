// The oracle of distances between surfaces in the tests: from each point of one surface to the
// other surface, through a vtkStaticCellLocator's exact closest points (VTK's code, not the
// plugin's).
#ifndef rgmcNearestDistances_h
#define rgmcNearestDistances_h

#include "vtkGenericCell.h"
#include "vtkNew.h"
#include "vtkPolyData.h"
#include "vtkStaticCellLocator.h"

#include <algorithm>
#include <cmath>

namespace rgmc_test
{

/// The largest and the mean distance from the points of one surface to another.
struct NearestDistances
{
  double Largest = 0;
  double Mean = 0;
};

/// The distances from every point of `from` to the surface `to`.
inline NearestDistances Nearest(vtkPolyData* from, vtkPolyData* to)
{
  vtkNew<vtkStaticCellLocator> locator;
  locator->SetDataSet(to);
  locator->BuildLocator();
  vtkNew<vtkGenericCell> cell;
  NearestDistances d;
  double sum = 0;
  for (vtkIdType p = 0; p < from->GetNumberOfPoints(); ++p)
  {
    double x[3], closest[3], d2;
    vtkIdType cellId;
    int subId;
    from->GetPoint(p, x);
    locator->FindClosestPoint(x, closest, cell, cellId, subId, d2);
    d.Largest = std::max(d.Largest, std::sqrt(d2));
    sum += std::sqrt(d2);
  }
  d.Mean = sum / std::max<vtkIdType>(1, from->GetNumberOfPoints());
  return d;
}

} // namespace rgmc_test

#endif

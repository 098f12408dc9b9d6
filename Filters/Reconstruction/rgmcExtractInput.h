// Reading the input volume for vtkRGMarchingCubes: the volume's geometry, the cells a piece owns
// (its cells not marked ghost), and the surface kernel over the piece's samples, whatever their
// array type (vtkArrayDispatch glue).
#ifndef rgmcExtractInput_h
#define rgmcExtractInput_h

#include "rgmcCaseTable.h"
#include "rgmcSurfaceKernel.h"

#include "vtkDataArrayRange.h"
#include "vtkDataSetAttributes.h"
#include "vtkImageData.h"
#include "vtkMarchingCubesTriangleCases.h"
#include "vtkMath.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>

namespace rgmc
{
namespace extract
{

inline const rgmc::CaseTable& Cases()
{
  static const rgmc::CaseTable table(&vtkMarchingCubesTriangleCases::GetCases()[0].edges[0]);
  return table;
}

// ---- geometry ------------------------------------------------------------------------------

/// Origin, spacing and direction of the volume, agreed on by all ranks (a rank without data
/// may carry default geometry).
struct Geometry
{
  double Origin[3] = { 0, 0, 0 };
  double Spacing[3] = { 1, 1, 1 };
  double Direction[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 1 };

  void IndexToWorldMatrix(double m[3][4]) const
  {
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 3; ++c)
      {
        m[r][c] = this->Direction[3 * r + c] * this->Spacing[c];
      }
      m[r][3] = this->Origin[r];
    }
  }

  void NormalMatrix(double m[3][3]) const
  {
    double d[3][3];
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 3; ++c)
      {
        d[r][c] = this->Direction[3 * r + c];
      }
    }
    const double det = vtkMath::Determinant3x3(d);
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 3; ++c)
      {
        m[r][c] = det * d[r][c] / this->Spacing[c];
      }
    }
  }

  /// Continuous index coordinates of a world point.
  void WorldToIndex(const double x[3], double idx[3]) const
  {
    double m[3][4], a[3][3], inv[3][3];
    this->IndexToWorldMatrix(m);
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 3; ++c)
      {
        a[r][c] = m[r][c];
      }
    }
    vtkMath::Invert3x3(a, inv);
    const double d[3] = { x[0] - m[0][3], x[1] - m[1][3], x[2] - m[2][3] };
    vtkMath::Multiply3x3(inv, d, idx);
  }

  /// World bounds of the volume of point extent `whole`.
  void Bounds(const int whole[6], double bounds[6]) const
  {
    double m[3][4];
    this->IndexToWorldMatrix(m);
    for (int a = 0; a < 3; ++a)
    {
      bounds[2 * a] = VTK_DOUBLE_MAX;
      bounds[2 * a + 1] = VTK_DOUBLE_MIN;
    }
    for (int c = 0; c < 8; ++c)
    {
      const double idx[3] = { double(whole[(c & 1) ? 1 : 0]), double(whole[(c & 2) ? 3 : 2]),
        double(whole[(c & 4) ? 5 : 4]) };
      for (int a = 0; a < 3; ++a)
      {
        const double x = m[a][0] * idx[0] + m[a][1] * idx[1] + m[a][2] * idx[2] + m[a][3];
        bounds[2 * a] = std::min(bounds[2 * a], x);
        bounds[2 * a + 1] = std::max(bounds[2 * a + 1], x);
      }
    }
  }

  /// The smallest world length of a unit index step (smallest singular value).
  double MinStep() const
  {
    double m[3][4], a[3][3], u[3][3], w[3], vt[3][3];
    this->IndexToWorldMatrix(m);
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 3; ++c)
      {
        a[r][c] = m[r][c];
      }
    }
    vtkMath::SingularValueDecomposition3x3(a, u, w, vt);
    return std::min(std::fabs(w[0]), std::min(std::fabs(w[1]), std::fabs(w[2])));
  }
};

// ---- ownership -----------------------------------------------------------------------------

/// The box of this piece's cells that are not ghosts. Ghost layers of image data are shells at
/// the extent's faces, so probing the lines through the centre finds the box; an unusual
/// pattern falls back to scanning the ghost array.
inline rgmc::CellBox OwnedCells(vtkImageData* input)
{
  rgmc::CellBox box;
  int ext[6];
  input->GetExtent(ext);
  for (int a = 0; a < 3; ++a)
  {
    box.Lo[a] = ext[2 * a];
    box.Hi[a] = ext[2 * a + 1] - 1;
  }
  vtkUnsignedCharArray* ghosts = input->GetCellGhostArray();
  if (!ghosts || box.Empty())
  {
    return box;
  }
  const vtkIdType nx = ext[1] - ext[0], nxy = nx * (ext[3] - ext[2]);
  auto ghost = [&](int i, int j, int k)
  {
    const vtkIdType id = (i - ext[0]) + nx * (j - ext[2]) + nxy * (k - ext[4]);
    return (ghosts->GetValue(id) & vtkDataSetAttributes::DUPLICATECELL) != 0;
  };
  const rgmc::CellBox all = box;
  int centre[3];
  for (int a = 0; a < 3; ++a)
  {
    centre[a] = (all.Lo[a] + all.Hi[a]) / 2;
  }
  bool probed = !ghost(centre[0], centre[1], centre[2]);
  for (int a = 0; a < 3 && probed; ++a)
  {
    int p[3] = { centre[0], centre[1], centre[2] };
    for (p[a] = all.Lo[a]; p[a] < centre[a] && ghost(p[0], p[1], p[2]); ++p[a])
    {
    }
    box.Lo[a] = p[a];
    for (p[a] = all.Hi[a]; p[a] > centre[a] && ghost(p[0], p[1], p[2]); --p[a])
    {
    }
    box.Hi[a] = p[a];
  }
  for (int c = 0; c < 8 && probed; ++c)
  {
    const int i = (c & 1) ? box.Hi[0] : box.Lo[0];
    const int j = (c & 2) ? box.Hi[1] : box.Lo[1];
    const int k = (c & 4) ? box.Hi[2] : box.Lo[2];
    probed = !ghost(i, j, k);
  }
  if (probed)
  {
    return box;
  }
  rgmc::CellBox found; // bounding box of all non-ghost cells
  for (int a = 0; a < 3; ++a)
  {
    found.Lo[a] = all.Hi[a] + 1;
    found.Hi[a] = all.Lo[a] - 1;
  }
  for (int k = all.Lo[2]; k <= all.Hi[2]; ++k)
  {
    for (int j = all.Lo[1]; j <= all.Hi[1]; ++j)
    {
      for (int i = all.Lo[0]; i <= all.Hi[0]; ++i)
      {
        if (!ghost(i, j, k))
        {
          const int p[3] = { i, j, k };
          for (int a = 0; a < 3; ++a)
          {
            found.Lo[a] = std::min(found.Lo[a], p[a]);
            found.Hi[a] = std::max(found.Hi[a], p[a]);
          }
        }
      }
    }
  }
  return found;
}

// ---- the kernel over the input's samples, whatever the array type ---------------------------

/// The samples' range, constructed before the kernel that keeps a reference to it.
template <typename Range>
struct SamplesHolder
{
  Range Samples;
};

/// The kernel (rgmc::Kernel's implementation) with the samples it reads.
template <typename Range>
struct KernelOnSamples
  : SamplesHolder<Range>
  , rgmc::SurfaceKernel<Range>
{
  KernelOnSamples(const Range& samples, const rgmc::Grid& grid, const rgmc::Ownership& ownership,
    const rgmc::SurfaceOptions& options)
    : SamplesHolder<Range>{ samples }
    , rgmc::SurfaceKernel<Range>(Cases(), grid, ownership, this->Samples, options)
  {
  }
};

/// Stands in for the samples on a rank that has none (it owns no cube, so nothing is read).
struct NoValues
{
  float operator[](std::int64_t) const { return 0.0f; }
};

struct KernelBuilder
{
  const rgmc::Grid* Grid;
  const rgmc::Ownership* Ownership;
  const rgmc::SurfaceOptions* Options;
  std::unique_ptr<rgmc::Kernel> Result;

  template <typename ArrayT>
  void operator()(ArrayT* array)
  {
    using Range = decltype(vtk::DataArrayValueRange<1>(array));
    this->Result.reset(new KernelOnSamples<Range>(
      vtk::DataArrayValueRange<1>(array), *this->Grid, *this->Ownership, *this->Options));
  }
};

} // namespace extract
} // namespace rgmc

#endif

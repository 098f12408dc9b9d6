#include "vtkRGPieces.h"

#include "vtkRGArrays.h"
#include "vtkRGParallel.h"

#include "vtkCellData.h"
#include "vtkDataSetAttributes.h"
#include "vtkExtentTranslator.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationIntegerRequestKey.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkUnsignedCharArray.h"

#include <cstring>

namespace
{

int Requested(vtkInformation* info, vtkInformationIntegerKey* key, int otherwise)
{
  return info->Has(key) ? info->Get(key) : otherwise;
}

/// Sets to `flag` the values outside the box `inside` of `values` (zero), the samples of the box
/// `box` (lo, hi per axis, hi exclusive) in x-fastest order, a row at a time on threads: the rows
/// of the owned part, most of the piece, are not touched.
void FillGhosts(unsigned char* values, const int box[6], const int inside[6], unsigned char flag)
{
  const vtkIdType nx = box[1] - box[0], ny = box[3] - box[2], nz = box[5] - box[4];
  // The row's run inside the box, clipped to the row: [x0, x1) of [0, nx).
  const vtkIdType x0 = std::min<vtkIdType>(nx, std::max(0, inside[0] - box[0]));
  const vtkIdType x1 = std::max<vtkIdType>(x0, std::min<vtkIdType>(nx, inside[1] - box[0]));
  rgmc::ParallelFor(nz, 1,
    [&](vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType z = begin; z < end; ++z)
      {
        const int k = box[4] + static_cast<int>(z);
        const bool slab = k >= inside[4] && k < inside[5];
        for (vtkIdType y = 0; y < ny; ++y)
        {
          const int j = box[2] + static_cast<int>(y);
          unsigned char* row = values + (z * ny + y) * nx;
          if (!slab || j < inside[2] || j >= inside[3])
          {
            std::memset(row, flag, static_cast<std::size_t>(nx));
            continue;
          }
          std::memset(row, flag, static_cast<std::size_t>(x0));
          std::memset(row + x1, flag, static_cast<std::size_t>(nx - x1));
        }
      }
    });
}

/// A ghost array for the samples of `box`, `flag` outside `inside`, with its range stored: 0 if
/// any sample is inside, `flag` if any is outside.
vtkSmartPointer<vtkUnsignedCharArray> GhostArray(
  const int box[6], const int inside[6], unsigned char flag)
{
  vtkIdType values = 1;
  bool anyInside = true, anyOutside = false;
  for (int a = 0; a < 3; ++a)
  {
    values *= box[2 * a + 1] - box[2 * a];
    anyInside = anyInside &&
      std::max(box[2 * a], inside[2 * a]) < std::min(box[2 * a + 1], inside[2 * a + 1]);
    anyOutside = anyOutside || inside[2 * a] > box[2 * a] || inside[2 * a + 1] < box[2 * a + 1];
  }
  auto ghosts = vtkSmartPointer<vtkUnsignedCharArray>::New();
  ghosts->SetName(vtkDataSetAttributes::GhostArrayName());
  FillGhosts(rgmc::AllocateZeroed(ghosts.Get(), values), box, inside, flag);
  const double range[2] = { anyInside ? 0.0 : double(flag), anyOutside ? double(flag) : 0.0 };
  rgmc::StoreRange(ghosts, range);
  return ghosts;
}

} // namespace

namespace rgmc
{

bool SlabPiece(vtkInformation* outInfo, const int whole[6], int extent[6], int owned[6])
{
  using SDDP = vtkStreamingDemandDrivenPipeline;
  const int piece = Requested(outInfo, SDDP::UPDATE_PIECE_NUMBER(), 0);
  const int pieces = Requested(outInfo, SDDP::UPDATE_NUMBER_OF_PIECES(), 1);
  // One ghost slice at least: the extraction asks for it, and a piece made without it would be
  // made again once the extraction runs (MarkGhosts tells the executive it is there).
  const int ghosts =
    std::max(pieces > 1 ? 1 : 0, Requested(outInfo, SDDP::UPDATE_NUMBER_OF_GHOST_LEVELS(), 0));
  if (pieces < 1 || piece < 0 || piece >= pieces)
  {
    return false;
  }
  std::copy(whole, whole + 6, owned);
  const int layers = whole[5] - whole[4]; // of cells, along z
  if (pieces <= std::max(1, layers))
  {
    int all[6];
    std::copy(whole, whole + 6, all);
    vtkNew<vtkExtentTranslator> translator;
    translator->PieceToExtentThreadSafe(
      piece, pieces, 0, all, owned, vtkExtentTranslator::Z_SLAB_MODE, 0);
  }
  else if (piece < std::max(1, layers))
  {
    // More pieces than layers of cells: vtkExtentTranslator would give several pieces the same
    // layer (pieces 0 and 1 of 20 over 12 layers, both owning it). A layer a piece, in order.
    owned[4] = whole[4] + piece;
    owned[5] = std::min(whole[5], owned[4] + 1);
  }
  else
  {
    return false; // more pieces than layers of cells: this one is empty
  }
  for (int a = 0; a < 3; ++a)
  {
    extent[2 * a] = std::max(whole[2 * a], owned[2 * a] - ghosts);
    extent[2 * a + 1] = std::min(whole[2 * a + 1], owned[2 * a + 1] + ghosts);
  }
  // A consumer that asks for less than the whole volume (a VOI) gets the part of its slab in it.
  if (outInfo->Has(SDDP::UPDATE_EXTENT()))
  {
    int request[6];
    outInfo->Get(SDDP::UPDATE_EXTENT(), request);
    for (int a = 0; a < 3; ++a)
    {
      extent[2 * a] = std::max(extent[2 * a], request[2 * a]);
      extent[2 * a + 1] = std::min(extent[2 * a + 1], request[2 * a + 1]);
      owned[2 * a] = std::max(owned[2 * a], request[2 * a]);
      owned[2 * a + 1] = std::min(owned[2 * a + 1], request[2 * a + 1]);
    }
  }
  return extent[0] <= extent[1] && extent[2] <= extent[3] && extent[4] <= extent[5];
}

void MarkGhosts(vtkImageData* image, const int owned[6])
{
  int extent[6];
  image->GetExtent(extent);
  if (std::equal(extent, extent + 6, owned) || extent[0] > extent[1] || extent[2] > extent[3] ||
    extent[4] > extent[5])
  {
    return;
  }
  if (image->GetPointData()->GetArray(vtkDataSetAttributes::GhostArrayName()) ||
    image->GetCellData()->GetArray(vtkDataSetAttributes::GhostArrayName()))
  {
    int zero[6];
    std::copy(owned, owned + 6, zero);
    image->GenerateGhostArray(zero);
    return;
  }
  // Points: a point is owned from owned[lo] to owned[hi], both included.
  int points[6], inside[6], cells[6], ownedCells[6];
  for (int a = 0; a < 3; ++a)
  {
    points[2 * a] = extent[2 * a];
    points[2 * a + 1] = extent[2 * a + 1] + 1;
    inside[2 * a] = owned[2 * a];
    inside[2 * a + 1] = owned[2 * a + 1] + 1;
    // Cells: cell i spans points i and i + 1, owned from owned[lo] to owned[hi] - 1; an axis of
    // one point is one cell, owned if its point is.
    const int flat = extent[2 * a] == extent[2 * a + 1];
    cells[2 * a] = extent[2 * a];
    cells[2 * a + 1] = extent[2 * a + 1] + flat;
    ownedCells[2 * a] = owned[2 * a];
    ownedCells[2 * a + 1] = owned[2 * a + 1] + flat;
  }
  auto pointGhosts = GhostArray(points, inside, vtkDataSetAttributes::DUPLICATEPOINT);
  auto cellGhosts = GhostArray(cells, ownedCells, vtkDataSetAttributes::DUPLICATECELL);
  image->GetPointData()->AddArray(pointGhosts);
  image->GetCellData()->AddArray(cellGhosts);
  // The ghost levels made, which the executive keeps when more than were asked for, so that a
  // consumer asking for them later does not make the piece again.
  int levels = 0;
  for (int a = 0; a < 3; ++a)
  {
    levels =
      std::max({ levels, owned[2 * a] - extent[2 * a], extent[2 * a + 1] - owned[2 * a + 1] });
  }
  image->GetInformation()->Set(vtkDataObject::DATA_NUMBER_OF_GHOST_LEVELS(), levels);
}

} // namespace rgmc

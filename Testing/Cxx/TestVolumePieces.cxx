// How the volume sources cut a volume over the ranks (vtkRGPieces.h), against VTK's own answers:
// - MarkGhosts gives the ghost arrays vtkDataSet::GenerateGhostArray gives, value for value, with
//   the ranges VTK's scan computes, for ghosts on every side, two levels, flat axes, an owned
//   part that is the whole piece or nothing, on 1 and 16 threads;
// - SlabPiece gives vtkExtentTranslator's z slabs, owned parts whose cells tile the volume, a
//   ghost slice at least once there are several pieces, a layer a piece and empty pieces past
//   the last layer when there are more pieces than layers (where the translator gives two
//   pieces the same layer), and a VOI's part;
// - a phantom piece asked for without ghost levels and then with one (as ParaView asks) is made
//   once, with the ghost marks VTK would give it, and equal to a fresh phantom's piece.
#include "rgmcCheck.h"
#include "rgmcThreadCompare.h"
#include "vtkRGPhantomSource.h"
#include "vtkRGPieces.h"

#include "vtkCallbackCommand.h"
#include "vtkCellData.h"
#include "vtkDataSetAttributes.h"
#include "vtkExtentTranslator.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkSMPTools.h"
#include "vtkShortArray.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <sstream>
#include <string>

namespace
{

std::string Extent(const int e[6])
{
  std::ostringstream s;
  s << "[" << e[0] << "," << e[1] << " " << e[2] << "," << e[3] << " " << e[4] << "," << e[5]
    << "]";
  return s.str();
}

vtkUnsignedCharArray* Ghosts(vtkDataSetAttributes* attributes)
{
  return vtkUnsignedCharArray::SafeDownCast(
    attributes->GetArray(vtkDataSetAttributes::GhostArrayName()));
}

/// Whether `a` and `b` hold the same values, and `a`'s range (stored or scanned) is `b`'s scanned.
bool SameGhosts(vtkUnsignedCharArray* a, vtkUnsignedCharArray* b)
{
  if (!a || !b)
  {
    return !a && !b;
  }
  if (a->GetNumberOfValues() != b->GetNumberOfValues() ||
    !std::equal(a->GetPointer(0), a->GetPointer(0) + a->GetNumberOfValues(), b->GetPointer(0)))
  {
    return false;
  }
  double ra[2], rb[2];
  a->GetRange(ra, 0);
  b->GetRange(rb, 0);
  return ra[0] == rb[0] && ra[1] == rb[1];
}

void CheckMarks(const int extent[6], const int owned[6], int levels)
{
  const std::string what = "the ghosts of " + Extent(extent) + " owning " + Extent(owned) + " on " +
    std::to_string(vtkSMPTools::GetEstimatedNumberOfThreads()) + " threads";
  vtkNew<vtkImageData> ours, vtks;
  ours->SetExtent(const_cast<int*>(extent));
  vtks->SetExtent(const_cast<int*>(extent));
  rgmc::MarkGhosts(ours, owned);
  int zero[6];
  std::copy(owned, owned + 6, zero);
  vtks->GenerateGhostArray(zero);
  RGMC_CHECK(SameGhosts(Ghosts(ours->GetPointData()), Ghosts(vtks->GetPointData())),
    what << ": the point ghosts differ from vtkDataSet::GenerateGhostArray's");
  RGMC_CHECK(SameGhosts(Ghosts(ours->GetCellData()), Ghosts(vtks->GetCellData())),
    what << ": the cell ghosts differ from vtkDataSet::GenerateGhostArray's");
  vtkInformation* info = ours->GetInformation();
  const int made = info->Has(vtkDataObject::DATA_NUMBER_OF_GHOST_LEVELS())
    ? info->Get(vtkDataObject::DATA_NUMBER_OF_GHOST_LEVELS())
    : 0;
  RGMC_CHECK(made == levels, what << ": " << made << " ghost levels recorded, not " << levels);
}

void CheckMarks()
{
  struct Case
  {
    int Extent[6], Owned[6], Levels;
  };
  const Case cases[] = {
    { { 0, 9, 0, 7, 0, 11 }, { 0, 9, 0, 7, 3, 8 }, 3 },    // an inner slab
    { { 0, 9, 0, 7, 0, 9 }, { 0, 9, 0, 7, 0, 8 }, 1 },     // the first slab
    { { 0, 9, 0, 7, 4, 11 }, { 0, 9, 0, 7, 5, 11 }, 1 },   // the last slab
    { { 2, 12, 0, 9, 5, 15 }, { 4, 10, 1, 9, 6, 13 }, 2 }, // ghosts along every axis
    { { 0, 9, 0, 9, 0, 19 }, { 0, 9, 0, 9, 2, 17 }, 2 },   // two levels
    { { 0, 9, 0, 0, 0, 11 }, { 0, 9, 0, 0, 2, 7 }, 4 },    // one row of points along y
    { { 3, 3, 0, 5, 0, 5 }, { 3, 3, 0, 5, 1, 4 }, 1 },     // one column along x
    { { 0, 4, 0, 4, 0, 4 }, { 0, 4, 0, 4, 0, 4 }, 0 },     // owned whole: no arrays
    { { 0, 9, 0, 7, 0, 11 }, { 0, 9, 0, 7, 5, 4 }, 7 },    // owning nothing (a VOI's edge)
  };
  for (const Case& c : cases)
  {
    CheckMarks(c.Extent, c.Owned, c.Levels);
  }
}

void CheckSlabs()
{
  const int whole[6] = { 0, 20, 0, 15, 0, 12 };
  vtkNew<vtkExtentTranslator> translator;
  for (int pieces : { 1, 2, 3, 5, 13, 20 })
  {
    for (int ghosts : { 0, 1, 2 })
    {
      int covered = 0, next = whole[4];
      for (int piece = 0; piece < pieces; ++piece)
      {
        const std::string what = "piece " + std::to_string(piece) + " of " +
          std::to_string(pieces) + " with " + std::to_string(ghosts) + " ghost levels";
        vtkNew<vtkInformation> info;
        info->Set(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER(), piece);
        info->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES(), pieces);
        info->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_GHOST_LEVELS(), ghosts);
        int extent[6], owned[6], expected[6], expectedOwned[6], all[6];
        std::copy(whole, whole + 6, all);
        const bool any = rgmc::SlabPiece(info, whole, extent, owned);
        const int layers = whole[5] - whole[4];
        RGMC_CHECK(any == (piece < layers), what << ": empty is " << !any);
        if (!any)
        {
          continue;
        }
        if (pieces <= layers)
        {
          translator->PieceToExtentThreadSafe(
            piece, pieces, 0, all, expectedOwned, vtkExtentTranslator::Z_SLAB_MODE, 0);
          translator->PieceToExtentThreadSafe(piece, pieces, std::max(ghosts, pieces > 1 ? 1 : 0),
            all, expected, vtkExtentTranslator::Z_SLAB_MODE, 0);
          RGMC_CHECK(
            std::equal(owned, owned + 6, expectedOwned) && std::equal(extent, extent + 6, expected),
            what << ": " << Extent(extent) << " owning " << Extent(owned)
                 << ", vtkExtentTranslator's slab " << Extent(expected) << " owning "
                 << Extent(expectedOwned));
        }
        const int levels = std::max(ghosts, 1);
        RGMC_CHECK(extent[4] == std::max(whole[4], owned[4] - levels) &&
            extent[5] == std::min(whole[5], owned[5] + levels) &&
            std::equal(extent, extent + 4, whole) && std::equal(owned, owned + 4, whole),
          what << ": " << Extent(extent) << " owning " << Extent(owned) << " is not a slab with "
               << levels << " ghost levels");
        // Point extents: neighbours share their boundary slice, and own the cells between.
        RGMC_CHECK(owned[4] == next, what << ": the owned slabs leave a gap or overlap");
        next = owned[5];
        covered += owned[5] - owned[4];
      }
      RGMC_CHECK(covered == whole[5] - whole[4] && next == whole[5],
        pieces << " pieces own " << covered << " layers of cells of " << whole[5] - whole[4]);
    }
  }
  // A VOI: the part of the slab in it.
  vtkNew<vtkInformation> info;
  info->Set(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER(), 1);
  info->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES(), 2);
  const int voi[6] = { 2, 5, 3, 9, 1, 10 };
  info->Set(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(), voi, 6);
  int extent[6], owned[6];
  const bool any = rgmc::SlabPiece(info, whole, extent, owned);
  const int expected[6] = { 2, 5, 3, 9, 5, 10 }, expectedOwned[6] = { 2, 5, 3, 9, 6, 10 };
  RGMC_CHECK(
    any && std::equal(extent, extent + 6, expected) && std::equal(owned, owned + 6, expectedOwned),
    "piece 1 of 2 in the VOI " << Extent(voi) << ": " << Extent(extent) << " owning "
                               << Extent(owned));
}

void CheckPhantomMadeOnce()
{
  const std::string what =
    "a phantom piece on " + std::to_string(vtkSMPTools::GetEstimatedNumberOfThreads()) + " threads";
  vtkNew<vtkRGPhantomSource> phantom;
  phantom->SetDimensions(30, 28, 26);
  int made = 0;
  vtkNew<vtkCallbackCommand> count;
  count->SetClientData(&made);
  count->SetCallback(
    [](vtkObject*, unsigned long, void* data, void*) { ++*static_cast<int*>(data); });
  phantom->AddObserver(vtkCommand::StartEvent, count);
  phantom->UpdatePiece(1, 3, 0);
  phantom->UpdatePiece(1, 3, 1);
  RGMC_CHECK(made == 1,
    what << " asked for again with one ghost level was made " << made << " times, not once");
  vtkImageData* piece = phantom->GetOutput();
  int extent[6], owned[6];
  piece->GetExtent(extent);
  const int whole[6] = { 0, 29, 0, 27, 0, 25 };
  vtkNew<vtkExtentTranslator> translator;
  int all[6];
  std::copy(whole, whole + 6, all);
  translator->PieceToExtentThreadSafe(1, 3, 0, all, owned, vtkExtentTranslator::Z_SLAB_MODE, 0);
  vtkNew<vtkImageData> marked;
  marked->SetExtent(extent);
  marked->GenerateGhostArray(owned);
  RGMC_CHECK(SameGhosts(Ghosts(piece->GetPointData()), Ghosts(marked->GetPointData())) &&
      SameGhosts(Ghosts(piece->GetCellData()), Ghosts(marked->GetCellData())),
    what << ": its ghost marks differ from vtkDataSet::GenerateGhostArray's");
  vtkNew<vtkRGPhantomSource> fresh;
  fresh->SetDimensions(30, 28, 26);
  fresh->UpdateExtent(extent);
  auto* a = vtkShortArray::SafeDownCast(piece->GetPointData()->GetScalars());
  auto* b = vtkShortArray::SafeDownCast(fresh->GetOutput()->GetPointData()->GetScalars());
  RGMC_CHECK(a && b && a->GetNumberOfValues() == b->GetNumberOfValues() &&
      std::equal(a->GetPointer(0), a->GetPointer(0) + a->GetNumberOfValues(), b->GetPointer(0)),
    what << " " << Extent(extent) << " differs from a fresh phantom's same extent");
  phantom->UpdatePiece(1, 3, 2);
  RGMC_CHECK(made == 2, what << " asked for with two ghost levels was not made again");
}

} // namespace

int main()
{
  rgmc_test::AllowThreads(64);
  for (int threads : { 1, 16 })
  {
    vtkSMPTools::LocalScope(vtkSMPTools::Config{ threads, "STDThread", false },
      [&]()
      {
        CheckMarks();
        CheckPhantomMadeOnce();
      });
  }
  CheckSlabs();
  return rgmc_test::Result("TestVolumePieces");
}

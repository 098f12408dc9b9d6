// The phantom asked for a piece and then for the same piece with ghost layers (as ParaView does
// once RG Marching Cubes needs them) copies the slices it made already: the result must be the
// piece a fresh phantom makes, for every piece of 1-4 (ParaView's pieces: extents from
// vtkExtentTranslator, in slabs and in blocks) and on 1 and 16 threads; and after a change (the
// noise level) nothing old may be copied.
#include "rgmcCheck.h"
#include "vtkRGPhantomSource.h"

#include "vtkExtentTranslator.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkSMPTools.h"
#include "vtkShortArray.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>
#include <string>

namespace
{

int Mode = vtkExtentTranslator::BLOCK_MODE;

vtkSmartPointer<vtkImageData> Piece(vtkRGPhantomSource* phantom, int piece, int pieces, int ghosts)
{
  phantom->UpdateInformation();
  int whole[6], extent[6];
  phantom->GetOutputInformation(0)->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole);
  vtkNew<vtkExtentTranslator> translator;
  translator->PieceToExtentThreadSafe(piece, pieces, ghosts, whole, extent, Mode, 0);
  phantom->UpdateExtent(extent);
  auto copy = vtkSmartPointer<vtkImageData>::New();
  copy->DeepCopy(phantom->GetOutput());
  return copy;
}

bool Same(vtkImageData* a, vtkImageData* b)
{
  int ea[6], eb[6];
  a->GetExtent(ea);
  b->GetExtent(eb);
  auto* va = vtkShortArray::SafeDownCast(a->GetPointData()->GetScalars());
  auto* vb = vtkShortArray::SafeDownCast(b->GetPointData()->GetScalars());
  return std::equal(ea, ea + 6, eb) && va && vb &&
    va->GetNumberOfValues() == vb->GetNumberOfValues() &&
    std::equal(va->GetPointer(0), va->GetPointer(0) + va->GetNumberOfValues(), vb->GetPointer(0));
}

vtkSmartPointer<vtkRGPhantomSource> NewPhantom(double noise)
{
  auto phantom = vtkSmartPointer<vtkRGPhantomSource>::New();
  phantom->SetDimensions(40, 36, 30);
  phantom->SetNoiseLevel(noise);
  return phantom;
}

} // namespace

void CheckPieces(int mode)
{
  Mode = mode;
  const char* split = mode == vtkExtentTranslator::BLOCK_MODE ? " (blocks)" : " (slabs)";
  for (int pieces = 1; pieces <= 4; ++pieces)
  {
    for (int piece = 0; piece < pieces; ++piece)
    {
      const std::string what = "piece " + std::to_string(piece) + " of " + std::to_string(pieces) +
        split + " on " + std::to_string(vtkSMPTools::GetEstimatedNumberOfThreads()) + " threads";
      auto phantom = NewPhantom(12);
      Piece(phantom, piece, pieces, 0);
      auto ghosted = Piece(phantom, piece, pieces, 1);
      RGMC_CHECK(Same(ghosted, Piece(NewPhantom(12), piece, pieces, 1)),
        what << ": with ghost layers after the piece differs from a fresh phantom's");
      phantom->SetNoiseLevel(30);
      RGMC_CHECK(Same(Piece(phantom, piece, pieces, 1), Piece(NewPhantom(30), piece, pieces, 1)),
        what << ": after a change of the noise level it differs from a fresh phantom's");
    }
  }
}

int main()
{
  for (int threads : { 1, 16 })
  {
    vtkSMPTools::LocalScope(vtkSMPTools::Config{ threads, "STDThread", false },
      [&]()
      {
        CheckPieces(vtkExtentTranslator::Z_SLAB_MODE);
        CheckPieces(vtkExtentTranslator::BLOCK_MODE);
      });
  }
  return rgmc_test::Result("TestPhantomPieces");
}

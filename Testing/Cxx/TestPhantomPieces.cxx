// The phantom's voxels are a contract (every documented count and fingerprint depends on them):
// - each voxel is its definition, Evaluate at the voxel's point plus the noise, clamped and
//   rounded (rgmcPhantomNoise.h), although rows skip the air around the head and Evaluate skips
//   the shapes far from the voxel; and the rounding is std::lround's;
// - whole volumes hash to what the phantom made before those shortcuts (2347b34), so a shortcut
//   inside Evaluate that changed a voxel fails too;
// - a piece asked for again with ghost layers (as ParaView does once RG Marching Cubes needs
//   them) copies the slices it made already: the result must be the piece a fresh phantom makes,
//   for every piece of 1-4 (ParaView's pieces: extents from vtkExtentTranslator, in slabs and in
//   blocks); and after a change (the noise level) nothing old may be copied.
// All on 1 and 16 threads.
#include "rgmcCheck.h"
#include "rgmcPhantomNoise.h"
#include "rgmcThreadCompare.h"
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
#include <cmath>
#include <cstdint>
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

vtkShortArray* Voxels(vtkImageData* image)
{
  return vtkShortArray::SafeDownCast(image->GetPointData()->GetScalars());
}

/// Sum of the voxels (as uint16) times 0x100000001B3^index, modulo 2^64.
std::uint64_t Hash(vtkShortArray* values)
{
  std::uint64_t hash = 0, weight = 1;
  for (vtkIdType n = 0; n < values->GetNumberOfValues(); ++n)
  {
    hash += std::uint64_t(std::uint16_t(values->GetValue(n))) * weight;
    weight *= 0x100000001B3ull;
  }
  return hash;
}

} // namespace

void CheckRounding()
{
  int wrong = 0;
  auto check = [&](double x)
  {
    const long expected = std::lround(std::max(-1024.0, std::min(3071.0, x)));
    wrong += rgmc::phantom::Voxel(x) != expected ? 1 : 0;
  };
  for (int eighth = -1100 * 8; eighth <= 3100 * 8; ++eighth)
  {
    const double x = eighth / 8.0;
    check(x);
    check(std::nextafter(x, -1e9));
    check(std::nextafter(x, 1e9));
  }
  check(-0.0);
  check(0.49999999999999994);
  check(-0.49999999999999994);
  RGMC_CHECK(wrong == 0, wrong << " values rounded otherwise than std::lround rounds them");
}

void CheckDefinition(int nx, int ny, int nz, double fieldOfView, double noise, int seed)
{
  vtkNew<vtkRGPhantomSource> phantom;
  phantom->SetDimensions(nx, ny, nz);
  phantom->SetFieldOfView(fieldOfView);
  phantom->SetNoiseLevel(noise);
  phantom->SetRandomSeed(seed);
  phantom->Update();
  vtkImageData* image = phantom->GetOutput();
  vtkShortArray* values = Voxels(image);
  vtkIdType wrong = 0, air = 0;
  for (int k = 0; k < nz; ++k)
  {
    for (int j = 0; j < ny; ++j)
    {
      for (int i = 0; i < nx; ++i)
      {
        double p[3];
        const vtkIdType index = (vtkIdType(k) * ny + j) * nx + i;
        image->GetPoint(index, p);
        const double value = phantom->Evaluate(p);
        air += value == -1000.0 ? 1 : 0;
        const short expected = noise > 0
          ? rgmc::phantom::NoisyVoxel(value, noise, std::uint64_t(index), seed)
          : rgmc::phantom::Voxel(value);
        wrong += values->GetValue(index) != expected ? 1 : 0;
      }
    }
  }
  RGMC_CHECK(wrong == 0,
    wrong << " voxels of the " << nx << " x " << ny << " x " << nz << " phantom (field of view "
          << fieldOfView << ", noise " << noise << ") differ from their definition");
  RGMC_CHECK(air > 0 && air < values->GetNumberOfValues(),
    "the " << nx << " x " << ny << " x " << nz << " phantom should hold air and the head");
}

void CheckHashes()
{
  struct Volume
  {
    int Dimensions[3];
    double Noise;
    int Seed;
    std::uint64_t Hash; // made by 2347b34's phantom, a voxel at a time
  };
  const Volume volumes[] = { { { 64, 64, 64 }, 12, 1, 0x0b7282f98cdb9590ull },
    { { 97, 80, 61 }, 12, 7, 0x20dc7914b2a54413ull },
    { { 50, 50, 50 }, 1000, 3, 0x651925c37ffb8013ull },
    { { 64, 64, 64 }, 0, 1, 0xacc586e22e7453e5ull },
    { { 200, 180, 40 }, 12, -5, 0x62296b750f39e3c3ull } };
  for (const Volume& volume : volumes)
  {
    vtkNew<vtkRGPhantomSource> phantom;
    phantom->SetDimensions(volume.Dimensions[0], volume.Dimensions[1], volume.Dimensions[2]);
    phantom->SetNoiseLevel(volume.Noise);
    phantom->SetRandomSeed(volume.Seed);
    phantom->Update();
    RGMC_CHECK(Hash(Voxels(phantom->GetOutput())) == volume.Hash,
      "the " << volume.Dimensions[0] << " x " << volume.Dimensions[1] << " x "
             << volume.Dimensions[2] << " phantom (noise " << volume.Noise << ", seed "
             << volume.Seed << ") is not the one made before");
  }
}

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
  rgmc_test::AllowThreads(64);
  CheckRounding();
  for (int threads : { 1, 16 })
  {
    vtkSMPTools::LocalScope(vtkSMPTools::Config{ threads, "STDThread", false },
      [&]()
      {
        CheckDefinition(160, 30, 200, 240, 12, 3);
        CheckDefinition(40, 70, 33, 170, 0, 1);
        CheckDefinition(33, 31, 90, 300, 1000, -2);
        CheckHashes();
        CheckPieces(vtkExtentTranslator::Z_SLAB_MODE);
        CheckPieces(vtkExtentTranslator::BLOCK_MODE);
      });
  }
  return rgmc_test::Result("TestPhantomPieces");
}

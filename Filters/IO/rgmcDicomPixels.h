// Decoding the pixel data of one DICOM file on the rank whose slab holds it, and reading a
// decoded frame's samples; the range of the rescaled samples, which decides the output type.
#ifndef rgmcDicomPixels_h
#define rgmcDicomPixels_h

#include "rgmcDicomStack.h"
#include "rgmcDicomTags.h"

#include "vtkType.h"

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace rgmc
{

/// The range of the rescaled samples, whether they are all integers, and whether float cannot
/// hold the stored values.
struct SampleRange
{
  bool Integral = true;
  double Lo = VTK_DOUBLE_MAX, Hi = VTK_DOUBLE_MIN;
  bool Wide = false;
};
/// PASS 6 of the scan, for one sample per pixel: the stored range under every slice's rescale.
SampleRange RescaledRange(const DicomHeader& first, const std::vector<DicomSlice>& slices);

/// PASS 6 of the scan, for colour images (unscaled): the type of their stored samples.
int ColourScalarType(int bitsAllocated);

/// The pixel data of the file decoded last (a multi-frame file serves several slices).
struct DecodedFile
{
  std::string Path;                 // empty before the first file
  std::vector<unsigned char> Bytes; // every frame, samples in this host's byte order
  int Planar = 0; // the planar configuration of Bytes (a codec may interleave samples)
};

/// Bytes of one decoded frame: decoders give full frames; native YBR_FULL_422 stays subsampled
/// (FrameLayout expands it).
std::size_t DecodedFrameBytes(const PixelDescription& pixels);

/// Decodes every frame of the file at `path` into `decoded`; false with `message` (naming the
/// file) when it is truncated, corrupt or not decodable. The file may have changed since the
/// scan: GDCM sees it only if its structure holds.
bool DecodeFile(const std::string& path, const PixelDescription& pixels, DecodedFile& decoded,
  std::string& message);

/// Where sample c of pixel (i, j) lies in a decoded frame, counted in samples: interleaved,
/// planar (planar configuration 1 stores each colour plane after the other) or, for native
/// YBR_FULL_422, subsampled (Y0 Y1 Cb Cr for each pair of pixels of a row).
class FrameLayout
{
public:
  FrameLayout(const PixelDescription& pixels, int decodedPlanar)
    : Columns(static_cast<std::size_t>(pixels.Columns))
    , Samples(pixels.Samples)
    , PixelsPerFrame(static_cast<std::size_t>(pixels.Rows) * pixels.Columns)
    , Planar(pixels.Samples == 3 && decodedPlanar == 1)
    , Subsampled(
        !pixels.Encapsulated && pixels.Samples == 3 && pixels.Photometric == "YBR_FULL_422")
  {
  }

  std::size_t Index(int i, int j, int c) const
  {
    if (this->Subsampled)
    {
      const std::size_t pair = (static_cast<std::size_t>(j) * this->Columns + (i & ~1)) * 2;
      return c == 0 ? pair + (i & 1) : pair + 1 + c;
    }
    const std::size_t pixel = static_cast<std::size_t>(j) * this->Columns + i;
    return this->Planar ? c * this->PixelsPerFrame + pixel : pixel * this->Samples + c;
  }

private:
  std::size_t Columns;
  int Samples;
  std::size_t PixelsPerFrame;
  bool Planar;
  bool Subsampled;
};

/// The stored value of the sample at `index` of a decoded frame: its stored bits, sign-extended
/// from the highest one when the samples are signed.
inline double StoredSample(
  const PixelDescription& pixels, const unsigned char* frame, std::size_t index)
{
  if (pixels.BitsAllocated == 1)
  {
    return (frame[index / 8] >> (index % 8)) & 1;
  }
  const std::size_t bytes = pixels.BitsAllocated / 8;
  std::uint32_t raw = 0;
  std::memcpy(&raw, frame + index * bytes, bytes); // little endian host, as GDCM's
  if (pixels.PixelRepresentation)
  {
    const unsigned width32 = 32 - pixels.BitsStored;
    return static_cast<double>(static_cast<std::int32_t>(raw << width32) >> width32);
  }
  return pixels.BitsStored >= 32 ? raw : (raw & ((std::uint32_t(1) << pixels.BitsStored) - 1));
}

} // namespace rgmc

#endif

// Decoding the pixel data of one DICOM file: native data read straight from the file, RLE
// decoded here, JPEG headers checked before GDCM's codecs see them, everything else through GDCM
// given the header scan's pixel description; and the range of the rescaled samples.
#include "rgmcDicomPixels.h"

#include "rgmcDicomStructure.h"

#include <gdcmDataSet.h>
#include <gdcmFile.h>
#include <gdcmImage.h>
#include <gdcmPhotometricInterpretation.h>
#include <gdcmPixelFormat.h>
#include <gdcmReader.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

namespace rgmc
{

/// PASS 6, for one sample per pixel: the stored range under every slice's rescale.
SampleRange RescaledRange(const DicomHeader& first, const std::vector<DicomSlice>& slices)
{
  SampleRange range;
  range.Wide = first.BitsStored > 24;
  const double storedLo = first.PixelRepresentation ? -std::ldexp(1.0, first.BitsStored - 1) : 0.0;
  const double storedHi = first.PixelRepresentation ? std::ldexp(1.0, first.BitsStored - 1) - 1
                                                    : std::ldexp(1.0, first.BitsStored) - 1;
  for (const DicomSlice& s : slices)
  {
    range.Integral =
      range.Integral && s.Slope == std::floor(s.Slope) && s.Intercept == std::floor(s.Intercept);
    const double a = s.Slope * storedLo + s.Intercept, b = s.Slope * storedHi + s.Intercept;
    range.Lo = std::min(range.Lo, std::min(a, b));
    range.Hi = std::max(range.Hi, std::max(a, b));
  }
  return range;
}

/// PASS 6, for colour images (unscaled): the type of their stored samples.
int ColourScalarType(int bitsAllocated)
{
  return bitsAllocated == 8 ? VTK_UNSIGNED_CHAR
                            : (bitsAllocated == 16 ? VTK_UNSIGNED_SHORT : VTK_UNSIGNED_INT);
}

namespace
{

/// Native pixel data: read straight from the file, swapped to this host's byte order. The byte
/// order applies to the value's words: 8-bit samples in an OW value come in swapped pairs in big
/// endian (pydicom 2.4's SC_rgb_small_odd_big_endian.dcm), the last one with the value's padding
/// byte when the sample count is odd.
bool ReadNativePixels(const std::string& path, const PixelDescription& pixels,
  const rgmc::DicomStructure& structure, std::size_t frameBytes, DecodedFile& decoded)
{
  const std::size_t expected = frameBytes * pixels.Frames;
  int word = pixels.BitsAllocated == 1 ? 1 : pixels.BitsAllocated / 8; // bits stay in bytes
  if (pixels.BitsAllocated == 8 && structure.PixelDataWords)
  {
    word = 2;
  }
  const bool swap = structure.BigEndian && word > 1;
  const std::size_t padded =
    swap && expected % word != 0 && structure.PixelDataLength >= expected + word - expected % word
    ? expected + word - expected % word
    : expected;
  std::vector<unsigned char>& buffer = decoded.Bytes;
  std::ifstream file(path, std::ios::binary);
  buffer.assign(padded, 0);
  file.seekg(static_cast<std::streamoff>(structure.PixelDataOffset));
  const bool read = static_cast<bool>(
    file.read(reinterpret_cast<char*>(buffer.data()), static_cast<std::streamsize>(padded)));
  if (swap)
  {
    for (std::size_t b = 0; b + word <= buffer.size(); b += word)
    {
      std::reverse(buffer.begin() + b, buffer.begin() + b + word);
    }
  }
  buffer.resize(expected);
  decoded.Planar = pixels.Planar;
  return read;
}

/// RLE Lossless, decoded here: GDCM 3.0.21 orders the bytes of 16- and 32-bit colour RLE
/// wrongly. False with `problem` when the pixel data is malformed.
bool DecodeRle(const std::string& path, const PixelDescription& pixels,
  const rgmc::DicomStructure& structure, std::size_t frameBytes, DecodedFile& decoded,
  std::string& problem)
{
  const std::size_t pixelsPerFrame = static_cast<std::size_t>(pixels.Rows) * pixels.Columns;
  bool ok = structure.Fragments.size() == static_cast<std::size_t>(pixels.Frames);
  problem = "it has " + std::to_string(structure.Fragments.size()) + " RLE fragments for " +
    std::to_string(pixels.Frames) + " frames";
  decoded.Bytes.assign(frameBytes * pixels.Frames, 0);
  for (int f = 0; ok && f < pixels.Frames; ++f)
  {
    ok = rgmc::DecodeRleFrame(path, structure.Fragments[f].first, structure.Fragments[f].second,
      pixelsPerFrame, pixels.Samples, pixels.BitsAllocated / 8,
      decoded.Bytes.data() + frameBytes * f, problem);
  }
  decoded.Planar = 0;
  return ok;
}

bool IsJpeg(int transferSyntax)
{
  return transferSyntax == gdcm::TransferSyntax::JPEGBaselineProcess1 ||
    transferSyntax == gdcm::TransferSyntax::JPEGExtendedProcess2_4 ||
    transferSyntax == gdcm::TransferSyntax::JPEGLosslessProcess14 ||
    transferSyntax == gdcm::TransferSyntax::JPEGLosslessProcess14_1;
}

/// The header of each JPEG frame (a fragment that starts with a start-of-image marker, and the
/// first fragment), checked before GDCM's codec sees it; false with `problem` when one is broken.
bool CheckJpegFrames(const std::string& path, const PixelDescription& pixels,
  const rgmc::DicomStructure& structure, std::string& problem)
{
  for (const auto& fragment : structure.Fragments)
  {
    std::string why;
    unsigned char start[2] = { 0, 0 };
    std::ifstream file(path, std::ios::binary);
    file.seekg(static_cast<std::streamoff>(fragment.first));
    file.read(reinterpret_cast<char*>(start), 2);
    const bool frameStart = start[0] == 0xff && start[1] == 0xd8;
    if ((frameStart || &fragment == &structure.Fragments.front()) &&
      !rgmc::CheckJpegHeader(path, fragment.first, fragment.second, pixels.Rows, pixels.Columns,
        pixels.Samples, pixels.BitsStored, why))
    {
      problem = why;
      return false;
    }
  }
  return true;
}

/// The pixel data of `file` as a GDCM image, described by the header scan (not guessed).
void DescribeImage(const PixelDescription& pixels, const gdcm::File& file, gdcm::Image& image)
{
  image.SetNumberOfDimensions(pixels.Frames > 1 ? 3 : 2);
  image.SetDimension(0, static_cast<unsigned>(pixels.Columns));
  image.SetDimension(1, static_cast<unsigned>(pixels.Rows));
  if (pixels.Frames > 1)
  {
    image.SetDimension(2, static_cast<unsigned>(pixels.Frames));
  }
  image.SetPixelFormat(gdcm::PixelFormat(static_cast<unsigned short>(pixels.Samples),
    static_cast<unsigned short>(pixels.BitsAllocated),
    static_cast<unsigned short>(pixels.BitsStored),
    static_cast<unsigned short>(pixels.BitsStored - 1),
    static_cast<unsigned short>(pixels.PixelRepresentation)));
  const gdcm::PhotometricInterpretation::PIType pi =
    gdcm::PhotometricInterpretation::GetPIType(pixels.Photometric.c_str());
  image.SetPhotometricInterpretation(pi == gdcm::PhotometricInterpretation::PI_END
      ? gdcm::PhotometricInterpretation(gdcm::PhotometricInterpretation::MONOCHROME2)
      : gdcm::PhotometricInterpretation(pi));
  if (pixels.Samples == 3)
  {
    image.SetPlanarConfiguration(static_cast<unsigned>(pixels.Planar));
  }
  image.SetTransferSyntax(file.GetHeader().GetDataSetTransferSyntax());
  image.SetDataElement(file.GetDataSet().GetDataElement(PixelDataTag));
}

/// GDCM's parser and codecs, given the pixel description of the header scan (its ImageReader
/// also guesses geometry, and asserts on some valid files while doing so). Bytes after the last
/// element (padding, junk) are not GDCM's to parse: it gets the data set alone.
bool DecodeWithGdcm(const std::string& path, const PixelDescription& pixels,
  const rgmc::DicomStructure& structure, std::size_t frameBytes, DecodedFile& decoded)
{
  gdcm::Reader reader;
  std::istringstream dataSet;
  if (structure.TrailingBytes > 0)
  {
    std::string bytes(static_cast<std::size_t>(structure.DataSetEnd), '\0');
    std::ifstream file(path, std::ios::binary);
    file.read(&bytes[0], static_cast<std::streamsize>(bytes.size()));
    dataSet.str(bytes);
    reader.SetStream(dataSet);
  }
  else
  {
    reader.SetFileName(path.c_str());
  }
  try
  {
    if (!reader.Read() || !reader.GetFile().GetDataSet().FindDataElement(PixelDataTag))
    {
      return false;
    }
    gdcm::Image image;
    DescribeImage(pixels, reader.GetFile(), image);
    decoded.Bytes.assign(
      std::max<std::size_t>(image.GetBufferLength(), frameBytes * pixels.Frames), 0);
    const bool ok = image.GetBuffer(reinterpret_cast<char*>(decoded.Bytes.data()));
    // A codec may hand back interleaved samples whatever the header said.
    decoded.Planar = pixels.Samples == 3 ? static_cast<int>(image.GetPlanarConfiguration()) : 0;
    return ok;
  }
  catch (...)
  {
    return false;
  }
}

} // namespace

/// Bytes of one decoded frame: decoders give full frames; native YBR_FULL_422 stays subsampled
/// (FrameLayout expands it).
std::size_t DecodedFrameBytes(const PixelDescription& pixels)
{
  return pixels.Encapsulated
    ? NativeFrameBytes(pixels.Rows, pixels.Columns, pixels.Samples, pixels.BitsAllocated, "")
    : NativeFrameBytes(
        pixels.Rows, pixels.Columns, pixels.Samples, pixels.BitsAllocated, pixels.Photometric);
}

/// Decodes every frame of the file at `path` into `decoded`; false with `message` (naming the
/// file) when it is truncated, corrupt or not decodable. The file may have changed since the
/// scan: GDCM sees it only if its structure holds.
bool DecodeFile(const std::string& path, const PixelDescription& pixels, DecodedFile& decoded,
  std::string& message)
{
  const rgmc::DicomStructure structure = rgmc::WalkDicom(path);
  if (!structure.Valid || !structure.HasPixelData ||
    structure.PixelDataEncapsulated != pixels.Encapsulated)
  {
    message = path + " is truncated or corrupt: " +
      (structure.Problem.empty() ? std::string("its pixel data changed since the header scan")
                                 : structure.Problem);
    return false;
  }
  const std::size_t frameBytes = DecodedFrameBytes(pixels);
  const std::size_t expected = frameBytes * pixels.Frames;
  if (!pixels.Encapsulated && structure.PixelDataLength < expected)
  {
    message = path + " is truncated: its pixel data has " +
      std::to_string(structure.PixelDataLength) + " bytes of the " + std::to_string(expected) +
      " its header announces";
    return false;
  }
  bool ok = false;
  std::string problem;
  if (!pixels.Encapsulated && structure.PixelDataOffset > 0)
  {
    ok = ReadNativePixels(path, pixels, structure, frameBytes, decoded);
  }
  else if (pixels.TransferSyntax == gdcm::TransferSyntax::RLELossless && pixels.BitsAllocated >= 8)
  {
    if (!DecodeRle(path, pixels, structure, frameBytes, decoded, problem))
    {
      message = path + " has malformed RLE pixel data: " + problem;
      return false;
    }
    ok = true;
  }
  else if (IsJpeg(pixels.TransferSyntax) && !CheckJpegFrames(path, pixels, structure, problem))
  {
    message = path + " has broken JPEG data: " + problem;
    return false;
  }
  else
  {
    ok = DecodeWithGdcm(path, pixels, structure, frameBytes, decoded);
  }
  if (!ok)
  {
    message = path + " cannot be decoded by GDCM (transfer syntax " +
      TransferSyntaxName(gdcm::TransferSyntax::GetTSString(
        static_cast<gdcm::TransferSyntax::TSType>(pixels.TransferSyntax))) +
      "): truncated or corrupt pixel data";
    return false;
  }
  decoded.Path = path;
  return true;
}

} // namespace rgmc

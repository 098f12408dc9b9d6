// Reading and checking one DICOM file's tags into a header record (rgmc::DicomHeader): GDCM's
// parser, stopping before the pixel data, runs only on files whose structure rgmc::WalkDicom
// has found sound.
#include "rgmcDicomTags.h"

#include "rgmcDicomStructure.h"

#include <gdcmByteValue.h>
#include <gdcmDataElement.h>
#include <gdcmDataSet.h>
#include <gdcmFile.h>
#include <gdcmReader.h>
#include <gdcmTrace.h>
#include <gdcmUIDs.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace rgmc
{

const gdcm::Tag PixelDataTag(0x7fe0, 0x0010);

QuietGDCM::QuietGDCM()
{
  gdcm::Trace::WarningOff();
  gdcm::Trace::ErrorOff();
  gdcm::Trace::DebugOff();
}

namespace
{

// Tags the scan reads.
const gdcm::Tag SeriesUIDTag(0x0020, 0x000e);
const gdcm::Tag SeriesDescriptionTag(0x0008, 0x103e);
const gdcm::Tag ModalityTag(0x0008, 0x0060);
const gdcm::Tag PositionTag(0x0020, 0x0032);
const gdcm::Tag OrientationTag(0x0020, 0x0037);
const gdcm::Tag PixelSpacingTag(0x0028, 0x0030);
const gdcm::Tag ImagerPixelSpacingTag(0x0018, 0x1164);
const gdcm::Tag RowsTag(0x0028, 0x0010);
const gdcm::Tag ColumnsTag(0x0028, 0x0011);
const gdcm::Tag SamplesTag(0x0028, 0x0002);
const gdcm::Tag PlanarTag(0x0028, 0x0006);
const gdcm::Tag PhotometricTag(0x0028, 0x0004);
const gdcm::Tag BitsAllocatedTag(0x0028, 0x0100);
const gdcm::Tag BitsStoredTag(0x0028, 0x0101);
const gdcm::Tag PixelRepresentationTag(0x0028, 0x0103);
const gdcm::Tag FramesTag(0x0028, 0x0008);
const gdcm::Tag InterceptTag(0x0028, 0x1052);
const gdcm::Tag SlopeTag(0x0028, 0x1053);
const gdcm::Tag FrameOffsetsTag(0x3004, 0x000c);
const gdcm::Tag SpacingBetweenSlicesTag(0x0018, 0x0088);
const gdcm::Tag SliceThicknessTag(0x0018, 0x0050);

std::string Trim(std::string s)
{
  while (!s.empty() && (s.back() == ' ' || s.back() == '\0'))
  {
    s.pop_back();
  }
  std::size_t first = 0;
  while (first < s.size() && s[first] == ' ')
  {
    ++first;
  }
  return s.substr(first);
}

/// The raw value of an element (text for string VRs), empty when absent.
std::string RawValue(const gdcm::DataSet& ds, const gdcm::Tag& tag, bool& present)
{
  present = false;
  if (!ds.FindDataElement(tag))
  {
    return std::string();
  }
  const gdcm::DataElement& de = ds.GetDataElement(tag);
  const gdcm::ByteValue* bv = de.GetByteValue();
  if (!bv || !bv->GetPointer())
  {
    return std::string();
  }
  present = true;
  return std::string(bv->GetPointer(), bv->GetLength());
}

std::string Text(const gdcm::DataSet& ds, const gdcm::Tag& tag)
{
  bool present;
  return Trim(RawValue(ds, tag, present));
}

/// Numbers of a DS or IS value ("1.5\-2\3"); false when one is not a finite number.
bool Numbers(const std::string& text, std::vector<double>& values)
{
  values.clear();
  std::stringstream parts(text);
  for (std::string part; std::getline(parts, part, '\\');)
  {
    part = Trim(part);
    if (part.empty())
    {
      return false;
    }
    char* end = nullptr;
    const double v = std::strtod(part.c_str(), &end);
    if (*end != '\0' || !std::isfinite(v))
    {
      return false;
    }
    values.push_back(v);
  }
  return !values.empty();
}

/// An unsigned short (US) element; GDCM keeps binary values little endian in memory.
bool UnsignedShort(const gdcm::DataSet& ds, const gdcm::Tag& tag, int& value)
{
  bool present;
  const std::string raw = RawValue(ds, tag, present);
  if (!present || raw.size() < 2)
  {
    return false;
  }
  value = static_cast<unsigned char>(raw[0]) | (static_cast<unsigned char>(raw[1]) << 8);
  return true;
}

bool DecodableTransferSyntax(int ts)
{
  switch (ts)
  {
    case gdcm::TransferSyntax::ImplicitVRLittleEndian:
    case gdcm::TransferSyntax::ImplicitVRBigEndianPrivateGE:
    case gdcm::TransferSyntax::ExplicitVRLittleEndian:
    case gdcm::TransferSyntax::DeflatedExplicitVRLittleEndian:
    case gdcm::TransferSyntax::ExplicitVRBigEndian:
    case gdcm::TransferSyntax::JPEGBaselineProcess1:
    case gdcm::TransferSyntax::JPEGExtendedProcess2_4:
    case gdcm::TransferSyntax::JPEGLosslessProcess14:
    case gdcm::TransferSyntax::JPEGLosslessProcess14_1:
    case gdcm::TransferSyntax::JPEGLSLossless:
    case gdcm::TransferSyntax::JPEGLSNearLossless:
    case gdcm::TransferSyntax::JPEG2000Lossless:
    case gdcm::TransferSyntax::JPEG2000:
    case gdcm::TransferSyntax::RLELossless:
      return true;
    default:
      return false;
  }
}

/// True when the file starts as a DICOM Part 10 file does (128 bytes, then "DICM").
bool HasDicomMark(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  char head[132];
  return in.read(head, 132) && std::memcmp(head + 128, "DICM", 4) == 0;
}

/// The pixel description, the series and the transfer syntax of a file whose header GDCM read;
/// false with `problem` when its NumberOfFrames is impossible.
bool ReadPixelTags(const gdcm::File& file, DicomHeader& h, std::string& problem)
{
  const gdcm::DataSet& ds = file.GetDataSet();
  const gdcm::TransferSyntax& ts = file.GetHeader().GetDataSetTransferSyntax();
  h.TransferSyntax = ts;
  h.TransferSyntaxUID = Trim(Text(file.GetHeader(), gdcm::Tag(0x0002, 0x0010)));
  if (h.TransferSyntaxUID.empty() && ts.IsValid())
  {
    h.TransferSyntaxUID = gdcm::TransferSyntax::GetTSString(ts);
  }
  h.SeriesUID = Text(ds, SeriesUIDTag);
  h.SeriesDescription = Text(ds, SeriesDescriptionTag);
  h.Modality = Text(ds, ModalityTag);
  UnsignedShort(ds, SamplesTag, h.Samples);
  UnsignedShort(ds, PlanarTag, h.Planar);
  h.Photometric = Text(ds, PhotometricTag);
  UnsignedShort(ds, BitsAllocatedTag, h.BitsAllocated);
  if (!UnsignedShort(ds, BitsStoredTag, h.BitsStored))
  {
    h.BitsStored = h.BitsAllocated;
  }
  UnsignedShort(ds, PixelRepresentationTag, h.PixelRepresentation);
  std::vector<double> v;
  if (Numbers(Text(ds, FramesTag), v))
  {
    if (v[0] < 1 || v[0] > 1e6 || v[0] != std::floor(v[0]))
    {
      problem = "has a NumberOfFrames of " + Text(ds, FramesTag);
      return false;
    }
    h.Frames = static_cast<int>(v[0]);
  }
  return true;
}

/// The `count` numbers of `name` (ImagePositionPatient, ImageOrientationPatient) into `values`,
/// with `present` set, when the file has them; false with `problem` when it has something else.
bool FixedNumbers(const gdcm::DataSet& ds, const gdcm::Tag& tag, const std::string& name,
  std::size_t count, double* values, bool& present, std::string& problem)
{
  std::vector<double> v;
  if (Numbers(Text(ds, tag), v))
  {
    if (v.size() != count)
    {
      problem = "has an " + name + " of " + std::to_string(v.size()) + " numbers, not " +
        std::to_string(count);
      return false;
    }
    present = true;
    std::copy(v.begin(), v.end(), values);
  }
  else if (!Text(ds, tag).empty())
  {
    problem = "has an " + name + " that is not " + std::to_string(count) + " numbers: '" +
      Text(ds, tag) + "'";
    return false;
  }
  return true;
}

/// Where the file's slice lies and how its samples scale; false with `problem` when a value is
/// impossible.
bool ReadSliceTags(const gdcm::DataSet& ds, DicomHeader& h, std::string& problem)
{
  if (!FixedNumbers(
        ds, PositionTag, "ImagePositionPatient", 3, h.Position, h.HasPosition, problem) ||
    !FixedNumbers(
      ds, OrientationTag, "ImageOrientationPatient", 6, h.Orientation, h.HasOrientation, problem))
  {
    return false;
  }
  std::vector<double> v;
  if (Numbers(Text(ds, PixelSpacingTag), v) || Numbers(Text(ds, ImagerPixelSpacingTag), v))
  {
    if (v.size() != 2 || v[0] <= 0 || v[1] <= 0)
    {
      problem = "has a PixelSpacing that is not two positive numbers";
      return false;
    }
    h.HasSpacing = true;
    h.PixelSpacing[0] = v[0];
    h.PixelSpacing[1] = v[1];
  }
  if (Numbers(Text(ds, SlopeTag), v))
  {
    h.Slope = v[0];
    if (h.Slope == 0)
    {
      problem = "has a RescaleSlope of 0";
      return false;
    }
  }
  if (Numbers(Text(ds, InterceptTag), v))
  {
    h.Intercept = v[0];
  }
  if (Numbers(Text(ds, FrameOffsetsTag), v))
  {
    h.FrameOffsets = v;
  }
  if (Numbers(Text(ds, SpacingBetweenSlicesTag), v) && v[0] > 0)
  {
    h.SpacingBetweenSlices = v[0];
  }
  if (Numbers(Text(ds, SliceThicknessTag), v) && v[0] > 0)
  {
    h.SliceThickness = v[0];
  }
  return true;
}

} // namespace

/// "1.2.840.10008.1.2.4.100 (MPEG2 Main Profile @ Main Level)", for messages.
std::string TransferSyntaxName(const std::string& uid)
{
  gdcm::UIDs known;
  if (known.SetFromUID(uid.c_str()) && known.GetName())
  {
    return uid + " (" + known.GetName() + ")";
  }
  return uid;
}

/// Reads one file's header (GDCM stops before the pixel data) into `h`.
DicomFileKind ReadDicomHeader(const std::string& path, DicomHeader& h, std::string& problem)
{
  h.Path = path;
  // GDCM aborts on some malformed files: it parses only files whose structure holds.
  const rgmc::DicomStructure structure = rgmc::WalkDicom(path);
  if (!structure.Dicom)
  {
    return DicomFileKind::NotDicom;
  }
  if (!structure.Valid)
  {
    problem = "is truncated or corrupt: " + structure.Problem;
    return DicomFileKind::Broken;
  }
  if (!structure.HasPixelData)
  {
    return DicomFileKind::NoImage;
  }
  h.Encapsulated = structure.PixelDataEncapsulated;
  h.PixelBytes = structure.PixelDataLength;
  if (!h.Encapsulated && structure.PixelDataDeclared > structure.PixelDataLength)
  {
    // Said before GDCM sees the file: GDCM 3.0.24 does not parse the header of a file whose
    // pixel data is cut short.
    problem = "is truncated: its pixel data has " + std::to_string(structure.PixelDataLength) +
      " bytes of the " + std::to_string(structure.PixelDataDeclared) + " its header announces";
    return DicomFileKind::Broken;
  }
  const bool marked = HasDicomMark(path);
  gdcm::Reader reader;
  reader.SetFileName(path.c_str());
  bool read = false;
  try
  {
    read = reader.ReadUpToTag(PixelDataTag);
  }
  catch (...)
  {
    read = false;
  }
  if (!read)
  {
    if (marked)
    {
      problem = "is marked as DICOM but GDCM cannot parse its header (truncated or corrupt)";
      return DicomFileKind::Broken;
    }
    return DicomFileKind::NotDicom;
  }
  const gdcm::File& file = reader.GetFile();
  const gdcm::DataSet& ds = file.GetDataSet();
  if (!ds.FindDataElement(PixelDataTag) || !UnsignedShort(ds, RowsTag, h.Rows) ||
    !UnsignedShort(ds, ColumnsTag, h.Columns))
  {
    return marked || ds.Size() > 0 ? DicomFileKind::NoImage : DicomFileKind::NotDicom;
  }
  return ReadPixelTags(file, h, problem) && ReadSliceTags(ds, h, problem) ? DicomFileKind::Image
                                                                          : DicomFileKind::Broken;
}

/// Checks of what one volume needs from a file's pixel description.
bool CheckPixelFormat(const DicomHeader& h, std::string& problem)
{
  std::ostringstream why;
  if (h.Rows < 1 || h.Columns < 1)
  {
    why << "has " << h.Rows << " rows and " << h.Columns << " columns";
  }
  else if (h.Samples != 1 && h.Samples != 3)
  {
    why << "has " << h.Samples << " samples per pixel (1 or 3 are read)";
  }
  else if (h.BitsAllocated != 1 && h.BitsAllocated != 8 && h.BitsAllocated != 16 &&
    h.BitsAllocated != 32)
  {
    why << "has " << h.BitsAllocated << " bits allocated per sample (1, 8, 16 or 32 are read)";
  }
  else if (h.BitsStored < 1 || h.BitsStored > h.BitsAllocated)
  {
    why << "stores " << h.BitsStored << " bits in " << h.BitsAllocated << " allocated";
  }
  else if (h.PixelRepresentation != 0 && h.PixelRepresentation != 1)
  {
    why << "has a PixelRepresentation of " << h.PixelRepresentation;
  }
  else if (h.Samples == 3 && h.Planar != 0 && h.Planar != 1)
  {
    why << "has a PlanarConfiguration of " << h.Planar << " (0 or 1)";
  }
  else if (!gdcm::TransferSyntax(static_cast<gdcm::TransferSyntax::TSType>(h.TransferSyntax))
              .IsValid())
  {
    why << "has the transfer syntax '" << h.TransferSyntaxUID
        << "', which GDCM does not know: unsupported transfer syntax";
  }
  else if (!DecodableTransferSyntax(h.TransferSyntax))
  {
    why << "has the transfer syntax " << TransferSyntaxName(h.TransferSyntaxUID)
        << ", which GDCM does not decode: unsupported transfer syntax";
  }
  problem = why.str();
  return problem.empty();
}

/// Bytes of one native frame. Uncompressed YBR_FULL_422 stores two luminance samples and one
/// pair of chroma samples per two pixels.
std::uint64_t NativeFrameBytes(
  int rows, int columns, int samples, int bitsAllocated, const std::string& photometric)
{
  const std::uint64_t pixels = std::uint64_t(rows) * columns;
  if (bitsAllocated == 1)
  {
    return (pixels * samples + 7) / 8;
  }
  if (samples == 3 && photometric == "YBR_FULL_422")
  {
    return pixels * 2 * (bitsAllocated / 8);
  }
  return pixels * samples * (bitsAllocated / 8);
}

std::string BaseName(const std::string& path)
{
  return std::filesystem::path(path).filename().string();
}

std::string ShortNumber(double v)
{
  char text[40];
  std::snprintf(text, sizeof(text), "%.6g", v);
  return text;
}

} // namespace rgmc

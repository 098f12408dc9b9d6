// The DICOM series reader: a header scan on rank 0 (GDCM's parser, stopping at the pixel data),
// grouping, sorting and checking; then each rank decodes the files of its own slab with GDCM.
#include "vtkRGDICOMSeriesReader.h"

#include "vtkRGPacking.h"

#include "rgmcDicomStructure.h"

#include "vtkDataArray.h"
#include "vtkMath.h"
#include "vtkObjectFactory.h"

#include <gdcmByteValue.h>
#include <gdcmDataElement.h>
#include <gdcmDataSet.h>
#include <gdcmFile.h>
#include <gdcmImage.h>
#include <gdcmPhotometricInterpretation.h>
#include <gdcmPixelFormat.h>
#include <gdcmReader.h>
#include <gdcmSequenceOfFragments.h>
#include <gdcmTag.h>
#include <gdcmTrace.h>
#include <gdcmTransferSyntax.h>
#include <gdcmUIDs.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <vector>

vtkStandardNewMacro(vtkRGDICOMSeriesReader);

namespace
{

namespace fs = std::filesystem;

// Tags the scan reads.
const gdcm::Tag PixelDataTag(0x7fe0, 0x0010);
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

/// GDCM prints its own warnings and errors to stderr; the reader reports in its own words.
struct QuietGDCM
{
  QuietGDCM()
  {
    gdcm::Trace::WarningOff();
    gdcm::Trace::ErrorOff();
    gdcm::Trace::DebugOff();
  }
};

/// What the scan keeps of one file.
struct FileHeader
{
  std::string Path, SeriesUID, SeriesDescription, Modality, TransferSyntaxUID, Photometric;
  int TransferSyntax = gdcm::TransferSyntax::TS_END;
  int Rows = 0, Columns = 0, Samples = 1, Planar = 0, BitsAllocated = 0, BitsStored = 0;
  int PixelRepresentation = 0, Frames = 1;
  bool HasPosition = false, HasOrientation = false, HasSpacing = false;
  double Position[3] = { 0, 0, 0 }, Orientation[6] = { 1, 0, 0, 0, 1, 0 };
  double PixelSpacing[2] = { 1, 1 };
  double Slope = 1, Intercept = 0;
  std::vector<double> FrameOffsets;
  double SpacingBetweenSlices = 0, SliceThickness = 0;
  double Projection = 0; // position along the slice normal
  bool Encapsulated = false;
  std::uint64_t PixelBytes = 0; // native pixel data present in the file
};

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

enum class Parsed
{
  Image,    // a DICOM file with an image
  NoImage,  // a DICOM file without pixel data (DICOMDIR, a report): not part of any volume
  NotDicom, // not DICOM at all (a README): skipped
  Broken    // marked as DICOM but unreadable: an error
};

/// Reads one file's header (GDCM stops before the pixel data) into `h`.
Parsed ParseHeader(const std::string& path, FileHeader& h, std::string& problem)
{
  h.Path = path;
  // GDCM aborts on some malformed files: it parses only files whose structure holds.
  const rgmc::DicomStructure structure = rgmc::WalkDicom(path);
  if (!structure.Dicom)
  {
    return Parsed::NotDicom;
  }
  if (!structure.Valid)
  {
    problem = "is truncated or corrupt: " + structure.Problem;
    return Parsed::Broken;
  }
  if (!structure.HasPixelData)
  {
    return Parsed::NoImage;
  }
  h.Encapsulated = structure.PixelDataEncapsulated;
  h.PixelBytes = structure.PixelDataLength;
  if (!h.Encapsulated && structure.PixelDataDeclared > structure.PixelDataLength)
  {
    // Said before GDCM sees the file: GDCM 3.0.24 (Debian sid) no longer parses the header of a
    // file whose pixel data is cut short.
    problem = "is truncated: its pixel data has " + std::to_string(structure.PixelDataLength) +
      " bytes of the " + std::to_string(structure.PixelDataDeclared) + " its header announces";
    return Parsed::Broken;
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
      return Parsed::Broken;
    }
    return Parsed::NotDicom;
  }
  const gdcm::File& file = reader.GetFile();
  const gdcm::DataSet& ds = file.GetDataSet();
  if (!ds.FindDataElement(PixelDataTag) || !UnsignedShort(ds, RowsTag, h.Rows) ||
    !UnsignedShort(ds, ColumnsTag, h.Columns))
  {
    return marked || ds.Size() > 0 ? Parsed::NoImage : Parsed::NotDicom;
  }
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
      return Parsed::Broken;
    }
    h.Frames = static_cast<int>(v[0]);
  }
  if (Numbers(Text(ds, PositionTag), v))
  {
    if (v.size() != 3)
    {
      problem = "has an ImagePositionPatient of " + std::to_string(v.size()) + " numbers, not 3";
      return Parsed::Broken;
    }
    h.HasPosition = true;
    std::copy(v.begin(), v.end(), h.Position);
  }
  else if (!Text(ds, PositionTag).empty())
  {
    problem = "has an ImagePositionPatient that is not 3 numbers: '" + Text(ds, PositionTag) + "'";
    return Parsed::Broken;
  }
  if (Numbers(Text(ds, OrientationTag), v))
  {
    if (v.size() != 6)
    {
      problem = "has an ImageOrientationPatient of " + std::to_string(v.size()) + " numbers, not 6";
      return Parsed::Broken;
    }
    h.HasOrientation = true;
    std::copy(v.begin(), v.end(), h.Orientation);
  }
  else if (!Text(ds, OrientationTag).empty())
  {
    problem =
      "has an ImageOrientationPatient that is not 6 numbers: '" + Text(ds, OrientationTag) + "'";
    return Parsed::Broken;
  }
  if (Numbers(Text(ds, PixelSpacingTag), v) || Numbers(Text(ds, ImagerPixelSpacingTag), v))
  {
    if (v.size() != 2 || v[0] <= 0 || v[1] <= 0)
    {
      problem = "has a PixelSpacing that is not two positive numbers";
      return Parsed::Broken;
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
      return Parsed::Broken;
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
  return Parsed::Image;
}

/// Checks of what one volume needs from a file's pixel description.
bool CheckPixelFormat(const FileHeader& h, std::string& problem)
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
  return fs::path(path).filename().string();
}

std::string Describe(double v)
{
  char text[40];
  std::snprintf(text, sizeof(text), "%.6g", v);
  return text;
}

/// One slice of the volume: a file and a frame in it, with its rescale.
struct Slice
{
  std::string Path;
  int Frame = 0;
  double Slope = 1, Intercept = 0;
};

} // namespace

struct vtkRGDICOMSeriesReader::Internals
{
  QuietGDCM Quiet;
  // From the header, the same on every rank.
  std::vector<Slice> Slices;
  int Rows = 0, Columns = 0, Samples = 1, Planar = 0, BitsAllocated = 0, BitsStored = 0;
  int PixelRepresentation = 0, TransferSyntax = 0, Frames = 1;
  bool Encapsulated = false;
  std::string Photometric;
  std::size_t Files = 0;
};

//------------------------------------------------------------------------------
vtkRGDICOMSeriesReader::vtkRGDICOMSeriesReader()
  : Internal(new Internals)
{
}

//------------------------------------------------------------------------------
vtkRGDICOMSeriesReader::~vtkRGDICOMSeriesReader()
{
  this->SetSeriesInstanceUID(nullptr);
}

//------------------------------------------------------------------------------
int vtkRGDICOMSeriesReader::GetNumberOfFiles() const
{
  return static_cast<int>(this->Internal->Files);
}

//------------------------------------------------------------------------------
const char* vtkRGDICOMSeriesReader::GetSliceFileName(int k) const
{
  const auto& slices = this->Internal->Slices;
  return k >= 0 && k < static_cast<int>(slices.size()) ? slices[k].Path.c_str() : nullptr;
}

//------------------------------------------------------------------------------
int vtkRGDICOMSeriesReader::CanReadFile(const char* name)
{
  if (!name)
  {
    return 0;
  }
  std::error_code error;
  FileHeader h;
  std::string problem;
  if (fs::is_directory(name, error))
  {
    // A directory holds a series when one of its first files is DICOM with an image.
    int looked = 0;
    for (const auto& entry : fs::directory_iterator(name, error))
    {
      if (entry.is_regular_file(error) && ++looked <= 64 &&
        ParseHeader(entry.path().string(), h, problem) == Parsed::Image)
      {
        return 1;
      }
    }
    return 0;
  }
  return fs::is_regular_file(name, error) && ParseHeader(name, h, problem) == Parsed::Image ? 1 : 0;
}

//------------------------------------------------------------------------------
bool vtkRGDICOMSeriesReader::Scan(std::string& header, std::string& message)
{
  std::error_code error;
  const std::string name = this->FileName;
  if (!fs::exists(name, error))
  {
    message = "no such file or directory";
    return false;
  }
  const bool isDirectory = fs::is_directory(name, error);
  const std::string directory = isDirectory ? name : fs::path(name).parent_path().string();

  // PASS 1: every file's header, in name order (a stable order for the messages).
  std::vector<std::string> paths;
  for (const auto& entry :
    fs::directory_iterator(directory.empty() ? std::string(".") : directory, error))
  {
    if (entry.is_regular_file(error))
    {
      paths.push_back(entry.path().string());
    }
  }
  if (error)
  {
    message = "cannot list the directory " + directory + ": " + error.message();
    return false;
  }
  std::sort(paths.begin(), paths.end());
  if (paths.empty())
  {
    message = "the directory " + directory + " is empty: no DICOM series";
    return false;
  }
  std::vector<FileHeader> images;
  std::string chosenUID = this->SeriesInstanceUID ? this->SeriesInstanceUID : "";
  std::size_t skipped = 0;
  for (const std::string& path : paths)
  {
    FileHeader h;
    std::string problem;
    switch (ParseHeader(path, h, problem))
    {
      case Parsed::Image:
        images.push_back(h);
        if (!isDirectory && chosenUID.empty() && fs::equivalent(path, name, error))
        {
          chosenUID = h.SeriesUID.empty() ? std::string("(none)") : h.SeriesUID;
        }
        break;
      case Parsed::Broken:
        message = path + " " + problem;
        return false;
      default:
        ++skipped;
    }
  }
  if (!isDirectory && chosenUID.empty())
  {
    message = name + " holds no DICOM image (no pixel data, or not DICOM)";
    return false;
  }
  if (images.empty())
  {
    message = "no DICOM image in the directory " + directory + " (" + std::to_string(skipped) +
      " files, none DICOM with pixel data): no DICOM series";
    return false;
  }

  // PASS 2: series by SeriesInstanceUID; the chosen one, else the largest (ties: smallest UID).
  std::map<std::string, std::vector<FileHeader>> series;
  for (const FileHeader& h : images)
  {
    series[h.SeriesUID.empty() ? std::string("(none)") : h.SeriesUID].push_back(h);
  }
  if (chosenUID.empty())
  {
    std::size_t most = 0;
    for (const auto& s : series)
    {
      if (s.second.size() > most)
      {
        most = s.second.size();
        chosenUID = s.first;
      }
    }
  }
  auto found = series.find(chosenUID);
  std::ostringstream list;
  auto describe = [&](const std::string& uid, const std::vector<FileHeader>& files)
  {
    list << uid << ": " << files.size() << " files";
    if (!files[0].SeriesDescription.empty())
    {
      list << ", " << files[0].SeriesDescription;
    }
    list << "\n";
  };
  if (found != series.end())
  {
    describe(found->first, found->second);
  }
  for (const auto& s : series)
  {
    if (s.first != chosenUID)
    {
      describe(s.first, s.second);
    }
  }
  if (found == series.end())
  {
    std::string held = list.str();
    held.pop_back();
    std::replace(held.begin(), held.end(), '\n', ';');
    message = "no series " + chosenUID + " in " + directory + "; it holds: " + held;
    return false;
  }
  std::vector<FileHeader>& files = found->second;
  std::ostringstream warnings;
  if (series.size() > 1)
  {
    warnings << directory << " holds " << series.size() << " series; reading " << chosenUID << " ("
             << files.size() << " files); the others:";
    for (const auto& s : series)
    {
      if (s.first != chosenUID)
      {
        warnings << " " << s.first << " (" << s.second.size() << " files)";
      }
    }
    warnings << "\n";
  }

  // PASS 3a: one series may hold several stacks (localizers, other acquisitions under the same
  // SeriesInstanceUID): images of one size, pixel format, orientation and pixel spacing form a
  // stack; the largest is read (the first found on a tie) and the others are named.
  std::string leftOut;
  {
    auto sameStack = [](const FileHeader& a, const FileHeader& b)
    {
      if (a.Rows != b.Rows || a.Columns != b.Columns || a.Samples != b.Samples ||
        a.BitsAllocated != b.BitsAllocated || a.BitsStored != b.BitsStored ||
        a.PixelRepresentation != b.PixelRepresentation || a.HasOrientation != b.HasOrientation ||
        a.HasSpacing != b.HasSpacing)
      {
        return false;
      }
      for (int c = 0; c < 6; ++c)
      {
        if (std::fabs(a.Orientation[c] - b.Orientation[c]) > 1e-4)
        {
          return false;
        }
      }
      return std::fabs(a.PixelSpacing[0] - b.PixelSpacing[0]) <= 1e-4 * b.PixelSpacing[0] &&
        std::fabs(a.PixelSpacing[1] - b.PixelSpacing[1]) <= 1e-4 * b.PixelSpacing[1];
    };
    std::vector<std::vector<FileHeader>> stacks;
    for (FileHeader& h : files)
    {
      auto stack = std::find_if(stacks.begin(), stacks.end(),
        [&](const std::vector<FileHeader>& st) { return sameStack(h, st.front()); });
      if (stack == stacks.end())
      {
        stacks.emplace_back();
        stack = stacks.end() - 1;
      }
      stack->push_back(h);
    }
    if (stacks.size() > 1)
    {
      std::size_t largest = 0;
      for (std::size_t st = 1; st < stacks.size(); ++st)
      {
        largest = stacks[st].size() > stacks[largest].size() ? st : largest;
      }
      const FileHeader& kept = stacks[largest].front();
      warnings << "series " << chosenUID << " in " << directory << " mixes " << stacks.size()
               << " stacks of images (localizers or other acquisitions): reading the largest, "
               << stacks[largest].size() << " files of " << kept.Columns << " x " << kept.Rows
               << " pixels; left out:";
      std::ostringstream names;
      for (std::size_t st = 0; st < stacks.size(); ++st)
      {
        if (st == largest)
        {
          continue;
        }
        const FileHeader& h = stacks[st].front();
        warnings << " " << stacks[st].size() << " file" << (stacks[st].size() > 1 ? "s" : "")
                 << " of " << h.Columns << " x " << h.Rows << " pixels, orientation ("
                 << Describe(h.Orientation[0]);
        for (int c = 1; c < 6; ++c)
        {
          warnings << ", " << Describe(h.Orientation[c]);
        }
        warnings << "), pixel spacing " << Describe(h.PixelSpacing[0]) << " x "
                 << Describe(h.PixelSpacing[1]) << " mm (";
        for (std::size_t f = 0; f < stacks[st].size(); ++f)
        {
          warnings << (f ? ", " : "") << BaseName(stacks[st][f].Path);
          names << (names.str().empty() ? "" : ", ") << BaseName(stacks[st][f].Path);
        }
        warnings << ");";
      }
      warnings << "\n";
      leftOut = names.str();
      std::vector<FileHeader> chosen = std::move(stacks[largest]);
      files.swap(chosen);
    }
  }

  // PASS 3: one volume's worth of consistency, each mismatch naming its file.
  const FileHeader& first = files.front();
  std::string problem;
  for (const FileHeader& h : files)
  {
    if (!CheckPixelFormat(h, problem))
    {
      message = h.Path + " " + problem;
      return false;
    }
    const std::uint64_t frame =
      NativeFrameBytes(h.Rows, h.Columns, h.Samples, h.BitsAllocated, h.Photometric);
    if (!h.Encapsulated && h.PixelBytes < frame * h.Frames)
    {
      message = h.Path + " is truncated: its pixel data has " + std::to_string(h.PixelBytes) +
        " of the " + std::to_string(frame * h.Frames) + " bytes its header announces";
      return false;
    }
  }
  for (const FileHeader& h : files)
  {
    std::ostringstream why;
    if (h.Rows != first.Rows || h.Columns != first.Columns)
    {
      why << "is " << h.Columns << " x " << h.Rows << " pixels, while " << BaseName(first.Path)
          << " is " << first.Columns << " x " << first.Rows << ": mixed image sizes in one series";
    }
    else if (h.Samples != first.Samples || h.BitsAllocated != first.BitsAllocated ||
      h.BitsStored != first.BitsStored || h.PixelRepresentation != first.PixelRepresentation)
    {
      why << "has another pixel format than " << BaseName(first.Path) << " (" << h.Samples
          << " samples of " << h.BitsStored << "/" << h.BitsAllocated << " bits, "
          << (h.PixelRepresentation ? "signed" : "unsigned") << ", against " << first.Samples
          << " of " << first.BitsStored << "/" << first.BitsAllocated << ", "
          << (first.PixelRepresentation ? "signed" : "unsigned") << ")";
    }
    else if (h.HasOrientation != first.HasOrientation ||
      [&]()
      {
        for (int c = 0; c < 6; ++c)
        {
          if (std::fabs(h.Orientation[c] - first.Orientation[c]) > 1e-4)
          {
            return true;
          }
        }
        return false;
      }())
    {
      why << "has the orientation (" << Describe(h.Orientation[0]);
      for (int c = 1; c < 6; ++c)
      {
        why << ", " << Describe(h.Orientation[c]);
      }
      why << ") while " << BaseName(first.Path) << " has (" << Describe(first.Orientation[0]);
      for (int c = 1; c < 6; ++c)
      {
        why << ", " << Describe(first.Orientation[c]);
      }
      why << "): inconsistent orientation in one series";
    }
    else if (h.HasSpacing != first.HasSpacing ||
      std::fabs(h.PixelSpacing[0] - first.PixelSpacing[0]) > 1e-4 * first.PixelSpacing[0] ||
      std::fabs(h.PixelSpacing[1] - first.PixelSpacing[1]) > 1e-4 * first.PixelSpacing[1])
    {
      why << "has the pixel spacing " << Describe(h.PixelSpacing[0]) << " x "
          << Describe(h.PixelSpacing[1]) << " mm while " << BaseName(first.Path) << " has "
          << Describe(first.PixelSpacing[0]) << " x " << Describe(first.PixelSpacing[1])
          << " mm: inconsistent pixel spacing in one series";
    }
    else if (files.size() > 1 && !h.HasPosition)
    {
      why << "has no ImagePositionPatient: its slice cannot be placed in a series of "
          << files.size() << " files";
    }
    else if (files.size() > 1 && h.Frames > 1)
    {
      why << "has " << h.Frames << " frames: a series of several multi-frame files is not read";
    }
    if (!why.str().empty())
    {
      message = h.Path + " " + why.str();
      return false;
    }
  }

  // PASS 4: geometry. Columns of the direction matrix: row direction (along a row, increasing
  // column index: x), column direction (y), their cross product (the slice normal: z).
  double row[3] = { first.Orientation[0], first.Orientation[1], first.Orientation[2] };
  double col[3] = { first.Orientation[3], first.Orientation[4], first.Orientation[5] };
  if (vtkMath::Normalize(row) < 1e-6 || vtkMath::Normalize(col) < 1e-6 ||
    std::fabs(vtkMath::Dot(row, col)) > 1e-3)
  {
    message = first.Path + " has an ImageOrientationPatient whose two directions are not " +
      "orthogonal unit vectors";
    return false;
  }
  double normal[3];
  vtkMath::Cross(row, col, normal);
  vtkMath::Normalize(normal);
  std::vector<Slice> slices;
  double sliceSpacing = 1.0, deviation = 0.0;
  double origin[3] = { first.Position[0], first.Position[1], first.Position[2] };
  if (files.size() == 1)
  {
    for (int f = 0; f < first.Frames; ++f)
    {
      slices.push_back(Slice{ first.Path, f, first.Slope, first.Intercept });
    }
    if (first.Frames > 1)
    {
      // A multi-frame volume: RT dose places its frames with GridFrameOffsetVector.
      if (first.FrameOffsets.size() == static_cast<std::size_t>(first.Frames))
      {
        const std::vector<double>& o = first.FrameOffsets;
        sliceSpacing = (o.back() - o.front()) / (first.Frames - 1);
        for (int f = 1; f < first.Frames; ++f)
        {
          deviation = std::max(deviation, std::fabs(o[f] - o[f - 1] - sliceSpacing));
        }
        for (int a = 0; a < 3; ++a)
        {
          origin[a] += o.front() * normal[a];
        }
        if (sliceSpacing < 0)
        {
          message = first.Path + " has a decreasing GridFrameOffsetVector";
          return false;
        }
      }
      else if (first.SpacingBetweenSlices > 0)
      {
        sliceSpacing = first.SpacingBetweenSlices;
      }
      else if (first.SliceThickness > 0)
      {
        sliceSpacing = first.SliceThickness;
        warnings << first.Path << " has " << first.Frames << " frames without "
                 << "SpacingBetweenSlices: spaced by their SliceThickness, "
                 << Describe(sliceSpacing) << " mm\n";
      }
      else
      {
        warnings << first.Path << " has " << first.Frames << " frames and no slice spacing: "
                 << "spaced by 1 mm\n";
      }
      if (sliceSpacing == 0)
      {
        message = first.Path + " has frames at one position (a zero frame spacing)";
        return false;
      }
    }
  }
  else
  {
    for (FileHeader& h : files)
    {
      h.Projection = vtkMath::Dot(h.Position, normal);
    }
    std::stable_sort(files.begin(), files.end(),
      [](const FileHeader& a, const FileHeader& b) { return a.Projection < b.Projection; });
    const double extentAlong = files.back().Projection - files.front().Projection;
    const double tolerance = std::max(1e-4, 1e-6 * std::fabs(extentAlong));
    for (std::size_t s = 1; s < files.size(); ++s)
    {
      if (files[s].Projection - files[s - 1].Projection <= tolerance)
      {
        message = files[s].Path + " and " + files[s - 1].Path + " are at the same position (" +
          Describe(files[s].Projection) + " mm along the slice normal): duplicated slice " +
          "positions (two acquisitions in one series?)";
        return false;
      }
    }
    sliceSpacing = extentAlong / (files.size() - 1);
    std::size_t worst = 1;
    double smallest = extentAlong, largest = 0.0;
    for (std::size_t s = 1; s < files.size(); ++s)
    {
      const double gap = files[s].Projection - files[s - 1].Projection;
      smallest = std::min(smallest, gap);
      largest = std::max(largest, gap);
      if (std::fabs(gap - sliceSpacing) > deviation)
      {
        deviation = std::fabs(gap - sliceSpacing);
        worst = s;
      }
    }
    // Slices are never stacked as if evenly spaced when they are not (a missing slice, a
    // variable spacing): under 1% of the mean gap, a warning with the spread; beyond, an error
    // that names the gap.
    if (deviation >= 0.01 * sliceSpacing)
    {
      message = "the slices of " + directory + " are not evenly spaced: " + files[worst - 1].Path +
        " and " + files[worst].Path + " are " +
        Describe(files[worst].Projection - files[worst - 1].Projection) +
        " mm apart along the slice normal (at " + Describe(files[worst - 1].Projection) + " and " +
        Describe(files[worst].Projection) + " mm), the mean gap is " + Describe(sliceSpacing) +
        " mm (a missing slice, or a variable spacing); gaps range from " + Describe(smallest) +
        " to " + Describe(largest) + " mm" +
        (leftOut.empty() ? std::string()
                         : "; left out of this stack as another acquisition: " + leftOut);
      return false;
    }
    if (deviation > std::max(1e-3 * sliceSpacing, 1e-4))
    {
      warnings << "irregular slice spacing in " << directory << ": the gaps between slices "
               << "range from " << Describe(smallest) << " to " << Describe(largest) << " mm (mean "
               << Describe(sliceSpacing) << " mm; largest deviation " << Describe(deviation)
               << " mm, at " << BaseName(files[worst].Path)
               << ", under 1%); the volume is read with the mean spacing\n";
    }
    // Positions off the normal through the first slice cannot be represented: a stack sheared
    // along its planes is a CT acquired with the gantry tilted. Said, with the tilt angle (the
    // shift of the last slice against its distance along the normal).
    double offPlane = 0.0, lastOff = 0.0;
    for (const FileHeader& h : files)
    {
      double d[3];
      for (int a = 0; a < 3; ++a)
      {
        d[a] = h.Position[a] - first.Position[a];
      }
      const double along = vtkMath::Dot(d, normal);
      for (int a = 0; a < 3; ++a)
      {
        d[a] -= along * normal[a];
      }
      offPlane = std::max(offPlane, vtkMath::Norm(d));
      lastOff = vtkMath::Norm(d);
    }
    if (offPlane > std::max(1e-3 * sliceSpacing, 1e-3))
    {
      const double tilt = vtkMath::DegreesFromRadians(std::atan2(lastOff, extentAlong));
      warnings << "the slices of " << directory << " are shifted within their planes by up to "
               << Describe(offPlane) << " mm: a gantry tilt of " << Describe(tilt)
               << " degrees (or slices that do not line up); the volume is read as if they were "
               << "stacked along the slice normal, so what it shows is sheared by that angle\n";
    }
    for (int a = 0; a < 3; ++a)
    {
      origin[a] = files.front().Position[a];
    }
    for (const FileHeader& h : files)
    {
      slices.push_back(Slice{ h.Path, 0, h.Slope, h.Intercept });
    }
  }

  // PASS 5: the output type from the stored range and every slice's rescale.
  bool integral = true;
  double lo = VTK_DOUBLE_MAX, hi = VTK_DOUBLE_MIN;
  const double storedLo = first.PixelRepresentation ? -std::ldexp(1.0, first.BitsStored - 1) : 0.0;
  const double storedHi = first.PixelRepresentation ? std::ldexp(1.0, first.BitsStored - 1) - 1
                                                    : std::ldexp(1.0, first.BitsStored) - 1;
  int type;
  if (first.Samples == 3)
  {
    type = first.BitsAllocated == 8
      ? VTK_UNSIGNED_CHAR
      : (first.BitsAllocated == 16 ? VTK_UNSIGNED_SHORT : VTK_UNSIGNED_INT);
  }
  else
  {
    for (const Slice& s : slices)
    {
      integral =
        integral && s.Slope == std::floor(s.Slope) && s.Intercept == std::floor(s.Intercept);
      const double a = s.Slope * storedLo + s.Intercept, b = s.Slope * storedHi + s.Intercept;
      lo = std::min(lo, std::min(a, b));
      hi = std::max(hi, std::max(a, b));
    }
    type = ChooseScalarType(integral, lo, hi, first.BitsStored > 24);
  }

  double spacing[3] = { first.PixelSpacing[1], first.PixelSpacing[0], std::fabs(sliceSpacing) };
  if (!first.HasSpacing)
  {
    warnings << first.Path << " has no PixelSpacing: 1 mm is used\n";
  }
  const bool isCT = first.Modality == "CT";
  std::ostringstream summary;
  summary << "DICOM series " << chosenUID << " (" << (first.Modality.empty() ? "?" : first.Modality)
          << "): " << first.Columns << " x " << first.Rows << " x " << slices.size() << ", spacing "
          << Describe(spacing[0]) << " x " << Describe(spacing[1]) << " x " << Describe(spacing[2])
          << " mm, transfer syntax " << TransferSyntaxName(first.TransferSyntaxUID) << ", rescale "
          << Describe(first.Slope) << " * stored " << (first.Intercept < 0 ? "- " : "+ ")
          << Describe(std::fabs(first.Intercept));

  rgmc::Packer p;
  const int dimensions[3] = { first.Columns, first.Rows, static_cast<int>(slices.size()) };
  double direction[9]; // row-major 3x3, columns row/col/normal
  for (int a = 0; a < 3; ++a)
  {
    direction[3 * a] = row[a];
    direction[3 * a + 1] = col[a];
    direction[3 * a + 2] = normal[a];
  }
  PackGeometry(p, dimensions, spacing, origin, direction, type);
  p.Number(first.Samples).Number(first.Planar).Number(first.BitsAllocated);
  p.Number(first.BitsStored).Number(first.PixelRepresentation).Number(first.TransferSyntax);
  p.Number(deviation).Number(static_cast<double>(files.size()));
  p.String(isCT ? "HU" : "Intensity").String(list.str()).String(warnings.str());
  p.String(summary.str()).String(first.Photometric);
  p.Number(first.Encapsulated ? 1 : 0).Number(first.Frames);
  for (const Slice& s : slices)
  {
    p.String(s.Path).Number(s.Frame).Number(s.Slope).Number(s.Intercept);
  }
  header = p.Text;
  return true;
}

//------------------------------------------------------------------------------
bool vtkRGDICOMSeriesReader::Parse(const std::string& header, std::string& message)
{
  rgmc::Unpacker u(header);
  Internals& in = *this->Internal;
  this->UnpackGeometry(u);
  in.Samples = u.Int();
  in.Planar = u.Int();
  in.BitsAllocated = u.Int();
  in.BitsStored = u.Int();
  in.PixelRepresentation = u.Int();
  in.TransferSyntax = u.Int();
  this->LargestSpacingDeviation = u.Number();
  in.Files = static_cast<std::size_t>(u.Number());
  this->ArrayName = u.String();
  this->SeriesList = u.String();
  this->Warnings = u.String();
  this->Summary = u.String();
  in.Photometric = u.String();
  in.Encapsulated = u.Int() != 0;
  in.Frames = u.Int();
  in.Columns = this->Dimensions[0];
  in.Rows = this->Dimensions[1];
  this->NumberOfComponents = in.Samples;
  in.Slices.assign(static_cast<std::size_t>(std::max(0, this->Dimensions[2])), Slice());
  for (Slice& s : in.Slices)
  {
    s.Path = u.String();
    s.Frame = u.Int();
    s.Slope = u.Number();
    s.Intercept = u.Number();
  }
  if (!u.Ok() || in.Slices.empty())
  {
    this->OutputScalarType = 0;
    message = "the header broadcast from rank 0 is damaged";
    return false;
  }
  this->RescaleSlope = in.Slices[0].Slope;
  this->RescaleIntercept = in.Slices[0].Intercept;
  return true;
}

//------------------------------------------------------------------------------
bool vtkRGDICOMSeriesReader::ReadExtent(
  const int extent[6], vtkDataArray* scalars, std::string& message)
{
  Internals& in = *this->Internal;
  const int samples = in.Samples;
  const std::size_t bytes = in.BitsAllocated == 1 ? 0 : in.BitsAllocated / 8;
  const std::size_t pixelsPerFrame = static_cast<std::size_t>(in.Rows) * in.Columns;
  const bool encapsulated = in.Encapsulated;
  // Decoders give full frames; native YBR_FULL_422 stays subsampled (expanded below).
  const bool subsampled = !encapsulated && samples == 3 && in.Photometric == "YBR_FULL_422";
  const std::size_t frameBytes = encapsulated
    ? NativeFrameBytes(in.Rows, in.Columns, samples, in.BitsAllocated, std::string())
    : NativeFrameBytes(in.Rows, in.Columns, samples, in.BitsAllocated, in.Photometric);
  const int width = extent[1] - extent[0] + 1;
  std::vector<double> values(static_cast<std::size_t>(width) * samples);
  std::vector<char> buffer;
  std::string loaded; // the file in `buffer` (a multi-frame file serves several slices)
  int decodedPlanar = in.Planar;
  vtkIdType at = 0;
  this->NumberOfFilesRead = 0;

  for (int k = extent[4]; k <= extent[5]; ++k)
  {
    const Slice& slice = in.Slices[k];
    if (slice.Path != loaded)
    {
      // The file may have changed since the scan: GDCM sees it only if its structure holds.
      const rgmc::DicomStructure structure = rgmc::WalkDicom(slice.Path);
      if (!structure.Valid || !structure.HasPixelData ||
        structure.PixelDataEncapsulated != encapsulated)
      {
        message = slice.Path + " is truncated or corrupt: " +
          (structure.Problem.empty() ? std::string("its pixel data changed since the header scan")
                                     : structure.Problem);
        return false;
      }
      const std::size_t expected = frameBytes * in.Frames;
      if (!encapsulated && structure.PixelDataLength < expected)
      {
        message = slice.Path + " is truncated: its pixel data has " +
          std::to_string(structure.PixelDataLength) + " bytes of the " + std::to_string(expected) +
          " its header announces";
        return false;
      }
      bool decoded = false;
      if (!encapsulated && structure.PixelDataOffset > 0)
      {
        // Native pixel data: read straight from the file, swapped to this host's byte order.
        // The byte order applies to the value's words: 8-bit samples in an OW value come in
        // swapped pairs in big endian (pydicom 2.4's SC_rgb_small_odd_big_endian.dcm), the last
        // one with the value's padding byte when the sample count is odd.
        int word = in.BitsAllocated == 1 ? 1 : in.BitsAllocated / 8; // bits stay in bytes
        if (in.BitsAllocated == 8 && structure.PixelDataWords)
        {
          word = 2;
        }
        const bool swap = structure.BigEndian && word > 1;
        const std::size_t padded = swap && expected % word != 0 &&
            structure.PixelDataLength >= expected + word - expected % word
          ? expected + word - expected % word
          : expected;
        std::ifstream file(slice.Path, std::ios::binary);
        buffer.assign(padded, 0);
        file.seekg(static_cast<std::streamoff>(structure.PixelDataOffset));
        decoded = static_cast<bool>(file.read(buffer.data(), static_cast<std::streamsize>(padded)));
        if (swap)
        {
          for (std::size_t b = 0; b + word <= buffer.size(); b += word)
          {
            std::reverse(buffer.begin() + b, buffer.begin() + b + word);
          }
        }
        buffer.resize(expected);
        decodedPlanar = in.Planar;
      }
      else if (in.TransferSyntax == gdcm::TransferSyntax::RLELossless && in.BitsAllocated >= 8)
      {
        // RLE ourselves: GDCM 3.0.21 orders the bytes of 16- and 32-bit colour RLE wrongly.
        decoded = structure.Fragments.size() == static_cast<std::size_t>(in.Frames);
        std::string problem = "it has " + std::to_string(structure.Fragments.size()) +
          " RLE fragments for " + std::to_string(in.Frames) + " frames";
        buffer.assign(expected, 0);
        for (int f = 0; decoded && f < in.Frames; ++f)
        {
          decoded = rgmc::DecodeRleFrame(slice.Path, structure.Fragments[f].first,
            structure.Fragments[f].second, pixelsPerFrame, samples, in.BitsAllocated / 8,
            buffer.data() + frameBytes * f, problem);
        }
        if (!decoded)
        {
          message = slice.Path + " has malformed RLE pixel data: " + problem;
          return false;
        }
        decodedPlanar = 0;
      }
      else
      {
        const int ts = in.TransferSyntax;
        if (ts == gdcm::TransferSyntax::JPEGBaselineProcess1 ||
          ts == gdcm::TransferSyntax::JPEGExtendedProcess2_4 ||
          ts == gdcm::TransferSyntax::JPEGLosslessProcess14 ||
          ts == gdcm::TransferSyntax::JPEGLosslessProcess14_1)
        {
          for (const auto& fragment : structure.Fragments)
          {
            std::string problem;
            char start[2] = { 0, 0 };
            std::ifstream file(slice.Path, std::ios::binary);
            file.seekg(static_cast<std::streamoff>(fragment.first));
            file.read(start, 2);
            const bool frameStart = static_cast<unsigned char>(start[0]) == 0xff &&
              static_cast<unsigned char>(start[1]) == 0xd8;
            if ((frameStart || &fragment == &structure.Fragments.front()) &&
              !rgmc::CheckJpegHeader(slice.Path, fragment.first, fragment.second, in.Rows,
                in.Columns, samples, in.BitsStored, problem))
            {
              message = slice.Path + " has broken JPEG data: " + problem;
              return false;
            }
          }
        }
        // GDCM's parser and codecs, given the pixel description of the header scan (its
        // ImageReader also guesses geometry, and asserts on some valid files while doing so).
        // Bytes after the last element (padding, junk) are not GDCM's to parse: it gets the
        // data set alone.
        gdcm::Reader reader;
        std::istringstream dataSet;
        if (structure.TrailingBytes > 0)
        {
          std::string bytes(static_cast<std::size_t>(structure.DataSetEnd), '\0');
          std::ifstream file(slice.Path, std::ios::binary);
          file.read(&bytes[0], static_cast<std::streamsize>(bytes.size()));
          dataSet.str(bytes);
          reader.SetStream(dataSet);
        }
        else
        {
          reader.SetFileName(slice.Path.c_str());
        }
        try
        {
          if (reader.Read() && reader.GetFile().GetDataSet().FindDataElement(PixelDataTag))
          {
            gdcm::Image image;
            image.SetNumberOfDimensions(in.Frames > 1 ? 3 : 2);
            image.SetDimension(0, static_cast<unsigned>(in.Columns));
            image.SetDimension(1, static_cast<unsigned>(in.Rows));
            if (in.Frames > 1)
            {
              image.SetDimension(2, static_cast<unsigned>(in.Frames));
            }
            image.SetPixelFormat(gdcm::PixelFormat(static_cast<unsigned short>(samples),
              static_cast<unsigned short>(in.BitsAllocated),
              static_cast<unsigned short>(in.BitsStored),
              static_cast<unsigned short>(in.BitsStored - 1),
              static_cast<unsigned short>(in.PixelRepresentation)));
            const gdcm::PhotometricInterpretation::PIType pi =
              gdcm::PhotometricInterpretation::GetPIType(in.Photometric.c_str());
            image.SetPhotometricInterpretation(pi == gdcm::PhotometricInterpretation::PI_END
                ? gdcm::PhotometricInterpretation(gdcm::PhotometricInterpretation::MONOCHROME2)
                : gdcm::PhotometricInterpretation(pi));
            if (samples == 3)
            {
              image.SetPlanarConfiguration(static_cast<unsigned>(in.Planar));
            }
            image.SetTransferSyntax(reader.GetFile().GetHeader().GetDataSetTransferSyntax());
            image.SetDataElement(reader.GetFile().GetDataSet().GetDataElement(PixelDataTag));
            buffer.assign(std::max<std::size_t>(image.GetBufferLength(), expected), 0);
            decoded = image.GetBuffer(buffer.data());
            // A codec may hand back interleaved samples whatever the header said.
            decodedPlanar = samples == 3 ? static_cast<int>(image.GetPlanarConfiguration()) : 0;
          }
        }
        catch (...)
        {
          decoded = false;
        }
      }
      if (!decoded)
      {
        message = slice.Path + " cannot be decoded by GDCM (transfer syntax " +
          TransferSyntaxName(gdcm::TransferSyntax::GetTSString(
            static_cast<gdcm::TransferSyntax::TSType>(in.TransferSyntax))) +
          "): truncated or corrupt pixel data";
        return false;
      }
      loaded = slice.Path;
      ++this->NumberOfFilesRead;
    }
    const char* frame = buffer.data() + frameBytes * slice.Frame;
    // Planar configuration 1 stores each colour plane after the other.
    const bool planar = samples == 3 && decodedPlanar == 1;
    for (int j = extent[2]; j <= extent[3]; ++j)
    {
      std::size_t n = 0;
      for (int i = extent[0]; i <= extent[1]; ++i)
      {
        for (int c = 0; c < samples; ++c)
        {
          const std::size_t pixel = static_cast<std::size_t>(j) * in.Columns + i;
          std::size_t index = planar ? c * pixelsPerFrame + pixel : pixel * samples + c;
          if (subsampled)
          {
            // Y0 Y1 Cb Cr for each pair of pixels of a row.
            const std::size_t pair = (static_cast<std::size_t>(j) * in.Columns + (i & ~1)) * 2;
            index = c == 0 ? pair + (i & 1) : pair + 1 + c;
          }
          double v;
          if (in.BitsAllocated == 1)
          {
            v = (static_cast<unsigned char>(frame[index / 8]) >> (index % 8)) & 1;
          }
          else
          {
            std::uint32_t raw = 0;
            std::memcpy(&raw, frame + index * bytes, bytes); // little endian host, as GDCM's
            // Keep the stored bits; a signed value is sign-extended from its highest stored bit.
            if (in.PixelRepresentation)
            {
              const unsigned width32 = 32 - in.BitsStored;
              v = static_cast<double>(static_cast<std::int32_t>(raw << width32) >> width32);
            }
            else
            {
              v = in.BitsStored >= 32 ? raw : (raw & ((std::uint32_t(1) << in.BitsStored) - 1));
            }
          }
          values[n++] = samples == 1 ? slice.Slope * v + slice.Intercept : v;
        }
      }
      Store(scalars, at, values.data(), values.size());
      at += static_cast<vtkIdType>(values.size());
    }
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkRGDICOMSeriesReader::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent
     << "SeriesInstanceUID: " << (this->SeriesInstanceUID ? this->SeriesInstanceUID : "(largest)")
     << "\n";
  os << indent << "SeriesList: " << this->SeriesList << "\n";
  os << indent << "NumberOfFiles: " << this->GetNumberOfFiles() << "\n";
  os << indent << "RescaleSlope: " << this->RescaleSlope << "\n";
  os << indent << "RescaleIntercept: " << this->RescaleIntercept << "\n";
  os << indent << "LargestSpacingDeviation: " << this->LargestSpacingDeviation << "\n";
  os << indent << "NumberOfFilesRead: " << this->NumberOfFilesRead << "\n";
}

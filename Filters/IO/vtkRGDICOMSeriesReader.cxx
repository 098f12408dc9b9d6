// The DICOM series reader: a header scan on rank 0 (GDCM's parser, stopping at the pixel data),
// grouping, sorting and checking; then each rank decodes the files of its own slab with GDCM.
#include "vtkRGDICOMSeriesReader.h"

#include "vtkRGMessage.h"

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

/// How the pixels of a file are stored: what the scan checks across a series, and what every
/// rank needs to decode the files of its slices.
struct PixelDescription
{
  int Rows = 0, Columns = 0, Samples = 1, Planar = 0, BitsAllocated = 0, BitsStored = 0;
  int PixelRepresentation = 0, Frames = 1;
  int TransferSyntax = gdcm::TransferSyntax::TS_END;
  std::string Photometric;
  bool Encapsulated = false;
};

/// What the scan keeps of one file.
struct FileHeader : PixelDescription
{
  std::string Path, SeriesUID, SeriesDescription, Modality, TransferSyntaxUID;
  bool HasPosition = false, HasOrientation = false, HasSpacing = false;
  double Position[3] = { 0, 0, 0 }, Orientation[6] = { 1, 0, 0, 0, 1, 0 };
  double PixelSpacing[2] = { 1, 1 };
  double Slope = 1, Intercept = 0;
  std::vector<double> FrameOffsets;
  double SpacingBetweenSlices = 0, SliceThickness = 0;
  double Projection = 0;        // position along the slice normal
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

/// The pixel description, the series and the transfer syntax of a file whose header GDCM read;
/// false with `problem` when its NumberOfFrames is impossible.
bool ReadPixelTags(const gdcm::File& file, FileHeader& h, std::string& problem)
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
bool ReadSliceTags(const gdcm::DataSet& ds, FileHeader& h, std::string& problem)
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
  return ReadPixelTags(file, h, problem) && ReadSliceTags(ds, h, problem) ? Parsed::Image
                                                                          : Parsed::Broken;
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
  PixelDescription Pixels;
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

namespace
{

/// What the header scan has found so far, pass by pass.
struct SeriesScan
{
  // What to read.
  std::string Name; // FileName: a directory, or one file of the series
  bool IsDirectory = false;
  std::string Directory; // the directory whose files are scanned
  std::string ChosenUID; // the series to read: SeriesInstanceUID, else found by passes 1 and 2
  // PASS 1
  std::vector<FileHeader> Images; // every DICOM image of the directory, in name order
  // PASS 2 and 3: the files of the volume, the chosen series' largest stack (sorted along the
  // slice normal by pass 5)
  std::vector<FileHeader> Files;
  std::string SeriesList; // one line per series, the chosen one first
  std::string LeftOut;    // the files of the series' other stacks, for messages
  // PASS 5
  double Normal[3] = { 0, 0, 1 };
  double Direction[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 1 }; // row-major; columns: row direction,
                                                       // column direction, slice normal
  double Origin[3] = { 0, 0, 0 };
  double SliceSpacing = 1.0; // the distance between slices along the normal (CheckSliceSpacing)
  double Deviation = 0.0;    // files: the largest distance of a slice from its place in the
                             // evenly spaced stack; frames: the largest deviation of a gap
  std::vector<Slice> Slices;
  int Dimensions[3] = { 0, 0, 0 };
  double Spacing[3] = { 1, 1, 1 };
  std::ostringstream Warnings; // one per line, in the order the passes find them
};

/// PASS 1, first step: the regular files of the directory (FileName's, when it is a file), in
/// name order (a stable order for the messages).
bool ListFiles(SeriesScan& scan, std::vector<std::string>& paths, std::string& message)
{
  std::error_code error;
  if (!fs::exists(scan.Name, error))
  {
    message = "no such file or directory";
    return false;
  }
  scan.IsDirectory = fs::is_directory(scan.Name, error);
  scan.Directory = scan.IsDirectory ? scan.Name : fs::path(scan.Name).parent_path().string();
  for (const auto& entry :
    fs::directory_iterator(scan.Directory.empty() ? std::string(".") : scan.Directory, error))
  {
    if (entry.is_regular_file(error))
    {
      paths.push_back(entry.path().string());
    }
  }
  if (error)
  {
    message = "cannot list the directory " + scan.Directory + ": " + error.message();
    return false;
  }
  std::sort(paths.begin(), paths.end());
  if (paths.empty())
  {
    message = "the directory " + scan.Directory + " is empty: no DICOM series";
    return false;
  }
  return true;
}

/// The key a file's series is known by: its SeriesInstanceUID, "(none)" without one.
std::string SeriesKey(const FileHeader& h)
{
  return h.SeriesUID.empty() ? std::string("(none)") : h.SeriesUID;
}

/// PASS 1: every file's header; FileName's series, when it is a file and no series is named.
bool ReadHeaders(SeriesScan& scan, std::string& message)
{
  std::vector<std::string> paths;
  if (!ListFiles(scan, paths, message))
  {
    return false;
  }
  std::error_code error;
  std::size_t skipped = 0;
  for (const std::string& path : paths)
  {
    FileHeader h;
    std::string problem;
    switch (ParseHeader(path, h, problem))
    {
      case Parsed::Image:
        scan.Images.push_back(h);
        if (!scan.IsDirectory && scan.ChosenUID.empty() && fs::equivalent(path, scan.Name, error))
        {
          scan.ChosenUID = SeriesKey(h);
        }
        break;
      case Parsed::Broken:
        message = path + " " + problem;
        return false;
      default:
        ++skipped;
    }
  }
  if (!scan.IsDirectory && scan.ChosenUID.empty())
  {
    message = scan.Name + " holds no DICOM image (no pixel data, or not DICOM)";
    return false;
  }
  if (scan.Images.empty())
  {
    message = "no DICOM image in the directory " + scan.Directory + " (" + std::to_string(skipped) +
      " files, none DICOM with pixel data): no DICOM series";
    return false;
  }
  return true;
}

using SeriesMap = std::map<std::string, std::vector<FileHeader>>;

/// One line per series ("UID: N files, description"), the chosen one first.
std::string ListSeries(const SeriesMap& series, const std::string& chosenUID)
{
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
  const auto found = series.find(chosenUID);
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
  return list.str();
}

/// PASS 2: series by SeriesInstanceUID; the chosen one, else the largest (ties: smallest UID).
bool ChooseSeries(SeriesScan& scan, std::string& message)
{
  SeriesMap series;
  for (const FileHeader& h : scan.Images)
  {
    series[SeriesKey(h)].push_back(h);
  }
  if (scan.ChosenUID.empty())
  {
    std::size_t most = 0;
    for (const auto& s : series)
    {
      if (s.second.size() > most)
      {
        most = s.second.size();
        scan.ChosenUID = s.first;
      }
    }
  }
  scan.SeriesList = ListSeries(series, scan.ChosenUID);
  const auto found = series.find(scan.ChosenUID);
  if (found == series.end())
  {
    std::string held = scan.SeriesList;
    held.pop_back();
    std::replace(held.begin(), held.end(), '\n', ';');
    message = "no series " + scan.ChosenUID + " in " + scan.Directory + "; it holds: " + held;
    return false;
  }
  if (series.size() > 1)
  {
    scan.Warnings << scan.Directory << " holds " << series.size() << " series; reading "
                  << scan.ChosenUID << " (" << found->second.size() << " files); the others:";
    for (const auto& s : series)
    {
      if (s.first != scan.ChosenUID)
      {
        scan.Warnings << " " << s.first << " (" << s.second.size() << " files)";
      }
    }
    scan.Warnings << "\n";
  }
  scan.Files = std::move(found->second);
  return true;
}

/// Whether two ImageOrientationPatient agree (each direction cosine to 1e-4).
bool SameOrientation(const double a[6], const double b[6])
{
  for (int c = 0; c < 6; ++c)
  {
    if (std::fabs(a[c] - b[c]) > 1e-4)
    {
      return false;
    }
  }
  return true;
}

/// Whether the pixel spacing of `a` agrees with that of `b` (to 1e-4 of b's).
bool SamePixelSpacing(const FileHeader& a, const FileHeader& b)
{
  return std::fabs(a.PixelSpacing[0] - b.PixelSpacing[0]) <= 1e-4 * b.PixelSpacing[0] &&
    std::fabs(a.PixelSpacing[1] - b.PixelSpacing[1]) <= 1e-4 * b.PixelSpacing[1];
}

/// "1, 0, 0, 0, 1, 0": the six direction cosines of an ImageOrientationPatient, for messages.
std::string DescribeOrientation(const double orientation[6])
{
  std::string text = Describe(orientation[0]);
  for (int c = 1; c < 6; ++c)
  {
    text += ", " + Describe(orientation[c]);
  }
  return text;
}

/// Whether two images belong to one stack: one size, pixel format, orientation, pixel spacing.
bool SameStack(const FileHeader& a, const FileHeader& b)
{
  return a.Rows == b.Rows && a.Columns == b.Columns && a.Samples == b.Samples &&
    a.BitsAllocated == b.BitsAllocated && a.BitsStored == b.BitsStored &&
    a.PixelRepresentation == b.PixelRepresentation && a.HasOrientation == b.HasOrientation &&
    a.HasSpacing == b.HasSpacing && SameOrientation(a.Orientation, b.Orientation) &&
    SamePixelSpacing(a, b);
}

/// Warns that the series mixes stacks and names the files of those left out (kept in
/// scan.LeftOut for the messages of pass 5).
void WarnOfOtherStacks(
  SeriesScan& scan, const std::vector<std::vector<FileHeader>>& stacks, std::size_t largest)
{
  std::ostringstream& warnings = scan.Warnings;
  const FileHeader& kept = stacks[largest].front();
  warnings << "series " << scan.ChosenUID << " in " << scan.Directory << " mixes " << stacks.size()
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
    warnings << " " << stacks[st].size() << " file" << (stacks[st].size() > 1 ? "s" : "") << " of "
             << h.Columns << " x " << h.Rows << " pixels, orientation ("
             << DescribeOrientation(h.Orientation) << "), pixel spacing "
             << Describe(h.PixelSpacing[0]) << " x " << Describe(h.PixelSpacing[1]) << " mm (";
    for (std::size_t f = 0; f < stacks[st].size(); ++f)
    {
      warnings << (f ? ", " : "") << BaseName(stacks[st][f].Path);
      names << (names.str().empty() ? "" : ", ") << BaseName(stacks[st][f].Path);
    }
    warnings << ");";
  }
  warnings << "\n";
  scan.LeftOut = names.str();
}

/// PASS 3: one series may hold several stacks (localizers, other acquisitions under the same
/// SeriesInstanceUID): images of one size, pixel format, orientation and pixel spacing form a
/// stack; the largest is read (the first found on a tie) and the others are named.
void ChooseStack(SeriesScan& scan)
{
  std::vector<std::vector<FileHeader>> stacks;
  for (const FileHeader& h : scan.Files)
  {
    auto stack = std::find_if(stacks.begin(), stacks.end(),
      [&](const std::vector<FileHeader>& st) { return SameStack(h, st.front()); });
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
    WarnOfOtherStacks(scan, stacks, largest);
    scan.Files = std::move(stacks[largest]);
  }
}

/// Why `h` cannot be a slice of one volume with `first`, in a series of `count` files; empty
/// when it can.
std::string Mismatch(const FileHeader& h, const FileHeader& first, std::size_t count)
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
    !SameOrientation(h.Orientation, first.Orientation))
  {
    why << "has the orientation (" << DescribeOrientation(h.Orientation) << ") while "
        << BaseName(first.Path) << " has (" << DescribeOrientation(first.Orientation)
        << "): inconsistent orientation in one series";
  }
  else if (h.HasSpacing != first.HasSpacing || !SamePixelSpacing(h, first))
  {
    why << "has the pixel spacing " << Describe(h.PixelSpacing[0]) << " x "
        << Describe(h.PixelSpacing[1]) << " mm while " << BaseName(first.Path) << " has "
        << Describe(first.PixelSpacing[0]) << " x " << Describe(first.PixelSpacing[1])
        << " mm: inconsistent pixel spacing in one series";
  }
  else if (count > 1 && !h.HasPosition)
  {
    why << "has no ImagePositionPatient: its slice cannot be placed in a series of " << count
        << " files";
  }
  else if (count > 1 && h.Frames > 1)
  {
    why << "has " << h.Frames << " frames: a series of several multi-frame files is not read";
  }
  return why.str();
}

/// PASS 4: one volume's worth of consistency, each mismatch naming its file.
bool CheckSeries(const std::vector<FileHeader>& files, std::string& message)
{
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
    const std::string why = Mismatch(h, files.front(), files.size());
    if (!why.empty())
    {
      message = h.Path + " " + why;
      return false;
    }
  }
  return true;
}

/// PASS 5, first step: the axes from the (unsorted) first file's orientation. Columns of the
/// direction matrix: row direction (along a row, increasing column index: x), column direction
/// (y), their cross product (the slice normal: z).
bool FindAxes(SeriesScan& scan, std::string& message)
{
  const FileHeader& first = scan.Files.front();
  double row[3] = { first.Orientation[0], first.Orientation[1], first.Orientation[2] };
  double column[3] = { first.Orientation[3], first.Orientation[4], first.Orientation[5] };
  if (vtkMath::Normalize(row) < 1e-6 || vtkMath::Normalize(column) < 1e-6 ||
    std::fabs(vtkMath::Dot(row, column)) > 1e-3)
  {
    message = first.Path + " has an ImageOrientationPatient whose two directions are not " +
      "orthogonal unit vectors";
    return false;
  }
  vtkMath::Cross(row, column, scan.Normal);
  vtkMath::Normalize(scan.Normal);
  for (int a = 0; a < 3; ++a)
  {
    scan.Direction[3 * a] = row[a];
    scan.Direction[3 * a + 1] = column[a];
    scan.Direction[3 * a + 2] = scan.Normal[a];
  }
  return true;
}

/// PASS 5 for a series of one file: a slice per frame, at the file's position. A multi-frame
/// volume is spaced by its GridFrameOffsetVector (RT dose), else SpacingBetweenSlices, else
/// SliceThickness (a warning), else 1 mm (a warning).
bool PlaceFrames(SeriesScan& scan, std::string& message)
{
  const FileHeader& first = scan.Files.front();
  std::copy(first.Position, first.Position + 3, scan.Origin);
  for (int f = 0; f < first.Frames; ++f)
  {
    scan.Slices.push_back(Slice{ first.Path, f, first.Slope, first.Intercept });
  }
  if (first.Frames <= 1)
  {
    return true;
  }
  if (first.FrameOffsets.size() == static_cast<std::size_t>(first.Frames))
  {
    const std::vector<double>& offsets = first.FrameOffsets;
    scan.SliceSpacing = (offsets.back() - offsets.front()) / (first.Frames - 1);
    for (int f = 1; f < first.Frames; ++f)
    {
      scan.Deviation =
        std::max(scan.Deviation, std::fabs(offsets[f] - offsets[f - 1] - scan.SliceSpacing));
    }
    for (int a = 0; a < 3; ++a)
    {
      scan.Origin[a] += offsets.front() * scan.Normal[a];
    }
    if (scan.SliceSpacing < 0)
    {
      message = first.Path + " has a decreasing GridFrameOffsetVector";
      return false;
    }
  }
  else if (first.SpacingBetweenSlices > 0)
  {
    scan.SliceSpacing = first.SpacingBetweenSlices;
  }
  else if (first.SliceThickness > 0)
  {
    scan.SliceSpacing = first.SliceThickness;
    scan.Warnings << first.Path << " has " << first.Frames << " frames without "
                  << "SpacingBetweenSlices: spaced by their SliceThickness, "
                  << Describe(scan.SliceSpacing) << " mm\n";
  }
  else
  {
    scan.Warnings << first.Path << " has " << first.Frames << " frames and no slice spacing: "
                  << "spaced by 1 mm\n";
  }
  if (scan.SliceSpacing == 0)
  {
    message = first.Path + " has frames at one position (a zero frame spacing)";
    return false;
  }
  return true;
}

/// PASS 5 for several files, first step: the files sorted by their position along the slice
/// normal; two at one position are an error.
bool SortAlongNormal(std::vector<FileHeader>& files, const double normal[3], std::string& message)
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
  return true;
}

/// How far a slice may lie from its place in an evenly spaced stack and still be read as part of
/// it: min(0.2 mm, a tenth of the spacing). 0.2 mm is the gap difference dcm2niix still treats
/// as one spacing (scanners' rounded positions jitter by less); the tenth keeps a missing slice
/// and a gap of 1.5 spacings errors on thin slices.
double SliceTolerance(double spacing)
{
  return std::min(0.2, 0.1 * spacing);
}

/// PASS 5 for several sorted files: the slice spacing, fitted to the slices' positions along the
/// normal (least squares: position = first + spacing * index), and how far a slice lies from its
/// place in that evenly spaced stack. Scanners write positions as rounded decimal strings, so an
/// oblique stack's gaps jitter: a slice within SliceTolerance of its place is rounding, and the
/// stack is read on the fitted spacing (with a warning giving the spread when a gap differs from
/// it by more than 1%). Farther, slices are never stacked as if evenly spaced: a missing slice or
/// a variable spacing is an error that names the gap that differs most.
bool CheckSliceSpacing(SeriesScan& scan, std::string& message)
{
  const std::vector<FileHeader>& files = scan.Files;
  const std::size_t n = files.size();
  const double extentAlong = files.back().Projection - files.front().Projection;
  const double mean = extentAlong / (n - 1);
  // The fit, about the middle index (sum of (s - middle)^2 = n (n^2 - 1) / 12).
  const double middle = 0.5 * static_cast<double>(n - 1);
  double meanPosition = 0.0;
  for (const FileHeader& h : files)
  {
    meanPosition += h.Projection;
  }
  meanPosition /= static_cast<double>(n);
  double moment = 0.0;
  for (std::size_t s = 0; s < n; ++s)
  {
    moment += (static_cast<double>(s) - middle) * (files[s].Projection - meanPosition);
  }
  const double spacing =
    moment / (static_cast<double>(n) * (static_cast<double>(n) * n - 1.0) / 12.0);
  double offPlace = 0.0; // the largest distance of a slice from its fitted place
  std::size_t farthest = 0;
  for (std::size_t s = 0; s < n; ++s)
  {
    const double place = meanPosition + (static_cast<double>(s) - middle) * spacing;
    if (std::fabs(files[s].Projection - place) > offPlace)
    {
      offPlace = std::fabs(files[s].Projection - place);
      farthest = s;
    }
  }
  double gapDeviation = 0.0;
  std::size_t worst = 1;
  double smallest = extentAlong, largest = 0.0;
  for (std::size_t s = 1; s < n; ++s)
  {
    const double gap = files[s].Projection - files[s - 1].Projection;
    smallest = std::min(smallest, gap);
    largest = std::max(largest, gap);
    if (std::fabs(gap - spacing) > gapDeviation)
    {
      gapDeviation = std::fabs(gap - spacing);
      worst = s;
    }
  }
  const double tolerance = SliceTolerance(spacing);
  if (offPlace > tolerance)
  {
    message = "the slices of " + scan.Directory +
      " are not evenly spaced: " + files[worst - 1].Path + " and " + files[worst].Path + " are " +
      Describe(files[worst].Projection - files[worst - 1].Projection) +
      " mm apart along the slice normal (at " + Describe(files[worst - 1].Projection) + " and " +
      Describe(files[worst].Projection) + " mm), the mean gap is " + Describe(mean) +
      " mm (a missing slice, or a variable spacing); gaps range from " + Describe(smallest) +
      " to " + Describe(largest) + " mm; " + BaseName(files[farthest].Path) + " lies " +
      Describe(offPlace) + " mm from its place in the evenly spaced stack that fits best (" +
      Describe(spacing) + " mm apart), more than the " + Describe(tolerance) +
      " mm allowed for rounded positions" +
      (scan.LeftOut.empty() ? std::string()
                            : "; left out of this stack as another acquisition: " + scan.LeftOut);
    return false;
  }
  if (gapDeviation > 0.01 * spacing)
  {
    scan.Warnings << "irregular slice spacing in " << scan.Directory << ": the gaps between "
                  << "slices range from " << Describe(smallest) << " to " << Describe(largest)
                  << " mm (the fitted spacing is " << Describe(spacing)
                  << " mm; every slice lies within " << Describe(offPlace)
                  << " mm of its place, at most " << Describe(tolerance)
                  << " mm is taken as rounded positions); the volume is read with the fitted "
                     "spacing\n";
  }
  scan.SliceSpacing = spacing;
  scan.Deviation = offPlace;
  return true;
}

/// PASS 5 for several sorted files: positions off the normal through the first slice cannot be
/// represented: a stack sheared along its planes is a CT acquired with the gantry tilted. Said,
/// with the tilt angle (the shift of the last slice against its distance along the normal).
void WarnOfGantryTilt(SeriesScan& scan)
{
  const std::vector<FileHeader>& files = scan.Files;
  const FileHeader& first = files.front();
  const double extentAlong = files.back().Projection - first.Projection;
  double offPlane = 0.0, lastOff = 0.0;
  for (const FileHeader& h : files)
  {
    double d[3];
    for (int a = 0; a < 3; ++a)
    {
      d[a] = h.Position[a] - first.Position[a];
    }
    const double along = vtkMath::Dot(d, scan.Normal);
    for (int a = 0; a < 3; ++a)
    {
      d[a] -= along * scan.Normal[a];
    }
    offPlane = std::max(offPlane, vtkMath::Norm(d));
    lastOff = vtkMath::Norm(d);
  }
  // Shifts no larger than the rounding that CheckSliceSpacing accepts along the normal are
  // rounded positions (an oblique stack's, written as decimal strings), not a tilt.
  if (offPlane > SliceTolerance(scan.SliceSpacing))
  {
    const double tilt = vtkMath::DegreesFromRadians(std::atan2(lastOff, extentAlong));
    scan.Warnings << "the slices of " << scan.Directory << " are shifted within their planes by "
                  << "up to " << Describe(offPlane) << " mm: a gantry tilt of " << Describe(tilt)
                  << " degrees (or slices that do not line up); the volume is read as if they "
                  << "were stacked along the slice normal, so what it shows is sheared by that "
                  << "angle\n";
  }
}

/// PASS 5 for a series of several files: a slice per file, sorted along the normal, evenly
/// spaced, from the first one's position.
bool PlaceFiles(SeriesScan& scan, std::string& message)
{
  if (!SortAlongNormal(scan.Files, scan.Normal, message) || !CheckSliceSpacing(scan, message))
  {
    return false;
  }
  WarnOfGantryTilt(scan);
  const FileHeader& first = scan.Files.front();
  std::copy(first.Position, first.Position + 3, scan.Origin);
  for (const FileHeader& h : scan.Files)
  {
    scan.Slices.push_back(Slice{ h.Path, 0, h.Slope, h.Intercept });
  }
  return true;
}

/// PASS 5: geometry: the axes, the slices in order along the normal, the spacing and the origin
/// (the first slice's position).
bool PlaceSlices(SeriesScan& scan, std::string& message)
{
  if (!FindAxes(scan, message) ||
    !(scan.Files.size() == 1 ? PlaceFrames(scan, message) : PlaceFiles(scan, message)))
  {
    return false;
  }
  const FileHeader& first = scan.Files.front();
  scan.Dimensions[0] = first.Columns;
  scan.Dimensions[1] = first.Rows;
  scan.Dimensions[2] = static_cast<int>(scan.Slices.size());
  scan.Spacing[0] = first.PixelSpacing[1];
  scan.Spacing[1] = first.PixelSpacing[0];
  scan.Spacing[2] = std::fabs(scan.SliceSpacing);
  if (!first.HasSpacing)
  {
    scan.Warnings << first.Path << " has no PixelSpacing: 1 mm is used\n";
  }
  return true;
}

/// The range of the rescaled samples, whether they are all integers, and whether float cannot
/// hold the stored values.
struct SampleRange
{
  bool Integral = true;
  double Lo = VTK_DOUBLE_MAX, Hi = VTK_DOUBLE_MIN;
  bool Wide = false;
};

/// PASS 6, for one sample per pixel: the stored range under every slice's rescale.
SampleRange RescaledRange(const FileHeader& first, const std::vector<Slice>& slices)
{
  SampleRange range;
  range.Wide = first.BitsStored > 24;
  const double storedLo = first.PixelRepresentation ? -std::ldexp(1.0, first.BitsStored - 1) : 0.0;
  const double storedHi = first.PixelRepresentation ? std::ldexp(1.0, first.BitsStored - 1) - 1
                                                    : std::ldexp(1.0, first.BitsStored) - 1;
  for (const Slice& s : slices)
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

/// The scan in words, for the log: the series, its size, spacing, transfer syntax and rescale.
std::string Summarize(const SeriesScan& scan)
{
  const FileHeader& first = scan.Files.front();
  std::ostringstream summary;
  summary << "DICOM series " << scan.ChosenUID << " ("
          << (first.Modality.empty() ? "?" : first.Modality) << "): " << first.Columns << " x "
          << first.Rows << " x " << scan.Slices.size() << ", spacing " << Describe(scan.Spacing[0])
          << " x " << Describe(scan.Spacing[1]) << " x " << Describe(scan.Spacing[2])
          << " mm, transfer syntax " << TransferSyntaxName(first.TransferSyntaxUID) << ", rescale "
          << Describe(first.Slope) << " * stored " << (first.Intercept < 0 ? "- " : "+ ")
          << Describe(std::fabs(first.Intercept));
  return summary.str();
}

/// What follows the geometry in the header, in the order Parse reads it: the pixel description,
/// the scan's words and every slice.
void PackSeries(rgmc::MessageWriter& p, const SeriesScan& scan)
{
  const FileHeader& first = scan.Files.front();
  p.Int(first.Samples).Int(first.Planar).Int(first.BitsAllocated);
  p.Int(first.BitsStored).Int(first.PixelRepresentation).Int(first.TransferSyntax);
  p.Real(scan.Deviation).Int(static_cast<std::int64_t>(scan.Files.size()));
  p.Text(first.Modality == "CT" ? "HU" : "Intensity")
    .Text(scan.SeriesList)
    .Text(scan.Warnings.str());
  p.Text(Summarize(scan)).Text(first.Photometric);
  p.Int(first.Encapsulated ? 1 : 0).Int(first.Frames);
  for (const Slice& s : scan.Slices)
  {
    p.Text(s.Path).Int(s.Frame).Real(s.Slope).Real(s.Intercept);
  }
}

} // namespace

//------------------------------------------------------------------------------
// Rank 0 alone runs the scan, and it makes no collective call: vtkRGVolumeReader's
// RequestInformation agrees on its status over all ranks, then broadcasts the header it writes.
//
//  PASS 1 ReadHeaders   every file's header (GDCM stops before the pixel data)
//  PASS 2 ChooseSeries  the series named, else FileName's, else the one with the most files
//  PASS 3 ChooseStack   the largest stack of the series (localizers and the like left out)
//  PASS 4 CheckSeries   one size, pixel format, orientation and pixel spacing for all
//  PASS 5 PlaceSlices   the axes, the slices sorted along the normal, their spacing, the origin
//  PASS 6               the output type; the header: geometry, pixel description, slices
bool vtkRGDICOMSeriesReader::Scan(std::vector<vtkIdType>& header, std::string& message)
{
  SeriesScan scan;
  scan.Name = this->FileName;
  scan.ChosenUID = this->SeriesInstanceUID ? this->SeriesInstanceUID : "";
  // PASS 1: every file's header, in name order (a stable order for the messages).
  if (!ReadHeaders(scan, message))
  {
    return false;
  }
  // PASS 2: series by SeriesInstanceUID; the chosen one, else the largest (ties: smallest UID).
  if (!ChooseSeries(scan, message))
  {
    return false;
  }
  // PASS 3: the largest stack of images alike in the series; the others named in a warning.
  ChooseStack(scan);
  // PASS 4: one volume's worth of consistency, each mismatch naming its file.
  if (!CheckSeries(scan.Files, message))
  {
    return false;
  }
  // PASS 5: geometry, in DICOM's patient coordinates.
  if (!PlaceSlices(scan, message))
  {
    return false;
  }
  // PASS 6: the output type from the stored range and every slice's rescale; the header.
  const FileHeader& first = scan.Files.front();
  const SampleRange range = RescaledRange(first, scan.Slices);
  const int type = first.Samples == 3
    ? ColourScalarType(first.BitsAllocated)
    : ChooseScalarType(range.Integral, range.Lo, range.Hi, range.Wide);
  header.clear();
  rgmc::MessageWriter p(header);
  PackGeometry(p, scan.Dimensions, scan.Spacing, scan.Origin, scan.Direction, type);
  PackSeries(p, scan);
  return true;
}

//------------------------------------------------------------------------------
bool vtkRGDICOMSeriesReader::Parse(const std::vector<vtkIdType>& header, std::string& message)
{
  rgmc::MessageReader u(header);
  Internals& in = *this->Internal;
  PixelDescription& pixels = in.Pixels;
  this->UnpackGeometry(u);
  pixels.Samples = static_cast<int>(u.Int());
  pixels.Planar = static_cast<int>(u.Int());
  pixels.BitsAllocated = static_cast<int>(u.Int());
  pixels.BitsStored = static_cast<int>(u.Int());
  pixels.PixelRepresentation = static_cast<int>(u.Int());
  pixels.TransferSyntax = static_cast<int>(u.Int());
  this->LargestSpacingDeviation = u.Real();
  in.Files = static_cast<std::size_t>(u.Int());
  this->ArrayName = u.Text();
  this->SeriesList = u.Text();
  this->Warnings = u.Text();
  this->Summary = u.Text();
  pixels.Photometric = u.Text();
  pixels.Encapsulated = u.Int() != 0;
  pixels.Frames = static_cast<int>(u.Int());
  pixels.Columns = this->Dimensions[0];
  pixels.Rows = this->Dimensions[1];
  this->NumberOfComponents = pixels.Samples;
  in.Slices.assign(static_cast<std::size_t>(std::max(0, this->Dimensions[2])), Slice());
  for (Slice& s : in.Slices)
  {
    s.Path = u.Text();
    s.Frame = static_cast<int>(u.Int());
    s.Slope = u.Real();
    s.Intercept = u.Real();
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

namespace
{

/// The pixel data of the file decoded last (a multi-frame file serves several slices).
struct DecodedFile
{
  std::string Path;        // empty before the first file
  std::vector<char> Bytes; // every frame, samples in this host's byte order
  int Planar = 0;          // the planar configuration of Bytes (a codec may interleave samples)
};

/// Bytes of one decoded frame: decoders give full frames; native YBR_FULL_422 stays subsampled
/// (FrameLayout expands it).
std::size_t DecodedFrameBytes(const PixelDescription& pixels)
{
  return pixels.Encapsulated
    ? NativeFrameBytes(pixels.Rows, pixels.Columns, pixels.Samples, pixels.BitsAllocated, "")
    : NativeFrameBytes(
        pixels.Rows, pixels.Columns, pixels.Samples, pixels.BitsAllocated, pixels.Photometric);
}

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
  std::vector<char>& buffer = decoded.Bytes;
  std::ifstream file(path, std::ios::binary);
  buffer.assign(padded, 0);
  file.seekg(static_cast<std::streamoff>(structure.PixelDataOffset));
  const bool read =
    static_cast<bool>(file.read(buffer.data(), static_cast<std::streamsize>(padded)));
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
    char start[2] = { 0, 0 };
    std::ifstream file(path, std::ios::binary);
    file.seekg(static_cast<std::streamoff>(fragment.first));
    file.read(start, 2);
    const bool frameStart =
      static_cast<unsigned char>(start[0]) == 0xff && static_cast<unsigned char>(start[1]) == 0xd8;
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
    const bool ok = image.GetBuffer(decoded.Bytes.data());
    // A codec may hand back interleaved samples whatever the header said.
    decoded.Planar = pixels.Samples == 3 ? static_cast<int>(image.GetPlanarConfiguration()) : 0;
    return ok;
  }
  catch (...)
  {
    return false;
  }
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
double StoredSample(const PixelDescription& pixels, const char* frame, std::size_t index)
{
  if (pixels.BitsAllocated == 1)
  {
    return (static_cast<unsigned char>(frame[index / 8]) >> (index % 8)) & 1;
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

} // namespace

//------------------------------------------------------------------------------
// No collective call here: vtkRGVolumeReader's RequestData agrees on the status over all ranks.
bool vtkRGDICOMSeriesReader::ReadExtent(
  const int extent[6], vtkDataArray* scalars, std::string& message)
{
  const Internals& in = *this->Internal;
  const PixelDescription& pixels = in.Pixels;
  const std::size_t frameBytes = DecodedFrameBytes(pixels);
  const int width = extent[1] - extent[0] + 1;
  std::vector<double> values(static_cast<std::size_t>(width) * pixels.Samples);
  DecodedFile decoded;
  decoded.Planar = pixels.Planar;
  vtkIdType at = 0;
  this->NumberOfFilesRead = 0;
  for (int k = extent[4]; k <= extent[5]; ++k)
  {
    // PASS 1, once per file: decode every frame of the slice's file.
    const Slice& slice = in.Slices[k];
    if (slice.Path != decoded.Path)
    {
      if (!DecodeFile(slice.Path, pixels, decoded, message))
      {
        return false;
      }
      ++this->NumberOfFilesRead;
    }
    // PASS 2: the rows of the extent in the slice's frame, rescaled (one sample per pixel).
    const char* frame = decoded.Bytes.data() + frameBytes * slice.Frame;
    const FrameLayout layout(pixels, decoded.Planar);
    for (int j = extent[2]; j <= extent[3]; ++j)
    {
      std::size_t n = 0;
      for (int i = extent[0]; i <= extent[1]; ++i)
      {
        for (int c = 0; c < pixels.Samples; ++c)
        {
          const double v = StoredSample(pixels, frame, layout.Index(i, j, c));
          values[n++] = pixels.Samples == 1 ? slice.Slope * v + slice.Intercept : v;
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

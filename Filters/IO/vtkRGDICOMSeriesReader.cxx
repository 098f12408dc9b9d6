// The DICOM series reader's schedule: a header scan on rank 0 (listing, grouping by series and
// stack, checking, placing the slices), then each rank decodes the files of its own slab. A file's
// tags are read in rgmcDicomTags, the stack's geometry is fitted in rgmcDicomStack, and pixel data
// is decoded in rgmcDicomPixels.
#include "vtkRGDICOMSeriesReader.h"

#include "vtkRGMessage.h"

#include "rgmcDicomPixels.h"
#include "rgmcDicomStack.h"
#include "rgmcDicomTags.h"

#include "vtkDataArray.h"
#include "vtkObjectFactory.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>
#include <vector>

vtkStandardNewMacro(vtkRGDICOMSeriesReader);

namespace fs = std::filesystem;

struct vtkRGDICOMSeriesReader::Internals
{
  rgmc::QuietGDCM Quiet;
  // From the header, the same on every rank.
  std::vector<rgmc::DicomSlice> Slices;
  rgmc::PixelDescription Pixels;
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
  rgmc::DicomHeader h;
  std::string problem;
  if (fs::is_directory(name, error))
  {
    // A directory holds a series when one of its first files is DICOM with an image.
    int looked = 0;
    for (const auto& entry : fs::directory_iterator(name, error))
    {
      if (entry.is_regular_file(error) && ++looked <= 64 &&
        rgmc::ReadDicomHeader(entry.path().string(), h, problem) == rgmc::DicomFileKind::Image)
      {
        return 1;
      }
    }
    return 0;
  }
  return fs::is_regular_file(name, error) &&
      rgmc::ReadDicomHeader(name, h, problem) == rgmc::DicomFileKind::Image
    ? 1
    : 0;
}

namespace
{

/// What the header scan has found so far, pass by pass: what to read, the series found, then
/// the stack that passes 2 and 3 choose and pass 5 places.
struct SeriesScan : rgmc::DicomStack
{
  // What to read.
  std::string Name; // FileName: a directory, or one file of the series
  bool IsDirectory = false;
  std::string ChosenUID; // the series to read: SeriesInstanceUID, else found by passes 1 and 2
  // PASS 1
  std::vector<rgmc::DicomHeader> Images; // every DICOM image of the directory, in name order
  // PASS 2
  std::string SeriesList; // one line per series, the chosen one first
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
std::string SeriesKey(const rgmc::DicomHeader& h)
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
    rgmc::DicomHeader h;
    std::string problem;
    switch (rgmc::ReadDicomHeader(path, h, problem))
    {
      case rgmc::DicomFileKind::Image:
        scan.Images.push_back(h);
        if (!scan.IsDirectory && scan.ChosenUID.empty() && fs::equivalent(path, scan.Name, error))
        {
          scan.ChosenUID = SeriesKey(h);
        }
        break;
      case rgmc::DicomFileKind::Broken:
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

using SeriesMap = std::map<std::string, std::vector<rgmc::DicomHeader>>;

/// One line per series ("UID: N files, description"), the chosen one first.
std::string ListSeries(const SeriesMap& series, const std::string& chosenUID)
{
  std::ostringstream list;
  auto describe = [&](const std::string& uid, const std::vector<rgmc::DicomHeader>& files)
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
  for (const rgmc::DicomHeader& h : scan.Images)
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

/// Warns that the series mixes stacks and names the files of those left out (kept in
/// scan.LeftOut for the messages of pass 5).
void WarnOfOtherStacks(
  SeriesScan& scan, const std::vector<std::vector<rgmc::DicomHeader>>& stacks, std::size_t largest)
{
  std::ostringstream& warnings = scan.Warnings;
  const rgmc::DicomHeader& kept = stacks[largest].front();
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
    const rgmc::DicomHeader& h = stacks[st].front();
    warnings << " " << stacks[st].size() << " file" << (stacks[st].size() > 1 ? "s" : "") << " of "
             << h.Columns << " x " << h.Rows << " pixels, orientation ("
             << rgmc::DescribeOrientation(h.Orientation) << "), pixel spacing "
             << rgmc::ShortNumber(h.PixelSpacing[0]) << " x "
             << rgmc::ShortNumber(h.PixelSpacing[1]) << " mm (";
    for (std::size_t f = 0; f < stacks[st].size(); ++f)
    {
      warnings << (f ? ", " : "") << rgmc::BaseName(stacks[st][f].Path);
      names << (names.str().empty() ? "" : ", ") << rgmc::BaseName(stacks[st][f].Path);
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
  std::vector<std::vector<rgmc::DicomHeader>> stacks;
  for (const rgmc::DicomHeader& h : scan.Files)
  {
    auto stack = std::find_if(stacks.begin(), stacks.end(),
      [&](const std::vector<rgmc::DicomHeader>& st) { return rgmc::SameStack(h, st.front()); });
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
std::string Mismatch(const rgmc::DicomHeader& h, const rgmc::DicomHeader& first, std::size_t count)
{
  std::ostringstream why;
  if (h.Rows != first.Rows || h.Columns != first.Columns)
  {
    why << "is " << h.Columns << " x " << h.Rows << " pixels, while " << rgmc::BaseName(first.Path)
        << " is " << first.Columns << " x " << first.Rows << ": mixed image sizes in one series";
  }
  else if (h.Samples != first.Samples || h.BitsAllocated != first.BitsAllocated ||
    h.BitsStored != first.BitsStored || h.PixelRepresentation != first.PixelRepresentation)
  {
    why << "has another pixel format than " << rgmc::BaseName(first.Path) << " (" << h.Samples
        << " samples of " << h.BitsStored << "/" << h.BitsAllocated << " bits, "
        << (h.PixelRepresentation ? "signed" : "unsigned") << ", against " << first.Samples
        << " of " << first.BitsStored << "/" << first.BitsAllocated << ", "
        << (first.PixelRepresentation ? "signed" : "unsigned") << ")";
  }
  else if (h.HasOrientation != first.HasOrientation ||
    !rgmc::SameOrientation(h.Orientation, first.Orientation))
  {
    why << "has the orientation (" << rgmc::DescribeOrientation(h.Orientation) << ") while "
        << rgmc::BaseName(first.Path) << " has (" << rgmc::DescribeOrientation(first.Orientation)
        << "): inconsistent orientation in one series";
  }
  else if (h.HasSpacing != first.HasSpacing || !rgmc::SamePixelSpacing(h, first))
  {
    why << "has the pixel spacing " << rgmc::ShortNumber(h.PixelSpacing[0]) << " x "
        << rgmc::ShortNumber(h.PixelSpacing[1]) << " mm while " << rgmc::BaseName(first.Path)
        << " has " << rgmc::ShortNumber(first.PixelSpacing[0]) << " x "
        << rgmc::ShortNumber(first.PixelSpacing[1])
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
bool CheckSeries(const std::vector<rgmc::DicomHeader>& files, std::string& message)
{
  std::string problem;
  for (const rgmc::DicomHeader& h : files)
  {
    if (!rgmc::CheckPixelFormat(h, problem))
    {
      message = h.Path + " " + problem;
      return false;
    }
    const std::uint64_t frame =
      rgmc::NativeFrameBytes(h.Rows, h.Columns, h.Samples, h.BitsAllocated, h.Photometric);
    if (!h.Encapsulated && h.PixelBytes < frame * h.Frames)
    {
      message = h.Path + " is truncated: its pixel data has " + std::to_string(h.PixelBytes) +
        " of the " + std::to_string(frame * h.Frames) + " bytes its header announces";
      return false;
    }
  }
  for (const rgmc::DicomHeader& h : files)
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

/// The scan in words, for the log: the series, its size, spacing, transfer syntax and rescale.
std::string Summarize(const SeriesScan& scan)
{
  const rgmc::DicomHeader& first = scan.Files.front();
  std::ostringstream summary;
  summary << "DICOM series " << scan.ChosenUID << " ("
          << (first.Modality.empty() ? "?" : first.Modality) << "): " << first.Columns << " x "
          << first.Rows << " x " << scan.Slices.size() << ", spacing "
          << rgmc::ShortNumber(scan.Spacing[0]) << " x " << rgmc::ShortNumber(scan.Spacing[1])
          << " x " << rgmc::ShortNumber(scan.Spacing[2]) << " mm, transfer syntax "
          << rgmc::TransferSyntaxName(first.TransferSyntaxUID) << ", rescale "
          << rgmc::ShortNumber(first.Slope) << " * stored " << (first.Intercept < 0 ? "- " : "+ ")
          << rgmc::ShortNumber(std::fabs(first.Intercept));
  return summary.str();
}

/// What follows the geometry in the header, in the order Parse reads it: the pixel description,
/// the scan's words and every slice.
void PackSeries(rgmc::MessageWriter& p, const SeriesScan& scan)
{
  const rgmc::DicomHeader& first = scan.Files.front();
  p.Int(first.Samples).Int(first.Planar).Int(first.BitsAllocated);
  p.Int(first.BitsStored).Int(first.PixelRepresentation).Int(first.TransferSyntax);
  p.Real(scan.Deviation).Int(static_cast<std::int64_t>(scan.Files.size()));
  p.Text(first.Modality == "CT" ? "HU" : "Intensity")
    .Text(scan.SeriesList)
    .Text(scan.Warnings.str());
  p.Text(Summarize(scan)).Text(first.Photometric);
  p.Int(first.Encapsulated ? 1 : 0).Int(first.Frames);
  for (const rgmc::DicomSlice& s : scan.Slices)
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
  if (!rgmc::PlaceSlices(scan, message))
  {
    return false;
  }
  // PASS 6: the output type from the stored range and every slice's rescale; the header.
  const rgmc::DicomHeader& first = scan.Files.front();
  const rgmc::SampleRange range = rgmc::RescaledRange(first, scan.Slices);
  const int type = first.Samples == 3
    ? rgmc::ColourScalarType(first.BitsAllocated)
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
  rgmc::PixelDescription& pixels = in.Pixels;
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
  in.Slices.assign(static_cast<std::size_t>(std::max(0, this->Dimensions[2])), rgmc::DicomSlice());
  for (rgmc::DicomSlice& s : in.Slices)
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

//------------------------------------------------------------------------------
int vtkRGDICOMSeriesReader::RequestData(
  vtkInformation* request, vtkInformationVector** inputs, vtkInformationVector* outputs)
{
  this->NumberOfFilesRead = 0; // counted over the ReadExtent calls of this update
  return this->Superclass::RequestData(request, inputs, outputs);
}

//------------------------------------------------------------------------------
// No collective call here: vtkRGVolumeReader's RequestData agrees on the status over all ranks.
bool vtkRGDICOMSeriesReader::ReadExtent(
  const int extent[6], vtkDataArray* scalars, std::string& message)
{
  const Internals& in = *this->Internal;
  const rgmc::PixelDescription& pixels = in.Pixels;
  const std::size_t frameBytes = rgmc::DecodedFrameBytes(pixels);
  const int width = extent[1] - extent[0] + 1;
  std::vector<double> values(static_cast<std::size_t>(width) * pixels.Samples);
  rgmc::DecodedFile decoded;
  decoded.Planar = pixels.Planar;
  vtkIdType at = 0;
  for (int k = extent[4]; k <= extent[5]; ++k)
  {
    // PASS 1, once per file: decode every frame of the slice's file.
    const rgmc::DicomSlice& slice = in.Slices[k];
    if (slice.Path != decoded.Path)
    {
      if (!rgmc::DecodeFile(slice.Path, pixels, decoded, message))
      {
        return false;
      }
      ++this->NumberOfFilesRead;
    }
    // PASS 2: the rows of the extent in the slice's frame, rescaled (one sample per pixel).
    const unsigned char* frame = decoded.Bytes.data() + frameBytes * slice.Frame;
    const rgmc::FrameLayout layout(pixels, decoded.Planar);
    for (int j = extent[2]; j <= extent[3]; ++j)
    {
      std::size_t n = 0;
      for (int i = extent[0]; i <= extent[1]; ++i)
      {
        for (int c = 0; c < pixels.Samples; ++c)
        {
          const double v = rgmc::StoredSample(pixels, frame, layout.Index(i, j, c));
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

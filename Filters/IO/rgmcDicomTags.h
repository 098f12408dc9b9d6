// The header record of one DICOM file, as the DICOM series reader's scan reads it: the tags it
// keeps (GDCM's parser stops before the pixel data), the checks of its pixel format, and the
// number formats the reader's messages use.
#ifndef rgmcDicomTags_h
#define rgmcDicomTags_h

#include <gdcmTag.h>
#include <gdcmTransferSyntax.h>

#include <cstdint>
#include <string>
#include <vector>

namespace rgmc
{

/// (7FE0,0010), where a file's pixel data is.
extern const gdcm::Tag PixelDataTag;

/// GDCM prints its own warnings and errors to stderr; the reader reports in its own words.
struct QuietGDCM
{
  QuietGDCM();
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
struct DicomHeader : PixelDescription
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

/// What a file turned out to be.
enum class DicomFileKind
{
  Image,    // a DICOM file with an image
  NoImage,  // a DICOM file without pixel data (DICOMDIR, a report): not part of any volume
  NotDicom, // not DICOM at all (a README): skipped
  Broken    // marked as DICOM but unreadable: an error
};

/// Reads one file's header (GDCM stops before the pixel data) into `h`; `problem` says why a
/// file is Broken.
DicomFileKind ReadDicomHeader(const std::string& path, DicomHeader& h, std::string& problem);

/// Checks of what one volume needs from a file's pixel description.
bool CheckPixelFormat(const DicomHeader& h, std::string& problem);

/// Bytes of one native frame.
std::uint64_t NativeFrameBytes(
  int rows, int columns, int samples, int bitsAllocated, const std::string& photometric);

/// "1.2.840.10008.1.2.4.100 (MPEG2 Main Profile @ Main Level)", for messages.
std::string TransferSyntaxName(const std::string& uid);

/// The file name of `path` without its directory, for messages.
std::string BaseName(const std::string& path);

/// A number in at most 6 significant digits ("%.6g"), for messages.
std::string ShortNumber(double v);

} // namespace rgmc

#endif

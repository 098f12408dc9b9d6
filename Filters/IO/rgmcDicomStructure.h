// Checks the structure of a DICOM file before GDCM parses it, without VTK or GDCM: every element
// length must fit in the file (and in its sequence or item), sequences and items must close,
// the nesting must stay shallow. GDCM (Debian's build keeps its assertions) aborts the process
// on some malformed files instead of reporting an error; a file that passes this walk is
// well-formed at the level GDCM's parser relies on, and a file that fails gets a message that
// says where it breaks. The walk also finds the native pixel data's length, so a file
// truncated inside its pixel data is reported as truncated.
#ifndef rgmcDicomStructure_h
#define rgmcDicomStructure_h

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace rgmc
{

struct DicomStructure
{
  bool Dicom = false;         // the file looks like DICOM (Part 10, or a bare data set)
  bool Valid = false;         // and its structure holds together
  std::string Problem;        // when not valid: what breaks, and at which byte
  std::string TransferSyntax; // from the file meta information (empty without one)
  bool HasPixelData = false;  // a top-level (7FE0,0010)
  bool PixelDataEncapsulated = false;
  std::uint64_t PixelDataLength = 0;   // bytes of native pixel data present in the file
  std::uint64_t PixelDataDeclared = 0; // bytes its header announces
  std::uint64_t PixelDataOffset = 0;   // where native pixel data starts in the file (0: not
                                       // directly readable, as in a deflated data set)
  bool BigEndian = false;              // the data set's byte order
  bool PixelDataWords = false;         // native pixel data of VR OW (16-bit words) explicitly
  std::uint64_t TrailingBytes = 0;     // bytes after the last element (zeros, or after pixel data)
  std::uint64_t DataSetEnd = 0;        // where they start (0: none)
  /// Encapsulated pixel data: (offset, length) of each fragment after the offset table.
  std::vector<std::pair<std::uint64_t, std::uint64_t>> Fragments;
};

/// Walks the file at `path`.
DicomStructure WalkDicom(const std::string& path);

/// Checks the marker segments of a JPEG stream (ITU T.81) in the fragment at `offset`, up to its
/// first scan: every segment's length within the fragment, one frame header whose size and
/// components are `columns` x `rows` x `samples` with a precision of at most `bits`. GDCM's
/// JPEG codec asserts on some broken streams instead of reporting them.
bool CheckJpegHeader(const std::string& path, std::uint64_t offset, std::uint64_t length, int rows,
  int columns, int samples, int bits, std::string& problem);

/// Decodes one RLE Lossless frame (DICOM Part 5 Annex G), the fragment at `offset` of `length`
/// bytes in `path`, into `out` (pixels * samples samples of `bytes` bytes each, interleaved, this
/// host's byte order). False with `problem` when the frame is malformed.
bool DecodeRleFrame(const std::string& path, std::uint64_t offset, std::uint64_t length,
  std::size_t pixels, int samples, int bytes, unsigned char* out, std::string& problem);

} // namespace rgmc

#endif

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
};

/// Walks the file at `path`.
DicomStructure WalkDicom(const std::string& path);

} // namespace rgmc

#endif

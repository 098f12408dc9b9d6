// Shared by the reader tests: gzip input, scratch directories, the DICOM generator run as a user
// runs it, reading a piece through the pipeline as ParaView asks for it, and checks that a
// message is the same on every rank.
#ifndef rgmcReaderTestData_h
#define rgmcReaderTestData_h

#include "rgmcDistributedData.h" // SameOnAllRanks
#include "rgmcTestData.h"

#include "vtkAlgorithm.h"
#include "vtkExecutive.h"
#include "vtkImageData.h"
#include "vtkMultiProcessController.h"
#include "vtkPointData.h"
#include "vtkRGPhantomSource.h"
#include "vtkShortArray.h"

#include <zlib.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

namespace rgmc_test
{

namespace fs = std::filesystem;

/// The bytes of a gzip file (what zlib could decompress of it).
inline std::vector<unsigned char> Gunzip(const std::string& path)
{
  std::vector<unsigned char> bytes;
  gzFile in = gzopen(path.c_str(), "rb");
  unsigned char chunk[1 << 16];
  for (int got; (got = gzread(in, chunk, sizeof(chunk))) > 0;)
  {
    bytes.insert(bytes.end(), chunk, chunk + got);
  }
  gzclose(in);
  return bytes;
}

/// A fresh, empty directory `name` under the current directory (rank 0 makes it).
inline std::string ScratchDirectory(vtkMultiProcessController* controller, const std::string& name)
{
  const fs::path dir = fs::absolute(fs::path(name));
  if (controller->GetLocalProcessId() == 0)
  {
    std::error_code error;
    fs::remove_all(dir, error);
    fs::create_directories(dir);
  }
  controller->Barrier();
  return dir.string();
}

/// Runs a shell command (rank 0 only when called so); true on exit status 0.
inline bool Run(const std::string& command)
{
  std::cout.flush();
  const int status = std::system(command.c_str());
  if (status != 0)
  {
    std::cerr << "command failed (" << status << "): " << command << "\n";
  }
  return status == 0;
}

/// The phantom over `extent` of a volume of `dims` samples (every piece equals the same region
/// of the whole volume).
inline vtkSmartPointer<vtkImageData> PhantomPiece(const int dims[3], const int extent[6])
{
  vtkNew<vtkRGPhantomSource> phantom;
  phantom->SetDimensions(dims[0], dims[1], dims[2]);
  phantom->UpdateExtent(const_cast<int*>(extent));
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->DeepCopy(phantom->GetOutput());
  return image;
}

/// Writes the int16 array "HU" of `image` as a .npy file (numpy order [k, j, i]).
inline bool WriteNpy(const std::string& path, vtkImageData* image)
{
  vtkShortArray* hu = vtkShortArray::SafeDownCast(image->GetPointData()->GetArray("HU"));
  int dims[3];
  image->GetDimensions(dims);
  std::ostringstream dict;
  dict << "{'descr': '<i2', 'fortran_order': False, 'shape': (" << dims[2] << ", " << dims[1]
       << ", " << dims[0] << "), }";
  std::string header = dict.str();
  while ((10 + header.size() + 1) % 64 != 0)
  {
    header += ' ';
  }
  header += '\n';
  std::ofstream out(path, std::ios::binary);
  out.write("\x93NUMPY\x01\x00", 8);
  const std::uint16_t length = static_cast<std::uint16_t>(header.size());
  const unsigned char le[2] = { static_cast<unsigned char>(length & 0xff),
    static_cast<unsigned char>(length >> 8) };
  out.write(reinterpret_cast<const char*>(le), 2);
  out << header;
  out.write(reinterpret_cast<const char*>(hu->GetPointer(0)),
    static_cast<std::streamsize>(hu->GetNumberOfValues() * sizeof(short)));
  return static_cast<bool>(out);
}

/// What reading one piece gave.
struct PieceRead
{
  vtkSmartPointer<vtkImageData> Image;
  std::string Errors, Warnings;
  bool Ok = false;
};

/// Updates `reader` for one piece as a ParaView pipeline would, catching its messages.
inline PieceRead ReadPiece(vtkAlgorithm* reader, int piece, int pieces, int ghosts)
{
  vtkNew<MessageCatcher> catcher;
  catcher->Watch(reader);
  catcher->Watch(reader->GetExecutive());
  PieceRead r;
  r.Ok = reader->UpdatePiece(piece, pieces, ghosts) != 0;
  r.Image = vtkSmartPointer<vtkImageData>::New();
  r.Image->ShallowCopy(vtkImageData::SafeDownCast(reader->GetOutputDataObject(0)));
  r.Errors = catcher->Errors;
  r.Warnings = catcher->Warnings;
  reader->RemoveObservers(vtkCommand::ErrorEvent);
  reader->RemoveObservers(vtkCommand::WarningEvent);
  reader->GetExecutive()->RemoveObservers(vtkCommand::ErrorEvent);
  reader->GetExecutive()->RemoveObservers(vtkCommand::WarningEvent);
  return r;
}

/// The reader's own message: the text after the "vtkClass (0x...): " prefix of its first line
/// that has one (the executive's failure line follows it).
inline std::string ReaderMessage(const std::string& errors)
{
  const std::size_t at = errors.find("): ");
  if (at == std::string::npos)
  {
    return errors;
  }
  const std::size_t end = errors.find('\n', at);
  return errors.substr(at + 3, end == std::string::npos ? std::string::npos : end - at - 3);
}

/// Checks that reading failed on this rank with a message holding every one of `texts`, the
/// same message as on every other rank, and an empty output.
inline void ExpectError(vtkMultiProcessController* controller, const PieceRead& r,
  const std::string& what, const std::vector<std::string>& texts)
{
  const int rank = controller->GetLocalProcessId();
  const std::string message = ReaderMessage(r.Errors);
  RGMC_CHECK(!r.Ok, what << " (rank " << rank << "): the update succeeded");
  for (const std::string& text : texts)
  {
    RGMC_CHECK(message.find(text) != std::string::npos,
      what << " (rank " << rank << "): expected '" << text << "' in [" << message << "]");
  }
  RGMC_CHECK(r.Image->GetNumberOfPoints() == 0 || r.Image->GetPointData()->GetScalars() == nullptr,
    what << " (rank " << rank << "): output not empty");
  RGMC_CHECK(SameOnAllRanks(controller, message), what << ": the ranks' messages differ");
  if (rank == 0)
  {
    std::cout << what << ": " << message << "\n";
  }
}

} // namespace rgmc_test

#endif

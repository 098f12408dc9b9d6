// The NIfTI-1 reader: the header on rank 0, broadcast; each rank seeks (.nii) or streams through
// zlib (.nii.gz) to the bytes of its own slab.
#include "vtkRGNIfTIReader.h"

#include "vtkRGMessage.h"

#include "vtkDataArray.h"
#include "vtkMath.h"
#include "vtkObjectFactory.h"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <vector>

vtkStandardNewMacro(vtkRGNIfTIReader);

namespace
{

constexpr int HeaderSize = 348;

/// A gzip stream (zlib reads an uncompressed file through the same calls), closed on scope exit.
class GzFile
{
public:
  explicit GzFile(const std::string& path)
    : File(gzopen(path.c_str(), "rb"))
  {
    if (this->File)
    {
      gzbuffer(this->File, 1 << 17);
    }
  }
  ~GzFile()
  {
    if (this->File)
    {
      gzclose(this->File);
    }
  }
  GzFile(const GzFile&) = delete;
  GzFile& operator=(const GzFile&) = delete;

  /// Reads `count` bytes from `offset` on; returns how many it read (-1 on a zlib error).
  long long Read(std::uint64_t offset, unsigned char* out, std::uint64_t count)
  {
    if (gzseek(this->File, static_cast<z_off_t>(offset), SEEK_SET) < 0)
    {
      return 0; // past the end of the data: nothing to read there
    }
    std::uint64_t done = 0;
    while (done < count)
    {
      const unsigned chunk = static_cast<unsigned>(std::min<std::uint64_t>(count - done, 1u << 30));
      const int got = gzread(this->File, out + done, chunk);
      if (got < 0)
      {
        return -1;
      }
      if (got == 0)
      {
        break;
      }
      done += static_cast<std::uint64_t>(got);
    }
    return static_cast<long long>(done);
  }
  std::string Error()
  {
    int code = 0;
    const char* text = gzerror(this->File, &code);
    return text ? text : "unknown zlib error";
  }

  gzFile File;
};

void SwapBytes(unsigned char* data, int size)
{
  std::reverse(data, data + size);
}

/// The header fields the reader uses, in host byte order.
struct Header
{
  bool ByteSwapped = false; // the file's byte order is not this host's
  std::int16_t Dim[8] = {};
  std::int16_t DataType = 0, BitPix = 0, QFormCode = 0, SFormCode = 0;
  float PixDim[8] = {}, VoxOffset = 0, SclSlope = 0, SclInter = 0;
  float Quatern[3] = {}, QOffset[3] = {}, SRow[3][4] = {};
  char Magic[4] = {};
};

template <typename T>
T Field(const unsigned char* raw, int offset, bool swap)
{
  T value;
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, raw + offset, sizeof(T));
  if (swap)
  {
    SwapBytes(bytes, sizeof(T));
  }
  std::memcpy(&value, bytes, sizeof(T));
  return value;
}

/// Parses a 348-byte header; false with `problem` when it is not a single-file NIfTI-1 header.
bool ParseHeader(const unsigned char* raw, Header& h, std::string& problem)
{
  const std::int32_t size = Field<std::int32_t>(raw, 0, false);
  const std::int32_t swapped = Field<std::int32_t>(raw, 0, true);
  if (size == 540 || swapped == 540)
  {
    problem = "is a NIfTI-2 file: only NIfTI-1 is read";
    return false;
  }
  if (size != HeaderSize && swapped != HeaderSize)
  {
    problem = "is not a NIfTI-1 file (its header size is " + std::to_string(size) + ", not 348)";
    return false;
  }
  h.ByteSwapped = size != HeaderSize;
  std::memcpy(h.Magic, raw + 344, 4);
  if (std::memcmp(h.Magic, "ni1", 4) == 0)
  {
    problem = "is the header of a .hdr/.img pair: only single-file NIfTI (.nii, .nii.gz) is read";
    return false;
  }
  if (std::memcmp(h.Magic, "n+1", 4) != 0)
  {
    problem = "has no NIfTI-1 magic 'n+1' (an Analyze 7.5 file?): only NIfTI-1 is read";
    return false;
  }
  for (int d = 0; d < 8; ++d)
  {
    h.Dim[d] = Field<std::int16_t>(raw, 40 + 2 * d, h.ByteSwapped);
    h.PixDim[d] = Field<float>(raw, 76 + 4 * d, h.ByteSwapped);
  }
  h.DataType = Field<std::int16_t>(raw, 70, h.ByteSwapped);
  h.BitPix = Field<std::int16_t>(raw, 72, h.ByteSwapped);
  h.VoxOffset = Field<float>(raw, 108, h.ByteSwapped);
  h.SclSlope = Field<float>(raw, 112, h.ByteSwapped);
  h.SclInter = Field<float>(raw, 116, h.ByteSwapped);
  h.QFormCode = Field<std::int16_t>(raw, 252, h.ByteSwapped);
  h.SFormCode = Field<std::int16_t>(raw, 254, h.ByteSwapped);
  for (int a = 0; a < 3; ++a)
  {
    h.Quatern[a] = Field<float>(raw, 256 + 4 * a, h.ByteSwapped);
    h.QOffset[a] = Field<float>(raw, 268 + 4 * a, h.ByteSwapped);
    for (int c = 0; c < 4; ++c)
    {
      h.SRow[a][c] = Field<float>(raw, 280 + 16 * a + 4 * c, h.ByteSwapped);
    }
  }
  return true;
}

/// Bytes per voxel and the VTK type of a NIfTI datatype; 0 when not read.
int DataTypeSize(int datatype, int& vtkType)
{
  switch (datatype)
  {
    case 2:
      vtkType = VTK_UNSIGNED_CHAR;
      return 1;
    case 256:
      vtkType = VTK_SIGNED_CHAR;
      return 1;
    case 4:
      vtkType = VTK_SHORT;
      return 2;
    case 512:
      vtkType = VTK_UNSIGNED_SHORT;
      return 2;
    case 8:
      vtkType = VTK_INT;
      return 4;
    case 768:
      vtkType = VTK_UNSIGNED_INT;
      return 4;
    case 16:
      vtkType = VTK_FLOAT;
      return 4;
    case 1024:
      vtkType = VTK_LONG_LONG;
      return 8;
    case 1280:
      vtkType = VTK_UNSIGNED_LONG_LONG;
      return 8;
    case 64:
      vtkType = VTK_DOUBLE;
      return 8;
    default:
      return 0;
  }
}

std::string DataTypeName(int datatype)
{
  switch (datatype)
  {
    case 32:
      return "complex64";
    case 128:
      return "RGB24";
    case 1536:
      return "float128";
    case 1792:
      return "complex128";
    case 2048:
      return "complex256";
    case 2304:
      return "RGBA32";
    default:
      return "code " + std::to_string(datatype);
  }
}

template <typename T>
double Value(const unsigned char* p, bool swap)
{
  return static_cast<double>(Field<T>(p, 0, swap));
}

/// One stored voxel as a double.
double Voxel(const unsigned char* p, int vtkType, bool swap)
{
  switch (vtkType)
  {
    case VTK_UNSIGNED_CHAR:
      return Value<std::uint8_t>(p, false);
    case VTK_SIGNED_CHAR:
      return Value<std::int8_t>(p, false);
    case VTK_SHORT:
      return Value<std::int16_t>(p, swap);
    case VTK_UNSIGNED_SHORT:
      return Value<std::uint16_t>(p, swap);
    case VTK_INT:
      return Value<std::int32_t>(p, swap);
    case VTK_UNSIGNED_INT:
      return Value<std::uint32_t>(p, swap);
    case VTK_FLOAT:
      return Value<float>(p, swap);
    case VTK_LONG_LONG:
      return Value<std::int64_t>(p, swap);
    case VTK_UNSIGNED_LONG_LONG:
      return Value<std::uint64_t>(p, swap);
    default:
      return Value<double>(p, swap);
  }
}

std::string Describe(double v)
{
  char text[40];
  std::snprintf(text, sizeof(text), "%.6g", v);
  return text;
}

} // namespace

//------------------------------------------------------------------------------
int vtkRGNIfTIReader::CanReadFile(const char* name)
{
  std::error_code error;
  if (!name || !std::filesystem::is_regular_file(name, error))
  {
    return 0;
  }
  GzFile file(name);
  unsigned char raw[HeaderSize];
  Header h;
  std::string problem;
  return file.File && file.Read(0, raw, HeaderSize) == HeaderSize && ParseHeader(raw, h, problem)
    ? 1
    : 0;
}

namespace
{

/// What the header scan has found so far, pass by pass.
struct VolumeScan
{
  std::string Path; // FileName
  // PASS 1
  Header Fields;           // the header, in host byte order
  bool Compressed = false; // a gzip stream (.nii.gz)
  // PASS 2 and 3
  int Dimensions[3] = { 1, 1, 1 };
  int StoredType = 0;    // the VTK type of the stored voxels
  int BytesPerVoxel = 0; // of the stored voxels
  // PASS 4
  double Slope = 1.0, Intercept = 0.0;
  // PASS 5
  int GeometryMethod = 1; // which matrix placed the volume: 3 sform, 2 qform, 1 pixdim only
  double Spacing[3] = { 1, 1, 1 };
  double Origin[3] = { 0, 0, 0 };
  double Direction[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 1 }; // row-major, LPS
  std::ostringstream Warnings;                         // one per line
};

/// PASS 1: the 348-byte header, read through zlib (compressed or not) and parsed.
bool ReadHeader(VolumeScan& scan, std::string& message)
{
  std::error_code error;
  if (!std::filesystem::is_regular_file(scan.Path, error))
  {
    message = std::filesystem::exists(scan.Path, error) ? "not a file" : "no such file";
    return false;
  }
  GzFile file(scan.Path);
  unsigned char raw[HeaderSize];
  const long long got = file.File ? file.Read(0, raw, HeaderSize) : -1;
  if (got < 0)
  {
    message = "cannot read its header (" + (file.File ? file.Error() : "cannot open") + ")";
    return false;
  }
  if (got < HeaderSize)
  {
    message = "is truncated: its header has " + std::to_string(got) + " of 348 bytes";
    return false;
  }
  if (!ParseHeader(raw, scan.Fields, message))
  {
    return false;
  }
  scan.Compressed = gzdirect(file.File) == 0;
  return true;
}

/// PASS 2: dimensions x, y, z; a fourth and later dimension beyond 1 gives the first volume.
bool ReadDimensions(VolumeScan& scan, std::string& message)
{
  const Header& h = scan.Fields;
  if (h.Dim[0] < 1 || h.Dim[0] > 7)
  {
    message = "has dim[0] = " + std::to_string(h.Dim[0]) + " (1 to 7 dimensions are valid)";
    return false;
  }
  int* dims = scan.Dimensions;
  for (int a = 0; a < 3; ++a)
  {
    if (a < h.Dim[0])
    {
      dims[a] = h.Dim[a + 1];
      if (dims[a] < 1)
      {
        message = "has dim[" + std::to_string(a + 1) + "] = " + std::to_string(dims[a]) +
          ": dimensions must be at least 1";
        return false;
      }
    }
  }
  long long volumes = 1;
  for (int d = 4; d <= h.Dim[0]; ++d)
  {
    if (h.Dim[d] < 1)
    {
      message = "has dim[" + std::to_string(d) + "] = " + std::to_string(h.Dim[d]);
      return false;
    }
    volumes *= h.Dim[d];
  }
  if (volumes > 1)
  {
    scan.Warnings << scan.Path << " holds " << volumes << " volumes: the first is read\n";
  }
  return true;
}

/// PASS 3: how the voxels are stored (a datatype read, its bitpix, where they start), and, in an
/// uncompressed file, that they are all there.
bool CheckVoxelData(VolumeScan& scan, std::string& message)
{
  const Header& h = scan.Fields;
  const int bytes = DataTypeSize(h.DataType, scan.StoredType);
  scan.BytesPerVoxel = bytes;
  if (bytes == 0)
  {
    message = "has the datatype " + DataTypeName(h.DataType) +
      ", which is not read (integers and real numbers of one component are)";
    return false;
  }
  if (h.BitPix != 8 * bytes)
  {
    message = "has bitpix " + std::to_string(h.BitPix) + " for a datatype of " +
      std::to_string(8 * bytes) + " bits";
    return false;
  }
  if (!std::isfinite(h.VoxOffset) || h.VoxOffset < HeaderSize + 4 ||
    h.VoxOffset != std::floor(h.VoxOffset))
  {
    message = "has vox_offset " + Describe(h.VoxOffset) + " (at least 352, a whole number)";
    return false;
  }
  const int* dims = scan.Dimensions;
  const std::uint64_t voxels = static_cast<std::uint64_t>(dims[0]) * dims[1] * dims[2];
  const std::uint64_t needed = static_cast<std::uint64_t>(h.VoxOffset) + voxels * bytes;
  if (!scan.Compressed)
  {
    std::error_code error;
    const std::uint64_t size = std::filesystem::file_size(scan.Path, error);
    if (!error && size < needed)
    {
      message = "is truncated: it has " + std::to_string(size) + " bytes, its header announces " +
        std::to_string(needed) + " (" + std::to_string(dims[0]) + " x " + std::to_string(dims[1]) +
        " x " + std::to_string(dims[2]) + " voxels of " + std::to_string(bytes) +
        " bytes from byte " + Describe(h.VoxOffset) + ")";
      return false;
    }
  }
  return true;
}

/// The range of the scaled samples, whether they are all integers, and whether float cannot
/// hold the stored values.
struct SampleRange
{
  bool Integral = false;
  double Lo = 0, Hi = 0;
  bool Wide = false;
};

/// PASS 4: the scaling, none when scl_slope is 0 or not finite (the standard's rule), and the
/// range it gives the stored type.
SampleRange ReadScaling(VolumeScan& scan)
{
  const Header& h = scan.Fields;
  if (std::isfinite(h.SclSlope) && h.SclSlope != 0)
  {
    scan.Slope = h.SclSlope;
    scan.Intercept = std::isfinite(h.SclInter) ? h.SclInter : 0.0;
  }
  const bool integerData = scan.StoredType != VTK_FLOAT && scan.StoredType != VTK_DOUBLE;
  double stored[2];
  vtkDataArray::GetDataTypeRange(scan.StoredType, stored);
  const double a = scan.Slope * stored[0] + scan.Intercept;
  const double b = scan.Slope * stored[1] + scan.Intercept;
  SampleRange range;
  range.Integral = integerData && scan.Slope == std::floor(scan.Slope) &&
    scan.Intercept == std::floor(scan.Intercept);
  range.Lo = std::min(a, b);
  range.Hi = std::max(a, b);
  range.Wide =
    scan.StoredType == VTK_DOUBLE || (integerData && (stored[1] - stored[0]) > 16777216.0);
  return range;
}

/// Whether the columns of a 3x3 matrix are non-zero and orthogonal (to 1e-4 of their lengths).
bool ColumnsOrthogonal(const double matrix[3][3])
{
  for (int p = 0; p < 3; ++p)
  {
    for (int q = p + 1; q < 3; ++q)
    {
      double dot = 0, np = 0, nq = 0;
      for (int r = 0; r < 3; ++r)
      {
        dot += matrix[r][p] * matrix[r][q];
        np += matrix[r][p] * matrix[r][p];
        nq += matrix[r][q] * matrix[r][q];
      }
      if (np == 0 || nq == 0 || std::fabs(dot) > 1e-4 * std::sqrt(np * nq))
      {
        return false;
      }
    }
  }
  return true;
}

/// The qform's voxel-to-world matrix (its quaternion's rotation, scaled by pixdim, the third
/// column flipped when qfac is negative) and its offset.
void QFormMatrix(const Header& h, const double spacing[3], double matrix[3][3], double origin[3])
{
  const double qb = h.Quatern[0], qc = h.Quatern[1], qd = h.Quatern[2];
  double qa = 1.0 - (qb * qb + qc * qc + qd * qd);
  qa = qa > 0 ? std::sqrt(qa) : 0.0;
  const double qfac = h.PixDim[0] < 0 ? -1.0 : 1.0;
  const double r[3][3] = { { qa * qa + qb * qb - qc * qc - qd * qd, 2 * (qb * qc - qa * qd),
                             2 * (qb * qd + qa * qc) },
    { 2 * (qb * qc + qa * qd), qa * qa + qc * qc - qb * qb - qd * qd, 2 * (qc * qd - qa * qb) },
    { 2 * (qb * qd - qa * qc), 2 * (qc * qd + qa * qb), qa * qa + qd * qd - qc * qc - qb * qb } };
  for (int row = 0; row < 3; ++row)
  {
    for (int c = 0; c < 3; ++c)
    {
      matrix[row][c] = r[row][c] * spacing[c] * (c == 2 ? qfac : 1.0);
    }
    origin[row] = h.QOffset[row];
  }
}

/// PASS 5, first step: the voxel-to-world matrix (RAS) and origin: the sform when sform_code > 0
/// (a shearing one gives way to a qform), else the qform when qform_code > 0, else pixdim.
bool VoxelToWorld(VolumeScan& scan, double matrix[3][3], std::string& message)
{
  const Header& h = scan.Fields;
  double spacing[3];
  for (int c = 0; c < 3; ++c)
  {
    spacing[c] = std::fabs(h.PixDim[c + 1]);
    if (!std::isfinite(spacing[c]) || spacing[c] == 0)
    {
      spacing[c] = 1.0;
    }
  }
  bool useS = h.SFormCode > 0;
  if (useS)
  {
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 3; ++c)
      {
        matrix[r][c] = h.SRow[r][c];
      }
    }
    if (!ColumnsOrthogonal(matrix))
    {
      if (h.QFormCode > 0)
      {
        scan.Warnings << scan.Path << " has a shearing (or degenerate) sform: its qform places "
                      << "the volume\n";
        useS = false;
      }
      else
      {
        message = "has an sform whose columns are not orthogonal (a shear) and no qform: "
                  "the volume cannot be placed on a grid";
        return false;
      }
    }
  }
  if (useS)
  {
    scan.GeometryMethod = 3;
    for (int r = 0; r < 3; ++r)
    {
      scan.Origin[r] = h.SRow[r][3];
    }
  }
  else if (h.QFormCode > 0)
  {
    scan.GeometryMethod = 2;
    QFormMatrix(h, spacing, matrix, scan.Origin);
  }
  else
  {
    for (int c = 0; c < 3; ++c)
    {
      matrix[c][c] = spacing[c];
    }
    scan.Warnings << scan.Path << " has neither a qform nor an sform: placed at the origin with "
                  << "its pixdim spacing, axes as stored\n";
  }
  return true;
}

/// PASS 5: geometry. The voxel-to-world matrix's columns, normalized, are the direction matrix
/// and their lengths the spacing; the world is turned from NIfTI's RAS into DICOM's LPS.
bool PlaceVolume(VolumeScan& scan, std::string& message)
{
  double matrix[3][3] = { { 0, 0, 0 }, { 0, 0, 0 }, { 0, 0, 0 } };
  if (!VoxelToWorld(scan, matrix, message))
  {
    return false;
  }
  for (int c = 0; c < 3; ++c)
  {
    const double length = std::sqrt(
      matrix[0][c] * matrix[0][c] + matrix[1][c] * matrix[1][c] + matrix[2][c] * matrix[2][c]);
    if (!(length > 0) || !std::isfinite(length))
    {
      message = "has a voxel-to-world matrix with a zero or invalid column " + std::to_string(c);
      return false;
    }
    scan.Spacing[c] = length;
    for (int r = 0; r < 3; ++r)
    {
      scan.Direction[3 * r + c] = matrix[r][c] / length;
    }
  }
  for (int a = 0; a < 3; ++a)
  {
    if (!std::isfinite(scan.Origin[a]))
    {
      message = "has a non-finite origin";
      return false;
    }
  }
  if (scan.GeometryMethod > 1)
  {
    // RAS to LPS: negate x and y of every world point.
    for (int c = 0; c < 3; ++c)
    {
      scan.Direction[c] = -scan.Direction[c];
      scan.Direction[3 + c] = -scan.Direction[3 + c];
    }
    scan.Origin[0] = -scan.Origin[0];
    scan.Origin[1] = -scan.Origin[1];
  }
  return true;
}

/// The scan in words, for the log: the size, the geometry's source, the spacing, the scaling.
std::string Summarize(const VolumeScan& scan)
{
  const int* dims = scan.Dimensions;
  std::ostringstream summary;
  summary << "NIfTI-1 " << (scan.Compressed ? "(gzip) " : "") << dims[0] << " x " << dims[1]
          << " x " << dims[2] << ", "
          << (scan.GeometryMethod == 3      ? "sform"
                 : scan.GeometryMethod == 2 ? "qform"
                                            : "pixdim")
          << " geometry, spacing " << Describe(scan.Spacing[0]) << " x "
          << Describe(scan.Spacing[1]) << " x " << Describe(scan.Spacing[2]) << " mm, scaling "
          << Describe(scan.Slope) << " * stored + " << Describe(scan.Intercept);
  return summary.str();
}

} // namespace

//------------------------------------------------------------------------------
// Rank 0 alone runs the scan, and it makes no collective call: vtkRGVolumeReader's
// RequestInformation agrees on its status over all ranks, then broadcasts the header it writes.
//
//  PASS 1 ReadHeader      the 348-byte header, either byte order, compressed or not
//  PASS 2 ReadDimensions  x, y, z (the first volume of a 4-D file)
//  PASS 3 CheckVoxelData  the datatype, where the voxels start, a truncated .nii
//  PASS 4 ReadScaling     scl_slope and scl_inter, and the output type they give
//  PASS 5 PlaceVolume     sform, else qform, else pixdim; RAS turned into LPS
bool vtkRGNIfTIReader::Scan(std::vector<vtkIdType>& header, std::string& message)
{
  VolumeScan scan;
  scan.Path = this->FileName;
  // PASS 1: the header.
  if (!ReadHeader(scan, message))
  {
    return false;
  }
  // PASS 2: dimensions; a fourth and later dimension beyond 1 gives the first volume.
  if (!ReadDimensions(scan, message))
  {
    return false;
  }
  // PASS 3: the stored voxels.
  if (!CheckVoxelData(scan, message))
  {
    return false;
  }
  // PASS 4: scaling and the output type.
  const SampleRange range = ReadScaling(scan);
  const int type = ChooseScalarType(range.Integral, range.Lo, range.Hi, range.Wide);
  // PASS 5: geometry, in DICOM's patient coordinates.
  if (!PlaceVolume(scan, message))
  {
    return false;
  }
  // The header every rank parses, in the order Parse reads it.
  header.clear();
  rgmc::MessageWriter p(header);
  PackGeometry(p, scan.Dimensions, scan.Spacing, scan.Origin, scan.Direction, type);
  p.Int(scan.StoredType).Int(scan.BytesPerVoxel).Int(scan.Fields.ByteSwapped ? 1 : 0);
  p.Real(scan.Fields.VoxOffset);
  p.Real(scan.Slope).Real(scan.Intercept).Int(scan.GeometryMethod);
  p.Text(scan.Warnings.str()).Text(Summarize(scan));
  return true;
}

//------------------------------------------------------------------------------
bool vtkRGNIfTIReader::Parse(const std::vector<vtkIdType>& header, std::string& message)
{
  rgmc::MessageReader u(header);
  this->UnpackGeometry(u);
  this->DataType = static_cast<int>(u.Int());
  this->BytesPerVoxel = static_cast<int>(u.Int());
  this->ByteSwapped = u.Int() != 0;
  this->VoxelOffset = u.Real();
  this->RescaleSlope = u.Real();
  this->RescaleIntercept = u.Real();
  this->GeometryMethod = static_cast<int>(u.Int());
  this->Warnings = u.Text();
  this->Summary = u.Text();
  this->NumberOfComponents = 1;
  this->ArrayName = "Intensity";
  if (!u.Ok())
  {
    this->OutputScalarType = 0;
    message = "the header broadcast from rank 0 is damaged";
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkRGNIfTIReader::ReadExtent(const int extent[6], vtkDataArray* scalars, std::string& message)
{
  GzFile file(this->FileName);
  if (!file.File)
  {
    message = "cannot open it to read its voxels";
    return false;
  }
  const std::uint64_t nx = static_cast<std::uint64_t>(this->Dimensions[0]);
  const std::uint64_t ny = static_cast<std::uint64_t>(this->Dimensions[1]);
  const int bytes = this->BytesPerVoxel;
  const int width = extent[1] - extent[0] + 1;
  const int rows = extent[3] - extent[2] + 1;
  std::vector<unsigned char> chunk(static_cast<std::size_t>(rows) * nx * bytes);
  std::vector<double> values(static_cast<std::size_t>(width));
  vtkIdType at = 0;
  // PASS: slice by slice, the rows of the extent in one read each (increasing offsets, so a
  // compressed stream is decompressed once up to the end of the slab).
  for (int k = extent[4]; k <= extent[5]; ++k)
  {
    const std::uint64_t offset = static_cast<std::uint64_t>(this->VoxelOffset) +
      ((static_cast<std::uint64_t>(k) * ny + extent[2]) * nx) * bytes;
    const long long got = file.Read(offset, chunk.data(), chunk.size());
    if (got < 0)
    {
      message = "its compressed data is corrupt near slice " + std::to_string(k) + " (" +
        file.Error() + ")";
      return false;
    }
    if (static_cast<std::uint64_t>(got) < chunk.size())
    {
      message = "is truncated: its voxel data ends in slice " + std::to_string(k) + " of " +
        std::to_string(this->Dimensions[2]) + " (byte " +
        std::to_string(offset + static_cast<std::uint64_t>(got)) + ")";
      return false;
    }
    for (int j = 0; j < rows; ++j)
    {
      const unsigned char* row =
        chunk.data() + (static_cast<std::size_t>(j) * nx + extent[0]) * bytes;
      for (int i = 0; i < width; ++i)
      {
        values[i] = this->RescaleSlope *
            Voxel(row + static_cast<std::size_t>(i) * bytes, this->DataType, this->ByteSwapped) +
          this->RescaleIntercept;
      }
      Store(scalars, at, values.data(), values.size());
      at += width;
    }
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkRGNIfTIReader::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "RescaleSlope: " << this->RescaleSlope << "\n";
  os << indent << "RescaleIntercept: " << this->RescaleIntercept << "\n";
  os << indent << "GeometryMethod: " << this->GeometryMethod << "\n";
  os << indent << "VoxelOffset: " << this->VoxelOffset << "\n";
  os << indent << "DataType: " << this->DataType << "\n";
  os << indent << "BytesPerVoxel: " << this->BytesPerVoxel << "\n";
  os << indent << "ByteSwapped: " << this->ByteSwapped << "\n";
}

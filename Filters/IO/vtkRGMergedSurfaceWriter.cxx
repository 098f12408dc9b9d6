// Writes a distributed surface as one mesh without gathering it: every rank writes its own
// records into the one file at offsets that every rank can compute (see the header).
#include "vtkRGMergedSurfaceWriter.h"

#include "vtkRGCollective.h"
#include "vtkRGMessage.h"
#include "vtkRGRunController.h"
#include "vtkRGSeamRepair.h"

#include "vtkCallbackCommand.h"
#include "vtkCellArray.h"
#include "vtkDataArray.h"
#include "vtkDataSetAttributes.h"
#include "vtkFieldData.h"
#include "vtkIdList.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkUnsignedCharArray.h"
#include "vtkXMLPPolyDataWriter.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <limits>
#include <new>
#include <string>
#include <sys/stat.h>
#include <unistd.h>
#include <utility>
#include <vector>

vtkStandardNewMacro(vtkRGMergedSurfaceWriter);
vtkCxxSetObjectMacro(vtkRGMergedSurfaceWriter, Controller, vtkMultiProcessController);

namespace
{
using Int = std::int64_t;

/// A file of which this rank writes byte ranges (POSIX pwrite). Records at consecutive offsets
/// are buffered and go out in one call; the first failure is kept, with the system's reason.
class RangeFile
{
public:
  ~RangeFile() { this->Close(); }

  /// Creates a new file beside `target` (in its directory, under a name of its own), which
  /// Replace later renames over it: so an earlier file at `target` stays whole until the new one
  /// is complete. A target that exists and is not a regular file (a device, a pipe) is written
  /// in place; a symbolic link is followed. Errors name the target.
  bool CreateBeside(const std::string& target)
  {
    this->Shown = target;
    this->Target = target;
    struct stat st;
    if (::lstat(target.c_str(), &st) == 0 && S_ISLNK(st.st_mode))
    {
      if (char* real = ::realpath(target.c_str(), nullptr))
      {
        this->Target = real;
        std::free(real);
      }
      else // a link to a file yet to be made
      {
        std::vector<char> to(static_cast<std::size_t>(st.st_size) + 1, '\0');
        const ssize_t n = ::readlink(target.c_str(), to.data(), to.size() - 1);
        const std::size_t slash = target.find_last_of('/');
        if (n > 0)
        {
          const std::string link(to.data(), static_cast<std::size_t>(n));
          this->Target = link[0] == '/' || slash == std::string::npos
            ? link
            : target.substr(0, slash + 1) + link;
        }
      }
    }
    if (::stat(this->Target.c_str(), &st) == 0 && !S_ISREG(st.st_mode))
    {
      this->Path = this->Target; // written in place: nothing to replace
      this->Descriptor = ::open(this->Path.c_str(), O_WRONLY | O_CLOEXEC | O_TRUNC);
    }
    else
    {
      for (int attempt = 0; attempt < 100 && this->Descriptor < 0; ++attempt)
      {
        this->Path = this->Target + ".rgmc-" + std::to_string(::getpid()) + "-" +
          std::to_string(attempt) + ".part";
        this->Descriptor =
          ::open(this->Path.c_str(), O_WRONLY | O_CLOEXEC | O_CREAT | O_EXCL, 0666);
        if (this->Descriptor < 0 && errno != EEXIST)
        {
          break;
        }
      }
    }
    if (this->Descriptor < 0)
    {
      this->Fail("cannot create ");
    }
    return !this->Failed;
  }

  /// Opens the file that rank 0 created (CreateBeside's Path) for `target`.
  bool Open(const std::string& path, const std::string& target)
  {
    this->Path = path;
    this->Shown = target;
    this->Descriptor = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
    if (this->Descriptor < 0)
    {
      this->Fail("cannot open ");
    }
    return !this->Failed;
  }

  /// The file being written (the temporary one, or the target written in place).
  const std::string& Written() const { return this->Path; }

  /// Whether Replace has anything to do (the file was written beside its target).
  bool Beside() const { return !this->Target.empty() && this->Path != this->Target; }

  /// Renames the complete file over its target (CreateBeside's side only), then makes the
  /// rename durable in the directory.
  bool Replace()
  {
    if (!this->Beside())
    {
      return true;
    }
    if (::rename(this->Path.c_str(), this->Target.c_str()) != 0)
    {
      this->Fail("cannot replace ");
      return false;
    }
    const std::size_t slash = this->Target.find_last_of('/');
    const std::string directory = slash == std::string::npos
      ? std::string(".")
      : (slash == 0 ? std::string("/") : this->Target.substr(0, slash));
    const int d = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (d >= 0)
    {
      ::fsync(d); // best effort: the rename is done either way
      ::close(d);
    }
    return true;
  }

  /// Removes the file written beside the target (after a failure anywhere).
  void Discard()
  {
    this->Close();
    if (this->Beside())
    {
      ::unlink(this->Path.c_str());
    }
  }

  void Write(Int offset, const char* data, std::size_t size)
  {
    if (this->Failed)
    {
      return;
    }
    if (!this->Buffer.empty() &&
      offset != this->BufferStart + static_cast<Int>(this->Buffer.size()))
    {
      this->Flush();
    }
    if (this->Buffer.empty())
    {
      this->BufferStart = offset;
    }
    this->Buffer.insert(this->Buffer.end(), data, data + size);
    if (this->Buffer.size() >= Capacity)
    {
      this->Flush();
    }
  }

  bool Flush()
  {
    std::size_t done = 0;
    while (!this->Failed && done < this->Buffer.size())
    {
      const ssize_t n = ::pwrite(this->Descriptor, this->Buffer.data() + done,
        this->Buffer.size() - done, static_cast<off_t>(this->BufferStart + static_cast<Int>(done)));
      if (n < 0 && errno == EINTR)
      {
        continue;
      }
      if (n <= 0)
      {
        if (n == 0)
        {
          errno = ENOSPC;
        }
        this->Fail("cannot write ");
      }
      else
      {
        done += static_cast<std::size_t>(n);
      }
    }
    this->Buffer.clear();
    return !this->Failed;
  }

  /// Writes out what is buffered, makes it durable (so that the file renamed over the target
  /// is complete even after a crash), and closes the file.
  bool Close()
  {
    if (this->Descriptor >= 0)
    {
      this->Flush();
      if (!this->Failed && ::fsync(this->Descriptor) != 0 && errno != EINVAL && errno != EROFS)
      {
        this->Fail("cannot write ");
      }
      if (::close(this->Descriptor) != 0 && !this->Failed)
      {
        this->Fail("cannot close ");
      }
      this->Descriptor = -1;
    }
    return !this->Failed;
  }

  bool Failed = false;
  std::string Problem;

private:
  static constexpr std::size_t Capacity = std::size_t(4) << 20;

  void Fail(const char* what)
  {
    const int error = errno;
    this->Failed = true;
    this->Problem = std::string(what) + this->Shown + ": " + std::strerror(error);
  }

  std::string Path;   // the file written
  std::string Shown;  // the file the user named, for errors
  std::string Target; // what Replace renames Path over (symbolic links followed)
  int Descriptor = -1;
  Int BufferStart = 0;
  std::vector<char> Buffer;
};

/// A run of fixed-size records in the file: record i lies at Start + i * Size.
struct Block
{
  Int Start = 0;
  Int Size = 0;
};

/// Where everything goes in the file: the texts that rank 0 writes, and the record blocks.
struct Layout
{
  std::vector<std::pair<Int, std::string>> Texts;
  Int End = 0;

  void Text(const std::string& text)
  {
    this->Texts.emplace_back(this->End, text);
    this->End += static_cast<Int>(text.size());
  }
  Block Records(Int count, Int size)
  {
    Block b{ this->End, size };
    this->End += count * size;
    return b;
  }
};

bool HostIsBigEndian()
{
  const std::uint16_t one = 1;
  return *reinterpret_cast<const unsigned char*>(&one) == 0;
}
const bool BigEndianHost = HostIsBigEndian();

// Little-endian bytes whatever the host.
template <typename T>
char* PutLittleEndian(char* out, T value)
{
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if (BigEndianHost)
  {
    std::reverse(bytes, bytes + sizeof(T));
  }
  std::memcpy(out, bytes, sizeof(T));
  return out + sizeof(T);
}

const char Base64Digits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/// Base64 of `size` bytes into `out`; returns its length. A multiple of 3 gives no padding, so
/// such records concatenate into one valid stream.
std::size_t Base64(const char* data, std::size_t size, char* out)
{
  char* start = out;
  const auto* in = reinterpret_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < size; i += 3)
  {
    const unsigned a = in[i], b = i + 1 < size ? in[i + 1] : 0, c = i + 2 < size ? in[i + 2] : 0;
    *out++ = Base64Digits[a >> 2];
    *out++ = Base64Digits[((a & 3) << 4) | (b >> 4)];
    *out++ = i + 1 < size ? Base64Digits[((b & 15) << 2) | (c >> 6)] : '=';
    *out++ = i + 2 < size ? Base64Digits[c & 63] : '=';
  }
  return static_cast<std::size_t>(out - start);
}

/// Text of fixed width: a number with its sign or a space, in scientific notation with all the
/// digits its type needs to read back exactly (9 significant digits for float, 17 for double).
/// Returns the length: 15 for float, 23 for double; anything else (not finite, or a double beyond
/// 1e100) does not fit the file's fixed-width records.
int FixedReal(char* out, double value, bool isDouble)
{
  // A space, not '+', before positive numbers: VTK 9.3's PLY reader reads "+1.5" as 0.
  return std::snprintf(out, 32, isDouble ? "% .16e" : "% .8e",
    isDouble ? value : static_cast<double>(static_cast<float>(value)));
}

/// Number of decimal digits of the largest of `value` and 1.
int Digits(Int value)
{
  int digits = 1;
  for (; value >= 10; value /= 10)
  {
    ++digits;
  }
  return digits;
}

enum class Format
{
  STL,
  PLY,
  VTP
};

/// This rank's part of the mesh, in the file's terms.
struct Mesh
{
  vtkPoints* Points = nullptr;
  vtkDataArray* Normals = nullptr;              // 3 components, or none
  vtkIdTypeArray* Ids = nullptr;                // global id of each local point
  std::vector<std::pair<Int, vtkIdType>> Owned; // (global id, local point), by global id
  std::vector<vtkIdType> Triangles;             // 3 local points each
};

enum class Collected
{
  Numbered,    // Seam Repair's numbering: contiguous global ids, duplicates flagged
  NotNumbered, // anything else: the writer numbers it first
  OutOfMemory
};

/// Collects what this rank writes.
Collected Collect(vtkPolyData* pd, Mesh& mesh)
{
  mesh = Mesh();
  try
  {
    mesh.Points = pd->GetPoints();
    const vtkIdType n = pd->GetNumberOfPoints();
    vtkIdTypeArray* ids = vtkIdTypeArray::SafeDownCast(pd->GetPointData()->GetGlobalIds());
    vtkUnsignedCharArray* ghosts = vtkUnsignedCharArray::SafeDownCast(
      pd->GetPointData()->GetArray(vtkDataSetAttributes::GhostArrayName()));
    if (pd->GetNumberOfVerts() + pd->GetNumberOfLines() + pd->GetNumberOfStrips() > 0 ||
      (n > 0 && (!ids || !ghosts || !pd->GetFieldData()->GetArray("UniquePoints"))))
    {
      return Collected::NotNumbered;
    }
    mesh.Ids = ids;
    for (vtkIdType p = 0; p < n; ++p)
    {
      if ((ghosts->GetValue(p) & vtkDataSetAttributes::DUPLICATEPOINT) == 0)
      {
        mesh.Owned.emplace_back(ids->GetValue(p), p);
      }
    }
    std::sort(mesh.Owned.begin(), mesh.Owned.end());
    vtkDataArray* normals = pd->GetPointData()->GetNormals();
    mesh.Normals = normals && normals->GetNumberOfComponents() == 3 ? normals : nullptr;
    vtkCellArray* polys = pd->GetPolys();
    mesh.Triangles.reserve(static_cast<std::size_t>(3 * polys->GetNumberOfCells()));
    vtkNew<vtkIdList> cell;
    for (vtkIdType c = 0; c < polys->GetNumberOfCells(); ++c)
    {
      polys->GetCellAtId(c, cell); // any storage, also VTK 9.6's fixed-size cell arrays
      if (cell->GetNumberOfIds() != 3)
      {
        return Collected::NotNumbered; // Seam Repair's numbering names the problem
      }
      mesh.Triangles.insert(mesh.Triangles.end(), cell->begin(), cell->end());
    }
  }
  catch (const std::bad_alloc&)
  {
    mesh = Mesh();
    return Collected::OutOfMemory;
  }
  return Collected::Numbered;
}

/// Whether the numbering is one this writer can place: every global id in [0, vertices), each
/// owned once.
bool Placeable(const Mesh& mesh, Int vertices)
{
  for (vtkIdType p = 0; mesh.Ids && p < mesh.Ids->GetNumberOfTuples(); ++p)
  {
    if (mesh.Ids->GetValue(p) < 0 || mesh.Ids->GetValue(p) >= vertices)
    {
      return false;
    }
  }
  for (std::size_t i = 1; i < mesh.Owned.size(); ++i)
  {
    if (mesh.Owned[i].first == mesh.Owned[i - 1].first)
    {
      return false;
    }
  }
  return true;
}

/// Records the first error message of `object` (and of what it runs) for the caller.
struct ErrorCatcher
{
  std::string Message;
  vtkNew<vtkCallbackCommand> Command;
  explicit ErrorCatcher(vtkObject* object)
  {
    this->Command->SetClientData(this);
    this->Command->SetCallback(
      [](vtkObject*, unsigned long, void* self, void* text)
      {
        auto* catcher = static_cast<ErrorCatcher*>(self);
        if (catcher->Message.empty() && text)
        {
          catcher->Message = static_cast<const char*>(text);
        }
      });
    object->AddObserver(vtkCommand::ErrorEvent, this->Command);
  }
};

/// One format's file: its layout (the same on every rank) and this rank's records.
class MergedFile
{
public:
  MergedFile(Format format, bool binary, const Mesh& mesh, Int vertices, Int triangles,
    Int firstTriangle, bool normals, bool doublePoints)
    : Kind(format)
    , Binary(binary)
    , LocalMesh(mesh)
    , Vertices(vertices)
    , Triangles(triangles)
    , FirstTriangle(firstTriangle)
    , WithNormals(normals)
    , DoublePoints(doublePoints)
  {
  }

  /// Why this mesh cannot be written in this format (empty when it can).
  std::string Limit() const
  {
    const Int u32 = std::numeric_limits<std::uint32_t>::max();
    if (this->Kind == Format::STL && this->Binary && this->Triangles > u32)
    {
      return "a binary STL file holds at most 4294967295 triangles (its count is 32-bit); this "
             "surface has " +
        std::to_string(this->Triangles) + ": write PLY, VTP or PVTP";
    }
    if (this->Kind == Format::PLY && this->Vertices > u32)
    {
      return "a PLY file's vertex indices are at most 32-bit; this surface has " +
        std::to_string(this->Vertices) + " vertices: write VTP or PVTP";
    }
    return std::string();
  }

  /// Lays the file out: every record's size comes from formatting a sample record, so the
  /// layout and the records cannot disagree.
  void Plan()
  {
    this->IdWidth = Digits(std::max<Int>(this->Vertices - 1, 0));
    this->OffsetWidth = Digits(3 * this->Triangles);
    const double zero[3] = { 0, 0, 0 };
    const vtkIdType sample[3] = { 0, 0, 0 };
    char buffer[RecordCapacity];
    const Int point = this->PointLength = this->PointRecord(buffer, zero, this->DoublePoints);
    const Int normal = this->NormalLength =
      this->WithNormals ? this->PointRecord(buffer, zero, false) : 0;
    const Int triangle = this->TriangleLength = this->TriangleRecord(buffer, sample, true);
    const Int offset = this->OffsetLength = this->OffsetRecord(buffer, 0);
    switch (this->Kind)
    {
      case Format::STL:
        this->PlanStl(triangle);
        break;
      case Format::PLY:
        this->PlanPly(point, normal, triangle);
        break;
      case Format::VTP:
        this->PlanVtp(point, normal, triangle, offset);
        break;
    }
  }

  /// Writes this rank's records (and, with `texts`, the headers). Records go out in file order
  /// where possible, so that the file sees long runs. False with Problem on bad values.
  bool Write(RangeFile& file, bool texts)
  {
    if (texts)
    {
      for (const auto& text : this->FileLayout.Texts)
      {
        file.Write(text.first, text.second.data(), text.second.size());
      }
    }
    char record[RecordCapacity];
    const bool interleaved = this->Kind == Format::PLY;
    // STL has no vertex list: its triangles carry their corners.
    for (const auto& owned : this->Kind == Format::STL ? NoVertices : this->LocalMesh.Owned)
    {
      double x[3];
      this->LocalMesh.Points->GetPoint(owned.second, x);
      const char end = interleaved && this->WithNormals ? ' ' : '\n';
      if (!this->Put(file, this->PointBlock, owned.first,
            this->PointRecord(record, x, this->DoublePoints, end), this->PointLength, record))
      {
        return false;
      }
      if (interleaved && this->WithNormals)
      {
        this->LocalMesh.Normals->GetTuple(owned.second, x);
        if (!this->Put(file, this->NormalBlock, owned.first, this->PointRecord(record, x, false),
              this->NormalLength, record))
        {
          return false;
        }
      }
    }
    if (!interleaved && this->WithNormals)
    {
      for (const auto& owned : this->LocalMesh.Owned)
      {
        double n[3];
        this->LocalMesh.Normals->GetTuple(owned.second, n);
        if (!this->Put(file, this->NormalBlock, owned.first, this->PointRecord(record, n, false),
              this->NormalLength, record))
        {
          return false;
        }
      }
    }
    const Int count = static_cast<Int>(this->LocalMesh.Triangles.size() / 3);
    for (Int t = 0; t < count; ++t)
    {
      const Int index = this->FirstTriangle + t;
      if (!this->Put(file, this->TriangleBlock, index,
            this->TriangleRecord(record, &this->LocalMesh.Triangles[3 * t], false),
            this->TriangleLength, record))
      {
        return false;
      }
    }
    for (Int t = 0; this->Kind == Format::VTP && t < count; ++t)
    {
      const Int index = this->FirstTriangle + t;
      if (!this->Put(file, this->OffsetBlock, index, this->OffsetRecord(record, index),
            this->OffsetLength, record))
      {
        return false;
      }
    }
    return true;
  }

  Int Size() const { return this->FileLayout.End; }
  std::string Problem;

private:
  static constexpr std::size_t RecordCapacity = 1024;
  static const std::vector<std::pair<Int, vtkIdType>> NoVertices;

  // STL: a header, then the facets.
  void PlanStl(Int triangle)
  {
    if (this->Binary)
    {
      // Padded with NULs: STL tools print the header as a C string (admesh 0.98.5 prints
      // the triangle count's bytes after a header padded with spaces).
      std::string header = "RGMC merged surface (binary STL)";
      header.resize(80, '\0');
      char count[4];
      PutLittleEndian(count, static_cast<std::uint32_t>(this->Triangles));
      this->FileLayout.Text(header + std::string(count, 4));
      this->TriangleBlock = this->FileLayout.Records(this->Triangles, triangle);
    }
    else
    {
      this->FileLayout.Text("solid rgmc\n");
      this->TriangleBlock = this->FileLayout.Records(this->Triangles, triangle);
      this->FileLayout.Text("endsolid rgmc\n");
    }
  }

  // PLY: a header, the vertices (coordinates and normal in one record), the faces.
  void PlanPly(Int point, Int normal, Int triangle)
  {
    const std::string real = this->DoublePoints ? "double" : "float";
    std::string header = std::string("ply\nformat ") +
      (this->Binary ? "binary_little_endian" : "ascii") +
      " 1.0\ncomment RGMC merged surface\nelement vertex " + std::to_string(this->Vertices) +
      "\nproperty " + real + " x\nproperty " + real + " y\nproperty " + real + " z\n";
    if (this->WithNormals)
    {
      header += "property float nx\nproperty float ny\nproperty float nz\n";
    }
    header += "element face " + std::to_string(this->Triangles) + "\nproperty list uchar " +
      (this->Vertices > std::numeric_limits<std::int32_t>::max() ? "uint" : "int") +
      " vertex_indices\nend_header\n";
    this->FileLayout.Text(header);
    // A PLY vertex is its coordinates then its normal: one record of both.
    this->PointBlock = this->FileLayout.Records(this->Vertices, point + normal);
    this->NormalBlock = Block{ this->PointBlock.Start + point, point + normal };
    this->TriangleBlock = this->FileLayout.Records(this->Triangles, triangle);
  }

  // VTP: the XML around inline arrays: normals, points, connectivity, offsets.
  void PlanVtp(Int point, Int normal, Int triangle, Int offset)
  {
    const Int realBytes = this->DoublePoints ? 8 : 4;
    this->FileLayout.Text("<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"1.0\" "
                          "byte_order=\"LittleEndian\" header_type=\"UInt64\">\n  <PolyData>\n    "
                          "<Piece NumberOfPoints=\"" +
      std::to_string(this->Vertices) +
      "\" NumberOfVerts=\"0\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"" +
      std::to_string(this->Triangles) + "\">\n");
    if (this->WithNormals)
    {
      this->FileLayout.Text("      <PointData Normals=\"Normals\">\n" +
        this->ArrayStart("Float32", "Normals", 3, 12 * this->Vertices, this->Binary));
      this->NormalBlock = this->FileLayout.Records(this->Vertices, normal);
      this->FileLayout.Text("\n        </DataArray>\n      </PointData>\n");
    }
    this->FileLayout.Text("      <Points>\n" +
      this->ArrayStart(this->DoublePoints ? "Float64" : "Float32", "Points", 3,
        3 * realBytes * this->Vertices, this->Binary));
    this->PointBlock = this->FileLayout.Records(this->Vertices, point);
    this->FileLayout.Text("\n        </DataArray>\n      </Points>\n      <Polys>\n" +
      this->ArrayStart("Int64", "connectivity", 1, 24 * this->Triangles, this->Binary));
    this->TriangleBlock = this->FileLayout.Records(this->Triangles, triangle);
    // 8-byte offsets cannot be placed by byte range in base64: fixed-width text always.
    this->FileLayout.Text(
      "\n        </DataArray>\n" + this->ArrayStart("Int64", "offsets", 1, 0, false));
    this->OffsetBlock = this->FileLayout.Records(this->Triangles, offset);
    this->FileLayout.Text(
      "        </DataArray>\n      </Polys>\n    </Piece>\n  </PolyData>\n</VTKFile>\n");
  }

  // Places a record of `length` bytes, which must be `expected`, at index `index` of `block`.
  bool Put(
    RangeFile& file, const Block& block, Int index, Int length, Int expected, const char* record)
  {
    if (length != expected)
    {
      this->Problem = "a coordinate or normal is not a finite number (or is beyond 1e100), so "
                      "it has no fixed-width text form";
      return false;
    }
    file.Write(block.Start + index * block.Size, record, static_cast<std::size_t>(length));
    return true;
  }

  // Coordinates or a normal: binary (base64 in VTP) or fixed-width text ending with `end`
  // (a PLY vertex's coordinates and normal share one line).
  Int PointRecord(char* out, const double v[3], bool isDouble, char end = '\n') const
  {
    if (this->Binary)
    {
      char bytes[24];
      char* end = bytes;
      for (int k = 0; k < 3; ++k)
      {
        end =
          isDouble ? PutLittleEndian(end, v[k]) : PutLittleEndian(end, static_cast<float>(v[k]));
      }
      if (this->Kind == Format::VTP)
      {
        return static_cast<Int>(Base64(bytes, static_cast<std::size_t>(end - bytes), out));
      }
      std::memcpy(out, bytes, static_cast<std::size_t>(end - bytes));
      return end - bytes;
    }
    Int length = 0;
    for (int k = 0; k < 3; ++k)
    {
      const int written = FixedReal(out + length, v[k], isDouble);
      if (written != (isDouble ? 23 : 15))
      {
        return -1;
      }
      length += written;
      out[length++] = k < 2 ? ' ' : end;
    }
    return length;
  }

  // One triangle: STL's facet with its own normal and vertices, PLY's face, VTP's connectivity.
  Int TriangleRecord(char* out, const vtkIdType* local, bool sample) const
  {
    if (this->Kind == Format::STL)
    {
      return this->FacetRecord(out, local, sample);
    }
    char* start = out;
    Int g[3] = { 0, 0, 0 };
    for (int v = 0; v < 3 && !sample; ++v)
    {
      g[v] = this->LocalMesh.Ids->GetValue(local[v]);
    }
    const bool wide = this->Vertices > std::numeric_limits<std::int32_t>::max();
    if (this->Kind == Format::PLY && this->Binary)
    {
      *out++ = 3;
      for (Int id : g)
      {
        out = wide ? PutLittleEndian(out, static_cast<std::uint32_t>(id))
                   : PutLittleEndian(out, static_cast<std::int32_t>(id));
      }
      return out - start;
    }
    if (this->Kind == Format::VTP && this->Binary)
    {
      char bytes[24];
      char* end = bytes;
      for (Int id : g)
      {
        end = PutLittleEndian(end, static_cast<std::int64_t>(id));
      }
      return static_cast<Int>(Base64(bytes, 24, out));
    }
    // Right-aligned with spaces, not zeros: VTK 9.3's PLY reader reads "010" as octal.
    return std::sprintf(out,
      this->Kind == Format::PLY ? "3 %*lld %*lld %*lld\n" : "%*lld %*lld %*lld\n", this->IdWidth,
      static_cast<long long>(g[0]), this->IdWidth, static_cast<long long>(g[1]), this->IdWidth,
      static_cast<long long>(g[2]));
  }

  // STL's facet: the normal of its corners as float, then the corners (a sample's are zeros).
  Int FacetRecord(char* out, const vtkIdType* local, bool sample) const
  {
    char* start = out;
    float f[3][3] = {};
    double n[3];
    this->Facet(local, sample, f, n);
    if (this->Binary)
    {
      for (int k = 0; k < 3; ++k)
      {
        out = PutLittleEndian(out, static_cast<float>(n[k]));
      }
      for (int v = 0; v < 3; ++v)
      {
        for (int k = 0; k < 3; ++k)
        {
          out = PutLittleEndian(out, f[v][k]);
        }
      }
      out = PutLittleEndian(out, std::uint16_t(0));
      return out - start;
    }
    char r[3][32];
    auto reals = [&r](const double* values)
    {
      for (int k = 0; k < 3; ++k)
      {
        if (FixedReal(r[k], values[k], false) != 15)
        {
          return false;
        }
      }
      return true;
    };
    if (!reals(n))
    {
      return -1;
    }
    out += std::sprintf(out, "facet normal %s %s %s\n  outer loop\n", r[0], r[1], r[2]);
    for (int v = 0; v < 3; ++v)
    {
      const double x[3] = { f[v][0], f[v][1], f[v][2] };
      if (!reals(x))
      {
        return -1;
      }
      out += std::sprintf(out, "    vertex %s %s %s\n", r[0], r[1], r[2]);
    }
    out += std::sprintf(out, "  endloop\nendfacet\n");
    return out - start;
  }

  // The corners of a facet, rounded to float as STL stores them, and the unit normal of those.
  void Facet(const vtkIdType* local, bool sample, float f[3][3], double n[3]) const
  {
    for (int v = 0; v < 3 && !sample; ++v)
    {
      double x[3];
      this->LocalMesh.Points->GetPoint(local[v], x);
      for (int k = 0; k < 3; ++k)
      {
        f[v][k] = static_cast<float>(x[k]);
      }
    }
    double a[3], b[3];
    for (int k = 0; k < 3; ++k)
    {
      a[k] = static_cast<double>(f[1][k]) - f[0][k];
      b[k] = static_cast<double>(f[2][k]) - f[0][k];
    }
    n[0] = a[1] * b[2] - a[2] * b[1];
    n[1] = a[2] * b[0] - a[0] * b[2];
    n[2] = a[0] * b[1] - a[1] * b[0];
    const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    for (int k = 0; k < 3 && length > 0; ++k)
    {
      n[k] /= length;
    }
  }

  // VTP's offset of triangle `index`: where its connectivity ends.
  Int OffsetRecord(char* out, Int index) const
  {
    return std::sprintf(out, "%*lld\n", this->OffsetWidth, static_cast<long long>(3 * (index + 1)));
  }

  // A DataArray's opening tag and, in binary, its base64 header (the byte count, encoded apart
  // from the data, as VTK's writer does).
  static std::string ArrayStart(
    const char* type, const char* name, int components, Int bytes, bool binary)
  {
    std::string text =
      std::string("        <DataArray type=\"") + type + "\" Name=\"" + name + "\"";
    if (components > 1)
    {
      text += " NumberOfComponents=\"" + std::to_string(components) + "\"";
    }
    text += std::string(" format=\"") + (binary ? "binary" : "ascii") + "\">\n";
    if (binary)
    {
      char header[8], encoded[12];
      PutLittleEndian(header, static_cast<std::uint64_t>(bytes));
      text.append(encoded, Base64(header, 8, encoded));
    }
    return text;
  }

  Format Kind;
  bool Binary;
  const Mesh& LocalMesh; // this rank's part
  Int Vertices, Triangles, FirstTriangle;
  bool WithNormals, DoublePoints;
  Layout FileLayout;
  Block PointBlock, NormalBlock, TriangleBlock, OffsetBlock;
  Int PointLength = 0, NormalLength = 0, TriangleLength = 0, OffsetLength = 0;
  int IdWidth = 1, OffsetWidth = 1;
};

const std::vector<std::pair<Int, vtkIdType>> MergedFile::NoVertices;

} // namespace

//------------------------------------------------------------------------------
vtkRGMergedSurfaceWriter::vtkRGMergedSurfaceWriter()
{
  this->SetController(vtkMultiProcessController::GetGlobalController());
}

//------------------------------------------------------------------------------
vtkRGMergedSurfaceWriter::~vtkRGMergedSurfaceWriter()
{
  this->SetFileName(nullptr);
  this->SetController(nullptr);
}

//------------------------------------------------------------------------------
int vtkRGMergedSurfaceWriter::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPolyData");
  return 1;
}

//------------------------------------------------------------------------------
vtkTypeBool vtkRGMergedSurfaceWriter::ProcessRequest(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  if (request->Has(vtkStreamingDemandDrivenPipeline::REQUEST_UPDATE_EXTENT()) && this->Controller)
  {
    // Each rank writes its own piece into the file.
    vtkInformation* inInfo = inputVector[0]->GetInformationObject(0);
    inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER(),
      this->Controller->GetLocalProcessId());
    inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES(),
      this->Controller->GetNumberOfProcesses());
    inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_GHOST_LEVELS(), 0);
    return 1;
  }
  return this->Superclass::ProcessRequest(request, inputVector, outputVector);
}

//------------------------------------------------------------------------------
/// What one execution carries from pass to pass on this rank.
struct vtkRGMergedSurfaceWriter::Run
{
  explicit Run(vtkMultiProcessController* controller)
    : Ranks(controller)
  {
  }
  rgmc::Ranks Ranks;
  std::string Problem;   // the agreed error of a failed pass
  std::string Name;      // the file's
  std::string Extension; // stl, ply, vtp or pvtp
  vtkNew<vtkPolyData> Surface;
  Mesh LocalMesh;                                     // this rank's part
  Int Vertices = 0, Triangles = 0, FirstTriangle = 0; // over all ranks; this rank's first
  bool Normals = true;                                // every rank has them
};

//------------------------------------------------------------------------------
// The collective schedule: every rank runs these passes in this order and makes the same
// collective calls in each (an agreement is one collective call on success, one or two
// broadcasts more on failure); a pass that fails returns on every rank at the same point.
//
//  PASS 1 AgreeOnFile     agreement (the name and format)
//         WritePieces     .pvtp only: vtkXMLPPolyDataWriter (its own collectives), agreement
//  PASS 2 NumberSurface   per attempt (at most 2): agreement (collected), AllGather (counts),
//                         agreement, a reduction (ready); before the second, Seam Repair
//                         without smoothing (its own schedule) and an agreement
//  PASS 3 WriteMerged     a reduction (double points); agreement (rank 0 created the file
//                         beside the target), a broadcast (its name: two calls),
//  PASS 4                 agreement (every rank opened it), agreement (every rank wrote it),
//  PASS 5                 agreement (rank 0 renamed it over the target)
void vtkRGMergedSurfaceWriter::WriteData()
{
  rgmc::RunController controller(this->Controller);
  Run run(controller);
  // PASS 1: the file name and the format, agreed.
  if (!this->AgreeOnFile(run))
  {
    this->Fail(run.Problem);
    return;
  }
  if (vtkPolyData* input = vtkPolyData::SafeDownCast(this->GetInput()))
  {
    run.Surface->ShallowCopy(input);
  }
  if (run.Extension == "pvtp")
  {
    if (!this->WritePieces(run))
    {
      this->Fail(run.Problem);
    }
    return;
  }
  // PASS 2: the surface numbered as one mesh.
  if (!this->NumberSurface(run))
  {
    this->Fail(run.Problem);
    return;
  }
  // PASS 3-4: one file, every rank writing its records.
  if (!this->WriteMerged(run))
  {
    this->Fail(run.Problem);
  }
}

//------------------------------------------------------------------------------
void vtkRGMergedSurfaceWriter::Fail(const std::string& problem)
{
  vtkErrorMacro(<< "Cannot write the surface: " << problem << ".");
  this->SetErrorCode(1);
}

//------------------------------------------------------------------------------
bool vtkRGMergedSurfaceWriter::AgreeOnFile(Run& run)
{
  run.Name = this->FileName ? this->FileName : "";
  const std::size_t dot = run.Name.find_last_of('.');
  run.Extension = dot == std::string::npos ? "" : run.Name.substr(dot + 1);
  const std::string& extension = run.Extension;
  if (run.Name.empty())
  {
    run.Problem = "no file name is set";
  }
  else if (extension != "stl" && extension != "ply" && extension != "vtp" && extension != "pvtp")
  {
    run.Problem = "the file name " + run.Name + " must end in .stl, .ply, .vtp or .pvtp";
  }
  return run.Ranks.Agree(run.Problem.empty(), run.Problem);
}

//------------------------------------------------------------------------------
// ParaView's parallel form: each rank's piece as it is, and the index on rank 0.
bool vtkRGMergedSurfaceWriter::WritePieces(Run& run)
{
  vtkNew<vtkXMLPPolyDataWriter> pieces;
  ErrorCatcher catcher(pieces);
  pieces->SetController(run.Ranks.Controller());
  pieces->SetNumberOfPieces(run.Ranks.Size);
  pieces->SetStartPiece(run.Ranks.Rank);
  pieces->SetEndPiece(run.Ranks.Rank);
  pieces->SetFileName(run.Name.c_str());
  if (this->FileType == VTK_ASCII)
  {
    pieces->SetDataModeToAscii();
  }
  else
  {
    pieces->SetDataModeToBinary(); // inline: appended data does not load on Debian 12
  }
  pieces->SetInputData(run.Surface);
  const bool ok = pieces->Write() != 0 && pieces->GetErrorCode() == 0;
  run.Problem = catcher.Message.empty() ? "could not write " + run.Name : catcher.Message;
  return run.Ranks.Agree(ok, run.Problem);
}

//------------------------------------------------------------------------------
// Seam Repair's numbering when the input has it, otherwise numbered here (by Seam Repair
// without smoothing, which also names what is not a triangle mesh), and the global counts with
// this rank's first triangle.
bool vtkRGMergedSurfaceWriter::NumberSurface(Run& run)
{
  rgmc::Ranks& ranks = run.Ranks;
  for (int attempt = 0;; ++attempt)
  {
    const Collected collected = Collect(run.Surface, run.LocalMesh);
    run.Problem = "out of memory while collecting this rank's vertices and triangles";
    if (!ranks.Agree(collected != Collected::OutOfMemory, run.Problem))
    {
      return false;
    }
    Int local[3] = { static_cast<Int>(run.LocalMesh.Owned.size()),
      static_cast<Int>(run.LocalMesh.Triangles.size() / 3),
      run.Surface->GetNumberOfPoints() > 0 && !run.LocalMesh.Normals ? 1 : 0 };
    std::vector<Int> all(3 * static_cast<std::size_t>(ranks.Size));
    ranks.AllGather(local, all.data(), 3, "exchanging the counts");
    if (!ranks.Agree(true, run.Problem))
    {
      return false;
    }
    run.Vertices = run.Triangles = run.FirstTriangle = 0;
    run.Normals = true;
    for (int r = 0; r < ranks.Size; ++r)
    {
      if (r == ranks.Rank)
      {
        run.FirstTriangle = run.Triangles;
      }
      run.Vertices += all[3 * r];
      run.Triangles += all[3 * r + 1];
      run.Normals = run.Normals && all[3 * r + 2] == 0;
    }
    const bool ready = collected == Collected::Numbered && Placeable(run.LocalMesh, run.Vertices);
    if (!ranks.Any(!ready))
    {
      return true;
    }
    if (attempt > 0)
    {
      run.Problem = "Seam Repair's numbering of the surface is not contiguous";
      return false;
    }
    vtkNew<vtkRGSeamRepair> numbering;
    ErrorCatcher catcher(numbering);
    numbering->SetController(ranks.Controller());
    numbering->SetSmoothingMethod(vtkRGSeamRepair::NO_SMOOTHING);
    numbering->SetInputData(run.Surface);
    numbering->Update(); // collective; it agrees its errors over the ranks itself
    run.Problem = "it cannot be numbered as one mesh: " + catcher.Message;
    if (!ranks.Agree(catcher.Message.empty(), run.Problem))
    {
      return false;
    }
    auto numbered = vtkSmartPointer<vtkPolyData>::New();
    numbered->ShallowCopy(numbering->GetOutput());
    run.Surface->ShallowCopy(numbered);
  }
}

//------------------------------------------------------------------------------
// Rank 0 creates a file beside the target, then every other rank opens it; every rank writes
// its records, rank 0 also the texts, and makes them durable; then rank 0 renames the file over
// the target. A file that failed on some rank is incomplete: it is removed and the target (an
// earlier file) is left as it was.
bool vtkRGMergedSurfaceWriter::WriteMerged(Run& run)
{
  rgmc::Ranks& ranks = run.Ranks;
  const std::string& extension = run.Extension;
  const bool normals = run.Normals && extension != "stl" && run.Vertices > 0;
  const Format format =
    extension == "stl" ? Format::STL : (extension == "ply" ? Format::PLY : Format::VTP);
  // The points' type is in the header: double when any rank has double points.
  const bool doublePoints = ranks.Any(format != Format::STL && run.LocalMesh.Points &&
    run.LocalMesh.Points->GetDataType() == VTK_DOUBLE);
  MergedFile file(format, this->FileType != VTK_ASCII, run.LocalMesh, run.Vertices, run.Triangles,
    run.FirstTriangle, normals, doublePoints);
  run.Problem = file.Limit();
  if (!run.Problem.empty())
  {
    return false; // the same on every rank: the counts are global
  }
  file.Plan();

  // PASS 3: rank 0 creates the file beside the target, then every other rank opens it.
  RangeFile out;
  bool ok = ranks.Rank != 0 || out.CreateBeside(run.Name);
  if (!ranks.Agree(ok, out.Problem))
  {
    run.Problem = out.Problem;
    return false;
  }
  std::vector<vtkIdType> words;
  rgmc::MessageWriter(words).Text(out.Written());
  ranks.Broadcast(words, 0);
  const std::string written = rgmc::MessageReader(words).Text();
  ok = ranks.Rank == 0 || out.Open(written, run.Name);
  run.Problem = out.Problem;
  if (ranks.Agree(ok, run.Problem))
  {
    // PASS 4: every rank writes its records; rank 0 also the texts.
    bool written = false;
    try
    {
      written = file.Write(out, ranks.Rank == 0);
      run.Problem = file.Problem;
    }
    catch (const std::bad_alloc&)
    {
      run.Problem = "out of memory while writing " + run.Name;
    }
    ok = out.Close() && written;
    if (!out.Problem.empty())
    {
      run.Problem = out.Problem;
    }
    // PASS 5: every rank's records are durable: rank 0 renames the file over the target.
    if (ranks.Agree(ok, run.Problem))
    {
      ok = ranks.Rank != 0 || out.Replace();
      run.Problem = out.Problem;
      if (ranks.Agree(ok, run.Problem))
      {
        return true;
      }
    }
  }
  if (ranks.Rank == 0)
  {
    out.Discard(); // the earlier file at the target, if any, is untouched
  }
  else
  {
    out.Close();
  }
  return false;
}

//------------------------------------------------------------------------------
void vtkRGMergedSurfaceWriter::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "FileName: " << (this->FileName ? this->FileName : "(none)") << "\n";
  os << indent << "FileType: " << this->FileType << "\n";
  os << indent << "Controller: " << this->Controller << "\n";
}

// vtkRGMergedSurfaceWriter on 1 rank (vtkDummyController) and under mpiexec: the phantom's
// skull, extracted and repaired on this many ranks, written as one file in every format (STL,
// PLY and VTP, binary and ASCII) with nothing gathered, then read back on rank 0 by VTK's own
// readers and compared with the 1-rank mesh: the same vertices to the bit, in the same
// (global-id) order, the same normals, the same triangles counted with multiplicity, for any
// rank count and decomposition. A surface that is not numbered yet (the extraction's output) is
// numbered by the writer. PVTP writes one piece per rank. Errors: a directory that does not
// exist, an unknown extension, and a disk that fills up on one rank only (a file size limit on
// that rank) give the same error on every rank, without a hang, and leave no file behind.
#include "rgmcDistributedData.h"
#include "rgmcTestController.h"
#include "rgmcTestData.h"

#include "vtkCellArray.h"
#include "vtkDataArray.h"
#include "vtkDummyController.h"
#include "vtkIdList.h"
#include "vtkPLYReader.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkRGMergedSurfaceWriter.h"
#include "vtkRGPhantomSource.h"
#include "vtkRGSeamRepair.h"
#include "vtkSTLReader.h"
#include "vtkXMLPPolyDataReader.h"
#include "vtkXMLPolyDataReader.h"

#include <algorithm>
#include <array>
#include <csignal>
#include <dirent.h>
#include <fstream>
#include <iostream>
#include <iterator>
#include <map>
#include <sstream>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

using namespace rgmc_test;

namespace
{

const int Whole[6] = { 0, 48, 0, 48, 0, 48 };

vtkSmartPointer<vtkImageData> Skull(const int extent[6])
{
  return PhantomPiece(extent, 49);
}

vtkSmartPointer<vtkPolyData> Repair(vtkMultiProcessController* controller, vtkPolyData* input)
{
  vtkNew<vtkRGSeamRepair> repair;
  repair->SetController(controller);
  repair->SetInputData(input);
  repair->SetSmoothingMethod(vtkRGSeamRepair::LAPLACIAN); // smoothed: with normals
  repair->Update();
  auto out = vtkSmartPointer<vtkPolyData>::New();
  out->ShallowCopy(repair->GetOutput());
  return out;
}

/// The 1-rank mesh as the files hold it: points (and point data) in global-id order, the
/// triangles over them.
vtkSmartPointer<vtkPolyData> InGlobalIdOrder(vtkPolyData* mesh)
{
  vtkIdTypeArray* ids = vtkIdTypeArray::SafeDownCast(mesh->GetPointData()->GetGlobalIds());
  const vtkIdType n = mesh->GetNumberOfPoints();
  vtkNew<vtkIdList> from, to;
  for (vtkIdType p = 0; p < n; ++p)
  {
    from->InsertNextId(p);
    to->InsertNextId(ids->GetValue(p));
  }
  auto ordered = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkPoints> points;
  points->SetDataType(mesh->GetPoints()->GetDataType());
  points->SetNumberOfPoints(n);
  for (vtkIdType p = 0; p < n; ++p)
  {
    points->SetPoint(ids->GetValue(p), mesh->GetPoint(p));
  }
  ordered->SetPoints(points);
  ordered->GetPointData()->CopyAllocate(mesh->GetPointData(), n);
  ordered->GetPointData()->CopyData(mesh->GetPointData(), from, to);
  vtkNew<vtkCellArray> polys;
  vtkIdType npts;
  const vtkIdType* pts;
  vtkCellArray* in = mesh->GetPolys();
  for (in->InitTraversal(); in->GetNextCell(npts, pts);)
  {
    std::vector<vtkIdType> cell;
    for (vtkIdType k = 0; k < npts; ++k)
    {
      cell.push_back(ids->GetValue(pts[k]));
    }
    polys->InsertNextCell(npts, cell.data());
  }
  ordered->SetPolys(polys);
  return ordered;
}

struct Written
{
  bool Ok = false;
  std::string Errors;
};

Written Write(
  vtkMultiProcessController* controller, vtkPolyData* surface, const std::string& path, int type)
{
  vtkNew<vtkRGMergedSurfaceWriter> writer;
  vtkNew<MessageCatcher> catcher;
  catcher->Watch(writer);
  writer->SetController(controller);
  writer->SetInputData(surface);
  writer->SetFileName(path.c_str());
  writer->SetFileType(type);
  writer->Write();
  return Written{ writer->GetErrorCode() == 0, catcher->Errors };
}

using Triangle = std::array<std::array<float, 3>, 3>;

/// A triangle as its three corners, rotated so that the smallest comes first (orientation kept).
Triangle Canonical(Triangle t)
{
  const int first = static_cast<int>(std::min_element(t.begin(), t.end()) - t.begin());
  std::rotate(t.begin(), t.begin() + first, t.end());
  return t;
}

/// The triangles of `pd` with their multiplicity.
std::map<Triangle, int> Triangles(vtkPolyData* pd)
{
  std::map<Triangle, int> triangles;
  vtkNew<vtkIdList> cell;
  vtkCellArray* polys = pd->GetPolys();
  for (vtkIdType c = 0; c < polys->GetNumberOfCells(); ++c)
  {
    polys->GetCellAtId(c, cell);
    Triangle t{};
    for (int v = 0; v < 3 && cell->GetNumberOfIds() == 3; ++v)
    {
      double x[3];
      pd->GetPoint(cell->GetId(v), x);
      t[v] = { static_cast<float>(x[0]), static_cast<float>(x[1]), static_cast<float>(x[2]) };
    }
    ++triangles[Canonical(t)];
  }
  return triangles;
}

/// Compares a file read back with the 1-rank mesh: points in the same order, to the bit (unless
/// `pointsInOrder` is false: STL has no vertex list), normals, triangles with multiplicity.
void Compare(vtkPolyData* read, vtkPolyData* reference, bool pointsInOrder, bool normals,
  const std::string& what)
{
  if (pointsInOrder)
  {
    RGMC_CHECK(read->GetNumberOfPoints() == reference->GetNumberOfPoints(),
      what << ": " << read->GetNumberOfPoints() << " vertices, the 1-rank mesh has "
           << reference->GetNumberOfPoints());
    vtkIdType differ = 0, normalsDiffer = 0;
    vtkDataArray* readNormals = read->GetPointData()->GetNormals();
    vtkDataArray* referenceNormals = reference->GetPointData()->GetNormals();
    RGMC_CHECK(!normals || (readNormals && referenceNormals), what << ": no normals");
    for (vtkIdType p = 0; p < std::min(read->GetNumberOfPoints(), reference->GetNumberOfPoints());
         ++p)
    {
      double a[3], b[3];
      read->GetPoint(p, a);
      reference->GetPoint(p, b);
      differ += static_cast<float>(a[0]) != static_cast<float>(b[0]) ||
        static_cast<float>(a[1]) != static_cast<float>(b[1]) ||
        static_cast<float>(a[2]) != static_cast<float>(b[2]);
      if (normals && readNormals && referenceNormals)
      {
        readNormals->GetTuple(p, a);
        referenceNormals->GetTuple(p, b);
        normalsDiffer += static_cast<float>(a[0]) != static_cast<float>(b[0]) ||
          static_cast<float>(a[1]) != static_cast<float>(b[1]) ||
          static_cast<float>(a[2]) != static_cast<float>(b[2]);
      }
    }
    RGMC_CHECK(differ == 0, what << ": " << differ << " vertices differ from the 1-rank mesh's");
    RGMC_CHECK(normalsDiffer == 0,
      what << ": " << normalsDiffer << " normals differ from the 1-rank mesh's");
  }
  RGMC_CHECK(read->GetNumberOfPolys() == reference->GetNumberOfPolys(),
    what << ": " << read->GetNumberOfPolys() << " triangles, the 1-rank mesh has "
         << reference->GetNumberOfPolys());
  RGMC_CHECK(Triangles(read) == Triangles(reference),
    what << ": the triangles (with multiplicity) differ from the 1-rank mesh's");
}

vtkSmartPointer<vtkPolyData> Read(const std::string& path)
{
  auto out = vtkSmartPointer<vtkPolyData>::New();
  const std::string extension = path.substr(path.find_last_of('.') + 1);
  if (extension == "ply")
  {
    vtkNew<vtkPLYReader> reader;
    reader->SetFileName(path.c_str());
    reader->Update();
    out->ShallowCopy(reader->GetOutput());
  }
  else if (extension == "stl")
  {
    vtkNew<vtkSTLReader> reader;
    reader->SetFileName(path.c_str());
    reader->MergingOff();
    reader->Update();
    out->ShallowCopy(reader->GetOutput());
  }
  else
  {
    vtkNew<vtkXMLPolyDataReader> reader;
    reader->SetFileName(path.c_str());
    reader->Update();
    out->ShallowCopy(reader->GetOutput());
  }
  return out;
}

/// The writer's own message: its first error line without the "vtkClass (0x...): " prefix,
/// which differs between processes.
std::string Message(const std::string& errors)
{
  const std::size_t at = errors.find("): ");
  if (at == std::string::npos)
  {
    return errors;
  }
  const std::size_t end = errors.find('\n', at);
  return errors.substr(at + 3, end == std::string::npos ? std::string::npos : end - at - 3);
}

/// A file's bytes (empty when it cannot be read).
std::string Bytes(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// The names in a directory, sorted.
std::vector<std::string> Listing(const std::string& dir)
{
  std::vector<std::string> names;
  if (DIR* d = ::opendir(dir.c_str()))
  {
    while (const struct dirent* entry = ::readdir(d))
    {
      names.emplace_back(entry->d_name);
    }
    ::closedir(d);
  }
  std::sort(names.begin(), names.end());
  return names;
}

std::string Join(const std::vector<std::string>& names)
{
  std::string joined;
  for (const std::string& name : names)
  {
    joined += (joined.empty() ? "" : " ") + name;
  }
  return joined;
}

} // namespace

int main(int argc, char* argv[])
{
  vtkSmartPointer<vtkMultiProcessController> controller = rgmc_test::StartController(argc, argv);
  const int rank = controller->GetLocalProcessId(), ranks = controller->GetNumberOfProcesses();
  vtkNew<vtkDummyController> single;
  const std::string dir = "TestMergedWriter-" + std::to_string(ranks);
  if (rank == 0)
  {
    ::mkdir(dir.c_str(), 0755);
  }
  controller->Barrier();
  const Seeds seeds = { { 0, 0, 105 } };

  // The 1-rank meshes: repaired and smoothed (with normals), and only numbered (no smoothing).
  vtkSmartPointer<vtkPolyData> reference, unsmoothed;
  if (rank == 0)
  {
    vtkSmartPointer<vtkImageData> whole = Skull(Whole);
    vtkSmartPointer<vtkPolyData> extracted =
      Extract(single, whole, 400, vtkRGMarchingCubes::SEEDED, seeds).Output;
    reference = InGlobalIdOrder(Repair(single, extracted));
    vtkNew<vtkRGSeamRepair> numbering;
    numbering->SetController(single);
    numbering->SetInputData(extracted);
    numbering->SetSmoothingMethod(vtkRGSeamRepair::NO_SMOOTHING);
    numbering->Update();
    unsmoothed = InGlobalIdOrder(numbering->GetOutput());
    std::cout << "1-rank skull: " << reference->GetNumberOfPoints() << " vertices, "
              << reference->GetNumberOfPolys() << " triangles\n";
  }

  const char* formats[] = { "stl", "ply", "vtp" };
  for (const std::string how : { "block", "slab-z", "empty-rank" })
  {
    if (ranks == 1 && how != "block")
    {
      continue;
    }
    vtkSmartPointer<vtkImageData> image = MakePiece(Skull, Whole, PieceOf(how, Whole, rank, ranks));
    vtkSmartPointer<vtkPolyData> extracted =
      Extract(controller, image, 400, vtkRGMarchingCubes::SEEDED, seeds).Output;
    vtkSmartPointer<vtkPolyData> repaired = Repair(controller, extracted);
    for (const char* format : formats)
    {
      for (int type : { VTK_BINARY, VTK_ASCII })
      {
        std::ostringstream what;
        what << format << (type == VTK_BINARY ? " binary" : " ASCII") << ", " << how << " on "
             << ranks << " ranks";
        const std::string path = dir + "/skull-" + how + "-" + std::to_string(type) + "." + format;
        const Written w = Write(controller, repaired, path, type);
        RGMC_CHECK(w.Ok && w.Errors.empty(), what.str() << ": " << w.Errors);
        if (rank == 0)
        {
          const bool stl = std::string(format) == "stl";
          Compare(Read(path), reference, !stl, !stl, what.str());
        }
      }
    }
    // Not numbered yet: the writer numbers it (by Seam Repair's rule) and writes the same mesh.
    {
      const std::string path = dir + "/unnumbered-" + how + ".ply";
      const Written w = Write(controller, extracted, path, VTK_BINARY);
      RGMC_CHECK(w.Ok && w.Errors.empty(), "unnumbered, " << how << ": " << w.Errors);
      if (rank == 0)
      {
        Compare(Read(path), unsmoothed, true, false, "unnumbered PLY, " + how);
      }
    }
  }

  // PVTP: one piece per rank, as they are.
  {
    vtkSmartPointer<vtkImageData> image =
      MakePiece(Skull, Whole, PieceOf("block", Whole, rank, ranks));
    vtkSmartPointer<vtkPolyData> repaired =
      Repair(controller, Extract(controller, image, 400, vtkRGMarchingCubes::SEEDED, seeds).Output);
    const std::string path = dir + "/skull.pvtp";
    const Written w = Write(controller, repaired, path, VTK_BINARY);
    RGMC_CHECK(w.Ok && w.Errors.empty(), "pvtp: " << w.Errors);
    if (rank == 0)
    {
      vtkNew<vtkXMLPPolyDataReader> reader;
      reader->SetFileName(path.c_str());
      reader->Update();
      RGMC_CHECK(reader->GetOutput()->GetNumberOfPolys() == reference->GetNumberOfPolys(),
        "pvtp: " << reader->GetOutput()->GetNumberOfPolys() << " triangles in its pieces, not "
                 << reference->GetNumberOfPolys());
    }

    // Errors, the same on every rank, and no file left behind.
    auto expectError = [&](
                         const std::string& file, const std::string& text, const std::string& what)
    {
      const Written e = Write(controller, repaired, file, VTK_BINARY);
      RGMC_CHECK(!e.Ok, what << ": no error");
      RGMC_CHECK(e.Errors.find(text) != std::string::npos,
        what << " (rank " << rank << "): the error does not say \"" << text << "\": " << e.Errors);
      RGMC_CHECK(
        SameOnAllRanks(controller, Message(e.Errors)), what << ": the ranks' messages differ");
    };
    expectError(dir + "/no-such-directory/skull.stl", "cannot create", "a missing directory");
    expectError(
      dir + "/skull.obj", "must end in .stl, .ply, .vtp or .pvtp", "an unknown extension");

    // The last rank's disk is full: a file size limit below its records (its writes fail with
    // EFBIG instead of the signal, which the test ignores). An earlier file at the target stays
    // byte for byte, and nothing is left beside it.
    const std::string full = dir + "/full.ply";
    const Written earlier = Write(controller, repaired, full, VTK_ASCII);
    RGMC_CHECK(earlier.Ok, "the earlier file: " << earlier.Errors);
    controller->Barrier();
    const std::string earlierBytes = rank == 0 ? Bytes(full) : std::string();
    const std::vector<std::string> earlierListing = Listing(dir);
    struct rlimit saved;
    ::getrlimit(RLIMIT_FSIZE, &saved);
    void (*previous)(int) = std::signal(SIGXFSZ, SIG_IGN);
    if (rank == ranks - 1)
    {
      struct rlimit small = saved;
      small.rlim_cur = 512;
      ::setrlimit(RLIMIT_FSIZE, &small);
    }
    const Written e = Write(controller, repaired, full, VTK_BINARY);
    if (rank == ranks - 1)
    {
      ::setrlimit(RLIMIT_FSIZE, &saved);
    }
    std::signal(SIGXFSZ, previous);
    RGMC_CHECK(!e.Ok, "a full disk on rank " << ranks - 1 << ": no error");
    RGMC_CHECK(e.Errors.find("cannot write") != std::string::npos &&
        e.Errors.find("File too large") != std::string::npos,
      "a full disk (rank " << rank << "): the error does not name it: " << e.Errors);
    RGMC_CHECK(
      SameOnAllRanks(controller, Message(e.Errors)), "a full disk: the ranks' messages differ");
    RGMC_CHECK(e.Errors.find(full) != std::string::npos,
      "a full disk (rank " << rank << "): the error does not name " << full << ": " << e.Errors);
    controller->Barrier();
    if (rank == 0)
    {
      RGMC_CHECK(Bytes(full) == earlierBytes,
        "a full disk: the earlier " << full << " was changed (" << Bytes(full).size()
                                    << " bytes, not " << earlierBytes.size() << ")");
      RGMC_CHECK(Listing(dir) == earlierListing,
        "a full disk: files were left beside the target: " << Join(Listing(dir)));
    }

    // Through a symbolic link: the file it points to is replaced, the link stays a link.
    if (rank == 0)
    {
      ::unlink((dir + "/link.stl").c_str());
      RGMC_CHECK(::symlink("pointed.stl", (dir + "/link.stl").c_str()) == 0, "symlink");
    }
    controller->Barrier();
    const Written linked = Write(controller, repaired, dir + "/link.stl", VTK_BINARY);
    RGMC_CHECK(linked.Ok && linked.Errors.empty(), "through a link: " << linked.Errors);
    if (rank == 0)
    {
      struct stat st;
      RGMC_CHECK(::lstat((dir + "/link.stl").c_str(), &st) == 0 && S_ISLNK(st.st_mode),
        "through a link: the link was replaced by a file");
      Compare(Read(dir + "/pointed.stl"), reference, false, false, "through a link");
    }
  }

  return rgmc_test::Finish(controller, "TestMergedWriter");
}

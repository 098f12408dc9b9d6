// vtkRGDICOMSeriesReader on 1 rank (vtkDummyController) and under mpiexec, on DICOM series that
// the project's generator (Scripts/rgmc_dicom_series.py, run with Debian's python3 as a user
// runs it) writes from the CT phantom with known geometry: axial, oblique, sagittal, big endian,
// RLE (coronal), rescale slopes 1, 0.5 and 0.25, shuffled file names. Each rank's piece must be
// a slab of whole slices, decoded from its own files only, equal to the phantom's voxels at the
// same indices exactly, placed with the geometry the generator was given; the union over ranks
// must equal the 1-rank volume. Broken series (every case of the issue) must give the same
// message, naming the file and the problem, on every rank (a gap in the spacing of 1% or more
// among them); spacing irregular by less than 1% and a second series give warnings and the
// volume is still read. (TestDICOMGeometry checks the geometry against dcm2niix's.)
#include "rgmcReaderTestData.h"
#include "rgmcTestController.h"

#include "vtkDummyController.h"
#include "vtkExtentTranslator.h"
#include "vtkMatrix3x3.h"
#include "vtkRGDICOMSeriesReader.h"

#include <cmath>
#include <cstdio>
#include <iostream>

using namespace rgmc_test;

namespace
{

const int Dims[3] = { 40, 36, 30 }; // x, y, z: unequal, so that a swapped axis shows

struct Series
{
  std::string Name, Options;
  int Type;
  double Oblique, Axis[3];
};

std::vector<Series> AllSeries()
{
  return {
    { "axial", "--slope 1 --intercept -1024", VTK_SHORT, 0, { 1, 2, 3 } },
    { "oblique",
      "--slope 0.5 --intercept -1024 --oblique 30 --axis 1,2,3 "
      "--transfer-syntax implicit-little",
      VTK_FLOAT, 30, { 1, 2, 3 } },
    { "bigendian", "--slope 0.25 --intercept -2048.5 --transfer-syntax explicit-big", VTK_FLOAT, 0,
      { 1, 2, 3 } },
    { "rle", "--slope 1 --intercept -1024 --oblique 90 --axis 1,0,0 --transfer-syntax rle",
      VTK_SHORT, 90, { 1, 0, 0 } },
    { "sagittal", "--slope 1 --intercept -1024 --oblique 90 --axis 0,1,0", VTK_SHORT, 90,
      { 0, 1, 0 } },
  };
}

/// The rotation about `axis` by `degrees`, as the generator builds ImageOrientationPatient.
void Rotation(const double axis[3], double degrees, double r[3][3])
{
  double a[3] = { axis[0], axis[1], axis[2] };
  vtkMath::Normalize(a);
  const double t = vtkMath::RadiansFromDegrees(degrees), s = std::sin(t), c = std::cos(t);
  const double k[3][3] = { { 0, -a[2], a[1] }, { a[2], 0, -a[0] }, { -a[1], a[0], 0 } };
  for (int i = 0; i < 3; ++i)
  {
    for (int j = 0; j < 3; ++j)
    {
      double kk = 0;
      for (int m = 0; m < 3; ++m)
      {
        kk += k[i][m] * k[m][j];
      }
      r[i][j] = (i == j ? 1.0 : 0.0) + s * k[i][j] + (1 - c) * kk;
    }
  }
}

std::string Triple(const double v[3])
{
  char text[100];
  std::snprintf(text, sizeof(text), "%.17g,%.17g,%.17g", v[0], v[1], v[2]);
  return text;
}

std::string Generate(const std::string& dir, const std::string& npy, vtkImageData* phantom,
  const std::string& name, const std::string& options)
{
  const std::string out = dir + "/" + name;
  Run(std::string(RGMC_SYSTEM_PYTHON) + " " + RGMC_SCRIPTS_DIR + "/rgmc_dicom_series.py --volume " +
    npy + " --spacing=" + Triple(phantom->GetSpacing()) + " --origin=" +
    Triple(phantom->GetOrigin()) + " --output " + out + " " + options + " > /dev/null");
  return out;
}

vtkSmartPointer<vtkRGDICOMSeriesReader> Reader(
  vtkMultiProcessController* controller, const std::string& name)
{
  auto reader = vtkSmartPointer<vtkRGDICOMSeriesReader>::New();
  reader->SetController(controller);
  reader->SetFileName(name.c_str());
  return reader;
}

/// Values of `image` that differ from the phantom's at the same indices.
vtkIdType Mismatches(vtkImageData* image, vtkImageData* phantom)
{
  int ext[6];
  image->GetExtent(ext);
  vtkDataArray* ours = image->GetPointData()->GetScalars();
  vtkDataArray* truth = phantom->GetPointData()->GetArray("HU");
  if (!ours || !truth)
  {
    return -1;
  }
  vtkIdType bad = 0;
  for (int k = ext[4]; k <= ext[5]; ++k)
  {
    for (int j = ext[2]; j <= ext[3]; ++j)
    {
      for (int i = ext[0]; i <= ext[1]; ++i)
      {
        int ijk[3] = { i, j, k };
        const vtkIdType a = image->ComputePointId(ijk), b = phantom->ComputePointId(ijk);
        bad += a < 0 || b < 0 || ours->GetComponent(a, 0) != truth->GetComponent(b, 0);
      }
    }
  }
  return bad;
}

void ReadGoodSeries(vtkMultiProcessController* controller, const std::string& dir,
  vtkImageData* whole, const Series& s)
{
  const int rank = controller->GetLocalProcessId(), ranks = controller->GetNumberOfProcesses();
  const std::string path = dir + "/" + s.Name;
  const std::string what = s.Name + " on " + std::to_string(ranks) + " ranks";
  vtkSmartPointer<vtkRGDICOMSeriesReader> reader = Reader(controller, path);
  PieceRead r = ReadPiece(reader, rank, ranks, 0);
  RGMC_CHECK(r.Ok && r.Errors.empty(), what << ": " << r.Errors);
  RGMC_CHECK(r.Warnings.empty(), what << ": unexpected warnings " << r.Warnings);

  // A slab of whole slices, ParaView's piece in Z_SLAB mode, decoded from its own files only;
  // on several ranks with the ghost slice the extraction asks for, asked for or not.
  const int wholeExtent[6] = { 0, Dims[0] - 1, 0, Dims[1] - 1, 0, Dims[2] - 1 };
  int owned[6], expected[6];
  vtkNew<vtkExtentTranslator> translator;
  translator->PieceToExtentThreadSafe(
    rank, ranks, 0, const_cast<int*>(wholeExtent), owned, vtkExtentTranslator::Z_SLAB_MODE, 0);
  translator->PieceToExtentThreadSafe(rank, ranks, ranks > 1 ? 1 : 0, const_cast<int*>(wholeExtent),
    expected, vtkExtentTranslator::Z_SLAB_MODE, 0);
  int ext[6];
  r.Image->GetExtent(ext);
  for (int a = 0; a < 6; ++a)
  {
    RGMC_CHECK(ext[a] == expected[a],
      what << ": extent[" << a << "] " << ext[a] << ", expected " << expected[a]);
  }
  const int slices = ext[5] - ext[4] + 1;
  RGMC_CHECK(reader->GetNumberOfFilesRead() == slices,
    what << ": rank " << rank << " decoded " << reader->GetNumberOfFilesRead() << " files for "
         << slices << " slices");
  int filesRead = reader->GetNumberOfFilesRead(), totalRead = 0;
  controller->AllReduce(&filesRead, &totalRead, 1, vtkCommunicator::SUM_OP);
  // Neighbouring pieces share one plane of points (every cell in one piece), and each holds the
  // next plane of the other as its ghost slice: N - 1 slices twice and 2 (N - 1) ghosts.
  RGMC_CHECK(totalRead == Dims[2] + 3 * (ranks - 1),
    what << ": " << totalRead << " files decoded over all ranks");

  // Voxels: the phantom's exactly (the generator's rescale stores every HU exactly).
  vtkDataArray* scalars = r.Image->GetPointData()->GetScalars();
  RGMC_CHECK(scalars && scalars->GetDataType() == s.Type,
    what << ": output type " << (scalars ? scalars->GetDataTypeAsString() : "none"));
  RGMC_CHECK(scalars && std::string(scalars->GetName()) == "HU", what << ": array not named HU");
  const vtkIdType bad = Mismatches(r.Image, whole);
  RGMC_CHECK(bad == 0, what << ": " << bad << " voxels differ from the phantom");

  // Geometry: DS values hold 16 characters, so positions carry about 1e-13 relative rounding.
  double rotation[3][3];
  Rotation(s.Axis, s.Oblique, rotation);
  const double* origin = r.Image->GetOrigin();
  const double* spacing = r.Image->GetSpacing();
  vtkMatrix3x3* direction = r.Image->GetDirectionMatrix();
  for (int a = 0; a < 3; ++a)
  {
    RGMC_CHECK(std::fabs(origin[a] - whole->GetOrigin()[a]) < 1e-9,
      what << ": origin[" << a << "] " << origin[a] << ", expected " << whole->GetOrigin()[a]);
    RGMC_CHECK(std::fabs(spacing[a] - whole->GetSpacing()[a]) < 1e-9,
      what << ": spacing[" << a << "] " << spacing[a] << ", expected " << whole->GetSpacing()[a]);
    for (int b = 0; b < 3; ++b)
    {
      RGMC_CHECK(std::fabs(direction->GetElement(a, b) - rotation[a][b]) < 1e-12,
        what << ": direction(" << a << "," << b << ") " << direction->GetElement(a, b)
             << ", expected " << rotation[a][b]);
    }
  }

  // The union of the owned parts is the 1-rank volume: same checksum, same values at every
  // index. Neighbouring slabs share a slice: it counts for the lower one.
  auto checksum = [](vtkImageData* image, int first, int last)
  {
    int e[6];
    image->GetExtent(e);
    vtkDataArray* a = image->GetPointData()->GetScalars();
    double total = 0;
    for (int k = first; a && k <= last; ++k)
    {
      for (int j = e[2]; j <= e[3]; ++j)
      {
        for (int i = e[0]; i <= e[1]; ++i)
        {
          int ijk[3] = { i, j, k };
          total += a->GetComponent(image->ComputePointId(ijk), 0) * (1 + (i + 3 * j + 7 * k) % 5);
        }
      }
    }
    return total;
  };
  double sum = checksum(r.Image, owned[4], owned[5] - (owned[5] < Dims[2] - 1 ? 1 : 0)), total = 0;
  controller->AllReduce(&sum, &total, 1, vtkCommunicator::SUM_OP);
  if (rank == 0)
  {
    vtkNew<vtkDummyController> single;
    vtkSmartPointer<vtkRGDICOMSeriesReader> one = Reader(single, path);
    PieceRead all = ReadPiece(one, 0, 1, 0);
    RGMC_CHECK(all.Ok, what << ": 1-rank read failed " << all.Errors);
    RGMC_CHECK(Mismatches(all.Image, whole) == 0, what << ": the 1-rank volume differs");
    RGMC_CHECK(checksum(all.Image, 0, Dims[2] - 1) == total,
      what << ": checksum " << total << " over the ranks, " << checksum(all.Image, 0, Dims[2] - 1)
           << " on 1 rank");
    std::cout << what << ": " << reader->GetSummary() << "; rank 0 decoded "
              << reader->GetNumberOfFilesRead() << " of " << Dims[2] << " files\n";
  }
  std::vector<vtkSmartPointer<vtkDataObject>> pieces;
  controller->Gather(r.Image, pieces, 0);
  if (rank == 0)
  {
    vtkIdType points = 0, differ = 0;
    for (auto& p : pieces)
    {
      vtkImageData* piece = vtkImageData::SafeDownCast(p);
      points += piece->GetNumberOfPoints();
      differ += Mismatches(piece, whole);
    }
    RGMC_CHECK(points == static_cast<vtkIdType>(Dims[0]) * Dims[1] * (Dims[2] + 3 * (ranks - 1)) &&
        differ == 0,
      what << ": the union of the pieces has " << points << " points, " << differ
           << " differ from 1 rank");
  }

  // The extraction's request for one ghost level finds the piece made: it is not read again.
  const vtkMTimeType made = reader->GetOutputDataObject(0)->GetMTime();
  PieceRead one = ReadPiece(reader, rank, ranks, 1);
  one.Image->GetExtent(ext);
  RGMC_CHECK(one.Ok && reader->GetOutputDataObject(0)->GetMTime() == made &&
      std::equal(ext, ext + 6, expected),
    what << ": asked for with one ghost level, rank " << rank << "'s piece was made again");
  // With two ghost levels a piece reaches one slice further on each inner side.
  PieceRead g = ReadPiece(reader, rank, ranks, 2);
  int gext[6];
  g.Image->GetExtent(gext);
  const int levels = ranks > 1 ? 2 : 0;
  RGMC_CHECK(g.Ok && gext[4] == std::max(0, owned[4] - levels) &&
      gext[5] == std::min(Dims[2] - 1, owned[5] + levels),
    what << ": ghost extent " << gext[4] << ".." << gext[5]);
  RGMC_CHECK(Mismatches(g.Image, whole) == 0, what << ": ghost slices differ");
  // The slices it held already are copied: only the new ghost layers' files are decoded (on one
  // rank there are none, and the pipeline does not run the reader again).
  const int ghostSlices = (gext[5] - gext[4]) - (expected[5] - expected[4]);
  RGMC_CHECK(ghostSlices == 0 || reader->GetNumberOfFilesRead() == ghostSlices,
    what << ": rank " << rank << " decoded " << reader->GetNumberOfFilesRead() << " files for its "
         << ghostSlices << " ghost slices");
  // A changed reader reads everything again.
  reader->Modified();
  PieceRead again = ReadPiece(reader, rank, ranks, 2);
  RGMC_CHECK(again.Ok && Mismatches(again.Image, whole) == 0 &&
      reader->GetNumberOfFilesRead() == gext[5] - gext[4] + 1,
    what << ": after a change, rank " << rank << " decoded " << reader->GetNumberOfFilesRead()
         << " files for " << gext[5] - gext[4] + 1 << " slices");
}

void BadSeries(vtkMultiProcessController* controller, const std::string& dir,
  const std::string& npy, vtkImageData* whole)
{
  const int rank = controller->GetLocalProcessId(), ranks = controller->GetNumberOfProcesses();
  auto read = [&](const std::string& path, const std::string& uid = std::string())
  {
    vtkSmartPointer<vtkRGDICOMSeriesReader> reader = Reader(controller, path);
    if (!uid.empty())
    {
      reader->SetSeriesInstanceUID(uid.c_str());
    }
    return ReadPiece(reader, rank, ranks, 0);
  };
  struct Defect
  {
    std::string Name;
    std::vector<std::string> Texts;
  };
  const std::vector<Defect> defects = {
    // A slice of another orientation, pixel spacing or size in the middle of the stack is left
    // out as another acquisition, and the gap it leaves is the error.
    { "orientation",
      { "/orientation/IM", "not evenly spaced",
        "left out of this stack as another acquisition: IM" } },
    { "pixel-spacing",
      { "/pixel-spacing/IM", "not evenly spaced",
        "left out of this stack as another acquisition: IM" } },
    { "duplicate-position", { "/duplicate-position/IM", "same position" } },
    { "image-size",
      { "/image-size/IM", "not evenly spaced",
        "left out of this stack as another acquisition: IM" } },
    { "no-position", { "/no-position/IM", "has no ImagePositionPatient" } },
    { "transfer-syntax", { "/transfer-syntax/IM", "unsupported transfer syntax", "MPEG" } },
    { "irregular-spacing",
      { "are not evenly spaced", "/irregular-spacing/IM", "mm apart along", "the mean gap is",
        "from its place in the evenly spaced stack that fits best" } },
    // Not rounding: a missing slice, a gap of 1.5 spacings, a steady drift of the gaps.
    { "missing-slice", { "are not evenly spaced", "/missing-slice/IM", "a missing slice" } },
    { "wide-gap", { "are not evenly spaced", "/wide-gap/IM", "mm allowed for rounded positions" } },
    { "drift", { "are not evenly spaced", "/drift/IM", "variable spacing" } },
  };
  if (rank == 0)
  {
    for (const Defect& d : defects)
    {
      Generate(dir, npy, whole, d.Name, "--slope 1 --intercept -1024 --defect " + d.Name);
    }
    Generate(dir, npy, whole, "slightly-irregular-spacing", "--defect slightly-irregular-spacing");
    Generate(
      dir, npy, whole, "rounded-positions", "--oblique 30 --axis 1,2,3 --defect rounded-positions");
    Generate(dir, npy, whole, "second-series", "--defect second-series");
    Generate(dir, npy, whole, "localizer", "--defect localizer");
    Generate(dir, npy, whole, "gantry-tilt", "--defect gantry-tilt");
    Generate(dir, npy, whole, "truncated", "");
    fs::create_directories(dir + "/empty");
    fs::create_directories(dir + "/not-dicom");
    std::ofstream(dir + "/not-dicom/README.txt") << "not a DICOM file\n";
    std::ofstream(dir + "/not-dicom/notes") << std::string(300, 'x');
  }
  controller->Barrier();
  for (const Defect& d : defects)
  {
    ExpectError(controller, read(dir + "/" + d.Name), d.Name, d.Texts);
  }
  ExpectError(controller, read(dir + "/empty"), "empty directory", { "is empty" });
  ExpectError(controller, read(dir + "/not-dicom"), "no DICOM file", { "no DICOM image" });
  ExpectError(controller, read(dir + "/missing"), "missing directory", { "no such file" });

  // One slice 0.005 spacings off its place: rounding, read on the fitted spacing without a
  // word; the largest distance from the fitted stack is the moved slice's, from the least
  // squares line over n slices (its residual: shift * (1 - 1/n - (k - m)^2 / S), m the middle
  // index, S = n (n^2 - 1) / 12).
  {
    vtkSmartPointer<vtkRGDICOMSeriesReader> reader =
      Reader(controller, dir + "/slightly-irregular-spacing");
    PieceRead r = ReadPiece(reader, rank, ranks, 0);
    const double n = Dims[2], k = Dims[2] / 2, m = 0.5 * (n - 1), S = n * (n * n - 1) / 12;
    const double expected = 0.005 * whole->GetSpacing()[2] * (1 - 1 / n - (k - m) * (k - m) / S);
    RGMC_CHECK(r.Ok && r.Errors.empty(), "slightly irregular spacing: " << r.Errors);
    RGMC_CHECK(r.Warnings.find("irregular slice spacing") == std::string::npos,
      "slightly irregular spacing: a warning on rank " << rank << " [" << r.Warnings << "]");
    RGMC_CHECK(std::fabs(reader->GetLargestSpacingDeviation() - expected) < 1e-9,
      "slightly irregular spacing: largest deviation " << reader->GetLargestSpacingDeviation()
                                                       << ", expected " << expected);
    RGMC_CHECK(r.Image->GetNumberOfPoints() > 0, "slightly irregular spacing: nothing read");
  }
  // An oblique stack whose positions are written with one decimal, as some scanners do: its
  // gaps jitter by several percent, every slice within 0.1 mm of its place. Read, with a
  // warning giving the spread, on a fitted spacing that puts the far end of the stack within
  // 0.2 mm of where the unrounded positions put it.
  {
    vtkSmartPointer<vtkRGDICOMSeriesReader> reader = Reader(controller, dir + "/rounded-positions");
    PieceRead r = ReadPiece(reader, rank, ranks, 0);
    const double spacing = whole->GetSpacing()[2];
    RGMC_CHECK(r.Ok && r.Errors.empty(), "rounded positions: " << r.Errors);
    RGMC_CHECK(r.Warnings.find("irregular slice spacing") != std::string::npos &&
        r.Warnings.find("the volume is read with the fitted spacing") != std::string::npos,
      "rounded positions: no warning on rank " << rank << " [" << r.Warnings << "]");
    RGMC_CHECK(
      reader->GetLargestSpacingDeviation() > 0.01 && reader->GetLargestSpacingDeviation() < 0.1,
      "rounded positions: slices up to " << reader->GetLargestSpacingDeviation()
                                         << " mm from their places (rounding to 0.1 mm)");
    if (r.Ok)
    {
      const double read = r.Image->GetSpacing()[2];
      RGMC_CHECK(std::fabs(read - spacing) * (Dims[2] - 1) < 0.2,
        "rounded positions: spacing " << read << " mm, the positions' " << spacing << " mm");
    }
    if (rank == 0)
    {
      std::cout << "rounded positions: " << ReaderMessage(r.Warnings) << "\n";
    }
  }
  // A tilted gantry (slices sheared along their planes): said, with the angle; still read.
  {
    vtkSmartPointer<vtkRGDICOMSeriesReader> reader = Reader(controller, dir + "/gantry-tilt");
    PieceRead r = ReadPiece(reader, rank, ranks, 0);
    RGMC_CHECK(r.Ok && r.Warnings.find("a gantry tilt of 12 degrees") != std::string::npos,
      "gantry tilt: expected a warning with its angle, got [" << r.Warnings << "] " << r.Errors);
    if (rank == 0)
    {
      std::cout << "gantry tilt: " << ReaderMessage(r.Warnings) << "\n";
    }
  }
  // Localizers in the series: the largest stack is read, the same volume as without them, with a
  // warning that names the files left out.
  {
    vtkSmartPointer<vtkRGDICOMSeriesReader> reader = Reader(controller, dir + "/localizer");
    PieceRead r = ReadPiece(reader, rank, ranks, 0);
    RGMC_CHECK(r.Ok && r.Warnings.find("mixes 2 stacks of images") != std::string::npos &&
        r.Warnings.find("LOC0") != std::string::npos &&
        r.Warnings.find("LOC1") != std::string::npos,
      "localizer: expected a warning naming LOC0 and LOC1, got [" << r.Warnings << "] "
                                                                  << r.Errors);
    RGMC_CHECK(reader->GetNumberOfFiles() == Dims[2],
      "localizer: read " << reader->GetNumberOfFiles() << " files");
    RGMC_CHECK(r.Ok && Mismatches(r.Image, whole) == 0, "localizer: the volume differs");
    if (rank == 0)
    {
      std::cout << "localizer: " << ReaderMessage(r.Warnings) << "\n";
    }
  }
  // Two series: the larger is read with a warning listing the other; a UID picks one; an
  // unknown UID is an error that lists what is there.
  {
    vtkSmartPointer<vtkRGDICOMSeriesReader> reader = Reader(controller, dir + "/second-series");
    PieceRead r = ReadPiece(reader, rank, ranks, 0);
    RGMC_CHECK(r.Ok && r.Warnings.find("holds 2 series") != std::string::npos,
      "second series: expected a warning, got [" << r.Warnings << "] " << r.Errors);
    RGMC_CHECK(reader->GetNumberOfFiles() == Dims[2], "second series: read the wrong series");
    std::string list = reader->GetSeriesList();
    const std::string other =
      list.substr(list.find('\n') + 1, list.find(':', list.find('\n')) - list.find('\n') - 1);
    vtkSmartPointer<vtkRGDICOMSeriesReader> scout = Reader(controller, dir + "/second-series");
    scout->SetSeriesInstanceUID(other.c_str());
    PieceRead s = ReadPiece(scout, rank, ranks, 0);
    RGMC_CHECK(s.Ok && scout->GetNumberOfFiles() == 3,
      "second series by UID " << other << ": " << scout->GetNumberOfFiles() << " files "
                              << s.Errors);
    ExpectError(controller, read(dir + "/second-series", "1.2.3.4"), "unknown series UID",
      { "no series 1.2.3.4", other });
    // One file of the scout series opens the scout series.
    vtkSmartPointer<vtkRGDICOMSeriesReader> byFile =
      Reader(controller, dir + "/second-series/SCOUT1");
    PieceRead f = ReadPiece(byFile, rank, ranks, 0);
    RGMC_CHECK(f.Ok && byFile->GetNumberOfFiles() == 3,
      "a scout file opens " << byFile->GetNumberOfFiles() << " files");
  }
  // A file truncated in its pixel data after the header scan: found by the rank that decodes
  // it (the last slice, the last rank's), reported by every rank. Then the same file found by
  // a new scan, then a file cut inside its header.
  {
    vtkSmartPointer<vtkRGDICOMSeriesReader> reader = Reader(controller, dir + "/truncated");
    reader->UpdateInformation();
    const std::string last = reader->GetSliceFileName(Dims[2] - 1);
    controller->Barrier();
    if (rank == 0)
    {
      fs::resize_file(last, fs::file_size(last) - 100);
    }
    controller->Barrier();
    ExpectError(controller, ReadPiece(reader, rank, ranks, 0), "truncated after the scan",
      { last, "is truncated: its pixel data has" });
    reader->Modified();
    ExpectError(controller, ReadPiece(reader, rank, ranks, 0), "truncated pixel data",
      { last, "is truncated: its pixel data has" });
    if (rank == 0)
    {
      fs::resize_file(last, 200);
    }
    controller->Barrier();
    ExpectError(controller, read(dir + "/truncated"), "truncated header",
      { last, "is truncated or corrupt" });
  }
}

} // namespace

int main(int argc, char* argv[])
{
  vtkSmartPointer<vtkMultiProcessController> controller = rgmc_test::StartController(argc, argv);
  const int rank = controller->GetLocalProcessId(), ranks = controller->GetNumberOfProcesses();

  const int wholeExtent[6] = { 0, Dims[0] - 1, 0, Dims[1] - 1, 0, Dims[2] - 1 };
  vtkSmartPointer<vtkImageData> whole = PhantomPiece(Dims, wholeExtent);
  const std::string dir =
    ScratchDirectory(controller, "TestDICOMSeries-" + std::to_string(ranks) + "ranks");
  const std::string npy = dir + "/phantom.npy";
  int generated = 1;
  if (rank == 0)
  {
    generated = WriteNpy(npy, whole);
    for (const Series& s : AllSeries())
    {
      Generate(dir, npy, whole, s.Name, s.Options);
      generated = generated && fs::is_directory(dir + "/" + s.Name);
    }
  }
  controller->Broadcast(&generated, 1, 0);
  RGMC_CHECK(generated, "the generator failed");
  if (generated)
  {
    for (const Series& s : AllSeries())
    {
      ReadGoodSeries(controller, dir, whole, s);
    }
    BadSeries(controller, dir, npy, whole);
  }

  int failures = Failures(), total = 0;
  controller->AllReduce(&failures, &total, 1, vtkCommunicator::SUM_OP);
  const int result = rank == 0 ? Result("TestDICOMSeries") : (failures ? 1 : 0);
  controller->Finalize();
  return total ? 1 : result;
}

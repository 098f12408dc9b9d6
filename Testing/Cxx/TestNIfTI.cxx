// vtkRGNIfTIReader on 1 rank (vtkDummyController) and under mpiexec against VTK's own
// vtkNIFTIImageReader on the real MRI volumes of Debian's mricron-data (uint8 with an sform,
// float32 at 0.5 mm, a qform with qfac -1 and header extensions), an uncompressed copy (the seek
// path) and a big-endian int16 file with scl_slope/scl_inter and a rotated qform (plain and
// gzipped). Each rank's piece must be its slab, its voxels VTK's (scaled), its world points
// VTK's (RAS, converted to our LPS); the union equals the 1-rank volume. Bad files give the
// same message, naming the file, on every rank.
#include "rgmcReaderTestData.h"
#include "rgmcTestController.h"

#include "vtkDummyController.h"
#include "vtkExtentTranslator.h"
#include "vtkMatrix3x3.h"
#include "vtkMatrix4x4.h"
#include "vtkNIFTIImageReader.h"
#include "vtkRGNIfTIReader.h"

#include <zlib.h>

#include <cmath>
#include <cstring>
#include <iostream>

using namespace rgmc_test;

namespace
{

const short SynDims[3] = { 20, 18, 16 };

double SynValue(int i, int j, int k)
{
  return (i * 7 + j * 13 + k * 31) % 2000 - 1000;
}

template <typename T>
void Put(std::vector<unsigned char>& h, int offset, T value, bool big)
{
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  if (big)
  {
    std::reverse(bytes, bytes + sizeof(T));
  }
  std::memcpy(h.data() + offset, bytes, sizeof(T));
}

/// A NIfTI-1 file written field by field (big endian), int16 data, slope 0.5, intercept 10, a
/// rotated qform with qfac -1, no sform; `sizeofHdr`, `magic` and `datatype` make it wrong.
std::vector<unsigned char> SyntheticNIfTI(
  int sizeofHdr = 348, const char* magic = "n+1", short datatype = 4, short dim0 = 3)
{
  const bool big = true;
  std::vector<unsigned char> h(352, 0);
  Put<std::int32_t>(h, 0, sizeofHdr, big);
  const short dim[8] = { dim0, SynDims[0], SynDims[1], SynDims[2], 1, 1, 1, 1 };
  for (int d = 0; d < 8; ++d)
  {
    Put<std::int16_t>(h, 40 + 2 * d, dim[d], big);
  }
  Put<std::int16_t>(h, 70, datatype, big);
  Put<std::int16_t>(h, 72, 16, big);
  const float pixdim[8] = { -1.0f, 1.2f, 0.9f, 2.5f, 1, 1, 1, 1 };
  for (int d = 0; d < 8; ++d)
  {
    Put<float>(h, 76 + 4 * d, pixdim[d], big);
  }
  Put<float>(h, 108, 352.0f, big);
  Put<float>(h, 112, 0.5f, big);
  Put<float>(h, 116, 10.0f, big);
  Put<std::int16_t>(h, 252, 1, big); // qform_code
  Put<std::int16_t>(h, 254, 0, big); // sform_code
  const float q[6] = { 0.1f, 0.2f, 0.3f, 5.0f, -7.0f, 9.0f };
  for (int a = 0; a < 6; ++a)
  {
    Put<float>(h, 256 + 4 * a, q[a], big);
  }
  std::memcpy(h.data() + 344, magic, 4);
  for (int k = 0; k < SynDims[2]; ++k)
  {
    for (int j = 0; j < SynDims[1]; ++j)
    {
      for (int i = 0; i < SynDims[0]; ++i)
      {
        const std::size_t at = h.size();
        h.resize(at + 2);
        Put<std::int16_t>(h, static_cast<int>(at), static_cast<short>(SynValue(i, j, k)), big);
      }
    }
  }
  return h;
}

void WritePlain(const std::string& path, const std::vector<unsigned char>& bytes)
{
  std::ofstream(path, std::ios::binary)
    .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

void WriteGz(const std::string& path, const std::vector<unsigned char>& bytes)
{
  gzFile out = gzopen(path.c_str(), "wb");
  gzwrite(out, bytes.data(), static_cast<unsigned>(bytes.size()));
  gzclose(out);
}

vtkSmartPointer<vtkRGNIfTIReader> Reader(vtkMultiProcessController* c, const std::string& path)
{
  auto reader = vtkSmartPointer<vtkRGNIfTIReader>::New();
  reader->SetController(c);
  reader->SetFileName(path.c_str());
  return reader;
}

void CompareWithVTK(vtkMultiProcessController* controller, const std::string& path, int outputType)
{
  const int rank = controller->GetLocalProcessId(), ranks = controller->GetNumberOfProcesses();
  const std::string what =
    fs::path(path).filename().string() + " on " + std::to_string(ranks) + " ranks";
  vtkSmartPointer<vtkRGNIfTIReader> reader = Reader(controller, path);
  PieceRead r = ReadPiece(reader, rank, ranks, 0);
  RGMC_CHECK(r.Ok && r.Errors.empty(), what << ": " << r.Errors);

  vtkNew<vtkNIFTIImageReader> vtk;
  vtk->SetFileName(path.c_str());
  vtk->Update();
  vtkImageData* theirs = vtk->GetOutput();
  int dims[3];
  theirs->GetDimensions(dims);
  const int whole[6] = { 0, dims[0] - 1, 0, dims[1] - 1, 0, dims[2] - 1 };
  // The rank's slab, on several ranks with the ghost slice the extraction asks for.
  int owned[6], expected[6], ext[6];
  vtkNew<vtkExtentTranslator> translator;
  translator->PieceToExtentThreadSafe(
    rank, ranks, 0, const_cast<int*>(whole), owned, vtkExtentTranslator::Z_SLAB_MODE, 0);
  translator->PieceToExtentThreadSafe(rank, ranks, ranks > 1 ? 1 : 0, const_cast<int*>(whole),
    expected, vtkExtentTranslator::Z_SLAB_MODE, 0);
  r.Image->GetExtent(ext);
  RGMC_CHECK(std::equal(ext, ext + 6, expected), what << ": not the rank's slab");
  vtkDataArray* ours = r.Image->GetPointData()->GetScalars();
  RGMC_CHECK(ours && ours->GetDataType() == outputType,
    what << ": output type " << (ours ? ours->GetDataTypeAsString() : "none"));
  if (!ours)
  {
    return;
  }

  // Voxels: VTK's, scaled; VTK reverses the slices when qfac is -1.
  const double slope = vtk->GetRescaleSlope() != 0 ? vtk->GetRescaleSlope() : 1.0;
  const double intercept = vtk->GetRescaleIntercept();
  const bool flip = vtk->GetQFac() < 0;
  vtkDataArray* values = theirs->GetPointData()->GetScalars();
  vtkIdType bad = 0;
  double sum = 0;
  for (int k = ext[4]; k <= ext[5]; ++k)
  {
    for (int j = ext[2]; j <= ext[3]; ++j)
    {
      for (int i = ext[0]; i <= ext[1]; ++i)
      {
        int ijk[3] = { i, j, k }, theirIjk[3] = { i, j, flip ? dims[2] - 1 - k : k };
        const double e =
          values->GetComponent(theirs->ComputePointId(theirIjk), 0) * slope + intercept;
        const double o = ours->GetComponent(r.Image->ComputePointId(ijk), 0);
        const double want = outputType == VTK_FLOAT ? static_cast<float>(e) : e;
        bad += o != want;
        // Neighbouring slabs share a slice: it counts for the lower one; ghosts for none.
        sum += k >= owned[4] && (k < owned[5] || k == dims[2] - 1) ? o : 0.0;
      }
    }
  }
  RGMC_CHECK(bad == 0, what << ": " << bad << " voxels differ from vtkNIFTIImageReader's");

  // World points of the corners: VTK's matrix (the one we used) maps its index space to RAS.
  vtkMatrix4x4* m =
    reader->GetGeometryMethod() == 3 ? vtk->GetSFormMatrix() : vtk->GetQFormMatrix();
  RGMC_CHECK(reader->GetGeometryMethod() >= 2 && m, what << ": no qform or sform used");
  double worst = 0;
  for (int c = 0; m && c < 8; ++c)
  {
    const int ijk[3] = { c & 1 ? dims[0] - 1 : 0, c & 2 ? dims[1] - 1 : 0,
      c & 4 ? dims[2] - 1 : 0 };
    double ours3[3];
    const double idx[3] = { double(ijk[0]), double(ijk[1]), double(ijk[2]) };
    r.Image->TransformContinuousIndexToPhysicalPoint(idx, ours3);
    const int kk = flip ? dims[2] - 1 - ijk[2] : ijk[2];
    double local[4] = { theirs->GetOrigin()[0] + ijk[0] * theirs->GetSpacing()[0],
      theirs->GetOrigin()[1] + ijk[1] * theirs->GetSpacing()[1],
      theirs->GetOrigin()[2] + kk * theirs->GetSpacing()[2], 1.0 };
    double ras[4];
    m->MultiplyPoint(local, ras);
    const double lps[3] = { -ras[0], -ras[1], ras[2] };
    worst = std::max(worst, std::sqrt(vtkMath::Distance2BetweenPoints(ours3, lps)));
  }
  RGMC_CHECK(worst < 1e-5, what << ": corners " << worst << " mm from VTK's (in LPS)");

  // The union over ranks: the same checksum as one rank.
  double total = 0;
  controller->AllReduce(&sum, &total, 1, vtkCommunicator::SUM_OP);
  if (rank == 0)
  {
    vtkNew<vtkDummyController> single;
    vtkSmartPointer<vtkRGNIfTIReader> one = Reader(single, path);
    PieceRead all = ReadPiece(one, 0, 1, 0);
    double wholeSum = 0;
    vtkDataArray* a = all.Image->GetPointData()->GetScalars();
    for (vtkIdType n = 0; a && n < a->GetNumberOfTuples(); ++n)
    {
      wholeSum += a->GetComponent(n, 0);
    }
    RGMC_CHECK(
      wholeSum == total, what << ": pieces sum to " << total << ", 1 rank to " << wholeSum);
    std::cout << what << ": " << reader->GetSummary() << "; corners within " << worst
              << " mm of vtkNIFTIImageReader's\n";
  }
}

void BadFiles(vtkMultiProcessController* controller, const std::string& dir)
{
  const int rank = controller->GetLocalProcessId(), ranks = controller->GetNumberOfProcesses();
  auto expect = [&](const std::string& name, const std::vector<std::string>& texts)
  {
    vtkSmartPointer<vtkRGNIfTIReader> reader = Reader(controller, dir + "/" + name);
    std::vector<std::string> all = texts;
    all.push_back(dir + "/" + name);
    ExpectError(controller, ReadPiece(reader, rank, ranks, 0), name, all);
  };
  if (rank == 0)
  {
    std::ofstream(dir + "/text.nii") << std::string(400, 'x');
    WritePlain(dir + "/nifti2.nii", SyntheticNIfTI(540));
    WritePlain(dir + "/pair.nii", SyntheticNIfTI(348, "ni1"));
    WritePlain(dir + "/analyze.nii", SyntheticNIfTI(348, "\0\0\0"));
    WritePlain(dir + "/complex.nii", SyntheticNIfTI(348, "n+1", 32));
    WritePlain(dir + "/dim0.nii", SyntheticNIfTI(348, "n+1", 4, 0));
    std::vector<unsigned char> good = SyntheticNIfTI();
    WritePlain(
      dir + "/short-header.nii", std::vector<unsigned char>(good.begin(), good.begin() + 200));
    WritePlain(dir + "/truncated.nii", std::vector<unsigned char>(good.begin(), good.end() - 1000));
    // A gzip stream cut at 60%: the ranks reading the last slices find the end.
    WriteGz(dir + "/full.nii.gz", good);
    std::ifstream in(dir + "/full.nii.gz", std::ios::binary);
    std::vector<unsigned char> z(
      (std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    WritePlain(dir + "/truncated.nii.gz",
      std::vector<unsigned char>(z.begin(), z.begin() + z.size() * 6 / 10));
  }
  controller->Barrier();
  expect("missing.nii", { "no such file" });
  expect("text.nii", { "is not a NIfTI-1 file" });
  expect("nifti2.nii", { "NIfTI-2" });
  expect("pair.nii", { ".hdr/.img pair" });
  expect("analyze.nii", { "no NIfTI-1 magic" });
  expect("complex.nii", { "complex64" });
  expect("dim0.nii", { "dim[0] = 0" });
  expect("short-header.nii", { "is truncated", "200 of 348" });
  expect("truncated.nii", { "is truncated" });
  expect("truncated.nii.gz", { "slice" });
}

} // namespace

int main(int argc, char* argv[])
{
  vtkSmartPointer<vtkMultiProcessController> controller = rgmc_test::StartController(argc, argv);
  const int rank = controller->GetLocalProcessId(), ranks = controller->GetNumberOfProcesses();
  const std::string dir =
    ScratchDirectory(controller, "TestNIfTI-" + std::to_string(ranks) + "ranks");
  const std::string mricron = RGMC_MRICRON_DIR;
  if (rank == 0)
  {
    WritePlain(dir + "/ch2.nii", Gunzip(mricron + "/ch2.nii.gz"));
    WritePlain(dir + "/synthetic-be.nii", SyntheticNIfTI());
    WriteGz(dir + "/synthetic-be.nii.gz", SyntheticNIfTI());
  }
  controller->Barrier();
  CompareWithVTK(controller, mricron + "/ch2.nii.gz", VTK_SHORT);
  CompareWithVTK(controller, dir + "/ch2.nii", VTK_SHORT);
  CompareWithVTK(controller, mricron + "/inia19-t1-brain.nii.gz", VTK_FLOAT);
  CompareWithVTK(controller, mricron + "/natbrainlab.nii.gz", VTK_SHORT);
  CompareWithVTK(controller, dir + "/synthetic-be.nii", VTK_FLOAT);
  CompareWithVTK(controller, dir + "/synthetic-be.nii.gz", VTK_FLOAT);
  BadFiles(controller, dir);

  int failures = Failures(), total = 0;
  controller->AllReduce(&failures, &total, 1, vtkCommunicator::SUM_OP);
  const int result = rank == 0 ? Result("TestNIfTI") : (failures ? 1 : 0);
  controller->Finalize();
  return total ? 1 : result;
}

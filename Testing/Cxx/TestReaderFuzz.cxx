// A bounded mutation fuzz test of both readers over real files: pydicom's DICOM files (native
// little and big endian, deflated, RLE, JPEG, JPEG-LS, JPEG 2000, multi-frame, 1-bit) and
// mricron's MRI volume (as .nii and .nii.gz). Each mutant (random byte flips, interesting
// values, truncations, inserted and deleted runs, mostly in the headers; a fixed seed, so every
// run tries the same mutants) is read; the reader must come back (no crash, no hang) with a
// volume or with an error that names the file. Every mutant is tried, however fast the machine
// (14 files x 100 = 1400 by default; ctest's timeout is the bound on a hang). The counts are
// checked: every mutant is read or refused, every refusal has a message naming the file, and
// at the default count each reader both reads some mutants and refuses some. Runs in the plain
// and the sanitizer builds.
//   TestReaderFuzz [mutants per file (default 100)]
#include "rgmcReaderTestData.h"

#include "vtkDummyController.h"
#include "vtkRGDICOMSeriesReader.h"
#include "vtkRGNIfTIReader.h"

#include <zlib.h>

#include <chrono>
#include <iostream>
#include <random>

using namespace rgmc_test;

namespace
{

std::vector<unsigned char> Load(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  return std::vector<unsigned char>(
    (std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void Save(const std::string& path, const std::vector<unsigned char>& bytes)
{
  std::ofstream(path, std::ios::binary)
    .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

/// One mutant of `bytes`: a few random edits, most of them in the first `focus` bytes.
std::vector<unsigned char> Mutate(
  std::vector<unsigned char> bytes, std::mt19937& random, std::size_t focus)
{
  auto position = [&]() -> std::size_t
  {
    if (bytes.empty())
    {
      return 0;
    }
    const std::size_t range = std::uniform_int_distribution<int>(0, 3)(random)
      ? std::min(focus, bytes.size())
      : bytes.size();
    return std::uniform_int_distribution<std::size_t>(0, range - 1)(random);
  };
  const int edits = std::uniform_int_distribution<int>(1, 4)(random);
  for (int e = 0; e < edits && !bytes.empty(); ++e)
  {
    switch (std::uniform_int_distribution<int>(0, 5)(random))
    {
      case 0: // flip bits
        bytes[position()] ^=
          static_cast<unsigned char>(1 << std::uniform_int_distribution<int>(0, 7)(random));
        break;
      case 1: // an interesting byte
      {
        static const unsigned char values[] = { 0x00, 0xff, 0x7f, 0x80, 0x01, 0x20 };
        bytes[position()] = values[std::uniform_int_distribution<int>(0, 5)(random)];
        break;
      }
      case 2: // an interesting 32-bit value (lengths, dimensions)
      {
        static const std::uint32_t values[] = { 0, 0xffffffffu, 0x7fffffffu, 0x80000000u, 0xfffe,
          1u << 20 };
        const std::uint32_t v = values[std::uniform_int_distribution<int>(0, 5)(random)];
        const std::size_t at = position();
        for (int b = 0; b < 4 && at + b < bytes.size(); ++b)
        {
          bytes[at + b] = static_cast<unsigned char>(v >> (8 * b));
        }
        break;
      }
      case 3: // truncate
        bytes.resize(position());
        break;
      case 4: // delete a run
      {
        const std::size_t at = position();
        const std::size_t n = std::min<std::size_t>(
          bytes.size() - at, std::uniform_int_distribution<int>(1, 64)(random));
        bytes.erase(bytes.begin() + at, bytes.begin() + at + n);
        break;
      }
      default: // insert a copy of a run
      {
        const std::size_t from = position(), to = position();
        const std::size_t n = std::min<std::size_t>(
          bytes.size() - from, std::uniform_int_distribution<int>(1, 64)(random));
        std::vector<unsigned char> run(bytes.begin() + from, bytes.begin() + from + n);
        bytes.insert(bytes.begin() + std::min(to, bytes.size()), run.begin(), run.end());
      }
    }
  }
  return bytes;
}

std::vector<unsigned char> Gzip(const std::vector<unsigned char>& bytes)
{
  uLongf size = compressBound(static_cast<uLong>(bytes.size())) + 32;
  std::vector<unsigned char> out(size);
  z_stream z{};
  deflateInit2(&z, 6, Z_DEFLATED, 15 + 16, 8, Z_DEFAULT_STRATEGY);
  z.next_in = const_cast<Bytef*>(bytes.data());
  z.avail_in = static_cast<uInt>(bytes.size());
  z.next_out = out.data();
  z.avail_out = static_cast<uInt>(out.size());
  deflate(&z, Z_FINISH);
  out.resize(z.total_out);
  deflateEnd(&z);
  return out;
}

} // namespace

int main(int argc, char* argv[])
{
  const int perFile = argc > 1 ? std::atoi(argv[1]) : 100;
  vtkNew<vtkDummyController> controller;
  vtkMultiProcessController::SetGlobalController(controller);
  const std::string work = ScratchDirectory(controller, "TestReaderFuzz");
  const std::string pydicom = RGMC_PYDICOM_DIR;
  const std::vector<std::string> dicom = { "CT_small.dcm", "MR_small_bigendian.dcm",
    "MR_small_RLE.dcm", "MR_small_jp2klossless.dcm", "MR_small_jpeg_ls_lossless.dcm",
    "SC_rgb_jpeg_dcmtk.dcm", "SC_rgb_rle_16bit.dcm", "JPGExtended.dcm", "image_dfl.dcm",
    "rtdose.dcm", "liver_1frame.dcm", "SC_ybr_full_422_uncompressed.dcm" };
  struct Seed
  {
    std::string Name;
    std::vector<unsigned char> Bytes;
    bool Nifti, Gzip;
  };
  std::vector<Seed> seeds;
  for (const std::string& name : dicom)
  {
    seeds.push_back(Seed{ name, Load(pydicom + "/" + name), false, false });
  }
  const std::vector<unsigned char> nifti =
    Gunzip(std::string(RGMC_MRICRON_DIR) + "/JHU-WhiteMatter-labels-2mm.nii.gz");
  seeds.push_back(Seed{ "labels.nii", nifti, true, false });
  seeds.push_back(Seed{ "labels.nii.gz", nifti, true, true });

  std::mt19937 random(20261122);
  const auto start = std::chrono::steady_clock::now();
  // Per reader (0 DICOM, 1 NIfTI): mutants tried, read, refused, and refused with a message that
  // names the file.
  struct Counts
  {
    int Tried = 0, Read = 0, Refused = 0, Named = 0;
  };
  Counts counts[2];
  int tried = 0;
  for (const Seed& seed : seeds)
  {
    for (int m = 0; m < perFile; ++m)
    {
      // A NIfTI mutant of the .nii.gz is mutated before compression (the header and voxels
      // matter; a broken gzip stream is also tried now and then).
      std::vector<unsigned char> bytes = Mutate(seed.Bytes, random, seed.Nifti ? 352 : 2048);
      if (seed.Gzip)
      {
        bytes = Gzip(bytes);
        if (m % 5 == 0)
        {
          bytes = Mutate(bytes, random, bytes.size());
        }
      }
      const std::string dir = work + "/" + std::to_string(tried);
      fs::create_directories(dir);
      const std::string path = dir + "/" + seed.Name;
      Save(path, bytes); // left on disk if the reader crashes: the failing input
      if (std::getenv("RGMC_FUZZ_VERBOSE"))
      {
        std::cout << "mutant " << tried << ": " << path << std::endl;
      }
      vtkSmartPointer<vtkRGVolumeReader> reader;
      if (seed.Nifti)
      {
        reader = vtkSmartPointer<vtkRGNIfTIReader>::New();
      }
      else
      {
        reader = vtkSmartPointer<vtkRGDICOMSeriesReader>::New();
      }
      reader->SetController(controller);
      reader->SetFileName(path.c_str());
      PieceRead r = ReadPiece(reader, 0, 1, 0);
      const std::string message = ReaderMessage(r.Errors);
      Counts& c = counts[seed.Nifti ? 1 : 0];
      ++c.Tried;
      if (r.Ok)
      {
        ++c.Read;
      }
      else
      {
        ++c.Refused;
        const bool named = !message.empty() && message.find(path) != std::string::npos;
        c.Named += named ? 1 : 0;
        RGMC_CHECK(named,
          "mutant " << tried << " of " << seed.Name
                    << ": refused without a message naming the file: [" << r.Errors << "]");
      }
      fs::remove_all(dir);
      ++tried;
    }
  }
  const double seconds =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const char* readerNames[2] = { "DICOM", "NIfTI" };
  std::cout << tried << " mutants of " << seeds.size() << " real files in " << seconds << " s\n";
  for (int k = 0; k < 2; ++k)
  {
    const Counts& c = counts[k];
    std::cout << "  " << readerNames[k] << ": " << c.Tried << " mutants, " << c.Read << " read, "
              << c.Refused << " refused, " << c.Named
              << " of them with a message naming the file\n";
    // Each mutant came back one way or the other, and every refusal said which file it was.
    RGMC_CHECK(c.Read + c.Refused == c.Tried,
      readerNames[k] << ": " << c.Read << " read + " << c.Refused << " refused != " << c.Tried
                     << " tried");
    RGMC_CHECK(c.Named == c.Refused,
      readerNames[k] << ": " << c.Refused - c.Named << " of " << c.Refused
                     << " refusals without a message naming the file");
    // With the fixed seed and the default count, the mutants of each reader include some it reads
    // (edits in a DICOM file's preamble or an element the reader ignores, in a NIfTI file's unused
    // header fields or its voxels) and some it must refuse (truncated headers and voxels). If
    // either count is 0, the mutator or the reader's checks have changed, and the test no longer
    // exercises both outcomes. A smaller count given on the command line may miss one.
    if (perFile >= 100)
    {
      RGMC_CHECK(c.Read > 0, readerNames[k] << ": no mutant was read");
      RGMC_CHECK(c.Refused > 0, readerNames[k] << ": no mutant was refused");
    }
  }
  return Result("TestReaderFuzz");
}

// vtkRGDICOMSeriesReader on the real DICOM files that Debian's python3-pydicom ships (many
// transfer syntaxes, both byte orders, signed and unsigned, 1 to 32 bits, RGB, multi-frame),
// against pydicom's own decoding (Testing/Python/Modules/pydicom_oracle.py, run with Debian's
// python3): every file pydicom decodes must decode to the same samples after the modality LUT,
// exactly.
// Files pydicom cannot decode are listed with pydicom's reason; the reader must still read them
// or fail with a message, never crash; the truncated one must be reported as truncated; files
// without pixel data must be refused with a message.
#include "rgmcReaderTestData.h"

#include "vtkDummyController.h"
#include "vtkRGDICOMSeriesReader.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iostream>
#include <iterator>
#include <map>

using namespace rgmc_test;

namespace
{

struct Entry
{
  std::string Name, Status, TransferSyntax, Note;
  int Frames = 0, Rows = 0, Columns = 0, Samples = 0;
};

std::vector<Entry> Manifest(const std::string& path)
{
  std::vector<Entry> entries;
  std::ifstream in(path);
  for (std::string line; std::getline(in, line);)
  {
    std::vector<std::string> fields;
    std::stringstream parts(line);
    for (std::string f; std::getline(parts, f, '\t');)
    {
      fields.push_back(f);
    }
    fields.resize(5);
    Entry e;
    e.Name = fields[0];
    e.Status = fields[1];
    e.TransferSyntax = fields[2];
    std::istringstream(fields[3]) >> e.Frames >> e.Rows >> e.Columns >> e.Samples;
    e.Note = fields[4];
    entries.push_back(e);
  }
  return entries;
}

/// The file's bytes.
std::vector<unsigned char> Bytes(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  return std::vector<unsigned char>(
    std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void Save(const std::string& path, const std::vector<unsigned char>& bytes)
{
  std::ofstream out(path, std::ios::binary);
  out.write(
    reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

std::vector<double> Samples(const std::string& path)
{
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  std::vector<double> values(static_cast<std::size_t>(in.tellg()) / sizeof(double));
  in.seekg(0);
  in.read(reinterpret_cast<char*>(values.data()),
    static_cast<std::streamsize>(values.size() * sizeof(double)));
  return values;
}

} // namespace

int main()
{
  vtkNew<vtkDummyController> controller;
  vtkMultiProcessController::SetGlobalController(controller);
  const std::string work = ScratchDirectory(controller, "TestDICOMFiles");
  const std::string oracle = work + "/pydicom";
  if (!Run(std::string(RGMC_SYSTEM_PYTHON) + " " + RGMC_TESTING_PYTHON_DIR + "/pydicom_oracle.py " +
        RGMC_PYDICOM_DIR + " " + oracle))
  {
    RGMC_CHECK(false, "the pydicom oracle failed");
    return Result("TestDICOMFiles");
  }
  int compared = 0;
  std::map<std::string, int> syntaxes;
  std::vector<std::string> skipped;
  for (const Entry& e : Manifest(oracle + "/manifest.tsv"))
  {
    // Each file alone in a directory: the reader reads the series of the file it is given.
    const std::string dir = work + "/" + e.Name;
    fs::create_directories(dir);
    fs::copy_file(std::string(RGMC_PYDICOM_DIR) + "/" + e.Name, dir + "/" + e.Name,
      fs::copy_options::overwrite_existing);
    vtkNew<vtkRGDICOMSeriesReader> reader;
    reader->SetController(controller);
    reader->SetFileName((dir + "/" + e.Name).c_str());
    PieceRead r = ReadPiece(reader, 0, 1, 0);
    const std::string message = ReaderMessage(r.Errors);

    if (e.Status == "decoded" || e.Status == "twin")
    {
      RGMC_CHECK(r.Ok, e.Name << " (" << e.TransferSyntax << "): not read: " << message);
      if (!r.Ok)
      {
        continue;
      }
      int ext[6];
      r.Image->GetExtent(ext);
      vtkDataArray* ours = r.Image->GetPointData()->GetScalars();
      const bool sameShape = ext[1] + 1 == e.Columns && ext[3] + 1 == e.Rows &&
        ext[5] + 1 == e.Frames && ours->GetNumberOfComponents() == e.Samples;
      RGMC_CHECK(sameShape,
        e.Name << ": " << ext[1] + 1 << " x " << ext[3] + 1 << " x " << ext[5] + 1 << " x "
               << ours->GetNumberOfComponents() << ", pydicom: " << e.Columns << " x " << e.Rows
               << " x " << e.Frames << " x " << e.Samples);
      if (!sameShape)
      {
        continue;
      }
      const std::vector<double> theirs = Samples(oracle + "/" + e.Name + ".f64");
      vtkIdType differ = 0;
      double worst = 0;
      for (vtkIdType n = 0; n < static_cast<vtkIdType>(theirs.size()); ++n)
      {
        const double a = ours->GetComponent(n / e.Samples, static_cast<int>(n % e.Samples));
        // Our float output holds pydicom's double exactly when it is exact in float.
        const double b =
          ours->GetDataType() == VTK_FLOAT ? static_cast<float>(theirs[n]) : theirs[n];
        differ += a != b;
        worst = std::max(worst, std::fabs(a - b));
      }
      RGMC_CHECK(differ == 0,
        e.Name << " (" << e.TransferSyntax << "): " << differ << " of " << theirs.size()
               << " samples differ from pydicom's, by up to " << worst);
      ++compared;
      ++syntaxes[e.TransferSyntax];
      std::cout << "same as pydicom" << (e.Status == "twin" ? " (on its twin " + e.Note + ")" : "")
                << ": " << e.Name << " " << e.TransferSyntax << " " << e.Columns << "x" << e.Rows
                << "x" << e.Frames << "x" << e.Samples << " " << ours->GetDataTypeAsString()
                << "\n";
    }
    else if (e.Status == "no-pixels")
    {
      RGMC_CHECK(!r.Ok &&
          (message.find("no DICOM image") != std::string::npos ||
            message.find("is truncated or corrupt") != std::string::npos),
        e.Name << ": a file without pixel data gave [" << message << "]");
    }
    else
    {
      // No oracle: the reader reads it or says why not; it must not crash (reaching here).
      skipped.push_back(e.Name + " (pydicom: " + e.Status + (e.Note.empty() ? "" : ", " + e.Note) +
        "); our reader: " + (r.Ok ? "read it" : message));
      RGMC_CHECK(r.Ok || !message.empty(), e.Name << ": failed without a message");
      if (e.Name == "MR_truncated.dcm")
      {
        RGMC_CHECK(!r.Ok && message.find("is truncated") != std::string::npos &&
            message.find(e.Name) != std::string::npos,
          e.Name << ": expected a truncation error naming the file, got [" << message << "]");
      }
    }
  }
  // What real scanners and archives write after the last element, on real files in three
  // syntaxes: read, with the samples pydicom decodes from the file without them. And what is
  // really broken is still refused.
  struct Quirk
  {
    std::string Name;
    std::vector<unsigned char> Tail;
  };
  const std::vector<std::pair<std::string, std::string>> files = { { "CT_small.dcm", "explicit" },
    { "MR_small_implicit.dcm", "implicit" }, { "MR_small_bigendian.dcm", "big" } };
  for (const auto& file : files)
  {
    const std::string name = file.first, syntax = file.second;
    const std::vector<unsigned char> original = Bytes(std::string(RGMC_PYDICOM_DIR) + "/" + name);
    const std::vector<double> theirs = Samples(oracle + "/" + name + ".f64");
    // Data Set Trailing Padding (FFFC,FFFC), OB, 6 bytes, in the file's own syntax.
    std::vector<unsigned char> padding;
    if (syntax == "big")
    {
      padding = { 0xff, 0xfc, 0xff, 0xfc, 'O', 'B', 0, 0, 0, 0, 0, 6, 0, 0, 0, 0, 0, 0 };
    }
    else if (syntax == "explicit")
    {
      padding = { 0xfc, 0xff, 0xfc, 0xff, 'O', 'B', 0, 0, 6, 0, 0, 0, 0, 0, 0, 0, 0, 0 };
    }
    else
    {
      padding = { 0xfc, 0xff, 0xfc, 0xff, 6, 0, 0, 0, 0, 0, 0, 0, 0, 0 };
    }
    std::vector<unsigned char> junk(3001);
    std::uint32_t state = 20261123;
    for (unsigned char& c : junk)
    {
      state = state * 1664525u + 1013904223u;
      c = static_cast<unsigned char>(state >> 24);
    }
    const std::vector<Quirk> quirks = { { "2.5 MB of zero bytes after the pixel data",
                                          std::vector<unsigned char>(2500000, 0) },
      { "Data Set Trailing Padding (FFFC,FFFC)", padding },
      { "3001 bytes of junk after the pixel data", junk } };
    for (const Quirk& q : quirks)
    {
      std::vector<unsigned char> bytes = original;
      bytes.insert(bytes.end(), q.Tail.begin(), q.Tail.end());
      const std::string dir = work + "/quirk-" + std::to_string(&q - quirks.data()) + "-" + name;
      fs::create_directories(dir);
      Save(dir + "/" + name, bytes);
      vtkNew<vtkRGDICOMSeriesReader> reader;
      reader->SetController(controller);
      reader->SetFileName((dir + "/" + name).c_str());
      PieceRead r = ReadPiece(reader, 0, 1, 0);
      vtkIdType differ = -1;
      if (r.Ok)
      {
        vtkDataArray* ours = r.Image->GetPointData()->GetScalars();
        differ = ours->GetNumberOfValues() == static_cast<vtkIdType>(theirs.size()) ? 0 : -2;
        for (vtkIdType n = 0; differ >= 0 && n < static_cast<vtkIdType>(theirs.size()); ++n)
        {
          const double b =
            ours->GetDataType() == VTK_FLOAT ? static_cast<float>(theirs[n]) : theirs[n];
          differ += ours->GetComponent(n, 0) != b;
        }
      }
      RGMC_CHECK(r.Ok && differ == 0,
        name << " with " << q.Name << ": " << (r.Ok ? "" : ReaderMessage(r.Errors))
             << (r.Ok ? std::to_string(differ) + " samples differ from pydicom's" : ""));
      std::cout << "read as pydicom decodes the file without them: " << name << " with " << q.Name
                << "\n";
    }
  }
  {
    // Structures scanners write, in pydicom's MR_small.dcm rewritten by pydicom itself
    // (Testing/Python/Modules/dicom_quirks.py): a private sequence of undefined length with items
    // of undefined length and a nested undefined-length sequence; a private element of odd length.
    const std::string quirks = work + "/structures";
    RGMC_CHECK(Run(std::string(RGMC_SYSTEM_PYTHON) + " " + RGMC_TESTING_PYTHON_DIR +
                 "/dicom_quirks.py " + RGMC_PYDICOM_DIR + " " + quirks),
      "dicom_quirks.py failed");
    const std::vector<double> theirs = Samples(oracle + "/MR_small.dcm.f64");
    for (const std::string name : { "undefined-length.dcm", "odd-length.dcm" })
    {
      const std::string dir = quirks + "/" + name + ".d";
      fs::create_directories(dir);
      fs::copy_file(quirks + "/" + name, dir + "/" + name, fs::copy_options::overwrite_existing);
      vtkNew<vtkRGDICOMSeriesReader> reader;
      reader->SetController(controller);
      reader->SetFileName((dir + "/" + name).c_str());
      PieceRead r = ReadPiece(reader, 0, 1, 0);
      vtkIdType differ = -1;
      if (r.Ok &&
        r.Image->GetPointData()->GetScalars()->GetNumberOfValues() ==
          static_cast<vtkIdType>(theirs.size()))
      {
        differ = 0;
        for (vtkIdType n = 0; n < static_cast<vtkIdType>(theirs.size()); ++n)
        {
          differ += r.Image->GetPointData()->GetScalars()->GetComponent(n, 0) != theirs[n];
        }
      }
      RGMC_CHECK(r.Ok && differ == 0,
        "MR_small.dcm as " << name << ": "
                           << (r.Ok ? std::to_string(differ) + " samples differ from pydicom's"
                                    : ReaderMessage(r.Errors)));
      std::cout << "read as pydicom decodes the original: MR_small.dcm as " << name << "\n";
    }
  }
  {
    // No preamble, no "DICM", no file meta information: MR_small_implicit.dcm's bare data set
    // (implicit VR little endian), as older archives hold them.
    const std::string name = "MR_small_implicit.dcm";
    const std::vector<unsigned char> original = Bytes(std::string(RGMC_PYDICOM_DIR) + "/" + name);
    // (0002,0000) UL, explicit VR little endian, right after "DICM": the meta group's length.
    std::uint32_t metaLength = 0;
    std::memcpy(&metaLength, original.data() + 132 + 8, 4);
    const std::vector<unsigned char> bare(original.begin() + 132 + 12 + metaLength, original.end());
    const std::string dir = work + "/bare-" + name;
    fs::create_directories(dir);
    Save(dir + "/" + name, bare);
    vtkNew<vtkRGDICOMSeriesReader> reader;
    reader->SetController(controller);
    reader->SetFileName((dir + "/" + name).c_str());
    PieceRead r = ReadPiece(reader, 0, 1, 0);
    const std::vector<double> theirs = Samples(oracle + "/" + name + ".f64");
    vtkIdType differ = -1;
    if (r.Ok &&
      r.Image->GetPointData()->GetScalars()->GetNumberOfValues() ==
        static_cast<vtkIdType>(theirs.size()))
    {
      differ = 0;
      for (vtkIdType n = 0; n < static_cast<vtkIdType>(theirs.size()); ++n)
      {
        differ += r.Image->GetPointData()->GetScalars()->GetComponent(n, 0) != theirs[n];
      }
    }
    RGMC_CHECK(r.Ok && differ == 0,
      name << " as a bare data set: "
           << (r.Ok ? std::to_string(differ) + " samples differ" : ReaderMessage(r.Errors)));
    std::cout << "read as pydicom decodes the original: " << name
              << " without preamble and file meta information\n";
  }
  {
    // Really broken: an element's value representation overwritten before the pixel data.
    std::vector<unsigned char> bytes = Bytes(std::string(RGMC_PYDICOM_DIR) + "/CT_small.dcm");
    const std::string vr = "DA";
    auto at = std::search(bytes.begin() + 132, bytes.end(), vr.begin(), vr.end());
    RGMC_CHECK(at != bytes.end(), "CT_small.dcm has no DA element");
    if (at != bytes.end())
    {
      at[0] = 'Z';
      at[1] = 'Z';
      const std::string dir = work + "/broken-vr";
      fs::create_directories(dir);
      Save(dir + "/CT_small.dcm", bytes);
      vtkNew<vtkRGDICOMSeriesReader> reader;
      reader->SetController(controller);
      reader->SetFileName((dir + "/CT_small.dcm").c_str());
      PieceRead r = ReadPiece(reader, 0, 1, 0);
      const std::string message = ReaderMessage(r.Errors);
      RGMC_CHECK(!r.Ok &&
          message.find("is truncated or corrupt: an element has no valid value "
                       "representation at byte " +
            std::to_string(at - bytes.begin() - 4)) != std::string::npos,
        "a broken value representation before the pixel data gave [" << message << "]");
    }
  }

  std::cout << compared << " files decode exactly as pydicom decodes them, over " << syntaxes.size()
            << " transfer syntaxes:";
  for (const auto& s : syntaxes)
  {
    std::cout << " " << s.first << " (" << s.second << ")";
  }
  std::cout << "\nnot compared (no pydicom decoding):\n";
  for (const std::string& s : skipped)
  {
    std::cout << "  " << s << "\n";
  }
  RGMC_CHECK(compared >= 40, "only " << compared << " files compared");
  RGMC_CHECK(syntaxes.size() >= 8, "only " << syntaxes.size() << " transfer syntaxes compared");
  return Result("TestDICOMFiles");
}

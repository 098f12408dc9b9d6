// 64-bit extents, on 1 rank (vtkDummyController) and under mpiexec: a small piece at the far
// corner of a 4096^3 whole extent (more than 2^36 grid points; nothing of that size is
// allocated). Vertex keys there exceed 2^32; extraction, Seam Repair and the merged writer must
// give the surface that the same samples give as a volume of their own, with keys that decode to
// the edges the vertices lie on.
#include "rgmcCheck.h"
#include "rgmcGrid.h"
#include "rgmcTestController.h"
#include "rgmcTestData.h" // MakeImage, MarkGhostCells

#include "vtkCellArray.h"
#include "vtkDummyController.h"
#include "vtkFieldData.h"
#include "vtkIdTypeArray.h"
#include "vtkImageAlgorithm.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkObjectFactory.h"
#include "vtkPLYReader.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkRGMarchingCubes.h"
#include "vtkRGMergedSurfaceWriter.h"
#include "vtkRGSeamRepair.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <vector>

namespace
{

constexpr int Whole = 4096;          // points per axis of the whole extent
constexpr int CornerLo = Whole - 16; // the corner block: points CornerLo .. Whole - 1
const double Center = Whole - 8.5;   // a sphere of radius 5 in it

double Field(int i, int j, int k)
{
  const double x = i - Center, y = j - Center + 0.25, z = k - Center - 0.125;
  return std::sqrt(x * x + y * y + z * z) - 5.0;
}

/// A source that reports a 4096^3 whole extent but produces only this rank's part of the corner
/// block (split along z, with one ghost layer, its ghost cells marked), whatever it is asked for:
/// as a reader of a huge volume whose other parts hold nothing.
class CornerSource : public vtkImageAlgorithm
{
public:
  static CornerSource* New();
  vtkTypeMacro(CornerSource, vtkImageAlgorithm);
  int Rank = 0, Ranks = 1;

protected:
  CornerSource() { this->SetNumberOfInputPorts(0); }
  int RequestInformation(
    vtkInformation*, vtkInformationVector**, vtkInformationVector* out) override
  {
    const int whole[6] = { 0, Whole - 1, 0, Whole - 1, 0, Whole - 1 };
    out->GetInformationObject(0)->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole, 6);
    return 1;
  }
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector* out) override
  {
    vtkImageData* output = vtkImageData::GetData(out);
    const int cells = Whole - 1 - CornerLo;
    int owned[6] = { CornerLo, Whole - 1, CornerLo, Whole - 1, 0, 0 };
    owned[4] = CornerLo + cells * this->Rank / this->Ranks;
    owned[5] = CornerLo + cells * (this->Rank + 1) / this->Ranks;
    int ghosted[6];
    std::copy(owned, owned + 6, ghosted);
    ghosted[4] = std::max(CornerLo, owned[4] - 1);
    ghosted[5] = std::min(Whole - 1, owned[5] + 1);
    vtkSmartPointer<vtkImageData> piece = rgmc_test::MakeImage(ghosted, VTK_FLOAT, Field);
    if (this->Ranks > 1)
    {
      rgmc_test::MarkGhostCells(piece, owned);
    }
    output->ShallowCopy(piece);
    return 1;
  }
};
vtkStandardNewMacro(CornerSource);

using Triangle = std::array<float, 9>;

/// The triangles of a mesh as coordinate triples, each rotated to start at its smallest corner.
std::vector<Triangle> Triangles(vtkPolyData* pd)
{
  std::vector<Triangle> out;
  vtkIdType npts;
  const vtkIdType* pts;
  vtkCellArray* polys = pd->GetPolys();
  for (polys->InitTraversal(); polys->GetNextCell(npts, pts);)
  {
    std::array<std::array<float, 3>, 3> c;
    for (int v = 0; v < 3; ++v)
    {
      double x[3];
      pd->GetPoint(pts[v], x);
      c[v] = { static_cast<float>(x[0]), static_cast<float>(x[1]), static_cast<float>(x[2]) };
    }
    const int first = static_cast<int>(std::min_element(c.begin(), c.end()) - c.begin());
    Triangle t;
    for (int v = 0; v < 3; ++v)
    {
      std::copy(c[(first + v) % 3].begin(), c[(first + v) % 3].end(), t.begin() + 3 * v);
    }
    out.push_back(t);
  }
  std::sort(out.begin(), out.end());
  return out;
}

/// Every rank's triangles, on rank 0 (sorted; with multiplicity).
std::vector<Triangle> Gathered(vtkMultiProcessController* c, vtkPolyData* pd)
{
  const std::vector<Triangle> mine = Triangles(pd);
  const int ranks = c->GetNumberOfProcesses();
  vtkIdType length = static_cast<vtkIdType>(9 * mine.size());
  std::vector<vtkIdType> lengths(ranks), offsets(ranks + 1, 0);
  c->AllGather(&length, lengths.data(), 1);
  for (int r = 0; r < ranks; ++r)
  {
    offsets[r + 1] = offsets[r] + lengths[r];
  }
  std::vector<float> all(static_cast<std::size_t>(offsets[ranks]) + 1);
  c->GatherV(mine.empty() ? all.data() : mine.front().data(), all.data(), length, lengths.data(),
    offsets.data(), 0);
  std::vector<Triangle> out(static_cast<std::size_t>(offsets[ranks] / 9));
  for (std::size_t t = 0; t < out.size(); ++t)
  {
    std::copy(all.begin() + 9 * t, all.begin() + 9 * t + 9, out[t].begin());
  }
  std::sort(out.begin(), out.end());
  return out;
}

vtkIdType FieldValue(vtkPolyData* pd, const char* name)
{
  vtkIdTypeArray* a = vtkIdTypeArray::SafeDownCast(pd->GetFieldData()->GetArray(name));
  return a ? a->GetValue(0) : -1;
}

} // namespace

int main(int argc, char* argv[])
{
  vtkSmartPointer<vtkMultiProcessController> controller = rgmc_test::StartController(argc, argv);
  const int rank = controller->GetLocalProcessId(), ranks = controller->GetNumberOfProcesses();
  vtkNew<vtkDummyController> single;
  const double seed[3] = { Center + 5.0, Center, Center };

  // The oracle: the corner block's samples as a volume of their own, on 1 rank.
  const int block[6] = { CornerLo, Whole - 1, CornerLo, Whole - 1, CornerLo, Whole - 1 };
  vtkNew<vtkRGMarchingCubes> small;
  small->SetController(single);
  small->SetInputData(rgmc_test::MakeImage(block, VTK_FLOAT, Field));
  small->AddSeedPoint(seed[0], seed[1], seed[2]);
  small->Update();
  vtkNew<vtkRGSeamRepair> smallRepair;
  smallRepair->SetController(single);
  smallRepair->SetInputConnection(small->GetOutputPort());
  smallRepair->SetSmoothingMethod(vtkRGSeamRepair::NO_SMOOTHING);
  smallRepair->Update();
  const std::vector<Triangle> expected = Triangles(small->GetOutput());
  RGMC_CHECK(expected.size() > 100, "the oracle has " << expected.size() << " triangles");

  // The same samples at the far corner of 4096^3, on this run's ranks.
  vtkNew<CornerSource> source;
  source->Rank = rank;
  source->Ranks = ranks;
  for (int mode : { vtkRGMarchingCubes::SEEDED, vtkRGMarchingCubes::ALL_COMPONENTS })
  {
    const char* name = mode == vtkRGMarchingCubes::SEEDED ? "seeded" : "all components";
    vtkNew<vtkRGMarchingCubes> extract;
    extract->SetController(controller);
    extract->SetInputConnection(source->GetOutputPort());
    extract->SetExtractionMode(mode);
    extract->AddSeedPoint(seed[0], seed[1], seed[2]);
    rgmc_test::UpdateAtThreads(extract, name);
    vtkPolyData* surface = extract->GetOutput();
    const std::vector<Triangle> got = Gathered(controller, surface);
    if (rank == 0)
    {
      RGMC_CHECK(got == expected,
        name << ": " << got.size() << " triangles at the far corner, " << expected.size()
             << " in a volume of their own, or they differ");
    }

    // Keys beyond 32 bits that decode to the edge (or grid point) the vertex lies on.
    const int whole[6] = { 0, Whole - 1, 0, Whole - 1, 0, Whole - 1 };
    const rgmc::Grid grid(whole, whole);
    vtkIdTypeArray* keys = vtkIdTypeArray::SafeDownCast(surface->GetPointData()->GetGlobalIds());
    RGMC_CHECK(keys || surface->GetNumberOfPoints() == 0, name << ": no vertex keys");
    vtkIdType wrong = 0, small32 = 0;
    for (vtkIdType p = 0; keys && p < surface->GetNumberOfPoints(); ++p)
    {
      const vtkIdType key = keys->GetValue(p);
      small32 += key < (vtkIdType(1) << 32);
      int g[3], axis;
      grid.Decode(key, g, axis);
      double x[3];
      surface->GetPoint(p, x);
      for (int a = 0; a < 3; ++a)
      {
        wrong += a == axis ? !(x[a] >= g[a] && x[a] <= g[a] + 1) : x[a] != g[a];
      }
    }
    RGMC_CHECK(
      small32 == 0, name << ": " << small32 << " vertex keys below 2^32 at the far corner");
    RGMC_CHECK(wrong == 0, name << ": " << wrong << " coordinates off the edge their key names");

    // Seam Repair: the same vertices; one closed surface; global ids 0..N-1.
    vtkNew<vtkRGSeamRepair> repair;
    repair->SetController(controller);
    repair->SetInputConnection(extract->GetOutputPort());
    repair->SetSmoothingMethod(vtkRGSeamRepair::NO_SMOOTHING);
    rgmc_test::UpdateAtThreads(repair, name);
    vtkPolyData* repaired = repair->GetOutput();
    const vtkIdType unique = FieldValue(repaired, "UniquePoints");
    RGMC_CHECK(unique == FieldValue(smallRepair->GetOutput(), "UniquePoints") &&
        FieldValue(repaired, "Closed") == 1,
      name << ": " << unique << " unique points ("
           << FieldValue(smallRepair->GetOutput(), "UniquePoints") << " expected), closed "
           << FieldValue(repaired, "Closed"));
    vtkIdTypeArray* gids = vtkIdTypeArray::SafeDownCast(repaired->GetPointData()->GetGlobalIds());
    vtkIdType outOfRange = 0;
    for (vtkIdType p = 0; gids && p < gids->GetNumberOfValues(); ++p)
    {
      outOfRange += gids->GetValue(p) < 0 || gids->GetValue(p) >= unique;
    }
    RGMC_CHECK(gids && outOfRange == 0,
      name << ": " << outOfRange << " global ids out of 0.." << unique - 1);

    // The merged writer: one PLY read back by VTK's reader.
    const std::string file = "TestFarCorner-" + std::to_string(ranks) + ".ply";
    vtkNew<vtkRGMergedSurfaceWriter> writer;
    writer->SetController(controller);
    writer->SetInputConnection(repair->GetOutputPort());
    writer->SetFileName(file.c_str());
    RGMC_CHECK(writer->Write() == 1, name << ": the writer failed");
    controller->Barrier();
    if (rank == 0)
    {
      vtkNew<vtkPLYReader> reader;
      reader->SetFileName(file.c_str());
      reader->Update();
      RGMC_CHECK(reader->GetOutput()->GetNumberOfPoints() == unique &&
          Triangles(reader->GetOutput()) == expected,
        name << ": the PLY file has " << reader->GetOutput()->GetNumberOfPoints()
             << " vertices and " << reader->GetOutput()->GetNumberOfPolys()
             << " triangles, or other triangles");
      ::unlink(file.c_str());
    }
    if (rank == 0)
    {
      std::cout << name << ": " << got.size() << " triangles, " << unique
                << " vertices at the far corner of " << Whole << "^3\n";
    }
  }
  return rgmc_test::Finish(controller, "TestFarCorner");
}

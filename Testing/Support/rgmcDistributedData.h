// Decompositions of a volume over ranks, as the pipeline and readers make them, for the
// distributed tests; and running vtkRGMarchingCubes on one rank's piece.
#ifndef rgmcDistributedData_h
#define rgmcDistributedData_h

#include "rgmcTestData.h"
#include "rgmcThreadCompare.h"

#include "vtkExtentTranslator.h"
#include "vtkFieldData.h"
#include "vtkIdTypeArray.h"
#include "vtkIntArray.h"
#include "vtkMultiProcessController.h"
#include "vtkRGMarchingCubes.h"
#include "vtkRGPhantomSource.h"

namespace rgmc_test
{

using Seeds = std::vector<std::array<double, 3>>;
/// Samples of a field over a point extent (with the field's spacing and origin).
using FieldMaker = std::function<vtkSmartPointer<vtkImageData>(const int extent[6])>;

/// What one rank holds in a decomposition: its owned points (empty box for none), whether it
/// gets a ghost layer (as the pipeline gives) or not (a reader that ignores requests), and the
/// points its ghost array marks as owned (normally Owned; "mismarked" marks another split's).
struct Piece
{
  int Owned[6] = { 0, -1, 0, -1, 0, -1 };
  int Marked[6] = { 0, -1, 0, -1, 0, -1 };
  bool Ghosts = true;
  bool Empty() const { return this->Owned[1] < this->Owned[0]; }
};

inline std::vector<std::string> Decompositions(int ranks)
{
  if (ranks == 1)
  {
    return { "block" };
  }
  return { "block", "slab-x", "slab-y", "slab-z", "rank0", "empty-rank", "overlap", "mismarked" };
}

/// This rank's block of `whole` as ParaView splits images: its owned point extent, and the same
/// with the one ghost layer the pipeline gives vtkRGMarchingCubes.
inline void BlockPiece(const int whole[6], int rank, int ranks, int owned[6], int ghosted[6])
{
  vtkNew<vtkExtentTranslator> split;
  split->PieceToExtentThreadSafe(
    rank, ranks, 0, const_cast<int*>(whole), owned, vtkExtentTranslator::BLOCK_MODE, 0);
  split->PieceToExtentThreadSafe(
    rank, ranks, 1, const_cast<int*>(whole), ghosted, vtkExtentTranslator::BLOCK_MODE, 0);
}

/// This rank's block (with its ghost layer, ghost cells marked) of a `size`^3 float gyroid,
/// sin x cos y + sin y cos z + sin z cos x = 0 with `period` samples per cell: one connected
/// surface through the whole volume that crosses every partition plane many times.
inline vtkSmartPointer<vtkImageData> GyroidPiece(int size, double period, int rank, int ranks)
{
  const int whole[6] = { 0, size - 1, 0, size - 1, 0, size - 1 };
  int owned[6], ghosted[6];
  BlockPiece(whole, rank, ranks, owned, ghosted);
  const double w = 2.0 * M_PI / period;
  vtkSmartPointer<vtkImageData> piece = MakeImage(ghosted, VTK_FLOAT,
    [w](int i, int j, int k)
    {
      const double x = w * (i + 0.25), y = w * (j + 0.5), z = w * (k + 0.125);
      return std::sin(x) * std::cos(y) + std::sin(y) * std::cos(z) + std::sin(z) * std::cos(x);
    });
  if (ranks > 1)
  {
    MarkGhostCells(piece, owned);
  }
  return piece;
}

/// This rank's piece of `whole` (a point extent with the same number of cells on each axis).
inline Piece PieceOf(const std::string& how, const int whole[6], int rank, int ranks)
{
  const int cells = whole[1] - whole[0];
  Piece p;
  auto block = [&](int piece, int pieces)
  {
    int ghosted[6];
    BlockPiece(whole, piece, pieces, p.Owned, ghosted);
  };
  if (how == "block")
  {
    block(rank, ranks);
  }
  else if (how.rfind("slab-", 0) == 0)
  {
    const int axis = how[5] - 'x';
    std::copy(whole, whole + 6, p.Owned);
    p.Owned[2 * axis] = whole[2 * axis] + cells * rank / ranks;
    p.Owned[2 * axis + 1] = whole[2 * axis] + cells * (rank + 1) / ranks;
  }
  else if (how == "rank0")
  {
    if (rank == 0)
    {
      std::copy(whole, whole + 6, p.Owned);
    }
    p.Ghosts = false;
  }
  else if (how == "empty-rank")
  {
    const int empty = ranks / 2;
    if (rank != empty)
    {
      block(rank < empty ? rank : rank - 1, ranks - 1);
    }
  }
  else if (how == "overlap")
  {
    std::copy(whole, whole + 6, p.Owned);
    p.Ghosts = false;
  }
  else if (how == "mismarked")
  {
    // Slabs along z whose ghost arrays mark the cells of slabs along x as owned, as VTK 9.2's
    // executive marks them when a reader splits in slabs while the executive assumes blocks.
    Piece z = PieceOf("slab-z", whole, rank, ranks), x = PieceOf("slab-x", whole, rank, ranks);
    std::copy(z.Owned, z.Owned + 6, p.Owned);
    std::copy(x.Owned, x.Owned + 6, p.Marked);
    return p;
  }
  std::copy(p.Owned, p.Owned + 6, p.Marked);
  return p;
}

inline vtkSmartPointer<vtkImageData> MakePiece(
  const FieldMaker& make, const int whole[6], const Piece& piece)
{
  if (piece.Empty())
  {
    return vtkSmartPointer<vtkImageData>::New();
  }
  int extent[6];
  WithGhostLayers(piece.Owned, whole, piece.Ghosts ? 1 : 0, extent);
  vtkSmartPointer<vtkImageData> image = make(extent);
  if (piece.Ghosts)
  {
    MarkGhostCells(image, piece.Marked);
  }
  return image;
}

struct Run
{
  vtkSmartPointer<vtkPolyData> Output;
  std::string Errors, Warnings;
  /// The filter's own counts of the run on this rank (see vtkRGMarchingCubes).
  int Rounds = 0;
  bool OneStep = false;
  long long Collectives = 0, Messages = 0, CubesExamined = 0, FacePointsRead = 0, TrianglesMade = 0;
};

inline Run Extract(vtkMultiProcessController* controller, vtkImageData* image, double isovalue,
  int mode, const Seeds& seeds, const std::function<void(vtkRGMarchingCubes*)>& tweak = nullptr)
{
  vtkNew<vtkRGMarchingCubes> rg;
  vtkNew<MessageCatcher> catcher;
  catcher->Watch(rg);
  rg->SetController(controller);
  rg->SetInputData(image);
  rg->SetIsovalue(isovalue);
  rg->SetExtractionMode(mode);
  for (const auto& s : seeds)
  {
    rg->AddSeedPoint(s[0], s[1], s[2]);
  }
  if (tweak)
  {
    tweak(rg);
  }
  UpdateAtThreads(rg, "extraction",
    [&catcher]()
    {
      catcher->Errors.clear();
      catcher->Warnings.clear();
    });
  Run r;
  r.Output = vtkSmartPointer<vtkPolyData>::New();
  r.Output->ShallowCopy(rg->GetOutput());
  r.Errors = catcher->Errors;
  r.Warnings = catcher->Warnings;
  r.Rounds = rg->GetNumberOfGrowthRounds();
  r.OneStep = rg->GetGrewInOneStep();
  r.Collectives = rg->GetNumberOfCollectives();
  r.Messages = rg->GetNumberOfMessages();
  r.CubesExamined = rg->GetNumberOfCubesExamined();
  r.FacePointsRead = rg->GetNumberOfFacePointsRead();
  r.TrianglesMade = rg->GetNumberOfTrianglesMade();
  return r;
}

/// The CT phantom sampled on `points`^3 points, over `extent` only (as a pipeline piece, without
/// the source's ghost marks).
inline vtkSmartPointer<vtkImageData> PhantomPiece(const int extent[6], int points)
{
  vtkNew<vtkRGPhantomSource> phantom;
  phantom->SetDimensions(points, points, points);
  phantom->UpdateExtent(const_cast<int*>(extent));
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->DeepCopy(phantom->GetOutput());
  image->GetCellData()->RemoveArray(vtkDataSetAttributes::GhostArrayName());
  return image;
}

/// A surface by vertex keys: triangles (sorted key triples) with their ComponentId, and each
/// key's coordinates and normal as bits.
struct Snapshot
{
  std::map<std::array<long long, 3>, int> Triangles;
  std::map<long long, std::array<std::uint32_t, 6>> Vertices;
  long long DuplicatedTriangles = 0;
  long long InconsistentVertices = 0;
  long long WrongRankIds = 0;

  void Add(vtkPolyData* pd, int rank)
  {
    vtkIdTypeArray* keys = vtkIdTypeArray::SafeDownCast(pd->GetPointData()->GetGlobalIds());
    vtkIntArray* comps = vtkIntArray::SafeDownCast(pd->GetCellData()->GetArray("ComponentId"));
    vtkIntArray* ranks = vtkIntArray::SafeDownCast(pd->GetCellData()->GetArray("RankId"));
    vtkDataArray* normals = pd->GetPointData()->GetNormals();
    if (pd->GetNumberOfPoints() == 0)
    {
      return;
    }
    for (vtkIdType p = 0; p < pd->GetNumberOfPoints(); ++p)
    {
      float x[3], n[3];
      double xd[3], nd[3];
      pd->GetPoint(p, xd);
      normals->GetTuple(p, nd);
      std::array<std::uint32_t, 6> bits;
      for (int a = 0; a < 3; ++a)
      {
        x[a] = static_cast<float>(xd[a]);
        n[a] = static_cast<float>(nd[a]);
        std::memcpy(&bits[a], &x[a], 4);
        std::memcpy(&bits[3 + a], &n[a], 4);
      }
      auto inserted = this->Vertices.emplace(keys->GetValue(p), bits);
      if (!inserted.second && inserted.first->second != bits)
      {
        ++this->InconsistentVertices;
      }
    }
    for (vtkIdType t = 0; t < pd->GetNumberOfCells(); ++t)
    {
      vtkIdType npts;
      const vtkIdType* pts;
      pd->GetCellPoints(t, npts, pts);
      std::array<long long, 3> tri = { keys->GetValue(pts[0]), keys->GetValue(pts[1]),
        keys->GetValue(pts[2]) };
      std::sort(tri.begin(), tri.end());
      if (!this->Triangles.emplace(tri, comps->GetValue(t)).second)
      {
        ++this->DuplicatedTriangles;
      }
      this->WrongRankIds += ranks->GetValue(t) != rank;
    }
  }
};

/// Gathers the pieces on rank 0 and compares their union with the reference.
inline void CompareUnion(vtkMultiProcessController* controller, vtkPolyData* piece,
  const Snapshot* reference, const std::string& what)
{
  std::vector<vtkSmartPointer<vtkDataObject>> pieces;
  controller->Gather(piece, pieces, 0);
  if (controller->GetLocalProcessId() == 0)
  {
    Snapshot united;
    for (std::size_t r = 0; r < pieces.size(); ++r)
    {
      united.Add(vtkPolyData::SafeDownCast(pieces[r]), static_cast<int>(r));
    }
    const bool same =
      united.Triangles == reference->Triangles && united.Vertices == reference->Vertices;
    RGMC_CHECK(same,
      what << ": the union differs from 1 rank: " << united.Triangles.size() << " vs "
           << reference->Triangles.size() << " triangles, " << united.Vertices.size() << " vs "
           << reference->Vertices.size() << " vertices");
    RGMC_CHECK(united.DuplicatedTriangles == 0,
      what << ": " << united.DuplicatedTriangles << " triangles on two ranks");
    RGMC_CHECK(united.InconsistentVertices == 0,
      what << ": " << united.InconsistentVertices << " vertices differ between ranks");
    RGMC_CHECK(united.WrongRankIds == 0, what << ": RankId is not the rank that made the triangle");
  }
  // Every rank reports the same global counts.
  vtkFieldData* fd = piece->GetFieldData();
  long long triangles = fd->GetArray("NumberOfTriangles")
    ? vtkIdTypeArray::SafeDownCast(fd->GetArray("NumberOfTriangles"))->GetValue(0)
    : -1;
  long long lo = 0, hi = 0;
  controller->AllReduce(&triangles, &lo, 1, vtkCommunicator::MIN_OP);
  controller->AllReduce(&triangles, &hi, 1, vtkCommunicator::MAX_OP);
  RGMC_CHECK(lo == hi, what << ": ranks disagree on NumberOfTriangles");
}

/// True when `text` is the same on every rank.
inline bool SameOnAllRanks(vtkMultiProcessController* controller, const std::string& text)
{
  long long h = static_cast<long long>(std::hash<std::string>()(text) >> 1), lo = 0, hi = 0;
  controller->AllReduce(&h, &lo, 1, vtkCommunicator::MIN_OP);
  controller->AllReduce(&h, &hi, 1, vtkCommunicator::MAX_OP);
  return lo == hi;
}

} // namespace rgmc_test

#endif

// vtkRGDecimate: quadric-error decimation in independent blocks, distributed over the ranks by a
// grid that depends on the surface alone (see the header for the scheme).
#include "vtkRGDecimate.h"
#include "rgmcDecimation.h"
#include "rgmcRadixSort.h"
#include "vtkRGArrays.h"
#include "vtkRGCollective.h"
#include "vtkRGCompatibility.h"
#include "vtkRGMessage.h"
#include "vtkRGParallel.h"
#include "vtkRGRunController.h"
#include "vtkRGSeamRepair.h"

#include "vtkAOSDataArrayTemplate.h"
#include "vtkCellArray.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkExecutive.h"
#include "vtkFieldData.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkLogger.h"
#include "vtkMath.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#if defined(__GLIBC__)
#include <malloc.h> // malloc_trim
#endif

vtkStandardNewMacro(vtkRGDecimate);
vtkCxxSetObjectMacro(vtkRGDecimate, Controller, vtkMultiProcessController);

namespace
{

using rgmc::Ranks;
using Triangle = std::array<vtkIdType, 3>;

// Message tags of the passes' exchanges.
enum Tags
{
  TrianglesTag = 7401,
  SharedTag = 7402,
  AnswersTag = 7403,
  HaloTag = 7404
};

constexpr int MaximumBlocksPerAxis = 32;
// The grid's offsets, in blocks, in the passes: each pass frees what the ones before left fixed.
constexpr double PassOffsets[] = { 0.0, 0.5, 0.25, 0.75, 0.125, 0.625, 0.375, 0.875 };
constexpr int Passes = 16;
// From this pass on, each makes all the collapses still needed that it can, not only its free
// vertices' share: with small blocks (most vertices near a face) the shares shrink slowly.
constexpr int AllFromPass = 5;

/// Returns the heap's free pages to the system where the C library can (glibc's malloc_trim).
void ReleaseFreeMemory()
{
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
}

/// A global id as a radix-sort key, in the ids' signed order.
std::uint64_t KeyOf(vtkIdType id)
{
  return static_cast<std::uint64_t>(id) ^ (std::uint64_t(1) << 63);
}

/// Sorted distinct ids.
template <typename Id>
void SortDistinct(std::vector<Id>& ids)
{
  rgmc::RadixSort(ids, [](Id id) { return KeyOf(static_cast<vtkIdType>(id)); });
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
}

/// A vertex's global id and position.
struct Vertex
{
  vtkIdType Id;
  double Point[3];
};

/// Vertices as they travel between passes: ids and positions and, from the second pass on, their
/// quadrics, kept apart (before the first pass has summed them there are none to carry, and the
/// records are then a quarter of the size).
class VertexTable
{
public:
  std::vector<Vertex> Vertices; // by increasing id once sorted
  std::vector<rgmc::Quadric> Quadrics;
  bool HasQuadrics = false;

  std::size_t Words() const { return this->HasQuadrics ? 14 : 4; }

  /// Message words of vertex `i`: id and position, then the quadric's 10 terms.
  void Write(std::size_t i, std::vector<vtkIdType>& words) const
  {
    const Vertex& v = this->Vertices[i];
    words.push_back(v.Id);
    for (double x : v.Point)
    {
      words.push_back(rgmc::WordOf(x));
    }
    for (std::size_t k = 0; this->HasQuadrics && k < 10; ++k)
    {
      words.push_back(rgmc::WordOf(this->Quadrics[i].Terms[k]));
    }
  }

  void Read(const vtkIdType* words)
  {
    Vertex v;
    v.Id = words[0];
    for (int k = 0; k < 3; ++k)
    {
      v.Point[k] = rgmc::RealOf(words[1 + k]);
    }
    this->Vertices.push_back(v);
    if (this->HasQuadrics)
    {
      rgmc::Quadric q;
      for (int k = 0; k < 10; ++k)
      {
        q.Terms[k] = rgmc::RealOf(words[4 + k]);
      }
      this->Quadrics.push_back(q);
    }
  }

  void Reserve(std::size_t n)
  {
    this->Vertices.reserve(n);
    this->Quadrics.reserve(this->HasQuadrics ? n : 0);
  }

  void Add(const Vertex& v, const rgmc::Quadric* q)
  {
    this->Vertices.push_back(v);
    if (this->HasQuadrics)
    {
      this->Quadrics.push_back(*q);
    }
  }

  /// The place of vertex `id`, or -1.
  std::ptrdiff_t Find(vtkIdType id) const
  {
    auto at = std::lower_bound(this->Vertices.begin(), this->Vertices.end(), id,
      [](const Vertex& v, vtkIdType key) { return v.Id < key; });
    return at != this->Vertices.end() && at->Id == id ? at - this->Vertices.begin() : -1;
  }

  /// Sorts by id and keeps one of each (copies of a vertex are equal: decimation never
  /// touches a vertex that more than one block has). In place: the records are not held twice.
  void SortUnique()
  {
    const std::size_t n = this->Vertices.size();
    std::vector<std::pair<vtkIdType, std::size_t>> order(n);
    for (std::size_t i = 0; i < n; ++i)
    {
      order[i] = { this->Vertices[i].Id, i };
    }
    rgmc::RadixSort(
      order, [](const std::pair<vtkIdType, std::size_t>& p) { return KeyOf(p.first); });
    // Record i becomes record order[i].second: each cycle of the permutation walked once, its
    // places marked done by pointing them at themselves.
    for (std::size_t i = 0; i < n; ++i)
    {
      if (order[i].second == i)
      {
        continue;
      }
      const Vertex vertex = this->Vertices[i];
      const rgmc::Quadric quadric = this->HasQuadrics ? this->Quadrics[i] : rgmc::Quadric();
      std::size_t at = i;
      while (order[at].second != i)
      {
        const std::size_t from = order[at].second;
        this->Vertices[at] = this->Vertices[from];
        if (this->HasQuadrics)
        {
          this->Quadrics[at] = this->Quadrics[from];
        }
        order[at].second = at;
        at = from;
      }
      this->Vertices[at] = vertex;
      if (this->HasQuadrics)
      {
        this->Quadrics[at] = quadric;
      }
      order[at].second = at;
    }
    std::vector<std::pair<vtkIdType, std::size_t>>().swap(order);
    std::size_t kept = 0;
    for (std::size_t i = 0; i < n; ++i)
    {
      if (kept == 0 || this->Vertices[i].Id != this->Vertices[kept - 1].Id)
      {
        this->Vertices[kept] = this->Vertices[i];
        if (this->HasQuadrics)
        {
          this->Quadrics[kept] = this->Quadrics[i];
        }
        ++kept;
      }
    }
    this->Vertices.resize(kept);
    this->Quadrics.resize(this->HasQuadrics ? kept : 0);
  }

  void Clear()
  {
    std::vector<Vertex>().swap(this->Vertices);
    std::vector<rgmc::Quadric>().swap(this->Quadrics);
  }
};

/// The blocks: cubes of edge Size from Origin, shifted by Offset blocks.
struct Grid
{
  double Origin[3] = { 0, 0, 0 };
  double Size = 1;
  int Dims[3] = { 1, 1, 1 };
  double Offset = 0;

  vtkIdType Count() const { return vtkIdType(this->Dims[0]) * this->Dims[1] * this->Dims[2]; }
  vtkIdType BlockOf(const double p[3]) const
  {
    vtkIdType index[3];
    for (int a = 0; a < 3; ++a)
    {
      const double x = std::floor((p[a] - this->Origin[a]) / this->Size + this->Offset);
      index[a] = static_cast<vtkIdType>(std::min<double>(std::max(x, 0.0), this->Dims[a] - 1));
    }
    return index[0] + this->Dims[0] * (index[1] + vtkIdType(this->Dims[1]) * index[2]);
  }
};

/// This rank's part of the surface at the start of a pass: its triangles as indices of its
/// vertices, and the vertices' global ids, positions and (after the first pass) quadrics. The
/// first pass reads the input where it is (its connectivity, global ids and points): a copy
/// would hold the whole surface twice while the blocks are made. The input may hold copies of a
/// vertex (the same id and position at several points); the blocks see each id once.
class SurfacePart
{
public:
  /// The input's triangles (every cell is one: CheckInput) and points, in place.
  void Read(vtkPolyData* input)
  {
    this->Clear();
    this->Input = input;
    vtkCellArray* polys = input->GetPolys();
    this->InputTriangles = static_cast<std::size_t>(polys->GetNumberOfCells());
    vtkDataArray* connectivity = polys->GetConnectivityArray();
    if (auto* ids = vtkAOSDataArrayTemplate<vtkIdType>::FastDownCast(connectivity))
    {
      this->Corner64 = ids->GetPointer(0);
    }
    else if (auto* ids32 = vtkAOSDataArrayTemplate<std::int32_t>::FastDownCast(connectivity))
    {
      this->Corner32 = ids32->GetPointer(0);
    }
    else
    {
      this->CornerCopy.reserve(3 * this->InputTriangles);
      vtkIdType npts;
      const vtkIdType* pts;
      for (polys->InitTraversal(); polys->GetNextCell(npts, pts);)
      {
        this->CornerCopy.insert(this->CornerCopy.end(), pts, pts + 3);
      }
      this->Corner64 = this->CornerCopy.data();
    }
    // No global ids only where there are no points (CheckInput).
    auto* ids = vtkIdTypeArray::SafeDownCast(input->GetPointData()->GetGlobalIds());
    this->GlobalIds = ids ? ids->GetPointer(0) : nullptr;
    vtkDataArray* points = input->GetPoints() ? input->GetPoints()->GetData() : nullptr;
    if (auto* d = vtkAOSDataArrayTemplate<double>::FastDownCast(points))
    {
      this->PointsDouble = d->GetPointer(0);
    }
    else if (auto* f = vtkAOSDataArrayTemplate<float>::FastDownCast(points))
    {
      this->PointsFloat = f->GetPointer(0);
    }
  }

  /// Takes the triangles (by global ids) and their vertices' records as the part's own: the
  /// records sorted by id with copies merged, the triangles turned into indices of them.
  void Adopt(std::vector<Triangle>& byId, VertexTable& vertices)
  {
    this->Clear();
    std::swap(this->Vertices, vertices);
    this->Vertices.SortUnique();
    if (this->Vertices.Vertices.size() > static_cast<std::size_t>(VTK_INT_MAX))
    {
      throw std::runtime_error("a rank's part of the surface has more than 2^31 vertices");
    }
    this->Triangles.resize(byId.size());
    for (std::size_t t = 0; t < byId.size(); ++t)
    {
      for (int k = 0; k < 3; ++k)
      {
        this->Triangles[t][k] = static_cast<std::int32_t>(this->Vertices.Find(byId[t][k]));
      }
    }
    std::vector<Triangle>().swap(byId);
  }

  /// Makes an input part the part's own (as Adopt would have it).
  void OwnInput()
  {
    if (!this->Input)
    {
      return;
    }
    std::vector<Triangle> byId(this->NumberOfTriangles());
    VertexTable vertices;
    std::vector<char> used(this->NumberOfVertices(), 0);
    for (std::size_t t = 0; t < byId.size(); ++t)
    {
      vtkIdType c[3];
      this->Corners(t, c);
      for (int k = 0; k < 3; ++k)
      {
        byId[t][k] = this->Id(c[k]);
        used[c[k]] = 1;
      }
    }
    for (std::size_t v = 0; v < used.size(); ++v)
    {
      if (used[v])
      {
        Vertex record;
        record.Id = this->Id(static_cast<vtkIdType>(v));
        this->Point(static_cast<vtkIdType>(v), record.Point);
        vertices.Add(record, nullptr);
      }
    }
    this->Adopt(byId, vertices);
  }

  std::size_t NumberOfTriangles() const
  {
    return this->Input ? this->InputTriangles : this->Triangles.size();
  }
  std::size_t NumberOfVertices() const
  {
    return this->Input ? static_cast<std::size_t>(this->Input->GetNumberOfPoints())
                       : this->Vertices.Vertices.size();
  }
  bool HasQuadrics() const { return !this->Input && this->Vertices.HasQuadrics; }

  /// The vertices of triangle `t`, as indices of the part's vertices.
  void Corners(std::size_t t, vtkIdType c[3]) const
  {
    for (std::size_t k = 0; k < 3; ++k)
    {
      c[k] = !this->Input ? static_cast<vtkIdType>(this->Triangles[t][k])
        : this->Corner64  ? this->Corner64[3 * t + k]
                          : static_cast<vtkIdType>(this->Corner32[3 * t + k]);
    }
  }
  vtkIdType Id(vtkIdType v) const
  {
    return this->Input ? this->GlobalIds[v] : this->Vertices.Vertices[v].Id;
  }
  void Point(vtkIdType v, double p[3]) const
  {
    if (!this->Input)
    {
      std::copy(this->Vertices.Vertices[v].Point, this->Vertices.Vertices[v].Point + 3, p);
    }
    else if (this->PointsDouble)
    {
      std::copy(this->PointsDouble + 3 * v, this->PointsDouble + 3 * v + 3, p);
    }
    else if (this->PointsFloat)
    {
      std::copy(this->PointsFloat + 3 * v, this->PointsFloat + 3 * v + 3, p);
    }
    else
    {
      this->Input->GetPoint(v, p);
    }
  }
  /// How many message words Write gives a vertex.
  std::size_t WordsPerVertex() const { return this->HasQuadrics() ? 14 : 4; }
  /// Message words of vertex `v`: id and position, then its quadric's 10 terms if it has one.
  void Write(vtkIdType v, std::vector<vtkIdType>& words) const
  {
    if (!this->Input)
    {
      this->Vertices.Write(static_cast<std::size_t>(v), words);
      return;
    }
    double p[3];
    this->Point(v, p);
    words.push_back(this->Id(v));
    for (double x : p)
    {
      words.push_back(rgmc::WordOf(x));
    }
  }

  void Clear()
  {
    this->Input = nullptr;
    this->Corner64 = nullptr;
    this->Corner32 = nullptr;
    std::vector<vtkIdType>().swap(this->CornerCopy);
    this->PointsDouble = nullptr;
    this->PointsFloat = nullptr;
    std::vector<std::array<std::int32_t, 3>>().swap(this->Triangles);
    this->Vertices.Clear();
  }

  std::vector<std::array<std::int32_t, 3>> Triangles; // the part's own: indices of Vertices
  VertexTable Vertices;                               // the part's own: by increasing id

private:
  vtkPolyData* Input = nullptr; // the first pass: the input, in place
  std::size_t InputTriangles = 0;
  const vtkIdType* Corner64 = nullptr;
  const std::int32_t* Corner32 = nullptr;
  std::vector<vtkIdType> CornerCopy; // when the input's connectivity is of another type
  const vtkIdType* GlobalIds = nullptr;
  const double* PointsDouble = nullptr;
  const float* PointsFloat = nullptr;
};

/// One block on its rank during a pass.
struct Block
{
  vtkIdType Id;
  int Wave = 0;
  std::vector<Triangle> Own, Halo; // by global ids, as they came
  rgmc::DecimationBlock Mesh;
  std::vector<rgmc::Collapse> Log;
  std::vector<double> Levels; // of the collapses in Log (non-decreasing)
  std::size_t Vertices = 0;   // of its own triangles
  std::size_t Fixed = 0;      // of those, the ones it shares with other blocks
  std::size_t Keep = 0;
};

std::vector<bool> Everyone(int size)
{
  return std::vector<bool>(static_cast<std::size_t>(size), true);
}

/// A triangle of this rank's part going to a block: (block, triangle, 1 if to its halo).
using Sending = std::array<vtkIdType, 3>;

/// A message of triangles for blocks: the counts of own and halo triangles, (block, three
/// vertex ids) for each (the own ones first), then the records of their vertices, each once, by
/// increasing id.
void WriteTriangles(
  std::vector<vtkIdType>& words, std::vector<Sending>& going, const SurfacePart& part)
{
  std::stable_partition(going.begin(), going.end(), [](const Sending& s) { return s[2] == 0; });
  const auto halos =
    std::count_if(going.begin(), going.end(), [](const Sending& s) { return s[2]; });
  // The corners' vertices, by id (each written once), first: the message's size is then known.
  std::vector<std::pair<vtkIdType, vtkIdType>> vertices; // (id, index in the part)
  vertices.reserve(3 * going.size());
  for (const Sending& s : going)
  {
    vtkIdType c[3];
    part.Corners(static_cast<std::size_t>(s[1]), c);
    for (vtkIdType v : c)
    {
      vertices.emplace_back(part.Id(v), v);
    }
  }
  rgmc::RadixSort(
    vertices, [](const std::pair<vtkIdType, vtkIdType>& p) { return KeyOf(p.first); });
  std::size_t distinct = 0;
  for (std::size_t i = 0; i < vertices.size(); ++i)
  {
    distinct += i == 0 || vertices[i].first != vertices[i - 1].first;
  }
  words.reserve(words.size() + 2 + 4 * going.size() + part.WordsPerVertex() * distinct);
  words.push_back(static_cast<vtkIdType>(going.size()) - halos);
  words.push_back(halos);
  for (const Sending& s : going)
  {
    vtkIdType c[3];
    part.Corners(static_cast<std::size_t>(s[1]), c);
    words.push_back(s[0]);
    for (vtkIdType v : c)
    {
      words.push_back(part.Id(v));
    }
  }
  for (std::size_t i = 0; i < vertices.size(); ++i)
  {
    if (i == 0 || vertices[i].first != vertices[i - 1].first)
    {
      part.Write(vertices[i].second, words);
    }
  }
}

/// Reads what WriteTriangles wrote: each triangle into its block's own or halo list
/// (`blockWithId`; a block this rank does not own is an error), the vertex records into `table`.
template <typename BlockWithId>
void ReadTriangles(
  const std::vector<vtkIdType>& words, BlockWithId&& blockWithId, VertexTable& table)
{
  if (words.size() < 2)
  {
    return;
  }
  const vtkIdType own = words[0], n = words[0] + words[1];
  std::size_t at = 2;
  for (vtkIdType t = 0; t < n; ++t, at += 4)
  {
    Block* block = blockWithId(words[at]);
    if (!block)
    {
      throw std::runtime_error("triangles came to a rank that does not own their block");
    }
    (t < own ? block->Own : block->Halo).push_back({ words[at + 1], words[at + 2], words[at + 3] });
  }
  const std::size_t size = table.Words();
  for (; at + size <= words.size(); at += size)
  {
    table.Read(words.data() + at);
  }
}

} // namespace

//------------------------------------------------------------------------------
vtkRGDecimate::vtkRGDecimate()
{
  this->SetController(vtkMultiProcessController::GetGlobalController());
}

//------------------------------------------------------------------------------
vtkRGDecimate::~vtkRGDecimate()
{
  this->SetController(nullptr);
}

//------------------------------------------------------------------------------
/// What one execution carries from pass to pass on this rank.
struct vtkRGDecimate::Run
{
  Run(vtkMultiProcessController* controller, vtkPolyData* input)
    : ranks(controller)
    , input(input)
  {
  }
  Ranks ranks;
  std::string problem;
  vtkPolyData* input;
  vtkIdType inputTriangles = 0; // over all ranks
  vtkIdType triangles = 0;      // now, over all ranks
  vtkIdType target = 0;         // the triangles to keep
  double lower[3], upper[3];    // the global bounds
  SurfacePart part;             // this rank's part of the surface at the start of the pass
  Grid grid;
  std::vector<vtkIdType> blockTriangles; // per block of the grid, over all ranks
  std::vector<int> owner;                // per block
  std::vector<int> waveOf;               // per block: the wave of its rank's blocks it is in
  int waves = 1;                         // on every rank, the same number
  std::vector<std::int32_t> partBlock;   // the block of each of the part's triangles
  // The blocks of the part's vertices that are in several blocks: those of vertex v are
  // sharedBlocks[sharedFirst[v]] to sharedBlocks[sharedFirst[v + 1] - 1] (none for the others).
  std::vector<std::uint32_t> sharedFirst;
  std::vector<std::int32_t> sharedBlocks;
  std::vector<Block> blocks; // this rank's, by increasing id, so by wave
  vtkIdType collapses = 0;   // made in the last pass, over all ranks
  int passes = 0;
  double maximumLevel = 0; // the largest quadric error kept, over all ranks

  /// This rank's blocks of `wave` (contiguous: blocks are in wave order).
  std::pair<std::vector<Block>::iterator, std::vector<Block>::iterator> BlocksOfWave(int wave)
  {
    return std::equal_range(this->blocks.begin(), this->blocks.end(), wave,
      [](const auto& a, const auto& b) { return WaveOf(a) < WaveOf(b); });
  }
  static int WaveOf(const Block& b) { return b.Wave; }
  static int WaveOf(int wave) { return wave; }

  Block* BlockWithId(vtkIdType id)
  {
    auto at = std::lower_bound(this->blocks.begin(), this->blocks.end(), id,
      [](const Block& b, vtkIdType key) { return b.Id < key; });
    return at != this->blocks.end() && at->Id == id ? &*at : nullptr;
  }
};

//------------------------------------------------------------------------------
// The collective schedule: every rank runs these passes in this order and makes the same
// collective calls ("exchange" is Ranks::Exchange with every rank).
//
//  PASS 0 CheckInput          agreement (properties, triangles, ids, finite points)
//  PASS 1 ReadSurface         agreement (memory), AllReduce (bounds), AllReduce (triangles),
//                             agreement
//  then, for each of up to 16 passes while the target is not reached and collapses are made:
//  PASS 2 PlaceBlocks         agreement, AllReduce (triangles per block), agreement
//  PASS 3 FindSharedVertices  agreement, exchange, agreement, exchange, agreement
//  then for each wave (one, or as many as PlaceBlocks sets, the same number on every rank):
//  PASS 4 SendTriangles       agreement, exchange, agreement
//  PASS 5 SimplifyBlocks      agreement
//  then:
//  PASS 6 KeepCheapest        AllReduce (collapses found, free and fixed vertices); when more
//                             are found than needed, one AllReduce per bisection step (the
//                             same number on every rank: they see the same sums) and an
//                             AllGather
//  PASS 7 ApplyCollapses      with one wave: agreement; with several, for each wave
//                             SendTriangles's schedule, then agreement; then agreement,
//                             AllReduce (triangles, collapses), AllReduce (error), agreement
//  PASS 8 NumberSurface       agreement; vtkRGSeamRepair's own schedule (no smoothing)
int vtkRGDecimate::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPolyData* output = vtkPolyData::GetData(outputVector);
  rgmc::ForgetEarlierAbort(this->AbortExecute);
  rgmc::RunController controller(this->Controller);
  Run run(controller, vtkPolyData::GetData(inputVector[0]));
  this->NumberOfCollectives = 0;
  struct Accounting
  {
    vtkRGDecimate* Filter;
    Run& Counted;
    ~Accounting() { this->Filter->NumberOfCollectives += this->Counted.ranks.Collectives; }
  } accounting{ this, run };
  auto fail = [this, &run, output]()
  {
    vtkErrorMacro(<< "Cannot decimate: " << run.problem << ".");
    output->Initialize();
    return 0;
  };

  // PASS 0-1: a numbered triangle mesh, read in place.
  if (!this->CheckInput(run) || !this->ReadSurface(run))
  {
    return fail();
  }
  this->UpdateProgress(0.05);
  for (int pass = 0; pass < Passes && run.triangles > run.target; ++pass)
  {
    // PASS 2-7: one pass of block simplification, its blocks made and simplified in waves.
    if (!this->PlaceBlocks(run, pass) || !this->FindSharedVertices(run))
    {
      return fail();
    }
    for (int wave = 0; wave < run.waves; ++wave)
    {
      if (!this->SendTriangles(run, wave) || !this->SimplifyBlocks(run, wave))
      {
        return fail();
      }
      if (run.waves > 1)
      {
        ReleaseFreeMemory(); // the wave's meshes and messages
      }
    }
    if (!this->KeepCheapest(run, pass >= AllFromPass) || !this->ApplyCollapses(run))
    {
      return fail();
    }
    run.passes = pass + 1;
    // The pass's blocks and messages are freed; give their pages back, so that the next pass's
    // do not come on top of them (glibc keeps freed memory, the threads' arenas most of all).
    ReleaseFreeMemory();
    this->UpdateProgress(0.05 + 0.8 * (pass + 1) / Passes);
    if (run.collapses == 0)
    {
      break;
    }
  }
  // PASS 8: one mesh again, with normals, checks and measures.
  if (!this->NumberSurface(run, output))
  {
    return fail();
  }
  if (run.ranks.Rank == 0)
  {
    vtkLogF(INFO,
      "Decimate: %lld -> %lld triangles (target %lld) in %d passes, largest quadric "
      "error %.6g.",
      static_cast<long long>(run.inputTriangles), static_cast<long long>(run.triangles),
      static_cast<long long>(run.target), run.passes, std::sqrt(run.maximumLevel));
  }
  this->UpdateProgress(1.0);
  return 1;
}

//------------------------------------------------------------------------------
bool vtkRGDecimate::CheckInput(Run& run)
{
  vtkPolyData* input = run.input;
  std::ostringstream problem;
  if (!(this->TargetReduction > 0.0 && this->TargetReduction < 1.0))
  {
    problem << "Target Reduction is " << this->TargetReduction
            << "; it must be greater than 0 and less than 1 (the fraction of the triangles to "
               "remove)";
  }
  else if (!(this->MaximumError >= 0.0) || !std::isfinite(this->MaximumError))
  {
    problem << "Maximum Error is " << this->MaximumError
            << "; it must be 0 (no limit) or a positive distance";
  }
  else if (input->GetNumberOfVerts() || input->GetNumberOfLines() || input->GetNumberOfStrips() ||
    rgmc::PolygonsNotTriangles(input->GetPolys()))
  {
    problem << "the input is not a triangle mesh: it has " << input->GetNumberOfVerts()
            << " vertex cells, " << input->GetNumberOfLines() << " lines, "
            << input->GetNumberOfStrips() << " triangle strips and "
            << rgmc::PolygonsNotTriangles(input->GetPolys())
            << " polygons that are not triangles (apply Triangulate first)";
  }
  else if (input->GetNumberOfPoints() > 0 &&
    !vtkIdTypeArray::SafeDownCast(input->GetPointData()->GetGlobalIds()))
  {
    problem << "rank " << run.ranks.Rank
            << " has points without global point ids (apply Seam Repair first: it numbers the "
               "surface as one mesh)";
  }
  else
  {
    vtkDataArray* points = input->GetPoints() ? input->GetPoints()->GetData() : nullptr;
    const vtkIdType n = points ? points->GetNumberOfValues() : 0;
    for (vtkIdType i = 0; i < n; ++i)
    {
      if (!std::isfinite(points->GetVariantValue(i).ToDouble()))
      {
        problem << "point " << i / 3 << " on rank " << run.ranks.Rank
                << " has a coordinate that is not a finite number";
        break;
      }
    }
  }
  run.problem = problem.str();
  return run.ranks.Agree(run.problem.empty(), run.problem);
}

//------------------------------------------------------------------------------
bool vtkRGDecimate::ReadSurface(Run& run)
{
  double mine[6] = { VTK_DOUBLE_MAX, VTK_DOUBLE_MAX, VTK_DOUBLE_MAX, VTK_DOUBLE_MAX, VTK_DOUBLE_MAX,
    VTK_DOUBLE_MAX };
  if (!run.ranks.Step("read the surface", run.problem,
        [&]()
        {
          SurfacePart& part = run.part;
          part.Read(run.input);
          std::vector<char> used(part.NumberOfVertices(), 0);
          for (std::size_t t = 0; t < part.NumberOfTriangles(); ++t)
          {
            vtkIdType c[3];
            part.Corners(t, c);
            used[c[0]] = used[c[1]] = used[c[2]] = 1;
          }
          // The bounds of the triangles' vertices, in one reduction: the maxima as negated
          // minima.
          for (std::size_t v = 0; v < used.size(); ++v)
          {
            if (used[v])
            {
              double p[3];
              part.Point(static_cast<vtkIdType>(v), p);
              for (int a = 0; a < 3; ++a)
              {
                mine[a] = std::min(mine[a], p[a]);
                mine[3 + a] = std::min(mine[3 + a], -p[a]);
              }
            }
          }
        }))
  {
    return false;
  }
  double all[6];
  run.ranks.AllReduce(mine, all, 6, vtkCommunicator::MIN_OP, "reducing the bounds");
  const vtkIdType local = static_cast<vtkIdType>(run.part.NumberOfTriangles());
  run.ranks.AllReduce(
    &local, &run.inputTriangles, 1, vtkCommunicator::SUM_OP, "counting the triangles");
  for (int a = 0; a < 3; ++a)
  {
    run.lower[a] = all[a];
    run.upper[a] = -all[3 + a];
  }
  run.triangles = run.inputTriangles;
  run.target = run.inputTriangles -
    static_cast<vtkIdType>(std::llround(this->TargetReduction * run.inputTriangles));
  if (run.problem.empty() && run.inputTriangles == 0)
  {
    run.problem = "the input has no triangles";
  }
  return run.ranks.Agree(run.problem.empty(), run.problem);
}

//------------------------------------------------------------------------------
// The grid (from the global bounds and triangle count, the same in every pass but for its
// offset), the triangles of each block over all ranks, the blocks' ranks and waves.
bool vtkRGDecimate::PlaceBlocks(Run& run, int pass)
{
  Grid& grid = run.grid;
  double longest = 0;
  for (int a = 0; a < 3; ++a)
  {
    longest = std::max(longest, run.upper[a] - run.lower[a]);
    grid.Origin[a] = run.lower[a];
  }
  const int perAxis = static_cast<int>(std::min<double>(MaximumBlocksPerAxis,
    std::max(
      1.0, std::ceil(std::sqrt(static_cast<double>(run.triangles) / this->TrianglesPerBlock)))));
  grid.Size = longest > 0 ? longest / perAxis : 1.0;
  for (int a = 0; a < 3; ++a)
  {
    grid.Dims[a] = static_cast<int>(std::floor((run.upper[a] - run.lower[a]) / grid.Size)) + 2;
  }
  grid.Offset = PassOffsets[pass % (sizeof PassOffsets / sizeof PassOffsets[0])];
  std::vector<vtkIdType> mine;
  if (!run.ranks.Step("count the triangles of the blocks", run.problem,
        [&]()
        {
          const SurfacePart& part = run.part;
          mine.assign(static_cast<std::size_t>(grid.Count()), 0);
          run.partBlock.resize(part.NumberOfTriangles());
          for (std::size_t t = 0; t < part.NumberOfTriangles(); ++t)
          {
            vtkIdType c[3];
            part.Corners(t, c);
            vtkIdType lowest = c[0];
            for (int k = 1; k < 3; ++k)
            {
              lowest = part.Id(c[k]) < part.Id(lowest) ? c[k] : lowest;
            }
            double p[3];
            part.Point(lowest, p);
            run.partBlock[t] = static_cast<std::int32_t>(grid.BlockOf(p));
            ++mine[run.partBlock[t]];
          }
          run.blockTriangles.assign(mine.size(), 0);
        }))
  {
    return false;
  }
  run.ranks.AllReduce(mine.data(), run.blockTriangles.data(), static_cast<vtkIdType>(mine.size()),
    vtkCommunicator::SUM_OP, "counting the blocks' triangles");
  // Contiguous ranges of blocks, of about equal triangle counts, rank after rank: the blocks'
  // order is then the ranks' order, and the output's triangles are in block order whatever
  // the number of ranks.
  const int size = run.ranks.Size;
  run.owner.assign(run.blockTriangles.size(), 0);
  std::vector<vtkIdType> ofRank(static_cast<std::size_t>(size), 0);
  vtkIdType before = 0;
  const vtkIdType total = std::max<vtkIdType>(1, run.triangles);
  for (std::size_t b = 0; b < run.blockTriangles.size(); ++b)
  {
    const vtkIdType count = run.blockTriangles[b];
    run.owner[b] =
      static_cast<int>(std::min<vtkIdType>(size - 1, (2 * before + count) * size / (2 * total)));
    before += count;
    ofRank[run.owner[b]] += count;
  }
  // Waves: a rank whose blocks hold more than TrianglesPerWave triangles makes them in waves
  // of contiguous blocks, at least 16, so that it holds one wave's blocks at a time. Every rank
  // computes the same number from the global counts; it never changes the result.
  const vtkIdType largest = *std::max_element(ofRank.begin(), ofRank.end());
  run.waves = largest <= this->TrianglesPerWave
    ? 1
    : static_cast<int>(
        std::max<vtkIdType>(16, (largest + this->TrianglesPerWave - 1) / this->TrianglesPerWave));
  run.waveOf.assign(run.blockTriangles.size(), 0);
  std::vector<vtkIdType> earlier(static_cast<std::size_t>(size), 0);
  run.blocks.clear();
  for (std::size_t b = 0; b < run.blockTriangles.size(); ++b)
  {
    const int r = run.owner[b];
    const vtkIdType count = run.blockTriangles[b];
    run.waveOf[b] = static_cast<int>(std::min<vtkIdType>(run.waves - 1,
      (2 * earlier[r] + count) * run.waves / (2 * std::max<vtkIdType>(1, ofRank[r]))));
    earlier[r] += count;
    if (count > 0 && r == run.ranks.Rank)
    {
      run.blocks.emplace_back();
      run.blocks.back().Id = static_cast<vtkIdType>(b);
      run.blocks.back().Wave = run.waveOf[b];
    }
  }
  return run.ranks.Agree(run.problem.empty(), run.problem);
}

//------------------------------------------------------------------------------
// The part's vertices that lie in several blocks, with all their blocks: (vertex, block) pairs
// meet at the vertex's rank (its id modulo the ranks), which tells each rank that sent one the
// blocks of each vertex in more than one.
bool vtkRGDecimate::FindSharedVertices(Run& run)
{
  const int size = run.ranks.Size;
  std::vector<std::vector<vtkIdType>> outgoing(static_cast<std::size_t>(size));
  if (!run.ranks.Step("list the vertices' blocks", run.problem,
        [&]()
        {
          const SurfacePart& part = run.part;
          const std::size_t nv = part.NumberOfVertices();
          // Each vertex's first block, and its other blocks apart (few vertices have any).
          std::vector<std::int32_t> first(nv, -1);
          std::vector<std::pair<vtkIdType, vtkIdType>> more;
          for (std::size_t t = 0; t < part.NumberOfTriangles(); ++t)
          {
            vtkIdType c[3];
            part.Corners(t, c);
            for (vtkIdType v : c)
            {
              if (first[v] < 0)
              {
                first[v] = run.partBlock[t];
              }
              else if (first[v] != run.partBlock[t])
              {
                more.emplace_back(v, run.partBlock[t]);
              }
            }
          }
          std::sort(more.begin(), more.end());
          more.erase(std::unique(more.begin(), more.end()), more.end());
          auto send = [&](vtkIdType v, vtkIdType block)
          {
            const vtkIdType id = part.Id(v);
            auto& words = outgoing[static_cast<std::size_t>(id % size)];
            words.push_back(id);
            words.push_back(v);
            words.push_back(block);
          };
          for (std::size_t v = 0; v < nv; ++v)
          {
            if (first[v] >= 0)
            {
              send(static_cast<vtkIdType>(v), first[v]);
            }
          }
          for (const auto& vb : more)
          {
            send(vb.first, vb.second);
          }
        }))
  {
    return false;
  }
  auto asked = run.ranks.Exchange(std::move(outgoing), Everyone(size), SharedTag);
  std::vector<std::vector<vtkIdType>> answers(static_cast<std::size_t>(size));
  if (!run.ranks.Step("find the shared vertices", run.problem,
        [&]()
        {
          // (vertex id, block, asking rank, its index of the vertex)
          std::vector<std::array<vtkIdType, 4>> all;
          for (int r = 0; r < size; ++r)
          {
            const auto& words = asked[r];
            for (std::size_t at = 0; at + 2 < words.size(); at += 3)
            {
              all.push_back({ words[at], words[at + 2], r, words[at + 1] });
            }
            std::vector<vtkIdType>().swap(asked[r]);
          }
          rgmc::RadixSort(all, [](const std::array<vtkIdType, 4>& e) { return KeyOf(e[0]); });
          std::vector<vtkIdType> blocks;
          std::vector<std::pair<vtkIdType, vtkIdType>> askers;
          for (std::size_t first = 0, last; first < all.size(); first = last)
          {
            blocks.clear();
            askers.clear();
            for (last = first; last < all.size() && all[last][0] == all[first][0]; ++last)
            {
              blocks.push_back(all[last][1]);
              askers.emplace_back(all[last][2], all[last][3]);
            }
            SortDistinct(blocks);
            if (blocks.size() < 2)
            {
              continue;
            }
            std::sort(askers.begin(), askers.end());
            askers.erase(std::unique(askers.begin(), askers.end()), askers.end());
            for (const auto& asker : askers)
            {
              auto& words = answers[asker.first];
              for (vtkIdType block : blocks)
              {
                words.push_back(asker.second);
                words.push_back(block);
              }
            }
          }
        }))
  {
    return false;
  }
  const auto told = run.ranks.Exchange(std::move(answers), Everyone(size), AnswersTag);
  return run.ranks.Step("record the shared vertices", run.problem,
    [&]()
    {
      std::vector<std::pair<vtkIdType, vtkIdType>> shared; // (vertex, block)
      for (const auto& words : told)
      {
        for (std::size_t at = 0; at + 1 < words.size(); at += 2)
        {
          shared.emplace_back(words[at], words[at + 1]);
        }
      }
      std::sort(shared.begin(), shared.end());
      shared.erase(std::unique(shared.begin(), shared.end()), shared.end());
      run.sharedFirst.assign(run.part.NumberOfVertices() + 1, 0);
      run.sharedBlocks.resize(shared.size());
      for (std::size_t i = 0; i < shared.size(); ++i)
      {
        ++run.sharedFirst[shared[i].first + 1];
        run.sharedBlocks[i] = static_cast<std::int32_t>(shared[i].second);
      }
      for (std::size_t v = 1; v < run.sharedFirst.size(); ++v)
      {
        run.sharedFirst[v] += run.sharedFirst[v - 1];
      }
    });
}

//------------------------------------------------------------------------------
// The wave's blocks: each triangle of the part to the rank of its block, if that block is in
// the wave, and to the blocks of the wave that share one of its vertices (their halo), with the
// vertices' records; then each block's mesh in local indices.
bool vtkRGDecimate::SendTriangles(Run& run, int wave)
{
  const int size = run.ranks.Size;
  std::vector<std::vector<vtkIdType>> outgoing(static_cast<std::size_t>(size));
  if (!run.ranks.Step("send the triangles to their blocks", run.problem,
        [&]()
        {
          const SurfacePart& part = run.part;
          std::vector<std::vector<Sending>> going(static_cast<std::size_t>(size));
          std::vector<vtkIdType> others;
          for (std::size_t t = 0; t < part.NumberOfTriangles(); ++t)
          {
            const vtkIdType block = run.partBlock[t];
            if (run.waveOf[block] == wave)
            {
              going[run.owner[block]].push_back({ block, static_cast<vtkIdType>(t), 0 });
            }
            vtkIdType c[3];
            part.Corners(t, c);
            others.clear();
            for (vtkIdType v : c)
            {
              for (std::uint32_t i = run.sharedFirst[v]; i < run.sharedFirst[v + 1]; ++i)
              {
                const vtkIdType other = run.sharedBlocks[i];
                if (other != block && run.waveOf[other] == wave)
                {
                  others.push_back(other);
                }
              }
            }
            if (others.empty())
            {
              continue;
            }
            std::sort(others.begin(), others.end());
            others.erase(std::unique(others.begin(), others.end()), others.end());
            for (vtkIdType other : others)
            {
              going[run.owner[other]].push_back({ other, static_cast<vtkIdType>(t), 1 });
            }
          }
          for (int r = 0; r < size; ++r)
          {
            WriteTriangles(outgoing[r], going[r], part);
            std::vector<Sending>().swap(going[r]);
          }
        }))
  {
    return false;
  }
  auto incoming = run.ranks.Exchange(std::move(outgoing), Everyone(size), TrianglesTag);
  return run.ranks.Step("assemble the blocks", run.problem,
    [&]()
    {
      VertexTable seen; // the vertices of the wave's blocks' triangles
      seen.HasQuadrics = run.part.HasQuadrics();
      for (auto& words : incoming)
      {
        ReadTriangles(
          words, [&run](vtkIdType id) { return run.BlockWithId(id); }, seen);
        std::vector<vtkIdType>().swap(words); // read: its memory goes back at once
      }
      seen.SortUnique();
      const auto blocks = run.BlocksOfWave(wave);
      const auto first = blocks.first, last = blocks.second;
      rgmc::ParallelFor(static_cast<vtkIdType>(last - first), 1,
        [&](vtkIdType from, vtkIdType to)
        {
          for (auto block = first + from; block != first + to; ++block)
          {
            rgmc::DecimationBlock& mesh = block->Mesh;
            for (const auto* list : { &block->Own, &block->Halo })
            {
              for (const Triangle& t : *list)
              {
                mesh.Ids.insert(mesh.Ids.end(), t.begin(), t.end());
              }
            }
            SortDistinct(mesh.Ids);
            const std::size_t n = mesh.Ids.size();
            mesh.Points.resize(3 * n);
            mesh.Quadrics.resize(n);
            for (std::size_t v = 0; v < n; ++v)
            {
              const std::ptrdiff_t at = seen.Find(mesh.Ids[v]);
              const Vertex& record = seen.Vertices[at];
              std::copy(record.Point, record.Point + 3, mesh.Points.begin() + 3 * v);
              if (seen.HasQuadrics)
              {
                mesh.Quadrics[v] = seen.Quadrics[at];
              }
            }
            auto local = [&mesh](vtkIdType id)
            {
              return static_cast<int>(
                std::lower_bound(mesh.Ids.begin(), mesh.Ids.end(), id) - mesh.Ids.begin());
            };
            // A vertex of the block's own triangles that a halo triangle has too is shared with
            // another block: fixed.
            std::vector<std::uint8_t> inOwn(n, 0), inHalo(n, 0);
            for (const Triangle& t : block->Own)
            {
              mesh.Triangles.push_back({ local(t[0]), local(t[1]), local(t[2]) });
              for (int v : mesh.Triangles.back())
              {
                inOwn[v] = 1;
              }
            }
            for (const Triangle& t : block->Halo)
            {
              mesh.Halo.push_back({ local(t[0]), local(t[1]), local(t[2]) });
              for (int v : mesh.Halo.back())
              {
                inHalo[v] = 1;
              }
            }
            mesh.Fixed.resize(n);
            for (std::size_t v = 0; v < n; ++v)
            {
              mesh.Fixed[v] = inOwn[v] & inHalo[v];
            }
            std::vector<Triangle>().swap(block->Own);
            std::vector<Triangle>().swap(block->Halo);
            mesh.SortTriangles();
            if (!seen.HasQuadrics)
            {
              // Area-weighted unless an error bound is asked for: see MaximumError.
              mesh.AreaWeighted = !(this->MaximumError > 0.0);
              mesh.ComputeQuadrics();
            }
          }
        });
    });
}

//------------------------------------------------------------------------------
// The wave's blocks simplified (threads over blocks). With several waves, only the collapses'
// levels are kept: ApplyCollapses makes the blocks again.
bool vtkRGDecimate::SimplifyBlocks(Run& run, int wave)
{
  const double maximumError = this->MaximumError;
  // No block needs more collapses than the whole surface still needs; and a block is stopped at
  // four times its share of them (a rule of global counts only, so the same on any ranks): the
  // passes after the first need few collapses, and would otherwise simplify every block as far
  // as it goes to keep a handful.
  const double needed = 0.5 * static_cast<double>(run.triangles - run.target);
  return run.ranks.Step("simplify the blocks", run.problem,
    [&]()
    {
      const auto blocks = run.BlocksOfWave(wave);
      rgmc::ParallelFor(static_cast<vtkIdType>(blocks.second - blocks.first), 1,
        [&](vtkIdType first, vtkIdType last)
        {
          for (vtkIdType b = first; b < last; ++b)
          {
            Block& block = blocks.first[b];
            const double share = 4.0 * needed * static_cast<double>(run.blockTriangles[block.Id]) /
              static_cast<double>(run.triangles);
            block.Log = rgmc::Simplify(block.Mesh, maximumError,
              static_cast<std::size_t>(std::ceil(std::min(needed, share))));
            block.Levels.resize(block.Log.size());
            for (std::size_t c = 0; c < block.Log.size(); ++c)
            {
              block.Levels[c] = block.Log[c].Level;
            }
            std::vector<char> used(block.Mesh.Ids.size(), 0);
            for (const auto& t : block.Mesh.Triangles)
            {
              used[t[0]] = used[t[1]] = used[t[2]] = 1;
            }
            for (std::size_t v = 0; v < used.size(); ++v)
            {
              block.Vertices += used[v];
              block.Fixed += used[v] && block.Mesh.Fixed[v];
            }
            if (run.waves > 1)
            {
              block.Mesh = rgmc::DecimationBlock();
              std::vector<rgmc::Collapse>().swap(block.Log);
            }
          }
        });
    });
}

//------------------------------------------------------------------------------
// How many collapses each block keeps: the cheapest over all blocks, by their level (the largest
// error so far in their block), ties by block and order.
bool vtkRGDecimate::KeepCheapest(Run& run, bool all)
{
  Ranks& ranks = run.ranks;
  // Collapses found, and the blocks' vertices, fixed or not.
  vtkIdType local[3] = { 0, 0, 0 }, sums[3] = { 0, 0, 0 };
  for (const Block& block : run.blocks)
  {
    local[0] += static_cast<vtkIdType>(block.Levels.size());
    local[1] += static_cast<vtkIdType>(block.Vertices);
    local[2] += static_cast<vtkIdType>(block.Fixed);
  }
  ranks.AllReduce(local, sums, 3, vtkCommunicator::SUM_OP, "counting the collapses");
  const vtkIdType found = sums[0];
  // Greedy decimation of the whole surface would also collapse edges among the vertices fixed in
  // this pass: a pass that is not the last makes only the free vertices' share of what is
  // needed, so that it does not decimate the blocks' insides further than the whole surface
  // will be (the next passes free the rest).
  vtkIdType needed = (run.triangles - run.target + 1) / 2;
  // The last few (5% of the triangles or less) are made at once.
  if (!all && 2 * needed > run.triangles / 20 && sums[1] > 0)
  {
    needed = static_cast<vtkIdType>(
      std::ceil(static_cast<double>(needed) * static_cast<double>(sums[1] - sums[2]) / sums[1]));
  }
  auto atMost = [&run](double level, bool strictly)
  {
    vtkIdType count = 0;
    for (const Block& block : run.blocks)
    {
      auto end = strictly ? std::lower_bound(block.Levels.begin(), block.Levels.end(), level)
                          : std::upper_bound(block.Levels.begin(), block.Levels.end(), level);
      count += static_cast<vtkIdType>(end - block.Levels.begin());
    }
    return count;
  };
  if (found <= needed)
  {
    for (Block& block : run.blocks)
    {
      block.Keep = block.Levels.size();
    }
    return true;
  }
  // The smallest level with at least `needed` collapses at or below it: bisection on the bits
  // of non-negative doubles, which order as their values do.
  std::int64_t low = 0, high = 0x7FF0000000000000; // 0 and +infinity
  while (low < high)
  {
    const std::int64_t middle = low + (high - low) / 2;
    double level;
    std::memcpy(&level, &middle, sizeof level);
    const vtkIdType mine = atMost(level, false);
    vtkIdType sum = 0;
    ranks.AllReduce(&mine, &sum, 1, vtkCommunicator::SUM_OP, "selecting the threshold");
    if (sum >= needed)
    {
      high = middle;
    }
    else
    {
      low = middle + 1;
    }
  }
  double threshold;
  std::memcpy(&threshold, &high, sizeof threshold);
  // All collapses below the threshold; at it, the first ones in block order over the ranks.
  const vtkIdType counts[2] = { atMost(threshold, true),
    atMost(threshold, false) - atMost(threshold, true) };
  std::vector<vtkIdType> gathered(2 * static_cast<std::size_t>(ranks.Size));
  ranks.AllGather(counts, gathered.data(), 2, "sharing the counts at the threshold");
  vtkIdType below = 0, earlierAt = 0;
  for (int r = 0; r < ranks.Size; ++r)
  {
    below += gathered[2 * r];
    earlierAt += r < ranks.Rank ? gathered[2 * r + 1] : 0;
  }
  vtkIdType atThreshold =
    std::max<vtkIdType>(0, std::min<vtkIdType>(counts[1], needed - below - earlierAt));
  for (Block& block : run.blocks)
  {
    auto lower = std::lower_bound(block.Levels.begin(), block.Levels.end(), threshold);
    auto upper = std::upper_bound(block.Levels.begin(), block.Levels.end(), threshold);
    const vtkIdType take = std::min<vtkIdType>(atThreshold, upper - lower);
    block.Keep = static_cast<std::size_t>((lower - block.Levels.begin()) + take);
    atThreshold -= take;
  }
  return true;
}

//------------------------------------------------------------------------------
// The kept collapses applied, and the blocks' triangles, in block order, become this rank's
// part. With several waves each wave's blocks are made again (the same content, so the same
// collapses) and simplified as far as they keep.
bool vtkRGDecimate::ApplyCollapses(Run& run)
{
  Ranks& ranks = run.ranks;
  std::vector<Triangle> surface; // by global ids
  VertexTable vertices;
  vertices.HasQuadrics = true;
  vtkIdType kept = 0;
  double level = 0;
  // Sized once from the counts (each collapse removes two of a block's own triangles), so that
  // the largest of these lists is not made twice by growing.
  std::size_t expected = 0;
  for (const Block& block : run.blocks)
  {
    const std::size_t own = static_cast<std::size_t>(run.blockTriangles[block.Id]);
    expected += own - std::min(own, 2 * block.Keep);
  }
  // The blocks' collapses are replayed in parallel (each block alone), then each block is
  // copied and freed, block after block.
  auto apply = [&](
                 std::vector<Block>::iterator first, std::vector<Block>::iterator last, bool again)
  {
    if (surface.capacity() == 0)
    {
      surface.reserve(expected);
      vertices.Reserve(expected / 2 + expected / 16);
    }
    std::vector<std::vector<char>> used(static_cast<std::size_t>(last - first));
    rgmc::ParallelFor(static_cast<vtkIdType>(last - first), 1,
      [&](vtkIdType from, vtkIdType to)
      {
        for (vtkIdType b = from; b < to; ++b)
        {
          Block& block = *(first + b);
          if (again)
          {
            block.Log = rgmc::Simplify(block.Mesh, this->MaximumError, block.Keep);
          }
          rgmc::ApplyCollapses(block.Mesh, block.Log, block.Keep);
          used[b].assign(block.Mesh.Ids.size(), 0);
          for (const auto& t : block.Mesh.Triangles)
          {
            used[b][t[0]] = used[b][t[1]] = used[b][t[2]] = 1;
          }
        }
      });
    for (auto block = first; block != last; ++block)
    {
      const std::size_t b = static_cast<std::size_t>(block - first);
      kept += static_cast<vtkIdType>(block->Keep);
      if (block->Keep > 0)
      {
        level = std::max(level, block->Levels[block->Keep - 1]);
      }
      const rgmc::DecimationBlock& mesh = block->Mesh;
      for (const auto& t : mesh.Triangles)
      {
        surface.push_back({ mesh.Ids[t[0]], mesh.Ids[t[1]], mesh.Ids[t[2]] });
      }
      for (std::size_t v = 0; v < used[b].size(); ++v)
      {
        if (used[b][v])
        {
          Vertex record;
          record.Id = mesh.Ids[v];
          std::copy(&mesh.Points[3 * v], &mesh.Points[3 * v] + 3, record.Point);
          vertices.Add(record, &mesh.Quadrics[v]);
        }
      }
      *block = Block{ block->Id, block->Wave, {}, {}, {}, {}, {}, 0, 0, 0 };
      std::vector<char>().swap(used[b]);
    }
  };
  if (run.waves == 1)
  {
    if (!ranks.Step("apply the collapses", run.problem,
          [&]() { apply(run.blocks.begin(), run.blocks.end(), false); }))
    {
      return false;
    }
  }
  else
  {
    for (int wave = 0; wave < run.waves; ++wave)
    {
      if (!this->SendTriangles(run, wave) ||
        !ranks.Step("apply the collapses", run.problem,
          [&]()
          {
            const auto blocks = run.BlocksOfWave(wave);
            const auto first = blocks.first, last = blocks.second;
            apply(first, last, true);
          }))
      {
        return false;
      }
      ReleaseFreeMemory();
    }
  }
  if (!ranks.Step("make the blocks the part", run.problem,
        [&]()
        {
          run.blocks.clear();
          std::vector<std::int32_t>().swap(run.partBlock);
          std::vector<std::uint32_t>().swap(run.sharedFirst);
          std::vector<std::int32_t>().swap(run.sharedBlocks);
          run.part.Adopt(surface, vertices);
        }))
  {
    return false;
  }
  const vtkIdType mine[2] = { static_cast<vtkIdType>(run.part.NumberOfTriangles()), kept };
  vtkIdType after[2] = { 0, 0 };
  ranks.AllReduce(mine, after, 2, vtkCommunicator::SUM_OP, "counting the triangles");
  double largest = 0;
  ranks.AllReduce(&level, &largest, 1, vtkCommunicator::MAX_OP, "reducing the error");
  run.triangles = after[0];
  run.collapses = after[1];
  run.maximumLevel = std::max(run.maximumLevel, largest);
  return ranks.Agree(run.problem.empty(), run.problem);
}

//------------------------------------------------------------------------------
// This rank's triangles as a piece keyed by the surviving vertices' global ids, numbered as one
// mesh by vtkRGSeamRepair (no smoothing): contiguous global ids, owners, normals, checks and
// measures.
bool vtkRGDecimate::NumberSurface(Run& run, vtkPolyData* output)
{
  vtkNew<vtkPolyData> piece;
  if (!run.ranks.Step("build the decimated piece", run.problem,
        [&]()
        {
          vtkNew<vtkPoints> points;
          if (run.input->GetPoints())
          {
            points->SetDataType(run.input->GetPoints()->GetDataType());
          }
          SurfacePart& part = run.part;
          part.OwnInput(); // when no pass ran
          const vtkIdType n = static_cast<vtkIdType>(part.Vertices.Vertices.size());
          points->SetNumberOfPoints(n);
          vtkNew<vtkIdTypeArray> ids;
          ids->SetName("DecimatedVertexIds");
          rgmc::Allocate(ids.Get(), n);
          for (vtkIdType v = 0; v < n; ++v)
          {
            points->SetPoint(v, part.Vertices.Vertices[v].Point);
            ids->SetValue(v, part.Vertices.Vertices[v].Id);
          }
          vtkNew<vtkIdTypeArray> connectivity, offsets;
          const vtkIdType t = static_cast<vtkIdType>(part.Triangles.size());
          vtkIdType* c = rgmc::Allocate(connectivity.Get(), 3 * t);
          vtkIdType* o = rgmc::Allocate(offsets.Get(), t + 1);
          for (vtkIdType i = 0; i < t; ++i)
          {
            o[i] = 3 * i;
            std::copy(part.Triangles[i].begin(), part.Triangles[i].end(), c + 3 * i);
          }
          o[t] = 3 * t;
          vtkNew<vtkCellArray> polys;
          polys->SetData(offsets, connectivity);
          piece->SetPoints(points);
          piece->SetPolys(polys);
          piece->GetPointData()->SetGlobalIds(ids);
          piece->GetFieldData()->PassData(run.input->GetFieldData());
          part.Clear();
        }))
  {
    return false;
  }
  vtkNew<vtkRGSeamRepair> numbering;
  numbering->SetController(run.ranks.Controller());
  numbering->SetSmoothingMethod(vtkRGSeamRepair::NO_SMOOTHING);
  numbering->SetInputData(piece);
  const int ok = numbering->GetExecutive()->Update();
  this->NumberOfCollectives += numbering->GetNumberOfCollectives();
  if (!ok)
  {
    run.problem = "numbering the decimated surface failed";
    return false;
  }
  output->ShallowCopy(numbering->GetOutput());
  output->GetPointData()->RemoveArray("DecimatedVertexIds");
  // The measures before decimation, where the input had them; Seam Repair's "before
  // smoothing" ones are the input's too.
  vtkFieldData* fd = output->GetFieldData();
  vtkFieldData* in = run.input->GetFieldData();
  auto copyAs = [fd, in](const char* from, const char* to)
  {
    fd->RemoveArray(to);
    if (vtkDataArray* a = vtkDataArray::SafeDownCast(in->GetAbstractArray(from)))
    {
      vtkNew<vtkDoubleArray> copy;
      copy->SetName(to);
      copy->InsertNextValue(a->GetTuple1(0));
      fd->AddArray(copy);
    }
  };
  copyAs("SurfaceAreaBeforeSmoothing", "SurfaceAreaBeforeSmoothing");
  copyAs("EnclosedVolumeBeforeSmoothing", "EnclosedVolumeBeforeSmoothing");
  copyAs("SurfaceArea", "SurfaceAreaBeforeDecimation");
  copyAs("EnclosedVolume", "EnclosedVolumeBeforeDecimation");
  auto add = [fd](const char* name, double value)
  {
    vtkNew<vtkDoubleArray> a;
    a->SetName(name);
    a->InsertNextValue(value);
    fd->AddArray(a);
  };
  add("TrianglesBeforeDecimation", static_cast<double>(run.inputTriangles));
  add("DecimationQuadricError", std::sqrt(run.maximumLevel));
  return true;
}

//------------------------------------------------------------------------------
void vtkRGDecimate::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "TargetReduction: " << this->TargetReduction << "\n";
  os << indent << "MaximumError: " << this->MaximumError << "\n";
  os << indent << "TrianglesPerBlock: " << this->TrianglesPerBlock << "\n";
  os << indent << "TrianglesPerWave: " << this->TrianglesPerWave << "\n";
  os << indent << "Controller: " << this->Controller << "\n";
  os << indent << "NumberOfCollectives: " << this->NumberOfCollectives << "\n";
}

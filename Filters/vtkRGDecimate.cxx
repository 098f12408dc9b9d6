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

#include "vtkCellArray.h"
#include "vtkCellArrayIterator.h"
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

  /// Sorts by id and keeps one of each (copies of a vertex are equal). The first `sortedPrefix`
  /// are sorted already; when the rest is too (what came from one rank), the two are merged.
  void SortUnique(std::size_t sortedPrefix = 0)
  {
    const std::size_t n = this->Vertices.size();
    std::vector<std::pair<vtkIdType, std::size_t>> order(n);
    for (std::size_t i = 0; i < n; ++i)
    {
      order[i] = { this->Vertices[i].Id, i };
    }
    const auto tail = order.begin() + static_cast<std::ptrdiff_t>(sortedPrefix);
    if (std::is_sorted(tail, order.end()))
    {
      std::inplace_merge(order.begin(), tail, order.end());
    }
    else
    {
      rgmc::RadixSort(
        order, [](const std::pair<vtkIdType, std::size_t>& p) { return KeyOf(p.first); });
    }
    std::vector<Vertex> vertices;
    std::vector<rgmc::Quadric> quadrics;
    vertices.reserve(n);
    quadrics.reserve(this->HasQuadrics ? n : 0);
    for (std::size_t i = 0; i < n; ++i)
    {
      if (i == 0 || order[i].first != order[i - 1].first)
      {
        vertices.push_back(this->Vertices[order[i].second]);
        if (this->HasQuadrics)
        {
          quadrics.push_back(this->Quadrics[order[i].second]);
        }
      }
    }
    this->Vertices.swap(vertices);
    this->Quadrics.swap(quadrics);
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

/// One block on its rank during a pass.
struct Block
{
  vtkIdType Id;
  std::vector<Triangle> Own, Halo;
  std::vector<std::pair<vtkIdType, vtkIdType>> SharedWith; // (vertex, other block), sorted
  rgmc::DecimationBlock Mesh;
  std::vector<rgmc::Collapse> Log;
  std::size_t Keep = 0;
};

std::vector<bool> Everyone(int size)
{
  return std::vector<bool>(static_cast<std::size_t>(size), true);
}

/// A message of triangles for blocks: their count, (block, three vertex ids) for each of the
/// `count` that `each(i, block)` gives, then the records of their vertices from `table`, each
/// once, by increasing id.
template <typename Each>
void WriteTriangles(
  std::vector<vtkIdType>& words, std::size_t count, const VertexTable& table, Each&& each)
{
  std::vector<vtkIdType> ids;
  words.push_back(static_cast<vtkIdType>(count));
  for (std::size_t i = 0; i < count; ++i)
  {
    vtkIdType block;
    const Triangle& t = each(i, block);
    words.push_back(block);
    words.insert(words.end(), t.begin(), t.end());
    ids.insert(ids.end(), t.begin(), t.end());
  }
  SortDistinct(ids);
  for (vtkIdType id : ids)
  {
    table.Write(table.Find(id), words);
  }
}

/// Reads what WriteTriangles wrote: each triangle into `list` of its block (`blockWithId`; one
/// this rank does not own is an error), the vertex records into `table`.
template <typename BlockWithId>
void ReadTriangles(const std::vector<vtkIdType>& words, std::vector<Triangle> Block::*list,
  BlockWithId&& blockWithId, VertexTable& table)
{
  if (words.empty())
  {
    return;
  }
  const vtkIdType n = words[0];
  std::size_t at = 1;
  for (vtkIdType t = 0; t < n; ++t, at += 4)
  {
    Block* block = blockWithId(words[at]);
    if (!block)
    {
      throw std::runtime_error("triangles came to a rank that does not own their block");
    }
    (block->*list).push_back({ words[at + 1], words[at + 2], words[at + 3] });
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
  // This rank's part of the surface between passes: triangles by global ids (in their cyclic
  // order) and their vertices.
  std::vector<Triangle> surface;
  VertexTable vertices;
  bool quadrics = false; // whether the vertices carry their quadrics yet
  Grid grid;
  std::vector<vtkIdType> blockTriangles; // per block of the grid, over all ranks
  std::vector<int> owner;                // per block
  std::vector<vtkIdType> surfaceBlock;   // the block of each of this rank's triangles
  std::vector<Block> blocks;             // this rank's, by increasing id
  VertexTable seen;                      // the vertices of its blocks' triangles and halos
  vtkIdType collapses = 0;               // made in the last pass, over all ranks
  int passes = 0;
  double maximumLevel = 0; // the largest quadric error kept, over all ranks

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
//  PASS 3 SendTriangles       agreement, exchange, agreement
//  PASS 4 FindSharedVertices  agreement, exchange, agreement, exchange, agreement
//  PASS 5 SendHalos           agreement, exchange, agreement
//  PASS 6 SimplifyBlocks      agreement
//  PASS 7 KeepCheapest        AllReduce (collapses found, free and fixed vertices); when more
//                             are found than needed, one AllReduce per bisection step (the
//                             same number on every rank: they see the same sums) and an
//                             AllGather; agreement; AllReduce (triangles, collapses);
//                             AllReduce (error); agreement
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

  // PASS 0-1: a numbered triangle mesh, read into global ids and positions.
  if (!this->CheckInput(run) || !this->ReadSurface(run))
  {
    return fail();
  }
  this->UpdateProgress(0.05);
  for (int pass = 0; pass < Passes && run.triangles > run.target; ++pass)
  {
    // PASS 2-7: one pass of block simplification.
    if (!this->PlaceBlocks(run, pass) || !this->SendTriangles(run) ||
      !this->FindSharedVertices(run) || !this->SendHalos(run) || !this->SimplifyBlocks(run) ||
      !this->KeepCheapest(run, pass >= AllFromPass))
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
  vtkPolyData* input = run.input;
  if (!run.ranks.Step("read the surface", run.problem,
        [&]()
        {
          vtkIdTypeArray* ids = vtkIdTypeArray::SafeDownCast(input->GetPointData()->GetGlobalIds());
          vtkCellArray* polys = input->GetPolys();
          run.surface.reserve(static_cast<std::size_t>(polys->GetNumberOfCells()));
          std::vector<char> used(static_cast<std::size_t>(input->GetNumberOfPoints()), 0);
          auto it = vtk::TakeSmartPointer(polys->NewIterator());
          for (it->GoToFirstCell(); !it->IsDoneWithTraversal(); it->GoToNextCell())
          {
            vtkIdType size;
            const vtkIdType* pts;
            it->GetCurrentCell(size, pts);
            run.surface.push_back(
              { ids->GetValue(pts[0]), ids->GetValue(pts[1]), ids->GetValue(pts[2]) });
            used[pts[0]] = used[pts[1]] = used[pts[2]] = 1;
          }
          for (vtkIdType p = 0; p < input->GetNumberOfPoints(); ++p)
          {
            if (used[p])
            {
              Vertex v;
              v.Id = ids->GetValue(p);
              input->GetPoint(p, v.Point);
              run.vertices.Add(v, nullptr);
            }
          }
          run.vertices.SortUnique();
        }))
  {
    return false;
  }
  double mine[6] = { VTK_DOUBLE_MAX, VTK_DOUBLE_MAX, VTK_DOUBLE_MAX, VTK_DOUBLE_MAX, VTK_DOUBLE_MAX,
    VTK_DOUBLE_MAX };
  for (const Vertex& v : run.vertices.Vertices)
  {
    for (int a = 0; a < 3; ++a)
    {
      mine[a] = std::min(mine[a], v.Point[a]);
      mine[3 + a] = std::min(mine[3 + a], -v.Point[a]);
    }
  }
  // The bounds in one reduction: the maxima as negated minima.
  double all[6];
  run.ranks.AllReduce(mine, all, 6, vtkCommunicator::MIN_OP, "reducing the bounds");
  const vtkIdType local = static_cast<vtkIdType>(run.surface.size());
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
// offset), the triangles of each block over all ranks, and the blocks' ranks.
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
          mine.assign(static_cast<std::size_t>(grid.Count()), 0);
          run.surfaceBlock.resize(run.surface.size());
          for (std::size_t t = 0; t < run.surface.size(); ++t)
          {
            const Triangle& tri = run.surface[t];
            const vtkIdType lowest = std::min({ tri[0], tri[1], tri[2] });
            run.surfaceBlock[t] =
              grid.BlockOf(run.vertices.Vertices[run.vertices.Find(lowest)].Point);
            ++mine[run.surfaceBlock[t]];
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
  run.owner.assign(run.blockTriangles.size(), 0);
  run.blocks.clear();
  vtkIdType before = 0;
  const vtkIdType total = std::max<vtkIdType>(1, run.triangles);
  for (std::size_t b = 0; b < run.blockTriangles.size(); ++b)
  {
    const vtkIdType count = run.blockTriangles[b];
    run.owner[b] = static_cast<int>(
      std::min<vtkIdType>(run.ranks.Size - 1, (2 * before + count) * run.ranks.Size / (2 * total)));
    before += count;
    if (count > 0 && run.owner[b] == run.ranks.Rank)
    {
      run.blocks.emplace_back();
      run.blocks.back().Id = static_cast<vtkIdType>(b);
    }
  }
  return run.ranks.Agree(run.problem.empty(), run.problem);
}

//------------------------------------------------------------------------------
// Each triangle, with its vertices, to the rank of its block.
bool vtkRGDecimate::SendTriangles(Run& run)
{
  const int size = run.ranks.Size;
  std::vector<std::vector<vtkIdType>> outgoing(static_cast<std::size_t>(size));
  if (!run.ranks.Step("send the triangles to their blocks", run.problem,
        [&]()
        {
          std::vector<std::vector<std::size_t>> going(static_cast<std::size_t>(size));
          for (std::size_t t = 0; t < run.surface.size(); ++t)
          {
            going[run.owner[run.surfaceBlock[t]]].push_back(t);
          }
          for (int r = 0; r < size; ++r)
          {
            WriteTriangles(outgoing[r], going[r].size(), run.vertices,
              [&](std::size_t i, vtkIdType& block) -> const Triangle&
              {
                block = run.surfaceBlock[going[r][i]];
                return run.surface[going[r][i]];
              });
          }
          std::vector<Triangle>().swap(run.surface);
          std::vector<vtkIdType>().swap(run.surfaceBlock);
          run.vertices.Clear();
        }))
  {
    return false;
  }
  auto incoming = run.ranks.Exchange(std::move(outgoing), Everyone(size), TrianglesTag);
  return run.ranks.Step("receive the blocks' triangles", run.problem,
    [&]()
    {
      run.seen.Clear();
      run.seen.HasQuadrics = run.quadrics;
      for (auto& words : incoming)
      {
        ReadTriangles(
          words, &Block::Own, [&run](vtkIdType id) { return run.BlockWithId(id); }, run.seen);
        std::vector<vtkIdType>().swap(words); // read: its memory goes back at once
      }
    });
}

//------------------------------------------------------------------------------
// The vertices each block shares with others: (vertex, block) pairs meet at the vertex's rank,
// which tells each block the other blocks of the vertex.
bool vtkRGDecimate::FindSharedVertices(Run& run)
{
  const int size = run.ranks.Size;
  std::vector<std::vector<vtkIdType>> outgoing(static_cast<std::size_t>(size));
  if (!run.ranks.Step("list the blocks' vertices", run.problem,
        [&]()
        {
          for (const Block& block : run.blocks)
          {
            std::vector<vtkIdType> ids;
            for (const Triangle& t : block.Own)
            {
              ids.insert(ids.end(), t.begin(), t.end());
            }
            SortDistinct(ids);
            for (vtkIdType id : ids)
            {
              auto& words = outgoing[static_cast<std::size_t>(id % size)];
              words.push_back(id);
              words.push_back(block.Id);
            }
          }
        }))
  {
    return false;
  }
  const auto pairs = run.ranks.Exchange(std::move(outgoing), Everyone(size), SharedTag);
  std::vector<std::vector<vtkIdType>> answers(static_cast<std::size_t>(size));
  if (!run.ranks.Step("find the shared vertices", run.problem,
        [&]()
        {
          std::vector<std::pair<vtkIdType, vtkIdType>> all; // (vertex, block)
          for (const auto& words : pairs)
          {
            for (std::size_t at = 0; at + 1 < words.size(); at += 2)
            {
              all.emplace_back(words[at], words[at + 1]);
            }
          }
          std::sort(all.begin(), all.end());
          for (std::size_t first = 0, last; first < all.size(); first = last)
          {
            for (last = first + 1; last < all.size() && all[last].first == all[first].first; ++last)
            {
            }
            for (std::size_t i = first; last - first > 1 && i < last; ++i)
            {
              auto& words = answers[run.owner[all[i].second]];
              for (std::size_t j = first; j < last; ++j)
              {
                if (j != i)
                {
                  words.push_back(all[i].second);
                  words.push_back(all[i].first);
                  words.push_back(all[j].second);
                }
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
      for (const auto& words : told)
      {
        for (std::size_t at = 0; at + 2 < words.size(); at += 3)
        {
          Block* block = run.BlockWithId(words[at]);
          if (!block)
          {
            throw std::runtime_error("a shared vertex was reported to the wrong rank");
          }
          block->SharedWith.emplace_back(words[at + 1], words[at + 2]);
        }
      }
      for (Block& block : run.blocks)
      {
        std::sort(block.SharedWith.begin(), block.SharedWith.end());
      }
    });
}

//------------------------------------------------------------------------------
// Each block's triangles around its shared vertices, with their vertices, to the other blocks of
// those vertices; then each block's mesh in local indices.
bool vtkRGDecimate::SendHalos(Run& run)
{
  const int size = run.ranks.Size;
  std::vector<std::vector<vtkIdType>> outgoing(static_cast<std::size_t>(size));
  run.seen.SortUnique();
  if (!run.ranks.Step("send the halos", run.problem,
        [&]()
        {
          // (rank, other block, block, triangle): each halo triangle once per block it goes to.
          std::vector<std::array<vtkIdType, 4>> going;
          for (std::size_t bi = 0; bi < run.blocks.size(); ++bi)
          {
            const Block& block = run.blocks[bi];
            if (block.SharedWith.empty())
            {
              continue;
            }
            for (std::size_t t = 0; t < block.Own.size(); ++t)
            {
              for (vtkIdType id : block.Own[t])
              {
                auto range = std::equal_range(block.SharedWith.begin(), block.SharedWith.end(),
                  std::make_pair(id, vtkIdType(0)),
                  [](const std::pair<vtkIdType, vtkIdType>& a,
                    const std::pair<vtkIdType, vtkIdType>& b) { return a.first < b.first; });
                for (auto it = range.first; it != range.second; ++it)
                {
                  going.push_back({ run.owner[it->second], it->second, static_cast<vtkIdType>(bi),
                    static_cast<vtkIdType>(t) });
                }
              }
            }
          }
          std::sort(going.begin(), going.end());
          going.erase(std::unique(going.begin(), going.end()), going.end());
          for (int r = 0; r < size; ++r)
          {
            auto first = std::lower_bound(going.begin(), going.end(),
              std::array<vtkIdType, 4>{ r, VTK_ID_MIN, VTK_ID_MIN, VTK_ID_MIN });
            auto last = std::lower_bound(going.begin(), going.end(),
              std::array<vtkIdType, 4>{ r + 1, VTK_ID_MIN, VTK_ID_MIN, VTK_ID_MIN });
            WriteTriangles(outgoing[r], static_cast<std::size_t>(last - first), run.seen,
              [&](std::size_t i, vtkIdType& block) -> const Triangle&
              {
                const auto& entry = *(first + static_cast<std::ptrdiff_t>(i));
                block = entry[1];
                return run.blocks[entry[2]].Own[entry[3]];
              });
          }
        }))
  {
    return false;
  }
  auto incoming = run.ranks.Exchange(std::move(outgoing), Everyone(size), HaloTag);
  const std::size_t seenBefore = run.seen.Vertices.size();
  return run.ranks.Step("assemble the blocks", run.problem,
    [&]()
    {
      for (auto& words : incoming)
      {
        ReadTriangles(
          words, &Block::Halo, [&run](vtkIdType id) { return run.BlockWithId(id); }, run.seen);
        std::vector<vtkIdType>().swap(words);
      }
      run.seen.SortUnique(seenBefore);
      rgmc::ParallelFor(static_cast<vtkIdType>(run.blocks.size()), 1,
        [&](vtkIdType first, vtkIdType last)
        {
          for (vtkIdType b = first; b < last; ++b)
          {
            Block& block = run.blocks[b];
            rgmc::DecimationBlock& mesh = block.Mesh;
            for (const auto* list : { &block.Own, &block.Halo })
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
            mesh.Fixed.assign(n, 0);
            for (std::size_t v = 0; v < n; ++v)
            {
              const std::ptrdiff_t at = run.seen.Find(mesh.Ids[v]);
              const Vertex& record = run.seen.Vertices[at];
              std::copy(record.Point, record.Point + 3, mesh.Points.begin() + 3 * v);
              if (run.seen.HasQuadrics)
              {
                mesh.Quadrics[v] = run.seen.Quadrics[at];
              }
            }
            auto local = [&mesh](vtkIdType id)
            {
              return static_cast<int>(
                std::lower_bound(mesh.Ids.begin(), mesh.Ids.end(), id) - mesh.Ids.begin());
            };
            for (const auto& shared : block.SharedWith)
            {
              mesh.Fixed[local(shared.first)] = 1;
            }
            for (const Triangle& t : block.Own)
            {
              mesh.Triangles.push_back({ local(t[0]), local(t[1]), local(t[2]) });
            }
            for (const Triangle& t : block.Halo)
            {
              mesh.Halo.push_back({ local(t[0]), local(t[1]), local(t[2]) });
            }
            std::vector<Triangle>().swap(block.Own);
            std::vector<Triangle>().swap(block.Halo);
            mesh.SortTriangles();
            if (!run.quadrics)
            {
              // Area-weighted unless an error bound is asked for: see MaximumError.
              mesh.AreaWeighted = !(this->MaximumError > 0.0);
              mesh.ComputeQuadrics();
            }
          }
        });
      run.seen.Clear();
    });
}

//------------------------------------------------------------------------------
bool vtkRGDecimate::SimplifyBlocks(Run& run)
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
      rgmc::ParallelFor(static_cast<vtkIdType>(run.blocks.size()), 1,
        [&](vtkIdType first, vtkIdType last)
        {
          for (vtkIdType b = first; b < last; ++b)
          {
            Block& block = run.blocks[b];
            const double share = 4.0 * needed * static_cast<double>(run.blockTriangles[block.Id]) /
              static_cast<double>(run.triangles);
            block.Log = rgmc::Simplify(block.Mesh, maximumError,
              static_cast<std::size_t>(std::ceil(std::min(needed, share))));
          }
        });
    });
}

//------------------------------------------------------------------------------
// How many collapses each block keeps: the cheapest over all blocks, by their level (the largest
// error so far in their block), ties by block and order; then the kept collapses are applied and
// the blocks' triangles become this rank's surface.
bool vtkRGDecimate::KeepCheapest(Run& run, bool all)
{
  Ranks& ranks = run.ranks;
  // Collapses found, and the blocks' vertices, fixed or not.
  vtkIdType local[3] = { 0, 0, 0 }, sums[3] = { 0, 0, 0 };
  for (const Block& block : run.blocks)
  {
    local[0] += static_cast<vtkIdType>(block.Log.size());
    std::vector<char> used(block.Mesh.Ids.size(), 0);
    for (const auto& t : block.Mesh.Triangles)
    {
      used[t[0]] = used[t[1]] = used[t[2]] = 1;
    }
    for (std::size_t v = 0; v < used.size(); ++v)
    {
      local[1] += used[v];
      local[2] += used[v] && block.Mesh.Fixed[v];
    }
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
      auto end = strictly ? std::lower_bound(block.Log.begin(), block.Log.end(), level,
                              [](const rgmc::Collapse& c, double x) { return c.Level < x; })
                          : std::upper_bound(block.Log.begin(), block.Log.end(), level,
                              [](double x, const rgmc::Collapse& c) { return x < c.Level; });
      count += static_cast<vtkIdType>(end - block.Log.begin());
    }
    return count;
  };
  if (found <= needed)
  {
    for (Block& block : run.blocks)
    {
      block.Keep = block.Log.size();
    }
  }
  else
  {
    // The smallest level with at least `needed` collapses at or below it: bisection on the bits
    // of non-negative doubles, which order as their values do.
    std::int64_t low = 0, high = 0x7FF0000000000000; // 0 and +infinity
    while (low < high)
    {
      const std::int64_t middle = low + (high - low) / 2;
      double level;
      std::memcpy(&level, &middle, sizeof level);
      const vtkIdType mine = atMost(level, false);
      vtkIdType all = 0;
      ranks.AllReduce(&mine, &all, 1, vtkCommunicator::SUM_OP, "selecting the threshold");
      if (all >= needed)
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
    std::vector<vtkIdType> all(2 * static_cast<std::size_t>(ranks.Size));
    ranks.AllGather(counts, all.data(), 2, "sharing the counts at the threshold");
    vtkIdType below = 0, earlierAt = 0;
    for (int r = 0; r < ranks.Size; ++r)
    {
      below += all[2 * r];
      earlierAt += r < ranks.Rank ? all[2 * r + 1] : 0;
    }
    vtkIdType atThreshold =
      std::max<vtkIdType>(0, std::min<vtkIdType>(counts[1], needed - below - earlierAt));
    for (Block& block : run.blocks)
    {
      auto lower = std::lower_bound(block.Log.begin(), block.Log.end(), threshold,
        [](const rgmc::Collapse& c, double x) { return c.Level < x; });
      auto upper = std::upper_bound(block.Log.begin(), block.Log.end(), threshold,
        [](double x, const rgmc::Collapse& c) { return x < c.Level; });
      const vtkIdType take = std::min<vtkIdType>(atThreshold, upper - lower);
      block.Keep = static_cast<std::size_t>((lower - block.Log.begin()) + take);
      atThreshold -= take;
    }
  }
  vtkIdType kept = 0;
  double level = 0;
  if (!ranks.Step("apply the collapses", run.problem,
        [&]()
        {
          run.vertices.Clear();
          run.vertices.HasQuadrics = true;
          // The blocks' collapses are replayed in parallel (each block alone); then the new
          // surface and vertex records are sized once, and filled block after block, each
          // block freed as soon as it is copied, so that the largest of these lists is not
          // made twice by growing.
          std::vector<std::vector<char>> used(run.blocks.size());
          rgmc::ParallelFor(static_cast<vtkIdType>(run.blocks.size()), 1,
            [&](vtkIdType first, vtkIdType last)
            {
              for (vtkIdType b = first; b < last; ++b)
              {
                Block& block = run.blocks[b];
                rgmc::ApplyCollapses(block.Mesh, block.Log, block.Keep);
                used[b].assign(block.Mesh.Ids.size(), 0);
                for (const auto& t : block.Mesh.Triangles)
                {
                  used[b][t[0]] = used[b][t[1]] = used[b][t[2]] = 1;
                }
              }
            });
          std::size_t triangles = 0, records = 0;
          for (std::size_t b = 0; b < run.blocks.size(); ++b)
          {
            triangles += run.blocks[b].Mesh.Triangles.size();
            records += static_cast<std::size_t>(std::count(used[b].begin(), used[b].end(), 1));
          }
          run.surface.reserve(triangles);
          run.vertices.Reserve(records);
          for (std::size_t b = 0; b < run.blocks.size(); ++b)
          {
            Block& block = run.blocks[b];
            kept += static_cast<vtkIdType>(block.Keep);
            if (block.Keep > 0)
            {
              level = std::max(level, block.Log[block.Keep - 1].Level);
            }
            const rgmc::DecimationBlock& mesh = block.Mesh;
            for (const auto& t : mesh.Triangles)
            {
              run.surface.push_back({ mesh.Ids[t[0]], mesh.Ids[t[1]], mesh.Ids[t[2]] });
            }
            for (std::size_t v = 0; v < used[b].size(); ++v)
            {
              if (used[b][v])
              {
                Vertex record;
                record.Id = mesh.Ids[v];
                std::copy(&mesh.Points[3 * v], &mesh.Points[3 * v] + 3, record.Point);
                run.vertices.Add(record, &mesh.Quadrics[v]);
              }
            }
            block = Block{ block.Id, {}, {}, {}, {}, {}, 0 };
            std::vector<char>().swap(used[b]);
          }
          run.vertices.SortUnique();
          run.blocks.clear();
          run.quadrics = true;
        }))
  {
    return false;
  }
  const vtkIdType mine[2] = { static_cast<vtkIdType>(run.surface.size()), kept };
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
          const vtkIdType n = static_cast<vtkIdType>(run.vertices.Vertices.size());
          points->SetNumberOfPoints(n);
          vtkNew<vtkIdTypeArray> ids;
          ids->SetName("DecimatedVertexIds");
          rgmc::Allocate(ids.Get(), n);
          for (vtkIdType v = 0; v < n; ++v)
          {
            points->SetPoint(v, run.vertices.Vertices[v].Point);
            ids->SetValue(v, run.vertices.Vertices[v].Id);
          }
          vtkNew<vtkIdTypeArray> connectivity, offsets;
          const vtkIdType t = static_cast<vtkIdType>(run.surface.size());
          vtkIdType* c = rgmc::Allocate(connectivity.Get(), 3 * t);
          vtkIdType* o = rgmc::Allocate(offsets.Get(), t + 1);
          for (vtkIdType i = 0; i < t; ++i)
          {
            o[i] = 3 * i;
            for (int k = 0; k < 3; ++k)
            {
              const vtkIdType id = run.surface[i][k];
              c[3 * i + k] = run.vertices.Find(id);
            }
          }
          o[t] = 3 * t;
          vtkNew<vtkCellArray> polys;
          polys->SetData(offsets, connectivity);
          piece->SetPoints(points);
          piece->SetPolys(polys);
          piece->GetPointData()->SetGlobalIds(ids);
          piece->GetFieldData()->PassData(run.input->GetFieldData());
          std::vector<Triangle>().swap(run.surface);
          run.vertices.Clear();
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
  os << indent << "Controller: " << this->Controller << "\n";
  os << indent << "NumberOfCollectives: " << this->NumberOfCollectives << "\n";
}

// vtkRGDecimate: quadric-error decimation in independent blocks, distributed over the ranks by a
// grid that depends on the surface alone (see the header for the scheme).
#include "vtkRGDecimate.h"
#include "rgmcDecimateBlocks.h"
#include "rgmcDecimateDistance.h"
#include "rgmcDecimateMessages.h"
#include "rgmcDecimateParts.h"
#include "rgmcDecimateShared.h"
#include "rgmcDecimation.h"
#include "rgmcRadixSort.h"
#include "vtkRGArrays.h"
#include "vtkRGCollective.h"
#include "vtkRGCompatibility.h"
#include "vtkRGParallel.h"
#include "vtkRGRunController.h"
#include "vtkRGSeamRepair.h"
#include "vtkRGSpan.h"

#include "vtkCellArray.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkExecutive.h"
#include "vtkFieldData.h"
#include "vtkIdTypeArray.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkLogger.h"
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
using namespace rgmc::decimate;

constexpr int MaximumBlocksPerAxis = 32;
// The grid's offsets, in blocks, in the passes: each pass frees what the ones before left fixed.
constexpr double PassOffsets[] = { 0.0, 0.5, 0.25, 0.75, 0.125, 0.625, 0.375, 0.875 };
constexpr int MaximumPasses = 16;
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

/// After a wave or a pass, whose blocks and messages are freed: a part made in waves (more than
/// TrianglesPerWave triangles, where memory is what the waves are for) gives their pages back,
/// so that the next one's do not come on top of them (glibc keeps freed memory, the threads'
/// arenas most of all). Otherwise the next pass, smaller, reuses them: trimmed, they were
/// faulted in again (the 512^3 skull on 2 threads: 2.84-3.39 -> 2.46-2.90 s, the same peak).
void ReleaseFreeMemoryInWaves(int waves)
{
  if (waves > 1)
  {
    ReleaseFreeMemory();
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
    : Ranks(controller)
    , Input(input)
  {
  }
  rgmc::Ranks Ranks;
  std::string Problem;
  vtkPolyData* Input;
  vtkIdType InputTriangles = 0; // over all ranks
  vtkIdType Triangles = 0;      // now, over all ranks
  vtkIdType Target = 0;         // the triangles to keep
  double Lower[3], Upper[3];    // the global bounds
  SurfacePart Part;             // this rank's part of the surface at the start of the pass
  BlockGrid Grid;
  std::vector<vtkIdType> BlockTriangles; // per block of the grid, over all ranks
  std::vector<int> Owner;                // per block
  std::vector<int> WaveOf;               // per block: the wave of its rank's blocks it is in
  int Waves = 1;                         // on every rank, the same number
  std::vector<std::int32_t> PartBlock;   // the block of each of the part's triangles
  // The blocks of the part's vertices that are in several blocks: those of vertex v are
  // SharedBlocks[SharedFirst[v]] to SharedBlocks[SharedFirst[v + 1] - 1] (none for the others).
  std::vector<std::uint32_t> SharedFirst;
  std::vector<std::int32_t> SharedBlocks;
  std::vector<Block> Blocks;   // this rank's, by increasing id, so by wave
  std::vector<Sendings> Going; // per rank: the wave's triangles for its blocks (ListSendings)
  vtkIdType Collapses = 0;     // made in the last pass, over all ranks
  int Passes = 0;
  double MaximumLevel = 0; // the largest quadric error kept, over all ranks

  /// This rank's blocks of `wave` (contiguous: blocks are in wave order).
  std::pair<std::vector<Block>::iterator, std::vector<Block>::iterator> BlocksOfWave(int wave)
  {
    return std::equal_range(this->Blocks.begin(), this->Blocks.end(), wave,
      [](const auto& a, const auto& b) { return WaveKey(a) < WaveKey(b); });
  }
  static int WaveKey(const Block& b) { return b.Wave; }
  static int WaveKey(int wave) { return wave; }
};

//------------------------------------------------------------------------------
// The collective schedule: every rank runs these passes in this order and makes the same
// collective calls ("exchange" is Ranks::Exchange with every rank; a step is local work, named
// by its method, then an agreement).
//
//  PASS 0 CheckInput          agreement (properties, triangles, ids, finite points)
//  PASS 1 ReadSurface         step ReadPartBounds, AllReduce (bounds), AllReduce (triangles),
//                             agreement
//  then, for each of up to 16 passes while the target is not reached and collapses are made:
//  PASS 2 PlaceBlocks         step CountBlockTriangles, AllReduce (triangles per block),
//                             AssignBlocks, agreement
//  PASS 3 FindSharedVertices  step ListVertexBlocks, exchange, step AnswerSharedVertices,
//                             exchange, step RecordSharedVertices
//  then for each wave (one, or as many as PlaceBlocks sets, the same number on every rank):
//  PASS 4 SendTriangles       step SendTrianglesToBlocks, exchange, step AssembleBlocks
//  PASS 5 SimplifyBlocks      step (SimplifyBlock on each block)
//  then:
//  PASS 6 KeepCheapest        AllReduce (collapses found, free and fixed vertices); when more
//                             are found than needed, SelectThreshold: one AllReduce per
//                             bisection step (the same number on every rank: they see the same
//                             sums), and KeepUpToThreshold: an AllGather
//  PASS 7 ApplyCollapses      with one wave: step (CollapsedBlocks::Apply); with several, for
//                             each wave SendTriangles's schedule, then that step; then step
//                             (the blocks become the part), AllReduce (triangles, collapses),
//                             AllReduce (error), agreement
//  PASS 8 NumberSurface       step BuildDecimatedPiece; vtkRGSeamRepair's own schedule (no
//                             smoothing)
//  PASS 9 (ComputeDistance)   rgmc::DecimationDistance's schedule (rgmcDecimateDistance.h): its
//                             collectives depend on counts every rank has agreed
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
    ~Accounting() { this->Filter->NumberOfCollectives += this->Counted.Ranks.Collectives; }
  } accounting{ this, run };
  auto fail = [this, &run, output]()
  {
    vtkErrorMacro(<< "Cannot decimate: " << run.Problem << ".");
    output->Initialize();
    return 0;
  };

  // PASS 0-1: a numbered triangle mesh, read in place.
  if (!this->CheckInput(run) || !this->ReadSurface(run))
  {
    return fail();
  }
  this->UpdateProgress(0.05);
  for (int pass = 0; pass < MaximumPasses && run.Triangles > run.Target; ++pass)
  {
    // PASS 2-7: one pass of block simplification, its blocks made and simplified in waves.
    if (!this->PlaceBlocks(run, pass) || !this->FindSharedVertices(run))
    {
      return fail();
    }
    for (int wave = 0; wave < run.Waves; ++wave)
    {
      if (!this->SendTriangles(run, wave) || !this->SimplifyBlocks(run, wave))
      {
        return fail();
      }
      ReleaseFreeMemoryInWaves(run.Waves); // the wave's meshes and messages
    }
    if (!this->KeepCheapest(run, pass >= AllFromPass) || !this->ApplyCollapses(run))
    {
      return fail();
    }
    run.Passes = pass + 1;
    rgmc::SpanMark("release memory");
    ReleaseFreeMemoryInWaves(run.Waves); // the pass's blocks and messages
    this->UpdateProgress(0.05 + 0.8 * (pass + 1) / MaximumPasses);
    if (run.Collapses == 0)
    {
      break;
    }
  }
  // PASS 8-9: one mesh again, with normals, checks and measures; the distance to the input.
  if (!this->NumberSurface(run, output))
  {
    return fail();
  }
  if (run.Ranks.Rank == 0)
  {
    vtkLogF(INFO,
      "Decimate: %lld -> %lld triangles (target %lld) in %d passes, largest quadric "
      "error %.6g.",
      static_cast<long long>(run.InputTriangles), static_cast<long long>(run.Triangles),
      static_cast<long long>(run.Target), run.Passes, std::sqrt(run.MaximumLevel));
  }
  this->UpdateProgress(1.0);
  return 1;
}

//------------------------------------------------------------------------------
bool vtkRGDecimate::CheckInput(Run& run)
{
  rgmc::SpanMark("read surface");
  vtkPolyData* input = run.Input;
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
    problem << "rank " << run.Ranks.Rank
            << " has points without global point ids (apply Seam Repair first: it numbers the "
               "surface as one mesh)";
  }
  else
  {
    vtkDataArray* points = input->GetPoints() ? input->GetPoints()->GetData() : nullptr;
    const vtkIdType bad = points ? rgmc::FirstNotFinite(points) : -1;
    if (bad >= 0)
    {
      problem << "point " << bad / 3 << " on rank " << run.Ranks.Rank
              << " has a coordinate that is not a finite number";
    }
  }
  run.Problem = problem.str();
  return run.Ranks.Agree(run.Problem.empty(), run.Problem);
}

//------------------------------------------------------------------------------
bool vtkRGDecimate::ReadSurface(Run& run)
{
  double mine[6] = { VTK_DOUBLE_MAX, VTK_DOUBLE_MAX, VTK_DOUBLE_MAX, VTK_DOUBLE_MAX, VTK_DOUBLE_MAX,
    VTK_DOUBLE_MAX };
  if (!run.Ranks.Step("read the surface", run.Problem, [&]() { this->ReadPartBounds(run, mine); }))
  {
    return false;
  }
  double all[6];
  run.Ranks.AllReduce(mine, all, 6, vtkCommunicator::MIN_OP, "reducing the bounds");
  const vtkIdType local = static_cast<vtkIdType>(run.Part.NumberOfTriangles());
  run.Ranks.AllReduce(
    &local, &run.InputTriangles, 1, vtkCommunicator::SUM_OP, "counting the triangles");
  for (int a = 0; a < 3; ++a)
  {
    run.Lower[a] = all[a];
    run.Upper[a] = -all[3 + a];
  }
  run.Triangles = run.InputTriangles;
  run.Target = run.InputTriangles -
    static_cast<vtkIdType>(std::llround(this->TargetReduction * run.InputTriangles));
  if (run.Problem.empty() && run.InputTriangles == 0)
  {
    run.Problem = "the input has no triangles";
  }
  return run.Ranks.Agree(run.Problem.empty(), run.Problem);
}

//------------------------------------------------------------------------------
// The input read in place as this rank's part, and the bounds of its triangles' vertices in one
// reduction's form: the minima, then the maxima as negated minima.
void vtkRGDecimate::ReadPartBounds(Run& run, double bounds[6])
{
  SurfacePart& part = run.Part;
  part.Read(run.Input);
  // Over the triangles' corners (a vertex met again changes nothing), in fixed chunks on
  // threads, then in chunk order: minima are exact in any order.
  const vtkIdType n = static_cast<vtkIdType>(part.NumberOfTriangles());
  const vtkIdType chunk = rgmc::ElementChunk;
  std::vector<std::array<double, 6>> found(static_cast<std::size_t>(rgmc::ChunksOf(n, chunk)));
  rgmc::ForEachChunk(n, chunk,
    [&](vtkIdType c, vtkIdType begin, vtkIdType end)
    {
      std::array<double, 6>& box = found[static_cast<std::size_t>(c)];
      std::copy(bounds, bounds + 6, box.begin());
      for (vtkIdType t = begin; t < end; ++t)
      {
        vtkIdType corners[3];
        part.Corners(static_cast<std::size_t>(t), corners);
        for (vtkIdType v : corners)
        {
          double p[3];
          part.Point(v, p);
          for (int a = 0; a < 3; ++a)
          {
            box[a] = std::min(box[a], p[a]);
            box[3 + a] = std::min(box[3 + a], -p[a]);
          }
        }
      }
    });
  for (const std::array<double, 6>& box : found)
  {
    for (int k = 0; k < 6; ++k)
    {
      bounds[k] = std::min(bounds[k], box[k]);
    }
  }
}

//------------------------------------------------------------------------------
// The grid (from the global bounds and triangle count, the same in every pass but for its
// offset), the triangles of each block over all ranks, the blocks' ranks and waves.
bool vtkRGDecimate::PlaceBlocks(Run& run, int pass)
{
  rgmc::SpanMark("place blocks");
  BlockGrid& grid = run.Grid;
  double longest = 0;
  for (int a = 0; a < 3; ++a)
  {
    longest = std::max(longest, run.Upper[a] - run.Lower[a]);
    grid.Origin[a] = run.Lower[a];
  }
  const int perAxis = static_cast<int>(std::min<double>(MaximumBlocksPerAxis,
    std::max(
      1.0, std::ceil(std::sqrt(static_cast<double>(run.Triangles) / this->TrianglesPerBlock)))));
  grid.Size = longest > 0 ? longest / perAxis : 1.0;
  for (int a = 0; a < 3; ++a)
  {
    grid.Dims[a] = static_cast<int>(std::floor((run.Upper[a] - run.Lower[a]) / grid.Size)) + 2;
  }
  grid.Offset = PassOffsets[pass % (sizeof PassOffsets / sizeof PassOffsets[0])];
  std::vector<vtkIdType> mine;
  if (!run.Ranks.Step("count the triangles of the blocks", run.Problem,
        [&]() { this->CountBlockTriangles(run, mine); }))
  {
    return false;
  }
  run.Ranks.AllReduce(mine.data(), run.BlockTriangles.data(), static_cast<vtkIdType>(mine.size()),
    vtkCommunicator::SUM_OP, "counting the blocks' triangles");
  rgmc::SpanMark("place blocks: assign");
  this->AssignBlocks(run);
  return run.Ranks.Agree(run.Problem.empty(), run.Problem);
}

//------------------------------------------------------------------------------
// The block of each of the part's triangles (that of its lowest-numbered vertex), and how many
// of them each block of the grid has on this rank.
void vtkRGDecimate::CountBlockTriangles(Run& run, std::vector<vtkIdType>& counts)
{
  const SurfacePart& part = run.Part;
  const BlockGrid& grid = run.Grid;
  const vtkIdType n = static_cast<vtkIdType>(part.NumberOfTriangles());
  run.PartBlock.resize(static_cast<std::size_t>(n));
  // The blocks on threads, in fixed chunks of triangles; the counts after, in order.
  rgmc::ForEachChunk(n, rgmc::ElementChunk,
    [&](vtkIdType, vtkIdType begin, vtkIdType end)
    {
      for (vtkIdType t = begin; t < end; ++t)
      {
        vtkIdType c[3];
        part.Corners(static_cast<std::size_t>(t), c);
        vtkIdType lowest = c[0];
        for (int k = 1; k < 3; ++k)
        {
          lowest = part.Id(c[k]) < part.Id(lowest) ? c[k] : lowest;
        }
        double p[3];
        part.Point(lowest, p);
        run.PartBlock[t] = static_cast<std::int32_t>(grid.BlockOf(p));
      }
    });
  counts.assign(static_cast<std::size_t>(grid.Count()), 0);
  for (std::int32_t block : run.PartBlock)
  {
    ++counts[block];
  }
  run.BlockTriangles.assign(counts.size(), 0);
}

//------------------------------------------------------------------------------
// The blocks' ranks and waves, from the global counts alone, so the same on every rank; and
// this rank's blocks.
void vtkRGDecimate::AssignBlocks(Run& run)
{
  // Contiguous ranges of blocks, of about equal triangle counts, rank after rank: the blocks'
  // order is then the ranks' order, and the output's triangles are in block order whatever
  // the number of ranks.
  const int size = run.Ranks.Size;
  run.Owner.assign(run.BlockTriangles.size(), 0);
  std::vector<vtkIdType> ofRank(static_cast<std::size_t>(size), 0);
  vtkIdType before = 0;
  const vtkIdType total = std::max<vtkIdType>(1, run.Triangles);
  for (std::size_t b = 0; b < run.BlockTriangles.size(); ++b)
  {
    const vtkIdType count = run.BlockTriangles[b];
    run.Owner[b] =
      static_cast<int>(std::min<vtkIdType>(size - 1, (2 * before + count) * size / (2 * total)));
    before += count;
    ofRank[run.Owner[b]] += count;
  }
  // Waves: a rank whose blocks hold more than TrianglesPerWave triangles makes them in waves
  // of contiguous blocks, at least 16, so that it holds one wave's blocks at a time. Every rank
  // computes the same number from the global counts; it never changes the result.
  const vtkIdType largest = *std::max_element(ofRank.begin(), ofRank.end());
  run.Waves = largest <= this->TrianglesPerWave
    ? 1
    : static_cast<int>(
        std::max<vtkIdType>(16, (largest + this->TrianglesPerWave - 1) / this->TrianglesPerWave));
  run.WaveOf.assign(run.BlockTriangles.size(), 0);
  std::vector<vtkIdType> earlier(static_cast<std::size_t>(size), 0);
  run.Blocks.clear();
  for (std::size_t b = 0; b < run.BlockTriangles.size(); ++b)
  {
    const int r = run.Owner[b];
    const vtkIdType count = run.BlockTriangles[b];
    run.WaveOf[b] = static_cast<int>(std::min<vtkIdType>(run.Waves - 1,
      (2 * earlier[r] + count) * run.Waves / (2 * std::max<vtkIdType>(1, ofRank[r]))));
    earlier[r] += count;
    if (count > 0 && r == run.Ranks.Rank)
    {
      run.Blocks.emplace_back();
      run.Blocks.back().Id = static_cast<vtkIdType>(b);
      run.Blocks.back().Wave = run.WaveOf[b];
    }
  }
}

//------------------------------------------------------------------------------
// The part's vertices that lie in several blocks, with all their blocks: (vertex, block) pairs
// meet at the vertex's rank (its id modulo the ranks), which tells each rank that sent one the
// blocks of each vertex in more than one.
bool vtkRGDecimate::FindSharedVertices(Run& run)
{
  rgmc::SpanMark("place blocks: shared vertices");
  const int size = run.Ranks.Size;
  Messages outgoing(static_cast<std::size_t>(size));
  if (!run.Ranks.Step(
        "list the vertices' blocks", run.Problem, [&]() { this->ListVertexBlocks(run, outgoing); }))
  {
    return false;
  }
  auto asked = run.Ranks.Exchange(std::move(outgoing), Everyone(size), SharedTag);
  Messages answers(static_cast<std::size_t>(size));
  if (!run.Ranks.Step("find the shared vertices", run.Problem,
        [&]() { this->AnswerSharedVertices(run, asked, answers); }))
  {
    return false;
  }
  const auto told = run.Ranks.Exchange(std::move(answers), Everyone(size), AnswersTag);
  return run.Ranks.Step(
    "record the shared vertices", run.Problem, [&]() { this->RecordSharedVertices(run, told); });
}

//------------------------------------------------------------------------------
// (vertex id, vertex, block) for each block of each of the part's vertices, to the vertex's
// rank (rgmcDecimateShared.h).
void vtkRGDecimate::ListVertexBlocks(Run& run, Messages& outgoing)
{
  const LowestBlocks lowest(run.Part, run.PartBlock);
  WriteVertexBlocks(run.Part, lowest, OtherBlocks(run.Part, run.PartBlock, lowest), outgoing);
}

//------------------------------------------------------------------------------
// At the vertices' rank: to each rank that asked about a vertex in several blocks, (its index
// of the vertex, block) for each of them.
void vtkRGDecimate::AnswerSharedVertices(Run&, Messages& asked, Messages& answers)
{
  rgmc::decimate::AnswerSharedVertices(AskedRecords(asked), answers);
}

//------------------------------------------------------------------------------
// The answers as the part's shared-vertex lists (SharedFirst, SharedBlocks).
void vtkRGDecimate::RecordSharedVertices(Run& run, const Messages& told)
{
  std::vector<std::pair<vtkIdType, vtkIdType>> shared; // (vertex, block)
  for (const auto& words : told)
  {
    for (std::size_t at = 0; at + 1 < words.size(); at += 2)
    {
      shared.emplace_back(words[at], words[at + 1]);
    }
  }
  rgmc::ParallelSort(shared); // equal pairs are the same pair: any order of them will do
  shared.erase(std::unique(shared.begin(), shared.end()), shared.end());
  run.SharedFirst.assign(run.Part.NumberOfVertices() + 1, 0);
  run.SharedBlocks.resize(shared.size());
  for (std::size_t i = 0; i < shared.size(); ++i)
  {
    ++run.SharedFirst[shared[i].first + 1];
    run.SharedBlocks[i] = static_cast<std::int32_t>(shared[i].second);
  }
  for (std::size_t v = 1; v < run.SharedFirst.size(); ++v)
  {
    run.SharedFirst[v] += run.SharedFirst[v - 1];
  }
}

//------------------------------------------------------------------------------
// The wave's blocks: each triangle of the part to the rank of its block, if that block is in
// the wave, and to the blocks of the wave that share one of its vertices (their halo), with the
// vertices' records; then each block's mesh in local indices.
bool vtkRGDecimate::SendTriangles(Run& run, int wave)
{
  rgmc::SpanMark("send triangles");
  const int size = run.Ranks.Size;
  Messages outgoing(static_cast<std::size_t>(size));
  if (!run.Ranks.Step("send the triangles to their blocks", run.Problem,
        [&]() { this->SendTrianglesToBlocks(run, wave, outgoing); }))
  {
    return false;
  }
  auto incoming = run.Ranks.Exchange(std::move(outgoing), Everyone(size), TrianglesTag);
  return run.Ranks.Step(
    "assemble the blocks", run.Problem, [&]() { this->AssembleBlocks(run, wave, incoming); });
}

//------------------------------------------------------------------------------
// The messages of the part's triangles to the ranks of the wave's blocks (ListSendings); what
// goes to this rank's own blocks stays in run.Going for AssembleBlocks, with no message.
void vtkRGDecimate::SendTrianglesToBlocks(Run& run, int wave, Messages& outgoing)
{
  const TriangleRoutes routes{ run.PartBlock.data(), run.WaveOf.data(), run.Owner.data(),
    run.SharedFirst.data(), run.SharedBlocks.data() };
  run.Going = ListSendings(run.Part, routes, wave, run.Ranks.Size);
  for (int r = 0; r < run.Ranks.Size; ++r)
  {
    if (r != run.Ranks.Rank)
    {
      WriteTriangles(outgoing[r], run.Going[r], run.Part);
      Sendings().swap(run.Going[r]);
    }
  }
}

//------------------------------------------------------------------------------
// The triangles received, and this rank's own for its blocks, made into the wave's blocks'
// meshes (threads over blocks).
void vtkRGDecimate::AssembleBlocks(Run& run, int wave, Messages& incoming)
{
  VertexTable seen; // the vertices of the wave's blocks' triangles
  seen.HasQuadrics = run.Part.HasQuadrics();
  for (int r = 0; r < run.Ranks.Size; ++r) // in rank order, as the blocks' lists must be
  {
    if (r == run.Ranks.Rank)
    {
      KeepTriangles(run.Going[r], run.Part, run.Blocks, seen);
      Sendings().swap(run.Going[r]);
      continue;
    }
    ReadTriangles(incoming[r], run.Blocks, seen);
    std::vector<vtkIdType>().swap(incoming[r]); // read: its memory goes back at once
  }
  seen.SortDistinct();
  // Area-weighted unless an error bound is asked for: see MaximumError.
  const bool areaWeighted = !(this->MaximumError > 0.0);
  const auto blocks = run.BlocksOfWave(wave);
  const auto first = blocks.first, last = blocks.second;
  rgmc::ParallelFor(static_cast<vtkIdType>(last - first), 1,
    [&](vtkIdType from, vtkIdType to)
    {
      for (auto block = first + from; block != first + to; ++block)
      {
        AssembleMesh(*block, seen, areaWeighted);
      }
    });
}

//------------------------------------------------------------------------------
// The wave's blocks simplified (threads over blocks). With several waves, only the collapses'
// levels are kept: ApplyCollapses makes the blocks again.
bool vtkRGDecimate::SimplifyBlocks(Run& run, int wave)
{
  rgmc::SpanMark("simplify blocks");
  const double maximumError = this->MaximumError;
  // No block needs more collapses than the whole surface still needs; and a block is stopped at
  // four times its share of them (a rule of global counts only, so the same on any ranks): the
  // passes after the first need few collapses, and would otherwise simplify every block as far
  // as it goes to keep a handful.
  const double needed = 0.5 * static_cast<double>(run.Triangles - run.Target);
  return run.Ranks.Step("simplify the blocks", run.Problem,
    [&]()
    {
      const auto blocks = run.BlocksOfWave(wave);
      rgmc::ParallelFor(static_cast<vtkIdType>(blocks.second - blocks.first), 1,
        [&](vtkIdType first, vtkIdType last)
        {
          for (vtkIdType b = first; b < last; ++b)
          {
            Block& block = blocks.first[b];
            const double share = 4.0 * needed * static_cast<double>(run.BlockTriangles[block.Id]) /
              static_cast<double>(run.Triangles);
            SimplifyBlock(block, maximumError,
              static_cast<std::size_t>(std::ceil(std::min(needed, share))), run.Waves > 1);
          }
        });
    });
}

//------------------------------------------------------------------------------
// How many collapses each block keeps: the cheapest over all blocks, by their level (the largest
// error so far in their block), ties by block and order.
bool vtkRGDecimate::KeepCheapest(Run& run, bool all)
{
  rgmc::SpanMark("keep cheapest");
  // Collapses found, and the blocks' vertices, fixed or not.
  vtkIdType local[3] = { 0, 0, 0 }, sums[3] = { 0, 0, 0 };
  for (const Block& block : run.Blocks)
  {
    local[0] += static_cast<vtkIdType>(block.Levels.size());
    local[1] += static_cast<vtkIdType>(block.Vertices);
    local[2] += static_cast<vtkIdType>(block.Fixed);
  }
  run.Ranks.AllReduce(local, sums, 3, vtkCommunicator::SUM_OP, "counting the collapses");
  const vtkIdType found = sums[0];
  // Greedy decimation of the whole surface would also collapse edges among the vertices fixed in
  // this pass: a pass that is not the last makes only the free vertices' share of what is
  // needed, so that it does not decimate the blocks' insides further than the whole surface
  // will be (the next passes free the rest).
  vtkIdType needed = (run.Triangles - run.Target + 1) / 2;
  // The last few (5% of the triangles or less) are made at once.
  if (!all && 2 * needed > run.Triangles / 20 && sums[1] > 0)
  {
    needed = static_cast<vtkIdType>(
      std::ceil(static_cast<double>(needed) * static_cast<double>(sums[1] - sums[2]) / sums[1]));
  }
  if (found <= needed)
  {
    for (Block& block : run.Blocks)
    {
      block.Keep = block.Levels.size();
    }
    return true;
  }
  const double threshold = this->SelectThreshold(run, needed);
  this->KeepUpToThreshold(run, threshold, needed);
  return true;
}

//------------------------------------------------------------------------------
// The smallest level with at least `needed` collapses at or below it over all ranks: bisection
// on the bits of non-negative doubles, which order as their values do.
double vtkRGDecimate::SelectThreshold(Run& run, vtkIdType needed)
{
  std::int64_t low = 0, high = 0x7FF0000000000000; // 0 and +infinity
  while (low < high)
  {
    const std::int64_t middle = low + (high - low) / 2;
    double level;
    std::memcpy(&level, &middle, sizeof level);
    const vtkIdType mine = CollapsesUpTo(run.Blocks, level, false);
    vtkIdType sum = 0;
    run.Ranks.AllReduce(&mine, &sum, 1, vtkCommunicator::SUM_OP, "selecting the threshold");
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
  return threshold;
}

//------------------------------------------------------------------------------
// Each block keeps all its collapses below the threshold; at it, the first ones in block order
// over the ranks, up to `needed` in all.
void vtkRGDecimate::KeepUpToThreshold(Run& run, double threshold, vtkIdType needed)
{
  Ranks& ranks = run.Ranks;
  const vtkIdType counts[2] = { CollapsesUpTo(run.Blocks, threshold, true),
    CollapsesUpTo(run.Blocks, threshold, false) - CollapsesUpTo(run.Blocks, threshold, true) };
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
  for (Block& block : run.Blocks)
  {
    auto lower = std::lower_bound(block.Levels.begin(), block.Levels.end(), threshold);
    auto upper = std::upper_bound(block.Levels.begin(), block.Levels.end(), threshold);
    const vtkIdType take = std::min<vtkIdType>(atThreshold, upper - lower);
    block.Keep = static_cast<std::size_t>((lower - block.Levels.begin()) + take);
    atThreshold -= take;
  }
}

//------------------------------------------------------------------------------
// The kept collapses applied, and the blocks' triangles, in block order, become this rank's
// part. With several waves each wave's blocks are made again (the same content, so the same
// collapses) and simplified as far as they keep.
bool vtkRGDecimate::ApplyCollapses(Run& run)
{
  rgmc::SpanMark("apply collapses");
  Ranks& ranks = run.Ranks;
  CollapsedBlocks collapsed;
  // Sized once from the counts (each collapse removes two of a block's own triangles), so that
  // the largest of these lists is not made twice by growing.
  for (const Block& block : run.Blocks)
  {
    const std::size_t own = static_cast<std::size_t>(run.BlockTriangles[block.Id]);
    collapsed.Expected += own - std::min(own, 2 * block.Keep);
  }
  const double maximumError = this->MaximumError;
  if (run.Waves == 1)
  {
    if (!ranks.Step("apply the collapses", run.Problem,
          [&]() { collapsed.Apply(run.Blocks.begin(), run.Blocks.end(), false, maximumError); }))
    {
      return false;
    }
  }
  else
  {
    for (int wave = 0; wave < run.Waves; ++wave)
    {
      if (!this->SendTriangles(run, wave) ||
        !ranks.Step("apply the collapses", run.Problem,
          [&]()
          {
            const auto blocks = run.BlocksOfWave(wave);
            const auto first = blocks.first, last = blocks.second;
            collapsed.Apply(first, last, true, maximumError);
          }))
      {
        return false;
      }
      ReleaseFreeMemory();
    }
  }
  rgmc::SpanMark("apply collapses: free blocks");
  if (!ranks.Step("make the blocks the part", run.Problem,
        [&]()
        {
          run.Blocks.clear();
          std::vector<std::int32_t>().swap(run.PartBlock);
          std::vector<std::uint32_t>().swap(run.SharedFirst);
          std::vector<std::int32_t>().swap(run.SharedBlocks);
          rgmc::SpanMark("apply collapses: adopt");
          run.Part.Adopt(collapsed.Surface, collapsed.Vertices);
        }))
  {
    return false;
  }
  const vtkIdType mine[2] = { static_cast<vtkIdType>(run.Part.NumberOfTriangles()),
    collapsed.Kept };
  vtkIdType after[2] = { 0, 0 };
  ranks.AllReduce(mine, after, 2, vtkCommunicator::SUM_OP, "counting the triangles");
  double largest = 0;
  ranks.AllReduce(&collapsed.Level, &largest, 1, vtkCommunicator::MAX_OP, "reducing the error");
  run.Triangles = after[0];
  run.Collapses = after[1];
  run.MaximumLevel = std::max(run.MaximumLevel, largest);
  return ranks.Agree(run.Problem.empty(), run.Problem);
}

//------------------------------------------------------------------------------
// This rank's triangles as a piece keyed by the surviving vertices' global ids, numbered as one
// mesh by vtkRGSeamRepair (no smoothing): contiguous global ids, owners, normals, checks and
// measures.
bool vtkRGDecimate::NumberSurface(Run& run, vtkPolyData* output)
{
  rgmc::SpanMark("decimated piece");
  vtkNew<vtkPolyData> piece;
  if (!run.Ranks.Step(
        "build the decimated piece", run.Problem, [&]() { this->BuildDecimatedPiece(run, piece); }))
  {
    return false;
  }
  vtkNew<vtkRGSeamRepair> numbering;
  int ok = 0;
  {
    // The numbering's phases in a work/span profile, until its run ends (not the report's).
    rgmc::SpanPrefix phases("numbering: ", "after numbering");
    numbering->SetController(run.Ranks.Controller());
    numbering->SetSmoothingMethod(vtkRGSeamRepair::NO_SMOOTHING);
    numbering->SetInputData(piece);
    ok = numbering->GetExecutive()->Update();
  }
  this->NumberOfCollectives += numbering->GetNumberOfCollectives();
  if (!ok)
  {
    run.Problem = "numbering the decimated surface failed";
    return false;
  }
  output->ShallowCopy(numbering->GetOutput());
  output->GetPointData()->RemoveArray("DecimatedVertexIds");
  // The measures before decimation, where the input had them; Seam Repair's "before
  // smoothing" ones are the input's too.
  vtkFieldData* fd = output->GetFieldData();
  vtkFieldData* in = run.Input->GetFieldData();
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
  add("TrianglesBeforeDecimation", static_cast<double>(run.InputTriangles));
  add("DecimationQuadricError", std::sqrt(run.MaximumLevel));
  // PASS 9: the distance from the input surface, where the triangles are.
  return !this->ComputeDistance ||
    rgmc::ReportDecimationDistance(run.Ranks, run.Input, output, run.Problem);
}

//------------------------------------------------------------------------------
// The part (or the input, when no pass ran) as a polydata of points, triangles and the
// vertices' global ids, with the input's field data.
void vtkRGDecimate::BuildDecimatedPiece(Run& run, vtkPolyData* piece)
{
  vtkNew<vtkPoints> points;
  if (run.Input->GetPoints())
  {
    points->SetDataType(run.Input->GetPoints()->GetDataType());
  }
  SurfacePart& part = run.Part;
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
  piece->GetFieldData()->PassData(run.Input->GetFieldData());
  part.Clear();
}
//------------------------------------------------------------------------------
void vtkRGDecimate::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "TargetReduction: " << this->TargetReduction << "\n";
  os << indent << "MaximumError: " << this->MaximumError << "\n";
  os << indent << "ComputeDistance: " << this->ComputeDistance << "\n";
  os << indent << "TrianglesPerBlock: " << this->TrianglesPerBlock << "\n";
  os << indent << "TrianglesPerWave: " << this->TrianglesPerWave << "\n";
  os << indent << "Controller: " << this->Controller << "\n";
  os << indent << "NumberOfCollectives: " << this->NumberOfCollectives << "\n";
}

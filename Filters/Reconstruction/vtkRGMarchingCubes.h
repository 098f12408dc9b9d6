/**
 * @class   vtkRGMarchingCubes
 * @brief   seeded, distributed region-growing marching cubes: the surface of one structure
 *
 * vtkRGMarchingCubes extracts the isosurface of a scalar volume (vtkImageData) that passes
 * nearest to one or more seed points: the skull, a femur, a forearm bone in a CT, picked with one
 * click. Instead of visiting every cube as marching cubes does, it grows from the seed's cube
 * through the cubes the surface passes through, so its cost follows the size of the extracted
 * surface, not of the volume (regional growth marching cubes; Wei, Bao, Pang and Cui, "Parallel
 * Regional Growth Marching Cubes: Efficient Surface Reconstruction Based on MPI", ICIG 2017).
 *
 * The output equals vtkMarchingCubes followed by vtkPolyDataConnectivityFilter in
 * closest-point-region mode: the same triangles, vertices and normals. Vertices are interpolated
 * from the lower end of each edge in index space (as vtkMarchingCubes does) and keyed by their
 * global edge, so every rank computes bitwise the same point. A vertex whose sample equals the
 * isovalue is that grid point, shared by all its edges; triangles that collapse are dropped.
 *
 * Outputs: points (float unless OutputPointsPrecision asks for double); point data `Normals`
 * (from central-difference gradients) and `VertexKey` (the global vertex key, set as the
 * global ids, so copies of a seam vertex on different ranks share one id); cell data `RankId`
 * (the rank that produced the triangle) and `ComponentId` (components numbered by their
 * smallest vertex key: the same for any number of ranks); field data `SeedVertexKeys`,
 * `SeedVertexPoints` (the vertices the seeds selected), `NumberOfTriangles` and
 * `NumberOfComponents` (global counts).
 *
 * Modes: Seeded (default): the components of the vertices nearest to the seeds, each searched
 * within SeedSearchRadius. LargestComponent: the component with most triangles. AllComponents:
 * every component (a distributed marching cubes whose seams match exactly).
 *
 * ### Distributed execution
 *
 * Problem: on N ranks each rank holds a piece of the volume (ParaView's decomposition, plus one
 * ghost layer). One seed lies in one piece, yet its surface may cross every piece, many times.
 * Growing only from the seed's rank would make the others wait; growing from a seed per piece
 * (the paper's method) needs a manual seed per part and misses pieces of the surface.
 *
 * Approach (Seeded mode): growth in rounds between neighbouring ranks, so that the work follows
 * the chosen structure. Largest and All modes must see every component anyway: they grow
 * everywhere at once and join the pieces in one step.
 * Steps:
 * 1. Ownership: every cube belongs to exactly one rank (the lowest whose non-ghost cells
 *    contain it); owned cell boxes are gathered on all ranks, and each rank knows its
 *    neighbours (ranks whose cubes touch its own) and the order in which it meets them.
 * 2. Seeds: each rank finds, among its cubes, the vertex nearest each seed; one gather picks
 *    the global one (ties: smallest key).
 * 3. Growth. Seeded: the ranks that own cubes around a seed vertex grow from it; a step into a
 *    cube of another rank becomes a departure (the vertex and its component), sent to that
 *    cube's owner, which grows on from it in the next round. A rank grows at most 65 536
 *    nodes per round, so that its neighbours get their part early and grow at the same time.
 *    Rounds end when a reduction says no rank sent anything or has growth left: a rank the
 *    structure never reaches reads no cube. After
 *    MaximumGrowthRounds rounds (a structure that crosses between ranks very often) the rest
 *    is grown in one step instead: every rank grows every component next to another rank's
 *    cubes, and step 4 keeps those joined to a seed. Largest and All: every rank scans all its
 *    cubes.
 * 4. Triangles are made; vertices shared with other ranks' cubes (ports) are exchanged with
 *    the neighbours and matched by key; the small component graph is gathered on rank 0,
 *    joined (union-find), and each rank learns which of its components to keep and their ids.
 * 5. Each rank outputs the triangles of its kept components: their union is the 1-rank output.
 * Messages go only between neighbours. The counts of collectives and messages of the last run
 * are logged at TRACE verbosity and kept (GetNumberOfCollectives and the like).
 * Every error is collective: a status is reduced before each collective step, so a failure on
 * one rank gives every rank the same message and an empty output instead of a deadlock.
 *
 * @warning
 * Normals at partition seams need one ghost layer, which the filter requests; a reader that
 * ignores piece requests entirely (whole volume on rank 0) also works. Seed points are in world
 * coordinates.
 *
 * @sa
 * vtkMarchingCubes vtkFlyingEdges3D vtkPolyDataConnectivityFilter vtkPConnectivityFilter
 */

#ifndef vtkRGMarchingCubes_h
#define vtkRGMarchingCubes_h

#include "RGMCReconstructionModule.h" // For export macro
#include "vtkPolyDataAlgorithm.h"

#include <cstdint> // For the vertex keys of the passes
#include <string>  // For DescribeInputProblem
#include <utility> // For the vertices received between ranks
#include <vector>  // For the seed points

class vtkImageData;
class vtkMultiProcessController;

class RGMCRECONSTRUCTION_EXPORT vtkRGMarchingCubes : public vtkPolyDataAlgorithm
{
public:
  static vtkRGMarchingCubes* New();
  vtkTypeMacro(vtkRGMarchingCubes, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  enum ExtractionModes
  {
    SEEDED = 0,
    LARGEST_COMPONENT = 1,
    ALL_COMPONENTS = 2
  };

  ///@{
  /**
   * The isovalue of the surface. A cube corner is inside when its sample is >= Isovalue.
   * Default 0.
   */
  vtkSetMacro(Isovalue, double);
  vtkGetMacro(Isovalue, double);
  ///@}

  ///@{
  /**
   * Seed points in world coordinates. Each selects the surface vertex nearest to it; the output
   * is the union of those vertices' components (Seeded mode).
   */
  void AddSeedPoint(double x, double y, double z);
  void RemoveAllSeedPoints();
  int GetNumberOfSeedPoints() const;
  void GetSeedPoint(int i, double x[3]) const;
  ///@}

  ///@{
  /**
   * How far (world units) from a seed its surface vertex is searched. A seed with no surface
   * within this distance gives a warning and an empty output. Default 10.
   */
  vtkSetClampMacro(SeedSearchRadius, double, 0.0, VTK_DOUBLE_MAX);
  vtkGetMacro(SeedSearchRadius, double);
  ///@}

  ///@{
  /**
   * Seeded (default), LargestComponent or AllComponents.
   */
  vtkSetClampMacro(ExtractionMode, int, SEEDED, ALL_COMPONENTS);
  vtkGetMacro(ExtractionMode, int);
  void SetExtractionModeToSeeded() { this->SetExtractionMode(SEEDED); }
  void SetExtractionModeToLargestComponent() { this->SetExtractionMode(LARGEST_COMPONENT); }
  void SetExtractionModeToAllComponents() { this->SetExtractionMode(ALL_COMPONENTS); }
  ///@}

  ///@{
  /**
   * Compute point normals from central-difference gradients (default on).
   */
  vtkSetMacro(ComputeNormals, bool);
  vtkGetMacro(ComputeNormals, bool);
  vtkBooleanMacro(ComputeNormals, bool);
  ///@}

  ///@{
  /**
   * vtkAlgorithm::SINGLE_PRECISION (default) or DOUBLE_PRECISION output points.
   */
  vtkSetClampMacro(OutputPointsPrecision, int, SINGLE_PRECISION, DEFAULT_PRECISION);
  vtkGetMacro(OutputPointsPrecision, int);
  ///@}

  ///@{
  /**
   * Seeded mode on several ranks: how many rounds of growth between ranks are made before the
   * rest of the structure is grown in one step (every rank growing every component next to
   * another rank's cubes, the unselected ones dropped afterwards). Each round costs one
   * reduction and one message to each neighbour; a structure needs one round each time it
   * passes from rank to rank along its longest path. The output is the same either way.
   * Default 256; 0 grows in one step at once.
   */
  vtkSetClampMacro(MaximumGrowthRounds, int, 0, VTK_INT_MAX);
  vtkGetMacro(MaximumGrowthRounds, int);
  ///@}

  ///@{
  /**
   * What the last run did on this rank (for tests, benchmarks and the TRACE log): rounds of
   * growth between ranks, whether the rest was grown in one step (MaximumGrowthRounds
   * reached, or Largest and All modes), collective calls, point-to-point messages sent and the
   * values they carried, cubes the growth examined, grid points of shared faces read by the
   * one-step growth, and triangles made before the selection of components.
   */
  vtkGetMacro(NumberOfGrowthRounds, int);
  vtkGetMacro(GrewInOneStep, bool);
  vtkGetMacro(NumberOfCollectives, vtkIdType);
  vtkGetMacro(NumberOfMessages, vtkIdType);
  vtkGetMacro(NumberOfValuesSent, vtkIdType);
  vtkGetMacro(NumberOfCubesExamined, vtkIdType);
  vtkGetMacro(NumberOfFacePointsRead, vtkIdType);
  vtkGetMacro(NumberOfTrianglesMade, vtkIdType);
  ///@}

  /**
   * Wall seconds of the last run on this rank, from the start of RequestData to its end (the
   * input's update not included).
   */
  vtkGetMacro(ExtractionSeconds, double);

  ///@{
  /**
   * The controller that links the ranks. Defaults to the global controller; a single process
   * without MPI runs the same code on a dummy controller.
   */
  void SetController(vtkMultiProcessController*);
  vtkGetObjectMacro(Controller, vtkMultiProcessController);
  ///@}

protected:
  vtkRGMarchingCubes();
  ~vtkRGMarchingCubes() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  double Isovalue = 0.0;
  std::vector<double> SeedPoints;
  double SeedSearchRadius = 10.0;
  int ExtractionMode = SEEDED;
  bool ComputeNormals = true;
  int OutputPointsPrecision = SINGLE_PRECISION;
  vtkMultiProcessController* Controller = nullptr;
  int MaximumGrowthRounds = 256;

  int NumberOfGrowthRounds = 0;
  bool GrewInOneStep = false;
  vtkIdType NumberOfCollectives = 0;
  vtkIdType NumberOfMessages = 0;
  vtkIdType NumberOfValuesSent = 0;
  vtkIdType NumberOfCubesExamined = 0;
  vtkIdType NumberOfFacePointsRead = 0;
  vtkIdType NumberOfTrianglesMade = 0;
  double ExtractionSeconds = 0;

private:
  vtkRGMarchingCubes(const vtkRGMarchingCubes&) = delete;
  void operator=(const vtkRGMarchingCubes&) = delete;

  // The passes of RequestData, each collective (the schedule is written down there). A pass
  // that fails leaves the agreed message in the run.
  struct Run;
  bool CheckInput(Run& run, vtkImageData* input, vtkInformationVector** inputVector);
  void AgreeOnWholeExtent(Run& run, vtkImageData* input, vtkInformation* inInfo);
  std::string DescribeInputProblem(
    Run& run, vtkImageData* input, vtkInformationVector** inputVector);
  void CheckScalars(
    Run& run, vtkImageData* input, vtkInformationVector** inputVector, std::ostream& msg);
  bool GatherPieces(Run& run, vtkImageData* input);
  void AssignCubes(Run& run);
  void BuildKernel(Run& run);
  /// 1: every seed has a vertex; 0: no surface near a seed (warned); -1: an error.
  int FindSeeds(Run& run);
  std::string DescribeSeedOutsideVolume(Run& run, std::vector<double>& seedIndex);
  bool GatherNearestVertices(
    Run& run, const std::vector<double>& seedIndex, std::vector<vtkIdType>& all);
  void WarnNoSurfaceNearSeed(Run& run, int seed);
  /// 1: done; 0: aborted; -1: an error.
  int GrowAndExtract(Run& run);
  /// Seeded growth on several ranks, in rounds; false on an error (in the run).
  bool GrowInRounds(Run& run, bool& aborted);
  void AddressDepartures(Run& run, const std::vector<std::pair<std::int64_t, int>>& received,
    std::vector<std::vector<vtkIdType>>& outgoing, bool& sending);
  void GrowFromNeighbours(Run& run, const std::vector<std::vector<vtkIdType>>& incoming,
    std::vector<std::pair<std::int64_t, int>>& received);
  void GrowComponentsAtSharedFaces(Run& run, std::string& problem);
  void GrowAndExtractLocally(Run& run, bool rounds, bool aborted);
  void JoinComponentsAtPorts(Run& run, bool aborted);
  /// 1: go on; 0: aborted; -1: an error.
  int AgreeOnGraphSizes(Run& run, bool aborted);
  void Account(Run& run);
  bool StoreSurface(Run& run, vtkPolyData* output);
  void AdoptSurface(Run& run, vtkPolyData* output);
  void DescribeSurface(Run& run, vtkPolyData* output);
};

#endif

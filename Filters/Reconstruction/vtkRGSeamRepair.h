/**
 * @class   vtkRGSeamRepair
 * @brief   one watertight, smoothed surface from a distributed triangle mesh
 *
 * A surface extracted on N ranks (vtkRGMarchingCubes, or ParaView's Contour) has a copy of every
 * vertex on a partition seam on each rank that uses it. Tools that look at one rank's piece see
 * the seam as a border: ParaView's Clean does not merge across ranks, and smoothing filters move
 * seam vertices as if they were on a boundary, so the pieces no longer fit. vtkRGSeamRepair
 * identifies the copies across ranks and makes the pieces behave as one mesh:
 *
 * - Every vertex gets a global id, `GlobalPointIds`, contiguous from 0 and the same for any
 *   number of ranks (vertices numbered in the order of their identity). Its owner is the lowest
 *   rank that uses it; the other ranks' copies are flagged DUPLICATEPOINT in `vtkGhostType`.
 *   Copies of one vertex on the same rank are merged.
 * - Global checks, in field data (`UniquePoints`, `Triangles`, `Edges`, `BoundaryEdges`,
 *   `VolumeBorderEdges`, `NonManifoldEdges`, `EulerCharacteristic`, `Closed`) and in the log:
 *   a closed surface has no boundary and no non-manifold edge; edges where the surface leaves
 *   the volume are counted apart (`VolumeBorderEdges`).
 * - Measures, in field data and in the log: `SurfaceArea` and `EnclosedVolume` of the output,
 *   and the same `...BeforeSmoothing`, in world units, the same to the bit on any number of
 *   ranks and threads (exact fixed-point sums, rgmcMeasure.h). A surface cut by the volume's
 *   border is closed by the border planes (their part: `BorderCapArea`; the box is the volume's
 *   when the input carries vtkRGMarchingCubes' `WholeExtent` and `VolumeGeometry`, else the
 *   mesh's bounds); a surface with a hole inside the volume has a NaN volume.
 * - Smoothing that does not see the seams: Laplacian in Jacobi form (default; 20 iterations,
 *   relaxation 0.01, as Wei et al. use) or windowed sinc (Taubin; the smoother without
 *   shrinkage, as vtkWindowedSincPolyDataFilter computes it on the merged mesh), with the
 *   neighbours of seam vertices exchanged every iteration and visited in global-id order, so
 *   the result is the same, to the bit, on any number of ranks. Normals are recomputed.
 *
 * Vertices are identified by the input's point global ids when every rank has them (the
 * `VertexKey` of vtkRGMarchingCubes), otherwise by their exact coordinates. The input must be
 * triangles (polygons of 3 points) only. On a rank whose points are all distinct (the
 * extraction's output), the output keeps the input's points in their order, its triangles and
 * its point data as they are (shared, not copied, unless smoothing moved the points);
 * `GlobalPointIds` gives each point its number. Otherwise a rank's copies of a vertex are merged
 * into one point.
 *
 * ### Distributed execution
 * Problem: which copies are one vertex, and who owns it, is known only across ranks.
 * Approach: a rendezvous on ranges of identities, then exchanges with neighbouring ranks only.
 * Steps:
 * 1. Each rank sorts its vertex identities; sampled identities give ranges of equal size.
 * 2. Identities go to the rank of their range, which merges the ranks' sorted streams, numbers
 *    them in order and answers every sender with the global id of each, and with the holders
 *    of the few held by several ranks (the lowest owns the vertex).
 * 3. The edges around each seam vertex are gathered at its owner: complete edge counts for the
 *    checks, complete neighbourhoods for the smoothing stencils. The other vertices' stencils
 *    come from the triangles around them on their own rank.
 * 4. Each smoothing iteration sends, from the ranks that hold them, the neighbour positions
 *    owners need, then the owners' new positions to the other holders.
 * 5. The measures, before and after smoothing: each rank's exact sums are reduced; the few
 *    triangle edges on the volume's border are gathered on every rank, which closes the
 *    surface there in one order.
 * Sorted arrays throughout (no per-vertex maps); memory on a rank is proportional to its own
 * piece. Errors are collective: a problem on one rank, a failed allocation included, is
 * reported by every rank, and the output is empty.
 *
 * @sa vtkRGMarchingCubes vtkWindowedSincPolyDataFilter vtkSmoothPolyDataFilter
 */

#ifndef vtkRGSeamRepair_h
#define vtkRGSeamRepair_h

#include "RGMCReconstructionModule.h" // For export macro
#include "vtkPolyDataAlgorithm.h"

class vtkMultiProcessController;

class RGMCRECONSTRUCTION_EXPORT vtkRGSeamRepair : public vtkPolyDataAlgorithm
{
public:
  static vtkRGSeamRepair* New();
  vtkTypeMacro(vtkRGSeamRepair, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  enum SmoothingMethods
  {
    NO_SMOOTHING = 0,
    LAPLACIAN = 1,
    WINDOWED_SINC = 2
  };

  ///@{
  /**
   * NO_SMOOTHING, LAPLACIAN (default) or WINDOWED_SINC.
   */
  vtkSetClampMacro(SmoothingMethod, int, NO_SMOOTHING, WINDOWED_SINC);
  vtkGetMacro(SmoothingMethod, int);
  ///@}

  ///@{
  /**
   * Smoothing iterations (default 20).
   */
  vtkSetClampMacro(NumberOfIterations, int, 0, 100000);
  vtkGetMacro(NumberOfIterations, int);
  ///@}

  ///@{
  /**
   * Laplacian relaxation factor (default 0.01): each iteration moves a vertex this fraction of
   * the way to the mean of its neighbours.
   */
  vtkSetClampMacro(RelaxationFactor, double, 0.0, 1.0);
  vtkGetMacro(RelaxationFactor, double);
  ///@}

  ///@{
  /**
   * Windowed-sinc pass band, between 0 and 2 (default 0.1; lower smooths more).
   */
  vtkSetClampMacro(PassBand, double, 0.0, 2.0);
  vtkGetMacro(PassBand, double);
  ///@}

  enum WindowFunctions
  {
    NUTTALL_WINDOW = 0,
    HAMMING_WINDOW = 1
  };

  ///@{
  /**
   * Windowed-sinc window: Nuttall (default, as vtkWindowedSincPolyDataFilter's since VTK 9.4) or
   * Hamming (VTK 9.2's, which shrinks surfaces by up to 1%).
   */
  vtkSetClampMacro(WindowFunction, int, NUTTALL_WINDOW, HAMMING_WINDOW);
  vtkGetMacro(WindowFunction, int);
  ///@}

  ///@{
  /**
   * The controller that links the ranks (default: the global controller).
   */
  void SetController(vtkMultiProcessController*);
  vtkGetObjectMacro(Controller, vtkMultiProcessController);
  ///@}

  /**
   * The collective calls this rank made in the last execution (agreements, reductions,
   * gathers; not the messages between pairs of ranks): the same on every rank (tested).
   */
  vtkGetMacro(NumberOfCollectives, vtkIdType);

protected:
  vtkRGSeamRepair();
  ~vtkRGSeamRepair() override;

  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int SmoothingMethod = LAPLACIAN;
  int NumberOfIterations = 20;
  double RelaxationFactor = 0.01;
  double PassBand = 0.1;
  int WindowFunction = NUTTALL_WINDOW;
  vtkMultiProcessController* Controller = nullptr;
  vtkIdType NumberOfCollectives = 0;

private:
  vtkRGSeamRepair(const vtkRGSeamRepair&) = delete;
  void operator=(const vtkRGSeamRepair&) = delete;

  // The passes of RequestData, in order (the collective schedule is written above it). Each
  // returns false on every rank alike, with the problem in the run.
  struct Run;
  bool CheckInput(Run& run);
  bool NumberVertices(Run& run);
  void FindBorder(Run& run);
  bool RepairSeams(Run& run);
  template <typename T, typename I>
  bool RepairSeamsIn(Run& run);
  template <typename Repair>
  bool SmoothSurface(Run& run, Repair& repair);
  bool StoreSurface(Run& run, vtkPolyData* output);
  void BuildOutput(Run& run, vtkPolyData* output);
  void ReportChecks(Run& run, vtkPolyData* output);
};

#endif

/**
 * @class   vtkRGDecimate
 * @brief   quadric-error decimation of a distributed surface, the same on any number of ranks
 *
 * Reduces a triangle surface numbered as one mesh (vtkRGSeamRepair's output: `GlobalPointIds`
 * on every rank) to a fraction of its triangles by edge collapses chosen by their quadric error
 * (Garland and Heckbert, "Surface simplification using quadric error metrics", SIGGRAPH 1997):
 * each vertex carries the sum of the squared-distance quadrics of the triangles merged into it,
 * and the cheapest collapse goes first, the merged vertex placed where its quadric is smallest
 * (rgmc::PlaceCollapse: the quadric's minimum when it is well defined and within two edge lengths
 * of the edge, else its minimum on the edge). Without a MaximumError each plane's quadric is
 * weighted by its triangle's area, as in Garland's thesis and vtkQuadricDecimation, so that the
 * error follows the surface's shape rather than how finely marching cubes cut each part of it
 * (its slivers count for little); with a MaximumError the planes count equally, so that the error
 * bounds the distance to each of them.
 *
 * What is kept:
 * - a closed manifold stays one, of the same topology: a collapse is made only when the edge's
 *   ends share no neighbour but the two corners of its triangles (the link condition) and no
 *   vertex is left with fewer than three neighbours, so no component shrinks away or pinches;
 * - no triangle turns over (its normal after a collapse keeps a positive dot product with its
 *   normal before);
 * - vertices on a boundary edge (where the surface leaves the volume) or a non-manifold edge
 *   neither move nor go, so the border stays where it is;
 * - the output is the same, to the bit and in the same order, for any number of ranks and
 *   threads, and it is one mesh across the ranks (global point ids, normals), as vtkRGSeamRepair
 *   makes it, so the Merged Surface Writer writes it as one file.
 *
 * ### Distributed execution
 * Problem: a greedy edge collapse is sequential, and the surface is spread over ranks in a way
 * that depends on their number.
 * Approach: space is cut into cubic blocks on a grid that depends only on the surface (its global
 * bounds and triangle count). A triangle belongs to the block of its lowest-numbered vertex.
 * Each block is simplified greedily on its own, with the vertices it shares with other blocks
 * fixed, so blocks are independent: their result does not depend on where or in what order they
 * are simplified. Further passes (up to 16) with the grid shifted by a half, a quarter, ... of a
 * block simplify what the ones before left fixed. In each pass, how many collapses each block
 * keeps is set by one threshold on the collapses' error over all blocks (a distributed
 * selection, ties broken by block and order), so the cheapest collapses of the whole surface are
 * the ones made; a pass that is not the last makes only the free vertices' share of what is
 * still needed, so that the blocks' insides are not decimated further than the whole surface
 * will be, and the triangle count lands on the target.
 * Steps of a pass:
 * 1. Count the triangles of each block (AllReduce); blocks go to ranks in contiguous ranges of
 *    balanced counts.
 * 2. Find the vertices shared by several blocks: (vertex, block) pairs go to the rank of the
 *    vertex (its global id modulo the ranks), which answers the ranks that hold the vertex with
 *    all its blocks.
 * 3. Send each triangle, with its vertices' positions and quadrics, to its block's rank, and to
 *    the other blocks of its vertices as their halo (the triangles around the vertices a block
 *    shares, which it needs to keep them fixed and to sum their quadrics).
 * 4. Simplify the blocks (threads over blocks); select the threshold (AllReduce, bisection on the
 *    error's bits); keep each block's collapses up to it.
 * A rank whose blocks hold more than TrianglesPerWave triangles does steps 3 and 4 in waves of
 * its blocks, keeping only the collapses' errors of each wave, and makes and simplifies each
 * wave again, as far as it keeps, once the threshold is known: it then holds one wave's blocks
 * at a time, not all of them. The first pass reads the input in place, without a copy.
 * After the last pass the pieces are numbered as one mesh by an internal vtkRGSeamRepair (no
 * smoothing), which also recomputes normals and the checks and measures in field data.
 * Nothing is gathered on one rank; a rank's memory follows its share of the blocks. Errors are
 * agreed on every rank.
 *
 * @warning The error bound (MaximumError) is on the quadric error: the root of the sum of the
 * squared distances from a merged vertex to the planes of the original triangles merged into it,
 * not the Hausdorff distance, which can be larger where planes extend beyond their triangles.
 *
 * @sa vtkRGSeamRepair vtkQuadricDecimation vtkDecimatePro
 */

#ifndef vtkRGDecimate_h
#define vtkRGDecimate_h

#include "RGMCReconstructionModule.h" // For export macro
#include "vtkPolyDataAlgorithm.h"

#include <vector> // For the passes' messages

class vtkMultiProcessController;

class RGMCRECONSTRUCTION_EXPORT vtkRGDecimate : public vtkPolyDataAlgorithm
{
public:
  static vtkRGDecimate* New();
  vtkTypeMacro(vtkRGDecimate, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * The fraction of the triangles to remove, greater than 0 and less than 1 (default 0.9: keep
   * a tenth). Fewer go when MaximumError stops the collapses first, or when no more collapse
   * keeps the surface valid.
   */
  vtkSetMacro(TargetReduction, double);
  vtkGetMacro(TargetReduction, double);
  ///@}

  ///@{
  /**
   * The largest quadric error of a collapse, in world units (default 0: no limit); see the
   * warning above. When set, the quadrics are not area-weighted (see the class description), so
   * that the bound holds for every plane.
   */
  vtkSetMacro(MaximumError, double);
  vtkGetMacro(MaximumError, double);
  ///@}

  ///@{
  /**
   * Whether to report the distance from the input surface (default on): field arrays
   * DecimationHausdorffDistance and DecimationMeanDistance, in world units, the same on every
   * rank. Measured from every vertex of each surface (each global vertex once) to the nearest
   * point of the other surface, exactly, where the triangles are (nothing is gathered):
   * Hausdorff is the largest of those distances, the mean is the mean of the two directions'
   * means (the sum exact, so the same for any number of ranks and threads).
   */
  vtkSetMacro(ComputeDistance, vtkTypeBool);
  vtkGetMacro(ComputeDistance, vtkTypeBool);
  vtkBooleanMacro(ComputeDistance, vtkTypeBool);
  ///@}

  ///@{
  /**
   * About how many triangles a block holds (default 20000; at least 100): the grid's cubes are
   * sized for this many on a surface spanning its bounds. Smaller blocks spread over more ranks
   * and threads, larger ones leave fewer vertices fixed at their faces. The result depends on
   * it, never on the number of ranks or threads.
   */
  vtkSetClampMacro(TrianglesPerBlock, vtkIdType, 100, VTK_ID_MAX);
  vtkGetMacro(TrianglesPerBlock, vtkIdType);
  ///@}

  ///@{
  /**
   * Memory: a rank whose blocks hold more than this many triangles in a pass (default
   * 4000000; at least 100) makes and simplifies them in waves of contiguous blocks, at least 16
   * and of about this many triangles each, holding one wave's blocks at a time instead of all;
   * the blocks are then made and simplified a second time, as far as the collapses kept, once
   * the threshold is known, so a pass takes longer. The result never depends on it.
   */
  vtkSetClampMacro(TrianglesPerWave, vtkIdType, 100, VTK_ID_MAX);
  vtkGetMacro(TrianglesPerWave, vtkIdType);
  ///@}

  ///@{
  /**
   * The controller that links the ranks (default: the global controller).
   */
  void SetController(vtkMultiProcessController*);
  vtkGetObjectMacro(Controller, vtkMultiProcessController);
  ///@}

  /**
   * The collective calls this rank made in the last execution: the same on every rank.
   */
  vtkGetMacro(NumberOfCollectives, vtkIdType);

protected:
  vtkRGDecimate();
  ~vtkRGDecimate() override;

  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  double TargetReduction = 0.9;
  double MaximumError = 0.0;
  vtkTypeBool ComputeDistance = 1;
  vtkIdType TrianglesPerBlock = 20000;
  vtkIdType TrianglesPerWave = 4000000;
  vtkMultiProcessController* Controller = nullptr;
  vtkIdType NumberOfCollectives = 0;

private:
  vtkRGDecimate(const vtkRGDecimate&) = delete;
  void operator=(const vtkRGDecimate&) = delete;

  // The passes of RequestData, in order (the collective schedule is written above it). Each
  // returns false on every rank alike, with the problem in the run.
  struct Run;
  bool CheckInput(Run& run);
  bool ReadSurface(Run& run);
  bool PlaceBlocks(Run& run, int pass);
  bool FindSharedVertices(Run& run);
  bool SendTriangles(Run& run, int wave);
  bool SimplifyBlocks(Run& run, int wave);
  bool KeepCheapest(Run& run, bool all);
  bool ApplyCollapses(Run& run);
  bool NumberSurface(Run& run, vtkPolyData* output);

  // The passes' local work, no communication: the steps named by their labels, and the parts
  // of KeepCheapest between its reductions.
  using Messages = std::vector<std::vector<vtkIdType>>; // one per rank
  void ReadPartBounds(Run& run, double bounds[6]);
  void CountBlockTriangles(Run& run, std::vector<vtkIdType>& counts);
  void AssignBlocks(Run& run);
  void ListVertexBlocks(Run& run, Messages& outgoing);
  void AnswerSharedVertices(Run& run, Messages& asked, Messages& answers);
  void RecordSharedVertices(Run& run, const Messages& told);
  void SendTrianglesToBlocks(Run& run, int wave, Messages& outgoing);
  void AssembleBlocks(Run& run, int wave, Messages& incoming);
  double SelectThreshold(Run& run, vtkIdType needed);
  void KeepUpToThreshold(Run& run, double threshold, vtkIdType needed);
  void BuildDecimatedPiece(Run& run, vtkPolyData* piece);
};

#endif

/**
 * @class   vtkRGMergedSurfaceWriter
 * @brief   writes a surface distributed over ranks as one mesh (STL, PLY, VTP) or as pieces (PVTP)
 *
 * Problem: ParaView's writers gather the pieces of a distributed surface to one rank and append
 * them, so the vertices on the partition seams are written once per rank that has them, and a
 * surface of tens of millions of triangles no longer fits the gather (more than 2^31 bytes).
 *
 * Approach: nothing is gathered. The surface is first numbered as one mesh (the GlobalPointIds
 * and duplicate flags of vtkRGSeamRepair; an input without them is numbered by an internal
 * vtkRGSeamRepair without smoothing). Every record of the file then has a place known to every
 * rank: vertex g at the vertex section's start plus g records, the ranks' triangles one after the
 * other (an exclusive prefix sum of their counts). Text formats use fixed-width numbers, so their
 * records have a fixed size too. Each rank writes its own records into the one file at those
 * byte offsets; rank 0 writes the headers. The file holds each vertex once, in global-id order,
 * and each triangle once: the same vertices, in the same order, for any number of ranks. All
 * counts and offsets are 64-bit.
 *
 * Steps (every rank makes the same collective calls):
 * 1. Agree the file name and format; number the mesh if needed (collective).
 * 2. Sum the owned vertex and triangle counts, and prefix-sum the triangles (collective).
 *    Formats whose counts are 32-bit (STL's triangle count, PLY's vertex indices) give an
 *    error before anything is written when the mesh is larger.
 * 3. Rank 0 creates a new file beside the target (same directory, the target's name followed
 *    by .rgmc-<process>-<n>.part); the others open it once that is agreed.
 * 4. Each rank writes its vertices (grouped in runs of consecutive ids) and its triangles and
 *    flushes them to the disk (fsync); the status of every rank is agreed.
 * 5. Rank 0 renames the file over the target. A file that failed anywhere is removed instead:
 *    an earlier file at the target is never lost or truncated, and the error (the same on every
 *    rank) names the target and the cause, for instance "No space left on device".
 *    A symbolic link is followed; a target that is not a regular file (a device, a pipe) is
 *    written in place. The .pvtp form is VTK's writer's and is written in place.
 *
 * The format follows the file name's extension: .stl (binary or ASCII), .ply (binary or ASCII,
 * with vertex normals when the surface has them), .vtp (VTK XML polydata with inline data,
 * binary or ASCII: Debian 12's expat cannot read appended data back), or .pvtp (ParaView's
 * parallel form: one .vtp piece per rank, as they are, and a .pvtp index).
 *
 * @warning The ranks write into one file: on a cluster, the file must be on a file system that
 * every rank sees (or use .pvtp). Only triangle surfaces can be written.
 *
 * @sa vtkRGSeamRepair
 */

#ifndef vtkRGMergedSurfaceWriter_h
#define vtkRGMergedSurfaceWriter_h

#include "RGMCIOModule.h" // For export macro
#include "vtkWriter.h"

#include <string> // For Fail

class vtkMultiProcessController;

class RGMCIO_EXPORT vtkRGMergedSurfaceWriter : public vtkWriter
{
public:
  static vtkRGMergedSurfaceWriter* New();
  vtkTypeMacro(vtkRGMergedSurfaceWriter, vtkWriter);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * The file to write; its extension (.stl, .ply, .vtp, .pvtp) chooses the format.
   */
  vtkSetStringMacro(FileName);
  vtkGetStringMacro(FileName);
  ///@}

  ///@{
  /**
   * VTK_BINARY (default) or VTK_ASCII.
   */
  vtkSetClampMacro(FileType, int, VTK_ASCII, VTK_BINARY);
  vtkGetMacro(FileType, int);
  ///@}

  ///@{
  /**
   * The controller that links the ranks (default: the global controller).
   */
  void SetController(vtkMultiProcessController*);
  vtkGetObjectMacro(Controller, vtkMultiProcessController);
  ///@}

protected:
  vtkRGMergedSurfaceWriter();
  ~vtkRGMergedSurfaceWriter() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  vtkTypeBool ProcessRequest(
    vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  void WriteData() override;

  char* FileName = nullptr;
  int FileType = VTK_BINARY;
  vtkMultiProcessController* Controller = nullptr;

private:
  vtkRGMergedSurfaceWriter(const vtkRGMergedSurfaceWriter&) = delete;
  void operator=(const vtkRGMergedSurfaceWriter&) = delete;

  // The passes of WriteData, in order (the collective schedule is written above it). Each
  // returns false on every rank alike, with the problem in the run.
  struct Run;
  bool AgreeOnFile(Run& run);
  bool WritePieces(Run& run);
  bool NumberSurface(Run& run);
  bool WriteMerged(Run& run);
  void Fail(const std::string& problem);
};

#endif

/**
 * @class   vtkRGMergedSurfaceWriter
 * @brief   writes a surface distributed over ranks as one mesh (STL, PLY or VTP)
 *
 * ParaView's writers gather the pieces of a distributed surface and append them: the vertices
 * on the partition seams are written once per rank that has them. This writer gathers the
 * pieces on the first rank and merges the points that share a global point id (the
 * GlobalPointIds of vtkRGSeamRepair, or the VertexKey of vtkRGMarchingCubes) before writing, so
 * the file holds one mesh: no duplicate vertices in PLY and VTP, and shared, identical vertices
 * in STL. Without global point ids the pieces are written as they are.
 *
 * The format follows the file name's extension: .stl (vtkSTLWriter), .ply (vtkPLYWriter) or
 * .vtp (vtkXMLPolyDataWriter, inline data: Debian 12's expat cannot read appended data back).
 * FileType chooses binary (default) or ASCII.
 */

#ifndef vtkRGMergedSurfaceWriter_h
#define vtkRGMergedSurfaceWriter_h

#include "RGMCFiltersModule.h" // For export macro
#include "vtkSmartPointer.h"   // For Merge
#include "vtkWriter.h"

#include <vector> // For Merge

class vtkDataObject;
class vtkMultiProcessController;
class vtkPolyData;

class RGMCFILTERS_EXPORT vtkRGMergedSurfaceWriter : public vtkWriter
{
public:
  static vtkRGMergedSurfaceWriter* New();
  vtkTypeMacro(vtkRGMergedSurfaceWriter, vtkWriter);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * The file to write; its extension (.stl, .ply, .vtp) chooses the format.
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

  /**
   * The pieces of all ranks appended, with the points that share a global id merged: what
   * this writer writes (exposed for tests).
   */
  static vtkSmartPointer<vtkPolyData> Merge(const std::vector<vtkSmartPointer<vtkDataObject>>& pieces);

protected:
  vtkRGMergedSurfaceWriter();
  ~vtkRGMergedSurfaceWriter() override;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  vtkTypeBool ProcessRequest(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  void WriteData() override;

  char* FileName = nullptr;
  int FileType = VTK_BINARY;
  vtkMultiProcessController* Controller = nullptr;

private:
  vtkRGMergedSurfaceWriter(const vtkRGMergedSurfaceWriter&) = delete;
  void operator=(const vtkRGMergedSurfaceWriter&) = delete;
};

#endif

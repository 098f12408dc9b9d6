/**
 * @class   vtkRGVolumeReader
 * @brief   base of the plugin's distributed volume readers: one header scan, each rank its slices
 *
 * Problem: VTK's NIfTI and MetaImage readers put the whole volume on rank 0, ParaView's NIfTI
 * reader crashes at 2 ranks and vtkDICOMImageReader copies every slice on every rank, while the
 * surface extraction after them is distributed.
 *
 * Approach: a reader of this kind scans the headers once, on rank 0 of its controller, and
 * broadcasts the result (the sorted slice list, the geometry, the scaling) to every rank. It
 * handles piece requests itself (CAN_HANDLE_PIECE_REQUEST): piece p of n is the p-th slab of
 * whole slices (vtkExtentTranslator's Z_SLAB_MODE) plus the ghost layers asked for, marked as
 * ghosts, so each rank reads only the slices of its own piece.
 *
 * Steps:
 * 1. RequestInformation, on every rank: rank 0 runs Scan(); its status is agreed over all
 *    ranks (an error on rank 0 becomes the same error on every rank), then its header is
 *    broadcast and every rank runs Parse() on it. The scan is repeated only when a property
 *    changed.
 * 2. RequestData, on every rank: ReadExtent() fills the rank's piece; its status is
 *    agreed over all ranks before the reader returns, so one rank's truncated file fails every
 *    rank and none is left waiting in a later collective.
 *
 * Output: vtkImageData with origin, spacing and direction matrix in patient coordinates in
 * millimetres, LPS (x towards the patient's left, y towards the back, z towards the head), as
 * DICOM defines them; one point array, int16 when every scaled value is an integer that int16
 * holds, float otherwise (double when the stored integers have more than 24 bits or the file
 * stores doubles).
 *
 * @sa vtkRGDICOMSeriesReader vtkRGNIfTIReader
 */

#ifndef vtkRGVolumeReader_h
#define vtkRGVolumeReader_h

#include "RGMCIOModule.h" // For export macro
#include "vtkImageAlgorithm.h"
#include "vtkSmartPointer.h" // For LastPiece

#include <string> // For std::string
#include <vector> // For the header

namespace rgmc
{
class MessageReader;
class MessageWriter;
}

class vtkDataArray;
class vtkMultiProcessController;

class RGMCIO_EXPORT vtkRGVolumeReader : public vtkImageAlgorithm
{
public:
  vtkTypeMacro(vtkRGVolumeReader, vtkImageAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * The file (or, for readers that accept one, the directory) to read.
   */
  vtkSetStringMacro(FileName);
  vtkGetStringMacro(FileName);
  ///@}

  ///@{
  /**
   * The controller whose ranks share the reading (default: the global controller; none means
   * one rank).
   */
  void SetController(vtkMultiProcessController* controller);
  vtkGetObjectMacro(Controller, vtkMultiProcessController);
  ///@}

  ///@{
  /**
   * What the last successful header scan found, for the log and the GUI: the geometry and
   * scaling in words, and the warnings it gave (irregular spacing, other series).
   */
  const char* GetSummary() const { return this->Summary.c_str(); }
  const char* GetScanWarnings() const { return this->Warnings.c_str(); }
  ///@}

protected:
  vtkRGVolumeReader();
  ~vtkRGVolumeReader() override;

  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  /**
   * Rank 0 only: reads the headers and writes everything every rank needs into `header`.
   * Returns false with `message` (naming the file and the problem) on error.
   */
  virtual bool Scan(std::vector<vtkIdType>& header, std::string& message) = 0;

  /**
   * Every rank: sets the members below (and the subclass's own) from the header of Scan.
   */
  virtual bool Parse(const std::vector<vtkIdType>& header, std::string& message) = 0;

  /**
   * Every rank: fills `scalars` (of OutputScalarType, NumberOfComponents components, allocated
   * for `extent`, x fastest) with the samples of `extent` (a non-empty sub-extent of the whole
   * volume). Returns false with `message` on error.
   */
  virtual bool ReadExtent(const int extent[6], vtkDataArray* scalars, std::string& message) = 0;


  /**
   * The output type for samples `slope * stored + intercept`: int16 when every such value is an
   * integer (integral stored values, integral slope and intercept) within [lo, hi] that int16
   * holds; double when `wide` (stored integers of more than 24 bits, or doubles); float
   * otherwise.
   */
  static int ChooseScalarType(bool integral, double lo, double hi, bool wide);

  /**
   * The geometry and sample type, in the order every header starts with: Scan writes them with
   * PackGeometry (direction row-major), Parse reads them into the members below with
   * UnpackGeometry.
   */
  static void PackGeometry(rgmc::MessageWriter& p, const int dimensions[3], const double spacing[3],
    const double origin[3], const double direction[9], int scalarType);
  void UnpackGeometry(rgmc::MessageReader& u);

  /// Writes `count` values into `scalars` (of OutputScalarType) from tuple component `at`.
  static void Store(vtkDataArray* scalars, vtkIdType at, const double* values, std::size_t count);

  char* FileName = nullptr;
  vtkMultiProcessController* Controller = nullptr;

  // The geometry and sample type, set by Parse().
  int Dimensions[3] = { 0, 0, 0 };
  double Origin[3] = { 0, 0, 0 };
  double Spacing[3] = { 1, 1, 1 };
  double Direction[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 1 };
  int OutputScalarType = 0;
  int NumberOfComponents = 1;
  std::string ArrayName = "Intensity";
  std::string Summary;
  std::string Warnings; // one per line; emitted by every rank after a scan

private:
  vtkRGVolumeReader(const vtkRGVolumeReader&) = delete;
  void operator=(const vtkRGVolumeReader&) = delete;

  /// Fills `scalars` for `extent` as ReadExtent does, copying the slices it shares with
  /// `previous` (the piece read last, of `previousExtent`; null when there is none to use) and
  /// reading only the others.
  bool ReadReusing(const int extent[6], vtkDataArray* scalars, vtkDataArray* previous,
    const int previousExtent[6], std::string& message);

  vtkTimeStamp ScanTime;
  // The piece of the last successful read (the output's own array: the pipeline empties the
  // output before it asks for the next piece), its extent, and when it was read.
  vtkSmartPointer<vtkDataArray> LastPiece;
  int LastExtent[6] = { 0, -1, 0, -1, 0, -1 };
  vtkTimeStamp ReadTime;
};

#endif

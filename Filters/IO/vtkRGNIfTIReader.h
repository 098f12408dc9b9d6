/**
 * @class   vtkRGNIfTIReader
 * @brief   reads a NIfTI-1 volume (.nii, .nii.gz); each MPI rank reads only its own slices
 *
 * The header (348 bytes, either byte order) is read once, on rank 0, and broadcast; each rank
 * then reads the bytes of its own slab: a seek in a .nii file, a zlib stream decompressed up to
 * the end of its slab in a .nii.gz file. Samples are scl_slope * stored + scl_inter (when
 * scl_slope is neither 0 nor NaN): int16 when every value is an integer that int16 holds,
 * float otherwise (double for double data). A 4-D file gives its first volume, with a warning.
 *
 * Geometry: NIfTI's world coordinates are RAS+ (x to the right of the patient, y to the front);
 * the output is in DICOM's LPS+ (x to the left, y to the back, z to the head), as
 * vtkRGDICOMSeriesReader's, so that the same patient scanned into a DICOM series and into a
 * NIfTI file lands at the same world coordinates: (x, y, z) LPS = (-x, -y, z) RAS. The
 * voxel-to-world matrix is the sform when sform_code > 0 (a shearing sform gives way to a valid
 * qform, with a warning), else the qform when qform_code > 0, else pixdim scaling alone (with
 * a warning). Its columns, normalized, are the direction matrix and their lengths the spacing;
 * voxel order is kept as stored (no slice is reordered).
 *
 * Errors name the file and the problem, on every rank: a missing file, a header that is not
 * NIfTI-1 (a NIfTI-2 or Analyze file, a .hdr/.img pair), an unsupported datatype, impossible
 * dimensions, truncated voxel data (in a .nii.gz, found by the rank that reads past its end).
 *
 * @sa vtkRGVolumeReader vtkRGDICOMSeriesReader vtkNIFTIImageReader
 */

#ifndef vtkRGNIfTIReader_h
#define vtkRGNIfTIReader_h

#include "RGMCIOModule.h" // For export macro
#include "vtkRGVolumeReader.h"

class RGMCIO_EXPORT vtkRGNIfTIReader : public vtkRGVolumeReader
{
public:
  static vtkRGNIfTIReader* New();
  vtkTypeMacro(vtkRGNIfTIReader, vtkRGVolumeReader);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /**
   * 1 when `name` starts with a NIfTI-1 single-file header (compressed or not); 0 otherwise.
   */
  int CanReadFile(const char* name);

  ///@{
  /**
   * After an update: the scaling applied, and which matrix placed the volume: 2 qform, 3 sform,
   * 1 neither (pixdim only), as NIfTI numbers its methods.
   */
  double GetRescaleSlope() const { return this->RescaleSlope; }
  double GetRescaleIntercept() const { return this->RescaleIntercept; }
  int GetGeometryMethod() const { return this->GeometryMethod; }
  ///@}

protected:
  vtkRGNIfTIReader() = default;
  ~vtkRGNIfTIReader() override = default;

  bool Scan(std::vector<vtkIdType>& header, std::string& message) override;
  bool Parse(const std::vector<vtkIdType>& header, std::string& message) override;
  bool ReadExtent(const int extent[6], vtkDataArray* scalars, std::string& message) override;

  double RescaleSlope = 1.0;
  double RescaleIntercept = 0.0;
  int GeometryMethod = 0;
  // From the header: where the voxels are and how they are stored.
  double VoxelOffset = 0;
  int DataType = 0;
  int BytesPerVoxel = 0;
  bool ByteSwapped = false;

private:
  vtkRGNIfTIReader(const vtkRGNIfTIReader&) = delete;
  void operator=(const vtkRGNIfTIReader&) = delete;
};

#endif

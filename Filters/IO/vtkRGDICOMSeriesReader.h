/**
 * @class   vtkRGDICOMSeriesReader
 * @brief   reads a DICOM series (GDCM) as one volume; each MPI rank reads only its own slices
 *
 * FileName is a directory, or one file of the series. The reader scans the directory's files
 * (not its subdirectories), groups them by SeriesInstanceUID and reads one series: the one
 * named by SeriesInstanceUID, else the series of FileName when it is a file, else the series
 * with the most files (the others are listed in a warning and in GetSeriesList()).
 *
 * Geometry, in DICOM's patient coordinates (LPS, mm): slices are sorted by ImagePositionPatient
 * projected on the slice normal (file names and InstanceNumber are not trusted); the slice
 * spacing comes from those positions (not SliceThickness); the direction matrix's columns are
 * the row direction, the column direction (ImageOrientationPatient) and their cross product;
 * the origin is the first sorted slice's position; the x and y spacings are PixelSpacing's
 * column and row spacings. Irregular slice spacing is a warning that gives the largest
 * deviation, and the volume is read with the mean spacing.
 *
 * Samples are RescaleSlope * stored + RescaleIntercept (Hounsfield units for CT; the array is
 * named "HU" for CT and "Intensity" otherwise): int16 when every value is an integer that
 * int16 holds, float otherwise. Any transfer syntax GDCM decodes is read: uncompressed little
 * and big endian, deflated, RLE, JPEG baseline, extended and lossless, JPEG-LS, JPEG 2000.
 * Colour images (3 samples per pixel) give 3 components, unscaled. One multi-frame file is a
 * volume of its frames (RT dose: GridFrameOffsetVector; otherwise SpacingBetweenSlices).
 *
 * Distribution (see vtkRGVolumeReader): rank 0 reads every header once and broadcasts the
 * sorted list through the controller; each rank then decodes only the files of its slab.
 *
 * Errors name the file and the problem, on every rank: no DICOM image in the directory, a
 * series that is not there, files of one series that differ in size, pixel format,
 * orientation or pixel spacing, two files at the same position, a file without a position in a
 * series of several, several multi-frame files, a transfer syntax GDCM does not decode, a
 * truncated or undecodable file.
 *
 * @sa vtkRGNIfTIReader vtkDICOMImageReader
 */

#ifndef vtkRGDICOMSeriesReader_h
#define vtkRGDICOMSeriesReader_h

#include "RGMCIOModule.h" // For export macro
#include "vtkRGVolumeReader.h"

#include <memory> // For std::unique_ptr
#include <string> // For std::string

class RGMCIO_EXPORT vtkRGDICOMSeriesReader : public vtkRGVolumeReader
{
public:
  static vtkRGDICOMSeriesReader* New();
  vtkTypeMacro(vtkRGDICOMSeriesReader, vtkRGVolumeReader);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * The SeriesInstanceUID of the series to read; empty (default) for the series of FileName
   * when it is a file, or else the series with the most files.
   */
  vtkSetStringMacro(SeriesInstanceUID);
  vtkGetStringMacro(SeriesInstanceUID);
  ///@}

  /**
   * 1 when `name` is a directory that holds a DICOM file, or a DICOM file (it has the "DICM"
   * mark, or GDCM reads a data set with an image from it); 0 otherwise.
   */
  int CanReadFile(const char* name);

  ///@{
  /**
   * After an update: the series found in the directory, one per line ("UID: N files,
   * description"), the chosen one first; the number of files of the series; the file of slice
   * k (sorted; null when out of range); the rescale of the first slice; how far the slices are
   * from an evenly spaced stack (mm): for a series of files, the largest distance of a slice
   * from its place in the evenly spaced stack fitted to their positions; for a multi-frame
   * file, the largest deviation of a frame gap from the mean.
   */
  const char* GetSeriesList() const { return this->SeriesList.c_str(); }
  int GetNumberOfFiles() const;
  const char* GetSliceFileName(int k) const;
  double GetRescaleSlope() const { return this->RescaleSlope; }
  double GetRescaleIntercept() const { return this->RescaleIntercept; }
  double GetLargestSpacingDeviation() const { return this->LargestSpacingDeviation; }
  ///@}

  /**
   * How many files this rank decoded in its last update: the files of its own slices only, and
   * of those only the ones the piece it held before did not have.
   */
  int GetNumberOfFilesRead() const { return this->NumberOfFilesRead; }

protected:
  vtkRGDICOMSeriesReader();
  ~vtkRGDICOMSeriesReader() override;

  bool Scan(std::vector<vtkIdType>& header, std::string& message) override;
  bool Parse(const std::vector<vtkIdType>& header, std::string& message) override;
  bool ReadExtent(const int extent[6], vtkDataArray* scalars, std::string& message) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  char* SeriesInstanceUID = nullptr;
  std::string SeriesList;
  double RescaleSlope = 1.0;
  double RescaleIntercept = 0.0;
  double LargestSpacingDeviation = 0.0;
  int NumberOfFilesRead = 0;

private:
  vtkRGDICOMSeriesReader(const vtkRGDICOMSeriesReader&) = delete;
  void operator=(const vtkRGDICOMSeriesReader&) = delete;

  struct Internals;
  std::unique_ptr<Internals> Internal;
};

#endif

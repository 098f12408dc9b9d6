/**
 * @class   vtkRGPhantomSource
 * @brief   a deterministic CT-like head phantom in Hounsfield units, at any size
 *
 * vtkRGPhantomSource makes an int16 CT volume (array "HU") of a head-like phantom: air (-1000)
 * around soft tissue (~40), a skull-like bone shell (700 to 1500 HU) with holes (foramen
 * magnum, orbits, two small foramina), a brain (~35) with ventricles (~8) and eyes inside, and
 * separate bone pieces below it (a U-shaped mandible, three vertebrae separated by discs, a small
 * fragment), with mild noise. Boundaries are ramps about one voxel wide, as partial volume
 * makes them in a real scanner.
 *
 * The field of view (default 240 mm) is centred on the origin; spacing is FieldOfView /
 * Dimensions. Every sample depends only on its global index and RandomSeed, so any piece (a
 * slab of slices per rank, with the ghost slices asked for, or any sub-extent asked for) is
 * identical to the same region of the whole volume: ranks generate their own pieces in parallel.
 *
 * World coordinates of useful seeds (mm): the top of the skull (0, 0, 105); the mandible
 * (0, 65, -75); the lowest vertebra (0, -20, -96).
 *
 * @sa vtkRTAnalyticSource
 */

#ifndef vtkRGPhantomSource_h
#define vtkRGPhantomSource_h

#include "RGMCReconstructionModule.h" // For export macro
#include "vtkImageAlgorithm.h"
#include "vtkShortArray.h"   // For LastPiece
#include "vtkSmartPointer.h" // For LastPiece

#include <cstdint> // For std::uint64_t

class RGMCRECONSTRUCTION_EXPORT vtkRGPhantomSource : public vtkImageAlgorithm
{
public:
  static vtkRGPhantomSource* New();
  vtkTypeMacro(vtkRGPhantomSource, vtkImageAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /**
   * Number of samples along x, y, z (default 128 each; at least 2).
   */
  vtkSetVector3Macro(Dimensions, int);
  vtkGetVector3Macro(Dimensions, int);
  ///@}

  ///@{
  /**
   * Physical size of the volume along its longest axis in mm (default 240).
   */
  vtkSetClampMacro(FieldOfView, double, 1e-3, VTK_DOUBLE_MAX);
  vtkGetMacro(FieldOfView, double);
  ///@}

  ///@{
  /**
   * Standard deviation of the noise in HU (default 12; 0 for a noiseless phantom).
   */
  vtkSetClampMacro(NoiseLevel, double, 0.0, 1000.0);
  vtkGetMacro(NoiseLevel, double);
  ///@}

  ///@{
  /**
   * Seed of the noise (default 1).
   */
  vtkSetMacro(RandomSeed, int);
  vtkGetMacro(RandomSeed, int);
  ///@}

  /**
   * The phantom's value in HU at a world point (mm), without noise; exposed for tests.
   */
  double Evaluate(const double x[3]) const;

protected:
  vtkRGPhantomSource();
  ~vtkRGPhantomSource() override = default;

  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  void ExecuteDataWithInformation(vtkDataObject* output, vtkInformation* outInfo) override;
  /// Sets `image` to the piece `outInfo` asks for (rgmc::SlabPiece), with `owned`, and gives it
  /// its HU array, allocated; nullptr when the piece is empty or memory is short (with an error).
  vtkShortArray* AllocatePiece(vtkImageData* image, vtkInformation* outInfo, int owned[6]);

  int Dimensions[3] = { 128, 128, 128 };
  double FieldOfView = 240.0;
  double NoiseLevel = 12.0;
  int RandomSeed = 1;

private:
  vtkRGPhantomSource(const vtkRGPhantomSource&) = delete;
  void operator=(const vtkRGPhantomSource&) = delete;

  double Spacing() const;
  double Ramp() const;
  /// The voxels first..last of row (j, k) in HU, noise included, clamped and rounded to int16:
  /// Evaluate and rgmc::phantom::NoisyVoxel's, to the bit.
  void SampleRow(const double origin[3], const double spacing[3], int first, int last, int j, int k,
    std::uint64_t nx, std::uint64_t ny, short* out) const;

  // The piece made last (the output's own array: the pipeline empties the output before it
  // asks for the next piece), its extent, and when it was made: a piece asked for again with
  // ghost layers copies the slices the two share.
  vtkSmartPointer<vtkShortArray> LastPiece;
  int LastExtent[6] = { 0, -1, 0, -1, 0, -1 };
  vtkTimeStamp MadeTime;
};

#endif

// The geometry of a stack of DICOM images (PASS 5 of the DICOM series reader's scan): which
// images stack together, the axes, the slices sorted along the slice normal, the slice spacing
// fitted to their positions, the origin.
#ifndef rgmcDicomStack_h
#define rgmcDicomStack_h

#include "rgmcDicomTags.h"

#include <sstream>
#include <string>
#include <vector>

namespace rgmc
{

/// One slice of the volume: a file and a frame in it, with its rescale.
struct DicomSlice
{
  std::string Path;
  int Frame = 0;
  double Slope = 1, Intercept = 0;
};

/// A stack of images of one series and, once PlaceSlices has run, the volume they make.
struct DicomStack
{
  std::string Directory; // the directory whose files are scanned, for messages
  // The files of the volume, the chosen series' largest stack (sorted along the slice normal by
  // PlaceSlices).
  std::vector<DicomHeader> Files;
  std::string LeftOut; // the files of the series' other stacks, for messages
  // PASS 5
  double Normal[3] = { 0, 0, 1 };
  double Direction[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 1 }; // row-major; columns: row direction,
                                                       // column direction, slice normal
  double Origin[3] = { 0, 0, 0 };
  double SliceSpacing = 1.0; // the distance between slices along the normal (CheckSliceSpacing)
  double Deviation = 0.0;    // files: the largest distance of a slice from its place in the
                             // evenly spaced stack; frames: the largest deviation of a gap
  std::vector<DicomSlice> Slices;
  int Dimensions[3] = { 0, 0, 0 };
  double Spacing[3] = { 1, 1, 1 };
  std::ostringstream Warnings; // one per line, in the order the passes find them
};

/// Whether two ImageOrientationPatient agree (each direction cosine to 1e-4).
bool SameOrientation(const double a[6], const double b[6]);

/// Whether the pixel spacing of `a` agrees with that of `b` (to 1e-4 of b's).
bool SamePixelSpacing(const DicomHeader& a, const DicomHeader& b);

/// "1, 0, 0, 0, 1, 0": the six direction cosines of an ImageOrientationPatient, for messages.
std::string DescribeOrientation(const double orientation[6]);

/// Whether two images belong to one stack: one size, pixel format, orientation, pixel spacing.
bool SameStack(const DicomHeader& a, const DicomHeader& b);

/// PASS 5: geometry: the axes, the slices in order along the normal, the spacing and the origin
/// (the first slice's position).
bool PlaceSlices(DicomStack& stack, std::string& message);

} // namespace rgmc

#endif

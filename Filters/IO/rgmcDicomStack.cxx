// The geometry of a stack of DICOM images: which images stack together, the axes from their
// orientation, the slices sorted along the normal, the slice spacing fitted to their positions
// (with the tolerance for rounded positions), the origin; a multi-frame file's frame spacing.
#include "rgmcDicomStack.h"

#include "vtkMath.h"

#include <algorithm>
#include <cmath>

namespace rgmc
{

/// Whether two ImageOrientationPatient agree (each direction cosine to 1e-4).
bool SameOrientation(const double a[6], const double b[6])
{
  for (int c = 0; c < 6; ++c)
  {
    if (std::fabs(a[c] - b[c]) > 1e-4)
    {
      return false;
    }
  }
  return true;
}

/// Whether the pixel spacing of `a` agrees with that of `b` (to 1e-4 of b's).
bool SamePixelSpacing(const DicomHeader& a, const DicomHeader& b)
{
  return std::fabs(a.PixelSpacing[0] - b.PixelSpacing[0]) <= 1e-4 * b.PixelSpacing[0] &&
    std::fabs(a.PixelSpacing[1] - b.PixelSpacing[1]) <= 1e-4 * b.PixelSpacing[1];
}

/// "1, 0, 0, 0, 1, 0": the six direction cosines of an ImageOrientationPatient, for messages.
std::string DescribeOrientation(const double orientation[6])
{
  std::string text = ShortNumber(orientation[0]);
  for (int c = 1; c < 6; ++c)
  {
    text += ", " + ShortNumber(orientation[c]);
  }
  return text;
}

/// Whether two images belong to one stack: one size, pixel format, orientation, pixel spacing.
bool SameStack(const DicomHeader& a, const DicomHeader& b)
{
  return a.Rows == b.Rows && a.Columns == b.Columns && a.Samples == b.Samples &&
    a.BitsAllocated == b.BitsAllocated && a.BitsStored == b.BitsStored &&
    a.PixelRepresentation == b.PixelRepresentation && a.HasOrientation == b.HasOrientation &&
    a.HasSpacing == b.HasSpacing && SameOrientation(a.Orientation, b.Orientation) &&
    SamePixelSpacing(a, b);
}

namespace
{

/// PASS 5, first step: the axes from the (unsorted) first file's orientation. Columns of the
/// direction matrix: row direction (along a row, increasing column index: x), column direction
/// (y), their cross product (the slice normal: z).
bool FindAxes(DicomStack& stack, std::string& message)
{
  const DicomHeader& first = stack.Files.front();
  double row[3] = { first.Orientation[0], first.Orientation[1], first.Orientation[2] };
  double column[3] = { first.Orientation[3], first.Orientation[4], first.Orientation[5] };
  if (vtkMath::Normalize(row) < 1e-6 || vtkMath::Normalize(column) < 1e-6 ||
    std::fabs(vtkMath::Dot(row, column)) > 1e-3)
  {
    message = first.Path + " has an ImageOrientationPatient whose two directions are not " +
      "orthogonal unit vectors";
    return false;
  }
  vtkMath::Cross(row, column, stack.Normal);
  vtkMath::Normalize(stack.Normal);
  for (int a = 0; a < 3; ++a)
  {
    stack.Direction[3 * a] = row[a];
    stack.Direction[3 * a + 1] = column[a];
    stack.Direction[3 * a + 2] = stack.Normal[a];
  }
  return true;
}

/// PASS 5 for a series of one file: a slice per frame, at the file's position. A multi-frame
/// volume is spaced by its GridFrameOffsetVector (RT dose), else SpacingBetweenSlices, else
/// SliceThickness (a warning), else 1 mm (a warning).
bool PlaceFrames(DicomStack& stack, std::string& message)
{
  const DicomHeader& first = stack.Files.front();
  std::copy(first.Position, first.Position + 3, stack.Origin);
  for (int f = 0; f < first.Frames; ++f)
  {
    stack.Slices.push_back(DicomSlice{ first.Path, f, first.Slope, first.Intercept });
  }
  if (first.Frames <= 1)
  {
    return true;
  }
  if (first.FrameOffsets.size() == static_cast<std::size_t>(first.Frames))
  {
    const std::vector<double>& offsets = first.FrameOffsets;
    stack.SliceSpacing = (offsets.back() - offsets.front()) / (first.Frames - 1);
    for (int f = 1; f < first.Frames; ++f)
    {
      stack.Deviation =
        std::max(stack.Deviation, std::fabs(offsets[f] - offsets[f - 1] - stack.SliceSpacing));
    }
    for (int a = 0; a < 3; ++a)
    {
      stack.Origin[a] += offsets.front() * stack.Normal[a];
    }
    if (stack.SliceSpacing < 0)
    {
      message = first.Path + " has a decreasing GridFrameOffsetVector";
      return false;
    }
  }
  else if (first.SpacingBetweenSlices > 0)
  {
    stack.SliceSpacing = first.SpacingBetweenSlices;
  }
  else if (first.SliceThickness > 0)
  {
    stack.SliceSpacing = first.SliceThickness;
    stack.Warnings << first.Path << " has " << first.Frames << " frames without "
                   << "SpacingBetweenSlices: spaced by their SliceThickness, "
                   << ShortNumber(stack.SliceSpacing) << " mm\n";
  }
  else
  {
    stack.Warnings << first.Path << " has " << first.Frames << " frames and no slice spacing: "
                   << "spaced by 1 mm\n";
  }
  if (stack.SliceSpacing == 0)
  {
    message = first.Path + " has frames at one position (a zero frame spacing)";
    return false;
  }
  return true;
}

/// PASS 5 for several files, first step: the files sorted by their position along the slice
/// normal; two at one position are an error.
bool SortAlongNormal(std::vector<DicomHeader>& files, const double normal[3], std::string& message)
{
  for (DicomHeader& h : files)
  {
    h.Projection = vtkMath::Dot(h.Position, normal);
  }
  std::stable_sort(files.begin(), files.end(),
    [](const DicomHeader& a, const DicomHeader& b) { return a.Projection < b.Projection; });
  const double extentAlong = files.back().Projection - files.front().Projection;
  const double tolerance = std::max(1e-4, 1e-6 * std::fabs(extentAlong));
  for (std::size_t s = 1; s < files.size(); ++s)
  {
    if (files[s].Projection - files[s - 1].Projection <= tolerance)
    {
      message = files[s].Path + " and " + files[s - 1].Path + " are at the same position (" +
        ShortNumber(files[s].Projection) + " mm along the slice normal): duplicated slice " +
        "positions (two acquisitions in one series?)";
      return false;
    }
  }
  return true;
}

/// How far a slice may lie from its place in an evenly spaced stack and still be read as part of
/// it: min(0.2 mm, a tenth of the spacing). 0.2 mm is the gap difference dcm2niix still treats
/// as one spacing (scanners' rounded positions jitter by less); the tenth keeps a missing slice
/// and a gap of 1.5 spacings errors on thin slices.
double SliceTolerance(double spacing)
{
  return std::min(0.2, 0.1 * spacing);
}

/// PASS 5 for several sorted files: the slice spacing, fitted to the slices' positions along the
/// normal (least squares: position = first + spacing * index), and how far a slice lies from its
/// place in that evenly spaced stack. Scanners write positions as rounded decimal strings, so an
/// oblique stack's gaps jitter: a slice within SliceTolerance of its place is rounding, and the
/// stack is read on the fitted spacing (with a warning giving the spread when a gap differs from
/// it by more than 1%). Farther, slices are never stacked as if evenly spaced: a missing slice or
/// a variable spacing is an error that names the gap that differs most.
bool CheckSliceSpacing(DicomStack& stack, std::string& message)
{
  const std::vector<DicomHeader>& files = stack.Files;
  const std::size_t n = files.size();
  const double extentAlong = files.back().Projection - files.front().Projection;
  const double mean = extentAlong / (n - 1);
  // The fit, about the middle index (sum of (s - middle)^2 = n (n^2 - 1) / 12).
  const double middle = 0.5 * static_cast<double>(n - 1);
  double meanPosition = 0.0;
  for (const DicomHeader& h : files)
  {
    meanPosition += h.Projection;
  }
  meanPosition /= static_cast<double>(n);
  double moment = 0.0;
  for (std::size_t s = 0; s < n; ++s)
  {
    moment += (static_cast<double>(s) - middle) * (files[s].Projection - meanPosition);
  }
  const double spacing =
    moment / (static_cast<double>(n) * (static_cast<double>(n) * n - 1.0) / 12.0);
  double offPlace = 0.0; // the largest distance of a slice from its fitted place
  std::size_t farthest = 0;
  for (std::size_t s = 0; s < n; ++s)
  {
    const double place = meanPosition + (static_cast<double>(s) - middle) * spacing;
    if (std::fabs(files[s].Projection - place) > offPlace)
    {
      offPlace = std::fabs(files[s].Projection - place);
      farthest = s;
    }
  }
  double gapDeviation = 0.0;
  std::size_t worst = 1;
  double smallest = extentAlong, largest = 0.0;
  for (std::size_t s = 1; s < n; ++s)
  {
    const double gap = files[s].Projection - files[s - 1].Projection;
    smallest = std::min(smallest, gap);
    largest = std::max(largest, gap);
    if (std::fabs(gap - spacing) > gapDeviation)
    {
      gapDeviation = std::fabs(gap - spacing);
      worst = s;
    }
  }
  const double tolerance = SliceTolerance(spacing);
  if (offPlace > tolerance)
  {
    message = "the slices of " + stack.Directory +
      " are not evenly spaced: " + files[worst - 1].Path + " and " + files[worst].Path + " are " +
      ShortNumber(files[worst].Projection - files[worst - 1].Projection) +
      " mm apart along the slice normal (at " + ShortNumber(files[worst - 1].Projection) + " and " +
      ShortNumber(files[worst].Projection) + " mm), the mean gap is " + ShortNumber(mean) +
      " mm (a missing slice, or a variable spacing); gaps range from " + ShortNumber(smallest) +
      " to " + ShortNumber(largest) + " mm; " + BaseName(files[farthest].Path) + " lies " +
      ShortNumber(offPlace) + " mm from its place in the evenly spaced stack that fits best (" +
      ShortNumber(spacing) + " mm apart), more than the " + ShortNumber(tolerance) +
      " mm allowed for rounded positions" +
      (stack.LeftOut.empty() ? std::string()
                             : "; left out of this stack as another acquisition: " + stack.LeftOut);
    return false;
  }
  if (gapDeviation > 0.01 * spacing)
  {
    stack.Warnings << "irregular slice spacing in " << stack.Directory << ": the gaps between "
                   << "slices range from " << ShortNumber(smallest) << " to "
                   << ShortNumber(largest) << " mm (the fitted spacing is " << ShortNumber(spacing)
                   << " mm; every slice lies within " << ShortNumber(offPlace)
                   << " mm of its place, at most " << ShortNumber(tolerance)
                   << " mm is taken as rounded positions); the volume is read with the fitted "
                      "spacing\n";
  }
  stack.SliceSpacing = spacing;
  stack.Deviation = offPlace;
  return true;
}

/// PASS 5 for several sorted files: positions off the normal through the first slice cannot be
/// represented: a stack sheared along its planes is a CT acquired with the gantry tilted. Said,
/// with the tilt angle (the shift of the last slice against its distance along the normal).
void WarnOfGantryTilt(DicomStack& stack)
{
  const std::vector<DicomHeader>& files = stack.Files;
  const DicomHeader& first = files.front();
  const double extentAlong = files.back().Projection - first.Projection;
  double offPlane = 0.0, lastOff = 0.0;
  for (const DicomHeader& h : files)
  {
    double d[3];
    for (int a = 0; a < 3; ++a)
    {
      d[a] = h.Position[a] - first.Position[a];
    }
    const double along = vtkMath::Dot(d, stack.Normal);
    for (int a = 0; a < 3; ++a)
    {
      d[a] -= along * stack.Normal[a];
    }
    offPlane = std::max(offPlane, vtkMath::Norm(d));
    lastOff = vtkMath::Norm(d);
  }
  // Shifts no larger than the rounding that CheckSliceSpacing accepts along the normal are
  // rounded positions (an oblique stack's, written as decimal strings), not a tilt.
  if (offPlane > SliceTolerance(stack.SliceSpacing))
  {
    const double tilt = vtkMath::DegreesFromRadians(std::atan2(lastOff, extentAlong));
    stack.Warnings << "the slices of " << stack.Directory << " are shifted within their planes by "
                   << "up to " << ShortNumber(offPlane) << " mm: a gantry tilt of "
                   << ShortNumber(tilt)
                   << " degrees (or slices that do not line up); the volume is read as if they "
                   << "were stacked along the slice normal, so what it shows is sheared by that "
                   << "angle\n";
  }
}

/// PASS 5 for a series of several files: a slice per file, sorted along the normal, evenly
/// spaced, from the first one's position.
bool PlaceFiles(DicomStack& stack, std::string& message)
{
  if (!SortAlongNormal(stack.Files, stack.Normal, message) || !CheckSliceSpacing(stack, message))
  {
    return false;
  }
  WarnOfGantryTilt(stack);
  const DicomHeader& first = stack.Files.front();
  std::copy(first.Position, first.Position + 3, stack.Origin);
  for (const DicomHeader& h : stack.Files)
  {
    stack.Slices.push_back(DicomSlice{ h.Path, 0, h.Slope, h.Intercept });
  }
  return true;
}

} // namespace

/// PASS 5: geometry: the axes, the slices in order along the normal, the spacing and the origin
/// (the first slice's position).
bool PlaceSlices(DicomStack& stack, std::string& message)
{
  if (!FindAxes(stack, message) ||
    !(stack.Files.size() == 1 ? PlaceFrames(stack, message) : PlaceFiles(stack, message)))
  {
    return false;
  }
  const DicomHeader& first = stack.Files.front();
  stack.Dimensions[0] = first.Columns;
  stack.Dimensions[1] = first.Rows;
  stack.Dimensions[2] = static_cast<int>(stack.Slices.size());
  stack.Spacing[0] = first.PixelSpacing[1];
  stack.Spacing[1] = first.PixelSpacing[0];
  stack.Spacing[2] = std::fabs(stack.SliceSpacing);
  if (!first.HasSpacing)
  {
    stack.Warnings << first.Path << " has no PixelSpacing: 1 mm is used\n";
  }
  return true;
}

} // namespace rgmc

// A CT-like head phantom built from signed distance functions, sampled with partial-volume
// ramps and deterministic per-voxel noise.
#include "vtkRGPhantomSource.h"

#include "rgmcPhantomNoise.h"
#include "vtkRGArrays.h"
#include "vtkRGParallel.h"
#include "vtkRGPieces.h"

#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkSMPTools.h"
#include "vtkShortArray.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

vtkStandardNewMacro(vtkRGPhantomSource);

namespace
{

double Length3(double x, double y, double z)
{
  return std::sqrt(x * x + y * y + z * z);
}

/// Signed distance (approximate, exact on the axes) to an axis-aligned ellipsoid.
double EllipsoidSd(const double p[3], const double c[3], const double r[3])
{
  const double q = Length3((p[0] - c[0]) / r[0], (p[1] - c[1]) / r[1], (p[2] - c[2]) / r[2]);
  return (q - 1.0) * std::min(r[0], std::min(r[1], r[2]));
}

/// Signed distance to an infinite cylinder along `axis` through (c) with radius r.
double CylinderSd(const double p[3], int axis, const double c[3], double r)
{
  double d2 = 0.0;
  for (int a = 0; a < 3; ++a)
  {
    if (a != axis)
    {
      d2 += (p[a] - c[a]) * (p[a] - c[a]);
    }
  }
  return std::sqrt(d2) - r;
}

/// Weight of "inside" across a boundary ramp of the given width.
double Inside(double sd, double ramp)
{
  return std::max(0.0, std::min(1.0, 0.5 - sd / ramp));
}

void Mix(double& value, double target, double weight)
{
  value += weight * (target - value);
}

// Most shapes are far from most voxels: there their weight is 0 (a Mix of nothing) or their
// test fails, so they are not evaluated. The boxes below are that, conservatively: a voxel
// outside one is farther than the ramp plus 1e-6 mm from the shape along one axis, and each
// shape's signed distance is at least its distance along any one axis (less the shape's
// reach), so the voxel's value is the same, to the bit, as if the shape had been evaluated.
constexpr double Margin = 1e-6;

/// Whether |p - c| is within `reach` + ramp along every axis.
bool Near(const double p[3], const double c[3], const double reach[3], double ramp)
{
  for (int a = 0; a < 3; ++a)
  {
    if (std::fabs(p[a] - c[a]) > reach[a] + ramp + Margin)
    {
      return false;
    }
  }
  return true;
}

/// Whether EllipsoidSd(p, c, r) can be at most `ramp`: q >= |p_a - c_a| / r_a on each axis, so
/// the distance exceeds the ramp beyond r_a (1 + ramp / min r).
bool NearEllipsoid(const double p[3], const double c[3], const double r[3], double ramp)
{
  const double grow = ramp / std::min(r[0], std::min(r[1], r[2]));
  const double reach[3] = { r[0] * grow + r[0], r[1] * grow + r[1], r[2] * grow + r[2] };
  return Near(p, c, reach, 0.0);
}

// The anatomy, in mm. The cranium is a shell between two ellipsoids.
const double HeadC[3] = { 0, 5, 0 }, HeadR[3] = { 80, 100, 115 };
const double SkullC[3] = { 0, 0, 25 }, SkullOuter[3] = { 72, 90, 80 },
             SkullInner[3] = { 65, 83, 73 };
const double VentricleR[3] = { 6, 20, 10 };
const double EyeR = 12;

/// Brain and ventricles inside the cranium (`inner`: the distance to its inner surface); eyes
/// in front of the orbits.
void AddBrainAndEyes(const double p[3], double inner, double ramp, double& v)
{
  if (inner < ramp)
  {
    Mix(v, 35.0, Inside(inner, ramp));
    for (int side = -1; side <= 1; side += 2)
    {
      const double c[3] = { 8.0 * side, 5, 30 };
      if (NearEllipsoid(p, c, VentricleR, ramp))
      {
        Mix(v, 8.0, Inside(EllipsoidSd(p, c, VentricleR), ramp));
      }
    }
  }
  for (int side = -1; side <= 1; side += 2)
  {
    const double c[3] = { 28.0 * side, 80, 20 };
    const double r[3] = { EyeR, EyeR, EyeR };
    if (NearEllipsoid(p, c, r, ramp))
    {
      Mix(v, 15.0, Inside(EllipsoidSd(p, c, r), ramp));
    }
  }
}

/// The cranium: a shell with holes, its density varying as cortical bone does.
void AddCranium(const double p[3], double inner, double ramp, double& v)
{
  const double outer = EllipsoidSd(p, SkullC, SkullOuter);
  if (outer < ramp)
  {
    double sd = std::max(outer, -inner);
    const double foramen[3] = { 0, -15, 0 };
    sd = std::max(sd, -std::max(CylinderSd(p, 2, foramen, 15), p[2] - 0.0));
    for (int side = -1; side <= 1; side += 2)
    {
      const double orbit[3] = { 28.0 * side, 0, 20 };
      sd = std::max(sd, -std::max(CylinderSd(p, 1, orbit, 14), 30.0 - p[1]));
    }
    const double small[3] = { 0, 0, -20 };
    sd = std::max(sd, -CylinderSd(p, 0, small, 5));
    const double hu = 1100 + 250 * std::sin(0.045 * p[0] + 0.5) * std::cos(0.035 * p[1]) +
      150 * std::sin(0.06 * p[2]);
    Mix(v, hu, Inside(sd, ramp));
  }
}

/// Separate bones below the cranium: the mandible, three vertebrae and a small fragment.
void AddLowerBones(const double p[3], double ramp, double& v)
{
  // Mandible: the front half of a torus (its distance is at least |p - c| - 47 across and
  // |p - c| - 7 along z, and at least 15 - y).
  const double mandible[3] = { 0, 25, -75 }, mandibleReach[3] = { 47, 47, 7 };
  if (Near(p, mandible, mandibleReach, ramp) && 15.0 - p[1] <= ramp + Margin)
  {
    const double* c = mandible;
    const double ring = std::sqrt((p[0] - c[0]) * (p[0] - c[0]) + (p[1] - c[1]) * (p[1] - c[1]));
    double sd = std::sqrt((ring - 40) * (ring - 40) + (p[2] - c[2]) * (p[2] - c[2])) - 7;
    sd = std::max(sd, 15.0 - p[1]);
    if (sd < ramp)
    {
      Mix(v, 1200.0, Inside(sd, ramp));
    }
  }
  // Three vertebrae (discs between them stay soft tissue).
  for (int n = 0; n < 3; ++n)
  {
    const double c[3] = { 0, -20, -96.0 + 14.0 * n }, reach[3] = { 14, 14, 4.5 };
    if (!Near(p, c, reach, ramp))
    {
      continue;
    }
    const double sd = std::max(CylinderSd(p, 2, c, 14), std::fabs(p[2] - c[2]) - 4.5);
    if (sd < ramp)
    {
      Mix(v, 950.0, Inside(sd, ramp));
    }
  }
  // A small fragment.
  {
    const double c[3] = { 50, -50, -45 }, r[3] = { 5, 5, 5 };
    const double sd = NearEllipsoid(p, c, r, ramp) ? EllipsoidSd(p, c, r) : ramp;
    if (sd < ramp)
    {
      Mix(v, 1000.0, Inside(sd, ramp));
    }
  }
}

} // namespace

//------------------------------------------------------------------------------
vtkRGPhantomSource::vtkRGPhantomSource()
{
  this->SetNumberOfInputPorts(0);
}

double vtkRGPhantomSource::Spacing() const
{
  const int longest =
    std::max(this->Dimensions[0], std::max(this->Dimensions[1], this->Dimensions[2]));
  return this->FieldOfView / std::max(1, longest);
}

double vtkRGPhantomSource::Ramp() const
{
  return std::max(1.2, 1.5 * this->Spacing());
}

//------------------------------------------------------------------------------
double vtkRGPhantomSource::Evaluate(const double p[3]) const
{
  const double ramp = this->Ramp();
  double v = -1000.0; // air

  const double head = EllipsoidSd(p, HeadC, HeadR);
  if (head > ramp)
  {
    return v;
  }
  Mix(v, 40.0, Inside(head, ramp));
  const double inner = EllipsoidSd(p, SkullC, SkullInner);
  AddBrainAndEyes(p, inner, ramp, v);
  AddCranium(p, inner, ramp, v);
  AddLowerBones(p, ramp, v);
  return v;
}

//------------------------------------------------------------------------------
int vtkRGPhantomSource::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  for (int a = 0; a < 3; ++a)
  {
    if (this->Dimensions[a] < 2)
    {
      vtkErrorMacro(<< "Dimensions must be at least 2 along each axis, not " << this->Dimensions[0]
                    << " x " << this->Dimensions[1] << " x " << this->Dimensions[2] << ".");
      return 0;
    }
  }
  const int whole[6] = { 0, this->Dimensions[0] - 1, 0, this->Dimensions[1] - 1, 0,
    this->Dimensions[2] - 1 };
  const double h = this->Spacing();
  const double spacing[3] = { h, h, h };
  double origin[3];
  for (int a = 0; a < 3; ++a)
  {
    origin[a] = -0.5 * (this->Dimensions[a] - 1) * h;
  }
  outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole, 6);
  outInfo->Set(vtkDataObject::SPACING(), spacing, 3);
  outInfo->Set(vtkDataObject::ORIGIN(), origin, 3);
  // A piece per rank in slabs, its ghost slices marked here (rgmc::SlabPiece says why).
  outInfo->Remove(vtkAlgorithm::CAN_PRODUCE_SUB_EXTENT());
  outInfo->Set(vtkAlgorithm::CAN_HANDLE_PIECE_REQUEST(), 1);
  vtkDataObject::SetPointDataActiveScalarInfo(outInfo, VTK_SHORT, 1);
  return 1;
}

//------------------------------------------------------------------------------
vtkShortArray* vtkRGPhantomSource::AllocatePiece(
  vtkImageData* image, vtkInformation* outInfo, int owned[6])
{
  const int whole[6] = { 0, this->Dimensions[0] - 1, 0, this->Dimensions[1] - 1, 0,
    this->Dimensions[2] - 1 };
  int ext[6];
  image->Initialize();
  image->SetSpacing(outInfo->Get(vtkDataObject::SPACING()));
  image->SetOrigin(outInfo->Get(vtkDataObject::ORIGIN()));
  if (!rgmc::SlabPiece(outInfo, whole, ext, owned))
  {
    return nullptr; // more pieces than layers: this one is empty
  }
  image->SetExtent(ext);
  vtkNew<vtkShortArray> hu;
  hu->SetName("HU");
  try
  {
    rgmc::Allocate(hu.Get(), image->GetNumberOfPoints());
  }
  catch (const std::bad_alloc&)
  {
    image->Initialize();
    vtkErrorMacro(<< "Could not allocate the int16 output array of " << image->GetNumberOfPoints()
                  << " voxels.");
    return nullptr;
  }
  image->GetPointData()->SetScalars(hu);
  return hu.Get(); // held by the image
}

//------------------------------------------------------------------------------
void vtkRGPhantomSource::ExecuteDataWithInformation(vtkDataObject* output, vtkInformation* outInfo)
{
  if (this->MadeTime < this->GetMTime())
  {
    this->LastPiece = nullptr; // changed since: of no use, and not to be held while allocating
  }
  vtkImageData* image = vtkImageData::SafeDownCast(output);
  int owned[6];
  vtkShortArray* hu = this->AllocatePiece(image, outInfo, owned);
  if (!hu)
  {
    return;
  }
  int ext[6];
  image->GetExtent(ext);
  double origin[3], spacing[3];
  image->GetOrigin(origin);
  image->GetSpacing(spacing);
  const std::uint64_t nx = this->Dimensions[0], ny = this->Dimensions[1];
  const vtkIdType slice = vtkIdType(ext[1] - ext[0] + 1) * (ext[3] - ext[2] + 1);
  short* out = hu->GetPointer(0);
  // The slices shared with the piece made last, when nothing has changed since, are copied.
  int lo, hi;
  vtkSmartPointer<vtkShortArray> previous;
  if (this->LastPiece && rgmc::SharedSlices(ext, this->LastExtent, lo, hi))
  {
    previous = this->LastPiece;
  }
  this->LastPiece = nullptr;
  const int* last = this->LastExtent;
  // Every voxel is a function of its index alone, so the slices are made on the threads with
  // the same result; progress and abort are checked between waves of slices, on this thread.
  const int wave = 4 * std::max(1, vtkSMPTools::GetEstimatedNumberOfThreads());
  bool aborted = false;
  for (int first = ext[4]; first <= ext[5]; first += wave)
  {
    if (ext[5] > ext[4])
    {
      this->UpdateProgress(double(first - ext[4]) / (ext[5] - ext[4] + 1));
    }
    if (this->CheckAbort())
    {
      aborted = true;
      break;
    }
    const int end = std::min(ext[5], first + wave - 1);
    rgmc::ParallelFor(end - first + 1, 1,
      [&](vtkIdType begin, vtkIdType stop)
      {
        for (vtkIdType s = begin; s < stop; ++s)
        {
          const int k = first + static_cast<int>(s);
          short* v = out + (k - ext[4]) * slice;
          if (previous && k >= lo && k <= hi)
          {
            const short* from = previous->GetPointer(0) + (k - last[4]) * slice;
            std::copy(from, from + slice, v);
            continue;
          }
          for (int j = ext[2]; j <= ext[3]; ++j)
          {
            this->SampleRow(origin, spacing, ext[0], ext[1], j, k, nx, ny, v);
            v += ext[1] - ext[0] + 1;
          }
        }
      });
  }
  if (!aborted)
  {
    this->LastPiece = hu;
    std::copy(ext, ext + 6, this->LastExtent);
    this->MadeTime.Modified();
  }
  rgmc::CacheRanges(hu);
  rgmc::MarkGhosts(image, owned);
}

//------------------------------------------------------------------------------
void vtkRGPhantomSource::SampleRow(const double origin[3], const double spacing[3], int first,
  int last, int j, int k, std::uint64_t nx, std::uint64_t ny, short* out) const
{
  double p[3] = { 0, origin[1] + j * spacing[1], origin[2] + k * spacing[2] };
  // Evaluate returns air (-1000) where the head's signed distance exceeds the ramp, that is
  // where q = |(p - HeadC) / HeadR| > 1 + ramp / min(HeadR). Along the row, q^2 = dx^2 + s: the
  // voxels with dx^2 > limit^2 - s + 1e-9 are air without evaluating them (the 1e-9 on q^2 is
  // far above the rounding of these sums, so none of them is a voxel Evaluate would not give
  // -1000).
  const double ramp = this->Ramp();
  const double limit = 1.0 + ramp / std::min(HeadR[0], std::min(HeadR[1], HeadR[2]));
  const double dy = (p[1] - HeadC[1]) / HeadR[1], dz = (p[2] - HeadC[2]) / HeadR[2];
  const double room = limit * limit - (dy * dy + dz * dz) + 1e-9;
  const double half = room > 0 ? HeadR[0] * std::sqrt(room) * (1.0 + 1e-12) : -1.0;
  const std::uint64_t row = (std::uint64_t(k) * ny + j) * nx;
  const double level = this->NoiseLevel;
  for (int i = first; i <= last; ++i)
  {
    p[0] = origin[0] + i * spacing[0];
    const double value = std::fabs(p[0] - HeadC[0]) > half ? -1000.0 : this->Evaluate(p);
    *out++ = level > 0 ? rgmc::phantom::NoisyVoxel(value, level, row + i, this->RandomSeed)
                       : rgmc::phantom::Voxel(value);
  }
}

//------------------------------------------------------------------------------
void vtkRGPhantomSource::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Dimensions: " << this->Dimensions[0] << " " << this->Dimensions[1] << " "
     << this->Dimensions[2] << "\n";
  os << indent << "FieldOfView: " << this->FieldOfView << "\n";
  os << indent << "NoiseLevel: " << this->NoiseLevel << "\n";
  os << indent << "RandomSeed: " << this->RandomSeed << "\n";
}

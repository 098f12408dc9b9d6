// The volumes the kernel and span benchmarks extract from: the CT phantom, a noisy CT-like
// head and a dense gyroid, each with its isovalue and a seed on its structure.
#ifndef rgmcBenchmarkVolumes_h
#define rgmcBenchmarkVolumes_h

#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkRGPhantomSource.h"
#include "vtkShortArray.h"
#include "vtkSmartPointer.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

namespace rgmc_benchmark
{

/// A volume to extract from, with its isovalue and a seed on the structure (world).
struct Volume
{
  std::string Name;
  vtkSmartPointer<vtkImageData> Image;
  double Isovalue;
  double Seed[3];
};

inline Volume Phantom(int size)
{
  vtkNew<vtkRGPhantomSource> phantom;
  phantom->SetDimensions(size, size, size);
  phantom->Update();
  Volume v{ "phantom" + std::to_string(size), vtkSmartPointer<vtkImageData>::New(), 400.0,
    { 0, 0, 105 } };
  v.Image->DeepCopy(phantom->GetOutput());
  v.Image->GetPointData()->SetActiveScalars("HU");
  return v;
}

/// A noisy CT-like head, int16 HU, 1 mm voxels: air, an ellipsoidal head of soft tissue (40 HU)
/// inside a bone shell (about 1100 HU, 6 % of the radius thick, thinner at the top), and under
/// it a curved head holder (500 HU) apart from the head; noise of about 40 HU from a fixed
/// sequence (the same volume on every run). The structure at 300 HU: the skull shell.
inline Volume NoisyHead(int size)
{
  Volume v{ "noisy_head" + std::to_string(size), vtkSmartPointer<vtkImageData>::New(), 300.0,
    { 0, 0, 0 } };
  vtkImageData* image = v.Image;
  image->SetDimensions(size, size, size);
  image->SetSpacing(1, 1, 1);
  image->SetOrigin(-0.5 * (size - 1), -0.5 * (size - 1), -0.5 * (size - 1));
  vtkNew<vtkShortArray> hu;
  hu->SetName("HU");
  hu->SetNumberOfTuples(static_cast<vtkIdType>(size) * size * size);
  const double r = 0.40 * size; // the head's half-axes: r, 1.15 r, 0.95 r
  std::uint64_t state = 0x9E3779B97F4A7C15ull;
  auto noise = [&state]()
  {
    // The sum of 4 uniform numbers: roughly Gaussian, sd ~ 40 HU.
    double sum = 0;
    for (int n = 0; n < 4; ++n)
    {
      state = state * 6364136223846793005ull + 1442695040888963407ull;
      sum += static_cast<double>(state >> 11) / 9007199254740992.0 - 0.5;
    }
    return 138.0 * sum;
  };
  const double c = 0.5 * (size - 1);
  for (int k = 0; k < size; ++k)
  {
    for (int j = 0; j < size; ++j)
    {
      for (int i = 0; i < size; ++i)
      {
        const double x = (i - c) / r, y = (j - c) / (1.15 * r), z = (k - c) / (0.95 * r);
        const double d = std::sqrt(x * x + y * y + z * z);
        const double thickness = 0.06 * (1.0 - 0.3 * std::max(0.0, z));
        double value = -1000.0;
        if (d < 1.0 - thickness)
        {
          value = 40.0;
        }
        else if (d < 1.0)
        {
          value = 1100.0;
        }
        // The holder: a curved plate under the head's back (y), apart from the skull.
        const double h = std::sqrt(x * x + z * z * 0.8 + (y + 0.3) * (y + 0.3));
        if (y < -0.2 && h > 1.12 && h < 1.17 && std::abs(z) < 0.6)
        {
          value = 500.0;
        }
        const double s = value + noise();
        hu->SetValue(i + static_cast<vtkIdType>(size) * (j + static_cast<vtkIdType>(size) * k),
          static_cast<short>(std::lround(std::max(-1024.0, std::min(3000.0, s)))));
      }
    }
  }
  image->GetPointData()->SetScalars(hu);
  // The seed: on the top of the skull shell, inside the bone.
  v.Seed[2] = 0.95 * r * (1.0 - 0.5 * 0.06 * 0.7);
  return v;
}

/// A dense surface, to measure the cost of a triangle rather than of a scan: an int16 gyroid,
/// 1000 (sin x cos y + sin y cos z + sin z cos x) with `period` voxels per cell, at 0.5 (no
/// sample equals it). Its level set is one connected surface through the whole volume, about
/// 0.6 triangles a voxel at period 16, so a seed anywhere on it selects nearly every triangle
/// vtkFlyingEdges3D makes.
inline Volume Gyroid(int size, double period)
{
  Volume v{ "gyroid" + std::to_string(size), vtkSmartPointer<vtkImageData>::New(), 0.5,
    { 0, 0, 0 } };
  vtkImageData* image = v.Image;
  image->SetDimensions(size, size, size);
  vtkNew<vtkShortArray> values;
  values->SetName("Gyroid");
  values->SetNumberOfTuples(static_cast<vtkIdType>(size) * size * size);
  const double w = 2.0 * M_PI / period;
  for (int k = 0; k < size; ++k)
  {
    for (int j = 0; j < size; ++j)
    {
      for (int i = 0; i < size; ++i)
      {
        const double x = w * (i + 0.25), y = w * (j + 0.5), z = w * (k + 0.125);
        const double g =
          std::sin(x) * std::cos(y) + std::sin(y) * std::cos(z) + std::sin(z) * std::cos(x);
        values->SetValue(i + static_cast<vtkIdType>(size) * (j + static_cast<vtkIdType>(size) * k),
          static_cast<short>(std::lround(1000.0 * g)));
      }
    }
  }
  image->GetPointData()->SetScalars(values);
  for (int a = 0; a < 3; ++a)
  {
    v.Seed[a] = 0.5 * (size - 1); // the surface passes within period / 2 of any point
  }
  return v;
}

} // namespace rgmc_benchmark

#endif

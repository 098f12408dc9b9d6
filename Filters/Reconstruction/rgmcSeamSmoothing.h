// Seam Repair: smoothing that is the same on any number of ranks.
#ifndef rgmcSeamSmoothing_h
#define rgmcSeamSmoothing_h

#include "rgmcBuffer.h"
#include "rgmcSeamAnalysis.h"
#include "rgmcSmoothing.h"
#include "vtkRGParallel.h"
#include "vtkRGSeamRepair.h"

#include <algorithm>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace rgmc
{
namespace seam
{

/// What the smoothing is asked to do.
struct SmoothingSettings
{
  int Method = vtkRGSeamRepair::NO_SMOOTHING;
  int Iterations = 0;
  double Relaxation = 0.0;
  double PassBand = 0.0;
  rgmc::SincWindow Window = rgmc::SincWindow::Nuttall;
};

/// The smoothing of the positions over the stencils, with the neighbours held elsewhere fetched
/// and the owners' new positions sent every iteration.
template <typename T, typename I>
class SeamSmoothing : public SeamAnalysis<T, I>
{
public:
  using SeamAnalysis<T, I>::SeamAnalysis;

  /// Smooths the positions into Smoothed. Returns false when aborted (`problem` empty) or
  /// failed. Per iteration: a reduction (abort) and two exchanges with the sharing ranks.
  bool Smooth(const SmoothingSettings& settings, const std::function<bool(double)>& progress,
    std::string& problem)
  {
    bool aborted = false;
    const bool done = settings.Method == vtkRGSeamRepair::WINDOWED_SINC
      ? this->SmoothWindowedSinc(settings, progress, aborted, problem)
      : this->SmoothLaplacian(settings, progress, aborted, problem);
    if (!done)
    {
      return false;
    }
    // The stencils are done with: the normals need the memory.
    rgmc::OverwriteVector<I>().swap(this->Stencil.Neighbours);
    rgmc::OverwriteVector<std::int64_t>().swap(this->Stencil.Offsets);
    rgmc::HeapOverwriteVector<I>().swap(this->Owned);
    if (!this->AllRanks.Agree(true, problem) || aborted)
    {
      return false;
    }
    this->Smoothed.resize(3 * this->NumVertices);
    return true;
  }

  /// Positions of this rank's vertices after smoothing: sized, then written whole on threads
  /// (a zeroed vector was faulted in and zeroed on one thread: 1.3 ms of the span's 12).
  rgmc::HeapOverwriteVector<T> Smoothed;

private:
  /// Jacobi Laplacian, in double, rounded once at the end.
  bool SmoothLaplacian(const SmoothingSettings& settings,
    const std::function<bool(double)>& progress, bool& aborted, std::string& problem)
  {
    const std::size_t size = 3 * (this->NumVertices + this->RemoteGids.size());
    rgmc::OverwriteVector<double> current, next; // both filled whole below, on threads
    if (!this->AllRanks.Step("smooth the surface", problem,
          [&]()
          {
            current.resize(size);
            next.resize(size);
            const std::size_t own = 3 * static_cast<std::size_t>(this->NumVertices);
            rgmc::ForEachChunk(static_cast<vtkIdType>(size), rgmc::ElementChunk,
              [&](vtkIdType, vtkIdType first, vtkIdType last)
              {
                for (vtkIdType i = first; i < last; ++i)
                {
                  current[i] = next[i] = static_cast<std::size_t>(i) < own
                    ? static_cast<double>(this->Positions[i])
                    : this->RemoteInitial[static_cast<std::size_t>(i) - own];
                }
              });
          }))
    {
      return false;
    }
    for (int it = 0; it < settings.Iterations && !aborted; ++it)
    {
      if (progress(double(it) / settings.Iterations))
      {
        aborted = true;
        break;
      }
      this->Fetch(current.data());
      rgmc::ParallelFor(static_cast<vtkIdType>(this->Owned.size()), RowGrain,
        [&](vtkIdType first, vtkIdType last)
        {
          rgmc::LaplacianStep(this->Stencil, this->Owned.data(), current.data(), next.data(),
            settings.Relaxation, first, last);
        });
      this->Update(next.data());
      std::swap(current, next);
    }
    rgmc::OverwriteVector<double>().swap(next);
    return this->AllRanks.Step("smooth the surface", problem,
      [&]()
      {
        this->Smoothed.resize(3 * static_cast<std::size_t>(this->NumVertices));
        rgmc::ForEachChunk(3 * this->NumVertices, rgmc::ElementChunk,
          [&](vtkIdType, vtkIdType first, vtkIdType last)
          {
            for (vtkIdType i = first; i < last; ++i)
            {
              this->Smoothed[i] = static_cast<T>(current[i]);
            }
          });
      });
  }

  /// Windowed sinc, in the points' type, as VTK's filter: x0, x1, x2 the last three states,
  /// `sum` the result.
  bool SmoothWindowedSinc(const SmoothingSettings& settings,
    const std::function<bool(double)>& progress, bool& aborted, std::string& problem)
  {
    const std::size_t size = 3 * (this->NumVertices + this->RemoteGids.size());
    std::vector<T> a, b, c;
    rgmc::HeapOverwriteVector<T> sum; // becomes Smoothed
    std::vector<double> coefficients;
    if (!this->AllRanks.Step("smooth the surface", problem,
          [&]()
          {
            a.resize(size);
            b.resize(size);
            std::copy(this->Positions, this->Positions + 3 * this->NumVertices, a.begin());
            for (std::size_t r = 0; r < this->RemoteGids.size(); ++r)
            {
              for (int k = 0; k < 3; ++k)
              {
                a[3 * (this->NumVertices + r) + k] = static_cast<T>(this->RemoteInitial[3 * r + k]);
              }
            }
            c.resize(size);
            sum.assign(size, T());
            coefficients =
              rgmc::SincCoefficients(settings.Iterations, settings.PassBand, settings.Window);
          }))
    {
      return false;
    }
    T* x0 = a.data();
    T* x1 = b.data();
    T* x2 = c.data();
    this->Fetch(x0);
    rgmc::ParallelFor(static_cast<vtkIdType>(this->Owned.size()), RowGrain,
      [&](vtkIdType first, vtkIdType last)
      {
        rgmc::SincFirstStep(
          this->Stencil, this->Owned.data(), x0, x1, sum.data(), coefficients.data(), first, last);
      });
    this->Update(x1);
    for (int it = 2; it <= settings.Iterations; ++it)
    {
      if (progress(double(it) / settings.Iterations))
      {
        aborted = true;
        break;
      }
      this->Fetch(x1);
      rgmc::ParallelFor(static_cast<vtkIdType>(this->Owned.size()), RowGrain,
        [&](vtkIdType first, vtkIdType last)
        {
          rgmc::SincStep(this->Stencil, this->Owned.data(), x0, x1, x2, sum.data(),
            coefficients[it], first, last);
        });
      this->Update(x2);
      T* oldest = x0;
      x0 = x1;
      x1 = x2;
      x2 = oldest;
    }
    this->Update(sum.data());
    this->Smoothed.swap(sum);
    return true;
  }
};

} // namespace seam
} // namespace rgmc

#endif // rgmcSeamSmoothing_h

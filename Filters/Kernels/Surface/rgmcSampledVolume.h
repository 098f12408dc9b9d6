// One rank's piece of the volume as the three passes read it: its samples (with NaN checks),
// the cubes it owns, the state the passes share (errors, abort, progress, threads), and the
// position and normal of a surface vertex, bitwise identical on every rank.
#ifndef rgmcSampledVolume_h
#define rgmcSampledVolume_h

#include "rgmcCubeSurface.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <exception>
#include <limits>
#include <mutex>
#include <sstream>
#include <string>
#include <type_traits>
#include <utility>

#if defined(__SSE2__)
#include <emmintrin.h>
#elif defined(__aarch64__)
#include <arm_neon.h>
#endif

namespace rgmc
{

/// x[v] = sqrt(x[v]) for v < N (N even), two at a time where the processor has them: the
/// compiler keeps std::sqrt scalar for errno's sake, and a square root is correctly rounded in
/// any width, so the values are std::sqrt's to the bit.
template <int N>
RGMC_INLINE void SquareRoots(double* x)
{
  static_assert(N % 2 == 0, "pairs");
#if defined(__SSE2__)
  for (int v = 0; v < N; v += 2)
  {
    _mm_storeu_pd(x + v, _mm_sqrt_pd(_mm_loadu_pd(x + v)));
  }
#elif defined(__aarch64__)
  for (int v = 0; v < N; v += 2)
  {
    vst1q_f64(x + v, vsqrtq_f64(vld1q_f64(x + v)));
  }
#else
  for (int v = 0; v < N; ++v)
  {
    x[v] = std::sqrt(x[v]);
  }
#endif
}

/// One rank's piece of the volume: its samples (NaN checked), the cubes it owns, and the
/// geometry of surface vertices (bitwise identical on every rank: computed from global indices
/// only).
template <typename Values>
class SampledVolume
{
public:
  using ValueType = typename std::decay<decltype(std::declval<const Values&>()[0])>::type;

  SampledVolume(const CaseTable& table, const Grid& grid, const Ownership& ownership,
    const Values& values, const SurfaceOptions& options)
    : Table(table)
    , GridOf(grid)
    , Owned(ownership)
    , Samples(values)
    , Options(options)
  {
    for (int v = 0; v < 8; ++v)
    {
      this->CornerStride[v] = CornerOffset[v][0] + this->GridOf.StrideY * CornerOffset[v][1] +
        this->GridOf.StrideZ * CornerOffset[v][2];
    }
    const CellBox& box = this->Owned.Mine();
    for (int a = 0; a < 3; ++a)
    {
      // Grid points where the gradient is central on every axis with samples at hand.
      this->CentralLo[a] = std::max(this->GridOf.WholeLo[a], this->GridOf.LocalLo[a]) + 1;
      this->CentralHi[a] = std::min(this->GridOf.WholeHi[a], this->GridOf.LocalHi[a]) - 1;
      // Grid points all of whose surrounding cubes this rank owns (no ports there).
      this->InnerLo[a] = box.Lo[a] + 1;
      this->InnerHi[a] = box.Hi[a];
    }
  }

  const CaseTable& Table;
  const Grid& GridOf;
  const Ownership& Owned;
  const Values& Samples;
  const SurfaceOptions Options; // the isovalue among them

  // ---- state shared by the passes ------------------------------------------------------------

  /// Empty unless a sample was not a number (the message names the grid point).
  std::string Error() const
  {
    std::lock_guard<std::mutex> lock(this->ErrorMutex);
    return this->ErrorText;
  }
  bool Aborted() const { return this->AbortFlag; }
  /// Whether the work should stop: aborted, a NaN met, or a task of Parallel failed.
  bool Stopped() const
  {
    return this->AbortFlag.load(std::memory_order_relaxed) ||
      this->Failed.load(std::memory_order_relaxed) ||
      this->Interrupted.load(std::memory_order_relaxed);
  }
  /// True when a gradient needed a sample beyond this piece that lies inside the volume (the
  /// input lacked its ghost layer); such normals are one-sided.
  bool MissingGhosts() const { return this->GhostsMissing; }

  /// Reports progress (never backwards) and notes an abort. From the calling thread only.
  void Report(double fraction)
  {
    this->Reported = std::max(this->Reported, fraction);
    if (this->Options.Progress && this->Options.Progress(this->Reported))
    {
      this->AbortFlag = true;
    }
  }

  /// Names the phase of the work that starts here (Options.Phase). From the calling thread only.
  void Mark(const char* phase)
  {
    if (this->Options.Phase)
    {
      this->Options.Phase(phase);
    }
  }

  /// Runs task(i) for every i in [0, count), through Options.ParallelFor. An exception thrown
  /// by a task stops the others and is thrown again here (the first one caught).
  template <typename Task>
  void Parallel(std::int64_t count, Task&& task)
  {
    std::exception_ptr failure;
    std::mutex failureMutex;
    auto range = [&](std::int64_t begin, std::int64_t end)
    {
      for (std::int64_t i = begin; i < end && !this->Stopped(); ++i)
      {
        try
        {
          task(i);
        }
        catch (...)
        {
          std::lock_guard<std::mutex> lock(failureMutex);
          if (!failure)
          {
            failure = std::current_exception();
          }
          this->Interrupted = true;
        }
      }
    };
    if (this->Options.ParallelFor && count > 1)
    {
      this->Options.ParallelFor(count, range);
    }
    else
    {
      range(0, count);
    }
    if (failure)
    {
      std::rethrow_exception(failure);
    }
  }

  // ---- samples -------------------------------------------------------------------------------

  /// The sample at grid point (i, j, k) of this piece; a NaN stops the work with an error.
  double Read(int i, int j, int k)
  {
    const double s = static_cast<double>(this->Samples[this->GridOf.LocalIndex(i, j, k)]);
    if (!std::is_integral<ValueType>::value && s != s)
    {
      this->Fail(i, j, k);
    }
    return s;
  }

  /// Reads the 8 corners of cube (i, j, k); false when a sample is NaN.
  RGMC_INLINE bool Evaluate(int i, int j, int k, CubeSamples& st)
  {
    const std::int64_t base = this->GridOf.LocalIndex(i, j, k);
    int code = 0;
    bool degenerate = false;
    for (int v = 0; v < 8; ++v)
    {
      const double s = static_cast<double>(this->Samples[base + this->CornerStride[v]]);
      if (!std::is_integral<ValueType>::value && s != s)
      {
        this->Fail(i + CornerOffset[v][0], j + CornerOffset[v][1], k + CornerOffset[v][2]);
        return false;
      }
      st.Corners[v] = s;
      code |= (s >= this->Options.Isovalue) << v;
      degenerate |= (s == this->Options.Isovalue);
    }
    st.Case = code;
    st.Degenerate = degenerate;
    return true;
  }

  /// What Describe needs of a surface node's cube: the case growth found and, for a cube with a
  /// degenerate sample, its samples read again (the others need only their case). False when a
  /// sample is NaN, as for Evaluate.
  RGMC_INLINE bool NodeSamples(const SurfaceNode& n, CubeSamples& st)
  {
    st.Case = n.Case;
    st.Degenerate = n.Degenerate;
    return !n.Degenerate || this->Evaluate(n.I, n.J, n.K, st);
  }

  /// Classifies the grid points (i0 + b, j, k), 0 <= b < n <= 64, as Evaluate would: bit b of
  /// `above` is set when the sample is at or above the isovalue, of `notNumber` when it is NaN
  /// (floating-point samples only). Reads each sample once, in memory order.
  RGMC_INLINE void ClassifyRow(
    int i0, int n, int j, int k, std::uint64_t& above, std::uint64_t& notNumber) const
  {
    const std::int64_t base = this->GridOf.LocalIndex(i0, j, k);
    const double c = this->Options.Isovalue;
    if constexpr (std::is_integral<ValueType>::value && sizeof(ValueType) <= 4 &&
      std::is_lvalue_reference<decltype(std::declval<const Values&>()[0])>::value)
    {
      // Integers of up to 32 bits are exact in double: s >= c exactly when s >= ceil(c), which
      // is compared in the samples' own type, a row at a time (the compiler vectorizes it).
      notNumber = 0;
      const double t = std::ceil(c);
      if (!(t <= static_cast<double>(std::numeric_limits<ValueType>::max())))
      {
        above = 0; // c above every sample, or NaN (nothing is >= NaN)
        return;
      }
      const std::uint64_t all = n == 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << n) - 1;
      if (t <= static_cast<double>(std::numeric_limits<ValueType>::min()))
      {
        above = all;
        return;
      }
      const ValueType threshold = static_cast<ValueType>(t);
      const ValueType* row = &this->Samples[base];
      unsigned char at[64];
      for (int b = 0; b < n; ++b)
      {
        at[b] = row[b] >= threshold;
      }
      std::uint64_t a = 0;
      for (int b = 0; b < n; ++b)
      {
        a |= static_cast<std::uint64_t>(at[b]) << b;
      }
      above = a;
      return;
    }
    std::uint64_t a = 0, x = 0;
    for (int b = 0; b < n; ++b)
    {
      const double s = static_cast<double>(this->Samples[base + b]);
      a |= static_cast<std::uint64_t>(s >= c) << b;
      if (!std::is_integral<ValueType>::value)
      {
        x |= static_cast<std::uint64_t>(s != s) << b;
      }
    }
    above = a;
    notNumber = x;
  }

  /// Asks the processor to fetch the samples that extraction reads for cube (i, j, k): its
  /// corners and their neighbours along each axis (the gradients' central differences), rows
  /// j - 1 to j + 2 of planes k and k + 1 and rows j, j + 1 of planes k - 1 and k + 2. Only
  /// where all of them lie in this piece; a hint, it changes no result.
  RGMC_INLINE void PrefetchAround(int i, int j, int k) const
  {
    if constexpr (std::is_lvalue_reference<decltype(std::declval<const Values&>()[0])>::value)
    {
      this->PrefetchSamples(i, j, k);
    }
  }

  /// The surface nodes of cube (i, j, k) with samples `st`.
  RGMC_INLINE void Describe(int i, int j, int k, const CubeSamples& st, CubeSurface& surface) const
  {
    surface.Set(this->Table, this->GridOf, this->Options.Isovalue, i, j, k, st);
  }

  // ---- vertex geometry -----------------------------------------------------------------------

  void ToWorld(const double idx[3], double x[3]) const
  {
    const auto& m = this->Options.IndexToWorld;
    for (int r = 0; r < 3; ++r)
    {
      x[r] = m[r][0] * idx[0] + m[r][1] * idx[1] + m[r][2] * idx[2] + m[r][3];
    }
  }

  /// The vertex on the edge leaving grid point p along `axis`, interpolated from the lower end
  /// as vtkMarchingCubes does (x = p_lo + t (p_hi - p_lo)); returns t.
  double EdgePosition(const int p[3], int axis, double sLo, double sHi, double x[3]) const
  {
    const double t = (this->Options.Isovalue - sLo) / (sHi - sLo);
    double idx[3] = { double(p[0]), double(p[1]), double(p[2]) };
    idx[axis] = idx[axis] + t * 1.0;
    this->ToWorld(idx, x);
    return t;
  }

  /// The world position of a vertex of a cube with samples `st`.
  void Position(const SurfaceVertex& v, const CubeSamples& st, double x[3]) const
  {
    if (v.Axis < 0)
    {
      const double idx[3] = { double(v.Point[0]), double(v.Point[1]), double(v.Point[2]) };
      this->ToWorld(idx, x);
    }
    else
    {
      this->EdgePosition(
        v.Point, v.Axis, st.Corners[EdgeCorners[v.Edge][0]], st.Corners[EdgeCorners[v.Edge][1]], x);
    }
  }

  /// Position and normal of a vertex: on a grid point (axis < 0) or on the edge leaving p
  /// along `axis` with end samples sLo, sHi. The normal interpolates the two grid points'
  /// gradients with the vertex's t.
  void PositionAndNormal(
    const int p[3], int axis, double sLo, double sHi, double x[3], float normal[3])
  {
    if (axis < 0)
    {
      const double idx[3] = { double(p[0]), double(p[1]), double(p[2]) };
      this->ToWorld(idx, x);
      if (this->Options.ComputeNormals)
      {
        double g[3];
        this->Gradient(p[0], p[1], p[2], g);
        this->FinishNormal(g, normal);
      }
      return;
    }
    const double t = this->EdgePosition(p, axis, sLo, sHi, x);
    if (this->Options.ComputeNormals)
    {
      double g0[3], g1[3], g[3];
      int q[3] = { p[0], p[1], p[2] };
      this->Gradient(q[0], q[1], q[2], g0);
      ++q[axis];
      this->Gradient(q[0], q[1], q[2], g1);
      for (int a = 0; a < 3; ++a)
      {
        g[a] = g0[a] + t * (g1[a] - g0[a]);
      }
      this->FinishNormal(g, normal);
    }
  }

  /// The most vertices PositionsAndNormals takes at once.
  static constexpr int VertexBatch = 16;

  /// PositionAndNormal of `n` (at most VertexBatch) vertices on the edges leaving p[v] along
  /// axis[v] (-1: on the grid point p[v]), to the bit: the same operations in the same order,
  /// each vertex's samples read first and the arithmetic then done over all of them in one loop,
  /// which the compiler vectorizes (square roots and divisions are correctly rounded in any
  /// width). Vertices on grid points, near the piece's border or next to a NaN sample take
  /// PositionAndNormal itself.
  void PositionsAndNormals(
    const int (*p)[3], const int* axis, int n, double (*x)[3], float (*normal)[3])
  {
    constexpr int B = VertexBatch;
    if (n <= 0)
    {
      return;
    }
    // The samples, by vertex: the edge's ends and the gradients' central differences at both.
    alignas(64) double lo[B], hi[B], idx[3][B], g0[3][B], g1[3][B];
    bool oneByOne[B]; // the lane takes PositionAndNormal, its batched arithmetic dropped
    int along[B];     // the lane's edge axis (-1: the lane is not computed here)
    for (int v = 0; v < B; ++v)
    {
      this->LoadLane(p, axis, n, v, lo, hi, idx, g0, g1, oneByOne, along);
    }
    alignas(64) double t[B], out[3][B], w[3][B];
    this->LanePositions(lo, hi, along, idx, t, out);
    const bool normals = this->Options.ComputeNormals;
    if (normals)
    {
      this->LaneNormals(t, g0, g1, w);
    }
    for (int v = 0; v < n; ++v)
    {
      if (oneByOne[v])
      {
        this->PositionAndNormalOf(p[v], axis[v], x[v], normal[v]);
        continue;
      }
      for (int a = 0; a < 3; ++a)
      {
        x[v][a] = out[a][v];
        normal[v][a] = normals ? static_cast<float>(w[a][v]) : 0.0f;
      }
    }
  }

  /// Whether a cube that contains this vertex lies in the volume but not in this rank's cubes.
  RGMC_INLINE bool IsPort(const int p[3], int axis) const
  {
    if (this->Owned.Overlaps().empty() && p[0] >= this->InnerLo[0] && p[0] <= this->InnerHi[0] &&
      p[1] >= this->InnerLo[1] && p[1] <= this->InnerHi[1] && p[2] >= this->InnerLo[2] &&
      p[2] <= this->InnerHi[2])
    {
      return false; // the 8 cubes around p lie in this rank's box
    }
    bool port = false;
    ForCubesAround(p, axis,
      [&](int i, int j, int k, int)
      { port = port || (this->GridOf.HasCell(i, j, k) && !this->Owned.Owns(i, j, k)); });
    return port;
  }

private:
  // ---- PositionsAndNormals' steps, over the lanes of a batch ---------------------------------

  /// Reads lane v's samples (vertex v, when v < n and on an edge): its edge's end samples and
  /// the central differences at both ends; leaves the lane to PositionAndNormal (oneByOne) when
  /// they are not all at hand or one is NaN. Idle lanes compute on harmless values.
  RGMC_INLINE void LoadLane(const int (*p)[3], const int* axis, int n, int v,
    double (&lo)[VertexBatch], double (&hi)[VertexBatch], double (&idx)[3][VertexBatch],
    double (&g0)[3][VertexBatch], double (&g1)[3][VertexBatch], bool (&oneByOne)[VertexBatch],
    int (&along)[VertexBatch]) const
  {
    const Grid& g = this->GridOf;
    oneByOne[v] = true;
    along[v] = -1;
    lo[v] = 0.0;
    hi[v] = 1.0;
    for (int a = 0; a < 3; ++a)
    {
      idx[a][v] = g0[a][v] = g1[a][v] = 0.0;
    }
    if (v >= n || axis[v] < 0)
    {
      return;
    }
    int q[3] = { p[v][0], p[v][1], p[v][2] };
    ++q[axis[v]];
    if (!this->IsCentral(p[v][0], p[v][1], p[v][2]) || !this->IsCentral(q[0], q[1], q[2]))
    {
      return;
    }
    const std::int64_t at = g.LocalIndex(p[v][0], p[v][1], p[v][2]);
    const std::int64_t at1 = at + (axis[v] == 0 ? 1 : (axis[v] == 1 ? g.StrideY : g.StrideZ));
    lo[v] = static_cast<double>(this->Samples[at]);
    hi[v] = static_cast<double>(this->Samples[at1]);
    double d0[3], d1[3];
    this->CentralDifferences(at, d0);
    this->CentralDifferences(at1, d1);
    for (int a = 0; a < 3; ++a)
    {
      g0[a][v] = d0[a];
      g1[a][v] = d1[a];
    }
    bool noNaN = true;
    if (!std::is_integral<ValueType>::value)
    {
      noNaN = lo[v] == lo[v] && hi[v] == hi[v];
      for (int a = 0; a < 3; ++a)
      {
        noNaN = noNaN && g0[a][v] == g0[a][v] && g1[a][v] == g1[a][v];
      }
    }
    if (!noNaN)
    {
      return; // PositionAndNormal names the NaN sample (this lane's arithmetic is dropped)
    }
    for (int a = 0; a < 3; ++a)
    {
      idx[a][v] = static_cast<double>(p[v][a]);
    }
    oneByOne[v] = false;
    along[v] = axis[v];
  }

  /// EdgePosition over all lanes, term by term as it computes: each lane's t and world position
  /// (`idx` moved along the lane's edge).
  RGMC_INLINE void LanePositions(const double (&lo)[VertexBatch], const double (&hi)[VertexBatch],
    const int (&along)[VertexBatch], double (&idx)[3][VertexBatch], double (&t)[VertexBatch],
    double (&out)[3][VertexBatch]) const
  {
    constexpr int B = VertexBatch;
    const double iso = this->Options.Isovalue;
    const auto& m = this->Options.IndexToWorld;
    for (int v = 0; v < B; ++v)
    {
      t[v] = (iso - lo[v]) / (hi[v] - lo[v]);
    }
    for (int v = 0; v < B; ++v)
    {
      idx[0][v] = along[v] == 0 ? idx[0][v] + t[v] * 1.0 : idx[0][v];
      idx[1][v] = along[v] == 1 ? idx[1][v] + t[v] * 1.0 : idx[1][v];
      idx[2][v] = along[v] == 2 ? idx[2][v] + t[v] * 1.0 : idx[2][v];
    }
    for (int c = 0; c < 3; ++c)
    {
      for (int v = 0; v < B; ++v)
      {
        out[c][v] = m[c][0] * idx[0][v] + m[c][1] * idx[1][v] + m[c][2] * idx[2][v] + m[c][3];
      }
    }
  }

  /// Gradient's interpolation and FinishNormal over all lanes, term by term as they compute:
  /// each lane's unit normal `w` (`g0` becomes the interpolated gradient).
  RGMC_INLINE void LaneNormals(const double (&t)[VertexBatch], double (&g0)[3][VertexBatch],
    const double (&g1)[3][VertexBatch], double (&w)[3][VertexBatch]) const
  {
    constexpr int B = VertexBatch;
    const auto& r = this->Options.NormalToWorld;
    for (int a = 0; a < 3; ++a)
    {
      for (int v = 0; v < B; ++v)
      {
        g0[a][v] = g0[a][v] + t[v] * (g1[a][v] - g0[a][v]);
      }
    }
    for (int c = 0; c < 3; ++c)
    {
      for (int v = 0; v < B; ++v)
      {
        w[c][v] = r[c][0] * g0[0][v] + r[c][1] * g0[1][v] + r[c][2] * g0[2][v];
      }
    }
    alignas(64) double len[B];
    for (int v = 0; v < B; ++v)
    {
      len[v] = w[0][v] * w[0][v] + w[1][v] * w[1][v] + w[2][v] * w[2][v];
    }
    SquareRoots<B>(len);
    for (int v = 0; v < B; ++v)
    {
      // len > 0: w / len, as FinishNormal; else w / 1, which is w.
      const double by = len[v] > 0.0 ? len[v] : 1.0;
      w[0][v] = w[0][v] / by;
      w[1][v] = w[1][v] / by;
      w[2][v] = w[2][v] / by;
    }
  }

  /// PositionAndNormal of one vertex of a batch that the lanes do not compute, its edge's end
  /// samples read (and checked) here.
  RGMC_INLINE void PositionAndNormalOf(const int p[3], int axis, double x[3], float normal[3])
  {
    double sLo = 0.0, sHi = 0.0;
    if (axis >= 0)
    {
      int q[3] = { p[0], p[1], p[2] };
      ++q[axis];
      sLo = this->Read(p[0], p[1], p[2]);
      sHi = this->Read(q[0], q[1], q[2]);
    }
    normal[0] = normal[1] = normal[2] = 0.0f;
    this->PositionAndNormal(p, axis, sLo, sHi, x, normal);
  }

  RGMC_INLINE void PrefetchSamples(int i, int j, int k) const
  {
    if (i <= this->CentralLo[0] || i >= this->CentralHi[0] || j <= this->CentralLo[1] ||
      j >= this->CentralHi[1] || k <= this->CentralLo[2] || k >= this->CentralHi[2])
    {
      return;
    }
    const auto* at = &this->Samples[this->GridOf.LocalIndex(i, j, k)];
    const std::int64_t sy = this->GridOf.StrideY, sz = this->GridOf.StrideZ;
    for (const std::int64_t row : { -sz, -sz + sy, -sy, std::int64_t(0), sy, 2 * sy, sz - sy, sz,
           sz + sy, sz + 2 * sy, 2 * sz, 2 * sz + sy })
    {
      __builtin_prefetch(at + row - 1);
      __builtin_prefetch(at + row + 2);
    }
  }

  void Fail(int i, int j, int k)
  {
    std::lock_guard<std::mutex> lock(this->ErrorMutex);
    this->Failed = true;
    if (this->ErrorText.empty())
    {
      std::ostringstream msg;
      msg << "the scalar value at grid point (" << i << ", " << j << ", " << k
          << ") is NaN; replace NaN samples before extracting a surface (for example with "
             "the Python Calculator and numpy.nan_to_num)";
      this->ErrorText = msg.str();
    }
  }

  /// Whether the gradient at grid point (i, j, k) is central on every axis with samples at
  /// hand (CentralDifferences applies).
  RGMC_INLINE bool IsCentral(int i, int j, int k) const
  {
    return i >= this->CentralLo[0] && i <= this->CentralHi[0] && j >= this->CentralLo[1] &&
      j <= this->CentralHi[1] && k >= this->CentralLo[2] && k <= this->CentralHi[2];
  }

  /// Negative gradient by central differences at the sample with local index `at` (IsCentral).
  RGMC_INLINE void CentralDifferences(std::int64_t at, double n[3]) const
  {
    const std::int64_t sy = this->GridOf.StrideY, sz = this->GridOf.StrideZ;
    const Values& s = this->Samples;
    n[0] = 0.5 * (static_cast<double>(s[at - 1]) - static_cast<double>(s[at + 1]));
    n[1] = 0.5 * (static_cast<double>(s[at - sy]) - static_cast<double>(s[at + sy]));
    n[2] = 0.5 * (static_cast<double>(s[at - sz]) - static_cast<double>(s[at + sz]));
  }

  /// Negative gradient at a grid point by central differences, one-sided on the volume's
  /// border, as vtkMarchingCubes computes it.
  RGMC_INLINE void Gradient(int i, int j, int k, double n[3])
  {
    const Grid& g = this->GridOf;
    if (this->IsCentral(i, j, k))
    {
      // Central differences on all axes, the samples at hand: the common case.
      this->CentralDifferences(g.LocalIndex(i, j, k), n);
      if (std::is_integral<ValueType>::value || (n[0] == n[0] && n[1] == n[1] && n[2] == n[2]))
      {
        return;
      }
      // A NaN sample: the general path below names it.
    }
    const int p[3] = { i, j, k };
    const double s0 = this->Read(i, j, k);
    for (int a = 0; a < 3; ++a)
    {
      bool hasLow = p[a] > g.WholeLo[a];
      bool hasHigh = p[a] < g.WholeHi[a];
      if (hasLow && p[a] - 1 < g.LocalLo[a])
      {
        hasLow = false;
        this->GhostsMissing = true;
      }
      if (hasHigh && p[a] + 1 > g.LocalHi[a])
      {
        hasHigh = false;
        this->GhostsMissing = true;
      }
      int lo[3] = { i, j, k }, hi[3] = { i, j, k };
      --lo[a];
      ++hi[a];
      if (hasLow && hasHigh)
      {
        n[a] = 0.5 * (this->Read(lo[0], lo[1], lo[2]) - this->Read(hi[0], hi[1], hi[2]));
      }
      else if (hasHigh)
      {
        n[a] = s0 - this->Read(hi[0], hi[1], hi[2]);
      }
      else if (hasLow)
      {
        n[a] = this->Read(lo[0], lo[1], lo[2]) - s0;
      }
      else
      {
        n[a] = 0.0;
      }
    }
  }

  RGMC_INLINE void FinishNormal(const double n[3], float out[3]) const
  {
    const auto& m = this->Options.NormalToWorld;
    double w[3];
    for (int r = 0; r < 3; ++r)
    {
      w[r] = m[r][0] * n[0] + m[r][1] * n[1] + m[r][2] * n[2];
    }
    const double len = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    if (len > 0.0)
    {
      w[0] /= len;
      w[1] /= len;
      w[2] /= len;
    }
    out[0] = static_cast<float>(w[0]);
    out[1] = static_cast<float>(w[1]);
    out[2] = static_cast<float>(w[2]);
  }

  std::int64_t CornerStride[8];
  int CentralLo[3], CentralHi[3];
  int InnerLo[3], InnerHi[3];
  double Reported = 0.0;
  mutable std::mutex ErrorMutex;
  std::string ErrorText;
  std::atomic<bool> Failed{ false };
  std::atomic<bool> AbortFlag{ false };
  std::atomic<bool> Interrupted{ false };
  std::atomic<bool> GhostsMissing{ false };
};

} // namespace rgmc

#endif

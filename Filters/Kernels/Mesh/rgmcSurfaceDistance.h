// The distance from points to a triangle surface, exactly: the smallest distance from the point
// to any triangle (closest point on the triangle, Ericson's regions), found through a grid of
// buckets over the triangles and bounded by a search radius. The distance of a point to one
// triangle is computed from the triangle's corners in a canonical rotation (smallest corner
// first, orientation kept), so it is the same double whatever order the triangles come in and
// whichever other triangles are near: the smallest over any superset of the triangles within
// the radius is the same value, to the bit.
#ifndef rgmcSurfaceDistance_h
#define rgmcSurfaceDistance_h

#include "rgmcBuffer.h"
#include "rgmcKeyIndex.h"
#include "rgmcRadixSort.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace rgmc
{

/// The squared distance from p to the triangle (a, b, c) (its closest point, by the region of
/// the triangle's plane p projects into; Ericson, Real-Time Collision Detection, 5.1.5).
inline double PointTriangleDistance2(
  const double p[3], const double a[3], const double b[3], const double c[3])
{
  auto sub = [](const double* u, const double* v, double* w)
  {
    w[0] = u[0] - v[0];
    w[1] = u[1] - v[1];
    w[2] = u[2] - v[2];
  };
  auto dot = [](const double* u, const double* v)
  { return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]; };
  auto to = [&](const double* q)
  {
    double d[3];
    sub(p, q, d);
    return dot(d, d);
  };
  auto along = [&](const double* from, const double* e, double t)
  {
    const double q[3] = { from[0] + t * e[0], from[1] + t * e[1], from[2] + t * e[2] };
    return to(q);
  };
  double ab[3], ac[3], ap[3], bp[3], cp[3];
  sub(b, a, ab);
  sub(c, a, ac);
  sub(p, a, ap);
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0)
  {
    return to(a);
  }
  sub(p, b, bp);
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3)
  {
    return to(b);
  }
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0)
  {
    return along(a, ab, d1 / (d1 - d3));
  }
  sub(p, c, cp);
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6)
  {
    return to(c);
  }
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0)
  {
    return along(a, ac, d2 / (d2 - d6));
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
  {
    double bc[3];
    sub(c, b, bc);
    return along(b, bc, (d4 - d3) / ((d4 - d3) + (d5 - d6)));
  }
  const double sum = va + vb + vc;
  if (!(sum > 0)) // a degenerate triangle: its three edges
  {
    double bc[3];
    sub(c, b, bc);
    auto segment = [&](const double* from, const double* e)
    {
      const double l = dot(e, e);
      double d[3];
      sub(p, from, d);
      const double t = l > 0 ? std::min(1.0, std::max(0.0, dot(d, e) / l)) : 0.0;
      return along(from, e, t);
    };
    return std::min({ segment(a, ab), segment(a, ac), segment(b, bc) });
  }
  const double v = vb / sum, w = vc / sum;
  const double q[3] = { a[0] + ab[0] * v + ac[0] * w, a[1] + ab[1] * v + ac[1] * w,
    a[2] + ab[2] * v + ac[2] * w };
  return to(q);
}

/// Rotates a triangle's 9 coordinates so that its smallest corner (x, then y, then z) comes
/// first, keeping its orientation: the canonical form PointTriangleDistance2 is applied to.
inline void CanonicalTriangle(double t[9])
{
  auto less = [t](int i, int j)
  { return std::lexicographical_compare(t + 3 * i, t + 3 * i + 3, t + 3 * j, t + 3 * j + 3); };
  const int first = less(1, 0) ? (less(2, 1) ? 2 : 1) : (less(2, 0) ? 2 : 0);
  if (first != 0)
  {
    double r[9];
    for (int k = 0; k < 9; ++k)
    {
      r[k] = t[(3 * first + k) % 9];
    }
    std::copy(r, r + 9, t);
  }
}

/// The box [lo, hi] of the triangle t (9 coordinates, floats or doubles), as doubles.
template <typename T>
void TriangleBox(const T* t, double lo[3], double hi[3])
{
  for (int a = 0; a < 3; ++a)
  {
    lo[a] = std::min({ t[a], t[3 + a], t[6 + a] });
    hi[a] = std::max({ t[a], t[3 + a], t[6 + a] });
  }
}

/// The buckets a search looked up lately, by key (direct-mapped): searches from nearby points,
/// one after another, look up the same buckets, and each lookup in the index is a cache miss
/// (its slots are scattered on purpose). A memo per thread of searches; what a search finds
/// never depends on it. The same for buckets of any coordinate type.
class TriangleBucketsMemo
{
public:
  TriangleBucketsMemo() { std::fill(this->Keys, this->Keys + Size, std::int64_t(-1)); }

private:
  template <typename>
  friend class TriangleBuckets;
  static constexpr std::size_t Size = 512;
  std::int64_t Keys[Size];
  std::int64_t Found[Size];
  std::vector<double> Boxes; // a bucket's triangles' box distances (VisitBucket)
  std::size_t Cursor = 0;    // the last home bucket found
  // The last home bucket's triangles side by side (searches in HomeOrder come to the same home
  // bucket one after another): their boxes by axis, Low[a][i] to High[a][i], and their corners
  // (9 a triangle), read here instead of across the whole surface.
  std::int64_t Home = -1;
  std::vector<double> Low[3], High[3], Corners;
};

/// Triangles (9 coordinates each, canonical) in a grid of cubic buckets: each triangle is in
/// every bucket its bounding box overlaps. Built on tasks (`parallel`, as the radix sort's):
/// the (bucket, triangle) pairs of fixed chunks of triangles, sorted by bucket; a bucket's
/// triangles are in increasing order whatever the threads (not that a search would care: the
/// smallest distance is the same in any order). A search visits the buckets shell by shell
/// around its point and skips a bucket, or a triangle, whose box is farther than the best
/// distance so far (in each bucket the triangle whose box is nearest is measured first); what
/// it returns is the minimum over all triangles within its limit, to the bit (TestSurfaceDistance
/// holds it to the brute force). The corners are kept as `T` (float or double: a float surface's
/// triangles in half the memory) and measured as doubles, which hold any float exactly.
template <typename T>
class TriangleBuckets
{
public:
  /// The buckets a search looked up lately (TriangleBucketsMemo).
  using Memo = TriangleBucketsMemo;

  /// `corners`: 9 coordinates a triangle (a contiguous container of T: a std::vector with any
  /// allocator), kept by reference; `size`: the buckets' edge.
  template <typename Container, typename Parallel = SerialTasks>
  TriangleBuckets(const Container& corners, double size, Parallel&& parallel = Parallel())
    : Corners(corners.data())
    , Triangles(corners.size() / 9)
  {
    this->Build(this->Triangles, size, parallel);
  }

  /// The smallest squared distance from p to a triangle, searching the buckets within `limit`
  /// of p (a triangle farther than `limit` may be missed: a result above limit^2 means "none
  /// within limit"). Infinity when there is no triangle within reach.
  double Nearest2(const double p[3], double limit) const
  {
    Memo memo;
    return this->Nearest2(p, limit, memo);
  }

  /// Nearest2, with the buckets' lookups remembered in `memo` for the next searches.
  double Nearest2(const double p[3], double limit, Memo& memo) const
  {
    double best = std::numeric_limits<double>::infinity();
    if (this->Start.empty())
    {
      return best;
    }
    const double reach2 = limit * limit;
    int home[3];
    for (int a = 0; a < 3; ++a)
    {
      home[a] = this->Cell(p[a], a);
    }
    const int shells = static_cast<int>(std::min<double>(std::ceil(limit / this->Size) + 1,
      std::max({ this->Dims[0], this->Dims[1], this->Dims[2] })));
    // How far p is inside its home bucket (negative outside it): no bucket of shell s >= 1 is
    // nearer than inside + (s - 1) * Size, so most searches end with the home bucket.
    double inside = std::numeric_limits<double>::max();
    for (int a = 0; a < 3; ++a)
    {
      const double lo = this->Origin[a] + home[a] * this->Size;
      inside = std::min({ inside, p[a] - lo, lo + this->Size - p[a] });
    }
    for (int s = 0; s <= shells; ++s)
    {
      const double gap = std::max(inside + (s - 1) * this->Size, (s - 1) * this->Size);
      if (s > 0 && gap > std::sqrt(std::min(best, reach2)) * (1 + 1e-9) + this->Slack)
      {
        break;
      }
      this->VisitShell(p, home, s, reach2, best, memo);
    }
    return best;
  }

  /// The order in which to search from the points p[3 i], 0 <= i < n, so that searches one after
  /// another read the same buckets: by home bucket (an index i a word, `order & IndexMask`).
  /// The points' own order where a bucket's key and an index do not fit one word.
  template <typename Parallel = SerialTasks>
  OverwriteVector<std::uint64_t> HomeOrder(const double* p, std::size_t n, std::uint64_t& indexMask,
    Parallel&& parallel = Parallel()) const
  {
    OverwriteVector<std::uint64_t> order(n); // filled whole below
    const int indexBits = BitsFor(n > 0 ? n - 1 : 0);
    indexMask = (std::uint64_t(1) << indexBits) - 1;
    const bool fits = this->KeyBits() + indexBits <= 64;
    ForEachIndex(n, parallel,
      [&](std::size_t i)
      {
        const double* q = p + 3 * i;
        const std::uint64_t key = fits ? static_cast<std::uint64_t>(this->Key(this->Cell(q[0], 0),
                                           this->Cell(q[1], 1), this->Cell(q[2], 2)))
                                       : 0;
        order[i] = key << indexBits | i;
      });
    if (fits)
    {
      RadixSort(
        order, [indexBits](std::uint64_t w) { return w >> indexBits; }, parallel);
    }
    return order;
  }

private:
  /// Triangles a task of the build (fixed: the chunks never depend on the threads).
  static constexpr std::size_t Chunk = 16384;

  /// The bucket along axis a of x (clamped to the grid): monotone in x, as every search needs; by
  /// the edge's inverse, so a coordinate may land a rounding outside its bucket's box (the
  /// searches' Slack covers far more).
  int Cell(double x, int a) const
  {
    const double c = std::floor((x - this->Origin[a]) * this->Inverse);
    return static_cast<int>(std::max(0.0, std::min<double>(c, this->Dims[a] - 1)));
  }

  template <typename Parallel>
  void Build(std::size_t n, double size, Parallel& parallel)
  {
    if (n == 0)
    {
      return;
    }
    const std::size_t chunks = (n + Chunk - 1) / Chunk;
    this->Place(n, chunks, size, parallel);
    // A pair as one word (the bucket's key above the triangle's bits) where it fits, else as
    // two; sorted by key, stably, so each bucket's triangles stay in increasing order.
    const int triangleBits = BitsFor(n - 1);
    const int keyBits = this->KeyBits();
    if (keyBits + triangleBits <= 64)
    {
      OverwriteVector<std::uint64_t> words =
        this->Pairs<OverwriteVector<std::uint64_t>>(chunks, parallel,
          [triangleBits](std::int64_t key, std::size_t t)
          { return static_cast<std::uint64_t>(key) << triangleBits | t; });
      RadixSort(
        words, [triangleBits](std::uint64_t w) { return w >> triangleBits; }, parallel);
      const std::uint64_t mask = (std::uint64_t(1) << triangleBits) - 1;
      this->Group(
        words.size(), parallel,
        [&](std::size_t i) { return static_cast<std::int64_t>(words[i] >> triangleBits); },
        [&](std::size_t i) { return static_cast<std::uint32_t>(words[i] & mask); });
      return;
    }
    using Pair = std::pair<std::uint64_t, std::uint32_t>;
    LargeVector<Pair> pairs = this->Pairs<LargeVector<Pair>>(chunks, parallel,
      [](std::int64_t key, std::size_t t)
      { return Pair(static_cast<std::uint64_t>(key), static_cast<std::uint32_t>(t)); });
    RadixSort(
      pairs, [](const Pair& p) { return p.first; }, parallel);
    this->Group(
      pairs.size(), parallel,
      [&](std::size_t i) { return static_cast<std::int64_t>(pairs[i].first); },
      [&](std::size_t i) { return pairs[i].second; });
  }

  /// The grid: the triangles' box (chunk by chunk, then in chunk order: exact either way), and
  /// buckets of edge `size` over it.
  template <typename Parallel>
  void Place(std::size_t n, std::size_t chunks, double size, Parallel& parallel)
  {
    constexpr double inf = std::numeric_limits<double>::infinity();
    std::vector<std::array<double, 6>> boxes(chunks, { inf, inf, inf, -inf, -inf, -inf });
    parallel(static_cast<std::int64_t>(chunks),
      [&](std::int64_t c)
      {
        std::array<double, 6>& box = boxes[static_cast<std::size_t>(c)];
        const std::size_t last = std::min(n, (static_cast<std::size_t>(c) + 1) * Chunk);
        for (std::size_t k = 9 * Chunk * static_cast<std::size_t>(c); k < 9 * last; ++k)
        {
          box[k % 3] = std::min(box[k % 3], static_cast<double>(this->Corners[k]));
          box[3 + k % 3] = std::max(box[3 + k % 3], static_cast<double>(this->Corners[k]));
        }
      });
    double lo[3] = { inf, inf, inf }, hi[3] = { -inf, -inf, -inf };
    for (const auto& box : boxes)
    {
      for (int a = 0; a < 3; ++a)
      {
        lo[a] = std::min(lo[a], box[a]);
        hi[a] = std::max(hi[a], box[3 + a]);
      }
    }
    // Buckets are kept only where there are triangles (a hash of their position), so their size
    // follows the queries, not the box; at most 2^20 along an axis.
    double extent = 0;
    for (int a = 0; a < 3; ++a)
    {
      extent = std::max(extent, hi[a] - lo[a]);
    }
    this->Size = std::max(size, extent / (1 << 20));
    if (!(this->Size > 0))
    {
      this->Size = 1;
    }
    this->Inverse = 1 / this->Size;
    double magnitude = 0;
    for (int a = 0; a < 3; ++a)
    {
      this->Origin[a] = lo[a];
      this->Dims[a] = std::max(1, static_cast<int>(std::floor((hi[a] - lo[a]) / this->Size)) + 1);
      magnitude = std::max({ magnitude, std::abs(lo[a]), std::abs(hi[a]) });
    }
    this->Slack = 1e-9 * magnitude;
  }

  /// Every (bucket, triangle) pair as make(key, triangle), chunk after chunk, in one pass over
  /// the triangles (a count first would find each triangle's buckets twice): each chunk writes
  /// its pairs at its own place in a scratch array (the rest, for a chunk of larger triangles
  /// than its room allows, in a vector of its own), then all go side by side. The room a chunk:
  /// a quarter more pairs a triangle than every 61st triangle has (1.55 on average on the 512^3
  /// skull's 2 M triangles in the report's buckets, 3.6 on its 10% decimation's), at most 16.
  template <typename Vector, typename Parallel, typename Make>
  Vector Pairs(std::size_t chunks, Parallel& parallel, Make&& make) const
  {
    using P = typename Vector::value_type;
    double sampled = 0, found = 0;
    for (std::size_t t = 0; t < this->Triangles; t += 61)
    {
      int lo[3], hi[3];
      this->CellRange(t, lo, hi);
      found += double(hi[0] - lo[0] + 1) * (hi[1] - lo[1] + 1) * (hi[2] - lo[2] + 1);
      ++sampled;
    }
    const std::size_t room =
      static_cast<std::size_t>(std::ceil(std::min(16.0, 0.25 + 1.25 * found / sampled) * Chunk));
    OverwriteVector<P> scratch(chunks * room); // each chunk's part written as far as it needs
    std::vector<std::vector<P>> more(chunks);
    std::vector<std::size_t> first(chunks + 1, 0);
    parallel(static_cast<std::int64_t>(chunks),
      [&](std::int64_t c)
      {
        P* at = scratch.data() + static_cast<std::size_t>(c) * room;
        std::size_t k = 0;
        this->ForBuckets(static_cast<std::size_t>(c),
          [&](std::int64_t key, std::size_t t)
          {
            if (k < room)
            {
              at[k] = make(key, t);
            }
            else
            {
              more[c].push_back(make(key, t));
            }
            ++k;
          });
        first[c + 1] = k;
      });
    for (std::size_t c = 0; c < chunks; ++c)
    {
      first[c + 1] += first[c];
    }
    Vector all(first.back());
    parallel(static_cast<std::int64_t>(chunks),
      [&](std::int64_t c)
      {
        const P* from = scratch.data() + static_cast<std::size_t>(c) * room;
        const std::size_t k = first[c + 1] - first[c];
        std::copy(from, from + std::min(k, room), all.begin() + first[c]);
        std::copy(more[c].begin(), more[c].end(), all.begin() + first[c] + std::min(k, room));
      });
    return all;
  }

  /// The sorted pairs (keyAt(i), triangleAt(i)) as buckets: Start, Items, and the keys' index.
  template <typename Parallel, typename KeyAt, typename TriangleAt>
  void Group(std::size_t pairs, Parallel& parallel, KeyAt&& keyAt, TriangleAt&& triangleAt)
  {
    this->Items.resize(pairs);
    ForEachIndex(pairs, parallel, [&](std::size_t i) { this->Items[i] = triangleAt(i); });
    const std::int64_t ranges = static_cast<std::int64_t>((pairs + Chunk - 1) / Chunk);
    // Each bucket's first pair: counted per range, then written at the range's place.
    auto starts = [&keyAt](std::int64_t i) { return i == 0 || keyAt(i) != keyAt(i - 1); };
    const std::vector<std::size_t> before =
      CountBefore(static_cast<std::int64_t>(pairs), Chunk, starts, parallel);
    this->Start.resize(before.back());
    parallel(ranges,
      [&](std::int64_t r)
      {
        std::size_t at = before[static_cast<std::size_t>(r)];
        const std::size_t last = std::min(pairs, (static_cast<std::size_t>(r) + 1) * Chunk);
        for (std::size_t i = static_cast<std::size_t>(r) * Chunk; i < last; ++i)
        {
          if (starts(i))
          {
            this->Start[at++] = i;
          }
        }
      });
    this->Keys.resize(this->Start.size());
    ForEachIndex(
      this->Keys.size(), parallel, [&](std::size_t b) { this->Keys[b] = keyAt(this->Start[b]); });
    this->Index = KeyIndex(
      this->Keys.size(), [&](std::size_t b) { return this->Keys[b]; }, parallel);
    this->Start.push_back(pairs);
  }

  /// The buckets triangle t's box overlaps: from lo[a] to hi[a] along each axis a.
  void CellRange(std::size_t t, int lo[3], int hi[3]) const
  {
    double box[2][3];
    TriangleBox(this->Corners + 9 * t, box[0], box[1]);
    for (int a = 0; a < 3; ++a)
    {
      lo[a] = this->Cell(box[0][a], a);
      hi[a] = this->Cell(box[1][a], a);
    }
  }

  /// f(key, triangle) for each bucket of each triangle of chunk c, in triangle order.
  template <typename F>
  void ForBuckets(std::size_t c, F&& f) const
  {
    const std::size_t n = this->Triangles;
    for (std::size_t t = c * Chunk; t < std::min(n, (c + 1) * Chunk); ++t)
    {
      int lo[3], hi[3];
      this->CellRange(t, lo, hi);
      for (int z = lo[2]; z <= hi[2]; ++z)
      {
        for (int y = lo[1]; y <= hi[1]; ++y)
        {
          for (int x = lo[0]; x <= hi[0]; ++x)
          {
            f(this->Key(x, y, z), t);
          }
        }
      }
    }
  }

  /// f(i) for each i in [0, n), in tasks of Chunk on `parallel`.
  template <typename Parallel, typename F>
  static void ForEachIndex(std::size_t n, Parallel& parallel, F&& f)
  {
    parallel(static_cast<std::int64_t>((n + Chunk - 1) / Chunk),
      [&](std::int64_t c)
      {
        const std::size_t last = std::min(n, (static_cast<std::size_t>(c) + 1) * Chunk);
        for (std::size_t i = static_cast<std::size_t>(c) * Chunk; i < last; ++i)
        {
          f(i);
        }
      });
  }

  /// The bits (at least one) that hold every value up to `largest`.
  static int BitsFor(std::uint64_t largest)
  {
    int bits = 1;
    while (bits < 64 && (largest >> bits) != 0)
    {
      ++bits;
    }
    return bits;
  }

  /// The bits the largest bucket key needs.
  int KeyBits() const
  {
    return BitsFor(static_cast<std::uint64_t>(
      this->Key(this->Dims[0] - 1, this->Dims[1] - 1, this->Dims[2] - 1)));
  }

  std::int64_t Key(int x, int y, int z) const
  {
    return x + std::int64_t(this->Dims[0]) * (y + std::int64_t(this->Dims[1]) * z);
  }

  /// The buckets at Chebyshev distance s from `home` whose box is within `reach2` (squared) of p
  /// and within the cutoff of the best so far (with its slack: a triangle counted in a bucket may
  /// lie outside the bucket's box by a rounding of Cell).
  void VisitShell(
    const double p[3], const int home[3], int s, double reach2, double& best, Memo& memo) const
  {
    double cutoff = this->Cutoff(best);
    for (int z = home[2] - s; z <= home[2] + s; ++z)
    {
      for (int y = home[1] - s; y <= home[1] + s; ++y)
      {
        const bool edge =
          z == home[2] - s || z == home[2] + s || y == home[1] - s || y == home[1] + s;
        for (int x = home[0] - s; x <= home[0] + s; x += (edge || s == 0) ? 1 : 2 * s)
        {
          const int c[3] = { x, y, z };
          double box2 = 0;
          bool inside = true;
          for (int a = 0; a < 3 && inside; ++a)
          {
            inside = c[a] >= 0 && c[a] < this->Dims[a];
            const double lo = this->Origin[a] + c[a] * this->Size;
            const double d = std::max(std::max(0.0, lo - p[a]), p[a] - (lo + this->Size));
            box2 += d * d;
          }
          if (!inside || box2 > std::min(reach2, cutoff))
          {
            continue;
          }
          const std::int64_t found = this->Find(this->Key(x, y, z), memo, s == 0);
          if (found < 0)
          {
            continue;
          }
          this->VisitBucket(p, static_cast<std::size_t>(found), s == 0, best, cutoff, memo);
        }
      }
    }
  }

  /// The triangles of bucket b against p: the one whose box is nearest first (it gives a small
  /// best, which cuts off most of the others), then those whose box is within the cutoff. A home
  /// bucket's triangles are read from the memo's copy (made when the home bucket changes).
  void VisitBucket(
    const double p[3], std::size_t b, bool home, double& best, double& cutoff, Memo& memo) const
  {
    const std::uint64_t first = this->Start[b], count = this->Start[b + 1] - first;
    std::vector<double>& box2 = memo.Boxes;
    box2.resize(count);
    if (home && memo.Home != static_cast<std::int64_t>(b))
    {
      this->CopyBucket(b, memo);
    }
    if (home)
    {
      for (int a = 0; a < 3; ++a) // an axis at a time: loops the compiler vectorizes
      {
        const double* lo = memo.Low[a].data();
        const double* hi = memo.High[a].data();
        const double x = p[a];
        for (std::uint64_t i = 0; i < count; ++i)
        {
          const double d = std::max(std::max(0.0, lo[i] - x), x - hi[i]);
          box2[i] = (a == 0 ? 0.0 : box2[i]) + d * d;
        }
      }
    }
    else
    {
      for (std::uint64_t i = 0; i < count; ++i)
      {
        box2[i] = BoxDistance2(p, this->Corners + 9 * std::size_t(this->Items[first + i]));
      }
    }
    // The first of the nearest boxes, its distance kept in a register: a comparison a triangle,
    // not a load that waits on the one before.
    std::uint64_t nearest = 0;
    double nearestBox2 = count > 0 ? box2[0] : 0.0;
    for (std::uint64_t i = 1; i < count; ++i)
    {
      if (box2[i] < nearestBox2)
      {
        nearestBox2 = box2[i];
        nearest = i;
      }
    }
    auto measure = [&](std::uint64_t i)
    {
      double corners[9];
      const double* t = home ? memo.Corners.data() + 9 * i : corners;
      if (!home)
      {
        const T* c = this->Corners + 9 * std::size_t(this->Items[first + i]);
        std::copy(c, c + 9, corners);
      }
      const double d2 = PointTriangleDistance2(p, t, t + 3, t + 6);
      if (d2 < best)
      {
        best = d2;
        cutoff = this->Cutoff(best);
      }
    };
    if (count == 0 || box2[nearest] > cutoff)
    {
      return;
    }
    measure(nearest);
    for (std::uint64_t i = 0; i < count; ++i)
    {
      if (i != nearest && box2[i] <= cutoff)
      {
        measure(i);
      }
    }
  }

  /// Bucket b's triangles into the memo, side by side: their boxes by axis and their corners.
  void CopyBucket(std::size_t b, Memo& memo) const
  {
    const std::uint64_t first = this->Start[b], count = this->Start[b + 1] - first;
    memo.Home = static_cast<std::int64_t>(b);
    memo.Corners.resize(9 * count);
    for (int a = 0; a < 3; ++a)
    {
      memo.Low[a].resize(count);
      memo.High[a].resize(count);
    }
    // The triangles' corners are scattered over the surface: their loads asked for all at once,
    // before the copy's loop, whose work per triangle would otherwise leave few of them in flight.
    for (std::uint64_t i = 0; i < count; ++i)
    {
      const T* t = this->Corners + 9 * std::size_t(this->Items[first + i]);
      __builtin_prefetch(t);
      __builtin_prefetch(t + 8); // a triangle may straddle two cache lines
    }
    for (std::uint64_t i = 0; i < count; ++i)
    {
      const T* t = this->Corners + 9 * std::size_t(this->Items[first + i]);
      std::copy(t, t + 9, memo.Corners.data() + 9 * i);
      double lo[3], hi[3];
      TriangleBox(t, lo, hi);
      for (int a = 0; a < 3; ++a)
      {
        memo.Low[a][i] = lo[a];
        memo.High[a][i] = hi[a];
      }
    }
  }

  /// The squared distance from p to the box of the triangle t: never above the distance to the
  /// triangle itself.
  static double BoxDistance2(const double p[3], const T* t)
  {
    double lo[3], hi[3];
    TriangleBox(t, lo, hi);
    double box2 = 0;
    for (int a = 0; a < 3; ++a)
    {
      const double d = std::max(std::max(0.0, lo[a] - p[a]), p[a] - hi[a]); // no branches
      box2 += d * d;
    }
    return box2;
  }

  /// The squared box distance beyond which a triangle cannot come nearer than `best` (squared):
  /// sqrt(best) widened by a billionth of itself and by Slack, far more than the rounding of
  /// either distance, so that a triangle skipped could never have given a smaller value.
  double Cutoff(double best) const
  {
    const double reach = std::sqrt(best) * (1 + 1e-9) + this->Slack;
    return reach * reach;
  }

  /// The bucket number of `key` (-1: no triangles there), through the memo.
  std::int64_t Find(std::int64_t key, Memo& memo, bool home) const
  {
    // A home bucket first at or just after the last one (searches in HomeOrder come to their
    // buckets in the keys' order): no lookup in the index.
    const std::size_t window = std::min(this->Keys.size(), memo.Cursor + 3);
    for (std::size_t b = memo.Cursor; home && b < window && this->Keys[b] <= key; ++b)
    {
      if (this->Keys[b] == key)
      {
        memo.Cursor = b;
        return static_cast<std::int64_t>(b);
      }
    }
    const std::size_t m = static_cast<std::size_t>(key) % Memo::Size;
    if (memo.Keys[m] != key)
    {
      memo.Keys[m] = key;
      memo.Found[m] = this->Index.Find(key);
    }
    if (home && memo.Found[m] >= 0)
    {
      memo.Cursor = static_cast<std::size_t>(memo.Found[m]);
    }
    return memo.Found[m];
  }

  const T* Corners;
  std::size_t Triangles;
  double Origin[3] = { 0, 0, 0 };
  double Size = 1;
  double Inverse = 1; // 1 / Size
  double Slack = 0;   // a distance far above the rounding of any coordinate (Cutoff)
  int Dims[3] = { 1, 1, 1 };
  std::vector<std::int64_t> Keys;       // bucket b's key (Key), increasing
  KeyIndex Index;                       // a bucket's key to its number b
  std::vector<std::uint64_t> Start;     // bucket b's items: [Start[b], Start[b + 1])
  OverwriteVector<std::uint32_t> Items; // written whole by Group
};

/// Buckets of the corners' type: TriangleBuckets buckets(corners, size, parallel).
template <typename Container, typename... Parallel>
TriangleBuckets(const Container&, double, Parallel&&...)
  -> TriangleBuckets<typename Container::value_type>;

} // namespace rgmc

#endif

// Seed search: the surface vertex nearest to a seed point among the cubes one rank owns,
// searched in shells of cubes around the seed's cube, so that the cost follows the distance to
// the surface, not the size of the volume.
#ifndef rgmcSeedSearch_h
#define rgmcSeedSearch_h

#include "rgmcSampledVolume.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>

namespace rgmc
{

/// The surface vertex a seed selected on one rank: its squared distance, key and position.
struct SeedHit
{
  bool Found = false;
  double Distance2 = std::numeric_limits<double>::infinity();
  std::int64_t Key = std::numeric_limits<std::int64_t>::max();
  double Point[3] = { 0, 0, 0 };
};

/// Calls f(i, j, k) for the cubes of `clip` at Chebyshev distance exactly r from cube c.
template <typename F>
void ForCubesInShell(const CellBox& clip, const int c[3], int r, F&& f)
{
  for (int k = clip.Lo[2]; k <= clip.Hi[2]; ++k)
  {
    for (int j = clip.Lo[1]; j <= clip.Hi[1]; ++j)
    {
      if (std::abs(k - c[2]) == r || std::abs(j - c[1]) == r)
      {
        for (int i = clip.Lo[0]; i <= clip.Hi[0]; ++i)
        {
          f(i, j, k);
        }
      }
      else
      {
        if (c[0] - r >= clip.Lo[0])
        {
          f(c[0] - r, j, k);
        }
        if (r > 0 && c[0] + r <= clip.Hi[0])
        {
          f(c[0] + r, j, k);
        }
      }
    }
  }
}

/// The surface vertex nearest to a seed among the cubes `volume`'s rank owns, ties broken by
/// the smaller key. `seedIndex` is the seed in continuous index coordinates (inside the
/// volume), `seedWorld` the same point in world coordinates. Only vertices within `radius`
/// count. `minStep` is a lower bound of the world length of any index step of length 1 (the
/// smallest singular value of direction * spacing); it bounds the search shells.
template <typename Values>
SeedHit NearestVertex(SampledVolume<Values>& volume, const double seedIndex[3],
  const double seedWorld[3], double radius, double minStep)
{
  SeedHit best;
  const Ownership& own = volume.Owned;
  if (own.OwnsNothing())
  {
    return best;
  }
  const CellBox& box = own.Mine();
  const Grid& grid = volume.GridOf;
  int c[3];
  for (int a = 0; a < 3; ++a)
  {
    c[a] = static_cast<int>(std::floor(seedIndex[a]));
    c[a] = std::max(grid.WholeLo[a], std::min(grid.WholeHi[a] - 1, c[a]));
  }
  const double radius2 = radius * radius;
  CubeSamples st;
  CubeSurface surface;
  auto consider = [&](const SurfaceVertex& v)
  {
    double x[3];
    volume.Position(v, st, x);
    const double dx = x[0] - seedWorld[0], dy = x[1] - seedWorld[1], dz = x[2] - seedWorld[2];
    const double d2 = dx * dx + dy * dy + dz * dz;
    if (d2 <= radius2 && (d2 < best.Distance2 || (d2 == best.Distance2 && v.Key < best.Key)))
    {
      best.Found = true;
      best.Distance2 = d2;
      best.Key = v.Key;
      std::copy(x, x + 3, best.Point);
    }
  };
  for (int r = 0;; ++r)
  {
    if (r >= 1)
    {
      // Every vertex of shell r or beyond is at least (r - 1) index steps away.
      const double bound = (r - 1) * minStep;
      if (bound > radius || (best.Found && std::sqrt(best.Distance2) < bound))
      {
        break;
      }
    }
    CellBox shell;
    for (int a = 0; a < 3; ++a)
    {
      shell.Lo[a] = c[a] - r;
      shell.Hi[a] = c[a] + r;
    }
    const CellBox clip = shell.Intersect(box);
    if (!clip.Empty())
    {
      ForCubesInShell(clip, c, r,
        [&](int i, int j, int k)
        {
          if (volume.Stopped() || !own.Owns(i, j, k) || !volume.Evaluate(i, j, k, st) ||
            st.Case == 0 || st.Case == 255)
          {
            return;
          }
          volume.Describe(i, j, k, st, surface);
          surface.ForEachVertex(-1, consider);
        });
    }
    if (shell.ContainsBox(box) || volume.Stopped())
    {
      break;
    }
  }
  return best;
}

} // namespace rgmc

#endif

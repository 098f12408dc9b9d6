// The CT phantom's per-voxel noise and rounding: a standard normal sample from the voxel's global
// index (Box-Muller on two hashed uniforms) is added to the voxel's value, which is then clamped
// to -1024..3071 HU and rounded to int16. These definitions are a contract: every documented
// count and fingerprint of the phantom depends on them to the bit.
#ifndef rgmcPhantomNoise_h
#define rgmcPhantomNoise_h

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace rgmc
{
namespace phantom
{

inline std::uint64_t SplitMix(std::uint64_t x)
{
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

/// The two uniforms of a voxel: u1 in (0, 1], u2 in [0, 1), both multiples of 2^-53.
inline void Uniforms(std::uint64_t index, int seed, double& u1, double& u2)
{
  const std::uint64_t h1 = SplitMix(index * 2 + (std::uint64_t(std::uint32_t(seed)) << 40));
  const std::uint64_t h2 = SplitMix(h1 ^ 0xD1B54A32D192ED03ull);
  u1 = (double(std::int64_t(h1 >> 11)) + 1.0) / 9007199254740992.0; // signed: exact, and faster
  u2 = double(std::int64_t(h2 >> 11)) / 9007199254740992.0;
}

/// The definition: a standard normal sample from a voxel's global index.
inline double Noise(std::uint64_t index, int seed)
{
  double u1, u2;
  Uniforms(index, seed, u1, u2);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * 3.14159265358979323846 * u2);
}

/// A value in HU clamped to int16 CT's -1024..3071 and rounded, halves away from zero:
/// std::lround's result, without its call (x - t is exact: t is x truncated, within 1 of it).
inline short Voxel(double value)
{
  const double x = std::max(-1024.0, std::min(3071.0, value));
  const int t = static_cast<int>(x);
  const double d = x - t;
  return static_cast<short>(t + (d >= 0.5 ? 1 : 0) - (d <= -0.5 ? 1 : 0));
}

/// A voxel: `value` plus `level` times the voxel's noise, clamped and rounded.
inline short NoisyVoxel(double value, double level, std::uint64_t index, int seed)
{
  return Voxel(value + level * Noise(index, seed));
}

} // namespace phantom
} // namespace rgmc

#endif

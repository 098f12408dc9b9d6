// Area and enclosed volume of a triangle mesh, the same to the bit for any number of ranks and
// threads, without VTK.
//
// Each triangle's terms (twice its area, and six times the signed volume of the tetrahedron it
// makes with the volume's centre) are rounded once to fixed point (ExactSum: 2^-60 of the
// mesh's scale, summed in 128 bits), so that sums over any split of the triangles, in any
// order, are the same integers.
//
// A surface cut by the volume's border is closed by the border planes (BorderCaps): on each face
// of the volume's box, the cap is the part of the face inside the structure, bounded by the
// mesh's boundary edges on that face and, between their ends, by the face's own sides, walked
// counterclockwise seen from outside. Its volume term is the cone from the centre over the cap.
#ifndef rgmcMeasure_h
#define rgmcMeasure_h

#include <cmath>
#include <cstdint>
#include <vector>

namespace rgmc
{

/// A sum of doubles that does not depend on their order: each term is rounded (toward zero) to
/// a multiple of 2^-FractionBits and summed as a 128-bit integer (modulo 2^128, exact while the
/// true sum fits: |sum| < 2^(127 - FractionBits)). Terms below 8 in magnitude, as the measures'
/// are, take one conversion to a 64-bit integer; larger ones go through 128 bits.
class ExactSum
{
public:
  static constexpr int FractionBits = 60;

  void Add(double term)
  {
    constexpr double one = static_cast<double>(std::int64_t(1) << FractionBits);
    const double scaled = term * one; // a power of two: exact
    if (std::fabs(term) < 8.0)
    {
      this->Value +=
        static_cast<unsigned __int128>(static_cast<__int128>(static_cast<std::int64_t>(scaled)));
    }
    else if (std::fabs(term) < 0x1p60) // and not NaN
    {
      this->Value += static_cast<unsigned __int128>(static_cast<__int128>(scaled));
    }
    else
    {
      ++this->NotFinite; // a NaN or infinite point: the sum is NaN
    }
  }
  void Add(const ExactSum& other)
  {
    this->Value += other.Value;
    this->NotFinite += other.NotFinite;
  }

  /// The sum as Words values: four 32-bit words and the count of terms that were not finite,
  /// each in an int64 (summed over ranks, they cannot overflow).
  static constexpr int Words = 5;
  void ToWords(std::int64_t words[Words]) const
  {
    for (int w = 0; w < 4; ++w)
    {
      words[w] = static_cast<std::int64_t>((this->Value >> (32 * w)) & 0xffffffffu);
    }
    words[4] = this->NotFinite;
  }
  /// The sum of the ranks' sums, from the sums of their words.
  static ExactSum FromWordSums(const std::int64_t words[Words])
  {
    ExactSum sum;
    for (int w = 0; w < 4; ++w)
    {
      sum.Value += static_cast<unsigned __int128>(words[w]) << (32 * w);
    }
    sum.NotFinite = words[4];
    return sum;
  }
  double Get() const
  {
    return this->NotFinite
      ? std::nan("")
      : std::ldexp(static_cast<double>(static_cast<__int128>(this->Value)), -FractionBits);
  }

private:
  unsigned __int128 Value = 0;
  std::int64_t NotFinite = 0;
};

/// The box of the volume the surface came from: index space [Extent] mapped to the world by
/// world = Origin + Direction * (Spacing .* index) (Direction row-major, orthonormal).
struct VolumeBox
{
  double Origin[3] = { 0, 0, 0 };
  double Spacing[3] = { 1, 1, 1 };
  double Direction[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 1 };
  double Extent[6] = { 0, 0, 0, 0, 0, 0 }; // index bounds, lo and hi per axis

  void ToIndex(const double world[3], double index[3]) const;
  void ToWorld(const double index[3], double world[3]) const;
  /// The box's centre in the world, and a power of two at least its diagonal: the measures
  /// work on (x - centre) / scale, within [-1/2, 1/2] for points in the box.
  void Frame(double centre[3], double& scale) const;
  /// -1 when Direction mirrors (a triangle counterclockwise in index space is clockwise in the
  /// world), else 1.
  double Handedness() const;
};

/// Twice the area and six times the volume of triangles, in units of scale^2 and scale^3.
struct TriangleSums
{
  ExactSum TwiceArea;
  ExactSum SixVolume;

  template <typename T, typename I>
  void Add(const T* positions, const I* triangles, std::int64_t first, std::int64_t last,
    const double centre[3], double scale)
  {
    const double inverse = 1.0 / scale; // a power of two: exact
    for (std::int64_t t = first; t < last; ++t)
    {
      double p[3][3];
      for (int c = 0; c < 3; ++c)
      {
        const T* x = positions + 3 * static_cast<std::int64_t>(triangles[3 * t + c]);
        for (int k = 0; k < 3; ++k)
        {
          p[c][k] = (static_cast<double>(x[k]) - centre[k]) * inverse;
        }
      }
      const double u[3] = { p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2] };
      const double v[3] = { p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2] };
      const double n[3] = { u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0] };
      this->TwiceArea.Add(std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]));
      // p0 . (p1 x p2) = p0 . ((p1 - p0) x (p2 - p0)) = p0 . n
      this->SixVolume.Add(p[0][0] * n[0] + p[0][1] * n[1] + p[0][2] * n[2]);
    }
  }
  void Add(const TriangleSums& other)
  {
    this->TwiceArea.Add(other.TwiceArea);
    this->SixVolume.Add(other.SixVolume);
  }
};

/// A triangle edge whose two ends lie on a common face of the volume's box (a candidate for the
/// caps: it is on the mesh's boundary when no other triangle has it), as the triangle runs it.
struct BorderEdge
{
  std::int64_t From, To;           // global point ids
  int FromFaces, ToFaces;          // faces each end lies on: bits x-, x+, y-, y+, z-, z+
  double FromIndex[3], ToIndex[3]; // positions in index space

  static constexpr int Words = 10; // as doubles, for a gather
  void Pack(double* out) const;
  static BorderEdge Unpack(const double* in);
};

/// What the caps add to a surface cut by the border.
struct Caps
{
  double SixVolume = 0.0; // in world units^3 (not scaled)
  double Area = 0.0;      // their area, world units^2
  int Faces = 0;          // faces of the box with a cap
  bool Closed = true;     // false: a boundary edge on a face does not end on the face's sides
};

/// The caps closing the surface whose candidate border edges (from every rank, in any order)
/// are `edges`, for triangles ordered counterclockwise seen from outside in index space (as
/// marching cubes orders them, the values above the isovalue inside).
Caps BorderCaps(std::vector<BorderEdge> edges, const VolumeBox& box);

} // namespace rgmc

#endif

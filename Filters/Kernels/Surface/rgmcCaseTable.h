// Marching-cubes conventions (VTK's corner and edge order) and the tables derived, in code, from
// VTK's triangle table: for each of the 256 cases its triangles, its cut edges and its sheets
// (groups of triangles connected through shared edge vertices).
#ifndef rgmcCaseTable_h
#define rgmcCaseTable_h

#include <array>
#include <cstdint>
#include <string>

namespace rgmc
{

/// Offset (x, y, z) of corner v of a cube, in VTK's voxel order.
constexpr int CornerOffset[8][3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 1, 1, 0 }, { 0, 1, 0 },
  { 0, 0, 1 }, { 1, 0, 1 }, { 1, 1, 1 }, { 0, 1, 1 } };

/// Edge e joins corner EdgeCorners[e][0] (the lower one along the edge's axis) to
/// EdgeCorners[e][1]; VTK's marching-cubes edge order, which the triangle table refers to.
constexpr int EdgeCorners[12][2] = { { 0, 1 }, { 1, 2 }, { 3, 2 }, { 0, 3 }, { 4, 5 }, { 5, 6 },
  { 7, 6 }, { 4, 7 }, { 0, 4 }, { 1, 5 }, { 3, 7 }, { 2, 6 } };

constexpr int MaxTriangles = 5;
constexpr int MaxSheets = 5;

/// Everything the growth needs to know about one case.
struct CaseEntry
{
  int NumTriangles = 0;
  int NumSheets = 0;
  /// Edge ids of each triangle's vertices, in the triangle table's order (orientation kept).
  std::array<std::array<std::int8_t, 3>, MaxTriangles> Triangles{};
  std::array<std::int8_t, MaxTriangles> TriangleSheet{};
  /// Bit e set when the sheet has a vertex on edge e.
  std::array<std::uint16_t, MaxSheets> SheetEdges{};
  /// The sheet whose vertex lies on edge e, or -1 when the edge is not cut.
  std::array<std::int8_t, 12> EdgeSheet{};
  /// Bit e set when the corners of edge e are on opposite sides of the isovalue.
  std::uint16_t CutEdges = 0;
};

class CaseTable
{
public:
  /// `triangleEdges` holds 256 rows of 16 ints, each row the edge triples of one case ended by
  /// -1: the layout of VTK's vtkMarchingCubesTriangleCases.
  explicit CaseTable(const int* triangleEdges);

  const CaseEntry& operator[](int caseIndex) const { return this->Cases[caseIndex]; }

  /// Empty when the triangle table agrees with the corner/edge conventions above; otherwise
  /// what disagrees (a triangle on an uncut edge, a cut edge no triangle uses).
  const std::string& Problem() const { return this->Inconsistency; }

  /// Axis (0, 1, 2) along which edge e runs.
  static int EdgeAxis(int e);

  /// The edge of a cube that runs along `axis` and whose lower corner is offset by `du`, `dv`
  /// (0 or 1) along the two other axes, taken in increasing axis order.
  static int EdgeAt(int axis, int du, int dv);

private:
  std::array<CaseEntry, 256> Cases;
  std::string Inconsistency;
};

} // namespace rgmc

#endif

// Builds the per-case tables (cut edges, sheets) from VTK's marching-cubes triangle table.
#include "rgmcCaseTable.h"

#include <sstream>

namespace rgmc
{

namespace
{
int Find(int* parent, int x)
{
  while (parent[x] != x)
  {
    x = parent[x] = parent[parent[x]];
  }
  return x;
}
} // namespace

int CaseTable::EdgeAxis(int e)
{
  const int* a = CornerOffset[EdgeCorners[e][0]];
  const int* b = CornerOffset[EdgeCorners[e][1]];
  for (int axis = 0; axis < 3; ++axis)
  {
    if (a[axis] != b[axis])
    {
      return axis;
    }
  }
  return -1;
}

int CaseTable::EdgeAt(int axis, int du, int dv)
{
  const int u = axis == 0 ? 1 : 0;
  const int v = axis == 2 ? 1 : 2;
  for (int e = 0; e < 12; ++e)
  {
    const int* lo = CornerOffset[EdgeCorners[e][0]];
    if (EdgeAxis(e) == axis && lo[u] == du && lo[v] == dv)
    {
      return e;
    }
  }
  return -1;
}

CaseTable::CaseTable(const int* triangleEdges)
{
  std::ostringstream problems;
  for (int c = 0; c < 256; ++c)
  {
    CaseEntry& entry = this->Cases[c];
    entry.EdgeSheet.fill(-1);
    for (int e = 0; e < 12; ++e)
    {
      const bool loInside = (c >> EdgeCorners[e][0]) & 1;
      const bool hiInside = (c >> EdgeCorners[e][1]) & 1;
      if (loInside != hiInside)
      {
        entry.CutEdges |= static_cast<std::uint16_t>(1u << e);
      }
    }

    const int* row = triangleEdges + 16 * c;
    std::uint16_t usedEdges = 0;
    for (int t = 0; t < MaxTriangles && row[3 * t] >= 0; ++t)
    {
      for (int v = 0; v < 3; ++v)
      {
        entry.Triangles[t][v] = static_cast<std::int8_t>(row[3 * t + v]);
        usedEdges |= static_cast<std::uint16_t>(1u << row[3 * t + v]);
      }
      ++entry.NumTriangles;
    }
    if (usedEdges != entry.CutEdges)
    {
      problems << "case " << c << ": triangles use edges 0x" << std::hex << usedEdges
               << " but the cut edges are 0x" << entry.CutEdges << std::dec << "; ";
    }

    // Sheets: triangles joined through a shared edge (hence a shared vertex).
    int parent[MaxTriangles];
    for (int t = 0; t < entry.NumTriangles; ++t)
    {
      parent[t] = t;
    }
    for (int a = 0; a < entry.NumTriangles; ++a)
    {
      for (int b = a + 1; b < entry.NumTriangles; ++b)
      {
        for (int va = 0; va < 3; ++va)
        {
          for (int vb = 0; vb < 3; ++vb)
          {
            if (entry.Triangles[a][va] == entry.Triangles[b][vb])
            {
              parent[Find(parent, a)] = Find(parent, b);
            }
          }
        }
      }
    }
    int sheetOfRoot[MaxTriangles];
    for (int t = 0; t < entry.NumTriangles; ++t)
    {
      sheetOfRoot[t] = -1;
    }
    for (int t = 0; t < entry.NumTriangles; ++t)
    {
      const int root = Find(parent, t);
      if (sheetOfRoot[root] < 0)
      {
        sheetOfRoot[root] = entry.NumSheets++;
      }
      const int sheet = sheetOfRoot[root];
      entry.TriangleSheet[t] = static_cast<std::int8_t>(sheet);
      for (int v = 0; v < 3; ++v)
      {
        const int e = entry.Triangles[t][v];
        entry.SheetEdges[sheet] |= static_cast<std::uint16_t>(1u << e);
        entry.EdgeSheet[e] = static_cast<std::int8_t>(sheet);
      }
    }
  }
  this->Inconsistency = problems.str();
}

} // namespace rgmc

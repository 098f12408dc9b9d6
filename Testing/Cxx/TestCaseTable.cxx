// Unit test of the case and sheet tables derived from VTK's marching-cubes triangle table:
// the conventions agree with the table, and every case's sheets partition its triangles.
#include "rgmcCaseTable.h"
#include "rgmcCheck.h"

#include "vtkMarchingCubesTriangleCases.h"

#include <set>

int main()
{
  const rgmc::CaseTable table(&vtkMarchingCubesTriangleCases::GetCases()[0].edges[0]);
  RGMC_CHECK(table.Problem().empty(), "VTK's table disagrees with the conventions: " << table.Problem());

  // Edge conventions: each edge joins corners that differ along exactly one axis, from the lower
  // corner; EdgeAt inverts (axis, offsets) -> edge.
  for (int e = 0; e < 12; ++e)
  {
    const int axis = rgmc::CaseTable::EdgeAxis(e);
    const int* lo = rgmc::CornerOffset[rgmc::EdgeCorners[e][0]];
    const int* hi = rgmc::CornerOffset[rgmc::EdgeCorners[e][1]];
    int differing = 0;
    for (int a = 0; a < 3; ++a)
    {
      differing += lo[a] != hi[a];
    }
    RGMC_CHECK(differing == 1 && lo[axis] == 0 && hi[axis] == 1, "edge " << e);
    const int u = axis == 0 ? 1 : 0, v = axis == 2 ? 1 : 2;
    RGMC_CHECK(rgmc::CaseTable::EdgeAt(axis, lo[u], lo[v]) == e, "EdgeAt for edge " << e);
  }

  int totalSheets = 0, multiSheet = 0;
  for (int c = 0; c < 256; ++c)
  {
    const rgmc::CaseEntry& ce = table[c];
    RGMC_CHECK((c == 0 || c == 255) == (ce.NumTriangles == 0), "case " << c << " triangles");
    totalSheets += ce.NumSheets;
    multiSheet += ce.NumSheets > 1;

    // Every triangle is in exactly one sheet, and the sheets' edges are the cut edges.
    std::uint16_t union_ = 0;
    for (int s = 0; s < ce.NumSheets; ++s)
    {
      RGMC_CHECK(ce.SheetEdges[s] != 0, "case " << c << " sheet " << s << " is empty");
      RGMC_CHECK((union_ & ce.SheetEdges[s]) == 0, "case " << c << ": sheets share an edge");
      union_ |= ce.SheetEdges[s];
    }
    RGMC_CHECK(union_ == ce.CutEdges, "case " << c << ": sheets do not cover the cut edges");
    for (int t = 0; t < ce.NumTriangles; ++t)
    {
      const int s = ce.TriangleSheet[t];
      RGMC_CHECK(s >= 0 && s < ce.NumSheets, "case " << c << " triangle " << t);
      for (int v = 0; v < 3; ++v)
      {
        RGMC_CHECK(ce.EdgeSheet[ce.Triangles[t][v]] == s, "case " << c << " triangle " << t);
      }
    }
    for (int e = 0; e < 12; ++e)
    {
      const bool cut = (ce.CutEdges >> e) & 1;
      RGMC_CHECK(cut == (ce.EdgeSheet[e] >= 0), "case " << c << " edge " << e);
    }

    // Each sheet is connected: a flood over shared edges from its first triangle reaches all.
    for (int s = 0; s < ce.NumSheets; ++s)
    {
      std::set<int> reached, edges;
      for (int t = 0; t < ce.NumTriangles && reached.empty(); ++t)
      {
        if (ce.TriangleSheet[t] == s)
        {
          reached.insert(t);
          edges.insert(ce.Triangles[t].begin(), ce.Triangles[t].end());
        }
      }
      for (bool grew = true; grew;)
      {
        grew = false;
        for (int t = 0; t < ce.NumTriangles; ++t)
        {
          if (reached.count(t))
          {
            continue;
          }
          for (int v = 0; v < 3; ++v)
          {
            if (edges.count(ce.Triangles[t][v]))
            {
              reached.insert(t);
              edges.insert(ce.Triangles[t].begin(), ce.Triangles[t].end());
              grew = true;
              break;
            }
          }
        }
      }
      int members = 0;
      for (int t = 0; t < ce.NumTriangles; ++t)
      {
        members += ce.TriangleSheet[t] == s;
      }
      RGMC_CHECK(static_cast<int>(reached.size()) == members,
        "case " << c << " sheet " << s << " is not connected");
    }

    // A case and its complement cut the same edges.
    RGMC_CHECK(ce.CutEdges == table[255 - c].CutEdges, "case " << c << " vs its complement");
  }
  // The classic table: the ambiguous cases have several sheets (e.g. two opposite corners).
  RGMC_CHECK(table[1 | 64].NumSheets == 2, "case 65 (corners 0 and 6) should have 2 sheets");
  RGMC_CHECK(multiSheet > 0 && totalSheets > 254, "sheet counts " << multiSheet << " " << totalSheets);
  return rgmc_test::Result("TestCaseTable");
}

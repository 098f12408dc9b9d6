// Index arithmetic shared by every rank: global vertex keys over the whole extent, the local
// sample layout of one piece, and which rank owns which cube.
#ifndef rgmcGrid_h
#define rgmcGrid_h

#include "rgmcInline.h"

#include <algorithm>
#include <cstdint>
#include <utility>
#include <vector>

namespace rgmc
{

/// An inclusive box of cube (cell) indices; empty when Lo > Hi on any axis.
struct CellBox
{
  int Lo[3] = { 0, 0, 0 };
  int Hi[3] = { -1, -1, -1 };

  bool Empty() const { return Lo[0] > Hi[0] || Lo[1] > Hi[1] || Lo[2] > Hi[2]; }
  RGMC_INLINE bool Contains(int i, int j, int k) const
  {
    return i >= Lo[0] && i <= Hi[0] && j >= Lo[1] && j <= Hi[1] && k >= Lo[2] && k <= Hi[2];
  }
  std::int64_t Count() const
  {
    return this->Empty()
      ? 0
      : std::int64_t(Hi[0] - Lo[0] + 1) * (Hi[1] - Lo[1] + 1) * (Hi[2] - Lo[2] + 1);
  }
  CellBox Intersect(const CellBox& o) const
  {
    CellBox r;
    for (int a = 0; a < 3; ++a)
    {
      r.Lo[a] = std::max(Lo[a], o.Lo[a]);
      r.Hi[a] = std::min(Hi[a], o.Hi[a]);
    }
    return r;
  }
  CellBox Grown(int n) const
  {
    CellBox r = *this;
    for (int a = 0; a < 3; ++a)
    {
      r.Lo[a] -= n;
      r.Hi[a] += n;
    }
    return r;
  }
  bool ContainsBox(const CellBox& o) const
  {
    return o.Empty() ||
      (Contains(o.Lo[0], o.Lo[1], o.Lo[2]) && Contains(o.Hi[0], o.Hi[1], o.Hi[2]));
  }
};

/// Whether every cell of `region` lies in at least one of `boxes`. Exact: the boxes that meet
/// the region cut it into a grid of blocks (at their faces), and each block is checked once.
inline bool Covers(const std::vector<CellBox>& boxes, const CellBox& region)
{
  if (region.Empty())
  {
    return true;
  }
  std::vector<CellBox> near;
  std::vector<int> cuts[3];
  for (int a = 0; a < 3; ++a)
  {
    cuts[a] = { region.Lo[a], region.Hi[a] + 1 };
  }
  for (const CellBox& b : boxes)
  {
    const CellBox part = b.Intersect(region);
    if (part.Empty())
    {
      continue;
    }
    near.push_back(part);
    for (int a = 0; a < 3; ++a)
    {
      cuts[a].push_back(part.Lo[a]);
      cuts[a].push_back(part.Hi[a] + 1);
    }
  }
  for (auto& c : cuts)
  {
    std::sort(c.begin(), c.end());
    c.erase(std::unique(c.begin(), c.end()), c.end());
  }
  for (std::size_t z = 0; z + 1 < cuts[2].size(); ++z)
  {
    for (std::size_t y = 0; y + 1 < cuts[1].size(); ++y)
    {
      for (std::size_t x = 0; x + 1 < cuts[0].size(); ++x)
      {
        // A block lies wholly inside or wholly outside each box: its first cell decides.
        const int i = cuts[0][x], j = cuts[1][y], k = cuts[2][z];
        bool inside = false;
        for (const CellBox& b : near)
        {
          if (b.Contains(i, j, k))
          {
            inside = true;
            break;
          }
        }
        if (!inside)
        {
          return false;
        }
      }
    }
  }
  return true;
}

/// Point extents use VTK's order (x0, x1, y0, y1, z0, z1), inclusive.
class Grid
{
public:
  Grid(const int whole[6], const int local[6])
  {
    for (int a = 0; a < 3; ++a)
    {
      this->WholeLo[a] = whole[2 * a];
      this->WholeHi[a] = whole[2 * a + 1];
      this->LocalLo[a] = local[2 * a];
      this->LocalHi[a] = local[2 * a + 1];
    }
    this->WholeNx = this->WholeHi[0] - this->WholeLo[0] + 1;
    this->WholeNxy = this->WholeNx * (this->WholeHi[1] - this->WholeLo[1] + 1);
    this->NumPoints = this->WholeNxy * (this->WholeHi[2] - this->WholeLo[2] + 1);
    this->StrideY = this->LocalHi[0] - this->LocalLo[0] + 1;
    this->StrideZ = this->StrideY * (this->LocalHi[1] - this->LocalLo[1] + 1);
  }

  /// Global id of a grid point, the same on every rank.
  std::int64_t PointId(int i, int j, int k) const
  {
    return (i - this->WholeLo[0]) + this->WholeNx * (j - this->WholeLo[1]) +
      this->WholeNxy * (k - this->WholeLo[2]);
  }

  /// Key of the vertex on the edge that leaves grid point (i, j, k) along `axis`.
  std::int64_t EdgeKey(int i, int j, int k, int axis) const
  {
    return 3 * this->PointId(i, j, k) + axis;
  }

  /// Key of a vertex that sits on grid point (i, j, k) (its sample equals the isovalue). Placed
  /// after all edge keys so that the two kinds never collide.
  std::int64_t PointKey(int i, int j, int k) const
  {
    return 3 * this->NumPoints + this->PointId(i, j, k);
  }

  bool IsPointKey(std::int64_t key) const { return key >= 3 * this->NumPoints; }

  /// Inverse of EdgeKey / PointKey: the grid point and the axis (-1 for a point key).
  void Decode(std::int64_t key, int p[3], int& axis) const
  {
    std::int64_t id;
    if (this->IsPointKey(key))
    {
      id = key - 3 * this->NumPoints;
      axis = -1;
    }
    else
    {
      id = key / 3;
      axis = static_cast<int>(key % 3);
    }
    p[2] = static_cast<int>(id / this->WholeNxy) + this->WholeLo[2];
    id %= this->WholeNxy;
    p[1] = static_cast<int>(id / this->WholeNx) + this->WholeLo[1];
    p[0] = static_cast<int>(id % this->WholeNx) + this->WholeLo[0];
  }

  /// Whether cube (i, j, k) lies inside the whole extent.
  bool HasCell(int i, int j, int k) const
  {
    return i >= this->WholeLo[0] && i < this->WholeHi[0] && j >= this->WholeLo[1] &&
      j < this->WholeHi[1] && k >= this->WholeLo[2] && k < this->WholeHi[2];
  }

  CellBox WholeCells() const
  {
    CellBox b;
    for (int a = 0; a < 3; ++a)
    {
      b.Lo[a] = this->WholeLo[a];
      b.Hi[a] = this->WholeHi[a] - 1;
    }
    return b;
  }

  bool LocalHasPoint(int i, int j, int k) const
  {
    return i >= this->LocalLo[0] && i <= this->LocalHi[0] && j >= this->LocalLo[1] &&
      j <= this->LocalHi[1] && k >= this->LocalLo[2] && k <= this->LocalHi[2];
  }

  /// Index of grid point (i, j, k) in this piece's sample array.
  std::int64_t LocalIndex(int i, int j, int k) const
  {
    return (i - this->LocalLo[0]) + this->StrideY * (j - this->LocalLo[1]) +
      this->StrideZ * (k - this->LocalLo[2]);
  }

  int WholeLo[3], WholeHi[3];
  int LocalLo[3], LocalHi[3];
  std::int64_t WholeNx, WholeNxy, NumPoints;
  std::int64_t StrideY, StrideZ;
};

/// Which rank owns each cube: the lowest rank whose box of non-ghost cells contains it. With
/// ParaView's decompositions the boxes do not overlap; a reader that ignores piece requests can
/// make them overlap, and then the lower rank wins.
class Ownership
{
public:
  Ownership() = default;
  Ownership(std::vector<CellBox> boxes, int rank)
    : Boxes(std::move(boxes))
    , Rank(rank)
  {
    const CellBox& mine = this->Boxes[rank];
    for (int r = 0; r < rank; ++r)
    {
      const CellBox overlap = mine.Intersect(this->Boxes[r]);
      if (!overlap.Empty())
      {
        this->LowerOverlaps.push_back(overlap);
        if (overlap.ContainsBox(mine))
        {
          this->CoveredByLower = true;
        }
      }
    }
    // Which ranks touch which, and a proper colouring of those pairs, greedily in the order of
    // the pairs: the same on every rank, as every rank knows every box. A rank meets its
    // neighbours in the order of their pairs' colours; the pending meeting of smallest colour
    // can always go ahead (both its ranks are through the smaller colours, and no rank has two
    // pairs of one colour), so blocking sends in that order cannot deadlock, and there are
    // fewer steps than twice the most neighbours a rank has, whatever the number of ranks.
    const int numRanks = static_cast<int>(this->Boxes.size());
    std::vector<std::vector<std::uint8_t>> used(static_cast<std::size_t>(numRanks));
    std::vector<std::pair<int, int>> mineByColour;
    for (int a = 0; a < numRanks; ++a)
    {
      for (int b = a + 1; b < numRanks; ++b)
      {
        if (!Touch(this->Boxes[a], this->Boxes[b]))
        {
          continue;
        }
        std::size_t colour = 0;
        while ((colour < used[a].size() && used[a][colour]) ||
          (colour < used[b].size() && used[b][colour]))
        {
          ++colour;
        }
        for (const int r : { a, b })
        {
          used[r].resize(std::max(used[r].size(), colour + 1), 0);
          used[r][colour] = 1;
        }
        if (a == rank || b == rank)
        {
          const int other = a == rank ? b : a;
          this->NeighbourRanks.push_back(other);
          mineByColour.emplace_back(static_cast<int>(colour), other);
        }
      }
    }
    std::sort(this->NeighbourRanks.begin(), this->NeighbourRanks.end());
    std::sort(mineByColour.begin(), mineByColour.end());
    for (const auto& m : mineByColour)
    {
      this->Meetings.push_back(m.second);
    }
  }

  /// Whether two non-empty boxes of cubes share a cube, a face, an edge or a corner: then some
  /// vertex can have cubes of both around it.
  static bool Touch(const CellBox& a, const CellBox& b)
  {
    return !a.Empty() && !b.Empty() && !a.Grown(1).Intersect(b).Empty();
  }

  const CellBox& Mine() const { return this->Boxes[this->Rank]; }
  bool OwnsNothing() const { return this->Mine().Empty() || this->CoveredByLower; }
  const std::vector<CellBox>& Overlaps() const { return this->LowerOverlaps; }
  int NumberOfRanks() const { return static_cast<int>(this->Boxes.size()); }
  const CellBox& BoxOf(int rank) const { return this->Boxes[rank]; }

  RGMC_INLINE bool Owns(int i, int j, int k) const
  {
    if (!this->Mine().Contains(i, j, k))
    {
      return false;
    }
    for (const CellBox& b : this->LowerOverlaps)
    {
      if (b.Contains(i, j, k))
      {
        return false;
      }
    }
    return true;
  }

  /// The ranks whose cubes touch this rank's (sorted): the only ones a vertex of this rank's
  /// cubes can be shared with.
  const std::vector<int>& Neighbours() const { return this->NeighbourRanks; }

  /// This rank's neighbours in the order in which it exchanges messages with them (see the
  /// constructor): for Ranks::ExchangeInOrder.
  const std::vector<int>& MeetingOrder() const { return this->Meetings; }

  /// The owning rank of a cube that touches this rank's cubes (a cube around one of its
  /// vertices), or -1 when no rank has it. Looks at this rank and its neighbours only.
  int OwnerNear(int i, int j, int k) const
  {
    // The lowest rank whose box contains the cube: this rank's place among its neighbours.
    bool mineChecked = false;
    for (const int r : this->NeighbourRanks)
    {
      if (!mineChecked && r > this->Rank)
      {
        mineChecked = true;
        if (this->Mine().Contains(i, j, k))
        {
          return this->Rank;
        }
      }
      if (this->Boxes[r].Contains(i, j, k))
      {
        return r;
      }
    }
    return !mineChecked && this->Mine().Contains(i, j, k) ? this->Rank : -1;
  }

private:
  std::vector<CellBox> Boxes;
  int Rank = 0;
  std::vector<CellBox> LowerOverlaps;
  std::vector<int> NeighbourRanks;
  std::vector<int> Meetings;
  bool CoveredByLower = false;
};

} // namespace rgmc

#endif

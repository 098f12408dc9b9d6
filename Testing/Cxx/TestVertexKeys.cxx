// Unit test of vertex keys and ownership: keys are unique, decodable, independent of the piece
// a rank holds, and every cube has exactly one owner.
#include "rgmcCheck.h"
#include "rgmcGrid.h"

#include <algorithm>
#include <set>
#include <utility>
#include <vector>

int main()
{
  const int whole[6] = { -2, 3, 1, 4, 5, 7 }; // a whole extent that does not start at 0
  const int pieceA[6] = { -2, 1, 1, 4, 5, 7 };
  const int pieceB[6] = { 0, 3, 2, 4, 5, 6 };
  const rgmc::Grid full(whole, whole), a(whole, pieceA), b(whole, pieceB);

  std::set<std::int64_t> keys;
  for (int k = whole[4]; k <= whole[5]; ++k)
  {
    for (int j = whole[2]; j <= whole[3]; ++j)
    {
      for (int i = whole[0]; i <= whole[1]; ++i)
      {
        for (int axis = -1; axis < 3; ++axis)
        {
          const std::int64_t key = axis < 0 ? full.PointKey(i, j, k) : full.EdgeKey(i, j, k, axis);
          RGMC_CHECK(keys.insert(key).second, "duplicate key at " << i << " " << j << " " << k);
          RGMC_CHECK(
            full.IsPointKey(key) == (axis < 0), "key kind at " << i << " " << j << " " << k);
          int p[3], decodedAxis;
          full.Decode(key, p, decodedAxis);
          RGMC_CHECK(
            p[0] == i && p[1] == j && p[2] == k && decodedAxis == axis, "decode of " << key);
          // The key depends on the whole extent only, not on the piece.
          const std::int64_t ka = axis < 0 ? a.PointKey(i, j, k) : a.EdgeKey(i, j, k, axis);
          const std::int64_t kb = axis < 0 ? b.PointKey(i, j, k) : b.EdgeKey(i, j, k, axis);
          RGMC_CHECK(
            ka == key && kb == key, "piece-dependent key at " << i << " " << j << " " << k);
        }
      }
    }
  }
  RGMC_CHECK(static_cast<std::int64_t>(keys.size()) == 4 * full.NumPoints, "key count");

  // Local indices follow the piece's layout.
  RGMC_CHECK(b.LocalIndex(0, 2, 5) == 0, "first sample of piece B");
  RGMC_CHECK(b.LocalIndex(3, 4, 6) == 4 * 3 * 2 - 1, "last sample of piece B");

  // Ownership: overlapping boxes go to the lowest rank; every whole cell has one owner.
  std::vector<rgmc::CellBox> boxes(3);
  boxes[0].Lo[0] = -2, boxes[0].Hi[0] = 0, boxes[0].Lo[1] = 1, boxes[0].Hi[1] = 3;
  boxes[0].Lo[2] = 5, boxes[0].Hi[2] = 6;
  boxes[1] = full.WholeCells(); // a reader that ignored the piece request
  boxes[2] = rgmc::CellBox();   // a rank with no data
  std::vector<rgmc::Ownership> owners;
  for (int r = 0; r < 3; ++r)
  {
    owners.emplace_back(boxes, r);
  }
  RGMC_CHECK(owners[2].OwnsNothing(), "the empty rank owns nothing");
  RGMC_CHECK(!owners[1].OwnsNothing(), "rank 1 owns what rank 0 lacks");
  const rgmc::CellBox cells = full.WholeCells();
  for (int k = cells.Lo[2]; k <= cells.Hi[2]; ++k)
  {
    for (int j = cells.Lo[1]; j <= cells.Hi[1]; ++j)
    {
      for (int i = cells.Lo[0]; i <= cells.Hi[0]; ++i)
      {
        int count = 0, who = -1;
        for (int r = 0; r < 3; ++r)
        {
          if (owners[r].Owns(i, j, k))
          {
            ++count;
            who = r;
          }
        }
        RGMC_CHECK(
          count == 1, "cell " << i << " " << j << " " << k << " has " << count << " owners");
        for (int r = 0; r < 3; ++r)
        {
          // Every rank whose cubes the cell touches knows its owner.
          if (!boxes[r].Empty() && boxes[r].Grown(1).Contains(i, j, k))
          {
            RGMC_CHECK(owners[r].OwnerNear(i, j, k) == who,
              "OwnerNear() on rank " << r << " of " << i << " " << j << " " << k);
          }
        }
      }
    }
  }

  // Coverage, against counting cell by cell: random boxes, some overlapping, over a region.
  {
    std::uint32_t state = 12345;
    auto next = [&state](int n)
    {
      state = state * 1664525u + 1013904223u;
      return static_cast<int>((state >> 8) % static_cast<std::uint32_t>(n));
    };
    for (int trial = 0; trial < 300; ++trial)
    {
      rgmc::CellBox region;
      for (int a = 0; a < 3; ++a)
      {
        region.Lo[a] = next(3);
        region.Hi[a] = region.Lo[a] + next(6);
      }
      std::vector<rgmc::CellBox> boxes(1 + next(6));
      for (rgmc::CellBox& b : boxes)
      {
        for (int a = 0; a < 3; ++a)
        {
          b.Lo[a] = next(8) - 1;
          b.Hi[a] = b.Lo[a] + next(7) - 1; // sometimes empty
        }
      }
      if (trial % 3 == 0)
      {
        boxes.push_back(region.Grown(next(2))); // sometimes the region is covered
      }
      bool expected = true;
      for (int k = region.Lo[2]; k <= region.Hi[2]; ++k)
      {
        for (int j = region.Lo[1]; j <= region.Hi[1]; ++j)
        {
          for (int i = region.Lo[0]; i <= region.Hi[0]; ++i)
          {
            bool in = false;
            for (const rgmc::CellBox& b : boxes)
            {
              in = in || b.Contains(i, j, k);
            }
            expected = expected && in;
          }
        }
      }
      RGMC_CHECK(rgmc::Covers(boxes, region) == expected, "Covers() in trial " << trial);
    }
  }
  // Neighbours and the order of meetings, on ParaView-like splits of up to 64 ranks and on
  // random overlapping boxes: neighbours are exactly the ranks whose boxes touch, both ways;
  // meeting each neighbour once in MeetingOrder() with blocking exchanges finishes (simulated:
  // a meeting happens when both ranks are at it); the steps stay few whatever the rank count.
  {
    std::uint32_t state = 777;
    auto next = [&state](int n)
    {
      state = state * 1664525u + 1013904223u;
      return static_cast<int>((state >> 8) % static_cast<std::uint32_t>(n));
    };
    for (int trial = 0; trial < 40; ++trial)
    {
      std::vector<rgmc::CellBox> boxes;
      if (trial < 20)
      {
        // Recursive halving along the largest axis into 1 + trial * 3 pieces.
        const int pieces = 1 + trial * 3;
        std::vector<std::pair<rgmc::CellBox, int>> work;
        rgmc::CellBox all;
        for (int a = 0; a < 3; ++a)
        {
          all.Lo[a] = 0;
          all.Hi[a] = 40 + 7 * a;
        }
        work.emplace_back(all, pieces);
        while (!work.empty())
        {
          const auto w = work.back();
          work.pop_back();
          if (w.second == 1)
          {
            boxes.push_back(w.first);
            continue;
          }
          int axis = 0;
          for (int a = 1; a < 3; ++a)
          {
            if (w.first.Hi[a] - w.first.Lo[a] > w.first.Hi[axis] - w.first.Lo[axis])
            {
              axis = a;
            }
          }
          const int lower = w.second / 2;
          rgmc::CellBox lo = w.first, hi = w.first;
          lo.Hi[axis] =
            w.first.Lo[axis] + (w.first.Hi[axis] - w.first.Lo[axis] + 1) * lower / w.second - 1;
          hi.Lo[axis] = lo.Hi[axis] + 1;
          work.emplace_back(hi, w.second - lower);
          work.emplace_back(lo, lower);
        }
      }
      else
      {
        boxes.resize(2 + next(30));
        for (rgmc::CellBox& b : boxes)
        {
          for (int a = 0; a < 3; ++a)
          {
            b.Lo[a] = next(20) - 1;
            b.Hi[a] = b.Lo[a] + next(12) - 1; // sometimes empty
          }
        }
      }
      const int n = static_cast<int>(boxes.size());
      std::vector<rgmc::Ownership> own;
      std::size_t most = 0, steps = 0;
      for (int r = 0; r < n; ++r)
      {
        own.emplace_back(boxes, r);
        most = std::max(most, own[r].Neighbours().size());
      }
      for (int r = 0; r < n; ++r)
      {
        std::vector<int> order = own[r].MeetingOrder();
        std::sort(order.begin(), order.end());
        RGMC_CHECK(order == own[r].Neighbours(), "trial " << trial << ": meetings of rank " << r);
        for (int q = 0; q < n; ++q)
        {
          const bool touch = q != r && !boxes[r].Empty() && !boxes[q].Empty() &&
            !boxes[r].Grown(1).Intersect(boxes[q]).Empty();
          const auto& nb = own[r].Neighbours();
          RGMC_CHECK(std::count(nb.begin(), nb.end(), q) == (touch ? 1 : 0),
            "trial " << trial << ": ranks " << r << " and " << q);
        }
      }
      std::vector<std::size_t> at(n, 0);
      for (bool progress = true; progress;)
      {
        progress = false;
        for (int r = 0; r < n; ++r)
        {
          if (at[r] < own[r].MeetingOrder().size())
          {
            const int q = own[r].MeetingOrder()[at[r]];
            if (q > r && at[q] < own[q].MeetingOrder().size() && own[q].MeetingOrder()[at[q]] == r)
            {
              ++at[r];
              ++at[q];
              progress = true;
            }
          }
        }
        steps += progress ? 1 : 0;
      }
      for (int r = 0; r < n; ++r)
      {
        RGMC_CHECK(at[r] == own[r].MeetingOrder().size(),
          "trial " << trial << ": rank " << r << " is stuck before meeting rank "
                   << own[r].MeetingOrder()[at[r]] << " (a deadlock)");
      }
      RGMC_CHECK(steps <= 2 * most,
        "trial " << trial << ": " << steps << " steps for at most " << most
                 << " neighbours of a rank");
    }
  }
  return rgmc_test::Result("TestVertexKeys");
}

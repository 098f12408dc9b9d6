// Seam Repair: vertex normals that are the same to the bit on any number of ranks.
#ifndef rgmcSeamNormals_h
#define rgmcSeamNormals_h

#include "rgmcBuffer.h"
#include "rgmcSeamSmoothing.h"
#include "vtkRGArrays.h"
#include "vtkRGMessage.h"
#include "vtkRGParallel.h"

#include "vtkFloatArray.h"
#include "vtkMath.h"
#include "vtkSmartPointer.h"

#include <algorithm>
#include <array>
#include <string>
#include <utility>
#include <vector>

namespace rgmc
{
namespace seam
{

constexpr int NormalTag = 48812, NormalBackTag = 48814;

/// Area-weighted vertex normals of the smoothed positions, summed at each vertex's owner in one
/// order fixed by the mesh.
template <typename T, typename I>
class SeamNormals : public SeamSmoothing<T, I>
{
public:
  using SeamSmoothing<T, I>::SeamSmoothing;

  /// Area-weighted vertex normals of the smoothed positions. Each vertex sums its triangles'
  /// area vectors in one order fixed by the mesh (by the triangles' sorted global ids), at its
  /// owner, so that the normals are the same to the bit for any number of ranks. Two exchanges,
  /// three agreements; the output's array "Normals", or null on failure.
  vtkSmartPointer<vtkFloatArray> Normals(std::string& problem)
  {
    rgmc::OverwriteVector<double> sums; // every vertex's written by SumOwnTerms
    std::vector<std::vector<vtkIdType>> toOwners(this->AllRanks.Size);
    if (!this->AllRanks.Step("compute normals", problem,
          [&]()
          {
            sums.resize(static_cast<std::size_t>(3 * this->NumVertices));
            if (this->CornerOffsets.empty())
            {
              this->CornersAround(this->CornerOffsets, this->Corners);
            }
            this->ComputeTriangleCrosses();
            this->ListSharedTerms(toOwners);
          }))
    {
      return nullptr;
    }
    const auto received = this->AllRanks.Exchange(toOwners, this->Partners, NormalTag);
    if (!this->AllRanks.Step("compute normals", problem,
          [&]()
          {
            this->SumOwnTerms(sums);
            this->SumSharedTerms(received, sums);
          }))
    {
      return nullptr;
    }
    rgmc::OverwriteVector<double>().swap(this->TriangleCross);
    rgmc::OverwriteVector<std::uint32_t>().swap(this->FanOrder);
    this->Update(sums.data(), NormalBackTag);
    auto normals = vtkSmartPointer<vtkFloatArray>::New();
    if (!this->AllRanks.Step("compute normals", problem,
          [&]()
          {
            // Straight into the output's array, rounded to float on threads.
            normals->SetName("Normals");
            normals->SetNumberOfComponents(3);
            float* out = rgmc::Allocate(normals.Get(), 3 * this->NumVertices);
            rgmc::ParallelFor(3 * this->NumVertices, 3 * RowGrain,
              [&](vtkIdType first, vtkIdType last)
              {
                for (vtkIdType i = first; i < last; ++i)
                {
                  out[i] = static_cast<float>(sums[i]);
                }
              });
          }))
    {
      return nullptr;
    }
    return normals;
  }

private:
  /// A triangle's contribution to a vertex normal: its sorted global ids, and its area vector
  /// taken from its corner of smallest global id (orientation kept), so that every rank
  /// computes the same bits.
  struct NormalTerm
  {
    std::array<vtkIdType, 3> Key;
    double Cross[3];
    bool operator<(const NormalTerm& o) const { return this->Key < o.Key; }
  };

  /// Each triangle's area vector at the smoothed positions, taken from its corner of smallest
  /// global id (orientation kept): the same bits whichever vertex or rank asks. Once per
  /// triangle, on threads (the stencils' memory, released, holds it).
  void ComputeTriangleCrosses()
  {
    this->TriangleCross.resize(static_cast<std::size_t>(3 * this->NumTriangles));
    const auto& gid = this->Numbering.Gid;
    const T* x = this->Smoothed.data();
    rgmc::ParallelFor(this->NumTriangles, 4096, // tasks of about 0.06 ms
      [&](vtkIdType firstTriangle, vtkIdType lastTriangle)
      {
        for (vtkIdType t = firstTriangle; t < lastTriangle; ++t)
        {
          vtkIdType c[3] = { static_cast<vtkIdType>(this->Triangles[3 * t]),
            static_cast<vtkIdType>(this->Triangles[3 * t + 1]),
            static_cast<vtkIdType>(this->Triangles[3 * t + 2]) };
          const int first = gid[c[0]] < gid[c[1]] ? (gid[c[0]] < gid[c[2]] ? 0 : 2)
                                                  : (gid[c[1]] < gid[c[2]] ? 1 : 2);
          std::rotate(c, c + first, c + 3);
          double e1[3], e2[3];
          for (int k = 0; k < 3; ++k)
          {
            e1[k] = static_cast<double>(x[3 * c[1] + k]) - static_cast<double>(x[3 * c[0] + k]);
            e2[k] = static_cast<double>(x[3 * c[2] + k]) - static_cast<double>(x[3 * c[0] + k]);
          }
          vtkMath::Cross(e1, e2, &this->TriangleCross[3 * t]);
        }
      });
  }

  NormalTerm TermOf(vtkIdType t) const
  {
    const auto& gid = this->Numbering.Gid;
    NormalTerm out;
    out.Key = { gid[static_cast<vtkIdType>(this->Triangles[3 * t])],
      gid[static_cast<vtkIdType>(this->Triangles[3 * t + 1])],
      gid[static_cast<vtkIdType>(this->Triangles[3 * t + 2])] };
    std::sort(out.Key.begin(), out.Key.end());
    std::copy_n(&this->TriangleCross[3 * t], 3, out.Cross);
    return out;
  }

  /// The terms of this rank's triangles at vertex v, into `terms`.
  void LocalTerms(vtkIdType v, std::vector<NormalTerm>& terms) const
  {
    terms.clear();
    for (vtkIdType c = this->CornerOffsets[v]; c < this->CornerOffsets[v + 1]; ++c)
    {
      terms.push_back(this->TermOf(this->Corners[c] / 3));
    }
  }

  /// The normal of a vertex: its terms summed in the order of their keys.
  static void SumTerms(std::vector<NormalTerm>& terms, double n[3])
  {
    std::sort(terms.begin(), terms.end());
    n[0] = n[1] = n[2] = 0;
    for (const NormalTerm& t : terms)
    {
      for (int k = 0; k < 3; ++k)
      {
        n[k] += t.Cross[k];
      }
    }
    vtkMath::Normalize(n);
  }

  /// The terms of shared vertices go to their owners (in gid order, as the owners list them).
  void ListSharedTerms(std::vector<std::vector<vtkIdType>>& toOwners) const
  {
    std::vector<NormalTerm> terms;
    for (int o = 0; o < this->AllRanks.Size; ++o)
    {
      rgmc::MessageWriter out(toOwners[o]);
      for (vtkIdType v : this->FromOwner[o])
      {
        this->LocalTerms(v, terms);
        out.Int(static_cast<std::int64_t>(terms.size()));
        for (const NormalTerm& t : terms)
        {
          out.Int(t.Key[0]).Int(t.Key[1]).Int(t.Key[2]);
          out.Real(t.Cross[0]).Real(t.Cross[1]).Real(t.Cross[2]);
        }
      }
    }
  }

  /// A triangle at a vertex, by the global ids of its two other corners (sorted) and its index.
  /// Triangles that share the vertex compare by these pairs exactly as their NormalTerms compare
  /// by all three sorted ids (putting one common value into sorted pairs keeps their order,
  /// ties included), so sorting them with the same std::sort, from the same corner order, gives
  /// the terms' order without building the terms.
  struct TriangleAtVertex
  {
    vtkIdType A, B;
    vtkIdType Triangle;
    bool operator<(const TriangleAtVertex& o) const
    {
      return this->A < o.A || (this->A == o.A && this->B < o.B);
    }
  };

  /// Each vertex's sum of this rank's terms, on threads, in SumTerms' order (TriangleAtVertex).
  /// Owned shared vertices are summed again with every holder's terms (SumSharedTerms); the
  /// other shared ones get their owner's.
  void SumOwnTerms(rgmc::OverwriteVector<double>& sums) const
  {
    rgmc::ParallelFor(this->NumVertices, RowGrain,
      [&](vtkIdType first, vtkIdType last)
      {
        std::vector<TriangleAtVertex> around; // for fans larger than SmallFan
        for (vtkIdType v = first; v < last; ++v)
        {
          double* n = &sums[3 * v];
          if (!this->SumSmallFan(v, n))
          {
            this->SumLargeFan(v, around, n);
          }
          vtkMath::Normalize(n);
        }
      });
  }

  static constexpr int SmallFan = 16;
  static constexpr vtkIdType FanPrefetch = 256;

  /// The sum at a vertex of at most SmallFan triangles, with no list and no sort: each
  /// triangle's place in TriangleAtVertex's order is counted, equal pairs kept in corner order
  /// (std::sort sorts so few by insertion, which keeps them so); or, for an oriented fan the
  /// stencils' pass ordered (FanOrder), in that order. False, with nothing summed, for a larger
  /// fan.
  bool SumSmallFan(vtkIdType v, double n[3]) const
  {
    const vtkIdType first = this->CornerOffsets[v];
    const int count = static_cast<int>(this->CornerOffsets[v + 1] - first);
    if (count > SmallFan)
    {
      return false;
    }
    // The triangles of the vertex about 40 ahead (FanPrefetch corners) are asked for early: they
    // lie all over the mesh (measured: the normals about 10% faster on the 512^3 skull).
    const vtkIdType ahead = first + FanPrefetch;
    const vtkIdType aheadEnd =
      std::min(ahead + count, static_cast<vtkIdType>(this->Corners.size()));
    for (vtkIdType c = ahead; c < aheadEnd; ++c)
    {
      const vtkIdType t = this->Corners[c] / 3;
      __builtin_prefetch(this->Triangles + 3 * t);
      __builtin_prefetch(this->TriangleCross.data() + 3 * t);
    }
    if (!this->FanOrder.empty() && this->FanOrder[v] != this->NoFanOrder)
    {
      // The order the stencils' pass found: no gid looked up, no triangle read.
      const std::uint32_t places = this->FanOrder[v];
      vtkIdType order[SmallFan];
      for (int p = 0; p < count; ++p)
      {
        order[p] = this->Corners[first + ((places >> (4 * p)) & 15u)] / 3;
      }
      this->SumCrosses(order, static_cast<std::size_t>(count), n);
      return true;
    }
    const vtkIdType* gid = this->Numbering.Gid.data();
    vtkIdType a[SmallFan], b[SmallFan], triangle[SmallFan], order[SmallFan];
    for (int i = 0; i < count; ++i)
    {
      const std::pair<vtkIdType, vtkIdType> ends = this->AroundCorner(this->Corners[first + i]);
      a[i] = std::min(gid[ends.first], gid[ends.second]);
      b[i] = std::max(gid[ends.first], gid[ends.second]);
      triangle[i] = this->Corners[first + i] / 3;
    }
    for (int i = 0; i < count; ++i)
    {
      int place = 0;
      for (int j = 0; j < count; ++j)
      {
        place += a[j] < a[i] || (a[j] == a[i] && (b[j] < b[i] || (b[j] == b[i] && j < i)));
      }
      order[place] = triangle[i];
    }
    this->SumCrosses(order, static_cast<std::size_t>(count), n);
    return true;
  }

  /// The area vectors of `count` triangles summed into n, in the given order.
  void SumCrosses(const vtkIdType* triangles, std::size_t count, double n[3]) const
  {
    n[0] = n[1] = n[2] = 0;
    for (std::size_t p = 0; p < count; ++p)
    {
      for (int k = 0; k < 3; ++k)
      {
        n[k] += this->TriangleCross[3 * triangles[p] + k];
      }
    }
  }

  /// The sum at a vertex of more than SmallFan triangles, sorted in a list.
  void SumLargeFan(vtkIdType v, std::vector<TriangleAtVertex>& around, double n[3]) const
  {
    const auto& gid = this->Numbering.Gid;
    around.clear();
    for (vtkIdType c = this->CornerOffsets[v]; c < this->CornerOffsets[v + 1]; ++c)
    {
      const std::pair<vtkIdType, vtkIdType> ends = this->AroundCorner(this->Corners[c]);
      around.push_back(TriangleAtVertex{ std::min(gid[ends.first], gid[ends.second]),
        std::max(gid[ends.first], gid[ends.second]), this->Corners[c] / 3 });
    }
    std::sort(around.begin(), around.end());
    std::vector<vtkIdType> order(around.size());
    std::transform(around.begin(), around.end(), order.begin(),
      [](const TriangleAtVertex& at) { return at.Triangle; });
    this->SumCrosses(order.data(), order.size(), n);
  }

  /// Owned shared vertices: their own terms and every holder's, in the same order.
  void SumSharedTerms(
    const std::vector<std::vector<vtkIdType>>& received, rgmc::OverwriteVector<double>& sums) const
  {
    const auto& gid = this->Numbering.Gid;
    std::vector<std::size_t> cursor(this->AllRanks.Size, 0);
    std::vector<std::pair<vtkIdType, int>> order; // (gid, sharer) of owned shared vertices
    for (int s = 0; s < this->AllRanks.Size; ++s)
    {
      if (s != this->AllRanks.Rank)
      {
        for (vtkIdType v : this->ToSharer[s])
        {
          order.emplace_back(gid[v], s);
        }
      }
    }
    std::sort(order.begin(), order.end());
    std::vector<NormalTerm> terms;
    for (std::size_t i = 0; i < order.size();)
    {
      const vtkIdType v = this->VertexOfGid(order[i].first);
      this->LocalTerms(v, terms);
      for (; i < order.size() && order[i].first == gid[v]; ++i)
      {
        const std::vector<vtkIdType>& in = received[order[i].second];
        std::size_t& at = cursor[order[i].second];
        const vtkIdType count = at < in.size() ? in[at++] : 0;
        for (vtkIdType j = 0; j < count && at + 5 < in.size(); ++j, at += 6)
        {
          rgmc::MessageReader term(in.data() + at, 6);
          NormalTerm t;
          t.Key = { term.Int(), term.Int(), term.Int() };
          t.Cross[0] = term.Real();
          t.Cross[1] = term.Real();
          t.Cross[2] = term.Real();
          terms.push_back(t);
        }
      }
      SumTerms(terms, &sums[3 * v]);
    }
  }

  // Per triangle, while the normals are summed (written whole by ComputeTriangleCrosses).
  rgmc::OverwriteVector<double> TriangleCross;
};

} // namespace seam
} // namespace rgmc

#endif // rgmcSeamNormals_h

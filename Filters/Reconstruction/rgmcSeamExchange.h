// Seam Repair: the exchanges of vertex states between the ranks that share vertices.
#ifndef rgmcSeamExchange_h
#define rgmcSeamExchange_h

#include "rgmcSeamPiece.h"
#include "vtkRGCollective.h"

#include <vector>

namespace rgmc
{
namespace seam
{

constexpr int StateTag = 48808, UpdateTag = 48810;

/// The plan of the exchanges with the ranks that share vertices, made by the seams' analysis,
/// and the exchanges themselves: the neighbours an owner lacks fetched from ranks that hold
/// them (remote slots NumVertices, NumVertices + 1, ...), the owners' new states sent to the
/// other holders.
template <typename T, typename I>
class SeamExchange : public SeamPiece<T, I>
{
public:
  using SeamPiece<T, I>::SeamPiece;

protected:
  /// Who sends what each iteration: the neighbours owners lack, from ranks that hold them; the
  /// owners' new positions, to the other holders (both sides list a pair's vertices in gid
  /// order).
  void ListSharedVertices()
  {
    for (std::size_t r = 0; r < this->RemoteGids.size(); ++r)
    {
      this->RequestLists[this->RemoteProviders[r]].push_back(this->RemoteGids[r]);
      this->RemoteOrder[this->RemoteProviders[r]].push_back(
        this->NumVertices + static_cast<vtkIdType>(r));
    }
    for (std::size_t i = 0; i < this->Numbering.SharedVertex.size(); ++i)
    {
      const vtkIdType v = this->Numbering.SharedVertex[i];
      if (this->Numbering.SharedOwner[i] == this->AllRanks.Rank)
      {
        for (vtkIdType h = this->Numbering.SharerOffsets[i];
             h < this->Numbering.SharerOffsets[i + 1]; ++h)
        {
          this->ToSharer[this->Numbering.Sharers[h]].push_back(v);
        }
      }
      else
      {
        this->FromOwner[this->Numbering.SharedOwner[i]].push_back(v);
      }
    }
  }

  /// The vertices each rank asked this one to send every iteration.
  void ListProvided(const std::vector<std::vector<vtkIdType>>& asked)
  {
    for (int s = 0; s < this->AllRanks.Size; ++s)
    {
      for (vtkIdType g : asked[s])
      {
        this->Provide[s].push_back(this->VertexOfGid(g));
      }
    }
  }

  /// Sends each rank r the triples of `state` at the vertices send[r], and stores the triples
  /// rank r sends at the vertices receive[r] (both sides list a pair's vertices in one order).
  template <typename S>
  void Share(const std::vector<std::vector<vtkIdType>>& send,
    const std::vector<std::vector<vtkIdType>>& receive, S* state, int tag)
  {
    std::vector<std::vector<double>> out(this->AllRanks.Size);
    for (int r = 0; r < this->AllRanks.Size; ++r)
    {
      for (vtkIdType v : send[r])
      {
        out[r].insert(out[r].end(), state + 3 * v, state + 3 * v + 3);
      }
    }
    const auto in = this->AllRanks.Exchange(out, this->Partners, tag);
    for (int r = 0; r < this->AllRanks.Size; ++r)
    {
      const std::vector<vtkIdType>& list = receive[r];
      for (std::size_t i = 0; i < list.size() && 3 * i + 2 < in[r].size(); ++i)
      {
        for (int k = 0; k < 3; ++k)
        {
          state[3 * list[i] + k] = static_cast<S>(in[r][3 * i + k]);
        }
      }
    }
  }

  /// Fills the remote slots of `state` with the neighbours' states from their holders.
  template <typename S>
  void Fetch(S* state)
  {
    this->Share(this->Provide, this->RemoteOrder, state, StateTag);
  }

  /// Sends the owned shared vertices' `state` to their other holders.
  template <typename S>
  void Update(S* state, int tag = UpdateTag)
  {
    this->Share(this->ToSharer, this->FromOwner, state, tag);
  }

  std::vector<vtkIdType> RemoteGids; // neighbours of owned vertices held elsewhere, by slot
  std::vector<int> RemoteProviders;
  std::vector<double> RemoteInitial;
  // Per rank: holder -> owned shared vertices; owner -> vertices it updates here; requester ->
  // vertices to send; provider -> slots, in request order; provider -> gids asked of it.
  std::vector<std::vector<vtkIdType>> ToSharer = this->PerRank();
  std::vector<std::vector<vtkIdType>> FromOwner = this->PerRank();
  std::vector<std::vector<vtkIdType>> Provide = this->PerRank();
  std::vector<std::vector<vtkIdType>> RemoteOrder = this->PerRank();
  std::vector<std::vector<vtkIdType>> RequestLists = this->PerRank();
};

} // namespace seam
} // namespace rgmc

#endif // rgmcSeamExchange_h

// Collective helpers shared by the plugin's distributed filters (private to the module): agreeing
// on a status so that an error on one rank becomes an error on every rank, and a deadlock-free
// pairwise exchange. All communication goes through vtkMultiProcessController.
#ifndef vtkRGCollective_h
#define vtkRGCollective_h

#include "vtkCommunicator.h"
#include "vtkMultiProcessController.h"
#include "vtkType.h"

#include <string>
#include <vector>

namespace rgmc
{

/// Thin helpers over the controller; every rank must make the same calls in the same order.
class Ranks
{
public:
  explicit Ranks(vtkMultiProcessController* controller);

  /// True when `ok` holds on every rank. Otherwise every rank gets, in `message`, the message of
  /// the lowest failing rank.
  bool Agree(bool ok, std::string& message);

  /// Whether `flag` holds on some rank.
  bool Any(bool flag);

  /// Gives every rank the `text` of rank `root`.
  void Broadcast(std::string& text, int root);

  /// Sends outgoing[r] to every rank r marked in `partners` (a symmetric relation) and returns
  /// what each sent back. Rounds follow a round-robin tournament, so every round is a perfect
  /// matching and blocking sends cannot deadlock; their number depends on the rank count only.
  std::vector<std::vector<vtkIdType>> Exchange(const std::vector<std::vector<vtkIdType>>& outgoing,
    const std::vector<bool>& partners, int tag);

  /// Exchange for doubles.
  std::vector<std::vector<double>> Exchange(
    const std::vector<std::vector<double>>& outgoing, const std::vector<bool>& partners, int tag);

  vtkMultiProcessController* C;
  const int Rank;
  const int Size;

private:
  template <typename T>
  std::vector<std::vector<T>> ExchangeAny(
    const std::vector<std::vector<T>>& outgoing, const std::vector<bool>& partners, int tag);
};

} // namespace rgmc

#endif

// Collective helpers shared by the plugin's distributed filters (private to the module): agreeing
// on a status so that an error on one rank becomes an error on every rank, and a deadlock-free
// pairwise exchange. All communication goes through vtkMultiProcessController.
#ifndef vtkRGCollective_h
#define vtkRGCollective_h

#include "vtkRGOutOfMemory.h"

#include "vtkCommunicator.h"
#include "vtkMultiProcessController.h"
#include "vtkType.h"

#include <algorithm>
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

namespace rgmc
{

/// Thin helpers over the controller; every rank must make the same calls in the same order.
class Ranks
{
public:
  explicit Ranks(vtkMultiProcessController* controller);

  /// True when `ok` holds on every rank and no communication of this rank has failed since the
  /// last agreement. Otherwise every rank gets, in `message`, the message of the lowest failing
  /// rank.
  bool Agree(bool ok, std::string& message);

  /// Agree, and in the same reduction: each of `anyOf` becomes true when it is true on some
  /// rank, and each of `minimums` becomes its smallest value over the ranks (one collective call
  /// where a status, flags and small reductions would otherwise take several). The values are
  /// reduced even when the status fails.
  bool Agree(bool ok, std::string& message, std::initializer_list<bool*> anyOf,
    std::initializer_list<int*> minimums = {});

  /// Agree, and in the same collective call give every rank the `mine` of every rank (each
  /// rank passes the same number of values): `all` holds them rank after rank. The values are
  /// gathered even when the status fails.
  template <typename T>
  bool AgreeGather(bool ok, std::string& message, const std::vector<T>& mine, std::vector<T>& all)
  {
    std::vector<T> sent(1 + mine.size()), gathered(sent.size() * this->Size);
    if (ok && !this->Failure.empty())
    {
      ok = false;
      message = this->Failure;
    }
    this->Failure.clear();
    sent[0] = static_cast<T>(ok ? this->Size : this->Rank);
    std::copy(mine.begin(), mine.end(), sent.begin() + 1);
    ++this->Collectives;
    if (this->MultiProcess->AllGather(
          sent.data(), gathered.data(), static_cast<vtkIdType>(sent.size())) != 1)
    {
      message = "communication between the ranks failed (agreeing on a status)";
      return false;
    }
    int first = this->Size;
    all.resize(mine.size() * this->Size);
    for (int r = 0; r < this->Size; ++r)
    {
      const T* from = gathered.data() + r * sent.size();
      first = std::min(first, static_cast<int>(from[0]));
      std::copy(from + 1, from + sent.size(), all.begin() + r * mine.size());
    }
    return first == this->Size || this->ShareMessage(first, message);
  }

  /// Runs `work` (local work, no communication) unless `problem` is already set; an allocation
  /// failure becomes the problem "not enough memory to <what>" (TryLocally). Then agrees, as
  /// Agree does.
  template <typename Work>
  bool Step(const char* what, std::string& problem, Work&& work)
  {
    TryLocally(problem, what, std::forward<Work>(work));
    return this->Agree(problem.empty(), problem);
  }

  /// Records the status of a call to the controller (1 is success): a failure is reported at the
  /// next Agree, on every rank. Returns whether the call succeeded.
  bool Check(int status, const char* what);

  /// Whether `flag` holds on some rank.
  bool Any(bool flag);

  /// Gives every rank the `words` of rank `root` (a message, see vtkRGMessage.h).
  void Broadcast(std::vector<vtkIdType>& words, int root);

  /// Sends outgoing[r] to every rank r marked in `partners` (a symmetric relation) and returns
  /// what each sent back. Rounds follow a round-robin tournament, so every round is a perfect
  /// matching and blocking sends cannot deadlock; their number depends on the rank count only.
  /// Messages go in chunks of at most MaxChunk values (MPI counts are 32-bit). A message that
  /// cannot be received (no memory for it) is drained and dropped, and the failure is reported at
  /// the next Agree: the ranks never fall out of step.
  std::vector<std::vector<vtkIdType>> Exchange(const std::vector<std::vector<vtkIdType>>& outgoing,
    const std::vector<bool>& partners, int tag);

  /// Exchange that consumes `outgoing`: each message is freed once sent, and what a rank sends
  /// to itself is moved, not copied, so the messages are not held twice.
  std::vector<std::vector<vtkIdType>> Exchange(
    std::vector<std::vector<vtkIdType>>&& outgoing, const std::vector<bool>& partners, int tag);

  /// Exchange for doubles, and for floats (half the bytes for values that are floats anyway);
  /// copying or consuming `outgoing`.
  std::vector<std::vector<double>> Exchange(
    const std::vector<std::vector<double>>& outgoing, const std::vector<bool>& partners, int tag);
  std::vector<std::vector<double>> Exchange(
    std::vector<std::vector<double>>&& outgoing, const std::vector<bool>& partners, int tag);
  std::vector<std::vector<float>> Exchange(
    std::vector<std::vector<float>>&& outgoing, const std::vector<bool>& partners, int tag);

  /// Exchange with the ranks of `order` only, one after the other in that order, which the
  /// ranks must have agreed to be deadlock-free (rgmc::Ownership::MeetingOrder): messages go to
  /// neighbours only, and the number of steps does not depend on the number of ranks.
  std::vector<std::vector<vtkIdType>> ExchangeInOrder(
    const std::vector<std::vector<vtkIdType>>& outgoing, const std::vector<int>& order, int tag);

  /// The controller's collectives, with the status checked (see Check) and counted.
  template <typename T>
  void AllReduce(const T* mine, T* reduced, vtkIdType n, int op, const char* what)
  {
    ++this->Collectives;
    this->Check(this->MultiProcess->AllReduce(mine, reduced, n, op), what);
  }
  template <typename T>
  void AllGather(const T* mine, T* all, vtkIdType n, const char* what)
  {
    ++this->Collectives;
    this->Check(this->MultiProcess->AllGather(mine, all, n), what);
  }
  template <typename T>
  void BroadcastValues(T* values, vtkIdType n, int root, const char* what)
  {
    ++this->Collectives;
    this->Check(this->MultiProcess->Broadcast(values, n, root), what);
  }
  template <typename T>
  void AllGatherV(
    const T* mine, T* all, vtkIdType n, vtkIdType* lengths, vtkIdType* offsets, const char* what)
  {
    ++this->Collectives;
    this->Check(this->MultiProcess->AllGatherV(mine, all, n, lengths, offsets), what);
  }
  template <typename T>
  void GatherV(const T* mine, T* all, vtkIdType n, vtkIdType* lengths, vtkIdType* offsets, int root,
    const char* what)
  {
    ++this->Collectives;
    this->Check(this->MultiProcess->GatherV(mine, all, n, lengths, offsets, root), what);
  }
  template <typename T>
  void ScatterV(const T* all, T* mine, vtkIdType* lengths, vtkIdType* offsets, vtkIdType n,
    int root, const char* what)
  {
    ++this->Collectives;
    this->Check(this->MultiProcess->ScatterV(all, mine, lengths, offsets, n, root), what);
  }

  /// The controller, to hand to a VTK filter that runs on the same ranks (never to call
  /// directly: every collective goes through the counted, checked calls above).
  vtkMultiProcessController* Controller() const { return this->MultiProcess; }

  const int Rank;
  const int Size;

  /// What this rank has done since it was made: collective calls, and point-to-point messages
  /// it sent (a message's size counts as one) with the values they carried.
  std::int64_t Collectives = 0;
  std::int64_t Messages = 0;
  std::int64_t ValuesSent = 0;

  static constexpr vtkIdType MaxChunk = vtkIdType(1) << 20;

private:
  vtkMultiProcessController* MultiProcess;
  std::string Failure;                    // the first failed communication since the last agreement
  std::unique_ptr<std::uint64_t[]> Drain; // MaxChunk values, for messages without memory

  /// Gives every rank the message of rank `first` (a failed agreement); returns false.
  bool ShareMessage(int first, std::string& message);

  /// The partners of `partners` in the order of a round-robin tournament over all ranks.
  std::vector<int> TournamentOrder(const std::vector<bool>& partners) const;

  /// With `consumed` (the same list as `outgoing`, given as modifiable), frees each message once
  /// sent and moves the rank's own: the list is left with empty messages.
  template <typename T>
  std::vector<std::vector<T>> ExchangeAny(const std::vector<std::vector<T>>& outgoing,
    const std::vector<int>& order, int tag, std::vector<std::vector<T>>* consumed = nullptr);
};

} // namespace rgmc

#endif

// Collective helpers shared by the plugin's distributed filters.
#include "vtkRGCollective.h"

#include <algorithm>
#include <string>

namespace rgmc
{

Ranks::Ranks(vtkMultiProcessController* controller)
  : Rank(controller->GetLocalProcessId())
  , Size(controller->GetNumberOfProcesses())
  , MultiProcess(controller)
{
  // Room to drain a message that finds no memory, reserved now: not touched (so it costs no
  // memory) unless it is needed, when allocating it could fail too.
  try
  {
    this->Drain.reset(new std::uint64_t[static_cast<std::size_t>(MaxChunk)]);
  }
  catch (const std::bad_alloc&)
  {
    this->Failure = "not enough memory to receive messages from the other ranks";
  }
}

bool Ranks::Check(int status, const char* what)
{
  if (status != 1 && this->Failure.empty())
  {
    this->Failure = std::string("communication between the ranks failed (") + what + ")";
  }
  return status == 1;
}

bool Ranks::Agree(bool ok, std::string& message)
{
  return this->Agree(ok, message, {}, {});
}

bool Ranks::Agree(bool ok, std::string& message, std::initializer_list<bool*> anyOf,
  std::initializer_list<int*> minimums)
{
  if (ok && !this->Failure.empty())
  {
    ok = false;
    message = this->Failure;
  }
  this->Failure.clear();
  // One MIN reduction: the first failing rank, 0 for a flag set somewhere, the minimums.
  std::vector<int> mine, reduced(1 + anyOf.size() + minimums.size());
  mine.push_back(ok ? this->Size : this->Rank);
  for (const bool* flag : anyOf)
  {
    mine.push_back(*flag ? 0 : 1);
  }
  for (const int* value : minimums)
  {
    mine.push_back(*value);
  }
  ++this->Collectives;
  if (this->MultiProcess->AllReduce(mine.data(), reduced.data(),
        static_cast<vtkIdType>(mine.size()), vtkCommunicator::MIN_OP) != 1)
  {
    // The agreement itself failed: nothing more can be trusted of the other ranks.
    message = "communication between the ranks failed (agreeing on a status)";
    return false;
  }
  std::size_t n = 1;
  for (bool* flag : anyOf)
  {
    *flag = reduced[n++] == 0;
  }
  for (int* value : minimums)
  {
    *value = reduced[n++];
  }
  const int first = reduced[0];
  return first == this->Size || this->ShareMessage(first, message);
}

bool Ranks::ShareMessage(int first, std::string& message)
{
  vtkIdType length = this->Rank == first ? static_cast<vtkIdType>(message.size()) : 0;
  ++this->Collectives;
  this->MultiProcess->Broadcast(&length, 1, first);
  this->Collectives += length > 0 ? 1 : 0;
  std::vector<char> text(static_cast<std::size_t>(length) + 1, '\0');
  if (this->Rank == first)
  {
    std::copy(message.begin(), message.end(), text.begin());
  }
  if (length > 0)
  {
    this->MultiProcess->Broadcast(text.data(), length, first);
  }
  message.assign(text.data(), static_cast<std::size_t>(length));
  return false;
}

bool Ranks::Any(bool flag)
{
  int mine = flag ? 1 : 0, any = 0;
  this->AllReduce(&mine, &any, 1, vtkCommunicator::MAX_OP, "a reduction");
  return any != 0;
}

void Ranks::Broadcast(std::vector<vtkIdType>& words, int root)
{
  vtkIdType length = static_cast<vtkIdType>(words.size());
  this->BroadcastValues(&length, 1, root, "a broadcast");
  if (this->Rank != root)
  {
    words.assign(static_cast<std::size_t>(length), 0);
  }
  if (length > 0)
  {
    this->BroadcastValues(words.data(), length, root, "a broadcast");
  }
}

std::vector<int> Ranks::TournamentOrder(const std::vector<bool>& partners) const
{
  std::vector<int> order;
  const int n = this->Size + (this->Size % 2);
  const int m = n - 1;
  const int me = this->Rank;
  for (int round = 0; round < m; ++round)
  {
    int partner;
    if (me == n - 1)
    {
      partner = round;
    }
    else if (me == round)
    {
      partner = n - 1;
    }
    else
    {
      partner = ((2 * round - me) % m + m) % m;
    }
    if (partner < this->Size && partner != me && partners[partner])
    {
      order.push_back(partner);
    }
  }
  return order;
}

template <typename T>
std::vector<std::vector<T>> Ranks::ExchangeAny(const std::vector<std::vector<T>>& outgoing,
  const std::vector<int>& order, int tag, std::vector<std::vector<T>>* consumed)
{
  std::vector<std::vector<T>> incoming(this->Size);
  const int me = this->Rank;
  for (const int partner : order)
  {
    auto send = [&]()
    {
      const vtkIdType count = static_cast<vtkIdType>(outgoing[partner].size());
      this->Check(this->MultiProcess->Send(&count, 1, partner, tag), "sending a message's size");
      ++this->Messages;
      this->ValuesSent += count;
      for (vtkIdType at = 0; at < count; at += MaxChunk)
      {
        ++this->Messages;
        this->Check(this->MultiProcess->Send(outgoing[partner].data() + at,
                      std::min(MaxChunk, count - at), partner, tag + 1),
          "sending a message");
      }
    };
    auto receive = [&]()
    {
      vtkIdType count = 0;
      this->Check(
        this->MultiProcess->Receive(&count, 1, partner, tag), "receiving a message's size");
      std::vector<T>& in = incoming[partner];
      T* target = nullptr;
      try
      {
        in.resize(static_cast<std::size_t>(count));
        target = in.data();
      }
      catch (const std::bad_alloc&)
      {
        if (this->Failure.empty())
        {
          this->Failure = "not enough memory to receive a message of " + std::to_string(count) +
            " values from rank " + std::to_string(partner);
        }
      }
      for (vtkIdType at = 0; at < count; at += MaxChunk)
      {
        const vtkIdType length = std::min(MaxChunk, count - at);
        static_assert(sizeof(T) <= sizeof(std::uint64_t), "the drain holds MaxChunk values");
        T* drain = reinterpret_cast<T*>(this->Drain.get());
        if (!target && !drain)
        {
          break; // the agreement that follows fails anyway (Failure is set)
        }
        this->Check(
          this->MultiProcess->Receive(target ? target + at : drain, length, partner, tag + 1),
          "receiving a message");
      }
    };
    if (me < partner)
    {
      send();
      receive();
    }
    else
    {
      receive();
      send();
    }
    if (consumed)
    {
      std::vector<T>().swap((*consumed)[partner]);
    }
  }
  // What a rank "sends" to itself stays here.
  if (consumed)
  {
    incoming[me].swap((*consumed)[me]);
  }
  else
  {
    incoming[me] = outgoing[me];
  }
  return incoming;
}

std::vector<std::vector<vtkIdType>> Ranks::Exchange(
  const std::vector<std::vector<vtkIdType>>& outgoing, const std::vector<bool>& partners, int tag)
{
  return this->ExchangeAny(outgoing, this->TournamentOrder(partners), tag);
}

std::vector<std::vector<vtkIdType>> Ranks::Exchange(
  std::vector<std::vector<vtkIdType>>&& outgoing, const std::vector<bool>& partners, int tag)
{
  return this->ExchangeAny(outgoing, this->TournamentOrder(partners), tag, &outgoing);
}

std::vector<std::vector<double>> Ranks::Exchange(
  const std::vector<std::vector<double>>& outgoing, const std::vector<bool>& partners, int tag)
{
  return this->ExchangeAny(outgoing, this->TournamentOrder(partners), tag);
}

std::vector<std::vector<double>> Ranks::Exchange(
  std::vector<std::vector<double>>&& outgoing, const std::vector<bool>& partners, int tag)
{
  return this->ExchangeAny(outgoing, this->TournamentOrder(partners), tag, &outgoing);
}

std::vector<std::vector<float>> Ranks::Exchange(
  std::vector<std::vector<float>>&& outgoing, const std::vector<bool>& partners, int tag)
{
  return this->ExchangeAny(outgoing, this->TournamentOrder(partners), tag, &outgoing);
}

std::vector<std::vector<vtkIdType>> Ranks::ExchangeInOrder(
  const std::vector<std::vector<vtkIdType>>& outgoing, const std::vector<int>& order, int tag)
{
  return this->ExchangeAny(outgoing, order, tag);
}

} // namespace rgmc

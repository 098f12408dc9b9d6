// Collective helpers shared by the plugin's distributed filters.
#include "vtkRGCollective.h"

#include <algorithm>

namespace rgmc
{

Ranks::Ranks(vtkMultiProcessController* controller)
  : C(controller)
  , Rank(controller->GetLocalProcessId())
  , Size(controller->GetNumberOfProcesses())
{
}

bool Ranks::Agree(bool ok, std::string& message)
{
  int mine = ok ? this->Size : this->Rank, first = this->Size;
  this->C->AllReduce(&mine, &first, 1, vtkCommunicator::MIN_OP);
  if (first == this->Size)
  {
    return true;
  }
  vtkIdType length = this->Rank == first ? static_cast<vtkIdType>(message.size()) : 0;
  this->C->Broadcast(&length, 1, first);
  std::vector<char> text(static_cast<std::size_t>(length) + 1, '\0');
  if (this->Rank == first)
  {
    std::copy(message.begin(), message.end(), text.begin());
  }
  if (length > 0)
  {
    this->C->Broadcast(text.data(), length, first);
  }
  message.assign(text.data(), static_cast<std::size_t>(length));
  return false;
}

bool Ranks::Any(bool flag)
{
  int mine = flag ? 1 : 0, any = 0;
  this->C->AllReduce(&mine, &any, 1, vtkCommunicator::MAX_OP);
  return any != 0;
}

void Ranks::Broadcast(std::string& text, int root)
{
  vtkIdType length = static_cast<vtkIdType>(text.size());
  this->C->Broadcast(&length, 1, root);
  if (this->Rank != root)
  {
    text.assign(static_cast<std::size_t>(length), '\0');
  }
  if (length > 0)
  {
    this->C->Broadcast(&text[0], length, root);
  }
}

template <typename T>
std::vector<std::vector<T>> Ranks::ExchangeAny(
  const std::vector<std::vector<T>>& outgoing, const std::vector<bool>& partners, int tag)
{
  std::vector<std::vector<T>> incoming(this->Size);
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
    if (partner >= this->Size || partner == me || !partners[partner])
    {
      continue;
    }
    auto send = [&]()
    {
      vtkIdType count = static_cast<vtkIdType>(outgoing[partner].size());
      this->C->Send(&count, 1, partner, tag);
      if (count > 0)
      {
        this->C->Send(outgoing[partner].data(), count, partner, tag + 1);
      }
    };
    auto receive = [&]()
    {
      vtkIdType count = 0;
      this->C->Receive(&count, 1, partner, tag);
      incoming[partner].resize(static_cast<std::size_t>(count));
      if (count > 0)
      {
        this->C->Receive(incoming[partner].data(), count, partner, tag + 1);
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
  }
  // What a rank "sends" to itself stays here.
  incoming[me] = outgoing[me];
  return incoming;
}

std::vector<std::vector<vtkIdType>> Ranks::Exchange(
  const std::vector<std::vector<vtkIdType>>& outgoing, const std::vector<bool>& partners, int tag)
{
  return this->ExchangeAny(outgoing, partners, tag);
}

std::vector<std::vector<double>> Ranks::Exchange(
  const std::vector<std::vector<double>>& outgoing, const std::vector<bool>& partners, int tag)
{
  return this->ExchangeAny(outgoing, partners, tag);
}

} // namespace rgmc

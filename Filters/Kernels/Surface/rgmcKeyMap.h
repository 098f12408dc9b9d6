// A flat open-addressing hash map from non-negative 64-bit keys to 32-bit values: the vertex
// table of the growth (vertex key -> output point), sized by the output, never by the volume.
#ifndef rgmcKeyMap_h
#define rgmcKeyMap_h

#include <cstdint>
#include <vector>

namespace rgmc
{

class KeyMap
{
public:
  explicit KeyMap(std::size_t expected = 1024) { this->Rehash(Capacity(expected)); }

  std::size_t Size() const { return this->Count; }

  /// The value stored for `key`, inserted as `fresh` when the key is new; `inserted` says which.
  std::int32_t& FindOrInsert(std::int64_t key, std::int32_t fresh, bool& inserted)
  {
    if (2 * (this->Count + 1) > this->Slots.size())
    {
      this->Rehash(2 * this->Slots.size());
    }
    std::size_t i = this->Home(key);
    while (this->Slots[i].Key >= 0)
    {
      if (this->Slots[i].Key == key)
      {
        inserted = false;
        return this->Slots[i].Value;
      }
      i = (i + 1) & this->Mask;
    }
    this->Slots[i].Key = key;
    this->Slots[i].Value = fresh;
    ++this->Count;
    inserted = true;
    return this->Slots[i].Value;
  }

  /// The value stored for `key`, or nullptr.
  const std::int32_t* Find(std::int64_t key) const
  {
    std::size_t i = this->Home(key);
    while (this->Slots[i].Key >= 0)
    {
      if (this->Slots[i].Key == key)
      {
        return &this->Slots[i].Value;
      }
      i = (i + 1) & this->Mask;
    }
    return nullptr;
  }

private:
  struct Slot
  {
    std::int64_t Key = -1;
    std::int32_t Value = 0;
  };

  static std::size_t Capacity(std::size_t expected)
  {
    std::size_t c = 16;
    while (c < 2 * expected)
    {
      c *= 2;
    }
    return c;
  }

  std::size_t Home(std::int64_t key) const
  {
    // Fibonacci hashing: keys of neighbouring edges differ in their low bits.
    return static_cast<std::size_t>(
      (static_cast<std::uint64_t>(key) * 0x9E3779B97F4A7C15ull) >> this->Shift);
  }

  void Rehash(std::size_t capacity)
  {
    std::vector<Slot> old;
    old.swap(this->Slots);
    this->Slots.assign(capacity, Slot());
    this->Mask = capacity - 1;
    this->Shift = 64;
    for (std::size_t c = capacity; c > 1; c >>= 1)
    {
      --this->Shift;
    }
    this->Count = 0;
    for (const Slot& s : old)
    {
      if (s.Key >= 0)
      {
        bool inserted;
        this->FindOrInsert(s.Key, s.Value, inserted);
      }
    }
  }

  std::vector<Slot> Slots;
  std::size_t Mask = 0;
  int Shift = 64;
  std::size_t Count = 0;
};

} // namespace rgmc

#endif

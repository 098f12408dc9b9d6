// An index from n distinct non-negative 64-bit keys to their places 0..n-1, built on tasks at
// once: open addressing with linear probing over a fixed table (twice n or more slots), each
// key claiming the first free slot from its home by a compare-and-swap. Where a key lands
// depends on the threads; what Find returns never does, since every key is in the table once,
// on the probe path from its home. (rgmc::KeyMap, the growth's vertex table, grows one insertion
// at a time; this one is for a set known whole, such as the distance report's buckets.)
#ifndef rgmcKeyIndex_h
#define rgmcKeyIndex_h

#include "rgmcTasks.h"

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>

namespace rgmc
{

class KeyIndex
{
public:
  KeyIndex() = default;

  /// The index of keyAt(i), 0 <= i < n (distinct, non-negative), filled on `parallel`'s tasks.
  template <typename KeyAt, typename Parallel = SerialTasks>
  KeyIndex(std::size_t n, KeyAt&& keyAt, Parallel&& parallel = Parallel())
  {
    std::size_t capacity = 16;
    this->Shift = 60;
    while (capacity < 2 * n)
    {
      capacity *= 2;
      --this->Shift;
    }
    this->Mask = capacity - 1;
    this->Slots.reset(new Slot[capacity]); // unset: first written by the tasks below
    const std::int64_t ranges = static_cast<std::int64_t>((capacity + Range - 1) / Range);
    parallel(ranges,
      [this, capacity](std::int64_t r)
      {
        const std::size_t end = std::min(capacity, static_cast<std::size_t>(r + 1) * Range);
        for (std::size_t i = static_cast<std::size_t>(r) * Range; i < end; ++i)
        {
          this->Slots[i].Key.store(-1, std::memory_order_relaxed);
        }
      });
    parallel(static_cast<std::int64_t>((n + Range - 1) / Range),
      [&](std::int64_t r)
      {
        const std::size_t end = std::min(n, static_cast<std::size_t>(r + 1) * Range);
        for (std::size_t k = static_cast<std::size_t>(r) * Range; k < end; ++k)
        {
          const std::int64_t key = static_cast<std::int64_t>(keyAt(k));
          for (std::size_t i = this->Home(key);; i = (i + 1) & this->Mask)
          {
            std::int64_t empty = -1;
            if (this->Slots[i].Key.compare_exchange_strong(
                  empty, key, std::memory_order_relaxed, std::memory_order_relaxed))
            {
              this->Slots[i].Value = static_cast<std::int64_t>(k);
              break;
            }
          }
        }
      });
  }

  /// The place of `key`, or -1 when it is not in the index. Only once the index is built (the
  /// tasks' end orders their writes before any Find).
  std::int64_t Find(std::int64_t key) const
  {
    if (!this->Slots)
    {
      return -1;
    }
    for (std::size_t i = this->Home(key);; i = (i + 1) & this->Mask)
    {
      const std::int64_t here = this->Slots[i].Key.load(std::memory_order_relaxed);
      if (here == key)
      {
        return this->Slots[i].Value;
      }
      if (here < 0)
      {
        return -1;
      }
    }
  }

private:
  /// Slots a task fills or keys a task inserts (any number would do: Find does not depend on it).
  static constexpr std::size_t Range = 65536;

  struct Slot
  {
    std::atomic<std::int64_t> Key;
    std::int64_t Value;
  };

  std::size_t Home(std::int64_t key) const
  {
    // Fibonacci hashing, as rgmc::KeyMap: neighbouring keys land far apart.
    return static_cast<std::size_t>(
      (static_cast<std::uint64_t>(key) * 0x9E3779B97F4A7C15ull) >> this->Shift);
  }

  std::unique_ptr<Slot[]> Slots;
  std::size_t Mask = 0;
  int Shift = 60;
};

} // namespace rgmc

#endif

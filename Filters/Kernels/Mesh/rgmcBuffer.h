// A growable array of trivially copyable values in malloc'ed memory that can hand its storage
// over (Release), so that the VTK layer adopts the mesh without copying it.
#ifndef rgmcBuffer_h
#define rgmcBuffer_h

#include "rgmcInline.h"

#include <algorithm>
#include <cstdlib>
#if defined(__unix__) || defined(__APPLE__)
#include <sys/mman.h>
#define RGMC_HAVE_MMAP 1
#endif
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace rgmc
{

/// A huge page (Linux's transparent huge pages on x86-64 and arm64).
constexpr std::size_t HugePage = std::size_t(1) << 21;

/// Asks the operating system to back the 2 MiB-aligned part of [data, data + bytes) with huge
/// pages where it can (Linux's transparent huge pages, which Debian's kernels give on request):
/// a large array is then paged in 2 MiB at a time, one page fault where there would be 512.
/// Only a hint; nothing else changes. Below 4 MiB it does nothing.
inline void AdviseHugePages(void* data, std::size_t bytes)
{
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  constexpr std::uintptr_t huge = HugePage;
  if (!data || bytes < 2 * huge)
  {
    return;
  }
  const std::uintptr_t at = reinterpret_cast<std::uintptr_t>(data);
  const std::uintptr_t begin = (at + huge - 1) & ~(huge - 1);
  const std::uintptr_t end = (at + bytes) & ~(huge - 1);
  if (end > begin)
  {
    madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
  }
#else
  (void)data;
  (void)bytes;
#endif
}

/// Gives the whole 4 KiB pages inside [data, data + bytes) back to the operating system now (on
/// Linux; elsewhere nothing): their contents are lost, and a later touch finds zeros. For
/// memory about to be freed: the C library keeps a freed block from its heap resident until the
/// blocks above it are freed too, so a step that frees many blocks one by one while it fills a
/// large array (extraction's join of its chunks) would hold both at once.
inline void DiscardPages(void* data, std::size_t bytes)
{
#if defined(__linux__) && defined(MADV_DONTNEED)
  constexpr std::uintptr_t page = 4096;
  const std::uintptr_t at = reinterpret_cast<std::uintptr_t>(data);
  const std::uintptr_t begin = (at + page - 1) & ~(page - 1);
  const std::uintptr_t end = (at + bytes) & ~(page - 1);
  if (data && end > begin)
  {
    madvise(reinterpret_cast<void*>(begin), end - begin, MADV_DONTNEED);
  }
#else
  (void)data;
  (void)bytes;
#endif
}

/// Whether an array of `bytes` goes in whole huge pages (AllocateHugePages): 4 MiB or more.
inline bool WantsHugePages(std::size_t bytes)
{
  return bytes >= 2 * HugePage;
}

/// Storage for an array of `bytes` that is written whole soon after (WantsHugePages), in whole
/// huge pages: 2 MiB-aligned, rounded up to 2 MiB, huge pages asked for. AdviseHugePages alone
/// leaves up to 2 MiB at each end of an array in 4 KiB pages; under a hypervisor a page fault
/// costs microseconds, and a 2 M-triangle surface's arrays are 20 000 pages of 4 KiB. The cost:
/// up to 2 MiB resident beyond the array (the rest of its last huge page), so not for a
/// reserved upper bound. Sets `rounded` to the bytes given; released with std::free.
inline void* AllocateHugePages(std::size_t bytes, std::size_t& rounded)
{
  if (bytes > static_cast<std::size_t>(PTRDIFF_MAX) - HugePage)
  {
    throw std::bad_alloc();
  }
  rounded = (bytes + HugePage - 1) & ~(HugePage - 1);
  void* data = std::aligned_alloc(HugePage, rounded);
  if (!data)
  {
    throw std::bad_alloc();
  }
  AdviseHugePages(data, rounded);
  return data;
}

/// std::allocator for large arrays (Seam Repair's per-vertex and per-triangle arrays): those of
/// 4 MiB or more in whole huge pages (AllocateHugePages), which fault in far fewer times than
/// 4 KiB pages for a few MiB more at the peak (docs/evaluation.md, Memory).
template <typename T>
struct LargeArrayAllocator
{
  using value_type = T;
  LargeArrayAllocator() = default;
  template <typename U>
  LargeArrayAllocator(const LargeArrayAllocator<U>&) noexcept
  {
  }
  T* allocate(std::size_t n)
  {
    if (n > std::size_t(PTRDIFF_MAX) / sizeof(T) || !WantsHugePages(n * sizeof(T)))
    {
      return std::allocator<T>().allocate(n); // throws on a length too large
    }
    std::size_t rounded;
    return static_cast<T*>(AllocateHugePages(n * sizeof(T), rounded));
  }
  void deallocate(T* data, std::size_t n) noexcept
  {
    if (!WantsHugePages(n * sizeof(T)))
    {
      std::allocator<T>().deallocate(data, n);
      return;
    }
    std::free(data);
  }
  template <typename U>
  bool operator==(const LargeArrayAllocator<U>&) const noexcept
  {
    return true;
  }
  template <typename U>
  bool operator!=(const LargeArrayAllocator<U>&) const noexcept
  {
    return false;
  }
};

/// A std::vector that may be large (LargeArrayAllocator).
template <typename T>
using LargeVector = std::vector<T, LargeArrayAllocator<T>>;

/// std::allocator for large arrays a filter allocates again on every run (Seam Repair's): from
/// the C library's heap, whose freed blocks a re-run gets back already faulted in (the slider
/// re-runs the filters); LargeArrayAllocator's arrays are unmapped when freed and faulted in again
/// (24 MiB in huge pages: 1.6-2.0 ms a time here, against 0.03 ms from the heap). Huge pages are
/// asked for the 2 MiB-aligned part of those of 4 MiB or more (AdviseHugePages), for their first
/// run. Arrays above the C library's mmap threshold (at most 32 MiB) are mapped apart all the same.
template <typename T>
struct HeapArrayAllocator : std::allocator<T>
{
  using value_type = T;
  template <typename U>
  struct rebind
  {
    using other = HeapArrayAllocator<U>;
  };
  HeapArrayAllocator() = default;
  template <typename U>
  HeapArrayAllocator(const HeapArrayAllocator<U>&) noexcept
  {
  }
  T* allocate(std::size_t n)
  {
    T* data = std::allocator<T>::allocate(n);
    AdviseHugePages(data, n * sizeof(T)); // below 4 MiB: nothing
    return data;
  }
};

/// An allocator (LargeArrayAllocator by default, or HeapArrayAllocator) whose vectors leave the
/// values they grow by unset (default-initialized: nothing is written for plain values), for
/// arrays sized first and then written whole, on threads: their pages are then first touched, and
/// faulted in, by the threads that fill them, not zeroed on one thread before. Aggregates
/// (std::array) stay unset; std::pair's constructor zeroes it.
template <typename T, template <typename> class Base = LargeArrayAllocator>
struct OverwriteAllocator : Base<T>
{
  using value_type = T;
  template <typename U>
  struct rebind
  {
    using other = OverwriteAllocator<U, Base>;
  };
  OverwriteAllocator() = default;
  template <typename U>
  OverwriteAllocator(const OverwriteAllocator<U, Base>&) noexcept
  {
  }
  template <typename U>
  void construct(U* at) noexcept(std::is_nothrow_default_constructible<U>::value)
  {
    ::new (static_cast<void*>(at)) U;
  }
  template <typename U, typename... Args>
  void construct(U* at, Args&&... args)
  {
    ::new (static_cast<void*>(at)) U(std::forward<Args>(args)...);
  }
};

/// A std::vector sized, then written whole (OverwriteAllocator): resize leaves the new values
/// unset.
template <typename T>
using OverwriteVector = std::vector<T, OverwriteAllocator<T>>;

/// An OverwriteVector in the C library's heap (HeapArrayAllocator), for arrays made again on
/// every run of a filter.
template <typename T>
using HeapOverwriteVector = std::vector<T, OverwriteAllocator<T, HeapArrayAllocator>>;

/// True for a vector whose allocator leaves new values unset (OverwriteVector,
/// HeapOverwriteVector): one that `vector(n)` hands over untouched, for its first writer to fault
/// in.
template <typename Vector>
struct LeavesValuesUnset : std::false_type
{
};
template <typename T, template <typename> class Base>
struct LeavesValuesUnset<std::vector<T, OverwriteAllocator<T, Base>>> : std::true_type
{
};

template <typename T>
class Buffer
{
  static_assert(std::is_trivially_copyable<T>::value, "Buffer holds plain values");

public:
  Buffer() = default;
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;
  Buffer(Buffer&& other) noexcept
    : Data(other.Data)
    , Size(other.Size)
    , Capacity(other.Capacity)
    , Borrowed(other.Borrowed)
  {
    other.Data = nullptr;
    other.Size = other.Capacity = 0;
    other.Borrowed = false;
  }
  Buffer& operator=(Buffer&& other) noexcept
  {
    if (this != &other)
    {
      this->FreeOwn();
      this->Data = other.Data;
      this->Size = other.Size;
      this->Capacity = other.Capacity;
      this->Borrowed = other.Borrowed;
      other.Data = nullptr;
      other.Size = other.Capacity = 0;
      other.Borrowed = false;
    }
    return *this;
  }
  ~Buffer() { this->FreeOwn(); }

  /// Empties the buffer and gives it `capacity` values at `data` as its storage, owned by the
  /// caller (a slice of a larger array), which must outlive its use here: many buffers filled
  /// at once then share one array's huge pages instead of each paging in its own 4 KiB pages.
  /// Growth beyond `capacity` moves the values to storage of the buffer's own.
  void Borrow(T* data, std::size_t capacity)
  {
    this->FreeOwn();
    this->Data = data;
    this->Size = 0;
    this->Capacity = capacity;
    this->Borrowed = true;
  }

  std::size_t size() const { return this->Size; }
  bool empty() const { return this->Size == 0; }
  T* data() { return this->Data; }
  const T* data() const { return this->Data; }
  T& operator[](std::size_t i) { return this->Data[i]; }
  const T& operator[](std::size_t i) const { return this->Data[i]; }
  T* begin() { return this->Data; }
  T* end() { return this->Data + this->Size; }
  const T* begin() const { return this->Data; }
  const T* end() const { return this->Data + this->Size; }

  /// Room for `capacity` values (an upper bound: what is not written is never paged in).
  void reserve(std::size_t capacity)
  {
    if (capacity > this->Capacity)
    {
      T* grown =
        static_cast<T*>(std::realloc(this->Borrowed ? nullptr : this->Data, capacity * sizeof(T)));
      if (!grown)
      {
        throw std::bad_alloc();
      }
      if (this->Borrowed && this->Size > 0)
      {
        std::memcpy(grown, this->Data, this->Size * sizeof(T));
      }
      this->Data = grown;
      this->Capacity = capacity;
      this->Borrowed = false;
    }
  }

  // push_back and append are in extraction's loop over triangles: always inlined (the
  // plugin's library, which holds the kernel for every sample type, called them otherwise),
  // their growth out of line.
  RGMC_INLINE void push_back(const T& value)
  {
    if (this->Size == this->Capacity)
    {
      this->Grow(this->Capacity ? 2 * this->Capacity : 64);
    }
    this->Data[this->Size++] = value;
  }

  /// Appends n values.
  RGMC_INLINE void append(const T* values, std::size_t n)
  {
    if (this->Size + n > this->Capacity)
    {
      this->Grow(std::max(this->Size + n, 2 * this->Capacity));
    }
    std::memcpy(this->Data + this->Size, values, n * sizeof(T));
    this->Size += n;
  }

  /// Holds n values, those beyond the old size left unset (to be written next, all of them):
  /// new storage of 4 MiB or more (the joined mesh's arrays) in whole huge pages
  /// (AllocateHugePages; not in reserve, whose upper bounds would keep their last one unused).
  void resize_for_overwrite(std::size_t n)
  {
    if (n <= this->Capacity || !WantsHugePages(n * sizeof(T)))
    {
      this->reserve(n);
      this->Size = n;
      return;
    }
    std::size_t rounded;
    T* grown = static_cast<T*>(AllocateHugePages(n * sizeof(T), rounded));
    if (this->Size > 0)
    {
      std::memcpy(grown, this->Data, this->Size * sizeof(T));
    }
    this->FreeOwn();
    this->Data = grown;
    this->Capacity = rounded / sizeof(T);
    this->Size = n;
  }

  /// Shrinks to the first n values (n <= size()).
  void resize_down(std::size_t n) { this->Size = n < this->Size ? n : this->Size; }

  /// Frees the storage now, its pages given back first (DiscardPages: borrowed storage too, the
  /// whole pages inside it), and empties the buffer.
  void FreeNow()
  {
    DiscardPages(this->Data, this->Capacity * sizeof(T));
    this->FreeOwn();
    this->Data = nullptr;
    this->Size = this->Capacity = 0;
  }

  /// Hands over the storage (to be released with std::free; borrowed values are copied to
  /// storage of the buffer's own first) and empties the buffer.
  T* Release()
  {
    if (this->Borrowed)
    {
      this->reserve(this->Capacity + 1);
    }
    T* data = this->Data;
    this->Data = nullptr;
    this->Size = this->Capacity = 0;
    return data;
  }

private:
  RGMC_NOINLINE void Grow(std::size_t capacity) { this->reserve(capacity); }

  void FreeOwn()
  {
    if (!this->Borrowed)
    {
      std::free(this->Data);
    }
    this->Borrowed = false;
  }

  T* Data = nullptr;
  std::size_t Size = 0;
  std::size_t Capacity = 0;
  bool Borrowed = false; // Data is the caller's (Borrow)
};

/// A fixed-size array of zeros whose pages come from the operating system as they are first
/// touched, so a large array that is used sparsely (a bit per cube of the volume) costs what is
/// touched, not its size. (calloc may instead clear reused heap memory up front.)
template <typename T>
class ZeroedArray
{
  static_assert(std::is_trivially_copyable<T>::value, "ZeroedArray holds plain values");

public:
  ZeroedArray() = default;
  ZeroedArray(const ZeroedArray&) = delete;
  ZeroedArray& operator=(const ZeroedArray&) = delete;
  ~ZeroedArray() { this->Free(); }

  /// n zeros (the previous contents are dropped).
  void Allocate(std::size_t n)
  {
    this->Free();
    this->Bytes = n * sizeof(T);
    if (n == 0)
    {
      return;
    }
#ifdef RGMC_HAVE_MMAP
    if (this->Bytes >= (std::size_t(1) << 20))
    {
      void* p =
        mmap(nullptr, this->Bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
      if (p == MAP_FAILED)
      {
        throw std::bad_alloc();
      }
      this->Data = static_cast<T*>(p);
      this->Mapped = true;
      return;
    }
#endif
    this->Data = static_cast<T*>(std::calloc(n, sizeof(T)));
    if (!this->Data)
    {
      throw std::bad_alloc();
    }
  }
  T& operator[](std::size_t i)
  {
    return this->Data[i];
  }
  const T& operator[](std::size_t i) const
  {
    return this->Data[i];
  }

private:
  void Free()
  {
#ifdef RGMC_HAVE_MMAP
    if (this->Mapped)
    {
      munmap(this->Data, this->Bytes);
      this->Data = nullptr;
      this->Mapped = false;
      return;
    }
#endif
    std::free(this->Data);
    this->Data = nullptr;
  }

  T* Data = nullptr;
  std::size_t Bytes = 0;
  bool Mapped = false;
};

} // namespace rgmc

#endif

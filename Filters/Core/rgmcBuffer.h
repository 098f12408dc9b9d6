// A growable array of trivially copyable values in malloc'ed memory that can hand its storage
// over (Release), so that the VTK layer adopts the mesh without copying it.
#ifndef rgmcBuffer_h
#define rgmcBuffer_h

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <new>
#include <type_traits>

namespace rgmc
{

template <typename T>
class Buffer
{
  static_assert(std::is_trivially_copyable<T>::value, "Buffer holds plain values");

public:
  Buffer() = default;
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;
  ~Buffer() { std::free(this->Data); }

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

  void reserve(std::size_t capacity)
  {
    if (capacity > this->Capacity)
    {
      T* grown = static_cast<T*>(std::realloc(this->Data, capacity * sizeof(T)));
      if (!grown)
      {
        throw std::bad_alloc();
      }
      this->Data = grown;
      this->Capacity = capacity;
    }
  }

  void push_back(const T& value)
  {
    if (this->Size == this->Capacity)
    {
      this->reserve(this->Capacity ? 2 * this->Capacity : 64);
    }
    this->Data[this->Size++] = value;
  }

  /// Appends n values.
  void append(const T* values, std::size_t n)
  {
    if (this->Size + n > this->Capacity)
    {
      this->reserve(std::max(this->Size + n, 2 * this->Capacity));
    }
    std::memcpy(this->Data + this->Size, values, n * sizeof(T));
    this->Size += n;
  }

  /// Shrinks to the first n values (n <= size()).
  void resize_down(std::size_t n) { this->Size = n < this->Size ? n : this->Size; }

  /// Hands over the storage (to be released with std::free) and empties the buffer.
  T* Release()
  {
    T* data = this->Data;
    this->Data = nullptr;
    this->Size = this->Capacity = 0;
    return data;
  }

private:
  T* Data = nullptr;
  std::size_t Size = 0;
  std::size_t Capacity = 0;
};

} // namespace rgmc

#endif

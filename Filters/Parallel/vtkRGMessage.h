// The one way the plugin puts mixed values into a message between ranks: a sequence of 64-bit
// words (what rgmc::Ranks exchanges, gathers and broadcasts), integers as they are, doubles bit
// for bit, strings as their length and then eight characters a word. Private to the module.
#ifndef vtkRGMessage_h
#define vtkRGMessage_h

#include "vtkType.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace rgmc
{

/// A double as a message word, bit for bit (so that it arrives exactly), and back.
inline vtkIdType WordOf(double value)
{
  vtkIdType word;
  std::memcpy(&word, &value, sizeof word);
  return word;
}

inline double RealOf(vtkIdType word)
{
  double value;
  std::memcpy(&value, &word, sizeof value);
  return value;
}

/// Appends values to a message.
class MessageWriter
{
public:
  explicit MessageWriter(std::vector<vtkIdType>& words)
    : Words(words)
  {
  }
  MessageWriter& Int(std::int64_t value)
  {
    this->Words.push_back(static_cast<vtkIdType>(value));
    return *this;
  }
  MessageWriter& Real(double value)
  {
    this->Words.push_back(WordOf(value));
    return *this;
  }
  MessageWriter& Text(const std::string& value)
  {
    this->Int(static_cast<std::int64_t>(value.size()));
    for (std::size_t at = 0; at < value.size(); at += sizeof(vtkIdType))
    {
      vtkIdType word = 0;
      std::memcpy(&word, value.data() + at, std::min(sizeof word, value.size() - at));
      this->Words.push_back(word);
    }
    return *this;
  }

private:
  std::vector<vtkIdType>& Words;
};

/// Reads what a MessageWriter wrote, in the same order; Ok() turns false at the first read past
/// the end (or of a string longer than what is left), and every value read after that is 0.
class MessageReader
{
public:
  MessageReader(const vtkIdType* words, std::size_t count)
    : Words(words)
    , Count(count)
  {
  }
  explicit MessageReader(const std::vector<vtkIdType>& words)
    : MessageReader(words.data(), words.size())
  {
  }
  std::int64_t Int()
  {
    if (!this->Good || this->At >= this->Count)
    {
      this->Good = false;
      return 0;
    }
    return static_cast<std::int64_t>(this->Words[this->At++]);
  }
  double Real()
  {
    return this->Good && this->At < this->Count ? RealOf(this->Words[this->At++]) : this->Fail();
  }
  std::string Text()
  {
    const std::int64_t length = this->Int();
    const std::size_t words = length > 0
      ? (static_cast<std::size_t>(length) + sizeof(vtkIdType) - 1) / sizeof(vtkIdType)
      : 0;
    if (!this->Good || length < 0 || words > this->Count - this->At)
    {
      this->Good = false;
      return std::string();
    }
    std::string value(static_cast<std::size_t>(length), '\0');
    std::memcpy(&value[0], this->Words + this->At, value.size());
    this->At += words;
    return value;
  }
  bool Ok() const { return this->Good; }
  /// Where the reader is: the words read so far.
  std::size_t Position() const { return this->At; }

private:
  double Fail()
  {
    this->Good = false;
    return 0;
  }

  const vtkIdType* Words;
  std::size_t Count;
  std::size_t At = 0;
  bool Good = true;
};

} // namespace rgmc

#endif
// VTK-HeaderTest-Exclude: vtkRGMessage.h

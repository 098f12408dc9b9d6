// Packs what a reader's header scan found into one string for a broadcast, and unpacks it: a
// sequence of numbers (written to the last bit) and length-prefixed strings. Private to the
// module.
#ifndef vtkRGPacking_h
#define vtkRGPacking_h

#include <cstdio>
#include <cstdlib>
#include <string>

namespace rgmc
{

class Packer
{
public:
  Packer& Number(double value)
  {
    char text[40];
    std::snprintf(text, sizeof(text), "%.17g ", value);
    this->Text += text;
    return *this;
  }
  Packer& String(const std::string& value)
  {
    this->Number(static_cast<double>(value.size()));
    this->Text += value;
    return *this;
  }
  std::string Text;
};

/// Reads what a Packer wrote, in the same order; Ok() turns false at the first mismatch.
class Unpacker
{
public:
  explicit Unpacker(const std::string& text)
    : Text(text)
  {
  }
  double Number()
  {
    if (!this->Good || this->At >= this->Text.size())
    {
      this->Good = false;
      return 0;
    }
    const char* begin = this->Text.c_str() + this->At;
    char* end = nullptr;
    const double value = std::strtod(begin, &end);
    if (end == begin || *end != ' ')
    {
      this->Good = false;
      return 0;
    }
    this->At += static_cast<std::size_t>(end - begin) + 1;
    return value;
  }
  int Int() { return static_cast<int>(this->Number()); }
  std::string String()
  {
    const double length = this->Number();
    if (!this->Good || length < 0 || this->At + length > this->Text.size())
    {
      this->Good = false;
      return std::string();
    }
    std::string value = this->Text.substr(this->At, static_cast<std::size_t>(length));
    this->At += static_cast<std::size_t>(length);
    return value;
  }
  bool Ok() const { return this->Good; }

private:
  const std::string& Text;
  std::size_t At = 0;
  bool Good = true;
};

} // namespace rgmc

#endif

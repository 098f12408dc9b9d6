// A DICOM structure walk over a file (seeking past values) or, for the deflated transfer syntax,
// over the inflated data set in memory.
#include "rgmcDicomStructure.h"

#include <zlib.h>

#include <cstring>
#include <fstream>
#include <vector>

namespace rgmc
{
namespace
{

constexpr std::uint32_t Undefined = 0xffffffffu;
constexpr int MaximumDepth = 32;

/// Bytes from a file or from memory, by absolute position.
class Source
{
public:
  explicit Source(const std::string& path)
    : File(path, std::ios::binary)
  {
    if (this->File)
    {
      this->File.seekg(0, std::ios::end);
      this->Size = static_cast<std::uint64_t>(this->File.tellg());
    }
  }
  explicit Source(std::vector<unsigned char> memory)
    : Memory(std::move(memory))
    , InMemory(true)
  {
    this->Size = this->Memory.size();
  }
  bool Read(std::uint64_t at, void* out, std::size_t n)
  {
    if (at > this->Size || n > this->Size - at)
    {
      return false;
    }
    if (this->InMemory)
    {
      std::memcpy(out, this->Memory.data() + at, n);
      return true;
    }
    this->File.clear();
    this->File.seekg(static_cast<std::streamoff>(at));
    return static_cast<bool>(
      this->File.read(static_cast<char*>(out), static_cast<std::streamsize>(n)));
  }
  std::ifstream File;
  std::vector<unsigned char> Memory;
  bool InMemory = false;
  std::uint64_t Size = 0;
};

struct Syntax
{
  bool Explicit = true;
  bool BigEndian = false;
};

class Walker
{
public:
  Walker(Source& source, DicomStructure& result)
    : Bytes(source)
    , Structure(result)
  {
  }

  std::uint16_t U16(const unsigned char* b, bool big) const
  {
    return big ? static_cast<std::uint16_t>((b[0] << 8) | b[1])
               : static_cast<std::uint16_t>(b[0] | (b[1] << 8));
  }
  std::uint32_t U32(const unsigned char* b, bool big) const
  {
    return big ? (std::uint32_t(b[0]) << 24) | (std::uint32_t(b[1]) << 16) |
        (std::uint32_t(b[2]) << 8) | b[3]
               : (std::uint32_t(b[3]) << 24) | (std::uint32_t(b[2]) << 16) |
        (std::uint32_t(b[1]) << 8) | b[0];
  }

  bool Fail(std::uint64_t at, const std::string& what)
  {
    if (this->Structure.Problem.empty())
    {
      this->Structure.Problem = what + " at byte " + std::to_string(at);
    }
    return false;
  }

  struct Element
  {
    std::uint16_t Group = 0, Number = 0;
    char VR[3] = { 0, 0, 0 };
    std::uint32_t Length = 0;
    std::uint64_t Value = 0; // position of the value
  };

  /// Reads an element header at `at`; items and delimiters have no VR in any syntax.
  bool Header(std::uint64_t at, std::uint64_t end, const Syntax& sx, Element& e)
  {
    unsigned char b[12];
    if (at + 8 > end || !this->Bytes.Read(at, b, 8))
    {
      return this->Fail(at, "an element header runs past the end of the file or its item");
    }
    e.Group = this->U16(b, sx.BigEndian);
    e.Number = this->U16(b + 2, sx.BigEndian);
    if (e.Group == 0xfffe || !sx.Explicit)
    {
      e.VR[0] = e.VR[1] = 0;
      e.Length = this->U32(b + 4, sx.BigEndian);
      e.Value = at + 8;
      return true;
    }
    e.VR[0] = static_cast<char>(b[4]);
    e.VR[1] = static_cast<char>(b[5]);
    // GDCM asserts on a value representation it does not know: only DICOM's are accepted.
    static const char known[] =
      "AEASATCSDADSDTFLFDISLOLTOBODOFOLOVOWPNSHSLSQSSSTSVTMUCUIULUNURUSUTUV";
    bool valid = false;
    for (std::size_t v = 0; v + 1 < sizeof(known); v += 2)
    {
      valid = valid || (known[v] == e.VR[0] && known[v + 1] == e.VR[1]);
    }
    if (!valid)
    {
      return this->Fail(at, "an element has no valid value representation");
    }
    static const char* const longForms[] = { "OB", "OD", "OF", "OL", "OV", "OW", "SQ", "UC", "UN",
      "UR", "UT", "SV", "UV" };
    bool longForm = false;
    for (const char* vr : longForms)
    {
      longForm = longForm || (vr[0] == e.VR[0] && vr[1] == e.VR[1]);
    }
    if (longForm)
    {
      if (at + 12 > end || !this->Bytes.Read(at + 8, b + 8, 4))
      {
        return this->Fail(at, "an element header runs past the end of the file or its item");
      }
      e.Length = this->U32(b + 8, sx.BigEndian);
      e.Value = at + 12;
    }
    else
    {
      e.Length = this->U16(b + 6, sx.BigEndian);
      e.Value = at + 8;
    }
    return true;
  }

  /// Items of a sequence (or fragments of encapsulated pixel data) from `at` until the sequence
  /// delimiter (undefined length) or `end`; `after` gets the position after the sequence.
  bool Items(std::uint64_t at, std::uint64_t end, bool undefined, const Syntax& sx, int depth,
    bool fragments, std::uint64_t& after)
  {
    while (undefined || at < end)
    {
      Element e;
      if (!this->Header(at, end, Syntax{ false, sx.BigEndian }, e))
      {
        return false;
      }
      if (e.Group == 0xfffe && e.Number == 0xe0dd)
      {
        after = e.Value;
        return undefined || this->Fail(at, "a sequence delimiter in a sequence of known length");
      }
      if (e.Group != 0xfffe || e.Number != 0xe000)
      {
        return this->Fail(at, "a sequence holds something other than items");
      }
      if (e.Length == Undefined)
      {
        if (fragments)
        {
          return this->Fail(at, "a pixel data fragment of undefined length");
        }
        std::uint64_t next = 0;
        if (!this->DataSet(e.Value, end, true, sx, depth + 1, next))
        {
          return false;
        }
        at = next;
      }
      else
      {
        if (e.Value + e.Length > end)
        {
          return this->Fail(at,
            "an item of " + std::to_string(e.Length) +
              " bytes runs past the end of the file or its sequence");
        }
        if (!fragments)
        {
          std::uint64_t next = 0;
          if (!this->DataSet(e.Value, e.Value + e.Length, false, sx, depth + 1, next))
          {
            return false;
          }
        }
        else if (depth == 0)
        {
          // The first item is the basic offset table; the others are the fragments.
          if (this->FirstItem)
          {
            this->FirstItem = false;
          }
          else if (!this->Bytes.InMemory)
          {
            this->Structure.Fragments.emplace_back(e.Value, e.Length);
          }
        }
        at = e.Value + e.Length;
      }
    }
    after = at;
    return true;
  }

  /// Elements from `at` to `end` (or, in an item of undefined length, to its delimiter).
  bool DataSet(std::uint64_t at, std::uint64_t end, bool untilDelimiter, const Syntax& sx,
    int depth, std::uint64_t& after)
  {
    if (depth > MaximumDepth)
    {
      return this->Fail(at, "sequences nested more than " + std::to_string(MaximumDepth) + " deep");
    }
    while (untilDelimiter || at < end)
    {
      Element e;
      // What real files carry after their last element, as pydicom and dcmtk accept it: zero
      // bytes (a scanner's padding), or anything after the pixel data.
      // (Not in a deflated data set: GDCM inflates and parses all of it, so its end must hold.)
      const bool topLevel = depth == 0 && !untilDelimiter && !this->Bytes.InMemory;
      const bool element = this->Header(at, end, sx, e);
      if (!element || (topLevel && this->Structure.HasPixelData && !this->Plausible(e, at, end)))
      {
        if (!topLevel || !(this->Structure.HasPixelData || this->ZerosFrom(at, end)))
        {
          return false;
        }
        this->Structure.Problem.clear();
        this->Structure.TrailingBytes = end - at;
        this->Structure.DataSetEnd = at;
        after = end;
        return true;
      }
      if (e.Group == 0xfffe)
      {
        if (e.Number == 0xe00d && untilDelimiter)
        {
          after = e.Value;
          return true;
        }
        return this->Fail(at, "an item or delimiter out of place");
      }
      const bool pixelData = e.Group == 0x7fe0 && e.Number == 0x0010; // an icon's, too
      const bool topPixelData = pixelData && depth == 0;
      const bool sequence = (e.VR[0] == 'S' && e.VR[1] == 'Q') ||
        (e.Length == Undefined && (e.VR[0] == 0 || (e.VR[0] == 'U' && e.VR[1] == 'N')));
      if (e.Length == Undefined)
      {
        if (!sequence && !pixelData)
        {
          return this->Fail(at, "an element of undefined length that is not a sequence");
        }
        // The content of an undefined-length UN is implicit VR little endian (Part 5, 6.2.2).
        const Syntax inner = e.VR[0] == 'U' ? Syntax{ false, false } : sx;
        std::uint64_t next = 0;
        if (!this->Items(e.Value, end, true, inner, depth, pixelData, next))
        {
          return false;
        }
        if (topPixelData)
        {
          this->Structure.HasPixelData = true;
          this->Structure.PixelDataEncapsulated = true;
        }
        at = next;
        continue;
      }
      if (topPixelData)
      {
        this->Structure.HasPixelData = true;
        this->Structure.PixelDataDeclared = e.Length;
        this->Structure.PixelDataOffset = this->Bytes.InMemory ? 0 : e.Value;
        this->Structure.PixelDataWords = e.VR[0] == 'O' && e.VR[1] == 'W';
        this->Structure.PixelDataLength = e.Value >= this->Bytes.Size
          ? 0
          : std::min<std::uint64_t>(e.Length, this->Bytes.Size - e.Value);
        if (e.Value + e.Length > end)
        {
          // A short native pixel data: reported as truncated by the reader, with both lengths.
          after = end;
          return true;
        }
      }
      else if (e.Value + e.Length > end)
      {
        return this->Fail(at,
          "element (" + Hex(e.Group) + "," + Hex(e.Number) + ") announces " +
            std::to_string(e.Length) + " bytes, more than the file or its item has left");
      }
      if (e.VR[0] == 'S' && e.VR[1] == 'Q' && e.Length > 0)
      {
        std::uint64_t next = 0;
        if (!this->Items(e.Value, e.Value + e.Length, false, sx, depth, false, next))
        {
          return false;
        }
      }
      if (depth == 0)
      {
        this->LastTopTag = (std::uint32_t(e.Group) << 16) | e.Number;
      }
      if (depth == 0 && e.Group == 0x0002 && e.Number == 0x0010 && e.Length < 256)
      {
        this->Structure.TransferSyntax = this->Uid(e);
      }
      at = e.Value + e.Length;
    }
    after = at;
    return true;
  }

  /// The value of a UI element (TransferSyntaxUID), without its padding.
  std::string Uid(const Element& e)
  {
    std::string uid(e.Length, '\0');
    this->Bytes.Read(e.Value, &uid[0], e.Length);
    while (!uid.empty() && (uid.back() == '\0' || uid.back() == ' '))
    {
      uid.pop_back();
    }
    return uid;
  }

  /// Whether the bytes from `at` to `end` are all zero.
  bool ZerosFrom(std::uint64_t at, std::uint64_t end)
  {
    unsigned char block[65536];
    while (at < end)
    {
      const std::size_t n =
        static_cast<std::size_t>(std::min<std::uint64_t>(sizeof block, end - at));
      if (!this->Bytes.Read(at, block, n))
      {
        return false;
      }
      for (std::size_t i = 0; i < n; ++i)
      {
        if (block[i] != 0)
        {
          return false;
        }
      }
      at += n;
    }
    return true;
  }

  /// Whether a top-level element read where trailing bytes may start is an element: a tag that
  /// does not go back (elements are in increasing tag order) and a value inside the file.
  bool Plausible(const Element& e, std::uint64_t at, std::uint64_t end) const
  {
    const std::uint32_t tag = (std::uint32_t(e.Group) << 16) | e.Number;
    return tag > this->LastTopTag && (e.Length == Undefined || e.Value + e.Length <= end) &&
      at < end;
  }

  static std::string Hex(std::uint16_t v)
  {
    static const char digits[] = "0123456789ABCDEF";
    std::string s(4, '0');
    for (int n = 3; n >= 0; --n, v >>= 4)
    {
      s[n] = digits[v & 15];
    }
    return s;
  }

  Source& Bytes;             // the file, or the inflated data set
  DicomStructure& Structure; // what the walk finds
  bool FirstItem = true;
  std::uint32_t LastTopTag = 0;
};

/// Inflates raw deflate data from `at` to the end of the file (the deflated transfer syntax).
bool Inflate(Source& s, std::uint64_t at, std::vector<unsigned char>& out)
{
  std::vector<unsigned char> in(static_cast<std::size_t>(s.Size - at));
  if (!s.Read(at, in.data(), in.size()))
  {
    return false;
  }
  z_stream z;
  std::memset(&z, 0, sizeof(z));
  if (inflateInit2(&z, -15) != Z_OK)
  {
    return false;
  }
  z.next_in = in.data();
  z.avail_in = static_cast<uInt>(in.size());
  unsigned char chunk[1 << 15];
  int status = Z_OK;
  while (status == Z_OK)
  {
    z.next_out = chunk;
    z.avail_out = sizeof(chunk);
    status = inflate(&z, Z_NO_FLUSH);
    out.insert(out.end(), chunk, chunk + (sizeof(chunk) - z.avail_out));
    if (out.size() > (std::uint64_t(1) << 32))
    {
      status = Z_DATA_ERROR;
    }
  }
  inflateEnd(&z);
  return status == Z_STREAM_END;
}

} // namespace

bool CheckJpegHeader(const std::string& path, std::uint64_t offset, std::uint64_t length, int rows,
  int columns, int samples, int bits, std::string& problem)
{
  Source source(path);
  std::vector<unsigned char> data(
    static_cast<std::size_t>(std::min<std::uint64_t>(length, 1 << 20)));
  if (!source.Read(offset, data.data(), data.size()))
  {
    problem = "a JPEG fragment past the end of the file";
    return false;
  }
  const std::size_t n = data.size();
  if (n < 4 || data[0] != 0xff || data[1] != 0xd8)
  {
    problem = "a JPEG frame that does not start with a start-of-image marker";
    return false;
  }
  bool frame = false;
  for (std::size_t at = 2; at < n;)
  {
    if (data[at] != 0xff)
    {
      problem = "a JPEG header with bytes outside a marker segment at " + std::to_string(at);
      return false;
    }
    while (at < n && data[at] == 0xff)
    {
      ++at; // fill bytes
    }
    if (at + 2 >= n)
    {
      return true; // the header goes on in the next fragment: nothing more to check here
    }
    const unsigned char marker = data[at++];
    if (marker == 0x00 || marker == 0xd8 || marker == 0xd9 || (marker >= 0xd0 && marker <= 0xd7))
    {
      problem = "a JPEG header with a misplaced marker";
      return false;
    }
    const std::size_t size = (std::size_t(data[at]) << 8) | data[at + 1];
    if (size < 2 || at + size > n)
    {
      problem = "a JPEG marker segment of " + std::to_string(size) + " bytes past its fragment";
      return false;
    }
    const bool sof =
      marker >= 0xc0 && marker <= 0xcf && marker != 0xc4 && marker != 0xc8 && marker != 0xcc;
    if (sof)
    {
      if (frame || size < 8)
      {
        problem = "a JPEG stream with two frame headers, or a short one";
        return false;
      }
      frame = true;
      const int precision = data[at + 2];
      const int height = (data[at + 3] << 8) | data[at + 4];
      const int width = (data[at + 5] << 8) | data[at + 6];
      const int components = data[at + 7];
      if (height != rows || width != columns || components != samples || precision < 2 ||
        precision > std::max(bits, 8) || size != 8 + 3 * std::size_t(components))
      {
        problem = "a JPEG frame of " + std::to_string(width) + " x " + std::to_string(height) +
          " x " + std::to_string(components) + " samples of " + std::to_string(precision) +
          " bits where the DICOM header says " + std::to_string(columns) + " x " +
          std::to_string(rows) + " x " + std::to_string(samples);
        return false;
      }
    }
    if (marker == 0xda)
    {
      if (!frame)
      {
        problem = "a JPEG scan before any frame header";
        return false;
      }
      return true;
    }
    at += size;
  }
  return true;
}

bool DecodeRleFrame(const std::string& path, std::uint64_t offset, std::uint64_t length,
  std::size_t pixels, int samples, int bytes, unsigned char* out, std::string& problem)
{
  Source source(path);
  std::vector<unsigned char> data(static_cast<std::size_t>(length));
  if (length < 64 || !source.Read(offset, data.data(), data.size()))
  {
    problem = "an RLE frame shorter than its 64-byte header";
    return false;
  }
  auto u32 = [&](std::size_t at)
  {
    return std::uint32_t(data[at]) | (std::uint32_t(data[at + 1]) << 8) |
      (std::uint32_t(data[at + 2]) << 16) | (std::uint32_t(data[at + 3]) << 24);
  };
  const std::uint32_t segments = u32(0);
  if (segments != static_cast<std::uint32_t>(samples * bytes))
  {
    problem = "an RLE frame of " + std::to_string(segments) + " segments, not " +
      std::to_string(samples * bytes);
    return false;
  }
  // Segment s holds, for every pixel, byte (bytes - 1 - s % bytes) (most significant first) of
  // sample s / bytes.
  for (std::uint32_t s = 0; s < segments; ++s)
  {
    const std::uint64_t begin = u32(4 + 4 * s);
    const std::uint64_t end = s + 1 < segments ? u32(8 + 4 * s) : length;
    if (begin < 64 || begin > end || end > length)
    {
      problem = "an RLE segment offset outside its frame";
      return false;
    }
    const int sample = static_cast<int>(s) / bytes;
    const int byte = bytes - 1 - static_cast<int>(s) % bytes; // little endian host
    std::size_t pixel = 0;
    auto put = [&](unsigned char v)
    {
      if (pixel < pixels)
      {
        out[(pixel * samples + sample) * bytes + byte] = v;
      }
      ++pixel;
    };
    for (std::uint64_t at = begin; at < end && pixel < pixels;)
    {
      const int n = static_cast<signed char>(data[at++]);
      if (n >= 0)
      {
        for (int c = 0; c <= n && at < end; ++c)
        {
          put(data[at++]);
        }
      }
      else if (n != -128 && at < end)
      {
        const unsigned char v = data[at++];
        for (int c = 0; c < 1 - n; ++c)
        {
          put(v);
        }
      }
    }
    if (pixel < pixels)
    {
      problem = "an RLE segment that decodes to " + std::to_string(pixel) + " of " +
        std::to_string(pixels) + " pixels";
      return false;
    }
  }
  return true;
}

namespace
{

/// The file meta information of a Part 10 file, from `at` (after the preamble and "DICM"):
/// explicit VR little endian, group 0002 only. `at` ends after it; false, with the problem said,
/// when it is truncated or corrupt.
bool ReadFileMeta(Source& source, Walker& walker, DicomStructure& result, std::uint64_t& at)
{
  while (true)
  {
    unsigned char tag[2];
    if (!source.Read(at, tag, 2) || (tag[0] | (tag[1] << 8)) != 0x0002)
    {
      return true;
    }
    Walker::Element e;
    if (!walker.Header(at, source.Size, Syntax{ true, false }, e) || e.Length == Undefined ||
      e.Value + e.Length > source.Size)
    {
      if (result.Problem.empty())
      {
        result.Problem =
          "its file meta information is truncated or corrupt at byte " + std::to_string(at);
      }
      return false;
    }
    if (e.Number == 0x0010 && e.Length < 256)
    {
      result.TransferSyntax = walker.Uid(e);
    }
    at = e.Value + e.Length;
  }
}

/// The syntax of the data set at `at`, from the transfer syntax `ts`. Some files declare
/// explicit VR and hold implicit VR (or the reverse): as pydicom and GDCM do, the first data set
/// element decides.
Syntax DataSetSyntax(Source& source, const std::string& ts, std::uint64_t at)
{
  Syntax sx;
  sx.Explicit = ts != "1.2.840.10008.1.2" && ts != "1.2.840.113619.5.2" && !ts.empty();
  sx.BigEndian = ts == "1.2.840.10008.1.2.2" || ts == "1.2.840.113619.5.2";
  unsigned char b[6];
  if (ts != "1.2.840.10008.1.2.1.99" && source.Read(at, b, 6))
  {
    sx.Explicit = b[4] >= 'A' && b[4] <= 'Z' && b[5] >= 'A' && b[5] <= 'Z';
  }
  return sx;
}

/// A deflated data set, from `at` to the end of the file: walked once inflated in memory.
void WalkDeflated(Source& source, std::uint64_t at, const Syntax& sx, DicomStructure& result)
{
  std::vector<unsigned char> inflated;
  if (!Inflate(source, at, inflated))
  {
    result.Problem = "its deflated data set does not inflate (truncated or corrupt)";
    return;
  }
  Source memory(std::move(inflated));
  DicomStructure inner;
  Walker innerWalker(memory, inner);
  std::uint64_t after = 0;
  result.Valid = innerWalker.DataSet(0, memory.Size, false, sx, 0, after);
  result.Problem = inner.Problem;
  result.HasPixelData = inner.HasPixelData;
  result.PixelDataEncapsulated = inner.PixelDataEncapsulated;
  result.PixelDataLength = inner.PixelDataLength;
  result.PixelDataDeclared = inner.PixelDataDeclared;
}

/// A bare data set (no preamble): it starts with a small group (0008 usually), in either VR
/// form; anything else is not DICOM.
void WalkBareDataSet(Source& source, Walker& walker, DicomStructure& result)
{
  unsigned char b[8];
  if (!source.Read(0, b, 8) || b[1] != 0 || b[0] == 0 || b[0] > 0x28 || b[3] != 0)
  {
    return; // not DICOM
  }
  result.Dicom = true;
  const bool explicitVR = b[4] >= 'A' && b[4] <= 'Z' && b[5] >= 'A' && b[5] <= 'Z';
  std::uint64_t after = 0;
  result.Valid = walker.DataSet(0, source.Size, false, Syntax{ explicitVR, false }, 0, after);
}

} // namespace

DicomStructure WalkDicom(const std::string& path)
{
  DicomStructure result;
  Source source(path);
  if (!source.File)
  {
    result.Problem = "cannot be opened";
    return result;
  }
  unsigned char head[132];
  Walker walker(source, result);
  if (!source.Read(0, head, 132) || std::memcmp(head + 128, "DICM", 4) != 0)
  {
    WalkBareDataSet(source, walker, result);
    return result;
  }
  result.Dicom = true;
  std::uint64_t at = 132;
  if (!ReadFileMeta(source, walker, result, at))
  {
    return result;
  }
  const Syntax sx = DataSetSyntax(source, result.TransferSyntax, at);
  result.BigEndian = sx.BigEndian;
  if (result.TransferSyntax == "1.2.840.10008.1.2.1.99")
  {
    WalkDeflated(source, at, sx, result);
    return result;
  }
  std::uint64_t after = 0;
  result.Valid = walker.DataSet(at, source.Size, false, sx, 0, after);
  return result;
}

} // namespace rgmc

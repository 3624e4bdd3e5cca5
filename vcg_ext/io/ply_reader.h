// PLY reader (ascii, binary_little_endian, binary_big_endian) that validates before it allocates
// or indexes: element counts against the file size, every list length and vertex index, the end
// of the data. Reads vertex x/y/z (float or double) and the faces' vertex_indices/vertex_index
// lists (fan-triangulated as vcglib does) and Stanford `tristrips`; every other element and
// property, lists included, is skipped.
#pragma once

#include <vcg_ext/io/reader_common.h>

#include <cstring>

namespace molremesh {

namespace ply_detail {

enum class Format { Ascii, BinaryLittle, BinaryBig };

/// A scalar type of the PLY header; bytes 0 for an unknown name.
struct ScalarType {
  int bytes = 0;
  bool isInteger = false, isSigned = false;
};

inline ScalarType ScalarTypeNamed(const std::string& name) {
  if (name == "char" || name == "int8") return {1, true, true};
  if (name == "uchar" || name == "uint8") return {1, true, false};
  if (name == "short" || name == "int16") return {2, true, true};
  if (name == "ushort" || name == "uint16") return {2, true, false};
  if (name == "int" || name == "int32") return {4, true, true};
  if (name == "uint" || name == "uint32") return {4, true, false};
  if (name == "float" || name == "float32") return {4, false, true};
  if (name == "double" || name == "float64") return {8, false, true};
  return {};
}

struct Property {
  std::string name;
  ScalarType type;      // of the value, or of the list items
  ScalarType countType; // bytes 0: not a list
  bool IsList() const { return countType.bytes != 0; }
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
};

struct Header {
  Format format = Format::Ascii;
  std::vector<Element> elements;
  std::size_t bodyOffset = 0;
  std::size_t bodyLine = 1; // for ascii messages
};

/// One value of a property: integers exactly, floating point as read (float kept as float so the
/// coordinates are exactly what the file holds).
struct Value {
  bool isInteger = true;
  long long integer = 0;
  double real = 0;
};

/// Reads the body one value at a time, ascii tokens or binary scalars, never past the end.
class BodyCursor {
public:
  BodyCursor(std::string_view body, Format format, std::size_t firstLine)
      : format_(format), body_(body), tokens_(body, firstLine) {}

  bool Read(const ScalarType& type, Value& value, std::string& error) {
    if (format_ == Format::Ascii) return ReadAscii(type, value, error);
    if (body_.size() - pos_ < std::size_t(type.bytes)) {
      error = "the file ends inside the data (truncated)";
      return false;
    }
    unsigned char raw[8];
    std::memcpy(raw, body_.data() + pos_, std::size_t(type.bytes));
    pos_ += std::size_t(type.bytes);
    if (format_ == Format::BinaryBig)
      for (int i = 0; i < type.bytes / 2; ++i) std::swap(raw[i], raw[type.bytes - 1 - i]);
    value = Decode(type, raw);
    return true;
  }
  /// Skips count values of type (binary: one bounds check, no loop).
  bool Skip(const ScalarType& type, std::uint64_t count, std::string& error) {
    if (format_ != Format::Ascii) {
      if (count > (body_.size() - pos_) / std::size_t(type.bytes)) {
        error = "the file ends inside the data (truncated)";
        return false;
      }
      pos_ += std::size_t(count) * std::size_t(type.bytes);
      return true;
    }
    Value ignored;
    for (std::uint64_t i = 0; i < count; ++i)
      if (!ReadAscii(type, ignored, error)) return false;
    return true;
  }
  /// After the last element only whitespace may follow: more data means the counts lie.
  bool CheckEnd(std::string& error) {
    const bool atEnd = format_ == Format::Ascii
                           ? tokens_.AtEnd()
                           : body_.find_first_not_of(" \t\r\n", pos_) == std::string_view::npos;
    if (!atEnd)
      error = "data after the last declared element at " + Where() + " (the header's counts are wrong)";
    return atEnd;
  }
  /// Where the reading is (a line, or a byte offset into the data), cheap to take per item.
  std::size_t Mark() { return format_ == Format::Ascii ? tokens_.NextLine() : pos_; }
  /// A mark for messages.
  std::string Where(std::size_t mark) const {
    return format_ == Format::Ascii ? "line " + std::to_string(mark)
                                    : "byte " + std::to_string(mark) + " of the data";
  }
  std::string Where() { return Where(Mark()); }

private:
  bool ReadAscii(const ScalarType& type, Value& value, std::string& error) {
    const std::string_view token = tokens_.Next();
    if (token.empty()) {
      error = "the file ends inside the data (truncated)";
      return false;
    }
    value.isInteger = type.isInteger;
    bool ok = false;
    if (type.isInteger) {
      ok = ParseIntegerToken(token, value.integer) && FitsInteger(type, value.integer);
    } else if (type.bytes == 4) {
      float f = 0;
      ok = ParseFloatToken(token, f);
      value.real = f;
    } else {
      ok = ParseDoubleToken(token, value.real);
    }
    if (!ok)
      error = "bad " + std::string(type.isInteger ? "integer" : "number") + " " + QuoteToken(token) +
              " at line " + std::to_string(tokens_.Line());
    return ok;
  }
  static bool FitsInteger(const ScalarType& type, long long v) {
    const int bits = 8 * type.bytes;
    if (type.isSigned) return v >= -(1LL << (bits - 1)) && v < (1LL << (bits - 1));
    return v >= 0 && v < (1LL << bits);
  }
  static Value Decode(const ScalarType& type, const unsigned char* raw) {
    Value v;
    v.isInteger = type.isInteger;
    if (!type.isInteger) {
      if (type.bytes == 4) {
        float f;
        std::memcpy(&f, raw, 4);
        v.real = f;
      } else {
        std::memcpy(&v.real, raw, 8);
      }
      return v;
    }
    std::uint64_t bits = 0;
    std::memcpy(&bits, raw, std::size_t(type.bytes)); // little endian host
    if (type.isSigned && type.bytes < 8 && (bits >> (8 * type.bytes - 1)) != 0)
      bits |= ~std::uint64_t(0) << (8 * type.bytes);
    v.integer = type.isSigned ? static_cast<long long>(bits) : static_cast<long long>(bits);
    return v;
  }

  Format format_;
  std::string_view body_;
  std::size_t pos_ = 0;
  TokenCursor tokens_;
};

/// Parses one header line ("element", "property", "format", ...) into header.
inline bool ParseHeaderLine(const std::string& line, std::size_t lineNumber, Header& header, bool& sawFormat,
                            std::string& error) {
  TokenCursor words(line);
  const std::string keyword(words.Next());
  const std::string at = " at header line " + std::to_string(lineNumber);
  if (keyword.empty() || keyword == "comment" || keyword == "obj_info") return true;
  if (keyword == "format") {
    const std::string kind(words.Next());
    if (kind == "ascii")
      header.format = Format::Ascii;
    else if (kind == "binary_little_endian")
      header.format = Format::BinaryLittle;
    else if (kind == "binary_big_endian")
      header.format = Format::BinaryBig;
    else {
      error = "unknown PLY format " + QuoteToken(kind) + at;
      return false;
    }
    sawFormat = true;
    return true;
  }
  if (keyword == "element") {
    Element element;
    element.name = std::string(words.Next());
    const std::string_view countToken = words.Next();
    long long count = -1;
    if (element.name.empty() || countToken.empty()) {
      error = "'element' without a name and a count" + at;
      return false;
    }
    if (!ParseIntegerToken(countToken, count) || count < 0) {
      error = "element '" + element.name + "' has a bad count " + QuoteToken(countToken) + at;
      return false;
    }
    element.count = std::uint64_t(count);
    header.elements.push_back(element);
    return true;
  }
  if (keyword == "property") {
    if (header.elements.empty()) {
      error = "'property' before any 'element'" + at;
      return false;
    }
    Property property;
    std::string typeName(words.Next());
    if (typeName == "list") {
      const std::string countName(words.Next());
      property.countType = ScalarTypeNamed(countName);
      if (property.countType.bytes == 0 || !property.countType.isInteger) {
        error = "a list property needs an integer count type, not " + QuoteToken(countName) + at;
        return false;
      }
      typeName = std::string(words.Next());
    }
    property.type = ScalarTypeNamed(typeName);
    property.name = std::string(words.Next());
    if (property.type.bytes == 0 || property.name.empty()) {
      error = "bad property (unknown type " + QuoteToken(typeName) + " or no name)" + at;
      return false;
    }
    header.elements.back().properties.push_back(property);
    return true;
  }
  error = "unknown header keyword " + QuoteToken(keyword) + at;
  return false;
}

/// Reads the header up to end_header; bodyOffset is where the data starts.
inline bool ParseHeader(std::string_view bytes, Header& header, std::string& error) {
  if (bytes.substr(0, 4) != "ply\n" && bytes.substr(0, 5) != "ply\r\n") {
    error = "not a PLY file (it does not start with 'ply')";
    return false;
  }
  std::size_t pos = bytes[3] == '\n' ? 4 : 5;
  bool sawFormat = false;
  for (std::size_t lineNumber = 2;; ++lineNumber) {
    const std::size_t end = bytes.find('\n', pos);
    if (end == std::string_view::npos) {
      error = "the PLY header has no end_header line (truncated or not PLY)";
      return false;
    }
    std::string line(bytes.substr(pos, end - pos));
    if (!line.empty() && line.back() == '\r') line.pop_back();
    pos = end + 1;
    if (line == "end_header") {
      header.bodyLine = lineNumber + 1;
      break;
    }
    if (!ParseHeaderLine(line, lineNumber, header, sawFormat, error)) return false;
  }
  if (!sawFormat) {
    error = "the PLY header has no 'format' line";
    return false;
  }
  header.bodyOffset = pos;
  return true;
}

/// The fewest bytes an item of element can take: ascii at least two per value (digit and
/// separator), binary the scalar sizes and the list counts.
inline std::uint64_t MinItemBytes(const Element& element, Format format) {
  std::uint64_t bytes = 0;
  for (const Property& p : element.properties)
    bytes += format == Format::Ascii ? 2 : std::uint64_t(p.IsList() ? p.countType.bytes : p.type.bytes);
  return bytes;
}

/// Refuses counts the file cannot hold, before anything is allocated.
inline bool CheckCountsAgainstSize(const Header& header, std::size_t fileBytes, std::string& error) {
  long double needed = (long double)header.bodyOffset;
  std::uint64_t vertices = 0, faces = 0;
  for (const Element& e : header.elements) {
    needed += (long double)e.count * (long double)MinItemBytes(e, header.format);
    if (e.name == "vertex") vertices = e.count;
    if (e.name == "face") faces = e.count;
    if ((e.name == "vertex" || e.name == "face") && e.count > kMaxElementCount) {
      error =
          "its header declares " + std::to_string(e.count) + " " + e.name + " elements, more than supported";
      return false;
    }
  }
  // (- 1: an ascii file's last value needs no separator.)
  if (needed - 1 > (long double)fileBytes) {
    error = "its header declares " + std::to_string(vertices) + " vertices and " + std::to_string(faces) +
            " faces, at least " + ByteCountText(needed) + " bytes, but the file has " +
            std::to_string(fileBytes) + " (truncated or corrupt)";
    return false;
  }
  return true;
}

} // namespace ply_detail

/// Parses a whole PLY file (its bytes) into raw; false with one line in error otherwise.
class PlyReader {
public:
  static bool Read(std::string_view bytes, RawMesh& raw, std::string& error) {
    using namespace ply_detail;
    raw = RawMesh();
    Header header;
    if (!ParseHeader(bytes, header, error)) return false;
    if (!CheckCountsAgainstSize(header, bytes.size(), error)) return false;
    const Element* vertex = nullptr;
    for (const Element& e : header.elements)
      if (e.name == "vertex") {
        if (vertex) {
          error = "the PLY header declares two 'vertex' elements";
          return false;
        }
        vertex = &e;
      }
    if (!vertex) {
      error = "the PLY header declares no 'vertex' element";
      return false;
    }
    int xyz[3] = {-1, -1, -1};
    if (!FindCoordinates(*vertex, xyz, error)) return false;
    BodyCursor body(bytes.substr(header.bodyOffset), header.format, header.bodyLine);
    for (const Element& e : header.elements) {
      bool ok = true;
      if (&e == vertex)
        ok = ReadVertices(e, xyz, body, raw, error);
      else if (e.name == "face")
        ok = ReadFaces(e, vertex->count, body, raw, error);
      else if (e.name == "tristrips")
        ok = ReadTristrips(e, vertex->count, body, raw, error);
      else
        ok = SkipElement(e, body, error);
      if (!ok) return false;
    }
    return body.CheckEnd(error);
  }

private:
  using Element = ply_detail::Element;
  using Property = ply_detail::Property;
  using BodyCursor = ply_detail::BodyCursor;
  using Value = ply_detail::Value;

  static bool FindCoordinates(const Element& vertex, int xyz[3], std::string& error) {
    const char* names[3] = {"x", "y", "z"};
    for (int k = 0; k < 3; ++k) {
      for (std::size_t i = 0; i < vertex.properties.size(); ++i)
        if (vertex.properties[i].name == names[k]) xyz[k] = int(i);
      if (xyz[k] < 0) {
        error = std::string("the vertex element has no '") + names[k] + "' property";
        return false;
      }
      const Property& p = vertex.properties[std::size_t(xyz[k])];
      if (p.IsList() || p.type.isInteger) {
        error = std::string("the vertex property '") + names[k] + "' must be a float or double";
        return false;
      }
    }
    return true;
  }

  /// Reads (or skips) one property value of an item; a list's count is checked before its items.
  static bool ReadProperty(const Property& p, BodyCursor& body, Value& value, std::string& error) {
    if (!p.IsList()) return body.Read(p.type, value, error);
    Value count;
    if (!body.Read(p.countType, count, error)) return false;
    if (count.integer < 0) {
      error = "a list of property '" + p.name + "' has a negative length at " + body.Where();
      return false;
    }
    return body.Skip(p.type, std::uint64_t(count.integer), error);
  }

  static bool ReadVertices(const Element& e, const int xyz[3], BodyCursor& body, RawMesh& raw,
                           std::string& error) {
    raw.points.reserve(std::size_t(e.count));
    Value value;
    for (std::uint64_t i = 0; i < e.count; ++i) {
      vcg::Point3d p(0, 0, 0);
      for (std::size_t k = 0; k < e.properties.size(); ++k) {
        if (!ReadProperty(e.properties[k], body, value, error)) return false;
        for (int c = 0; c < 3; ++c)
          if (int(k) == xyz[c]) p[c] = value.real;
      }
      raw.points.push_back(p);
    }
    return true;
  }

  /// Reads a list of vertex indices, each checked against vertexCount; length bounded.
  static bool ReadIndexList(const Property& p, std::uint64_t vertexCount, std::size_t maxLength,
                            bool allowRestart, BodyCursor& body, std::vector<int>& indices,
                            std::string& error) {
    Value count;
    const std::size_t mark = body.Mark();
    if (!body.Read(p.countType, count, error)) return false;
    const auto where = [&]() { return body.Where(mark); };
    if (count.integer < 0 || std::uint64_t(count.integer) > maxLength) {
      error = count.integer < 0 ? "a face list has a negative length at " + where()
                                : PolygonSizeMessage(std::size_t(count.integer)) + " at " + where();
      return false;
    }
    indices.clear();
    Value index;
    for (long long k = 0; k < count.integer; ++k) {
      if (!body.Read(p.type, index, error)) return false;
      if (allowRestart && index.integer == -1) {
        indices.push_back(-1);
        continue;
      }
      if (index.integer < 0 || std::uint64_t(index.integer) >= vertexCount) {
        error = "a face refers to vertex " + std::to_string(index.integer) + " of " +
                std::to_string(vertexCount) + " at " + where();
        return false;
      }
      indices.push_back(int(index.integer));
    }
    return true;
  }

  static int IndexListProperty(const Element& e, std::string& error) {
    for (std::size_t i = 0; i < e.properties.size(); ++i) {
      const Property& p = e.properties[i];
      if (p.name != "vertex_indices" && p.name != "vertex_index") continue;
      if (!p.IsList() || !p.type.isInteger) {
        error = "the " + e.name + " property '" + p.name + "' must be a list of integers";
        return -1;
      }
      return int(i);
    }
    error = "the " + e.name + " element has no vertex_indices list";
    return -1;
  }

  static bool ReadFaces(const Element& e, std::uint64_t vertexCount, BodyCursor& body, RawMesh& raw,
                        std::string& error) {
    const int listIndex = IndexListProperty(e, error);
    if (listIndex < 0) return false;
    raw.triangles.reserve(raw.triangles.size() + std::size_t(e.count));
    std::vector<int> corners;
    Value ignored;
    for (std::uint64_t f = 0; f < e.count; ++f) {
      for (std::size_t k = 0; k < e.properties.size(); ++k) {
        if (int(k) != listIndex) {
          if (!ReadProperty(e.properties[k], body, ignored, error)) return false;
          continue;
        }
        const std::size_t mark = body.Mark();
        if (!ReadIndexList(e.properties[k], vertexCount, kMaxPolygonCorners, false, body, corners, error))
          return false;
        if (!AppendFanTriangles(corners, raw.triangles)) {
          error = PolygonSizeMessage(corners.size()) + " at " + body.Where(mark);
          return false;
        }
      }
      if (raw.triangles.size() > kMaxElementCount) {
        error = "too many triangles";
        return false;
      }
    }
    return true;
  }

  /// Stanford triangle strips: -1 restarts a strip; every other triangle is flipped to keep the
  /// orientation (the order and orientation vcglib's importer gives).
  static bool ReadTristrips(const Element& e, std::uint64_t vertexCount, BodyCursor& body, RawMesh& raw,
                            std::string& error) {
    const int listIndex = IndexListProperty(e, error);
    if (listIndex < 0) return false;
    std::vector<int> strip;
    Value ignored;
    for (std::uint64_t s = 0; s < e.count; ++s) {
      for (std::size_t k = 0; k < e.properties.size(); ++k) {
        if (int(k) != listIndex) {
          if (!ReadProperty(e.properties[k], body, ignored, error)) return false;
          continue;
        }
        // A strip's length is bounded by the file (each index takes bytes), not by a corner limit.
        if (!ReadIndexList(e.properties[k], vertexCount, std::size_t(kMaxElementCount), true, body, strip,
                           error))
          return false;
        AppendStrip(strip, raw.triangles);
      }
      if (raw.triangles.size() > kMaxElementCount) {
        error = "too many triangles";
        return false;
      }
    }
    return true;
  }

  static void AppendStrip(const std::vector<int>& v, std::vector<std::array<int, 3>>& triangles) {
    int remainder = 0;
    for (std::size_t k = 0; k + 2 < v.size(); ++k) {
      if (v[k] == -1 || v[k + 1] == -1) continue; // a restart in the first two slots of a window
      if (v[k + 2] == -1) {
        k += 2;
        remainder = (k % 2) ? 0 : 1;
        continue;
      }
      std::array<int, 3> t = {v[k], v[k + 1], v[k + 2]};
      if ((k + std::size_t(remainder)) % 2) std::swap(t[0], t[1]);
      triangles.push_back(t);
    }
  }

  static bool SkipElement(const Element& e, BodyCursor& body, std::string& error) {
    if (e.properties.empty()) return true; // nothing stored, whatever the count
    Value ignored;
    for (std::uint64_t i = 0; i < e.count; ++i)
      for (const Property& p : e.properties)
        if (!ReadProperty(p, body, ignored, error)) return false;
    return true;
  }
};

} // namespace molremesh

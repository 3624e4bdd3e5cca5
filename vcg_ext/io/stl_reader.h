// STL reader, ascii and binary, that refuses what does not add up instead of adding or dropping
// facets: a binary file must be exactly 84 + 50 n bytes for its n facets, an ascii file must
// close every loop, facet and solid. Each facet gets three vertices of its own (welded later).
#pragma once

#include <vcg_ext/io/reader_common.h>

#include <algorithm>
#include <cctype>
#include <cstring>

namespace molremesh {

class StlReader {
public:
  static bool Read(std::string_view bytes, RawMesh& raw, std::string& error) {
    raw = RawMesh();
    if (bytes.size() >= 84) {
      std::uint32_t facets = 0;
      std::memcpy(&facets, bytes.data() + 80, 4); // little endian, as the format says
      if (bytes.size() == 84 + 50 * std::uint64_t(facets)) return ReadBinary(bytes, facets, raw);
    }
    if (LooksAscii(bytes)) return ReadAscii(bytes, raw, error);
    if (bytes.size() < 84) {
      error = "not a valid STL file (" + std::to_string(bytes.size()) +
              " bytes: not 'solid ...' text and too short for binary STL)";
      return false;
    }
    std::uint32_t facets = 0;
    std::memcpy(&facets, bytes.data() + 80, 4);
    error = "not a valid STL file: not 'solid ...' text, and as binary STL it declares " +
            std::to_string(facets) + " facets (" + std::to_string(84 + 50 * std::uint64_t(facets)) +
            " bytes) but has " + std::to_string(bytes.size()) + " bytes (truncated or a wrong facet count)";
    return false;
  }

private:
  /// "solid" first and only text in the first kilobyte (binary headers may start with "solid" too).
  static bool LooksAscii(std::string_view bytes) {
    std::size_t start = 0;
    while (start < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[start]))) ++start;
    if (!KeywordIs(bytes.substr(start, 5), "solid")) return false;
    const std::string_view head = bytes.substr(0, 1024);
    return std::none_of(head.begin(), head.end(), [](char c) {
      const unsigned char u = static_cast<unsigned char>(c);
      return u == 0 || u > 127;
    });
  }

  static bool KeywordIs(std::string_view token, const char* keyword) {
    const std::size_t n = std::strlen(keyword);
    if (token.size() != n) return false;
    for (std::size_t i = 0; i < n; ++i)
      if (std::tolower(static_cast<unsigned char>(token[i])) != keyword[i]) return false;
    return true;
  }

  static bool ReadBinary(std::string_view bytes, std::uint32_t facets, RawMesh& raw) {
    raw.points.reserve(3 * std::size_t(facets));
    raw.triangles.reserve(facets);
    for (std::uint32_t f = 0; f < facets; ++f) {
      const char* facet = bytes.data() + 84 + 50 * std::size_t(f);
      for (int k = 0; k < 3; ++k) {
        float xyz[3];
        std::memcpy(xyz, facet + 12 + 12 * k, 12);
        raw.points.emplace_back(xyz[0], xyz[1], xyz[2]);
      }
      const int first = int(3 * f);
      raw.triangles.push_back({first, first + 1, first + 2});
    }
    return true;
  }

  static bool Expect(TokenCursor& tokens, const char* keyword, std::string& error) {
    const std::string_view t = tokens.Next();
    if (KeywordIs(t, keyword)) return true;
    error = t.empty() ? std::string("the file ends where '") + keyword + "' was expected (truncated)"
                      : std::string("expected '") + keyword + "' at line " + std::to_string(tokens.Line()) +
                            ", found " + QuoteToken(t);
    return false;
  }

  static bool ReadFloat(TokenCursor& tokens, double& value, std::string& error) {
    const std::string_view t = tokens.Next();
    float f = 0;
    if (!ParseFloatToken(t, f)) {
      error = t.empty() ? "the file ends inside a facet (truncated)"
                        : "bad number " + QuoteToken(t) + " at line " + std::to_string(tokens.Line());
      return false;
    }
    value = f;
    return true;
  }

  static bool ReadFacet(TokenCursor& tokens, RawMesh& raw, std::string& error) {
    double ignored = 0;
    if (!Expect(tokens, "normal", error)) return false;
    for (int c = 0; c < 3; ++c)
      if (!ReadFloat(tokens, ignored, error)) return false;
    if (!Expect(tokens, "outer", error) || !Expect(tokens, "loop", error)) return false;
    for (int k = 0; k < 3; ++k) {
      if (!Expect(tokens, "vertex", error)) return false;
      vcg::Point3d p;
      for (int c = 0; c < 3; ++c)
        if (!ReadFloat(tokens, p[c], error)) return false;
      raw.points.push_back(p);
    }
    if (!Expect(tokens, "endloop", error) || !Expect(tokens, "endfacet", error)) return false;
    const int first = int(raw.points.size()) - 3;
    raw.triangles.push_back({first, first + 1, first + 2});
    return true;
  }

  /// solid name / facet ... endfacet (any number) / endsolid name, one or more solids.
  static bool ReadAscii(std::string_view bytes, RawMesh& raw, std::string& error) {
    TokenCursor tokens(bytes);
    while (!tokens.AtEnd()) {
      if (!Expect(tokens, "solid", error)) return false;
      tokens.SkipRestOfLine(); // the solid's name
      for (;;) {
        const std::string_view t = tokens.Next();
        if (KeywordIs(t, "endsolid")) break;
        if (t.empty()) {
          error = "the file ends before 'endsolid' (truncated)";
          return false;
        }
        if (!KeywordIs(t, "facet")) {
          error = "expected 'facet' or 'endsolid' at line " + std::to_string(tokens.Line()) + ", found " +
                  QuoteToken(t);
          return false;
        }
        if (raw.triangles.size() >= kMaxElementCount / 3) {
          error = "too many facets";
          return false;
        }
        if (!ReadFacet(tokens, raw, error)) return false;
      }
      tokens.SkipRestOfLine(); // the solid's name
    }
    return true;
  }
};

} // namespace molremesh

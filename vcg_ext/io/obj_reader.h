// Wavefront OBJ reader: `v` positions and `f` polygons (fan-triangulated, at most
// kMaxPolygonCorners corners; v, v/t, v//n, v/t/n corners; negative indices relative to the
// vertices read so far); every other statement (vt, vn, g, o, s, usemtl, l, p...) is ignored.
//
// Our own reader rather than Debian's tinyobjloader: tinyobjloader (1.0.x) reads face indices with
// atoi-like parsing and accepts `f 4294967297` (wrapping to vertex 1), `f 1.9` and `f 1abc` without
// a word, and vcglib's ImporterOBJ miscounts faces on some files. Here every number is a whole
// token and every index is checked.
#pragma once

#include <vcg_ext/io/reader_common.h>

namespace molremesh {

class ObjReader {
public:
  static bool Read(std::string_view bytes, RawMesh& raw, std::string& error) {
    raw = RawMesh();
    std::vector<int> corners;
    std::size_t lineNumber = 0;
    for (std::size_t pos = 0; pos < bytes.size();) {
      std::size_t end = bytes.find('\n', pos);
      if (end == std::string_view::npos) end = bytes.size();
      const std::string_view line = bytes.substr(pos, end - pos);
      pos = end + 1;
      ++lineNumber;
      const std::string at = " at line " + std::to_string(lineNumber);
      TokenCursor tokens(line);
      const std::string_view kind = tokens.Next();
      if (kind == "v") {
        vcg::Point3d p;
        for (int c = 0; c < 3; ++c)
          if (!ParseDoubleToken(tokens.Next(), p[c])) {
            error = "bad vertex" + at + " (need three numbers)";
            return false;
          }
        raw.points.push_back(p);
      } else if (kind == "f") {
        if (!ReadFace(tokens, raw.points.size(), corners, error)) {
          error += at;
          return false;
        }
        if (!AppendFanTriangles(corners, raw.triangles)) {
          error = PolygonSizeMessage(corners.size()) + at;
          return false;
        }
      }
      if (raw.points.size() > kMaxElementCount || raw.triangles.size() > kMaxElementCount) {
        error = "too many vertices or faces";
        return false;
      }
    }
    if (raw.points.empty()) {
      error = "no vertices found (not an OBJ file?)";
      return false;
    }
    // Positive indices may name vertices defined further down; checked once all are read.
    for (const auto& t : raw.triangles)
      for (int i : t)
        if (std::size_t(i) >= raw.points.size()) {
          error =
              "a face refers to vertex " + std::to_string(i + 1) + " of " + std::to_string(raw.points.size());
          return false;
        }
    return true;
  }

private:
  /// Corners of an `f` statement as 0-based vertex indices (upper bound checked by the caller).
  static bool ReadFace(TokenCursor& tokens, std::size_t pointsSoFar, std::vector<int>& corners,
                       std::string& error) {
    corners.clear();
    for (std::string_view corner = tokens.Next(); !corner.empty(); corner = tokens.Next()) {
      const std::size_t slash = corner.find('/');
      long long index = 0;
      if (!ParseIntegerToken(corner.substr(0, slash), index) || index == 0 || !ValidTail(corner, slash)) {
        error = "bad face corner " + QuoteToken(corner);
        return false;
      }
      const long long resolved = index > 0 ? index - 1 : (long long)pointsSoFar + index;
      if (resolved < 0 || resolved >= (long long)kMaxElementCount) {
        error = "face corner " + QuoteToken(corner) + " is out of range";
        return false;
      }
      corners.push_back(int(resolved));
    }
    return true;
  }

  /// The "/t", "//n" or "/t/n" part after the vertex index: integers or empty texture slot.
  static bool ValidTail(std::string_view corner, std::size_t slash) {
    if (slash == std::string_view::npos) return true;
    std::string_view rest = corner.substr(slash + 1);
    const std::size_t second = rest.find('/');
    long long ignored = 0;
    const std::string_view texture = rest.substr(0, second);
    if (!texture.empty() && !ParseIntegerToken(texture, ignored)) return false;
    if (second == std::string_view::npos) return !texture.empty();
    const std::string_view normal = rest.substr(second + 1);
    return ParseIntegerToken(normal, ignored);
  }
};

} // namespace molremesh

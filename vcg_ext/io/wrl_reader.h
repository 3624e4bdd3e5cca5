// VRML 2.0 (VRML97) reader: the IndexedFaceSet geometry of a .wrl file, as PyMOL, Chimera and
// MeshLab write it. Each set's `coord Coordinate { point [...] }` and `coordIndex [...]` (polygons
// ended by -1, fan-triangulated, at most kMaxPolygonCorners corners; `ccw FALSE` reverses them);
// several sets are concatenated. Everything else (colors, normals, lights, viewpoints) is skipped.
//
// Primitive shapes (Sphere, Cylinder: PyMOL's sticks and spheres) are not meshes and are skipped.
// Refused, in one line: VRML 1.0 and other headers; an IndexedFaceSet inside a Transform that moves
// it (translation, rotation or scale other than the identity: the reader does not apply transforms
// and would misplace the geometry); coordinates shared with DEF/USE; a coordinate list whose count
// is not a multiple of 3; an index below -1 or beyond its set's points; unbalanced braces or
// brackets; a file with no IndexedFaceSet. No library in Debian reads VRML without a scene graph
// (Coin3D, OpenVRML), and what molremesh needs of the format is this small, so it is read here.
#pragma once

#include <vcg_ext/io/reader_common.h>

#include <algorithm>
#include <cstring>

namespace molremesh {

class WrlReader {
public:
  static bool Read(std::string_view bytes, RawMesh& raw, std::string& error) {
    raw = RawMesh();
    if (bytes.substr(0, 10) != "#VRML V2.0") {
      error = bytes.substr(0, 10) == "#VRML V1.0" ? "VRML 1.0 is not supported (VRML 2.0 / VRML97 only)"
                                                  : "not a VRML 2.0 file (no '#VRML V2.0' header)";
      return false;
    }
    Tokens tokens(bytes);
    std::vector<Transform> transforms; // the Transform nodes the scan is inside, innermost last
    bool anySet = false;
    for (std::string_view t = tokens.Next(); !t.empty(); t = tokens.Next()) {
      while (!transforms.empty() && tokens.depth < transforms.back().depth) transforms.pop_back();
      if (t == "IndexedFaceSet" && tokens.Peek() == "{") {
        for (const Transform& enclosing : transforms)
          if (!enclosing.moving.empty()) {
            error =
                "a Transform " + enclosing.moving + " is not supported (only untransformed geometry is read)";
            return Fail(tokens, error);
          }
        tokens.Next();
        if (!ReadFaceSet(tokens, raw, error)) return Fail(tokens, error);
        anySet = true;
      } else if (t == "Transform" && tokens.Peek() == "{") {
        tokens.Next();
        transforms.push_back({tokens.depth, ""});
      } else if ((t == "translation" || t == "rotation" || t == "scale") && !transforms.empty() &&
                 tokens.depth == transforms.back().depth && !IdentityTransformField(tokens, t)) {
        transforms.back().moving = std::string(t);
      }
      if (!tokens.error.empty()) return Fail(tokens, error = tokens.error);
    }
    if (!tokens.error.empty()) return Fail(tokens, error = tokens.error);
    if (tokens.depth != 0) {
      error = "the file ends inside a node or list (unbalanced braces)";
      return false;
    }
    if (!anySet) {
      error = "no IndexedFaceSet found (only VRML 2.0 IndexedFaceSet geometry is read)";
      return false;
    }
    return true;
  }

private:
  /// VRML's lexical rules: '#' comments to the end of the line, commas are white space, braces
  /// and brackets are tokens of their own, strings are quoted (with backslash escapes).
  struct Tokens {
    explicit Tokens(std::string_view text) : text(text) {}

    std::string_view Next() {
      const std::string_view t = Peek();
      pos = peekEnd;
      line = peekLine;
      if (t == "{" || t == "[") ++depth;
      if (t == "}" || t == "]") {
        if (depth == 0 && error.empty()) error = "unbalanced '" + std::string(t) + "'";
        depth = depth > 0 ? depth - 1 : 0;
      }
      return t;
    }

    std::string_view Peek() {
      std::size_t at = pos, lineAt = line;
      while (at < text.size()) {
        const char c = text[at];
        if (c == '\n') ++lineAt;
        if (c == '#') {
          while (at < text.size() && text[at] != '\n') ++at;
        } else if (c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == ',' || c == '\v' || c == '\f') {
          ++at;
        } else {
          break;
        }
      }
      std::size_t end = at;
      if (at < text.size()) {
        if (std::strchr("{}[]", text[at]) != nullptr) {
          end = at + 1;
        } else if (text[at] == '"') {
          for (end = at + 1; end < text.size() && text[end] != '"'; ++end)
            if (text[end] == '\\') ++end;
          end = std::min(end + 1, text.size());
        } else {
          while (end < text.size() && std::strchr(" \t\n\r\v\f,#{}[]\"", text[end]) == nullptr) ++end;
        }
      }
      peekEnd = end;
      peekLine = lineAt;
      return text.substr(at, end - at);
    }

    std::string_view text;
    std::size_t pos = 0, peekEnd = 0, line = 1, peekLine = 1;
    int depth = 0;     ///< open braces and brackets
    std::string error; ///< a lexical error (unbalanced closer)
  };

  /// A Transform node the scan is inside: the depth of its body, and the first field that moves
  /// its children ("" while none does).
  struct Transform {
    int depth;
    std::string moving;
  };

  static bool Fail(const Tokens& tokens, std::string& error) {
    error += " at line " + std::to_string(tokens.line);
    return false;
  }

  /// The body of an IndexedFaceSet after its '{': its coordinates and faces appended to raw.
  static bool ReadFaceSet(Tokens& tokens, RawMesh& raw, std::string& error) {
    const int depth = tokens.depth;
    const std::size_t firstPoint = raw.points.size();
    std::vector<long long> indices;
    bool haveCoord = false, haveIndex = false, ccw = true;
    for (;;) {
      const std::string_view t = tokens.Next();
      if (t.empty()) {
        error = "the file ends inside an IndexedFaceSet";
        return false;
      }
      if (t == "}" && tokens.depth == depth - 1) break;
      if (t == "coord") {
        if (!ReadCoordinate(tokens, raw, error)) return false;
        haveCoord = true;
      } else if (t == "coordIndex") {
        if (!ReadNumberList(tokens, indices, error)) return false;
        haveIndex = true;
      } else if (t == "ccw") {
        ccw = tokens.Next() != "FALSE";
      } else if (t == "{" || t == "[") {
        if (!SkipBalanced(tokens, error)) return false;
      }
    }
    if (haveIndex && !haveCoord) {
      error = "an IndexedFaceSet has coordIndex but no coord";
      return false;
    }
    return AppendPolygons(indices, firstPoint, raw.points.size() - firstPoint, ccw, raw, error);
  }

  /// `coord [DEF name] Coordinate { point [ x y z, ... ] }`.
  static bool ReadCoordinate(Tokens& tokens, RawMesh& raw, std::string& error) {
    std::string_view t = tokens.Next();
    if (t == "DEF") {
      tokens.Next();
      t = tokens.Next();
    }
    if (t == "USE") {
      error = "coordinates shared with USE are not supported";
      return false;
    }
    if (t != "Coordinate" || tokens.Next() != "{") {
      error = "coord is not a Coordinate node";
      return false;
    }
    const int depth = tokens.depth;
    for (;;) {
      t = tokens.Next();
      if (t.empty()) {
        error = "the file ends inside a Coordinate node";
        return false;
      }
      if (t == "}" && tokens.depth == depth - 1) return true;
      if (t != "point") {
        if ((t == "{" || t == "[") && !SkipBalanced(tokens, error)) return false;
        continue;
      }
      std::vector<double> values;
      if (!ReadNumberList(tokens, values, error)) return false;
      if (values.size() % 3 != 0) {
        error = "a Coordinate has " + std::to_string(values.size()) + " numbers, not a multiple of 3";
        return false;
      }
      if (raw.points.size() + values.size() / 3 > kMaxElementCount) {
        error = "too many vertices";
        return false;
      }
      for (std::size_t i = 0; i < values.size(); i += 3)
        raw.points.emplace_back(values[i], values[i + 1], values[i + 2]);
    }
  }

  /// `[ a, b, ... ]` or a single number, each a whole token of type Number (long long or double).
  template <class Number>
  static bool ReadNumberList(Tokens& tokens, std::vector<Number>& values, std::string& error) {
    const bool list = tokens.Peek() == "[";
    if (list) tokens.Next();
    for (;;) {
      const std::string_view t = tokens.Next();
      if (list && t == "]") return true;
      Number value{};
      if (!Parse(t, value)) {
        error = t.empty() ? std::string("the file ends inside a list") : "bad number " + QuoteToken(t);
        return false;
      }
      values.push_back(value);
      if (!list) return true;
    }
  }

  static bool Parse(std::string_view t, long long& value) { return ParseIntegerToken(t, value); }
  static bool Parse(std::string_view t, double& value) { return ParseDoubleToken(t, value); }

  /// Skips to the closer of the brace or bracket just read.
  static bool SkipBalanced(Tokens& tokens, std::string& error) {
    const int depth = tokens.depth;
    while (tokens.depth >= depth) {
      if (tokens.Next().empty()) {
        error = "the file ends inside a node or list";
        return false;
      }
    }
    return true;
  }

  /// Whether a Transform's translation (0 0 0), rotation (angle 0) or scale (1 1 1) is the
  /// identity; its values are consumed.
  static bool IdentityTransformField(Tokens& tokens, std::string_view field) {
    const int count = field == "rotation" ? 4 : 3;
    double v[4] = {0, 0, 0, 0};
    for (int k = 0; k < count && ParseDoubleToken(tokens.Peek(), v[k]); ++k) tokens.Next();
    return field == "translation" ? v[0] == 0 && v[1] == 0 && v[2] == 0
           : field == "rotation"  ? v[3] == 0
                                  : v[0] == 1 && v[1] == 1 && v[2] == 1;
  }

  /// The -1-terminated polygons of indices (into the set's count points from first) as triangles.
  static bool AppendPolygons(const std::vector<long long>& indices, std::size_t first, std::size_t count,
                             bool ccw, RawMesh& raw, std::string& error) {
    std::vector<int> corners;
    for (std::size_t i = 0; i <= indices.size(); ++i) {
      const bool end = i == indices.size() || indices[i] == -1;
      if (!end) {
        if (indices[i] < -1 || indices[i] >= (long long)count) {
          error = "coordIndex " + std::to_string(indices[i]) + " is out of range (the set has " +
                  std::to_string(count) + " points)";
          return false;
        }
        corners.push_back(int(first + std::size_t(indices[i])));
        continue;
      }
      if (corners.empty()) continue; // a trailing -1
      if (!ccw) std::reverse(corners.begin(), corners.end());
      if (!AppendFanTriangles(corners, raw.triangles)) {
        error = PolygonSizeMessage(corners.size());
        return false;
      }
      if (raw.triangles.size() > kMaxElementCount) {
        error = "too many faces";
        return false;
      }
      corners.clear();
    }
    return true;
  }
};

} // namespace molremesh

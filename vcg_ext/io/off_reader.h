// OFF reader ([ST][C][N]OFF headers as vcglib accepts them, counts on the header line or the
// next, '#' comments) that validates before it allocates or indexes: counts against the file size,
// every coordinate parsed whole, face sizes and indices checked, truncation detected.
#pragma once

#include <vcg_ext/io/reader_common.h>

#include <vcg/space/point3.h>
#include <vcg/space/triangle3.h>

#include <set>
#include <utility>

namespace molremesh {

namespace off_detail {

/// The non-empty, non-comment lines of an OFF file as tokens ('#' starts a comment anywhere).
class LineTokens {
public:
  explicit LineTokens(std::string_view text) : text_(text) {}

  /// Tokens of the next non-empty line; false at the end of the file.
  bool NextLine(std::vector<std::string_view>& tokens) {
    while (pos_ < text_.size()) {
      std::size_t end = text_.find('\n', pos_);
      if (end == std::string_view::npos) end = text_.size();
      std::string_view line = text_.substr(pos_, end - pos_);
      pos_ = end + 1;
      ++line_;
      const std::size_t hash = line.find('#');
      if (hash != std::string_view::npos) line = line.substr(0, hash);
      tokens.clear();
      TokenCursor words(line);
      for (std::string_view t = words.Next(); !t.empty(); t = words.Next()) tokens.push_back(t);
      if (!tokens.empty()) return true;
    }
    return false;
  }
  std::size_t Line() const { return line_; }
  std::size_t BytesLeft() const { return pos_ < text_.size() ? text_.size() - pos_ : 0; }

private:
  std::string_view text_;
  std::size_t pos_ = 0;
  std::size_t line_ = 0;
};

struct HeaderFlags {
  bool normals = false, colors = false, texCoords = false;
};

/// [ST][C][N]OFF; 4OFF and nOFF (other dimensions) are refused as vcglib does.
inline bool ParseKeyword(std::string_view keyword, HeaderFlags& flags, std::string& error) {
  const std::size_t at = keyword.rfind("OFF");
  if (at == std::string_view::npos || at + 3 != keyword.size()) {
    error = "not an OFF file (the first line is " + QuoteToken(keyword) + ", not OFF, COFF, NOFF, STOFF...)";
    return false;
  }
  for (std::size_t u = 0; u < at; ++u) {
    const char c = keyword[u];
    if (c == 'C')
      flags.colors = true;
    else if (c == 'N')
      flags.normals = true;
    else if (c == 'S' && u + 1 < at && keyword[u + 1] == 'T')
      flags.texCoords = true, ++u;
    else if (c == '4' || c == 'n') {
      error = "homogeneous or n-dimensional OFF (" + QuoteToken(keyword) + ") is not supported";
      return false;
    } else {
      error = "unknown OFF header keyword " + QuoteToken(keyword);
      return false;
    }
  }
  return true;
}

} // namespace off_detail

/// Parses a whole OFF file (its bytes) into raw; false with one line in error otherwise.
class OffReader {
public:
  static bool Read(std::string_view bytes, RawMesh& raw, std::string& error) {
    raw = RawMesh();
    off_detail::LineTokens lines(bytes);
    std::vector<std::string_view> tokens;
    off_detail::HeaderFlags flags;
    if (!lines.NextLine(tokens)) {
      error = "not an OFF file (no header line)";
      return false;
    }
    if (!off_detail::ParseKeyword(tokens[0], flags, error)) return false;
    if (tokens.size() == 1) {
      if (!lines.NextLine(tokens)) {
        error = "the OFF file ends before its counts";
        return false;
      }
    } else {
      tokens.erase(tokens.begin());
    }
    long long vertices = -1, faces = -1;
    if (tokens.size() < 2 || !ParseIntegerToken(tokens[0], vertices) ||
        !ParseIntegerToken(tokens[1], faces) || vertices < 0 || faces < 0) {
      error =
          "bad OFF counts at line " + std::to_string(lines.Line()) + " (need vertex and face counts >= 0)";
      return false;
    }
    // At least "x y z\n" (6 bytes) per vertex and "3 a b c\n" (8) per face; - 1 for a last line
    // without its newline.
    const long double needed = 6.0L * vertices + 8.0L * faces - 1;
    if (needed > (long double)lines.BytesLeft() || std::uint64_t(vertices) > kMaxElementCount ||
        std::uint64_t(faces) > kMaxElementCount) {
      const std::size_t headerBytes = bytes.size() - lines.BytesLeft();
      error = "its header declares " + std::to_string(vertices) + " vertices and " + std::to_string(faces) +
              " faces, at least " + ByteCountText(needed + 1 + headerBytes) + " bytes, but the file has " +
              std::to_string(bytes.size()) + " (truncated or corrupt)";
      return false;
    }
    return ReadVertices(lines, flags, std::size_t(vertices), raw, error) &&
           ReadFaces(lines, std::size_t(faces), raw, error);
  }

private:
  using Tokens = std::vector<std::string_view>;

  /// The next token of the vertex block, which may continue on the next lines.
  static bool NextValue(off_detail::LineTokens& lines, Tokens& tokens, std::size_t& k, double& value,
                        const char* what, std::size_t vertex, std::string& error) {
    if (k == tokens.size()) {
      if (!lines.NextLine(tokens)) {
        error = "the file ends inside vertex " + std::to_string(vertex) + " (truncated)";
        return false;
      }
      k = 0;
    }
    if (!ParseDoubleToken(tokens[k], value)) {
      error = std::string("bad ") + what + " " + QuoteToken(tokens[k]) + " of vertex " +
              std::to_string(vertex) + " at line " + std::to_string(lines.Line());
      return false;
    }
    ++k;
    return true;
  }

  static bool ReadVertices(off_detail::LineTokens& lines, const off_detail::HeaderFlags& flags,
                           std::size_t count, RawMesh& raw, std::string& error) {
    raw.points.reserve(count);
    Tokens tokens;
    std::size_t k = 0;
    double value = 0;
    for (std::size_t i = 0; i < count; ++i) {
      vcg::Point3d p;
      for (int c = 0; c < 3; ++c)
        if (!NextValue(lines, tokens, k, p[c], "coordinate", i, error)) return false;
      for (int c = 0; flags.normals && c < 3; ++c)
        if (!NextValue(lines, tokens, k, value, "normal", i, error)) return false;
      if (flags.colors) { // the rest of the line, less the texture coordinates: 0 to 4 numbers
        const long long colors = (long long)tokens.size() - (long long)k - (flags.texCoords ? 2 : 0);
        if (colors < 0 || colors > 4) {
          error = "vertex " + std::to_string(i) + " has a color of " + std::to_string(colors) +
                  " numbers at line " + std::to_string(lines.Line());
          return false;
        }
        for (long long c = 0; c < colors; ++c)
          if (!NextValue(lines, tokens, k, value, "color", i, error)) return false;
      }
      for (int c = 0; flags.texCoords && c < 2; ++c)
        if (!NextValue(lines, tokens, k, value, "texture coordinate", i, error)) return false;
      raw.points.push_back(p);
    }
    return true;
  }

  static bool ReadFaces(off_detail::LineTokens& lines, std::size_t count, RawMesh& raw, std::string& error) {
    raw.triangles.reserve(count);
    Tokens tokens;
    std::vector<int> corners;
    std::set<std::pair<int, int>> quadDiagonals;
    for (std::size_t f = 0; f < count; ++f) {
      if (!lines.NextLine(tokens)) {
        error = "the file ends after " + std::to_string(f) + " of " + std::to_string(count) +
                " faces (truncated)";
        return false;
      }
      const std::string at = " (face " + std::to_string(f) + ", line " + std::to_string(lines.Line()) + ")";
      long long size = 0;
      if (!ParseIntegerToken(tokens[0], size)) {
        error = "bad face size " + QuoteToken(tokens[0]) + at;
        return false;
      }
      if (size < 3 || size > (long long)kMaxPolygonCorners) {
        error = PolygonSizeMessage(std::size_t(std::max(size, 0LL))) + at;
        if (size < 0) error = "a face has a negative size" + at;
        return false;
      }
      corners.clear();
      std::size_t k = 1;
      for (long long j = 0; j < size; ++j, ++k) {
        if (k == tokens.size()) {
          if (!lines.NextLine(tokens)) {
            error = "the file ends inside face " + std::to_string(f) + " (truncated)";
            return false;
          }
          k = 0;
        }
        long long index = -1;
        if (!ParseIntegerToken(tokens[k], index) || index < 0 || std::size_t(index) >= raw.points.size()) {
          error = "face " + std::to_string(f) + " refers to vertex " + QuoteToken(tokens[k]) + " of " +
                  std::to_string(raw.points.size()) + " at line " + std::to_string(lines.Line());
          return false;
        }
        corners.push_back(int(index));
      }
      // (Tokens after the indices are the face's color: skipped.)
      if (size == 4)
        AppendQuad(corners, raw, quadDiagonals);
      else
        AppendFanTriangles(corners, raw.triangles);
    }
    if (lines.NextLine(tokens)) {
      error = "data after the last of the " + std::to_string(count) + " declared faces at line " +
              std::to_string(lines.Line()) + " (the header's counts are wrong)";
      return false;
    }
    return true;
  }

  /// Splits a quad along the diagonal vcglib's OFF importer picks (BitQuad::QuadTriangulate): the
  /// one whose worse triangle is better unless that folds the quad, and never a diagonal an
  /// earlier quad already used. Kept identical so meshes read as before.
  static void AppendQuad(std::vector<int>& q, RawMesh& raw, std::set<std::pair<int, int>>& diagonals) {
    const auto& P = raw.points;
    const vcg::Point3d &p0 = P[std::size_t(q[0])], &p1 = P[std::size_t(q[1])], &p2 = P[std::size_t(q[2])],
                       &p3 = P[std::size_t(q[3])];
    const double angle0 = vcg::Angle(vcg::Normal(p0, p1, p2), vcg::Normal(p0, p2, p3));
    const double angle1 = vcg::Angle(vcg::Normal(p1, p2, p3), vcg::Normal(p1, p3, p0));
    const bool qualityImproves = std::min(vcg::QualityRadii(p0, p1, p2), vcg::QualityRadii(p0, p2, p3)) <
                                 std::min(vcg::QualityRadii(p1, p2, p3), vcg::QualityRadii(p1, p3, p0));
    const bool swapFlips = angle1 > M_PI / 2.0 && angle0 < M_PI / 2.0;
    if (qualityImproves && !swapFlips) std::rotate(q.begin(), q.begin() + 1, q.end());
    if (!diagonals.insert(std::minmax(q[0], q[2])).second) std::rotate(q.begin(), q.begin() + 1, q.end());
    raw.triangles.push_back({q[0], q[1], q[2]});
    raw.triangles.push_back({q[0], q[2], q[3]});
  }
};

} // namespace molremesh

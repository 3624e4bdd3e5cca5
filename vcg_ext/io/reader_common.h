// Pieces the mesh readers share: reading a file that must be a regular file, numbers parsed as
// whole tokens, bounded polygon triangulation and the vcg mesh built from points and triangles.
//
// The readers parse into a RawMesh first and build the vcg mesh only from a fully validated one,
// so a bad file never leaves a half-built mesh and no index is used before it is checked.
#pragma once

#include <vcg/complex/allocate.h>

#include <sys/stat.h>

#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <fstream>
#include <limits>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

namespace molremesh {

/// Points and triangles of a mesh as read from a file, before it becomes a vcg mesh.
struct RawMesh {
  std::vector<vcg::Point3d> points;
  std::vector<std::array<int, 3>> triangles;
};

/// Polygons with more corners are refused: a face of thousands of corners is never a surface
/// mesh face, and its fan makes the later per-face searches super-linear.
constexpr std::size_t kMaxPolygonCorners = 256;

/// Vertex and triangle counts above this are refused before anything is allocated (the mesh
/// stores indices as int).
constexpr std::uint64_t kMaxElementCount = std::uint64_t(std::numeric_limits<int>::max());

/// Reads the whole file at path into bytes. Refuses what is not a regular file (directories,
/// FIFOs, devices: reading them blocks or loops) and empty files, with the reason in error.
inline bool ReadRegularFile(const std::string& path, std::string& bytes, std::string& error) {
  struct stat status {};
  if (stat(path.c_str(), &status) != 0) {
    error = errno == ENOENT ? "no such file" : "cannot access the file";
    return false;
  }
  if (S_ISDIR(status.st_mode)) {
    error = "it is a directory, not a mesh file";
    return false;
  }
  if (!S_ISREG(status.st_mode)) {
    error = "it is not a regular file (a FIFO, device or socket), refused";
    return false;
  }
  if (status.st_size == 0) {
    error = "the file is empty";
    return false;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    error = "the file is not readable";
    return false;
  }
  bytes.assign(std::size_t(status.st_size), '\0');
  in.read(&bytes[0], std::streamsize(bytes.size()));
  if (std::size_t(in.gcount()) != bytes.size()) {
    error = "the file could not be read completely";
    return false;
  }
  return true;
}

/// Parses token as a whole decimal integer (optional sign); false on anything else (trailing
/// garbage, "1.9", out of the range of long long).
inline bool ParseIntegerToken(std::string_view token, long long& value) {
  if (token.size() > 1 && token[0] == '+' && token[1] != '-') token.remove_prefix(1);
  if (token.empty()) return false;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  return ec == std::errc() && end == token.data() + token.size();
}

/// Parses token as a whole decimal floating-point number into double; "nan" and "inf" are
/// accepted as text because writers print non-finite coordinates that way and the cleaning
/// stage, not the reader, decides about them. Hexadecimal and trailing garbage are refused.
inline bool ParseDoubleToken(std::string_view token, double& value) {
  if (token.size() > 1 && token[0] == '+' && token[1] != '-') token.remove_prefix(1);
  if (token.empty()) return false;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  return ec == std::errc() && end == token.data() + token.size();
}

/// As ParseDoubleToken, rounded to float once (as reading with "%f" does); a value beyond
/// float's range becomes +-inf and one below its smallest subnormal 0, as with strtof.
inline bool ParseFloatToken(std::string_view token, float& value) {
  if (token.size() > 1 && token[0] == '+' && token[1] != '-') token.remove_prefix(1);
  if (token.empty()) return false;
  const char* first = token.data();
  const char* last = first + token.size();
  const auto [end, ec] = std::from_chars(first, last, value);
  if (ec == std::errc()) return end == last;
  if (ec != std::errc::result_out_of_range) return false;
  double wide = 0;
  const auto [wideEnd, wideEc] = std::from_chars(first, last, wide);
  if (wideEc != std::errc() || wideEnd != last) return false;
  if (std::fabs(wide) > double(std::numeric_limits<float>::max()))
    value = wide > 0 ? std::numeric_limits<float>::infinity() : -std::numeric_limits<float>::infinity();
  else
    value = float(wide);
  return true;
}

/// Appends the fan (c0, c[k-1], c[k]) of a polygon: the triangulation vcglib's importers use, exact
/// for convex polygons (surface meshers write triangles, and quads or small convex polygons at
/// most). False when the polygon has fewer than 3 or more than kMaxPolygonCorners corners.
inline bool AppendFanTriangles(const std::vector<int>& corners, std::vector<std::array<int, 3>>& triangles) {
  if (corners.size() < 3 || corners.size() > kMaxPolygonCorners) return false;
  for (std::size_t k = 2; k < corners.size(); ++k)
    triangles.push_back({corners[0], corners[k - 1], corners[k]});
  return true;
}

/// A non-negative byte count for an "at least N bytes" message, "10^18" from there on (a header's
/// declared counts can be as large as 9.2e18 each; casting their product to an integer is undefined).
inline std::string ByteCountText(long double bytes) {
  if (!(bytes < 1e18L)) return "10^18";
  return std::to_string((unsigned long long)(bytes < 0 ? 0 : bytes));
}

/// "a face has N corners" message with the limits.
inline std::string PolygonSizeMessage(std::size_t corners) {
  return "a face has " + std::to_string(corners) + " corners (3 to " + std::to_string(kMaxPolygonCorners) +
         " supported)";
}

/// Replaces m by raw's points and triangles, in their order. Every triangle index must be in
/// range (the readers check it).
template <class MeshType>
void BuildMeshFromRaw(MeshType& m, const RawMesh& raw) {
  using Scalar = typename MeshType::ScalarType;
  m.Clear();
  if (!raw.points.empty()) vcg::tri::Allocator<MeshType>::AddVertices(m, raw.points.size());
  for (std::size_t i = 0; i < raw.points.size(); ++i)
    m.vert[i].P() =
        vcg::Point3<Scalar>(Scalar(raw.points[i][0]), Scalar(raw.points[i][1]), Scalar(raw.points[i][2]));
  if (!raw.triangles.empty()) vcg::tri::Allocator<MeshType>::AddFaces(m, raw.triangles.size());
  for (std::size_t f = 0; f < raw.triangles.size(); ++f)
    for (int k = 0; k < 3; ++k) m.face[f].V(k) = &m.vert[std::size_t(raw.triangles[f][k])];
}

/// Splits text into whitespace-separated tokens on demand, tracking the line of each token.
class TokenCursor {
public:
  explicit TokenCursor(std::string_view text, std::size_t firstLine = 1) : text_(text), line_(firstLine) {}

  /// The next token, or an empty view at the end of the text.
  std::string_view Next() {
    SkipSpace();
    const std::size_t start = pos_;
    while (pos_ < text_.size() && !IsSpace(text_[pos_])) ++pos_;
    tokenLine_ = line_;
    return text_.substr(start, pos_ - start);
  }
  bool AtEnd() {
    SkipSpace();
    return pos_ >= text_.size();
  }
  /// Moves past the end of the current line (what is left of it is not tokens: a name, say).
  void SkipRestOfLine() {
    while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
    if (pos_ < text_.size()) {
      ++pos_;
      ++line_;
    }
  }
  /// Line of the token Next() will return.
  std::size_t NextLine() {
    SkipSpace();
    return line_;
  }
  /// Line of the token Next() returned last.
  std::size_t Line() const { return tokenLine_; }
  std::size_t Offset() const { return pos_; }

private:
  static bool IsSpace(char c) {
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
  }
  void SkipSpace() {
    while (pos_ < text_.size() && IsSpace(text_[pos_])) {
      if (text_[pos_] == '\n') ++line_;
      ++pos_;
    }
  }
  std::string_view text_;
  std::size_t pos_ = 0;
  std::size_t line_ = 1;
  std::size_t tokenLine_ = 1;
};

/// A token for a message: at most 40 characters, non-printable bytes as '?'.
inline std::string QuoteToken(std::string_view token) {
  std::string out = "'";
  for (std::size_t i = 0; i < token.size() && i < 40; ++i) {
    const unsigned char c = static_cast<unsigned char>(token[i]);
    out += (c >= 32 && c < 127) ? char(c) : '?';
  }
  if (token.size() > 40) out += "...";
  return out + "'";
}

} // namespace molremesh

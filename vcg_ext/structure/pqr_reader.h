// A strict reader of PQR files as pdb2pqr writes them: ATOM/HETATM records of whitespace-separated
// fields, the atom's charge and radius after its coordinates.
//
//   ATOM  serial name resName [chain] resSeq x y z charge radius
//
// 10 fields (no chain) or 11 (with one); every other record (REMARK, TER, END ...) is ignored.
// pdb2pqr's default layout is read too: PDB columns up to the coordinates (where a chain and a
// 4-digit residue number, or two wide coordinates, run together), then charge and radius.
// Each rejected record gives one line naming the file, the line number and what is wrong with it.
#pragma once

#include <vcg_ext/structure/atoms.h>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

namespace molremesh {

namespace pqr_detail {

inline std::vector<std::string_view> SplitFields(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    const std::size_t start = i;
    while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    if (i > start) fields.push_back(line.substr(start, i - start));
  }
  return fields;
}

/// The whole field as a number (strtod accepts "nan" and "inf": the caller checks finiteness).
inline bool ParseNumber(std::string_view field, double& value) {
  const std::string text(field);
  char* end = nullptr;
  errno = 0;
  value = std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size() && !text.empty() && errno != ERANGE;
}

/// Residue number, with an optional insertion code letter after the digits ("52A").
inline bool ParseResidueNumber(std::string_view field, int& value) {
  std::string text(field);
  if (!text.empty() && std::isalpha(static_cast<unsigned char>(text.back()))) text.pop_back();
  char* end = nullptr;
  const long n = std::strtol(text.c_str(), &end, 10);
  value = int(n);
  return !text.empty() && end == text.c_str() + text.size();
}

/// pdb2pqr's column layout: coordinates in columns 31-54 as %8.3f, then two whitespace fields.
inline bool IsColumnLayout(const std::string& line) {
  return line.size() >= 58 && line[34] == '.' && line[42] == '.' && line[50] == '.' &&
         SplitFields(std::string_view(line).substr(54)).size() == 2;
}

/// The fields of a column-layout record, in the whitespace layout's order with a chain (11 fields).
inline std::vector<std::string_view> ColumnFields(const std::string& line,
                                                  std::vector<std::string>& storage) {
  auto trimmed = [&](std::size_t first, std::size_t count) {
    const std::vector<std::string_view> f = SplitFields(std::string_view(line).substr(first, count));
    return f.empty() ? std::string() : std::string(f[0]);
  };
  storage = {line.substr(0, 6).find("HETATM") == 0 ? "HETATM" : "ATOM",
             trimmed(6, 5),
             trimmed(12, 4),
             trimmed(17, 3),
             line[21] == ' ' ? "-" : std::string(1, line[21]),
             trimmed(22, 5),
             trimmed(30, 8),
             trimmed(38, 8),
             trimmed(46, 8)};
  for (std::string_view f : SplitFields(std::string_view(line).substr(54))) storage.emplace_back(f);
  return std::vector<std::string_view>(storage.begin(), storage.end());
}

} // namespace pqr_detail

/// Reads the atoms of a PQR file's text; `name` is the file name used in messages.
/// Precondition: none (any text gives atoms or one clear error). Radii must be finite and >= 0;
/// coordinates finite; a file without atoms is an error.
inline StructureReadResult ReadPqr(const std::string& text, const std::string& name,
                                   const StructureReadOptions& options = {}) {
  using namespace pqr_detail;
  StructureReadResult result;
  std::istringstream in(text);
  std::string line;
  std::size_t lineNumber = 0;
  auto fail = [&](const std::string& why) {
    return StructureReadResult::Failure("'" + name + "' line " + std::to_string(lineNumber) + ": " + why);
  };
  while (std::getline(in, line)) {
    ++lineNumber;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const bool atomRecord = line.rfind("ATOM", 0) == 0, hetatmRecord = line.rfind("HETATM", 0) == 0;
    if (!atomRecord && !hetatmRecord) continue;
    std::vector<std::string> storage;
    const std::vector<std::string_view> f =
        IsColumnLayout(line) ? ColumnFields(line, storage) : SplitFields(line);
    if (f[0] != "ATOM" && f[0] != "HETATM") continue; // e.g. "ATOMIC ..." in a free-text record
    if (f.size() < 10)
      return fail("truncated record (" + std::to_string(f.size()) + " fields, expected 10 or 11)");
    if (f.size() > 11)
      return fail("unexpected record (" + std::to_string(f.size()) +
                  " fields, expected 10 or 11 whitespace-separated: is it a fixed-column PDB file?)");
    Atom atom;
    atom.hetatm = hetatmRecord;
    atom.name = std::string(f[2]);
    atom.residueName = std::string(f[3]);
    if (f.size() == 11) atom.chain = f[4].size() == 1 && f[4] != "-" ? f[4][0] : ' ';
    if (!ParseResidueNumber(f[f.size() - 6], atom.residueNumber))
      return fail("bad residue number '" + std::string(f[f.size() - 6]) + "'");
    double values[5];
    for (int k = 0; k < 5; ++k)
      if (!ParseNumber(f[f.size() - 5 + k], values[k]))
        return fail("bad number '" + std::string(f[f.size() - 5 + k]) + "'");
    atom.position = Point(values[0], values[1], values[2]);
    if (!IsFinite(atom.position)) return fail("coordinate is NaN or infinite");
    atom.radius = values[4];
    if (!std::isfinite(atom.radius) || atom.radius < 0)
      return fail("bad radius " + std::string(f[f.size() - 1]) + " (must be a finite number >= 0)");
    if (SkippedByOptions(options, IsWaterResidue(atom.residueName), IsHydrogenAtom(atom.element, atom.name),
                         atom.hetatm, result))
      continue;
    result.atoms.push_back(std::move(atom));
  }
  if (result.atoms.empty())
    return StructureReadResult::Failure("'" + name + "': no atoms (no ATOM/HETATM record kept)");
  result.ok = true;
  return result;
}

} // namespace molremesh

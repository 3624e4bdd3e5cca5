// PDB files read by Debian's freesasa library, radii by its ProtOr (default) or NACCESS classifier.
//
// freesasa parses the fixed-column records and classifies the atoms; before it does, one pass over
// the text here applies the skip rules (waters, hydrogens, HETATM, alternate locations: the first
// label seen per file), keeps the first MODEL only, rejects truncated records and non-finite
// coordinates with their line number, and fills in an element symbol from the atom name where the
// element columns (77-78) are blank or hold something else (old files put a serial number there).
// The lines it hands to freesasa map one to one to freesasa's atoms, so every later message (an
// element freesasa cannot give a radius) still names its line.
#pragma once

#include <vcg_ext/structure/atoms.h>

#include <freesasa.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

namespace molremesh {

namespace pdb_detail {

inline std::string Columns(const std::string& line, std::size_t first, std::size_t count) {
  return first < line.size() ? line.substr(first, count) : std::string();
}
inline std::string Trim(const std::string& s) {
  const auto b = s.find_first_not_of(' '), e = s.find_last_not_of(' ');
  return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}

/// Element from the atom name (columns 13-16): PDB right-justifies one-letter elements in
/// column 14; a two-letter element starting in column 13 is only taken for HETATM records (ions).
inline std::string ElementFromAtomName(const std::string& name4, bool hetatm) {
  static const char* twoLetter[] = {"FE", "ZN", "MG", "MN", "CU", "CO", "NI", "CL", "BR", "NA", "SE", "CD",
                                    "HG", "CA", "K",  "LI", "SR", "BA", "AL", "AU", "PT", "AG", "IR"};
  if (hetatm && name4.size() >= 2 && std::isalpha(static_cast<unsigned char>(name4[0])) &&
      std::isalpha(static_cast<unsigned char>(name4[1])))
    for (const char* e : twoLetter)
      if (name4.compare(0, 2, e) == 0) return e;
  for (char c : name4)
    if (std::isalpha(static_cast<unsigned char>(c))) return std::string(1, char(std::toupper(c)));
  return "";
}

inline bool IsElementField(const std::string& e) {
  if (e.empty() || e.size() > 2) return false;
  for (char c : e)
    if (!std::isalpha(static_cast<unsigned char>(c))) return false;
  return true;
}

/// One kept record: its line number and the atom data freesasa does not return.
struct KeptRecord {
  std::size_t lineNumber;
  bool hetatm;
  std::string element;
};

/// The skip rules and checks on the text; fills `records`, returns the text for freesasa or sets `error`.
inline std::string FilterRecords(const std::string& text, const std::string& name,
                                 const StructureReadOptions& options, StructureReadResult& counts,
                                 std::vector<KeptRecord>& records, std::string& error) {
  std::istringstream in(text);
  std::ostringstream out;
  std::string line;
  std::size_t lineNumber = 0;
  char firstAltLoc = 0;
  while (std::getline(in, line)) {
    ++lineNumber;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.rfind("ENDMDL", 0) == 0) break; // the first model only
    const bool hetatm = line.rfind("HETATM", 0) == 0;
    if (!hetatm && line.rfind("ATOM  ", 0) != 0) continue;
    const std::string where = "'" + name + "' line " + std::to_string(lineNumber) + ": ";
    if (line.size() < 54) {
      error = where + "truncated record (" + std::to_string(line.size()) + " columns, coordinates end at 54)";
      return {};
    }
    for (int k = 0; k < 3; ++k) {
      const std::string field = Columns(line, 30 + 8 * k, 8);
      char* end = nullptr;
      const double v = std::strtod(field.c_str(), &end);
      if (end == field.c_str()) {
        error = where + "bad coordinate '" + Trim(field) + "'";
        return {};
      }
      if (!std::isfinite(v)) {
        error = where + "coordinate is NaN or infinite";
        return {};
      }
    }
    const std::string residue = Trim(Columns(line, 17, 3)), atomName = Columns(line, 12, 4);
    std::string element = Trim(Columns(line, 76, 2));
    if (!IsElementField(element)) element = ElementFromAtomName(atomName, hetatm);
    for (char& c : element) c = char(std::toupper(c));
    const char altLoc = line[16];
    if (SkippedByOptions(options, IsWaterResidue(residue), element == "H" || element == "D", hetatm, counts))
      continue;
    if (altLoc != ' ') {
      if (options.allAltLocs) {
        line[16] = ' '; // freesasa keeps one location only; a blank label makes it keep this one
      } else {
        if (firstAltLoc == 0) firstAltLoc = altLoc;
        if (altLoc != firstAltLoc) {
          ++counts.skippedAltLocs;
          continue;
        }
      }
    }
    line.resize(std::max<std::size_t>(line.size(), 80), ' ');
    line.replace(76, 2, element.size() == 1 ? " " + element : element);
    records.push_back({lineNumber, hetatm, element});
    out << line << '\n';
  }
  return out.str();
}

/// freesasa's messages go to a FILE*; this one collects them in memory for our error line.
class CapturedFreesasaErrors {
public:
  CapturedFreesasaErrors() : stream_(open_memstream(&buffer_, &size_)) {
    if (stream_) freesasa_set_err_out(stream_);
    freesasa_set_verbosity(FREESASA_V_NOWARNINGS);
  }
  ~CapturedFreesasaErrors() {
    freesasa_set_err_out(stderr);
    freesasa_set_verbosity(FREESASA_V_NORMAL);
    if (stream_) std::fclose(stream_);
    std::free(buffer_);
  }
  std::string FirstLine() {
    if (!stream_) return {};
    std::fflush(stream_);
    const std::string all(buffer_ ? buffer_ : "", size_);
    return all.substr(0, all.find('\n'));
  }

private:
  char* buffer_ = nullptr;
  std::size_t size_ = 0;
  FILE* stream_ = nullptr;
};

/// The atoms freesasa made of the kept records (in their order), with the element and record kind
/// it does not keep; `where` names a record's position in messages ("line", "atom site row").
inline StructureReadResult AtomsOfStructure(const freesasa_structure& structure,
                                            const std::vector<KeptRecord>& records, const std::string& name,
                                            const char* where, StructureReadResult& result) {
  const int n = freesasa_structure_n(&structure);
  if (n != int(records.size()))
    return StructureReadResult::Failure("'" + name + "': freesasa read " + std::to_string(n) + " of the " +
                                        std::to_string(records.size()) + " atom records");
  const double* xyz = freesasa_structure_coord_array(&structure);
  result.atoms.resize(n);
  for (int i = 0; i < n; ++i) {
    Atom& a = result.atoms[i];
    a.position = Point(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
    a.radius = freesasa_structure_atom_radius(&structure, i);
    a.name = Trim(freesasa_structure_atom_name(&structure, i));
    a.residueName = Trim(freesasa_structure_atom_res_name(&structure, i));
    a.residueNumber = std::atoi(freesasa_structure_atom_res_number(&structure, i));
    a.chain = freesasa_structure_atom_chain(&structure, i);
    a.element = records[i].element;
    a.hetatm = records[i].hetatm;
    if (!(a.radius > 0))
      return StructureReadResult::Failure(
          "'" + name + "' " + where + " " + std::to_string(records[i].lineNumber) + ": unknown element '" +
          a.element + "' (atom " + a.name + " of " + a.residueName + "): no radius for it");
  }
  result.ok = true;
  return std::move(result);
}

/// freesasa's classifier of the radii option.
inline const freesasa_classifier* Classifier(const StructureReadOptions& options) {
  return options.radii == StructureReadOptions::Radii::Naccess ? &freesasa_naccess_classifier
                                                               : &freesasa_protor_classifier;
}

} // namespace pdb_detail

/// Reads the atoms of a PDB file's text (already decompressed); `name` is used in messages.
inline StructureReadResult ReadPdb(const std::string& text, const std::string& name,
                                   const StructureReadOptions& options = {}) {
  using namespace pdb_detail;
  StructureReadResult result;
  std::vector<KeptRecord> records;
  std::string error;
  std::string kept = FilterRecords(text, name, options, result, records, error);
  if (!error.empty()) return StructureReadResult::Failure(error);
  if (records.empty())
    return StructureReadResult::Failure("'" + name + "': no atoms (no ATOM/HETATM record kept)");

  CapturedFreesasaErrors errors;
  std::unique_ptr<FILE, int (*)(FILE*)> file(fmemopen(kept.data(), kept.size(), "r"), &std::fclose);
  if (!file) return StructureReadResult::Failure("'" + name + "': cannot open the text in memory");
  const freesasa_classifier* classifier = Classifier(options);
  std::unique_ptr<freesasa_structure, void (*)(freesasa_structure*)> structure(
      freesasa_structure_from_pdb(file.get(), classifier,
                                  FREESASA_INCLUDE_HETATM | FREESASA_INCLUDE_HYDROGEN),
      &freesasa_structure_free);
  if (!structure) return StructureReadResult::Failure("'" + name + "': freesasa: " + errors.FirstLine());
  return AtomsOfStructure(*structure, records, name, "line", result);
}

} // namespace molremesh

// mmCIF structure files: the _atom_site loop parsed by gemmi's CIF reader (Debian's gemmi-dev,
// header-only for this part), the same skip rules and checks as the PDB reader, radii from
// freesasa's classifiers (freesasa_structure_add_cif_atom, as the freesasa program reads mmCIF).
//
// Kept from each row: group_PDB (ATOM/HETATM), auth_asym_id (the chain: its first character, as
// freesasa stores one), auth_seq_id, pdbx_PDB_ins_code, auth_comp_id, auth_atom_id,
// label_alt_id, type_symbol, Cartn_x/y/z; only the first model (pdbx_PDB_model_num) is read.
#pragma once

#include <vcg_ext/structure/atoms.h>
#include <vcg_ext/structure/pdb_reader.h>

#include <freesasa.h>
#include <gemmi/cif.hpp>

#include <cmath>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

namespace molremesh {

namespace mmcif_detail {

/// The atom site columns read, in this order (model number optional).
inline const std::vector<std::string>& SiteColumns() {
  static const std::vector<std::string> columns = {
      "group_PDB",    "auth_asym_id", "auth_seq_id",   "?pdbx_PDB_ins_code",
      "auth_comp_id", "auth_atom_id", "?label_alt_id", "type_symbol",
      "Cartn_x",      "Cartn_y",      "Cartn_z",       "?pdbx_PDB_model_num"};
  return columns;
}

/// One kept atom site: the strings freesasa_cif_atom points to, and its coordinates.
struct KeptSite {
  std::string group, chain, seqId, insCode, residue, atom, element;
  double xyz[3];
};

/// A CIF value as text: quotes removed, '.' and '?' (not given) as empty.
inline std::string Value(const std::string& raw) {
  const std::string v = gemmi::cif::as_string(raw);
  return v == "." || v == "?" ? std::string() : v;
}

/// The coordinate of a row, or false (with error) when it is not a finite number.
inline bool Coordinate(const std::string& raw, const std::string& where, double& v, std::string& error) {
  const std::string text = Value(raw);
  char* end = nullptr;
  v = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size()) {
    error = where + "bad coordinate '" + text + "'";
    return false;
  }
  if (!std::isfinite(v)) {
    error = where + "coordinate is NaN or infinite";
    return false;
  }
  return true;
}

/// The skip rules and checks on the atom sites of the first block; fills sites and records.
inline bool FilterSites(const gemmi::cif::Document& doc, const std::string& name,
                        const StructureReadOptions& options, StructureReadResult& counts,
                        std::vector<KeptSite>& sites, std::vector<pdb_detail::KeptRecord>& records,
                        std::string& error) {
  if (doc.blocks.empty()) {
    error = "'" + name + "': no data block";
    return false;
  }
  gemmi::cif::Block& block = const_cast<gemmi::cif::Block&>(doc.blocks.front());
  std::string firstModel, firstAltLoc;
  std::size_t row = 0;
  for (auto site : block.find("_atom_site.", SiteColumns())) {
    ++row;
    const std::string where = "'" + name + "' atom site row " + std::to_string(row) + ": ";
    const std::string model = site.has(11) ? Value(site[11]) : std::string();
    if (row == 1) firstModel = model;
    if (model != firstModel) break; // the first model only
    KeptSite s;
    s.group = Value(site[0]);
    const bool hetatm = s.group == "HETATM";
    if (!hetatm && s.group != "ATOM") continue;
    for (int k = 0; k < 3; ++k)
      if (!Coordinate(site[8 + k], where, s.xyz[k], error)) return false;
    s.chain = Value(site[1]);
    s.seqId = Value(site[2]);
    s.insCode = site.has(3) ? Value(site[3]) : std::string();
    s.residue = Value(site[4]);
    s.atom = Value(site[5]);
    s.element = Value(site[7]);
    for (char& c : s.element) c = char(std::toupper(static_cast<unsigned char>(c)));
    const std::string altLoc = site.has(6) ? Value(site[6]) : std::string();
    if (SkippedByOptions(options, IsWaterResidue(s.residue), s.element == "H" || s.element == "D", hetatm,
                         counts))
      continue;
    if (!altLoc.empty() && !options.allAltLocs) {
      if (firstAltLoc.empty()) firstAltLoc = altLoc;
      if (altLoc != firstAltLoc) {
        ++counts.skippedAltLocs;
        continue;
      }
    }
    records.push_back({row, hetatm, s.element});
    sites.push_back(std::move(s));
  }
  return true;
}

} // namespace mmcif_detail

/// Reads the atoms of an mmCIF file's text (already decompressed); `name` is used in messages.
inline StructureReadResult ReadMmCif(const std::string& text, const std::string& name,
                                     const StructureReadOptions& options = {}) {
  using namespace mmcif_detail;
  StructureReadResult result;
  gemmi::cif::Document doc;
  try {
    doc = gemmi::cif::read_memory(text.data(), text.size(), name.c_str());
  } catch (const std::exception& e) {
    std::string what = e.what();
    return StructureReadResult::Failure("'" + name + "': not a valid CIF file (" +
                                        what.substr(0, what.find('\n')) + ")");
  }
  std::vector<KeptSite> sites;
  std::vector<pdb_detail::KeptRecord> records;
  std::string error;
  if (!FilterSites(doc, name, options, result, sites, records, error))
    return StructureReadResult::Failure(error);
  if (sites.empty()) return StructureReadResult::Failure("'" + name + "': no atoms (no atom site kept)");

  pdb_detail::CapturedFreesasaErrors errors;
  std::unique_ptr<freesasa_structure, void (*)(freesasa_structure*)> structure(freesasa_structure_new(),
                                                                               &freesasa_structure_free);
  if (!structure) return StructureReadResult::Failure("'" + name + "': freesasa: out of memory");
  const freesasa_classifier* classifier = pdb_detail::Classifier(options);
  for (const KeptSite& s : sites) {
    // The alternate location is chosen above; freesasa is given none, so it keeps every site.
    const freesasa_cif_atom atom = {s.group.c_str(),
                                    s.chain.empty() ? ' ' : s.chain[0],
                                    s.seqId.c_str(),
                                    s.insCode.empty() ? "?" : s.insCode.c_str(),
                                    s.residue.c_str(),
                                    s.atom.c_str(),
                                    ".",
                                    s.element.c_str(),
                                    s.xyz[0],
                                    s.xyz[1],
                                    s.xyz[2]};
    if (freesasa_structure_add_cif_atom(structure.get(), const_cast<freesasa_cif_atom*>(&atom), classifier,
                                        FREESASA_INCLUDE_HETATM | FREESASA_INCLUDE_HYDROGEN) == FREESASA_FAIL)
      return StructureReadResult::Failure("'" + name + "': freesasa: " + errors.FirstLine());
  }
  return pdb_detail::AtomsOfStructure(*structure, records, name, "atom site row", result);
}

} // namespace molremesh

// Atoms of a molecular structure as the surface builders need them: centre, radius, and enough of
// the record (element, residue, chain) to say which atom a message or a skip rule is about.
#pragma once

#include <vcg_ext/geometry/point.h>

#include <cctype>
#include <cstddef>
#include <string>
#include <vector>

namespace molremesh {

struct Atom {
  Point position;          ///< centre, in Å
  double radius = 0;       ///< van der Waals radius, in Å (from the file or the classifier)
  std::string name;        ///< atom name, e.g. "CA"
  std::string element;     ///< element symbol, e.g. "C" (may be empty for PQR files without one)
  std::string residueName; ///< e.g. "LYS"
  int residueNumber = 0;
  char chain = ' ';
  bool hetatm = false; ///< a HETATM record
};

/// Which atoms a reader keeps and where their radii come from.
struct StructureReadOptions {
  enum class Radii {
    ProtOr, ///< freesasa's ProtOr classifier (Tsai et al. 1999), the default for PDB and mmCIF
    Naccess ///< freesasa's NACCESS classifier
  };
  bool keepWaters = false; ///< HOH/WAT/... residues (crystal waters are not part of the molecule's surface)
  bool keepHydrogens = false;  ///< H and D atoms (X-ray structures rarely have them; PQR files always do)
  bool keepHetatm = true;      ///< ligands, ions, cofactors
  bool allAltLocs = false;     ///< every alternate location instead of the first one only
  Radii radii = Radii::ProtOr; ///< ignored for PQR files, whose radii are in the file
};

/// What a reader kept and skipped; on failure `ok` is false, `message` says why in one line
/// (with the line number where there is one) and `atoms` is empty.
struct StructureReadResult {
  bool ok = false;
  std::string message;
  std::vector<Atom> atoms;
  std::size_t skippedWaters = 0, skippedHydrogens = 0, skippedHetatm = 0, skippedAltLocs = 0;

  static StructureReadResult Failure(std::string why) {
    StructureReadResult r;
    r.message = std::move(why);
    return r;
  }
};

/// The skip rules every reader applies: true (and the count of its kind raised) for a water, a
/// hydrogen or a HETATM record that the options leave out. Alternate locations are the caller's.
inline bool SkippedByOptions(const StructureReadOptions& options, bool water, bool hydrogen, bool hetatm,
                             StructureReadResult& counts) {
  if (!options.keepWaters && water) return ++counts.skippedWaters, true;
  if (!options.keepHydrogens && hydrogen) return ++counts.skippedHydrogens, true;
  if (!options.keepHetatm && hetatm) return ++counts.skippedHetatm, true;
  return false;
}

/// Residue names of water molecules in PDB, PQR (pdb2pqr, AMBER, CHARMM) and mmCIF files.
inline bool IsWaterResidue(const std::string& residueName) {
  return residueName == "HOH" || residueName == "WAT" || residueName == "H2O" || residueName == "DOD" ||
         residueName == "SOL" || residueName == "TIP3" || residueName == "TIP" || residueName == "SPC";
}

/// Hydrogen (or deuterium) by element symbol, or by atom name when the element is missing (PQR).
inline bool IsHydrogenAtom(const std::string& element, const std::string& atomName) {
  if (!element.empty()) return element == "H" || element == "D";
  // PQR names: H, HA, HB2, 1HD1, HH11 ... ; a leading digit precedes the element letter.
  std::size_t i = 0;
  while (i < atomName.size() && std::isdigit(static_cast<unsigned char>(atomName[i]))) ++i;
  return i < atomName.size() && (atomName[i] == 'H' || atomName[i] == 'D');
}

} // namespace molremesh

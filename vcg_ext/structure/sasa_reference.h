// Solvent-accessible surface area of a set of atoms by freesasa (Lee-Richards or Shrake-Rupley),
// the reference the SAS mesh's area is checked against.
#pragma once

#include <vcg_ext/structure/atoms.h>

#include <freesasa.h>

#include <vector>

namespace molremesh {

struct SasaParams {
  double probeRadius = 1.4;  ///< Å, as the surfaces' default
  bool shrakeRupley = false; ///< false: Lee-Richards (freesasa's default)
  int resolution = 100;      ///< Lee-Richards slices per atom, or Shrake-Rupley points per atom
  int threads = 1;
};

/// Total SASA in Å², or a negative value when freesasa fails (no atoms, say).
inline double FreesasaArea(const std::vector<Atom>& atoms, const SasaParams& params = {}) {
  if (atoms.empty()) return -1;
  std::vector<double> xyz, radii;
  xyz.reserve(3 * atoms.size());
  radii.reserve(atoms.size());
  for (const Atom& a : atoms) {
    xyz.insert(xyz.end(), {a.position[0], a.position[1], a.position[2]});
    radii.push_back(a.radius);
  }
  freesasa_parameters p = freesasa_default_parameters;
  p.alg = params.shrakeRupley ? FREESASA_SHRAKE_RUPLEY : FREESASA_LEE_RICHARDS;
  p.probe_radius = params.probeRadius;
  if (params.shrakeRupley)
    p.shrake_rupley_n_points = params.resolution;
  else
    p.lee_richards_n_slices = params.resolution;
  p.n_threads = params.threads;
  freesasa_result* result = freesasa_calc_coord(xyz.data(), radii.data(), int(atoms.size()), &p);
  if (!result) return -1;
  const double total = result->total;
  freesasa_result_free(result);
  return total;
}

} // namespace molremesh

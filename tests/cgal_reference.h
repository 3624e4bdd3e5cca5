// CGAL's figures on the shared meshes (tests/data/cgal_reference.json, written by
// scripts/make_cgal_reference.py from a benchmark run), the tests' yardstick for "as good as CGAL".
#pragma once

#include <cmath>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

namespace molremesh::test {

/// CGAL's figures on `mesh` (its name without .ply), or null when the reference has none.
inline nlohmann::json CgalReference(const std::string& mesh) {
  std::ifstream in(MOLREMESH_CGAL_REFERENCE_JSON);
  if (!in) return {};
  const nlohmann::json all = nlohmann::json::parse(in);
  return all.contains(mesh) ? all[mesh] : nlohmann::json();
}

/// `x` rounded to `decimals` decimals, to compare a figure written in a test with the reference.
inline double Rounded(double x, int decimals) {
  const double scale = std::pow(10.0, decimals);
  return std::round(x * scale) / scale;
}

} // namespace molremesh::test

// Preconditions shared by every molremesh entry point (filters, CLI stages).
//
// Checked before anything touches the mesh, so a refused input is left exactly as it was.
#pragma once

#include <cmath>
#include <cstddef>
#include <string>

namespace molremesh {

/// Result of CheckTriangleMeshInput: ok, or a one-line message that says what is wrong.
struct InputCheck {
  bool ok = true;
  std::string message;
  std::size_t nonFiniteVertices = 0;
};

/// Accepts a mesh with at least one face and only finite vertex coordinates.
/// Empty meshes, point clouds and NaN/Inf coordinates are refused with a clear message;
/// everything else (non-manifold, open, degenerate, several components) is accepted and is
/// the business of the quality report or of the cleaning stage.
template <class MeshType>
InputCheck CheckTriangleMeshInput(const MeshType& m) {
  InputCheck check;
  if (m.vn == 0) {
    check.ok = false;
    check.message = "the mesh is empty (no vertices)";
    return check;
  }
  if (m.fn == 0) {
    check.ok = false;
    check.message = "the mesh has no faces (a point cloud of " + std::to_string(m.vn) +
                    " vertices); a triangle mesh is required";
    return check;
  }
  for (const auto& v : m.vert) {
    if (v.IsD()) continue;
    const auto& p = v.cP();
    if (!std::isfinite(double(p[0])) || !std::isfinite(double(p[1])) || !std::isfinite(double(p[2])))
      ++check.nonFiniteVertices;
  }
  if (check.nonFiniteVertices > 0) {
    check.ok = false;
    check.message = "the mesh has " + std::to_string(check.nonFiniteVertices) +
                    " vertices with NaN or infinite coordinates; remove or repair them first";
  }
  return check;
}

} // namespace molremesh

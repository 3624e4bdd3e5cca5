// The mean edge length of a mesh: the default target edge length L of every stage.
#pragma once

#include <vcg_ext/geometry/point.h>

#include <cstddef>

namespace molremesh {

/// Mean length of the face sides of m (deleted faces skipped; 0 without a face). Interior edges
/// count twice and border edges once, so on a closed mesh it is the mean over distinct edges
/// (MeshQuality's figure). skipCollapsedSides leaves out the sides whose two ends are the same
/// vertex (faces with a repeated corner, which only a raw input has): the cleaning stage's scale.
template <class MeshType>
double MeanEdgeLength(const MeshType& m, bool skipCollapsedSides = false) {
  double sum = 0;
  std::size_t n = 0;
  for (const auto& f : m.face) {
    if (f.IsD()) continue;
    for (int e = 0; e < 3; ++e) {
      if (skipCollapsedSides && f.cV(e) == f.cV((e + 1) % 3)) continue;
      sum += (PositionOf(f.cV(e)) - PositionOf(f.cV((e + 1) % 3))).Norm();
      ++n;
    }
  }
  return n ? sum / double(n) : 0.0;
}

} // namespace molremesh

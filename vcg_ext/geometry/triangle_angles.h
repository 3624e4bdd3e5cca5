// Triangle angle figures shared by the local stages (small-angle elimination, obtuse reduction,
// local smoothing): the smallest and largest angle of a triangle, a tally of them over a set of
// triangles.
//
// Everything is computed in double precision whatever the mesh's scalar type, so a float mesh
// (MeshLab's CMeshO) and a double mesh take the same decisions. The stages compare these angles
// against their thresholds to choose and accept edits: changing a formula here changes their
// output, so the formulas are kept exactly as the stages were validated with.
#pragma once

#include <vcg_ext/core/parallel_for.h>
#include <vcg_ext/geometry/point.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

namespace molremesh {

/// Smallest and largest angle (degrees) of triangle (a, b, c), by the law of cosines on the
/// squared side lengths (one square root per corner). A corner with a zero-length side gets 0.
inline void TriangleAngleRange(const vcg::Point3d& a, const vcg::Point3d& b, const vcg::Point3d& c,
                               double& minDeg, double& maxDeg) {
  const double la = (b - c).SquaredNorm(), lb = (c - a).SquaredNorm(), lc = (a - b).SquaredNorm();
  auto at = [](double opposite, double s1, double s2) {
    const double d = 2.0 * std::sqrt(s1 * s2);
    return d > 0 ? std::acos(std::clamp((s1 + s2 - opposite) / d, -1.0, 1.0)) * (180.0 / kPi) : 0.0;
  };
  const double A = at(la, lb, lc), B = at(lb, lc, la), C = at(lc, la, lb);
  minDeg = std::min({A, B, C});
  maxDeg = std::max({A, B, C});
}

/// Smallest and largest angle (degrees) of face f (TriangleAngleRange of its corners).
template <class FaceType>
void FaceAngleRange(const FaceType& f, double& minDeg, double& maxDeg) {
  TriangleAngleRange(PositionOf(f.cV(0)), PositionOf(f.cV(1)), PositionOf(f.cV(2)), minDeg, maxDeg);
}

/// FaceAngleRange of every face of m, indexed like m.face ({180, 0} for a deleted face: no angle),
/// computed on `threads` threads (0 = all cores). The values are exactly the serial ones: the
/// stages scan the whole mesh with this before and after their edits, and their rounds select
/// faces from it.
template <class MeshType>
void FaceAngleRanges(const MeshType& m, int threads, std::vector<std::array<double, 2>>& ranges) {
  ranges.resize(m.face.size());
  ParallelFor(m.face.size(), threads, [&](std::size_t begin, std::size_t end, int) {
    for (std::size_t fi = begin; fi < end; ++fi) {
      ranges[fi] = {180.0, 0.0};
      if (!m.face[fi].IsD()) FaceAngleRange(m.face[fi], ranges[fi][0], ranges[fi][1]);
    }
  });
}

/// Worst angles of a set of triangles and how many of them have an angle below a threshold: what
/// the local stages judge the region of an edit by, before and after it.
struct AngleTally {
  double minDeg = 180.0, maxDeg = 0.0; ///< smallest and largest angle so far (degrees)
  int small = 0;                       ///< triangles with an angle below the threshold
  void Add(const vcg::Point3d& a, const vcg::Point3d& b, const vcg::Point3d& c, double threshold) {
    double lo, hi;
    TriangleAngleRange(a, b, c, lo, hi);
    minDeg = std::min(minDeg, lo);
    maxDeg = std::max(maxDeg, hi);
    if (lo < threshold) ++small;
  }
};

} // namespace molremesh

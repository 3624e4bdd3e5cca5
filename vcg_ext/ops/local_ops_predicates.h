// Geometric predicates of the guarded local edits: the separating-plane shortcut in front of
// MeshQuality's exact intersection test, the simple-fan test of a vertex star and a face's unit
// normal. Evaluated in double precision (molremesh::Point).
#pragma once

#include <vcg_ext/geometry/point.h>
#include <vcg_ext/geometry/triangle_intersection.h>

#include <array>
#include <cmath>
#include <utility>

namespace molremesh {

namespace local_ops_detail {

/// True when every corner of q but `skip` (-1: none) lies strictly on one side of the plane
/// through `origin` with unit normal n, farther than margin.
inline bool SeparatedByPlane(const Point& n, const Point& origin, const std::array<Point, 3>& q, int skip,
                             double margin) {
  if (!(n.SquaredNorm() > 0)) return false;
  int sign = 0;
  for (int k = 0; k < 3; ++k) {
    if (k == skip) continue;
    const double d = n * (q[k] - origin);
    const int s = d > margin ? 1 : d < -margin ? -1 : 0;
    if (s == 0 || (sign != 0 && s != sign)) return false;
    sign = s;
  }
  return true;
}

/// Whether two faces meet the way MeshQuality counts a self-intersection: faces sharing no
/// vertex meet at all, faces sharing one vertex meet anywhere else; faces sharing an edge are
/// never reported (folds are a separate check). A separating-plane test with a margin far
/// above rounding noise settles almost every pair before the exact predicates run; it only
/// answers "apart" when MeshQuality's predicates would too. (Faces sharing one vertex whose
/// star is a simple fan never meet, see StarIsSimpleFan: the batch sweep skips them.)
template <class VertexPointer>
bool FacesIntersect(const std::array<Point, 3>& a, const Point& na, const std::array<VertexPointer, 3>& va,
                    const std::array<Point, 3>& b, const Point& nb, const std::array<VertexPointer, 3>& vb,
                    double margin) {
  int shared = 0, ca = -1, cb = -1;
  for (int x = 0; x < 3; ++x)
    for (int y = 0; y < 3; ++y)
      if (va[x] == vb[y]) ++shared, ca = x, cb = y;
  if (shared >= 2) return false;
  if (shared == 0) {
    if (SeparatedByPlane(na, a[0], b, -1, margin) || SeparatedByPlane(nb, b[0], a, -1, margin)) return false;
    return TrianglesIntersect(MakePlanarTriangle(a[0], a[1], a[2]), MakePlanarTriangle(b[0], b[1], b[2]));
  }
  if (SeparatedByPlane(na, a[ca], b, cb, margin) || SeparatedByPlane(nb, b[cb], a, ca, margin)) return false;
  return SharedCornerOverlap(MakePlanarTriangle(a[0], a[1], a[2]), ca, MakePlanarTriangle(b[0], b[1], b[2]),
                             cb);
}

/// Whether the star of a vertex at `center`, given as its link edges (a_i, b_i) in the faces'
/// orientation, projects along its mean normal onto a simple fan: every face positively
/// oriented (with margin) and the angles at the center summing to exactly one turn (less than
/// one on the boundary). Then two faces of the star that share only the center meet nowhere
/// else: their projections lie in disjoint wedges, and a common point would project onto the
/// center, which only the center itself does (no face is parallel to the projection direction).
inline bool StarIsSimpleFan(const Point& center, const std::pair<Point, Point>* link, int count,
                            bool boundary) {
  if (count < 1) return false;
  Point d(0, 0, 0);
  for (int i = 0; i < count; ++i) d += (link[i].first - center) ^ (link[i].second - center);
  const double len = d.Norm();
  if (!(len > 0)) return false;
  d /= len;
  // Every wedge positively oriented. Around an interior vertex the link is a closed cycle, so
  // the wedge angles then sum to 2 pi k (k turns); k = 1 is certain when an upper bound of the
  // sum, pi sqrt((1 - cos)/2) >= the angle per wedge, stays below 4 pi, which spares the atan2
  // of every wedge in all but the strangest stars.
  double halfTurnsBound = 0;
  for (int i = 0; i < count; ++i) {
    const Point u = link[i].first - center, v = link[i].second - center;
    // Components orthogonal to d.
    const Point pu = u - d * (u * d), pv = v - d * (v * d);
    const double cross = (pu ^ pv) * d, norms = pu.Norm() * pv.Norm();
    if (!(cross > 1e-6 * norms)) return false; // positively oriented, not flat
    halfTurnsBound += std::sqrt(std::max(0.0, 0.5 * (1.0 - (pu * pv) / norms)));
  }
  if (!boundary && halfTurnsBound < 4.0) return true;
  double turn = 0;
  for (int i = 0; i < count; ++i) {
    const Point u = link[i].first - center, v = link[i].second - center;
    const Point pu = u - d * (u * d), pv = v - d * (v * d);
    turn += std::atan2((pu ^ pv) * d, pu * pv);
  }
  const double twoPi = 2.0 * kPi;
  return boundary ? turn < twoPi - 1e-6 : std::fabs(turn - twoPi) < 1e-6;
}

inline Point UnitNormal(const std::array<Point, 3>& p) {
  const Point n = (p[1] - p[0]) ^ (p[2] - p[0]);
  const double len = n.Norm();
  return len > 0 ? n / len : Point(0, 0, 0);
}

} // namespace local_ops_detail

} // namespace molremesh

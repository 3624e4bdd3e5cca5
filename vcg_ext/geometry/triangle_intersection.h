// Closed triangle/triangle intersection tests in double precision, the one set of predicates that
// the quality report, the cleaning stage and the guarded edits all judge self-intersections by.
//
// Both tests reduce to "closed segment meets closed triangle": two triangles meet iff an edge of
// one meets the other (the intersection is convex and its extreme points lie on edges). Plane
// sides are signed distances snapped to 0 within rounding noise, so that exactly coplanar inputs
// (flat patches) take the 2D branch instead of a numerically meaningless line crossing.
#pragma once

#include <vcg_ext/geometry/point.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace molremesh {

// Both tests reduce to "closed segment meets closed triangle": two triangles meet iff an edge of
// one meets the other (the intersection is convex and its extreme points lie on edges). Plane
// sides are signed distances snapped to 0 within rounding noise, so that exactly coplanar inputs
// (flat patches) take the 2D branch instead of a numerically meaningless line crossing.

/// Triangle with its plane and the axis dropped to project it to 2D.
struct PlanarTriangle {
  std::array<Point, 3> p;
  Point unitNormal;
  int axisU = 0, axisV = 1; ///< coordinates kept by the 2D projection
};

inline PlanarTriangle MakePlanarTriangle(const Point& a, const Point& b, const Point& c) {
  PlanarTriangle t;
  t.p = {a, b, c};
  const Point n = (b - a) ^ (c - a);
  const double len = n.Norm();
  t.unitNormal = len > 0 ? n / len : Point(0, 0, 0);
  int drop = 0;
  if (std::fabs(n[1]) > std::fabs(n[drop])) drop = 1;
  if (std::fabs(n[2]) > std::fabs(n[drop])) drop = 2;
  t.axisU = (drop + 1) % 3;
  t.axisV = (drop + 2) % 3;
  return t;
}

inline double Orient2D(const Point& a, const Point& b, const Point& c, int u, int v) {
  return (b[u] - a[u]) * (c[v] - a[v]) - (b[v] - a[v]) * (c[u] - a[u]);
}

/// Closed point-in-triangle test in the triangle's 2D projection.
inline bool PointInTriangle2D(const PlanarTriangle& t, const Point& x) {
  const double d0 = Orient2D(t.p[0], t.p[1], x, t.axisU, t.axisV);
  const double d1 = Orient2D(t.p[1], t.p[2], x, t.axisU, t.axisV);
  const double d2 = Orient2D(t.p[2], t.p[0], x, t.axisU, t.axisV);
  return (d0 >= 0 && d1 >= 0 && d2 >= 0) || (d0 <= 0 && d1 <= 0 && d2 <= 0);
}

/// Closed segment/segment test in 2D (coordinates u, v).
inline bool SegmentsMeet2D(const Point& p, const Point& q, const Point& a, const Point& b, int u, int v) {
  const double o1 = Orient2D(p, q, a, u, v), o2 = Orient2D(p, q, b, u, v);
  const double o3 = Orient2D(a, b, p, u, v), o4 = Orient2D(a, b, q, u, v);
  if ((o1 > 0 && o2 > 0) || (o1 < 0 && o2 < 0)) return false;
  if ((o3 > 0 && o4 > 0) || (o3 < 0 && o4 < 0)) return false;
  if ((o1 == 0 && o2 == 0) || (o3 == 0 && o4 == 0)) {
    // Collinear: the segments meet iff their extents overlap on both axes.
    for (int axis : {u, v})
      if (std::max(p[axis], q[axis]) < std::min(a[axis], b[axis]) ||
          std::max(a[axis], b[axis]) < std::min(p[axis], q[axis]))
        return false;
  }
  return true;
}

/// Signed distance of x from the plane of t, snapped to 0 when it is within rounding noise, so
/// that exactly coplanar inputs (flat patches) take the 2D branch. It is measured from the corner
/// nearest to x: measuring from a far corner (a fan around a vertex sent far away) would lose to
/// cancellation all the digits that tell neighbouring faces apart. The snap threshold scales with
/// the magnitude of the coordinates involved, which bounds their rounding error; erring small
/// is safe (a missed snap only costs the exact 2D answer, never invents an intersection).
inline double PlaneDistance(const PlanarTriangle& t, const Point& x) {
  int nearest = 0;
  double best = (x - t.p[0]).SquaredNorm();
  for (int k = 1; k < 3; ++k) {
    const double d2 = (x - t.p[k]).SquaredNorm();
    if (d2 < best) best = d2, nearest = k;
  }
  const double d = t.unitNormal * (x - t.p[nearest]);
  const double tol = 1e-13 * (MaxAbs(x) + MaxAbs(t.p[nearest]));
  return std::fabs(d) <= tol ? 0.0 : d;
}

/// Closed segment pq against closed triangle t.
inline bool SegmentMeetsTriangle(const Point& p, const Point& q, const PlanarTriangle& t) {
  const double dp = PlaneDistance(t, p), dq = PlaneDistance(t, q);
  if ((dp > 0 && dq > 0) || (dp < 0 && dq < 0)) return false;
  if (dp == 0 && dq == 0) {
    if (PointInTriangle2D(t, p) || PointInTriangle2D(t, q)) return true;
    for (int i = 0; i < 3; ++i)
      if (SegmentsMeet2D(p, q, t.p[i], t.p[(i + 1) % 3], t.axisU, t.axisV)) return true;
    return false;
  }
  // Exactly one crossing point of the plane; it is inside the segment by the sign test.
  const Point x = p + (q - p) * (dp / (dp - dq));
  return PointInTriangle2D(t, x);
}

/// True when every vertex of `other` is strictly on the same side of t's plane.
inline bool StrictlyOnOneSide(const PlanarTriangle& t, const PlanarTriangle& other) {
  const double d0 = PlaneDistance(t, other.p[0]);
  const double d1 = PlaneDistance(t, other.p[1]);
  const double d2 = PlaneDistance(t, other.p[2]);
  return (d0 > 0 && d1 > 0 && d2 > 0) || (d0 < 0 && d1 < 0 && d2 < 0);
}

/// Closed triangle/triangle intersection (for faces sharing no vertex).
inline bool TrianglesIntersect(const PlanarTriangle& a, const PlanarTriangle& b) {
  if (StrictlyOnOneSide(a, b) || StrictlyOnOneSide(b, a)) return false;
  for (int i = 0; i < 3; ++i) {
    if (SegmentMeetsTriangle(b.p[i], b.p[(i + 1) % 3], a)) return true;
    if (SegmentMeetsTriangle(a.p[i], a.p[(i + 1) % 3], b)) return true;
  }
  return false;
}

/// Triangles sharing exactly the corner a.p[ca] == b.p[cb]: true when they meet anywhere else.
/// Their intersection is a convex set containing the shared corner; it holds another point iff
/// the edge opposite the shared corner of one triangle meets the other (that edge does not
/// contain the shared corner, so the trivial contact is never reported).
inline bool SharedCornerOverlap(const PlanarTriangle& a, int ca, const PlanarTriangle& b, int cb) {
  return SegmentMeetsTriangle(a.p[(ca + 1) % 3], a.p[(ca + 2) % 3], b) ||
         SegmentMeetsTriangle(b.p[(cb + 1) % 3], b.p[(cb + 2) % 3], a);
}

} // namespace molremesh

// Shape figures of one triangle (area, quality Q, aspect ratio, angles), in double precision.
//
// The quality report measures every face with ShapeOf; the formulas are chosen for accuracy on
// the needles and caps of raw molecular meshes (Heron's product without cancellation, angles by
// atan2), and the reported figures depend on them bit for bit.
#pragma once

#include <vcg_ext/geometry/point.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace molremesh {

struct TriangleShape {
  bool degenerate = true;
  double area = 0;
  double q = 0;
  double aspectRatio = std::numeric_limits<double>::infinity();
  std::array<double, 3> angles{0.0, 0.0, 180.0};
};

/// Shape of the triangle (p0, p1, p2); degenerate when the area is <= degenerateArea or a corner
/// is not finite. The area is returned even for degenerate (finite) triangles.
inline TriangleShape ShapeOf(const Point& p0, const Point& p1, const Point& p2, double degenerateArea) {
  TriangleShape s;
  if (!IsFinite(p0) || !IsFinite(p1) || !IsFinite(p2)) return s;
  const std::array<Point, 3> p{p0, p1, p2};
  std::array<double, 3> len{}; // len[i] = edge opposite corner i
  for (int i = 0; i < 3; ++i) len[i] = (p[(i + 2) % 3] - p[(i + 1) % 3]).Norm();
  s.area = 0.5 * ((p1 - p0) ^ (p2 - p0)).Norm();
  if (!(s.area > degenerateArea) || !std::isfinite(s.area)) return s;

  s.degenerate = false;
  const double halfPerimeter = 0.5 * (len[0] + len[1] + len[2]);
  const double longest = std::max({len[0], len[1], len[2]});
  s.q = (6.0 / std::sqrt(3.0)) * s.area / (halfPerimeter * longest);
  // (s-a)(s-b)(s-c) = A^2 / s (Heron): avoids the cancellation of s-a on needle triangles.
  s.aspectRatio = len[0] * len[1] * len[2] * halfPerimeter / (8.0 * s.area * s.area);
  for (int i = 0; i < 3; ++i) {
    // atan2(|u x v|, u.v) stays accurate near 0 and 180 degrees, where acos loses digits.
    const Point u = p[(i + 1) % 3] - p[i];
    const Point v = p[(i + 2) % 3] - p[i];
    s.angles[i] = std::atan2((u ^ v).Norm(), u * v) * (180.0 / kPi);
  }
  return s;
}

} // namespace molremesh

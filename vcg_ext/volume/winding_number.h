// The generalized winding number of a triangle mesh at a point (Jacobson et al. 2013): the sum of
// the signed solid angles its triangles subtend, over 4 pi. Inside a closed, outward-oriented
// surface it is 1, outside 0, inside a cavity 0; where closed surfaces overlap it counts them, and
// on a soup, a surface with cracks or a few flipped faces it degrades gracefully instead of
// flipping like a ray-parity test. Unlike a flood fill from outside, it tells a cavity (a closed
// sheet facing into the void) from an enclosed region of the molecule.
#pragma once

#include <vcg_ext/core/parallel_for.h>
#include <vcg_ext/geometry/point.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

namespace molremesh {

/// Signed solid angle of triangle (a, b, c) seen from p, in [-2 pi, 2 pi]: positive when p sees
/// the triangle's back (p on the side its normal points away from). Van Oosterom and Strackee's
/// formula; 0 for a degenerate triangle or p on the triangle's plane.
inline double SolidAngle(const Point& p, const Point& a, const Point& b, const Point& c) {
  const Point x = a - p, y = b - p, z = c - p;
  const double lx = x.Norm(), ly = y.Norm(), lz = z.Norm();
  const double numerator = x * (y ^ z);
  const double denominator = lx * ly * lz + (x * y) * lz + (y * z) * lx + (z * x) * ly;
  if (numerator == 0 && denominator <= 0) return 0; // p on the triangle
  return 2.0 * std::atan2(numerator, denominator);
}

/// Indexed triangles in double precision, the input of WindingNumbers.
struct TriangleSet {
  std::vector<Point> points;
  std::vector<std::array<std::size_t, 3>> triangles;
};

/// Winding number of the triangles at each query point (a brute-force sum: O(triangles) per point,
/// for the few hundred points of a region classification). Summed in triangle order per point, so
/// the figures do not depend on the thread count.
inline std::vector<double> WindingNumbers(const TriangleSet& set, const std::vector<Point>& queries,
                                          int threads) {
  constexpr double kFourPi = 4.0 * kPi;
  std::vector<double> w(queries.size(), 0.0);
  ParallelFor(
      queries.size(), threads,
      [&](std::size_t begin, std::size_t end, int) {
        for (std::size_t q = begin; q < end; ++q) {
          double sum = 0;
          for (const auto& t : set.triangles)
            sum += SolidAngle(queries[q], set.points[t[0]], set.points[t[1]], set.points[t[2]]);
          w[q] = sum / kFourPi;
        }
      },
      1);
  return w;
}

} // namespace molremesh

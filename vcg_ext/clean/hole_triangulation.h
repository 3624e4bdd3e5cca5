// Minimum-weight triangulation of a hole's boundary polygon (Liepa 2003), with forbidden triangles.
//
// Reusable on its own: it works on the polygon's points and the unit normals of the faces along its
// sides only, knows nothing of a mesh, and lets the caller veto diagonals (diagonalOk) and whole
// triangles (forbidden), which is how CleanRawMesh re-triangulates after a fill triangle fails its
// checks. The weight, compared lexicographically with a 1e-3 tolerance, is: the largest dihedral
// angle between adjacent triangles (and against the faces along the sides), then the smallest
// triangle angle, then the area. O(n^3) time, O(n^2) memory for an n-sided polygon.
#pragma once

#include <vcg/space/point3.h>

#include <vcg_ext/geometry/point.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_set>
#include <utility>
#include <vector>

namespace molremesh {
namespace hole_triangulation {

inline double TriArea(const Point& a, const Point& b, const Point& c) {
  return 0.5 * ((b - a) ^ (c - a)).Norm();
}
inline Point UnitNormal(const Point& a, const Point& b, const Point& c) {
  Point n = (b - a) ^ (c - a);
  const double len = n.Norm();
  return len > 0 ? n / len : Point(0, 0, 0);
}
/// Smallest angle (radians) of triangle abc.
inline double MinAngle(const Point& a, const Point& b, const Point& c) {
  const std::array<Point, 3> p{a, b, c};
  double best = kPi;
  for (int i = 0; i < 3; ++i) {
    const Point u = p[(i + 1) % 3] - p[i], v = p[(i + 2) % 3] - p[i];
    best = std::min(best, std::atan2((u ^ v).Norm(), u * v));
  }
  return best;
}
inline double AngleBetween(const Point& a, const Point& b) {
  if (a.SquaredNorm() == 0 || b.SquaredNorm() == 0) return 0; // undefined: do not constrain
  return std::acos(std::clamp(a * b, -1.0, 1.0));
}
struct Weight {
  double dihedral = 0;   ///< largest dihedral angle (radians) between adjacent triangles
  double minAngle = kPi; ///< smallest triangle angle (radians)
  double area = 0;
};
inline bool Better(const Weight& a, const Weight& b) {
  if (std::fabs(a.dihedral - b.dihedral) > 1e-3) return a.dihedral < b.dihedral;
  if (std::fabs(a.minAngle - b.minAngle) > 1e-3) return a.minAngle > b.minAngle;
  return a.area < b.area;
}

/// Polygon p[0..n-1] whose side i (p[i] -> p[i+1]) is a boundary half-edge of a face with unit normal
/// outer[i]. Fills `tris` with local corner triples (i, m, j), i < m < j; the mesh face is
/// (p[j], p[m], p[i]) so that it runs every side the opposite way of its boundary face.
/// diagonalOk(i, j) says whether the diagonal may be created; forbidden holds keys of triangles
/// rejected by validation. False when no admissible triangulation exists.
template <class DiagonalOk>
bool Triangulate(const std::vector<Point>& p, const std::vector<Point>& outer, DiagonalOk diagonalOk,
                 const std::unordered_set<std::uint64_t>& forbidden, double minArea, double maxDihedral,
                 std::vector<std::array<int, 3>>& tris) {
  const int n = int(p.size());
  tris.clear();
  if (n < 3) return false;
  auto key = [n](int i, int k, int j) { return (std::uint64_t(i) * n + k) * n + j; };
  auto normalOf = [&p](int i, int k, int j) { return UnitNormal(p[j], p[k], p[i]); };
  std::vector<Weight> w(std::size_t(n) * n);
  std::vector<int> split(std::size_t(n) * n, -1); // -1: not computed/invalid
  auto at = [n](int i, int j) { return std::size_t(i) * n + j; };
  for (int i = 0; i + 1 < n; ++i) split[at(i, i + 1)] = -2; // a side: nothing to fill
  for (int len = 2; len < n; ++len) {
    for (int i = 0; i + len < n; ++i) {
      const int j = i + len;
      if (!(i == 0 && j == n - 1) && !diagonalOk(i, j)) continue;
      Weight best;
      int bestK = -1;
      for (int k = i + 1; k < j; ++k) {
        if (split[at(i, k)] == -1 || split[at(k, j)] == -1) continue;
        if (forbidden.count(key(i, k, j))) continue;
        const double area = TriArea(p[j], p[k], p[i]);
        if (!(area > minArea)) continue;
        const Point nt = normalOf(i, k, j);
        const Point n1 = (k == i + 1) ? outer[i] : normalOf(i, split[at(i, k)], k);
        const Point n2 = (j == k + 1) ? outer[k] : normalOf(k, split[at(k, j)], j);
        double dihedral = std::max(AngleBetween(nt, n1), AngleBetween(nt, n2));
        if (i == 0 && j == n - 1) dihedral = std::max(dihedral, AngleBetween(nt, outer[n - 1]));
        if (dihedral > maxDihedral) continue;
        Weight cand;
        const Weight& a = w[at(i, k)];
        const Weight& b = w[at(k, j)];
        cand.dihedral = std::max({a.dihedral, b.dihedral, dihedral});
        cand.minAngle = std::min({a.minAngle, b.minAngle, MinAngle(p[i], p[k], p[j])});
        cand.area = a.area + b.area + area;
        if (bestK < 0 || Better(cand, best)) {
          best = cand;
          bestK = k;
        }
      }
      if (bestK >= 0) {
        w[at(i, j)] = best;
        split[at(i, j)] = bestK;
      }
    }
  }
  if (split[at(0, n - 1)] < 0) return false;
  std::vector<std::pair<int, int>> stack{{0, n - 1}};
  while (!stack.empty()) {
    const auto [i, j] = stack.back();
    stack.pop_back();
    if (j - i < 2) continue;
    const int k = split[at(i, j)];
    tris.push_back({i, k, j});
    stack.emplace_back(i, k);
    stack.emplace_back(k, j);
  }
  return true;
}

} // namespace hole_triangulation
} // namespace molremesh

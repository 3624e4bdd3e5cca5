// Triangles bucketed by their shadow along one direction: the candidates a ray of that direction
// may cross.
//
// Counting how often a ray crosses a component (the inside test of a point) against every face
// costs the component's face count per ray; a molecular surface of a million faces with hundreds
// of enclosed pieces then spends most of the cleaning there. Projected on the plane across the
// ray's direction, the ray is a point and only the triangles whose shadow covers it can be
// crossed: here each triangle is listed in the cells of a uniform 2D grid its shadow's bounding
// box (widened by a small tolerance) overlaps, so Candidates(origin) returns a superset of the
// faces the ray can meet, in increasing order of their index. A crossing test over the candidates
// then decides exactly as over all the faces.
#pragma once

#include <vcg_ext/geometry/point.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace molremesh {

class ProjectedFaceGrid {
public:
  /// Shadows widened by this x the triangle's longest edge (the crossing tests accept
  /// barycentric coordinates slightly outside [0, 1]).
  static constexpr double kWidening = 1e-6;
  /// Bound on the grid's side, in cells (memory: at most about 2 cells per triangle anyway).
  static constexpr double kMaxCellsPerSide = 4000;

  /// `count` triangles, triangle i's corners given by corners(i) as std::array<Point, 3>;
  /// `direction` need not be unit. About two shadows per cell on average.
  template <class Corners>
  ProjectedFaceGrid(std::size_t count, const Corners& corners, const Point& direction) {
    Basis(direction);
    if (count == 0) return;
    double x0 = HUGE_VAL, y0 = HUGE_VAL, x1 = -HUGE_VAL, y1 = -HUGE_VAL, area = 0;
    for (std::size_t i = 0; i < count; ++i) {
      const std::array<double, 4> b = Shadow(corners(i));
      x0 = std::min(x0, b[0]), y0 = std::min(y0, b[1]), x1 = std::max(x1, b[2]), y1 = std::max(y1, b[3]);
      area += (b[2] - b[0]) * (b[3] - b[1]);
    }
    origin_ = {x0, y0};
    cell_ = std::sqrt(std::max(area, (x1 - x0) * (y1 - y0) / 4.0) / (0.5 * double(count)));
    cell_ = std::max({cell_, (x1 - x0) / kMaxCellsPerSide, (y1 - y0) / kMaxCellsPerSide});
    if (!(cell_ > 0)) cell_ = 1;
    nx_ = std::size_t((x1 - x0) / cell_) + 1;
    ny_ = std::size_t((y1 - y0) / cell_) + 1;
    Fill(count, corners);
  }

  /// Indices of the triangles whose widened shadow holds the projection of p, increasing.
  std::pair<const std::uint32_t*, const std::uint32_t*> Candidates(const Point& p) const {
    if (start_.empty()) return {nullptr, nullptr};
    const double x = p * u_, y = p * v_;
    const long cx = long(std::floor((x - origin_[0]) / cell_)),
               cy = long(std::floor((y - origin_[1]) / cell_));
    if (cx < 0 || cy < 0 || cx >= long(nx_) || cy >= long(ny_)) return {nullptr, nullptr};
    const std::size_t c = std::size_t(cy) * nx_ + std::size_t(cx);
    return {faces_.data() + start_[c], faces_.data() + start_[c + 1]};
  }

private:
  void Basis(const Point& direction) {
    const Point d = direction / direction.Norm();
    const Point helper = std::fabs(d[0]) < 0.9 ? Point(1, 0, 0) : Point(0, 1, 0);
    u_ = (d ^ helper).Normalize();
    v_ = d ^ u_;
  }

  std::array<double, 4> Shadow(const std::array<Point, 3>& t) const {
    std::array<double, 4> b{HUGE_VAL, HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    double longest = 0;
    for (int k = 0; k < 3; ++k) {
      const double x = t[k] * u_, y = t[k] * v_;
      b[0] = std::min(b[0], x), b[1] = std::min(b[1], y), b[2] = std::max(b[2], x), b[3] = std::max(b[3], y);
      longest = std::max(longest, (t[k] - t[(k + 1) % 3]).Norm());
    }
    const double w = kWidening * longest + 1e-12 * (std::fabs(b[2]) + std::fabs(b[3]) + 1);
    return {b[0] - w, b[1] - w, b[2] + w, b[3] + w};
  }

  /// The cell range a box covers, clamped to the grid.
  void Range(const std::array<double, 4>& b, std::size_t& cx0, std::size_t& cy0, std::size_t& cx1,
             std::size_t& cy1) const {
    auto clampTo = [](double t, std::size_t n) {
      return std::size_t(std::min(std::max(t, 0.0), double(n - 1)));
    };
    cx0 = clampTo(std::floor((b[0] - origin_[0]) / cell_), nx_),
    cx1 = clampTo(std::floor((b[2] - origin_[0]) / cell_), nx_);
    cy0 = clampTo(std::floor((b[1] - origin_[1]) / cell_), ny_),
    cy1 = clampTo(std::floor((b[3] - origin_[1]) / cell_), ny_);
  }

  /// Counting sort of (cell, triangle) into start_ / faces_: each cell's list in triangle order.
  /// The shadows are projected again in each pass rather than stored (memory).
  template <class Corners>
  void Fill(std::size_t count, const Corners& corners) {
    start_.assign(nx_ * ny_ + 1, 0);
    std::size_t cx0, cy0, cx1, cy1;
    for (std::size_t i = 0; i < count; ++i) {
      Range(Shadow(corners(i)), cx0, cy0, cx1, cy1);
      for (std::size_t y = cy0; y <= cy1; ++y)
        for (std::size_t x = cx0; x <= cx1; ++x) ++start_[y * nx_ + x + 1];
    }
    for (std::size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
    faces_.resize(start_.back());
    std::vector<std::uint32_t> next(start_.begin(), start_.end() - 1);
    for (std::size_t i = 0; i < count; ++i) {
      Range(Shadow(corners(i)), cx0, cy0, cx1, cy1);
      for (std::size_t y = cy0; y <= cy1; ++y)
        for (std::size_t x = cx0; x <= cx1; ++x) faces_[next[y * nx_ + x]++] = std::uint32_t(i);
    }
  }

  Point u_, v_;
  std::array<double, 2> origin_{0, 0};
  double cell_ = 1;
  std::size_t nx_ = 0, ny_ = 0;
  std::vector<std::uint32_t> start_, faces_;
};

} // namespace molremesh

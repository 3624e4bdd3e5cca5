// A bounding box in single precision that contains the double box it was made from.
//
// The face grids of the remeshing stages keep one box per face and test millions of pairs of
// them; in float they take half the memory and cache. Each bound is rounded outward, so a stored
// box always contains the true one: two faces whose true boxes touch always touch as FloatBoxes
// (a few more pairs may touch after rounding; the exact tests after the box test reject them).
#pragma once

#include <vcg/space/box3.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>

namespace molremesh {

struct FloatBox {
  std::array<float, 3> lo{}, hi{};

  static FloatBox Outward(const vcg::Box3d& b) {
    FloatBox r;
    for (int k = 0; k < 3; ++k) {
      float lo = float(b.min[k]), hi = float(b.max[k]);
      if (double(lo) > b.min[k]) lo = NextDown(lo);
      if (double(hi) < b.max[k]) hi = NextUp(hi);
      r.lo[k] = lo;
      r.hi[k] = hi;
    }
    return r;
  }
  /// std::nextafter(x, -inf) and std::nextafter(x, +inf) for a non-NaN x, inline: the grids
  /// round millions of boxes per pass, and the library call dominated that.
  static float NextDown(float x) {
    if (x == 0.0f) return -std::numeric_limits<float>::denorm_min();
    if (x == -std::numeric_limits<float>::infinity()) return x;
    std::uint32_t bits;
    std::memcpy(&bits, &x, sizeof bits);
    bits = x > 0.0f ? bits - 1 : bits + 1;
    std::memcpy(&x, &bits, sizeof bits);
    return x;
  }
  static float NextUp(float x) { return -NextDown(-x); }
  bool Touches(const FloatBox& o) const {
    return lo[0] <= o.hi[0] && o.lo[0] <= hi[0] && lo[1] <= o.hi[1] && o.lo[1] <= hi[1] && lo[2] <= o.hi[2] &&
           o.lo[2] <= hi[2];
  }
  /// Whether this box touches the double box b.
  bool Touches(const vcg::Box3d& b) const {
    for (int k = 0; k < 3; ++k)
      if (double(lo[k]) > b.max[k] || b.min[k] > double(hi[k])) return false;
    return true;
  }
  vcg::Box3d ToBox() const {
    return vcg::Box3d(vcg::Point3d(lo[0], lo[1], lo[2]), vcg::Point3d(hi[0], hi[1], hi[2]));
  }
};

} // namespace molremesh

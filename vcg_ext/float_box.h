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
#include <limits>

namespace molremesh {

struct FloatBox {
  std::array<float, 3> lo{}, hi{};

  static FloatBox Outward(const vcg::Box3d& b) {
    FloatBox r;
    for (int k = 0; k < 3; ++k) {
      float lo = float(b.min[k]), hi = float(b.max[k]);
      if (double(lo) > b.min[k]) lo = std::nextafter(lo, -std::numeric_limits<float>::infinity());
      if (double(hi) < b.max[k]) hi = std::nextafter(hi, std::numeric_limits<float>::infinity());
      r.lo[k] = lo;
      r.hi[k] = hi;
    }
    return r;
  }
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

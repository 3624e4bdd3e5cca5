// The pipeline's working frame: coordinates recentred when their magnitude dwarfs the mesh.
//
// The stages' tolerances follow the coordinates' magnitude (the intersection predicates snap
// within 1e-12 x the largest coordinate, the rounding of a coordinate of that size), so a small
// mesh far from the origin makes every local edit query a box as large as the mesh: a unit sphere
// at x = 1e15 has a snap distance of 1000. Measured on a unit icosphere (5120 faces, bounding box
// diagonal 2): the output is the same as at the origin up to an offset of 1e5 (5e4 diagonals),
// its angles change from 1e6 on and the run is 5 times slower from 1e7 on; at 1e14 the CVT stage
// took minutes. So the pipeline works in a recentred frame when the bounding box centre is more
// than kRecentreRatio = 1e3 diagonals from the origin on some axis: those axes are translated by
// the centre (rounded to the mesh's scalar type; the difference of two coordinates that close is
// exact), and translated back on output. Ordinary meshes (molecular surfaces lie within a few
// diagonals of the origin) are not touched. Scale is left alone: the stages measure everything in
// units of the target edge length.
//
// Recentring cannot restore precision the file never had: at 1e15 a double holds a coordinate to
// 0.125, coarser than the edges of a unit sphere, and the output would be rounded to that grid
// again. Such an input is refused (CoarseResolution says why) when the spacing of representable
// coordinates at its magnitude exceeds kMaxResolutionShare = 1/100 of its mean edge length, the
// share below which the rounding moves an angle by well under a degree.
#pragma once

#include <vcg_ext/geometry/mean_edge_length.h>
#include <vcg_ext/geometry/point.h>

#include <cmath>
#include <limits>
#include <sstream>
#include <string>

namespace molremesh {

template <class MeshType>
class CoordinateFrame {
public:
  using ScalarType = typename MeshType::ScalarType;
  static constexpr double kRecentreRatio = 1e3;       ///< |centre| / bbox diagonal that recentres an axis
  static constexpr double kMaxResolutionShare = 1e-2; ///< coordinate spacing / mean edge length refused above

  /// The frame for m (live vertices): the offset of each axis to recentre, zero for the others.
  static CoordinateFrame For(const MeshType& m) {
    CoordinateFrame frame;
    Point lo(std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
             std::numeric_limits<double>::infinity());
    Point hi = -lo;
    for (const auto& v : m.vert) {
      if (v.IsD()) continue;
      const Point p = PositionOf(&v);
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], p[k]);
        hi[k] = std::max(hi[k], p[k]);
      }
    }
    if (!IsFinite(lo) || !IsFinite(hi)) return frame;
    const double diagonal = (hi - lo).Norm();
    frame.magnitude_ = std::max(MaxAbs(lo), MaxAbs(hi));
    for (int k = 0; k < 3; ++k) {
      const double centre = 0.5 * lo[k] + 0.5 * hi[k];
      if (std::fabs(centre) > kRecentreRatio * diagonal) frame.offset_[k] = double(ScalarType(centre));
    }
    return frame;
  }

  bool Recentres() const { return offset_ != Point(0, 0, 0); }
  const Point& Offset() const { return offset_; }

  /// "" when the coordinates resolve the mesh, else the one-line reason to refuse it: the
  /// spacing of representable coordinates at the mesh's magnitude is above kMaxResolutionShare
  /// of its mean edge length (sides of collapsed faces left out).
  std::string CoarseResolution(const MeshType& m) const {
    const ScalarType at = ScalarType(magnitude_);
    const double spacing =
        double(std::nextafter(at, std::numeric_limits<ScalarType>::infinity())) - double(at);
    const double meanEdge = MeanEdgeLength(m, true);
    if (!(meanEdge > 0) || spacing <= kMaxResolutionShare * meanEdge) return {};
    std::ostringstream s;
    s << "the coordinates reach " << magnitude_ << ", where they are only resolved to " << spacing
      << ", more than 1/" << int(1 / kMaxResolutionShare) << " of the mean edge length " << meanEdge
      << ": move the mesh nearer the origin";
    return s.str();
  }

  /// Moves m into the working frame (the recentred axes by -offset).
  void Enter(MeshType& m) const { Translate(m, -1); }
  /// Moves m back to the input's frame.
  void Leave(MeshType& m) const { Translate(m, +1); }

private:
  void Translate(MeshType& m, int sign) const {
    if (!Recentres()) return;
    for (auto& v : m.vert)
      if (!v.IsD())
        for (int k = 0; k < 3; ++k)
          if (offset_[k] != 0) v.P()[k] = ScalarType(double(v.P()[k]) + sign * offset_[k]);
  }

  Point offset_{0, 0, 0};
  double magnitude_ = 0; ///< largest absolute coordinate of the input
};

} // namespace molremesh

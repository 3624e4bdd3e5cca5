// Points in double precision, whatever the scalar type of the mesh they come from.
//
// Every molremesh algorithm evaluates geometry in double precision, so MeshLab's float CMeshO and
// the CLI's double mesh take the same decisions and give the same figures for the same file.
// These are the only conversions from a mesh's coordinates to that precision.
#pragma once

#include <vcg/space/point3.h>

#include <algorithm>
#include <cmath>

namespace molremesh {

using Point = vcg::Point3d;

constexpr double kPi = 3.14159265358979323846;

/// A coordinate of any scalar type as a double-precision point.
template <class CoordType>
Point ToPoint(const CoordType& c) {
  return Point(double(c[0]), double(c[1]), double(c[2]));
}

/// A vertex position in double precision (the scalar type of the mesh may be float).
template <class VertexType>
Point PositionOf(const VertexType* v) {
  return ToPoint(v->cP());
}

/// True when no coordinate is NaN or infinite.
inline bool IsFinite(const Point& p) {
  return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
}

/// Largest absolute coordinate.
inline double MaxAbs(const Point& p) {
  return std::max({std::fabs(p[0]), std::fabs(p[1]), std::fabs(p[2])});
}

/// An orthonormal basis (e1, e2) of the plane orthogonal to the unit normal n.
inline void TangentBasis(const Point& n, Point& e1, Point& e2) {
  e1 = std::fabs(n[0]) < 0.9 ? Point(1, 0, 0) ^ n : Point(0, 1, 0) ^ n;
  e1.Normalize();
  e2 = n ^ e1;
}

} // namespace molremesh

// Exact scalar fields of a set of atoms, and the projection of extracted vertices onto their level.
//
// An isosurface extracted from a grid lies where the trilinear interpolation of the samples
// crosses the level; for a convex field (the distance to a ball) that is inside the true surface
// by about h^2 / (8 r): 0.03 Å, 3 % of a hydrogen's area at h = 0.4 Å. Newton steps on the exact
// field (the union of balls: a projection onto the nearest ball's sphere; the Gaussian density:
// its sum and gradient) take the vertices onto the true surface. A step is at most a grid spacing,
// and a vertex whose move would flip one of its faces stays where it was, so the extraction's
// validity (no flipped face, hence no new intersection from a sub-voxel move) is kept.
#pragma once

#include <vcg_ext/core/index.h>
#include <vcg_ext/core/parallel_for.h>
#include <vcg_ext/geometry/mean_edge_length.h>
#include <vcg_ext/geometry/point.h>
#include <vcg_ext/spatial/self_intersections.h>
#include <vcg_ext/structure/atoms.h>

#include <openvdb/openvdb.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace molremesh {

/// The largest atom radius (0 for no atoms): the reach of a cell grid's neighbourhood queries.
inline double MaxAtomRadius(const std::vector<Atom>& atoms) {
  double r = 0;
  for (const Atom& a : atoms) r = std::max(r, a.radius);
  return r;
}

/// Atoms bucketed in cubic cells of a given size, for "atoms near x" queries (the 27 cells around).
class AtomCells {
public:
  AtomCells(const std::vector<Atom>& atoms, double cell) : atoms_(&atoms), cell_(cell) {
    for (std::size_t i = 0; i < atoms.size(); ++i) cells_[Key(atoms[i].position)].push_back(std::uint32_t(i));
  }
  template <class Visit>
  void ForNear(const Point& x, Visit&& visit) const {
    const long cx = long(std::floor(x[0] / cell_)), cy = long(std::floor(x[1] / cell_)),
               cz = long(std::floor(x[2] / cell_));
    for (long i = cx - 1; i <= cx + 1; ++i)
      for (long j = cy - 1; j <= cy + 1; ++j)
        for (long k = cz - 1; k <= cz + 1; ++k) {
          const auto it = cells_.find(Pack(i, j, k));
          if (it == cells_.end()) continue;
          for (std::uint32_t a : it->second) visit((*atoms_)[a]);
        }
  }

private:
  static std::int64_t Pack(long i, long j, long k) {
    return (std::int64_t(i & 0x1FFFFF) << 42) | (std::int64_t(j & 0x1FFFFF) << 21) |
           std::int64_t(k & 0x1FFFFF);
  }
  std::int64_t Key(const Point& p) const {
    return Pack(long(std::floor(p[0] / cell_)), long(std::floor(p[1] / cell_)),
                long(std::floor(p[2] / cell_)));
  }
  const std::vector<Atom>* atoms_;
  double cell_;
  std::unordered_map<std::int64_t, std::vector<std::uint32_t>> cells_;
};

/// Signed distance to the union of balls (radius r + grow), exact outside and on the surface:
/// min_i |x - c_i| - r_i, valid for points within `reach` of the surface.
class BallUnionDistance {
public:
  BallUnionDistance(const std::vector<Atom>& atoms, double grow, double reach)
      : grow_(grow), cells_(atoms, MaxAtomRadius(atoms) + grow + reach) {}
  /// Value at x, and its gradient (the unit direction from the nearest ball's centre).
  double operator()(const Point& x, Point& gradient) const {
    double best = 1e300;
    gradient = Point(0, 0, 0);
    cells_.ForNear(x, [&](const Atom& a) {
      const Point d = x - a.position;
      const double n = d.Norm(), value = n - (a.radius + grow_);
      if (value < best && n > 0) {
        best = value;
        gradient = d / n;
      }
    });
    return best;
  }

private:
  double grow_;
  AtomCells cells_;
};

/// TMSmesh's Gaussian density sum_i exp(-d (|x - c_i|^2 / r_i^2 - 1)), terms below `cutoff` of 1
/// at their centre's reach left out (as on the grid).
class GaussianDensity {
public:
  GaussianDensity(const std::vector<Atom>& atoms, double decay, double reachInRadii)
      : decay_(decay), reach2_(reachInRadii * reachInRadii),
        cells_(atoms, MaxAtomRadius(atoms) * reachInRadii) {}
  double operator()(const Point& x, Point& gradient) const {
    double sum = 0;
    gradient = Point(0, 0, 0);
    cells_.ForNear(x, [&](const Atom& a) {
      const Point d = x - a.position;
      const double invR2 = 1.0 / (a.radius * a.radius), s2 = d.SquaredNorm() * invR2;
      if (s2 > reach2_) return;
      const double term = std::exp(-decay_ * (s2 - 1.0));
      sum += term;
      gradient += d * (-2.0 * decay_ * invR2 * term);
    });
    return sum;
  }

private:
  double decay_, reach2_;
  AtomCells cells_;
};

/// A grid's values by triquadratic interpolation (OpenVDB's QuadraticSampler: per axis, the parabola
/// through the voxel below the point, the one before it and the one after it), the gradient as that
/// interpolant's own derivative: one read of the 27 voxels per call, where central differences read
/// them seven times. Safe to call from several threads (each call has its own accessor).
class QuadraticGridField {
public:
  explicit QuadraticGridField(const openvdb::FloatGrid& grid)
      : grid_(&grid), inverseVoxel_(1.0 / grid.voxelSize()[0]) {}
  double operator()(const Point& x, Point& gradient) const {
    const openvdb::FloatGrid::ConstAccessor accessor = grid_->getConstAccessor();
    const openvdb::Vec3d u = grid_->transform().worldToIndex(openvdb::Vec3d(x[0], x[1], x[2]));
    const openvdb::Coord low(int(std::floor(u[0])) - 1, int(std::floor(u[1])) - 1, int(std::floor(u[2])) - 1);
    const double t[3] = {u[0] - (low[0] + 1), u[1] - (low[1] + 1), u[2] - (low[2] + 1)};
    // Along z first: the value and the z-derivative on each of the 3x3 lines.
    double along[3][3], alongDz[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        double v[3];
        for (int k = 0; k < 3; ++k) v[k] = accessor.getValue(low.offsetBy(i, j, k));
        Parabola(v, t[2], along[i][j], alongDz[i][j]);
      }
    // Then y (of the values: value and y-derivative; of the z-derivatives: value), then x.
    double plane[3], planeDy[3], planeDz[3], unused;
    for (int i = 0; i < 3; ++i) {
      Parabola(along[i], t[1], plane[i], planeDy[i]);
      Parabola(alongDz[i], t[1], planeDz[i], unused);
    }
    double value, dx, dy, dz;
    Parabola(plane, t[0], value, dx);
    Parabola(planeDy, t[0], dy, unused);
    Parabola(planeDz, t[0], dz, unused);
    gradient = Point(dx, dy, dz) * inverseVoxel_;
    return value;
  }

private:
  /// The parabola through v at -1, 0, 1, and its derivative, at t.
  static void Parabola(const double v[3], double t, double& value, double& derivative) {
    const double a = 0.5 * (v[0] + v[2]) - v[1], b = 0.5 * (v[2] - v[0]);
    value = t * (t * a + b) + v[1];
    derivative = 2 * a * t + b;
  }

  const openvdb::FloatGrid* grid_;
  double inverseVoxel_;
};

/// Newton steps from x towards field == level, the total move capped at maxMove; they stop early
/// once the field is within `tolerance` of the level (an exact distance needs one step).
template <class Field>
Point ProjectToLevel(const Point& x, const Field& field, double level, double maxMove, int iterations = 4,
                     double tolerance = 0) {
  Point y = x, g;
  for (int it = 0; it < iterations; ++it) {
    const double residual = field(y, g) - level, g2 = g.SquaredNorm();
    if (!(g2 > 1e-24) || !std::isfinite(residual) || std::fabs(residual) <= tolerance) break;
    y -= g * (residual / g2);
    const Point move = y - x;
    if (move.Norm() > maxMove) y = x + move * (maxMove / move.Norm());
  }
  return y;
}

/// Puts the vertices of every pair of crossing faces back where they were (`before`), in rounds of
/// the exact pair test until no pair is left or nothing changes. The mesher's output does not
/// cross itself; the moves onto the exact surface can, where a concave crease between two spheres
/// folds a sliver through its neighbour (ubiquitin's van der Waals surface: 14 pairs at 0.4 Å).
template <class MeshType>
void RevertCrossingMoves(MeshType& m, const std::vector<Point>& before, int threads) {
  using CoordType = typename MeshType::CoordType;
  using ScalarType = typename MeshType::ScalarType;
  std::vector<std::array<Index, 3>> tris;
  tris.reserve(m.face.size());
  for (const auto& f : m.face)
    if (!f.IsD())
      tris.push_back({Index(vcg::tri::Index(m, f.cV(0))), Index(vcg::tri::Index(m, f.cV(1))),
                      Index(vcg::tri::Index(m, f.cV(2)))});
  const double cell = MeanEdgeLength(m);
  std::vector<Point> points(m.vert.size());
  for (int round = 0; round < 10; ++round) {
    for (std::size_t v = 0; v < m.vert.size(); ++v) points[v] = PositionOf(&m.vert[v]);
    bool reverted = false;
    for (const IntersectingPair& pair : FindSelfIntersections(tris, points, cell, threads))
      for (const Index face : {pair.i, pair.j})
        for (const Index v : tris[face]) {
          if (points[v] == before[v]) continue;
          m.vert[v].P() =
              CoordType(ScalarType(before[v][0]), ScalarType(before[v][1]), ScalarType(before[v][2]));
          reverted = true;
        }
    if (!reverted) break;
  }
}

/// Moves each vertex of m to move(position) (each on its own: the result does not depend on the
/// thread count); a vertex whose move flips one of its faces' normals (or makes it degenerate) is
/// put back, until no face is flipped, and so are the vertices of faces the moves made cross
/// (RevertCrossingMoves).
template <class MeshType, class Move>
void MoveVerticesKeepingValid(MeshType& m, const Move& move, int threads = 0) {
  using CoordType = typename MeshType::CoordType;
  using ScalarType = typename MeshType::ScalarType;
  std::vector<Point> before(m.vert.size());
  ParallelFor(m.vert.size(), threads, [&](std::size_t begin, std::size_t end, int) {
    for (std::size_t i = begin; i < end; ++i) {
      before[i] = PositionOf(&m.vert[i]);
      if (m.vert[i].IsD()) continue;
      const Point p = move(before[i]);
      m.vert[i].P() = CoordType(ScalarType(p[0]), ScalarType(p[1]), ScalarType(p[2]));
    }
  });
  auto normalAt = [&](const typename MeshType::FaceType& f, bool original) {
    Point p[3];
    for (int k = 0; k < 3; ++k)
      p[k] = original ? before[std::size_t(vcg::tri::Index(m, f.cV(k)))] : PositionOf(f.cV(k));
    return (p[1] - p[0]) ^ (p[2] - p[0]);
  };
  for (int round = 0; round < 10; ++round) {
    bool reverted = false;
    for (const auto& f : m.face) {
      if (f.IsD()) continue;
      const Point n0 = normalAt(f, true), n1 = normalAt(f, false);
      if (n0 * n1 > 0.25 * n0.SquaredNorm()) continue; // same side, not collapsed
      for (int k = 0; k < 3; ++k) {
        auto* v = const_cast<typename MeshType::VertexType*>(f.cV(k));
        const Point& p = before[std::size_t(vcg::tri::Index(m, v))];
        v->P() = CoordType(ScalarType(p[0]), ScalarType(p[1]), ScalarType(p[2]));
      }
      reverted = true;
    }
    if (!reverted) break;
  }
  RevertCrossingMoves(m, before, threads);
}

/// Moves m's vertices onto field == level (ProjectToLevel), keeping the mesh valid
/// (MoveVerticesKeepingValid).
template <class MeshType, class Field>
void ProjectVerticesToLevel(MeshType& m, const Field& field, double level, double maxMove, int threads = 0,
                            double tolerance = 0) {
  MoveVerticesKeepingValid(
      m, [&](const Point& x) { return ProjectToLevel(x, field, level, maxMove, 4, tolerance); }, threads);
}

} // namespace molremesh

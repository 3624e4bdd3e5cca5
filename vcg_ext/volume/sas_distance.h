// The exact depth of a point inside the solvent-accessible surface: its distance to the nearest
// point of the SAS boundary, the field whose level -probe is the solvent-excluded surface.
//
// The SAS boundary is made of exposed sphere patches (radius r + probe), the arcs where two of them
// meet (concave creases) and the points where three meet (SAS vertices). The nearest boundary point
// of x is the radial projection onto a sphere, the closest point of a crease circle, or a SAS vertex,
// whichever of those is not buried in another sphere and is nearest: where the projection onto a
// sphere is buried, the nearest exposed point of that sphere is on an arc bounding its patch, and
// where the closest point of a circle is buried, the nearest exposed point of the circle is an arc's
// end, a SAS vertex (the distance along a circle has one minimum). The SES's toroidal patches are at
// probe distance from the creases, its reentrant spherical patches from the SAS vertices.
//
// A distance field rebuilt from an extracted SAS mesh cuts those creases with chords and their
// corners with flat triangles, so it overestimates the depth under them and puts the SES's
// reentrant patches up to several tenths of an Å too far out (1UBQ at 0.4 Å: SES area -4.2 % and
// volume +2.3 % against BALL's analytic SES; both errors linear in the grid spacing).
//
// Cost: the SAS vertices and the crease circles with an exposed point are found once; a query
// looks only at those (inside a protein most creases are buried whole, and a query near the SES
// has a dozen spheres within reach, whose pairs it would otherwise all try).
#pragma once

#include <vcg_ext/core/parallel_for.h>
#include <vcg_ext/geometry/point.h>
#include <vcg_ext/structure/atoms.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace molremesh {

class SasBoundaryDistance {
public:
  /// The SAS of the atoms' balls grown by `probe`; exact for points whose distance to the SAS
  /// boundary is at most `reach` (the deeper ones get a value of at most -reach).
  SasBoundaryDistance(const std::vector<Atom>& atoms, double probe, double reach, int threads = 0)
      : reach_(reach) {
    double largest = 0;
    Point lo(1e300, 1e300, 1e300), hi(-1e300, -1e300, -1e300);
    for (const Atom& a : atoms) {
      largest = std::max(largest, a.radius + probe);
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], a.position[k]);
        hi[k] = std::max(hi[k], a.position[k]);
      }
    }
    // A sphere whose surface is within reach of x has its centre within largest + reach of x.
    largest_ = largest;
    query_ = largest + reach;
    origin_ = lo;
    for (int k = 0; k < 3; ++k) size_[k] = atoms.empty() ? 1 : long((hi[k] - lo[k]) / kCell) + 1;
    std::vector<std::size_t> cellOf(atoms.size());
    start_.assign(std::size_t(size_[0] * size_[1] * size_[2]) + 1, 0);
    for (std::size_t i = 0; i < atoms.size(); ++i) {
      cellOf[i] =
          CellIndex(CellOf(atoms[i].position, 0), CellOf(atoms[i].position, 1), CellOf(atoms[i].position, 2));
      ++start_[cellOf[i] + 1];
    }
    for (std::size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
    std::vector<std::size_t> fill(start_.begin(), start_.end() - 1);
    centres_.resize(atoms.size());
    radii_.resize(atoms.size());
    for (std::size_t i = 0; i < atoms.size(); ++i) { // in atom order within a cell: deterministic
      const std::size_t at = fill[cellOf[i]]++;
      centres_[at] = atoms[i].position;
      radii_[at] = atoms[i].radius + probe;
    }
    const std::vector<std::vector<std::uint32_t>> partners = MeetingSpheres(threads);
    std::vector<std::vector<SpherePair>> cornered = FindExposedCorners(partners, threads);
    FindExposedCreases(partners, std::move(cornered), threads);
  }

  /// Minus the distance from x to the SAS boundary (x inside the SAS, negative), or the distance
  /// to the union of balls (x outside, positive); the gradient points from x to the nearest
  /// boundary point (inside) or away from the nearest ball (outside).
  double operator()(const Point& x, Point& gradient) const { return Depth(x, gradient, reach_); }

  /// The same, searched first within `bound` of x (an upper bound of the depth, such as a rebuilt
  /// distance field's value: a smaller search), then, if x is not inside within it, within reach.
  double Depth(const Point& x, Point& gradient, double bound) const {
    if (bound < reach_) {
      double depth = 0;
      if (Search(x, bound, gradient, depth)) return depth;
    }
    double depth = 0;
    Search(x, reach_, gradient, depth);
    return depth;
  }

  /// The exposed SAS vertices (where three spheres meet, in no other sphere), sorted by cell.
  const std::vector<Point>& ExposedVertices() const { return corners_; }
  /// The depth up to which the field is exact.
  double Reach() const { return reach_; }

private:
  /// The depth of x searched within `bound` (at most reach_); false when x is outside the balls
  /// or no boundary point is within the bound (then depth is not set unless bound == reach_).
  bool Search(const Point& x, double bound, Point& gradient, double& depth) const {
    Around around;
    std::vector<Sphere>& near = around.near;
    bool inside = false;
    double outside = 1e300;
    Point away(0, 0, 0);
    ForNear(x, largest_ + bound, [&](std::uint32_t i) {
      const Point d = x - centres_[i];
      const double n = d.Norm(), gap = n - radii_[i];
      if (gap < 0) inside = true;
      if (gap < outside && n > 0) {
        outside = gap;
        away = d / n;
      }
      if (std::fabs(gap) <= bound)
        near.push_back({i, std::fabs(gap)});
      else if (gap < 0)
        around.buried.push_back(i);
    });
    const bool full = bound >= reach_;
    if (!inside) {
      if (!full) return false; // the nearest ball may be further than the bound's search
      gradient = away;
      depth = outside;
      return true;
    }
    std::sort(near.begin(), near.end(), [](const Sphere& a, const Sphere& b) {
      return a.gap < b.gap || (a.gap == b.gap && a.index < b.index);
    });
    Nearest best{bound, Point(0, 0, 0), false};
    Corners(x, best); // first: a cheap look-up whose bound cuts the other two short
    Spheres(x, around, best);
    Circles(x, around, best);
    if (!best.found) {
      if (!full) return false;
      gradient = Point(0, 0, 0);
      depth = -reach_;
      return true;
    }
    gradient = (best.point - x) / best.distance;
    depth = -best.distance;
    return true;
  }

  struct Sphere {
    std::uint32_t index;
    double gap; ///< | |x - centre| - radius |: a lower bound of the distance to its points
  };
  /// The spheres around a query point: those whose surface is within reach (sorted by that
  /// distance), and those it is deeper in.
  struct Around {
    std::vector<Sphere> near;
    std::vector<std::uint32_t> buried;
  };
  struct Nearest {
    double distance;
    Point point;
    bool found;
  };

  void Consider(const Point& x, const Point& y, Nearest& best, const Around& around, std::uint32_t a,
                std::uint32_t b, std::uint32_t c) const {
    const double d = (y - x).Norm();
    if (!(d < best.distance) || !Exposed(y, around, a, b, c)) return;
    best = {d, y, true};
  }

  /// y is on the boundary: in no sphere but a, b, c (those it lies on).
  bool Exposed(const Point& y, const Around& around, std::uint32_t a, std::uint32_t b,
               std::uint32_t c) const {
    auto covers = [&](std::uint32_t i) {
      return i != a && i != b && i != c && (y - centres_[i]).SquaredNorm() < radii_[i] * radii_[i] * kInside;
    };
    for (const Sphere& s : around.near)
      if (covers(s.index)) return false;
    for (std::uint32_t i : around.buried)
      if (covers(i)) return false;
    return true;
  }

  void Spheres(const Point& x, const Around& around, Nearest& best) const {
    for (const Sphere& s : around.near) {
      if (!(s.gap < best.distance)) break; // sorted by the lower bound
      const Point d = x - centres_[s.index];
      const double n = d.Norm();
      if (n > 0)
        Consider(x, centres_[s.index] + d * (radii_[s.index] / n), best, around, s.index, s.index, s.index);
    }
  }

  /// The nearest exposed points of the crease circles of the near spheres (only the circles with an
  /// exposed point: most creases inside the protein are buried whole). A circle is no nearer than
  /// its farther sphere, so each pair is visited from its nearer sphere.
  void Circles(const Point& x, const Around& around, Nearest& best) const {
    for (const Sphere& s : around.near) {
      if (!(s.gap < best.distance)) break; // sorted by the lower bound
      for (std::size_t n = creaseStart_[s.index]; n < creaseStart_[s.index + 1]; ++n) {
        const Crease& crease = creases_[n];
        const std::uint32_t b = crease.other;
        const double gap = std::fabs((x - centres_[b]).Norm() - radii_[b]);
        if (!(gap < best.distance) || gap < s.gap || (gap == s.gap && b < s.index)) continue;
        Point radial = x - crease.centre;
        radial -= crease.axis * (radial * crease.axis);
        const double norm = radial.Norm();
        if (norm > 0) Consider(x, crease.centre + radial * (crease.rho / norm), best, around, s.index, b, b);
      }
    }
  }

  /// The nearest exposed SAS vertex, if nearer than best (they were found once, FindExposedCorners).
  void Corners(const Point& x, Nearest& best) const {
    long from[3], to[3];
    for (int k = 0; k < 3; ++k) {
      from[k] = std::max(0L, long(std::floor((x[k] - best.distance - origin_[k]) / kCell)));
      to[k] = std::min(size_[k] - 1, long(std::floor((x[k] + best.distance - origin_[k]) / kCell)));
    }
    for (long i = from[0]; i <= to[0]; ++i)
      for (long j = from[1]; j <= to[1]; ++j)
        for (long k = from[2]; k <= to[2]; ++k) {
          const std::size_t c = CellIndex(i, j, k);
          for (std::size_t v = cornerStart_[c]; v < cornerStart_[c + 1]; ++v) {
            const double d = (corners_[v] - x).Norm();
            if (d < best.distance) best = {d, corners_[v], true};
          }
        }
  }

  struct SpherePair {
    std::uint32_t a, b; ///< a < b
    bool operator<(const SpherePair& o) const { return a < o.a || (a == o.a && b < o.b); }
    bool operator==(const SpherePair& o) const { return a == o.a && b == o.b; }
  };

  /// Per sphere, the other spheres it meets, in increasing order.
  std::vector<std::vector<std::uint32_t>> MeetingSpheres(int threads) const {
    std::vector<std::vector<std::uint32_t>> partners(centres_.size());
    ParallelFor(centres_.size(), threads, [&](std::size_t begin, std::size_t end, int) {
      for (std::size_t a = begin; a < end; ++a) {
        ForNear(centres_[a], 2 * largest_, [&](std::uint32_t b) {
          if (b != a && Meet(std::uint32_t(a), b)) partners[a].push_back(b);
        });
        std::sort(partners[a].begin(), partners[a].end());
      }
    });
    return partners;
  }

  /// The points where three spheres meet that lie on no other sphere (the SAS vertices), sorted
  /// into the cells: per sphere a in cell order, the corners with two later spheres b < c. Returns,
  /// per sphere a, the sphere pairs of its corners that have a point on no other sphere (their
  /// circles have an exposed point).
  std::vector<std::vector<SpherePair>>
  FindExposedCorners(const std::vector<std::vector<std::uint32_t>>& meeting, int threads) {
    const std::size_t n = centres_.size();
    std::vector<std::vector<Point>> found(n);
    std::vector<std::vector<SpherePair>> creases(n); // pairs with a corner on no other sphere
    ParallelFor(n, threads, [&](std::size_t begin, std::size_t end, int) {
      for (std::size_t a = begin; a < end; ++a) {
        const std::vector<std::uint32_t>& partners = meeting[a];
        const std::size_t later = // the partners after a
            std::size_t(std::upper_bound(partners.begin(), partners.end(), std::uint32_t(a)) -
                        partners.begin());
        for (std::size_t i = later; i < partners.size(); ++i)
          for (std::size_t j = i + 1; j < partners.size(); ++j) {
            Point y[2];
            const std::uint32_t b = partners[i], c = partners[j];
            if (!Meet(b, c) || !Corner(std::uint32_t(a), b, c, y)) continue;
            bool onCrease = false;
            for (const Point& corner : y) {
              const double cover = Cover(corner, std::uint32_t(a), b, c);
              if (!(cover < kInside)) found[a].push_back(corner);
              onCrease = onCrease || !(cover < kLooselyInside);
            }
            if (onCrease)
              for (const SpherePair& pair :
                   {SpherePair{std::uint32_t(a), b}, SpherePair{std::uint32_t(a), c}, SpherePair{b, c}})
                creases[a].push_back(pair);
          }
      }
    });
    cornerStart_.assign(start_.size(), 0);
    for (const auto& list : found)
      for (const Point& y : list) ++cornerStart_[CellIndex(CellOf(y, 0), CellOf(y, 1), CellOf(y, 2)) + 1];
    for (std::size_t c = 1; c < cornerStart_.size(); ++c) cornerStart_[c] += cornerStart_[c - 1];
    std::vector<std::size_t> fill(cornerStart_.begin(), cornerStart_.end() - 1);
    corners_.resize(cornerStart_.back());
    for (const auto& list : found)
      for (const Point& y : list) corners_[fill[CellIndex(CellOf(y, 0), CellOf(y, 1), CellOf(y, 2))]++] = y;
    return creases;
  }

  /// The crease circles with an exposed point, listed under both spheres: those with an exposed
  /// corner (`withCorner`, per sphere) and those no third sphere cuts that lie in no single other
  /// sphere (whole exposed circles; a circle no sphere cuts is inside or outside each sphere whole).
  void FindExposedCreases(const std::vector<std::vector<std::uint32_t>>& meeting,
                          std::vector<std::vector<SpherePair>> withCorner, int threads) {
    const std::size_t n = centres_.size();
    std::vector<std::vector<SpherePair>> whole(n);
    ParallelFor(n, threads, [&](std::size_t begin, std::size_t end, int) {
      for (std::size_t a = begin; a < end; ++a)
        for (const std::uint32_t b : meeting[a])
          if (b > a && WholeCircleExposed(std::uint32_t(a), b, meeting[a]))
            whole[a].push_back({std::uint32_t(a), b});
    });
    std::vector<SpherePair> pairs;
    for (auto* lists : {&withCorner, &whole})
      for (const auto& list : *lists) pairs.insert(pairs.end(), list.begin(), list.end());
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    std::vector<Crease> circles(pairs.size()); // each computed once, from the lower index
    std::size_t kept = 0;
    for (std::size_t i = 0; i < pairs.size(); ++i)
      if (Circle(pairs[i].a, pairs[i].b, circles[kept].centre, circles[kept].axis, circles[kept].rho)) {
        pairs[kept] = pairs[i];
        ++kept;
      }
    pairs.resize(kept);
    creaseStart_.assign(n + 1, 0);
    for (const SpherePair& pair : pairs) ++creaseStart_[pair.a + 1], ++creaseStart_[pair.b + 1];
    for (std::size_t i = 1; i <= n; ++i) creaseStart_[i] += creaseStart_[i - 1];
    std::vector<std::size_t> fill(creaseStart_.begin(), creaseStart_.end() - 1);
    creases_.resize(creaseStart_.back());
    for (std::size_t i = 0; i < pairs.size(); ++i) {
      Crease crease = circles[i];
      crease.other = pairs[i].b;
      creases_[fill[pairs[i].a]++] = crease;
      crease.other = pairs[i].a;
      creases_[fill[pairs[i].b]++] = crease;
    }
  }

  /// The circle of spheres a and b lies in no other sphere and no partner of a cuts it (a circle
  /// with a corner is exposed only if a corner is). One point of it inside another sphere settles
  /// it: that sphere holds the circle whole or cuts it.
  bool WholeCircleExposed(std::uint32_t a, std::uint32_t b,
                          const std::vector<std::uint32_t>& partners) const {
    Point centre, axis;
    double rho;
    if (!Circle(a, b, centre, axis, rho)) return false;
    const Point across = std::fabs(axis[0]) < 0.9 ? Point(1, 0, 0) : Point(0, 1, 0);
    const Point y = centre + (axis ^ across).Normalize() * rho;
    for (const std::uint32_t c : partners)
      if (c != b && (y - centres_[c]).SquaredNorm() < radii_[c] * radii_[c] * kLooselyInside) return false;
    for (const std::uint32_t c : partners) {
      Point corner[2];
      if (c != b && Meet(b, c) && Corner(a, b, c, corner)) return false;
    }
    return true;
  }

  bool Meet(std::uint32_t a, std::uint32_t b) const {
    const double r = radii_[a] + radii_[b];
    return (centres_[a] - centres_[b]).SquaredNorm() < r * r;
  }

  /// How deep y is in the spheres other than a, b, c: the least |y - centre|^2 / radius^2 (y is in
  /// no other sphere when it is at least 1).
  double Cover(const Point& y, std::uint32_t a, std::uint32_t b, std::uint32_t c) const {
    double least = 1e300;
    ForNear(y, largest_, [&](std::uint32_t i) {
      if (i != a && i != b && i != c)
        least = std::min(least, (y - centres_[i]).SquaredNorm() / (radii_[i] * radii_[i]));
    });
    return least;
  }

  /// The circle where spheres a and b meet; false when they do not.
  bool Circle(std::uint32_t a, std::uint32_t b, Point& centre, Point& axis, double& rho) const {
    const Point ab = centres_[b] - centres_[a];
    const double d = ab.Norm(), ra = radii_[a], rb = radii_[b];
    if (!(d > 0) || d >= ra + rb || d <= std::fabs(ra - rb)) return false;
    axis = ab / d;
    const double along = (d * d + ra * ra - rb * rb) / (2 * d), rho2 = ra * ra - along * along;
    if (!(rho2 > 0)) return false;
    centre = centres_[a] + axis * along;
    rho = std::sqrt(rho2);
    return true;
  }

  /// The two points where spheres a, b and c meet; false when they do not.
  bool Corner(std::uint32_t a, std::uint32_t b, std::uint32_t c, Point y[2]) const {
    Point centre, axis;
    double rho;
    if (!Circle(a, b, centre, axis, rho)) return false;
    // The circle's plane cut with sphere c: a circle around c's foot in the plane.
    const double lift = (centres_[c] - centre) * axis;
    const double rc2 = radii_[c] * radii_[c] - lift * lift;
    if (!(rc2 > 0)) return false;
    const Point foot = centres_[c] - axis * lift, towards = foot - centre;
    const double d = towards.Norm(), rc = std::sqrt(rc2);
    if (!(d > 0) || d >= rho + rc || d <= std::fabs(rho - rc)) return false;
    const Point u = towards / d, v = axis ^ u;
    const double along = (d * d + rho * rho - rc2) / (2 * d),
                 side = std::sqrt(std::max(0.0, rho * rho - along * along));
    y[0] = centre + u * along + v * side;
    y[1] = centre + u * along - v * side;
    return true;
  }

  /// Visits the spheres whose centre may be within `radius` of x (in the cells that ball touches).
  template <class Visit>
  void ForNear(const Point& x, double radius, Visit&& visit) const {
    long from[3], to[3];
    for (int k = 0; k < 3; ++k) {
      from[k] = std::max(0L, long(std::floor((x[k] - radius - origin_[k]) / kCell)));
      to[k] = std::min(size_[k] - 1, long(std::floor((x[k] + radius - origin_[k]) / kCell)));
    }
    const double reach2 = (radius + kCell * 0.8660254037844386) * (radius + kCell * 0.8660254037844386);
    for (long i = from[0]; i <= to[0]; ++i)
      for (long j = from[1]; j <= to[1]; ++j)
        for (long k = from[2]; k <= to[2]; ++k) {
          const Point middle = origin_ + Point((i + 0.5) * kCell, (j + 0.5) * kCell, (k + 0.5) * kCell);
          if ((middle - x).SquaredNorm() > reach2) continue;
          const std::size_t c = CellIndex(i, j, k);
          for (std::size_t a = start_[c]; a < start_[c + 1]; ++a) visit(std::uint32_t(a));
        }
  }
  long CellOf(const Point& p, int k) const {
    return std::min(size_[k] - 1, std::max(0L, long(std::floor((p[k] - origin_[k]) / kCell))));
  }
  std::size_t CellIndex(long i, long j, long k) const {
    return std::size_t((i * size_[1] + j) * size_[2] + k);
  }

  static constexpr double kCell = 1.5; ///< Å, edge of the cells the spheres are sorted in
  /// A point on a sphere computed from another sphere's circle is not "inside" it by rounding.
  static constexpr double kInside = 1.0 - 1e-9;
  /// Where a crease's exposure is decided (a corner, a whole circle): more points count as
  /// exposed, so no crease with an exposed point is left out by rounding.
  static constexpr double kLooselyInside = 1.0 - 1e-6;
  struct Crease {
    std::uint32_t other; ///< the other sphere
    Point centre, axis;
    double rho;
  };
  double reach_, largest_ = 0, query_ = 0;
  Point origin_;
  long size_[3] = {1, 1, 1};
  std::vector<std::size_t> start_;       ///< per cell: its first sphere; one past the last at the end
  std::vector<Point> centres_;           ///< sorted by cell
  std::vector<double> radii_;            ///< r + probe, in the same order
  std::vector<std::size_t> cornerStart_; ///< per cell: its first SAS vertex, as start_
  std::vector<Point> corners_;           ///< the exposed SAS vertices, sorted by cell
  std::vector<std::size_t> creaseStart_; ///< per sphere: its first crease with an exposed point
  std::vector<Crease> creases_;          ///< those creases, under each of their two spheres
};

} // namespace molremesh

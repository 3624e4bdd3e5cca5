// Obtuse reduction (Khan et al. 2020, section 3.5): lowers the largest angles of a mesh that lies on
// a ReferenceSurface, without bringing back angles below Params::minAngleDeg (30 degrees).
//
// ObtuseReduction<MeshType> runs the paper's two tools:
//  1. vertex translation, for decreasing max-angle thresholds (Params::thresholdsDeg: 110, 100 and
//     90 degrees), up to iterationsPerThreshold rounds each: the vertex at the largest angle of every
//     triangle above the threshold is moved inside a feasible disc of its tangent plane (radius
//     discRadiusFactor x its shortest edge), projected back onto the reference near its footpoint.
//     The disc is sampled (discRings x discDirections positions, deterministic) rather than solved
//     for exactly: the feasible region (the angle at the vertex below the threshold, every other
//     angle of the star in [minAngleDeg, threshold)) is an intersection of discs and lunes that a
//     curved reference bends anyway. The best sample (smallest largest angle of the star, then
//     largest smallest angle) is applied only when it lowers the star's largest angle and creates
//     no angle below minAngleDeg (no more star triangles below it, no smaller angle than before);
//     starting with a threshold of 110 degrees lets the worst angles move first, with room to spare.
//     Where that vertex is pinned (locked on a region's border, or every sample would make a small
//     angle), the two other corners are tried the same way (moving B toward the line AC closes
//     the angle at A), and where all three are pinned, the free neighbours of the obtuse corner
//     first widen the angles of the faces they share with it (each moved to the sample that most
//     raises them, by 0.5 degrees at least, with no larger angle in its star and no new small
//     angle), then the three corners are tried again;
//  2. pentagon point insertion, on the triangles still obtuse: the obtuse triangle, its neighbour
//     across its longest edge and the neighbour of that one across its own longest edge (of the two
//     other edges, when the longest is the shared one) form a pentagon when the three are distinct,
//     make a disk with five boundary vertices and no inner one, and their normals agree within
//     pentagonNormalDeg. The two inner edges are removed and one vertex is inserted: every edge of
//     the pentagon sees the new point under an angle below 90 degrees exactly when the point lies
//     outside the circle having that edge as diameter (Thales), so the point is searched (a
//     pentagonSamples x pentagonSamples grid over the pentagon in its mean plane, inside the
//     polygon) for the fan whose largest angle is smallest among those with every angle >=
//     minAngleDeg. The insertion (LocalRemeshingOps::ReplaceDisk) is accepted only when the largest
//     angle of the region improves and no angle below minAngleDeg appears.
//     A last translation round at the final threshold settles the inserted vertices.
// Triangles that stay obtuse are those where every feasible move is refused by the guards (folds
// across sharp creases, intersections across narrow gaps) or where the two tools have no room.
//
// Every edit goes through LocalRemeshingOps (Params::guards), so the mesh stays a 2-manifold with
// the same genus and closed components, no intersecting pair appears and every vertex stays on the
// reference. Edits are local and keep vertices on the reference, so the volume barely changes.
//
// Determinism: edits run serially in a fixed order (faces by largest angle, then index); no random
// choice is made (the seed is accepted for the pipeline's uniform interface); the output does not
// depend on the thread count. A mesh without an angle above the smallest threshold is only scanned.
#pragma once

#include <vcg/complex/complex.h>

#include <vcg_ext/topology/face_face_topology.h>
#include <vcg_ext/core/input_check.h>
#include <vcg_ext/geometry/point.h>
#include <vcg_ext/ops/local_remeshing_ops.h>
#include <vcg_ext/stages/local_stage.h>
#include <vcg_ext/surface/reference_surface.h>
#include <vcg_ext/geometry/triangle_angles.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace molremesh {

template <class MeshType>
class ObtuseReduction {
public:
  using VertexType = typename MeshType::VertexType;
  using FaceType = typename MeshType::FaceType;
  using VertexPointer = typename MeshType::VertexPointer;
  using FacePointer = typename MeshType::FacePointer;
  using Ops = LocalRemeshingOps<MeshType>;
  using Reference = ReferenceSurface<MeshType>;
  using Point = vcg::Point3d;

  /// Guards of the stage's edits: new angles below 30 degrees only where the region's smallest
  /// angle improves; the largest angle is the stage's own business (checked before each edit).
  /// New faces may lean up to 85 degrees from the reference normals at their corners (75 for the
  /// other stages): at the tight saddles of a molecular surface a face spans reference faces whose
  /// normals differ that much, and the move that lowers its last obtuse angle leans further than
  /// 75 degrees (1UBQ's PyMOL SES at quality 1: 95.9 -> 89.4 degrees). The stage's moves are short
  /// (half the vertex's shortest edge) and stay on the reference; the fold guard still applies.
  static LocalOpsGuards DefaultGuards() {
    LocalOpsGuards g = GuardsWithAngleBounds(30.0, 180.0);
    g.maxNormalDeviationDeg = 85.0;
    return g;
  }

  struct Params {
    double targetEdgeLength = 0; ///< L; 0 = mean edge length of the mesh
    int threads = 0;             ///< 0 = all cores (the output does not depend on it)
    std::uint64_t seed = 1;      ///< seed of every random choice (the stage makes none)
    /// Vertices never moved or removed, nor joined by an edit of an edge between two of them
    /// (indexed like m.vert at entry; nonzero = locked; empty = none): the border of a region.
    std::vector<std::uint8_t> lockedVertices;
    std::vector<double> thresholdsDeg{110.0, 100.0,
                                      90.0}; ///< max-angle thresholds of vertex translation, in order
    int iterationsPerThreshold = 20;         ///< translation rounds per threshold (cap)
    double minAngleDeg = 30.0;               ///< no edit creates an angle below it
    double discRadiusFactor = 0.5;           ///< feasible disc radius, relative to the vertex's shortest edge
    int discRings = 4;                       ///< sampled radii of the disc
    int discDirections = 16;                 ///< sampled directions per radius
    bool pentagonInsertion = true;           ///< pentagon point insertion after the translations
    double pentagonNormalDeg = 30.0;         ///< the three triangles' normals must agree within this angle
    int pentagonSamples = 12;                ///< grid resolution of the point search in the pentagon
    /// Last resort for the faces still obtuse after the rounds, as in small-angle elimination:
    /// where the reference turns by more than the default guards allow within an edge length (the
    /// sharp tip of a Gaussian cavity near a critical level, a cusp between atom spheres), every
    /// translation tilts a face past guards.maxNormalDeviationDeg or folds an adjacent pair past
    /// guards.maxFoldAngleDeg. The rounds run once more with the normal guard relaxed to this
    /// angle (below 90, so no face turns over) and the fold guard to creaseFoldAngleDeg;
    /// intersections and the angle guards unchanged. 0 = off.
    double creaseNormalDeviationDeg = 89.0;
    double creaseFoldAngleDeg = 165.0; ///< the fold guard of the crease pass
    LocalOpsGuards guards =
        DefaultGuards(); ///< guards of every edit (minAngleDeg is set to Params::minAngleDeg)
  };

  struct Result {
    bool ok = false;
    std::string message;                           ///< why it failed, or a one-line summary
    std::size_t obtuseBefore = 0, obtuseAfter = 0; ///< faces with an angle >= 90 degrees
    double angleMaxBefore = 0, angleMaxAfter = 0;  ///< largest angle, degrees
    double angleMinBefore = 0, angleMinAfter = 0;  ///< smallest angle, degrees
    std::size_t moves = 0, insertions = 0;         ///< applied translations and pentagon insertions
    std::size_t refused = 0;                       ///< edits refused by the guards of LocalRemeshingOps
    int rounds = 0;                                ///< translation rounds run, all thresholds
    bool creasePass = false;                       ///< the last-resort pass ran
  };

  /// Runs the stage on m (a 2-manifold, consistently oriented mesh with FF and VF adjacency
  /// enabled, lying on reference). On failure m is left untouched (FF/VF adjacency recomputed)
  /// and Result::message says why.
  static Result Do(MeshType& m, const Reference& reference, const Params& params) {
    Result r;
    auto finish = [&](bool ok, const std::string& message) { return FinishStage(r, ok, message); };
    const std::string refused = "obtuse reduction refused: ";
    const InputCheck check = CheckTriangleMeshInput(m);
    if (!check.ok) return finish(false, refused + check.message);
    if (params.thresholdsDeg.empty()) return finish(false, refused + "no max-angle threshold given");
    for (const double t : params.thresholdsDeg)
      if (!(t >= 60.0 && t < 180.0))
        return finish(false, refused + "max-angle thresholds must be in [60, 180)");
    if (!(params.minAngleDeg >= 0 && params.minAngleDeg < 60))
      return finish(false, refused + "minAngleDeg must be in [0, 60)");
    if (params.iterationsPerThreshold < 0 || params.discRings < 1 || params.discDirections < 1 ||
        params.pentagonSamples < 1 || !(params.discRadiusFactor > 0))
      return finish(false, refused + "iteration and sampling counts must be positive");
    double L = 0;
    std::string error;
    if (!PrepareLocalStage(m, reference, params.targetEdgeLength, L, error))
      return finish(false, refused + error);

    const double lowest = *std::min_element(params.thresholdsDeg.begin(), params.thresholdsDeg.end());
    std::size_t above = 0;
    Measure(m, lowest, params.threads, r.obtuseBefore, above, r.angleMinBefore, r.angleMaxBefore);
    if (above == 0 && (!params.pentagonInsertion || r.obtuseBefore == 0)) { // nothing to do: a scan only
      r.obtuseAfter = r.obtuseBefore;
      r.angleMaxAfter = r.angleMaxBefore;
      r.angleMinAfter = r.angleMinBefore;
      return finish(true, "obtuse reduction: nothing above " + std::to_string(lowest) + " degrees");
    }
    LocalOpsGuards guards = params.guards;
    guards.minAngleDeg = params.minAngleDeg;
    const auto edits = [&](Ops& ops) {
      Session session(ops, params);
      session.Run(r);
      const auto stillObtuse = [&] {
        std::size_t obtuse = 0, over = 0;
        double lo = 0, hi = 0;
        Measure(m, lowest, params.threads, obtuse, over, lo, hi);
        return obtuse > 0;
      };
      r.creasePass = RunCreasePass(ops, guards, params.creaseNormalDeviationDeg, params.creaseFoldAngleDeg,
                                   stillObtuse, [&] { session.Run(r); });
    };
    if (!RunLocalEdits(m, reference, L, guards, params.threads, params.lockedVertices, error, r.refused,
                       edits))
      return finish(false, refused + error);
    Measure(m, lowest, params.threads, r.obtuseAfter, above, r.angleMinAfter, r.angleMaxAfter);
    return finish(true, "obtuse reduction: " + std::to_string(r.obtuseBefore) + " -> " +
                            std::to_string(r.obtuseAfter) + " obtuse faces");
  }

private:
  static void Measure(const MeshType& m, double threshold, int threads, std::size_t& obtuse,
                      std::size_t& above, double& angleMin, double& angleMax) {
    obtuse = above = 0;
    angleMin = 180.0;
    angleMax = 0.0;
    std::vector<std::array<double, 2>> ranges;
    FaceAngleRanges(m, threads, ranges);
    for (std::size_t fi = 0; fi < m.face.size(); ++fi) {
      if (m.face[fi].IsD()) continue;
      const auto [lo, hi] = ranges[fi];
      angleMin = std::min(angleMin, lo);
      angleMax = std::max(angleMax, hi);
      if (hi >= 90.0) ++obtuse;
      if (hi > threshold) ++above;
    }
  }

  /// Worst angles and number of small-angle triangles of a set of triangles.
  struct Shape : AngleTally {
    /// Better for the stage: smaller largest angle first, then larger smallest angle.
    bool BetterThan(const Shape& o) const {
      if (maxDeg != o.maxDeg) return maxDeg < o.maxDeg;
      return minDeg > o.minDeg;
    }
  };

  class Session {
  public:
    Session(Ops& ops, const Params& params)
        : ops_(ops), m_(ops.Mesh()), ref_(ops.GetReference()), params_(params) {}

    void Run(Result& r) {
      for (const double t : params_.thresholdsDeg) TranslationRounds(t, params_.iterationsPerThreshold, r);
      if (!params_.pentagonInsertion) return;
      Collect(90.0);
      for (const auto& [key, fi] : faces_) {
        if (m_.face[fi].IsD() || !(MaxAngle(m_.face[fi]) >= 90.0)) continue;
        if (InsertInPentagon(fi)) ++r.insertions;
      }
      TranslationRounds(params_.thresholdsDeg.back(), 1, r);
    }

  private:
    std::size_t VIndex(const VertexType* v) const { return std::size_t(v - &m_.vert[0]); }
    double MinAngleBound() const { return params_.minAngleDeg; }

    double MaxAngle(const FaceType& f) const {
      double lo, hi;
      FaceAngleRange(f, lo, hi);
      return hi;
    }
    /// Faces with a largest angle above t (>= when t is 90: obtuse), worst first.
    void Collect(double t) {
      faces_.clear();
      FaceAngleRanges(m_, params_.threads, ranges_);
      for (std::size_t fi = 0; fi < m_.face.size(); ++fi) {
        if (m_.face[fi].IsD()) continue;
        const double a = ranges_[fi][1];
        if (a > t || (t == 90.0 && a >= t)) faces_.emplace_back(-a, std::uint32_t(fi));
      }
      std::sort(faces_.begin(), faces_.end());
    }
    /// Whether `after` may replace `before`: a smaller largest angle and no new small angle.
    bool Acceptable(const Shape& before, const Shape& after) const {
      return after.maxDeg < before.maxDeg - 1e-9 && after.small <= before.small &&
             after.minDeg >= std::min(before.minDeg, MinAngleBound());
    }

    void TranslationRounds(double threshold, int rounds, Result& r) {
      for (int round = 0; round < rounds; ++round) {
        Collect(threshold);
        if (faces_.empty()) return;
        ++r.rounds;
        std::size_t moved = 0;
        for (const auto& [key, fi] : faces_) {
          const FaceType& f = m_.face[fi];
          if (f.IsD() || !(MaxAngle(f) > threshold || (threshold == 90.0 && MaxAngle(f) >= 90.0))) continue;
          // The vertex at the largest angle: opposite the longest edge.
          int corner = 0;
          double longest = -1;
          for (int k = 0; k < 3; ++k) {
            const double l = (PositionOf(f.cV((k + 1) % 3)) - PositionOf(f.cV((k + 2) % 3))).SquaredNorm();
            if (l > longest) longest = l, corner = k;
          }
          if (TranslateAnyCorner(f, corner)) ++r.moves, ++moved;
        }
        if (moved == 0) return;
      }
    }

    Shape StarShape(const VertexType* v, const Point& q) const {
      return StarShapeAt<Shape, FaceType>(v, q, MinAngleBound());
    }

    /// Lowers the largest angle of f, at `corner`: by moving that vertex; where its other faces pin
    /// it, by moving one of the two others (moving B toward the line AC shrinks the angle at A;
    /// their stars contain f, so Translate's test applies unchanged); where all three are pinned,
    /// after widening the angles that pin the first one (MakeRoomAround).
    bool TranslateAnyCorner(const FaceType& f, int corner) {
      const std::size_t a = VIndex(f.cV(corner)), b = VIndex(f.cV((corner + 1) % 3)),
                        c = VIndex(f.cV((corner + 2) % 3));
      if (Translate(a) || Translate(b) || Translate(c)) return true;
      return MakeRoomAround(a) && (Translate(a) || Translate(b) || Translate(c));
    }

    /// Moves vertex vi to the best sample of its feasible disc, when that lowers the largest angle
    /// of its star without a new small angle.
    bool Translate(std::size_t vi) {
      VertexType& v = m_.vert[vi];
      const Shape before = StarShape(&v, PositionOf(&v));
      candidates_.clear();
      const bool sampled = ForEachDiscSample(vi, [&](const Point& q, int foot) {
        const Shape s = StarShape(&v, q);
        if (Acceptable(before, s)) candidates_.push_back({s, 0.0, q, foot});
      });
      if (!sampled) return false;
      std::stable_sort(candidates_.begin(), candidates_.end(),
                       [](const Candidate& x, const Candidate& y) { return x.shape.BetterThan(y.shape); });
      return MoveToFirstAccepted(v);
    }

    /// Widens the angles that keep vertex ai from moving: each free neighbour u of it goes to the
    /// disc sample that most raises the smallest angle of the faces u and ai share (by at least
    /// kRoomGainDeg), when u's star gets no larger largest angle and no new small angle. True when
    /// a neighbour moved.
    bool MakeRoomAround(std::size_t ai) {
      VertexType& a = m_.vert[ai];
      if (!IsFreeVertex(ops_, a)) return false;
      std::vector<std::size_t> ring;
      for (vcg::face::VFIterator<FaceType> it(&a); !it.End(); ++it)
        ring.push_back(VIndex(it.F()->cV((it.I() + 1) % 3)));
      bool moved = false;
      for (const std::size_t ui : ring) moved = WidenSharedAngles(ui, a) || moved;
      return moved;
    }

    bool WidenSharedAngles(std::size_t ui, const VertexType& a) {
      constexpr double kRoomGainDeg = 0.5;
      VertexType& u = m_.vert[ui];
      const Point p0 = PositionOf(&u);
      const Shape before = StarShape(&u, p0);
      const double sharedBefore = SharedMinAngle(u, a, p0);
      candidates_.clear();
      const bool sampled = ForEachDiscSample(ui, [&](const Point& q, int foot) {
        const Shape s = StarShape(&u, q);
        if (s.maxDeg > before.maxDeg + 1e-9 || s.small > before.small ||
            s.minDeg < std::min(before.minDeg, MinAngleBound()))
          return;
        const double shared = SharedMinAngle(u, a, q);
        if (shared > sharedBefore + kRoomGainDeg) candidates_.push_back({s, shared, q, foot});
      });
      if (!sampled) return false;
      std::stable_sort(candidates_.begin(), candidates_.end(),
                       [](const Candidate& x, const Candidate& y) { return x.gain > y.gain; });
      return MoveToFirstAccepted(u);
    }

    /// The smallest angle of the faces around u that have a corner at a, with u at q.
    double SharedMinAngle(const VertexType& u, const VertexType& a, const Point& q) const {
      AngleTally t;
      for (vcg::face::VFIterator<FaceType> it(const_cast<VertexType*>(&u)); !it.End(); ++it) {
        const VertexType* next = it.F()->cV((it.I() + 1) % 3);
        const VertexType* prev = it.F()->cV((it.I() + 2) % 3);
        if (next == &a || prev == &a) t.Add(q, PositionOf(next), PositionOf(prev), MinAngleBound());
      }
      return t.minDeg;
    }

    /// Calls visit(point, footFace) for each sample of the feasible disc of vertex vi
    /// (discRings x discDirections positions in its tangent plane, radius up to discRadiusFactor x
    /// its shortest edge), projected onto the reference near its footpoint. False when vi is not
    /// free or has no tangent plane.
    template <class Visit>
    bool ForEachDiscSample(std::size_t vi, Visit&& visit) {
      ops_.EnsureFootpointsAround(m_.vert[vi]); // lazy footpoints (Init)
      VertexType& v = m_.vert[vi];
      if (!IsFreeVertex(ops_, v)) return false;
      const Point p0 = PositionOf(&v);
      Point n(0, 0, 0);
      double shortest = std::numeric_limits<double>::infinity();
      for (vcg::face::VFIterator<FaceType> it(&v); !it.End(); ++it) {
        const Point a = PositionOf(it.F()->cV((it.I() + 1) % 3)),
                    b = PositionOf(it.F()->cV((it.I() + 2) % 3));
        n += (a - p0) ^ (b - p0);
        shortest = std::min(shortest, (a - p0).Norm());
      }
      if (!(n.Norm() > 0) || !(shortest > 0)) return false;
      n.Normalize();
      Point e1, e2;
      TangentBasis(n, e1, e2);
      const int foot = ops_.Footpoint(v);
      for (int ri = 1; ri <= params_.discRings; ++ri) {
        const double radius = params_.discRadiusFactor * shortest * ri / params_.discRings;
        for (int d = 0; d < params_.discDirections; ++d) {
          const double t = 2.0 * kPi * d / params_.discDirections;
          const SurfaceProjection proj =
              ref_.Project(p0 + (e1 * std::cos(t) + e2 * std::sin(t)) * radius, foot, scratch_);
          if (proj.ok()) visit(proj.point, proj.face);
        }
      }
      return true;
    }

    /// Moves v to the first of the (sorted) candidates the guards accept, trying four at most.
    bool MoveToFirstAccepted(VertexType& v) {
      for (std::size_t i = 0; i < candidates_.size() && i < 4; ++i)
        if (ops_.MoveVertexTo(&v, candidates_[i].point, candidates_[i].foot)) return true;
      return false;
    }

    /// Index of the longest edge of f, skipping edge `skip` (-1: none).
    static int LongestEdge(const FaceType& f, int skip) {
      int best = -1;
      double longest = -1;
      for (int e = 0; e < 3; ++e) {
        if (e == skip) continue;
        const double l = (PositionOf(f.cV(e)) - PositionOf(f.cV((e + 1) % 3))).SquaredNorm();
        if (l > longest) longest = l, best = e;
      }
      return best;
    }

    static Point Normal(const FaceType& f) {
      Point n = (PositionOf(f.cV(1)) - PositionOf(f.cV(0))) ^ (PositionOf(f.cV(2)) - PositionOf(f.cV(0)));
      const double len = n.Norm();
      return len > 0 ? n / len : Point(0, 0, 0);
    }

    /// Pentagon point insertion around obtuse face fi (see the file comment).
    bool InsertInPentagon(std::size_t fi) {
      ops_.EnsureFootpointsAround(m_.face[fi]); // lazy footpoints (Init)

      FaceType& f = m_.face[fi];
      const int z = LongestEdge(f, -1);
      FacePointer g = f.FFp(z);
      if (g == &f) return false;
      int e2 = LongestEdge(*g, -1);
      if (g->FFp(e2) == &f) e2 = LongestEdge(*g, f.FFi(z));
      FacePointer h = g->FFp(e2);
      if (h == g || h == &f) return false;
      const Point nf = Normal(f), ng = Normal(*g), nh = Normal(*h);
      const double cosLimit = std::cos(params_.pentagonNormalDeg * kPi / 180.0);
      if (nf * ng < cosLimit || ng * nh < cosLimit || nf * nh < cosLimit) return false;
      region_ = {&f, g, h};
      if (!ops_.DiskBoundary(region_, loop_, interior_) || loop_.size() != 5 || !interior_.empty())
        return false;
      Shape before;
      for (const FacePointer r : region_)
        before.Add(PositionOf(r->cV(0)), PositionOf(r->cV(1)), PositionOf(r->cV(2)), MinAngleBound());
      std::array<Point, 5> q;
      Point centroid(0, 0, 0);
      for (int i = 0; i < 5; ++i) centroid += (q[i] = PositionOf(loop_[i]));
      centroid /= 5.0;
      Point n = nf + ng + nh;
      n.Normalize();
      Point e1 = q[0] - centroid;
      e1 -= n * (e1 * n);
      if (!(e1.Norm() > 0)) return false;
      e1.Normalize();
      const Point e2d = n ^ e1;
      // The pentagon in its mean plane, for the inside test and the sampling box.
      std::array<std::pair<double, double>, 5> poly;
      double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
      for (int i = 0; i < 5; ++i) {
        const Point d = q[i] - centroid;
        poly[i] = {d * e1, d * e2d};
        x0 = std::min(x0, poly[i].first), x1 = std::max(x1, poly[i].first);
        y0 = std::min(y0, poly[i].second), y1 = std::max(y1, poly[i].second);
      }
      auto inside = [&](double x, double y) {
        // Strictly inside a counter-clockwise polygon (the loop follows the faces' orientation).
        for (int i = 0; i < 5; ++i) {
          const auto [ax, ay] = poly[i];
          const auto [bx, by] = poly[(i + 1) % 5];
          if ((bx - ax) * (y - ay) - (by - ay) * (x - ax) <= 0) return false;
        }
        return true;
      };
      auto fanShape = [&](const Point& p) {
        Shape s;
        for (int i = 0; i < 5; ++i) s.Add(q[i], q[(i + 1) % 5], p, MinAngleBound());
        return s;
      };
      bool found = false;
      Shape best;
      Point bestPoint;
      const int N = params_.pentagonSamples;
      for (int j = 0; j <= N; ++j)
        for (int i = 0; i <= N; ++i) {
          const double x = x0 + (x1 - x0) * (i + 0.5 * (j % 2)) / (N + 0.5), y = y0 + (y1 - y0) * j / N;
          if (!inside(x, y)) continue;
          const Point p = centroid + e1 * x + e2d * y;
          const Shape s = fanShape(p);
          if (!found || s.small < best.small || (s.small == best.small && s.BetterThan(best)))
            found = true, best = s, bestPoint = p;
        }
      if (!found || !Acceptable(before, best)) return false;
      // Project as ReplaceDisk will (near the footpoint of the closest loop vertex) and check again.
      int nearest = 0;
      for (int i = 1; i < 5; ++i)
        if ((q[i] - bestPoint).SquaredNorm() < (q[nearest] - bestPoint).SquaredNorm()) nearest = i;
      const SurfaceProjection proj = ref_.Project(bestPoint, ops_.Footpoint(*loop_[nearest]), scratch_);
      if (!proj.ok() || !Acceptable(before, fanShape(proj.point))) return false;
      const std::vector<std::array<int, 3>> fan{{0, 1, 5}, {1, 2, 5}, {2, 3, 5}, {3, 4, 5}, {4, 0, 5}};
      return ops_.ReplaceDisk(region_, loop_, {proj.point}, fan);
    }

    struct Candidate {
      Shape shape;
      double gain; ///< MakeRoomAround: the smallest shared angle reached
      Point point;
      int foot;
    };

    Ops& ops_;
    MeshType& m_;
    const Reference& ref_;
    const Params& params_;
    typename Reference::Scratch scratch_;
    std::vector<std::pair<double, std::uint32_t>> faces_;
    std::vector<std::array<double, 2>> ranges_; ///< scratch of Collect
    std::vector<Candidate> candidates_;
    std::vector<FacePointer> region_;
    std::vector<VertexPointer> loop_, interior_;
  };
};

} // namespace molremesh

// Local smoothing (Khan et al. 2020, section 3.6): Laplacian translation and local RAR-like edits
// (flip, collapse, split) on the triangles that are still bad after the previous stages, a mesh
// lying on a ReferenceSurface.
//
// A triangle is bad when it has an angle below Params::minAngleDeg (30 degrees) or one at or above
// Params::maxAngleDeg (90 degrees: obtuse). Each round gathers the bad triangles and their direct
// neighbours (across an edge) and tries, in this order:
//  1. Laplacian translation of each of their vertices: to the centroid of its one-ring, moved in
//     the tangent plane and projected onto the reference near its footpoint (half the step when
//     the full one is not accepted);
//  2. flip of each edge of a bad triangle;
//  3. collapse of the shortest edge of a triangle with a small angle (one end point staying where
//     it is, the one giving the better triangles);
//  4. split of the longest edge of an obtuse triangle at its midpoint (projected onto the
//     reference exactly as LocalRemeshingOps::SplitEdge does), then a Laplacian move of the new
//     vertex.
// The faces an edit would produce are known before it is applied, so every edit is judged on them
// against the faces it replaces and applied only when it improves them: fewer bad triangles, or as
// many with a smaller worst excess max(largest - maxAngleDeg, minAngleDeg - smallest), and in any
// case no new small angle (no more triangles below minAngleDeg, no angle below the smaller of
// minAngleDeg and the region's former smallest), no more obtuse triangles and no largest angle at
// or above maxAngleDeg that is larger than the region's former largest. Rounds stop when
// nothing is bad, when a round changes nothing, or after Params::iterations rounds.
//
// Every edit goes through LocalRemeshingOps (Params::guards): the mesh stays a 2-manifold with its
// genus and closed components, no intersecting pair appears, every vertex stays on the reference.
//
// Determinism: edits run serially in a fixed order (faces by excess, then index); no random choice
// is made (the seed is accepted for the pipeline's uniform interface); the output does not depend on
// the thread count. A mesh without a bad triangle is only scanned.
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
class LocalSmoothing {
public:
  using VertexType = typename MeshType::VertexType;
  using FaceType = typename MeshType::FaceType;
  using VertexPointer = typename MeshType::VertexPointer;
  using FacePointer = typename MeshType::FacePointer;
  using Ops = LocalRemeshingOps<MeshType>;
  using Reference = ReferenceSurface<MeshType>;
  using Point = vcg::Point3d;

  /// Guards of the stage's edits: new angles below 30 degrees only where the region's smallest
  /// angle improves; the stage judges the largest angle itself.
  static LocalOpsGuards DefaultGuards() { return GuardsWithAngleBounds(30.0, 180.0); }

  struct Params {
    double targetEdgeLength = 0; ///< L; 0 = mean edge length of the mesh
    int threads = 0;             ///< 0 = all cores (the output does not depend on it)
    std::uint64_t seed = 1;      ///< seed of every random choice (the stage makes none)
    /// Vertices never moved or removed, nor joined by an edit of an edge between two of them
    /// (indexed like m.vert at entry; nonzero = locked; empty = none): the border of a region.
    std::vector<std::uint8_t> lockedVertices;
    double minAngleDeg = 30.0;  ///< triangles with a smaller angle are bad
    double maxAngleDeg = 90.0;  ///< triangles with an angle at or above it are bad (obtuse)
    int iterations = 5;         ///< rounds (cap)
    bool laplacian = true;      ///< Laplacian translation of the bad region's vertices
    bool flips = true;          ///< flips of the bad triangles' edges
    bool collapses = true;      ///< collapses of the small-angle triangles' shortest edges
    bool splits = true;         ///< splits of the obtuse triangles' longest edges
    double maxEdgeFactor = 2.0; ///< a collapse never creates an edge longer than this x L
    LocalOpsGuards guards =
        DefaultGuards(); ///< guards of every edit (minAngleDeg is set to Params::minAngleDeg)
  };

  struct Result {
    bool ok = false;
    std::string message;                     ///< why it failed, or a one-line summary
    std::size_t badBefore = 0, badAfter = 0; ///< bad triangles (small or obtuse)
    std::size_t smallAfter = 0, obtuseAfter = 0;
    double angleMinBefore = 0, angleMinAfter = 0, angleMaxBefore = 0, angleMaxAfter = 0; ///< degrees
    std::size_t moves = 0, flips = 0, collapses = 0, splits = 0;                         ///< applied edits
    std::size_t refused = 0; ///< edits refused by the guards of LocalRemeshingOps
    int rounds = 0;
  };

  /// Runs the stage on m (a 2-manifold, consistently oriented mesh with FF and VF adjacency
  /// enabled, lying on reference). On failure m is left untouched (FF/VF adjacency recomputed)
  /// and Result::message says why.
  static Result Do(MeshType& m, const Reference& reference, const Params& params) {
    Result r;
    auto finish = [&](bool ok, const std::string& message) { return FinishStage(r, ok, message); };
    const std::string refused = "local smoothing refused: ";
    const InputCheck check = CheckTriangleMeshInput(m);
    if (!check.ok) return finish(false, refused + check.message);
    if (!(params.minAngleDeg >= 0 && params.minAngleDeg < 60) ||
        !(params.maxAngleDeg > 60 && params.maxAngleDeg <= 180))
      return finish(false, refused + "need 0 <= minAngleDeg < 60 < maxAngleDeg <= 180");
    if (params.iterations < 0) return finish(false, refused + "negative iteration count");
    double L = 0;
    std::string error;
    if (!PrepareLocalStage(m, reference, params.targetEdgeLength, L, error))
      return finish(false, refused + error);

    std::size_t small = 0, obtuse = 0;
    r.badBefore = Measure(m, params, small, obtuse, r.angleMinBefore, r.angleMaxBefore);
    if (r.badBefore == 0) { // nothing to do: a scan only
      r.angleMinAfter = r.angleMinBefore;
      r.angleMaxAfter = r.angleMaxBefore;
      return finish(true, "local smoothing: no bad triangle");
    }
    LocalOpsGuards guards = params.guards;
    guards.minAngleDeg = params.minAngleDeg;
    const auto edits = [&](Ops& ops) {
      Session session(ops, params, L);
      session.Run(r);
    };
    if (!RunLocalEdits(m, reference, L, guards, params.threads, params.lockedVertices, error, r.refused,
                       edits))
      return finish(false, refused + error);
    r.badAfter = Measure(m, params, r.smallAfter, r.obtuseAfter, r.angleMinAfter, r.angleMaxAfter);
    return finish(true, "local smoothing: " + std::to_string(r.badBefore) + " -> " +
                            std::to_string(r.badAfter) + " bad faces");
  }

private:
  static std::size_t Measure(const MeshType& m, const Params& p, std::size_t& small, std::size_t& obtuse,
                             double& angleMin, double& angleMax) {
    std::size_t bad = 0;
    small = obtuse = 0;
    angleMin = 180.0;
    angleMax = 0.0;
    std::vector<std::array<double, 2>> ranges;
    FaceAngleRanges(m, p.threads, ranges);
    for (std::size_t fi = 0; fi < m.face.size(); ++fi) {
      if (m.face[fi].IsD()) continue;
      const auto [lo, hi] = ranges[fi];
      angleMin = std::min(angleMin, lo);
      angleMax = std::max(angleMax, hi);
      const bool s = lo < p.minAngleDeg, o = hi >= p.maxAngleDeg;
      small += s;
      obtuse += o;
      bad += (s || o);
    }
    return bad;
  }

  /// What the stage judges a set of triangles by.
  struct Shape {
    double minDeg = 180.0, maxDeg = 0.0;
    int small = 0, obtuse = 0, bad = 0;
    double excess = 0; ///< worst max(largest - maxAngle, minAngle - smallest, 0)
    void Add(const Point& a, const Point& b, const Point& c, const Params& p) {
      double lo, hi;
      TriangleAngleRange(a, b, c, lo, hi);
      Add(lo, hi, p);
    }
    /// The shape of one triangle with angle range [lo, hi].
    static Shape OfRange(double lo, double hi, const Params& p) {
      Shape s;
      s.Add(lo, hi, p);
      return s;
    }
    void Add(double lo, double hi, const Params& p) {
      minDeg = std::min(minDeg, lo);
      maxDeg = std::max(maxDeg, hi);
      const bool s = lo < p.minAngleDeg, o = hi >= p.maxAngleDeg;
      small += s;
      obtuse += o;
      bad += (s || o);
      excess = std::max({excess, hi - p.maxAngleDeg, p.minAngleDeg - lo});
    }
  };

  class Session {
  public:
    Session(Ops& ops, const Params& params, double L)
        : ops_(ops), m_(ops.Mesh()), ref_(ops.GetReference()), params_(params), L_(L) {}

    void Run(Result& r) {
      for (int round = 0; round < params_.iterations; ++round) {
        CollectBad();
        if (bad_.empty()) return;
        r.rounds = round + 1;
        std::size_t changed = 0;
        if (params_.laplacian) {
          // The vertices of the bad triangles and of their neighbours, each once, in a fixed order.
          std::vector<std::uint32_t> verts;
          for (const auto& [key, fi] : bad_) {
            const FaceType& f = m_.face[fi];
            for (int e = 0; e < 3; ++e) {
              verts.push_back(std::uint32_t(VIndex(f.cV(e))));
              verts.push_back(std::uint32_t(VIndex(f.cFFp(e)->cV((f.cFFi(e) + 2) % 3))));
            }
          }
          std::sort(verts.begin(), verts.end());
          verts.erase(std::unique(verts.begin(), verts.end()), verts.end());
          for (const std::uint32_t vi : verts)
            if (Laplacian(vi)) ++r.moves, ++changed;
        }
        if (params_.flips) {
          CollectBad();
          for (const auto& [key, fi] : bad_)
            if (!m_.face[fi].IsD() && IsBad(m_.face[fi]) && Flip(fi)) ++r.flips, ++changed;
        }
        if (params_.collapses) {
          CollectBad();
          for (const auto& [key, fi] : bad_)
            if (!m_.face[fi].IsD() && MinAngle(m_.face[fi]) < params_.minAngleDeg && Collapse(fi))
              ++r.collapses, ++changed;
        }
        if (params_.splits) {
          CollectBad();
          for (const auto& [key, fi] : bad_) {
            if (m_.face[fi].IsD() || !(MaxAngle(m_.face[fi]) >= params_.maxAngleDeg)) continue;
            const long v = Split(fi);
            if (v < 0) continue;
            ++r.splits, ++changed;
            if (params_.laplacian && Laplacian(std::size_t(v))) ++r.moves;
          }
        }
        if (changed == 0) return;
      }
    }

  private:
    std::size_t VIndex(const VertexType* v) const { return std::size_t(v - &m_.vert[0]); }

    Shape FaceShape(const FaceType& f) const {
      Shape s;
      s.Add(PositionOf(f.cV(0)), PositionOf(f.cV(1)), PositionOf(f.cV(2)), params_);
      return s;
    }
    double MinAngle(const FaceType& f) const { return FaceShape(f).minDeg; }
    double MaxAngle(const FaceType& f) const { return FaceShape(f).maxDeg; }
    bool IsBad(const FaceType& f) const { return FaceShape(f).bad > 0; }

    void CollectBad() {
      bad_.clear();
      FaceAngleRanges(m_, params_.threads, ranges_);
      for (std::size_t fi = 0; fi < m_.face.size(); ++fi) {
        if (m_.face[fi].IsD()) continue;
        const Shape s = Shape::OfRange(ranges_[fi][0], ranges_[fi][1], params_);
        if (s.bad) bad_.emplace_back(-s.excess, std::uint32_t(fi));
      }
      std::sort(bad_.begin(), bad_.end());
    }

    /// Whether `after` may replace `before` (see the file comment).
    bool Improves(const Shape& before, const Shape& after) const {
      if (after.small > before.small || after.obtuse > before.obtuse) return false;
      if (after.minDeg < std::min(before.minDeg, params_.minAngleDeg)) return false;
      // The largest angle never grows past the bound (fewer bad triangles do not pay for a worse one).
      if (after.maxDeg >= params_.maxAngleDeg && after.maxDeg > before.maxDeg) return false;
      if (after.bad != before.bad) return after.bad < before.bad;
      return after.excess < before.excess - 1e-9;
    }

    Shape StarShape(const VertexType* v, const Point& q) const {
      return StarShapeAt<Shape, FaceType>(v, q, params_);
    }

    bool Laplacian(std::size_t vi) {
      ops_.EnsureFootpointsAround(m_.vert[vi]); // lazy footpoints (Init)

      VertexType& v = m_.vert[vi];
      if (!IsFreeVertex(ops_, v)) return false;
      const Point p0 = PositionOf(&v);
      Point c(0, 0, 0), n(0, 0, 0);
      int count = 0;
      for (vcg::face::VFIterator<FaceType> it(&v); !it.End(); ++it) {
        const Point a = PositionOf(it.F()->cV((it.I() + 1) % 3)),
                    b = PositionOf(it.F()->cV((it.I() + 2) % 3));
        c += a;
        n += (a - p0) ^ (b - p0);
        ++count;
      }
      if (count < 3 || !(n.Norm() > 0)) return false;
      n.Normalize();
      Point step = c / double(count) - p0;
      step -= n * (step * n);
      const Shape before = StarShape(&v, p0);
      for (const double t : {1.0, 0.5}) {
        const SurfaceProjection proj = ref_.Project(p0 + step * t, ops_.Footpoint(v), scratch_);
        if (!proj.ok() || !Improves(before, StarShape(&v, proj.point))) continue;
        if (ops_.MoveVertexTo(&v, proj.point, proj.face)) return true;
      }
      return false;
    }

    /// Flips the edge of fi whose flip improves its two triangles most.
    bool Flip(std::size_t fi) {
      ops_.EnsureFootpointsAround(m_.face[fi]); // lazy footpoints (Init)

      FaceType& f = m_.face[fi];
      int bestEdge = -1;
      Shape best;
      for (int z = 0; z < 3; ++z) {
        if (f.cFFp(z) == &f) continue;
        Shape before, after;
        FlipShapes(EdgeQuad(f, z), params_, before, after);
        if (!Improves(before, after)) continue;
        if (bestEdge < 0 || after.bad < best.bad || (after.bad == best.bad && after.excess < best.excess))
          bestEdge = z, best = after;
      }
      return bestEdge >= 0 && ops_.FlipEdge(&f, bestEdge);
    }

    /// Collapses the shortest edge of fi, one end point staying, when that improves the region.
    bool Collapse(std::size_t fi) {
      ops_.EnsureFootpointsAround(m_.face[fi]); // lazy footpoints (Init)

      FaceType& f = m_.face[fi];
      const int z = ShortestEdgeIndex(f);
      VertexPointer a = f.V(z), b = f.V((z + 1) % 3);
      if (ops_.IsBoundaryVertex(*a) || ops_.IsBoundaryVertex(*b)) return false;
      Shape before;
      for (VertexPointer v : {a, b})
        for (vcg::face::VFIterator<FaceType> it(v); !it.End(); ++it)
          if (v == a || !(it.F()->cV(0) == a || it.F()->cV(1) == a || it.F()->cV(2) == a))
            before.Add(PositionOf(it.F()->cV(0)), PositionOf(it.F()->cV(1)), PositionOf(it.F()->cV(2)),
                       params_);
      int bestKeep = -1;
      Shape best;
      for (int keep = 0; keep < 2; ++keep) {
        const Point q = keep == 0 ? PositionOf(a) : PositionOf(b);
        Shape s;
        for (VertexPointer v : {a, b})
          for (vcg::face::VFIterator<FaceType> it(v); !it.End(); ++it) {
            const FaceType* g = it.F();
            const bool hasA = g->cV(0) == a || g->cV(1) == a || g->cV(2) == a;
            const bool hasB = g->cV(0) == b || g->cV(1) == b || g->cV(2) == b;
            if (hasA && hasB) continue; // removed by the collapse
            std::array<Point, 3> p;
            for (int c = 0; c < 3; ++c) p[c] = (g->cV(c) == a || g->cV(c) == b) ? q : PositionOf(g->cV(c));
            s.Add(p[0], p[1], p[2], params_);
          }
        if (!Improves(before, s)) continue;
        if (bestKeep < 0 || s.bad < best.bad || (s.bad == best.bad && s.excess < best.excess))
          bestKeep = keep, best = s;
      }
      if (bestKeep < 0) return false;
      VertexType& keeper = bestKeep == 0 ? *a : *b;
      const bool wasLocked = ops_.IsLocked(keeper);
      ops_.SetLocked(keeper, true);
      const bool ok = ops_.CollapseEdge(&f, z, params_.maxEdgeFactor * L_);
      ops_.SetLocked(keeper, wasLocked);
      return ok;
    }

    /// Splits the longest edge of obtuse face fi when that improves the two triangles; returns the
    /// new vertex's index or -1.
    long Split(std::size_t fi) {
      ops_.EnsureFootpointsAround(m_.face[fi]); // lazy footpoints (Init)
      FaceType& f = m_.face[fi];
      int z = 0;
      double longest = -1;
      for (int k = 0; k < 3; ++k) {
        const double l = (PositionOf(f.cV(k)) - PositionOf(f.cV((k + 1) % 3))).SquaredNorm();
        if (l > longest) longest = l, z = k;
      }
      const FaceType* g = f.cFFp(z);
      if (g == &f) return -1;
      const auto [p0, p1, p2, p3] = EdgeQuad(f, z);
      // The midpoint exactly where SplitEdge puts it.
      const SurfaceProjection proj = ref_.Project((p0 + p1) * 0.5, ops_.Footpoint(*f.cV(z)), scratch_);
      if (!proj.ok()) return -1;
      const Point q = proj.point;
      Shape before, after;
      before.Add(p0, p1, p2, params_);
      before.Add(p1, p0, p3, params_);
      after.Add(p0, q, p2, params_);
      after.Add(q, p1, p2, params_);
      after.Add(p1, q, p3, params_);
      after.Add(q, p0, p3, params_);
      if (!Improves(before, after)) return -1;
      const VertexPointer v = ops_.SplitEdge(&f, z);
      return v == nullptr ? -1 : long(VIndex(v));
    }

    Ops& ops_;
    MeshType& m_;
    const Reference& ref_;
    const Params& params_;
    double L_;
    typename Reference::Scratch scratch_;
    std::vector<std::pair<double, std::uint32_t>> bad_;
    std::vector<std::array<double, 2>> ranges_; ///< scratch of CollectBad
  };
};

} // namespace molremesh

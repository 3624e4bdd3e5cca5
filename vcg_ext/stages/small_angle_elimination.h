// Small-angle elimination (Khan et al. 2020, section 3.4): removes every angle below
// Params::minAngleDeg (30 degrees) from a mesh that lies on a ReferenceSurface.
//
// SmallAngleElimination<MeshType> works on the triangles that still have a small angle, in rounds;
// each round runs the paper's four tools, cheapest first, each on the faces still bad:
//  1. collapse: a triangle with an angle below collapseAngleDeg (20 degrees, a needle) has its
//     shortest edge (the one opposite that angle) collapsed. Three outcomes are evaluated — either
//     end point survives where it is, or the midpoint — and the one whose new faces have the
//     largest smallest angle is tried first, because a needle's shortest edge is usually an
//     artefact of the input triangulation, not of the surface;
//  2. flip: an edge of a bad triangle is flipped when that raises the smallest angle of the pair
//     (a cap's longest edge, typically), the cheap part of "local RAR";
//  3. constrained vertex translation: each corner of a bad triangle is moved to the Laplacian
//     position of its one-ring (tangential, projected onto the reference), else to the best of a
//     ring of nearby positions (a compass search in the tangent plane). A move is applied only
//     when it raises the smallest angle of the star and creates no new triangle with an angle
//     below minAngleDeg (counted, not just the worst one), and no angle above maxAngleDeg that
//     was not there;
//  4. delete-and-refill: a corner whose star still has a small angle is deleted and its hole
//     (the link polygon) retriangulated without it by the triangulation that maximizes the
//     smallest angle (dynamic programming over the polygon's triangulations, O(n^3) with n the
//     valence), through LocalRemeshingOps::ReplaceDisk; then the refilled area gets a flip and a
//     Laplacian round (the paper's "RAR/Laplacian on the refilled area").
// Rounds stop when no angle below minAngleDeg is left, when a round changes nothing, or after
// maxIterations rounds, so the stage always ends. Angles that survive sit where the reference
// itself is too sharp (cusps of the molecular surface) for any guarded edit.
//
// Every edit goes through LocalRemeshingOps (guards: Params::guards), so the mesh stays a
// 2-manifold with the same genus and closed components, no intersecting pair appears, and every
// vertex stays on the reference near its previous footpoint. Edits are local, so the enclosed
// volume changes only by the chords of the few edited triangles.
//
// Determinism: the edits run serially, in a fixed order (faces by smallest angle, then index);
// only Init's footpoint search runs in parallel. No random choice is made: the output does not
// depend on the thread count, and the seed is accepted for the pipeline's uniform interface.
// A mesh without a small angle is only scanned (no reference lookup): the stage is then a no-op.
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
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace molremesh {

template <class MeshType>
class SmallAngleElimination {
public:
  using VertexType = typename MeshType::VertexType;
  using FaceType = typename MeshType::FaceType;
  using VertexPointer = typename MeshType::VertexPointer;
  using FacePointer = typename MeshType::FacePointer;
  using Ops = LocalRemeshingOps<MeshType>;
  using Reference = ReferenceSurface<MeshType>;
  using Point = vcg::Point3d;

  /// Guards of the stage's edits: new angles below 30 degrees or above 120 degrees only where the
  /// region's worst angle improves (Khan et al.'s angle bounds).
  static LocalOpsGuards DefaultGuards() { return GuardsWithAngleBounds(30.0, 120.0); }

  struct Params {
    double targetEdgeLength = 0; ///< L; 0 = mean edge length of the mesh
    int threads = 0;             ///< 0 = all cores (the output does not depend on it)
    std::uint64_t seed = 1;      ///< seed of every random choice (the stage makes none)
    /// Vertices never moved or removed, nor joined by an edit of an edge between two of them
    /// (indexed like m.vert at entry; nonzero = locked; empty = none): the border of a region.
    std::vector<std::uint8_t> lockedVertices;
    double minAngleDeg = 30.0;      ///< goal: no angle below it
    double collapseAngleDeg = 20.0; ///< triangles with an angle below it get their shortest edge collapsed
    double maxAngleDeg = 120.0; ///< moves and refills never create an angle above it (unless one was there)
    int maxIterations = 10;     ///< rounds of collapse / flip / translation / refill (cap)
    int compassDirections = 12; ///< nearby positions tried per radius when the Laplacian one fails
    int compassRadii = 3; ///< radii of nearby positions: k / compassRadii x compassRadiusFactor x ring size
    double compassRadiusFactor = 0.4; ///< largest radius, relative to the mean length of the vertex's edges
    bool deleteAndRefill = true; ///< delete vertices that keep a small angle and retriangulate their hole
    int maxRefillValence = 12;   ///< only vertices of at most this valence are deleted
    double maxEdgeFactor = 2.0;  ///< a collapse never creates an edge longer than this x L
    /// Last resort for the faces still bad after the rounds: they usually straddle a sharp crease
    /// of the reference (a cusp between atom spheres), where every edit tilts a face more than
    /// guards.maxNormalDeviationDeg away from the reference normals averaged over its corners.
    /// The rounds run once more with the normal guard relaxed to this angle (still below 90, so
    /// no face turns over; intersections and the angle guards unchanged). 0 = off.
    double creaseNormalDeviationDeg = 89.0;
    /// ... and the fold guard relaxed to this angle between adjacent normals, as RAR's repair
    /// pass does: across a crease whose sides meet at 110-120 degrees (PyMOL's and EDTSurf's van
    /// der Waals cusps) every move of a crease vertex tilts some pair past the default 120.
    double creaseFoldAngleDeg = 165.0;
    LocalOpsGuards guards =
        DefaultGuards(); ///< guards of every edit (minAngleDeg is set to Params::minAngleDeg)
  };

  struct Result {
    bool ok = false;
    std::string message;                          ///< why it failed, or a one-line summary
    bool creasePass = false;                      ///< the last-resort pass ran
    std::size_t smallFacesBefore = 0;             ///< faces with an angle below minAngleDeg, before
    std::size_t smallFacesAfter = 0;              ///< ... and after
    double angleMinBefore = 0, angleMinAfter = 0; ///< smallest angle, degrees
    std::size_t collapses = 0, flips = 0, moves = 0, refills = 0; ///< applied edits
    std::size_t refused = 0; ///< edits refused by the guards of LocalRemeshingOps
    int iterations = 0;      ///< rounds run
  };

  /// Runs the stage on m (a 2-manifold, consistently oriented mesh with FF and VF adjacency
  /// enabled, lying on reference). On failure m is left untouched (FF/VF adjacency recomputed)
  /// and Result::message says why.
  static Result Do(MeshType& m, const Reference& reference, const Params& params) {
    Result r;
    auto finish = [&](bool ok, const std::string& message) { return FinishStage(r, ok, message); };
    const std::string refused = "small-angle elimination refused: ";
    const InputCheck check = CheckTriangleMeshInput(m);
    if (!check.ok) return finish(false, refused + check.message);
    if (!(params.minAngleDeg > 0 && params.minAngleDeg < 60))
      return finish(false, refused + "minAngleDeg must be in (0, 60)");
    if (params.maxIterations < 0) return finish(false, refused + "negative maxIterations");
    double L = 0;
    std::string error;
    if (!PrepareLocalStage(m, reference, params.targetEdgeLength, L, error))
      return finish(false, refused + error);

    r.smallFacesBefore = CountSmall(m, params.minAngleDeg, params.threads, r.angleMinBefore);
    if (r.smallFacesBefore == 0) { // the fast path: nothing to do
      r.smallFacesAfter = 0;
      r.angleMinAfter = r.angleMinBefore;
      return finish(true, "small-angle elimination: no angle below " + Degrees(params.minAngleDeg));
    }
    LocalOpsGuards guards = params.guards;
    guards.minAngleDeg = params.minAngleDeg;
    const auto edits = [&](Ops& ops) {
      Session session(ops, params, L);
      session.Run(r);
      const auto stillSmall = [&] {
        double angleMin = 0;
        return CountSmall(m, params.minAngleDeg, params.threads, angleMin) > 0;
      };
      const auto moreRounds = [&] {
        const int rounds = r.iterations;
        session.Run(r);
        r.iterations += rounds;
      };
      r.creasePass = RunCreasePass(ops, guards, params.creaseNormalDeviationDeg, params.creaseFoldAngleDeg,
                                   stillSmall, moreRounds);
    };
    if (!RunLocalEdits(m, reference, L, guards, params.threads, params.lockedVertices, error, r.refused,
                       edits))
      return finish(false, refused + error);
    r.smallFacesAfter = CountSmall(m, params.minAngleDeg, params.threads, r.angleMinAfter);
    return finish(true, "small-angle elimination: " + std::to_string(r.smallFacesBefore) + " -> " +
                            std::to_string(r.smallFacesAfter) + " faces with an angle below " +
                            Degrees(params.minAngleDeg));
  }

private:
  /// An angle bound for the summary: "30 degrees", "27.5 degrees".
  static std::string Degrees(double deg) {
    std::ostringstream s;
    s << deg << " degrees";
    return s.str();
  }

  static std::size_t CountSmall(const MeshType& m, double minAngleDeg, int threads, double& angleMin) {
    std::size_t n = 0;
    angleMin = 180.0;
    std::vector<std::array<double, 2>> ranges;
    FaceAngleRanges(m, threads, ranges);
    for (std::size_t fi = 0; fi < m.face.size(); ++fi) {
      if (m.face[fi].IsD()) continue;
      const double lo = ranges[fi][0];
      angleMin = std::min(angleMin, lo);
      if (lo < minAngleDeg) ++n;
    }
    return n;
  }

  /// Worst angles and number of bad triangles of a set of triangles.
  using Shape = AngleTally;

  class Session {
  public:
    Session(Ops& ops, const Params& params, double L)
        : ops_(ops), m_(ops.Mesh()), ref_(ops.GetReference()), params_(params), L_(L) {}

    void Run(Result& r) {
      for (int round = 0; round < params_.maxIterations; ++round) {
        CollectBad();
        if (bad_.empty()) break;
        r.iterations = round + 1;
        std::size_t changed = 0;
        // 1. Needles: collapse their shortest edge.
        for (const auto& [angle, fi] : bad_) {
          if (!(angle < params_.collapseAngleDeg) || m_.face[fi].IsD()) continue;
          if (Collapse(fi)) ++r.collapses, ++changed;
        }
        // 2. Flips, 3. translations, on the faces still bad.
        CollectBad();
        for (const auto& [angle, fi] : bad_) {
          if (m_.face[fi].IsD() || !IsBad(m_.face[fi])) continue;
          if (FlipFace(fi)) ++r.flips, ++changed;
        }
        CollectBad();
        for (const auto& [angle, fi] : bad_) {
          for (int k = 0; k < 3; ++k) {
            if (m_.face[fi].IsD() || !IsBad(m_.face[fi])) break;
            if (Translate(VIndex(m_.face[fi].cV(k)))) ++r.moves, ++changed;
          }
        }
        // 4. Delete-and-refill what is left, then flips and translations around the refill.
        if (params_.deleteAndRefill) {
          CollectBad();
          for (const auto& [angle, fi] : bad_) {
            if (m_.face[fi].IsD() || !IsBad(m_.face[fi])) continue;
            if (Refill(fi, r)) ++r.refills, ++changed;
          }
        }
        if (changed == 0) break;
      }
    }

  private:
    std::size_t VIndex(const VertexType* v) const { return std::size_t(v - &m_.vert[0]); }
    std::size_t FIndex(const FaceType* f) const { return std::size_t(f - &m_.face[0]); }
    double Threshold() const { return params_.minAngleDeg; }

    double MinAngle(const FaceType& f) const {
      double lo, hi;
      FaceAngleRange(f, lo, hi);
      return lo;
    }
    bool IsBad(const FaceType& f) const { return MinAngle(f) < Threshold(); }

    /// Faces with a small angle, worst first (index breaks ties).
    void CollectBad() {
      bad_.clear();
      FaceAngleRanges(m_, params_.threads, ranges_);
      for (std::size_t fi = 0; fi < m_.face.size(); ++fi) {
        if (m_.face[fi].IsD()) continue;
        const double a = ranges_[fi][0];
        if (a < Threshold()) bad_.emplace_back(a, std::uint32_t(fi));
      }
      std::sort(bad_.begin(), bad_.end());
    }

    /// Shape of the star of v with v at q.
    Shape StarShape(const VertexType* v, const Point& q) const {
      return StarShapeAt<Shape, FaceType>(v, q, Threshold());
    }
    /// Whether `after` is an improvement over `before` the stage may apply: a larger smallest
    /// angle, no more bad triangles, no angle above the bound that was not there.
    bool Improves(const Shape& before, const Shape& after) const {
      return after.minDeg > before.minDeg + 1e-9 && after.small <= before.small &&
             after.maxDeg <= std::max(before.maxDeg, params_.maxAngleDeg);
    }

    // --- 1. Needle collapse ----------------------------------------------------------------------

    bool Collapse(std::size_t fi) {
      ops_.EnsureFootpointsAround(m_.face[fi]); // lazy footpoints (Init)

      FaceType& f = m_.face[fi];
      const int z = ShortestEdgeIndex(f);
      VertexPointer a = f.V(z), b = f.V((z + 1) % 3);
      if (ops_.IsBoundaryVertex(*a) || ops_.IsBoundaryVertex(*b)) return false;
      // Old region: the stars of a and b. Candidates: survivor a, b (staying), or the midpoint.
      Shape before;
      for (VertexPointer v : {a, b})
        for (vcg::face::VFIterator<FaceType> it(v); !it.End(); ++it)
          before.Add(PositionOf(it.F()->cV(0)), PositionOf(it.F()->cV(1)), PositionOf(it.F()->cV(2)),
                     Threshold());
      struct Option {
        Shape shape;
        int keep; ///< 0: a stays, 1: b stays, 2: midpoint
      };
      std::vector<Option> options;
      const Point mid = (PositionOf(a) + PositionOf(b)) * 0.5;
      for (int keep = 0; keep < 3; ++keep) {
        const Point q = keep == 0 ? PositionOf(a) : keep == 1 ? PositionOf(b) : mid;
        Shape s;
        for (VertexPointer v : {a, b})
          for (vcg::face::VFIterator<FaceType> it(v); !it.End(); ++it) {
            const FaceType* g = it.F();
            bool onEdge = false;
            for (int c = 0; c < 3; ++c)
              if ((g->cV(c) == a && g->cV((c + 1) % 3) == b) || (g->cV(c) == b && g->cV((c + 1) % 3) == a))
                onEdge = true;
            if (onEdge) continue; // removed by the collapse
            std::array<Point, 3> p;
            for (int c = 0; c < 3; ++c) p[c] = (g->cV(c) == a || g->cV(c) == b) ? q : PositionOf(g->cV(c));
            s.Add(p[0], p[1], p[2], Threshold());
          }
        // Faces of both stars appear twice when they hold a and b: only the edge faces do, skipped.
        if (s.minDeg > before.minDeg + 1e-9 && s.maxDeg <= std::max(before.maxDeg, params_.maxAngleDeg))
          options.push_back({s, keep});
      }
      std::sort(options.begin(), options.end(), [](const Option& x, const Option& y) {
        if (x.shape.small != y.shape.small) return x.shape.small < y.shape.small;
        if (x.shape.minDeg != y.shape.minDeg) return x.shape.minDeg > y.shape.minDeg;
        return x.keep < y.keep;
      });
      const std::size_t ai = VIndex(a), bi = VIndex(b);
      for (const Option& o : options) {
        FacePointer g = nullptr;
        int w = 0;
        if (!ops_.FindEdge(&m_.vert[ai], &m_.vert[bi], g, w)) return false;
        const std::size_t keepIndex = o.keep == 0 ? ai : bi;
        const bool wasLocked = ops_.IsLocked(m_.vert[keepIndex]);
        if (o.keep < 2) ops_.SetLocked(m_.vert[keepIndex], true);
        const bool ok = ops_.CollapseEdge(g, w, params_.maxEdgeFactor * L_);
        if (o.keep < 2) ops_.SetLocked(m_.vert[keepIndex], wasLocked);
        if (ok) return true;
      }
      return false;
    }

    // --- 2. Flips ----------------------------------------------------------------------------------

    /// Flips the edge of face fi whose flip raises the smallest angle of the two triangles most.
    bool FlipFace(std::size_t fi) {
      ops_.EnsureFootpointsAround(m_.face[fi]); // lazy footpoints (Init)

      FaceType& f = m_.face[fi];
      int bestEdge = -1;
      double bestMin = -1;
      for (int z = 0; z < 3; ++z) {
        if (f.cFFp(z) == &f) continue;
        Shape before, after;
        FlipShapes(EdgeQuad(f, z), Threshold(), before, after);
        if (Improves(before, after) && after.minDeg > bestMin) bestMin = after.minDeg, bestEdge = z;
      }
      return bestEdge >= 0 && ops_.FlipEdge(&f, bestEdge);
    }

    // --- 3. Constrained translation ----------------------------------------------------------------

    /// Moves vertex vi to its Laplacian position, or else to the best nearby position, when that
    /// improves its star (see Improves).
    bool Translate(std::size_t vi) {
      ops_.EnsureFootpointsAround(m_.vert[vi]); // lazy footpoints (Init)

      VertexType& v = m_.vert[vi];
      if (!IsFreeVertex(ops_, v)) return false;
      const Point p0 = PositionOf(&v);
      Point centroid(0, 0, 0), n(0, 0, 0);
      double ring = 0;
      int count = 0;
      for (vcg::face::VFIterator<FaceType> it(&v); !it.End(); ++it) {
        const Point a = PositionOf(it.F()->cV((it.I() + 1) % 3)),
                    b = PositionOf(it.F()->cV((it.I() + 2) % 3));
        centroid += a;
        n += (a - p0) ^ (b - p0);
        ring += (a - p0).Norm();
        ++count;
      }
      if (count < 3 || !(n.Norm() > 0)) return false;
      centroid /= double(count);
      ring /= double(count);
      n.Normalize();
      const Shape before = StarShape(&v, p0);
      const int foot = ops_.Footpoint(v);
      // Candidates: the Laplacian position first, then the compass ring, best first.
      candidates_.clear();
      Point lap = centroid - p0;
      lap -= n * (lap * n);
      auto consider = [&](const Point& q, bool laplacian) {
        const SurfaceProjection proj = ref_.Project(q, foot, scratch_);
        if (!proj.ok()) return;
        const Shape s = StarShape(&v, proj.point);
        if (Improves(before, s)) candidates_.push_back({laplacian, s, proj.point, proj.face});
      };
      consider(p0 + lap, true);
      if (candidates_.empty()) {
        Point e1, e2;
        TangentBasis(n, e1, e2);
        for (int ri = 1; ri <= params_.compassRadii; ++ri) {
          const double radius = params_.compassRadiusFactor * ring * ri / std::max(1, params_.compassRadii);
          for (int d = 0; d < params_.compassDirections; ++d) {
            const double t = 2.0 * kPi * d / std::max(1, params_.compassDirections);
            consider(p0 + (e1 * std::cos(t) + e2 * std::sin(t)) * radius, false);
          }
        }
        std::stable_sort(candidates_.begin(), candidates_.end(), [](const Candidate& x, const Candidate& y) {
          if (x.shape.small != y.shape.small) return x.shape.small < y.shape.small;
          return x.shape.minDeg > y.shape.minDeg;
        });
      }
      for (std::size_t i = 0; i < candidates_.size() && i < 4; ++i)
        if (ops_.MoveVertexTo(&v, candidates_[i].point, candidates_[i].foot)) return true;
      return false;
    }

    // --- 4. Delete and refill ----------------------------------------------------------------------

    /// Deletes a corner of bad face fi (the one at its smallest angle first) and retriangulates its
    /// hole with the max-min-angle triangulation, when that improves the region.
    bool Refill(std::size_t fi, Result& r) {
      ops_.EnsureFootpointsAround(m_.face[fi]); // lazy footpoints (Init)

      std::array<std::pair<double, std::size_t>, 3> corners;
      {
        const FaceType& f = m_.face[fi];
        for (int k = 0; k < 3; ++k) {
          const Point p = PositionOf(f.cV(k)), a = PositionOf(f.cV((k + 1) % 3)),
                      b = PositionOf(f.cV((k + 2) % 3));
          const Point u = a - p, w = b - p;
          const double c = (u * w) / std::max(1e-300, u.Norm() * w.Norm());
          corners[k] = {-c, VIndex(f.cV(k))}; // smallest angle = largest cosine first
        }
      }
      std::sort(corners.begin(), corners.end());
      for (const auto& [key, vi] : corners) {
        if (m_.face[fi].IsD()) return false;
        if (RefillVertex(vi, r)) return true;
      }
      return false;
    }

    bool RefillVertex(std::size_t vi, Result& r) {
      VertexType& v = m_.vert[vi];
      if (!IsFreeVertex(ops_, v)) return false;
      region_.clear();
      for (vcg::face::VFIterator<FaceType> it(&v); !it.End(); ++it) region_.push_back(it.F());
      if (region_.size() < 3 || int(region_.size()) > params_.maxRefillValence) return false;
      if (!ops_.DiskBoundary(region_, loop_, interior_) || interior_.size() != 1) return false;
      Shape before;
      for (const FacePointer g : region_)
        before.Add(PositionOf(g->cV(0)), PositionOf(g->cV(1)), PositionOf(g->cV(2)), Threshold());
      std::vector<Point> poly;
      for (const VertexPointer u : loop_) poly.push_back(PositionOf(u));
      std::vector<std::array<int, 3>> tris;
      Shape after;
      if (!MaxMinTriangulation(poly, tris, after)) return false;
      if (!Improves(before, after)) return false;
      std::vector<std::size_t> ring;
      for (const VertexPointer u : loop_) ring.push_back(VIndex(u));
      if (!ops_.ReplaceDisk(region_, loop_, {}, tris)) return false;
      // Local RAR/Laplacian on the refilled area: flips of its bad faces, then moves of its
      // vertices, each only when it improves (as everywhere in the stage).
      for (const std::size_t ui : ring) {
        VertexType& u = m_.vert[ui];
        for (vcg::face::VFIterator<FaceType> it(&u); !it.End(); ++it) {
          const std::size_t gi = FIndex(it.F());
          if (IsBad(m_.face[gi]) && FlipFace(gi)) {
            ++r.flips;
            break; // the VF list changed
          }
        }
      }
      for (const std::size_t ui : ring)
        if (StarShape(&m_.vert[ui], PositionOf(&m_.vert[ui])).small > 0 && Translate(ui)) ++r.moves;
      return true;
    }

    /// Triangulation of polygon `poly` (a closed loop, no new vertex) maximizing the smallest angle,
    /// then minimizing the largest; `shape` gets its worst angles. False when n < 3.
    bool MaxMinTriangulation(const std::vector<Point>& poly, std::vector<std::array<int, 3>>& tris,
                             Shape& shape) const {
      const int n = int(poly.size());
      if (n < 3) return false;
      // best[i][j]: (smallest angle, -largest angle) of the best triangulation of poly i..j.
      using Key = std::pair<double, double>;
      const Key none(-1.0, -1e9);
      std::vector<Key> best(std::size_t(n * n), Key(180.0, 0.0));
      std::vector<int> split(std::size_t(n * n), -1);
      for (int len = 2; len < n; ++len)
        for (int i = 0; i + len < n; ++i) {
          const int j = i + len;
          Key bij = none;
          for (int k = i + 1; k < j; ++k) {
            double lo, hi;
            TriangleAngleRange(poly[i], poly[k], poly[j], lo, hi);
            const Key left = best[std::size_t(i * n + k)], right = best[std::size_t(k * n + j)];
            const Key cand(std::min({lo, left.first, right.first}),
                           std::min({-hi, left.second, right.second}));
            if (cand > bij) bij = cand, split[std::size_t(i * n + j)] = k;
          }
          best[std::size_t(i * n + j)] = bij;
        }
      tris.clear();
      std::vector<std::pair<int, int>> stack{{0, n - 1}};
      while (!stack.empty()) {
        const auto [i, j] = stack.back();
        stack.pop_back();
        if (j - i < 2) continue;
        const int k = split[std::size_t(i * n + j)];
        if (k < 0) return false;
        tris.push_back({i, k, j});
        stack.emplace_back(i, k);
        stack.emplace_back(k, j);
      }
      shape = Shape();
      for (const auto& t : tris) shape.Add(poly[t[0]], poly[t[1]], poly[t[2]], Threshold());
      return true;
    }

    struct Candidate {
      bool laplacian;
      Shape shape;
      Point point;
      int foot;
    };

    Ops& ops_;
    MeshType& m_;
    const Reference& ref_;
    const Params& params_;
    double L_;
    typename Reference::Scratch scratch_;
    std::vector<std::pair<double, std::uint32_t>> bad_;
    std::vector<std::array<double, 2>> ranges_; ///< scratch of CollectBad
    std::vector<Candidate> candidates_;
    std::vector<FacePointer> region_;
    std::vector<VertexPointer> loop_, interior_;
  };
};

} // namespace molremesh

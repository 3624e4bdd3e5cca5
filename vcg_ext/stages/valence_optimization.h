// Valence optimization (Khan et al. 2020, section 3.2): makes (almost) every vertex valence 5, 6
// or 7 without creating a bad angle.
//
// ValenceOptimization<MeshType>::Do(m, reference, params) repeats, for Params::rounds rounds or
// until nothing changes:
//  1. guarded edge flips and collapses around every irregular vertex that lower the valence
//     deviation: the number of irregular vertices (interior valence not 5/6/7, boundary valence
//     not 3/4/5) first, then sum (valence - ideal)^2 with ideal 6 (4 on the boundary), both over
//     the vertices the edit touches;
//  2. two-phase removal: every irregular interior vertex is removed with its star, which leaves
//     a hole (phase 1); irregular vertices on that hole's rim are removed too while the hole's
//     area stays below Params::areaFactor times the mean triangle area (phase 2);
//  3. refilling: a hole of 3 or 4 rim vertices is closed by 1 or 2 triangles; 5 or 6 rim
//     vertices get one new vertex (a fan); 7 to 10 get two new vertices joined by an edge, each
//     fanning one chain of the rim. Every rotation of the fill is scored by the valences it
//     gives (same order as in 1), only fills that lower it are tried, best first. The new
//     vertices go to the feasible region: a pattern search in the hole's mean plane maximises
//     the smallest angle of the fill while pushing each angle at a new vertex below 90 degrees
//     (outside the circle that has the rim edge as diameter), then ReplaceDisk projects them
//     onto the reference. When the phase-2 hole cannot be filled, the phase-1 hole is tried; when
//     that fails too the mesh stays as it was (every edit is transactional: a refused edit
//     leaves the mesh bit-identical);
//  4. with Params::refillOnReference (polish), for a vertex steps 2 and 3 could not mend: its
//     star refilled again (valence 8 or more) or a strip of three faces refilled as a fan
//     (valence 3 or 4), with each trial position of the new vertices scored where it lands on
//     the reference;
//  5. with Params::relaxedFlips (polish), for a vertex steps 1 to 4 left irregular: a flip that
//     lowers the valence deviation (of v's edges when v has 8 or more, of the edges opposite v when
//     it has 3 or 4) made as one edit with every vertex of its quad's stars re-placed on the
//     reference by the search of step 4, scored by the distance to the angle bounds. Alone the
//     flip leaves a face outside the bounds; moved together its neighbours often bring every face
//     back (1UBQ EDTSurf VdW f2 at the CLI's defaults: 127 -> 93 irregular vertices).
// Every edit goes through LocalRemeshingOps with the angle guard Params::minAngleDeg and
// Params::maxAngleDeg in strict form (Guards::noMoreBadFaces): an edit never leaves more faces
// with an angle below the min (above the max) than it removed, and never makes the worst angle
// of its region worse; plus the fold, normal and intersection checks, and the fidelity guard
// (Params::maxInputDistance): no edit leaves an input point near it farther than 0.25 L from the
// mesh unless it was as far before. Without it, a collapse or refill that removes the vertex on
// an input spike cuts the spike off (1UBQ Jmol: the valence stage took the farthest input point
// from 1.0 L to 2.0 L from the CVT mesh, and polish undid RAR's work on 1UBQ EDTSurf, 0.39 L to
// 0.65 L, and on lysozyme, 0.29 L to 0.54 L). So the stage keeps the
// mesh 2-manifold, keeps closed components closed and their genus, adds no self-intersection
// and keeps every vertex on the reference surface. Vertices are visited in index order and
// every choice is deterministic (no randomness; seed and threads only reach the checks).
#pragma once

#include <vcg/complex/complex.h>

#include <vcg_ext/topology/face_face_topology.h>
#include <vcg_ext/core/input_check.h>
#include <vcg_ext/geometry/point.h>
#include <vcg_ext/ops/local_remeshing_ops.h>
#include <vcg_ext/quality/mesh_quality.h>
#include <vcg_ext/core/parallel_for.h>
#include <vcg_ext/surface/reference_surface.h>

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

/// Valence figures of a mesh (interior vertices: 5, 6, 7 regular; boundary: 3, 4, 5).
struct ValenceCensus {
  std::size_t vertices = 0;  ///< referenced vertices
  std::size_t irregular = 0; ///< of them, not regular
  double RegularPercent() const {
    return vertices ? 100.0 * double(vertices - irregular) / double(vertices) : 100.0;
  }
};

/// The triangulations ValenceOptimization's refill tries for a hole with n rim vertices, in the
/// order it considers them: the triangles (rim vertices 0..n-1, new vertices n and n+1) and the
/// number of new vertices.
inline std::vector<std::pair<std::vector<std::array<int, 3>>, int>> ValenceRefillCandidates(std::size_t n) {
  std::vector<std::pair<std::vector<std::array<int, 3>>, int>> out;
  const int N = int(n);
  if (n == 3) out.emplace_back(std::vector<std::array<int, 3>>{{0, 1, 2}}, 0);
  if (n == 4)
    for (int r = 0; r < 2; ++r)
      out.emplace_back(
          std::vector<std::array<int, 3>>{{r, r + 1, (r + 2) % 4}, {r, (r + 2) % 4, (r + 3) % 4}}, 0);
  if (n >= 4 && n <= 7) {
    std::vector<std::array<int, 3>> fan;
    for (int i = 0; i < N; ++i) fan.push_back({i, (i + 1) % N, N});
    out.emplace_back(fan, 1);
  }
  if (n >= 7)
    for (int i = 0; i < N; ++i)
      for (int len = std::max(2, N / 2 - 1); len <= std::min(N - 2, N / 2 + 1); ++len) {
        // New vertex a = N fans loop[i..i+len], b = N+1 fans loop[i+len..i+N].
        const int j = (i + len) % N;
        std::vector<std::array<int, 3>> tris;
        for (int t = 0; t < len; ++t) tris.push_back({(i + t) % N, (i + t + 1) % N, N});
        for (int t = 0; t < N - len; ++t) tris.push_back({(j + t) % N, (j + t + 1) % N, N + 1});
        tris.push_back({N, j, N + 1});
        tris.push_back({N, N + 1, i});
        out.emplace_back(tris, 2);
      }
  return out;
}

template <class MeshType>
class ValenceOptimization {
public:
  using Reference = ReferenceSurface<MeshType>;
  using Ops = LocalRemeshingOps<MeshType>;
  using VertexType = typename MeshType::VertexType;
  using VertexPointer = typename MeshType::VertexPointer;
  using FaceType = typename MeshType::FaceType;
  using FacePointer = typename MeshType::FacePointer;
  using Point = vcg::Point3d;

  struct Params {
    double targetEdgeLength = 0; ///< L (scales tolerances); 0 = mean edge length of the mesh
    int threads = 0;             ///< 0 = all cores (the output does not depend on it)
    std::uint64_t seed = 1;      ///< unused: the stage makes no random choice
    /// Vertices never moved or removed, nor joined by an edit of an edge between two of them
    /// (indexed like m.vert at entry; nonzero = locked; empty = none): the border of a region.
    std::vector<std::uint8_t> lockedVertices;
    double minAngleDeg = 30.0;     ///< no edit leaves more faces with an angle below it
    double maxAngleDeg = 120.0;    ///< no edit leaves more faces with an angle above it
    double areaFactor = 9.0;       ///< phase 2: a hole's area stays below this times the mean face area
    int rounds = 4;                ///< repetitions of flips/collapses + removal/refilling (stops early)
    bool flipsAndCollapses = true; ///< step 1
    bool removeAndRefill = true;   ///< steps 2 and 3
    /// Step 4, for the vertices removal could not mend: refills whose new vertices are placed by
    /// a search that scores each trial point where it lands on the reference (in a pit or a saddle
    /// the point found in the hole's mean plane projects elsewhere and its angles change). A
    /// vertex of valence 8 or more gets its star refilled again so; one of valence 3 or 4 gets one
    /// more edge from a strip of three faces (its face, the one across the opposite edge, one
    /// more) refilled as a fan around a new vertex.
    bool refillOnReference = false;
    /// Step 5, for the vertices steps 1 to 4 left irregular: a flip the angle bounds refused on
    /// its own is tried again with the vertices around it relaxed. The flip's quad and every
    /// vertex of its neighbourhood are re-placed on the reference (the search of step 4) and the
    /// whole neighbourhood goes through the guards as one edit. The flips are those of v's edges
    /// (valence 8 or more) and of the edges opposite v (valence 3 or 4).
    bool relaxedFlips = false;
    /// No edit leaves a point of the input near it farther than this x L from the mesh unless it
    /// was as far before (LocalOpsGuards::maxInputDistanceFactor; 0 = off): removing a vertex on
    /// a spike or cusp of the input would otherwise cut it off.
    double maxInputDistance = 0.25;
    LocalOpsGuards guards; ///< the other checks (normal, fold, intersections); angles from above
  };

  struct Result {
    bool ok = false;
    std::string message; ///< why it failed
    ValenceCensus before, after;
    std::size_t smallAnglesBefore = 0, smallAnglesAfter = 0; ///< faces with an angle below minAngleDeg
    std::size_t largeAnglesBefore = 0, largeAnglesAfter = 0; ///< faces with an angle above maxAngleDeg
    std::size_t flips = 0, collapses = 0;
    std::size_t filledZero = 0, filledOne = 0, filledTwo = 0; ///< holes closed with 0, 1, 2 new vertices
    std::size_t phaseTwoHoles = 0;                            ///< filled holes that grew in phase 2
    std::size_t holesKept = 0;        ///< holes no fill was accepted for (the mesh kept its faces)
    std::size_t starsOnReference = 0; ///< stars refilled with their new vertices on the reference (step 4)
    std::size_t strips = 0;           ///< strips refilled (step 4)
    std::size_t relaxedFlips = 0;     ///< flips made with their neighbourhood relaxed (step 5)
    int rounds = 0;
  };

  /// Runs the stage on m, a 2-manifold lying on `reference` (FF and VF adjacency enabled). On
  /// failure m is left untouched (but its adjacency recomputed) and Result::message says why.
  static Result Do(MeshType& m, const Reference& reference, const Params& params);

  /// Valence census of m (FF and VF adjacency up to date).
  static ValenceCensus Census(const MeshType& m);

private:
  /// Valence deviation of a set of vertices: lexicographic (irregular count, squared deviation).
  struct Deviation {
    int irregular = 0;
    int squared = 0;
    void Add(int valence, bool boundary) {
      const int ideal = boundary ? 4 : 6;
      irregular += std::abs(valence - ideal) > 1;
      squared += (valence - ideal) * (valence - ideal);
    }
    bool operator<(const Deviation& o) const {
      return irregular != o.irregular ? irregular < o.irregular : squared < o.squared;
    }
  };

  struct Session {
    Session(MeshType& mesh, Ops& o, const Params& p, Result& r)
        : m(mesh), ops(o), params(p), result(r), meanFaceArea(MeanFaceArea(mesh)) {}
    MeshType& m;
    Ops& ops;
    const Params& params;
    Result& result;
    double meanFaceArea; ///< phase 2 compares hole areas with it
    // Scratch.
    std::vector<FacePointer> region, phaseOne;
    std::vector<VertexPointer> loop, interior;

    bool Irregular(const VertexType& v) const {
      const int val = ops.Valence(v);
      if (val == 0) return false;
      return ops.IsBoundaryVertex(v) ? std::abs(val - 4) > 1 : (val < 5 || val > 7);
    }
    /// Footpoints of every vertex an edit around v can touch (its 2-ring).
    void EnsureFootpoints(VertexPointer v) { ops.EnsureFootpointsAround(*v, 2); }
    bool ImproveByFlipOrCollapse(VertexPointer v);
    bool RemoveAndRefill(VertexPointer v);
    /// Step 4 for the vertex m.vert[vIndex] whose star (faces starIdx) no planar refill mended.
    bool RefillOnReference(std::size_t vIndex, const std::vector<std::size_t>& starIdx);
    /// Step 4 for a vertex of valence 3 or 4.
    bool RefillStrip(VertexPointer v);
    /// Step 5 for the vertex m.vert[vIndex].
    bool RelaxedFlip(std::size_t vIndex);
    /// Flips edge z of face fIndex with the vertices of the union of its quad's stars re-placed.
    bool FlipWithNeighbourhoodRelaxed(std::size_t fIndex, int z);
    /// The faces at these indices (kept as indices where a refused refill may move the faces).
    std::vector<FacePointer> FacesAt(const std::vector<std::size_t>& idx) {
      std::vector<FacePointer> faces;
      for (const std::size_t i : idx) faces.push_back(&m.face[i]);
      return faces;
    }
    bool Refill(const std::vector<FacePointer>& faces, bool onReference = false);
    /// The new vertices pts[n..] moved by a compass search that scores each trial point where
    /// ReplaceDisk will put it (score(pts): higher is better).
    template <class Score>
    void RefineOnReference(std::vector<Point>& pts, std::size_t n, double step, Score&& score);
    typename Reference::Scratch scratch;
  };

  static double MeanFaceArea(const MeshType& m) {
    double area = 0;
    for (const auto& f : m.face)
      if (!f.IsD()) area += FaceArea(f);
    return m.fn ? area / double(m.fn) : 0;
  }
  static double FaceArea(const FaceType& f) {
    return 0.5 * vcg::Norm((f.cP(1) - f.cP(0)) ^ (f.cP(2) - f.cP(0)));
  }
  /// Smallest and largest angle (degrees) of triangle (a, b, c). Deliberately not
  /// TriangleAngleRange (triangle_angles.h): this formula (side lengths, third angle = 180 - A - B)
  /// is the one the stage was validated with; the other's last-bit differences change its refills
  /// (`--stages clean,valence` on lysozyme_Lys1_msms comes out different).
  static void AngleRange(const Point& a, const Point& b, const Point& c, double& lo, double& hi) {
    const double la = (b - c).Norm(), lb = (c - a).Norm(), lc = (a - b).Norm();
    auto at = [](double opp, double s1, double s2) {
      const double d = 2 * s1 * s2;
      if (!(d > 0)) return 0.0;
      return std::acos(std::clamp((s1 * s1 + s2 * s2 - opp * opp) / d, -1.0, 1.0)) * 180.0 / M_PI;
    };
    const double A = at(la, lb, lc), B = at(lb, lc, la), C = 180.0 - A - B;
    lo = std::min({A, B, C});
    hi = std::max({A, B, C});
  }
  /// Places the new vertices of a fill: pattern search in the plane (origin, normal) maximising
  /// the smallest angle of `triangles` (indices into pts, the first n fixed) with a penalty on
  /// angles at new vertices of 90 degrees or more. Returns the smallest angle reached.
  static double PlaceNewVertices(std::vector<Point>& pts, std::size_t n,
                                 const std::vector<std::array<int, 3>>& tris, const Point& normal,
                                 double step);
  static double FillScore(const std::vector<Point>& pts, std::size_t n,
                          const std::vector<std::array<int, 3>>& tris, double* minAngle = nullptr,
                          double* maxAngle = nullptr);
  /// How far the triangles' angles stay inside [minAngle, maxAngle] (negative: how far outside).
  static double BoundsMargin(const std::vector<Point>& pts, const std::vector<std::array<int, 3>>& tris,
                             double minAngle, double maxAngle) {
    double margin = std::numeric_limits<double>::infinity();
    for (const auto& t : tris) {
      double lo, hi;
      AngleRange(pts[t[0]], pts[t[1]], pts[t[2]], lo, hi);
      margin = std::min({margin, lo - minAngle, maxAngle - hi});
    }
    return margin;
  }
  /// Compass search on the new vertices pts[n..]: each tries pts[j] + d x step for every direction
  /// d, through place(j, point) (where the trial point would land), kept when score(pts) improves;
  /// up to `passes` sweeps per step, `levels` halvings of the step.
  template <std::size_t D, class Place, class Score>
  static void CompassSearch(std::vector<Point>& pts, std::size_t n, const std::array<Point, D>& dirs,
                            double step, int levels, int passes, Place&& place, Score&& score) {
    double best = score(pts);
    for (int level = 0; level < levels; ++level, step *= 0.5) {
      bool improved = true;
      for (int pass = 0; pass < passes && improved; ++pass) {
        improved = false;
        for (std::size_t j = n; j < pts.size(); ++j)
          for (const Point& d : dirs) {
            const Point keep = pts[j];
            pts[j] = place(j, keep + d * step);
            const double trial = score(pts);
            if (trial > best + 1e-9) {
              best = trial;
              improved = true;
            } else {
              pts[j] = keep;
            }
          }
      }
    }
  }
};

// ------------------------------------------------------------------------------------------------
// Implementation
// ------------------------------------------------------------------------------------------------

template <class MeshType>
ValenceCensus ValenceOptimization<MeshType>::Census(const MeshType& m) {
  ValenceCensus c;
  std::vector<int> faces(m.vert.size(), 0);
  std::vector<std::uint8_t> boundary(m.vert.size(), 0);
  for (const auto& f : m.face) {
    if (f.IsD()) continue;
    for (int k = 0; k < 3; ++k) {
      const std::size_t i = vcg::tri::Index(m, f.cV(k));
      ++faces[i];
      if (f.cFFp(k) == &f) {
        boundary[i] = 1;
        boundary[vcg::tri::Index(m, f.cV((k + 1) % 3))] = 1;
      }
    }
  }
  for (std::size_t i = 0; i < m.vert.size(); ++i) {
    if (m.vert[i].IsD() || faces[i] == 0) continue;
    ++c.vertices;
    const int val = faces[i] + boundary[i];
    c.irregular += boundary[i] ? std::abs(val - 4) > 1 : (val < 5 || val > 7);
  }
  return c;
}

template <class MeshType>
double ValenceOptimization<MeshType>::FillScore(const std::vector<Point>& pts, std::size_t n,
                                                const std::vector<std::array<int, 3>>& tris, double* minAngle,
                                                double* maxAngle) {
  double lo = 180, hi = 0, penalty = 0;
  for (const auto& t : tris) {
    const Point &a = pts[t[0]], &b = pts[t[1]], &c = pts[t[2]];
    double tlo, thi;
    AngleRange(a, b, c, tlo, thi);
    lo = std::min(lo, tlo);
    hi = std::max(hi, thi);
    // Feasible region: a new vertex sees each rim edge under less than 90 degrees.
    for (int k = 0; k < 3; ++k) {
      if (std::size_t(t[k]) < n) continue;
      const Point u = pts[t[(k + 1) % 3]] - pts[t[k]], w = pts[t[(k + 2) % 3]] - pts[t[k]];
      const double d = u.Norm() * w.Norm();
      if (!(d > 0)) return -1e9;
      const double angle = std::acos(std::clamp((u * w) / d, -1.0, 1.0)) * 180.0 / M_PI;
      penalty += std::max(0.0, angle - 85.0);
    }
  }
  if (minAngle) *minAngle = lo;
  if (maxAngle) *maxAngle = hi;
  return lo - 0.5 * penalty - 0.25 * std::max(0.0, hi - 90.0);
}

template <class MeshType>
double ValenceOptimization<MeshType>::PlaceNewVertices(std::vector<Point>& pts, std::size_t n,
                                                       const std::vector<std::array<int, 3>>& tris,
                                                       const Point& normal, double step) {
  // Tangent basis of the hole's plane.
  Point t1 = std::fabs(normal[0]) < 0.9 ? Point(1, 0, 0) : Point(0, 1, 0);
  t1 = (t1 - normal * (t1 * normal)).Normalize();
  const Point t2 = normal ^ t1;
  const std::array<Point, 8> dirs = {t1,
                                     -t1,
                                     t2,
                                     -t2,
                                     (t1 + t2) * M_SQRT1_2,
                                     (t1 - t2) * M_SQRT1_2,
                                     (-t1 + t2) * M_SQRT1_2,
                                     (-t1 - t2) * M_SQRT1_2};
  CompassSearch(
      pts, n, dirs, step, 7, 12, [](std::size_t, const Point& p) { return p; },
      [&](const std::vector<Point>& p) { return FillScore(p, n, tris); });
  double lo;
  FillScore(pts, n, tris, &lo);
  return lo;
}

template <class MeshType>
bool ValenceOptimization<MeshType>::Session::ImproveByFlipOrCollapse(VertexPointer v) {
  // Candidate edits on the edges of v, best valence gain first.
  struct Candidate {
    Deviation after;
    bool flip;
    FacePointer f;
    int z;
  };
  std::vector<Candidate> candidates;
  Deviation best; // of the current state, per candidate neighbourhood (compared per edit)
  for (vcg::face::VFIterator<FaceType> it(v); !it.End(); ++it) {
    FacePointer f = it.F();
    const int z = it.I(); // edge (v, next)
    if (f->FFp(z) == f) continue;
    FacePointer g = f->FFp(z);
    const int w = f->FFi(z);
    VertexPointer v0 = f->V(z), v1 = f->V((z + 1) % 3), v2 = f->V((z + 2) % 3), v3 = g->V((w + 2) % 3);
    const int a0 = ops.Valence(*v0), a1 = ops.Valence(*v1), a2 = ops.Valence(*v2), a3 = ops.Valence(*v3);
    const bool b0 = ops.IsBoundaryVertex(*v0), b1 = ops.IsBoundaryVertex(*v1), b2 = ops.IsBoundaryVertex(*v2),
               b3 = ops.IsBoundaryVertex(*v3);
    Deviation now;
    now.Add(a0, b0);
    now.Add(a1, b1);
    now.Add(a2, b2);
    now.Add(a3, b3);
    // Flip (v0 v1) -> (v2 v3).
    Deviation flip;
    flip.Add(a0 - 1, b0);
    flip.Add(a1 - 1, b1);
    flip.Add(a2 + 1, b2);
    flip.Add(a3 + 1, b3);
    if (flip < now) candidates.push_back({flip, true, f, z});
    // Collapse (v0 v1): one vertex of valence a0 + a1 - 4; v2 and v3 lose one edge. Only
    // between interior vertices (boundary collapses change the outline).
    if (!b0 && !b1) {
      Deviation collapse;
      collapse.Add(a0 + a1 - 4, false);
      collapse.Add(a2 - 1, b2);
      collapse.Add(a3 - 1, b3);
      // Compare with the same vertex set before: v0 and v1 become one vertex, so count the
      // removed one as an ideal vertex gone (adding 0 deviation), the comparison stays fair.
      if (collapse < now) candidates.push_back({collapse, false, f, z});
    }
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& a, const Candidate& b) { return a.after < b.after; });
  for (const Candidate& c : candidates) {
    if (c.flip) {
      if (ops.FlipEdge(c.f, c.z)) {
        ++result.flips;
        return true;
      }
    } else if (ops.CollapseEdge(c.f, c.z, 1.6 * ops.TargetEdgeLength())) {
      ++result.collapses;
      return true;
    }
  }
  return false;
}

template <class MeshType>
template <class Score>
void ValenceOptimization<MeshType>::Session::RefineOnReference(std::vector<Point>& pts, std::size_t n,
                                                               double step, Score&& score) {
  // The compass search of PlaceNewVertices, but each trial point is scored where ReplaceDisk will
  // put it: projected onto the reference near the closest rim vertex's footpoint. In a pit or a
  // saddle the planar optimum lands elsewhere and its angles change.
  const Reference& ref = ops.GetReference();
  std::vector<int> hint(pts.size() - n, -1);
  for (std::size_t j = n; j < pts.size(); ++j) {
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < n; ++i) {
      const double d = (pts[i] - pts[j]).SquaredNorm();
      if (d < best) best = d, hint[j - n] = ops.Footpoint(*loop[i]);
    }
  }
  auto project = [&](std::size_t j, const Point& p) {
    const SurfaceProjection q = ref.Project(p, hint[j - n], scratch);
    return q.ok() ? q.point : p;
  };
  for (std::size_t j = n; j < pts.size(); ++j) pts[j] = project(j, pts[j]);
  const std::array<Point, 6> dirs = {Point(1, 0, 0),  Point(-1, 0, 0), Point(0, 1, 0),
                                     Point(0, -1, 0), Point(0, 0, 1),  Point(0, 0, -1)};
  CompassSearch(pts, n, dirs, step, 4, 6, project, score);
}

template <class MeshType>
bool ValenceOptimization<MeshType>::Session::Refill(const std::vector<FacePointer>& faces, bool onReference) {
  if (!ops.DiskBoundary(faces, loop, interior)) return false;
  const std::size_t n = loop.size();
  if (n < 3 || n > 10) return false;
  // Current deviation over the rim and the removed vertices; faces per rim vertex in the hole.
  Deviation now;
  std::vector<int> valence(n), inHole(n, 0);
  std::vector<bool> boundary(n);
  for (std::size_t i = 0; i < n; ++i) {
    valence[i] = ops.Valence(*loop[i]);
    boundary[i] = ops.IsBoundaryVertex(*loop[i]);
    now.Add(valence[i], boundary[i]);
  }
  for (const VertexPointer u : interior) now.Add(ops.Valence(*u), false);
  for (const FacePointer f : faces)
    for (int k = 0; k < 3; ++k) {
      const auto it = std::find(loop.begin(), loop.end(), f->V(k));
      if (it != loop.end()) ++inHole[std::size_t(it - loop.begin())];
    }
  Point centroid(0, 0, 0), normal(0, 0, 0);
  double rim = 0;
  for (std::size_t i = 0; i < n; ++i) {
    centroid += PositionOf(loop[i]);
    rim += (PositionOf(loop[(i + 1) % n]) - PositionOf(loop[i])).Norm();
  }
  centroid /= double(n);
  for (const FacePointer f : faces)
    normal += (PositionOf(f->V(1)) - PositionOf(f->V(0))) ^ (PositionOf(f->V(2)) - PositionOf(f->V(0)));
  if (!(normal.Norm() > 0)) return false;
  normal.Normalize();
  const double meanRim = rim / double(n);

  struct Fill {
    Deviation after;
    std::vector<std::array<int, 3>> tris;
    int newVertices;
    double minAngle = 0;
    std::vector<Point> pts;
  };
  std::vector<Fill> fills;
  auto consider = [&](std::vector<std::array<int, 3>> tris, int k) {
    std::vector<int> count(n + std::size_t(k), 0);
    for (const auto& t : tris)
      for (const int c : t) ++count[std::size_t(c)];
    Fill fill;
    for (std::size_t i = 0; i < n; ++i) fill.after.Add(valence[i] - inHole[i] + count[i], boundary[i]);
    for (int j = 0; j < k; ++j) fill.after.Add(count[n + std::size_t(j)], false);
    if (!(fill.after < now)) return;
    fill.tris = std::move(tris);
    fill.newVertices = k;
    fills.push_back(std::move(fill));
  };
  const int N = int(n);
  for (auto& [tris, k] : ValenceRefillCandidates(n)) consider(std::move(tris), k);
  if (fills.empty()) return false;
  // Place the new vertices of the best-scoring fills and try them, best first.
  std::stable_sort(fills.begin(), fills.end(),
                   [](const Fill& a, const Fill& b) { return a.after < b.after; });
  const std::size_t tryCount = std::min<std::size_t>(fills.size(), 6);
  for (std::size_t c = 0; c < tryCount; ++c) {
    Fill& fill = fills[c];
    fill.pts.resize(n + std::size_t(fill.newVertices));
    for (std::size_t i = 0; i < n; ++i) fill.pts[i] = PositionOf(loop[i]);
    for (int j = 0; j < fill.newVertices; ++j) {
      // Start at the centroid of the rim vertices the new vertex fans, pulled to the hole's centre.
      Point s(0, 0, 0);
      int cnt = 0;
      for (const auto& t : fill.tris)
        for (int k = 0; k < 3; ++k)
          if (t[k] == N + j)
            for (const int o : {t[(k + 1) % 3], t[(k + 2) % 3]})
              if (o < N) {
                s += fill.pts[std::size_t(o)];
                ++cnt;
              }
      const Point start = cnt ? s / double(cnt) : centroid;
      fill.pts[n + std::size_t(j)] = (start + centroid) * 0.5;
    }
    fill.minAngle =
        fill.newVertices ? PlaceNewVertices(fill.pts, n, fill.tris, normal, 0.25 * meanRim) : [&] {
          double lo;
          FillScore(fill.pts, n, fill.tris, &lo);
          return lo;
        }();
    if (onReference && fill.newVertices) {
      RefineOnReference(fill.pts, n, 0.1 * meanRim,
                        [&](const std::vector<Point>& p) { return FillScore(p, n, fill.tris); });
      FillScore(fill.pts, n, fill.tris, &fill.minAngle);
    }
  }
  std::stable_sort(fills.begin(), fills.begin() + std::ptrdiff_t(tryCount), [](const Fill& a, const Fill& b) {
    return a.after < b.after || (!(b.after < a.after) && a.minAngle > b.minAngle);
  });
  // A refused ReplaceDisk may have made room (moving the elements): keep indices.
  std::vector<std::size_t> faceIdx, loopIdx;
  for (const FacePointer f : faces) faceIdx.push_back(vcg::tri::Index(m, f));
  for (const VertexPointer u : loop) loopIdx.push_back(vcg::tri::Index(m, u));
  std::vector<FacePointer> hole(faces.size());
  for (std::size_t c = 0; c < tryCount; ++c) {
    const Fill& fill = fills[c];
    for (std::size_t i = 0; i < faceIdx.size(); ++i) hole[i] = &m.face[faceIdx[i]];
    for (std::size_t i = 0; i < n; ++i) loop[i] = &m.vert[loopIdx[i]];
    std::vector<Point> newPoints(fill.pts.begin() + std::ptrdiff_t(n), fill.pts.end());
    if (ops.ReplaceDisk(hole, loop, newPoints, fill.tris)) {
      (fill.newVertices == 0   ? result.filledZero
       : fill.newVertices == 1 ? result.filledOne
                               : result.filledTwo)++;
      return true;
    }
  }
  return false;
}

template <class MeshType>
bool ValenceOptimization<MeshType>::Session::RemoveAndRefill(VertexPointer v) {
  if (ops.IsBoundaryVertex(*v) || ops.IsLocked(*v)) return false;
  const std::size_t vIndex = vcg::tri::Index(m, v); // a refused fill may move the vertices
  // Phase 1: the star of v.
  phaseOne.clear();
  double area = 0;
  for (vcg::face::VFIterator<FaceType> it(v); !it.End(); ++it) {
    phaseOne.push_back(it.F());
    area += FaceArea(*it.F());
  }
  // Phase 2: irregular interior vertices on the rim, while the hole stays small.
  region = phaseOne;
  std::vector<VertexPointer> rim;
  for (const FacePointer f : phaseOne)
    for (int k = 0; k < 3; ++k)
      if (f->V(k) != v && std::find(rim.begin(), rim.end(), f->V(k)) == rim.end()) rim.push_back(f->V(k));
  std::sort(rim.begin(), rim.end()); // pointer order = index order: deterministic
  bool grown = false;
  for (const VertexPointer u : rim) {
    if (!Irregular(*u) || ops.IsBoundaryVertex(*u) || ops.IsLocked(*u)) continue;
    std::vector<FacePointer> more;
    double extra = 0;
    for (vcg::face::VFIterator<FaceType> it(u); !it.End(); ++it)
      if (std::find(region.begin(), region.end(), it.F()) == region.end()) {
        more.push_back(it.F());
        extra += FaceArea(*it.F());
      }
    if (area + extra >= params.areaFactor * meanFaceArea) continue;
    std::vector<FacePointer> grownRegion = region;
    grownRegion.insert(grownRegion.end(), more.begin(), more.end());
    if (!ops.DiskBoundary(grownRegion, loop, interior)) continue;
    region = std::move(grownRegion);
    area += extra;
    grown = true;
  }
  // Faces may move in memory when a fill makes room: copy the regions by index.
  std::vector<std::size_t> phaseOneIdx;
  for (const FacePointer f : phaseOne) phaseOneIdx.push_back(vcg::tri::Index(m, f));
  if (grown) {
    if (Refill(region)) {
      ++result.phaseTwoHoles;
      return true;
    }
    phaseOne = FacesAt(phaseOneIdx);
  }
  if (Refill(phaseOne)) return true;
  if (params.refillOnReference && RefillOnReference(vIndex, phaseOneIdx)) return true;
  if (params.relaxedFlips && RelaxedFlip(vIndex)) return true;
  ++result.holesKept;
  return false;
}

template <class MeshType>
bool ValenceOptimization<MeshType>::Session::RefillOnReference(std::size_t vIndex,
                                                               const std::vector<std::size_t>& starIdx) {
  VertexPointer v = &m.vert[vIndex];
  const int valence = ops.Valence(*v);
  if (valence <= 4) return RefillStrip(v);
  if (valence < 8) return false;
  // The planar refill of the star was refused (a failed refill may have moved the faces).
  if (!Refill(FacesAt(starIdx), /*onReference=*/true)) return false;
  ++result.starsOnReference;
  return true;
}

template <class MeshType>
bool ValenceOptimization<MeshType>::Session::RefillStrip(VertexPointer v) {
  // Strips of three faces: a face of v, the face across the edge opposite v, and one of the
  // faces across that face's two other edges. Their loop has five vertices, v among them.
  std::vector<std::vector<std::size_t>> strips;
  for (vcg::face::VFIterator<FaceType> it(v); !it.End(); ++it) {
    FacePointer f0 = it.F();
    const int e = (it.I() + 1) % 3;
    FacePointer f1 = f0->FFp(e);
    if (f1 == f0) continue;
    const int j = f0->FFi(e);
    for (const int e1 : {(j + 1) % 3, (j + 2) % 3}) {
      FacePointer f2 = f1->FFp(e1);
      if (f2 == f1 || f2 == f0) continue;
      strips.push_back({vcg::tri::Index(m, f0), vcg::tri::Index(m, f1), vcg::tri::Index(m, f2)});
    }
  }
  for (const auto& s : strips) {
    if (Refill(FacesAt(s), /*onReference=*/true)) {
      ++result.strips;
      return true;
    }
  }
  return false;
}

template <class MeshType>
bool ValenceOptimization<MeshType>::Session::RelaxedFlip(std::size_t vIndex) {
  // Flips that lower the valence deviation of their four vertices: of the edges at v when its
  // valence is high, of the edges opposite v (which give v one more edge) when it is low.
  VertexPointer v = &m.vert[vIndex];
  const bool low = ops.Valence(*v) < 5;
  struct Candidate {
    Deviation after;
    std::size_t face;
    int z;
  };
  std::vector<Candidate> candidates;
  for (vcg::face::VFIterator<FaceType> it(v); !it.End(); ++it) {
    FacePointer f = it.F();
    const int z = low ? (it.I() + 1) % 3 : it.I();
    if (f->FFp(z) == f) continue;
    const FacePointer g = f->FFp(z);
    const std::array<VertexPointer, 4> quad = {f->V(z), f->V((z + 1) % 3), f->V((z + 2) % 3),
                                               g->V((f->FFi(z) + 2) % 3)};
    Deviation now, flip;
    for (int k = 0; k < 4; ++k) {
      const int val = ops.Valence(*quad[std::size_t(k)]);
      const bool boundary = ops.IsBoundaryVertex(*quad[std::size_t(k)]);
      now.Add(val, boundary);
      flip.Add(k < 2 ? val - 1 : val + 1, boundary);
    }
    if (flip < now) candidates.push_back({flip, vcg::tri::Index(m, f), z});
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& a, const Candidate& b) { return a.after < b.after; });
  for (const Candidate& c : candidates)
    if (FlipWithNeighbourhoodRelaxed(c.face, c.z)) {
      ++result.relaxedFlips;
      return true;
    }
  return false;
}

template <class MeshType>
bool ValenceOptimization<MeshType>::Session::FlipWithNeighbourhoodRelaxed(std::size_t fIndex, int z) {
  const FacePointer f = &m.face[fIndex], g = f->FFp(z);
  const int w = f->FFi(z);
  const std::array<VertexPointer, 4> quad = {f->V(z), f->V((z + 1) % 3), f->V((z + 2) % 3),
                                             g->V((w + 2) % 3)};
  if (quad[2] == quad[3]) return false;
  for (const VertexPointer u : quad)
    if (ops.IsLocked(*u) || ops.IsBoundaryVertex(*u)) return false;
  region.clear();
  for (const VertexPointer u : quad)
    for (vcg::face::VFIterator<FaceType> it(u); !it.End(); ++it)
      if (std::find(region.begin(), region.end(), it.F()) == region.end()) region.push_back(it.F());
  if (!ops.DiskBoundary(region, loop, interior)) return false;
  for (const VertexPointer u : interior)
    if (ops.IsLocked(*u)) return false;
  // The region's faces on loop indices 0..n-1 and interior ones n.., f and g flipped.
  const std::size_t n = loop.size();
  auto index = [&](VertexPointer u) {
    const auto it = std::find(loop.begin(), loop.end(), u);
    if (it != loop.end()) return int(it - loop.begin());
    return int(n) + int(std::find(interior.begin(), interior.end(), u) - interior.begin());
  };
  std::vector<std::array<int, 3>> tris;
  for (const FacePointer h : region)
    if (h != f && h != g) tris.push_back({index(h->V(0)), index(h->V(1)), index(h->V(2))});
  const int a = index(quad[0]), b = index(quad[1]), c = index(quad[2]), d = index(quad[3]);
  tris.push_back({a, d, c});
  tris.push_back({b, c, d});
  std::vector<Point> pts;
  for (const VertexPointer u : loop) pts.push_back(PositionOf(u));
  double meanEdge = 0;
  for (std::size_t i = 0; i < n; ++i) meanEdge += (pts[(i + 1) % n] - pts[i]).Norm();
  meanEdge /= double(n);
  for (const VertexPointer u : interior) pts.push_back(PositionOf(u));
  // The score is the distance to the angle bounds: the relaxation must bring every face inside.
  RefineOnReference(pts, n, 0.1 * meanEdge, [&](const std::vector<Point>& p) {
    return BoundsMargin(p, tris, params.minAngleDeg, params.maxAngleDeg);
  });
  if (BoundsMargin(pts, tris, params.minAngleDeg, params.maxAngleDeg) < 0) return false;
  const std::vector<Point> newPoints(pts.begin() + std::ptrdiff_t(n), pts.end());
  return ops.ReplaceDisk(region, loop, newPoints, tris);
}

template <class MeshType>
typename ValenceOptimization<MeshType>::Result
ValenceOptimization<MeshType>::Do(MeshType& m, const Reference& reference, const Params& params) {
  Result result;
  const InputCheck check = CheckTriangleMeshInput(m);
  if (!check.ok) {
    result.message = "valence optimization refused: " + check.message;
    return result;
  }
  if (!vcg::tri::HasFFAdjacency(m) || !vcg::tri::HasVFAdjacency(m)) {
    result.message = "valence optimization refused: face-face and vertex-face adjacency must be enabled";
    return result;
  }
  if (!(params.minAngleDeg >= 0 && params.minAngleDeg < 60 && params.maxAngleDeg > 60 &&
        params.maxAngleDeg <= 180) ||
      !(params.areaFactor >= 0) || params.rounds < 0) {
    result.message =
        "valence optimization refused: need 0 <= min angle < 60 < max angle <= 180, area factor >= 0, "
        "rounds >= 0";
    return result;
  }
  double L = params.targetEdgeLength;
  if (!(L > 0)) {
    typename MeshQuality<MeshType>::Params qp;
    qp.computeSelfIntersections = false;
    qp.threads = params.threads;
    L = MeshQuality<MeshType>::Compute(m, qp).meanEdgeLength;
  }
  if (!(L > 0) || !std::isfinite(L)) {
    result.message = "valence optimization refused: no valid target edge length";
    return result;
  }
  LocalOpsGuards guards = params.guards;
  guards.minAngleDeg = params.minAngleDeg;
  guards.maxAngleDeg = params.maxAngleDeg;
  guards.noMoreBadFaces = true;
  guards.maxInputDistanceFactor = params.maxInputDistance;
  Ops ops(m, reference, L, guards, params.threads);
  std::string error;
  // Footpoints on demand: the stage edits around a few irregular vertices (0.1-0.4 % of them), so
  // finding every vertex's footpoint up front would cost more than all the edits.
  if (!ops.Init(&error, false, false, /*lazyFootpoints=*/true)) {
    result.message = "valence optimization refused: " + error;
    return result;
  }
  LockVertices(ops, params.lockedVertices);
  // The scans below read the mesh only: they run on every thread, each counting (or flagging)
  // into its own slots, so their results do not depend on the thread count.
  const int threads = ResolveThreadCount(params.threads);
  auto countBad = [&](std::size_t& small, std::size_t& large) {
    std::vector<std::array<std::size_t, 2>> counts(std::size_t(threads), {0, 0});
    ParallelFor(m.face.size(), threads, [&](std::size_t begin, std::size_t end, int t) {
      for (std::size_t fi = begin; fi < end; ++fi) {
        const FaceType& f = m.face[fi];
        if (f.IsD()) continue;
        double lo, hi;
        AngleRange(PositionOf(f.cV(0)), PositionOf(f.cV(1)), PositionOf(f.cV(2)), lo, hi);
        // Same tolerance as the guard's cosine comparison: an angle of exactly the bound is fine.
        counts[std::size_t(t)][0] += lo < params.minAngleDeg - 1e-9;
        counts[std::size_t(t)][1] += hi > params.maxAngleDeg + 1e-9;
      }
    });
    small = large = 0;
    for (const auto& c : counts) small += c[0], large += c[1];
  };
  result.before = Census(m);
  countBad(result.smallAnglesBefore, result.largeAnglesBefore);

  Session session(m, ops, params, result);
  std::vector<std::size_t> irregular;
  std::vector<std::uint8_t> isIrregular;
  auto collectIrregular = [&]() {
    isIrregular.assign(m.vert.size(), 0);
    ParallelFor(m.vert.size(), threads, [&](std::size_t begin, std::size_t end, int) {
      for (std::size_t i = begin; i < end; ++i)
        isIrregular[i] = !m.vert[i].IsD() && session.Irregular(m.vert[i]) ? 1 : 0;
    });
    irregular.clear();
    for (std::size_t i = 0; i < m.vert.size(); ++i)
      if (isIrregular[i]) irregular.push_back(i);
  };
  for (int round = 0; round < params.rounds; ++round) {
    bool changed = false;
    if (params.flipsAndCollapses) {
      // Sweeps until no edit helps (a collapse or flip may make a neighbour irregular).
      for (int sweep = 0; sweep < 8; ++sweep) {
        collectIrregular();
        bool any = false;
        for (const std::size_t i : irregular) {
          VertexType& v = m.vert[i];
          if (v.IsD() || !session.Irregular(v)) continue;
          session.EnsureFootpoints(&v);
          if (session.ImproveByFlipOrCollapse(&v)) any = true;
        }
        if (!any) break;
        changed = true;
      }
    }
    if (params.removeAndRefill) {
      collectIrregular();
      for (const std::size_t i : irregular) {
        VertexType& v = m.vert[i];
        if (v.IsD() || !session.Irregular(v)) continue;
        session.EnsureFootpoints(&v);
        if (session.RemoveAndRefill(&v)) changed = true;
      }
    }
    result.rounds = round + 1;
    if (!changed) break;
  }
  ops.Finish();
  UpdateAdjacency(m);
  result.after = Census(m);
  countBad(result.smallAnglesAfter, result.largeAnglesAfter);
  result.ok = true;
  std::ostringstream message;
  message.setf(std::ios::fixed);
  message.precision(2);
  message << "valence optimization: V567 " << result.before.RegularPercent() << "% -> "
          << result.after.RegularPercent() << "%";
  result.message = message.str();
  return result;
}

} // namespace molremesh

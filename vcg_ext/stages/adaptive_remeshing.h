// Real-time adaptive remeshing (RAR) of Dunyach et al. 2013, "Adaptive remeshing for real-time
// mesh deformation" (Eurographics short papers), the remeshing Khan et al. 2020 apply to every
// patch of their segmentation (section 3.3).
//
// AdaptiveRemeshing<MeshType> drives the guarded, transactional edits of LocalRemeshingOps:
//  - sizing field: a target edge length L(x) per vertex from the largest absolute principal
//    curvature kappa, L = sqrt(6 eps / kappa - 3 eps^2) (the edge length of an equilateral
//    triangle inscribed in a circle of radius 1/kappa whose sagitta is eps), clamped to
//    [minLengthFactor, maxLengthFactor] x L0 and averaged over the one-ring; eps is
//    approximationTolerance x L0. kappa is estimated on the mesh itself: the normal curvature
//    along each edge, 2 n.(p_i - p_j) / |p_i - p_j|^2 (exact on a sphere for any edge length),
//    fitted by a 2x2 curvature tensor per vertex (least squares), whose eigenvalues are the
//    principal curvatures; with Params::meanEdgeAtTarget (the pipeline's setting) the field is
//    then scaled so that the mesh it describes has mean edge length L0 (ScaleSizingToMeanEdge);
//  - per iteration: split the edges longer than splitFactor x L(edge), collapse those shorter
//    than collapseFactor x L(edge) unless an edge of the result would be longer than
//    splitFactor x L, flip edges toward valence 6 (4 on the boundary), then tangential
//    relaxation (sizing-weighted area centroid, moved in the tangent plane, projected onto the
//    reference near the vertex's footpoint, all vertices at once and verified: Jacobi style).
//    L(edge) is the smaller target length of its two end points;
//  - after the iterations, a repair pass (an addition of ours, not in Dunyach et al.): every
//    triangle whose smallest angle is below repairMinAngleDeg or whose quality Q is below
//    repairMinQuality has the edge opposite its largest angle flipped when that improves both
//    triangles, and its free corners moved to the position of their one-ring that maximizes
//    the ring's worst score min(angle / repairMinAngleDeg, Q / repairMinQuality) (compass
//    search on the reference). Q = 6/sqrt(3) A / (s h), s the half perimeter and h the longest
//    edge, is the quality MeshQuality reports (1 for an equilateral triangle). A needle whose
//    smallest angle is below guards.minAngleDeg (from the input, or from a split, whose guard
//    is looser) has its shortest edge collapsed, with the fold, normal and largest-angle guards
//    relaxed to repairGuards: the needles that survive relaxation sit on sharp creases of the
//    input (cusps where atomic spheres meet), where any triangulation has a sharp dihedral
//    angle. When the guards refuse the best position of a corner, the move backs off toward
//    the start (a crease may fold beyond the best position, not before it). An interior
//    corner of valence 3 or 4 (its triangles have right or obtuse angles whatever its position)
//    is removed by collapsing it into the neighbour that leaves the best triangles, or gets one
//    more edge by a flip of its link.
//  - finally (Finalize: Do, and PatchwiseRemeshing after its strip pass) first the
//    approximation error at the input's own vertices (an addition of ours): chords between
//    vertices on the input cut off its cusps, spikes and the lips of grooves, where the input's
//    vertices end up to ~0.9 L0 from the result (the one-sided Hausdorff distance input ->
//    result). Every input vertex farther than snapTolerance x L0 from the result (exact
//    distances to a grid of the result) has the nearest free corner of its closest face moved
//    onto it, farthest first, under snapGuards (angles 36..100 degrees), and beyond
//    snapLooseTolerance x L0 under snapLooseGuards (down to 25 degrees); a few rounds. Where the
//    guards refuse every corner, a last round moves one 3/4 or 1/2 of the way (a shorter chord
//    over the cusp) for the input vertices at least snapPartialShare of the farthest one's
//    distance away (those set the Hausdorff distance), where every face around the corner and
//    its neighbours has its angles in the snap guards' range before and after, the input
//    vertex's distance drops by a fifth and no other input point near it ends farther from the
//    result than the input vertex then is (the fidelity guard): on galactose the one-sided
//    distance drops from 0.135 to 0.096 L0.
//    The snapped vertices stay locked through the last repair pass, except those of a triangle
//    the pass leaves below the angle guard: they are released and the pass runs again. Then the volume:
//    vertices on the input enclose less volume than the input where it is convex (chords cut it), so each
//    closed component is offset along its area-weighted vertex normals by
//    (V_input - V) / A, twice (the second pass takes the curvature term out), no vertex
//    farther than maxVolumeOffset x L0 from the input, through the verified batch move; and the
//    repair pass once more.
// Every edit goes through LocalRemeshingOps, so none creates a fold, a flipped or degenerate
// face, an intersecting pair or a non-manifold configuration, none moves or removes a locked
// vertex, and the angle guards (Params::guards, Params::splitGuards) hold: an edit never
// brings an angle below the guard unless the region's smallest angle improves.
//
// Determinism: the edits run serially in a fixed order (edges sorted by length ratio, vertex
// indices breaking ties); only per-vertex computations run in parallel, so the output is
// bit-identical for any thread count.
#pragma once

#include <vcg/complex/complex.h>

#include <vcg_ext/core/input_check.h>
#include <vcg_ext/core/parallel_for.h>
#include <vcg_ext/geometry/point.h>
#include <vcg_ext/geometry/triangle_angles.h>
#include <vcg_ext/ops/local_remeshing_ops.h>
#include <vcg_ext/quality/mesh_quality.h>
#include <vcg_ext/surface/reference_surface.h>
#include <vcg_ext/surface/surface_distance.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <numeric>
#include <string>
#include <tuple>
#include <vector>

namespace molremesh {

/// What one RAR run did (summed over patches by PatchwiseRemeshing).
struct AdaptiveRemeshingStats {
  std::size_t splits = 0, collapses = 0, flips = 0; ///< applied by the split / collapse / flip passes
  std::size_t movesApplied = 0, movesRejected = 0;  ///< tangential relaxation
  std::size_t repairMoves = 0, repairFlips = 0, repairCollapses = 0; ///< repair pass (collapses:
                                                                     ///< needles and low-valence vertices)
  std::size_t snapMoves = 0; ///< vertices moved onto far input vertices (Finalize)
  std::size_t refused = 0;   ///< refused local operations, all reasons
  double volumeOffset = 0;   ///< largest |normal offset| of RestoreVolume, in units of L0
  int iterations = 0;        ///< iterations done

  void Add(const AdaptiveRemeshingStats& o) {
    splits += o.splits;
    collapses += o.collapses;
    flips += o.flips;
    movesApplied += o.movesApplied;
    movesRejected += o.movesRejected;
    repairMoves += o.repairMoves;
    repairFlips += o.repairFlips;
    repairCollapses += o.repairCollapses;
    snapMoves += o.snapMoves;
    refused += o.refused;
    volumeOffset = std::max(volumeOffset, o.volumeOffset);
    iterations = std::max(iterations, o.iterations);
  }
};

/// The guards RAR edits with: no new angle below 30 degrees or above 120 degrees (Khan et al.'s
/// angle bound) unless the region's worst angle improves.
inline LocalOpsGuards RarDefaultGuards() {
  LocalOpsGuards g;
  g.minAngleDeg = 30.0;
  g.maxAngleDeg = 120.0;
  return g;
}

/// Guards of the split pass: a split at the midpoint of an edge of an equilateral pair makes
/// 30-degree angles, so refinement needs a looser bound; relaxation and repair fix them.
inline LocalOpsGuards RarDefaultSplitGuards() {
  LocalOpsGuards g;
  g.minAngleDeg = 20.0;
  g.maxAngleDeg = 150.0;
  return g;
}

/// Guards of the snapping moves of Finalize (a vertex moved onto an input vertex the remeshed
/// surface cuts off): angles between 36 and 89.5 degrees (no new obtuse face: the snapped
/// vertex stays locked through the last repair pass), folds and normals as loose as the
/// repair pass allows on sharp creases (the input vertices far from the result sit on cusps and
/// spikes).
inline LocalOpsGuards RarDefaultSnapGuards() {
  LocalOpsGuards g;
  g.minAngleDeg = 36.0;
  g.maxAngleDeg = 89.5;
  g.maxFoldAngleDeg = 150.0;
  g.maxNormalDeviationDeg = 90.0;
  return g;
}

/// Guards of the snapping moves onto input vertices farther than Params::snapLooseTolerance:
/// angles from 25 to 120 degrees (the repair pass then reshapes the neighbourhood around the
/// tip; an obtuse face may remain next to the snapped vertex).
inline LocalOpsGuards RarDefaultSnapLooseGuards() {
  LocalOpsGuards g = RarDefaultSnapGuards();
  g.minAngleDeg = 25.0;
  g.maxAngleDeg = 120.0;
  return g;
}

/// Guards of the needle collapses of the repair pass: the angle guards of RarDefaultGuards, but
/// folds up to 165 degrees and normals up to 90 degrees off the reference (sharp creases).
inline LocalOpsGuards RarDefaultRepairGuards() {
  LocalOpsGuards g = RarDefaultGuards();
  g.maxAngleDeg = 150.0;
  g.maxFoldAngleDeg = 165.0;
  g.maxNormalDeviationDeg = 90.0;
  return g;
}

template <class MeshType>
class AdaptiveRemeshing {
public:
  using VertexType = typename MeshType::VertexType;
  using FaceType = typename MeshType::FaceType;
  using VertexPointer = typename MeshType::VertexPointer;
  using FacePointer = typename MeshType::FacePointer;
  using Ops = LocalRemeshingOps<MeshType>;
  using Reference = ReferenceSurface<MeshType>;
  using Point = vcg::Point3d;
  /// Where a vertex may be created or moved to (patch confinement); empty = anywhere.
  using PositionFilter = std::function<bool(const Point&)>;

  struct Params {
    int iterations = 5;                   ///< split / collapse / flip / relax iterations
    double targetEdgeLength = 0;          ///< L0, the base length; 0 = the mesh's mean edge length
    double approximationTolerance = 0.05; ///< eps / L0: allowed sagitta of an edge over the curved surface
    double minLengthFactor = 0.6;         ///< L(x) >= this x L0
    double maxLengthFactor = 1.0;         ///< L(x) <= this x L0
    int sizingSmoothingPasses = 2;        ///< averaging passes of L over each vertex and its one-ring
    bool meanEdgeAtTarget = false;        ///< scale L(x) to a mean edge length of L0 (ScaleSizingToMeanEdge)
    double splitFactor = 4.0 / 3.0;       ///< split edges longer than this x L(edge)
    double collapseFactor = 4.0 / 5.0;    ///< collapse edges shorter than this x L(edge)
    int maxSplitPasses = 4;               ///< split passes per iteration (new edges may still be long)
    int maxFlipPasses = 3;                ///< valence flip passes per iteration
    int relaxationSteps = 1;              ///< tangential relaxation rounds per iteration
    double minMoveFactor = 0.05;          ///< relaxation moves shorter than this x L0 are skipped (converged)
    int repairPasses = 3;                 ///< repair passes after the iterations (0 = off)
    double repairMinAngleDeg = 40.0;      ///< repair triangles with a smaller angle ...
    double repairMinQuality = 0.75;       ///< ... or a smaller quality Q
    bool preserveVolume = true;    ///< offset closed components along their normals to the input's volume
    double maxVolumeOffset = 0.05; ///< bound on that offset, in units of L0
    double volumeTolerance = 1e-4; ///< components whose volume is off by less (relative) are left alone
    double snapTolerance = 0.1;    ///< Finalize: input vertices farther than this x L0 from the result (the
                                   ///< tips of cusps and spikes that chords cut off) get the nearest free
                                   ///< corner of the closest face moved onto them (0 = off)
    double snapLooseTolerance =
        0.3;                  ///< input vertices farther than this x L0 may be snapped with snapLooseGuards
    double snapMaxMove = 1.0; ///< such a move is at most this x L0 long
    int snapRounds = 3;       ///< rounds of snapping at most (each measures the distances anew;
                              ///< they stop when they stall), then one round of partial moves
    double snapPartialShare = 0.5; ///< partial moves only toward input vertices at least this share
                                   ///< of the farthest one's distance away (> 1: none)
    LocalOpsGuards snapGuards = RarDefaultSnapGuards();           ///< guards of the snapping moves
    LocalOpsGuards snapLooseGuards = RarDefaultSnapLooseGuards(); ///< second try, beyond snapLooseTolerance
    LocalOpsGuards guards = RarDefaultGuards();                   ///< collapses, flips, relaxation, repair
    LocalOpsGuards splitGuards = RarDefaultSplitGuards();         ///< splits
    LocalOpsGuards repairGuards = RarDefaultRepairGuards();       ///< collapses of needles in the repair pass
    int threads = 0; ///< worker threads; 0 = all cores (the result does not depend on it)
  };

  struct Result {
    bool ok = false;
    std::string message;                                 ///< why it failed, or a one-line summary
    double targetEdgeLength = 0;                         ///< L0 used
    double minSizing = 0, maxSizing = 0, meanSizing = 0; ///< the sizing field at the start
    std::size_t verticesIn = 0, facesIn = 0, verticesOut = 0, facesOut = 0;
    AdaptiveRemeshingStats stats;
    LocalOpsStats operations;
  };

  /// Remeshes m in place, projecting onto `reference` (which m must lie on). m must be a
  /// 2-manifold, consistently oriented triangle mesh with FF and VF adjacency enabled. A refused
  /// input is left untouched and Result::message says why.
  static Result Do(MeshType& m, const Reference& reference, const Params& params = Params(),
                   vcg::CallBackPos* cb = nullptr);
  /// Same, with a reference surface built from m on entry.
  static Result Do(MeshType& m, const Params& params = Params(), vcg::CallBackPos* cb = nullptr);

  /// Target edge length per vertex (indexed like m.vert; deleted / unreferenced vertices get
  /// L0) from the curvature of m, as described in the file comment. Needs up-to-date VF
  /// adjacency. Thread-safe reads only; deterministic.
  static std::vector<double> ComputeSizing(const MeshType& m, double L0, const Params& params, int threads);

  /// Scales sizing (per vertex of m) so that the mean edge length of a mesh following it is L0:
  /// a region of area A meshed at length L has about A / L^2 edges of length L, so the mean is
  /// sum(A_i / L_i) / sum(A_i / L_i^2) over the vertices, A_i a third of their faces' area.
  static void ScaleSizingToMeanEdge(const MeshType& m, double L0, std::vector<double>& sizing);
  /// The mean edge length of a mesh of m's surface following sizing (0 when m has no area).
  static double MeanEdgeOfSizing(const MeshType& m, const std::vector<double>& sizing);

  /// Largest absolute principal curvature at v, estimated from its one-ring (see the file comment).
  static double MaxAbsCurvature(const VertexType& v);

  /// Runs `iterations` RAR iterations and the repair passes on the mesh held by ops, which must be
  /// Init-ed, with its locks set. sizing holds L per vertex index and grows with the mesh.
  /// allowed, when not empty, restricts where vertices are created or moved to. threads only
  /// affects speed.
  static AdaptiveRemeshingStats Remesh(Ops& ops, std::vector<double>& sizing, const Params& params,
                                       int iterations, int threads,
                                       const PositionFilter& allowed = PositionFilter());

  /// The end of a RAR run on the whole mesh: RestoreVolume (when params.preserveVolume), then the
  /// repair passes once more (the normal offsets change the shape of triangles on sharp creases).
  /// Every vertex is unlocked first. Returns the repair counts and the volume offset.
  static AdaptiveRemeshingStats Finalize(Ops& ops, std::vector<double>& sizing, const Params& params,
                                         int threads);

  /// Offsets every closed component of the mesh held by ops along its vertex normals so that it
  /// encloses the volume of the reference component it lies on (see the file comment); no vertex
  /// ends farther than maxOffset from the reference; components within `tolerance` (relative
  /// volume error) are left alone; locked and boundary vertices stay. Returns the largest
  /// |offset| from the reference of a moved vertex.
  static double RestoreVolume(Ops& ops, double maxOffset, double tolerance, int threads);

  /// Moves mesh vertices onto the input vertices (reference vertices) that lie farther than
  /// params.snapTolerance x L0 from the mesh, farthest first: the free corners of the closest
  /// face, nearest first, each at most snapMaxMove x L0, guarded by params.snapGuards. Vertices
  /// moved are flagged in `snapped` (indexed like m.vert) and never moved again by it. Returns the
  /// number of moves. Deterministic (distances computed in parallel, edits serial in a fixed order).
  static std::size_t SnapToInputVertices(Ops& ops, const Params& params, int threads,
                                         std::vector<std::uint8_t>& snapped);

  /// Smallest angle of triangle (a, b, c) in degrees and its quality Q (see the file comment).
  static void TriangleShape(const Point& a, const Point& b, const Point& c, double& minAngleDeg,
                            double& quality);

private:
  class Session;

  // Pieces of SnapToInputVertices.

  /// Whether a triangle with angles in [smallest, largest] lies in the snap guards' range.
  static bool InSnapRange(const LocalOpsGuards& snapGuards, double smallest, double largest) {
    return smallest >= snapGuards.minAngleDeg && largest <= snapGuards.maxAngleDeg;
  }
  /// Distance from p to the faces around v with v moved to q; infinite when one of these faces
  /// would leave the snap guards' range (a partial move is locked through the repair pass, so it
  /// must leave good triangles, not merely better ones).
  static double SnapStarDistance(const LocalOpsGuards& snapGuards, VertexPointer v, const Point& q,
                                 const Point& p);
  /// Whether every face around v and around its neighbours has its angles in the snap guards'
  /// range: a partial move, locked through the repair, must not sit in a region the repair has
  /// still to fix.
  static bool SnapCalmAround(const LocalOpsGuards& snapGuards, VertexPointer v);
  /// The mesh's live triangles (vertex indices) and the index in m.face of each: the same every
  /// snap round (the rounds only move vertices), so a hit face of one round names the same face
  /// in the next.
  static void CollectSnapTriangles(MeshType& m, std::vector<std::array<Index, 3>>& tris,
                                   std::vector<std::size_t>& faceOf);
  /// Exact distances of the reference vertices measure[k] to the current mesh (its triangles
  /// `tris`), and the closest triangle of each (an index in tris), computed in parallel.
  static void MeasureInputDistances(const MeshType& m, const Reference& ref,
                                    const std::vector<std::array<Index, 3>>& tris,
                                    const std::vector<std::uint32_t>& measure, int threads,
                                    std::vector<double>& distance, std::vector<long long>& hitFace);
  /// The lengths of one SnapToInputVertices call (params' factors times L0).
  struct SnapLimits {
    double L0;             ///< target edge length
    double tolerance;      ///< input vertices farther than this from the mesh are snapped to
    double maxMove;        ///< no corner moves farther than this
    double looseTolerance; ///< beyond this, a refused full snap is retried with the loose guards
  };
  /// The reference vertices to measure anew in a round after the first: those that were far, and
  /// those whose closest face has a corner moved by the round before. For any other, that face is
  /// unchanged, so its distance can only have dropped and it was within the tolerance already: the
  /// far points and their distances are then exactly what measuring every vertex would give.
  static void SelectSnapMeasurements(MeshType& m, const std::vector<std::size_t>& movedLastRound,
                                     const std::vector<double>& distance,
                                     const std::vector<long long>& hitFace,
                                     const std::vector<std::size_t>& faceOf, double tolerance,
                                     std::vector<std::uint32_t>& measure);
  /// The reference vertices farther than tolerance from the mesh, as (-distance, index), farthest
  /// first; in the partial phase only those within partialShare of the farthest distance.
  static std::vector<std::pair<double, std::uint32_t>> FarInputVertices(const std::vector<double>& distance,
                                                                        const std::vector<long long>& hitFace,
                                                                        double tolerance, bool partialPhase,
                                                                        double partialShare);
  /// Snaps one corner of face fi (the closest face of reference vertex i, distanceBefore away when
  /// measured) towards i, nearest corner first, trying each of `fractions` of the way in turn.
  /// Records the moved vertex in `snapped` and `movedLastRound`. Returns whether a corner moved.
  static bool SnapInputVertex(Ops& ops, const Params& params, const SnapLimits& limits,
                              const std::vector<double>& fractions, std::uint32_t i, double distanceBefore,
                              std::size_t fi, std::vector<std::uint8_t>& snapped,
                              std::vector<std::size_t>& movedLastRound);
  /// One guarded move of v towards input vertex i at p: the whole way (with the loose guards as a
  /// fallback beyond looseTolerance), or `fraction` of the way when that brings v's star clearly
  /// closer to p than its face now is (now2: squared distance). Returns whether v moved.
  static bool TrySnapMove(Ops& ops, const Params& params, const SnapLimits& limits, VertexPointer v,
                          std::uint32_t i, const Point& p, double fraction, double distanceBefore,
                          double now2);
};

// ------------------------------------------------------------------------------------------------
// Implementation
// ------------------------------------------------------------------------------------------------

namespace rar_detail {

inline double AngleAt(const Point& apex, const Point& a, const Point& b) {
  const Point u = a - apex, v = b - apex;
  const double nu = u.Norm(), nv = v.Norm();
  if (!(nu > 0) || !(nv > 0)) return 0.0;
  return std::acos(std::clamp((u * v) / (nu * nv), -1.0, 1.0)) * (180.0 / kPi);
}

} // namespace rar_detail

template <class MeshType>
void AdaptiveRemeshing<MeshType>::TriangleShape(const Point& a, const Point& b, const Point& c,
                                                double& minAngleDeg, double& quality) {
  const double la = (b - c).Norm(), lb = (c - a).Norm(), lc = (a - b).Norm();
  const double area = 0.5 * ((b - a) ^ (c - a)).Norm();
  const double s = 0.5 * (la + lb + lc), h = std::max({la, lb, lc});
  quality = s > 0 && h > 0 ? (6.0 / std::sqrt(3.0)) * area / (s * h) : 0.0;
  // The smallest angle faces the shortest edge.
  if (la <= lb && la <= lc)
    minAngleDeg = rar_detail::AngleAt(a, b, c);
  else if (lb <= lc)
    minAngleDeg = rar_detail::AngleAt(b, c, a);
  else
    minAngleDeg = rar_detail::AngleAt(c, a, b);
}

template <class MeshType>
double AdaptiveRemeshing<MeshType>::MaxAbsCurvature(const VertexType& v) {
  const Point p = PositionOf(&v);
  Point n(0, 0, 0);
  // Area-weighted normal and the neighbours (each once: the next corner of every face, plus the
  // previous corner across a border edge).
  std::array<Point, 32> nb;
  int count = 0;
  for (vcg::face::VFIterator<FaceType> it(const_cast<VertexType*>(&v)); !it.End(); ++it) {
    const FaceType* f = it.F();
    const int k = it.I();
    const Point a = PositionOf(f->cV((k + 1) % 3)), b = PositionOf(f->cV((k + 2) % 3));
    n += (a - p) ^ (b - p);
    if (count < int(nb.size())) nb[count++] = a;
    if (f->cFFp((k + 2) % 3) == f && count < int(nb.size())) nb[count++] = b;
  }
  const double len = n.Norm();
  if (!(len > 0) || count < 2) return 0.0;
  n /= len;
  Point e1, e2;
  TangentBasis(n, e1, e2);
  // Least squares fit of kappa(t) = a x^2 + 2 b x y + c y^2 over the unit tangent directions.
  double M[3][3] = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}, r[3] = {0, 0, 0};
  double maxAbs = 0;
  for (int i = 0; i < count; ++i) {
    const Point d = nb[i] - p;
    const double d2 = d.SquaredNorm();
    if (!(d2 > 0)) continue;
    const double kappa = -2.0 * (n * d) / d2;
    maxAbs = std::max(maxAbs, std::fabs(kappa));
    double x = d * e1, y = d * e2;
    const double t = std::sqrt(x * x + y * y);
    if (!(t > 0)) continue;
    x /= t;
    y /= t;
    const double row[3] = {x * x, 2 * x * y, y * y};
    for (int a = 0; a < 3; ++a) {
      r[a] += row[a] * kappa;
      for (int b = 0; b < 3; ++b) M[a][b] += row[a] * row[b];
    }
  }
  // Solve the 3x3 normal equations (Cramer); fall back to the largest edge curvature.
  auto det3 = [](const double A[3][3]) {
    return A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) -
           A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0]) +
           A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]);
  };
  const double det = det3(M);
  if (count < 3 || !(std::fabs(det) > 1e-9)) return maxAbs;
  double sol[3];
  for (int c = 0; c < 3; ++c) {
    double A[3][3];
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) A[a][b] = b == c ? r[a] : M[a][b];
    sol[c] = det3(A) / det;
  }
  const double mean = 0.5 * (sol[0] + sol[2]);
  const double disc = std::sqrt(0.25 * (sol[0] - sol[2]) * (sol[0] - sol[2]) + sol[1] * sol[1]);
  const double k = std::max(std::fabs(mean + disc), std::fabs(mean - disc));
  return std::isfinite(k) ? k : maxAbs;
}

template <class MeshType>
std::vector<double> AdaptiveRemeshing<MeshType>::ComputeSizing(const MeshType& m, double L0,
                                                               const Params& params, int threads) {
  const std::size_t n = m.vert.size();
  std::vector<double> sizing(n, L0), next(n, L0);
  const double eps = params.approximationTolerance * L0;
  const double lo = params.minLengthFactor * L0, hi = std::max(lo, params.maxLengthFactor * L0);
  auto live = [&](std::size_t i) { return !m.vert[i].IsD() && m.vert[i].cVFp() != nullptr; };
  ParallelFor(n, threads, [&](std::size_t begin, std::size_t end, int) {
    for (std::size_t i = begin; i < end; ++i) {
      if (!live(i)) continue;
      const double kappa = MaxAbsCurvature(m.vert[i]);
      double L = hi;
      if (eps > 0 && kappa > 0) {
        const double s = 6.0 * eps / kappa - 3.0 * eps * eps;
        L = s > 0 ? std::sqrt(s) : lo;
      } else if (!(eps > 0)) {
        L = L0;
      }
      sizing[i] = std::clamp(L, lo, hi);
    }
  });
  for (int pass = 0; pass < params.sizingSmoothingPasses; ++pass) {
    ParallelFor(n, threads, [&](std::size_t begin, std::size_t end, int) {
      for (std::size_t i = begin; i < end; ++i) {
        if (!live(i)) {
          next[i] = sizing[i];
          continue;
        }
        const VertexType& v = m.vert[i];
        double sum = sizing[i];
        int count = 1;
        for (vcg::face::VFIterator<FaceType> it(const_cast<VertexType*>(&v)); !it.End(); ++it) {
          sum += sizing[vcg::tri::Index(m, it.F()->cV((it.I() + 1) % 3))];
          ++count;
        }
        next[i] = sum / count;
      }
    });
    sizing.swap(next);
  }
  if (params.meanEdgeAtTarget) ScaleSizingToMeanEdge(m, L0, sizing);
  return sizing;
}

namespace rar_detail {
/// sum(A_i / L_i) and sum(A_i / L_i^2) over the vertices of m (see ScaleSizingToMeanEdge).
template <class MeshType>
std::pair<double, double> SizingSums(const MeshType& m, const std::vector<double>& sizing) {
  std::vector<double> area(m.vert.size(), 0.0);
  for (const auto& f : m.face) {
    if (f.IsD()) continue;
    const vcg::Point3d a = PositionOf(f.cV(0)), b = PositionOf(f.cV(1)), c = PositionOf(f.cV(2));
    const double third = ((b - a) ^ (c - a)).Norm() / 6.0;
    for (int k = 0; k < 3; ++k) area[vcg::tri::Index(m, f.cV(k))] += third;
  }
  double lengths = 0, edges = 0;
  for (std::size_t i = 0; i < sizing.size() && i < area.size(); ++i)
    if (area[i] > 0 && sizing[i] > 0) {
      lengths += area[i] / sizing[i];
      edges += area[i] / (sizing[i] * sizing[i]);
    }
  return {lengths, edges};
}
} // namespace rar_detail

template <class MeshType>
double AdaptiveRemeshing<MeshType>::MeanEdgeOfSizing(const MeshType& m, const std::vector<double>& sizing) {
  const auto [lengths, edges] = rar_detail::SizingSums(m, sizing);
  return edges > 0 ? lengths / edges : 0.0;
}

template <class MeshType>
void AdaptiveRemeshing<MeshType>::ScaleSizingToMeanEdge(const MeshType& m, double L0,
                                                        std::vector<double>& sizing) {
  const auto [lengths, edges] = rar_detail::SizingSums(m, sizing);
  const double scale = edges > 0 ? L0 * edges / lengths : 1.0;
  if (!(scale > 0) || !std::isfinite(scale)) return;
  for (double& L : sizing) L *= scale;
}

// --- The remeshing session -------------------------------------------------------------------------

template <class MeshType>
class AdaptiveRemeshing<MeshType>::Session {
public:
  Session(Ops& ops, std::vector<double>& sizing, const Params& params, int threads,
          const PositionFilter& allowed)
      : ops_(ops), m_(ops.Mesh()), ref_(ops.GetReference()), sizing_(sizing), params_(params),
        threads_(ResolveThreadCount(threads)), allowed_(allowed), scratch_(std::size_t(threads_)) {
    L0_ = ops.TargetEdgeLength();
    Grow();
  }

  AdaptiveRemeshingStats Run(int iterations) {
    const LocalOpsGuards saved = ops_.Guards();
    const std::size_t refusedBefore = ops_.Stats().Refused();
    for (int it = 0; it < iterations; ++it) {
      ops_.SetGuards(params_.splitGuards);
      for (int pass = 0; pass < params_.maxSplitPasses; ++pass)
        if (SplitPass() == 0) break;
      ops_.SetGuards(params_.guards);
      CollapsePass();
      for (int pass = 0; pass < params_.maxFlipPasses; ++pass)
        if (FlipPass() == 0) break;
      for (int step = 0; step < params_.relaxationSteps; ++step) Relax();
      stats_.iterations = it + 1;
    }
    ops_.SetGuards(params_.guards);
    for (int pass = 0; pass < params_.repairPasses; ++pass)
      if (RepairPass() == 0) break;
    ops_.SetGuards(saved);
    stats_.refused = ops_.Stats().Refused() - refusedBefore;
    return stats_;
  }

private:
  struct EdgeCandidate {
    double ratio;       ///< length / L(edge)
    std::uint32_t a, b; ///< vertex indices, a < b
  };

  std::size_t VIndex(const VertexType* v) const { return std::size_t(v - &m_.vert[0]); }
  Point Pos(const VertexType* v) const { return PositionOf(v); }
  bool Allowed(const Point& p) const { return !allowed_ || allowed_(p); }
  void Grow() {
    if (sizing_.size() < m_.vert.size()) sizing_.resize(m_.vert.size(), L0_);
  }
  double EdgeTarget(std::size_t a, std::size_t b) const { return std::min(sizing_[a], sizing_[b]); }
  bool Live(std::size_t vi) const { return !m_.vert[vi].IsD() && m_.vert[vi].cVFp() != nullptr; }

  /// Edges (each once) whose length ratio is above (longer) or below the factor, sorted most
  /// extreme first, vertex indices breaking ties. Edges between two locked vertices are skipped.
  void CollectEdges(double factor, bool longer) {
    edges_.clear();
    for (const FaceType& f : m_.face) {
      if (f.IsD()) continue;
      for (int e = 0; e < 3; ++e) {
        const FaceType* g = f.cFFp(e);
        if (g != &f && g < &f) continue;
        std::uint32_t a = std::uint32_t(VIndex(f.cV(e))), b = std::uint32_t(VIndex(f.cV((e + 1) % 3)));
        if (ops_.IsLocked(m_.vert[a]) && ops_.IsLocked(m_.vert[b])) continue;
        const double L = EdgeTarget(a, b);
        const double ratio = (Pos(f.cV(e)) - Pos(f.cV((e + 1) % 3))).Norm() / L;
        if (longer ? ratio > factor : ratio < factor) {
          if (b < a) std::swap(a, b);
          edges_.push_back({ratio, a, b});
        }
      }
    }
    std::sort(edges_.begin(), edges_.end(), [longer](const EdgeCandidate& x, const EdgeCandidate& y) {
      if (x.ratio != y.ratio) return longer ? x.ratio > y.ratio : x.ratio < y.ratio;
      return std::tie(x.a, x.b) < std::tie(y.a, y.b);
    });
  }

  std::size_t SplitPass() {
    CollectEdges(params_.splitFactor, true);
    std::size_t done = 0;
    for (const EdgeCandidate& e : edges_) {
      if (!Live(e.a) || !Live(e.b)) continue;
      FacePointer f = nullptr;
      int z = 0;
      if (!ops_.FindEdge(&m_.vert[e.a], &m_.vert[e.b], f, z)) continue;
      const Point pa = Pos(&m_.vert[e.a]), pb = Pos(&m_.vert[e.b]);
      const double La = sizing_[e.a], Lb = sizing_[e.b];
      if (!((pa - pb).Norm() > params_.splitFactor * std::min(La, Lb))) continue;
      if (!Allowed((pa + pb) * 0.5)) continue;
      const VertexPointer nv = ops_.SplitEdge(f, z);
      if (nv == nullptr) continue;
      Grow();
      sizing_[VIndex(nv)] = 0.5 * (La + Lb);
      ++done;
    }
    stats_.splits += done;
    return done;
  }

  /// Smallest target length over v and its neighbours.
  double MinSizingAround(std::size_t vi) const {
    double L = sizing_[vi];
    for (vcg::face::VFIterator<FaceType> it(&m_.vert[vi]); !it.End(); ++it) {
      L = std::min(L, sizing_[VIndex(it.F()->cV((it.I() + 1) % 3))]);
      L = std::min(L, sizing_[VIndex(it.F()->cV((it.I() + 2) % 3))]);
    }
    return L;
  }

  std::size_t CollapsePass() {
    CollectEdges(params_.collapseFactor, false);
    std::size_t done = 0;
    for (const EdgeCandidate& e : edges_) {
      if (!Live(e.a) || !Live(e.b)) continue;
      FacePointer f = nullptr;
      int z = 0;
      if (!ops_.FindEdge(&m_.vert[e.a], &m_.vert[e.b], f, z)) continue;
      const Point pa = Pos(&m_.vert[e.a]), pb = Pos(&m_.vert[e.b]);
      const double La = sizing_[e.a], Lb = sizing_[e.b];
      if (!((pa - pb).Norm() < params_.collapseFactor * std::min(La, Lb))) continue;
      const bool freeA = !ops_.IsLocked(m_.vert[e.a]) && !ops_.IsBoundaryVertex(m_.vert[e.a]);
      const bool freeB = !ops_.IsLocked(m_.vert[e.b]) && !ops_.IsBoundaryVertex(m_.vert[e.b]);
      if (freeA && freeB && !Allowed((pa + pb) * 0.5)) continue;
      const double maxNew = params_.splitFactor * std::min(MinSizingAround(e.a), MinSizingAround(e.b));
      if (!ops_.CollapseEdge(f, z, maxNew)) continue;
      const std::uint32_t survivor = m_.vert[e.a].IsD() ? e.b : e.a;
      if (freeA && freeB) sizing_[survivor] = 0.5 * (La + Lb);
      ++done;
    }
    stats_.collapses += done;
    return done;
  }

  /// Valence of every vertex and whether it is on the boundary (for the flip passes).
  void ComputeValences() {
    valence_.assign(m_.vert.size(), 0);
    boundary_.assign(m_.vert.size(), 0);
    for (const FaceType& f : m_.face) {
      if (f.IsD()) continue;
      for (int e = 0; e < 3; ++e) {
        const FaceType* g = f.cFFp(e);
        const std::size_t a = VIndex(f.cV(e)), b = VIndex(f.cV((e + 1) % 3));
        if (g == &f) {
          boundary_[a] = boundary_[b] = 1;
          ++valence_[a];
          ++valence_[b];
        } else if (&f < g) {
          ++valence_[a];
          ++valence_[b];
        }
      }
    }
  }

  /// Flips edge e of f when that lowers the sum of |valence - ideal| of its four vertices
  /// (ideal 6, 4 on the boundary), as LocalRemeshingOps::FlipValenceGain, from cached valences.
  std::size_t FlipPass() {
    ComputeValences();
    // Only faces with a free corner can hold a flippable edge (one with a free end), and only
    // they change when one is flipped (both faces hold its free end): the others are skipped
    // without being read, which matters when most of the mesh is locked (the strip pass).
    const std::size_t nf = m_.face.size();
    activeFlag_.assign(nf, 0);
    ParallelFor(nf, threads_, [&](std::size_t begin, std::size_t end, int) {
      for (std::size_t fi = begin; fi < end; ++fi) {
        const FaceType& f = m_.face[fi];
        activeFlag_[fi] =
            !f.IsD() && !(ops_.IsLocked(*f.cV(0)) && ops_.IsLocked(*f.cV(1)) && ops_.IsLocked(*f.cV(2)));
      }
    });
    std::size_t done = 0;
    for (std::size_t fi = 0; fi < nf; ++fi) {
      if (!activeFlag_[fi]) continue; // live, with a free corner (flips delete no face)
      FaceType& f = m_.face[fi];
      for (int e = 0; e < 3; ++e) {
        FaceType* g = f.FFp(e);
        if (g == &f || g < &f) continue;
        const std::size_t v0 = VIndex(f.cV(e)), v1 = VIndex(f.cV((e + 1) % 3)),
                          v2 = VIndex(f.cV((e + 2) % 3));
        const std::size_t v3 = VIndex(g->cV((f.FFi(e) + 2) % 3));
        if (ops_.IsLocked(m_.vert[v0]) && ops_.IsLocked(m_.vert[v1])) continue;
        auto deviation = [&](std::size_t v, int change) {
          return std::abs(valence_[v] + change - (boundary_[v] ? 4 : 6));
        };
        const int before = deviation(v0, 0) + deviation(v1, 0) + deviation(v2, 0) + deviation(v3, 0);
        const int after = deviation(v0, -1) + deviation(v1, -1) + deviation(v2, 1) + deviation(v3, 1);
        if (after >= before) continue;
        if (!ops_.FlipEdge(&f, e)) continue;
        --valence_[v0];
        --valence_[v1];
        ++valence_[v2];
        ++valence_[v3];
        ++done;
      }
    }
    stats_.flips += done;
    return done;
  }

  /// Sizing-weighted area centroid of v's one-ring and its area-weighted normal.
  void RingCentroid(const VertexType& v, Point& centroid, Point& normal) const {
    const Point p = Pos(&v);
    const double Lv = sizing_[VIndex(&v)];
    Point c(0, 0, 0);
    normal = Point(0, 0, 0);
    double wsum = 0;
    for (vcg::face::VFIterator<FaceType> it(const_cast<VertexType*>(&v)); !it.End(); ++it) {
      const VertexType* a = it.F()->cV((it.I() + 1) % 3);
      const VertexType* b = it.F()->cV((it.I() + 2) % 3);
      const Point pa = Pos(a), pb = Pos(b);
      const Point cross = (pa - p) ^ (pb - p);
      normal += cross;
      double area = cross.Norm();
      if (!(area > 0)) area = 1e-30;
      const double s = (Lv + sizing_[VIndex(a)] + sizing_[VIndex(b)]) / 3.0;
      const double w = area / (s * s);
      c += (p + pa + pb) * (w / 3.0);
      wsum += w;
    }
    centroid = wsum > 0 ? c / wsum : p;
    const double len = normal.Norm();
    normal = len > 0 ? normal / len : Point(0, 0, 0);
  }

  void Relax() {
    movable_.clear();
    for (std::size_t i = 0; i < m_.vert.size(); ++i) {
      const VertexType& v = m_.vert[i];
      if (v.IsD() || v.cVFp() == nullptr || ops_.IsLocked(v) || ops_.IsBoundaryVertex(v)) continue;
      movable_.push_back(std::uint32_t(i));
    }
    targets_.resize(movable_.size());
    feet_.resize(movable_.size());
    const double minMove2 = params_.minMoveFactor * L0_ * params_.minMoveFactor * L0_;
    ParallelFor(movable_.size(), threads_, [&](std::size_t begin, std::size_t end, int t) {
      for (std::size_t i = begin; i < end; ++i) {
        const VertexType& v = m_.vert[movable_[i]];
        Point c, n;
        RingCentroid(v, c, n);
        const Point p = Pos(&v);
        Point u = c - p;
        u -= n * (u * n);
        feet_[i] = -1;
        if (!(u.SquaredNorm() > minMove2)) continue;
        const Point q = p + u;
        if (!Allowed(q)) continue;
        const SurfaceProjection proj = ref_.Project(q, ops_.Footpoint(v), scratch_[std::size_t(t)]);
        if (!proj.ok() || !Allowed(proj.point)) continue;
        targets_[i] = proj.point;
        feet_[i] = proj.face;
      }
    });
    std::size_t kept = 0;
    for (std::size_t i = 0; i < movable_.size(); ++i) {
      if (feet_[i] < 0) continue;
      movable_[kept] = movable_[i];
      targets_[kept] = targets_[i];
      feet_[kept] = feet_[i];
      ++kept;
    }
    movable_.resize(kept);
    targets_.resize(kept);
    feet_.resize(kept);
    const BatchMoveResult r = ops_.MoveVerticesJacobi(movable_, targets_, feet_, threads_);
    stats_.movesApplied += r.applied;
    stats_.movesRejected += r.rejected;
  }

  // --- Angle repair ------------------------------------------------------------------------------

  /// min(smallest angle / repairMinAngleDeg, Q / repairMinQuality): below 1 means "to repair".
  double Score(const Point& a, const Point& b, const Point& c) const {
    double angle, quality;
    TriangleShape(a, b, c, angle, quality);
    return std::min(angle / params_.repairMinAngleDeg, quality / params_.repairMinQuality);
  }
  double FaceScore(const FaceType& f) const { return Score(Pos(f.cV(0)), Pos(f.cV(1)), Pos(f.cV(2))); }
  /// Worst score of v's one-ring with v at q.
  double StarScore(const Point& q) const {
    double s = std::numeric_limits<double>::infinity();
    for (const auto& ab : ring_) s = std::min(s, Score(q, ab.first, ab.second));
    return s;
  }

  /// Moves free vertex vi to the position of its one-ring (on the reference) maximizing the
  /// ring's worst triangle score: a compass search in the tangent plane.
  bool OptimizeVertex(std::size_t vi) {
    VertexType& v = m_.vert[vi];
    if (ops_.IsLocked(v) || ops_.IsBoundaryVertex(v) || v.VFp() == nullptr) return false;
    ring_.clear();
    const Point p0 = Pos(&v);
    Point n(0, 0, 0);
    double spacing = 0;
    for (vcg::face::VFIterator<FaceType> it(&v); !it.End(); ++it) {
      const Point a = Pos(it.F()->cV((it.I() + 1) % 3)), b = Pos(it.F()->cV((it.I() + 2) % 3));
      ring_.emplace_back(a, b);
      n += (a - p0) ^ (b - p0);
      spacing += (a - p0).Norm();
    }
    if (ring_.size() < 3 || !(n.Norm() > 0)) return false;
    n.Normalize();
    spacing /= double(ring_.size());
    Point e1, e2;
    TangentBasis(n, e1, e2);
    const double start = StarScore(p0);
    Point best = p0;
    int bestFoot = ops_.Footpoint(v);
    double bestScore = start;
    double h = 0.25 * spacing;
    for (int iter = 0; iter < 24 && h > 1e-3 * spacing; ++iter) {
      Point roundBest = best;
      int roundFoot = -1;
      double roundScore = bestScore;
      for (int k = 0; k < 8; ++k) {
        const double angle = k * (kPi / 4.0);
        const Point q = best + (e1 * std::cos(angle) + e2 * std::sin(angle)) * h;
        const SurfaceProjection proj = ref_.Project(q, bestFoot, scratch_[0]);
        if (!proj.ok()) continue;
        const double s = StarScore(proj.point);
        if (s > roundScore + 1e-9) {
          roundScore = s;
          roundBest = proj.point;
          roundFoot = proj.face;
        }
      }
      if (roundFoot >= 0) {
        best = roundBest;
        bestFoot = roundFoot;
        bestScore = roundScore;
      } else {
        h *= 0.5;
      }
    }
    if (!(bestScore > start + 1e-9)) return false;
    // The guards may refuse the best position (a fold across a sharp crease, say): back off
    // toward the start while the ring still improves.
    Point target = best;
    int foot = bestFoot;
    for (int attempt = 0; attempt < 4; ++attempt) {
      if (Allowed(target) && ops_.MoveVertexTo(&v, target, foot)) return true;
      const SurfaceProjection proj = ref_.Project((p0 + target) * 0.5, foot, scratch_[0]);
      if (!proj.ok() || !(StarScore(proj.point) > start + 1e-9)) return false;
      target = proj.point;
      foot = proj.face;
    }
    return false;
  }

  /// Flips the edge opposite f's largest angle when both triangles get a better worst score.
  bool RepairFlip(std::size_t fi) {
    FaceType& f = m_.face[fi];
    int z = 0;
    double worst = -1;
    for (int k = 0; k < 3; ++k) { // edge k is opposite corner k + 2
      const double angle = rar_detail::AngleAt(Pos(f.cV((k + 2) % 3)), Pos(f.cV(k)), Pos(f.cV((k + 1) % 3)));
      if (angle > worst) worst = angle, z = k;
    }
    FaceType* g = f.FFp(z);
    if (g == &f) return false;
    if (ops_.IsLocked(*f.V(z)) && ops_.IsLocked(*f.V((z + 1) % 3))) return false;
    const int w = f.FFi(z);
    const Point p0 = Pos(f.cV(z)), p1 = Pos(f.cV((z + 1) % 3)), p2 = Pos(f.cV((z + 2) % 3)),
                p3 = Pos(g->cV((w + 2) % 3));
    const double before = std::min(Score(p0, p1, p2), Score(p1, p0, p3));
    const double after = std::min(Score(p0, p3, p2), Score(p1, p2, p3));
    if (!(after > before + 1e-9)) return false;
    return ops_.FlipEdge(&f, z);
  }

  /// Collapses the shortest edge of needle fi (smallest angle below the guard) with the repair
  /// guards. Returns the survivor's index, or -1.
  long RepairCollapse(std::size_t fi) {
    FaceType& f = m_.face[fi];
    int z = 0;
    double shortest = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k) {
      const double l = (Pos(f.cV(k)) - Pos(f.cV((k + 1) % 3))).Norm();
      if (l < shortest) shortest = l, z = k;
    }
    double angle, quality;
    TriangleShape(Pos(f.cV(0)), Pos(f.cV(1)), Pos(f.cV(2)), angle, quality);
    if (!(angle < params_.guards.minAngleDeg)) return -1;
    const std::size_t a = VIndex(f.cV(z)), b = VIndex(f.cV((z + 1) % 3));
    if (ops_.IsLocked(m_.vert[a]) && ops_.IsLocked(m_.vert[b])) return -1;
    const bool bothFree = !ops_.IsLocked(m_.vert[a]) && !ops_.IsBoundaryVertex(m_.vert[a]) &&
                          !ops_.IsLocked(m_.vert[b]) && !ops_.IsBoundaryVertex(m_.vert[b]);
    if (bothFree && !Allowed((Pos(f.cV(z)) + Pos(f.cV((z + 1) % 3))) * 0.5)) return -1;
    const double La = sizing_[a], Lb = sizing_[b];
    // New edges may be as long as the needle's longest one (they usually are: the needle spans it).
    double longest = 0;
    for (int k = 0; k < 3; ++k) longest = std::max(longest, (Pos(f.cV(k)) - Pos(f.cV((k + 1) % 3))).Norm());
    const double maxNew =
        std::max(longest, params_.splitFactor * std::min(MinSizingAround(a), MinSizingAround(b)));
    ops_.SetGuards(params_.repairGuards);
    const bool ok = ops_.CollapseEdge(&f, z, maxNew);
    ops_.SetGuards(params_.guards);
    if (!ok) return -1;
    const std::size_t survivor = m_.vert[a].IsD() ? b : a;
    if (bothFree) sizing_[survivor] = 0.5 * (La + Lb);
    return long(survivor);
  }

  /// Removes free interior vertex vi of valence 3 or 4 by collapsing it into the neighbour whose
  /// resulting triangles have the best worst score, when that beats the worst score of vi's
  /// star; otherwise flips the edge of its link that raises its valence, when that improves
  /// the two triangles. Returns the vertex to optimize next (the neighbour, or vi), or -1.
  long RepairLowValence(std::size_t vi) {
    VertexType& v = m_.vert[vi];
    if (v.VFp() == nullptr || ops_.IsLocked(v) || ops_.IsBoundaryVertex(v)) return -1;
    star_.clear();
    for (vcg::face::VFIterator<FaceType> it(&v); !it.End(); ++it) star_.emplace_back(it.F(), it.I());
    if (star_.size() > 4) return -1;
    double before = std::numeric_limits<double>::infinity();
    for (const auto& [f, k] : star_) before = std::min(before, FaceScore(*f));
    // Candidate survivors: the neighbours (the next corner of every face of the star).
    double best = before;
    std::size_t bestW = 0;
    bool found = false;
    for (const auto& [f0, k0] : star_) {
      const VertexType* w = f0->cV((k0 + 1) % 3);
      const Point pw = Pos(w);
      double after = std::numeric_limits<double>::infinity();
      for (const auto& [f, k] : star_) {
        const VertexType* a = f->cV((k + 1) % 3);
        const VertexType* b = f->cV((k + 2) % 3);
        if (a == w || b == w) continue; // removed by the collapse
        after = std::min(after, Score(pw, Pos(a), Pos(b)));
      }
      if (after > best + 1e-9) {
        best = after;
        bestW = VIndex(w);
        found = true;
      }
    }
    if (!found) {
      // No collapse helps: flip the link edge that raises vi's valence with the best result.
      FacePointer flipFace = nullptr;
      int flipEdge = 0;
      double flipBest = -std::numeric_limits<double>::infinity();
      for (const auto& [sf, sk] : star_) {
        const int e = (sk + 1) % 3; // the edge opposite vi
        FacePointer g = sf->FFp(e);
        if (g == sf) continue;
        const Point pv = Pos(&v), pa = Pos(sf->cV(e)), pb = Pos(sf->cV((e + 1) % 3));
        const Point px = Pos(g->cV((sf->FFi(e) + 2) % 3));
        const double was = std::min(Score(pv, pa, pb), Score(pb, pa, px));
        const double then = std::min(Score(pv, pa, px), Score(pv, px, pb));
        if (then > was + 1e-9 && then > flipBest) {
          flipBest = then;
          flipFace = sf;
          flipEdge = e;
        }
      }
      if (flipFace != nullptr && ops_.FlipEdge(flipFace, flipEdge)) {
        ++stats_.repairFlips;
        return long(vi);
      }
      return -1;
    }
    FacePointer f = nullptr;
    int z = 0;
    if (!ops_.FindEdge(&v, &m_.vert[bestW], f, z)) return -1;
    // The survivor must stay where it is: lock it for the collapse.
    const bool wasLocked = ops_.IsLocked(m_.vert[bestW]);
    ops_.SetLocked(m_.vert[bestW], true);
    double longest = 0;
    for (const auto& [g, k] : star_)
      longest = std::max(longest, (Pos(g->cV((k + 1) % 3)) - Pos(&m_.vert[bestW])).Norm());
    const bool ok = ops_.CollapseEdge(f, z, longest * (1.0 + 1e-9));
    ops_.SetLocked(m_.vert[bestW], wasLocked);
    if (!ok) return -1;
    ++stats_.repairCollapses;
    return long(bestW);
  }

  std::size_t RepairPass() {
    const double threshold = 1.0;
    bad_.clear();
    // Scores on all threads, the bad faces collected in face order.
    const std::size_t nf = m_.face.size();
    score_.resize(nf);
    ParallelFor(nf, threads_, [&](std::size_t begin, std::size_t end, int) {
      for (std::size_t fi = begin; fi < end; ++fi)
        score_[fi] = m_.face[fi].IsD() ? threshold : FaceScore(m_.face[fi]);
    });
    for (std::size_t fi = 0; fi < nf; ++fi)
      if (score_[fi] < threshold) bad_.emplace_back(score_[fi], std::uint32_t(fi));
    std::sort(bad_.begin(), bad_.end());
    std::size_t done = 0;
    for (const auto& [score, fi] : bad_) {
      const FaceType& f = m_.face[fi];
      if (f.IsD() || !(FaceScore(f) < threshold)) continue;
      // Needles (below the guard) first: collapse their shortest edge.
      const long survivor = RepairCollapse(fi);
      if (survivor >= 0) {
        ++stats_.repairCollapses;
        ++done;
        if (OptimizeVertex(std::size_t(survivor))) ++stats_.repairMoves;
        continue;
      }
      // Corners of valence 3 or 4 next: remove them (or raise their valence).
      long kept = -1;
      for (int k = 0; k < 3 && kept < 0; ++k) kept = RepairLowValence(VIndex(m_.face[fi].cV(k)));
      if (kept >= 0) {
        ++done;
        if (OptimizeVertex(std::size_t(kept))) ++stats_.repairMoves;
        continue;
      }
      bool changed = false;
      if (RepairFlip(fi)) {
        ++stats_.repairFlips;
        changed = true;
      }
      const std::array<std::size_t, 3> corners{VIndex(m_.face[fi].cV(0)), VIndex(m_.face[fi].cV(1)),
                                               VIndex(m_.face[fi].cV(2))};
      for (const std::size_t vi : corners) {
        if (OptimizeVertex(vi)) {
          ++stats_.repairMoves;
          changed = true;
        }
      }
      if (changed) ++done;
    }
    return done;
  }

  Ops& ops_;
  MeshType& m_;
  const Reference& ref_;
  std::vector<double>& sizing_;
  const Params& params_;
  int threads_;
  const PositionFilter& allowed_;
  double L0_ = 1;
  std::vector<typename Reference::Scratch> scratch_;
  AdaptiveRemeshingStats stats_;
  std::vector<EdgeCandidate> edges_;
  std::vector<std::uint32_t> movable_;
  std::vector<Point> targets_;
  std::vector<int> feet_;
  std::vector<std::pair<double, std::uint32_t>> bad_;
  std::vector<double> score_;            ///< RepairPass: every face's score
  std::vector<std::uint8_t> activeFlag_; ///< FlipPass: faces with a free corner
  std::vector<std::pair<Point, Point>> ring_;
  std::vector<int> valence_;
  std::vector<std::uint8_t> boundary_;
  std::vector<std::pair<FacePointer, int>> star_;
};

template <class MeshType>
double AdaptiveRemeshing<MeshType>::RestoreVolume(Ops& ops, double maxOffset, double tolerance, int threads) {
  MeshType& m = ops.Mesh();
  const Reference& reference = ops.GetReference();
  // Components of the mesh through shared edges, each with the reference component it lies on.
  std::vector<int> component(m.face.size(), -1);
  std::vector<int> refComponent;
  std::vector<char> closed;
  std::vector<std::size_t> stack;
  for (std::size_t seed = 0; seed < m.face.size(); ++seed) {
    if (m.face[seed].IsD() || component[seed] >= 0) continue;
    const int c = int(refComponent.size());
    const int foot = ops.Footpoint(*m.face[seed].cV(0));
    refComponent.push_back(foot >= 0 ? reference.Component(foot) : -1);
    closed.push_back(1);
    component[seed] = c;
    stack.assign(1, seed);
    while (!stack.empty()) {
      const FaceType& f = m.face[stack.back()];
      stack.pop_back();
      for (int e = 0; e < 3; ++e) {
        const FaceType* g = f.cFFp(e);
        if (g == &f) {
          closed[std::size_t(c)] = 0;
          continue;
        }
        const std::size_t gi = vcg::tri::Index(m, g);
        if (component[gi] < 0) {
          component[gi] = c;
          stack.push_back(gi);
        }
      }
    }
  }
  const std::size_t nc = refComponent.size();
  const Point origin = reference.BoundingBox().Center();
  std::vector<double> volume(nc), area(nc), delta(nc, 0.0);
  std::vector<Point> normal(m.vert.size());
  std::vector<int> vertexComponent(m.vert.size(), -1);
  std::vector<std::uint32_t> vertices;
  std::vector<Point> targets;
  std::vector<int> feet;
  double largest = 0;
  for (int pass = 0; pass < 2; ++pass) {
    std::fill(volume.begin(), volume.end(), 0.0);
    std::fill(area.begin(), area.end(), 0.0);
    std::fill(normal.begin(), normal.end(), Point(0, 0, 0));
    for (std::size_t fi = 0; fi < m.face.size(); ++fi) {
      const FaceType& f = m.face[fi];
      if (f.IsD()) continue;
      const Point p0 = PositionOf(f.cV(0)) - origin, p1 = PositionOf(f.cV(1)) - origin,
                  p2 = PositionOf(f.cV(2)) - origin;
      const Point cross = (p1 - p0) ^ (p2 - p0);
      const std::size_t c = std::size_t(component[fi]);
      volume[c] += (p0 * (p1 ^ p2)) / 6.0;
      area[c] += 0.5 * cross.Norm();
      for (int k = 0; k < 3; ++k) {
        const std::size_t vi = vcg::tri::Index(m, f.cV(k));
        normal[vi] += cross;
        vertexComponent[vi] = int(c);
      }
    }
    bool any = false;
    for (std::size_t c = 0; c < nc; ++c) {
      const int rc = refComponent[c];
      const bool usable = closed[c] && rc >= 0 && reference.ComponentClosed(rc) && area[c] > 0;
      const double target = usable ? reference.ComponentVolume(rc) : 0.0;
      const bool off = usable && std::fabs(target - volume[c]) > tolerance * std::fabs(target);
      const double wanted = off ? (target - volume[c]) / area[c] : 0.0;
      delta[c] = wanted;
      any = any || delta[c] != 0;
    }
    if (!any) break;
    vertices.clear();
    for (std::size_t vi = 0; vi < m.vert.size(); ++vi) {
      const VertexType& v = m.vert[vi];
      if (v.IsD() || v.cVFp() == nullptr || vertexComponent[vi] < 0 || ops.IsLocked(v)) continue;
      if (delta[std::size_t(vertexComponent[vi])] == 0 || !(normal[vi].Norm() > 0)) continue;
      vertices.push_back(std::uint32_t(vi));
    }
    // The offset is measured from the reference (vertices may already be off it, e.g. by the
    // CVT stage's own volume restoration), so no vertex ends farther than maxOffset from it.
    targets.resize(vertices.size());
    feet.resize(vertices.size());
    std::vector<double> reached(vertices.size(), 0.0);
    std::vector<typename Reference::Scratch> scratch(std::size_t(ResolveThreadCount(threads)));
    ParallelFor(vertices.size(), threads, [&](std::size_t begin, std::size_t end, int t) {
      for (std::size_t i = begin; i < end; ++i) {
        const VertexType& v = m.vert[vertices[i]];
        const Point n = normal[vertices[i]] / normal[vertices[i]].Norm();
        const Point p = PositionOf(&v);
        const SurfaceProjection proj = reference.Project(p, ops.Footpoint(v), scratch[std::size_t(t)]);
        const double now = proj.ok() ? (p - proj.point) * n : 0.0;
        const double want =
            std::clamp(now + delta[std::size_t(vertexComponent[vertices[i]])], -maxOffset, maxOffset);
        targets[i] = p + n * (want - now);
        feet[i] = proj.ok() ? proj.face : ops.Footpoint(v);
        reached[i] = std::fabs(want);
      }
    });
    for (const double r : reached) largest = std::max(largest, r);
    ops.MoveVerticesJacobi(vertices, targets, feet, threads);
  }
  return largest;
}

template <class MeshType>
AdaptiveRemeshingStats AdaptiveRemeshing<MeshType>::Finalize(Ops& ops, std::vector<double>& sizing,
                                                             const Params& params, int threads) {
  MeshType& m = ops.Mesh();
  for (std::size_t i = 0; i < m.vert.size(); ++i) ops.SetLocked(m.vert[i], false);
  const double L0 = ops.TargetEdgeLength();
  std::vector<std::uint8_t> snapped(m.vert.size(), 0);
  const std::size_t snaps = SnapToInputVertices(ops, params, threads, snapped);
  double offset = 0;
  if (params.preserveVolume)
    offset = RestoreVolume(ops, params.maxVolumeOffset * L0, params.volumeTolerance, threads);
  // The snapped vertices stay during the repair (it would move them off the tips again).
  for (std::size_t i = 0; i < snapped.size() && i < m.vert.size(); ++i)
    if (snapped[i]) ops.SetLocked(m.vert[i], true);
  AdaptiveRemeshingStats stats = Remesh(ops, sizing, params, 0, threads);
  // Fidelity yields to the angle bound: a snapped vertex of a triangle the repair left with an
  // angle below the guard is released, and the repair runs once more.
  bool released = false;
  std::vector<std::array<double, 2>> angles;
  FaceAngleRanges(m, threads, angles); // deleted faces get {180, 0}: never below the guard
  for (std::size_t fi = 0; fi < m.face.size(); ++fi) {
    if (angles[fi][0] >= params.guards.minAngleDeg) continue;
    for (int k = 0; k < 3; ++k)
      if (ops.IsLocked(*m.face[fi].V(k))) {
        ops.SetLocked(*m.face[fi].V(k), false);
        released = true;
      }
  }
  if (released) stats.Add(Remesh(ops, sizing, params, 0, threads));
  for (std::size_t i = 0; i < m.vert.size(); ++i) ops.SetLocked(m.vert[i], false);
  stats.volumeOffset = offset / L0;
  stats.snapMoves = snaps;
  return stats;
}

template <class MeshType>
double AdaptiveRemeshing<MeshType>::SnapStarDistance(const LocalOpsGuards& snapGuards, VertexPointer v,
                                                     const Point& q, const Point& p) {
  double best2 = std::numeric_limits<double>::infinity();
  for (vcg::face::VFIterator<FaceType> it(v); !it.End(); ++it) {
    std::array<Point, 3> corner;
    for (int k = 0; k < 3; ++k) corner[k] = it.F()->V(k) == v ? q : PositionOf(it.F()->cV(k));
    double smallest = 0, largest = 0;
    TriangleAngleRange(corner[0], corner[1], corner[2], smallest, largest);
    if (!InSnapRange(snapGuards, smallest, largest)) return std::numeric_limits<double>::infinity();
    Point closest;
    best2 = std::min(best2, distance_detail::TriangleDistance2(p, corner[0], corner[1], corner[2], closest));
  }
  return std::sqrt(best2);
}

template <class MeshType>
bool AdaptiveRemeshing<MeshType>::SnapCalmAround(const LocalOpsGuards& snapGuards, VertexPointer v) {
  const auto calm = [&](VertexPointer u) {
    for (vcg::face::VFIterator<FaceType> it(u); !it.End(); ++it) {
      double smallest = 0, largest = 0;
      FaceAngleRange(*it.F(), smallest, largest);
      if (!InSnapRange(snapGuards, smallest, largest)) return false;
    }
    return true;
  };
  for (vcg::face::VFIterator<FaceType> it(v); !it.End(); ++it)
    if (!calm(it.F()->V1(it.I()))) return false;
  return calm(v);
}

template <class MeshType>
void AdaptiveRemeshing<MeshType>::CollectSnapTriangles(MeshType& m, std::vector<std::array<Index, 3>>& tris,
                                                       std::vector<std::size_t>& faceOf) {
  tris.reserve(m.face.size());
  faceOf.reserve(m.face.size());
  for (std::size_t fi = 0; fi < m.face.size(); ++fi) {
    const FaceType& f = m.face[fi];
    if (f.IsD()) continue;
    tris.push_back({Index(vcg::tri::Index(m, f.cV(0))), Index(vcg::tri::Index(m, f.cV(1))),
                    Index(vcg::tri::Index(m, f.cV(2)))});
    faceOf.push_back(fi);
  }
}

template <class MeshType>
void AdaptiveRemeshing<MeshType>::MeasureInputDistances(const MeshType& m, const Reference& ref,
                                                        const std::vector<std::array<Index, 3>>& tris,
                                                        const std::vector<std::uint32_t>& measure,
                                                        int threads, std::vector<double>& distance,
                                                        std::vector<long long>& hitFace) {
  using distance_detail::TriangleGrid;
  std::vector<Point> points(m.vert.size());
  for (std::size_t i = 0; i < m.vert.size(); ++i) points[i] = PositionOf(&m.vert[i]);
  TriangleGrid grid;
  grid.Build(std::move(points), tris, threads);
  std::vector<TriangleGrid::QueryScratch> scratch(static_cast<std::size_t>(threads));
  ParallelFor(measure.size(), threads, [&](std::size_t begin, std::size_t end, int t) {
    for (std::size_t k = begin; k < end; ++k) {
      const std::uint32_t i = measure[k];
      const TriangleGrid::Hit hit = grid.Closest(ref.Vertex(i), scratch[std::size_t(t)]);
      distance[i] = hit.distance;
      hitFace[i] = hit.face;
    }
  });
}

template <class MeshType>
std::size_t AdaptiveRemeshing<MeshType>::SnapToInputVertices(Ops& ops, const Params& params, int threads,
                                                             std::vector<std::uint8_t>& snapped) {
  MeshType& m = ops.Mesh();
  const Reference& ref = ops.GetReference();
  const double L0 = ops.TargetEdgeLength();
  const SnapLimits limits{L0, params.snapTolerance * L0, params.snapMaxMove * L0,
                          params.snapLooseTolerance * L0};
  const double tolerance = limits.tolerance;
  snapped.resize(m.vert.size(), 0);
  if (!(tolerance > 0) || params.snapRounds <= 0 || ref.VertexCount() == 0) return 0;
  threads = ResolveThreadCount(threads);
  ops.VerifyPendingMoves(threads);
  const LocalOpsGuards saved = ops.Guards();
  ops.SetGuards(params.snapGuards);
  std::size_t moves = 0;
  std::vector<double> distance(ref.VertexCount());
  std::vector<long long> hitFace(ref.VertexCount());
  const std::vector<double> kFullFraction{1.0},
      kPartialFractions{0.75, 0.5}; // of the way to the input vertex
  bool partialPhase = false;        // after the full snaps stop: part of the way
  // Reference vertices whose distance is measured (anew) in a round: all of them in the first,
  // later those SelectSnapMeasurements picks.
  std::vector<std::uint32_t> measure(ref.VertexCount());
  std::iota(measure.begin(), measure.end(), std::uint32_t(0));
  // The mesh's triangles, the same every round (the rounds only move vertices), so a hit face
  // of one round names the same face in the next.
  std::vector<std::array<Index, 3>> tris;
  std::vector<std::size_t> faceOf, movedLastRound;
  CollectSnapTriangles(m, tris, faceOf);
  for (int round = 0; round < params.snapRounds + 1 && !tris.empty(); ++round) {
    if (round > 0) {
      SelectSnapMeasurements(m, movedLastRound, distance, hitFace, faceOf, tolerance, measure);
      movedLastRound.clear();
    }
    MeasureInputDistances(m, ref, tris, measure, threads, distance, hitFace);
    const std::vector<std::pair<double, std::uint32_t>> far =
        FarInputVertices(distance, hitFace, tolerance, partialPhase, params.snapPartialShare);
    std::size_t roundMoves = 0;
    for (const auto& [negative, i] : far)
      if (SnapInputVertex(ops, params, limits, partialPhase ? kPartialFractions : kFullFraction, i, -negative,
                          faceOf[std::size_t(hitFace[i])], snapped, movedLastRound))
        ++roundMoves;
    moves += roundMoves;
    // One partial round once the full snaps stall (under 1 % of the far points moved) or the
    // rounds are spent.
    if (partialPhase) break;
    if (roundMoves * 100 < far.size() || round + 1 == params.snapRounds) partialPhase = true;
  }
  ops.SetGuards(saved);
  return moves;
}

template <class MeshType>
void AdaptiveRemeshing<MeshType>::SelectSnapMeasurements(
    MeshType& m, const std::vector<std::size_t>& movedLastRound, const std::vector<double>& distance,
    const std::vector<long long>& hitFace, const std::vector<std::size_t>& faceOf, double tolerance,
    std::vector<std::uint32_t>& measure) {
  std::vector<std::uint8_t> touched(m.face.size(), 0);
  for (const std::size_t vi : movedLastRound)
    for (vcg::face::VFIterator<FaceType> it(&m.vert[vi]); !it.End(); ++it)
      touched[std::size_t(vcg::tri::Index(m, it.F()))] = 1;
  measure.clear();
  for (std::size_t i = 0; i < distance.size(); ++i)
    if (distance[i] > tolerance || hitFace[i] < 0 || touched[faceOf[std::size_t(hitFace[i])]])
      measure.push_back(std::uint32_t(i));
}

template <class MeshType>
std::vector<std::pair<double, std::uint32_t>>
AdaptiveRemeshing<MeshType>::FarInputVertices(const std::vector<double>& distance,
                                              const std::vector<long long>& hitFace, double tolerance,
                                              bool partialPhase, double partialShare) {
  std::vector<std::pair<double, std::uint32_t>> far;
  for (std::size_t i = 0; i < distance.size(); ++i)
    if (distance[i] > tolerance && hitFace[i] >= 0) far.emplace_back(-distance[i], std::uint32_t(i));
  std::sort(far.begin(), far.end());
  // The partial moves are a compromise worth making only where the largest distances are.
  if (partialPhase && !far.empty()) {
    const double keep = -far.front().first * partialShare;
    while (!far.empty() && -far.back().first < keep) far.pop_back();
  }
  return far;
}

template <class MeshType>
bool AdaptiveRemeshing<MeshType>::SnapInputVertex(Ops& ops, const Params& params, const SnapLimits& limits,
                                                  const std::vector<double>& fractions, std::uint32_t i,
                                                  double distanceBefore, std::size_t fi,
                                                  std::vector<std::uint8_t>& snapped,
                                                  std::vector<std::size_t>& movedLastRound) {
  MeshType& m = ops.Mesh();
  if (fi >= m.face.size() || m.face[fi].IsD()) return false;
  const Point p = ops.GetReference().Vertex(i);
  FaceType& f = m.face[fi];
  Point closest;
  const double now2 = distance_detail::TriangleDistance2(p, PositionOf(f.cV(0)), PositionOf(f.cV(1)),
                                                         PositionOf(f.cV(2)), closest);
  if (!(now2 > limits.tolerance * limits.tolerance)) return false; // an earlier move fixed it
  std::array<std::pair<double, int>, 3> order;
  for (int k = 0; k < 3; ++k) order[k] = {(PositionOf(f.cV(k)) - p).SquaredNorm(), k};
  std::sort(order.begin(), order.end());
  // Onto the input vertex first; where the angle guards refuse that on every corner, part of
  // the way (the cusp is then cut by a shorter chord), when that brings the star of the
  // corner clearly closer to the input vertex. The partial round does not retry the full snaps
  // the rounds before it refused.
  for (const double fraction : fractions) {
    for (const auto& [d2, k] : order) {
      VertexPointer v = f.V(k);
      const std::size_t vi = std::size_t(vcg::tri::Index(m, v));
      if (vi < snapped.size() && snapped[vi]) continue;
      if (d2 > limits.maxMove * limits.maxMove || ops.IsLocked(*v) || ops.IsBoundaryVertex(*v)) continue;
      if (!TrySnapMove(ops, params, limits, v, i, p, fraction, distanceBefore, now2)) continue;
      if (vi >= snapped.size()) snapped.resize(vi + 1, 0);
      snapped[vi] = 1;
      movedLastRound.push_back(vi);
      return true;
    }
  }
  return false;
}

template <class MeshType>
bool AdaptiveRemeshing<MeshType>::TrySnapMove(Ops& ops, const Params& params, const SnapLimits& limits,
                                              VertexPointer v, std::uint32_t i, const Point& p,
                                              double fraction, double distanceBefore, double now2) {
  const Reference& ref = ops.GetReference();
  const LocalOpsGuards& snapGuards = params.snapGuards;
  if (fraction == 1.0) {
    bool okMove = ops.MoveVertexTo(v, p, ref.VertexFace(i));
    if (!okMove && distanceBefore > limits.looseTolerance) {
      ops.SetGuards(params.snapLooseGuards);
      okMove = ops.MoveVertexTo(v, p, ref.VertexFace(i));
      ops.SetGuards(snapGuards);
    }
    return okMove;
  }
  constexpr double partialGain = 0.8; // a partial move must cut the distance by 20 % at least
  if (!SnapCalmAround(snapGuards, v)) return false;
  const Point start = PositionOf(v);
  const SurfaceProjection target = ref.Project(start + (p - start) * fraction, ops.Footpoint(*v));
  const double reached = target.ok() ? SnapStarDistance(snapGuards, v, target.point, p)
                                     : std::numeric_limits<double>::infinity();
  if (!(reached < partialGain * std::sqrt(now2))) return false;
  // Not at the expense of another input point: none may end farther than p now is.
  LocalOpsGuards partialGuards = snapGuards;
  partialGuards.maxInputDistanceFactor = std::max(reached, limits.tolerance) / limits.L0;
  // Input points farther than L0 / 2 from the moved faces are held by other faces.
  partialGuards.inputReachFactor = 0.5;
  ops.SetGuards(partialGuards);
  const bool okMove = ops.MoveVertexTo(v, target.point, target.face);
  ops.SetGuards(snapGuards);
  return okMove;
}

template <class MeshType>
AdaptiveRemeshingStats AdaptiveRemeshing<MeshType>::Remesh(Ops& ops, std::vector<double>& sizing,
                                                           const Params& params, int iterations, int threads,
                                                           const PositionFilter& allowed) {
  Session session(ops, sizing, params, threads, allowed);
  return session.Run(iterations);
}

template <class MeshType>
typename AdaptiveRemeshing<MeshType>::Result
AdaptiveRemeshing<MeshType>::Do(MeshType& m, const Params& params, vcg::CallBackPos* cb) {
  Result result;
  const InputCheck check = CheckTriangleMeshInput(m);
  if (!check.ok) {
    result.message = "adaptive remeshing refused: " + check.message;
    return result;
  }
  Reference reference;
  std::string error;
  if (!reference.Build(m, typename Reference::Params(), &error)) {
    result.message = "adaptive remeshing refused: " + error;
    return result;
  }
  return Do(m, reference, params, cb);
}

template <class MeshType>
typename AdaptiveRemeshing<MeshType>::Result
AdaptiveRemeshing<MeshType>::Do(MeshType& m, const Reference& reference, const Params& params,
                                vcg::CallBackPos* cb) {
  Result result;
  auto finish = [&](bool ok, const std::string& message) {
    result.ok = ok;
    result.message = message;
    return result;
  };
  const InputCheck check = CheckTriangleMeshInput(m);
  if (!check.ok) return finish(false, "adaptive remeshing refused: " + check.message);
  if (!vcg::tri::HasFFAdjacency(m) || !vcg::tri::HasVFAdjacency(m))
    return finish(false, "adaptive remeshing refused: face-face and vertex-face adjacency must be enabled");
  if (params.iterations < 0) return finish(false, "adaptive remeshing refused: negative iteration count");
  if (!(params.minLengthFactor > 0) || params.maxLengthFactor < params.minLengthFactor)
    return finish(false, "adaptive remeshing refused: need 0 < minLengthFactor <= maxLengthFactor");
  if (!(params.collapseFactor < params.splitFactor))
    return finish(false, "adaptive remeshing refused: collapseFactor must be below splitFactor");
  typename MeshQuality<MeshType>::Params qp;
  qp.computeSelfIntersections = false;
  qp.threads = params.threads;
  const QualityReport input = MeshQuality<MeshType>::Compute(m, qp);
  const double L0 = params.targetEdgeLength > 0 ? params.targetEdgeLength : input.meanEdgeLength;
  if (!(L0 > 0) || !std::isfinite(L0))
    return finish(false, "adaptive remeshing refused: no valid target edge length");
  result.targetEdgeLength = L0;
  result.verticesIn = std::size_t(m.vn);
  result.facesIn = std::size_t(m.fn);

  Ops ops(m, reference, L0, params.guards, params.threads);
  std::string error;
  if (!ops.Init(&error)) return finish(false, "adaptive remeshing refused: " + error);
  if (cb) cb(5, "RAR: sizing field");
  std::vector<double> sizing = ComputeSizing(m, L0, params, params.threads);
  {
    double lo = std::numeric_limits<double>::infinity(), hi = 0, sum = 0;
    std::size_t n = 0;
    for (std::size_t i = 0; i < m.vert.size(); ++i) {
      if (m.vert[i].IsD() || m.vert[i].cVFp() == nullptr) continue;
      lo = std::min(lo, sizing[i]);
      hi = std::max(hi, sizing[i]);
      sum += sizing[i];
      ++n;
    }
    result.minSizing = n ? lo : 0;
    result.maxSizing = hi;
    result.meanSizing = n ? sum / double(n) : 0;
  }
  if (cb) cb(10, "RAR: remeshing");
  result.stats = Remesh(ops, sizing, params, params.iterations, params.threads);
  result.stats.Add(Finalize(ops, sizing, params, params.threads));
  result.operations = ops.Stats();
  ops.Finish();
  result.verticesOut = std::size_t(m.vn);
  result.facesOut = std::size_t(m.fn);
  if (cb) cb(100, "RAR: done");
  return finish(true, "adaptive remeshing: " + std::to_string(result.verticesIn) + " -> " +
                          std::to_string(result.verticesOut) + " vertices, " +
                          std::to_string(result.stats.iterations) + " iterations");
}

} // namespace molremesh

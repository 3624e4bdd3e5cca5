// Guarded, transactional local edits of a triangle mesh that lies on a ReferenceSurface.
//
// LocalRemeshingOps<MeshType> is the toolbox every remeshing stage edits through: edge split,
// edge collapse, edge flip and vertex relocation. Each operation first builds the faces it
// would produce, checks all of them, and only then changes the mesh; a refused operation leaves
// the mesh bit-identical (no rollback needed). The checks:
//  - topology: link condition for collapses (the common neighbours of the two end points are
//    exactly the vertices opposite the edge; no ear, no valence below 3), the new edge of a flip
//    must not exist, locked vertices are never moved or removed;
//  - no degenerate face (area below Guards::minAreaFactor * L^2);
//  - angle guard: the smallest angle of the new faces must be >= Guards::minAngleDeg unless it
//    is larger than the smallest angle of the faces they replace (so bad regions may improve);
//    the same for the largest angle with Guards::maxAngleDeg;
//  - orientation: every new face's normal must be within Guards::maxNormalDeviationDeg of the
//    reference normal at its corners' footpoints, and adjacent faces in and around the edited
//    region must not fold onto each other (angle between normals <= Guards::maxFoldAngleDeg),
//    in both cases unless no worse than before;
//  - no new intersection: the new faces are tested against every face whose bounding box they
//    touch (dynamic FaceHashGrid) and against each other, with the exact same closed-triangle
//    predicates MeshQuality uses to count self-intersections: faces sharing no vertex must not
//    meet, faces sharing one vertex must not meet anywhere else;
//  - optionally, fidelity to the input (Guards::maxInputDistanceFactor): the input points near
//    the region (reference vertices, face centroids and the points halfway between centroid
//    and corners) must stay within that distance of the mesh, or no farther than before. The
//    distance after the edit is exact: to the new faces, then to the unchanged faces around
//    them (intersection grid), so a point held by another part of the mesh is never a reason
//    to refuse. Off by default; it costs a scan of the input around the region per edit.
// Vertices created or moved are placed on the reference surface with ReferenceSurface::Project
// from their previous footpoint (per-vertex footpoint faces are kept here), so they never jump
// across a narrow gap.
//
// Smoothing moves many vertices at once: MoveVerticesJacobi (or MoveVertexUnchecked followed by
// VerifyPendingMoves, to verify every few steps only) applies all moves, verifies every changed
// face in parallel with the same guards, face by face, and puts the vertices of failing faces
// back to their last verified position until nothing fails; intersecting pairs are found by one
// cache-friendly sweep over all faces (TrianglePairScan) when most faces changed.
//
// Locking: a per-vertex lock kept by this object (SetLocked/IsLocked, indexed by vertex index;
// no vcg flag is used). A locked vertex is never moved or removed; an edge whose two end points
// are locked is never split, collapsed or flipped, and no flip creates an edge between two
// locked vertices. Boundary vertices (on a border edge) are never relocated; a boundary vertex
// is only removed by collapsing a border edge.
//
// Preconditions (checked by Init): a 2-manifold, consistently oriented mesh with per-face FF and
// per-vertex/per-face VF adjacency available (Init recomputes both), no face with a repeated
// vertex. Element pointers stay valid across operations except when a split needs more room;
// indices are stable until Finish(), which compacts the mesh. Deleted elements are recycled.
#pragma once

#include <vcg/complex/complex.h>

#include <vcg_ext/topology/face_face_topology.h>
#include <vcg_ext/spatial/face_hash_grid.h>
#include <vcg_ext/geometry/triangle_intersection.h>
#include <vcg_ext/quality/mesh_quality.h>
#include <vcg_ext/core/parallel_for.h>
#include <vcg_ext/surface/reference_surface.h>
#include <vcg_ext/spatial/triangle_pair_scan.h>

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

/// Why an operation was refused. Counted per reason in LocalOpsStats::refused.
enum class OpRefusal : int {
  None = 0,
  Locked,        ///< touches a locked vertex or edge
  Boundary,      ///< boundary vertex relocation, boundary edge flip, boundary vertex removal off the border
  Topology,      ///< link condition, ear, valence, existing edge
  Degenerate,    ///< a new face would have (nearly) zero area
  MinAngle,      ///< angle guard (smallest angle)
  MaxAngle,      ///< angle guard (largest angle)
  Normal,        ///< a new face deviates from the reference normal
  Fold,          ///< two adjacent faces would fold onto each other
  EdgeLength,    ///< a collapse would create an edge longer than allowed
  Intersection,  ///< a new face would intersect another face
  InputDistance, ///< an input point near the region would end too far from the mesh
  Count
};

/// Thresholds of the checks every operation runs (see the file comment for their meaning).
struct LocalOpsGuards {
  double minAngleDeg = 10.0;  ///< new angles below it only if the region's smallest angle improves
  double maxAngleDeg = 180.0; ///< new angles above it only if the region's largest angle improves (180 = off)
  double maxNormalDeviationDeg = 75.0; ///< new face normal vs reference normal at its corners
  double maxFoldAngleDeg = 120.0;      ///< angle between the normals of two adjacent faces
  double minAreaFactor = 1e-8;         ///< faces with area below factor * L^2 are never created
  bool checkIntersections = true;      ///< refuse edits that would create an intersecting pair
  /// Also refuse edits that leave more faces with an angle below minAngleDeg (above
  /// maxAngleDeg) than the faces they replace had: an improving edit may then not spread a bad
  /// angle over more faces. For stages that promise "no new angle below the guard".
  bool noMoreBadFaces = false;
  double gridCellFactor = 1.0; ///< intersection grid cell size, in target edge lengths
  /// Fidelity to the input (0 = off): an edit may not leave a point of the input near the edited
  /// region (a reference vertex or face centroid within inputReachFactor x L of it) farther than
  /// this x L from the mesh, unless the point was at least as far before. Chords of collapses and
  /// refills otherwise cut off the input's spikes and cusps, which sets the Hausdorff distance.
  double maxInputDistanceFactor = 0.0;
  double inputReachFactor = 1.5; ///< how far around the region input points are examined, x L
};

namespace local_ops_detail {

using Point = vcg::Point3d;

/// True when every corner of q but `skip` (-1: none) lies strictly on one side of the plane
/// through `origin` with unit normal n, farther than margin.
inline bool SeparatedByPlane(const Point& n, const Point& origin, const std::array<Point, 3>& q, int skip,
                             double margin) {
  if (!(n.SquaredNorm() > 0)) return false;
  int sign = 0;
  for (int k = 0; k < 3; ++k) {
    if (k == skip) continue;
    const double d = n * (q[k] - origin);
    const int s = d > margin ? 1 : d < -margin ? -1 : 0;
    if (s == 0 || (sign != 0 && s != sign)) return false;
    sign = s;
  }
  return true;
}

/// Whether two faces meet the way MeshQuality counts a self-intersection: faces sharing no
/// vertex meet at all, faces sharing one vertex meet anywhere else; faces sharing an edge are
/// never reported (folds are a separate check). A separating-plane test with a margin far
/// above rounding noise settles almost every pair before the exact predicates run; it only
/// answers "apart" when MeshQuality's predicates would too. (Faces sharing one vertex whose
/// star is a simple fan never meet, see StarIsSimpleFan: the batch sweep skips them.)
template <class VertexPointer>
bool FacesIntersect(const std::array<Point, 3>& a, const Point& na, const std::array<VertexPointer, 3>& va,
                    const std::array<Point, 3>& b, const Point& nb, const std::array<VertexPointer, 3>& vb,
                    double margin) {
  int shared = 0, ca = -1, cb = -1;
  for (int x = 0; x < 3; ++x)
    for (int y = 0; y < 3; ++y)
      if (va[x] == vb[y]) ++shared, ca = x, cb = y;
  if (shared >= 2) return false;
  if (shared == 0) {
    if (SeparatedByPlane(na, a[0], b, -1, margin) || SeparatedByPlane(nb, b[0], a, -1, margin)) return false;
    return TrianglesIntersect(MakePlanarTriangle(a[0], a[1], a[2]),
                                              MakePlanarTriangle(b[0], b[1], b[2]));
  }
  if (SeparatedByPlane(na, a[ca], b, cb, margin) || SeparatedByPlane(nb, b[cb], a, ca, margin)) return false;
  return SharedCornerOverlap(MakePlanarTriangle(a[0], a[1], a[2]), ca,
                                             MakePlanarTriangle(b[0], b[1], b[2]), cb);
}

/// Whether the star of a vertex at `center`, given as its link edges (a_i, b_i) in the faces'
/// orientation, projects along its mean normal onto a simple fan: every face positively
/// oriented (with margin) and the angles at the center summing to exactly one turn (less than
/// one on the boundary). Then two faces of the star that share only the center meet nowhere
/// else: their projections lie in disjoint wedges, and a common point would project onto the
/// center, which only the center itself does (no face is parallel to the projection direction).
inline bool StarIsSimpleFan(const Point& center, const std::pair<Point, Point>* link, int count,
                            bool boundary) {
  if (count < 1) return false;
  Point d(0, 0, 0);
  for (int i = 0; i < count; ++i) d += (link[i].first - center) ^ (link[i].second - center);
  const double len = d.Norm();
  if (!(len > 0)) return false;
  d /= len;
  // Every wedge positively oriented. Around an interior vertex the link is a closed cycle, so
  // the wedge angles then sum to 2 pi k (k turns); k = 1 is certain when an upper bound of the
  // sum, pi sqrt((1 - cos)/2) >= the angle per wedge, stays below 4 pi, which spares the atan2
  // of every wedge in all but the strangest stars.
  double halfTurnsBound = 0;
  for (int i = 0; i < count; ++i) {
    const Point u = link[i].first - center, v = link[i].second - center;
    // Components orthogonal to d.
    const Point pu = u - d * (u * d), pv = v - d * (v * d);
    const double cross = (pu ^ pv) * d, norms = pu.Norm() * pv.Norm();
    if (!(cross > 1e-6 * norms)) return false; // positively oriented, not flat
    halfTurnsBound += std::sqrt(std::max(0.0, 0.5 * (1.0 - (pu * pv) / norms)));
  }
  if (!boundary && halfTurnsBound < 4.0) return true;
  double turn = 0;
  for (int i = 0; i < count; ++i) {
    const Point u = link[i].first - center, v = link[i].second - center;
    const Point pu = u - d * (u * d), pv = v - d * (v * d);
    turn += std::atan2((pu ^ pv) * d, pu * pv);
  }
  const double twoPi = 2.0 * 3.14159265358979323846;
  return boundary ? turn < twoPi - 1e-6 : std::fabs(turn - twoPi) < 1e-6;
}

inline Point UnitNormal(const std::array<Point, 3>& p) {
  const Point n = (p[1] - p[0]) ^ (p[2] - p[0]);
  const double len = n.Norm();
  return len > 0 ? n / len : Point(0, 0, 0);
}

} // namespace local_ops_detail

/// Outcome of LocalRemeshingOps::MoveVerticesJacobi.
struct BatchMoveResult {
  std::size_t applied = 0;  ///< vertices now at their target
  std::size_t rejected = 0; ///< vertices left where they were (refused or reverted)
  int rounds = 0;           ///< verification rounds
};

/// What the operations did since the object was created (or ResetStats).
struct LocalOpsStats {
  std::size_t splits = 0, collapses = 0, flips = 0, moves = 0, replacements = 0;
  std::array<std::size_t, std::size_t(OpRefusal::Count)> refused{}; ///< by OpRefusal
  std::size_t Refused() const {
    std::size_t n = 0;
    for (std::size_t r : refused) n += r;
    return n;
  }
};

template <class MeshType>
class LocalRemeshingOps {
public:
  using VertexType = typename MeshType::VertexType;
  using FaceType = typename MeshType::FaceType;
  using VertexPointer = typename MeshType::VertexPointer;
  using FacePointer = typename MeshType::FacePointer;
  using CoordType = typename MeshType::CoordType;
  using ScalarType = typename MeshType::ScalarType;
  using Point = vcg::Point3d;
  using Reference = ReferenceSurface<MeshType>;

  /// m and reference must outlive this object. targetEdgeLength (L) scales the tolerances and
  /// the intersection grid. threads: for Init's footpoint search and the batch verification
  /// (0 = all cores; results never depend on it).
  LocalRemeshingOps(MeshType& m, const Reference& reference, double targetEdgeLength,
                    const LocalOpsGuards& guards = LocalOpsGuards(), int threads = 0)
      : m_(m), ref_(reference), L_(targetEdgeLength), guards_(guards), threads_(threads) {}

  /// Checks the preconditions, (re)computes FF and VF adjacency, finds each vertex's footpoint on
  /// the reference and fills the intersection grid. meshIsReference: the reference was (probably)
  /// built from this very mesh, so each vertex's footpoint is tried as the reference copy of one
  /// of its own faces, kept when that face's corner is exactly the vertex; the other vertices
  /// get a global closest-point search. Returns false (mesh
  /// untouched except for the adjacency) with a message when a precondition fails.
  /// lazyFootpoints: find no footpoint now; the caller calls EnsureFootpoint on every vertex of
  /// the faces an operation will touch before it (for stages that edit only a few places of a
  /// large mesh, where the global search for every vertex would cost more than the edits).
  /// globalFeet (indexed like m.vert): for each vertex, what the global search
  /// (ReferenceSurface::ProjectGlobal) returns for its current position, found by the caller for
  /// several meshes sharing vertices (the patches and their halos); -1 = search here.
  bool Init(std::string* error = nullptr, bool meshIsReference = false, bool topologyReady = false,
            bool lazyFootpoints = false, const std::vector<int>* globalFeet = nullptr);
  /// Finds v's footpoint if Init(lazyFootpoints) left it unknown (no-op otherwise).
  void EnsureFootpoint(const VertexType& v) {
    int& foot = foot_[VIndex(v)];
    if (foot == kUnknownFoot) foot = ref_.ProjectGlobal(Pos(&v)).face;
  }
  /// EnsureFootpoint on every vertex within `rings` rings of v (rings = 2 covers every vertex a
  /// split, collapse, flip or move of an edge or face at v, or a disk of stars around it, touches).
  void EnsureFootpointsAround(const VertexType& v, int rings = 2) {
    EnsureFootpoint(v);
    if (rings <= 0 || v.cVFp() == nullptr) return;
    for (vcg::face::VFIterator<FaceType> it(const_cast<VertexType*>(&v)); !it.End(); ++it)
      for (int k = 1; k < 3; ++k) EnsureFootpointsAround(*it.F()->V((it.I() + k) % 3), rings - 1);
  }
  /// EnsureFootpointsAround each corner of f.
  void EnsureFootpointsAround(const FaceType& f, int rings = 2) {
    for (int k = 0; k < 3; ++k) EnsureFootpointsAround(*f.cV(k), rings);
  }

  /// The topology part of Init, usable on its own before anything costly is built: recomputes
  /// FF and VF adjacency and checks that m is a 2-manifold, consistently oriented mesh without
  /// faces with a repeated vertex. Returns false with a message otherwise (only the adjacency
  /// has changed then). Init runs it unless told topologyReady. The checks run on `threads` cores (0 = all).
  static bool PrepareTopology(MeshType& m, std::string* error = nullptr, int threads = 0);

  // --- Operations: each returns whether it was applied; a refused one changes nothing. -------

  /// Splits edge z of f at its midpoint projected onto the reference. Returns the new vertex or
  /// nullptr. May reallocate m.vert / m.face (growing them): element pointers held by the caller
  /// are then invalid (indices are not).
  VertexPointer SplitEdge(FacePointer f, int z);
  /// Collapses edge z of f. A free end point (not locked, not on the boundary unless the edge is
  /// a border edge) is removed; when both are free the survivor goes to the projected midpoint,
  /// otherwise it stays where it is. No edge of the result may be longer than maxNewEdgeLength.
  bool CollapseEdge(FacePointer f, int z, double maxNewEdgeLength = std::numeric_limits<double>::infinity());
  /// Flips interior edge z of f.
  bool FlipEdge(FacePointer f, int z);
  /// The boundary of a set of faces that forms a topological disk: `loop` gets its vertices in
  /// the faces' orientation (loop[i] -> loop[i+1] is an edge of a region face), `interior` the
  /// vertices all of whose faces are in the region. False (with Topology or Boundary as the last
  /// refusal) when the faces are not one disk with one simple boundary loop, or when the region
  /// reaches the mesh border.
  bool DiskBoundary(const std::vector<FacePointer>& region, std::vector<VertexPointer>& loop,
                    std::vector<VertexPointer>& interior);
  /// Replaces a disk of faces (see DiskBoundary; `loop` must be the loop it returns) by a new
  /// triangulation: `triangles` index loop vertices as 0..n-1 and new vertices as n..n+k-1,
  /// where the k new vertices are `newPoints` projected onto the reference (near the footpoint of
  /// the closest loop vertex). Triangles must be oriented like the loop and cover the disk once
  /// (each loop edge used once, each inner edge twice). The region's interior vertices are
  /// removed. Every guard of the other operations applies; refused = mesh unchanged. `created`
  /// receives the new vertices. May reallocate m.vert / m.face (pointers held by the caller are
  /// then invalid; indices are not).
  bool ReplaceDisk(const std::vector<FacePointer>& region, const std::vector<VertexPointer>& loop,
                   const std::vector<Point>& newPoints, const std::vector<std::array<int, 3>>& triangles,
                   std::vector<VertexPointer>* created = nullptr);
  /// Moves v toward target: target is projected onto the reference near v's footpoint.
  bool RelocateVertex(VertexPointer v, const Point& target);
  /// Moves v to a point already on the reference (footFace: the reference face holding it).
  bool MoveVertexTo(VertexPointer v, const Point& onSurface, int footFace);

  /// Moves many vertices at once, Jacobi style: vertices[i] goes to targets[i] (a point on the
  /// reference, in reference face feet[i]). Afterwards every vertex is either at its target or
  /// where it was, and every face touched passes the same guards as the single operations, face
  /// by face (angles and normal deviation no worse than the guard or than before, no fold, no
  /// new intersecting pair): all moves are applied, the changed faces are verified in parallel,
  /// the vertices of failing faces are put back and their neighbourhoods verified again until
  /// nothing fails. Deterministic for any thread count. Locked, boundary and unreferenced
  /// vertices are not moved (counted as rejected).
  BatchMoveResult MoveVerticesJacobi(const std::vector<std::uint32_t>& vertices,
                                     const std::vector<Point>& targets, const std::vector<int>& feet,
                                     int threads);

  /// Deferred form of MoveVerticesJacobi, for smoothing loops that verify every few steps:
  /// moves v to a point on the reference (in reference face footFace) without any check,
  /// remembering where it was at the last verified state. Refused (false, nothing changes) for
  /// locked, boundary and unreferenced vertices. Until VerifyPendingMoves runs the mesh may be
  /// invalid; every other operation (and Finish) verifies the pending moves first.
  bool MoveVertexUnchecked(VertexPointer v, const Point& onSurface, int footFace);
  /// Verifies all pending moves at once (see MoveVerticesJacobi): each moved vertex ends at its
  /// latest position or at its last verified one. threads <= 0: the constructor's count.
  BatchMoveResult VerifyPendingMoves(int threads = 0);
  bool HasPendingMoves() const { return !batch_.empty(); }

  /// Last refusal reason of any operation (None after a success).
  OpRefusal LastRefusal() const { return lastRefusal_; }

  // --- Queries --------------------------------------------------------------------------------

  /// Finds the edge between a and b: a face f and index z with {f.V(z), f.V1(z)} = {a, b}.
  bool FindEdge(VertexPointer a, VertexPointer b, FacePointer& f, int& z) const;
  bool IsBoundaryVertex(const VertexType& v) const;
  /// Number of edges at v (faces + 1 on the boundary); 0 for an unreferenced vertex.
  int Valence(const VertexType& v) const;
  /// True when edge z of f is locally Delaunay (the angles opposite it sum to <= 180 degrees).
  bool IsDelaunay(const FaceType& f, int z) const;
  /// Reduction of sum |valence - ideal| (ideal 6, 4 on the boundary) that flipping edge z of f
  /// would bring (positive = better). Border edges give 0.
  int FlipValenceGain(const FaceType& f, int z) const;

  int Footpoint(const VertexType& v) const { return foot_[VIndex(v)]; }
  void SetLocked(const VertexType& v, bool locked) { locked_[VIndex(v)] = locked ? 1 : 0; }
  bool IsLocked(const VertexType& v) const { return locked_[VIndex(v)] != 0; }

  double TargetEdgeLength() const { return L_; }
  void SetTargetEdgeLength(double L) { L_ = L; }
  const LocalOpsGuards& Guards() const { return guards_; }
  void SetGuards(const LocalOpsGuards& g) {
    guards_ = g;
    UpdateGuardCosines();
  }
  const Reference& GetReference() const { return ref_; }
  MeshType& Mesh() { return m_; }
  const LocalOpsStats& Stats() const { return stats_; }
  void ResetStats() { stats_ = LocalOpsStats(); }

  /// Removes the deleted elements from the mesh vectors (indices change: locks and footpoints
  /// are dropped) and updates per-face / per-vertex normals when the mesh has them. The object
  /// must be Init-ed again before further use.
  void Finish();

  /// Consistency of m's FF and VF adjacency with its faces (for tests and debugging): empty
  /// when every live face's FF links are mutual and match the edge, and every live vertex's VF
  /// list holds exactly its live faces; otherwise a description of the first problem.
  static std::string AdjacencyProblem(const MeshType& m);

  static Point ToPoint(const CoordType& c) { return Point(double(c[0]), double(c[1]), double(c[2])); }
  static CoordType ToCoord(const Point& p) {
    return CoordType(ScalarType(p[0]), ScalarType(p[1]), ScalarType(p[2]));
  }

private:
  /// A face an operation would produce, with its corners' new positions and footpoints.
  struct NewFace {
    std::array<VertexPointer, 3> v{};
    std::array<Point, 3> p;
    std::array<int, 3> foot{};
    std::array<FacePointer, 3> outside{}; ///< face across edge e (v[e], v[e+1]) outside the region, or null
    // Filled by CheckRegion:
    std::array<int, 3> internal{}; ///< new face across edge e, or -1
    Point n{0, 0, 0};              ///< unit normal
    vcg::Box3d box;
  };
  /// Worst values over a set of faces, as cosines (larger angle = smaller cosine).
  struct RegionMetrics {
    double cosMinAngle = -1; ///< cos of the smallest angle (max over faces)
    double cosMaxAngle = 1;  ///< cos of the largest angle (min over faces)
    double cosNormal = 1;    ///< cos of the largest deviation from the reference normal
    double cosFold = 1;      ///< cos of the largest angle between adjacent normals
    int smallFaces = 0;      ///< faces with an angle below Guards::minAngleDeg
    int largeFaces = 0;      ///< faces with an angle above Guards::maxAngleDeg
  };

  std::size_t VIndex(const VertexType& v) const { return std::size_t(&v - &m_.vert[0]); }
  std::size_t FIndex(const FaceType& f) const { return std::size_t(&f - &m_.face[0]); }
  Point Pos(const VertexType* v) const { return ToPoint(v->cP()); }
  static int IndexIn(const FaceType& f, const VertexType* v) {
    return f.cV(0) == v ? 0 : f.cV(1) == v ? 1 : f.cV(2) == v ? 2 : -1;
  }
  static bool IsBorder(const FaceType& f, int e) { return f.cFFp(e) == &f; }
  Point FaceNormal(const FaceType& f) const {
    const Point n = (Pos(f.cV(1)) - Pos(f.cV(0))) ^ (Pos(f.cV(2)) - Pos(f.cV(0)));
    const double len = n.Norm();
    return len > 0 ? n / len : Point(0, 0, 0);
  }
  vcg::Box3d FaceBox(const FaceType& f) const {
    vcg::Box3d b;
    for (int k = 0; k < 3; ++k) b.Add(Pos(f.cV(k)));
    return b;
  }
  Point RefNormalSum(const std::array<int, 3>& feet) const {
    Point s(0, 0, 0);
    for (int k = 0; k < 3; ++k)
      if (feet[k] >= 0) s += ref_.FaceNormal(feet[k]);
    return s;
  }

  void UpdateGuardCosines();
  void NewStamp();
  /// Star of v: (face, index of v in it) pairs, into `star`; returns whether v is on the boundary.
  bool GatherStar(const VertexType* v, std::vector<std::pair<FacePointer, int>>& star) const;
  /// Makes sure the free lists hold nv vertices and nf faces; f is updated if m.face moves.
  void EnsureFree(std::size_t nv, std::size_t nf, FacePointer& f);
  void GrowPerElementArrays();
  VertexPointer TakeFreeVertex();
  FacePointer TakeFreeFace();
  void Release(FaceType& f);
  void Release(VertexType& v);

  /// vcg::face::VFAppend, but also ending the face's link when the vertex's list was empty
  /// (vcg leaves the old link there, which would splice a stale list onto the vertex).
  static void VFAppend(FacePointer f, int z) {
    f->VFp(z) = nullptr;
    f->VFi(z) = -1;
    vcg::face::VFAppend(f, z);
  }
  static void AngleCosines(const Point& a, const Point& b, const Point& c, double& cosMin, double& cosMax);
  RegionMetrics OldMetrics() const;
  OpRefusal CheckRegion(double maxEdgeFromVertexLength = std::numeric_limits<double>::infinity(),
                        const VertexType* lengthVertex = nullptr);
  bool NewFacesIntersect();
  /// Appends to `pairs` the pairs (f, g), f < g, of faces that share exactly one vertex, involve a
  /// face moved in the batch and meet beyond that vertex (FacesIntersect), found star by star:
  /// a star that is a simple fan (StarIsSimpleFan) has no such pair. `scan` is the sweep's scan,
  /// built over the current faces: their corners, normals and moved flags are read from it.
  void StarPairs(const TrianglePairScan& scan, int threads,
                 std::vector<std::pair<std::uint32_t, std::uint32_t>>& pairs) const;
  /// The fidelity guard (LocalOpsGuards::maxInputDistanceFactor): true when the new faces leave
  /// an input point near the region farther from the mesh than allowed.
  bool NewFacesLeaveInput();
  OpRefusal Refuse(OpRefusal r) {
    lastRefusal_ = r;
    ++stats_.refused[std::size_t(r)];
    return r;
  }

  MeshType& m_;
  const Reference& ref_;
  double L_;
  LocalOpsGuards guards_;
  int threads_;

  // Guards as cosines / absolute values.
  double cosMinAngleGuard_ = 0, cosMaxAngleGuard_ = 0, cosNormalGuard_ = 0, cosFoldGuard_ = 0;
  double minArea2_ = 0; ///< squared (2 * area) threshold
  double tol_ = 0;      ///< snap distance of the intersection predicates

  std::vector<int> foot_;                 ///< per vertex: reference face of its footpoint
  static constexpr int kUnknownFoot = -2; ///< foot_ of a vertex whose footpoint Init left to find
  std::vector<std::uint8_t> locked_;      ///< per vertex
  std::vector<std::uint32_t> vertStamp_, faceStamp_;
  std::uint32_t stamp_ = 0;
  std::vector<std::size_t> freeVerts_, freeFaces_;
  FaceHashGrid grid_;
  typename Reference::Scratch scratch_, inputScratch_;
  LocalOpsStats stats_;
  OpRefusal lastRefusal_ = OpRefusal::None;

  // Batch moves.
  struct BatchEntry {
    std::uint32_t vertex;
    CoordType target, old;
    int targetFoot, oldFoot;
    bool atTarget;
  };
  struct FaceVerdict {
    bool fail = false;
    int partner = -1; ///< other face to revert with it, or -1
  };
  /// Position of u before the batch (its current one unless it is at a batch target).
  CoordType OldCoord(const VertexType* u) const {
    const int b = batchIndex_[VIndex(*u)];
    return (b >= 0 && batch_[b].atTarget) ? batch_[b].old : u->cP();
  }
  int OldFoot(const VertexType* u) const {
    const int b = batchIndex_[VIndex(*u)];
    return (b >= 0 && batch_[b].atTarget) ? batch_[b].oldFoot : foot_[VIndex(*u)];
  }
  bool MovedInBatch(const FaceType& f) const {
    for (int k = 0; k < 3; ++k) {
      const int b = batchIndex_[VIndex(*f.cV(k))];
      if (b >= 0 && batch_[b].atTarget) return true;
    }
    return false;
  }
  /// The guards on face fi of a batch (see VerifyPendingMoves); intersections through the grid
  /// when `intersections`. `scan`, when given, is built over the current faces: their unit normals
  /// and moved flags are read from it instead of being computed again.
  FaceVerdict VerifyBatchFace(std::size_t fi, FaceHashGrid::QueryMarks& marks, bool intersections,
                              const TrianglePairScan* scan = nullptr) const;
  TrianglePairScan scan_;
  std::vector<Point> scanPositions_; ///< vertex positions for scan_ (by vertex index)
  std::vector<std::pair<std::uint32_t, std::uint32_t>> scanPairs_;
  std::vector<int> batchIndex_; ///< per vertex: entry in batch_, or -1
  std::vector<BatchEntry> batch_;
  std::vector<std::size_t> dirty_;
  std::vector<std::uint8_t> updateInPlace_;
  std::vector<FaceVerdict> verdicts_;
  std::vector<FaceHashGrid::QueryMarks> marks_;
  double margin_ = 0;      ///< separating-plane margin of the fast intersection rejection
  bool hasBorder_ = false; ///< some edge is a border edge (otherwise no vertex is on the boundary)

  // Scratch buffers (kept to avoid allocation in the operations).
  std::vector<NewFace> newFaces_;
  std::vector<FacePointer> oldFaces_;
  std::vector<std::pair<FacePointer, int>> star0_, star1_;
  std::vector<std::size_t> candidates_;
  std::vector<std::pair<VertexPointer, VertexPointer>> loopEdges_;
};

// ------------------------------------------------------------------------------------------------
// Implementation
// ------------------------------------------------------------------------------------------------

template <class MeshType>
void LocalRemeshingOps<MeshType>::UpdateGuardCosines() {
  const double toRad = 3.14159265358979323846 / 180.0;
  cosMinAngleGuard_ = std::cos(guards_.minAngleDeg * toRad);
  cosMaxAngleGuard_ = std::cos(guards_.maxAngleDeg * toRad);
  cosNormalGuard_ = std::cos(guards_.maxNormalDeviationDeg * toRad);
  cosFoldGuard_ = std::cos(guards_.maxFoldAngleDeg * toRad);
  const double minArea2 = 2.0 * guards_.minAreaFactor * L_ * L_;
  minArea2_ = minArea2 * minArea2;
}

template <class MeshType>
void LocalRemeshingOps<MeshType>::NewStamp() {
  if (++stamp_ == 0) {
    std::fill(vertStamp_.begin(), vertStamp_.end(), 0);
    std::fill(faceStamp_.begin(), faceStamp_.end(), 0);
    stamp_ = 1;
  }
}

template <class MeshType>
std::string LocalRemeshingOps<MeshType>::AdjacencyProblem(const MeshType& m) {
  std::vector<std::size_t> uses(m.vert.size(), 0);
  for (std::size_t fi = 0; fi < m.face.size(); ++fi) {
    const FaceType& f = m.face[fi];
    if (f.IsD()) continue;
    const std::string where = "face " + std::to_string(fi) + ": ";
    for (int e = 0; e < 3; ++e) {
      if (f.cV(e) == nullptr || f.cV(e)->IsD()) return where + "missing or deleted vertex";
      ++uses[vcg::tri::Index(m, f.cV(e))];
      const FaceType* g = f.cFFp(e);
      const int w = f.cFFi(e);
      if (g == nullptr || g->IsD()) return where + "FF link to a missing or deleted face";
      if (g == &f) {
        if (w != e) return where + "border edge with a wrong FF index";
        continue;
      }
      if (w < 0 || w > 2 || g->cFFp(w) != &f || g->cFFi(w) != e) return where + "FF link not mutual";
      if (g->cV(w) != f.cV((e + 1) % 3) || g->cV((w + 1) % 3) != f.cV(e))
        return where + "FF link across another edge";
    }
  }
  for (std::size_t vi = 0; vi < m.vert.size(); ++vi) {
    const VertexType& v = m.vert[vi];
    if (v.IsD()) continue;
    std::size_t listed = 0;
    if (v.cVFp() != nullptr) {
      for (vcg::face::VFIterator<FaceType> it(const_cast<VertexType*>(&v)); !it.End(); ++it) {
        if (++listed > uses[vi]) return "vertex " + std::to_string(vi) + ": VF list too long (or cyclic)";
        if (it.F()->IsD()) return "vertex " + std::to_string(vi) + ": VF list holds a deleted face";
        if (it.I() < 0 || it.I() > 2 || it.F()->cV(it.I()) != &v)
          return "vertex " + std::to_string(vi) + ": VF entry does not point back";
      }
    }
    if (listed != uses[vi]) return "vertex " + std::to_string(vi) + ": VF list misses faces";
  }
  return std::string();
}

template <class MeshType>
bool LocalRemeshingOps<MeshType>::PrepareTopology(MeshType& m, std::string* error, int threads) {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (!vcg::tri::HasFFAdjacency(m) || !vcg::tri::HasVFAdjacency(m))
    return fail("face-face and vertex-face adjacency must be enabled on the mesh");
  for (const auto& f : m.face) {
    if (f.IsD()) continue;
    if (f.cV(0) == nullptr || f.cV(1) == nullptr || f.cV(2) == nullptr || f.cV(0) == f.cV(1) ||
        f.cV(1) == f.cV(2) || f.cV(2) == f.cV(0))
      return fail("the mesh has faces with a repeated or missing vertex; clean it first");
  }
  UpdateAdjacency(m, threads);

  // 2-manifold and consistently oriented: every edge has one or two faces, two faces traverse
  // it in opposite directions, and the faces at each vertex form a single fan. Read-only, so
  // the checks run on `threads` cores (0 = all; each thread counts into its own slot).
  threads = ResolveThreadCount(threads);
  std::vector<std::array<std::size_t, 3>> counts(std::size_t(threads), {0, 0, 0});
  ParallelFor(m.face.size(), threads, [&](std::size_t begin, std::size_t end, int t) {
    std::array<std::size_t, 3>& c = counts[std::size_t(t)];
    for (std::size_t fi = begin; fi < end; ++fi) {
      const FaceType& f = m.face[fi];
      if (f.IsD()) continue;
      for (int e = 0; e < 3; ++e) {
        if (IsBorder(f, e)) continue;
        const FaceType* g = f.cFFp(e);
        const int w = f.cFFi(e);
        if (g->cFFp(w) != &f)
          ++c[0];
        else if (g->cV(w) != f.cV((e + 1) % 3) || g->cV((w + 1) % 3) != f.cV(e))
          ++c[1];
      }
    }
  });
  std::size_t nonManifoldEdges = 0, misoriented = 0, nonManifoldVertices = 0;
  for (const auto& c : counts) {
    nonManifoldEdges += c[0];
    misoriented += c[1];
  }
  if (nonManifoldEdges > 0) return fail("the mesh has non-manifold edges; run the cleaning stage first");
  if (misoriented > 0) return fail("the mesh is not consistently oriented; run the cleaning stage first");
  ParallelFor(m.vert.size(), threads, [&](std::size_t begin, std::size_t end, int t) {
    for (std::size_t vi = begin; vi < end; ++vi) {
      VertexType& v = m.vert[vi];
      if (v.IsD() || v.VFp() == nullptr) continue;
      std::size_t inList = 0;
      for (vcg::face::VFIterator<FaceType> it(&v); !it.End(); ++it) ++inList;
      // Walk the fan through FF in both directions from the first face.
      std::size_t inFan = 0;
      FacePointer f0 = v.VFp();
      FacePointer f = f0;
      int k = v.VFi();
      bool border = false;
      do {
        ++inFan;
        FacePointer g = f->FFp(k); // across edge (v, next)
        if (g == f) {
          border = true;
          break;
        }
        k = IndexIn(*g, &v);
        f = g;
      } while (f != f0 && inFan <= inList);
      if (border) {
        f = f0;
        k = v.VFi();
        for (;;) {
          FacePointer g = f->FFp((k + 2) % 3); // across edge (prev, v)
          if (g == f || inFan > inList) break;
          ++inFan;
          k = IndexIn(*g, &v);
          f = g;
        }
      }
      if (inFan != inList) ++counts[std::size_t(t)][2];
    }
  });
  for (const auto& c : counts) nonManifoldVertices += c[2];
  if (nonManifoldVertices > 0)
    return fail("the mesh has non-manifold vertices; run the cleaning stage first");

  return true;
}

template <class MeshType>
bool LocalRemeshingOps<MeshType>::Init(std::string* error, bool meshIsReference, bool topologyReady,
                                       bool lazyFootpoints, const std::vector<int>* globalFeet) {
  auto fail = [&](const std::string& message) {
    if (error) *error = message;
    return false;
  };
  if (!vcg::tri::HasFFAdjacency(m_) || !vcg::tri::HasVFAdjacency(m_))
    return fail("face-face and vertex-face adjacency must be enabled on the mesh");
  if (ref_.Empty()) return fail("the reference surface is empty");
  if (!(L_ > 0) || !std::isfinite(L_)) return fail("the target edge length must be positive");
  if (!topologyReady && !PrepareTopology(m_, error, threads_)) return false;
  hasBorder_ = false;
  for (const auto& f : m_.face)
    if (!f.IsD() && (IsBorder(f, 0) || IsBorder(f, 1) || IsBorder(f, 2))) hasBorder_ = true;
  UpdateGuardCosines();
  const vcg::Box3d& rb = ref_.BoundingBox();
  const double maxAbs = std::max({std::fabs(rb.min[0]), std::fabs(rb.min[1]), std::fabs(rb.min[2]),
                                  std::fabs(rb.max[0]), std::fabs(rb.max[1]), std::fabs(rb.max[2])});
  tol_ = 1e-12 * (maxAbs + L_);
  margin_ = 1e-9 * (maxAbs + L_);

  foot_.assign(m_.vert.size(), -1);
  batchIndex_.assign(m_.vert.size(), -1);
  locked_.assign(m_.vert.size(), 0);
  vertStamp_.assign(m_.vert.size(), 0);
  faceStamp_.assign(m_.face.size(), 0);
  stamp_ = 0;
  freeVerts_.clear();
  freeFaces_.clear();
  // Recycle elements deleted before (in reverse so the lowest index is taken first).
  for (std::size_t i = m_.vert.size(); i-- > 0;)
    if (m_.vert[i].IsD()) freeVerts_.push_back(i);
  for (std::size_t i = m_.face.size(); i-- > 0;)
    if (m_.face[i].IsD()) freeFaces_.push_back(i);

  // Footpoints.
  std::vector<std::uint8_t> needsSearch(m_.vert.size(), 0);
  for (std::size_t i = 0; i < m_.vert.size(); ++i) {
    const VertexType& v = m_.vert[i];
    if (v.IsD() || v.cVFp() == nullptr) continue;
    needsSearch[i] = 1;
    if (globalFeet != nullptr && i < globalFeet->size() && (*globalFeet)[i] >= 0) {
      foot_[i] = (*globalFeet)[i];
      needsSearch[i] = 0;
      continue;
    }
    if (!meshIsReference) continue;
    const int rf = ref_.ReferenceFaceOf(FIndex(*v.cVFp()));
    if (rf < 0) continue;
    const int k = v.cVFi();
    if (ref_.Corner(rf, k) == Pos(&v)) {
      foot_[i] = rf;
      needsSearch[i] = 0;
    }
  }
  if (lazyFootpoints) {
    for (std::size_t i = 0; i < m_.vert.size(); ++i)
      if (needsSearch[i]) foot_[i] = kUnknownFoot;
  } else {
    ParallelFor(m_.vert.size(), threads_, [&](std::size_t begin, std::size_t end, int) {
      for (std::size_t i = begin; i < end; ++i)
        if (needsSearch[i]) foot_[i] = ref_.ProjectGlobal(Pos(&m_.vert[i])).face;
    });
  }

  grid_.Reset(guards_.gridCellFactor * L_, rb.min);
  grid_.InsertAll(
      m_.face.size(),
      [&](std::size_t i, vcg::Box3d& box) {
        if (m_.face[i].IsD()) return false;
        box = FaceBox(m_.face[i]);
        return true;
      },
      threads_);
  lastRefusal_ = OpRefusal::None;
  return true;
}

template <class MeshType>
void LocalRemeshingOps<MeshType>::Finish() {
  if (HasPendingMoves()) VerifyPendingMoves();
  vcg::tri::Allocator<MeshType>::CompactEveryVector(m_);
  if (vcg::tri::HasPerFaceNormal(m_)) vcg::tri::UpdateNormal<MeshType>::PerFaceNormalized(m_);
  if (vcg::tri::HasPerVertexNormal(m_)) vcg::tri::UpdateNormal<MeshType>::PerVertexNormalized(m_);
  foot_.clear();
  batchIndex_.clear();
  locked_.clear();
  vertStamp_.clear();
  faceStamp_.clear();
  freeVerts_.clear();
  freeFaces_.clear();
  grid_.Reset(1.0, Point(0, 0, 0));
}

// --- Element recycling ---------------------------------------------------------------------------

template <class MeshType>
void LocalRemeshingOps<MeshType>::GrowPerElementArrays() {
  foot_.resize(m_.vert.size(), -1);
  batchIndex_.resize(m_.vert.size(), -1);
  locked_.resize(m_.vert.size(), 0);
  vertStamp_.resize(m_.vert.size(), 0);
  faceStamp_.resize(m_.face.size(), 0);
  grid_.Resize(m_.face.size());
}

template <class MeshType>
void LocalRemeshingOps<MeshType>::EnsureFree(std::size_t nv, std::size_t nf, FacePointer& f) {
  if (freeVerts_.size() < nv) {
    const std::size_t grow = std::max<std::size_t>({nv, 64, m_.vert.size() / 8});
    const std::size_t first = m_.vert.size();
    vcg::tri::Allocator<MeshType>::AddVertices(m_, grow);
    for (std::size_t i = m_.vert.size(); i-- > first;) {
      vcg::tri::Allocator<MeshType>::DeleteVertex(m_, m_.vert[i]);
      freeVerts_.push_back(i);
    }
  }
  if (freeFaces_.size() < nf) {
    const std::size_t grow = std::max<std::size_t>({nf, 64, m_.face.size() / 8});
    const std::size_t first = m_.face.size();
    typename vcg::tri::Allocator<MeshType>::template PointerUpdater<FacePointer> pu;
    vcg::tri::Allocator<MeshType>::AddFaces(m_, grow, pu);
    if (pu.NeedUpdate()) pu.Update(f);
    for (std::size_t i = m_.face.size(); i-- > first;) {
      vcg::tri::Allocator<MeshType>::DeleteFace(m_, m_.face[i]);
      freeFaces_.push_back(i);
    }
  }
  GrowPerElementArrays();
}

template <class MeshType>
typename MeshType::VertexPointer LocalRemeshingOps<MeshType>::TakeFreeVertex() {
  VertexType& v = m_.vert[freeVerts_.back()];
  freeVerts_.pop_back();
  v.ClearD();
  ++m_.vn;
  return &v;
}

template <class MeshType>
typename MeshType::FacePointer LocalRemeshingOps<MeshType>::TakeFreeFace() {
  FaceType& f = m_.face[freeFaces_.back()];
  freeFaces_.pop_back();
  f.ClearD();
  ++m_.fn;
  return &f;
}

template <class MeshType>
void LocalRemeshingOps<MeshType>::Release(FaceType& f) {
  grid_.Remove(FIndex(f));
  vcg::tri::Allocator<MeshType>::DeleteFace(m_, f);
  freeFaces_.push_back(FIndex(f));
}

template <class MeshType>
void LocalRemeshingOps<MeshType>::Release(VertexType& v) {
  vcg::tri::Allocator<MeshType>::DeleteVertex(m_, v);
  v.VFp() = nullptr;
  v.VFi() = -1;
  locked_[VIndex(v)] = 0;
  freeVerts_.push_back(VIndex(v));
}

// --- Queries -------------------------------------------------------------------------------------

template <class MeshType>
bool LocalRemeshingOps<MeshType>::GatherStar(const VertexType* v,
                                             std::vector<std::pair<FacePointer, int>>& star) const {
  star.clear();
  bool boundary = false;
  for (vcg::face::VFIterator<FaceType> it(const_cast<VertexType*>(v)); !it.End(); ++it) {
    star.emplace_back(it.F(), it.I());
    if (IsBorder(*it.F(), it.I()) || IsBorder(*it.F(), (it.I() + 2) % 3)) boundary = true;
  }
  return boundary;
}

template <class MeshType>
bool LocalRemeshingOps<MeshType>::IsBoundaryVertex(const VertexType& v) const {
  if (!hasBorder_ || v.cVFp() == nullptr) return false;
  for (vcg::face::VFIterator<FaceType> it(const_cast<VertexType*>(&v)); !it.End(); ++it)
    if (IsBorder(*it.F(), it.I()) || IsBorder(*it.F(), (it.I() + 2) % 3)) return true;
  return false;
}

template <class MeshType>
int LocalRemeshingOps<MeshType>::Valence(const VertexType& v) const {
  if (v.cVFp() == nullptr) return 0;
  int faces = 0;
  bool boundary = false;
  for (vcg::face::VFIterator<FaceType> it(const_cast<VertexType*>(&v)); !it.End(); ++it) {
    ++faces;
    if (hasBorder_ && (IsBorder(*it.F(), it.I()) || IsBorder(*it.F(), (it.I() + 2) % 3))) boundary = true;
  }
  return boundary ? faces + 1 : faces;
}

template <class MeshType>
bool LocalRemeshingOps<MeshType>::FindEdge(VertexPointer a, VertexPointer b, FacePointer& f, int& z) const {
  if (a->VFp() == nullptr) return false;
  for (vcg::face::VFIterator<FaceType> it(a); !it.End(); ++it) {
    const int k = it.I();
    if (it.F()->V((k + 1) % 3) == b) {
      f = it.F();
      z = k;
      return true;
    }
    if (it.F()->V((k + 2) % 3) == b) {
      f = it.F();
      z = (k + 2) % 3;
      return true;
    }
  }
  return false;
}

template <class MeshType>
bool LocalRemeshingOps<MeshType>::IsDelaunay(const FaceType& f, int z) const {
  if (IsBorder(f, z)) return true;
  const FaceType& g = *f.cFFp(z);
  const int w = f.cFFi(z);
  // cot(alpha) + cot(beta) >= 0  <=>  alpha + beta <= pi
  auto cot = [&](const Point& apex, const Point& a, const Point& b) {
    const Point u = a - apex, v = b - apex;
    const double s = (u ^ v).Norm();
    return s > 0 ? (u * v) / s : std::numeric_limits<double>::infinity() * ((u * v) >= 0 ? 1 : -1);
  };
  const Point a = Pos(f.cV(z)), b = Pos(f.cV((z + 1) % 3));
  const double sum = cot(Pos(f.cV((z + 2) % 3)), a, b) + cot(Pos(g.cV((w + 2) % 3)), a, b);
  return !(sum < -1e-12);
}

template <class MeshType>
int LocalRemeshingOps<MeshType>::FlipValenceGain(const FaceType& f, int z) const {
  if (IsBorder(f, z)) return 0;
  const FaceType& g = *f.cFFp(z);
  const int w = f.cFFi(z);
  const std::array<const VertexType*, 4> v{f.cV(z), f.cV((z + 1) % 3), f.cV((z + 2) % 3), g.cV((w + 2) % 3)};
  const std::array<int, 4> change{-1, -1, +1, +1};
  int before = 0, after = 0;
  for (int i = 0; i < 4; ++i) {
    const int valence = Valence(*v[i]);
    const int ideal = IsBoundaryVertex(*v[i]) ? 4 : 6;
    before += std::abs(valence - ideal);
    after += std::abs(valence + change[i] - ideal);
  }
  return before - after;
}

// --- Checks --------------------------------------------------------------------------------------

template <class MeshType>
void LocalRemeshingOps<MeshType>::AngleCosines(const Point& a, const Point& b, const Point& c, double& cosMin,
                                               double& cosMax) {
  // Squared edge lengths opposite each corner; the smallest angle faces the shortest edge and the
  // largest angle the longest one (law of cosines, no trigonometry).
  const double la = (b - c).SquaredNorm(), lb = (c - a).SquaredNorm(), lc = (a - b).SquaredNorm();
  auto cosAt = [](double opposite, double s1, double s2) {
    const double d = 2.0 * std::sqrt(s1 * s2);
    return d > 0 ? std::clamp((s1 + s2 - opposite) / d, -1.0, 1.0) : 1.0;
  };
  double lo = la, hi = la;
  int iLo = 0, iHi = 0;
  if (lb < lo) lo = lb, iLo = 1;
  if (lc < lo) lo = lc, iLo = 2;
  if (lb > hi) hi = lb, iHi = 1;
  if (lc > hi) hi = lc, iHi = 2;
  const std::array<double, 3> l{la, lb, lc};
  cosMin = cosAt(l[iLo], l[(iLo + 1) % 3], l[(iLo + 2) % 3]);
  cosMax = cosAt(l[iHi], l[(iHi + 1) % 3], l[(iHi + 2) % 3]);
}

template <class MeshType>
typename LocalRemeshingOps<MeshType>::RegionMetrics LocalRemeshingOps<MeshType>::OldMetrics() const {
  RegionMetrics r;
  for (const FacePointer f : oldFaces_) {
    const Point a = Pos(f->cV(0)), b = Pos(f->cV(1)), c = Pos(f->cV(2));
    double cmin, cmax;
    AngleCosines(a, b, c, cmin, cmax);
    r.cosMinAngle = std::max(r.cosMinAngle, cmin);
    r.cosMaxAngle = std::min(r.cosMaxAngle, cmax);
    r.smallFaces += cmin > cosMinAngleGuard_;
    r.largeFaces += cmax < cosMaxAngleGuard_;
    const Point n = FaceNormal(*f);
    const std::array<int, 3> feet{foot_[VIndex(*f->cV(0))], foot_[VIndex(*f->cV(1))],
                                  foot_[VIndex(*f->cV(2))]};
    const Point s = RefNormalSum(feet);
    const double len = s.Norm();
    r.cosNormal = std::min(r.cosNormal, len > 1e-12 ? (n * s) / len : -1.0);
    for (int e = 0; e < 3; ++e)
      if (!IsBorder(*f, e)) r.cosFold = std::min(r.cosFold, n * FaceNormal(*f->cFFp(e)));
  }
  return r;
}

template <class MeshType>
OpRefusal LocalRemeshingOps<MeshType>::CheckRegion(double maxEdgeLength, const VertexType* lengthVertex) {
  const std::size_t n = newFaces_.size();
  RegionMetrics nm;
  for (std::size_t i = 0; i < n; ++i) {
    NewFace& nf = newFaces_[i];
    const Point cross = (nf.p[1] - nf.p[0]) ^ (nf.p[2] - nf.p[0]);
    const double area2 = cross.SquaredNorm();
    if (!(area2 > minArea2_)) return OpRefusal::Degenerate;
    nf.n = cross / std::sqrt(area2);
    nf.box.SetNull();
    for (int k = 0; k < 3; ++k) nf.box.Add(nf.p[k]);
    double cmin, cmax;
    AngleCosines(nf.p[0], nf.p[1], nf.p[2], cmin, cmax);
    nm.cosMinAngle = std::max(nm.cosMinAngle, cmin);
    nm.cosMaxAngle = std::min(nm.cosMaxAngle, cmax);
    nm.smallFaces += cmin > cosMinAngleGuard_;
    nm.largeFaces += cmax < cosMaxAngleGuard_;
    const Point s = RefNormalSum(nf.foot);
    const double len = s.Norm();
    nm.cosNormal = std::min(nm.cosNormal, len > 1e-12 ? (nf.n * s) / len : -1.0);
  }
  if (lengthVertex != nullptr && maxEdgeLength < std::numeric_limits<double>::infinity()) {
    const double max2 = maxEdgeLength * maxEdgeLength;
    for (const NewFace& nf : newFaces_)
      for (int k = 0; k < 3; ++k)
        if (nf.v[k] == lengthVertex)
          for (int j = 1; j < 3; ++j)
            if ((nf.p[(k + j) % 3] - nf.p[k]).SquaredNorm() > max2) return OpRefusal::EdgeLength;
  }
  // Internal adjacency among the new faces and fold angles.
  for (std::size_t i = 0; i < n; ++i) {
    NewFace& nf = newFaces_[i];
    for (int e = 0; e < 3; ++e) {
      nf.internal[e] = -1;
      const VertexPointer a = nf.v[e], b = nf.v[(e + 1) % 3];
      for (std::size_t j = 0; j < n && nf.internal[e] < 0; ++j) {
        if (j == i) continue;
        const NewFace& o = newFaces_[j];
        for (int k = 0; k < 3; ++k)
          if (o.v[k] == b && o.v[(k + 1) % 3] == a) {
            nf.internal[e] = int(j);
            break;
          }
      }
      if (nf.internal[e] >= 0)
        nm.cosFold = std::min(nm.cosFold, nf.n * newFaces_[nf.internal[e]].n);
      else if (nf.outside[e] != nullptr)
        nm.cosFold = std::min(nm.cosFold, nf.n * FaceNormal(*nf.outside[e]));
    }
  }
  const bool minOk = nm.cosMinAngle <= cosMinAngleGuard_;
  const bool maxOk = nm.cosMaxAngle >= cosMaxAngleGuard_;
  const bool normalOk = nm.cosNormal >= cosNormalGuard_;
  const bool foldOk = nm.cosFold >= cosFoldGuard_;
  if (!(minOk && maxOk && normalOk && foldOk)) {
    const RegionMetrics om = OldMetrics();
    if (!minOk && !(nm.cosMinAngle < om.cosMinAngle)) return OpRefusal::MinAngle;
    if (!maxOk && !(nm.cosMaxAngle > om.cosMaxAngle)) return OpRefusal::MaxAngle;
    if (!normalOk && !(nm.cosNormal >= om.cosNormal)) return OpRefusal::Normal;
    if (!foldOk && !(nm.cosFold >= om.cosFold)) return OpRefusal::Fold;
  }
  if (guards_.noMoreBadFaces && (!minOk || !maxOk)) {
    const RegionMetrics om = OldMetrics();
    if (nm.smallFaces > om.smallFaces) return OpRefusal::MinAngle;
    if (nm.largeFaces > om.largeFaces) return OpRefusal::MaxAngle;
  }
  if (guards_.checkIntersections && NewFacesIntersect()) return OpRefusal::Intersection;
  if (guards_.maxInputDistanceFactor > 0 && NewFacesLeaveInput()) return OpRefusal::InputDistance;
  return OpRefusal::None;
}

template <class MeshType>
bool LocalRemeshingOps<MeshType>::NewFacesLeaveInput() {
  using reference_detail::ClosestPointOnTriangle;
  const double tol = guards_.maxInputDistanceFactor * L_;
  const double tol2 = tol * tol;
  const double reach = std::max(tol, guards_.inputReachFactor * L_);
  vcg::Box3d box;
  for (const FacePointer f : oldFaces_)
    for (int k = 0; k < 3; ++k) box.Add(Pos(f->cV(k)));
  for (const NewFace& nf : newFaces_)
    for (int k = 0; k < 3; ++k) box.Add(nf.p[k]);
  box.Offset(reach);
  auto distance2 = [](const Point& q, const Point& a, const Point& b, const Point& c) {
    return (ClosestPointOnTriangle(q, a, b, c) - q).SquaredNorm();
  };
  // Whether q ends farther than tol from the mesh and farther than it was.
  auto worse = [&](const Point& q) {
    double new2 = std::numeric_limits<double>::infinity();
    for (const NewFace& nf : newFaces_) {
      new2 = std::min(new2, distance2(q, nf.p[0], nf.p[1], nf.p[2]));
      if (new2 <= tol2) return false;
    }
    double old2 = std::numeric_limits<double>::infinity();
    for (const FacePointer f : oldFaces_)
      old2 = std::min(old2, distance2(q, Pos(f->cV(0)), Pos(f->cV(1)), Pos(f->cV(2))));
    if (new2 <= old2) return false;
    // The rest of the mesh (unchanged) may hold q closer than the new faces.
    const double r = std::sqrt(new2);
    double rest2 = new2;
    grid_.Query(vcg::Box3d(q - Point(r, r, r), q + Point(r, r, r)), [&](std::size_t g) {
      if (faceStamp_[g] == stamp_ || rest2 <= tol2) return;
      const FaceType& face = m_.face[g];
      rest2 = std::min(rest2, distance2(q, Pos(face.cV(0)), Pos(face.cV(1)), Pos(face.cV(2))));
    });
    return rest2 > tol2 && rest2 > old2;
  };
  bool leaves = false;
  ref_.ForEachFaceInBox(box, inputScratch_, [&](int f) {
    if (leaves) return;
    // The centroid and the points halfway between it and the corners: on a face across a ridge
    // of the input, the farthest point is inside, not at a corner.
    const Point &a = ref_.Corner(f, 0), &b = ref_.Corner(f, 1), &c = ref_.Corner(f, 2);
    const Point centroid = (a + b + c) / 3.0;
    for (const Point& q : {centroid, (centroid + a) * 0.5, (centroid + b) * 0.5, (centroid + c) * 0.5})
      if (box.IsIn(q) && worse(q)) {
        leaves = true;
        return;
      }
    for (int k = 0; k < 3 && !leaves; ++k) {
      const std::uint32_t vi = ref_.FaceVertices(f)[k];
      if (ref_.VertexFace(vi) == f && box.IsIn(ref_.Vertex(vi)) && worse(ref_.Vertex(vi))) leaves = true;
    }
  });
  return leaves;
}

template <class MeshType>
void LocalRemeshingOps<MeshType>::StarPairs(
    const TrianglePairScan& scan, int threads,
    std::vector<std::pair<std::uint32_t, std::uint32_t>>& pairs) const {
  threads = ResolveThreadCount(threads);
  std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> found(static_cast<std::size_t>(threads));
  ParallelFor(m_.vert.size(), threads, [&](std::size_t begin, std::size_t end, int t) {
    std::vector<std::uint32_t> star;
    std::vector<std::pair<Point, Point>> link;
    for (std::size_t vi = begin; vi < end; ++vi) {
      const VertexType& v = m_.vert[vi];
      if (v.IsD() || v.cVFp() == nullptr) continue;
      star.clear();
      link.clear();
      bool boundary = false, moved = false;
      for (vcg::face::VFIterator<FaceType> it(const_cast<VertexType*>(&v)); !it.End(); ++it) {
        const int k = it.I();
        star.push_back(std::uint32_t(FIndex(*it.F())));
        // The corners as the scan collected them: no vertex record to read.
        link.emplace_back(scan.Corner(star.back(), (k + 1) % 3), scan.Corner(star.back(), (k + 2) % 3));
        if (IsBorder(*it.F(), k) || IsBorder(*it.F(), (k + 2) % 3)) boundary = true;
        if (scan.Input(star.back()).moved) moved = true;
      }
      if (!moved) continue;
      if (local_ops_detail::StarIsSimpleFan(Pos(&v), link.data(), int(link.size()), boundary)) continue;
      for (std::size_t i = 0; i < star.size(); ++i)
        for (std::size_t j = i + 1; j < star.size(); ++j) {
          const TrianglePairScan::Triangle &a = scan.Input(star[i]), &b = scan.Input(star[j]);
          if (!a.moved && !b.moved) continue;
          int shared = 0;
          for (int x = 0; x < 3; ++x)
            for (int y = 0; y < 3; ++y) shared += a.v[x] == b.v[y] ? 1 : 0;
          if (shared != 1) continue;
          if (!local_ops_detail::FacesIntersect(scan.Corners(star[i]), scan.Normal(star[i]), a.v,
                                                scan.Corners(star[j]), scan.Normal(star[j]), b.v, margin_))
            continue;
          found[std::size_t(t)].emplace_back(std::min(star[i], star[j]), std::max(star[i], star[j]));
        }
    }
  });
  for (const auto& list : found) pairs.insert(pairs.end(), list.begin(), list.end());
}

template <class MeshType>
bool LocalRemeshingOps<MeshType>::NewFacesIntersect() {
  using local_ops_detail::FacesIntersect;
  const std::size_t n = newFaces_.size();
  vcg::Box3d all;
  for (std::size_t i = 0; i < n; ++i) {
    newFaces_[i].box.Offset(tol_);
    all.Add(newFaces_[i].box);
  }
  // Against the faces outside the region (the region's old faces carry the current stamp).
  candidates_.clear();
  grid_.Query(all, [&](std::size_t g) {
    if (faceStamp_[g] != stamp_) candidates_.push_back(g);
  });
  for (const std::size_t gi : candidates_) {
    const FaceType& g = m_.face[gi];
    const vcg::Box3d gbox = grid_.BoxOf(gi);
    bool built = false;
    std::array<Point, 3> gp;
    std::array<VertexPointer, 3> gv{};
    Point gn;
    for (std::size_t i = 0; i < n; ++i) {
      const NewFace& nf = newFaces_[i];
      if (!FaceHashGrid::Touch(nf.box, gbox)) continue;
      if (!built) {
        for (int k = 0; k < 3; ++k) {
          gv[k] = const_cast<VertexPointer>(g.cV(k));
          gp[k] = Pos(g.cV(k));
        }
        gn = local_ops_detail::UnitNormal(gp);
        built = true;
      }
      if (FacesIntersect(nf.p, nf.n, nf.v, gp, gn, gv, margin_)) return true;
    }
  }
  // Among the new faces.
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) {
      const NewFace& a = newFaces_[i];
      const NewFace& b = newFaces_[j];
      if (FaceHashGrid::Touch(a.box, b.box) && FacesIntersect(a.p, a.n, a.v, b.p, b.n, b.v, margin_))
        return true;
    }
  return false;
}

// --- Batch (Jacobi) relocation -------------------------------------------------------------------

template <class MeshType>
typename LocalRemeshingOps<MeshType>::FaceVerdict
LocalRemeshingOps<MeshType>::VerifyBatchFace(std::size_t fi, FaceHashGrid::QueryMarks& marks,
                                             bool intersections, const TrianglePairScan* scan) const {
  using local_ops_detail::UnitNormal;
  FaceVerdict verdict;
  const FaceType& f = m_.face[fi];
  std::array<Point, 3> p, o;
  std::array<VertexPointer, 3> v{};
  std::array<int, 3> feet{}, oldFeet{};
  for (int k = 0; k < 3; ++k) {
    v[k] = const_cast<VertexPointer>(f.cV(k));
    p[k] = Pos(v[k]);
    o[k] = ToPoint(OldCoord(v[k]));
    feet[k] = foot_[VIndex(*v[k])];
    oldFeet[k] = OldFoot(v[k]);
  }
  const bool moved = scan ? scan->Input(fi).moved : MovedInBatch(f);
  const Point n = scan ? scan->Normal(fi) : UnitNormal(p);
  auto fail = [&](int partner) {
    verdict.fail = true;
    verdict.partner = partner;
    return verdict;
  };
  if (moved) {
    const Point cross = (p[1] - p[0]) ^ (p[2] - p[0]);
    if (!(cross.SquaredNorm() > minArea2_)) return fail(-1);
    double cmin, cmax, ocmin, ocmax;
    AngleCosines(p[0], p[1], p[2], cmin, cmax);
    if (cmin > cosMinAngleGuard_ || cmax < cosMaxAngleGuard_) {
      AngleCosines(o[0], o[1], o[2], ocmin, ocmax);
      if (cmin > cosMinAngleGuard_ && cmin > ocmin) return fail(-1);
      if (cmax < cosMaxAngleGuard_ && cmax < ocmax) return fail(-1);
    }
    auto deviation = [&](const Point& normal, const std::array<int, 3>& corners) {
      const Point s = RefNormalSum(corners);
      const double len = s.Norm();
      return len > 1e-12 ? (normal * s) / len : -1.0;
    };
    const double dev = deviation(n, feet);
    if (dev < cosNormalGuard_ && dev < deviation(UnitNormal(o), oldFeet)) return fail(-1);
  }
  // Folds across the edges (each edge once when both faces are being verified).
  for (int e = 0; e < 3; ++e) {
    const FaceType* g = f.cFFp(e);
    if (g == &f) continue;
    const std::size_t gi = FIndex(*g);
    if (faceStamp_[gi] == stamp_ && gi < fi) continue;
    if (!moved && !(scan ? scan->Input(gi).moved : MovedInBatch(*g))) continue;
    Point ng;
    if (scan) {
      ng = scan->Normal(gi);
    } else {
      std::array<Point, 3> q;
      for (int k = 0; k < 3; ++k) q[k] = Pos(g->cV(k));
      ng = UnitNormal(q);
    }
    const double c = n * ng;
    if (c >= cosFoldGuard_) continue;
    std::array<Point, 3> qo;
    for (int k = 0; k < 3; ++k) qo[k] = ToPoint(OldCoord(g->cV(k)));
    if (c < UnitNormal(o) * UnitNormal(qo)) return fail(int(gi));
  }
  if (!guards_.checkIntersections || !intersections) return verdict;
  // New intersecting pairs: against every face whose (stored, outward rounded) box touches
  // this one's (the grid is up to date for the faces being verified).
  int partner = -1;
  grid_.QueryFace(fi, marks, [&](std::size_t gi) {
    if (partner >= 0) return;
    if (faceStamp_[gi] == stamp_ && gi < fi) return; // verified from the other side
    const FaceType& g = m_.face[gi];
    if (!moved && !MovedInBatch(g)) return; // two untouched faces: not new
    std::array<Point, 3> q;
    std::array<VertexPointer, 3> gv{};
    for (int k = 0; k < 3; ++k) {
      gv[k] = const_cast<VertexPointer>(g.cV(k));
      q[k] = Pos(gv[k]);
    }
    if (local_ops_detail::FacesIntersect(p, n, v, q, UnitNormal(q), gv, margin_)) partner = int(gi);
  });
  if (partner >= 0) return fail(partner);
  return verdict;
}

template <class MeshType>
bool LocalRemeshingOps<MeshType>::MoveVertexUnchecked(VertexPointer v, const Point& onSurface, int footFace) {
  const std::size_t vi = VIndex(*v);
  if (v->IsD() || v->VFp() == nullptr || locked_[vi] || footFace < 0 || IsBoundaryVertex(*v)) return false;
  const CoordType stored = ToCoord(onSurface);
  if (batchIndex_[vi] < 0) {
    if (stored == v->cP()) return true;
    batchIndex_[vi] = int(batch_.size());
    batch_.push_back({std::uint32_t(vi), stored, v->cP(), footFace, foot_[vi], true});
  } else {
    batch_[batchIndex_[vi]].target = stored;
    batch_[batchIndex_[vi]].targetFoot = footFace;
  }
  v->P() = stored;
  foot_[vi] = footFace;
  return true;
}

template <class MeshType>
BatchMoveResult LocalRemeshingOps<MeshType>::MoveVerticesJacobi(const std::vector<std::uint32_t>& vertices,
                                                                const std::vector<Point>& targets,
                                                                const std::vector<int>& feet, int threads) {
  std::size_t refused = 0;
  for (std::size_t i = 0; i < vertices.size(); ++i)
    if (!MoveVertexUnchecked(&m_.vert[vertices[i]], targets[i], feet[i])) ++refused;
  BatchMoveResult result = VerifyPendingMoves(threads);
  result.rejected += refused;
  return result;
}

template <class MeshType>
BatchMoveResult LocalRemeshingOps<MeshType>::VerifyPendingMoves(int threads) {
  BatchMoveResult result;
  if (batch_.empty()) return result;
  if (threads <= 0) threads = threads_;
  // Faces to verify: the stars of the moved vertices, in increasing index order.
  auto collectStars = [&](auto&& vertexList) {
    NewStamp();
    dirty_.clear();
    for (const std::uint32_t vi : vertexList)
      for (vcg::face::VFIterator<FaceType> it(&m_.vert[vi]); !it.End(); ++it) {
        const std::size_t fi = FIndex(*it.F());
        if (faceStamp_[fi] != stamp_) {
          faceStamp_[fi] = stamp_;
          dirty_.push_back(fi);
        }
      }
    std::sort(dirty_.begin(), dirty_.end());
  };
  const int nThreads = ResolveThreadCount(threads);
  if (4 * batch_.size() > std::size_t(m_.vn)) {
    // Most vertices moved: one parallel pass over the faces finds the changed ones.
    NewStamp();
    ParallelFor(m_.face.size(), nThreads, [&](std::size_t begin, std::size_t end, int) {
      for (std::size_t fi = begin; fi < end; ++fi)
        if (!m_.face[fi].IsD() && MovedInBatch(m_.face[fi])) faceStamp_[fi] = stamp_;
    });
    dirty_.clear();
    for (std::size_t fi = 0; fi < m_.face.size(); ++fi)
      if (faceStamp_[fi] == stamp_) dirty_.push_back(fi);
  } else {
    std::vector<std::uint32_t> moved;
    moved.reserve(batch_.size());
    for (const BatchEntry& b : batch_) moved.push_back(b.vertex);
    collectStars(moved);
  }
  if (int(marks_.size()) < nThreads) marks_.resize(nThreads);
  std::vector<std::uint32_t> reverted;
  while (!dirty_.empty()) {
    ++result.rounds;
    // Boxes that stay in their cells are updated in parallel, the others in order.
    updateInPlace_.assign(dirty_.size(), 0);
    ParallelFor(dirty_.size(), nThreads, [&](std::size_t begin, std::size_t end, int) {
      for (std::size_t i = begin; i < end; ++i)
        updateInPlace_[i] = grid_.UpdateInPlace(dirty_[i], FaceBox(m_.face[dirty_[i]])) ? 1 : 0;
    });
    for (std::size_t i = 0; i < dirty_.size(); ++i)
      if (!updateInPlace_[i]) grid_.Update(dirty_[i], FaceBox(m_.face[dirty_[i]]));
    // When most faces changed, one sweep over all of them finds the intersecting pairs faster
    // than a grid query per face.
    const bool sweep = guards_.checkIntersections && 4 * dirty_.size() > std::size_t(m_.fn);
    scanPairs_.clear();
    // The sweep's scan is built first: the per-face guards read its normals and moved flags.
    if (sweep) {
      scanPositions_.resize(m_.vert.size());
      ParallelFor(m_.vert.size(), nThreads, [&](std::size_t begin, std::size_t end, int) {
        for (std::size_t vi = begin; vi < end; ++vi) scanPositions_[vi] = Pos(&m_.vert[vi]);
      });
      scan_.Build(
          m_.face.size(), scanPositions_.data(),
          [&](std::size_t fi, TrianglePairScan::Triangle& t) {
            const FaceType& f = m_.face[fi];
            if (f.IsD()) return;
            t.live = true;
            t.moved = MovedInBatch(f);
            for (int k = 0; k < 3; ++k) t.v[k] = std::uint32_t(VIndex(*f.cV(k)));
          },
          nThreads);
    }
    verdicts_.assign(dirty_.size(), FaceVerdict());
    ParallelFor(
        dirty_.size(), nThreads,
        [&](std::size_t begin, std::size_t end, int t) {
          for (std::size_t i = begin; i < end; ++i)
            verdicts_[i] = VerifyBatchFace(dirty_[i], marks_[t], !sweep, sweep ? &scan_ : nullptr);
        },
        256);
    if (sweep) {
      // Pairs without a common vertex: the scan. Pairs sharing an edge are never reported, and
      // pairs sharing one vertex are settled star by star: none of them can meet when the star
      // is a simple fan, which nearly every star is.
      scan_.FindPairs(
          nThreads,
          [&](std::uint32_t a, std::uint32_t b) {
            return local_ops_detail::FacesIntersect(scan_.Corners(a), scan_.Normal(a), scan_.Input(a).v,
                                                    scan_.Corners(b), scan_.Normal(b), scan_.Input(b).v,
                                                    margin_);
          },
          scanPairs_, /*skipSharedVertex=*/true);
      StarPairs(scan_, nThreads, scanPairs_);
      std::sort(scanPairs_.begin(), scanPairs_.end());
      scanPairs_.erase(std::unique(scanPairs_.begin(), scanPairs_.end()), scanPairs_.end());
    }
    reverted.clear();
    auto revertFace = [&](const FaceType& f) {
      for (int k = 0; k < 3; ++k) {
        const int b = batchIndex_[VIndex(*f.cV(k))];
        if (b < 0 || !batch_[b].atTarget) continue;
        BatchEntry& e = batch_[b];
        e.atTarget = false;
        m_.vert[e.vertex].P() = e.old;
        foot_[e.vertex] = e.oldFoot;
        reverted.push_back(e.vertex);
      }
    };
    for (std::size_t i = 0; i < dirty_.size(); ++i) {
      if (!verdicts_[i].fail) continue;
      revertFace(m_.face[dirty_[i]]);
      if (verdicts_[i].partner >= 0) revertFace(m_.face[verdicts_[i].partner]);
    }
    for (const auto& [a, b] : scanPairs_) {
      revertFace(m_.face[a]);
      revertFace(m_.face[b]);
    }
    if (reverted.empty()) break;
    collectStars(reverted);
  }
  for (const BatchEntry& b : batch_) {
    batchIndex_[b.vertex] = -1;
    if (b.atTarget)
      ++result.applied;
    else
      ++result.rejected;
  }
  stats_.moves += result.applied;
  batch_.clear();
  return result;
}

// --- Vertex relocation ---------------------------------------------------------------------------

template <class MeshType>
bool LocalRemeshingOps<MeshType>::RelocateVertex(VertexPointer v, const Point& target) {
  const SurfaceProjection proj = ref_.Project(target, foot_[VIndex(*v)], scratch_);
  if (!proj.ok()) {
    Refuse(OpRefusal::Degenerate);
    return false;
  }
  return MoveVertexTo(v, proj.point, proj.face);
}

template <class MeshType>
bool LocalRemeshingOps<MeshType>::MoveVertexTo(VertexPointer v, const Point& onSurface, int footFace) {
  if (HasPendingMoves()) VerifyPendingMoves();
  const std::size_t vi = VIndex(*v);
  if (locked_[vi]) return Refuse(OpRefusal::Locked), false;
  if (v->VFp() == nullptr) return Refuse(OpRefusal::Topology), false;
  if (GatherStar(v, star0_)) return Refuse(OpRefusal::Boundary), false;
  // Checked at the position the mesh can store (float meshes round it).
  const CoordType stored = ToCoord(onSurface);
  const Point p = ToPoint(stored);

  NewStamp();
  oldFaces_.clear();
  newFaces_.clear();
  for (const auto& [f, z] : star0_) {
    faceStamp_[FIndex(*f)] = stamp_;
    oldFaces_.push_back(f);
  }
  for (const auto& [f, z] : star0_) {
    NewFace nf;
    for (int k = 0; k < 3; ++k) {
      nf.v[k] = f->V(k);
      nf.p[k] = k == z ? p : Pos(f->V(k));
      nf.foot[k] = k == z ? footFace : foot_[VIndex(*f->V(k))];
      nf.outside[k] = nullptr;
    }
    const int opposite = (z + 1) % 3;
    FacePointer g = f->FFp(opposite);
    if (g != f && faceStamp_[FIndex(*g)] != stamp_) nf.outside[opposite] = g;
    newFaces_.push_back(nf);
  }
  const OpRefusal r = CheckRegion();
  if (r != OpRefusal::None) return Refuse(r), false;

  v->P() = stored;
  foot_[vi] = footFace;
  for (std::size_t i = 0; i < star0_.size(); ++i)
    grid_.Update(FIndex(*star0_[i].first), FaceBox(*star0_[i].first));
  ++stats_.moves;
  lastRefusal_ = OpRefusal::None;
  return true;
}

// --- Edge split ----------------------------------------------------------------------------------

template <class MeshType>
typename MeshType::VertexPointer LocalRemeshingOps<MeshType>::SplitEdge(FacePointer f, int z) {
  if (HasPendingMoves()) VerifyPendingMoves();
  EnsureFree(1, 2, f);
  const bool border = IsBorder(*f, z);
  const VertexPointer v0 = f->V(z), v1 = f->V((z + 1) % 3), v2 = f->V((z + 2) % 3);
  if (locked_[VIndex(*v0)] && locked_[VIndex(*v1)]) return Refuse(OpRefusal::Locked), nullptr;
  FacePointer g = border ? nullptr : f->FFp(z);
  const int w = border ? -1 : f->FFi(z);
  const VertexPointer v3 = border ? nullptr : g->V((w + 2) % 3);
  if (!border && v3 == v2) return Refuse(OpRefusal::Topology), nullptr;

  const SurfaceProjection proj = ref_.Project((Pos(v0) + Pos(v1)) * 0.5, foot_[VIndex(*v0)], scratch_);
  if (!proj.ok()) return Refuse(OpRefusal::Degenerate), nullptr;
  const CoordType stored = ToCoord(proj.point);
  const Point p = ToPoint(stored);
  const VertexPointer nv = &m_.vert[freeVerts_.back()]; // identity only until applied

  NewStamp();
  oldFaces_.clear();
  newFaces_.clear();
  oldFaces_.push_back(f);
  faceStamp_[FIndex(*f)] = stamp_;
  if (!border) {
    oldFaces_.push_back(g);
    faceStamp_[FIndex(*g)] = stamp_;
  }
  auto make = [&](VertexPointer a, VertexPointer b, VertexPointer c, FacePointer outAB, FacePointer outBC,
                  FacePointer outCA) {
    NewFace nf;
    nf.v = {a, b, c};
    for (int k = 0; k < 3; ++k) {
      nf.p[k] = nf.v[k] == nv ? p : Pos(nf.v[k]);
      nf.foot[k] = nf.v[k] == nv ? proj.face : foot_[VIndex(*nf.v[k])];
    }
    nf.outside = {outAB, outBC, outCA};
    newFaces_.push_back(nf);
  };
  auto outside = [&](FacePointer face, int e) -> FacePointer {
    FacePointer o = face->FFp(e);
    return (o == face || faceStamp_[FIndex(*o)] == stamp_) ? nullptr : o;
  };
  make(v0, nv, v2, nullptr, nullptr, outside(f, (z + 2) % 3)); // f after the split
  make(nv, v1, v2, nullptr, outside(f, (z + 1) % 3), nullptr); // new face f2
  if (!border) {
    make(v1, nv, v3, nullptr, nullptr, outside(g, (w + 2) % 3)); // g after the split
    make(nv, v0, v3, nullptr, outside(g, (w + 1) % 3), nullptr); // new face g2
  }
  const OpRefusal r = CheckRegion();
  if (r != OpRefusal::None) return Refuse(r), nullptr;

  // Apply.
  const VertexPointer mv = TakeFreeVertex();
  mv->ImportData(*v0);
  mv->P() = stored;
  mv->VFp() = nullptr;
  mv->VFi() = -1;
  foot_[VIndex(*mv)] = proj.face;
  locked_[VIndex(*mv)] = 0;

  const int z1 = (z + 1) % 3;
  FacePointer fa = f->FFp(z1);
  const int ia = f->FFi(z1);
  const FacePointer f2 = TakeFreeFace();
  f2->ImportData(*f);
  vcg::face::VFDetach(*f, z1);
  f->V(z1) = mv;
  f2->V(0) = mv;
  f2->V(1) = v1;
  f2->V(2) = v2;
  f->FFp(z1) = f2;
  f->FFi(z1) = 2;
  f2->FFp(2) = f;
  f2->FFi(2) = z1;
  if (fa == f) {
    f2->FFp(1) = f2;
    f2->FFi(1) = 1;
  } else {
    f2->FFp(1) = fa;
    f2->FFi(1) = ia;
    fa->FFp(ia) = f2;
    fa->FFi(ia) = 1;
  }
  FacePointer g2 = nullptr;
  if (border) {
    f->FFp(z) = f;
    f->FFi(z) = z;
    f2->FFp(0) = f2;
    f2->FFi(0) = 0;
  } else {
    const int w1 = (w + 1) % 3;
    FacePointer gb = g->FFp(w1);
    const int ib = g->FFi(w1);
    g2 = TakeFreeFace();
    g2->ImportData(*g);
    vcg::face::VFDetach(*g, w1);
    g->V(w1) = mv;
    g2->V(0) = mv;
    g2->V(1) = v0;
    g2->V(2) = v3;
    g->FFp(w1) = g2;
    g->FFi(w1) = 2;
    g2->FFp(2) = g;
    g2->FFi(2) = w1;
    if (gb == g) {
      g2->FFp(1) = g2;
      g2->FFi(1) = 1;
    } else {
      g2->FFp(1) = gb;
      g2->FFi(1) = ib;
      gb->FFp(ib) = g2;
      gb->FFi(ib) = 1;
    }
    f->FFp(z) = g2;
    f->FFi(z) = 0;
    g2->FFp(0) = f;
    g2->FFi(0) = z;
    g->FFp(w) = f2;
    g->FFi(w) = 0;
    f2->FFp(0) = g;
    f2->FFi(0) = w;
  }
  VFAppend(f, z1);
  for (int k = 0; k < 3; ++k) VFAppend(f2, k);
  grid_.Update(FIndex(*f), FaceBox(*f));
  grid_.Insert(FIndex(*f2), FaceBox(*f2));
  if (!border) {
    VFAppend(g, (w + 1) % 3);
    for (int k = 0; k < 3; ++k) VFAppend(g2, k);
    grid_.Update(FIndex(*g), FaceBox(*g));
    grid_.Insert(FIndex(*g2), FaceBox(*g2));
  }
  ++stats_.splits;
  lastRefusal_ = OpRefusal::None;
  return mv;
}

// --- Edge collapse -------------------------------------------------------------------------------

template <class MeshType>
bool LocalRemeshingOps<MeshType>::CollapseEdge(FacePointer f, int z, double maxNewEdgeLength) {
  if (HasPendingMoves()) VerifyPendingMoves();
  const bool edgeBorder = IsBorder(*f, z);
  VertexPointer v0 = f->V(z), v1 = f->V((z + 1) % 3);
  const bool l0 = locked_[VIndex(*v0)] != 0, l1 = locked_[VIndex(*v1)] != 0;
  if (l0 && l1) return Refuse(OpRefusal::Locked), false;
  const bool b0 = IsBoundaryVertex(*v0), b1 = IsBoundaryVertex(*v1);
  const bool canRemove0 = !l0 && (!b0 || edgeBorder);
  const bool canRemove1 = !l1 && (!b1 || edgeBorder);
  if (!canRemove0 && !canRemove1) return Refuse((l0 || l1) ? OpRefusal::Locked : OpRefusal::Boundary), false;
  // Remove v0 and keep v1 when possible; the survivor moves only if it could have been removed too.
  const bool removeV0 = canRemove0;
  const bool survivorMoves = canRemove0 && canRemove1;
  VertexPointer vr = removeV0 ? v0 : v1;
  VertexPointer vk = removeV0 ? v1 : v0;

  // Cheap pre-test of the edge lengths around the midpoint (the exact test follows at the
  // projected position): most refused collapses stop here, before any star is gathered.
  if (maxNewEdgeLength < std::numeric_limits<double>::infinity()) {
    const Point q = survivorMoves ? (Pos(v0) + Pos(v1)) * 0.5 : Pos(vk);
    const double max2 = maxNewEdgeLength * maxNewEdgeLength;
    for (const VertexPointer u : {v0, v1})
      for (vcg::face::VFIterator<FaceType> it(u); !it.End(); ++it)
        for (const int j : {(it.I() + 1) % 3, (it.I() + 2) % 3})
          if ((Pos(it.F()->V(j)) - q).SquaredNorm() > max2) return Refuse(OpRefusal::EdgeLength), false;
  }
  GatherStar(vr, star0_); // star0_: star of the removed vertex
  GatherStar(vk, star1_);
  const auto& starR = star0_;
  const auto& starK = star1_;

  // Link condition.
  FacePointer g = edgeBorder ? nullptr : f->FFp(z);
  const int w = edgeBorder ? -1 : f->FFi(z);
  const VertexPointer vl = f->V((z + 2) % 3);
  const VertexPointer vrr = edgeBorder ? nullptr : g->V((w + 2) % 3);
  if (vl == vrr) return Refuse(OpRefusal::Topology), false;
  if (IsBorder(*f, (z + 1) % 3) && IsBorder(*f, (z + 2) % 3)) return Refuse(OpRefusal::Topology), false;
  if (!edgeBorder && IsBorder(*g, (w + 1) % 3) && IsBorder(*g, (w + 2) % 3))
    return Refuse(OpRefusal::Topology), false;
  for (const VertexPointer o : {vl, vrr})
    if (o != nullptr && !IsBoundaryVertex(*o) && Valence(*o) <= 3) return Refuse(OpRefusal::Topology), false;
  NewStamp();
  for (const auto& [face, k] : starR) {
    vertStamp_[VIndex(*face->V((k + 1) % 3))] = stamp_;
    vertStamp_[VIndex(*face->V((k + 2) % 3))] = stamp_;
  }
  for (const auto& [face, k] : starK)
    for (const int j : {(k + 1) % 3, (k + 2) % 3}) {
      const VertexPointer u = face->V(j);
      if (u != vl && u != vrr && u != vr && vertStamp_[VIndex(*u)] == stamp_)
        return Refuse(OpRefusal::Topology), false;
    }

  // Position of the survivor.
  Point p = Pos(vk);
  int footK = foot_[VIndex(*vk)];
  CoordType stored = vk->cP();
  if (survivorMoves) {
    const SurfaceProjection proj = ref_.Project((Pos(v0) + Pos(v1)) * 0.5, foot_[VIndex(*v0)], scratch_);
    if (!proj.ok()) return Refuse(OpRefusal::Degenerate), false;
    stored = ToCoord(proj.point);
    p = ToPoint(stored);
    footK = proj.face;
  }

  // The faces after the collapse: both stars minus f and g, vr replaced by vk at p.
  oldFaces_.clear();
  newFaces_.clear();
  for (const auto* star : {&starR, &starK})
    for (const auto& [face, k] : *star)
      if (faceStamp_[FIndex(*face)] != stamp_) {
        faceStamp_[FIndex(*face)] = stamp_;
        oldFaces_.push_back(face);
      }
  for (const auto* star : {&starR, &starK})
    for (const auto& [face, k] : *star) {
      if (face == f || face == g) continue;
      NewFace nf;
      for (int j = 0; j < 3; ++j) {
        const VertexPointer u = face->V(j);
        const bool moved = u == vr || u == vk;
        nf.v[j] = moved ? vk : u;
        nf.p[j] = moved ? p : Pos(u);
        nf.foot[j] = moved ? footK : foot_[VIndex(*u)];
        nf.outside[j] = nullptr;
      }
      const int opposite = (k + 1) % 3;
      FacePointer o = face->FFp(opposite);
      if (o != face && faceStamp_[FIndex(*o)] != stamp_) nf.outside[opposite] = o;
      newFaces_.push_back(nf);
    }
  const OpRefusal r = CheckRegion(maxNewEdgeLength, vk);
  if (r != OpRefusal::None) return Refuse(r), false;

  // Apply: glue the faces around f and g, then move vr's faces to vk.
  auto glue = [](FacePointer face, int e) {
    FacePointer a = face->FFp((e + 1) % 3);
    const int ia = face->FFi((e + 1) % 3);
    FacePointer b = face->FFp((e + 2) % 3);
    const int ib = face->FFi((e + 2) % 3);
    const bool aBorder = a == face, bBorder = b == face;
    if (!aBorder && !bBorder) {
      a->FFp(ia) = b;
      a->FFi(ia) = ib;
      b->FFp(ib) = a;
      b->FFi(ib) = ia;
    } else if (aBorder) {
      b->FFp(ib) = b;
      b->FFi(ib) = ib;
    } else {
      a->FFp(ia) = a;
      a->FFi(ia) = ia;
    }
  };
  glue(f, z);
  if (g != nullptr) glue(g, w);
  vcg::face::VFDetach(*f);
  if (g != nullptr) vcg::face::VFDetach(*g);
  for (const auto& [face, k] : starR) {
    if (face == f || face == g) continue;
    vcg::face::VFDetach(*face, k);
    face->V(k) = vk;
    VFAppend(face, k);
  }
  Release(*f);
  if (g != nullptr) Release(*g);
  Release(*vr);
  vk->P() = stored;
  foot_[VIndex(*vk)] = footK;
  for (const FacePointer face : oldFaces_)
    if (!face->IsD()) grid_.Update(FIndex(*face), FaceBox(*face));
  ++stats_.collapses;
  lastRefusal_ = OpRefusal::None;
  return true;
}

// --- Edge flip -----------------------------------------------------------------------------------

template <class MeshType>
bool LocalRemeshingOps<MeshType>::FlipEdge(FacePointer f, int z) {
  if (HasPendingMoves()) VerifyPendingMoves();
  if (IsBorder(*f, z)) return Refuse(OpRefusal::Boundary), false;
  FacePointer g = f->FFp(z);
  const int w = f->FFi(z);
  const VertexPointer v0 = f->V(z), v1 = f->V((z + 1) % 3), v2 = f->V((z + 2) % 3), v3 = g->V((w + 2) % 3);
  if ((locked_[VIndex(*v0)] && locked_[VIndex(*v1)]) || (locked_[VIndex(*v2)] && locked_[VIndex(*v3)]))
    return Refuse(OpRefusal::Locked), false;
  if (v2 == v3) return Refuse(OpRefusal::Topology), false;
  for (const VertexPointer u : {v0, v1})
    if (Valence(*u) <= (IsBoundaryVertex(*u) ? 2 : 3)) return Refuse(OpRefusal::Topology), false;
  for (vcg::face::VFIterator<FaceType> it(v2); !it.End(); ++it)
    if (it.F()->V((it.I() + 1) % 3) == v3 || it.F()->V((it.I() + 2) % 3) == v3)
      return Refuse(OpRefusal::Topology), false;

  NewStamp();
  faceStamp_[FIndex(*f)] = stamp_;
  faceStamp_[FIndex(*g)] = stamp_;
  oldFaces_.clear();
  oldFaces_.push_back(f);
  oldFaces_.push_back(g);
  newFaces_.clear();
  auto outside = [&](FacePointer face, int e) -> FacePointer {
    FacePointer o = face->FFp(e);
    return (o == face || faceStamp_[FIndex(*o)] == stamp_) ? nullptr : o;
  };
  auto make = [&](VertexPointer a, VertexPointer b, VertexPointer c, FacePointer outAB, FacePointer outBC,
                  FacePointer outCA) {
    NewFace nf;
    nf.v = {a, b, c};
    for (int k = 0; k < 3; ++k) {
      nf.p[k] = Pos(nf.v[k]);
      nf.foot[k] = foot_[VIndex(*nf.v[k])];
    }
    nf.outside = {outAB, outBC, outCA};
    newFaces_.push_back(nf);
  };
  make(v0, v3, v2, outside(g, (w + 1) % 3), nullptr, outside(f, (z + 2) % 3));
  make(v1, v2, v3, outside(f, (z + 1) % 3), nullptr, outside(g, (w + 2) % 3));
  const OpRefusal r = CheckRegion();
  if (r != OpRefusal::None) return Refuse(r), false;

  const int z1 = (z + 1) % 3, w1 = (w + 1) % 3;
  FacePointer fa = f->FFp(z1);
  const int ia = f->FFi(z1);
  FacePointer gb = g->FFp(w1);
  const int ib = g->FFi(w1);
  vcg::face::VFDetach(*f, z1); // v1 leaves f
  vcg::face::VFDetach(*g, w1); // v0 leaves g
  f->V(z1) = v3;
  g->V(w1) = v2;
  // f = (v0, v3, v2): edge z = (v0, v3) takes g's old (v0, v3) neighbour.
  if (gb == g) {
    f->FFp(z) = f;
    f->FFi(z) = z;
  } else {
    f->FFp(z) = gb;
    f->FFi(z) = ib;
    gb->FFp(ib) = f;
    gb->FFi(ib) = z;
  }
  // g = (v1, v2, v3): edge w = (v1, v2) takes f's old (v1, v2) neighbour.
  if (fa == f) {
    g->FFp(w) = g;
    g->FFi(w) = w;
  } else {
    g->FFp(w) = fa;
    g->FFi(w) = ia;
    fa->FFp(ia) = g;
    fa->FFi(ia) = w;
  }
  f->FFp(z1) = g;
  f->FFi(z1) = w1;
  g->FFp(w1) = f;
  g->FFi(w1) = z1;
  VFAppend(f, z1);
  VFAppend(g, w1);
  grid_.Update(FIndex(*f), FaceBox(*f));
  grid_.Update(FIndex(*g), FaceBox(*g));
  ++stats_.flips;
  lastRefusal_ = OpRefusal::None;
  return true;
}

// --- Disk replacement ----------------------------------------------------------------------------

template <class MeshType>
bool LocalRemeshingOps<MeshType>::DiskBoundary(const std::vector<FacePointer>& region,
                                               std::vector<VertexPointer>& loop,
                                               std::vector<VertexPointer>& interior) {
  loop.clear();
  interior.clear();
  if (region.empty()) return Refuse(OpRefusal::Topology), false;
  NewStamp();
  for (const FacePointer f : region) {
    if (f->IsD() || faceStamp_[FIndex(*f)] == stamp_) return Refuse(OpRefusal::Topology), false;
    faceStamp_[FIndex(*f)] = stamp_;
  }
  // Boundary edges: region edges whose other side is outside the region. vertStamp_ marks the
  // start vertex of a boundary edge; next_ holds its end (one outgoing edge per vertex allowed).
  std::vector<std::pair<VertexPointer, VertexPointer>>& edges = loopEdges_;
  edges.clear();
  for (const FacePointer f : region)
    for (int e = 0; e < 3; ++e) {
      if (IsBorder(*f, e)) return Refuse(OpRefusal::Boundary), false;
      if (faceStamp_[FIndex(*f->FFp(e))] != stamp_) edges.emplace_back(f->V(e), f->V((e + 1) % 3));
    }
  if (edges.size() < 3) return Refuse(OpRefusal::Topology), false;
  for (const auto& [a, b] : edges) {
    if (vertStamp_[VIndex(*a)] == stamp_) return Refuse(OpRefusal::Topology), false; // pinched loop
    vertStamp_[VIndex(*a)] = stamp_;
  }
  // Walk the loop (edges are few: a linear search per step is cheapest).
  loop.push_back(edges[0].first);
  VertexPointer cur = edges[0].second;
  while (cur != loop.front()) {
    if (loop.size() > edges.size()) return Refuse(OpRefusal::Topology), false;
    loop.push_back(cur);
    const auto it = std::find_if(edges.begin(), edges.end(), [&](const auto& ab) { return ab.first == cur; });
    if (it == edges.end()) return Refuse(OpRefusal::Topology), false;
    cur = it->second;
  }
  if (loop.size() != edges.size()) return Refuse(OpRefusal::Topology), false; // several loops
  // Interior vertices: on region faces, not on the loop; all their faces must be region faces.
  for (const FacePointer f : region)
    for (int k = 0; k < 3; ++k) {
      const VertexPointer u = f->V(k);
      if (vertStamp_[VIndex(*u)] == stamp_) continue;
      vertStamp_[VIndex(*u)] = stamp_;
      for (vcg::face::VFIterator<FaceType> it(u); !it.End(); ++it)
        if (faceStamp_[FIndex(*it.F())] != stamp_) return Refuse(OpRefusal::Topology), false;
      interior.push_back(u);
    }
  // Euler characteristic of a disk: V - E + F = 1.
  const long V = long(loop.size() + interior.size()), F = long(region.size());
  const long E = (3 * F + long(loop.size())) / 2;
  if (V - E + F != 1) return Refuse(OpRefusal::Topology), false;
  return true;
}

template <class MeshType>
bool LocalRemeshingOps<MeshType>::ReplaceDisk(const std::vector<FacePointer>& regionIn,
                                              const std::vector<VertexPointer>& loopIn,
                                              const std::vector<Point>& newPoints,
                                              const std::vector<std::array<int, 3>>& triangles,
                                              std::vector<VertexPointer>* created) {
  if (HasPendingMoves()) VerifyPendingMoves();
  if (created) created->clear();
  const std::size_t n = loopIn.size(), k = newPoints.size(), total = n + k;
  if (triangles.empty()) return Refuse(OpRefusal::Topology), false;
  // Element pointers may move when room is made: work on indices across EnsureFree.
  std::vector<std::size_t> regionIdx, loopIdx;
  for (const FacePointer f : regionIn) regionIdx.push_back(FIndex(*f));
  for (const VertexPointer v : loopIn) loopIdx.push_back(VIndex(*v));
  FacePointer any = regionIn.empty() ? nullptr : regionIn.front();
  if (any == nullptr) return Refuse(OpRefusal::Topology), false;
  EnsureFree(k, triangles.size(), any);
  std::vector<FacePointer> region;
  std::vector<VertexPointer> loop, interior;
  for (const std::size_t i : regionIdx) region.push_back(&m_.face[i]);
  for (const std::size_t i : loopIdx) loop.push_back(&m_.vert[i]);

  std::vector<VertexPointer> checkLoop;
  if (!DiskBoundary(region, checkLoop, interior)) return false;
  if (checkLoop.size() != n) return Refuse(OpRefusal::Topology), false;
  {
    const auto it = std::find(checkLoop.begin(), checkLoop.end(), loop[0]);
    if (it == checkLoop.end()) return Refuse(OpRefusal::Topology), false;
    std::rotate(checkLoop.begin(), it, checkLoop.end());
    if (checkLoop != loop) return Refuse(OpRefusal::Topology), false;
  }
  for (const VertexPointer u : interior)
    if (locked_[VIndex(*u)]) return Refuse(OpRefusal::Locked), false;

  // The triangulation must cover the disk once: loop edges once in loop direction, inner edges
  // once in each direction, no inner edge along the loop reversed, every index in range.
  std::vector<std::pair<int, int>> directed;
  for (const auto& t : triangles)
    for (int e = 0; e < 3; ++e) {
      const int a = t[e], b = t[(e + 1) % 3];
      if (a < 0 || b < 0 || std::size_t(a) >= total || std::size_t(b) >= total || a == b)
        return Refuse(OpRefusal::Topology), false;
      directed.emplace_back(a, b);
    }
  std::sort(directed.begin(), directed.end());
  if (std::adjacent_find(directed.begin(), directed.end()) != directed.end())
    return Refuse(OpRefusal::Topology), false;
  auto hasDirected = [&](int a, int b) {
    return std::binary_search(directed.begin(), directed.end(), std::make_pair(a, b));
  };
  auto isLoopEdge = [&](int a, int b) { return a < int(n) && b < int(n) && (a + 1) % int(n) == b; };
  for (const auto& [a, b] : directed) {
    if (isLoopEdge(a, b)) continue;
    if (isLoopEdge(b, a) || !hasDirected(b, a)) return Refuse(OpRefusal::Topology), false;
  }
  for (int i = 0; i < int(n); ++i)
    if (!hasDirected(i, (i + 1) % int(n))) return Refuse(OpRefusal::Topology), false;
  for (std::size_t j = 0; j < k; ++j) // every new vertex is used
    if (std::none_of(directed.begin(), directed.end(),
                     [&](const auto& ab) { return ab.first == int(n + j); }))
      return Refuse(OpRefusal::Topology), false;
  // New chords between loop vertices must not exist outside the region, nor join two locked ones.
  for (const auto& [a, b] : directed) {
    if (a >= int(n) || b >= int(n) || a > b || isLoopEdge(a, b) || isLoopEdge(b, a)) continue;
    if (locked_[VIndex(*loop[a])] && locked_[VIndex(*loop[b])]) return Refuse(OpRefusal::Locked), false;
    for (vcg::face::VFIterator<FaceType> it(loop[a]); !it.End(); ++it) {
      if (faceStamp_[FIndex(*it.F())] == stamp_) continue;
      if (it.F()->V((it.I() + 1) % 3) == loop[b] || it.F()->V((it.I() + 2) % 3) == loop[b])
        return Refuse(OpRefusal::Topology), false;
    }
  }

  // New vertices on the reference, near the closest loop vertex.
  std::vector<Point> pos(total);
  std::vector<int> feet(total);
  std::vector<CoordType> stored(k);
  for (std::size_t i = 0; i < n; ++i) {
    pos[i] = Pos(loop[i]);
    feet[i] = foot_[VIndex(*loop[i])];
  }
  for (std::size_t j = 0; j < k; ++j) {
    std::size_t nearest = 0;
    for (std::size_t i = 1; i < n; ++i)
      if ((pos[i] - newPoints[j]).SquaredNorm() < (pos[nearest] - newPoints[j]).SquaredNorm()) nearest = i;
    const SurfaceProjection proj = ref_.Project(newPoints[j], feet[nearest], scratch_);
    if (!proj.ok()) return Refuse(OpRefusal::Degenerate), false;
    stored[j] = ToCoord(proj.point);
    pos[n + j] = ToPoint(stored[j]);
    feet[n + j] = proj.face;
  }
  // Identities for the new vertices until they exist: the free slots they will take.
  std::vector<VertexPointer> vid(total);
  for (std::size_t i = 0; i < n; ++i) vid[i] = loop[i];
  for (std::size_t j = 0; j < k; ++j) vid[n + j] = &m_.vert[freeVerts_[freeVerts_.size() - 1 - j]];

  // Outside neighbours of the loop edges.
  std::vector<FacePointer> outFace(n, nullptr);
  std::vector<int> outIndex(n, -1);
  for (const FacePointer f : region)
    for (int e = 0; e < 3; ++e) {
      const FacePointer o = f->FFp(e);
      if (faceStamp_[FIndex(*o)] == stamp_) continue;
      const std::size_t i = std::size_t(std::find(loop.begin(), loop.end(), f->V(e)) - loop.begin());
      outFace[i] = o;
      outIndex[i] = f->FFi(e);
    }
  oldFaces_ = region;
  newFaces_.clear();
  for (const auto& t : triangles) {
    NewFace nf;
    for (int c = 0; c < 3; ++c) {
      nf.v[c] = vid[t[c]];
      nf.p[c] = pos[t[c]];
      nf.foot[c] = feet[t[c]];
      nf.outside[c] = isLoopEdge(t[c], t[(c + 1) % 3]) ? outFace[t[c]] : nullptr;
    }
    newFaces_.push_back(nf);
  }
  const OpRefusal r = CheckRegion();
  if (r != OpRefusal::None) return Refuse(r), false;

  // Apply: new vertices, new faces (their data from a region face), then drop the old ones.
  for (std::size_t j = 0; j < k; ++j) {
    const VertexPointer v = TakeFreeVertex();
    v->ImportData(*loop[0]);
    v->P() = stored[j];
    v->VFp() = nullptr;
    v->VFi() = -1;
    foot_[VIndex(*v)] = feet[n + j];
    locked_[VIndex(*v)] = 0;
    if (created) created->push_back(v);
  }
  std::vector<FacePointer> made;
  for (std::size_t t = 0; t < triangles.size(); ++t) {
    const FacePointer f = TakeFreeFace();
    f->ImportData(*region[0]);
    f->ClearD();
    for (int c = 0; c < 3; ++c) f->V(c) = vid[triangles[t][c]];
    made.push_back(f);
  }
  for (const FacePointer f : region)
    for (int c = 0; c < 3; ++c) vcg::face::VFDetach(*f, c);
  for (const FacePointer f : region) Release(*f);
  for (const VertexPointer u : interior) Release(*u);
  for (std::size_t t = 0; t < made.size(); ++t) {
    const FacePointer f = made[t];
    for (int c = 0; c < 3; ++c) {
      const int a = triangles[t][c], b = triangles[t][(c + 1) % 3];
      if (isLoopEdge(a, b)) {
        f->FFp(c) = outFace[a];
        f->FFi(c) = outIndex[a];
        outFace[a]->FFp(outIndex[a]) = f;
        outFace[a]->FFi(outIndex[a]) = c;
        continue;
      }
      const int s = newFaces_[t].internal[c];
      const FacePointer g = made[s];
      for (int d = 0; d < 3; ++d)
        if (triangles[s][d] == b && triangles[s][(d + 1) % 3] == a) {
          f->FFp(c) = g;
          f->FFi(c) = d;
        }
    }
  }
  for (const FacePointer f : made) {
    for (int c = 0; c < 3; ++c) VFAppend(f, c);
    grid_.Insert(FIndex(*f), FaceBox(*f));
  }
  ++stats_.replacements;
  lastRefusal_ = OpRefusal::None;
  return true;
}

} // namespace molremesh

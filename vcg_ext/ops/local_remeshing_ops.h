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
//
// Layout: this header declares the class; its member definitions live in one header per concern
// (local_ops_setup.h, local_ops_element_pool.h, local_ops_queries.h, local_ops_checks.h,
// local_ops_batch_moves.h, local_ops_relocate.h, local_ops_edge_split.h, local_ops_edge_collapse.h,
// local_ops_edge_flip.h, local_ops_replace_disk.h), included at the end. It stays one class of
// more than 600 lines in all because every operation reads and writes the same transactional
// state: the free lists, the stamps, the per-vertex footpoints and locks, the intersection grid,
// the pending batch and the faces under check; split into components they would all share it.
#pragma once

#include <vcg/complex/complex.h>

#include <vcg_ext/geometry/point.h>
#include <vcg_ext/ops/local_ops_guards.h>
#include <vcg_ext/ops/local_ops_predicates.h>
#include <vcg_ext/topology/face_face_topology.h>
#include <vcg_ext/spatial/face_hash_grid.h>
#include <vcg_ext/geometry/triangle_intersection.h>
#include <vcg_ext/quality/mesh_quality.h>
#include <vcg_ext/core/element_capacity.h>
#include <vcg_ext/core/vector_growth.h>
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

template <class MeshType>
class LocalRemeshingOps {
public:
  using VertexType = typename MeshType::VertexType;
  using FaceType = typename MeshType::FaceType;
  using VertexPointer = typename MeshType::VertexPointer;
  using FacePointer = typename MeshType::FacePointer;
  using CoordType = typename MeshType::CoordType;
  using ScalarType = typename MeshType::ScalarType;
  using Point = molremesh::Point;
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

  static Point ToPoint(const CoordType& c) { return molremesh::ToPoint(c); }
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
  // Steps of CollapseEdge.
  /// Makes the two neighbours of `face` across its sides other than e neighbours of each other
  /// (or border sides when one of them is a border), before `face` is dropped.
  static void GlueAcross(FacePointer face, int e);
  /// Applies a checked collapse of edge z of f (g, w: the other side, or nullptr): f and g are
  /// dropped, the faces of the removed vertex vr's star (star0_) move to vk, which goes to stored.
  void ApplyCollapse(FacePointer f, int z, FacePointer g, int w, VertexPointer vr, VertexPointer vk,
                     const CoordType& stored, int footK);
  /// Step of SplitEdge: f = (a, b, c) with edge z = (a, b) becomes (a, mv, c) and the new face
  /// (mv, b, c) it returns takes its other part, linked to f (side 2) and to f's old neighbour
  /// across (b, c) (side 1); side 0 is left to the caller.
  FacePointer SplitOffFace(FacePointer f, int z, VertexPointer mv, VertexPointer b, VertexPointer c);
  // Steps of ReplaceDisk.
  static bool IsLoopEdge(int a, int b, std::size_t n) {
    return a < int(n) && b < int(n) && (a + 1) % int(n) == b;
  }
  /// Whether `triangles` (indices into the loop, then the new vertices; `total` in all) cover the
  /// disk inside `loop` once, without a chord that exists outside the region (faceStamp_) or joins
  /// two locked vertices; the refusal reason otherwise.
  OpRefusal CheckDiskTriangulation(const std::vector<VertexPointer>& loop,
                                   const std::vector<std::array<int, 3>>& triangles, std::size_t total) const;
  /// Positions and footpoints of the loop vertices and of the new vertices projected on the
  /// reference from the nearest loop vertex's footpoint (stored: their coordinates); false when a
  /// projection fails.
  bool PlaceDiskVertices(const std::vector<VertexPointer>& loop, const std::vector<Point>& newPoints,
                         std::vector<Point>& pos, std::vector<int>& feet, std::vector<CoordType>& stored);
  /// Creates the new vertices and faces of a checked replacement, links them to the outside
  /// neighbours of the loop edges and to each other, and drops the region and its interior vertices.
  void ApplyDiskReplacement(const std::vector<FacePointer>& region,
                            const std::vector<VertexPointer>& interior,
                            const std::vector<VertexPointer>& loop, const std::vector<VertexPointer>& vid,
                            const std::vector<CoordType>& stored, const std::vector<int>& feet,
                            const std::vector<std::array<int, 3>>& triangles,
                            const std::vector<FacePointer>& outFace, const std::vector<int>& outIndex,
                            std::vector<VertexPointer>* created);
  // Steps of VerifyPendingMoves.
  /// dirty_ = the faces of the stars of `vertices`, in increasing index order.
  void CollectStarFaces(const std::vector<std::uint32_t>& vertices);
  /// dirty_ = the faces a moved vertex of the batch touches, in increasing index order.
  void CollectBatchFaces(int threads);
  /// The grid boxes of the faces in dirty_: those that stay in their cells in parallel, the others in order.
  void UpdateDirtyBoxes(int threads);
  /// Builds scan_ over the current faces (positions, live and moved flags).
  void BuildBatchScan(int threads);
  /// scanPairs_ = the intersecting pairs the sweep finds: pairs without a common vertex through
  /// scan_, pairs sharing one vertex star by star; sorted, without repetition.
  void FindBatchScanPairs(int threads);
  /// Puts back the batch vertices of the failing faces (verdicts_, scanPairs_) at their last
  /// verified position; `reverted` = those vertices.
  void RevertFailingFaces(std::vector<std::uint32_t>& reverted);
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

} // namespace molremesh

// Member definitions, one concern per header.
#include <vcg_ext/ops/local_ops_setup.h>
#include <vcg_ext/ops/local_ops_element_pool.h>
#include <vcg_ext/ops/local_ops_queries.h>
#include <vcg_ext/ops/local_ops_checks.h>
#include <vcg_ext/ops/local_ops_batch_moves.h>
#include <vcg_ext/ops/local_ops_relocate.h>
#include <vcg_ext/ops/local_ops_edge_split.h>
#include <vcg_ext/ops/local_ops_edge_collapse.h>
#include <vcg_ext/ops/local_ops_edge_flip.h>
#include <vcg_ext/ops/local_ops_replace_disk.h>

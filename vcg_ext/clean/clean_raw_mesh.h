// Stage 0 of molremesh: clean a raw molecular surface mesh so that the remeshing stages start from
// a valid 2-manifold (SMOPT-style cleaning, done with local, checked edits).
//
// CleanRawMesh<MeshType>::Do(m, params, cb) runs, in this order (the order matters: each step relies
// on what the previous ones guarantee):
//   1. merge vertices closer than params.mergeTolerance * mean edge length (the surviving vertex keeps
//      its position; nothing moves), drop faces with a repeated vertex index, duplicate faces (same
//      vertex set) and unreferenced vertices;
//   2. make every edge manifold by removing, on each edge with k > 2 faces, the k - 2 faces that do not
//      belong to the flattest consistently oriented pair (the holes this leaves are closed later);
//   3. orient every component coherently (the majority orientation of the input wins);
//   4. remove zero-area faces without opening a hole: a "cap" (a vertex lying on the opposite edge)
//      is removed by flipping that edge, which leaves the surface geometrically unchanged; a "needle"
//      (a vanishing edge) by collapsing that edge onto one of its end points (link condition, no
//      normal flip); a zero-area face on the boundary is simply dropped when that cannot pinch a vertex;
//   5. split non-manifold vertices that join closed fans (two surfaces touching at a point);
//      boundary "pinch" vertices (a hole boundary passing twice through a vertex) are left to step 8,
//      which closes them into a single manifold fan;
//   6. remove connected components with fewer than params.minComponentFraction of the faces (never
//      the largest one). Then a split copy and its original that both kept faces would touch (a
//      self-intersection): the copy's fan (or else the original's) is removed and its hole refilled
//      without the vertex; if that is impossible, the copy is moved by 1% of the way into its own fan
//      (vcglib's moveThreshold idea) when that is valid;
//   7. with params.repairTangles, repair local tangles: first the faces of self-intersecting pairs,
//      then the faces where the orientation cannot be made coherent (re-orienting after each repair,
//      since the traversal's other seams vanish with the real defect). A tangle (plus up to
//      params.maxRepairGrowth rings around it) is removed and its hole refilled; the repair is kept
//      only when every refill is valid, otherwise the faces are restored, so a repair never opens a
//      hole, never adds an intersection and never leaves a non-manifold vertex;
//   8. close every hole whose boundary loop has at most params.maxHoleEdges edges with a minimum-
//      weight triangulation (Liepa 2003: minimize the largest dihedral angle, then maximize the
//      smallest triangle angle, then minimize the area; O(n^3) per loop). A loop that passes several
//      times through a vertex is cut there into simple loops, each filled on its own. Every fill
//      triangle is checked before anything is added: no existing edge is duplicated, no face becomes
//      duplicate, no fold beyond params.maxFillDihedral, and it intersects no face of the mesh nor
//      another fill triangle (the closed-triangle test of MeshQuality's self-intersection count). A
//      triangle that fails is forbidden and the triangulation recomputed; a loop that cannot be
//      filled so (a twisted marching-cubes slit) is grown instead: its boundary faces, and up to
//      params.maxRepairGrowth rings around them, are removed and the larger hole is refilled as a
//      tangle is (kept only when valid); a loop that still cannot be filled stays open and is counted.
//      vcglib's Hole<> is not used: its ear cutting needs vertex normals, can leave a hole half filled, and
//      checks intersections only against the faces around the hole, not against a nearby sheet;
//   9. split any vertex that is still non-manifold (next to an unfilled hole, or where two separate
//      loops met at a vertex) and separate the copies as in step 6;
//  10. orient every closed component outward: positive volume, except, with
//      params.orientCavitiesInward, components nested inside an odd number of other components
//      (cavities of a molecular surface), whose normals point into the cavity (negative volume), as
//      PyMOL writes them;
//  11. delete vertices left without faces, compact the vectors, measure the result (MeshQuality).
// Every action is counted in the returned CleanRawMeshResult; nothing is removed silently.
//
// Contract
//  - Refusals happen before the mesh is touched: an empty mesh, a point cloud, NaN/Inf coordinates
//    (molremesh::CheckTriangleMeshInput), a face referencing a missing vertex, a mesh whose faces are
//    all degenerate, invalid parameters, or FF/VF adjacency not enabled give ok == false, a one-line
//    message and an unchanged mesh.
//  - Requires: per-vertex and per-face BitFlags (always present in vcglib meshes), FF and VF adjacency
//    enabled (MeshLab: updateDataMask(MM_FACEFACETOPO | MM_VERTFACETOPO)). The adjacency need not be
//    up to date: it is recomputed with vcg::tri::UpdateTopology. Only generic vcglib API is used, so it
//    compiles for molremesh::MeshD (double) and MeshLab's CMeshO (float, optional components).
//  - On return (ok or not, once started) the mesh is compact (no deleted elements) and FF/VF adjacency
//    is up to date. Face and vertex normals are NOT recomputed: call vcg::tri::UpdateNormal afterwards.
//    Faces added by the hole filling have default attributes (color, quality); split vertices copy the
//    attributes of the vertex they were split from. Selection, visited and user flags are not used.
//  - cb reports progress only; its return value is ignored (a half-done cleaning is not offered).
//  - The triangle/triangle predicates are MeshQuality's (TrianglesIntersect,
//    SharedCornerOverlap), so "no self-intersection" means the same here and in the quality report.
//  - Vertices that are already fine never move: merging keeps the surviving vertex's position, a
//    collapse keeps one end point in place, splits create copies at the same position. The only
//    vertices ever moved are split copies that cannot be separated otherwise (movedSplitVertices).
//  - Geometry is evaluated in double precision whatever the mesh's scalar type.
#pragma once

// complex.h first: vcglib's algorithm headers rely on it being included before them.
#include <vcg/complex/complex.h>
#include <vcg/complex/algorithms/update/topology.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <iterator>
#include <limits>
#include <memory>
#include <numeric>
#include <optional>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include <vcg_ext/topology/face_face_topology.h>
#include <vcg_ext/core/input_check.h>
#include <vcg_ext/quality/mesh_quality.h>
#include <vcg_ext/core/parallel_for.h>
#include <vcg_ext/geometry/mean_edge_length.h>
#include <vcg_ext/geometry/point.h>
#include <vcg_ext/core/index.h>
#include <vcg_ext/spatial/self_intersections.h>
#include <vcg_ext/spatial/static_face_grid.h>
#include <vcg_ext/clean/hole_triangulation.h>

namespace molremesh {

/// What CleanRawMesh did. Counts are of elements, in the order of the steps.
struct CleanRawMeshResult {
  bool ok = true; ///< false when the input was refused (then the mesh is unchanged) or on an internal error
  std::string message; ///< why it was refused; empty when ok

  // Before / after (MeshQuality figures of the input and of the result)
  std::size_t verticesBefore = 0, verticesAfter = 0;
  std::size_t facesBefore = 0, facesAfter = 0;
  double areaBefore = 0, areaAfter = 0;     ///< total surface area
  double volumeBefore = 0, volumeAfter = 0; ///< signed enclosed volume

  // Steps 1 and 4: vertices and trivially bad faces
  std::size_t mergedVertices = 0;              ///< vertices merged into a coincident one
  std::size_t removedUnreferencedVertices = 0; ///< vertices no face used in the input
  std::size_t removedDuplicateFaces = 0;       ///< faces with the same vertex set as an earlier face
  std::size_t removedDegenerateFaces = 0;      ///< repeated vertex index, or zero area removed by a collapse
  std::size_t flippedDegenerateFaces = 0;      ///< zero-area faces made proper by flipping their longest edge
  std::size_t collapsedDegenerateEdges = 0;    ///< vanishing edges of zero-area faces collapsed
  std::size_t remainingDegenerateFaces = 0;    ///< zero-area faces no safe edit could remove (left in place)
  // Steps 2, 5 and 9: manifoldness
  std::size_t removedNonManifoldFaces = 0;  ///< faces removed to make non-manifold edges manifold
  std::size_t splitNonManifoldVertices = 0; ///< vertex copies created by splitting non-manifold vertices
  std::size_t retriangulatedPinchFans =
      0; ///< copies whose fan was removed and refilled so the two no longer touch
  std::size_t pinchFanFacesRemoved = 0, pinchFanFacesAdded = 0; ///< faces of those retriangulations
  std::size_t movedSplitVertices =
      0; ///< copies moved by 1% into their own fan instead (no valid retriangulation)
  std::size_t touchingSplitVertices = 0; ///< copies left touching their original (neither worked)
  // Steps 3 and 10: orientation
  std::size_t flippedFacesForOrientation = 0; ///< input faces whose orientation was reversed
  std::size_t flippedComponents = 0;          ///< closed components turned outward (included above)
  std::size_t nonOrientableComponents = 0;    ///< components that cannot be oriented (left as they are)
  // Steps 6 and 7: components and self-intersections
  std::size_t removedSmallComponents = 0; ///< components below minComponentFraction
  std::size_t removedComponentFaces = 0;  ///< their faces
  std::size_t repairedTangles =
      0; ///< tangles (intersecting or incoherently oriented faces) removed and refilled
  std::size_t unrepairedTangles = 0; ///< tangles left as they are: intersecting regions with no valid refill,
                                     ///< plus one per component left non-orientable
  std::size_t tangleFacesRemoved = 0, tangleFacesAdded = 0; ///< faces removed and added by those repairs
  // Step 8: holes
  std::size_t closedHoles = 0;              ///< boundary loops filled
  std::size_t holeFacesAdded = 0;           ///< faces added to fill them
  std::size_t grownHoles = 0;               ///< of the closed holes, those grown first (see FillHoles)
  std::size_t holeFacesRemoved = 0;         ///< faces removed around them
  std::size_t unfilledHoles = 0;            ///< boundary loops left open (too long, or no valid fill)
  std::size_t largestUnfilledHoleEdges = 0; ///< edges of the longest loop left open
  // Step 11
  std::size_t removedOrphanedVertices = 0; ///< vertices left without faces by the removals above

  // Self-intersecting faces (MeshQuality's count: pairs sharing no vertex that meet, or sharing one
  // vertex and meeting elsewhere), measured when params.measureSelfIntersections.
  bool selfIntersectionsMeasured = false;
  std::size_t selfIntersectingFacesBefore = 0, selfIntersectingFacesAfter = 0;

  // Validity of the result (MeshQuality)
  std::size_t boundaryEdgesAfter = 0, nonManifoldEdgesAfter = 0, nonManifoldVerticesAfter = 0;
  std::size_t degenerateFacesAfter = 0, componentsAfter = 0;
  int genusAfter = -1;
  /// The whole report of the result the figures above come from (MeshQuality with the cleaning's
  /// degenerateAreaEpsilon and thread count; self-intersections when measureSelfIntersections).
  QualityReport reportAfter;
};

template <class MeshType>
class CleanRawMesh {
public:
  using Result = CleanRawMeshResult;

  struct Params {
    double mergeTolerance =
        1e-6; ///< merge vertices closer than this * mean edge length (0: exact copies only)
    double degenerateAreaEpsilon =
        1e-12; ///< zero-area face: area <= this * (mean edge length)^2 (MeshQuality's definition)
    int maxHoleEdges = 100; ///< close boundary loops with at most this many edges (1UBQ EDTSurf's crack: 29)
    double minComponentFraction =
        0.01; ///< remove components with fewer than this fraction of the faces (not the largest)
    bool repairTangles = true;      ///< remove and refill local tangles (self-intersecting faces, orientation
                                    ///< conflicts); a repair is kept only if its refill is valid
    int maxRepairGrowth = 2;        ///< rings of faces added around a tangle when its first refill fails
    int maxRepairRegionFaces = 200; ///< larger tangles are left alone
    int maxRepairAttempts = 64; ///< remove-and-refill attempts in all (each rebuilds the adjacency, O(faces))
    bool orientCavitiesInward =
        true; ///< cavity components (nested in another closed one) get negative volume
    bool measureSelfIntersections =
        true; ///< count self-intersecting faces before and after (grid accelerated)
    double maxFillDihedral =
        150.0;       ///< degrees; a fill triangle never folds more than this against a neighbour
    int threads = 0; ///< worker threads of the tangle search and the before/after
                     ///< measurements; 0 = all cores (same result)
  };

  /// Cleans m in place; see the file comment for the steps, the preconditions and the guarantees.
  /// Never throws: internal errors (e.g. out of memory) are reported as ok == false.
  static Result Do(MeshType& m, const Params& params = Params(), vcg::CallBackPos* cb = nullptr) {
    Result r;
    if (!Refuse(m, params, r)) return r;
    try {
      Run(m, params, cb, r);
    } catch (const std::exception& e) {
      r.ok = false;
      r.message =
          std::string("internal error while cleaning (the mesh is valid but may be partially cleaned): ") +
          e.what();
      try {
        Finish(m);
      } catch (...) {
      }
    }
    return r;
  }

private:
  using FaceType = typename MeshType::FaceType;
  using VertexType = typename MeshType::VertexType;
  using FacePointer = typename MeshType::FacePointer;
  using VertexPointer = typename MeshType::VertexPointer;
  using Tri = std::array<Index, 3>;
  using Quality = MeshQuality<MeshType>;
  static constexpr Index kNone = kNoIndex;

  // ------------------------------------------------------------------------------------------------
  // Small helpers
  // ------------------------------------------------------------------------------------------------

  static Index VI(const MeshType& m, const FaceType& f, int k) { return Index(f.cV(k) - &m.vert[0]); }
  static Index FI(const MeshType& m, const FaceType* f) { return Index(f - &m.face[0]); }
  static Tri FaceTri(const MeshType& m, const FaceType& f) { return {VI(m, f, 0), VI(m, f, 1), VI(m, f, 2)}; }
  static std::uint64_t EdgeKey(Index a, Index b) {
    return (std::uint64_t(std::min(a, b)) << 32) | std::uint64_t(std::max(a, b));
  }
  static double FaceArea(const MeshType& m, const FaceType& f) {
    return hole_triangulation::TriArea(PositionOf(&m.vert[VI(m, f, 0)]), PositionOf(&m.vert[VI(m, f, 1)]),
                                       PositionOf(&m.vert[VI(m, f, 2)]));
  }
  static Point FaceNormal(const MeshType& m, const FaceType& f) {
    return hole_triangulation::UnitNormal(PositionOf(&m.vert[VI(m, f, 0)]), PositionOf(&m.vert[VI(m, f, 1)]),
                                          PositionOf(&m.vert[VI(m, f, 2)]));
  }
  static void Progress(vcg::CallBackPos* cb, int percent, const char* what) {
    if (cb) (*cb)(percent, what);
  }
  static void RebuildTopology(MeshType& m) {
    // The linear-time adjacency is vcglib's wherever an edge has at most two faces. On a
    // non-manifold edge vcglib orders the ring by its own sort, and the repairs here walk such
    // rings, so a mesh that has any keeps vcglib's construction (and the same cleaning).
    if (UpdateFaceFaceTopology(m) > 0) vcg::tri::UpdateTopology<MeshType>::FaceFace(m);
    vcg::tri::UpdateTopology<MeshType>::VertexFace(m);
  }
  static bool IsBorderEdge(const FaceType& f, int e) { return f.cFFp(e) == &f; }

  static void DeleteFace(MeshType& m, Index f) {
    if (!m.face[f].IsD()) vcg::tri::Allocator<MeshType>::DeleteFace(m, m.face[f]);
  }
  static void UndeleteFace(MeshType& m, Index f) {
    if (m.face[f].IsD()) {
      m.face[f].ClearD();
      ++m.fn;
    }
  }

  /// Live faces around vertex v (needs fresh VF adjacency; deleted faces are skipped): (face, corner).
  static void Star(MeshType& m, Index v, std::vector<std::pair<Index, int>>& out) {
    out.clear();
    for (vcg::face::VFIterator<FaceType> it(&m.vert[v]); !it.End(); ++it)
      if (!it.F()->IsD()) out.emplace_back(FI(m, it.F()), it.I());
  }
  /// Distinct neighbours of v through live faces.
  static void Neighbours(MeshType& m, Index v, std::vector<Index>& out) {
    out.clear();
    for (vcg::face::VFIterator<FaceType> it(&m.vert[v]); !it.End(); ++it) {
      if (it.F()->IsD()) continue;
      out.push_back(VI(m, *it.F(), (it.I() + 1) % 3));
      out.push_back(VI(m, *it.F(), (it.I() + 2) % 3));
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  }
  static bool HasBorderEdgeAt(MeshType& m, Index v) {
    for (vcg::face::VFIterator<FaceType> it(&m.vert[v]); !it.End(); ++it) {
      if (it.F()->IsD()) continue;
      const int k = it.I();
      if (IsBorderEdge(*it.F(), k) || IsBorderEdge(*it.F(), (k + 2) % 3)) return true;
    }
    return false;
  }

  // ------------------------------------------------------------------------------------------------
  // Refusal (nothing is modified before this returns true)
  // ------------------------------------------------------------------------------------------------

  static bool Refuse(MeshType& m, const Params& params, Result& r) {
    auto refuse = [&r](const std::string& message) {
      r.ok = false;
      r.message = message;
      return false;
    };
    const InputCheck check = CheckTriangleMeshInput(m);
    if (!check.ok) return refuse(check.message);
    if (!vcg::tri::HasFFAdjacency(m) || !vcg::tri::HasVFAdjacency(m))
      return refuse("face-face and vertex-face adjacency must be enabled before cleaning");
    if (!(params.mergeTolerance >= 0) || !std::isfinite(params.mergeTolerance))
      return refuse("mergeTolerance must be a finite number >= 0");
    if (!(params.degenerateAreaEpsilon >= 0) || !std::isfinite(params.degenerateAreaEpsilon))
      return refuse("degenerateAreaEpsilon must be a finite number >= 0");
    if (params.maxHoleEdges < 0) return refuse("maxHoleEdges must be >= 0");
    if (!(params.minComponentFraction >= 0 && params.minComponentFraction <= 1))
      return refuse("minComponentFraction must be in [0, 1]");
    if (params.maxRepairGrowth < 0 || params.maxRepairRegionFaces < 0 || params.maxRepairAttempts < 0)
      return refuse("maxRepairGrowth, maxRepairRegionFaces and maxRepairAttempts must be >= 0");
    if (!(params.maxFillDihedral > 0 && params.maxFillDihedral <= 180))
      return refuse("maxFillDihedral must be in (0, 180] degrees");
    if (m.vert.size() >= std::size_t(kNone) / 2 || m.face.size() >= std::size_t(kNone) / 2)
      return refuse("the mesh is too large (more than 2^31 elements)");
    const VertexType* begin = &m.vert[0];
    const VertexType* end = begin + m.vert.size();
    std::size_t fi = 0;
    for (const auto& f : m.face) {
      ++fi;
      if (f.IsD()) continue;
      for (int k = 0; k < 3; ++k)
        if (f.cV(k) == nullptr || f.cV(k) < begin || f.cV(k) >= end || f.cV(k)->IsD())
          return refuse("face " + std::to_string(fi - 1) + " references a missing or deleted vertex");
    }
    const double meanEdge = MeanEdgeLength(m, /*skipCollapsedSides=*/true);
    const double minArea = params.degenerateAreaEpsilon * meanEdge * meanEdge;
    bool anyProper = false;
    for (const auto& f : m.face) {
      if (f.IsD() || f.cV(0) == f.cV(1) || f.cV(1) == f.cV(2) || f.cV(2) == f.cV(0)) continue;
      if (FaceArea(m, f) > minArea) {
        anyProper = true;
        break;
      }
    }
    if (!anyProper) return refuse("every face of the mesh is degenerate (repeated vertex or zero area)");
    return true;
  }

  // ------------------------------------------------------------------------------------------------
  // Driver
  // ------------------------------------------------------------------------------------------------

  static void Run(MeshType& m, const Params& params, vcg::CallBackPos* cb, Result& r) {
    typename Quality::Params qp;
    qp.computeSelfIntersections = params.measureSelfIntersections;
    qp.degenerateAreaEpsilon = params.degenerateAreaEpsilon;
    qp.threads = params.threads;
    Progress(cb, 0, "Measuring the input");
    const QualityReport before = Quality::Compute(m, qp);
    r.verticesBefore = before.vertices;
    r.facesBefore = before.faces;
    r.areaBefore = before.area;
    r.volumeBefore = before.volume;
    r.selfIntersectionsMeasured = before.selfIntersectionsComputed;
    r.selfIntersectingFacesBefore = before.selfIntersectingFaces;
    // The tolerances are relative to MeshQuality's mean edge length, so that "degenerate" means the
    // same thing here and in the report.
    const double meanEdge =
        before.meanEdgeLength > 0 ? before.meanEdgeLength : MeanEdgeLength(m, /*skipCollapsedSides=*/true);
    const std::size_t inputFaces = m.face.size();

    Progress(cb, 5, "Merging coincident vertices");
    r.mergedVertices = MergeCloseVertices(m, params.mergeTolerance * meanEdge, 0.5 * meanEdge);
    r.removedDegenerateFaces += RemoveIndexDegenerateFaces(m);
    r.removedDuplicateFaces = RemoveDuplicateFaces(m);
    r.removedUnreferencedVertices = RemoveUnreferencedVertices(m);
    RebuildTopology(m);

    Progress(cb, 15, "Removing faces on non-manifold edges");
    r.removedNonManifoldFaces = ResolveNonManifoldEdges(m);
    if (r.removedNonManifoldFaces > 0) RebuildTopology(m);

    Progress(cb, 20, "Orienting coherently");
    std::vector<std::uint8_t> flipped(m.face.size(),
                                      0); // per face: orientation reversed an odd number of times
    std::vector<std::pair<Index, Index>> orientationConflicts;
    OrientCoherently(m, flipped, orientationConflicts);

    Progress(cb, 25, "Removing zero-area faces");
    const double degenerateArea = params.degenerateAreaEpsilon * meanEdge * meanEdge;
    FixZeroAreaFaces(m, degenerateArea, r);

    Progress(cb, 35, "Splitting non-manifold vertices");
    const auto splitEarly = SplitNonManifoldVertices(m, true);
    r.splitNonManifoldVertices += splitEarly.size();

    Progress(cb, 40, "Removing small components");
    RemoveSmallComponents(m, params.minComponentFraction, r);

    const double tol = PlaneTolerance(m, meanEdge);
    int attemptsLeft = params.maxRepairAttempts;
    SeparateSplitCopies(m, splitEarly, params, meanEdge, tol, attemptsLeft, r);
    if (params.repairTangles) {
      Progress(cb, 50, "Repairing local tangles");
      // Intersecting faces first: a tangle often also makes its component non-orientable, and the
      // seams where the orientation traversal met itself are no defect once it is gone. Then the
      // orientation conflicts that remain.
      RepairTangles(m, params, meanEdge, tol, true, {}, attemptsLeft, r);
      flipped.resize(m.face.size(), 0);
      OrientCoherently(m, flipped, orientationConflicts);
      for (int round = 0; round < 16 && !orientationConflicts.empty(); ++round) {
        if (!RepairTangles(m, params, meanEdge, tol, false, orientationConflicts, attemptsLeft, r)) break;
        flipped.resize(m.face.size(), 0);
        OrientCoherently(m, flipped, orientationConflicts);
      }
    }
    {
      // Components still holding an orientation conflict cannot be oriented.
      std::vector<Index> label;
      std::vector<std::size_t> size;
      LabelComponents(m, label, size);
      std::vector<std::uint8_t> bad(size.size(), 0);
      for (const auto& conflict : orientationConflicts)
        if (!m.face[conflict.first].IsD()) bad[label[conflict.first]] = 1;
      r.nonOrientableComponents = std::size_t(std::count(bad.begin(), bad.end(), 1));
      r.unrepairedTangles += r.nonOrientableComponents; // at least one orientation defect in each
    }

    Progress(cb, 70, "Closing holes");
    FillHoles(m, params, meanEdge, tol, attemptsLeft, r);

    Progress(cb, 85, "Splitting remaining non-manifold vertices");
    const auto splitLate = SplitNonManifoldVertices(m, false);
    r.splitNonManifoldVertices += splitLate.size();
    SeparateSplitCopies(m, splitLate, params, meanEdge, tol, attemptsLeft, r);

    Progress(cb, 90, "Orienting closed components outward");
    flipped.resize(m.face.size(), 0);
    OrientOutward(m, params.orientCavitiesInward, flipped, r);
    for (std::size_t f = 0; f < inputFaces && f < m.face.size(); ++f)
      if (!m.face[f].IsD() && flipped[f]) ++r.flippedFacesForOrientation;

    Progress(cb, 95, "Compacting");
    r.removedOrphanedVertices = Finish(m);

    const QualityReport after = Quality::Compute(m, qp);
    r.verticesAfter = after.vertices;
    r.facesAfter = after.faces;
    r.areaAfter = after.area;
    r.volumeAfter = after.volume;
    r.selfIntersectingFacesAfter = after.selfIntersectingFaces;
    r.boundaryEdgesAfter = after.boundaryEdges;
    r.nonManifoldEdgesAfter = after.nonManifoldEdges;
    r.nonManifoldVerticesAfter = after.nonManifoldVertices;
    r.degenerateFacesAfter = after.degenerateFaces;
    r.componentsAfter = after.components;
    r.genusAfter = after.genus;
    r.reportAfter = after;
    Progress(cb, 100, "Clean raw mesh done");
  }

  /// Deletes unreferenced vertices, compacts every vector and rebuilds FF/VF. Returns the vertices deleted.
  static std::size_t Finish(MeshType& m) {
    const std::size_t removed = RemoveUnreferencedVertices(m);
    vcg::tri::Allocator<MeshType>::CompactEveryVector(m);
    RebuildTopology(m);
    return removed;
  }

  /// Snap distance for the plane-side tests of the triangle/triangle predicates, as in MeshQuality.
  static double PlaneTolerance(const MeshType& m, double meanEdge) {
    double maxAbs = 0;
    for (const auto& v : m.vert)
      if (!v.IsD())
        for (int k = 0; k < 3; ++k) maxAbs = std::max(maxAbs, std::fabs(double(v.cP()[k])));
    return 1e-12 * (maxAbs + meanEdge);
  }

  // ------------------------------------------------------------------------------------------------
  // Step 1: merge, index-degenerate, duplicate faces, unreferenced vertices (no adjacency needed)
  // ------------------------------------------------------------------------------------------------

  /// Maps every vertex within `radius` of an earlier surviving vertex onto it (in index order, so the
  /// result is deterministic), re-references the faces and deletes the merged vertices. radius 0 (or
  /// too small to grid) merges exact copies only. Positions are never changed.
  static std::size_t MergeCloseVertices(MeshType& m, double radius, double cellSize) {
    const std::size_t n = m.vert.size();
    std::vector<Index> target(n, kNone);
    std::size_t merged = 0;
    if (!(radius > 1e-300)) {
      std::vector<Index> order;
      for (Index v = 0; v < n; ++v)
        if (!m.vert[v].IsD()) order.push_back(v);
      auto less = [&m](Index a, Index b) {
        const Point pa = PositionOf(&m.vert[a]), pb = PositionOf(&m.vert[b]);
        if (pa != pb) return pa < pb;
        return a < b;
      };
      std::sort(order.begin(), order.end(), less);
      for (std::size_t i = 1; i < order.size(); ++i) {
        if (PositionOf(&m.vert[order[i]]) != PositionOf(&m.vert[order[i - 1]])) continue;
        const Index keep = target[order[i - 1]] != kNone ? target[order[i - 1]] : order[i - 1];
        target[order[i]] = keep;
        ++merged;
      }
    } else {
      // Vertices sorted by their cell (cells of size >= radius): the merge partners of a vertex are in
      // its own cell or in a neighbouring cell closer than radius. Only earlier vertices that survive
      // are candidates, so the result is that of a scan in index order, independent of the sort.
      using Cell = std::array<std::int64_t, 3>;
      const double size = std::max(radius, cellSize);
      const double inv = 1.0 / size;
      std::vector<Cell> cell(n);
      std::vector<std::pair<Cell, Index>> sorted;
      sorted.reserve(n);
      for (Index v = 0; v < n; ++v) {
        if (m.vert[v].IsD()) continue;
        const Point p = PositionOf(&m.vert[v]);
        cell[v] = {std::int64_t(std::floor(p[0] * inv)), std::int64_t(std::floor(p[1] * inv)),
                   std::int64_t(std::floor(p[2] * inv))};
        sorted.emplace_back(cell[v], v);
      }
      std::sort(sorted.begin(), sorted.end());
      for (Index v = 0; v < n; ++v) {
        if (m.vert[v].IsD()) continue;
        const Point p = PositionOf(&m.vert[v]);
        Index best = kNone;
        double bestDistance = radius;
        std::array<std::int64_t, 3> lo{}, hi{};
        for (int a = 0; a < 3; ++a) {
          lo[a] = std::int64_t(std::floor((p[a] - radius) * inv)) - cell[v][a];
          hi[a] = std::int64_t(std::floor((p[a] + radius) * inv)) - cell[v][a];
        }
        for (std::int64_t dx = lo[0]; dx <= hi[0]; ++dx)
          for (std::int64_t dy = lo[1]; dy <= hi[1]; ++dy)
            for (std::int64_t dz = lo[2]; dz <= hi[2]; ++dz) {
              const Cell c{cell[v][0] + dx, cell[v][1] + dy, cell[v][2] + dz};
              auto it = std::lower_bound(sorted.begin(), sorted.end(), std::make_pair(c, Index(0)));
              for (; it != sorted.end() && it->first == c && it->second < v; ++it) {
                const Index w = it->second;
                if (target[w] != kNone) continue; // merged itself: not a survivor
                const double d = (PositionOf(&m.vert[w]) - p).Norm();
                if (d <= bestDistance && (best == kNone || d < bestDistance || w < best)) {
                  best = w;
                  bestDistance = d;
                }
              }
            }
        if (best != kNone) {
          target[v] = best;
          ++merged;
        }
      }
    }
    if (merged == 0) return 0;
    for (auto& f : m.face) {
      if (f.IsD()) continue;
      for (int k = 0; k < 3; ++k) {
        const Index t = target[VI(m, f, k)];
        if (t != kNone) f.V(k) = &m.vert[t];
      }
    }
    for (Index v = 0; v < n; ++v)
      if (target[v] != kNone) vcg::tri::Allocator<MeshType>::DeleteVertex(m, m.vert[v]);
    return merged;
  }

  static std::size_t RemoveIndexDegenerateFaces(MeshType& m) {
    std::size_t removed = 0;
    for (auto& f : m.face)
      if (!f.IsD() && (f.V(0) == f.V(1) || f.V(1) == f.V(2) || f.V(2) == f.V(0))) {
        vcg::tri::Allocator<MeshType>::DeleteFace(m, f);
        ++removed;
      }
    return removed;
  }

  /// Keeps the first face (in index order) of every set of faces with the same three vertices.
  static std::size_t RemoveDuplicateFaces(MeshType& m) {
    std::vector<std::pair<Tri, Index>> keys;
    keys.reserve(m.face.size());
    for (Index f = 0; f < m.face.size(); ++f) {
      if (m.face[f].IsD()) continue;
      Tri t = FaceTri(m, m.face[f]);
      std::sort(t.begin(), t.end());
      keys.emplace_back(t, f);
    }
    std::sort(keys.begin(), keys.end());
    std::size_t removed = 0;
    for (std::size_t i = 1; i < keys.size(); ++i)
      if (keys[i].first == keys[i - 1].first) {
        DeleteFace(m, keys[i].second);
        ++removed;
      }
    return removed;
  }

  static std::size_t RemoveUnreferencedVertices(MeshType& m) {
    std::vector<std::uint8_t> used(m.vert.size(), 0);
    for (const auto& f : m.face)
      if (!f.IsD())
        for (int k = 0; k < 3; ++k) used[VI(m, f, k)] = 1;
    std::size_t removed = 0;
    for (std::size_t v = 0; v < m.vert.size(); ++v)
      if (!m.vert[v].IsD() && !used[v]) {
        vcg::tri::Allocator<MeshType>::DeleteVertex(m, m.vert[v]);
        ++removed;
      }
    return removed;
  }

  // ------------------------------------------------------------------------------------------------
  // Step 2: non-manifold edges
  // ------------------------------------------------------------------------------------------------

  /// On every edge with k > 2 faces keeps the pair that is consistently oriented (opposite directions
  /// along the edge) and the flattest (normals agreeing), and removes the k - 2 others. Edges are
  /// processed in a fixed order and faces already removed no longer count, so a face removed for one
  /// edge may make a later edge manifold. No adjacency needed.
  static std::size_t ResolveNonManifoldEdges(MeshType& m) {
    struct Entry {
      std::uint64_t key;
      Index face;
      bool forward; // the face runs the edge from min to max vertex
      bool operator<(const Entry& o) const { return key != o.key ? key < o.key : face < o.face; }
    };
    std::vector<Entry> entries;
    entries.reserve(3 * std::size_t(m.fn));
    for (Index f = 0; f < m.face.size(); ++f) {
      if (m.face[f].IsD()) continue;
      for (int k = 0; k < 3; ++k) {
        const Index a = VI(m, m.face[f], k), b = VI(m, m.face[f], (k + 1) % 3);
        entries.push_back({EdgeKey(a, b), f, a < b});
      }
    }
    std::sort(entries.begin(), entries.end());
    std::size_t removed = 0;
    std::vector<Entry> group;
    for (std::size_t i = 0; i < entries.size();) {
      std::size_t j = i;
      while (j < entries.size() && entries[j].key == entries[i].key) ++j;
      if (j - i > 2) {
        group.clear();
        for (std::size_t k = i; k < j; ++k)
          if (!m.face[entries[k].face].IsD()) group.push_back(entries[k]);
        if (group.size() > 2) {
          std::size_t keepA = 0, keepB = 1;
          double bestScore = -std::numeric_limits<double>::infinity();
          for (std::size_t a = 0; a < group.size(); ++a)
            for (std::size_t b = a + 1; b < group.size(); ++b) {
              const Point na = FaceNormal(m, m.face[group[a].face]),
                          nb = FaceNormal(m, m.face[group[b].face]);
              const bool consistent = group[a].forward != group[b].forward;
              const double score = (consistent ? 2.0 : 0.0) + (consistent ? na * nb : -(na * nb));
              if (score > bestScore) {
                bestScore = score;
                keepA = a;
                keepB = b;
              }
            }
          for (std::size_t a = 0; a < group.size(); ++a)
            if (a != keepA && a != keepB) {
              DeleteFace(m, group[a].face);
              ++removed;
            }
        }
      }
      i = j;
    }
    return removed;
  }

  // ------------------------------------------------------------------------------------------------
  // Step 3: coherent orientation (FF adjacency, edge-manifold mesh)
  // ------------------------------------------------------------------------------------------------

  static bool Coherent(const FaceType& f, int e) {
    const FaceType* g = f.cFFp(e);
    const int ge = f.cFFi(e);
    return g->cV(ge) == f.cV((e + 1) % 3) && g->cV((ge + 1) % 3) == f.cV(e);
  }

  /// Traversal over manifold edges; a neighbour seen the wrong way round is flipped
  /// (vcg::face::SwapEdge keeps FF consistent). When more than half of a component was flipped, the
  /// whole component is flipped back so the input's majority orientation wins. Pairs of faces that
  /// stay incoherent (the component is not orientable as it is) are returned in `conflicts`. vcglib's
  /// Clean::OrientCoherentlyMesh is not used because it stops at the first non-orientable component.
  static void OrientCoherently(MeshType& m, std::vector<std::uint8_t>& flipped,
                               std::vector<std::pair<Index, Index>>& conflicts) {
    conflicts.clear();
    std::vector<std::uint8_t> seen(m.face.size(), 0);
    std::vector<Index> component, queue;
    bool changed = false;
    for (Index s = 0; s < m.face.size(); ++s) {
      if (m.face[s].IsD() || seen[s]) continue;
      component.clear();
      queue.assign(1, s);
      seen[s] = 1;
      std::size_t flips = 0;
      bool orientable = true;
      while (!queue.empty()) {
        const Index f = queue.back();
        queue.pop_back();
        component.push_back(f);
        FaceType& F = m.face[f];
        for (int e = 0; e < 3; ++e) {
          if (IsBorderEdge(F, e)) continue;
          FaceType* g = F.FFp(e);
          if (g->FFp(F.FFi(e)) != &F) continue; // not a manifold edge
          const Index gi = FI(m, g);
          if (!Coherent(F, e)) {
            if (!seen[gi]) {
              vcg::face::SwapEdge<FaceType, true>(*g, 0);
              flipped[gi] ^= 1;
              ++flips;
              changed = true;
            } else {
              orientable = false;
              conflicts.emplace_back(std::min(f, gi), std::max(f, gi));
            }
          }
          if (!seen[gi]) {
            seen[gi] = 1;
            queue.push_back(gi);
          }
        }
      }
      if (orientable && 2 * flips > component.size()) {
        for (Index f : component) {
          vcg::face::SwapEdge<FaceType, false>(m.face[f], 0);
          flipped[f] ^= 1;
        }
        changed = true;
      }
    }
    std::sort(conflicts.begin(), conflicts.end());
    conflicts.erase(std::unique(conflicts.begin(), conflicts.end()), conflicts.end());
    if (changed) RebuildTopology(m);
  }

  // ------------------------------------------------------------------------------------------------
  // Step 4: zero-area faces (FF + VF adjacency, coherent orientation)
  // ------------------------------------------------------------------------------------------------

  /// Passes over the zero-area faces; each pass edits an independent set (no edit touches a vertex
  /// marked by an earlier edit of the same pass, so the pass reads only valid adjacency), then the
  /// adjacency is rebuilt. Stops when none is left or a pass changes nothing.
  static void FixZeroAreaFaces(MeshType& m, double degenerateArea, Result& r) {
    const int maxPasses = 50;
    std::vector<std::uint8_t> dirty;
    for (int pass = 0; pass < maxPasses; ++pass) {
      std::vector<Index> bad;
      for (Index f = 0; f < m.face.size(); ++f)
        if (!m.face[f].IsD() && FaceArea(m, m.face[f]) <= degenerateArea) bad.push_back(f);
      r.remainingDegenerateFaces = bad.size();
      if (bad.empty()) return;
      dirty.assign(m.vert.size(), 0);
      bool progress = false;
      for (Index f : bad) {
        const FaceType& F = m.face[f];
        if (F.IsD()) continue;
        const Tri t = FaceTri(m, F);
        if (dirty[t[0]] || dirty[t[1]] || dirty[t[2]]) continue;
        std::array<double, 3> len{};
        for (int k = 0; k < 3; ++k)
          len[k] = (PositionOf(&m.vert[t[(k + 1) % 3]]) - PositionOf(&m.vert[t[k]])).Norm();
        const int longest = int(std::max_element(len.begin(), len.end()) - len.begin());
        const int shortest = int(std::min_element(len.begin(), len.end()) - len.begin());
        const bool needle = len[shortest] < 1e-3 * len[longest];
        bool done = false;
        if (!needle) done = FlipCap(m, f, longest, degenerateArea, dirty, r);
        if (!done) done = CollapseEdge(m, f, shortest, degenerateArea, dirty, r);
        if (!done && needle) done = FlipCap(m, f, longest, degenerateArea, dirty, r);
        progress = progress || done;
      }
      RebuildTopology(m);
      if (!progress) break;
    }
    r.remainingDegenerateFaces = 0;
    for (const auto& f : m.face)
      if (!f.IsD() && FaceArea(m, f) <= degenerateArea) ++r.remainingDegenerateFaces;
  }

  static bool EdgeExistsInStar(MeshType& m, Index a, Index b) {
    for (vcg::face::VFIterator<FaceType> it(&m.vert[a]); !it.End(); ++it)
      if (!it.F()->IsD())
        for (int k = 0; k < 3; ++k)
          if (it.F()->V(k) == &m.vert[b]) return true;
    return false;
  }

  /// Face f = (a, b, c) with edge e = ab its longest edge and c (nearly) on it. Interior: flip ab into
  /// cd with the neighbour (b, a, d): the two new faces (c, a, d) and (c, d, b) cover exactly the
  /// neighbour, so the surface does not change. Boundary: drop f when c is an interior vertex.
  static bool FlipCap(MeshType& m, Index f, int e, double degenerateArea, std::vector<std::uint8_t>& dirty,
                      Result& r) {
    FaceType& F = m.face[f];
    const Index a = VI(m, F, e), b = VI(m, F, (e + 1) % 3), c = VI(m, F, (e + 2) % 3);
    if (IsBorderEdge(F, e)) {
      if (HasBorderEdgeAt(m, c)) return false; // dropping f would pinch c
      DeleteFace(m, f);
      dirty[a] = dirty[b] = dirty[c] = 1;
      ++r.removedDegenerateFaces;
      return true;
    }
    FaceType* G = F.FFp(e);
    const int j = F.FFi(e);
    if (G->IsD() || G->FFp(j) != &F) return false;
    if (G->V(j) != &m.vert[b] || G->V((j + 1) % 3) != &m.vert[a]) return false; // not coherent
    const Index d = VI(m, *G, (j + 2) % 3);
    if (d == c || dirty[d]) return false;
    if (FaceArea(m, *G) <= degenerateArea)
      return false; // neighbour degenerate too: let another edit go first
    if (EdgeExistsInStar(m, c, d)) return false;
    const Point pa = PositionOf(&m.vert[a]), pb = PositionOf(&m.vert[b]), pc = PositionOf(&m.vert[c]),
                pd = PositionOf(&m.vert[d]);
    if (hole_triangulation::TriArea(pc, pa, pd) <= degenerateArea ||
        hole_triangulation::TriArea(pc, pd, pb) <= degenerateArea)
      return false;
    const Point ng = FaceNormal(m, *G);
    if (hole_triangulation::UnitNormal(pc, pa, pd) * ng <= 0 ||
        hole_triangulation::UnitNormal(pc, pd, pb) * ng <= 0)
      return false;
    F.V(0) = &m.vert[c];
    F.V(1) = &m.vert[a];
    F.V(2) = &m.vert[d];
    G->V(0) = &m.vert[c];
    G->V(1) = &m.vert[d];
    G->V(2) = &m.vert[b];
    dirty[a] = dirty[b] = dirty[c] = dirty[d] = 1;
    ++r.flippedDegenerateFaces;
    return true;
  }

  /// Collapses edge e of face f onto one of its end points (which keeps its position): the boundary
  /// one if only one is on the boundary. Checked: manifold edge, link condition, no pinch of the
  /// boundary, no face of the star degenerates or turns over.
  static bool CollapseEdge(MeshType& m, Index f, int e, double degenerateArea,
                           std::vector<std::uint8_t>& dirty, Result& r) {
    const FaceType& F = m.face[f];
    Index u = VI(m, F, e), v = VI(m, F, (e + 1) % 3); // u is removed, v kept
    if (dirty[u] || dirty[v]) return false;
    const bool uBorder = HasBorderEdgeAt(m, u), vBorder = HasBorderEdgeAt(m, v);
    if (uBorder && !vBorder) std::swap(u, v);
    std::vector<std::pair<Index, int>> starU;
    Star(m, u, starU);
    std::vector<Index> edgeFaces, opposite;
    for (const auto& [g, k] : starU) {
      const FaceType& G = m.face[g];
      for (int i = 1; i < 3; ++i)
        if (VI(m, G, (k + i) % 3) == v) {
          edgeFaces.push_back(g);
          opposite.push_back(VI(m, G, (k + 3 - i) % 3));
        }
    }
    if (edgeFaces.empty() || edgeFaces.size() > 2) return false;
    const bool edgeBorder = edgeFaces.size() == 1;
    if (uBorder && vBorder && !edgeBorder) return false; // would pinch the boundary
    // Link condition: the common neighbours of u and v are exactly the opposite vertices.
    std::vector<Index> nu, nv, common;
    Neighbours(m, u, nu);
    Neighbours(m, v, nv);
    for (Index w : nu)
      if (dirty[w]) return false;
    for (Index w : nv)
      if (dirty[w]) return false;
    std::set_intersection(nu.begin(), nu.end(), nv.begin(), nv.end(), std::back_inserter(common));
    std::sort(opposite.begin(), opposite.end());
    if (common != opposite) return false;
    // Geometry of the faces that keep existing with u replaced by v.
    for (const auto& [g, k] : starU) {
      if (std::find(edgeFaces.begin(), edgeFaces.end(), g) != edgeFaces.end()) continue;
      const FaceType& G = m.face[g];
      const Point p1 = PositionOf(&m.vert[VI(m, G, (k + 1) % 3)]),
                  p2 = PositionOf(&m.vert[VI(m, G, (k + 2) % 3)]);
      const Point oldP = PositionOf(&m.vert[u]), newP = PositionOf(&m.vert[v]);
      if (hole_triangulation::TriArea(newP, p1, p2) <= degenerateArea) return false;
      const Point oldN = hole_triangulation::UnitNormal(oldP, p1, p2),
                  newN = hole_triangulation::UnitNormal(newP, p1, p2);
      if (hole_triangulation::TriArea(oldP, p1, p2) > degenerateArea && oldN * newN <= 0.1) return false;
    }
    for (Index g : edgeFaces) {
      DeleteFace(m, g);
      ++r.removedDegenerateFaces;
    }
    for (const auto& [g, k] : starU)
      if (!m.face[g].IsD()) m.face[g].V(k) = &m.vert[v];
    dirty[u] = dirty[v] = 1;
    for (Index w : nu) dirty[w] = 1;
    for (Index w : nv) dirty[w] = 1;
    ++r.collapsedDegenerateEdges;
    return true;
  }

  // ------------------------------------------------------------------------------------------------
  // Steps 5 and 9: non-manifold vertices (FF + VF adjacency, edge-manifold mesh)
  // ------------------------------------------------------------------------------------------------

  /// Splits vertices whose faces form several fans (joined through edges at the vertex). With
  /// onlyClosedFans, only closed fans are split off (open fans of a boundary pinch stay together for
  /// the hole filling); otherwise every fan but the first gets its own vertex. Copies keep the
  /// position and attributes of the original. vcglib's Clean::SplitNonManifoldVertex is not used: it
  /// splits one fan per vertex and call and cannot tell closed fans from open ones.
  static std::vector<std::pair<Index, Index>> SplitNonManifoldVertices(MeshType& m, bool onlyClosedFans) {
    struct Split {
      Index vertex;
      std::vector<std::pair<Index, int>> corners; // (face, corner) moving to the copy
    };
    std::vector<Split> splits;
    std::vector<std::pair<Index, int>> star;
    std::vector<int> parent;
    for (Index v = 0; v < m.vert.size(); ++v) {
      if (m.vert[v].IsD()) continue;
      Star(m, v, star);
      if (star.size() < 2) continue;
      parent.resize(star.size());
      std::iota(parent.begin(), parent.end(), 0);
      auto find = [&parent](int x) {
        while (parent[x] != x) x = parent[x] = parent[parent[x]];
        return x;
      };
      auto local = [&star](Index face) {
        for (std::size_t i = 0; i < star.size(); ++i)
          if (star[i].first == face) return int(i);
        return -1;
      };
      std::vector<std::uint8_t> open(star.size(), 0);
      for (std::size_t i = 0; i < star.size(); ++i) {
        const FaceType& F = m.face[star[i].first];
        const int k = star[i].second;
        for (int e : {k, (k + 2) % 3}) {
          if (IsBorderEdge(F, e)) {
            open[i] = 1;
            continue;
          }
          const int j = local(FI(m, F.cFFp(e)));
          if (j >= 0) {
            const int a = find(int(i)), b = find(j);
            if (a != b) parent[std::max(a, b)] = std::min(a, b);
          }
        }
      }
      std::vector<int> roots;
      for (std::size_t i = 0; i < star.size(); ++i)
        if (find(int(i)) == int(i)) roots.push_back(int(i));
      if (roots.size() < 2) continue;
      std::vector<std::uint8_t> fanOpen(star.size(), 0);
      for (std::size_t i = 0; i < star.size(); ++i)
        if (open[i]) fanOpen[find(int(i))] = 1;
      std::size_t openFans = 0;
      for (int root : roots) openFans += fanOpen[root];
      // The fan that keeps the original vertex: the first open one, else the first.
      int keep = roots.front();
      for (int root : roots)
        if (fanOpen[root]) {
          keep = root;
          break;
        }
      if (onlyClosedFans && openFans == roots.size()) continue;
      for (int root : roots) {
        if (root == keep) continue;
        if (onlyClosedFans && fanOpen[root]) continue;
        Split s{v, {}};
        for (std::size_t i = 0; i < star.size(); ++i)
          if (find(int(i)) == root) s.corners.push_back(star[i]);
        splits.push_back(std::move(s));
      }
    }
    std::vector<std::pair<Index, Index>> made;
    if (splits.empty()) return made;
    const Index first = Index(m.vert.size());
    vcg::tri::Allocator<MeshType>::AddVertices(m, splits.size());
    for (std::size_t i = 0; i < splits.size(); ++i) {
      VertexType& copy = m.vert[first + i];
      copy.ImportData(m.vert[splits[i].vertex]);
      for (const auto& [face, corner] : splits[i].corners) m.face[face].V(corner) = &copy;
      made.emplace_back(splits[i].vertex, first + Index(i));
    }
    RebuildTopology(m);
    return made;
  }

  // ------------------------------------------------------------------------------------------------
  // Step 6: components (FF adjacency)
  // ------------------------------------------------------------------------------------------------

  /// Face components through shared edges, numbered in order of their lowest face.
  static std::size_t LabelComponents(const MeshType& m, std::vector<Index>& label,
                                     std::vector<std::size_t>& size) {
    label.assign(m.face.size(), kNone);
    size.clear();
    std::vector<Index> stack;
    for (Index s = 0; s < m.face.size(); ++s) {
      if (m.face[s].IsD() || label[s] != kNone) continue;
      const Index c = Index(size.size());
      size.push_back(0);
      label[s] = c;
      stack.assign(1, s);
      while (!stack.empty()) {
        const Index f = stack.back();
        stack.pop_back();
        ++size[c];
        for (int e = 0; e < 3; ++e) {
          const FaceType* g = m.face[f].cFFp(e);
          const Index gi = FI(m, g);
          if (g->IsD() || label[gi] != kNone) continue;
          label[gi] = c;
          stack.push_back(gi);
        }
      }
    }
    return size.size();
  }

  static void RemoveSmallComponents(MeshType& m, double fraction, Result& r) {
    std::vector<Index> label;
    std::vector<std::size_t> size;
    const std::size_t count = LabelComponents(m, label, size);
    if (count < 2) return;
    const std::size_t largest = std::size_t(std::max_element(size.begin(), size.end()) - size.begin());
    const double limit = fraction * double(m.fn);
    std::vector<std::uint8_t> remove(count, 0);
    for (std::size_t c = 0; c < count; ++c)
      if (c != largest && double(size[c]) < limit) {
        remove[c] = 1;
        ++r.removedSmallComponents;
        r.removedComponentFaces += size[c];
      }
    if (r.removedSmallComponents == 0) return;
    for (Index f = 0; f < m.face.size(); ++f)
      if (!m.face[f].IsD() && remove[label[f]]) DeleteFace(m, f);
    RebuildTopology(m);
  }

  // ------------------------------------------------------------------------------------------------
  // Face grid and the closed triangle/triangle predicates of MeshQuality
  // ------------------------------------------------------------------------------------------------

  using FaceGrid = StaticFaceGrid<MeshType>;

  /// Closed-triangle conflict as MeshQuality counts it: no shared vertex and the triangles meet, or
  /// one shared vertex and they meet elsewhere too; three shared vertices (a duplicate) also conflict.
  /// Two shared vertices (a shared edge) never conflict here: folds are the dihedral check's business.
  static bool Conflict(const MeshType& m, const Tri& a, const Tri& b) {
    int shared = 0, ca = -1, cb = -1;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (a[i] == b[j]) ++shared, ca = i, cb = j;
    if (shared >= 3) return true;
    if (shared == 2) return false;
    const PlanarTriangle ta =
        MakePlanarTriangle(PositionOf(&m.vert[a[0]]), PositionOf(&m.vert[a[1]]), PositionOf(&m.vert[a[2]]));
    const PlanarTriangle tb =
        MakePlanarTriangle(PositionOf(&m.vert[b[0]]), PositionOf(&m.vert[b[1]]), PositionOf(&m.vert[b[2]]));
    if (shared == 0) return TrianglesIntersect(ta, tb);
    return SharedCornerOverlap(ta, ca, tb, cb);
  }

  // ------------------------------------------------------------------------------------------------
  // Boundary loops (FF adjacency, coherent orientation)
  // ------------------------------------------------------------------------------------------------

  struct Loop {
    std::vector<Index> verts; ///< verts[i] -> verts[i+1] is a boundary half-edge ...
    std::vector<Index> faces; ///< ... of face faces[i]
  };

  /// Follows the boundary from half-edge (f0, e0) to the next one around each end vertex within its
  /// fan (as vcglib's Pos::NextB), so a pinch vertex is passed once per fan. False when the loop does
  /// not close properly (inconsistent orientation around a non-orientable spot).
  static bool TraceLoop(MeshType& m, Index f0, int e0, std::vector<std::uint8_t>& visited, Loop& loop) {
    loop.verts.clear();
    loop.faces.clear();
    Index f = f0;
    int e = e0;
    const std::size_t maxSteps = 3 * m.face.size() + 3;
    for (std::size_t step = 0; step < maxSteps; ++step) {
      visited[f] |= std::uint8_t(1u << e);
      FaceType* F = &m.face[f];
      loop.verts.push_back(VI(m, *F, e));
      loop.faces.push_back(f);
      const VertexPointer v = F->V((e + 1) % 3);
      FaceType* g = F;
      int ge = (e + 1) % 3; // edge of g leaving v
      int guard = 0;
      while (!IsBorderEdge(*g, ge)) {
        FaceType* h = g->FFp(ge);
        const int he = g->FFi(ge);
        if (h->V((he + 1) % 3) != v) return false; // incoherent orientation
        g = h;
        ge = (he + 1) % 3;
        if (++guard > 100000 || (g == F && ge == (e + 1) % 3)) return false;
      }
      f = FI(m, g);
      e = ge;
      if (f == f0 && e == e0) return loop.verts.size() >= 3;
      if (visited[f] & (1u << e)) return false;
    }
    return false;
  }

  /// Whether every boundary half-edge of `loop` is still there: an earlier grown fill may have
  /// removed one of its faces or closed one of its sides.
  static bool LoopStillOpen(const MeshType& m, const Loop& loop) {
    const std::size_t n = loop.verts.size();
    for (std::size_t i = 0; i < n; ++i) {
      const FaceType& f = m.face[loop.faces[i]];
      if (f.IsD()) return false;
      int e = 0;
      while (e < 3 && !(VI(m, f, e) == loop.verts[i] && VI(m, f, (e + 1) % 3) == loop.verts[(i + 1) % n]))
        ++e;
      if (e == 3 || !IsBorderEdge(f, e)) return false;
    }
    return true;
  }

  /// Cuts a loop at its repeated vertices into simple cycles ("lobes"). Each lobe is filled on its
  /// own, which turns a pinch vertex (boundary passing twice) into a single manifold fan.
  static std::vector<Loop> SplitIntoLobes(const Loop& loop) {
    std::vector<Loop> lobes;
    std::vector<std::pair<Index, Index>> path; // (start vertex, face) of the half-edges on the stack
    std::unordered_map<Index, std::size_t> at; // start vertex -> position on the stack
    const std::size_t n = loop.verts.size();
    for (std::size_t k = 0; k < n; ++k) {
      at[loop.verts[k]] = path.size();
      path.emplace_back(loop.verts[k], loop.faces[k]);
      const Index end = loop.verts[(k + 1) % n];
      const auto it = at.find(end);
      if (it == at.end()) continue;
      const std::size_t s = it->second;
      Loop lobe;
      for (std::size_t i = s; i < path.size(); ++i) {
        lobe.verts.push_back(path[i].first);
        lobe.faces.push_back(path[i].second);
        at.erase(path[i].first);
      }
      path.resize(s);
      lobes.push_back(std::move(lobe));
    }
    if (!path.empty()) lobes.clear(); // cannot happen for a closed loop; be safe
    return lobes;
  }

  // ------------------------------------------------------------------------------------------------
  // Minimum-weight triangulation of a simple polygon (Liepa 2003), with forbidden triangles
  // ------------------------------------------------------------------------------------------------

  /// State shared by the fills of one step: the grid of faces, and the edges and faces created since
  /// the VF adjacency was last rebuilt.
  struct FillContext {
    FaceGrid* grid = nullptr;
    std::unordered_set<std::uint64_t> addedEdges;
    double minArea = 0, maxDihedral = kPi, tol = 0;
  };

  static bool EdgeExists(MeshType& m, const FillContext& ctx, Index a, Index b) {
    return ctx.addedEdges.count(EdgeKey(a, b)) > 0 || EdgeExistsInStar(m, a, b);
  }

  /// Triangulates every lobe of the loop, validates the triangles against the mesh and against each
  /// other, and retries without a triangle that failed. Returns the mesh faces (oriented) to add, or
  /// false when the loop cannot be filled. Nothing is modified.
  static bool PlanLoopFill(MeshType& m, const Loop& loop, const FillContext& ctx, std::vector<Tri>& out) {
    out.clear();
    const std::vector<Loop> lobes = SplitIntoLobes(loop);
    if (lobes.empty()) return false;
    std::vector<Index> candidates;
    for (const Loop& lobe : lobes) {
      const int n = int(lobe.verts.size());
      if (n < 3) return false;
      std::vector<Point> p(n), outer(n);
      for (int i = 0; i < n; ++i) {
        p[i] = PositionOf(&m.vert[lobe.verts[i]]);
        outer[i] = FaceNormal(m, m.face[lobe.faces[i]]);
      }
      // Diagonals that already exist as mesh edges would become non-manifold.
      std::vector<std::uint8_t> ok(std::size_t(n) * n, 1);
      for (int i = 0; i < n; ++i)
        for (int j = i + 2; j < n; ++j)
          if (!(i == 0 && j == n - 1) && EdgeExists(m, ctx, lobe.verts[i], lobe.verts[j]))
            ok[std::size_t(i) * n + j] = 0;
      auto diagonalOk = [&ok, n](int i, int j) { return ok[std::size_t(i) * n + j] != 0; };
      std::unordered_set<std::uint64_t> forbidden;
      std::vector<std::array<int, 3>> local;
      bool accepted = false;
      const int maxAttempts = 4 * n + 16;
      for (int attempt = 0; attempt < maxAttempts && !accepted; ++attempt) {
        if (!hole_triangulation::Triangulate(p, outer, diagonalOk, forbidden, ctx.minArea, ctx.maxDihedral,
                                             local)) {
          return false;
        }
        accepted = true;
        std::vector<Tri> mapped;
        for (const auto& t : local) mapped.push_back({lobe.verts[t[2]], lobe.verts[t[1]], lobe.verts[t[0]]});
        for (std::size_t a = 0; a < mapped.size() && accepted; ++a) {
          bool bad = false;
          // A triangle whose three sides are boundary sides duplicates an existing face when that
          // face is the only one around (an isolated triangle).
          if (n == 3) {
            for (Index f : lobe.faces) {
              Tri s = FaceTri(m, m.face[f]), t = mapped[a];
              std::sort(s.begin(), s.end());
              std::sort(t.begin(), t.end());
              if (s == t) return false;
            }
          }
          ctx.grid->Query(m, FaceGrid::Box(m, mapped[a], ctx.tol), candidates);
          for (Index g : candidates)
            if (Conflict(m, mapped[a], FaceTri(m, m.face[g]))) {
              bad = true;
              break;
            }
          for (std::size_t b = 0; b < a && !bad; ++b) bad = Conflict(m, mapped[a], mapped[b]);
          for (std::size_t b = 0; b < out.size() && !bad; ++b) bad = Conflict(m, mapped[a], out[b]);
          if (bad) {
            const auto& t = local[a];
            forbidden.insert((std::uint64_t(t[0]) * n + t[1]) * n + t[2]);
            accepted = false;
          }
        }
        if (accepted) out.insert(out.end(), mapped.begin(), mapped.end());
      }
      if (!accepted) return false;
    }
    // Lobes of one loop share at most their pinch vertices, but a diagonal could still repeat across
    // lobes (or repeat a side): every directed half-edge must be unique, or the edge is non-manifold.
    std::unordered_set<std::uint64_t> halfEdges;
    for (const Tri& t : out)
      for (int k = 0; k < 3; ++k)
        if (!halfEdges.insert((std::uint64_t(t[k]) << 32) | t[(k + 1) % 3]).second) return false;
    return true;
  }

  /// Adds the planned faces and registers them in the grid and the added-edge set.
  static void CommitFill(MeshType& m, const std::vector<Tri>& tris, FillContext& ctx) {
    if (tris.empty()) return;
    const Index first = Index(m.face.size());
    vcg::tri::Allocator<MeshType>::AddFaces(m, tris.size());
    for (std::size_t i = 0; i < tris.size(); ++i) {
      FaceType& f = m.face[first + i];
      for (int k = 0; k < 3; ++k) f.V(k) = &m.vert[tris[i][k]];
      for (int k = 0; k < 3; ++k) f.FFp(k) = &f, f.FFi(k) = k; // valid until the next rebuild
      ctx.grid->Insert(m, first + Index(i));
      for (int k = 0; k < 3; ++k) ctx.addedEdges.insert(EdgeKey(tris[i][k], tris[i][(k + 1) % 3]));
    }
  }

  static FillContext MakeContext(const Params& params, double meanEdge, double tol, FaceGrid* grid) {
    FillContext ctx;
    ctx.grid = grid;
    // Fill triangles must be clearly proper, far above the degenerate threshold.
    ctx.minArea = std::max(params.degenerateAreaEpsilon, 1e-8) * meanEdge * meanEdge;
    ctx.maxDihedral = params.maxFillDihedral * kPi / 180.0;
    ctx.tol = tol;
    return ctx;
  }

  // ------------------------------------------------------------------------------------------------
  // Step 7: local self-intersection repair
  // ------------------------------------------------------------------------------------------------

  /// Regions to repair: faces of intersecting pairs (MeshQuality's definition) and faces on both sides
  /// of an orientation conflict, grouped through those pairs and through shared edges.
  /// Returns whether anything was repaired.
  static bool RepairTangles(MeshType& m, const Params& params, double meanEdge, double tol,
                            bool intersections,
                            const std::vector<std::pair<Index, Index>>& orientationConflicts,
                            int& attemptsLeft, Result& r) {
    // Intersecting pairs, grouped into regions (union-find over faces).
    std::vector<Index> parent(m.face.size());
    std::iota(parent.begin(), parent.end(), Index(0));
    auto find = [&parent](Index x) {
      while (parent[x] != x) x = parent[x] = parent[parent[x]];
      return x;
    };
    std::vector<std::uint8_t> involved(m.face.size(), 0);
    if (intersections) {
      // All pairs at once with MeshQuality's parallel broad phase and Conflict's predicates
      // (faces on the same three vertices intersect). Each region's root is its smallest face,
      // so the regions do not depend on the order the pairs come in.
      std::vector<Tri> tris;
      std::vector<Index> faceOf;
      for (Index f = 0; f < m.face.size(); ++f) {
        if (m.face[f].IsD()) continue;
        tris.push_back(FaceTri(m, m.face[f]));
        faceOf.push_back(f);
      }
      std::vector<Point> points(m.vert.size());
      for (Index v = 0; v < m.vert.size(); ++v) points[v] = PositionOf(&m.vert[v]);
      const auto pairs =
          FindSelfIntersections(tris, points, meanEdge, ResolveThreadCount(params.threads), true);
      for (const IntersectingPair& pair : pairs) {
        const Index f = faceOf[pair.i], g = faceOf[pair.j];
        involved[f] = involved[g] = 1;
        const Index a = find(f), b = find(g);
        if (a != b) parent[std::max(a, b)] = std::min(a, b);
      }
    }
    for (const auto& [f, g] : orientationConflicts) {
      if (m.face[f].IsD() || m.face[g].IsD()) continue;
      involved[f] = involved[g] = 1;
      const Index a = find(f), b = find(g);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
    // Faces of one tangle that share an edge belong to the same region too.
    for (Index f = 0; f < m.face.size(); ++f) {
      if (!involved[f]) continue;
      for (int e = 0; e < 3; ++e) {
        const Index g = FI(m, m.face[f].FFp(e));
        if (involved[g]) {
          const Index a = find(f), b = find(g);
          if (a != b) parent[std::max(a, b)] = std::min(a, b);
        }
      }
    }
    std::unordered_map<Index, std::vector<Index>> regions;
    std::vector<Index> roots;
    for (Index f = 0; f < m.face.size(); ++f)
      if (involved[f]) {
        const Index root = find(f);
        if (regions.find(root) == regions.end()) roots.push_back(root);
        regions[root].push_back(f);
      }
    // Smallest first. For orientation conflicts, stop at the first repair: the caller re-orients, and
    // the other conflicts were often only where the traversal met itself around that one defect.
    std::stable_sort(roots.begin(), roots.end(),
                     [&regions](Index a, Index b) { return regions[a].size() < regions[b].size(); });
    std::size_t repaired = 0;
    // The repairs' face grid, built once there is something to repair (from the faces as they are
    // now: nothing above has edited them).
    std::optional<FaceGrid> grid;
    if (!roots.empty()) grid.emplace(m, 2.0 * meanEdge);
    for (Index root : roots) {
      // An earlier repair may have taken some of these faces with it (its grown rings).
      std::vector<Index> live;
      for (Index f : regions[root])
        if (!m.face[f].IsD()) live.push_back(f);
      if (live.empty()) continue;
      if (RepairRegion(m, live, params, meanEdge, tol, *grid, attemptsLeft, r.tangleFacesRemoved,
                       r.tangleFacesAdded)) {
        ++r.repairedTangles;
        ++repaired;
        if (!intersections) return true;
      } else if (intersections) {
        ++r.unrepairedTangles;
      }
    }
    return repaired > 0;
  }

  /// Removes `seed` plus `ring` rings of faces around it and refills; keeps the result only if every
  /// loop opened by the removal is filled validly. Tries growing rings. Topology is fresh on return.
  static bool RepairRegion(MeshType& m, const std::vector<Index>& seed, const Params& params, double meanEdge,
                           double tol, FaceGrid& grid, int& attemptsLeft, std::size_t& facesRemoved,
                           std::size_t& facesAdded, const std::vector<Index>* reinsertExcept = nullptr) {
    for (Index f : seed)
      if (m.face[f].IsD()) return false;
    std::vector<Index> region = seed;
    std::vector<std::pair<Index, int>> star;
    for (int ring = 0; ring <= params.maxRepairGrowth; ++ring) {
      if (ring > 0) { // grow by the faces sharing a vertex with the region
        std::vector<Index> grown = region;
        for (Index f : region)
          for (int k = 0; k < 3; ++k) {
            Star(m, VI(m, m.face[f], k), star);
            for (const auto& sf : star) grown.push_back(sf.first);
          }
        std::sort(grown.begin(), grown.end());
        grown.erase(std::unique(grown.begin(), grown.end()), grown.end());
        if (grown.size() == region.size()) break;
        region = std::move(grown);
      }
      if (int(region.size()) > params.maxRepairRegionFaces || attemptsLeft <= 0) return false;
      --attemptsLeft;
      // Half-edges of the remaining mesh that will bound the hole.
      std::vector<std::uint8_t> inRegion(m.face.size(), 0);
      for (Index f : region) inRegion[f] = 1;
      std::vector<std::pair<Index, int>> seeds;
      for (Index f : region)
        for (int e = 0; e < 3; ++e) {
          const FaceType* g = m.face[f].cFFp(e);
          const Index gi = FI(m, g);
          if (!inRegion[gi]) seeds.emplace_back(gi, m.face[f].cFFi(e));
        }
      if (seeds.empty()) return false; // a whole component: not a local tangle
      for (Index f : region) DeleteFace(m, f);
      RebuildTopology(m);
      FillContext ctx = MakeContext(params, meanEdge, tol, &grid);
      std::vector<std::uint8_t> visited(m.face.size(), 0);
      std::vector<std::vector<Tri>> plans;
      bool ok = true;
      Loop loop;
      std::unordered_set<Index> onEarlierLoops;
      for (const auto& [f, e] : seeds) {
        if (visited[f] & (1u << e)) continue;
        if (!IsBorderEdge(m.face[f], e) || !TraceLoop(m, f, e, visited, loop) ||
            int(loop.verts.size()) > std::max(params.maxHoleEdges, 3 * int(region.size()) + 3)) {
          ok = false;
          break;
        }
        // A vertex on two loops would be left with two closed fans (a pinch): take a larger region.
        std::vector<Index> loopVerts = loop.verts;
        std::sort(loopVerts.begin(), loopVerts.end());
        loopVerts.erase(std::unique(loopVerts.begin(), loopVerts.end()), loopVerts.end());
        for (Index v : loopVerts)
          if (!onEarlierLoops.insert(v).second) ok = false;
        if (!ok) break;
        std::vector<Tri> plan;
        if (!PlanLoopFill(m, loop, ctx, plan)) {
          ok = false;
          break;
        }
        for (const Tri& t : plan)
          for (int k = 0; k < 3; ++k) ctx.addedEdges.insert(EdgeKey(t[k], t[(k + 1) % 3]));
        plans.push_back(std::move(plan));
      }
      // Fill triangles of different loops must not meet either.
      if (ok) {
        std::vector<Tri> all;
        for (const auto& plan : plans) all.insert(all.end(), plan.begin(), plan.end());
        for (std::size_t a = 0; a < all.size() && ok; ++a)
          for (std::size_t b = 0; b < a && ok; ++b) ok = !Conflict(m, all[a], all[b]);
        if (ok) {
          ctx.addedEdges.clear();
          std::size_t added = 0;
          const Index firstAdded = Index(m.face.size());
          for (const auto& plan : plans) {
            CommitFill(m, plan, ctx);
            added += plan.size();
          }
          if (reinsertExcept) {
            std::vector<std::uint8_t> onLoop(m.vert.size(), 0);
            for (Index f = firstAdded; f < m.face.size(); ++f)
              for (int k = 0; k < 3; ++k) onLoop[VI(m, m.face[f], k)] = 1;
            std::vector<Index> inner;
            for (Index f : region)
              for (int k = 0; k < 3; ++k) {
                const Index v = VI(m, m.face[f], k);
                if (onLoop[v] ||
                    std::find(reinsertExcept->begin(), reinsertExcept->end(), v) != reinsertExcept->end())
                  continue;
                inner.push_back(v);
              }
            std::sort(inner.begin(), inner.end());
            inner.erase(std::unique(inner.begin(), inner.end()), inner.end());
            added += ReinsertVertices(m, inner, firstAdded, ctx);
          }
          RebuildTopology(m);
          facesRemoved += region.size();
          facesAdded += added;
          return true;
        }
      }
      for (Index f : region) UndeleteFace(m, f);
      RebuildTopology(m);
    }
    return false;
  }

  /// Puts vertices of a removed region back into its fill, each into the fill face it lies closest
  /// above or below (split 1 -> 3), farthest first, when the three new faces are proper, keep the
  /// face's orientation and meet no other face. A fill without interior vertices is flat; this
  /// brings it back onto the surface it replaced. Returns the faces added.
  static std::size_t ReinsertVertices(MeshType& m, const std::vector<Index>& vertices, Index firstFill,
                                      FillContext& ctx) {
    std::size_t added = 0;
    std::vector<Index> near;
    std::vector<std::uint8_t> done(vertices.size(), 0);
    for (std::size_t round = 0; round < vertices.size(); ++round) {
      // The vertex farthest from the fill goes first.
      double bestDistance = -1;
      std::size_t bestVertex = vertices.size();
      Index bestFace = 0;
      for (std::size_t i = 0; i < vertices.size(); ++i) {
        if (done[i]) continue;
        const Point p = PositionOf(&m.vert[vertices[i]]);
        double nearest = std::numeric_limits<double>::infinity();
        Index face = 0;
        for (Index f = firstFill; f < m.face.size(); ++f) {
          if (m.face[f].IsD()) continue;
          const Tri t = FaceTri(m, m.face[f]);
          const std::array<Point, 3> c{PositionOf(&m.vert[t[0]]), PositionOf(&m.vert[t[1]]),
                                       PositionOf(&m.vert[t[2]])};
          const Point n = hole_triangulation::UnitNormal(c[0], c[1], c[2]);
          if (n == Point(0, 0, 0)) continue;
          bool inside = true; // p projects into the face
          for (int k = 0; k < 3; ++k)
            if (((c[(k + 1) % 3] - c[k]) ^ (p - c[k])) * n < 0) inside = false;
          if (!inside) continue;
          const double d = std::fabs((p - c[0]) * n);
          if (d < nearest) nearest = d, face = f;
        }
        if (nearest == std::numeric_limits<double>::infinity()) continue;
        if (nearest > bestDistance) bestDistance = nearest, bestVertex = i, bestFace = face;
      }
      if (bestVertex == vertices.size()) break;
      done[bestVertex] = 1;
      const Index v = vertices[bestVertex];
      const Tri t = FaceTri(m, m.face[bestFace]);
      const std::array<Tri, 3> split{Tri{t[0], t[1], v}, Tri{t[1], t[2], v}, Tri{t[2], t[0], v}};
      const Point n = FaceNormal(m, m.face[bestFace]);
      bool ok = true;
      for (const Tri& nt : split) { // proper, and within 60 degrees of the face it splits
        const Point a = PositionOf(&m.vert[nt[0]]), b = PositionOf(&m.vert[nt[1]]),
                    c = PositionOf(&m.vert[nt[2]]);
        if (!(hole_triangulation::TriArea(a, b, c) > ctx.minArea) ||
            hole_triangulation::UnitNormal(a, b, c) * n <= 0.5)
          ok = false;
      }
      if (!ok) continue;
      for (const Tri& nt : split) {
        ctx.grid->Query(m, FaceGrid::Box(m, nt, ctx.tol), near);
        for (Index g : near)
          if (g != bestFace && Conflict(m, nt, FaceTri(m, m.face[g]))) ok = false;
        if (!ok) break;
      }
      if (!ok) continue;
      FaceType& f = m.face[bestFace];
      f.V(2) = &m.vert[v];
      const Index first = Index(m.face.size());
      vcg::tri::Allocator<MeshType>::AddFaces(m, 2);
      for (int i = 0; i < 2; ++i) {
        FaceType& g = m.face[first + Index(i)];
        for (int k = 0; k < 3; ++k) g.V(k) = &m.vert[split[std::size_t(i) + 1][k]];
        for (int k = 0; k < 3; ++k) g.FFp(k) = &g, g.FFi(k) = k;
        ctx.grid->Insert(m, first + Index(i));
      }
      ctx.grid->Insert(m, bestFace);
      added += 2;
    }
    return added;
  }

  /// A split vertex and its copy sit at the same point: when both keep faces, their fans touch, which
  /// is a self-intersection. Remove the copy's fan (or else the original's) and refill the hole
  /// around it without the vertex, checked like any fill. When no refill is possible (the fan is a
  /// whole open component, say) move the copy (or else the original) a little into its own fan, as
  /// vcglib's SplitNonManifoldVertex does with its moveThreshold, if that creates no intersection and
  /// turns no face over. Otherwise they stay touching (counted).
  static void SeparateSplitCopies(MeshType& m, const std::vector<std::pair<Index, Index>>& pairs,
                                  const Params& params, double meanEdge, double tol, int& attemptsLeft,
                                  Result& r) {
    std::unique_ptr<FaceGrid> grid;
    std::vector<std::pair<Index, int>> starA, starB;
    for (const auto& [original, copy] : pairs) {
      Star(m, original, starA);
      Star(m, copy, starB);
      if (starA.empty() || starB.empty()) continue; // one side was removed (e.g. a small component)
      if (!grid) grid.reset(new FaceGrid(m, 2.0 * meanEdge));
      bool done = false;
      for (const auto* star : {&starB, &starA}) {
        std::vector<Index> fan;
        for (const auto& corner : *star) fan.push_back(corner.first);
        std::size_t removed = 0, added = 0;
        const std::vector<Index> split{original, copy};
        if (RepairRegion(m, fan, params, meanEdge, tol, *grid, attemptsLeft, removed, added, &split)) {
          r.retriangulatedPinchFans += 1;
          r.pinchFanFacesRemoved += removed;
          r.pinchFanFacesAdded += added;
          done = true;
          break;
        }
        Star(m, original, starA); // the failed attempt rebuilt the adjacency
      }
      if (!done) {
        for (const Index v : {copy, original}) {
          if (NudgeIntoFan(m, v, meanEdge, *grid)) {
            ++r.movedSplitVertices;
            done = true;
            break;
          }
        }
      }
      if (!done) ++r.touchingSplitVertices;
    }
  }

  /// Moves v by 1% of the way to the centroid of its fan's faces when no face of the fan degenerates,
  /// turns over or meets another face. Returns false (and leaves v where it was) otherwise.
  static bool NudgeIntoFan(MeshType& m, Index v, double meanEdge, FaceGrid& grid) {
    std::vector<std::pair<Index, int>> star;
    Star(m, v, star);
    if (star.empty()) return false;
    const Point old = PositionOf(&m.vert[v]);
    Point centroid(0, 0, 0);
    for (const auto& corner : star) {
      const Tri t = FaceTri(m, m.face[corner.first]);
      centroid += (PositionOf(&m.vert[t[0]]) + PositionOf(&m.vert[t[1]]) + PositionOf(&m.vert[t[2]])) / 3.0;
    }
    centroid /= double(star.size());
    std::vector<Point> oldNormals;
    for (const auto& corner : star) oldNormals.push_back(FaceNormal(m, m.face[corner.first]));
    const Point target = old + (centroid - old) * 0.01;
    using CoordType = typename MeshType::CoordType;
    using Scalar = typename MeshType::ScalarType;
    m.vert[v].P() = CoordType(Scalar(target[0]), Scalar(target[1]), Scalar(target[2]));
    bool ok = PositionOf(&m.vert[v]) != old;
    std::vector<Index> candidates;
    for (std::size_t i = 0; i < star.size() && ok; ++i) {
      const Tri t = FaceTri(m, m.face[star[i].first]);
      if (FaceArea(m, m.face[star[i].first]) <= 1e-10 * meanEdge * meanEdge ||
          FaceNormal(m, m.face[star[i].first]) * oldNormals[i] < 0.9) {
        ok = false;
        break;
      }
      grid.Query(m, FaceGrid::Box(m, t, 1e-9 * meanEdge), candidates);
      for (Index g : candidates)
        if (g != star[i].first && Conflict(m, t, FaceTri(m, m.face[g]))) {
          ok = false;
          break;
        }
    }
    if (!ok) m.vert[v].P() = CoordType(Scalar(old[0]), Scalar(old[1]), Scalar(old[2]));
    return ok;
  }

  // ------------------------------------------------------------------------------------------------
  // Step 8: holes
  // ------------------------------------------------------------------------------------------------

  /// A loop within params.maxHoleEdges that no triangulation of its own vertices fills validly (a
  /// twisted marching-cubes slit whose only fold-bounded triangulation crosses the mesh) is grown
  /// instead: its boundary faces, then up to params.maxRepairGrowth rings around them, are removed
  /// and the larger hole refilled (RepairRegion, as a tangle; kept only when valid).
  static void FillHoles(MeshType& m, const Params& params, double meanEdge, double tol, int& attemptsLeft,
                        Result& r) {
    std::vector<std::uint8_t> visited(m.face.size(), 0);
    std::vector<Loop> loops;
    Loop loop;
    for (Index f = 0; f < m.face.size(); ++f) {
      if (m.face[f].IsD()) continue;
      for (int e = 0; e < 3; ++e)
        if (IsBorderEdge(m.face[f], e) && !(visited[f] & (1u << e))) {
          if (TraceLoop(m, f, e, visited, loop))
            loops.push_back(loop);
          else
            ++r.unfilledHoles;
        }
    }
    if (loops.empty()) return;
    std::unique_ptr<FaceGrid> grid;
    FillContext ctx;
    bool changed = false;
    std::vector<const Loop*> unfilled;
    for (const Loop& l : loops) {
      const std::size_t edges = l.verts.size();
      if (int(edges) <= params.maxHoleEdges) {
        if (!grid) {
          grid.reset(new FaceGrid(m, 2.0 * meanEdge));
          ctx = MakeContext(params, meanEdge, tol, grid.get());
        }
        std::vector<Tri> plan;
        if (PlanLoopFill(m, l, ctx, plan)) {
          CommitFill(m, plan, ctx);
          changed = true;
          ++r.closedHoles;
          r.holeFacesAdded += plan.size();
          continue;
        }
      }
      unfilled.push_back(&l);
    }
    if (changed) RebuildTopology(m);
    for (const Loop* l : unfilled) {
      bool filled = false;
      if (int(l->verts.size()) <= params.maxHoleEdges) {
        // Its faces, each once (a face with two boundary sides is on the loop twice).
        std::vector<Index> seed = l->faces;
        std::sort(seed.begin(), seed.end());
        seed.erase(std::unique(seed.begin(), seed.end()), seed.end());
        std::size_t removed = 0, added = 0;
        if (LoopStillOpen(m, *l) &&
            RepairRegion(m, seed, params, meanEdge, tol, *grid, attemptsLeft, removed, added)) {
          filled = true;
          ++r.closedHoles;
          ++r.grownHoles;
          r.holeFacesRemoved += removed;
          r.holeFacesAdded += added;
        }
      }
      if (!filled) {
        ++r.unfilledHoles;
        r.largestUnfilledHoleEdges = std::max(r.largestUnfilledHoleEdges, l->verts.size());
      }
    }
  }

  // ------------------------------------------------------------------------------------------------
  // Step 10: outward orientation of closed components
  // ------------------------------------------------------------------------------------------------

  /// Parity of the crossings of the ray origin + t dir (t > 0) with the faces; ambiguous when the ray
  /// grazes an edge or a vertex (then another direction is tried).
  static bool RayParity(const MeshType& m, const std::vector<Index>& faces, const Point& origin,
                        const Point& dir, bool& ambiguous) {
    ambiguous = false;
    bool odd = false;
    for (Index f : faces) {
      const Tri t = FaceTri(m, m.face[f]);
      const Point a = PositionOf(&m.vert[t[0]]), b = PositionOf(&m.vert[t[1]]), c = PositionOf(&m.vert[t[2]]);
      const Point e1 = b - a, e2 = c - a;
      const Point q = dir ^ e2;
      const double det = e1 * q;
      const double scale = e1.Norm() * e2.Norm();
      if (std::fabs(det) <= 1e-12 * scale) continue; // parallel: cannot cross transversally
      const double inv = 1.0 / det;
      const Point s = origin - a;
      const double u = (s * q) * inv;
      if (u < -1e-9 || u > 1 + 1e-9) continue;
      const Point rr = s ^ e1;
      const double v = (dir * rr) * inv;
      if (v < -1e-9 || u + v > 1 + 1e-9) continue;
      const double t0 = (e2 * rr) * inv;
      if (t0 <= 0) continue;
      if (u < 1e-9 || v < 1e-9 || u + v > 1 - 1e-9) {
        ambiguous = true;
        return false;
      }
      odd = !odd;
    }
    return odd;
  }

  static void OrientOutward(MeshType& m, bool cavitiesInward, std::vector<std::uint8_t>& flipped, Result& r) {
    std::vector<Index> label;
    std::vector<std::size_t> size;
    const std::size_t count = LabelComponents(m, label, size);
    std::vector<std::vector<Index>> faces(count);
    std::vector<std::uint8_t> closed(count, 1);
    for (Index f = 0; f < m.face.size(); ++f) {
      if (m.face[f].IsD()) continue;
      faces[label[f]].push_back(f);
      for (int e = 0; e < 3; ++e)
        if (IsBorderEdge(m.face[f], e)) closed[label[f]] = 0;
    }
    std::vector<double> volume(count, 0);
    std::vector<vcg::Box3d> box(count);
    for (std::size_t c = 0; c < count; ++c) {
      Point centroid(0, 0, 0);
      std::size_t n = 0;
      for (Index f : faces[c])
        for (int k = 0; k < 3; ++k) {
          centroid += PositionOf(&m.vert[VI(m, m.face[f], k)]);
          box[c].Add(PositionOf(&m.vert[VI(m, m.face[f], k)]));
          ++n;
        }
      centroid /= double(n);
      for (Index f : faces[c]) {
        const Tri t = FaceTri(m, m.face[f]);
        volume[c] += (PositionOf(&m.vert[t[0]]) - centroid) *
                     ((PositionOf(&m.vert[t[1]]) - centroid) ^ (PositionOf(&m.vert[t[2]]) - centroid)) / 6.0;
      }
    }
    const std::array<Point, 5> directions{Point(0.5773, 0.5774, 0.5775), Point(-0.7071, 0.4082, 0.5774),
                                          Point(0.1, -0.9, 0.4243), Point(-0.3, -0.2, -0.9327),
                                          Point(0.8, 0.1, -0.5916)};
    bool changed = false;
    for (std::size_t c = 0; c < count; ++c) {
      if (!closed[c] || volume[c] == 0) continue;
      int depth = 0;
      if (cavitiesInward) {
        // A point on the component: the centroid of its largest face.
        Index probe = faces[c].front();
        double bestArea = -1;
        for (Index f : faces[c]) {
          const double a = FaceArea(m, m.face[f]);
          if (a > bestArea) bestArea = a, probe = f;
        }
        const Tri t = FaceTri(m, m.face[probe]);
        const Point origin =
            (PositionOf(&m.vert[t[0]]) + PositionOf(&m.vert[t[1]]) + PositionOf(&m.vert[t[2]])) / 3.0;
        // Containers may be open (a hole left unfilled): the vote over several rays tolerates a ray
        // escaping through a small hole.
        for (std::size_t d = 0; d < count; ++d) {
          if (d == c || !box[d].IsIn(box[c].min) || !box[d].IsIn(box[c].max)) continue;
          int inside = 0, outside = 0;
          for (const Point& dir : directions) {
            bool ambiguous = false;
            const bool in = RayParity(m, faces[d], origin, dir / dir.Norm(), ambiguous);
            if (!ambiguous) (in ? inside : outside) += 1;
          }
          if (inside > outside) ++depth;
        }
      }
      const bool wantPositive = depth % 2 == 0;
      if ((volume[c] > 0) == wantPositive) continue;
      for (Index f : faces[c]) {
        std::swap(m.face[f].V(1), m.face[f].V(2));
        flipped[f] ^= 1;
      }
      ++r.flippedComponents;
      changed = true;
    }
    if (changed) RebuildTopology(m);
  }
};

} // namespace molremesh

// Stage 0 of molremesh: clean a raw molecular surface mesh so that the remeshing stages start from
// a valid 2-manifold (SMOPT-style cleaning, done with local, checked edits).
//
// CleanRawMesh<MeshType>::Do(m, params, cb) runs these steps, in this order (the order matters: each
// step relies on what the previous ones guarantee). Each step is one entry point of a header in
// vcg_ext/clean/, which states its preconditions; this class only sequences them and fills the result.
//   1. vertex_merging.h, degenerate_faces.h: merge vertices closer than params.mergeTolerance * mean
//      edge length (the surviving vertex keeps its position; nothing moves), drop faces with a repeated
//      vertex index, duplicate faces (same vertex set) and unreferenced vertices;
//   2. non_manifold_edges.h: make every edge manifold by removing, on each edge with k > 2 faces, the
//      k - 2 faces that do not belong to the flattest consistently oriented pair (the holes this leaves
//      are closed in step 9);
//   3. orientation.h: orient every component coherently (the majority orientation of the input wins);
//   4. degenerate_faces.h: remove zero-area faces without opening a hole (a cap by an edge flip, a
//      needle by an edge collapse, a zero-area boundary face by dropping it when that pinches nothing);
//   5. non_manifold_vertices.h: split non-manifold vertices that join closed fans (two surfaces
//      touching at a point); boundary "pinch" vertices (a hole boundary passing twice through a
//      vertex) are left to step 9, which closes them into a single manifold fan;
//   6. component_filter.h (the component policy): keep every component that encloses a volume (outer
//      surface, cavities, separate parts); remove pieces that enclose none (fewer than 4 faces, or at
//      most params.flatComponentVolume * mean edge^3) and, only when asked, components below
//      params.minComponentVolume, params.minComponentFaces or params.minComponentFraction (never
//      the largest one);
//   7. non_manifold_vertices.h: a split copy and its original that both kept faces touch (a
//      self-intersection): the copy's fan (or else the original's) is removed and its hole refilled
//      without the vertex (region_refill.h); if that is impossible, the copy is moved by 1% of the way
//      into its own fan (vcglib's moveThreshold idea) when that is valid;
//   8. tangle_repair.h, with params.repairTangles: repair local tangles, first the faces of
//      self-intersecting pairs, then the faces where the orientation cannot be made coherent
//      (re-orienting after each repair). A tangle (plus up to params.maxRepairGrowth rings around it) is
//      removed and its hole refilled (region_refill.h), kept only when every refill is valid, so a
//      repair never opens a hole, never adds an intersection and never leaves a non-manifold vertex.
//      Then the components still holding an orientation conflict are counted as non-orientable;
//   9. hole_filling.h: close every hole whose boundary loop has at most params.maxHoleEdges edges with
//      a minimum-weight triangulation (loop_fill.h over hole_triangulation.h, Liepa 2003), every fill
//      triangle checked against the mesh and the other fill triangles; a loop that cannot be filled so
//      is grown and refilled as a tangle is; a loop that still cannot be filled stays open (counted);
//  10. non_manifold_vertices.h: split any vertex that is still non-manifold (next to an unfilled hole,
//      or where two separate loops met at a vertex) and separate the copies as in step 7;
//  11. orientation.h: orient every closed component outward: positive volume, except, with
//      params.orientCavitiesInward, the cavities of a molecular surface, whose normals point into
//      the cavity (negative volume). params.nestedComponents says how a nested component is read:
//      by the union of what the pieces enclose (one oriented as the region around it lies inside
//      it, as PyMOL leaves inside its SES, and is removed) or by the parity of its depth;
//  12. delete vertices left without faces, compact the vectors, measure the result (MeshQuality).
//  13. volumetric_fallback.h, with params.volumetricFallback: when a defect is left (a component that
//      cannot be oriented, an unrepaired tangle, an unfilled hole, a boundary, non-manifold or
//      degenerate element, a self-intersection when measured), the whole surface is rebuilt as the
//      boundary of the union of the regions it encloses (OpenVDB; cavities and separate parts kept)
//      and steps 1-12 run again on it; the remaining-defect counts are then the second pass's. The
//      rebuilt surface is a re-extraction: there the "vertices never move" guarantee below does not
//      hold. With params.volumetricRebuild the step runs whatever the local steps left (opt-in: it
//      removes the parts thinner than about two voxels, see clean_params.h). Without the volume
//      layer (a build without OpenVDB) the step reports "not available".
// Every action is counted in the returned CleanRawMeshResult (clean_result.h); nothing is removed
// silently. The remove-and-refill steps (7, 8, 9 and 10) share one budget of params.maxRepairAttempts
// attempts (clean::CleanRunState, clean_params.h), drawn from in that order, and each of them has its
// own budget of fill planning work, params.fillWorkPerFace per input face (loop_fill.h): a region or
// loop whose fill the budget cannot pay for is left as it is (counted in fillBudgetRefusals and as an
// unrepaired tangle or unfilled hole), so the whole cleaning stays near-linear in the faces.
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

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <iomanip>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <vcg_ext/clean/clean_mesh_access.h>
#include <vcg_ext/clean/clean_params.h>
#include <vcg_ext/clean/clean_result.h>
#include <vcg_ext/clean/component_filter.h>
#include <vcg_ext/clean/degenerate_faces.h>
#include <vcg_ext/clean/hole_filling.h>
#include <vcg_ext/clean/non_manifold_edges.h>
#include <vcg_ext/clean/non_manifold_vertices.h>
#include <vcg_ext/clean/orientation.h>
#include <vcg_ext/clean/tangle_repair.h>
#include <vcg_ext/clean/vertex_merging.h>
#include <vcg_ext/clean/volumetric_fallback.h>
#include <vcg_ext/core/index.h>
#include <vcg_ext/core/input_check.h>
#include <vcg_ext/geometry/mean_edge_length.h>
#include <vcg_ext/quality/mesh_quality.h>
#include <vcg_ext/spatial/self_intersections.h>

namespace molremesh {

template <class MeshType>
class CleanRawMesh {
public:
  using Result = CleanRawMeshResult;
  using Params = CleanRawMeshParams;

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
  using VertexType = typename MeshType::VertexType;
  using Quality = MeshQuality<MeshType>;
  using Orientation = clean::Orientation<MeshType>;
  using SplitPairs = std::vector<std::pair<Index, Index>>; ///< (original, copy) of split vertices

  static void Progress(const Params& params, vcg::CallBackPos* cb, int percent, const char* what) {
    if (cb) (*cb)(percent, what);
    if (params.progress) params.progress(percent / 100.0, what);
  }

  // Refusal (nothing is modified before this returns true)
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
    if (!(params.minComponentVolume >= 0) || !std::isfinite(params.minComponentVolume) ||
        params.minComponentFaces < 0 || std::isnan(params.flatComponentVolume) ||
        !std::isfinite(params.flatComponentVolume))
      return refuse("minComponentVolume and minComponentFaces must be >= 0, flatComponentVolume finite");
    if (!(params.fillWorkPerFace >= 0) || !std::isfinite(params.fillWorkPerFace))
      return refuse("fillWorkPerFace must be a finite number >= 0");
    if (params.maxRepairGrowth < 0 || params.maxRepairRegionFaces < 0 || params.maxRepairAttempts < 0)
      return refuse("maxRepairGrowth, maxRepairRegionFaces and maxRepairAttempts must be >= 0");
    if (!(params.maxFillDihedral > 0 && params.maxFillDihedral <= 180))
      return refuse("maxFillDihedral must be in (0, 180] degrees");
    if (m.vert.size() >= std::size_t(clean::kNone) / 2 || m.face.size() >= std::size_t(clean::kNone) / 2)
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
      if (clean::FaceArea(m, f) > minArea) {
        anyProper = true;
        break;
      }
    }
    if (!anyProper) return refuse("every face of the mesh is degenerate (repeated vertex or zero area)");
    if (const std::string why = OverlapBeyondRepair(m, meanEdge, params.threads); !why.empty())
      return refuse(why);
    return true;
  }

  /// "" unless the faces overlap so much that the search for tangles would not end in reasonable
  /// time and memory: more candidate pairs than CandidatePairBound (10^7 + 1000 per face; 320
  /// random 255-gons in a 350 KB file have 3.3e9, 40 480 per face, where 56 molecular surfaces of
  /// every generator here have 22 to 43). Such a file is a soup of overlapping polygons, not a
  /// surface to repair.
  static std::string OverlapBeyondRepair(const MeshType& m, double meanEdge, int threads) {
    std::vector<clean::Tri> tris;
    for (const auto& f : m.face)
      if (!f.IsD() && f.cV(0) != f.cV(1) && f.cV(1) != f.cV(2) && f.cV(2) != f.cV(0))
        tris.push_back(clean::FaceTri(m, f));
    std::vector<Point> points(m.vert.size());
    for (std::size_t v = 0; v < m.vert.size(); ++v) points[v] = PositionOf(&m.vert[v]);
    const double pairs = CountCandidatePairs(tris, points, meanEdge, threads);
    if (!(pairs > CandidatePairBound(tris.size()))) return {};
    std::ostringstream s;
    s << "the faces overlap beyond repair: the search for intersecting faces would test " << std::fixed
      << std::setprecision(0) << pairs << " pairs (" << pairs / double(tris.size())
      << " per face; molecular surfaces have 22 to 43, the bound is 10^7 + "
      << kCandidatePairsPerTriangleBound << " per face)";
    return s.str();
  }

  // The steps, in order (see the file comment)

  /// measureInputIntersections = false: reportBefore without the self-intersection search (the
  /// cleaning of a rebuilt surface, whose own check found none and whose report nobody reads).
  static void Run(MeshType& m, const Params& params, vcg::CallBackPos* cb, Result& r,
                  bool measureInputIntersections = true) {
    typename Quality::Params qp;
    qp.computeSelfIntersections = params.measureSelfIntersections;
    qp.degenerateAreaEpsilon = params.degenerateAreaEpsilon;
    qp.threads = params.threads;
    Progress(params, cb, 0, "Measuring the input");
    typename Quality::Params qpBefore = qp;
    qpBefore.computeSelfIntersections = qp.computeSelfIntersections && measureInputIntersections;
    r.reportBefore = Quality::Compute(m, qpBefore);
    // The tolerances are relative to MeshQuality's mean edge length, so that "degenerate" means the
    // same thing here and in the report.
    const double meanEdge = r.reportBefore.meanEdgeLength > 0
                                ? r.reportBefore.meanEdgeLength
                                : MeanEdgeLength(m, /*skipCollapsedSides=*/true);
    const std::size_t inputFaces = m.face.size();

    Progress(params, cb, 5, "Merging coincident vertices");
    MergeAndDropBadFaces(m, params, meanEdge, r); // step 1

    Progress(params, cb, 15, "Removing faces on non-manifold edges");
    r.removedNonManifoldFaces = clean::ResolveNonManifoldEdges(m); // step 2
    if (r.removedNonManifoldFaces > 0) clean::RebuildTopology(m);

    Progress(params, cb, 20, "Orienting coherently");
    std::vector<std::uint8_t> flipped(m.face.size(),
                                      0); // per face: orientation reversed an odd number of times
    std::vector<std::pair<Index, Index>> orientationConflicts;
    Orientation::OrientCoherently(m, flipped, orientationConflicts); // step 3

    Progress(params, cb, 25, "Removing zero-area faces");
    FixZeroAreaFaces(m, params.degenerateAreaEpsilon * meanEdge * meanEdge, r); // step 4

    Progress(params, cb, 35, "Splitting non-manifold vertices");
    const SplitPairs splitEarly = SplitNonManifoldVertices(m, true, r); // step 5

    Progress(params, cb, 40, "Removing small components");
    RemoveSmallComponents(m, params, meanEdge, r); // step 6

    clean::CleanRunState run{params, meanEdge, PlaneTolerance(m, meanEdge), params.maxRepairAttempts};
    clean::ResetFillBudget(run, inputFaces);
    SeparateSplitCopies(m, splitEarly, run, r); // step 7
    if (params.repairTangles) {
      Progress(params, cb, 50, "Repairing local tangles");
      clean::ResetFillBudget(run, inputFaces);
      RepairTangles(m, run, flipped, orientationConflicts, r); // step 8
    }
    r.nonOrientableComponents = Orientation::CountNonOrientableComponents(m, orientationConflicts);
    r.unrepairedTangles += r.nonOrientableComponents; // at least one orientation defect in each

    Progress(params, cb, 70, "Closing holes");
    clean::ResetFillBudget(run, inputFaces);
    CloseHoles(m, run, r); // step 9

    Progress(params, cb, 85, "Splitting remaining non-manifold vertices");
    const SplitPairs splitLate = SplitNonManifoldVertices(m, false, r); // step 10
    clean::ResetFillBudget(run, inputFaces);
    SeparateSplitCopies(m, splitLate, run, r);
    r.fillBudgetRefusals = run.fillBudgetRefusals;

    Progress(params, cb, 90, "Orienting closed components outward");
    flipped.resize(m.face.size(), 0);
    const auto outward = Orientation::OrientOutward(m, params.orientCavitiesInward,
                                                    ReadNestedAsUnion(params, r), flipped); // step 11
    r.flippedComponents = outward.flippedComponents;
    r.removedInteriorComponents = outward.interior.size();
    r.removedInteriorFaces = outward.interiorFaces;
    r.removedComponents.insert(r.removedComponents.end(), outward.interior.begin(), outward.interior.end());
    for (std::size_t f = 0; f < inputFaces && f < m.face.size(); ++f)
      if (!m.face[f].IsD() && flipped[f]) ++r.flippedFacesForOrientation;

    Progress(params, cb, 95, "Compacting");
    r.removedOrphanedVertices = Finish(m); // step 12
    r.keptComponents = clean::KeptComponents(m);
    // A requested rebuild replaces this report by the rebuilt surface's: measured only if it fails.
    if (!params.volumetricRebuild) r.reportAfter = Quality::Compute(m, qp);
    const std::string trigger =
        params.volumetricRebuild ? std::string(kRebuildRequested) : FallbackTrigger(r);
    if ((params.volumetricFallback || params.volumetricRebuild) && !trigger.empty())
      FallBack(m, params, trigger, cb, r); // step 13
    if (params.volumetricRebuild && !r.fallback.rebuilt) r.reportAfter = Quality::Compute(m, qp);
    Progress(params, cb, 100, "Clean raw mesh done");
  }

  /// The trigger of step 13 when params.volumetricRebuild asks for it.
  static constexpr const char* kRebuildRequested = "the request to rebuild (volumetricRebuild)";

  /// The defects the local steps left, as a phrase; empty when there is none.
  static std::string FallbackTrigger(const Result& r) {
    std::string s;
    auto add = [&s](std::size_t n, const char* what) {
      if (n > 0) s += (s.empty() ? "" : ", ") + std::to_string(n) + " " + what;
    };
    add(r.nonOrientableComponents, "non-orientable components");
    add(r.unrepairedTangles, "unrepaired tangles");
    add(r.unfilledHoles, "unfilled holes");
    add(r.reportAfter.boundaryEdges, "boundary edges");
    add(r.reportAfter.nonManifoldEdges + r.reportAfter.nonManifoldVertices, "non-manifold elements");
    add(r.reportAfter.degenerateFaces, "degenerate faces");
    if (r.reportAfter.selfIntersectionsComputed)
      add(r.reportAfter.selfIntersectingFaces, "self-intersecting faces");
    return s;
  }

  /// Step 13 (volumetric_fallback.h): the whole surface rebuilt from the union of what it encloses,
  /// then cleaned again without the fallback; the remaining-defect counts become the second pass's.
  static void FallBack(MeshType& m, const Params& params, const std::string& trigger, vcg::CallBackPos* cb,
                       Result& r) {
    Progress(params, cb, 96, "Rebuilding the surface volumetrically");
    r.fallback.trigger = trigger;
    const clean::VolumetricFallbackOutcome o = clean::RebuildVolumetrically(m, params.threads);
    r.fallback.available = o.available;
    r.fallback.message = o.message;
    if (!o.ok) return; // m unchanged
    r.fallback.rebuilt = true;
    r.fallback.facesIn = o.facesIn, r.fallback.facesOut = o.facesOut;
    r.fallback.areaIn = o.areaIn, r.fallback.areaOut = o.areaOut;
    r.fallback.voxelSize = o.voxelSize;
    Params again = params;
    again.volumetricFallback = again.volumetricRebuild = false;
    Result second;
    Run(m, again, nullptr, second, /*measureInputIntersections=*/false);
    r.nonOrientableComponents = second.nonOrientableComponents;
    r.unrepairedTangles = second.unrepairedTangles;
    r.unfilledHoles = second.unfilledHoles;
    r.largestUnfilledHoleEdges = second.largestUnfilledHoleEdges;
    r.remainingDegenerateFaces = second.remainingDegenerateFaces;
    r.touchingSplitVertices = second.touchingSplitVertices;
    r.removedComponents.insert(r.removedComponents.end(), second.removedComponents.begin(),
                               second.removedComponents.end());
    r.removedSmallComponents += second.removedSmallComponents;
    r.removedComponentFaces += second.removedComponentFaces;
    r.removedInteriorComponents += second.removedInteriorComponents;
    r.removedInteriorFaces += second.removedInteriorFaces;
    r.keptComponents = std::move(second.keptComponents);
    r.reportAfter = second.reportAfter;
  }

  static void MergeAndDropBadFaces(MeshType& m, const Params& params, double meanEdge, Result& r) {
    r.mergedVertices = clean::MergeCloseVertices(m, params.mergeTolerance * meanEdge, 0.5 * meanEdge);
    r.removedDegenerateFaces += clean::RemoveIndexDegenerateFaces(m);
    r.removedDuplicateFaces = clean::RemoveDuplicateFaces(m);
    r.removedUnreferencedVertices = clean::RemoveUnreferencedVertices(m);
    clean::RebuildTopology(m);
  }

  static void FixZeroAreaFaces(MeshType& m, double degenerateArea, Result& r) {
    clean::ZeroAreaFaceCounts c;
    clean::ZeroAreaFaces<MeshType>::Fix(m, degenerateArea, c);
    r.removedDegenerateFaces += c.removed;
    r.flippedDegenerateFaces = c.flipped;
    r.collapsedDegenerateEdges = c.collapsed;
    r.remainingDegenerateFaces = c.remaining;
  }

  static SplitPairs SplitNonManifoldVertices(MeshType& m, bool onlyClosedFans, Result& r) {
    const SplitPairs made = clean::NonManifoldVertices<MeshType>::SplitNonManifoldVertices(m, onlyClosedFans);
    r.splitNonManifoldVertices += made.size();
    return made;
  }

  /// Whether step 11 reads nested components by the union of what the pieces enclose: asked for,
  /// or, by default, for a triangle soup (most of its vertices merged in step 1) whose sheets
  /// overlap (tangles or non-manifold edges to repair).
  static bool ReadNestedAsUnion(const Params& params, const Result& r) {
    if (params.nestedComponents != NestedComponents::Auto)
      return params.nestedComponents == NestedComponents::Union;
    const bool soup = r.mergedVertices > 0 && 2 * r.mergedVertices >= r.reportBefore.vertices;
    return soup && r.repairedTangles + r.unrepairedTangles + r.removedNonManifoldFaces > 0;
  }

  /// The component policy (component_filter.h).
  static void RemoveSmallComponents(MeshType& m, const Params& params, double meanEdge, Result& r) {
    clean::ComponentFilterCounts c;
    clean::RemoveSmallComponents(m, params, meanEdge, c);
    r.removedSmallComponents = c.removedComponents;
    r.removedComponentFaces = c.removedFaces;
    r.removedComponents = std::move(c.removed);
  }

  static void SeparateSplitCopies(MeshType& m, const SplitPairs& pairs, clean::CleanRunState& run,
                                  Result& r) {
    clean::SplitSeparationCounts c;
    clean::NonManifoldVertices<MeshType>::SeparateSplitCopies(m, pairs, run, c);
    r.retriangulatedPinchFans += c.retriangulatedFans;
    r.pinchFanFacesRemoved += c.fanFacesRemoved;
    r.pinchFanFacesAdded += c.fanFacesAdded;
    r.movedSplitVertices += c.moved;
    r.touchingSplitVertices += c.touching;
  }

  /// The tangle repair (tangle_repair.h).
  static void RepairTangles(MeshType& m, clean::CleanRunState& run, std::vector<std::uint8_t>& flipped,
                            std::vector<std::pair<Index, Index>>& orientationConflicts, Result& r) {
    clean::TangleRepairCounts c;
    clean::TangleRepair<MeshType>::Run(m, run, flipped, orientationConflicts, c);
    r.repairedTangles = c.repaired;
    r.unrepairedTangles = c.unrepaired;
    r.tangleFacesRemoved = c.facesRemoved;
    r.tangleFacesAdded = c.facesAdded;
  }

  static void CloseHoles(MeshType& m, clean::CleanRunState& run, Result& r) {
    clean::HoleFillCounts c;
    clean::HoleFilling<MeshType>::Run(m, run, c);
    r.closedHoles = c.closed;
    r.holeFacesAdded = c.facesAdded;
    r.grownHoles = c.grown;
    r.holeFacesRemoved = c.facesRemoved;
    r.unfilledHoles = c.unfilled;
    r.largestUnfilledHoleEdges = c.largestUnfilledEdges;
  }

  /// Deletes unreferenced vertices, compacts every vector and rebuilds FF/VF. Returns the vertices deleted.
  static std::size_t Finish(MeshType& m) {
    const std::size_t removed = clean::RemoveUnreferencedVertices(m);
    vcg::tri::Allocator<MeshType>::CompactEveryVector(m);
    clean::RebuildTopology(m);
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
};

} // namespace molremesh

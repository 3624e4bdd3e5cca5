// What CleanRawMesh (vcg_ext/clean/clean_raw_mesh.h) returns: the counts of every step and the
// quality reports of the input and of the result. Formatted by CleanRawMeshSummary
// (vcg_ext/quality/stage_summary.h).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <vcg_ext/quality/mesh_quality.h>

namespace molremesh {

/// One connected component (through shared edges), kept or removed by the component policy.
struct CleanComponent {
  std::size_t faces = 0;
  double volume = 0;            ///< signed volume about its centroid: > 0 outward, < 0 a cavity (inward)
  bool closed = true;           ///< no boundary edge
  const char* reason = nullptr; ///< why it was removed (component_filter.h); nullptr for a kept one
};

/// Step 13, the volumetric fallback (volumetric_fallback.h).
struct CleanFallback {
  std::string trigger;    ///< the defects the local steps left (empty: the fallback was not needed)
  bool available = false; ///< built with the volume layer
  bool rebuilt = false;   ///< the surface was replaced by its rebuild
  std::string message;    ///< why it was not rebuilt, when triggered
  std::size_t facesIn = 0, facesOut = 0; ///< faces before the rebuild and of the rebuild
  double areaIn = 0, areaOut = 0;        ///< area replaced (the whole surface) and rebuilt
  double voxelSize = 0;
};

/// What CleanRawMesh did. Counts are of elements, in the order of the steps.
struct CleanRawMeshResult {
  bool ok = true; ///< false when the input was refused (then the mesh is unchanged) or on an internal error
  std::string message; ///< why it was refused; empty when ok

  // Steps 1 and 4: vertices and trivially bad faces
  std::size_t mergedVertices = 0;              ///< vertices merged into a coincident one
  std::size_t removedUnreferencedVertices = 0; ///< vertices no face used in the input
  std::size_t removedDuplicateFaces = 0;       ///< faces with the same vertex set as an earlier face
  std::size_t removedDegenerateFaces = 0;      ///< repeated vertex index, or zero area removed by a collapse
  std::size_t flippedDegenerateFaces = 0;      ///< zero-area faces made proper by flipping their longest edge
  std::size_t collapsedDegenerateEdges = 0;    ///< vanishing edges of zero-area faces collapsed
  std::size_t remainingDegenerateFaces = 0;    ///< zero-area faces no safe edit could remove (left in place)
  // Steps 2, 5, 7 and 10: manifoldness
  std::size_t removedNonManifoldFaces = 0;  ///< faces removed to make non-manifold edges manifold
  std::size_t splitNonManifoldVertices = 0; ///< vertex copies created by splitting non-manifold vertices
  std::size_t retriangulatedPinchFans =
      0; ///< copies whose fan was removed and refilled so the two no longer touch
  std::size_t pinchFanFacesRemoved = 0, pinchFanFacesAdded = 0; ///< faces of those retriangulations
  std::size_t movedSplitVertices =
      0; ///< copies moved by 1% into their own fan instead (no valid retriangulation)
  std::size_t touchingSplitVertices = 0; ///< copies left touching their original (neither worked)
  // Steps 3 and 11: orientation
  std::size_t flippedFacesForOrientation = 0; ///< input faces whose orientation was reversed
  std::size_t flippedComponents = 0;          ///< closed components turned outward (included above)
  std::size_t nonOrientableComponents = 0;    ///< components that cannot be oriented (left as they are)
  // Steps 6 and 8: components and self-intersections
  std::size_t removedSmallComponents = 0;    ///< components removed by the component policy (see
                                             ///< component_filter.h: no enclosed volume, or below an opt-in
                                             ///< threshold)
  std::size_t removedComponentFaces = 0;     ///< their faces
  std::size_t removedInteriorComponents = 0; ///< step 11: closed components inside the union, removed
  std::size_t removedInteriorFaces = 0;      ///< their faces
  std::vector<CleanComponent> removedComponents; ///< each removed one (policy or interior), volume and reason
  std::vector<CleanComponent> keptComponents;    ///< the components of the result, largest first
  std::size_t repairedTangles =
      0; ///< tangles (intersecting or incoherently oriented faces) removed and refilled
  std::size_t unrepairedTangles = 0; ///< tangles left as they are: intersecting regions with no valid refill,
                                     ///< plus one per component left non-orientable
  std::size_t tangleFacesRemoved = 0, tangleFacesAdded = 0; ///< faces removed and added by those repairs
  // Step 9: holes
  std::size_t closedHoles = 0;              ///< boundary loops filled
  std::size_t holeFacesAdded = 0;           ///< faces added to fill them
  std::size_t grownHoles = 0;               ///< of the closed holes, those grown first (see hole_filling.h)
  std::size_t holeFacesRemoved = 0;         ///< faces removed around them
  std::size_t unfilledHoles = 0;            ///< boundary loops left open (too long, or no valid fill)
  std::size_t largestUnfilledHoleEdges = 0; ///< edges of the longest loop left open
  std::size_t fillBudgetRefusals = 0;       ///< fills refused because their step's planning budget
                                            ///< (params.fillWorkPerFace) ran out: the region or loop
                                            ///< was left as it is (among the unrepaired / unfilled)
  // Step 12
  std::size_t removedOrphanedVertices = 0; ///< vertices left without faces by the removals above
  CleanFallback fallback; ///< step 13; when rebuilt, the remaining-defect counts above are the
                          ///< second pass's (over the rebuild), the others the first pass's

  /// MeshQuality's report of the input and of the result, with the cleaning's degenerateAreaEpsilon
  /// and thread count, self-intersections included when params.measureSelfIntersections (MeshQuality's
  /// count: pairs sharing no vertex that meet, or sharing one vertex and meeting elsewhere). The
  /// before/after figures of the summary (vertices, faces, area, volume, validity) are read from here.
  QualityReport reportBefore, reportAfter;

  /// Defects left that make the result invalid, not merely open: unrepaired tangles (non-orientable
  /// components among them), non-manifold elements, degenerate faces, self-intersecting faces (when
  /// measured).
  std::size_t InvalidDefectsLeft() const {
    return unrepairedTangles + reportAfter.nonManifoldEdges + reportAfter.nonManifoldVertices +
           reportAfter.degenerateFaces +
           (reportAfter.selfIntersectionsComputed ? reportAfter.selfIntersectingFaces : 0);
  }
  /// Step 13 was triggered and could run (the volume layer is built in) but refused the rebuild.
  bool RebuildRefused() const { return !fallback.trigger.empty() && fallback.available && !fallback.rebuilt; }
};

} // namespace molremesh

// Human-readable summaries of the stages' results, one "name: value" line per figure, and the
// line of stage times, shared by the pipeline's stage records, the CLI and the MeshLab plugin log.
//
// The stages' Result types carry data only; their text lives here, as free functions. The local
// stages' Result types are nested in class templates, so their formatters take the Result as a
// template parameter and read its fields by name.
#pragma once

#include <algorithm>
#include <cstdio>
#include <ios>
#include <sstream>
#include <string>

#include <vcg_ext/clean/clean_raw_mesh.h>
#include <vcg_ext/stages/random_segmentation.h>

namespace molremesh {

/// A short list of components: the count, then the first few with their faces, enclosed volume
/// (negative: a cavity) and, for removed ones, why.
inline std::string CleanComponentList(const char* name, const std::vector<CleanComponent>& list) {
  constexpr std::size_t kShown = 8;
  std::string s = std::string(name) + ": " + std::to_string(list.size());
  for (std::size_t i = 0; i < list.size() && i < kShown; ++i) {
    char buffer[160];
    std::snprintf(buffer, sizeof buffer, "%s%zu faces, volume %.6g%s%s%s", i == 0 ? " (" : "; ",
                  list[i].faces, list[i].volume, list[i].closed ? "" : " open", list[i].reason ? ", " : "",
                  list[i].reason ? list[i].reason : "");
    s += buffer;
  }
  if (list.size() > kShown) s += "; ...";
  if (!list.empty()) s += ")";
  return s + "\n";
}

/// CleanRawMesh: every count of the cleaning, then the validity of the result.
inline std::string CleanRawMeshSummary(const CleanRawMeshResult& r) {
  if (!r.ok) return "clean raw mesh refused: " + r.message + "\n";
  std::string s;
  auto line = [&s](const char* name, std::size_t value) {
    s += std::string(name) + ": " + std::to_string(value) + "\n";
  };
  auto real = [&s](const char* name, double value) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, "%.6g", value);
    s += std::string(name) + ": " + buffer + "\n";
  };
  line("vertices before", r.reportBefore.vertices);
  line("faces before", r.reportBefore.faces);
  line("merged vertices", r.mergedVertices);
  line("removed unreferenced vertices", r.removedUnreferencedVertices);
  line("removed duplicate faces", r.removedDuplicateFaces);
  line("removed degenerate faces", r.removedDegenerateFaces);
  line("flipped degenerate faces", r.flippedDegenerateFaces);
  line("collapsed degenerate edges", r.collapsedDegenerateEdges);
  line("remaining degenerate faces", r.remainingDegenerateFaces);
  line("removed non-manifold faces", r.removedNonManifoldFaces);
  line("split non-manifold vertices", r.splitNonManifoldVertices);
  line("retriangulated pinch fans", r.retriangulatedPinchFans);
  line("pinch fan faces removed", r.pinchFanFacesRemoved);
  line("pinch fan faces added", r.pinchFanFacesAdded);
  line("moved split vertices", r.movedSplitVertices);
  line("touching split vertices", r.touchingSplitVertices);
  line("flipped faces for orientation", r.flippedFacesForOrientation);
  line("flipped components", r.flippedComponents);
  line("non-orientable components", r.nonOrientableComponents);
  line("removed small components", r.removedSmallComponents);
  line("removed component faces", r.removedComponentFaces);
  line("removed interior components", r.removedInteriorComponents);
  line("removed interior component faces", r.removedInteriorFaces);
  line("repaired tangles", r.repairedTangles);
  line("unrepaired tangles", r.unrepairedTangles);
  line("tangle faces removed", r.tangleFacesRemoved);
  line("tangle faces added", r.tangleFacesAdded);
  line("closed holes", r.closedHoles);
  line("hole faces added", r.holeFacesAdded);
  line("grown holes", r.grownHoles);
  line("faces removed around grown holes", r.holeFacesRemoved);
  line("unfilled holes", r.unfilledHoles);
  line("largest unfilled hole edges", r.largestUnfilledHoleEdges);
  line("fills refused for the planning budget", r.fillBudgetRefusals);
  line("removed orphaned vertices", r.removedOrphanedVertices);
  if (!r.fallback.trigger.empty()) {
    s += "volumetric fallback: " +
         (r.fallback.rebuilt ? std::string("rebuilt") : "not rebuilt (" + r.fallback.message + ")") +
         " after " + r.fallback.trigger + "\n";
    if (r.fallback.rebuilt) {
      line("rebuilt faces in", r.fallback.facesIn);
      line("rebuilt faces out", r.fallback.facesOut);
      real("rebuilt area in", r.fallback.areaIn);
      real("rebuilt area out", r.fallback.areaOut);
      real("rebuild voxel size", r.fallback.voxelSize);
    }
  }
  if (r.reportBefore.selfIntersectionsComputed) {
    line("self-intersecting faces before", r.reportBefore.selfIntersectingFaces);
    line("self-intersecting faces after", r.reportAfter.selfIntersectingFaces);
  }
  line("vertices after", r.reportAfter.vertices);
  line("faces after", r.reportAfter.faces);
  line("boundary edges after", r.reportAfter.boundaryEdges);
  line("non-manifold edges after", r.reportAfter.nonManifoldEdges);
  line("non-manifold vertices after", r.reportAfter.nonManifoldVertices);
  line("degenerate faces after", r.reportAfter.degenerateFaces);
  line("components after", r.reportAfter.components);
  s += "genus after: " + std::to_string(r.reportAfter.genus) + "\n";
  s += CleanComponentList("kept components", r.keptComponents);
  s += CleanComponentList("removed components", r.removedComponents);
  real("area before", r.reportBefore.area);
  real("area after", r.reportAfter.area);
  real("volume before", r.reportBefore.volume);
  real("volume after", r.reportAfter.volume);
  return s;
}

/// RandomSegmentation: the patches and their borders.
inline std::string SegmentationSummary(const SegmentationResult& r) {
  return "patches: " + std::to_string(r.patchCount) + "\nborder edges: " + std::to_string(r.borderEdges) +
         "\nborder vertices: " + std::to_string(r.borderVertices) + "\n";
}

/// PatchwiseRemeshing<MeshType>::Result: the patches, the edits of the patches and the strip
/// summed, the conflicts between patches and the sizes.
template <class Result>
std::string PatchwiseRemeshingSummary(const Result& r) {
  const auto& p = r.patchStats;
  const auto& q = r.stripStats;
  std::ostringstream s;
  s << "patches: " << r.patches << "\n"
    << "border vertices: " << r.borderVertices << "\n"
    << "strip vertices: " << r.stripVertices << "\n"
    << "halo faces: " << r.haloFaces << "\n"
    << "sizing (x L0): " << r.minSizing << " .. " << r.maxSizing << "\n"
    << "splits: " << p.splits + q.splits << "\n"
    << "collapses: " << p.collapses + q.collapses << "\n"
    << "flips: " << p.flips + q.flips << "\n"
    << "relaxation moves: " << p.movesApplied + q.movesApplied << "\n"
    << "repair moves/flips/collapses: " << p.repairMoves + q.repairMoves << "/"
    << p.repairFlips + q.repairFlips << "/" << p.repairCollapses + q.repairCollapses << "\n"
    << "snapped onto far input vertices: " << p.snapMoves + q.snapMoves << "\n"
    << "volume offset (x L0): " << std::max(p.volumeOffset, q.volumeOffset) << "\n"
    << "cross-patch conflicts: " << r.conflictPairs << "\n"
    << "patches redone: " << r.patchesRedone << "\n"
    << "patches frozen: " << r.patchesFrozen << "\n"
    << "patches failed: " << r.patchesFailed << (r.firstFailure.empty() ? "" : " (" + r.firstFailure + ")")
    << "\n"
    << "vertices: " << r.verticesIn << " -> " << r.verticesOut << "\n"
    << "faces: " << r.facesIn << " -> " << r.facesOut << "\n";
  return s.str();
}

/// ValenceOptimization<MeshType>::Result: the share of valence 5-7 vertices and the edits.
template <class Result>
std::string ValenceOptimizationSummary(const Result& r) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(3);
  s << "V567: " << r.before.RegularPercent() << "% -> " << r.after.RegularPercent()
    << "% (irregular vertices " << r.before.irregular << " -> " << r.after.irregular << ")\n"
    << "faces with an angle below the min: " << r.smallAnglesBefore << " -> " << r.smallAnglesAfter << "\n"
    << "faces with an angle above the max: " << r.largeAnglesBefore << " -> " << r.largeAnglesAfter << "\n"
    << "flips: " << r.flips << ", collapses: " << r.collapses << "\n"
    << "holes refilled with 0/1/2 new vertices: " << r.filledZero << "/" << r.filledOne << "/" << r.filledTwo
    << " (grown in phase 2: " << r.phaseTwoHoles << "; on the reference: " << r.starsOnReference << " stars, "
    << r.strips << " strips"
    << "), left as they were: " << r.holesKept << "\n"
    << "flips with their neighbourhood relaxed: " << r.relaxedFlips << "\n"
    << "rounds: " << r.rounds << "\n";
  return s.str();
}

/// SmallAngleElimination<MeshType>::Result: its message, the small-angle faces and the edits.
template <class Result>
std::string SmallAngleEliminationSummary(const Result& r) {
  return r.message + "\nfaces with an angle < min: " + std::to_string(r.smallFacesBefore) + " -> " +
         std::to_string(r.smallFacesAfter) + "\nsmallest angle: " + std::to_string(r.angleMinBefore) +
         " -> " + std::to_string(r.angleMinAfter) + "\ncollapses: " + std::to_string(r.collapses) +
         "\nflips: " + std::to_string(r.flips) + "\nmoves: " + std::to_string(r.moves) +
         "\nrefills: " + std::to_string(r.refills) + "\nrefused: " + std::to_string(r.refused) +
         "\nrounds: " + std::to_string(r.iterations) + (r.creasePass ? " (with the crease pass)" : "") + "\n";
}

/// ObtuseReduction<MeshType>::Result: its message, the obtuse faces and the edits.
template <class Result>
std::string ObtuseReductionSummary(const Result& r) {
  return r.message + "\nobtuse faces: " + std::to_string(r.obtuseBefore) + " -> " +
         std::to_string(r.obtuseAfter) + "\nlargest angle: " + std::to_string(r.angleMaxBefore) + " -> " +
         std::to_string(r.angleMaxAfter) + "\nsmallest angle: " + std::to_string(r.angleMinBefore) + " -> " +
         std::to_string(r.angleMinAfter) + "\nmoves: " + std::to_string(r.moves) +
         "\npentagon insertions: " + std::to_string(r.insertions) +
         "\nrefused: " + std::to_string(r.refused) + "\nrounds: " + std::to_string(r.rounds) +
         (r.creasePass ? " (with the crease pass)" : "") + "\n";
}

/// LocalSmoothing<MeshType>::Result: its message, the bad faces, the angle range and the edits.
template <class Result>
std::string LocalSmoothingSummary(const Result& r) {
  return r.message + "\nbad faces: " + std::to_string(r.badBefore) + " -> " + std::to_string(r.badAfter) +
         " (small " + std::to_string(r.smallAfter) + ", obtuse " + std::to_string(r.obtuseAfter) + ")" +
         "\nsmallest angle: " + std::to_string(r.angleMinBefore) + " -> " + std::to_string(r.angleMinAfter) +
         "\nlargest angle: " + std::to_string(r.angleMaxBefore) + " -> " + std::to_string(r.angleMaxAfter) +
         "\nmoves: " + std::to_string(r.moves) + "\nflips: " + std::to_string(r.flips) +
         "\ncollapses: " + std::to_string(r.collapses) + "\nsplits: " + std::to_string(r.splits) +
         "\nrefused: " + std::to_string(r.refused) + "\nrounds: " + std::to_string(r.rounds) + "\n";
}

/// "stage times (s): clean=... cvt=... total=..." (no newline) from a PipelineResult's stage
/// records: the one place the run's timing is reported.
template <class PipelineResult>
std::string StageTimesLine(const PipelineResult& result) {
  std::ostringstream s;
  s << "stage times (s):";
  for (const auto& stage : result.stages) s << ' ' << stage.name << '=' << stage.seconds;
  s << " total=" << result.seconds;
  return s.str();
}

} // namespace molremesh

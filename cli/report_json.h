// QualityReport as JSON for `molremesh report --json` (machine-readable; the keys are stable).
#pragma once

#include <cmath>
#include <nlohmann/json.hpp>

#include <vcg_ext/quality/mesh_quality.h>

namespace molremesh {

/// JSON has no infinity or NaN: those become null.
inline nlohmann::json FiniteOrNull(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

inline nlohmann::json ToJson(const QualityReport& r) {
  nlohmann::json histogram = nlohmann::json::object();
  for (const auto& [valence, count] : r.valenceHistogram) histogram[std::to_string(valence)] = count;
  nlohmann::json components = nlohmann::json::array();
  for (const ComponentInfo& c : r.componentInfo)
    components.push_back({{"faces", c.faces},
                          {"boundary_edges", c.boundaryEdges},
                          {"manifold", c.manifold},
                          {"closed", c.closed},
                          {"euler", c.euler},
                          {"genus", c.genus >= 0 ? nlohmann::json(c.genus) : nlohmann::json(nullptr)}});
  return {
      {"vertices", r.vertices},
      {"referenced_vertices", r.referencedVertices},
      {"unreferenced_vertices", r.unreferencedVertices},
      {"non_finite_vertices", r.nonFiniteVertices},
      {"faces", r.faces},
      {"edges", r.edges},
      {"mean_edge_length", FiniteOrNull(r.meanEdgeLength)},
      {"median_edge_length", FiniteOrNull(r.medianEdgeLength)},
      {"q_min", FiniteOrNull(r.qMin)},
      {"q_avg", FiniteOrNull(r.qAvg)},
      {"angle_min_deg", FiniteOrNull(r.angleMin)},
      {"mean_min_angle_deg", FiniteOrNull(r.meanMinAngle)},
      {"angle_max_deg", FiniteOrNull(r.angleMax)},
      {"aspect_ratio_max", FiniteOrNull(r.aspectRatioMax)},
      {"aspect_ratio_mean", FiniteOrNull(r.aspectRatioMean)},
      {"small_angle_faces", r.smallAngleFaces},
      {"small_angle_percent", r.smallAnglePercent},
      {"obtuse_faces", r.obtuseFaces},
      {"obtuse_percent", r.obtusePercent},
      {"large_angle_faces", r.largeAngleFaces},
      {"large_angle_percent", r.largeAnglePercent},
      {"interior_vertices", r.interiorVertices},
      {"regular_vertices", r.regularVertices},
      {"irregular_vertices", r.interiorVertices - r.regularVertices},
      {"v567_percent", r.v567Percent},
      {"valence_histogram", histogram},
      {"area", FiniteOrNull(r.area)},
      {"volume", FiniteOrNull(r.volume)},
      {"euler", r.euler},
      {"genus", r.genus >= 0 ? nlohmann::json(r.genus) : nlohmann::json(nullptr)},
      {"components", r.components},
      {"component_info", components},
      {"boundary_edges", r.boundaryEdges},
      {"boundary_loops", r.boundaryLoops},
      {"non_manifold_edges", r.nonManifoldEdges},
      {"non_manifold_vertices", r.nonManifoldVertices},
      {"degenerate_faces", r.degenerateFaces},
      {"self_intersecting_pairs",
       r.selfIntersectionsComputed ? nlohmann::json(r.selfIntersectingPairs) : nlohmann::json(nullptr)},
      {"self_intersecting_faces",
       r.selfIntersectionsComputed ? nlohmann::json(r.selfIntersectingFaces) : nlohmann::json(nullptr)},
      {"two_manifold", r.isTwoManifold()},
  };
}

} // namespace molremesh

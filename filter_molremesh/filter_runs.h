// The molremesh filters' runs, shared by the MeshLab 2020.09 and 2023.12 adapters: parameter
// values in, vcg_ext called, results and log lines out. Templated on the host's mesh type (CMeshO:
// float in MeshLab, double in PyMeshLab); the adapters keep only what their interface owns (layers,
// attribute masks, the log and error channels).
//
// Include this before any Qt header: Qt defines `slots` and `signals` as macros, which must not
// reach the vcg_ext templates.
#pragma once

#include "filter_catalog.h"

#include <vcg_ext/core/input_check.h>
#include <vcg_ext/core/mesh_copy.h>
#include <vcg_ext/geometry/mean_edge_length.h>
#include <vcg_ext/pipeline/region_remeshing.h>
#include <vcg_ext/pipeline/remesh_pipeline.h>
#include <vcg_ext/quality/bad_element_coloring.h>
#include <vcg_ext/quality/mesh_quality.h>
#include <vcg_ext/quality/quality_report_format.h>
#include <vcg_ext/quality/quality_report_html.h>
#include <vcg_ext/quality/stage_summary.h>
#include <vcg_ext/volume/molecular_surface.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace molremesh::filters {

/// Where a run's messages go. rich: the host shows the log as rich text (MeshLab's GUI).
struct RunLog {
  std::function<void(const std::string&)> info;
  std::function<void(const std::string&)> warning;
  bool rich = false;

  /// A plain-text block: one <pre> entry as rich text, one entry per line otherwise.
  void Text(const std::string& text) const {
    if (rich) {
      info(PreformattedHtml(text));
      return;
    }
    Lines(info, text);
  }
  /// Logs a multi-line text one line at a time: MeshLab's log shows one entry per call.
  static void Lines(const std::function<void(const std::string&)>& log, const std::string& text) {
    std::istringstream lines(text);
    std::string line;
    while (std::getline(lines, line)) log(line);
  }
};

/// The Length default and range of a layer.
template <class Mesh>
LengthRange LengthRangeOfMesh(const Mesh& m) {
  return LengthRangeOf(MeanEdgeLength(m), m.bbox.Diag());
}

/// A figure of a quality report, as a filter's output value (PyMeshLab returns them to the script).
struct Figure {
  std::string name; ///< as in the CLI's JSON report
  double value;
  bool count; ///< an integer (a count or a topological number)
};

/// The figures a script checks, named as in the CLI's JSON report.
inline std::vector<Figure> QualityFigures(const QualityReport& r) {
  std::vector<Figure> figures = {
      {"vertices", double(r.vertices), true},
      {"faces", double(r.faces), true},
      {"q_min", r.qMin, false},
      {"q_avg", r.qAvg, false},
      {"mean_edge_length", r.meanEdgeLength, false},
      {"angle_min_deg", r.angleMin, false},
      {"angle_max_deg", r.angleMax, false},
      {"v567_percent", r.v567Percent, false},
      {"small_angle_percent", r.smallAnglePercent, false},
      {"obtuse_percent", r.obtusePercent, false},
      {"large_angle_percent", r.largeAnglePercent, false},
      {"area", r.area, false},
      {"volume", r.volume, false},
      {"euler", double(r.euler), true},
      {"genus", double(r.genus), true},
      {"components", double(r.components), true},
      {"boundary_edges", double(r.boundaryEdges), true},
      {"non_manifold_edges", double(r.nonManifoldEdges), true},
      {"non_manifold_vertices", double(r.nonManifoldVertices), true},
      {"degenerate_faces", double(r.degenerateFaces), true},
  };
  if (r.selfIntersectionsComputed) {
    figures.push_back({"self_intersecting_pairs", double(r.selfIntersectingPairs), true});
    figures.push_back({"self_intersecting_faces", double(r.selfIntersectingFaces), true});
  }
  return figures;
}

/// Quality Report: the figures, logged as the quality table.
template <class Mesh>
QualityReport RunQualityReport(const Mesh& m, const ParameterValues& values, const std::string& meshName,
                               const RunLog& log) {
  typename MeshQuality<Mesh>::Params params;
  params.computeSelfIntersections = values.Bool("selfIntersections");
  const QualityReport report = MeshQuality<Mesh>::Compute(m, params);
  log.info("Molecular Remesh quality report of " + meshName);
  log.Text(FormatQualityTable(report, "value"));
  log.info("valence histogram (interior vertices): " + FormatValenceHistogram(report));
  if (!report.selfIntersectionsSkipped.empty())
    log.warning(report.selfIntersectionsSkipped + ": self-intersections not counted");
  return report;
}

/// Color Bad Elements: "" or why the parameters are refused (the mesh then untouched);
/// enableAttributes (the host's vertex/face color and quality) is called before the coloring.
template <class Mesh>
std::string RunColorBadElements(Mesh& m, const ParameterValues& values, const RunLog& log,
                                const std::function<void()>& enableAttributes, BadElementCounts& counts) {
  using Coloring = BadElementColoring<Mesh>;
  typename Coloring::Params params;
  params.smallAngle = values.Float("smallAngle");
  params.obtuseAngle = values.Float("obtuseAngle");
  params.palette = Coloring::ColorBlindSafePalette();
  if (!(params.smallAngle >= 0 && params.smallAngle <= 60))
    return "Small angle must be between 0 and 60 degrees";
  if (!(params.obtuseAngle >= 60 && params.obtuseAngle <= 180))
    return "Obtuse angle must be between 60 and 180 degrees";
  enableAttributes();
  counts = Coloring::Do(m, params);
  const BadElementPalette& c = params.palette;
  auto entry = [](const vcg::Color4b& color, const std::string& label, std::size_t count) {
    return LegendEntry{color[0], color[1], color[2], label, count};
  };
  char obtuse[64], small[64];
  std::snprintf(obtuse, sizeof obtuse, "obtuse faces (largest angle >= %g deg)", params.obtuseAngle);
  std::snprintf(small, sizeof small, "small-angle faces (an angle < %g deg)", params.smallAngle);
  const std::size_t obtuseOnly = counts.obtuseFaces - counts.obtuseAndSmallFaces;
  const std::size_t smallOnly = counts.smallAngleFaces - counts.obtuseAndSmallFaces;
  const std::vector<LegendEntry> faces = {
      entry(c.obtuseFace, obtuse, obtuseOnly), entry(c.smallAngleFace, small, smallOnly),
      entry(c.obtuseAndSmallFace, "faces both obtuse and small-angle", counts.obtuseAndSmallFaces),
      entry(c.neutral, "other faces",
            std::size_t(m.fn) - obtuseOnly - smallOnly - counts.obtuseAndSmallFaces)};
  const std::vector<LegendEntry> vertices = {
      entry(c.lowValenceVertex, "interior vertices of valence below 5", counts.lowValenceVertices),
      entry(c.highValenceVertex, "interior vertices of valence above 7", counts.highValenceVertices)};
  if (log.rich) {
    log.info(FormatColorLegendHtml("Face colors (shown now)", faces));
    log.info(FormatColorLegendHtml("Vertex colors (layer render settings: Color > Vert)", vertices));
  } else {
    auto line = [&log](const char* format, auto... numbers) {
      char text[256];
      std::snprintf(text, sizeof text, format, numbers...);
      log.info(text);
    };
    line("Irregular vertices: %zu (valence below 5, bluish green: %zu; above 7, yellow: %zu)",
         counts.irregularVertices, counts.lowValenceVertices, counts.highValenceVertices);
    line("Obtuse faces (vermillion or reddish purple): %zu", counts.obtuseFaces);
    line("Small-angle faces (blue or reddish purple): %zu", counts.smallAngleFaces);
    line("Obtuse and small-angle faces (reddish purple): %zu", counts.obtuseAndSmallFaces);
  }
  return {};
}

/// Random Segmentation: "" or why it failed; enableAttributes (the host's face-face topology and
/// face color) is called once the parameters are accepted. Colors the faces by patch and stores the patch in
/// the attribute "molremesh_patch".
template <class Mesh>
std::string RunRandomSegmentation(Mesh& m, const ParameterValues& values, const RunLog& log,
                                  const std::function<void()>& enableAttributes, SegmentationResult& result) {
  using Segmentation = RandomSegmentation<Mesh>;
  typename Segmentation::Params params;
  params.patchCount = values.Int("patchCount");
  params.seed = std::uint64_t(values.Int("seed"));
  if (params.patchCount < 0) return "Patches must be 0 (automatic) or more";
  enableAttributes();
  vcg::tri::UpdateTopology<Mesh>::FaceFace(m);
  result = Segmentation::Do(m, params);
  if (!result.ok) return result.message;
  Segmentation::ColorPatches(m, result);
  auto patchAttribute = vcg::tri::Allocator<Mesh>::template GetPerFaceAttribute<int>(m, "molremesh_patch");
  for (std::size_t i = 0; i < m.face.size(); ++i) patchAttribute[i] = result.facePatch[i];
  char text[160];
  std::snprintf(text, sizeof text, "Random segmentation: %d patches, %zu border edges, %zu border vertices",
                result.patchCount, result.borderEdges, result.borderVertices);
  log.info(text);
  return {};
}

/// The host's progress bar over a whole run: each stage gets a share of the bar by its usual cost
/// (its time on a large mesh: CVT and RAR take most of it), moves through it with the CVT and RAR
/// steps, and the label names the stage and its step ("cvt (2/9): Lloyd iteration 17/42").
class RunProgress {
public:
  using Callback = std::function<void(int percent, const std::string& label)>;
  RunProgress(Callback cb, const std::vector<PipelineStage>& stages) : cb_(std::move(cb)) {
    double total = 0;
    for (auto stage : stages) {
      names_.push_back(StageName(stage));
      starts_.push_back(total);
      total += Weight(stage);
    }
    for (double& start : starts_) start /= total;
    starts_.push_back(1.0);
  }
  /// The pipeline's "stage <name> ..." log line starts a stage.
  void OnLogLine(const std::string& line) {
    for (std::size_t i = 0; i < names_.size(); ++i)
      if (line == "stage " + names_[i] + " ...") {
        stage_ = i;
        Step(0.0, "");
      }
  }
  /// fraction of the current stage done, and its step.
  void Step(double fraction, const std::string& step) {
    if (!cb_ || names_.empty()) return;
    const double share = starts_[stage_ + 1] - starts_[stage_];
    const int percent = int(100 * (starts_[stage_] + share * std::clamp(fraction, 0.0, 1.0)));
    const std::string label = names_[stage_] + " (" + std::to_string(stage_ + 1) + "/" +
                              std::to_string(names_.size()) + ")" + (step.empty() ? "" : ": " + step);
    cb_(percent, label);
  }

private:
  /// Seconds of the stage in the full pipeline on the 378k-face 1HPV surface (on 2 busy cores).
  static double Weight(PipelineStage stage) {
    switch (stage) {
    case PipelineStage::Clean:
      return 7.5;
    case PipelineStage::Cvt:
      return 48;
    case PipelineStage::Valence:
      return 3;
    case PipelineStage::Segment:
      return 0.6;
    case PipelineStage::Rar:
      return 26;
    case PipelineStage::Small:
      return 0.6;
    case PipelineStage::Obtuse:
      return 2.5;
    default:
      return 2; // smooth, polish
    }
  }
  Callback cb_;
  std::vector<std::string> names_;
  std::vector<double> starts_; ///< share of the bar before each stage, then 1
  std::size_t stage_ = 0;
};

/// The stages' summaries and the quality tables of a run.
void LogPipelineRun(const PipelineResult& result, const RunLog& log);

/// What Surface from Structure File built.
struct StructureSurfaceRun {
  std::string layerName; ///< the new layer's name: the file's base name and the surface ("1UBQ SES")
  std::size_t atoms = 0;
  MolecularSurfaceResult surface;
  bool remeshed = false;
  PipelineResult pipeline; ///< when remeshed
};

/// Surface from Structure File: the file's atoms, their molecular surface and (unless "remesh" is
/// off) the full pipeline on it, into `mesh`. Returns "" or why not (one line; `mesh` then empty).
std::string RunSurfaceFromStructure(const ParameterValues& values, const RunLog& log,
                                    const RunProgress::Callback& progressCallback, MeshD& mesh,
                                    StructureSurfaceRun& run);

/// Whether m has a selected face (the region filters' parameter is offered only then).
template <class Mesh>
bool HasSelectedFace(const Mesh& m) {
  return std::any_of(m.face.begin(), m.face.end(), [](const auto& f) { return !f.IsD() && f.IsS(); });
}

/// "Remesh only selected faces": the stages on m's selected faces of `work` (a copy of m), the rest
/// unchanged; selected receives the region of the result (per face). Returns why it refused.
template <class Mesh>
std::string RunSelectedRegion(const Mesh& m, const Pipeline::Params& params, const RunLog& log, MeshD& work,
                              std::vector<std::uint8_t>& selected) {
  RegionRemeshing<MeshD>::Params regionParams;
  regionParams.pipeline = params;
  for (const auto& f : m.face) // in CopyTriangles' order
    if (!f.IsD()) regionParams.faceMask.push_back(f.IsS() ? 1 : 0);
  const auto region = RegionRemeshing<MeshD>::Do(work, regionParams);
  if (!region.ok) return region.message;
  log.info(region.message);
  for (const std::string& line : region.stageSummaries) log.info(line);
  selected = region.faceMask;
  return {};
}

/// Runs a stage filter's stages on `work`, a double-precision copy of m (on its selected faces
/// only when the filter's regionOnly is on; selected then receives the new region per face).
/// Returns "" when every stage succeeded (the host then puts `work` into the layer or a new one),
/// else why not; either way nothing of the host's mesh has changed.
template <class Mesh>
std::string RunStages(const Mesh& m, const FilterSpec& filter, const ParameterValues& values,
                      const RunLog& log, RunProgress::Callback progressCallback, MeshD& work,
                      PipelineResult& result, std::vector<std::uint8_t>& selected) {
  Pipeline::Params params;
  params.stages = filter.stages;
  if (std::string why = ReadStageParameters(values, params); !why.empty()) return why;
  // Self-intersections are counted before and after, not between stages (the slowest figure;
  // every edit already refuses new intersections).
  params.intersectionsEachStage = false;
  // The run works on a copy and writes it back only when every stage succeeded: the layer stays
  // as it was on failure without the pipeline's own backup copy of the input.
  params.restoreOnFailure = false;
  // Checked on the layer, before the copy (which the estimate includes), then not again.
  if (const std::string why = Pipeline::MemoryCheck(m, params); !why.empty())
    return "refused: " + why +
           " (the layer is unchanged; the Memory limit parameter sets the limit, -1 turns the check off)";
  params.memoryLimitMB = -1;
  RunProgress progress(std::move(progressCallback), params.stages);
  params.cvt.progress = [&progress](double fraction, const std::string& step) {
    progress.Step(fraction, step);
  };
  params.rar.progress = params.cvt.progress;
  params.clean.progress = params.cvt.progress;
  CopyTriangles(work, m);
  if (values.Has("regionOnly") && values.Bool("regionOnly"))
    return RunSelectedRegion(m, params, log, work, selected);
  result = Pipeline::Do(work, params, [&log, &progress](const std::string& line) {
    progress.OnLogLine(line);
    log.info(line);
  });
  if (!result.ok) return result.message;
  LogPipelineRun(result, log);
  return {};
}

} // namespace molremesh::filters

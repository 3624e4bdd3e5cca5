// The molremesh pipeline: the stages of Khan et al. 2020 run in order on one mesh, sharing the
// cleaned input as reference surface, one target edge length and one seed.
//
// RemeshPipeline<MeshType>::Do(m, params) runs params.stages (any subset, always in pipeline
// order) and measures the mesh before and after each stage (MeshQuality). It is transactional:
// if a stage fails, the mesh is restored to the input and the failing stage says why. A mesh far
// from the origin compared with its size is remeshed in a recentred frame and moved back on output
// (CoordinateFrame); one whose coordinates cannot resolve its edges is refused.
#pragma once

#include <vcg/complex/append.h>
#include <vcg/complex/complex.h>

#include <vcg_ext/topology/face_face_topology.h>
#include <vcg_ext/geometry/mean_edge_length.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <functional>
#include <future>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <vcg_ext/clean/clean_raw_mesh.h>
#include <vcg_ext/pipeline/coordinate_frame.h>
#include <vcg_ext/stages/cvt_initialization.h>
#include <vcg_ext/core/input_check.h>
#include <vcg_ext/stages/local_smoothing.h>
#include <vcg_ext/core/element_capacity.h>
#include <vcg_ext/pipeline/memory_budget.h>
#include <vcg_ext/quality/mesh_quality.h>
#include <vcg_ext/quality/output_verdict.h>
#include <vcg_ext/stages/obtuse_reduction.h>
#include <vcg_ext/stages/patchwise_remeshing.h>
#include <vcg_ext/stages/random_segmentation.h>
#include <vcg_ext/surface/narrow_gaps.h>
#include <vcg_ext/surface/reference_surface.h>
#include <vcg_ext/stages/small_angle_elimination.h>
#include <vcg_ext/stages/tiny_components.h>
#include <vcg_ext/geometry/triangle_angles.h>
#include <vcg_ext/stages/valence_optimization.h>
#include <vcg_ext/quality/stage_summary.h>

namespace molremesh {

/// Pipeline stages, in the order they run.
enum class PipelineStage { Clean, Cvt, Valence, Segment, Rar, Small, Obtuse, Smooth, Polish };

struct PipelineStageInfo {
  PipelineStage stage;
  const char* name;        ///< as written in --stages lists
  const char* description; ///< one line
};

inline const std::vector<PipelineStageInfo>& PipelineStages() {
  static const std::vector<PipelineStageInfo> stages = {
      {PipelineStage::Clean, "clean",
       "clean the raw mesh (duplicates, degenerate faces, non-manifold, holes)"},
      {PipelineStage::Cvt, "cvt", "centroidal Voronoi tessellation initialization"},
      {PipelineStage::Valence, "valence",
       "valence optimization (guarded flips and collapses, removal and refilling of irregular vertices)"},
      {PipelineStage::Segment, "segment", "random segmentation into patches"},
      {PipelineStage::Rar, "rar",
       "patch-wise real-time adaptive remeshing (borders locked, then the strip around them)"},
      {PipelineStage::Small, "small", "small-angle elimination (every angle below the min angle)"},
      {PipelineStage::Obtuse, "obtuse", "obtuse reduction (vertex translation, pentagon point insertion)"},
      {PipelineStage::Smooth, "smooth", "local smoothing of the triangles still bad"},
      {PipelineStage::Polish, "polish",
       "final valence optimization under the obtuse guard (max angle 90): the irregular vertices RAR leaves, "
       "removed without a new obtuse or small angle (beyond the paper)"},
  };
  return stages;
}

inline const char* StageName(PipelineStage stage) {
  for (const auto& info : PipelineStages())
    if (info.stage == stage) return info.name;
  return "?";
}

/// Parses "clean,cvt,..." into stages in pipeline order. Unknown or repeated names are errors.
inline bool ParseStageList(const std::string& list, std::vector<PipelineStage>& stages, std::string& error) {
  stages.clear();
  std::istringstream in(list);
  std::string name;
  while (std::getline(in, name, ',')) {
    name.erase(0, name.find_first_not_of(" \t"));
    name.erase(name.find_last_not_of(" \t") + 1);
    if (name.empty()) continue;
    auto it = std::find_if(PipelineStages().begin(), PipelineStages().end(),
                           [&](const PipelineStageInfo& info) { return name == info.name; });
    if (it == PipelineStages().end()) {
      error = "unknown stage '" + name + "' (known stages:";
      for (const auto& info : PipelineStages()) error += std::string(" ") + info.name;
      error += ")";
      return false;
    }
    if (std::find(stages.begin(), stages.end(), it->stage) != stages.end()) {
      error = "stage '" + name + "' is listed twice";
      return false;
    }
    stages.push_back(it->stage);
  }
  if (stages.empty()) {
    error = "no stage given";
    return false;
  }
  std::sort(stages.begin(), stages.end());
  return true;
}

/// What one stage did.
struct PipelineStageRecord {
  std::string name;
  bool ok = true;
  std::string summary; ///< the stage's own one-line-per-figure summary, or why it failed
  double seconds = 0;
  QualityReport after; ///< the mesh after the stage (when Params::measureEachStage)
};

struct PipelineResult {
  bool ok = true;
  std::string message;           ///< why it failed (the mesh is then the input again)
  bool refusedForMemory = false; ///< the memory check refused the run (Params::memoryLimitMB)
  double targetEdgeLength = 0;
  QualityReport input;                     ///< the mesh as given
  std::vector<PipelineStageRecord> stages; ///< in order
  std::vector<int> facePatch;              ///< the segmentation, when the segment stage ran (and no later
                                           ///< stage changed the faces: rar clears it)
  int patchCount = 0;
  double seconds = 0;
  /// What the output misses of the promises of the stages that ran (empty when all are met, and
  /// when the stages were not measured); see OutputVerdict.
  OutputVerdict verdict;
  OutputTargets targets;              ///< what the verdict checked
  bool rebuiltVolumetrically = false; ///< the clean stage rebuilt the surface from a volume
  /// The second run after a first whose angles missed their bounds (Params::rebuildWhenAnglesMiss).
  struct RebuildRetry {
    bool tried = false;  ///< a second run was made
    bool kept = false;   ///< its output is m (else m is the first run's)
    bool first = false;  ///< the run on the rebuilt surface was made first (Params::rebuildFirstGapShare)
    std::string message; ///< one line: why, and what the second run gave (empty when not tried)
  } rebuildRetry;
};

template <class MeshType>
class RemeshPipeline {
public:
  static constexpr int kMinFaces = 4; ///< smaller meshes are refused
  struct Params {
    std::vector<PipelineStage> stages = AllStages(); ///< which stages run (in pipeline order)
    /// L for every stage; 0 = mean edge length of the (cleaned) input, or of the raw input when the
    /// cleaning rebuilt it volumetrically. RAR's sizing field is capped
    /// at L, so the output's mean edge is 0.78-0.93 L on molecular surfaces, unless
    /// rar.rar.meanEdgeAtTarget scales the field to a mean edge of L.
    double targetEdgeLength = 0;
    std::uint64_t seed = 1;       ///< seed of every random choice
    int threads = 0;              ///< worker threads; 0 = all cores (the output does not depend on it)
    bool measureEachStage = true; ///< quality report after each stage
    /// With measureEachStage: false measures only the last stage (the output) and the stages whose
    /// report costs nothing (the cleaning's own); the other records' `after` stay empty. A caller
    /// that shows only the input and the output (the CLI without --verbose or --json) saves the
    /// reports' time and their mesh captures.
    bool measureIntermediateStages = true;
    /// Count self-intersecting pairs in every stage's report; otherwise only in the input's and the
    /// last stage's (every edit already refuses new intersections; the count is the slowest figure).
    bool intersectionsEachStage = true;
    /// Keep a copy of the input to put back into m when a stage fails (m is then unchanged). The
    /// copy is as large as the input mesh; a caller that drops m on failure (the CLI, which then
    /// writes nothing) turns it off; m then holds the last completed stage's result (every stage
    /// leaves the mesh as it was when it fails).
    bool restoreOnFailure = true;
    /// When the output has an angle outside [small.minAngleDeg, polish.maxAngleDeg] and the clean
    /// stage did not rebuild the surface, run the pipeline again from the input with the clean
    /// stage's volumetric rebuild (CleanRawMesh::Params::volumetricRebuild; L as in that run), and keep
    /// that output when it is valid and its angles are nearer the bounds. The usual cause of such
    /// angles is a part of the input thinner than L (a fin, a tube, a pinched void, a crevice
    /// between atom spheres), which the rebuild removes or seals: the area changes by a few percent
    /// (PipelineResult::rebuildRetry says by how much). Needs the clean, small and polish stages,
    /// measureEachStage, the volumetric fallback on and OpenVDB; keeps a copy of the input.
    bool rebuildWhenAnglesMiss = true;
    /// ... kept only when its area is within this share of the first output's: the rebuild seals
    /// crevices narrower than about L (2-7 % of the area of EDTSurf's coarsest van der Waals and
    /// solvent-accessible surfaces); more means it removed a part of the surface that matters.
    double retryMaxAreaChange = 0.1;
    /// With rebuildWhenAnglesMiss: when more than this share of the cleaned input's area faces the
    /// surface again within narrowGapReach x L in front of it (NarrowGaps: crevices between atom
    /// spheres, pinched voids), the run on the rebuilt surface is made first, and it is the output
    /// when it is valid and its area within retryMaxAreaChange of the cleaned input's (its angles
    /// are what they are: the run without the rebuild would miss them); otherwise the run without
    /// the rebuild follows and the two are compared as above. That saves the first run on the inputs
    /// whose angles would miss: on the unseen inputs (docs/pipeline.md) the four whose first run
    /// missed had 0.031-0.79 % of their area in such gaps, the 42 others at most 0.011 %. 0 (or
    /// less) turns the check off.
    double rebuildFirstGapShare = 2e-4;
    double narrowGapReach = 0.5; ///< in units of L
    /// A run whose estimated peak memory (MemoryBudget::Estimate: the input's size and the face
    /// count the target edge length implies) exceeds this many MB is refused before any stage,
    /// the mesh untouched; 0 = the memory available when the run starts; < 0 = no check.
    double memoryLimitMB = 0;
    /// The input surface the stages from CVT on project onto (built once, from the cleaned mesh);
    /// reference.phongAlpha is the share of the bounded lift toward its Phong surface, applied only
    /// when the run includes both the CVT and the RAR stage (see ensureReference in Do).
    typename ReferenceSurface<MeshType>::Params reference = ReferenceDefaults();
    typename CleanRawMesh<MeshType>::Params clean; ///< threads: the pipeline's
    typename CvtInitialization<MeshType>::Params cvt;
    typename RandomSegmentation<MeshType>::Params segment;
    typename PatchwiseRemeshing<MeshType>::Params
        rar; ///< rar.rar.targetEdgeLength 0 = the pipeline's L; threads: the pipeline's
    /// Skip the CVT stage when the mesh is a remesh at L already: every angle within [small.minAngleDeg,
    /// polish.maxAngleDeg], and the mean edge length within cvtSkipLengthTolerance x L of L or within
    /// rarSkipLengthTolerance of the mean edge of RAR's sizing field at L on the mesh (its output at
    /// L). CVT resamples from scratch, and a resampled remesh loses area to chords of its chords on
    /// every run.
    bool skipCvtOnRemesh = true;
    double cvtSkipLengthTolerance = 0.1;
    /// Keep such a remesh as it is (skip the valence, RAR and polish stages too; small, obtuse and
    /// smooth find nothing out of bounds) when V567 is at the verdict's target and the mesh has the
    /// resolution RAR would give it: with the default L (the mesh's own mean edge length, also when
    /// given explicitly, as MeshLab's dialog pre-fills it) always, since the field capped at L would
    /// refine the remesh by a fifth on every run; with an explicit L when the mean edge length of
    /// RAR's sizing field at L on this mesh is within rarSkipLengthTolerance of the mesh's own.
    /// Remeshing an output again with the same options then leaves it as it is (the valence stages
    /// would trade its smallest angles for a few regular vertices).
    bool skipRarOnRemesh = true;
    double rarSkipLengthTolerance = 0.05;
    /// The reference's lift toward its Phong surface (reference.phongAlpha) when the CVT stage was
    /// skipped: a remesh has no slivers, its vertex normals describe its curved surface, and RAR's
    /// moves on the flat triangles of a remesh cut its chords again. Measured on a second run over
    /// the output of BPTI (MSMS): area -0.36 % with lift 0, -0.18 % with 0.5, +0.01 % with 1.
    double remeshReferenceLift = 1.0;
    // For the following stages targetEdgeLength 0 = the pipeline's L; threads and seed: the pipeline's.
    typename ValenceOptimization<MeshType>::Params valence;
    typename SmallAngleElimination<MeshType>::Params small;
    typename ObtuseReduction<MeshType>::Params obtuse;
    typename LocalSmoothing<MeshType>::Params smooth;
    typename ValenceOptimization<MeshType>::Params polish = PolishDefaults(); ///< valence with max angle 90

    // Settings shared by several stages, set in one place so the CLI and the plugin agree.
    /// No edit of valence, small, obtuse, smooth or polish may leave an angle below it.
    void SetMinAngle(double deg) {
      valence.minAngleDeg = small.minAngleDeg = obtuse.minAngleDeg = smooth.minAngleDeg = polish.minAngleDeg =
          deg;
    }
    /// Max-angle guard of valence optimization and small-angle elimination.
    void SetMaxAngle(double deg) { valence.maxAngleDeg = small.maxAngleDeg = deg; }
    /// Obtuse reduction's thresholds, in order; polish keeps the lowest as its max angle.
    void SetObtuseThresholds(const std::vector<double>& thresholdsDeg) {
      obtuse.thresholdsDeg = thresholdsDeg;
      if (!thresholdsDeg.empty())
        polish.maxAngleDeg = *std::min_element(thresholdsDeg.begin(), thresholdsDeg.end());
    }
    /// Phase-2 area limit of both valence passes.
    void SetValenceAreaFactor(double factor) { valence.areaFactor = polish.areaFactor = factor; }
  };

  /// Half way toward the input's Phong surface, bounded (see vcg_ext/reference_surface.h): vertices
  /// on the flat input triangles make a remesh of chords of chords.
  static typename ReferenceSurface<MeshType>::Params ReferenceDefaults() {
    typename ReferenceSurface<MeshType>::Params p;
    p.phongAlpha = 0.5;
    return p;
  }

  static typename ValenceOptimization<MeshType>::Params PolishDefaults() {
    typename ValenceOptimization<MeshType>::Params p;
    p.maxAngleDeg = 90.0; // the last obtuse threshold: no edit may add an obtuse face
    p.refillOnReference = true;
    p.relaxedFlips = true;
    return p;
  }

  /// The run's estimated peak memory (MemoryBudget::Estimate). Resampling stages (CVT, RAR) make
  /// a mesh of the target edge length: its face count comes from the input's area and L (the
  /// input's mean edge length when L is not given; the cleaned input's, which the run uses, is no
  /// shorter, so the estimate errs high). Any vcg mesh type: a caller that copies its mesh into
  /// MeshType (the MeshLab plugin) checks before the copy.
  template <class AnyMesh>
  static MemoryEstimate EstimateMemory(const AnyMesh& m, const Params& params) {
    const auto runs = [&](PipelineStage stage) {
      return std::find(params.stages.begin(), params.stages.end(), stage) != params.stages.end();
    };
    const bool resamples = runs(PipelineStage::Cvt) || runs(PipelineStage::Rar);
    double area = 0, L = params.targetEdgeLength;
    if (resamples) {
      for (const auto& f : m.face)
        if (!f.IsD())
          area += 0.5 *
                  ((PositionOf(f.cV(1)) - PositionOf(f.cV(0))) ^ (PositionOf(f.cV(2)) - PositionOf(f.cV(0))))
                      .Norm();
      if (!(L > 0)) L = MeanEdgeLength(m);
    }
    return MemoryBudget::Estimate(std::size_t(m.fn), std::size_t(m.vn), resamples, area, L);
  }

  /// "" when the run fits the memory limit (Params::memoryLimitMB), else why not.
  template <class AnyMesh>
  static std::string MemoryCheck(const AnyMesh& m, const Params& params) {
    if (params.memoryLimitMB < 0) return {};
    return MemoryBudget::Check(EstimateMemory(m, params), params.memoryLimitMB);
  }

  static std::vector<PipelineStage> AllStages() {
    std::vector<PipelineStage> all;
    for (const auto& info : PipelineStages()) all.push_back(info.stage);
    return all;
  }

  /// Runs the stages on m, and once more on the input rebuilt from a volume when the output's
  /// angles miss their bounds (Params::rebuildWhenAnglesMiss), or on the rebuilt input first when
  /// the cleaned input has narrow gaps (Params::rebuildFirstGapShare). Requires FF and VF adjacency
  /// (enabled; they are recomputed). log, when given, receives one line per event (stage start and
  /// end) for progress output.
  static PipelineResult Do(MeshType& m, const Params& params,
                           const std::function<void(const std::string&)>& log = {},
                           vcg::CallBackPos* cb = nullptr) {
    if (!MayRetryWithRebuild(params)) return DoOnce(m, params, log, cb);
    MeshType input;
    vcg::tri::Append<MeshType, MeshType>::MeshCopy(input, m);
    GapCheck gaps;
    PipelineResult first = DoOnce(m, params, log, cb, {nullptr, &gaps});
    if (gaps.rebuildFirst) return RebuildFirst(m, input, gaps, first.seconds, params, log, cb);
    if (!first.ok || first.rebuiltVolumetrically || AngleExcess(first, params) <= 0) return first;
    const std::string why = AnglesMissed(first, params);
    if (log) log(why + ": the surface is rebuilt from a volume and remeshed again");
    std::string rebuildRefusal; // set when the second run's rebuild is refused: it stops there
    PipelineResult second = DoOnce(input, Rebuilding(params), log, cb, {&rebuildRefusal, nullptr});
    return Choose(m, input, first, second, rebuildRefusal, why, params, log);
  }

private:
  /// The narrow-gap check after the clean stage (Params::rebuildFirstGapShare).
  struct GapCheck {
    bool rebuildFirst = false; ///< the share was above the threshold: the run stopped after cleaning
    double share = 0;          ///< of the cleaned input's area in narrow gaps
    double reach = 0;          ///< the rays' reach (mesh units)
    double cleanedArea = 0;
  };
  /// What a run checks and stops for after its clean stage when the surface was not rebuilt.
  struct StopChecks {
    std::string* rebuildRefusal = nullptr; ///< stop, saying why the rebuild asked for was refused
    GapCheck* gaps = nullptr;              ///< measure the narrow gaps; stop when they are many
  };

  static Params Rebuilding(const Params& params) {
    Params again = params;
    again.clean.volumetricRebuild = true; // the run --volumetric-rebuild asks for, L included
    return again;
  }
  static std::string AnglesMissed(const PipelineResult& r, const Params& params) {
    return "the angles, " + AngleSpan(r) + ", are outside [" +
           detail::FormatNumber(params.small.minAngleDeg, 2) + ", " +
           detail::FormatNumber(params.polish.maxAngleDeg, 2) + "] deg";
  }

  /// The runs when the cleaned input has narrow gaps: on the rebuilt input first, kept when it is
  /// valid and keeps the area; otherwise the run without the rebuild and the choice of Do's retry.
  /// stoppedSeconds: the time of the run that measured the gaps and stopped.
  static PipelineResult RebuildFirst(MeshType& m, MeshType& input, const GapCheck& gaps,
                                     double stoppedSeconds, const Params& params,
                                     const std::function<void(const std::string&)>& log,
                                     vcg::CallBackPos* cb) {
    const std::string why = detail::FormatNumber(100 * gaps.share, 3) +
                            " % of the cleaned input's area faces the surface again within " +
                            detail::FormatNumber(gaps.reach, 3) + " in front of it";
    if (log) log(why + ": the surface is rebuilt from a volume before remeshing");
    vcg::tri::Append<MeshType, MeshType>::MeshCopy(m, input); // the stopped run cleaned m
    UpdateAdjacency(m);
    std::string rebuildRefusal;
    PipelineResult rebuilt = DoOnce(input, Rebuilding(params), log, cb, {&rebuildRefusal, nullptr});
    rebuilt.seconds += stoppedSeconds;
    const std::string refusal = RebuiltFirstRefusal(rebuilt, rebuildRefusal, gaps, params);
    if (refusal.empty()) {
      rebuilt.rebuildRetry.tried = rebuilt.rebuildRetry.kept = rebuilt.rebuildRetry.first = true;
      rebuilt.rebuildRetry.message =
          why + "; remeshed after rebuilding the surface from a volume: kept, angles " + AngleSpan(rebuilt) +
          ", " + Figures(rebuilt.input, rebuilt.stages.back().after);
      return Keep(m, input, std::move(rebuilt), log);
    }
    if (log) log(why + "; the rebuilt surface is not kept (" + refusal + "): remeshed without the rebuild");
    PipelineResult first = DoOnce(m, params, log, cb);
    if (!first.ok || first.rebuiltVolumetrically || AngleExcess(first, params) <= 0) {
      first.seconds += rebuilt.seconds;
      first.rebuildRetry.tried = first.rebuildRetry.first = true;
      first.rebuildRetry.message = why +
                                   "; remeshed first after rebuilding the surface from a volume: not kept (" +
                                   refusal + "); remeshed again without the rebuild";
      if (log) log(first.rebuildRetry.message);
      return first;
    }
    PipelineResult chosen =
        Choose(m, input, first, rebuilt, rebuildRefusal, AnglesMissed(first, params), params, log);
    chosen.rebuildRetry.first = true;
    return chosen;
  }
  /// Why the run on the rebuilt surface made first is not the output ("" = it is).
  static std::string RebuiltFirstRefusal(const PipelineResult& rebuilt, const std::string& rebuildRefusal,
                                         const GapCheck& gaps, const Params& params) {
    if (!rebuildRefusal.empty()) return "the rebuild was refused (" + rebuildRefusal + ")";
    if (!rebuilt.ok) return "the run failed (" + rebuilt.message + ")";
    if (!rebuilt.verdict.Valid()) return "its output is not valid";
    const double area = rebuilt.stages.back().after.area;
    if (!(std::fabs(area - gaps.cleanedArea) <= params.retryMaxAreaChange * gaps.cleanedArea))
      return "its area differs from the cleaned input's by " + PercentChange(gaps.cleanedArea, area) +
             ", more than " + detail::FormatNumber(100 * params.retryMaxAreaChange, 2) +
             " % (retryMaxAreaChange)";
    return {};
  }
  /// Keeps the first run's output or the second's (on input) by RetryRefusal, says why in the
  /// kept result's rebuildRetry and leaves the kept output in m.
  static PipelineResult Choose(MeshType& m, MeshType& input, PipelineResult& first, PipelineResult& second,
                               const std::string& rebuildRefusal, const std::string& why,
                               const Params& params, const std::function<void(const std::string&)>& log) {
    const std::string refusal = RetryRefusal(first, second, rebuildRefusal, params);
    const bool keep = refusal.empty();
    PipelineResult& kept = keep ? second : first;
    kept.rebuildRetry.tried = true;
    kept.rebuildRetry.kept = keep;
    kept.rebuildRetry.message = RetryMessage(why, first, second, refusal);
    kept.seconds = first.seconds + second.seconds;
    if (!keep) { // the verdict's advice to rebuild was followed
      first.targets.rebuildTried = true;
      first.verdict = OutputVerdict::Of(first.stages.back().after, first.targets);
      if (log) log(kept.rebuildRetry.message);
      return std::move(first);
    }
    return Keep(m, input, std::move(second), log);
  }
  /// m becomes the rebuilt run's output (made on input).
  static PipelineResult Keep(MeshType& m, MeshType& input, PipelineResult rebuilt,
                             const std::function<void(const std::string&)>& log) {
    vcg::tri::Append<MeshType, MeshType>::MeshCopy(m, input);
    UpdateAdjacency(m);
    if (log) log(rebuilt.rebuildRetry.message);
    return rebuilt;
  }

  /// One run of the stages. When its clean stage does not rebuild the surface, it stops after that
  /// stage (not ok) with checks.rebuildRefusal (which then says why: its remesh would repeat a run
  /// without the rebuild), or with checks.gaps when the cleaned input's narrow gaps are many.
  static PipelineResult DoOnce(MeshType& m, const Params& params,
                               const std::function<void(const std::string&)>& log, vcg::CallBackPos* cb,
                               StopChecks checks = {}) {
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    RunState run(m, params, log);
    if (!run.Admit()) return run.result;
    const std::size_t stageCount = params.stages.size();
    for (std::size_t s = 0; s < stageCount; ++s) {
      const PipelineStage stage = params.stages[s];
      const bool last = s + 1 == stageCount;
      PipelineStageRecord record;
      record.name = StageName(stage);
      run.Say(std::string("stage ") + record.name + " ...");
      if (cb) cb(int(100 * s / std::max<std::size_t>(1, stageCount)), record.name.c_str());
      const auto stageStart = Clock::now();
      std::optional<QualityReport> cleanReport; // the cleaning's own report of its result
      // A stage that leaves the mesh as it found it (segmentation always, a local stage with
      // nothing to fix) reuses the previous report instead of measuring the same mesh again.
      const bool mayReuseReport =
          params.measureEachStage && params.measureIntermediateStages && !run.result.stages.empty();
      const GeometrySnapshot before = mayReuseReport ? GeometrySnapshot::Of(m) : GeometrySnapshot();
      // Segmentation walks face-face adjacency without building it (RAR may segment first); every
      // other stage builds the adjacency it needs on entry.
      if (stage == PipelineStage::Segment || stage == PipelineStage::Rar) UpdateAdjacency(m);
      if (const std::string error = RunStage(run, stage, last, record.summary, cleanReport); !error.empty())
        return run.Fail(record, error);
      vcg::tri::Allocator<MeshType>::CompactEveryVector(m);
      // A stage that grew the mesh leaves its vectors up to twice as large as they are: the
      // stages after it would carry that room at their peaks.
      ElementCapacity<MeshType>::ShrinkToFit(m);
      record.seconds = std::chrono::duration<double>(Clock::now() - stageStart).count();
      PendingReport report = MeasureStage(run, last, mayReuseReport, before, cleanReport);
      run.Say(std::string("stage ") + record.name + " done in " + std::to_string(record.seconds) + " s");
      run.result.stages.push_back(record);
      run.stageReports.push_back(report);
      if (stage == PipelineStage::Clean && !run.targets.rebuiltVolumetrically) {
        if (const std::string stop = StopAfterClean(run, checks); !stop.empty()) {
          run.Stop(stop);
          run.result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
          return std::move(run.result);
        }
      }
    }
    run.ResolveReports();
    run.LeaveFrame();
    UpdateAdjacency(m);
    if (params.measureEachStage && !run.result.stages.empty()) {
      run.result.targets = Targets(run);
      run.result.verdict = OutputVerdict::Of(run.result.stages.back().after, run.result.targets);
    }
    run.result.rebuiltVolumetrically = run.targets.rebuiltVolumetrically;
    run.result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    if (cb) cb(100, "done");
    return std::move(run.result);
  }

  /// Whether Do may run a second time (Params::rebuildWhenAnglesMiss).
  static bool MayRetryWithRebuild(const Params& params) {
    return clean::kVolumetricRebuildAvailable && params.rebuildWhenAnglesMiss &&
           !params.clean.volumetricRebuild && params.clean.volumetricFallback && params.measureEachStage &&
           Runs(params, PipelineStage::Clean) && Runs(params, PipelineStage::Small) &&
           Runs(params, PipelineStage::Polish);
  }
  /// How far (degrees) the output's angles reach beyond [small.minAngleDeg, polish.maxAngleDeg].
  static double AngleExcess(const PipelineResult& r, const Params& params) {
    if (r.stages.empty()) return 0;
    const QualityReport& out = r.stages.back().after;
    return std::max({0.0, params.small.minAngleDeg - out.angleMin, out.angleMax - params.polish.maxAngleDeg});
  }
  static std::string AngleSpan(const PipelineResult& r) {
    const QualityReport& out = r.stages.back().after;
    return detail::FormatNumber(out.angleMin, 2) + "-" + detail::FormatNumber(out.angleMax, 2) + " deg";
  }
  /// Signed change from `from` to `to` in percent of |from|, as "+1.23 %".
  static std::string PercentChange(double from, double to) {
    const double percent = from != 0 ? 100.0 * (to - from) / std::fabs(from) : 0.0;
    return (percent >= 0 ? "+" : "") + detail::FormatNumber(percent, 2) + " %";
  }
  /// Why the second run's output is not kept ("" = kept): it must be valid, its worst angle nearer
  /// the bounds, its area within retryMaxAreaChange of the first's.
  static std::string RetryRefusal(const PipelineResult& first, const PipelineResult& second,
                                  const std::string& rebuildRefusal, const Params& params) {
    if (!rebuildRefusal.empty()) return "the rebuild was refused (" + rebuildRefusal + ")";
    if (!second.ok) return "the second run failed (" + second.message + ")";
    if (!second.verdict.Valid()) return "its output is not valid";
    if (!(AngleExcess(second, params) < AngleExcess(first, params)))
      return "its angles are no nearer the bounds";
    const double a = first.stages.back().after.area, b = second.stages.back().after.area;
    if (!(std::fabs(b - a) <= params.retryMaxAreaChange * a))
      return "its area differs from the first output's by " + PercentChange(a, b) + ", more than " +
             detail::FormatNumber(100 * params.retryMaxAreaChange, 2) + " % (retryMaxAreaChange)";
    return {};
  }
  /// The retry in one line: why, and the second run's figures against the first's. Volumes are
  /// compared with the input's magnitude (an inward input encloses a negative volume).
  static std::string RetryMessage(const std::string& why, const PipelineResult& first,
                                  const PipelineResult& second, const std::string& refusal) {
    if (!second.ok && !second.rebuiltVolumetrically) // stopped, or failed, before remeshing again
      return why + "; not remeshed again: " + refusal;
    const std::string head = why + "; remeshed again after rebuilding the surface from a volume: ";
    const std::string verdict = refusal.empty() ? "kept" : "not kept (" + refusal + ")";
    if (!second.ok || second.stages.empty()) return head + verdict;
    const QualityReport &in = first.input, &a = first.stages.back().after, &b = second.stages.back().after;
    const double inVolume = std::fabs(in.volume);
    return head + verdict + ", angles " + AngleSpan(second) + ", V567 " +
           detail::FormatNumber(b.v567Percent, 2) + " % (first: " + detail::FormatNumber(a.v567Percent, 2) +
           " %), area " + PercentChange(in.area, b.area) +
           " of the input's (first: " + PercentChange(in.area, a.area) + "), volume " +
           PercentChange(inVolume, b.volume) + " (first: " + PercentChange(inVolume, a.volume) +
           "), components " + std::to_string(b.components) + " (first: " + std::to_string(a.components) +
           "); parts thinner than about the edge length are removed and crevices as narrow sealed";
  }
  /// The rebuilt run's output against the input, for the note when it was made first.
  static std::string Figures(const QualityReport& in, const QualityReport& out) {
    return "V567 " + detail::FormatNumber(out.v567Percent, 2) + " %, area " +
           PercentChange(in.area, out.area) + " of the input's, volume " +
           PercentChange(std::fabs(in.volume), out.volume) + ", components " +
           std::to_string(out.components) +
           "; parts thinner than about the edge length are removed and crevices as narrow sealed";
  }

  /// A quality report being measured (or measured) on its own thread.
  struct PendingReport {
    std::shared_future<QualityReport> future;
    bool intersections = false; ///< whether Get() reports self-intersections (the measurement may
                                ///< have them when a stage without them reuses its report)
    QualityReport Get() const {
      QualityReport r = future.get();
      if (!intersections && r.selfIntersectionsComputed) { // as a measurement without them reports
        r.selfIntersectingPairs = r.adjacentOverlapPairs = 0;
        r.selfIntersectingFaces = 0;
        r.selfIntersectionsComputed = false;
      }
      return r;
    }
  };
  /// A report measured already.
  static PendingReport Ready(QualityReport report, bool intersections) {
    std::promise<QualityReport> done;
    done.set_value(std::move(report));
    PendingReport pending;
    pending.future = done.get_future().share();
    pending.intersections = intersections;
    return pending;
  }
  /// Captures m now and measures the capture on a thread of its own with one core.
  static PendingReport MeasureLater(const MeshType& m, typename MeshQuality<MeshType>::Params params) {
    PendingReport pending;
    pending.intersections = params.computeSelfIntersections;
    auto capture = std::make_shared<QualityCapture>(MeshQuality<MeshType>::Capture(m));
    params.threads = 1;
    pending.future = std::async(std::launch::async, [capture, params]() {
                       return MeshQuality<MeshType>::Compute(std::move(*capture), params);
                     }).share();
    return pending;
  }

  /// Positions and faces (vertex indices) of the live elements, to tell whether a stage changed
  /// the mesh. Exact comparison, no hash: a report is reused only for the very same mesh.
  struct GeometrySnapshot {
    std::vector<vcg::Point3d> positions;
    std::vector<std::size_t> faces;
    static GeometrySnapshot Of(const MeshType& m) {
      GeometrySnapshot g;
      g.positions.reserve(m.vert.size());
      for (const auto& v : m.vert) g.positions.push_back(Position(v));
      g.faces.reserve(3 * m.face.size());
      for (const auto& f : m.face)
        for (int k = 0; k < 3; ++k) g.faces.push_back(Corner(m, f, k));
      return g;
    }
    /// Whether m is still the mesh the snapshot was taken of (stops at the first difference).
    bool Matches(const MeshType& m) const {
      if (positions.size() != m.vert.size() || faces.size() != 3 * m.face.size()) return false;
      for (std::size_t i = 0; i < m.vert.size(); ++i)
        if (positions[i] != Position(m.vert[i])) return false;
      for (std::size_t i = 0; i < m.face.size(); ++i)
        for (int k = 0; k < 3; ++k)
          if (faces[3 * i + k] != Corner(m, m.face[i], k)) return false;
      return true;
    }

  private:
    /// A deleted vertex is marked by an infinite position (a live one is finite: the pipeline
    /// refuses other input), a deleted face by an impossible vertex index.
    static vcg::Point3d Position(const typename MeshType::VertexType& v) {
      constexpr double kDeleted = std::numeric_limits<double>::infinity();
      return v.IsD() ? vcg::Point3d(kDeleted, kDeleted, kDeleted) : vcg::Point3d::Construct(v.cP());
    }
    static std::size_t Corner(const MeshType& m, const typename MeshType::FaceType& f, int k) {
      return f.IsD() ? ~std::size_t(0) : std::size_t(vcg::tri::Index(m, f.cV(k)));
    }
  };

  /// Whether the run includes the stage.
  static bool Runs(const Params& params, PipelineStage stage) {
    return std::find(params.stages.begin(), params.stages.end(), stage) != params.stages.end();
  }

  /// What the stages of one run share: the mesh, the result so far, the quality reports being
  /// measured, the reference surface and the input's copy to restore on failure.
  struct RunState {
    MeshType& m;
    const Params& params;
    const std::function<void(const std::string&)>& log;
    PipelineResult result;
    typename MeshQuality<MeshType>::Params qualityParams;
    PendingReport inputReport;
    std::vector<PendingReport> stageReports; // one per record in result.stages
    std::unique_ptr<ReferenceSurface<MeshType>> reference;
    OutputTargets targets; // the causes are filled in by the clean stage
    MeshType backup;
    CoordinateFrame<MeshType> frame; // the stages run in it; m leaves it on output
    bool inFrame = false;            // whether m is in the recentred frame now
    bool cvtSkipped = false;         // the input was a remesh at L already (Params::skipCvtOnRemesh)
    bool remeshKept = false;    // ... with RAR's resolution: valence, RAR, polish skipped (skipRarOnRemesh)
    std::string rebuildRefusal; // why the clean stage's volumetric rebuild was refused, when it was

    RunState(MeshType& mesh, const Params& p, const std::function<void(const std::string&)>& logger)
        : m(mesh), params(p), log(logger) {}

    void Say(const std::string& line) const {
      if (log) log(line);
    }

    /// Checks the input and the memory it needs; when both pass, starts the input's report and
    /// keeps the copy to restore. False (result says why) when the run is refused.
    bool Admit() {
      const InputCheck check = CheckTriangleMeshInput(m);
      if (!check.ok) {
        result.ok = false;
        result.message = check.message;
        return false;
      }
      frame = CoordinateFrame<MeshType>::For(m);
      if (std::string why = frame.CoarseResolution(m); !why.empty()) {
        result.ok = false;
        result.message = "refused: " + why + " (the mesh is unchanged)";
        Say(result.message);
        return false;
      }
      if (std::string why = MemoryCheck(m, params); !why.empty()) {
        result.ok = false;
        result.refusedForMemory = true;
        result.message = "refused: " + why + " (the mesh is unchanged)";
        Say(result.message);
        return false;
      }
      qualityParams.threads = params.threads;
      // The reports are measured on a copy of the mesh (QualityCapture), each on a thread of its own
      // and one core, while the next stage runs: the stages are serial for long stretches, so a
      // report mostly takes the idle core instead of adding its time. The figures do not depend on
      // the thread count. A report is waited for where it is read: the target edge length (taken
      // from the last report) and the end. The last stage's report has nothing to overlap and runs
      // on all threads.
      inputReport = MeasureLater(m, qualityParams);
      if (params.restoreOnFailure) vcg::tri::Append<MeshType, MeshType>::MeshCopy(backup, m);
      frame.Enter(m);
      inFrame = frame.Recentres();
      return true;
    }

    /// Moves m back to the input's frame. The last report is measured again when that moved
    /// anything: rounding to the input's coordinates may change its figures.
    void LeaveFrame() {
      if (!inFrame) return;
      frame.Leave(m);
      inFrame = false;
      if (!params.measureEachStage || result.stages.empty()) return;
      typename MeshQuality<MeshType>::Params last = qualityParams;
      last.computeSelfIntersections = true;
      result.stages.back().after = MeshQuality<MeshType>::Compute(m, last);
    }

    void ResolveReports() {
      if (inputReport.future.valid()) result.input = inputReport.Get();
      for (std::size_t i = 0; i < stageReports.size() && i < result.stages.size(); ++i)
        if (stageReports[i].future.valid()) result.stages[i].after = stageReports[i].Get();
    }

    /// Ends the run at a failed stage: the record says why, m is the input again when the copy
    /// was kept.
    PipelineResult Fail(PipelineStageRecord& record, const std::string& why) {
      record.ok = false;
      record.summary = why;
      result.stages.push_back(record);
      result.ok = false;
      result.message = std::string("stage '") + record.name + "' failed: " + why;
      ResolveReports();
      if (params.restoreOnFailure) {
        result.message += " (the mesh is unchanged)";
        vcg::tri::Append<MeshType, MeshType>::MeshCopy(m, backup);
        inFrame = false;
        UpdateAdjacency(m);
      } else if (inFrame) {
        frame.Leave(m);
        inFrame = false;
      }
      Say(result.message);
      return result;
    }

    /// Ends the run before its next stage (not ok): message says why. m is left as it is.
    void Stop(const std::string& message) {
      result.ok = false;
      result.message = message;
      ResolveReports();
      if (inFrame) frame.Leave(m);
      inFrame = false;
      Say(result.message);
    }

    /// Builds the reference surface from m on first use. Returns the error.
    std::string EnsureReference() {
      if (reference) return {};
      reference = std::make_unique<ReferenceSurface<MeshType>>();
      std::string error;
      // The lift recovers the curved surface the molecular input's vertices sample. Only a run
      // that both resamples that input (CVT) and remeshes it to the final resolution (RAR) lifts.
      // A run that starts later gets a remesh as its reference, whose vertices a lift would move
      // again, stage after stage; a run that stopped after CVT would hand a lifted layer to the next
      // run as its reference, which is no longer the input (the filters, one per stage, chain so).
      typename ReferenceSurface<MeshType>::Params referenceParams = params.reference;
      if (!Runs(params, PipelineStage::Cvt) || !Runs(params, PipelineStage::Rar))
        referenceParams.phongAlpha = 0;
      else if (cvtSkipped)
        referenceParams.phongAlpha = params.remeshReferenceLift;
      if (!reference->Build(m, referenceParams, &error)) return error;
      return {};
    }

    /// Sets result.targetEdgeLength on first use: the given one, or the mean edge length of m.
    void EnsureTargetLength() {
      if (result.targetEdgeLength > 0) return;
      if (params.targetEdgeLength > 0) {
        result.targetEdgeLength = params.targetEdgeLength;
        return;
      }
      // The last report already measured m as it is now (the input, or the previous stage's
      // output): no second pass over the mesh.
      ResolveReports();
      if (result.stages.empty())
        result.targetEdgeLength = result.input.meanEdgeLength;
      else if (params.measureEachStage && stageReports.back().future.valid())
        result.targetEdgeLength = result.stages.back().after.meanEdgeLength;
      else
        result.targetEdgeLength =
            MeshQuality<MeshType>::Compute(m, NoIntersections(params.threads)).meanEdgeLength;
    }
  };

  /// Runs one stage on run.m; summary receives its summary. Returns the error ("" on success).
  static std::string RunStage(RunState& run, PipelineStage stage, bool last, std::string& summary,
                              std::optional<QualityReport>& cleanReport) {
    const MeshType& m = run.m;
    // A surface to remesh needs at least a tetrahedron's 4 faces; fewer (a lone triangle, a
    // pair) are refused with a message rather than passed through unchanged. (Cleaning runs
    // first, so an all-degenerate mesh is reported as such.)
    if (stage != PipelineStage::Clean && m.fn < kMinFaces)
      return "the mesh has only " + std::to_string(m.fn) + " face" + (m.fn == 1 ? "" : "s") +
             ": too few to remesh (a closed surface has at least " + std::to_string(kMinFaces) + ")";
    const Params& params = run.params;
    switch (stage) {
    case PipelineStage::Clean:
      return RunClean(run, last, summary, cleanReport);
    case PipelineStage::Cvt:
      return RunCvt(run, summary);
    case PipelineStage::Segment:
      return RunSegment(run, summary);
    case PipelineStage::Rar:
      return RunRar(run, summary);
    case PipelineStage::Valence:
    case PipelineStage::Polish: {
      if (run.remeshKept) {
        summary = "skipped: the remesh is kept (see cvt)";
        return {};
      }
      std::string error = RunLocalStage<ValenceOptimization<MeshType>>(
          run, stage == PipelineStage::Valence ? params.valence : params.polish, summary,
          [](const auto& r) { return ValenceOptimizationSummary(r); });
      if (error.empty() && stage == PipelineStage::Polish) RunTinyComponents(run, summary);
      return error;
    }
    case PipelineStage::Small:
      return RunLocalStage<SmallAngleElimination<MeshType>>(
          run, params.small, summary, [](const auto& r) { return SmallAngleEliminationSummary(r); });
    case PipelineStage::Obtuse:
      return RunLocalStage<ObtuseReduction<MeshType>>(
          run, params.obtuse, summary, [](const auto& r) { return ObtuseReductionSummary(r); });
    case PipelineStage::Smooth:
      return RunLocalStage<LocalSmoothing<MeshType>>(run, params.smooth, summary,
                                                     [](const auto& r) { return LocalSmoothingSummary(r); });
    }
    return {};
  }

  /// The closed components too small to be regular remade as icosahedra (tiny_components.h).
  static void RunTinyComponents(RunState& run, std::string& summary) {
    typename TinyComponentRegularization<MeshType>::Params tiny;
    tiny.minAngle = run.params.polish.minAngleDeg;
    tiny.maxAngle = run.params.polish.maxAngleDeg;
    const TinyComponentResult r = TinyComponentRegularization<MeshType>::Do(run.m, tiny);
    if (r.tiny > 0)
      summary += "\nsmall components remade as icosahedra: " + std::to_string(r.remade) + " of " +
                 std::to_string(r.tiny);
  }

  /// Why the cleaned mesh cannot be remeshed into a valid surface: the local repairs left it invalid
  /// (a tangle, a non-orientable or non-manifold part, a degenerate face) and the volumetric rebuild
  /// was tried and refused (the input encloses no volume, or the memory limit). Empty otherwise; an
  /// open but valid mesh is remeshed (its holes are named in the output verdict), and so is an invalid
  /// one when the fallback was off or is not built in (the verdict then says it is invalid).
  static std::string LeftInvalid(const typename CleanRawMesh<MeshType>::Result& r) {
    if (r.InvalidDefectsLeft() == 0 || !r.RebuildRefused()) return {};
    return "the input cannot be made a valid surface: the repairs left " + r.fallback.trigger +
           ", and the volumetric rebuild was refused (" + r.fallback.message + ")";
  }

  /// Why a run stops after its clean stage, which did not rebuild the surface ("" = it goes on).
  static std::string StopAfterClean(RunState& run, const StopChecks& checks) {
    if (checks.rebuildRefusal) {
      *checks.rebuildRefusal =
          run.rebuildRefusal.empty() ? "the clean stage did not rebuild" : run.rebuildRefusal;
      return "stopped after the clean stage: the volumetric rebuild was refused (" + *checks.rebuildRefusal +
             ")";
    }
    if (!checks.gaps || !(run.params.rebuildFirstGapShare > 0)) return {};
    GapCheck& gaps = *checks.gaps;
    run.EnsureTargetLength();
    gaps.reach = run.params.narrowGapReach * run.result.targetEdgeLength;
    typename NarrowGaps<MeshType>::Params gapParams;
    gapParams.reach = gaps.reach;
    gapParams.threads = run.params.threads;
    const NarrowGapsResult measured = NarrowGaps<MeshType>::Measure(run.m, gapParams);
    gaps.share = measured.Share();
    gaps.cleanedArea = measured.area;
    run.Say("narrow gaps: " + detail::FormatNumber(100 * gaps.share, 4) + " % of the area within " +
            detail::FormatNumber(gaps.reach, 4));
    if (!(gaps.share > run.params.rebuildFirstGapShare)) return {};
    gaps.rebuildFirst = true;
    return "stopped after the clean stage: narrow gaps on " + detail::FormatNumber(100 * gaps.share, 3) +
           " % of the area (rebuildFirstGapShare " +
           detail::FormatNumber(100 * run.params.rebuildFirstGapShare, 3) +
           " %): the surface is rebuilt first";
  }
  static std::string RunClean(RunState& run, bool last, std::string& summary,
                              std::optional<QualityReport>& cleanReport) {
    const Params& params = run.params;
    auto cleanParams = params.clean;
    cleanParams.threads = params.threads;
    // Its own before/after intersection counts would repeat the pipeline's input report and
    // final report (two grid sweeps), unless it is the last stage or every stage is checked.
    if (!params.intersectionsEachStage && !last) cleanParams.measureSelfIntersections = false;
    const auto r = CleanRawMesh<MeshType>::Do(run.m, cleanParams);
    if (!r.ok) return r.message;
    if (std::string why = LeftInvalid(r); !why.empty()) return why;
    summary = CleanRawMeshSummary(r);
    run.targets.unrepairedTangles = r.unrepairedTangles;
    run.targets.unfilledHoles = r.unfilledHoles;
    run.targets.largestUnfilledHoleEdges = r.largestUnfilledHoleEdges;
    run.targets.maxHoleEdges = cleanParams.maxHoleEdges;
    run.targets.rebuiltVolumetrically = r.fallback.rebuilt;
    if (r.RebuildRefused()) run.rebuildRefusal = r.fallback.message;
    // A volumetric rebuild's triangles follow its voxels (about half the input's edges): L stays
    // the input's mean edge, so a rebuilt surface is remeshed at the density the input asked for.
    if (r.fallback.rebuilt && !(params.targetEdgeLength > 0) && r.reportBefore.meanEdgeLength > 0)
      run.result.targetEdgeLength = r.reportBefore.meanEdgeLength;
    // The cleaning measured its result already: that report is the stage's when it was taken
    // the way the stage report would be.
    if (cleanParams.degenerateAreaEpsilon == run.qualityParams.degenerateAreaEpsilon &&
        cleanParams.measureSelfIntersections == (params.intersectionsEachStage || last))
      cleanReport = r.reportAfter;
    return {};
  }

  static std::string RunCvt(RunState& run, std::string& summary) {
    run.EnsureTargetLength();
    if (const RemeshFinding remesh = AlreadyRemeshed(run); !remesh.why.empty()) {
      run.cvtSkipped = true;
      summary = "CVT skipped: " + remesh.why;
      if (std::string kept = KeptAsItIs(run, remesh); !kept.empty()) {
        run.remeshKept = true;
        summary += "; kept as it is (valence, RAR and polish skipped): " + kept;
      }
      return {};
    }
    if (std::string error = run.EnsureReference(); !error.empty()) return error;
    auto cvtParams = run.params.cvt;
    if (cvtParams.targetEdgeLength <= 0 && cvtParams.targetVertexCount == 0)
      cvtParams.targetEdgeLength = run.result.targetEdgeLength;
    cvtParams.threads = run.params.threads;
    const auto r = CvtInitialization<MeshType>::Do(run.m, *run.reference, cvtParams);
    if (!r.ok) return r.message;
    summary = r.message;
    return {};
  }

  /// What AlreadyRemeshed finds: why run.m is a remesh at L ("" when it is not), its mean edge
  /// length, whether its V567 is at the verdict's target, and RarResolutionGap when it was needed.
  struct RemeshFinding {
    std::string why;
    double meanEdge = 0;
    bool valencesMet = false;
    std::optional<double> rarGap;
  };

  /// Whether run.m is a remesh at the target length already (Params::skipCvtOnRemesh).
  static RemeshFinding AlreadyRemeshed(RunState& run) {
    const Params& params = run.params;
    const double L = run.result.targetEdgeLength;
    // A vertex count asks CVT for its own L; parameters CVT refuses are reported by the stage itself.
    if (!params.skipCvtOnRemesh || !(L > 0) || params.cvt.targetVertexCount > 0 || params.cvt.iterations < 0)
      return {};
    double lo = 180, hi = 0;
    for (const auto& f : run.m.face) {
      if (f.IsD()) continue;
      double fmin = 0, fmax = 0;
      FaceAngleRange(f, fmin, fmax);
      lo = std::min(lo, fmin);
      hi = std::max(hi, fmax);
      if (lo < params.small.minAngleDeg || hi > params.polish.maxAngleDeg) return {};
    }
    // Only a valid surface counts: CVT's own checks refuse a non-manifold or open one.
    const QualityReport shape = MeshQuality<MeshType>::Compute(run.m, NoIntersections(params.threads));
    if (!shape.isTwoManifold() || shape.boundaryEdges != 0 || shape.degenerateFaces != 0) return {};
    RemeshFinding found;
    found.meanEdge = MeanEdgeLength(run.m);
    if (std::fabs(found.meanEdge - L) > params.cvtSkipLengthTolerance * L) {
      found.rarGap = RarResolutionGap(run, found.meanEdge);
      if (!(*found.rarGap <= params.rarSkipLengthTolerance)) return {};
    }
    found.valencesMet = shape.interiorVertices == 0 || shape.v567Percent >= run.targets.minV567Percent;
    std::ostringstream s;
    s << "the mesh is a remesh at L already (angles " << lo << " .. " << hi << " degrees, mean edge "
      << found.meanEdge / L << " L)";
    found.why = s.str();
    return found;
  }

  /// Why run.m, found a remesh at L, is kept as it is (Params::skipRarOnRemesh), or "".
  static std::string KeptAsItIs(RunState& run, const RemeshFinding& remesh) {
    const Params& params = run.params;
    // Below the V567 target, the valence stages have work to do.
    if (!params.skipRarOnRemesh || !remesh.valencesMet) return {};
    // The default L, or the mesh's own mean edge length given explicitly (as MeshLab's dialog
    // pre-fills it, rounded to a float).
    const double own = remesh.meanEdge, L = run.result.targetEdgeLength;
    if (!(params.rar.rar.targetEdgeLength > 0) &&
        (!(params.targetEdgeLength > 0) || std::fabs(L - own) <= 1e-5 * own))
      return "the target length is the mean edge length of a remesh";
    const double gap = remesh.rarGap ? *remesh.rarGap : RarResolutionGap(run, own);
    if (!(gap <= params.rarSkipLengthTolerance)) return {};
    std::ostringstream s;
    s << "its mean edge is within " << 100.0 * gap << " % of the one RAR's sizing field at L gives it";
    return s.str();
  }

  /// |mean edge length of RAR's sizing field at L on run.m - meanEdge (run.m's)|, relative to meanEdge.
  static double RarResolutionGap(RunState& run, double meanEdge) {
    const Params& params = run.params;
    UpdateAdjacency(run.m, params.threads);
    const std::vector<double> sizing = AdaptiveRemeshing<MeshType>::ComputeSizing(
        run.m, RarTargetLength(run), params.rar.rar, params.threads);
    const double field = AdaptiveRemeshing<MeshType>::MeanEdgeOfSizing(run.m, sizing);
    return meanEdge > 0 ? std::fabs(field - meanEdge) / meanEdge : std::numeric_limits<double>::infinity();
  }

  /// RAR's L: its own targetEdgeLength, or the pipeline's.
  static double RarTargetLength(const RunState& run) {
    const double own = run.params.rar.rar.targetEdgeLength;
    return own <= 0 ? run.result.targetEdgeLength : own;
  }

  /// Segments run.m with the pipeline's seed into run.result's facePatch and patchCount.
  static std::string Segment(RunState& run, SegmentationResult& r) {
    auto segmentParams = run.params.segment;
    segmentParams.seed = run.params.seed;
    r = RandomSegmentation<MeshType>::Do(run.m, segmentParams);
    if (!r.ok) return r.message;
    run.result.patchCount = r.patchCount;
    run.result.facePatch = std::move(r.facePatch);
    return {};
  }

  static std::string RunSegment(RunState& run, std::string& summary) {
    SegmentationResult r;
    if (std::string error = Segment(run, r); !error.empty()) return error;
    summary = SegmentationSummary(r);
    return {};
  }

  static std::string RunRar(RunState& run, std::string& summary) {
    run.EnsureTargetLength();
    if (run.remeshKept) {
      summary = "skipped: the remesh is kept (see cvt)";
      return {};
    }
    if (std::string error = run.EnsureReference(); !error.empty()) return error;
    std::string segmentSummary;
    if (run.result.facePatch.size() != run.m.face.size()) {
      // No segmentation of this mesh yet: segment with the pipeline's seed first.
      SegmentationResult seg;
      if (std::string error = Segment(run, seg); !error.empty()) return error;
      segmentSummary = "segmented first: " + std::to_string(seg.patchCount) + " patches\n";
    }
    auto rarParams = run.params.rar;
    rarParams.rar.targetEdgeLength = RarTargetLength(run);
    rarParams.threads = run.params.threads;
    const auto r = PatchwiseRemeshing<MeshType>::Do(run.m, *run.reference, run.result.facePatch, rarParams);
    if (!r.ok) return r.message;
    summary = segmentSummary + PatchwiseRemeshingSummary(r);
    // The faces changed: the segmentation no longer describes them.
    run.result.facePatch.clear();
    run.result.patchCount = 0;
    return {};
  }

  /// The stages from valence on share one interface: Do(m, reference, params) -> Result{ok, message},
  /// with targetEdgeLength, threads and seed in their Params. Returns the error.
  template <class Stage, class Summarize>
  static std::string RunLocalStage(RunState& run, typename Stage::Params stageParams, std::string& summary,
                                   Summarize summarize) {
    run.EnsureTargetLength();
    if (std::string error = run.EnsureReference(); !error.empty()) return error;
    if (stageParams.targetEdgeLength <= 0) stageParams.targetEdgeLength = run.result.targetEdgeLength;
    stageParams.threads = run.params.threads;
    stageParams.seed = run.params.seed;
    const auto r = Stage::Do(run.m, *run.reference, stageParams);
    if (!r.ok) return r.message.empty() ? std::string("failed") : r.message;
    summary = summarize(r);
    return {};
  }

  /// The report of the mesh after a stage: the previous one when the stage left the mesh as it
  /// was, the cleaning's own, measured now when it is read right away, or measured while the next
  /// stage runs. None when the stages are not measured.
  static PendingReport MeasureStage(RunState& run, bool last, bool mayReuseReport,
                                    const GeometrySnapshot& before,
                                    std::optional<QualityReport>& cleanReport) {
    PendingReport report;
    const Params& params = run.params;
    if (!params.measureEachStage) return report;
    if (!last && !params.measureIntermediateStages && !cleanReport) return report;
    typename MeshQuality<MeshType>::Params stageQuality = run.qualityParams;
    stageQuality.computeSelfIntersections = params.intersectionsEachStage || last;
    const PendingReport& previous = run.result.stages.empty() ? run.inputReport : run.stageReports.back();
    if (mayReuseReport && (previous.intersections || !stageQuality.computeSelfIntersections) &&
        before.Matches(run.m)) {
      report = previous;
      report.intersections = stageQuality.computeSelfIntersections;
    } else if (cleanReport) {
      report = Ready(std::move(*cleanReport), stageQuality.computeSelfIntersections);
    } else if (last || (run.result.targetEdgeLength <= 0 && params.targetEdgeLength <= 0)) {
      // Read right away (the next stage takes its target edge length from it), or the end.
      report =
          Ready(MeshQuality<MeshType>::Compute(run.m, stageQuality), stageQuality.computeSelfIntersections);
    } else {
      report = MeasureLater(run.m, stageQuality);
    }
    return report;
  }

  /// What the output misses of the promises of the stages that ran (the last stage's report).
  static OutputTargets Targets(const RunState& run) {
    const Params& params = run.params;
    OutputTargets targets = run.targets;
    targets.checkAngles = Runs(params, PipelineStage::Small);
    targets.minAngleDeg = params.small.minAngleDeg;
    targets.maxAngleDeg = params.small.maxAngleDeg;
    targets.checkValence = Runs(params, PipelineStage::Valence);
    return targets;
  }
  static typename MeshQuality<MeshType>::Params NoIntersections(int threads) {
    typename MeshQuality<MeshType>::Params p;
    p.computeSelfIntersections = false;
    p.threads = threads;
    return p;
  }
};

} // namespace molremesh

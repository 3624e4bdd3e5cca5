// molremesh: command-line front end for batch jobs. Parse, call vcg_ext, report.
//
// Every failure is one line on stderr starting with "molremesh: error:" and a non-zero exit
// status (2 for unusable input, 1 for command-line mistakes); never a crash. A remeshed output
// that is written but not valid (self-intersections the input's unrepairable tangles left, say)
// exits with status 3 and says why on stderr, as "molremesh: warning:" lines do for the targets a
// valid output misses (status 0).
#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <fstream>
#include <iostream>
#include <new>
#include <string>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <vcg_ext/quality/bad_element_coloring.h>
#include <vcg_ext/core/input_check.h>
#include <vcg_ext/io/mesh_io.h>
#include <vcg_ext/quality/mesh_quality.h>
#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/quality/quality_report_format.h>
#include <vcg_ext/pipeline/remesh_pipeline.h>
#include <vcg_ext/quality/stage_summary.h>

#include "report_json.h"
#include "surface_command.h"

namespace {

using molremesh::MeshD;

constexpr int kExitBadInput = 2;
constexpr int kExitInvalidOutput = 3; ///< the output was written, but it is not a valid surface mesh

struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Loads and validates a triangle mesh, or throws InputError with the reason.
void LoadValidMesh(MeshD& mesh, const std::string& path) {
  std::string error;
  if (!molremesh::LoadMesh(mesh, path, error)) throw InputError(error);
  const molremesh::InputCheck check = molremesh::CheckTriangleMeshInput(mesh);
  if (!check.ok) throw InputError("'" + path + "': " + check.message);
}

int RunReport(const std::string& input, bool json, bool skipSelfIntersections, int threads) {
  MeshD mesh;
  LoadValidMesh(mesh, input);
  molremesh::MeshQuality<MeshD>::Params params;
  params.computeSelfIntersections = !skipSelfIntersections;
  params.threads = threads;
  const molremesh::QualityReport report = molremesh::MeshQuality<MeshD>::Compute(mesh, params);
  if (json) {
    nlohmann::json out = molremesh::ToJson(report);
    out["file"] = input;
    std::cout << out.dump(2) << '\n';
  } else {
    std::cout << "Quality report of " << input << "\n"
              << molremesh::FormatQualityTable(report, "value")
              << "valence histogram (interior vertices): " << molremesh::FormatValenceHistogram(report)
              << '\n';
  }
  return 0;
}

int RunColor(const std::string& input, const std::string& output, double smallAngle, double obtuseAngle) {
  MeshD mesh;
  LoadValidMesh(mesh, input);
  molremesh::BadElementColoring<MeshD>::Params params;
  params.smallAngle = smallAngle;
  params.obtuseAngle = obtuseAngle;
  const molremesh::BadElementCounts counts = molremesh::BadElementColoring<MeshD>::Do(mesh, params);
  std::string error;
  if (!molremesh::SaveMesh(mesh, output, error, /*withQualityAndColor=*/true)) throw InputError(error);
  std::cout << "irregular vertices (red): " << counts.irregularVertices << '\n'
            << "obtuse faces (red or magenta): " << counts.obtuseFaces << '\n'
            << "small-angle faces (blue or magenta): " << counts.smallAngleFaces << '\n'
            << "obtuse and small-angle faces (magenta): " << counts.obtuseAndSmallFaces << '\n';
  return 0;
}

struct RemeshOptions {
  std::string stages;
  double targetLength = 0;
  std::uint64_t seed = 1;
  int threads = 0;
  int cvtIterations = 42;
  double surfaceLift = molremesh::RemeshPipeline<molremesh::MeshD>::ReferenceDefaults().phongAlpha;
  int patches = 0;
  double minAngle = 30;
  double maxAngle = 120;
  std::vector<double> obtuseThresholds{110, 100, 90};
  int translationIterations = 20;
  double areaFactor = 9;
  // Cleaning: the library's defaults.
  double mergeTolerance = molremesh::CleanRawMesh<MeshD>::Params().mergeTolerance;
  int maxHoleEdges = molremesh::CleanRawMesh<MeshD>::Params().maxHoleEdges;
  double minComponentPercent = 100.0 * molremesh::CleanRawMesh<MeshD>::Params().minComponentFraction;
  double memoryLimitMB = 0; // 0: the memory available when the run starts; < 0: no check
  std::string jsonPath;
  bool quiet = false;
  bool checkEachStage = false;
};

int RunRemesh(const std::string& input, const std::string& output, const RemeshOptions& options) {
  using Pipeline = molremesh::RemeshPipeline<MeshD>;
  Pipeline::Params params;
  if (!options.stages.empty()) {
    std::string error;
    if (!molremesh::ParseStageList(options.stages, params.stages, error))
      throw InputError("--stages: " + error);
  }
  params.targetEdgeLength = options.targetLength;
  params.seed = options.seed;
  params.threads = options.threads;
  params.intersectionsEachStage = options.checkEachStage;
  // On failure nothing is written, so no copy of the input (as large as the input) is kept.
  params.restoreOnFailure = false;
  params.cvt.iterations = options.cvtIterations;
  params.reference.phongAlpha = options.surfaceLift;
  params.segment.patchCount = options.patches;
  params.SetMinAngle(options.minAngle);
  params.SetMaxAngle(options.maxAngle);
  params.SetValenceAreaFactor(options.areaFactor);
  params.SetObtuseThresholds(options.obtuseThresholds);
  params.obtuse.iterationsPerThreshold = options.translationIterations;
  params.clean.mergeTolerance = options.mergeTolerance;
  params.clean.maxHoleEdges = options.maxHoleEdges;
  params.clean.minComponentFraction = options.minComponentPercent / 100.0;
  params.memoryLimitMB = options.memoryLimitMB;
  // The output format must be writable before hours of work are spent.
  if (molremesh::FormatFromPath(output) == molremesh::MeshFormat::Unknown)
    throw InputError("cannot write '" + output + "': unknown format (use .ply, .off, .obj or .stl)");

  MeshD mesh;
  LoadValidMesh(mesh, input);
  auto log = [&options](const std::string& line) {
    if (!options.quiet) std::cerr << "molremesh: " << line << std::endl;
  };
  const molremesh::PipelineResult result = Pipeline::Do(mesh, params, log);
  if (result.refusedForMemory)
    throw InputError(result.message + "; --memory-limit MB sets the limit, -1 turns the check off");
  if (!result.ok) throw InputError(result.message);

  std::string error;
  if (!molremesh::SaveMesh(mesh, output, error)) throw InputError(error);

  std::vector<molremesh::NamedReport> columns{{"input", result.input}};
  for (const auto& stage : result.stages) columns.emplace_back(stage.name, stage.after);
  std::cout << "Remeshed " << input << " -> " << output << " (target edge length " << result.targetEdgeLength
            << ", seed " << options.seed << ")\n"
            << molremesh::FormatQualityTable(columns);
  std::cout << molremesh::StageTimesLine(result) << '\n';
  for (const auto& stage : result.stages)
    if (!stage.summary.empty()) {
      std::cout << "-- " << stage.name << ":\n" << stage.summary;
      if (stage.summary.back() != '\n') std::cout << '\n';
    }

  if (!options.jsonPath.empty()) {
    nlohmann::json j;
    j["input_file"] = input;
    j["output_file"] = output;
    j["target_edge_length"] = result.targetEdgeLength;
    j["seed"] = options.seed;
    j["seconds"] = result.seconds;
    j["input"] = molremesh::ToJson(result.input);
    for (const auto& stage : result.stages)
      j["stages"].push_back({{"name", stage.name},
                             {"seconds", stage.seconds},
                             {"summary", stage.summary},
                             {"after", molremesh::ToJson(stage.after)}});
    j["verdict"] = {{"valid", result.verdict.Valid()},
                    {"all_targets_met", result.verdict.AllMet()},
                    {"invalid", result.verdict.invalid},
                    {"short_of", result.verdict.shortOf}};
    std::ofstream(options.jsonPath) << j.dump(2) << '\n';
  }
  // Not progress: printed with --quiet too.
  std::cerr << result.verdict.Lines("molremesh: warning: " + output + " ");
  if (!result.verdict.Valid()) {
    std::cerr << "molremesh: warning: " << output
              << " was written but is not a valid surface mesh (exit status " << kExitInvalidOutput << ")\n";
    return kExitInvalidOutput;
  }
  return 0;
}

/// The stages allocate and free large scratch vectors over and over (per Lloyd iteration, per
/// verification, per patch). glibc serves blocks above its mmap threshold (which grows only up to
/// 32 MB) with fresh mappings and hands freed heap tops back to the kernel, so each round faults
/// the same memory in again: about 500 000 page faults on the 535k-face mTOR mesh. Keeping it in
/// the heap halves them (0.5 s of system time there) for about 30 MB more peak memory. Set here,
/// in the batch tool only: the MeshLab plugin leaves its host's allocator alone.
void KeepFreedMemoryInTheHeap() {
#if defined(__GLIBC__)
  mallopt(M_MMAP_THRESHOLD, 128 << 20);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
#endif
}

/// What the command line sets: the arguments of the three subcommands.
struct CommandLine {
  std::string input, output;
  bool json = false, skipSelfIntersections = false; ///< report
  int reportThreads = 0;                            ///< report
  double smallAngle = 30.0, obtuseAngle = 90.0;     ///< color
  RemeshOptions remesh;
};

CLI::App* AddReportCommand(CLI::App& app, CommandLine& c) {
  CLI::App* report = app.add_subcommand("report", "Print the quality figures of a mesh (no change to it)");
  report->add_option("input", c.input, "Mesh file (.ply, .off, .obj, .stl)")->required();
  report->add_flag("--json", c.json, "Print JSON instead of a table");
  report->add_flag("--no-self-intersections", c.skipSelfIntersections,
                   "Skip the self-intersection count (the slowest figure)");
  report
      ->add_option("--threads", c.reportThreads,
                   "Worker threads, 0 = all cores (figures do not depend on it)")
      ->default_val(0)
      ->check(CLI::NonNegativeNumber);
  return report;
}

CLI::App* AddColorCommand(CLI::App& app, CommandLine& c) {
  CLI::App* color = app.add_subcommand("color", "Write a copy with irregular vertices and obtuse/small-angle "
                                                "faces colored, quality = valence / min angle");
  color->add_option("input", c.input, "Mesh file")->required();
  color->add_option("output", c.output, "Output mesh file (.ply keeps colors and quality)")->required();
  color->add_option("--small-angle", c.smallAngle, "Faces with an angle below it are blue (degrees)")
      ->default_val(30.0)
      ->check(CLI::Range(0.0, 60.0));
  color->add_option("--obtuse-angle", c.obtuseAngle, "Faces with an angle at or above it are red (degrees)")
      ->default_val(90.0)
      ->check(CLI::Range(60.0, 180.0));
  return color;
}

CLI::App* AddRemeshCommand(CLI::App& app, CommandLine& c) {
  std::string stageHelp = "Comma-separated stages to run, in pipeline order (default: all):";
  for (const auto& info : molremesh::PipelineStages()) stageHelp += std::string(" ") + info.name;
  CLI::App* remesh = app.add_subcommand("remesh", "Remesh a molecular surface (all stages, or --stages)");
  remesh->add_option("input", c.input, "Mesh file (.ply, .off, .obj, .stl)")->required();
  remesh->add_option("output", c.output, "Output mesh file")->required();
  remesh->add_option("--stages", c.remesh.stages, stageHelp);
  remesh
      ->add_option("--target-length", c.remesh.targetLength,
                   "Target edge length L (default: the cleaned input's mean edge length)")
      ->check(CLI::NonNegativeNumber);
  remesh->add_option("--seed", c.remesh.seed, "Seed of every random choice")->default_val(1);
  remesh
      ->add_option("--threads", c.remesh.threads,
                   "Worker threads, 0 = all cores (output does not depend on it)")
      ->default_val(0)
      ->check(CLI::NonNegativeNumber);
  remesh->add_option("--cvt-iterations", c.remesh.cvtIterations, "Lloyd iterations of the CVT stage")
      ->default_val(42)
      ->check(CLI::Range(0, 10000));
  remesh
      ->add_option("--surface-lift", c.remesh.surfaceLift,
                   "Share of the way from the input's flat triangles to its smooth (Phong) surface that "
                   "projected vertices go (at most 0.05 mean edge lengths, none at creases); 0 = on the "
                   "flat triangles")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  remesh->add_option("--patches", c.remesh.patches, "Patches of the segmentation, 0 = automatic")
      ->default_val(0)
      ->check(CLI::NonNegativeNumber);
  remesh->add_option("--min-angle", c.remesh.minAngle, "Min angle (deg): no edit creates one below it")
      ->default_val(30.0)
      ->check(CLI::Range(0.0, 59.0));
  remesh
      ->add_option("--max-angle", c.remesh.maxAngle,
                   "Max angle (deg) of valence optimization and small-angle elimination")
      ->default_val(120.0)
      ->check(CLI::Range(61.0, 180.0));
  remesh
      ->add_option("--obtuse-thresholds", c.remesh.obtuseThresholds,
                   "Max-angle thresholds (deg) of obtuse reduction, in order")
      ->default_str("110 100 90")
      ->check(CLI::Range(60.0, 180.0));
  remesh
      ->add_option("--translation-iterations", c.remesh.translationIterations,
                   "Vertex translation rounds per obtuse threshold")
      ->default_val(20)
      ->check(CLI::Range(0, 10000));
  remesh
      ->add_option("--area-factor", c.remesh.areaFactor,
                   "Valence optimization: a hole grows while its area is below this x the mean face area")
      ->default_val(9.0)
      ->check(CLI::NonNegativeNumber);
  remesh
      ->add_option("--merge-tolerance", c.remesh.mergeTolerance,
                   "Clean: merge vertices closer than this x the mean edge length")
      ->default_val(c.remesh.mergeTolerance)
      ->check(CLI::NonNegativeNumber);
  remesh
      ->add_option("--max-hole-edges", c.remesh.maxHoleEdges,
                   "Clean: close holes with at most this many boundary edges")
      ->default_val(c.remesh.maxHoleEdges)
      ->check(CLI::NonNegativeNumber);
  remesh
      ->add_option(
          "--min-component-percent", c.remesh.minComponentPercent,
          "Clean: remove components with fewer than this % of the faces (never the largest; 0 keeps all)")
      ->default_val(c.remesh.minComponentPercent)
      ->check(CLI::Range(0.0, 100.0));
  remesh
      ->add_option("--memory-limit", c.remesh.memoryLimitMB,
                   "Refuse (exit status 2, nothing written) a run whose estimated peak memory exceeds this "
                   "many MB; 0 = the memory available at the start, -1 = no check")
      ->default_val(0)
      ->check(CLI::Range(-1.0, 1e12));
  remesh->add_option("--json", c.remesh.jsonPath, "Also write the per-stage figures as JSON to this file");
  remesh->add_flag("--quiet", c.remesh.quiet, "No progress lines on stderr");
  remesh->add_flag("--check-each-stage", c.remesh.checkEachStage,
                   "Count self-intersections after every stage (default: input and output only)");
  return remesh;
}

} // namespace

int main(int argc, char** argv) {
  KeepFreedMemoryInTheHeap();
  CLI::App app{"molremesh: molecular surface remeshing (valence optimization and angle improvement)"};
  app.require_subcommand(1);
  app.footer("Exit status: 0 done (warnings name any target a valid output misses), 1 command-line mistake, "
             "2 unusable input, a failed stage or a run refused for memory (nothing written), 3 output "
             "written but not a valid surface mesh (the warnings say why).");

  CommandLine c;
  CLI::App* report = AddReportCommand(app, c);
  CLI::App* color = AddColorCommand(app, c);
  CLI::App* remesh = AddRemeshCommand(app, c);
  molremesh::SurfaceCommand surface(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }

  try {
    if (*report) return RunReport(c.input, c.json, c.skipSelfIntersections, c.reportThreads);
    if (*color) return RunColor(c.input, c.output, c.smallAngle, c.obtuseAngle);
    if (*remesh) return RunRemesh(c.input, c.output, c.remesh);
    if (surface.Chosen()) return surface.Run();
  } catch (const InputError& e) {
    std::cerr << "molremesh: error: " << e.what() << '\n';
    return kExitBadInput;
  } catch (const std::bad_alloc&) {
    std::cerr << "molremesh: error: out of memory (nothing written; --memory-limit sets the limit the run is "
                 "checked against before it starts)\n";
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::cerr << "molremesh: error: " << e.what() << '\n';
    return kExitBadInput;
  }
  return 1;
}

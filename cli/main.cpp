// molremesh: command-line front end for batch jobs. Parse, call vcg_ext, report.
//
// Every failure is one line on stderr starting with "molremesh: error:" and a non-zero exit
// status: 1 for command-line mistakes (every value is checked before any work, output paths
// included), 2 for unusable input; never a crash. A remeshed output that is written but not valid
// (self-intersections the input's unrepairable tangles left, say) exits with status 3 and says why
// on stderr, as "molremesh: warning:" lines do for the targets a valid output misses (status 0).
// `remesh` prints one summary line on stderr by default (and progress on a terminal), the
// per-stage tables with --verbose, and nothing but warnings and errors with --quiet.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <iostream>
#include <limits>
#include <new>
#include <sstream>
#include <string>
#include <system_error>
#include <thread>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include <vcg_ext_instances/extern_mesh_d_volume.h>
#include <vcg_ext/quality/bad_element_coloring.h>
#include <vcg_ext/core/input_check.h>
#include <vcg_ext/io/mesh_io.h>
#include <vcg_ext/quality/mesh_quality.h>
#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/quality/quality_report_format.h>
#include <vcg_ext/pipeline/memory_budget.h>
#include <vcg_ext/pipeline/region_remeshing.h>
#include <vcg_ext/pipeline/remesh_pipeline.h>
#include <vcg_ext/quality/stage_summary.h>

#include "report_json.h"
#include "surface_command.h"

namespace {

using molremesh::MeshD;
using namespace molremesh::cli;

const char* const kCommands = "report, color, remesh, surface";

// --- Values checked on the command line ------------------------------------------------------

std::string Readable(double x) {
  std::ostringstream s;
  s << x; // 6 significant digits: 1e+12, not 1000000000000.000000
  return s.str();
}

/// "in [0, 60]", "in (0, 59]", "in [60, 180)", or "at least 0" for an unbounded top.
std::string RangeText(double lo, double hi, bool lowOpen, bool highOpen) {
  if (!std::isfinite(hi)) return (lowOpen ? "above " : "at least ") + Readable(lo);
  return (lowOpen ? "in (" : "in [") + Readable(lo) + ", " + Readable(hi) + (highOpen ? ")" : "]");
}

/// Whole text parsed as a finite double (no trailing characters, no NaN or infinity).
bool ParseFinite(const std::string& text, double& value) {
  if (text.empty()) return false;
  char* end = nullptr;
  errno = 0;
  value = std::strtod(text.c_str(), &end);
  return end && *end == '\0' && errno != ERANGE && std::isfinite(value);
}

/// A finite number in the range; the message says the range as a user writes it.
CLI::Validator Number(double lo, double hi = std::numeric_limits<double>::infinity(), bool lowOpen = false,
                      bool highOpen = false) {
  const std::string range = RangeText(lo, hi, lowOpen, highOpen);
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        double value = 0;
        if (!ParseFinite(text, value)) return "'" + text + "' is not a finite number";
        if (value < lo || value > hi || (lowOpen && value == lo) || (highOpen && value == hi))
          return text + " is not " + range;
        return {};
      },
      range);
}

/// A whole number in [lo, hi].
CLI::Validator WholeNumber(long long lo, long long hi = std::numeric_limits<int>::max()) {
  const std::string range = "in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        char* end = nullptr;
        errno = 0;
        const long long value = std::strtoll(text.c_str(), &end, 10);
        if (text.empty() || !end || *end != '\0' || errno == ERANGE)
          return "'" + text + "' is not a whole number " + range;
        if (value < lo || value > hi) return text + " is not " + range;
        return {};
      },
      range);
}

/// A seed: a whole number in [0, 2^64 - 1], written in decimal digits only (no sign, no exponent).
bool ParseSeed(const std::string& text, std::uint64_t& seed) {
  if (text.empty() || text.size() > 20 ||
      !std::all_of(text.begin(), text.end(), [](char c) { return c >= '0' && c <= '9'; }))
    return false;
  char* end = nullptr;
  errno = 0;
  const unsigned long long value = std::strtoull(text.c_str(), &end, 10);
  if (errno == ERANGE || *end != '\0') return false;
  seed = value;
  return true;
}

CLI::Validator Seed() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        std::uint64_t seed = 0;
        return ParseSeed(text, seed) ? std::string()
                                     : "'" + text + "' is not a whole number in [0, 18446744073709551615]";
      },
      "in [0, 2^64 - 1]");
}

/// Thread counts beyond what the machine runs only cost thread starts (and may fail them): at most
/// 4 per core, with a warning. The output does not depend on the count.
int ClampThreads(int requested) {
  const int cores = int(std::max(1u, std::thread::hardware_concurrency()));
  const int cap = 4 * cores;
  if (requested <= cap) return requested;
  std::cerr << "molremesh: warning: --threads " << requested << " is more than 4 per core (" << cores
            << " cores); using " << cap << '\n';
  return cap;
}

/// Loads and validates a triangle mesh, or throws InputError with the reason.
void LoadValidMesh(MeshD& mesh, const std::string& path) {
  std::string error;
  if (!molremesh::LoadMesh(mesh, path, error)) throw InputError(error);
  const molremesh::InputCheck check = molremesh::CheckTriangleMeshInput(mesh);
  if (!check.ok) throw InputError("'" + path + "': " + check.message);
}

int RunReport(const std::string& input, bool json, bool skipSelfIntersections, int threads,
              double memoryLimitMB) {
  MeshD mesh;
  LoadValidMesh(mesh, input);
  molremesh::MeshQuality<MeshD>::Params params;
  params.computeSelfIntersections = !skipSelfIntersections;
  params.threads = threads;
  params.memoryLimitMB = memoryLimitMB;
  const molremesh::QualityReport report = molremesh::MeshQuality<MeshD>::Compute(mesh, params);
  if (!report.selfIntersectionsSkipped.empty())
    std::cerr << "molremesh: warning: " << report.selfIntersectionsSkipped << ": not counted"
              << (report.selfIntersectionsSkippedForMemory
                      ? " (--memory-limit MB sets the limit, -1 turns the check off)\n"
                      : "\n");
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
  CheckMeshOutput(output);
  MeshD mesh;
  LoadValidMesh(mesh, input);
  molremesh::BadElementColoring<MeshD>::Params params;
  params.smallAngle = smallAngle;
  params.obtuseAngle = obtuseAngle;
  // The plugin's colors, so a file colored here looks the same in MeshLab as one colored there.
  params.palette = molremesh::BadElementColoring<MeshD>::ColorBlindSafePalette();
  const molremesh::BadElementCounts counts = molremesh::BadElementColoring<MeshD>::Do(mesh, params);
  std::string error;
  if (!molremesh::SaveMesh(mesh, output, error, /*withQualityAndColor=*/true)) throw InputError(error);
  std::cout << "irregular vertices: " << counts.irregularVertices
            << " (valence below 5, bluish green: " << counts.lowValenceVertices
            << "; above 7, yellow: " << counts.highValenceVertices << ")\n"
            << "obtuse faces (vermillion, or reddish purple): " << counts.obtuseFaces << '\n'
            << "small-angle faces (blue, or reddish purple): " << counts.smallAngleFaces << '\n'
            << "obtuse and small-angle faces (reddish purple): " << counts.obtuseAndSmallFaces << '\n';
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
  double minComponentVolume = molremesh::CleanRawMesh<MeshD>::Params().minComponentVolume;
  int minComponentFaces = molremesh::CleanRawMesh<MeshD>::Params().minComponentFaces;
  bool noVolumetricFallback = !molremesh::CleanRawMesh<MeshD>::Params().volumetricFallback;
  bool volumetricRebuild = molremesh::CleanRawMesh<MeshD>::Params().volumetricRebuild;
  bool noRebuildRetry = !molremesh::RemeshPipeline<MeshD>::Params().rebuildWhenAnglesMiss;
  std::string nestedComponents = "auto";
  double memoryLimitMB = 0; // 0: the memory available when the run starts; < 0: no check
  std::string jsonPath;
  bool quiet = false;   ///< nothing but warnings and errors
  bool verbose = false; ///< progress, the per-stage table and the stage summaries
  bool checkEachStage = false;
  std::string regionPath; ///< --region: remesh only these faces (a text file of 0-based face indices)
};

/// The face indices of a --region file: whitespace-separated 0-based integers, each at most once.
/// A file that cannot be read or holds anything else is a command-line mistake.
std::vector<std::size_t> ReadRegionFile(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw UsageError("--region: cannot read '" + path + "'");
  std::vector<std::size_t> faces;
  std::string word;
  while (file >> word) {
    const bool digits = !word.empty() &&
                        std::all_of(word.begin(), word.end(), [](char ch) { return ch >= '0' && ch <= '9'; });
    errno = 0;
    const unsigned long long value = digits ? std::strtoull(word.c_str(), nullptr, 10) : 0;
    if (!digits || errno == ERANGE)
      throw UsageError("--region: '" + word + "' in '" + path +
                       "' is not a face index (0-based whole number)");
    faces.push_back(std::size_t(value));
  }
  if (faces.empty()) throw UsageError("--region: '" + path + "' lists no face");
  std::vector<std::size_t> sorted = faces;
  std::sort(sorted.begin(), sorted.end());
  if (const auto dup = std::adjacent_find(sorted.begin(), sorted.end()); dup != sorted.end())
    throw UsageError("--region: face " + std::to_string(*dup) + " is listed twice in '" + path + "'");
  return faces;
}

/// remesh --region: the stages run on the listed faces only (RegionRemeshing); everything else is
/// written back unchanged, the new faces last.
int RunRegionRemesh(MeshD& mesh, const std::string& input, const std::string& output,
                    const molremesh::RemeshPipeline<MeshD>::Params& pipeline,
                    const std::vector<std::size_t>& faces, bool quiet, bool verbose) {
  molremesh::RegionRemeshing<MeshD>::Params params;
  params.pipeline = pipeline;
  params.faceMask.assign(mesh.face.size(), 0);
  for (const std::size_t f : faces) {
    if (f >= mesh.face.size())
      throw InputError("--region: face " + std::to_string(f) + " is out of range (" + input + " has " +
                       std::to_string(mesh.face.size()) + " faces)");
    params.faceMask[f] = 1;
  }
  const molremesh::RegionRemeshing<MeshD>::Result result =
      molremesh::RegionRemeshing<MeshD>::Do(mesh, params);
  if (!result.ok) throw InputError(result.message);
  if (verbose)
    for (const std::string& line : result.stageSummaries) std::cerr << "molremesh: region " << line << "\n";
  std::string error;
  if (!molremesh::SaveMesh(mesh, output, error)) throw InputError(error);
  if (!quiet)
    std::cerr << "molremesh: " << input << " -> " << output << ": region " << result.regionFacesIn << " -> "
              << result.regionFacesOut << " faces, " << result.borderVertices << " border vertices kept, "
              << std::fixed << std::setprecision(1) << result.seconds << " s\n";
  return 0;
}

int RunRemesh(const std::string& input, const std::string& output, const RemeshOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  using Pipeline = molremesh::RemeshPipeline<MeshD>;
  Pipeline::Params params;
  if (!options.stages.empty()) {
    std::string error;
    if (!molremesh::ParseStageList(options.stages, params.stages, error))
      throw UsageError("--stages: " + error);
  }
  params.targetEdgeLength = options.targetLength;
  params.seed = options.seed;
  params.threads = options.threads;
  params.intersectionsEachStage = options.checkEachStage;
  // The default and --quiet outputs show the input and the output only: no per-stage reports.
  params.measureIntermediateStages = options.verbose || !options.jsonPath.empty() || options.checkEachStage;
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
  params.clean.minComponentVolume = options.minComponentVolume;
  params.clean.minComponentFaces = options.minComponentFaces;
  params.clean.volumetricFallback = !options.noVolumetricFallback;
  params.clean.volumetricRebuild = options.volumetricRebuild;
  params.rebuildWhenAnglesMiss = !options.noRebuildRetry;
  params.clean.nestedComponents = options.nestedComponents == "union"    ? molremesh::NestedComponents::Union
                                  : options.nestedComponents == "parity" ? molremesh::NestedComponents::Parity
                                                                         : molremesh::NestedComponents::Auto;
  params.memoryLimitMB = options.memoryLimitMB;
  CheckMeshOutput(output);
  if (!options.jsonPath.empty()) CheckWritable(options.jsonPath, "the JSON file");
  std::vector<std::size_t> regionFaces;
  if (!options.regionPath.empty()) {
    if (!options.jsonPath.empty()) throw UsageError("--region: --json is not available for a region run");
    regionFaces = ReadRegionFile(options.regionPath);
  }

  MeshD mesh;
  LoadValidMesh(mesh, input);
  if (!regionFaces.empty())
    return RunRegionRemesh(mesh, input, output, params, regionFaces, options.quiet, options.verbose);
  OutputRequest request;
  request.start = start;
  request.input = input;
  request.output = output;
  request.jsonPath = options.jsonPath;
  request.quiet = options.quiet;
  request.verbose = options.verbose;
  request.seed = options.seed;
  const bool progress = request.Progress();
  auto log = [progress](const std::string& line) {
    if (progress) std::cerr << "molremesh: " << line << std::endl;
  };
  const molremesh::PipelineResult result = Pipeline::Do(mesh, params, log);
  return SaveRemeshed(mesh, request, result);
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
  double reportMemoryLimitMB = 0;                   ///< report
  double smallAngle = 30.0, obtuseAngle = 90.0;     ///< color
  std::string seed = "1";                           ///< remesh, checked by Seed()
  RemeshOptions remesh;
};

const char* const kMemoryLimitHelp = "many MB; 0 = the memory available at the start, -1 = no check";

CLI::App* AddReportCommand(CLI::App& app, CommandLine& c) {
  CLI::App* report = app.add_subcommand("report", "Print the quality figures of a mesh (no change to it)");
  report->add_option("input", c.input, "Mesh file (.ply, .off, .obj, .stl, .wrl)")->required();
  report->add_flag("--json", c.json, "Print JSON instead of a table");
  report->add_flag("--no-self-intersections", c.skipSelfIntersections,
                   "Skip the self-intersection count (the slowest figure)");
  report
      ->add_option("--threads", c.reportThreads,
                   "Worker threads, 0 = all cores (figures do not depend on it)")
      ->default_val(0)
      ->check(WholeNumber(0));
  report
      ->add_option(
          "--memory-limit", c.reportMemoryLimitMB,
          std::string("Skip (with a warning) the self-intersection count when it could need more than "
                      "this ") +
              kMemoryLimitHelp)
      ->default_val(0)
      ->check(Number(-1, 1e12));
  return report;
}

CLI::App* AddColorCommand(CLI::App& app, CommandLine& c) {
  CLI::App* color = app.add_subcommand("color", "Write a copy with irregular vertices and obtuse/small-angle "
                                                "faces colored, quality = valence / min angle");
  color->add_option("input", c.input, "Mesh file")->required();
  color->add_option("output", c.output, "Output mesh file (.ply keeps colors and quality)")->required();
  color->add_option("--small-angle", c.smallAngle, "Faces with an angle below it are blue (degrees)")
      ->default_val(30.0)
      ->check(Number(0, 60));
  color
      ->add_option("--obtuse-angle", c.obtuseAngle,
                   "Faces with an angle at or above it are vermillion (degrees)")
      ->default_val(90.0)
      ->check(Number(60, 180));
  return color;
}

/// The stage options of remesh: angle bounds and iteration counts.
void AddStageOptions(CLI::App* remesh, CommandLine& c) {
  remesh->add_option("--cvt-iterations", c.remesh.cvtIterations, "Lloyd iterations of the CVT stage")
      ->default_val(42)
      ->check(WholeNumber(0, 10000));
  remesh
      ->add_option("--surface-lift", c.remesh.surfaceLift,
                   "Share of the way from the input's flat triangles to its smooth (Phong) surface that "
                   "projected vertices go (at most 0.05 mean edge lengths, none at creases); 0 = on the "
                   "flat triangles")
      ->capture_default_str()
      ->check(Number(0, 1));
  remesh->add_option("--patches", c.remesh.patches, "Patches of the segmentation, 0 = automatic")
      ->default_val(0)
      ->check(WholeNumber(0));
  remesh->add_option("--min-angle", c.remesh.minAngle, "Min angle (deg): no edit creates one below it")
      ->default_val(30.0)
      ->check(Number(0, 59, /*lowOpen=*/true));
  remesh
      ->add_option("--max-angle", c.remesh.maxAngle,
                   "Max angle (deg) of valence optimization and small-angle elimination")
      ->default_val(120.0)
      ->check(Number(61, 180));
  remesh
      ->add_option("--obtuse-thresholds", c.remesh.obtuseThresholds,
                   "Max-angle thresholds (deg) of obtuse reduction, in order")
      ->default_str("110 100 90")
      ->check(Number(60, 180, false, /*highOpen=*/true));
  remesh
      ->add_option("--translation-iterations", c.remesh.translationIterations,
                   "Vertex translation rounds per obtuse threshold")
      ->default_val(20)
      ->check(WholeNumber(0, 10000));
  remesh
      ->add_option("--area-factor", c.remesh.areaFactor,
                   "Valence optimization: a hole grows while its area is below this x the mean face area")
      ->default_val(9.0)
      ->check(Number(0));
}

/// The clean stage's options of remesh.
void AddCleanOptions(CLI::App* remesh, CommandLine& c) {
  remesh
      ->add_option("--merge-tolerance", c.remesh.mergeTolerance,
                   "Clean: merge vertices closer than this x the mean edge length")
      ->default_val(c.remesh.mergeTolerance)
      ->check(Number(0));
  remesh
      ->add_option("--max-hole-edges", c.remesh.maxHoleEdges,
                   "Clean: close holes with at most this many boundary edges")
      ->default_val(c.remesh.maxHoleEdges)
      ->check(WholeNumber(0));
  remesh
      ->add_option(
          "--min-component-percent", c.remesh.minComponentPercent,
          "Clean: remove components with fewer than this % of the faces (never the largest; 0 keeps all)")
      ->default_val(c.remesh.minComponentPercent)
      ->check(Number(0, 100));
  remesh
      ->add_option("--min-component-volume", c.remesh.minComponentVolume,
                   "Clean: remove components enclosing less than this volume (cubic units of the mesh, "
                   "Å³ for molecular surfaces; never the largest; 0 keeps outer surfaces and cavities alike)")
      ->default_val(c.remesh.minComponentVolume)
      ->check(Number(0));
  remesh
      ->add_option("--min-component-faces", c.remesh.minComponentFaces,
                   "Clean: remove components with fewer faces than this (never the largest; 0 keeps all)")
      ->default_val(c.remesh.minComponentFaces)
      ->check(WholeNumber(0));
  remesh->add_flag("--no-volumetric-fallback", c.remesh.noVolumetricFallback,
                   "Clean: do not rebuild the surface from a volume when the local repairs leave defects "
                   "(the output may then be invalid, exit status 3)");
  remesh->add_flag("--volumetric-rebuild", c.remesh.volumetricRebuild,
                   "Clean: rebuild the surface from a volume (voxel half the mean edge) even without "
                   "defects; removes the parts thinner than about the mean edge (fins, tubes, necks, "
                   "pinched voids) that no remesh keeps within the angle bounds, and seals crevices as "
                   "narrow");
  remesh->add_flag("--no-rebuild-retry", c.remesh.noRebuildRetry,
                   "Keep the remesh even when an angle is outside [min angle, 90] (by default the input is "
                   "then rebuilt as by --volumetric-rebuild and remeshed again at the same edge length, "
                   "and that output is kept when it is valid and its angles are nearer the bounds; a note "
                   "gives both runs' figures), and do not rebuild first an input with narrow crevices (by "
                   "default when over 0.02 % of the cleaned area faces the surface within half the edge "
                   "length)");
  remesh
      ->add_option(
          "--nested-components", c.remesh.nestedComponents,
          "Clean: how a closed component inside another is read: union (one oriented as the region "
          "around it lies inside the body and is removed), parity (every odd-depth one is a cavity), "
          "auto (union for a triangle soup whose sheets overlap, as PyMOL exports, else parity)")
      ->default_val(c.remesh.nestedComponents)
      ->check(CLI::IsMember({"auto", "union", "parity"}));
}

CLI::App* AddRemeshCommand(CLI::App& app, CommandLine& c) {
  std::string stageHelp = "Comma-separated stages to run, in pipeline order (default: all):";
  for (const auto& info : molremesh::PipelineStages()) stageHelp += std::string(" ") + info.name;
  CLI::App* remesh = app.add_subcommand("remesh", "Remesh a molecular surface (all stages, or --stages)");
  remesh->add_option("input", c.input, "Mesh file (.ply, .off, .obj, .stl, .wrl)")->required();
  remesh->add_option("output", c.output, "Output mesh file")->required();
  remesh->add_option("--stages", c.remesh.stages, stageHelp);
  remesh
      ->add_option("--target-length", c.remesh.targetLength,
                   "Target edge length L: the edge length of flat parts, curved parts get down to 0.6 L "
                   "(default: the cleaned input's mean edge length; a remesh at L with this resolution "
                   "already is kept as it is)")
      ->check(Number(0));
  remesh->add_option("--seed", c.seed, "Seed of every random choice")->default_str("1")->check(Seed());
  remesh
      ->add_option("--threads", c.remesh.threads,
                   "Worker threads, 0 = all cores (output does not depend on it)")
      ->default_val(0)
      ->check(WholeNumber(0));
  AddStageOptions(remesh, c);
  AddCleanOptions(remesh, c);
  remesh
      ->add_option("--memory-limit", c.remesh.memoryLimitMB,
                   std::string("Refuse (exit status 2, nothing written) a run whose estimated peak memory "
                               "exceeds this ") +
                       kMemoryLimitHelp)
      ->default_val(0)
      ->check(Number(-1, 1e12));
  remesh->add_option("--json", c.remesh.jsonPath, "Also write the per-stage figures as JSON to this file");
  CLI::Option* quiet =
      remesh->add_flag("--quiet", c.remesh.quiet, "Print nothing but warnings and errors (stderr)");
  remesh
      ->add_flag("--verbose", c.remesh.verbose,
                 "Print progress on stderr and the per-stage table and stage summaries on stdout")
      ->excludes(quiet);
  remesh->add_option("--region", c.remesh.regionPath,
                     "Remesh only these faces: a text file of 0-based face indices (whitespace-separated); "
                     "the rest and the region's border stay unchanged, the new faces come last");
  remesh->add_flag("--check-each-stage", c.remesh.checkEachStage,
                   "Count self-intersections after every stage (default: input and output only)");
  return remesh;
}

/// One line for a parse error of CLI11 (which prints two, and ranges in full double digits).
std::string ParseErrorLine(const CLI::ParseError& e, const std::string& command) {
  std::string message = e.what();
  message = message.substr(0, message.find('\n'));
  if (message.rfind("A subcommand", 0) == 0)
    return std::string("a command is required (use ") + kCommands + ")";
  const std::string help = command.empty() ? "molremesh --help" : "molremesh " + command + " --help";
  return message + " (" + help + " lists the options)";
}

bool IsCommand(const std::string& word) {
  return word == "report" || word == "color" || word == "remesh" || word == "surface";
}

} // namespace

int main(int argc, char** argv) {
  KeepFreedMemoryInTheHeap();
  CLI::App app{"molremesh: molecular surface remeshing (valence optimization and angle improvement)"};
  app.require_subcommand(1);
  app.footer(
      "Exit status: 0 done (warnings name any target a valid output misses), 1 command-line mistake "
      "(nothing read or written), 2 unusable input, a failed stage or a run refused for memory (nothing "
      "written), 3 output written but not a valid surface mesh (the warnings say why).");

  CommandLine c;
  CLI::App* report = AddReportCommand(app, c);
  CLI::App* color = AddColorCommand(app, c);
  CLI::App* remesh = AddRemeshCommand(app, c);
  molremesh::cli::SurfaceCommand surface(app);

  const std::string first = argc > 1 ? argv[1] : "";
  if (!first.empty() && first[0] != '-' && !IsCommand(first)) {
    std::cerr << "molremesh: error: unknown command '" << first << "' (use " << kCommands << ")\n";
    return kExitUsage;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e); // --help
    std::cerr << "molremesh: error: " << ParseErrorLine(e, IsCommand(first) ? first : "") << '\n';
    return kExitUsage;
  }

  std::string memoryHint; // what --memory-limit bounds, for the commands that have it
  try {
    if (*report) {
      memoryHint = "; --memory-limit bounds the self-intersection count only";
      return RunReport(c.input, c.json, c.skipSelfIntersections, ClampThreads(c.reportThreads),
                       c.reportMemoryLimitMB);
    }
    if (*color) return RunColor(c.input, c.output, c.smallAngle, c.obtuseAngle);
    if (*remesh) {
      memoryHint = "; --memory-limit sets the limit the run is checked against before it starts";
      ParseSeed(c.seed, c.remesh.seed); // checked by the parser
      c.remesh.threads = ClampThreads(c.remesh.threads);
      return RunRemesh(c.input, c.output, c.remesh);
    }
    if (surface.Chosen()) return surface.Run();
  } catch (const UsageError& e) {
    std::cerr << "molremesh: error: " << e.what() << '\n';
    return kExitUsage;
  } catch (const InputError& e) {
    std::cerr << "molremesh: error: " << e.what() << '\n';
    return kExitBadInput;
  } catch (const std::bad_alloc&) {
    std::cerr << "molremesh: error: out of memory (nothing written" << memoryHint << ")\n";
    return kExitBadInput;
  } catch (const std::system_error& e) {
    // EAGAIN: a thread the pipeline starts on its own (the background quality report) was refused.
    if (e.code() == std::errc::resource_unavailable_try_again)
      std::cerr << "molremesh: error: the system refused to start a thread (" << e.what()
                << "; nothing written): fewer --threads or more memory may help\n";
    else
      std::cerr << "molremesh: error: " << e.what() << '\n';
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::cerr << "molremesh: error: " << e.what() << '\n';
    return kExitBadInput;
  }
  return kExitUsage;
}

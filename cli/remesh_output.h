// What `remesh` and `surface` do once a mesh is ready: write it, report it at the chosen output
// level (one summary line on stderr by default, the per-stage tables with --verbose, nothing but
// warnings with --quiet), write the --json figures, say what the output misses, and return the
// exit status (3 for an output written but not valid). Also the error types and exit statuses of
// the CLI, and the output checks made before any work.
#pragma once

#include <nlohmann/json.hpp>

#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/io/mesh_io.h>
#include <vcg_ext/pipeline/remesh_pipeline.h>
#include <vcg_ext/quality/mesh_quality.h>
#include <vcg_ext/quality/output_verdict.h>
#include <vcg_ext/quality/quality_report_format.h>
#include <vcg_ext/quality/stage_summary.h>

#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include <fcntl.h>
#include <unistd.h>

#include "report_json.h"

namespace molremesh::cli {

constexpr int kExitUsage = 1;         ///< a command-line mistake: nothing was read or written
constexpr int kExitBadInput = 2;      ///< unusable input, a failed stage, a run refused for memory
constexpr int kExitInvalidOutput = 3; ///< the output was written, but it is not a valid surface mesh

/// Unusable input, a failed stage, a refused run: exit status 2.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
/// A command-line mistake found after parsing (an unwritable output path, a bad stage list).
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Throws UsageError unless `path` can be written, before any work and without destroying
/// anything: an existing file is opened for appending (not truncated), a new one is created and
/// removed again.
inline void CheckWritable(const std::string& path, const std::string& what) {
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  const std::string cannot = "cannot write " + what + " '" + path + "': ";
  if (std::filesystem::is_directory(status)) throw UsageError(cannot + "it is a directory");
  const bool exists = std::filesystem::exists(status);
  const int fd = exists ? ::open(path.c_str(), O_WRONLY | O_APPEND | O_NONBLOCK)
                        : ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0666);
  if (fd < 0) throw UsageError(cannot + std::strerror(errno));
  ::close(fd);
  if (!exists) ::unlink(path.c_str());
}

/// The output's format must be known and the file writable before hours of work are spent.
inline void CheckMeshOutput(const std::string& path) {
  CheckWritable(path, "the output");
  if (FormatFromPath(path) == MeshFormat::Unknown)
    throw UsageError("cannot write '" + path + "': unknown format (use .ply, .off, .obj or .stl)");
}

/// Where a mesh goes and how much is said about it.
struct OutputRequest {
  std::string input, output; ///< as named on the command line
  std::string jsonPath;      ///< "" = no JSON file
  bool quiet = false;        ///< nothing but warnings and errors
  bool verbose = false;      ///< progress, the per-stage table and the stage summaries
  std::uint64_t seed = 1;
  std::chrono::steady_clock::time_point start = std::chrono::steady_clock::now();

  /// Progress lines on stderr: with --verbose, or by default on a terminal.
  bool Progress() const { return verbose || (!quiet && ::isatty(STDERR_FILENO)); }
  double Seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
};

inline std::string SelfIntersectionsText(const QualityReport& r) {
  return r.selfIntersectionsComputed ? std::to_string(r.selfIntersectingPairs) : std::string("n/a");
}

inline const QualityReport& OutputReport(const PipelineResult& result) {
  return result.stages.empty() ? result.input : result.stages.back().after;
}

/// The default output of a run: one line, input and output figures side by side (`what` names
/// the input's kind, before the figures, when not empty).
inline std::string SummaryLine(const OutputRequest& request, const PipelineResult& result,
                               const std::string& what = "") {
  const QualityReport& in = result.input;
  const QualityReport& out = OutputReport(result);
  std::ostringstream s;
  s << std::fixed << std::setprecision(1) << "molremesh: " << request.input << " -> " << request.output
    << ": " << what << in.faces << " -> " << out.faces << " faces, θmin " << in.angleMin << "° -> "
    << out.angleMin << "°, θmax " << in.angleMax << "° -> " << out.angleMax << "°, V567 "
    << std::setprecision(2) << in.v567Percent << " % -> " << out.v567Percent << " %, SI "
    << SelfIntersectionsText(in) << " -> " << SelfIntersectionsText(out) << ", " << std::setprecision(1)
    << request.Seconds() << " s";
  return s.str();
}

/// --verbose: the per-stage table, the stage times and every stage's summary, on stdout.
inline void PrintStageTables(const OutputRequest& request, const PipelineResult& result) {
  std::vector<NamedReport> columns{{"input", result.input}};
  for (const auto& stage : result.stages) columns.emplace_back(stage.name, stage.after);
  std::cout << "Remeshed " << request.input << " -> " << request.output << " (target edge length "
            << result.targetEdgeLength << ", seed " << request.seed << ")\n"
            << FormatQualityTable(columns);
  std::cout << StageTimesLine(result) << '\n';
  for (const auto& stage : result.stages)
    if (!stage.summary.empty()) {
      std::cout << "-- " << stage.name << ":\n" << stage.summary;
      if (stage.summary.back() != '\n') std::cout << '\n';
    }
}

inline nlohmann::json VerdictJson(const OutputVerdict& verdict) {
  return {{"valid", verdict.Valid()},
          {"all_targets_met", verdict.AllMet()},
          {"invalid", verdict.invalid},
          {"short_of", verdict.shortOf}};
}

/// --json: the per-stage figures, `extra`'s keys added (a command's own figures).
inline nlohmann::json StageJson(const OutputRequest& request, const PipelineResult& result,
                                const nlohmann::json& extra) {
  nlohmann::json j;
  j["input_file"] = request.input;
  j["output_file"] = request.output;
  j["target_edge_length"] = result.targetEdgeLength;
  j["seed"] = request.seed;
  j["seconds"] = result.seconds;
  j["input"] = ToJson(result.input);
  for (const auto& stage : result.stages)
    j["stages"].push_back({{"name", stage.name},
                           {"seconds", stage.seconds},
                           {"summary", stage.summary},
                           {"after", ToJson(stage.after)}});
  j["output"] = ToJson(OutputReport(result));
  j["verdict"] = VerdictJson(result.verdict);
  j["rebuild_retry"] = {{"tried", result.rebuildRetry.tried},
                        {"kept", result.rebuildRetry.kept},
                        {"first", result.rebuildRetry.first},
                        {"message", result.rebuildRetry.message}};
  for (const auto& [key, value] : extra.items()) j[key] = value;
  return j;
}

/// A JSON file that cannot be written is an error (the mesh is written by then).
inline void WriteJsonFile(const nlohmann::json& j, const std::string& path, const std::string& output) {
  std::ofstream file(path);
  file << j.dump(2) << '\n';
  file.close();
  if (!file) throw InputError("cannot write the JSON file '" + path + "' (" + output + " is written)");
}

/// Prints the verdict's warnings (at every level) and returns the exit status it gives.
inline int VerdictStatus(const OutputVerdict& verdict, const std::string& output) {
  std::cerr << verdict.Lines("molremesh: warning: " + output + " ");
  if (verdict.Valid()) return 0;
  std::cerr << "molremesh: warning: " << output
            << " was written but is not a valid surface mesh (exit status " << kExitInvalidOutput << ")\n";
  return kExitInvalidOutput;
}

/// After a pipeline run: refusal and failure as InputError, else the mesh saved and reported.
inline int SaveRemeshed(MeshD& mesh, const OutputRequest& request, const PipelineResult& result,
                        const nlohmann::json& extraJson = nlohmann::json::object(),
                        const std::string& summaryWhat = "") {
  if (result.refusedForMemory)
    throw InputError(result.message + "; --memory-limit MB sets the limit, -1 turns the check off");
  if (!result.ok) throw InputError(result.message);
  std::string error;
  if (!SaveMesh(mesh, request.output, error)) throw InputError(error);
  if (request.verbose) PrintStageTables(request, result);
  if (!request.jsonPath.empty())
    WriteJsonFile(StageJson(request, result, extraJson), request.jsonPath, request.output);
  if (!request.quiet) std::cerr << SummaryLine(request, result, summaryWhat) << '\n';
  // At every level, like the verdict: a kept retry changes the area by a few percent.
  if (result.rebuildRetry.tried)
    std::cerr << "molremesh: note: " << request.output << ": " << result.rebuildRetry.message << '\n';
  return VerdictStatus(result.verdict, request.output);
}

} // namespace molremesh::cli

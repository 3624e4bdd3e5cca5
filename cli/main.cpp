// molremesh: command-line front end for batch jobs. Parse, call vcg_ext, report.
//
// Every failure is one line on stderr starting with "molremesh: error:" and a non-zero exit
// status (2 for unusable input, 1 for command-line mistakes); never a crash.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <iostream>
#include <string>

#include <vcg_ext/bad_element_coloring.h>
#include <vcg_ext/input_check.h>
#include <vcg_ext/mesh_io.h>
#include <vcg_ext/mesh_quality.h>
#include <vcg_ext/mesh_types.h>
#include <vcg_ext/quality_report_format.h>

#include "report_json.h"

namespace {

using molremesh::MeshD;

constexpr int kExitBadInput = 2;

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

int RunReport(const std::string& input, bool json, bool skipSelfIntersections) {
  MeshD mesh;
  LoadValidMesh(mesh, input);
  molremesh::MeshQuality<MeshD>::Params params;
  params.computeSelfIntersections = !skipSelfIntersections;
  const molremesh::QualityReport report = molremesh::MeshQuality<MeshD>::Compute(mesh, params);
  if (json) {
    nlohmann::json out = molremesh::ToJson(report);
    out["file"] = input;
    std::cout << out.dump(2) << '\n';
  } else {
    std::cout << "Quality report of " << input << "\n"
              << molremesh::FormatQualityTable(report, "value")
              << "valence histogram (interior vertices): " << molremesh::FormatValenceHistogram(report) << '\n';
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

} // namespace

int main(int argc, char** argv) {
  CLI::App app{"molremesh: molecular surface remeshing (valence optimization and angle improvement)"};
  app.require_subcommand(1);

  std::string input, output;
  bool json = false, skipSelfIntersections = false;
  auto* report = app.add_subcommand("report", "Print the quality figures of a mesh (no change to it)");
  report->add_option("input", input, "Mesh file (.ply, .off, .obj, .stl)")->required();
  report->add_flag("--json", json, "Print JSON instead of a table");
  report->add_flag("--no-self-intersections", skipSelfIntersections,
                   "Skip the self-intersection count (the slowest figure)");

  double smallAngle = 30.0, obtuseAngle = 90.0;
  auto* color = app.add_subcommand(
      "color", "Write a copy with irregular vertices and obtuse/small-angle faces colored, quality = valence / min angle");
  color->add_option("input", input, "Mesh file")->required();
  color->add_option("output", output, "Output mesh file (.ply keeps colors and quality)")->required();
  color->add_option("--small-angle", smallAngle, "Faces with an angle below it are blue (degrees)")
      ->default_val(30.0)
      ->check(CLI::Range(0.0, 60.0));
  color->add_option("--obtuse-angle", obtuseAngle, "Faces with an angle at or above it are red (degrees)")
      ->default_val(90.0)
      ->check(CLI::Range(60.0, 180.0));

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }

  try {
    if (*report) return RunReport(input, json, skipSelfIntersections);
    if (*color) return RunColor(input, output, smallAngle, obtuseAngle);
  } catch (const InputError& e) {
    std::cerr << "molremesh: error: " << e.what() << '\n';
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::cerr << "molremesh: error: " << e.what() << '\n';
    return kExitBadInput;
  }
  return 1;
}

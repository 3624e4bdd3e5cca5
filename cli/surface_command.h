// `molremesh surface`: a structure file (PQR, PDB, mmCIF, .gz) to a molecular surface mesh, remeshed by
// the full pipeline into a solver-ready mesh in one command (--no-remesh: the raw level-set
// surface). Parse, call vcg_ext, report as `remesh` does (cli/remesh_output.h): the same output
// levels, exit statuses and JSON, with the structure's atom counts and the surface's figures added.
#pragma once

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <tbb/global_control.h>

#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/pipeline/remesh_pipeline.h>
#include <vcg_ext/quality/mesh_quality.h>
#include <vcg_ext/quality/output_verdict.h>
#include <vcg_ext/quality/quality_report_format.h>
#include <vcg_ext/structure/sasa_reference.h>
#include <vcg_ext/structure/structure_file.h>
#include <vcg_ext/volume/molecular_surface.h>

#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>

#include "remesh_output.h"

namespace molremesh::cli {

/// The subcommand and its options: construct it on the app before parsing, Run it when Chosen.
class SurfaceCommand {
public:
  explicit SurfaceCommand(CLI::App& app) {
    app_ = app.add_subcommand("surface",
                              "Build the molecular surface of a structure file (PQR, PDB, mmCIF, .gz) "
                              "and remesh it (--no-remesh: the raw surface)");
    app_->add_option(
            "input", input_,
            "Structure file: .pqr (radii from the file), .pdb/.ent or .cif/.mmcif (ProtOr radii), .gz")
        ->required();
    app_->add_option("output", output_, "Output mesh file (.ply, .off, .obj, .stl)")->required();
    const std::map<std::string, MolecularSurfaceKind> kinds{{"ses", MolecularSurfaceKind::Ses},
                                                            {"sas", MolecularSurfaceKind::Sas},
                                                            {"vdw", MolecularSurfaceKind::VanDerWaals},
                                                            {"gaussian", MolecularSurfaceKind::Gaussian}};
    app_->add_option("--type", surface_.kind, "Surface: ses (solvent-excluded), sas, vdw or gaussian")
        ->transform(CLI::CheckedTransformer(kinds, CLI::ignore_case))
        ->default_str("ses");
    app_->add_option("--probe", surface_.probeRadius, "Probe radius (Å) of ses and sas")
        ->capture_default_str()
        ->check(CLI::Range(0.0, 10.0));
    app_->add_option("--min-feature", minFeature_,
                     "ses: solid features thinner than this radius (Å), necks and cusps below the grid's "
                     "resolution, are opened away (default: half the grid spacing; 0 keeps them)")
        ->check(CLI::Range(0.0, 5.0));
    app_->add_option("--grid", grid_,
                     "Grid spacing (Å): voxel edge of the level set (default 0.4 × the target length, 0.4 Å)")
        ->check(CLI::Range(0.05, 5.0));
    app_->add_option("--gaussian-decay", surface_.gaussianDecay, "Decay d of the gaussian surface")
        ->capture_default_str()
        ->check(CLI::Range(0.01, 100.0));
    app_->add_option("--gaussian-level", surface_.gaussianLevel, "Isolevel of the gaussian surface")
        ->capture_default_str()
        ->check(CLI::Range(0.01, 100.0));
    app_->add_flag("--outer-only", outerOnly_, "Drop the cavities (inner closed components); default: keep");
    app_->add_flag("--keep-waters", read_.keepWaters, "Keep water molecules (default: skipped)");
    app_->add_flag("--keep-hydrogens", read_.keepHydrogens, "Keep hydrogen atoms (default: skipped)");
    app_->add_flag("--no-hetatm", noHetatm_, "Skip HETATM records (ligands, ions; default: kept)");
    app_->add_flag("--all-altlocs", read_.allAltLocs, "Keep every alternate location (default: the first)");
    app_->add_option("--radii", radii_, "PDB radii: protor (default) or naccess (freesasa's classifiers)")
        ->check(CLI::IsMember({"protor", "naccess"}));
    app_->add_flag("--no-remesh", noRemesh_,
                   "Write the raw level-set surface (default: the full remeshing pipeline runs on it)");
    app_->add_option("--target-length", targetLength_,
                     "Target edge length (Å) of the remeshing (default 1.0); the grid spacing is 0.4 of it "
                     "unless --grid is given")
        ->check(CLI::PositiveNumber);
    app_->add_option("--seed", seed_, "Seed of every random choice of the remeshing")->default_val(1);
    app_->add_option("--threads", threads_, "Worker threads, 0 = all cores (output does not depend on it)")
        ->default_val(0)
        ->check(CLI::NonNegativeNumber);
    app_->add_option("--memory-limit", surface_.memoryLimitMB,
                     "Refuse (exit status 2, nothing written) a run estimated above this many MB; 0 = the "
                     "memory available at the start, -1 = no check")
        ->default_val(0)
        ->check(CLI::Range(-1.0, 1e12));
    app_->add_option("--json", request_.jsonPath,
                     "Also write the figures as JSON to this file (remesh's, with the structure's and the "
                     "surface's)");
    CLI::Option* quiet =
        app_->add_flag("--quiet", request_.quiet, "Print nothing but warnings and errors (stderr)");
    app_->add_flag("--verbose", request_.verbose,
                   "Print progress on stderr and the quality tables (per stage) on stdout")
        ->excludes(quiet);
  }

  bool Chosen() const { return app_->parsed(); }

  /// Runs the command; returns the exit status or throws InputError / UsageError.
  int Run() {
    request_.start = std::chrono::steady_clock::now();
    request_.input = input_;
    request_.output = output_;
    request_.seed = seed_;
    CheckMeshOutput(output_);
    if (!request_.jsonPath.empty()) CheckWritable(request_.jsonPath, "the JSON file");
    std::unique_ptr<tbb::global_control> threadLimit;
    if (threads_ > 0)
      threadLimit =
          std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads_);
    read_.keepHetatm = !noHetatm_;
    read_.radii =
        radii_ == "naccess" ? StructureReadOptions::Radii::Naccess : StructureReadOptions::Radii::ProtOr;
    const StructureReadResult atoms = ReadStructureFile(input_, read_);
    if (!atoms.ok) throw InputError(atoms.message);
    Log("read " + std::to_string(atoms.atoms.size()) + " atoms from " + input_ +
        " (skipped: " + std::to_string(atoms.skippedWaters) + " water, " +
        std::to_string(atoms.skippedHydrogens) + " hydrogen, " + std::to_string(atoms.skippedHetatm) +
        " HETATM, " + std::to_string(atoms.skippedAltLocs) + " alternate-location atoms)");

    surface_.keepCavities = !outerOnly_;
    surface_.gridSpacing = grid_ > 0 ? grid_ : 0.4 * targetLength_;
    surface_.minFeatureRadius = minFeature_ < 0 ? 0.5 * surface_.gridSpacing : minFeature_;
    surface_.threads = threads_;
    surface_.progress = [this](double, const std::string& step) { Log("surface: " + step); };
    MeshD mesh;
    const MolecularSurfaceResult surface = MolecularSurface<MeshD>::Build(atoms.atoms, mesh, surface_);
    if (!surface.ok) throw InputError("'" + input_ + "': " + surface.message);
    Log("surface " + std::string(ToString(surface_.kind)) + ": " + std::to_string(surface.faces) +
        " faces, " + std::to_string(surface.components) + " components (" + std::to_string(surface.cavities) +
        " cavities) in " + std::to_string(surface.seconds) + " s");

    const nlohmann::json figures = SurfaceJson(atoms, surface);
    const std::string what =
        std::to_string(atoms.atoms.size()) + " atoms, " + ToString(surface_.kind) + " surface ";
    return noRemesh_ ? SaveRaw(mesh, figures, what) : Remesh(mesh, figures, what);
  }

private:
  void Log(const std::string& line) const {
    if (request_.Progress()) std::cerr << "molremesh: " << line << std::endl;
  }

  /// The structure's and the surface's figures, added to the JSON of the run.
  nlohmann::json SurfaceJson(const StructureReadResult& atoms, const MolecularSurfaceResult& s) const {
    nlohmann::json j;
    j["structure"] = {{"atoms", atoms.atoms.size()},
                      {"skipped",
                       {{"waters", atoms.skippedWaters},
                        {"hydrogens", atoms.skippedHydrogens},
                        {"hetatm", atoms.skippedHetatm},
                        {"altlocs", atoms.skippedAltLocs}}}};
    j["surface"] = {{"type", ToString(surface_.kind)},
                    {"probe", surface_.probeRadius},
                    {"grid", surface_.gridSpacing},
                    {"min_feature", surface_.minFeatureRadius},
                    {"faces", s.faces},
                    {"components", s.components},
                    {"cavities", s.cavities},
                    {"removed_cavities", s.removedCavities},
                    {"area", s.area},
                    {"volume", s.volume},
                    {"estimated_mb", s.estimatedMB},
                    {"seconds", s.seconds}};
    if (surface_.kind == MolecularSurfaceKind::Sas) {
      SasaParams sasa;
      sasa.probeRadius = surface_.probeRadius;
      const double reference = FreesasaArea(atoms.atoms, sasa);
      j["surface"]["freesasa_sasa"] = reference;
      if (request_.verbose)
        std::cout << "SAS area " << s.area << " Å², freesasa (Lee-Richards) " << reference << " Å² ("
                  << 100.0 * (s.area - reference) / reference << " %)\n";
    }
    return j;
  }

  /// --no-remesh: the raw extraction, measured and written; status 3 unless it is a valid closed
  /// surface (closedness is the extraction's promise, so a boundary makes it invalid).
  int SaveRaw(MeshD& mesh, const nlohmann::json& figures, const std::string& what) const {
    MeshQuality<MeshD>::Params qp;
    qp.threads = threads_;
    const QualityReport q = MeshQuality<MeshD>::Compute(mesh, qp);
    OutputVerdict verdict = OutputVerdict::Of(q, OutputTargets{});
    verdict.invalid.insert(verdict.invalid.end(), verdict.shortOf.begin(), verdict.shortOf.end());
    verdict.shortOf.clear();
    std::string error;
    if (!SaveMesh(mesh, output_, error)) throw InputError(error);
    if (request_.verbose)
      std::cout << "Surface of " << input_ << " -> " << output_ << "\n" << FormatQualityTable(q, "value");
    if (!request_.jsonPath.empty()) {
      nlohmann::json j = {{"input_file", input_},
                          {"output_file", output_},
                          {"seconds", request_.Seconds()},
                          {"output", ToJson(q)},
                          {"verdict", VerdictJson(verdict)}};
      for (const auto& [key, value] : figures.items()) j[key] = value;
      WriteJsonFile(j, request_.jsonPath, output_);
    }
    if (!request_.quiet) {
      std::ostringstream s;
      s << std::fixed << std::setprecision(1) << "molremesh: " << input_ << " -> " << output_ << ": " << what
        << q.faces << " faces, θmin " << q.angleMin << "°, θmax " << q.angleMax << "°, V567 "
        << std::setprecision(2) << q.v567Percent << " %, SI " << SelfIntersectionsText(q) << ", "
        << std::setprecision(1) << request_.Seconds() << " s";
      std::cerr << s.str() << '\n';
    }
    return VerdictStatus(verdict, output_);
  }

  /// The full pipeline on the extraction, as `molremesh remesh` runs it with its defaults.
  int Remesh(MeshD& mesh, const nlohmann::json& figures, const std::string& what) const {
    using Pipeline = RemeshPipeline<MeshD>;
    Pipeline::Params params;
    params.targetEdgeLength = targetLength_;
    params.seed = seed_;
    params.threads = threads_;
    params.restoreOnFailure = false;
    params.measureIntermediateStages = request_.verbose || !request_.jsonPath.empty();
    params.memoryLimitMB = surface_.memoryLimitMB;
    const PipelineResult result = Pipeline::Do(mesh, params, [this](const std::string& line) { Log(line); });
    return SaveRemeshed(mesh, request_, result, figures, what);
  }

  CLI::App* app_ = nullptr;
  std::string input_, output_, radii_ = "protor";
  MolecularSurface<MeshD>::Params surface_;
  StructureReadOptions read_;
  OutputRequest request_;
  bool outerOnly_ = false, noHetatm_ = false, noRemesh_ = false;
  double targetLength_ = 1.0;
  double minFeature_ = -1; ///< < 0: half the grid spacing
  double grid_ = -1;       ///< < 0: 0.4 × the target length
  std::uint64_t seed_ = 1;
  int threads_ = 0;
};

} // namespace molremesh::cli

// `molremesh surface`: a structure file (PQR, PDB, .gz) to a molecular surface mesh, and with
// --remesh on to the remeshed, solver-ready mesh in one command. Parse, call vcg_ext, report.
//
// Bad input (an unreadable structure, an unwritable output, a refused run) throws
// std::runtime_error, which main reports as one "molremesh: error:" line with exit status 2; an
// output that was written but is not valid returns exit status 3, as `remesh` does.
#pragma once

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <tbb/global_control.h>

#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/io/mesh_io.h>
#include <vcg_ext/pipeline/remesh_pipeline.h>
#include <vcg_ext/quality/mesh_quality.h>
#include <vcg_ext/quality/quality_report_format.h>
#include <vcg_ext/structure/sasa_reference.h>
#include <vcg_ext/structure/structure_file.h>
#include <vcg_ext/volume/molecular_surface.h>

#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>

#include "report_json.h"

namespace molremesh {

/// The subcommand and its options: construct it on the app before parsing, Run it when Chosen.
class SurfaceCommand {
public:
  explicit SurfaceCommand(CLI::App& app) {
    app_ = app.add_subcommand("surface", "Build the molecular surface of a structure file (PQR, PDB, .gz) "
                                         "and, with --remesh, remesh it");
    app_->add_option("input", input_,
                     "Structure file: .pqr (radii from the file), .pdb/.ent (ProtOr radii), .gz")
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
    app_->add_option("--grid", surface_.gridSpacing, "Grid spacing (Å): voxel edge of the level set")
        ->capture_default_str()
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
    app_->add_flag("--remesh", remesh_, "Run the full remeshing pipeline on the extracted surface");
    app_->add_option(
            "--target-length", targetLength_,
            "Target edge length (Å) of --remesh (default 1.0; the grid spacing is 0.4 of it by default)")
        ->check(CLI::PositiveNumber);
    app_->add_option("--seed", seed_, "Seed of every random choice of --remesh")->default_val(1);
    app_->add_option("--threads", threads_, "Worker threads, 0 = all cores (output does not depend on it)")
        ->default_val(0)
        ->check(CLI::NonNegativeNumber);
    app_->add_option("--memory-limit", surface_.memoryLimitMB,
                     "Refuse (exit status 2, nothing written) a run estimated above this many MB; 0 = the "
                     "memory available at the start, -1 = no check")
        ->default_val(0)
        ->check(CLI::Range(-1.0, 1e12));
    app_->add_option("--json", jsonPath_, "Also write the figures as JSON to this file");
    app_->add_flag("--quiet", quiet_, "No progress lines on stderr");
  }

  bool Chosen() const { return app_->parsed(); }

  /// Runs the command; returns the exit status or throws std::runtime_error for bad input.
  int Run() {
    if (FormatFromPath(output_) == MeshFormat::Unknown)
      throw std::runtime_error("cannot write '" + output_ +
                               "': unknown format (use .ply, .off, .obj or .stl)");
    std::unique_ptr<tbb::global_control> threadLimit;
    if (threads_ > 0)
      threadLimit =
          std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads_);
    read_.keepHetatm = !noHetatm_;
    read_.radii =
        radii_ == "naccess" ? StructureReadOptions::Radii::Naccess : StructureReadOptions::Radii::ProtOr;
    const StructureReadResult atoms = ReadStructureFile(input_, read_);
    if (!atoms.ok) throw std::runtime_error(atoms.message);
    Log("read " + std::to_string(atoms.atoms.size()) + " atoms from " + input_ +
        " (skipped: " + std::to_string(atoms.skippedWaters) + " water, " +
        std::to_string(atoms.skippedHydrogens) + " hydrogen, " + std::to_string(atoms.skippedHetatm) +
        " HETATM, " + std::to_string(atoms.skippedAltLocs) + " alternate-location atoms)");

    surface_.keepCavities = !outerOnly_;
    surface_.threads = threads_;
    MeshD mesh;
    const MolecularSurfaceResult surface = MolecularSurface<MeshD>::Build(atoms.atoms, mesh, surface_);
    if (!surface.ok) throw std::runtime_error("'" + input_ + "': " + surface.message);
    Log("surface " + std::string(ToString(surface_.kind)) + ": " + std::to_string(surface.faces) +
        " faces, " + std::to_string(surface.components) + " components (" + std::to_string(surface.cavities) +
        " cavities) in " + std::to_string(surface.seconds) + " s");

    nlohmann::json j = SurfaceJson(atoms, surface);
    int status = 0;
    if (remesh_)
      status = RemeshAndSave(mesh, j);
    else
      status = CheckAndSave(mesh, j);
    if (!jsonPath_.empty()) std::ofstream(jsonPath_) << j.dump(2) << '\n';
    return status;
  }

private:
  void Log(const std::string& line) const {
    if (!quiet_) std::cerr << "molremesh: " << line << std::endl;
  }

  nlohmann::json SurfaceJson(const StructureReadResult& atoms, const MolecularSurfaceResult& s) const {
    nlohmann::json j;
    j["input_file"] = input_;
    j["output_file"] = output_;
    j["atoms"] = atoms.atoms.size();
    j["skipped"] = {{"waters", atoms.skippedWaters},
                    {"hydrogens", atoms.skippedHydrogens},
                    {"hetatm", atoms.skippedHetatm},
                    {"altlocs", atoms.skippedAltLocs}};
    j["surface"] = {{"type", ToString(surface_.kind)},
                    {"probe", surface_.probeRadius},
                    {"grid", surface_.gridSpacing},
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
      std::cout << "SAS area " << s.area << " Å², freesasa (Lee-Richards) " << reference << " Å² ("
                << 100.0 * (s.area - reference) / reference << " %)\n";
    }
    return j;
  }

  /// The raw extraction: measured, written; status 3 when it is not a valid closed surface.
  int CheckAndSave(MeshD& mesh, nlohmann::json& j) const {
    MeshQuality<MeshD>::Params qp;
    qp.threads = threads_;
    const QualityReport q = MeshQuality<MeshD>::Compute(mesh, qp);
    j["quality"] = ToJson(q);
    std::string error;
    if (!SaveMesh(mesh, output_, error)) throw std::runtime_error(error);
    std::cout << "Surface of " << input_ << " -> " << output_ << "\n" << FormatQualityTable(q, "value");
    const bool valid = q.boundaryEdges == 0 && q.nonManifoldEdges == 0 && q.nonManifoldVertices == 0 &&
                       q.degenerateFaces == 0 && q.selfIntersectingFaces == 0;
    if (valid) return 0;
    std::cerr << "molremesh: warning: " << output_ << " was written but is not a valid closed surface "
              << "(exit status 3)\n";
    return 3;
  }

  /// The full pipeline on the extraction, as `molremesh remesh` runs it with its defaults.
  int RemeshAndSave(MeshD& mesh, nlohmann::json& j) const {
    using Pipeline = RemeshPipeline<MeshD>;
    Pipeline::Params params;
    params.targetEdgeLength = targetLength_;
    params.seed = seed_;
    params.threads = threads_;
    params.restoreOnFailure = false;
    params.memoryLimitMB = surface_.memoryLimitMB;
    const PipelineResult result = Pipeline::Do(mesh, params, [this](const std::string& line) { Log(line); });
    if (result.refusedForMemory)
      throw std::runtime_error(result.message + "; --memory-limit MB sets the limit, -1 turns the check off");
    if (!result.ok) throw std::runtime_error(result.message);
    std::string error;
    if (!SaveMesh(mesh, output_, error)) throw std::runtime_error(error);
    const QualityReport& out = result.stages.empty() ? result.input : result.stages.back().after;
    std::cout << "Surface of " << input_ << " remeshed -> " << output_ << " (target edge length "
              << result.targetEdgeLength << ")\n"
              << FormatQualityTable({{"extracted", result.input}, {"remeshed", out}});
    j["remesh"] = {{"target_edge_length", result.targetEdgeLength},
                   {"seconds", result.seconds},
                   {"input", ToJson(result.input)},
                   {"output", ToJson(out)},
                   {"verdict",
                    {{"valid", result.verdict.Valid()},
                     {"all_targets_met", result.verdict.AllMet()},
                     {"invalid", result.verdict.invalid},
                     {"short_of", result.verdict.shortOf}}}};
    std::cerr << result.verdict.Lines("molremesh: warning: " + output_ + " ");
    if (result.verdict.Valid()) return 0;
    std::cerr << "molremesh: warning: " << output_
              << " was written but is not a valid surface mesh (exit status 3)\n";
    return 3;
  }

  CLI::App* app_ = nullptr;
  std::string input_, output_, radii_ = "protor", jsonPath_;
  MolecularSurface<MeshD>::Params surface_;
  StructureReadOptions read_;
  bool outerOnly_ = false, noHetatm_ = false, remesh_ = false, quiet_ = false;
  double targetLength_ = 1.0;
  std::uint64_t seed_ = 1;
  int threads_ = 0;
};

} // namespace molremesh

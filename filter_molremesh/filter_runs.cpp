// The part of the filters' runs that does not depend on the host's mesh type.
#if defined(MOLREMESH_MESH_D_INSTANCES) // built on vcg_ext's vcglib: MeshD's code is compiled already
#include <vcg_ext_instances/extern_mesh_d_volume.h>
#endif
#include "filter_runs.h"

#include <vcg_ext/structure/structure_file.h>

#include <tbb/task_arena.h>

#include <algorithm>
#include <cctype>
#include <cstring>

namespace molremesh::filters {

void LogPipelineRun(const PipelineResult& result, const RunLog& log) {
  std::vector<NamedReport> columns{{"before", result.input}};
  std::vector<double> seconds{0.0};
  for (const auto& stage : result.stages) {
    columns.emplace_back(stage.name, stage.after);
    seconds.push_back(stage.seconds);
  }
  if (log.rich) {
    // The log pane is narrow: each stage's summary as one paragraph, the full table before and
    // after only, and the per-stage figures in a short table.
    for (const auto& stage : result.stages) {
      std::string paragraph;
      std::istringstream lines(stage.summary);
      for (std::string line; std::getline(lines, line);)
        if (!line.empty()) paragraph += (paragraph.empty() ? "" : "; ") + line;
      log.info("<b>" + HtmlEscape(stage.name) + "</b>: " + HtmlEscape(paragraph));
    }
    std::vector<NamedReport> beforeAfter{columns.front()};
    if (columns.size() > 1) beforeAfter.emplace_back("after", columns.back().second);
    log.info(FormatQualityTableHtml(beforeAfter));
    log.info(PreformattedHtml(FormatStageTable(columns, seconds)));
  } else {
    for (const auto& stage : result.stages) log.Text(stage.summary);
    log.Text(FormatQualityTable(columns));
  }
  log.info(StageTimesLine(result));
  // The layer takes the result either way (it is better than the input), but never in silence
  // when it misses a promise: the warnings say what and why.
  // A kept retry changes the area by a few percent: said as a warning, not among the info lines.
  if (result.rebuildRetry.tried) log.warning("Note: " + result.rebuildRetry.message);
  RunLog::Lines(log.warning, result.verdict.Lines("Warning: the result is "));
}

namespace {
using Surface = MolecularSurface<MeshD>;

/// The surface parameters of Surface from Structure File; "" or why they are refused.
std::string ReadSurfaceParameters(const ParameterValues& values, StructureReadOptions& read,
                                  Surface::Params& surface, Pipeline::Params& pipeline) {
  const MolecularSurfaceKind kinds[] = {MolecularSurfaceKind::Ses, MolecularSurfaceKind::Sas,
                                        MolecularSurfaceKind::VanDerWaals, MolecularSurfaceKind::Gaussian};
  const int kind = values.Int("surfaceType");
  if (kind < 0 || kind > 3) return "Surface must be SES, SAS, van der Waals or Gaussian";
  surface.kind = kinds[kind];
  surface.probeRadius = values.Float("probeRadius");
  if (!(surface.probeRadius >= 0 && surface.probeRadius <= 10))
    return "Probe radius must be between 0 and 10 Å";
  pipeline.targetEdgeLength = values.Float("targetLength");
  if (!(pipeline.targetEdgeLength >= 0.1 && pipeline.targetEdgeLength <= 20))
    return "Edge length must be between 0.1 and 20 Å";
  const double grid = values.Float("gridSpacing");
  if (!(grid == 0 || (grid >= 0.05 && grid <= 5)))
    return "Grid spacing must be 0 (0.4 × edge length) or between 0.05 and 5 Å";
  surface.gridSpacing = grid > 0 ? grid : 0.4 * pipeline.targetEdgeLength;
  // Necks and cusps thinner than half a voxel are below the grid's resolution (as the CLI).
  surface.minFeatureRadius = 0.5 * surface.gridSpacing;
  surface.keepCavities = values.Bool("keepCavities");
  read.keepWaters = values.Bool("keepWaters");
  read.keepHydrogens = values.Bool("keepHydrogens");
  read.keepHetatm = values.Bool("keepHetatm");
  pipeline.seed = std::uint64_t(values.Int("seed"));
  pipeline.threads = surface.threads = std::max(0, values.Int("threads"));
  pipeline.memoryLimitMB = surface.memoryLimitMB = values.Float("memoryLimit");
  return {};
}

/// "1UBQ SES" for /data/1UBQ.pdb.gz.
std::string LayerNameOf(const std::string& path, MolecularSurfaceKind kind) {
  std::string base = path.substr(path.find_last_of("/\\") + 1);
  for (const char* extension : {".gz", ".pqr", ".pdb", ".ent", ".cif", ".mmcif"})
    if (base.size() > std::strlen(extension) &&
        base.compare(base.size() - std::strlen(extension), std::string::npos, extension) == 0)
      base.resize(base.size() - std::strlen(extension));
  std::string name = ToString(kind);
  std::transform(name.begin(), name.end(), name.begin(),
                 [](unsigned char c) { return char(std::toupper(c)); });
  return base + " " + name;
}

std::string AtomsLine(const StructureReadResult& atoms, const std::string& path) {
  return "read " + std::to_string(atoms.atoms.size()) + " atoms from " + path +
         " (skipped: " + std::to_string(atoms.skippedWaters) + " water, " +
         std::to_string(atoms.skippedHydrogens) + " hydrogen, " + std::to_string(atoms.skippedHetatm) +
         " HETATM, " + std::to_string(atoms.skippedAltLocs) + " alternate-location atoms)";
}

std::string SurfaceLine(const Surface::Params& p, const MolecularSurfaceResult& s) {
  char text[320];
  std::snprintf(text, sizeof text,
                "surface %s (probe %.2f Å, grid %.2f Å): %zu faces, %zu components (%zu cavities), area "
                "%.1f Å², volume %.1f Å³, %.1f s",
                ToString(p.kind), p.probeRadius, p.gridSpacing, s.faces, s.components, s.cavities, s.area,
                s.volume, s.seconds);
  return text;
}

/// The full pipeline on the extracted surface, the rest of the progress bar after surfaceShare.
std::string RemeshSurface(MeshD& mesh, Pipeline::Params& pipeline, const RunLog& log,
                          const RunProgress::Callback& progress, int surfaceShare, StructureSurfaceRun& run) {
  pipeline.restoreOnFailure = false;
  pipeline.intersectionsEachStage = false;
  RunProgress stages(
      [&progress, surfaceShare](int percent, const std::string& label) {
        progress(surfaceShare + percent * (100 - surfaceShare) / 100, label);
      },
      pipeline.stages);
  pipeline.cvt.progress = [&stages](double fraction, const std::string& step) {
    stages.Step(fraction, step);
  };
  pipeline.rar.progress = pipeline.clean.progress = pipeline.cvt.progress;
  run.pipeline = Pipeline::Do(mesh, pipeline, [&log, &stages](const std::string& line) {
    stages.OnLogLine(line);
    log.info(line);
  });
  if (!run.pipeline.ok) {
    mesh.Clear();
    return "the remeshing failed: " + run.pipeline.message;
  }
  run.remeshed = true;
  run.layerName += " remeshed";
  LogPipelineRun(run.pipeline, log);
  return {};
}

} // namespace

std::string RunSurfaceFromStructure(const ParameterValues& values, const RunLog& log,
                                    const RunProgress::Callback& progressCallback, MeshD& mesh,
                                    StructureSurfaceRun& run) {
  mesh.Clear();
  const std::string path = values.Has("structureFile") ? values.Text("structureFile") : std::string();
  // MeshLab's file parameter takes only what its ... button chose, not a typed path.
  if (path.empty()) return "Structure file: no file chosen (pick it with the ... button)";
  StructureReadOptions read;
  Surface::Params surface;
  Pipeline::Params pipeline;
  if (std::string why = ReadSurfaceParameters(values, read, surface, pipeline); !why.empty()) return why;
  const bool remesh = values.Bool("remesh");
  // The extraction takes about half of a remeshed run (1HPV, 4JSV); the bar's rest follows the stages.
  const int surfaceShare = remesh ? 50 : 100;
  auto progress = [&progressCallback](int percent, const std::string& label) {
    if (progressCallback) progressCallback(percent, label);
  };
  progress(0, "reading " + path);
  const StructureReadResult atoms = ReadStructureFile(path, read);
  if (!atoms.ok) return atoms.message;
  run.atoms = atoms.atoms.size();
  log.info(AtomsLine(atoms, path));
  const std::string kind = ToString(surface.kind);
  surface.progress = [&](double fraction, const std::string& step) {
    progress(1 + int(fraction * (surfaceShare - 1)), kind + " surface: " + step);
  };
  // OpenVDB runs on TBB's workers: the arena keeps it to the Threads parameter.
  tbb::task_arena arena(surface.threads > 0 ? surface.threads : tbb::task_arena::automatic);
  arena.execute([&] { run.surface = Surface::Build(atoms.atoms, mesh, surface); });
  if (!run.surface.ok) return "'" + path + "': " + run.surface.message;
  log.info(SurfaceLine(surface, run.surface));
  run.layerName = LayerNameOf(path, surface.kind);
  progress(surfaceShare, "surface built");
  return remesh ? RemeshSurface(mesh, pipeline, log, progress, surfaceShare, run) : std::string();
}

} // namespace molremesh::filters

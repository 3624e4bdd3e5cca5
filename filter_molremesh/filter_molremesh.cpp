// vcg_ext first: Qt (pulled in by the plugin header) defines `slots` and `signals` as macros,
// which must not reach our templates.
#include <vcg_ext/bad_element_coloring.h>
#include <vcg_ext/input_check.h>
#include <vcg_ext/mesh_copy.h>
#include <vcg_ext/mesh_quality.h>
#include <vcg_ext/mesh_types.h>
#include <vcg_ext/quality_report_format.h>
#include <vcg_ext/remesh_pipeline.h>

#include "filter_molremesh.h"

#include <sstream>
#include <string>

namespace {
const char* const kPluginName = "FilterMolRemesh";

/// Logs a multi-line text one line at a time: MeshLab's log shows one entry per call.
template <class Logger>
void LogLines(Logger&& log, const std::string& text) {
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) log(line);
}
} // namespace

FilterMolRemeshPlugin::FilterMolRemeshPlugin() {
  typeList << FP_QUALITY_REPORT << FP_COLOR_BAD_ELEMENTS << FP_CLEAN_RAW_MESH << FP_CVT_INITIALIZATION
           << FP_RANDOM_SEGMENTATION << FP_PATCHWISE_RAR;
  for (FilterIDType id : types()) actionList << new QAction(filterName(id), this);
}

QString FilterMolRemeshPlugin::pluginName() const {
  return kPluginName;
}

QString FilterMolRemeshPlugin::filterName(FilterIDType filter) const {
  switch (filter) {
  case FP_QUALITY_REPORT:
    return "Molecular Remesh: Quality Report";
  case FP_COLOR_BAD_ELEMENTS:
    return "Molecular Remesh: Color Bad Elements";
  case FP_CLEAN_RAW_MESH:
    return "Molecular Remesh: Clean Raw Mesh";
  case FP_CVT_INITIALIZATION:
    return "Molecular Remesh: CVT Initialization";
  case FP_RANDOM_SEGMENTATION:
    return "Molecular Remesh: Random Segmentation";
  case FP_PATCHWISE_RAR:
    return "Molecular Remesh: Patch-wise Adaptive Remeshing";
  }
  return "Molecular Remesh: unknown filter";
}

QString FilterMolRemeshPlugin::filterInfo(FilterIDType filter) const {
  switch (filter) {
  case FP_QUALITY_REPORT:
    return "Logs the mesh quality figures of Khan et al. 2020 (Qmin, Qavg, min/max angle, aspect ratio, "
           "V567 and valence histogram, % of triangles with an angle below 30 deg / obtuse / above 120 deg, "
           "area, volume) and the validity figures molremesh keeps (Euler characteristic, genus, components, "
           "boundary and non-manifold edges and vertices, degenerate faces, self-intersecting face pairs). "
           "The mesh is not changed.";
  case FP_COLOR_BAD_ELEMENTS:
    return "Colors elements for inspection. Per-vertex quality = valence; interior vertices whose valence is "
           "not 5, 6 or 7 are red. Per-face quality = minimal angle in degrees; obtuse faces are red, faces "
           "with an angle below the small-angle threshold are blue, faces that are both are magenta, all "
           "others gray. Save with vertex/face color and quality (meshlabserver -m vc fc vq fq) to keep "
           "them.";
  case FP_CLEAN_RAW_MESH:
    return "Stage 0 of molecular remeshing. Merges coincident vertices, removes unreferenced vertices, "
           "duplicate "
           "and zero-area faces, makes non-manifold edges and vertices manifold, orients every component "
           "coherently (closed ones outward), repairs small self-intersecting tangles, closes small holes "
           "and "
           "removes components below a fraction of the faces. Every action is counted in the log; a vertex "
           "that is already fine is never moved.";
  case FP_CVT_INITIALIZATION:
    return "Stage 1 of Khan et al. 2020: a centroidal Voronoi tessellation restricted to the surface and its "
           "dual "
           "triangulation, by Lloyd relaxation (42 iterations by default) of a triangulation whose "
           "connectivity "
           "only changes through guarded local operations, so the result stays 2-manifold, keeps every "
           "component's genus, never connects sheets across narrow gaps and has no self-intersection. Needs "
           "a "
           "clean 2-manifold input (run Clean Raw Mesh first).";
  case FP_RANDOM_SEGMENTATION:
    return "Stage 3 of Khan et al. 2020: splits the surface into random patches grown from seeded faces "
           "(their "
           "borders are locked during patch-wise remeshing). Colors the faces by patch and stores the patch "
           "id "
           "in the per-face attribute 'molremesh_patch'. Geometry is not changed.";
  case FP_PATCHWISE_RAR:
    return "Stage 3 of Khan et al. 2020: random segmentation (same seed and patch count as the Random "
           "Segmentation filter give the same patches), then each patch remeshed on its own, in parallel, with "
           "real-time adaptive remeshing (Dunyach et al. 2013: curvature-adapted target length, split > 4/3 L, "
           "collapse < 4/5 L, valence flips, tangential relaxation, projection onto the input) with its border "
           "locked; then the strip around the borders is remeshed. Every edit is guarded: no fold, no "
           "self-intersection, no new small angle. Needs a clean 2-manifold input.";
  }
  return QString();
}

MeshFilterInterface::FilterClass FilterMolRemeshPlugin::getClass(QAction*) {
  return MeshFilterInterface::Remeshing;
}

MeshFilterInterface::FILTER_ARITY FilterMolRemeshPlugin::filterArity(QAction*) const {
  return SINGLE_MESH;
}

int FilterMolRemeshPlugin::getPreConditions(QAction*) const {
  return MeshModel::MM_FACENUMBER;
}

int FilterMolRemeshPlugin::getRequirements(QAction*) {
  return MeshModel::MM_NONE;
}

int FilterMolRemeshPlugin::postCondition(QAction* action) const {
  switch (ID(action)) {
  case FP_QUALITY_REPORT:
    return MeshModel::MM_NONE;
  case FP_COLOR_BAD_ELEMENTS:
    return MeshModel::MM_VERTCOLOR | MeshModel::MM_FACECOLOR | MeshModel::MM_VERTQUALITY |
           MeshModel::MM_FACEQUALITY;
  case FP_RANDOM_SEGMENTATION:
    return MeshModel::MM_FACECOLOR;
  case FP_CLEAN_RAW_MESH:
  case FP_CVT_INITIALIZATION:
  case FP_PATCHWISE_RAR:
    return MeshModel::MM_ALL;
  }
  return MeshModel::MM_NONE;
}

void FilterMolRemeshPlugin::initParameterSet(QAction* action, MeshModel&, RichParameterList& parameters) {
  switch (ID(action)) {
  case FP_QUALITY_REPORT:
    parameters.addParam(RichBool("selfIntersections", true, "Count self-intersections",
                                 "Count pairs of faces that share no vertex and intersect (grid accelerated; "
                                 "the slowest figure on large meshes)."));
    break;
  case FP_COLOR_BAD_ELEMENTS: {
    const molremesh::BadElementColoring<CMeshO>::Params defaults;
    parameters.addParam(
        RichFloat("smallAngle", float(defaults.smallAngle), "Small angle (deg)",
                  "Faces with an angle below this are colored blue (magenta if also obtuse)."));
    parameters.addParam(RichFloat("obtuseAngle", float(defaults.obtuseAngle), "Obtuse angle (deg)",
                                  "Faces whose largest angle is at or above this are colored red."));
    break;
  }
  case FP_CLEAN_RAW_MESH: {
    const molremesh::CleanRawMesh<molremesh::MeshD>::Params defaults;
    parameters.addParam(RichFloat("mergeTolerance", float(defaults.mergeTolerance), "Merge tolerance",
                                  "Vertices closer than this times the mean edge length are merged."));
    parameters.addParam(RichInt("maxHoleEdges", defaults.maxHoleEdges, "Largest hole to close (edges)",
                                "Boundary loops with at most this many edges are closed."));
    parameters.addParam(
        RichFloat("minComponentPercent", float(100 * defaults.minComponentFraction),
                  "Smallest component kept (% of faces)",
                  "Components with fewer faces than this percentage are removed (and counted)."));
    parameters.addParam(
        RichBool("repairTangles", defaults.repairTangles, "Repair small tangles",
                 "Remove and refill small self-intersecting or incoherently oriented regions."));
    break;
  }
  case FP_CVT_INITIALIZATION: {
    const molremesh::CvtInitialization<molremesh::MeshD>::Params defaults;
    parameters.addParam(RichInt("iterations", defaults.iterations, "Lloyd iterations",
                                "Lloyd relaxation iterations (42 in Khan et al. 2020)."));
    parameters.addParam(
        RichFloat("targetLength", 0.f, "Target edge length",
                  "Target edge length in mesh units; 0 = the mean edge length of the input."));
    parameters.addParam(RichInt("targetVertexCount", 0, "Target vertex count",
                                "If > 0, the number of vertices wanted (overrides the target edge length)."));
    parameters.addParam(RichInt("threads", 0, "Threads",
                                "Worker threads; 0 = all cores. The result does not "
                                "depend on it."));
    break;
  }
  case FP_PATCHWISE_RAR: {
    const molremesh::PatchwiseRemeshing<molremesh::MeshD>::Params defaults;
    parameters.addParam(RichInt("patchCount", 0, "Patches", "Number of patches; 0 = automatic."));
    parameters.addParam(RichInt("seed", 1, "Seed", "Random seed of the segmentation."));
    parameters.addParam(RichInt("rarIterations", defaults.rar.iterations, "RAR iterations",
                                "Split/collapse/flip/relax iterations per patch."));
    parameters.addParam(RichFloat("targetLength", 0.f, "Target edge length",
                                  "Base target edge length L0 in mesh units; 0 = the mean edge length of the input."));
    parameters.addParam(RichFloat("approximationTolerance", float(defaults.rar.approximationTolerance),
                                  "Approximation tolerance (x L0)",
                                  "Allowed sagitta of an edge over the curved surface; smaller = finer where curved."));
    parameters.addParam(RichFloat("minLengthFactor", float(defaults.rar.minLengthFactor), "Min length (x L0)",
                                  "Smallest adaptive target length, relative to L0."));
    parameters.addParam(RichFloat("maxLengthFactor", float(defaults.rar.maxLengthFactor), "Max length (x L0)",
                                  "Largest adaptive target length, relative to L0."));
    parameters.addParam(RichInt("threads", 0, "Threads", "Worker threads; 0 = all cores. The result does not "
                                                         "depend on it."));
    break;
  }
  case FP_RANDOM_SEGMENTATION: {
    const molremesh::RandomSegmentation<CMeshO>::Params defaults;
    parameters.addParam(RichInt("patchCount", defaults.patchCount, "Patches",
                                "Number of patches; 0 = automatic (one per 4000 faces, at least 1)."));
    parameters.addParam(RichInt("seed", int(defaults.seed), "Seed",
                                "Random seed: same mesh and seed give the same "
                                "patches."));
    break;
  }
  }
}

bool FilterMolRemeshPlugin::fail(const QString& message) {
  errorMessage = message;
  Log(GLLogStream::WARNING, qUtf8Printable("Error: " + message));
  return false;
}

bool FilterMolRemeshPlugin::applyFilter(QAction* action, MeshDocument& md,
                                        const RichParameterList& parameters, vcg::CallBackPos* cb) {
  MeshModel* mm = md.mm();
  if (mm == nullptr) return fail(filterName(ID(action)) + ": there is no current mesh layer");
  // Every precondition is checked before the layer is touched, so a refused layer stays as it was.
  const molremesh::InputCheck check = molremesh::CheckTriangleMeshInput(mm->cm);
  if (!check.ok) return fail(filterName(ID(action)) + ": " + QString::fromStdString(check.message));

  switch (ID(action)) {
  case FP_QUALITY_REPORT:
    return qualityReport(*mm, parameters);
  case FP_COLOR_BAD_ELEMENTS:
    return colorBadElements(*mm, parameters);
  case FP_RANDOM_SEGMENTATION:
    return randomSegmentation(*mm, parameters);
  case FP_CLEAN_RAW_MESH:
    return runStages(*mm, {int(molremesh::PipelineStage::Clean)}, parameters, cb);
  case FP_CVT_INITIALIZATION:
    return runStages(*mm, {int(molremesh::PipelineStage::Cvt)}, parameters, cb);
  case FP_PATCHWISE_RAR:
    return runStages(*mm, {int(molremesh::PipelineStage::Segment), int(molremesh::PipelineStage::Rar)}, parameters,
                     cb);
  }
  return fail("unknown filter");
}

bool FilterMolRemeshPlugin::qualityReport(MeshModel& mm, const RichParameterList& parameters) {
  molremesh::MeshQuality<CMeshO>::Params params;
  params.computeSelfIntersections = parameters.getBool("selfIntersections");
  const molremesh::QualityReport report = molremesh::MeshQuality<CMeshO>::Compute(mm.cm, params);
  Log("Molecular Remesh quality report of %s", qUtf8Printable(mm.shortName()));
  LogLines([this](const std::string& line) { Log(line); }, molremesh::FormatQualityTable(report, "value"));
  Log(("valence histogram (interior vertices): " + molremesh::FormatValenceHistogram(report)).c_str());
  return true;
}

bool FilterMolRemeshPlugin::colorBadElements(MeshModel& mm, const RichParameterList& parameters) {
  molremesh::BadElementColoring<CMeshO>::Params params;
  params.smallAngle = parameters.getFloat("smallAngle");
  params.obtuseAngle = parameters.getFloat("obtuseAngle");
  if (!(params.smallAngle >= 0 && params.smallAngle <= 60))
    return fail("Small angle must be between 0 and 60 degrees");
  if (!(params.obtuseAngle >= 60 && params.obtuseAngle <= 180))
    return fail("Obtuse angle must be between 60 and 180 degrees");

  mm.updateDataMask(MeshModel::MM_VERTCOLOR | MeshModel::MM_FACECOLOR | MeshModel::MM_VERTQUALITY |
                    MeshModel::MM_FACEQUALITY);
  const molremesh::BadElementCounts counts = molremesh::BadElementColoring<CMeshO>::Do(mm.cm, params);
  Log("Irregular vertices (red): %zu", counts.irregularVertices);
  Log("Obtuse faces (red or magenta): %zu", counts.obtuseFaces);
  Log("Small-angle faces (blue or magenta): %zu", counts.smallAngleFaces);
  Log("Obtuse and small-angle faces (magenta): %zu", counts.obtuseAndSmallFaces);
  return true;
}

bool FilterMolRemeshPlugin::randomSegmentation(MeshModel& mm, const RichParameterList& parameters) {
  using Segmentation = molremesh::RandomSegmentation<CMeshO>;
  Segmentation::Params params;
  params.patchCount = parameters.getInt("patchCount");
  params.seed = std::uint64_t(parameters.getInt("seed"));
  if (params.patchCount < 0) return fail("Patches must be 0 (automatic) or more");
  mm.updateDataMask(MeshModel::MM_FACEFACETOPO | MeshModel::MM_FACECOLOR);
  vcg::tri::UpdateTopology<CMeshO>::FaceFace(mm.cm);
  const molremesh::SegmentationResult result = Segmentation::Do(mm.cm, params);
  if (!result.ok) return fail(QString::fromStdString(result.message));
  Segmentation::ColorPatches(mm.cm, result);
  auto patchAttribute = vcg::tri::Allocator<CMeshO>::GetPerFaceAttribute<int>(mm.cm, "molremesh_patch");
  for (std::size_t i = 0; i < mm.cm.face.size(); ++i) patchAttribute[i] = result.facePatch[i];
  Log("Random segmentation: %d patches, %zu border edges, %zu border vertices", result.patchCount,
      result.borderEdges, result.borderVertices);
  return true;
}

bool FilterMolRemeshPlugin::runStages(MeshModel& mm, const std::vector<int>& stages,
                                      const RichParameterList& parameters, vcg::CallBackPos* cb) {
  using Pipeline = molremesh::RemeshPipeline<molremesh::MeshD>;
  Pipeline::Params params;
  params.stages.clear();
  for (int stage : stages) params.stages.push_back(molremesh::PipelineStage(stage));
  // Each filter declares only its own parameters; read the ones present.
  if (parameters.hasParameter("mergeTolerance"))
    params.clean.mergeTolerance = parameters.getFloat("mergeTolerance");
  if (parameters.hasParameter("maxHoleEdges")) params.clean.maxHoleEdges = parameters.getInt("maxHoleEdges");
  if (parameters.hasParameter("minComponentPercent"))
    params.clean.minComponentFraction = parameters.getFloat("minComponentPercent") / 100.0;
  if (parameters.hasParameter("repairTangles"))
    params.clean.repairTangles = parameters.getBool("repairTangles");
  if (parameters.hasParameter("iterations")) params.cvt.iterations = parameters.getInt("iterations");
  if (parameters.hasParameter("targetLength")) params.targetEdgeLength = parameters.getFloat("targetLength");
  if (parameters.hasParameter("targetVertexCount"))
    params.cvt.targetVertexCount = std::size_t(std::max(0, parameters.getInt("targetVertexCount")));
  if (parameters.hasParameter("threads")) params.threads = std::max(0, parameters.getInt("threads"));
  if (parameters.hasParameter("seed")) params.seed = std::uint64_t(parameters.getInt("seed"));
  if (parameters.hasParameter("patchCount")) params.segment.patchCount = std::max(0, parameters.getInt("patchCount"));
  if (parameters.hasParameter("rarIterations")) params.rar.rar.iterations = parameters.getInt("rarIterations");
  if (parameters.hasParameter("approximationTolerance"))
    params.rar.rar.approximationTolerance = parameters.getFloat("approximationTolerance");
  if (parameters.hasParameter("minLengthFactor")) params.rar.rar.minLengthFactor = parameters.getFloat("minLengthFactor");
  if (parameters.hasParameter("maxLengthFactor")) params.rar.rar.maxLengthFactor = parameters.getFloat("maxLengthFactor");
  if (params.cvt.iterations < 0) return fail("Lloyd iterations must be 0 or more");
  if (params.targetEdgeLength < 0) return fail("Target edge length must be 0 (automatic) or more");

  molremesh::MeshD work;
  molremesh::CopyTriangles(work, mm.cm);
  const molremesh::PipelineResult result = Pipeline::Do(
      work, params, [this](const std::string& line) { Log(line.c_str()); }, cb);
  if (!result.ok) return fail(QString::fromStdString(result.message));

  std::vector<molremesh::NamedReport> columns{{"before", result.input}};
  for (const auto& stage : result.stages) {
    columns.emplace_back(stage.name, stage.after);
    LogLines([this](const std::string& line) { Log(line); }, stage.summary);
  }
  LogLines([this](const std::string& line) { Log(line); }, molremesh::FormatQualityTable(columns));

  // Success: replace the layer's triangles. Old per-element colors and qualities described the
  // old triangles, so they are dropped with them.
  mm.cm.Clear();
  mm.clearDataMask(MeshModel::MM_VERTCOLOR | MeshModel::MM_FACECOLOR | MeshModel::MM_VERTQUALITY |
                   MeshModel::MM_FACEQUALITY | MeshModel::MM_FACEFACETOPO | MeshModel::MM_VERTFACETOPO |
                   MeshModel::MM_WEDGTEXCOORD | MeshModel::MM_VERTTEXCOORD);
  molremesh::CopyTriangles(mm.cm, work);
  mm.UpdateBoxAndNormals();
  return true;
}

MESHLAB_PLUGIN_NAME_EXPORTER(FilterMolRemeshPlugin)

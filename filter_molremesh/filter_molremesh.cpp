// vcg_ext first: Qt (pulled in by the plugin header) defines `slots` and `signals` as macros,
// which must not reach our templates.
#include <vcg_ext/quality/bad_element_coloring.h>
#include <vcg_ext/core/input_check.h>
#include <vcg_ext/core/mesh_copy.h>
#include <vcg_ext/quality/mesh_quality.h>
#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/quality/quality_report_format.h>
#include <vcg_ext/pipeline/remesh_pipeline.h>
#include <vcg_ext/quality/stage_summary.h>

#include "filter_molremesh.h"

#include <algorithm>
#include <sstream>
#include <string>

namespace {
const char* const kPluginName = "FilterMolRemesh";
using Pipeline = molremesh::RemeshPipeline<molremesh::MeshD>;

/// Logs a multi-line text one line at a time: MeshLab's log shows one entry per call.
template <class Logger>
void LogLines(Logger&& log, const std::string& text) {
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) log(line);
}
} // namespace

namespace {
void AddMinAngleParameter(RichParameterList& parameters) {
  parameters.addParam(
      RichFloat("minAngle", 30.f, "Min angle (deg)",
                "No edit leaves more faces with an angle below this than it removed; the small-angle "
                "stage removes every angle below it."));
}
/// The clean stage's settings (Clean Raw Mesh and Full Pipeline).
void AddCleanParameters(RichParameterList& parameters) {
  const molremesh::CleanRawMesh<molremesh::MeshD>::Params defaults;
  parameters.addParam(RichFloat("mergeTolerance", float(defaults.mergeTolerance), "Merge tolerance",
                                "Vertices closer than this times the mean edge length are merged."));
  parameters.addParam(RichInt("maxHoleEdges", defaults.maxHoleEdges, "Largest hole to close (edges)",
                              "Boundary loops with at most this many edges are closed."));
  parameters.addParam(RichFloat("minComponentPercent", float(100 * defaults.minComponentFraction),
                                "Smallest component kept (% of faces)",
                                "Components with fewer faces than this percentage are removed (and counted; "
                                "never the largest). 0 keeps every component."));
  parameters.addParam(
      RichBool("repairTangles", defaults.repairTangles, "Repair small tangles",
               "Remove and refill small self-intersecting or incoherently oriented regions."));
}
void AddCommonParameters(RichParameterList& parameters) {
  parameters.addParam(
      RichFloat("targetLength", 0.f, "Target edge length",
                "Edge length L that scales the tolerances; 0 = the mean edge length of the mesh."));
  parameters.addParam(RichInt("threads", 0, "Threads",
                              "Worker threads; 0 = all cores. The result does not "
                              "depend on it."));
}
/// For the filters that build a new mesh at the target edge length (CVT, RAR, full pipeline).
void AddMemoryLimitParameter(RichParameterList& parameters) {
  parameters.addParam(
      RichFloat("memoryLimit", 0.f, "Memory limit (MB)",
                "The filter refuses to run (the layer untouched) when its estimated peak "
                "memory exceeds this; 0 = the memory available when it starts, -1 = no check. "
                "A target edge length far below the mesh's makes millions of faces."));
}
void AddValenceParameters(RichParameterList& parameters) {
  const molremesh::ValenceOptimization<molremesh::MeshD>::Params defaults;
  AddMinAngleParameter(parameters);
  parameters.addParam(RichFloat("maxAngle", float(defaults.maxAngleDeg), "Max angle (deg)",
                                "No edit leaves more faces with an angle above this than it removed."));
  parameters.addParam(
      RichFloat("areaFactor", float(defaults.areaFactor), "Area factor",
                "Phase 2 grows a hole while its area stays below this times the mean triangle "
                "area (9 in Khan et al. 2020)."));
  parameters.addParam(
      RichInt("rounds", defaults.rounds, "Rounds",
              "Repetitions of flips/collapses and removal/refilling (stops early when nothing "
              "changes)."));
}
void AddSmallAngleParameters(RichParameterList& parameters) {
  const molremesh::SmallAngleElimination<molremesh::MeshD>::Params defaults;
  AddMinAngleParameter(parameters);
  parameters.addParam(RichFloat("collapseAngle", float(defaults.collapseAngleDeg), "Collapse angle (deg)",
                                "Triangles with an angle below this get the edge opposite it collapsed."));
  parameters.addParam(RichFloat("maxAngle", float(defaults.maxAngleDeg), "Max angle (deg)",
                                "Moves and refills never leave more faces with an angle above this."));
  parameters.addParam(RichInt("smallIterations", defaults.maxIterations, "Iterations (cap)",
                              "Rounds of collapse, flip, translation and refilling at most."));
  parameters.addParam(RichBool("deleteAndRefill", defaults.deleteAndRefill, "Delete and refill",
                               "Delete vertices that keep a small angle and retriangulate their hole."));
}
void AddObtuseThresholds(RichParameterList& parameters) {
  const molremesh::ObtuseReduction<molremesh::MeshD>::Params defaults;
  const char* names[3] = {"obtuseThreshold1", "obtuseThreshold2", "obtuseThreshold3"};
  for (int i = 0; i < 3; ++i)
    parameters.addParam(
        RichFloat(names[i], float(defaults.thresholdsDeg[std::size_t(i)]),
                  QString("Max-angle threshold %1 (deg)").arg(i + 1),
                  "Vertex translation runs for each threshold in turn (110, 100, 90 in Khan et "
                  "al. 2020); 180 skips one."));
  parameters.addParam(RichInt("translationIterations", defaults.iterationsPerThreshold,
                              "Translation iterations",
                              "Vertex translation rounds per threshold (20 in Khan et al. 2020)."));
}
void AddObtuseParameters(RichParameterList& parameters) {
  const molremesh::ObtuseReduction<molremesh::MeshD>::Params defaults;
  AddMinAngleParameter(parameters);
  AddObtuseThresholds(parameters);
  parameters.addParam(
      RichBool("pentagonInsertion", defaults.pentagonInsertion, "Pentagon point insertion",
               "After the translations, refill pentagons around obtuse triangles with one vertex."));
  parameters.addParam(RichFloat("pentagonNormalAngle", float(defaults.pentagonNormalDeg),
                                "Pentagon normal agreement (deg)",
                                "The three triangles of a pentagon must have normals within this angle."));
}
} // namespace

FilterMolRemeshPlugin::FilterMolRemeshPlugin() {
  typeList << FP_QUALITY_REPORT << FP_COLOR_BAD_ELEMENTS << FP_CLEAN_RAW_MESH << FP_CVT_INITIALIZATION
           << FP_RANDOM_SEGMENTATION << FP_PATCHWISE_RAR << FP_VALENCE_OPTIMIZATION << FP_REMOVE_SMALL_ANGLES
           << FP_REDUCE_OBTUSE << FP_LOCAL_SMOOTHING << FP_FULL_PIPELINE;
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
  case FP_VALENCE_OPTIMIZATION:
    return "Molecular Remesh: Valence Optimization";
  case FP_REMOVE_SMALL_ANGLES:
    return "Molecular Remesh: Remove Small Angles";
  case FP_REDUCE_OBTUSE:
    return "Molecular Remesh: Reduce Obtuse Triangles";
  case FP_LOCAL_SMOOTHING:
    return "Molecular Remesh: Local Smoothing";
  case FP_FULL_PIPELINE:
    return "Molecular Remesh: Full Pipeline";
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
           "Segmentation filter give the same patches), then each patch remeshed on its own, in parallel, "
           "with "
           "real-time adaptive remeshing (Dunyach et al. 2013: curvature-adapted target length, split > 4/3 "
           "L, "
           "collapse < 4/5 L, valence flips, tangential relaxation, projection onto the input) with its "
           "border "
           "locked; then the strip around the borders is remeshed. Every edit is guarded: no fold, no "
           "self-intersection, no new small angle. Needs a clean 2-manifold input.";
  case FP_VALENCE_OPTIMIZATION:
    return "Stage 2 of Khan et al. 2020: makes vertices valence 5, 6 or 7. Guarded edge flips and collapses "
           "that lower the valence deviation, then two-phase removal of irregular vertices (their star, then "
           "irregular vertices on the hole's rim while the hole stays below the area factor times the mean "
           "triangle area) and refilling with 0, 1 or 2 new vertices placed in the feasible region. No edit "
           "leaves more faces with an angle below the min angle (or above the max angle) than it removed. "
           "Needs a clean 2-manifold input (run Clean Raw Mesh and CVT Initialization first).";
  case FP_REMOVE_SMALL_ANGLES:
    return "Stage 4 of Khan et al. 2020: removes angles below the min angle: collapses of short edges "
           "opposite angles below the collapse angle, flips, constrained vertex translation (Laplacian "
           "position, else nearby positions), deletion and refilling of vertices that keep a small angle; "
           "repeated up to the iteration cap. Every edit is guarded (no fold, no self-intersection, no new "
           "bad angle). Needs a clean 2-manifold input.";
  case FP_REDUCE_OBTUSE:
    return "Stage 5 of Khan et al. 2020: translation of the vertex at each obtuse angle inside a feasible "
           "disc (projected onto the surface) for the max-angle thresholds in turn, then pentagon point "
           "insertion (obtuse triangle + two neighbours across their longest edges, refilled with one "
           "vertex in the feasible region). No edit creates an angle below the min angle. Needs a clean "
           "2-manifold input.";
  case FP_LOCAL_SMOOTHING:
    return "Stage 6 of Khan et al. 2020: Laplacian translation and local remeshing of the triangles that are "
           "still obtuse or have a small angle, and their neighbours, accepted only when the worst angle "
           "improves and no small angle appears. Needs a clean 2-manifold input.";
  case FP_FULL_PIPELINE:
    return "All of molecular remeshing in the order of Khan et al. 2020: clean raw mesh, CVT initialization, "
           "valence optimization, random segmentation and patch-wise adaptive remeshing, small-angle "
           "elimination, obtuse reduction, local smoothing, and a final valence pass that may not add an "
           "obtuse "
           "face (polish, beyond the paper). Logs the quality table before, after and per "
           "stage with its time. Transactional: if a stage fails, the layer is left as it was.";
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
  case FP_VALENCE_OPTIMIZATION:
  case FP_REMOVE_SMALL_ANGLES:
  case FP_REDUCE_OBTUSE:
  case FP_LOCAL_SMOOTHING:
  case FP_FULL_PIPELINE:
    // MM_ALL is 0xffffffff in an unsigned enum; the interface returns int (all bits set).
    return static_cast<int>(MeshModel::MM_ALL);
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
  case FP_CLEAN_RAW_MESH:
    AddCleanParameters(parameters);
    break;
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
    AddMemoryLimitParameter(parameters);
    break;
  }
  case FP_PATCHWISE_RAR: {
    const molremesh::PatchwiseRemeshing<molremesh::MeshD>::Params defaults;
    parameters.addParam(RichInt("patchCount", 0, "Patches", "Number of patches; 0 = automatic."));
    parameters.addParam(RichInt("seed", 1, "Seed", "Random seed of the segmentation."));
    parameters.addParam(RichInt("rarIterations", defaults.rar.iterations, "RAR iterations",
                                "Split/collapse/flip/relax iterations per patch."));
    parameters.addParam(
        RichFloat("targetLength", 0.f, "Target edge length",
                  "Base target edge length L0 in mesh units; 0 = the mean edge length of the input."));
    parameters.addParam(
        RichFloat("approximationTolerance", float(defaults.rar.approximationTolerance),
                  "Approximation tolerance (x L0)",
                  "Allowed sagitta of an edge over the curved surface; smaller = finer where curved."));
    parameters.addParam(RichFloat("minLengthFactor", float(defaults.rar.minLengthFactor), "Min length (x L0)",
                                  "Smallest adaptive target length, relative to L0."));
    parameters.addParam(RichFloat("maxLengthFactor", float(defaults.rar.maxLengthFactor), "Max length (x L0)",
                                  "Largest adaptive target length, relative to L0."));
    parameters.addParam(RichInt("threads", 0, "Threads",
                                "Worker threads; 0 = all cores. The result does not "
                                "depend on it."));
    AddMemoryLimitParameter(parameters);
    break;
  }
  case FP_VALENCE_OPTIMIZATION:
    AddValenceParameters(parameters);
    AddCommonParameters(parameters);
    break;
  case FP_REMOVE_SMALL_ANGLES:
    AddSmallAngleParameters(parameters);
    AddCommonParameters(parameters);
    break;
  case FP_REDUCE_OBTUSE:
    AddObtuseParameters(parameters);
    AddCommonParameters(parameters);
    break;
  case FP_LOCAL_SMOOTHING:
    AddMinAngleParameter(parameters);
    parameters.addParam(RichInt("smoothIterations",
                                molremesh::LocalSmoothing<molremesh::MeshD>::Params().iterations,
                                "Iterations (cap)", "Rounds of smoothing at most."));
    AddCommonParameters(parameters);
    break;
  case FP_FULL_PIPELINE: {
    const Pipeline::Params defaults;
    parameters.addParam(
        RichFloat("targetLength", 0.f, "Target edge length",
                  "Target edge length L in mesh units; 0 = the mean edge length of the cleaned input."));
    parameters.addParam(
        RichInt("iterations", defaults.cvt.iterations, "CVT Lloyd iterations",
                "Lloyd relaxation iterations of the CVT initialization (42 in Khan et al. 2020)."));
    parameters.addParam(
        RichInt("patchCount", 0, "Patches", "Number of patches of the segmentation; 0 = automatic."));
    parameters.addParam(
        RichInt("seed", 1, "Seed", "Seed of every random choice: same mesh and seed, same result."));
    AddMinAngleParameter(parameters);
    parameters.addParam(
        RichFloat("maxAngle", float(defaults.valence.maxAngleDeg), "Max angle (deg)",
                  "Valence optimization and small-angle elimination never leave more faces with "
                  "an angle above this."));
    AddObtuseThresholds(parameters);
    parameters.addParam(
        RichFloat("areaFactor", float(defaults.valence.areaFactor), "Valence area factor",
                  "Phase 2 of valence optimization grows a hole while its area stays below this "
                  "times the mean triangle area."));
    AddCleanParameters(parameters);
    parameters.addParam(RichInt("threads", 0, "Threads",
                                "Worker threads; 0 = all cores. The result does not "
                                "depend on it."));
    AddMemoryLimitParameter(parameters);
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
    return runStages(*mm, {int(molremesh::PipelineStage::Segment), int(molremesh::PipelineStage::Rar)},
                     parameters, cb);
  case FP_VALENCE_OPTIMIZATION:
    return runStages(*mm, {int(molremesh::PipelineStage::Valence)}, parameters, cb);
  case FP_REMOVE_SMALL_ANGLES:
    return runStages(*mm, {int(molremesh::PipelineStage::Small)}, parameters, cb);
  case FP_REDUCE_OBTUSE:
    return runStages(*mm, {int(molremesh::PipelineStage::Obtuse)}, parameters, cb);
  case FP_LOCAL_SMOOTHING:
    return runStages(*mm, {int(molremesh::PipelineStage::Smooth)}, parameters, cb);
  case FP_FULL_PIPELINE: {
    std::vector<int> all;
    for (const auto& info : molremesh::PipelineStages()) all.push_back(int(info.stage));
    return runStages(*mm, all, parameters, cb);
  }
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
  if (parameters.hasParameter("memoryLimit")) params.memoryLimitMB = parameters.getFloat("memoryLimit");
  if (parameters.hasParameter("seed")) params.seed = std::uint64_t(parameters.getInt("seed"));
  if (parameters.hasParameter("patchCount"))
    params.segment.patchCount = std::max(0, parameters.getInt("patchCount"));
  if (parameters.hasParameter("rarIterations"))
    params.rar.rar.iterations = parameters.getInt("rarIterations");
  if (parameters.hasParameter("approximationTolerance"))
    params.rar.rar.approximationTolerance = parameters.getFloat("approximationTolerance");
  if (parameters.hasParameter("minLengthFactor"))
    params.rar.rar.minLengthFactor = parameters.getFloat("minLengthFactor");
  if (parameters.hasParameter("maxLengthFactor"))
    params.rar.rar.maxLengthFactor = parameters.getFloat("maxLengthFactor");
  if (parameters.hasParameter("minAngle")) {
    const double a = parameters.getFloat("minAngle");
    if (!(a >= 0 && a < 60)) return fail("Min angle must be at least 0 and below 60 degrees");
    params.SetMinAngle(a);
  }
  if (parameters.hasParameter("maxAngle")) {
    const double a = parameters.getFloat("maxAngle");
    if (!(a > 60 && a <= 180)) return fail("Max angle must be above 60 and at most 180 degrees");
    params.SetMaxAngle(a);
  }
  if (parameters.hasParameter("areaFactor")) params.SetValenceAreaFactor(parameters.getFloat("areaFactor"));
  if (parameters.hasParameter("rounds")) params.valence.rounds = parameters.getInt("rounds");
  if (parameters.hasParameter("collapseAngle"))
    params.small.collapseAngleDeg = parameters.getFloat("collapseAngle");
  if (parameters.hasParameter("smallIterations"))
    params.small.maxIterations = parameters.getInt("smallIterations");
  if (parameters.hasParameter("deleteAndRefill"))
    params.small.deleteAndRefill = parameters.getBool("deleteAndRefill");
  if (parameters.hasParameter("obtuseThreshold1")) {
    std::vector<double> thresholds;
    for (const char* name : {"obtuseThreshold1", "obtuseThreshold2", "obtuseThreshold3"}) {
      const double t = parameters.getFloat(name);
      if (!(t >= 60 && t <= 180)) return fail("Max-angle thresholds must be between 60 and 180 degrees");
      if (t < 180) thresholds.push_back(t);
    }
    params.SetObtuseThresholds(thresholds);
  }
  if (parameters.hasParameter("smoothIterations"))
    params.smooth.iterations = parameters.getInt("smoothIterations");
  if (parameters.hasParameter("translationIterations"))
    params.obtuse.iterationsPerThreshold = parameters.getInt("translationIterations");
  if (parameters.hasParameter("pentagonInsertion"))
    params.obtuse.pentagonInsertion = parameters.getBool("pentagonInsertion");
  if (parameters.hasParameter("pentagonNormalAngle"))
    params.obtuse.pentagonNormalDeg = parameters.getFloat("pentagonNormalAngle");
  if (params.valence.areaFactor < 0) return fail("Area factor must be 0 or more");
  if (params.valence.rounds < 0 || params.small.maxIterations < 0 || params.obtuse.iterationsPerThreshold < 0)
    return fail("Rounds and iteration counts must be 0 or more");
  if (params.cvt.iterations < 0) return fail("Lloyd iterations must be 0 or more");
  if (params.targetEdgeLength < 0) return fail("Target edge length must be 0 (automatic) or more");

  // Self-intersections are counted before and after, not between stages (the slowest figure;
  // every edit already refuses new intersections).
  params.intersectionsEachStage = false;
  // The run works on a copy and writes it back only when every stage succeeded: the layer stays
  // as it was on failure without the pipeline's own backup copy of the input.
  params.restoreOnFailure = false;
  // Checked on the layer, before the copy (which the estimate includes), then not again.
  if (const std::string why = Pipeline::MemoryCheck(mm.cm, params); !why.empty())
    return fail(
        QString::fromStdString("refused: " + why +
                               " (the layer is unchanged; the Memory limit parameter sets the limit, -1 "
                               "turns the check off)"));
  params.memoryLimitMB = -1;
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
  Log(molremesh::StageTimesLine(result).c_str());
  // The layer takes the result either way (it is better than the input), but never in silence
  // when it misses a promise: the warnings say what and why.
  LogLines([this](const std::string& line) { Log(GLLogStream::WARNING, line.c_str()); },
           result.verdict.Lines("Warning: the result is "));

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

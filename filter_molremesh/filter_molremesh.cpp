// vcg_ext first: Qt (pulled in by the plugin header) defines `slots` and `signals` as macros,
// which must not reach our templates.
#include <vcg_ext/quality/bad_element_coloring.h>
#include <vcg_ext/core/input_check.h>
#include <vcg_ext/core/mesh_copy.h>
#include <vcg_ext/quality/mesh_quality.h>
#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/geometry/mean_edge_length.h>
#include <vcg_ext/quality/quality_report_format.h>
#include <vcg_ext/quality/quality_report_html.h>
#include <vcg_ext/pipeline/region_remeshing.h>
#include <vcg_ext/pipeline/remesh_pipeline.h>
#include <vcg_ext/quality/stage_summary.h>

#include "filter_molremesh.h"

#include <common/mlapplication.h>

#include <QCoreApplication>
#include <QFileInfo>

#include <vcg/complex/algorithms/update/selection.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
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
// Parameter texts: the label says what it is and its unit; the help (MeshLab's tooltip) says what
// it changes, its default, when to change it, and the paper's name for it.
void AddMinAngleParameter(RichParameterList& parameters) {
  parameters.addParam(RichFloat(
      "minAngle", 30.f, "Smallest angle (°)",
      "No edit creates a triangle angle below this, and the small-angle step removes every angle below "
      "it. Default 30°; lower it (25°) for a mesh that keeps failing, above 35° is rarely reached. "
      "Paper: minimum angle θmin."));
}
/// The early stages' max-angle guard, and how it relates to the obtuse thresholds.
void AddMaxAngleParameter(RichParameterList& parameters, float defaultDeg) {
  parameters.addParam(RichFloat(
      "maxAngle", defaultDeg, "Largest angle, first steps (°)",
      "Valence and small-angle fixing never leave an angle above this (default 120°); the obtuse step "
      "that follows lowers the largest angles further, below 110°, 100° and then 90° (its thresholds, in "
      "Reduce Obtuse Triangles). Paper: maximum angle θmax."));
}
/// Edge length in Å (the mesh's units) and % of the bounding-box diagonal, pre-filled with the
/// layer's mean edge length, as MeshLab's own isotropic remeshing does.
void AddTargetLengthParameter(RichParameterList& parameters, const MeshModel& m, const QString& help) {
  double mean = molremesh::MeanEdgeLength(m.cm);
  double diagonal = m.cm.bbox.Diag();
  if (!std::isfinite(mean) || mean < 0) mean = 0;
  if (!std::isfinite(diagonal) || diagonal <= 0) diagonal = std::max(1.0, 10 * mean);
  parameters.addParam(RichAbsPerc("targetLength", float(mean), 0.f, float(diagonal), "Edge length (Å)",
                                  help + " Pre-filled with this mesh's mean edge length; 0 = the mean "
                                         "edge length of the input. Paper: target edge length L."));
}
void AddThreadsParameter(RichParameterList& parameters) {
  parameters.addParam(RichInt("threads", 0, "Threads",
                              "Worker threads; 0 = all cores. The result is the same for any count."));
}
void AddSeedParameter(RichParameterList& parameters) {
  parameters.addParam(RichInt("seed", 1, "Random seed",
                              "Same mesh, parameters and seed give the same result on any machine and thread "
                              "count; another seed gives another, equally good remesh. Default 1."));
}
/// For the filters that rebuild the mesh: the result in a new layer (on) or in place (off).
void AddNewLayerParameter(RichParameterList& parameters) {
  parameters.addParam(RichBool("newLayer", true, "Put the result in a new layer",
                               "On (default): the result becomes a new layer named after this one and this "
                               "layer is kept unchanged (hidden); MeshLab has no undo. Off: this layer is "
                               "replaced."));
}
/// The clean stage's settings (Clean Raw Mesh).
void AddCleanParameters(RichParameterList& parameters) {
  const molremesh::CleanRawMesh<molremesh::MeshD>::Params defaults;
  parameters.addParam(RichFloat("mergeTolerance", float(defaults.mergeTolerance),
                                "Merge distance (× mean edge length)",
                                "Vertices closer than this fraction of the mean edge length become one. "
                                "Default 1e-6: only coincident vertices (the seams of marching cubes)."));
  parameters.addParam(RichInt("maxHoleEdges", defaults.maxHoleEdges, "Largest hole to close (edges)",
                              "Holes whose rim has at most this many edges are filled (default 100); a crack "
                              "of a raw surface has a few, a real opening hundreds."));
  parameters.addParam(RichFloat("minComponentPercent", float(100 * defaults.minComponentFraction),
                                "Drop pieces below (% of faces)",
                                "Separate pieces with fewer faces than this share are removed (and counted; "
                                "never the largest). Default 1 %; 0 keeps every piece, e.g. cavities."));
  parameters.addParam(
      RichBool("repairTangles", defaults.repairTangles, "Repair small tangles",
               "Remove and refill small self-intersecting or inside-out regions (default on)."));
}
/// For the filters that build a new mesh at the target edge length (CVT, RAR, full pipeline).
void AddMemoryLimitParameter(RichParameterList& parameters) {
  parameters.addParam(RichFloat("memoryLimit", 0.f, "Memory limit (MB)",
                                "The filter refuses to start (the layer untouched) when it would need more "
                                "memory than this; 0 = the memory free when it starts, -1 = no check. Only "
                                "an edge length far below the mesh's makes that many faces."));
}
void AddRoundsParameter(RichParameterList& parameters, const char* name, int defaultValue) {
  parameters.addParam(RichInt(name, defaultValue, "Rounds (at most)",
                              QString("Repetitions of the whole step; it stops earlier when a round changes "
                                      "nothing. Default %1.")
                                  .arg(defaultValue)));
}
void AddValenceParameters(RichParameterList& parameters) {
  const molremesh::ValenceOptimization<molremesh::MeshD>::Params defaults;
  AddMinAngleParameter(parameters);
  AddMaxAngleParameter(parameters, float(defaults.maxAngleDeg));
  parameters.addParam(RichFloat(
      "areaFactor", float(defaults.areaFactor), "Largest hole (× mean triangle area)",
      "Clusters of irregular vertices are cut out together while the hole stays below this many mean "
      "triangle areas, then refilled. Default 9; larger fixes bigger clusters and changes more of the "
      "surface. Paper: area factor of the two-phase removal."));
  AddRoundsParameter(parameters, "rounds", defaults.rounds);
}
void AddSmallAngleParameters(RichParameterList& parameters) {
  const molremesh::SmallAngleElimination<molremesh::MeshD>::Params defaults;
  AddMinAngleParameter(parameters);
  parameters.addParam(RichFloat("collapseAngle", float(defaults.collapseAngleDeg), "Collapse below (°)",
                                QString("A triangle with an angle below this loses the short edge opposite "
                                        "it (the needle disappears). Default %1°.")
                                    .arg(defaults.collapseAngleDeg)));
  parameters.addParam(RichFloat("maxAngle", float(defaults.maxAngleDeg), "Largest angle (°)",
                                "Moves and refills never leave an angle above this (default 120°; the "
                                "obtuse step lowers it later). Paper: θmax."));
  AddRoundsParameter(parameters, "smallIterations", defaults.maxIterations);
  parameters.addParam(RichBool("deleteAndRefill", defaults.deleteAndRefill,
                               "Delete and refill stubborn vertices",
                               "A vertex that keeps a small angle after the moves is removed and its hole "
                               "retriangulated (default on)."));
}
void AddObtuseThresholds(RichParameterList& parameters) {
  const molremesh::ObtuseReduction<molremesh::MeshD>::Params defaults;
  const char* names[3] = {"obtuseThreshold1", "obtuseThreshold2", "obtuseThreshold3"};
  for (int i = 0; i < 3; ++i)
    parameters.addParam(RichFloat(
        names[i], float(defaults.thresholdsDeg[std::size_t(i)]),
        QString("Largest angle, step %1 (°)").arg(i + 1),
        "Vertices are moved until no angle exceeds 110°, then 100°, then 90° (the defaults of the three "
        "steps); 180 skips a step. Comes after the 120° bound of the first steps. Paper: obtuse "
        "thresholds."));
  parameters.addParam(RichInt("translationIterations", defaults.iterationsPerThreshold,
                              "Vertex moves per step",
                              "Rounds of vertex moves for each of the three steps. Default 20 (the paper's "
                              "translation iterations)."));
}
void AddObtuseParameters(RichParameterList& parameters) {
  const molremesh::ObtuseReduction<molremesh::MeshD>::Params defaults;
  AddMinAngleParameter(parameters);
  AddObtuseThresholds(parameters);
  parameters.addParam(RichBool("pentagonInsertion", defaults.pentagonInsertion,
                               "Refill pentagons around obtuse triangles",
                               "After the moves, an obtuse triangle and its two neighbours across its "
                               "longest edges are refilled around one new vertex (default on). Paper: "
                               "pentagon point insertion."));
  parameters.addParam(RichFloat("pentagonNormalAngle", float(defaults.pentagonNormalDeg),
                                "Pentagon flatness (°)",
                                "The three triangles of a pentagon may differ in direction by at most this "
                                "angle; keeps the refill off sharp folds."));
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
    return "Colors the triangles the remeshing is meant to remove, in colors told apart with color-blind "
           "vision: <font color=#d55e00><b>vermillion</b></font> obtuse (an angle at or above the obtuse "
           "angle), "
           "<font color=#0072b2><b>blue</b></font> an angle below the small angle, <font "
           "color=#cc79a7><b>reddish purple</b></font> both, light gray the rest; the view shows face colors "
           "right away. Irregular vertices (interior valence not 5, 6 or 7) get their own colors in the "
           "per-vertex color, <font color=#009e73><b>bluish green</b></font> below 5 and <font "
           "color=#c8b400><b>yellow</b></font> above 7 (Color &gt; Vert in the layer render settings shows "
           "them). The "
           "log "
           "gives the legend with the counts. Per-face quality = the smallest angle (degrees), per-vertex "
           "quality = the valence. Save with vertex/face color and quality (meshlabserver -m vc fc vq fq) to "
           "keep them.";
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
           "stage with its time. The result goes to a new layer (the input kept, hidden) unless that is "
           "turned off; if a stage fails, the document is left as it was.";
  }
  return QString();
}

MeshFilterInterface::FilterClass FilterMolRemeshPlugin::getClass(QAction* action) {
  switch (ID(action)) {
  case FP_QUALITY_REPORT:
    // "Quality Measure and Computations", where MeshLab users look for measures.
    return MeshFilterInterface::Measure;
  case FP_COLOR_BAD_ELEMENTS:
    // Quality: the same menu; FaceColoring: MeshLab draws the face colors after the filter. Not
    // VertexColoring, which would make the vertex colors win (see postCondition).
    return FilterClass(MeshFilterInterface::Quality | MeshFilterInterface::FaceColoring);
  default:
    return MeshFilterInterface::Remeshing;
  }
}

MeshFilterInterface::FILTER_ARITY FilterMolRemeshPlugin::filterArity(QAction*) const {
  return SINGLE_MESH;
}

int FilterMolRemeshPlugin::getPreConditions(QAction*) const {
  return MeshModel::MM_FACENUMBER;
}

int FilterMolRemeshPlugin::getRequirements(QAction* action) {
  // MeshLab enables these before it notes the layer's attributes, so the vertex colors the
  // coloring writes are not a change it switches the view to: the view shows the face classes.
  if (ID(action) == FP_COLOR_BAD_ELEMENTS) return MeshModel::MM_VERTCOLOR | MeshModel::MM_VERTQUALITY;
  return MeshModel::MM_NONE;
}

int FilterMolRemeshPlugin::postCondition(QAction* action) const {
  switch (ID(action)) {
  case FP_QUALITY_REPORT:
    return MeshModel::MM_NONE;
  case FP_COLOR_BAD_ELEMENTS:
    // Vertex colors are written too but left out: MeshLab's view follows the attributes a filter
    // reports, and vertex color outranks face color there.
    return MeshModel::MM_FACECOLOR | MeshModel::MM_VERTQUALITY | MeshModel::MM_FACEQUALITY;
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

void FilterMolRemeshPlugin::initParameterSet(QAction* action, MeshModel& m, RichParameterList& parameters) {
  switch (ID(action)) {
  case FP_QUALITY_REPORT:
    parameters.addParam(RichBool("selfIntersections", true, "Count self-intersections",
                                 "Count pairs of triangles that cross each other (the slowest figure: "
                                 "seconds on a million faces). Default on."));
    break;
  case FP_COLOR_BAD_ELEMENTS: {
    const molremesh::BadElementColoring<CMeshO>::Params defaults;
    parameters.addParam(RichFloat("smallAngle", float(defaults.smallAngle), "Small angle (°)",
                                  "Triangles with an angle below this are blue (reddish purple if also "
                                  "obtuse). Default 30°, the remeshing's smallest angle."));
    parameters.addParam(RichFloat("obtuseAngle", float(defaults.obtuseAngle), "Obtuse from (°)",
                                  "Triangles whose largest angle is at or above this are vermillion. "
                                  "Default 90°; 120° shows what the first steps leave."));
    break;
  }
  case FP_CLEAN_RAW_MESH:
    AddCleanParameters(parameters);
    AddNewLayerParameter(parameters);
    break;
  case FP_CVT_INITIALIZATION: {
    const molremesh::CvtInitialization<molremesh::MeshD>::Params defaults;
    parameters.addParam(RichInt("iterations", defaults.iterations, "Spacing iterations",
                                "Rounds that even out the spacing of the vertices over the surface. Default "
                                "42; more gives rounder triangles and takes longer. Paper: Lloyd iterations "
                                "of the centroidal Voronoi tessellation (CVT)."));
    AddTargetLengthParameter(parameters, m, "Length the new triangles' edges aim at.");
    parameters.addParam(RichInt("targetVertexCount", 0, "Number of vertices (0 = from edge length)",
                                "If above 0, the number of vertices wanted; it overrides the edge length."));
    AddThreadsParameter(parameters);
    AddMemoryLimitParameter(parameters);
    AddNewLayerParameter(parameters);
    break;
  }
  case FP_PATCHWISE_RAR: {
    const molremesh::PatchwiseRemeshing<molremesh::MeshD>::Params defaults;
    parameters.addParam(RichInt("patchCount", 0, "Number of patches (0 = automatic)",
                                "The surface is cut into random patches remeshed in parallel, their borders "
                                "fixed, then the borders are remeshed; 0 = one per 4000 faces. Paper: random "
                                "segmentation."));
    AddSeedParameter(parameters);
    parameters.addParam(
        RichInt("rarIterations", defaults.rar.iterations, "Remeshing rounds per patch",
                QString("Rounds of splitting, collapsing, flipping and relaxing edges in each "
                        "patch. Default %1. Paper: iterations of real-time adaptive remeshing "
                        "(Dunyach et al. 2013).")
                    .arg(defaults.rar.iterations)));
    AddTargetLengthParameter(parameters, m, "Edge length on flat parts; curved parts get shorter edges.");
    parameters.addParam(RichFloat("approximationTolerance", float(defaults.rar.approximationTolerance),
                                  "Curvature detail (× edge length)",
                                  "Largest gap allowed between an edge and the curved surface, as a fraction "
                                  "of the edge length; smaller gives shorter edges where the surface bends. "
                                  "Paper: approximation tolerance."));
    parameters.addParam(RichFloat("minLengthFactor", float(defaults.rar.minLengthFactor),
                                  "Shortest edge (× edge length)",
                                  "Lower bound of the curvature-adapted edge length."));
    parameters.addParam(RichFloat("maxLengthFactor", float(defaults.rar.maxLengthFactor),
                                  "Longest edge (× edge length)",
                                  "Upper bound of the curvature-adapted edge length."));
    AddThreadsParameter(parameters);
    AddMemoryLimitParameter(parameters);
    AddNewLayerParameter(parameters);
    break;
  }
  case FP_VALENCE_OPTIMIZATION:
    AddValenceParameters(parameters);
    AddTargetLengthParameter(parameters, m, "Scale of the tolerances of the edits.");
    AddThreadsParameter(parameters);
    AddNewLayerParameter(parameters);
    break;
  case FP_REMOVE_SMALL_ANGLES:
    AddSmallAngleParameters(parameters);
    AddTargetLengthParameter(parameters, m, "Scale of the tolerances of the edits.");
    AddThreadsParameter(parameters);
    AddNewLayerParameter(parameters);
    break;
  case FP_REDUCE_OBTUSE:
    AddObtuseParameters(parameters);
    AddTargetLengthParameter(parameters, m, "Scale of the tolerances of the edits.");
    AddThreadsParameter(parameters);
    AddNewLayerParameter(parameters);
    break;
  case FP_LOCAL_SMOOTHING:
    AddMinAngleParameter(parameters);
    AddRoundsParameter(parameters, "smoothIterations",
                       molremesh::LocalSmoothing<molremesh::MeshD>::Params().iterations);
    AddTargetLengthParameter(parameters, m, "Scale of the tolerances of the edits.");
    AddThreadsParameter(parameters);
    AddNewLayerParameter(parameters);
    break;
  case FP_FULL_PIPELINE: {
    // The settings a user changes; the others, at the paper's values, are in the single-step
    // filters, so this dialog fits on the screen.
    const Pipeline::Params defaults;
    AddTargetLengthParameter(parameters, m,
                             "Length the triangle edges aim at; half the length gives about four times "
                             "the triangles.");
    AddMinAngleParameter(parameters);
    AddMaxAngleParameter(parameters, float(defaults.valence.maxAngleDeg));
    parameters.addParam(RichFloat(
        "surfaceLift", float(defaults.reference.phongAlpha), "Follow the curved surface (0-1)",
        "How far new vertices go from the input's flat triangles toward the smooth surface through its "
        "vertices: 0 = on the triangles, 1 = all the way (at most 0.05 edge lengths, none at creases). "
        "Default 0.5. Paper: projection onto the input; here toward its Phong surface (CLI "
        "--surface-lift)."));
    AddSeedParameter(parameters);
    AddThreadsParameter(parameters);
    AddMemoryLimitParameter(parameters);
    AddNewLayerParameter(parameters);
    // Offered only when the layer has selected faces: there is nothing to restrict to otherwise.
    if (vcg::tri::UpdateSelection<CMeshO>::FaceCount(m.cm) > 0)
      parameters.addParam(RichBool(
          "regionOnly", false, "Remesh only selected faces",
          "On: the stages run on the selected faces only (clean, CVT and segmentation are skipped); every "
          "other face and the selection's border stay exactly as they are, the new faces are added last "
          "and selected (CLI --region)."));
    break;
  }
  case FP_RANDOM_SEGMENTATION: {
    const molremesh::RandomSegmentation<CMeshO>::Params defaults;
    parameters.addParam(RichInt("patchCount", defaults.patchCount, "Number of patches (0 = automatic)",
                                "Random patches grown from random triangles; 0 = one per 4000 faces."));
    parameters.addParam(RichInt("seed", int(defaults.seed), "Random seed",
                                "Same mesh and seed give the same patches (and the same as in Patch-wise "
                                "Adaptive Remeshing)."));
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

  using molremesh::PipelineStage;
  switch (ID(action)) {
  case FP_QUALITY_REPORT:
    return qualityReport(*mm, parameters);
  case FP_COLOR_BAD_ELEMENTS:
    return colorBadElements(*mm, parameters);
  case FP_RANDOM_SEGMENTATION:
    return randomSegmentation(*mm, parameters);
  case FP_CLEAN_RAW_MESH:
    return runStages(md, *mm, {int(PipelineStage::Clean)}, parameters, cb, "cleaned");
  case FP_CVT_INITIALIZATION:
    return runStages(md, *mm, {int(PipelineStage::Cvt)}, parameters, cb, "CVT");
  case FP_PATCHWISE_RAR:
    return runStages(md, *mm, {int(PipelineStage::Segment), int(PipelineStage::Rar)}, parameters, cb,
                     "adaptive remesh");
  case FP_VALENCE_OPTIMIZATION:
    return runStages(md, *mm, {int(PipelineStage::Valence)}, parameters, cb, "valence optimized");
  case FP_REMOVE_SMALL_ANGLES:
    return runStages(md, *mm, {int(PipelineStage::Small)}, parameters, cb, "small angles removed");
  case FP_REDUCE_OBTUSE:
    return runStages(md, *mm, {int(PipelineStage::Obtuse)}, parameters, cb, "obtuse reduced");
  case FP_LOCAL_SMOOTHING:
    return runStages(md, *mm, {int(PipelineStage::Smooth)}, parameters, cb, "smoothed");
  case FP_FULL_PIPELINE: {
    std::vector<int> all;
    for (const auto& info : molremesh::PipelineStages()) all.push_back(int(info.stage));
    return runStages(md, *mm, all, parameters, cb, "remeshed");
  }
  }
  return fail("unknown filter");
}

bool FilterMolRemeshPlugin::RichLog() {
  // MeshLab's GUI names its application "MeshLab..." and shows the log as rich text; meshlabserver
  // (and any other host) keeps the executable's name and prints the entries as they are.
  return QCoreApplication::applicationName().startsWith(MeshLabApplication::appName());
}

void FilterMolRemeshPlugin::logText(const std::string& text) {
  if (RichLog())
    Log("%s", molremesh::PreformattedHtml(text).c_str());
  else
    LogLines([this](const std::string& line) { Log("%s", line.c_str()); }, text);
}

bool FilterMolRemeshPlugin::qualityReport(MeshModel& mm, const RichParameterList& parameters) {
  molremesh::MeshQuality<CMeshO>::Params params;
  params.computeSelfIntersections = parameters.getBool("selfIntersections");
  const molremesh::QualityReport report = molremesh::MeshQuality<CMeshO>::Compute(mm.cm, params);
  Log("Molecular Remesh quality report of %s", qUtf8Printable(mm.shortName()));
  logText(molremesh::FormatQualityTable(report, "value"));
  Log("%s", ("valence histogram (interior vertices): " + molremesh::FormatValenceHistogram(report)).c_str());
  return true;
}

bool FilterMolRemeshPlugin::colorBadElements(MeshModel& mm, const RichParameterList& parameters) {
  using Coloring = molremesh::BadElementColoring<CMeshO>;
  Coloring::Params params;
  params.smallAngle = parameters.getFloat("smallAngle");
  params.obtuseAngle = parameters.getFloat("obtuseAngle");
  params.palette = Coloring::ColorBlindSafePalette();
  if (!(params.smallAngle >= 0 && params.smallAngle <= 60))
    return fail("Small angle must be between 0 and 60 degrees");
  if (!(params.obtuseAngle >= 60 && params.obtuseAngle <= 180))
    return fail("Obtuse angle must be between 60 and 180 degrees");

  mm.updateDataMask(MeshModel::MM_VERTCOLOR | MeshModel::MM_FACECOLOR | MeshModel::MM_VERTQUALITY |
                    MeshModel::MM_FACEQUALITY);
  const molremesh::BadElementCounts counts = Coloring::Do(mm.cm, params);
  const molremesh::BadElementPalette& c = params.palette;
  auto entry = [](const vcg::Color4b& color, const std::string& label, std::size_t count) {
    return molremesh::LegendEntry{color[0], color[1], color[2], label, count};
  };
  char obtuse[64], small[64];
  std::snprintf(obtuse, sizeof obtuse, "obtuse faces (largest angle >= %g deg)", params.obtuseAngle);
  std::snprintf(small, sizeof small, "small-angle faces (an angle < %g deg)", params.smallAngle);
  const std::size_t obtuseOnly = counts.obtuseFaces - counts.obtuseAndSmallFaces;
  const std::size_t smallOnly = counts.smallAngleFaces - counts.obtuseAndSmallFaces;
  const std::vector<molremesh::LegendEntry> faces = {
      entry(c.obtuseFace, obtuse, obtuseOnly), entry(c.smallAngleFace, small, smallOnly),
      entry(c.obtuseAndSmallFace, "faces both obtuse and small-angle", counts.obtuseAndSmallFaces),
      entry(c.neutral, "other faces",
            std::size_t(mm.cm.fn) - obtuseOnly - smallOnly - counts.obtuseAndSmallFaces)};
  const std::vector<molremesh::LegendEntry> vertices = {
      entry(c.lowValenceVertex, "interior vertices of valence below 5", counts.lowValenceVertices),
      entry(c.highValenceVertex, "interior vertices of valence above 7", counts.highValenceVertices)};
  if (RichLog()) {
    Log("%s", molremesh::FormatColorLegendHtml("Face colors (shown now)", faces).c_str());
    Log("%s",
        molremesh::FormatColorLegendHtml("Vertex colors (layer render settings: Color > Vert)", vertices)
            .c_str());
  } else {
    Log("Irregular vertices: %zu (valence below 5, bluish green: %zu; above 7, yellow: %zu)",
        counts.irregularVertices, counts.lowValenceVertices, counts.highValenceVertices);
    Log("Obtuse faces (vermillion or reddish purple): %zu", counts.obtuseFaces);
    Log("Small-angle faces (blue or reddish purple): %zu", counts.smallAngleFaces);
    Log("Obtuse and small-angle faces (reddish purple): %zu", counts.obtuseAndSmallFaces);
  }
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

namespace {
/// Reads the parameters a filter declares into the pipeline's Params; "" or why they are invalid.
std::string ReadStageParameters(const RichParameterList& parameters, Pipeline::Params& params) {
  // Each filter declares only its own parameters; read the ones present.
  auto has = [&](const char* name) { return parameters.hasParameter(name); };
  if (has("mergeTolerance")) params.clean.mergeTolerance = parameters.getFloat("mergeTolerance");
  if (has("maxHoleEdges")) params.clean.maxHoleEdges = parameters.getInt("maxHoleEdges");
  if (has("minComponentPercent"))
    params.clean.minComponentFraction = parameters.getFloat("minComponentPercent") / 100.0;
  if (has("repairTangles")) params.clean.repairTangles = parameters.getBool("repairTangles");
  if (has("iterations")) params.cvt.iterations = parameters.getInt("iterations");
  // getFloat reads both the absolute/percentage value of the dialog and a plain float of a script.
  if (has("targetLength")) params.targetEdgeLength = parameters.getFloat("targetLength");
  if (has("targetVertexCount"))
    params.cvt.targetVertexCount = std::size_t(std::max(0, parameters.getInt("targetVertexCount")));
  if (has("threads")) params.threads = std::max(0, parameters.getInt("threads"));
  if (has("memoryLimit")) params.memoryLimitMB = parameters.getFloat("memoryLimit");
  if (has("seed")) params.seed = std::uint64_t(parameters.getInt("seed"));
  if (has("patchCount")) params.segment.patchCount = std::max(0, parameters.getInt("patchCount"));
  if (has("rarIterations")) params.rar.rar.iterations = parameters.getInt("rarIterations");
  if (has("approximationTolerance"))
    params.rar.rar.approximationTolerance = parameters.getFloat("approximationTolerance");
  if (has("minLengthFactor")) params.rar.rar.minLengthFactor = parameters.getFloat("minLengthFactor");
  if (has("maxLengthFactor")) params.rar.rar.maxLengthFactor = parameters.getFloat("maxLengthFactor");
  if (has("surfaceLift")) {
    const double lift = parameters.getFloat("surfaceLift");
    if (!(lift >= 0 && lift <= 1)) return "Follow the curved surface must be between 0 and 1";
    params.reference.phongAlpha = lift;
  }
  if (has("minAngle")) {
    const double a = parameters.getFloat("minAngle");
    if (!(a >= 0 && a < 60)) return "Smallest angle must be at least 0 and below 60 degrees";
    params.SetMinAngle(a);
  }
  if (has("maxAngle")) {
    const double a = parameters.getFloat("maxAngle");
    if (!(a > 60 && a <= 180)) return "Largest angle must be above 60 and at most 180 degrees";
    params.SetMaxAngle(a);
  }
  if (has("areaFactor")) params.SetValenceAreaFactor(parameters.getFloat("areaFactor"));
  if (has("rounds")) params.valence.rounds = parameters.getInt("rounds");
  if (has("collapseAngle")) params.small.collapseAngleDeg = parameters.getFloat("collapseAngle");
  if (has("smallIterations")) params.small.maxIterations = parameters.getInt("smallIterations");
  if (has("deleteAndRefill")) params.small.deleteAndRefill = parameters.getBool("deleteAndRefill");
  if (has("obtuseThreshold1")) {
    std::vector<double> thresholds;
    for (const char* name : {"obtuseThreshold1", "obtuseThreshold2", "obtuseThreshold3"}) {
      const double t = parameters.getFloat(name);
      if (!(t >= 60 && t <= 180))
        return "The obtuse steps' largest angles must be between 60 and 180 degrees";
      if (t < 180) thresholds.push_back(t);
    }
    params.SetObtuseThresholds(thresholds);
  }
  if (has("smoothIterations")) params.smooth.iterations = parameters.getInt("smoothIterations");
  if (has("translationIterations"))
    params.obtuse.iterationsPerThreshold = parameters.getInt("translationIterations");
  if (has("pentagonInsertion")) params.obtuse.pentagonInsertion = parameters.getBool("pentagonInsertion");
  if (has("pentagonNormalAngle"))
    params.obtuse.pentagonNormalDeg = parameters.getFloat("pentagonNormalAngle");
  if (params.valence.areaFactor < 0) return "Largest hole must be 0 or more";
  if (params.valence.rounds < 0 || params.small.maxIterations < 0 || params.obtuse.iterationsPerThreshold < 0)
    return "Rounds and iteration counts must be 0 or more";
  if (params.cvt.iterations < 0) return "Spacing iterations must be 0 or more";
  if (!(params.targetEdgeLength >= 0)) return "Edge length must be 0 (automatic) or more";
  return {};
}
} // namespace

namespace {
/// MeshLab's progress bar over a whole run: each stage gets a share of the bar by its usual cost
/// (its time on a large mesh: CVT and RAR take most of it), moves
/// through it with the CVT and RAR steps, and the label names the stage and its step ("cvt (2/9):
/// Lloyd iteration 17/42"). MeshLab redraws only when the percentage changes.
class RunProgress {
public:
  RunProgress(vcg::CallBackPos* cb, const std::vector<molremesh::PipelineStage>& stages) : cb_(cb) {
    double total = 0;
    for (auto stage : stages) {
      names_.push_back(molremesh::StageName(stage));
      starts_.push_back(total);
      total += Weight(stage);
    }
    for (double& start : starts_) start /= total;
    starts_.push_back(1.0);
  }
  /// The pipeline's "stage <name> ..." log line starts a stage.
  void OnLogLine(const std::string& line) {
    for (std::size_t i = 0; i < names_.size(); ++i)
      if (line == "stage " + names_[i] + " ...") {
        stage_ = i;
        Step(0.0, "");
      }
  }
  /// fraction of the current stage done, and its step.
  void Step(double fraction, const std::string& step) {
    if (cb_ == nullptr || names_.empty()) return;
    const double share = starts_[stage_ + 1] - starts_[stage_];
    const int percent = int(100 * (starts_[stage_] + share * std::clamp(fraction, 0.0, 1.0)));
    const std::string label = names_[stage_] + " (" + std::to_string(stage_ + 1) + "/" +
                              std::to_string(names_.size()) + ")" + (step.empty() ? "" : ": " + step);
    cb_(percent, label.c_str());
  }

private:
  /// Seconds of the stage in the full pipeline on the 378k-face 1HPV surface (on 2 busy cores).
  static double Weight(molremesh::PipelineStage stage) {
    using molremesh::PipelineStage;
    switch (stage) {
    case PipelineStage::Clean:
      return 7.5;
    case PipelineStage::Cvt:
      return 48;
    case PipelineStage::Valence:
      return 3;
    case PipelineStage::Segment:
      return 0.6;
    case PipelineStage::Rar:
      return 26;
    case PipelineStage::Small:
      return 0.6;
    case PipelineStage::Obtuse:
      return 2.5;
    default:
      return 2; // smooth, polish
    }
  }
  vcg::CallBackPos* cb_;
  std::vector<std::string> names_;
  std::vector<double> starts_; ///< share of the bar before each stage, then 1
  std::size_t stage_ = 0;
};
} // namespace

void FilterMolRemeshPlugin::logRun(const molremesh::PipelineResult& result) {
  std::vector<molremesh::NamedReport> columns{{"before", result.input}};
  std::vector<double> seconds{0.0};
  for (const auto& stage : result.stages) {
    columns.emplace_back(stage.name, stage.after);
    seconds.push_back(stage.seconds);
  }
  if (RichLog()) {
    // The log pane is narrow: each stage's summary as one paragraph, the full table before and
    // after only, and the per-stage figures in a short table.
    for (const auto& stage : result.stages) {
      std::string paragraph;
      std::istringstream lines(stage.summary);
      for (std::string line; std::getline(lines, line);)
        if (!line.empty()) paragraph += (paragraph.empty() ? "" : "; ") + line;
      Log("%s",
          ("<b>" + molremesh::HtmlEscape(stage.name) + "</b>: " + molremesh::HtmlEscape(paragraph)).c_str());
    }
    std::vector<molremesh::NamedReport> beforeAfter{columns.front()};
    if (columns.size() > 1) beforeAfter.emplace_back("after", columns.back().second);
    Log("%s", molremesh::FormatQualityTableHtml(beforeAfter).c_str());
    Log("%s", molremesh::PreformattedHtml(molremesh::FormatStageTable(columns, seconds)).c_str());
  } else {
    for (const auto& stage : result.stages) logText(stage.summary);
    logText(molremesh::FormatQualityTable(columns));
  }
  Log("%s", molremesh::StageTimesLine(result).c_str());
  // The layer takes the result either way (it is better than the input), but never in silence
  // when it misses a promise: the warnings say what and why.
  LogLines([this](const std::string& line) { Log(GLLogStream::WARNING, line.c_str()); },
           result.verdict.Lines("Warning: the result is "));
}

bool FilterMolRemeshPlugin::runStages(MeshDocument& md, MeshModel& mm, const std::vector<int>& stages,
                                      const RichParameterList& parameters, vcg::CallBackPos* cb,
                                      const char* layerSuffix) {
  Pipeline::Params params;
  params.stages.clear();
  for (int stage : stages) params.stages.push_back(molremesh::PipelineStage(stage));
  if (const std::string why = ReadStageParameters(parameters, params); !why.empty())
    return fail(QString::fromStdString(why));
  const bool newLayer = parameters.hasParameter("newLayer") && parameters.getBool("newLayer");

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
  RunProgress progress(cb, params.stages);
  params.cvt.progress = [&progress](double fraction, const std::string& step) {
    progress.Step(fraction, step);
  };
  params.rar.progress = params.cvt.progress;
  molremesh::MeshD work;
  molremesh::CopyTriangles(work, mm.cm);
  std::vector<std::uint8_t> selected; // per face of the result: the remeshed region
  if (parameters.hasParameter("regionOnly") && parameters.getBool("regionOnly")) {
    molremesh::RegionRemeshing<molremesh::MeshD>::Params regionParams;
    regionParams.pipeline = params;
    for (const auto& f : mm.cm.face) // in CopyTriangles' order
      if (!f.IsD()) regionParams.faceMask.push_back(f.IsS() ? 1 : 0);
    const auto region = molremesh::RegionRemeshing<molremesh::MeshD>::Do(work, regionParams);
    if (!region.ok) return fail(QString::fromStdString(region.message));
    Log("%s", region.message.c_str());
    for (const std::string& line : region.stageSummaries) Log("%s", line.c_str());
    selected = region.faceMask;
  } else {
    const molremesh::PipelineResult result =
        Pipeline::Do(work, params, [this, &progress](const std::string& line) {
          progress.OnLogLine(line);
          Log("%s", line.c_str());
        });
    if (!result.ok) return fail(QString::fromStdString(result.message));
    logRun(result);
  }

  MeshModel* target = &mm;
  if (newLayer) {
    // The input layer is kept as it was, only hidden so that the result is seen.
    const QString name = QFileInfo(mm.label()).completeBaseName() + " " + layerSuffix;
    // Hidden before the new layer is added: MeshLab's views take the layers' visibility when the
    // document's layers change.
    mm.visible = false;
    target = md.addNewMesh("", name, true);
    target->cm.Tr = mm.cm.Tr;
    Log("%s", qUtf8Printable("Result in the new layer \"" + target->label() + "\"; \"" + mm.label() +
                             "\" is unchanged (hidden)"));
  } else {
    // In place: old per-element colors and qualities described the old triangles, so they are
    // dropped with them.
    mm.cm.Clear();
    mm.clearDataMask(MeshModel::MM_VERTCOLOR | MeshModel::MM_FACECOLOR | MeshModel::MM_VERTQUALITY |
                     MeshModel::MM_FACEQUALITY | MeshModel::MM_FACEFACETOPO | MeshModel::MM_VERTFACETOPO |
                     MeshModel::MM_WEDGTEXCOORD | MeshModel::MM_VERTTEXCOORD);
  }
  molremesh::CopyTriangles(target->cm, work);
  for (std::size_t fi = 0; fi < selected.size() && fi < target->cm.face.size(); ++fi)
    if (selected[fi]) target->cm.face[fi].SetS();
  target->UpdateBoxAndNormals();
  return true;
}

MESHLAB_PLUGIN_NAME_EXPORTER(FilterMolRemeshPlugin)

// The molremesh filters' descriptions and parameters, shared by the MeshLab 2020.09 and 2023.12
// adapters.
#include "filter_catalog.h"

#include <vcg_ext/quality/bad_element_coloring.h>
#include <vcg_ext/structure/atoms.h>
#include <vcg_ext/volume/molecular_surface.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace molremesh::filters {

const std::vector<FilterSpec>& Filters() {
  static const std::vector<FilterSpec> filters = {
      {FilterId::QualityReport,
       "Molecular Remesh: Quality Report",
       "Logs the mesh quality figures of Khan et al. 2020 (Qmin, Qavg, min/max angle, aspect ratio, "
       "V567 and valence histogram, % of triangles with an angle below 30 deg / obtuse / above 120 deg, "
       "area, volume) and the validity figures molremesh keeps (Euler characteristic, genus, components, "
       "boundary and non-manifold edges and vertices, degenerate faces, self-intersecting face pairs). "
       "The mesh is not changed.",
       FilterKind::Measure,
       {},
       ""},
      {FilterId::ColorBadElements,
       "Molecular Remesh: Color Bad Elements",
       "Colors the triangles the remeshing is meant to remove, in colors told apart with color-blind "
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
       "keep them.",
       FilterKind::Coloring,
       {},
       ""},
      {FilterId::CleanRawMesh,
       "Molecular Remesh: Clean Raw Mesh",
       "Stage 0 of molecular remeshing. Merges coincident vertices, removes unreferenced vertices, "
       "duplicate "
       "and zero-area faces, makes non-manifold edges and vertices manifold, orients every component "
       "coherently (closed ones outward), repairs small self-intersecting tangles, closes small holes "
       "and "
       "removes components below a fraction of the faces. Every action is counted in the log; a vertex "
       "that is already fine is never moved.",
       FilterKind::Stages,
       {PipelineStage::Clean},
       "cleaned"},
      {FilterId::CvtInitialization,
       "Molecular Remesh: CVT Initialization",
       "Stage 1 of Khan et al. 2020: a centroidal Voronoi tessellation restricted to the surface and its "
       "dual "
       "triangulation, by Lloyd relaxation (42 iterations by default) of a triangulation whose "
       "connectivity "
       "only changes through guarded local operations, so the result stays 2-manifold, keeps every "
       "component's genus, never connects sheets across narrow gaps and has no self-intersection. Needs "
       "a "
       "clean 2-manifold input (run Clean Raw Mesh first).",
       FilterKind::Stages,
       {PipelineStage::Cvt},
       "CVT"},
      {FilterId::RandomSegmentation,
       "Molecular Remesh: Random Segmentation",
       "Stage 3 of Khan et al. 2020: splits the surface into random patches grown from seeded faces "
       "(their "
       "borders are locked during patch-wise remeshing). Colors the faces by patch and stores the patch "
       "id "
       "in the per-face attribute 'molremesh_patch'. Geometry is not changed.",
       FilterKind::Segmentation,
       {},
       ""},
      {FilterId::PatchwiseRar,
       "Molecular Remesh: Patch-wise Adaptive Remeshing",
       "Stage 3 of Khan et al. 2020: random segmentation (same seed and patch count as the Random "
       "Segmentation filter give the same patches), then each patch remeshed on its own, in parallel, "
       "with "
       "real-time adaptive remeshing (Dunyach et al. 2013: curvature-adapted target length, split > 4/3 "
       "L, "
       "collapse < 4/5 L, valence flips, tangential relaxation, projection onto the input) with its "
       "border "
       "locked; then the strip around the borders is remeshed. Every edit is guarded: no fold, no "
       "self-intersection, no new small angle. Needs a clean 2-manifold input.",
       FilterKind::Stages,
       {PipelineStage::Segment, PipelineStage::Rar},
       "adaptive remesh"},
      {FilterId::ValenceOptimization,
       "Molecular Remesh: Valence Optimization",
       "Stage 2 of Khan et al. 2020: makes vertices valence 5, 6 or 7. Guarded edge flips and collapses "
       "that lower the valence deviation, then two-phase removal of irregular vertices (their star, then "
       "irregular vertices on the hole's rim while the hole stays below the area factor times the mean "
       "triangle area) and refilling with 0, 1 or 2 new vertices placed in the feasible region. No edit "
       "leaves more faces with an angle below the min angle (or above the max angle) than it removed. "
       "Needs a clean 2-manifold input (run Clean Raw Mesh and CVT Initialization first).",
       FilterKind::Stages,
       {PipelineStage::Valence},
       "valence optimized"},
      {FilterId::RemoveSmallAngles,
       "Molecular Remesh: Remove Small Angles",
       "Stage 4 of Khan et al. 2020: removes angles below the min angle: collapses of short edges "
       "opposite angles below the collapse angle, flips, constrained vertex translation (Laplacian "
       "position, else nearby positions), deletion and refilling of vertices that keep a small angle; "
       "repeated up to the iteration cap. Every edit is guarded (no fold, no self-intersection, no new "
       "bad angle). Needs a clean 2-manifold input.",
       FilterKind::Stages,
       {PipelineStage::Small},
       "small angles removed"},
      {FilterId::ReduceObtuse,
       "Molecular Remesh: Reduce Obtuse Triangles",
       "Stage 5 of Khan et al. 2020: translation of the vertex at each obtuse angle inside a feasible "
       "disc (projected onto the surface) for the max-angle thresholds in turn, then pentagon point "
       "insertion (obtuse triangle + two neighbours across their longest edges, refilled with one "
       "vertex in the feasible region). No edit creates an angle below the min angle. Needs a clean "
       "2-manifold input.",
       FilterKind::Stages,
       {PipelineStage::Obtuse},
       "obtuse reduced"},
      {FilterId::LocalSmoothing,
       "Molecular Remesh: Local Smoothing",
       "Stage 6 of Khan et al. 2020: Laplacian translation and local remeshing of the triangles that are "
       "still obtuse or have a small angle, and their neighbours, accepted only when the worst angle "
       "improves and no small angle appears. Needs a clean 2-manifold input.",
       FilterKind::Stages,
       {PipelineStage::Smooth},
       "smoothed"},
      {FilterId::FullPipeline, "Molecular Remesh: Full Pipeline",
       "All of molecular remeshing in the order of Khan et al. 2020: clean raw mesh, CVT initialization, "
       "valence optimization, random segmentation and patch-wise adaptive remeshing, small-angle "
       "elimination, obtuse reduction, local smoothing, and a final valence pass that may not add an "
       "obtuse "
       "face (polish, beyond the paper). Logs the quality table before, after and per "
       "stage with its time. The result goes to a new layer (the input kept, hidden) unless that is "
       "turned off; if a stage fails, the document is left as it was.",
       FilterKind::Stages, Pipeline::Params().stages, "remeshed"},
      {FilterId::SurfaceFromStructure, "Molecular Remesh: Surface from Structure File",
       "Builds the molecular surface of a PQR, PDB or mmCIF file (.gz too) in a new layer: SES (probe "
       "1.4 &Aring;), SAS, van der Waals or Gaussian, a closed level set with every cavity kept, then "
       "remeshed for TetGen and BEM/FEM solvers (off: the raw surface). Pick the file with the ... button. "
       "Needs no open layer; CLI: molremesh surface.",
       FilterKind::Creation, Pipeline::Params().stages, "surface"},
  };
  return filters;
}

const FilterSpec& Filter(FilterId id) {
  for (const FilterSpec& spec : Filters())
    if (spec.id == id) return spec;
  throw std::out_of_range("molremesh: unknown filter id");
}

double DecimalOf(float value) {
  char text[32];
  const auto written = std::to_chars(text, text + sizeof text, value); // shortest round trip
  double decimal = double(value);
  std::from_chars(text, written.ptr, decimal);
  return decimal;
}

LengthRange LengthRangeOf(double meanEdgeLength, double diagonal) {
  if (!std::isfinite(meanEdgeLength) || meanEdgeLength < 0) meanEdgeLength = 0;
  if (!std::isfinite(diagonal) || diagonal <= 0) diagonal = std::max(1.0, 10 * meanEdgeLength);
  return {meanEdgeLength, diagonal};
}

namespace {
using Type = ParameterSpec::Type;
using List = std::vector<ParameterSpec>;

/// printf-style formatting of one number into a help text.
template <class T>
std::string Format(const char* format, T value) {
  char text[512];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

// Parameter texts: the label says what it is and its unit; the help (MeshLab's tooltip) says what
// it changes, its default, when to change it, and the paper's name for it.
void AddMinAngle(List& list) {
  list.push_back({Type::Float, "minAngle", 30.0, "Smallest angle (°)",
                  "No edit creates a triangle angle below this, and the small-angle step removes every angle "
                  "below it. Default 30°; lower it (25°) for a mesh that keeps failing, above 35° is rarely "
                  "reached. Paper: minimum angle θmin."});
}
/// The early stages' max-angle guard, and how it relates to the obtuse thresholds.
void AddMaxAngle(List& list, double defaultDeg) {
  list.push_back({Type::Float, "maxAngle", defaultDeg, "Largest angle, first steps (°)",
                  "Valence and small-angle fixing never leave an angle above this (default 120°); the obtuse "
                  "step that follows lowers the largest angles further, below 110°, 100° and then 90° (its "
                  "thresholds, in Reduce Obtuse Triangles). Paper: maximum angle θmax."});
}
/// Edge length in Å (the mesh's units), pre-filled by the adapter with the layer's mean edge
/// length, as MeshLab's own isotropic remeshing does.
void AddTargetLength(List& list, const std::string& help) {
  list.push_back({Type::Length, "targetLength", 0.0, "Edge length (Å)",
                  help + " Pre-filled with this mesh's mean edge length; 0 = the mean edge length of the "
                         "input. Paper: target edge length L."});
}
void AddThreads(List& list) {
  list.push_back({Type::Int, "threads", 0, "Threads",
                  "Worker threads; 0 = all cores. The result is the same for any count."});
}
void AddSeed(List& list) {
  list.push_back({Type::Int, "seed", 1, "Random seed",
                  "Same mesh, parameters and seed give the same result on any machine and thread count; "
                  "another seed gives another, equally good remesh. Default 1."});
}
/// For the filters that rebuild the mesh: the result in a new layer (on) or in place (off).
void AddNewLayer(List& list) {
  list.push_back({Type::Bool, "newLayer", 1, "Put the result in a new layer",
                  "On (default): the result becomes a new layer named after this one and this layer is "
                  "kept unchanged (hidden); MeshLab has no undo. Off: this layer is replaced."});
}
/// The clean stage's settings (Clean Raw Mesh).
void AddClean(List& list) {
  const CleanRawMesh<MeshD>::Params defaults;
  list.push_back({Type::Float, "mergeTolerance", defaults.mergeTolerance,
                  "Merge distance (× mean edge length)",
                  "Vertices closer than this fraction of the mean edge length become one. Default 1e-6: only "
                  "coincident vertices (the seams of marching cubes)."});
  list.push_back({Type::Int, "maxHoleEdges", double(defaults.maxHoleEdges), "Largest hole to close (edges)",
                  "Holes whose rim has at most this many edges are filled (default 100); a crack of a raw "
                  "surface has a few, a real opening hundreds."});
  list.push_back({Type::Float, "minComponentPercent", 100 * defaults.minComponentFraction,
                  "Drop pieces below (% of faces)",
                  "Separate pieces with fewer faces than this share are removed (and counted; never the "
                  "largest). Default 0: every piece is kept, cavities included."});
  list.push_back({Type::Bool, "repairTangles", double(defaults.repairTangles), "Repair small tangles",
                  "Remove and refill small self-intersecting or inside-out regions (default on)."});
  list.push_back({Type::Bool, "volumetricRebuild", double(defaults.volumetricRebuild),
                  "Rebuild from a volume",
                  "Rebuild the whole surface from the volume it encloses (voxel half the mean edge) even "
                  "when it has no defect (default off; a surface the repairs leave broken is rebuilt "
                  "anyway). Parts thinner than about the mean edge go (fins, tubes, necks, pinched voids "
                  "that no remesh keeps within the angle bounds) and crevices as narrow are sealed."});
}
/// For the filters that build a new mesh at the target edge length (CVT, RAR, full pipeline).
void AddMemoryLimit(List& list) {
  list.push_back({Type::Float, "memoryLimit", 0.0, "Memory limit (MB)",
                  "The filter refuses to start (the layer untouched) when it would need more memory than "
                  "this; 0 = the memory free when it starts, -1 = no check. Only an edge length far below "
                  "the mesh's makes that many faces."});
}
void AddRounds(List& list, const char* name, int defaultValue) {
  list.push_back({Type::Int, name, double(defaultValue), "Rounds (at most)",
                  Format("Repetitions of the whole step; it stops earlier when a round changes nothing. "
                         "Default %d.",
                         defaultValue)});
}
void AddValence(List& list) {
  const ValenceOptimization<MeshD>::Params defaults;
  AddMinAngle(list);
  AddMaxAngle(list, defaults.maxAngleDeg);
  list.push_back({Type::Float, "areaFactor", defaults.areaFactor, "Largest hole (× mean triangle area)",
                  "Clusters of irregular vertices are cut out together while the hole stays below this many "
                  "mean triangle areas, then refilled. Default 9; larger fixes bigger clusters and changes "
                  "more of the surface. Paper: area factor of the two-phase removal."});
  AddRounds(list, "rounds", defaults.rounds);
}
void AddSmallAngle(List& list) {
  const SmallAngleElimination<MeshD>::Params defaults;
  AddMinAngle(list);
  list.push_back({Type::Float, "collapseAngle", defaults.collapseAngleDeg, "Collapse below (°)",
                  Format("A triangle with an angle below this loses the short edge opposite it (the needle "
                         "disappears). Default %g°.",
                         defaults.collapseAngleDeg)});
  list.push_back({Type::Float, "maxAngle", defaults.maxAngleDeg, "Largest angle (°)",
                  "Moves and refills never leave an angle above this (default 120°; the obtuse step lowers "
                  "it later). Paper: θmax."});
  AddRounds(list, "smallIterations", defaults.maxIterations);
  list.push_back({Type::Bool, "deleteAndRefill", double(defaults.deleteAndRefill),
                  "Delete and refill stubborn vertices",
                  "A vertex that keeps a small angle after the moves is removed and its hole retriangulated "
                  "(default on)."});
}
void AddObtuseThresholds(List& list) {
  const ObtuseReduction<MeshD>::Params defaults;
  const char* names[3] = {"obtuseThreshold1", "obtuseThreshold2", "obtuseThreshold3"};
  for (int i = 0; i < 3; ++i)
    list.push_back(
        {Type::Float, names[i], defaults.thresholdsDeg[std::size_t(i)],
         Format("Largest angle, step %d (°)", i + 1),
         "Vertices are moved until no angle exceeds 110°, then 100°, then 90° (the defaults of the "
         "three steps); 180 skips a step. Comes after the 120° bound of the first steps. Paper: "
         "obtuse thresholds."});
  list.push_back({Type::Int, "translationIterations", double(defaults.iterationsPerThreshold),
                  "Vertex moves per step",
                  "Rounds of vertex moves for each of the three steps. Default 20 (the paper's translation "
                  "iterations)."});
}
void AddObtuse(List& list) {
  const ObtuseReduction<MeshD>::Params defaults;
  AddMinAngle(list);
  AddObtuseThresholds(list);
  list.push_back({Type::Bool, "pentagonInsertion", double(defaults.pentagonInsertion),
                  "Refill pentagons around obtuse triangles",
                  "After the moves, an obtuse triangle and its two neighbours across its longest edges are "
                  "refilled around one new vertex (default on). Paper: pentagon point insertion."});
  list.push_back({Type::Float, "pentagonNormalAngle", defaults.pentagonNormalDeg, "Pentagon flatness (°)",
                  "The three triangles of a pentagon may differ in direction by at most this angle; keeps "
                  "the refill off sharp folds."});
}
const char* const kEditScale = "Scale of the tolerances of the edits.";

List CvtParameters() {
  const CvtInitialization<MeshD>::Params defaults;
  List list;
  list.push_back({Type::Int, "iterations", double(defaults.iterations), "Spacing iterations",
                  "Rounds that even out the spacing of the vertices over the surface. Default 42; more gives "
                  "rounder triangles and takes longer. Paper: Lloyd iterations of the centroidal Voronoi "
                  "tessellation (CVT)."});
  AddTargetLength(list, "Length the new triangles' edges aim at.");
  list.push_back({Type::Int, "targetVertexCount", 0, "Number of vertices (0 = from edge length)",
                  "If above 0, the number of vertices wanted; it overrides the edge length."});
  AddThreads(list);
  AddMemoryLimit(list);
  AddNewLayer(list);
  return list;
}
/// "Remesh only selected faces", offered when the layer has a face selection; what names what runs.
void AddRegionOnly(List& list, const std::string& what) {
  list.push_back({Type::Bool, "regionOnly", 0, "Remesh only selected faces",
                  what + "every other face and the selection's border stay exactly as they are, the new "
                         "faces are added last and selected (CLI --region).",
                  /*needsFaceSelection=*/true});
}
List RarParameters() {
  const PatchwiseRemeshing<MeshD>::Params defaults;
  List list;
  list.push_back(
      {Type::Int, "patchCount", 0, "Number of patches (0 = automatic)",
       "The surface is cut into random patches remeshed in parallel, their borders fixed, then the "
       "borders are remeshed; 0 = one per 4000 faces. Paper: random segmentation."});
  AddSeed(list);
  list.push_back(
      {Type::Int, "rarIterations", double(defaults.rar.iterations), "Remeshing rounds per patch",
       Format("Rounds of splitting, collapsing, flipping and relaxing edges in each patch. Default "
              "%d. Paper: iterations of real-time adaptive remeshing (Dunyach et al. 2013).",
              defaults.rar.iterations)});
  AddTargetLength(list, "Edge length on flat parts; curved parts get shorter edges.");
  list.push_back({Type::Float, "approximationTolerance", defaults.rar.approximationTolerance,
                  "Curvature detail (× edge length)",
                  "Largest gap allowed between an edge and the curved surface, as a fraction of the edge "
                  "length; smaller gives shorter edges where the surface bends. Paper: approximation "
                  "tolerance."});
  list.push_back({Type::Float, "minLengthFactor", defaults.rar.minLengthFactor,
                  "Shortest edge (× edge length)", "Lower bound of the curvature-adapted edge length."});
  list.push_back({Type::Float, "maxLengthFactor", defaults.rar.maxLengthFactor,
                  "Longest edge (× edge length)", "Upper bound of the curvature-adapted edge length."});
  AddThreads(list);
  AddMemoryLimit(list);
  AddNewLayer(list);
  AddRegionOnly(list, "On: the filter runs on the selected faces only; ");
  return list;
}
List FullPipelineParameters() {
  // The settings a user changes; the others, at the paper's values, are in the single-step
  // filters, so this dialog fits on the screen.
  const Pipeline::Params defaults;
  List list;
  AddTargetLength(list, "Edge length on flat parts (curved parts get shorter edges); half the length gives "
                        "about four times the triangles. A remesh run again at its own mean edge length is "
                        "kept as it is.");
  AddMinAngle(list);
  AddMaxAngle(list, defaults.valence.maxAngleDeg);
  list.push_back({Type::Float, "surfaceLift", defaults.reference.phongAlpha,
                  "Follow the curved surface (0-1)",
                  "How far new vertices go from the input's flat triangles toward the smooth surface through "
                  "its vertices: 0 = on the triangles, 1 = all the way (at most 0.05 edge lengths, none at "
                  "creases). Default 0.5. Paper: projection onto the input; here toward its Phong surface "
                  "(CLI --surface-lift)."});
  AddSeed(list);
  AddThreads(list);
  AddMemoryLimit(list);
  AddNewLayer(list);
  AddRegionOnly(list, "On: the stages run on the selected faces only (clean, CVT and segmentation are "
                      "skipped); ");
  return list;
}
List SurfaceParameters() {
  const MolecularSurface<MeshD>::Params defaults;
  const StructureReadOptions read;
  List list;
  list.push_back({Type::File,
                  "structureFile",
                  0,
                  "Structure file",
                  "A .pqr file (its radii are used), .pdb/.ent or .cif/.mmcif (radii by freesasa's ProtOr "
                  "classifier), each also as .gz.",
                  false,
                  {"*.pqr", "*.pdb", "*.ent", "*.cif", "*.mmcif", "*.gz"}});
  list.push_back({Type::Enum,
                  "surfaceType",
                  0,
                  "Surface",
                  "SES: the solvent-excluded surface, where a probe ball rolling on the atoms touches them "
                  "(the molecular surface of solvers). SAS: where the probe's centre can go. Van der Waals: "
                  "the atom balls. Gaussian: a smooth blend of the atoms, like TMSmesh's.",
                  false,
                  {"SES (solvent-excluded)", "SAS (solvent-accessible)", "van der Waals", "Gaussian"}});
  list.push_back({Type::Float, "probeRadius", defaults.probeRadius, "Probe radius (Å)",
                  "Radius of the solvent ball of SES and SAS (default 1.4 Å, a water molecule)."});
  list.push_back({Type::Float, "gridSpacing", 0.0, "Grid spacing (Å, 0 = 0.4 × edge length)",
                  "Voxel edge of the level set: smaller follows the atoms more closely and takes longer "
                  "(memory grows as 1/spacing²). 0 = 0.4 times the edge length (0.4 Å by default, the area "
                  "of a sphere within 0.5 %)."});
  list.push_back({Type::Bool, "keepCavities", double(defaults.keepCavities), "Keep cavities",
                  "Buried voids the probe fits in are part of the SES and stay as their own closed pieces "
                  "(default on); off keeps only the outer surface."});
  list.push_back({Type::Bool, "keepWaters", double(read.keepWaters), "Keep waters",
                  "Crystal waters (HOH, WAT ...) are skipped by default."});
  list.push_back({Type::Bool, "keepHydrogens", double(read.keepHydrogens), "Keep hydrogens",
                  "Hydrogen atoms are skipped by default (PQR files always have them)."});
  list.push_back({Type::Bool, "keepHetatm", double(read.keepHetatm), "Keep HETATM records",
                  "Ligands, ions and cofactors are part of the surface by default."});
  list.push_back({Type::Bool, "remesh", 1, "Remesh for solvers",
                  "On (default): the full pipeline turns the level-set surface into a mesh with every angle "
                  "in [30°, 90°] and regular vertices. Off: the raw level-set surface (slivers included)."});
  list.push_back({Type::Float, "targetLength", 1.0, "Edge length (Å)",
                  "Length the triangle edges of the remeshed surface aim at (default 1 Å); also sets the "
                  "default grid spacing."});
  AddSeed(list);
  AddThreads(list);
  list.push_back({Type::Float, "memoryLimit", 0.0, "Memory limit (MB)",
                  "The filter refuses to start (no layer added) when the surface or its remeshing would "
                  "need more memory than this; 0 = the memory free when it starts, -1 = no check. A large "
                  "complex on a fine grid needs gigabytes."});
  return list;
}
/// The single-step filters that edit a clean mesh: their own settings, then the common ones.
List StepParameters(void (*addOwn)(List&)) {
  List list;
  addOwn(list);
  AddTargetLength(list, kEditScale);
  AddThreads(list);
  AddNewLayer(list);
  AddRegionOnly(list, "On: the filter runs on the selected faces only; ");
  return list;
}
void AddSmoothing(List& list) {
  AddMinAngle(list);
  AddRounds(list, "smoothIterations", LocalSmoothing<MeshD>::Params().iterations);
}
} // namespace

std::vector<ParameterSpec> Parameters(FilterId id) {
  switch (id) {
  case FilterId::QualityReport:
    return {{Type::Bool, "selfIntersections", 1, "Count self-intersections",
             "Count pairs of triangles that cross each other (the slowest figure: seconds on a million "
             "faces). Default on."}};
  case FilterId::ColorBadElements: {
    const BadElementColoring<MeshD>::Params defaults;
    return {{Type::Float, "smallAngle", defaults.smallAngle, "Small angle (°)",
             "Triangles with an angle below this are blue (reddish purple if also obtuse). Default 30°, the "
             "remeshing's smallest angle."},
            {Type::Float, "obtuseAngle", defaults.obtuseAngle, "Obtuse from (°)",
             "Triangles whose largest angle is at or above this are vermillion. Default 90°; 120° shows "
             "what the first steps leave."}};
  }
  case FilterId::CleanRawMesh: {
    List list;
    AddClean(list);
    AddNewLayer(list);
    return list;
  }
  case FilterId::CvtInitialization:
    return CvtParameters();
  case FilterId::PatchwiseRar:
    return RarParameters();
  case FilterId::ValenceOptimization:
    return StepParameters(AddValence);
  case FilterId::RemoveSmallAngles:
    return StepParameters(AddSmallAngle);
  case FilterId::ReduceObtuse:
    return StepParameters(AddObtuse);
  case FilterId::LocalSmoothing:
    return StepParameters(AddSmoothing);
  case FilterId::FullPipeline:
    return FullPipelineParameters();
  case FilterId::SurfaceFromStructure:
    return SurfaceParameters();
  case FilterId::RandomSegmentation: {
    const RandomSegmentation<MeshD>::Params defaults;
    return {{Type::Int, "patchCount", double(defaults.patchCount), "Number of patches (0 = automatic)",
             "Random patches grown from random triangles; 0 = one per 4000 faces."},
            {Type::Int, "seed", double(int(defaults.seed)), "Random seed",
             "Same mesh and seed give the same patches (and the same as in Patch-wise Adaptive "
             "Remeshing)."}};
  }
  }
  return {};
}

std::string ReadStageParameters(const ParameterValues& values, Pipeline::Params& params) {
  // Each filter declares only its own parameters; read the ones present.
  auto has = [&](const char* name) { return values.Has(name); };
  if (has("mergeTolerance")) params.clean.mergeTolerance = values.Float("mergeTolerance");
  if (has("maxHoleEdges")) params.clean.maxHoleEdges = values.Int("maxHoleEdges");
  if (has("minComponentPercent"))
    params.clean.minComponentFraction = values.Float("minComponentPercent") / 100.0;
  if (has("repairTangles")) params.clean.repairTangles = values.Bool("repairTangles");
  if (has("volumetricRebuild")) params.clean.volumetricRebuild = values.Bool("volumetricRebuild");
  if (has("iterations")) params.cvt.iterations = values.Int("iterations");
  if (has("targetLength")) params.targetEdgeLength = values.Float("targetLength");
  if (has("targetVertexCount"))
    params.cvt.targetVertexCount = std::size_t(std::max(0, values.Int("targetVertexCount")));
  if (has("threads")) params.threads = std::max(0, values.Int("threads"));
  if (has("memoryLimit")) params.memoryLimitMB = values.Float("memoryLimit");
  if (has("seed")) params.seed = std::uint64_t(values.Int("seed"));
  if (has("patchCount")) params.segment.patchCount = std::max(0, values.Int("patchCount"));
  if (has("rarIterations")) params.rar.rar.iterations = values.Int("rarIterations");
  if (has("approximationTolerance"))
    params.rar.rar.approximationTolerance = values.Float("approximationTolerance");
  if (has("minLengthFactor")) params.rar.rar.minLengthFactor = values.Float("minLengthFactor");
  if (has("maxLengthFactor")) params.rar.rar.maxLengthFactor = values.Float("maxLengthFactor");
  if (has("surfaceLift")) {
    const double lift = values.Float("surfaceLift");
    if (!(lift >= 0 && lift <= 1)) return "Follow the curved surface must be between 0 and 1";
    params.reference.phongAlpha = lift;
  }
  if (has("minAngle")) {
    const double a = values.Float("minAngle");
    if (!(a >= 0 && a < 60)) return "Smallest angle must be at least 0 and below 60 degrees";
    params.SetMinAngle(a);
  }
  if (has("maxAngle")) {
    const double a = values.Float("maxAngle");
    if (!(a > 60 && a <= 180)) return "Largest angle must be above 60 and at most 180 degrees";
    params.SetMaxAngle(a);
  }
  if (has("areaFactor")) params.SetValenceAreaFactor(values.Float("areaFactor"));
  if (has("rounds")) params.valence.rounds = values.Int("rounds");
  if (has("collapseAngle")) params.small.collapseAngleDeg = values.Float("collapseAngle");
  if (has("smallIterations")) params.small.maxIterations = values.Int("smallIterations");
  if (has("deleteAndRefill")) params.small.deleteAndRefill = values.Bool("deleteAndRefill");
  if (has("obtuseThreshold1")) {
    std::vector<double> thresholds;
    for (const char* name : {"obtuseThreshold1", "obtuseThreshold2", "obtuseThreshold3"}) {
      const double t = values.Float(name);
      if (!(t >= 60 && t <= 180))
        return "The obtuse steps' largest angles must be between 60 and 180 degrees";
      if (t < 180) thresholds.push_back(t);
    }
    params.SetObtuseThresholds(thresholds);
  }
  if (has("smoothIterations")) params.smooth.iterations = values.Int("smoothIterations");
  if (has("translationIterations"))
    params.obtuse.iterationsPerThreshold = values.Int("translationIterations");
  if (has("pentagonInsertion")) params.obtuse.pentagonInsertion = values.Bool("pentagonInsertion");
  if (has("pentagonNormalAngle")) params.obtuse.pentagonNormalDeg = values.Float("pentagonNormalAngle");
  if (params.valence.areaFactor < 0) return "Largest hole must be 0 or more";
  if (params.valence.rounds < 0 || params.small.maxIterations < 0 || params.obtuse.iterationsPerThreshold < 0)
    return "Rounds and iteration counts must be 0 or more";
  if (params.cvt.iterations < 0) return "Spacing iterations must be 0 or more";
  if (!(params.targetEdgeLength >= 0)) return "Edge length must be 0 (automatic) or more";
  return {};
}

} // namespace molremesh::filters

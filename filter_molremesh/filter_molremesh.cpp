#include "filter_molremesh.h"

#include <sstream>
#include <string>

#include <vcg_ext/bad_element_coloring.h>
#include <vcg_ext/input_check.h>
#include <vcg_ext/mesh_quality.h>
#include <vcg_ext/quality_report_format.h>

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
  typeList << FP_QUALITY_REPORT << FP_COLOR_BAD_ELEMENTS;
  for (FilterIDType id : types()) actionList << new QAction(filterName(id), this);
}

QString FilterMolRemeshPlugin::pluginName() const { return kPluginName; }

QString FilterMolRemeshPlugin::filterName(FilterIDType filter) const {
  switch (filter) {
  case FP_QUALITY_REPORT: return "Molecular Remesh: Quality Report";
  case FP_COLOR_BAD_ELEMENTS: return "Molecular Remesh: Color Bad Elements";
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
           "others gray. Save with vertex/face color and quality (meshlabserver -m vc fc vq fq) to keep them.";
  }
  return QString();
}

MeshFilterInterface::FilterClass FilterMolRemeshPlugin::getClass(QAction*) {
  return MeshFilterInterface::Remeshing;
}

MeshFilterInterface::FILTER_ARITY FilterMolRemeshPlugin::filterArity(QAction*) const { return SINGLE_MESH; }

int FilterMolRemeshPlugin::getPreConditions(QAction*) const { return MeshModel::MM_FACENUMBER; }

int FilterMolRemeshPlugin::getRequirements(QAction*) { return MeshModel::MM_NONE; }

int FilterMolRemeshPlugin::postCondition(QAction* action) const {
  switch (ID(action)) {
  case FP_QUALITY_REPORT: return MeshModel::MM_NONE;
  case FP_COLOR_BAD_ELEMENTS:
    return MeshModel::MM_VERTCOLOR | MeshModel::MM_FACECOLOR | MeshModel::MM_VERTQUALITY |
           MeshModel::MM_FACEQUALITY;
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
    parameters.addParam(RichFloat("smallAngle", float(defaults.smallAngle), "Small angle (deg)",
                                  "Faces with an angle below this are colored blue (magenta if also obtuse)."));
    parameters.addParam(RichFloat("obtuseAngle", float(defaults.obtuseAngle), "Obtuse angle (deg)",
                                  "Faces whose largest angle is at or above this are colored red."));
    break;
  }
  }
}

bool FilterMolRemeshPlugin::fail(const QString& message) {
  errorMessage = message;
  Log(GLLogStream::WARNING, qUtf8Printable("Error: " + message));
  return false;
}

bool FilterMolRemeshPlugin::applyFilter(QAction* action, MeshDocument& md, const RichParameterList& parameters,
                                        vcg::CallBackPos*) {
  MeshModel* mm = md.mm();
  if (mm == nullptr) return fail(filterName(ID(action)) + ": there is no current mesh layer");
  // Every precondition is checked before the layer is touched, so a refused layer stays as it was.
  const molremesh::InputCheck check = molremesh::CheckTriangleMeshInput(mm->cm);
  if (!check.ok) return fail(filterName(ID(action)) + ": " + QString::fromStdString(check.message));

  switch (ID(action)) {
  case FP_QUALITY_REPORT: return qualityReport(*mm, parameters);
  case FP_COLOR_BAD_ELEMENTS: return colorBadElements(*mm, parameters);
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

MESHLAB_PLUGIN_NAME_EXPORTER(FilterMolRemeshPlugin)

// The shared runs first: Qt (pulled in by the plugin header) defines `slots` and `signals` as
// macros, which must not reach the vcg_ext templates.
#include "../filter_runs.h"

#include "../host_parameters.h"
#include "filter_molremesh.h"

#include <common/mlapplication.h>
#include <common/mlexception.h>

#include <QCoreApplication>
#include <QFileInfo>

#include <cmath>
#include <string>

namespace {
namespace filters = molremesh::filters;
using filters::FilterId;
using filters::FilterKind;

const int kFilterCount = int(filters::Filters().size());

bool IsFilter(int id) {
  return id >= 0 && id < kFilterCount;
}

FilterId IdOf(int id) {
  return FilterId(id);
}

/// The catalog's parameters as MeshLab 2023.12 RichParameters (Scalarm: double in PyMeshLab); m
/// is the current layer, null for a filter that needs none.
RichParameterList MakeParameters(FilterId id, const MeshModel* m) {
  using Type = filters::ParameterSpec::Type;
  RichParameterList parameters;
  for (const filters::ParameterSpec& p : filters::Parameters(id)) {
    if (p.needsFaceSelection && (m == nullptr || !filters::HasSelectedFace(m->cm))) continue;
    const QString name = QString::fromStdString(p.name);
    const QString label = QString::fromStdString(p.label);
    const QString help = QString::fromStdString(p.help);
    switch (p.type) {
    case Type::Bool:
      parameters.addParam(RichBool(name, p.defaultValue != 0, label, help));
      break;
    case Type::Int:
      parameters.addParam(RichInt(name, int(p.defaultValue), label, help));
      break;
    case Type::Float:
      parameters.addParam(RichFloat(name, Scalarm(p.defaultValue), label, help));
      break;
    case Type::Length: {
      // Absolute and % of the bounding-box diagonal, as MeshLab's own isotropic remeshing.
      const filters::LengthRange range =
          m != nullptr ? filters::LengthRangeOfMesh(m->cm) : filters::LengthRangeOf(0, 1);
      parameters.addParam(RichPercentage(name, Scalarm(range.value), 0, Scalarm(range.max), label, help));
      break;
    }
    case Type::Enum:
      parameters.addParam(
          RichEnum(name, int(p.defaultValue), filters::ToQStringList(p.choices), label, help));
      break;
    case Type::File:
      parameters.addParam(RichFileOpen(name, QString(), filters::ToQStringList(p.choices), label, help));
      break;
    }
  }
  return parameters;
}

/// The quality figures as output values: counts as int, measures as double.
void AddFigures(std::map<std::string, QVariant>& outputs, const molremesh::QualityReport& report,
                const std::string& prefix = "") {
  for (const filters::Figure& figure : filters::QualityFigures(report)) {
    if (figure.count)
      outputs[prefix + figure.name] = QVariant(int(figure.value));
    else
      outputs[prefix + figure.name] = QVariant(figure.value);
  }
}
} // namespace

FilterMolRemeshPlugin::FilterMolRemeshPlugin() {
  for (const filters::FilterSpec& filter : filters::Filters()) typeList.push_back(int(filter.id));
  for (ActionIDType id : types()) actionList.push_back(new QAction(filterName(id), this));
}

QString FilterMolRemeshPlugin::pluginName() const {
  return "FilterMolRemesh";
}

QString FilterMolRemeshPlugin::vendor() const {
  return "molremesh";
}

QString FilterMolRemeshPlugin::filterName(ActionIDType filter) const {
  if (!IsFilter(filter)) return "Molecular Remesh: unknown filter";
  return QString::fromStdString(filters::Filter(IdOf(filter)).name);
}

QString FilterMolRemeshPlugin::filterInfo(ActionIDType filter) const {
  if (!IsFilter(filter)) return QString();
  return QString::fromStdString(filters::Filter(IdOf(filter)).info);
}

FilterPlugin::FilterClass FilterMolRemeshPlugin::getClass(const QAction* action) const {
  switch (filters::Filter(IdOf(ID(action))).kind) {
  case FilterKind::Measure:
    // "Quality Measure and Computations", where MeshLab users look for measures.
    return FilterPlugin::Measure;
  case FilterKind::Coloring:
    // Quality: the same menu; FaceColoring: MeshLab draws the face colors after the filter.
    return FilterClass(FilterPlugin::Quality | FilterPlugin::FaceColoring);
  case FilterKind::Creation:
    // "Create New Mesh Layer": runs without an open layer, the result is a new one.
    return FilterPlugin::MeshCreation;
  default:
    return FilterPlugin::Remeshing;
  }
}

FilterPlugin::FilterArity FilterMolRemeshPlugin::filterArity(const QAction* action) const {
  // NONE: the host runs it without a layer (PyMeshLab on an empty MeshSet).
  if (filters::Filter(IdOf(ID(action))).kind == FilterKind::Creation) return NONE;
  return SINGLE_MESH;
}

int FilterMolRemeshPlugin::getPreConditions(const QAction* action) const {
  if (filters::Filter(IdOf(ID(action))).kind == FilterKind::Creation) return MeshModel::MM_NONE;
  return MeshModel::MM_FACENUMBER;
}

int FilterMolRemeshPlugin::getRequirements(const QAction* action) {
  // Enabled before MeshLab notes the layer's attributes, so the vertex colors the coloring writes
  // are not a change it switches the view to: the view shows the face classes.
  if (IdOf(ID(action)) == FilterId::ColorBadElements)
    return MeshModel::MM_VERTCOLOR | MeshModel::MM_VERTQUALITY;
  return MeshModel::MM_NONE;
}

int FilterMolRemeshPlugin::postCondition(const QAction* action) const {
  switch (filters::Filter(IdOf(ID(action))).kind) {
  case FilterKind::Measure:
    return MeshModel::MM_NONE;
  case FilterKind::Coloring:
    // Vertex colors are written too but left out: MeshLab's view follows the attributes a filter
    // reports, and vertex color outranks face color there.
    return MeshModel::MM_FACECOLOR | MeshModel::MM_VERTQUALITY | MeshModel::MM_FACEQUALITY;
  case FilterKind::Segmentation:
    return MeshModel::MM_FACECOLOR;
  case FilterKind::Stages:
    return static_cast<int>(MeshModel::MM_ALL);
  case FilterKind::Creation: // a new layer; the current one is not touched
    return MeshModel::MM_NONE;
  }
  return MeshModel::MM_NONE;
}

RichParameterList FilterMolRemeshPlugin::initParameterList(const QAction* action, const MeshModel& m) {
  return MakeParameters(IdOf(ID(action)), &m);
}

RichParameterList FilterMolRemeshPlugin::initParameterList(const QAction* action, const MeshDocument& md) {
  return MakeParameters(IdOf(ID(action)), md.mm());
}

void FilterMolRemeshPlugin::fail(const QString& message) const {
  log(GLLogStream::WARNING, qUtf8Printable("Error: " + message));
  throw MLException(message);
}

filters::RunLog FilterMolRemeshPlugin::runLog() const {
  filters::RunLog runLog;
  runLog.info = [this](const std::string& line) { log("%s", line.c_str()); };
  runLog.warning = [this](const std::string& line) { log(GLLogStream::WARNING, "%s", line.c_str()); };
  // MeshLab's GUI names its application "MeshLab..." and shows the log as rich text; PyMeshLab
  // (and any other host) prints the entries as they are.
  runLog.rich = QCoreApplication::instance() != nullptr &&
                QCoreApplication::applicationName().startsWith(MeshLabApplication::appName());
  return runLog;
}

std::map<std::string, QVariant>
FilterMolRemeshPlugin::applyFilter(const QAction* action, const RichParameterList& parameters,
                                   MeshDocument& md, unsigned int& postConditionMask, vcg::CallBackPos* cb) {
  const ActionIDType id = ID(action);
  if (!IsFilter(id)) fail("unknown filter");
  if (filters::Filter(IdOf(id)).kind == FilterKind::Creation) {
    postConditionMask = unsigned(postCondition(action));
    return surfaceFromStructure(md, parameters, cb);
  }
  MeshModel* mm = md.mm();
  if (mm == nullptr) fail(filterName(id) + ": there is no current mesh layer");
  // Every precondition is checked before the layer is touched, so a refused layer stays as it was.
  const molremesh::InputCheck check = molremesh::CheckTriangleMeshInput(mm->cm);
  if (!check.ok) fail(filterName(id) + ": " + QString::fromStdString(check.message));
  postConditionMask = unsigned(postCondition(action));

  const FilterId filter = IdOf(id);
  const filters::ParameterValues values = filters::ReadValues(filter, parameters);
  Outputs outputs;
  switch (filters::Filter(filter).kind) {
  case FilterKind::Measure:
    AddFigures(outputs, filters::RunQualityReport(mm->cm, values, mm->shortName().toStdString(), runLog()));
    return outputs;
  case FilterKind::Coloring: {
    molremesh::BadElementCounts counts;
    const std::string why = filters::RunColorBadElements(
        mm->cm, values, runLog(),
        [mm] {
          mm->updateDataMask(MeshModel::MM_VERTCOLOR | MeshModel::MM_FACECOLOR | MeshModel::MM_VERTQUALITY |
                             MeshModel::MM_FACEQUALITY);
        },
        counts);
    if (!why.empty()) fail(QString::fromStdString(why));
    outputs["irregular_vertices"] = int(counts.irregularVertices);
    outputs["low_valence_vertices"] = int(counts.lowValenceVertices);
    outputs["high_valence_vertices"] = int(counts.highValenceVertices);
    outputs["obtuse_faces"] = int(counts.obtuseFaces);
    outputs["small_angle_faces"] = int(counts.smallAngleFaces);
    outputs["obtuse_and_small_faces"] = int(counts.obtuseAndSmallFaces);
    return outputs;
  }
  case FilterKind::Segmentation: {
    molremesh::SegmentationResult result;
    const std::string why = filters::RunRandomSegmentation(
        mm->cm, values, runLog(),
        [mm] { mm->updateDataMask(MeshModel::MM_FACEFACETOPO | MeshModel::MM_FACECOLOR); }, result);
    if (!why.empty()) fail(QString::fromStdString(why));
    outputs["patches"] = result.patchCount;
    outputs["border_edges"] = int(result.borderEdges);
    outputs["border_vertices"] = int(result.borderVertices);
    return outputs;
  }
  case FilterKind::Stages:
    return runStages(md, *mm, id, parameters, cb);
  case FilterKind::Creation:
    break; // run above
  }
  return outputs;
}

FilterMolRemeshPlugin::Outputs FilterMolRemeshPlugin::runStages(MeshDocument& md, MeshModel& mm,
                                                                ActionIDType id,
                                                                const RichParameterList& parameters,
                                                                vcg::CallBackPos* cb) {
  const filters::FilterSpec& filter = filters::Filter(IdOf(id));
  const filters::ParameterValues values = filters::ReadValues(filter.id, parameters);
  const bool newLayer = values.Has("newLayer") && values.Bool("newLayer");
  const filters::RunProgress::Callback progress = filters::HostProgress(cb);
  molremesh::MeshD work;
  molremesh::PipelineResult result;
  std::vector<std::uint8_t> selected; // per face of the result: the remeshed region
  const std::string why =
      filters::RunStages(mm.cm, filter, values, runLog(), progress, work, result, selected);
  if (!why.empty()) fail(QString::fromStdString(why));

  MeshModel* target = &mm;
  if (newLayer) {
    // The input layer is kept as it was, only hidden so that the result is seen.
    const QString name =
        QFileInfo(mm.label()).completeBaseName() + " " + QString::fromStdString(filter.layerSuffix);
    mm.setVisible(false);
    target = md.addNewMesh("", name, true);
    target->cm.Tr = mm.cm.Tr;
    log("%s", qUtf8Printable("Result in the new layer \"" + target->label() + "\"; \"" + mm.label() +
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
  target->updateBoxAndNormals();

  Outputs outputs;
  AddFigures(outputs, result.input, "input_");
  if (!result.stages.empty()) AddFigures(outputs, result.stages.back().after);
  outputs["target_edge_length"] = result.targetEdgeLength;
  outputs["seconds"] = result.seconds;
  // The promises of the stages that ran: a valid surface, and every target met.
  outputs["valid"] = result.verdict.Valid();
  outputs["all_targets_met"] = result.verdict.AllMet();
  return outputs;
}

FilterMolRemeshPlugin::Outputs
FilterMolRemeshPlugin::surfaceFromStructure(MeshDocument& md, const RichParameterList& parameters,
                                            vcg::CallBackPos* cb) {
  const filters::RunProgress::Callback progress = filters::HostProgress(cb);
  molremesh::MeshD surface;
  filters::StructureSurfaceRun run;
  const std::string why = filters::RunSurfaceFromStructure(
      filters::ReadValues(FilterId::SurfaceFromStructure, parameters), runLog(), progress, surface, run);
  if (!why.empty()) fail(QString::fromStdString(why));
  // Added only now: a refused file leaves the document as it was.
  MeshModel* layer = md.addNewMesh("", QString::fromStdString(run.layerName), true);
  molremesh::CopyTriangles(layer->cm, surface);
  layer->updateBoxAndNormals();
  log("%s", qUtf8Printable("Surface in the new layer \"" + layer->label() + "\""));

  Outputs outputs;
  outputs["atoms"] = int(run.atoms);
  outputs["surface_faces"] = int(run.surface.faces);
  outputs["surface_components"] = int(run.surface.components);
  outputs["surface_cavities"] = int(run.surface.cavities);
  outputs["surface_area"] = run.surface.area;
  outputs["surface_volume"] = run.surface.volume;
  if (run.remeshed && !run.pipeline.stages.empty()) {
    AddFigures(outputs, run.pipeline.stages.back().after);
    outputs["valid"] = run.pipeline.verdict.Valid();
    outputs["all_targets_met"] = run.pipeline.verdict.AllMet();
  }
  return outputs;
}

MESHLAB_PLUGIN_NAME_EXPORTER(FilterMolRemeshPlugin)

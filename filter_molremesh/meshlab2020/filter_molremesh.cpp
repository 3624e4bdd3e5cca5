// The shared runs first: Qt (pulled in by the plugin header) defines `slots` and `signals` as
// macros, which must not reach the vcg_ext templates.
#include "../filter_runs.h"

#include "../host_parameters.h"
#include "filter_molremesh.h"

#include <common/mlapplication.h>

#include <QCoreApplication>
#include <QFileInfo>

#include <string>

namespace {
const char* const kPluginName = "FilterMolRemesh";
namespace filters = molremesh::filters;
using filters::FilterId;
using filters::FilterKind;

static_assert(int(FilterId::QualityReport) == FilterMolRemeshPlugin::FP_QUALITY_REPORT &&
                  int(FilterId::FullPipeline) == FilterMolRemeshPlugin::FP_FULL_PIPELINE &&
                  int(FilterId::SurfaceFromStructure) == FilterMolRemeshPlugin::FP_SURFACE_FROM_STRUCTURE,
              "the plugin's filter ids are the catalog's");

bool IsFilter(int id) {
  return id >= 0 && id <= FilterMolRemeshPlugin::FP_SURFACE_FROM_STRUCTURE;
}

FilterId IdOf(int filter) {
  return FilterId(filter);
}

/// The catalog's parameters as MeshLab 2020.09 RichParameters (float scalars); m is the current
/// layer, null for a filter that needs none.
void AddParameters(FilterId id, const MeshModel* m, RichParameterList& parameters) {
  using Type = filters::ParameterSpec::Type;
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
      parameters.addParam(RichFloat(name, float(p.defaultValue), label, help));
      break;
    case Type::Length: {
      // Absolute and % of the bounding-box diagonal, as MeshLab's own isotropic remeshing.
      const filters::LengthRange range =
          m != nullptr ? filters::LengthRangeOfMesh(m->cm) : filters::LengthRangeOf(0, 1);
      parameters.addParam(RichAbsPerc(name, float(range.value), 0.f, float(range.max), label, help));
      break;
    }
    case Type::Enum:
      parameters.addParam(
          RichEnum(name, int(p.defaultValue), filters::ToQStringList(p.choices), label, help));
      break;
    case Type::File:
      parameters.addParam(RichOpenFile(name, QString(), filters::ToQStringList(p.choices), label, help));
      break;
    }
  }
}

} // namespace

FilterMolRemeshPlugin::FilterMolRemeshPlugin() {
  for (const filters::FilterSpec& filter : filters::Filters()) typeList << int(filter.id);
  for (FilterIDType id : types()) actionList << new QAction(filterName(id), this);
}

QString FilterMolRemeshPlugin::pluginName() const {
  return kPluginName;
}

QString FilterMolRemeshPlugin::filterName(FilterIDType filter) const {
  if (!IsFilter(filter)) return "Molecular Remesh: unknown filter";
  return QString::fromStdString(filters::Filter(IdOf(filter)).name);
}

QString FilterMolRemeshPlugin::filterInfo(FilterIDType filter) const {
  if (!IsFilter(filter)) return QString();
  return QString::fromStdString(filters::Filter(IdOf(filter)).info);
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
  case FP_SURFACE_FROM_STRUCTURE:
    // "Create New Mesh Layer": runs without an open layer, the result is a new one.
    return MeshFilterInterface::MeshCreation;
  default:
    return MeshFilterInterface::Remeshing;
  }
}

MeshFilterInterface::FILTER_ARITY FilterMolRemeshPlugin::filterArity(QAction* action) const {
  // NONE: the host runs it without a layer.
  if (ID(action) == FP_SURFACE_FROM_STRUCTURE) return NONE;
  return SINGLE_MESH;
}

int FilterMolRemeshPlugin::getPreConditions(QAction* action) const {
  if (ID(action) == FP_SURFACE_FROM_STRUCTURE) return MeshModel::MM_NONE;
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
  case FP_SURFACE_FROM_STRUCTURE: // a new layer; the current one is not touched
    return MeshModel::MM_NONE;
  }
  return MeshModel::MM_NONE;
}

void FilterMolRemeshPlugin::initParameterSet(QAction* action, MeshModel& m, RichParameterList& parameters) {
  AddParameters(IdOf(ID(action)), &m, parameters);
}

void FilterMolRemeshPlugin::initParameterSet(QAction* action, MeshDocument& md,
                                             RichParameterList& parameters) {
  AddParameters(IdOf(ID(action)), md.mm(), parameters);
}

bool FilterMolRemeshPlugin::fail(const QString& message) {
  errorMessage = message;
  Log(GLLogStream::WARNING, qUtf8Printable("Error: " + message));
  return false;
}

bool FilterMolRemeshPlugin::applyFilter(QAction* action, MeshDocument& md,
                                        const RichParameterList& parameters, vcg::CallBackPos* cb) {
  if (ID(action) == FP_SURFACE_FROM_STRUCTURE) return surfaceFromStructure(md, parameters, cb);
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
  default:
    if (!IsFilter(ID(action))) return fail("unknown filter");
    return runStages(md, *mm, ID(action), parameters, cb);
  }
}

bool FilterMolRemeshPlugin::RichLog() {
  // MeshLab's GUI names its application "MeshLab..." and shows the log as rich text; meshlabserver
  // (and any other host) keeps the executable's name and prints the entries as they are.
  return QCoreApplication::applicationName().startsWith(MeshLabApplication::appName());
}

filters::RunLog FilterMolRemeshPlugin::runLog() {
  filters::RunLog log;
  log.info = [this](const std::string& line) { Log("%s", line.c_str()); };
  log.warning = [this](const std::string& line) { Log(GLLogStream::WARNING, line.c_str()); };
  log.rich = RichLog();
  return log;
}

bool FilterMolRemeshPlugin::qualityReport(MeshModel& mm, const RichParameterList& parameters) {
  filters::RunQualityReport(mm.cm, filters::ReadValues(filters::FilterId::QualityReport, parameters),
                            mm.shortName().toStdString(), runLog());
  return true;
}

bool FilterMolRemeshPlugin::colorBadElements(MeshModel& mm, const RichParameterList& parameters) {
  molremesh::BadElementCounts counts;
  const std::string why = filters::RunColorBadElements(
      mm.cm, filters::ReadValues(filters::FilterId::ColorBadElements, parameters), runLog(),
      [&mm] {
        mm.updateDataMask(MeshModel::MM_VERTCOLOR | MeshModel::MM_FACECOLOR | MeshModel::MM_VERTQUALITY |
                          MeshModel::MM_FACEQUALITY);
      },
      counts);
  return why.empty() || fail(QString::fromStdString(why));
}

bool FilterMolRemeshPlugin::randomSegmentation(MeshModel& mm, const RichParameterList& parameters) {
  molremesh::SegmentationResult result;
  const std::string why = filters::RunRandomSegmentation(
      mm.cm, filters::ReadValues(filters::FilterId::RandomSegmentation, parameters), runLog(),
      [&mm] { mm.updateDataMask(MeshModel::MM_FACEFACETOPO | MeshModel::MM_FACECOLOR); }, result);
  return why.empty() || fail(QString::fromStdString(why));
}

bool FilterMolRemeshPlugin::runStages(MeshDocument& md, MeshModel& mm, FilterIDType id,
                                      const RichParameterList& parameters, vcg::CallBackPos* cb) {
  const filters::FilterSpec& filter = filters::Filter(IdOf(id));
  const filters::ParameterValues values = filters::ReadValues(filter.id, parameters);
  const bool newLayer = values.Has("newLayer") && values.Bool("newLayer");
  const filters::RunProgress::Callback progress = filters::HostProgress(cb);
  molremesh::MeshD work;
  molremesh::PipelineResult result;
  std::vector<std::uint8_t> selected; // per face of the result: the remeshed region
  const std::string why =
      filters::RunStages(mm.cm, filter, values, runLog(), progress, work, result, selected);
  if (!why.empty()) return fail(QString::fromStdString(why));

  MeshModel* target = &mm;
  if (newLayer) {
    // The input layer is kept as it was, only hidden so that the result is seen.
    const QString name =
        QFileInfo(mm.label()).completeBaseName() + " " + QString::fromStdString(filter.layerSuffix);
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

bool FilterMolRemeshPlugin::surfaceFromStructure(MeshDocument& md, const RichParameterList& parameters,
                                                 vcg::CallBackPos* cb) {
  const filters::RunProgress::Callback progress = filters::HostProgress(cb);
  molremesh::MeshD surface;
  filters::StructureSurfaceRun run;
  const std::string why = filters::RunSurfaceFromStructure(
      filters::ReadValues(filters::FilterId::SurfaceFromStructure, parameters), runLog(), progress, surface,
      run);
  if (!why.empty()) return fail(QString::fromStdString(why));
  // Added only now: a refused file leaves the document as it was.
  MeshModel* layer = md.addNewMesh("", QString::fromStdString(run.layerName), true);
  molremesh::CopyTriangles(layer->cm, surface);
  layer->UpdateBoxAndNormals();
  Log("%s", qUtf8Printable("Surface in the new layer \"" + layer->label() + "\""));
  return true;
}

MESHLAB_PLUGIN_NAME_EXPORTER(FilterMolRemeshPlugin)

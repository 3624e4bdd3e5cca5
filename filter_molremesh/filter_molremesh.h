// MeshLab 2020.09 filter plugin of molremesh.
//
// The plugin only translates MeshLab parameters into vcg_ext Params, checks the input before
// anything is changed, calls vcg_ext and logs the result. No geometry lives here.
#pragma once

#include <common/interfaces.h>

#include <string>
#include <vector>

namespace molremesh {
struct PipelineResult;
}

class FilterMolRemeshPlugin : public QObject, public MeshFilterInterface {
  Q_OBJECT
  MESHLAB_PLUGIN_IID_EXPORTER(MESH_FILTER_INTERFACE_IID)
  Q_INTERFACES(MeshFilterInterface)

public:
  enum FilterId {
    FP_QUALITY_REPORT,
    FP_COLOR_BAD_ELEMENTS,
    FP_CLEAN_RAW_MESH,
    FP_CVT_INITIALIZATION,
    FP_RANDOM_SEGMENTATION,
    FP_PATCHWISE_RAR,
    FP_VALENCE_OPTIMIZATION,
    FP_REMOVE_SMALL_ANGLES,
    FP_REDUCE_OBTUSE,
    FP_LOCAL_SMOOTHING,
    FP_FULL_PIPELINE,
  };

  FilterMolRemeshPlugin();

  QString pluginName() const override;
  QString filterName(FilterIDType filter) const override;
  QString filterInfo(FilterIDType filter) const override;
  FilterClass getClass(QAction* action) override;
  FILTER_ARITY filterArity(QAction* action) const override;
  int getPreConditions(QAction* action) const override;
  int getRequirements(QAction* action) override;
  int postCondition(QAction* action) const override;
  void initParameterSet(QAction* action, MeshModel& m, RichParameterList& parameters) override;
  bool applyFilter(QAction* action, MeshDocument& md, const RichParameterList& parameters,
                   vcg::CallBackPos* cb) override;

private:
  bool qualityReport(MeshModel& mm, const RichParameterList& parameters);
  bool colorBadElements(MeshModel& mm, const RichParameterList& parameters);
  bool randomSegmentation(MeshModel& mm, const RichParameterList& parameters);
  /// Runs pipeline stages on a double-precision copy of the layer and, only when every stage
  /// succeeded, puts the result into a new layer "<name> <layerSuffix>" (parameter newLayer on) or
  /// into the layer itself: a failure leaves the document exactly as it was.
  bool runStages(MeshDocument& md, MeshModel& mm, const std::vector<int>& stages,
                 const RichParameterList& parameters, vcg::CallBackPos* cb, const char* layerSuffix);
  /// The stages' summaries and the quality tables of a run, as rich text in MeshLab's GUI.
  void logRun(const molremesh::PipelineResult& result);
  /// A plain-text block: one <pre> entry in MeshLab's GUI, one entry per line elsewhere.
  void logText(const std::string& text);
  /// Whether the log is shown as rich text (MeshLab's GUI), not printed (meshlabserver).
  static bool RichLog();
  /// Sets errorMessage (and logs it, so meshlabserver users see the reason too); returns false.
  bool fail(const QString& message);
};

// MeshLab 2020.09 filter plugin of molremesh (MeshFilterInterface, Debian's MeshLab and
// meshlabserver).
//
// A thin adapter: the filters, their parameters and runs are described once in
// ../filter_catalog.h and ../filter_runs.h; this class turns them into MeshLab 2020.09's
// RichParameters, layers and log. No geometry lives here.
#pragma once

#include <common/interfaces.h>

#include <string>
#include <vector>

namespace molremesh::filters {
struct RunLog;
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
    FP_SURFACE_FROM_STRUCTURE,
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
  /// The document's version, which MeshLab calls: Surface from Structure File needs no layer.
  void initParameterSet(QAction* action, MeshDocument& md, RichParameterList& parameters) override;
  bool applyFilter(QAction* action, MeshDocument& md, const RichParameterList& parameters,
                   vcg::CallBackPos* cb) override;

private:
  bool qualityReport(MeshModel& mm, const RichParameterList& parameters);
  bool colorBadElements(MeshModel& mm, const RichParameterList& parameters);
  bool randomSegmentation(MeshModel& mm, const RichParameterList& parameters);
  /// Runs a stage filter on a double-precision copy of the layer and, only when every stage
  /// succeeded, puts the result into a new layer "<name> <layerSuffix>" (parameter newLayer on) or
  /// into the layer itself: a failure leaves the document exactly as it was.
  bool runStages(MeshDocument& md, MeshModel& mm, FilterIDType id, const RichParameterList& parameters,
                 vcg::CallBackPos* cb);
  /// Surface from Structure File: the surface into a new layer, which becomes the current one.
  bool surfaceFromStructure(MeshDocument& md, const RichParameterList& parameters, vcg::CallBackPos* cb);
  /// The log channels of a run.
  molremesh::filters::RunLog runLog();
  /// Whether the log is shown as rich text (MeshLab's GUI), not printed (meshlabserver).
  static bool RichLog();
  /// Sets errorMessage (and logs it, so meshlabserver users see the reason too); returns false.
  bool fail(const QString& message);
};

// MeshLab 2020.09 filter plugin of molremesh.
//
// The plugin only translates MeshLab parameters into vcg_ext Params, checks the input before
// anything is changed, calls vcg_ext and logs the result. No geometry lives here.
#pragma once

#include <common/interfaces.h>

#include <vector>

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
  /// Runs pipeline stages on a double-precision copy of the layer and writes the result back
  /// only when every stage succeeded: a failure leaves the layer exactly as it was.
  bool runStages(MeshModel& mm, const std::vector<int>& stages, const RichParameterList& parameters,
                 vcg::CallBackPos* cb);
  /// Sets errorMessage (and logs it, so meshlabserver users see the reason too); returns false.
  bool fail(const QString& message);
};

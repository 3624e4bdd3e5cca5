// MeshLab 2023.12 filter plugin of molremesh (the FilterPlugin interface of MeshLab 2022 and later,
// and of PyMeshLab 2023.12).
//
// A thin adapter: the filters, their parameters and runs are described once in
// ../filter_catalog.h and ../filter_runs.h; this class turns them into MeshLab 2023.12's
// RichParameters, layers, log and output values (the quality figures a script reads). A refused
// input or parameter throws MLException (PyMeshLab: PyMeshLabException) with the layer unchanged.
#pragma once

#include <common/plugins/interfaces/filter_plugin.h>

#include <map>
#include <string>

namespace molremesh::filters {
struct RunLog;
}

class FilterMolRemeshPlugin : public QObject, public FilterPlugin {
  Q_OBJECT
  MESHLAB_PLUGIN_IID_EXPORTER(FILTER_PLUGIN_IID)
  Q_INTERFACES(FilterPlugin)

public:
  FilterMolRemeshPlugin();

  QString pluginName() const override;
  QString vendor() const override;
  QString filterName(ActionIDType filter) const override;
  QString filterInfo(ActionIDType filter) const override;
  FilterClass getClass(const QAction* action) const override;
  FilterArity filterArity(const QAction* action) const override;
  int getPreConditions(const QAction* action) const override;
  int getRequirements(const QAction* action) override;
  int postCondition(const QAction* action) const override;
  RichParameterList initParameterList(const QAction* action, const MeshModel& m) override;
  /// The document's version, which the host calls: Surface from Structure File needs no layer.
  RichParameterList initParameterList(const QAction* action, const MeshDocument& md) override;
  std::map<std::string, QVariant> applyFilter(const QAction* action, const RichParameterList& parameters,
                                              MeshDocument& md, unsigned int& postConditionMask,
                                              vcg::CallBackPos* cb) override;

private:
  using Outputs = std::map<std::string, QVariant>;
  Outputs runStages(MeshDocument& md, MeshModel& mm, ActionIDType id, const RichParameterList& parameters,
                    vcg::CallBackPos* cb);
  /// Surface from Structure File: the surface into a new layer, which becomes the current one.
  Outputs surfaceFromStructure(MeshDocument& md, const RichParameterList& parameters, vcg::CallBackPos* cb);
  /// The log channels of a run.
  molremesh::filters::RunLog runLog() const;
  /// Logs the message and throws it as MLException (the host's error channel).
  [[noreturn]] void fail(const QString& message) const;
};

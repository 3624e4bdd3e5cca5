// The part of the adapters' host glue that is the same for MeshLab 2020.09 and 2023.12: both
// RichParameterList classes have the same getters, so one template reads a run's values; the
// catalog's choices become the QStringList both RichEnum and the file parameters take; and both
// hosts' progress callbacks (vcg::CallBackPos) become a run's progress callback the same way.
//
// Include after filter_runs.h (Qt's keyword macros must not reach the vcg_ext templates).
#pragma once

#include "filter_catalog.h"
#include "filter_runs.h"

#include <QString>
#include <QStringList>

#include <string>
#include <vector>

namespace molremesh::filters {

inline QStringList ToQStringList(const std::vector<std::string>& texts) {
  QStringList list;
  for (const std::string& text : texts) list << QString::fromStdString(text);
  return list;
}

/// The run's progress callback that forwards to the host's bar; empty when the host gives none
/// (meshlabserver may pass a null callback).
template <class HostCallback>
RunProgress::Callback HostProgress(HostCallback* cb) {
  if (cb == nullptr) return {};
  return [cb](int percent, const std::string& label) { cb(percent, label.c_str()); };
}

/// The values of the parameters the filter declares, read from the host's list (a script may
/// leave some out: those are skipped).
template <class RichParameterList>
ParameterValues ReadValues(FilterId id, const RichParameterList& parameters) {
  using Type = ParameterSpec::Type;
  ParameterValues values;
  for (const ParameterSpec& p : Parameters(id)) {
    const QString name = QString::fromStdString(p.name);
    if (!parameters.hasParameter(name)) continue;
    switch (p.type) {
    case Type::Bool:
      values.Set(p.name, parameters.getBool(name) ? 1 : 0);
      break;
    case Type::Int:
      values.Set(p.name, parameters.getInt(name));
      break;
    case Type::Float:
    case Type::Length:
      // getFloat reads both the absolute/percentage value of the dialog and a plain float of a
      // script; both hosts store it as float (2023.12 returns it as Scalarm).
      values.Set(p.name, DecimalOf(float(parameters.getFloat(name))));
      break;
    case Type::Enum:
      values.Set(p.name, parameters.getEnum(name));
      break;
    case Type::File:
      values.SetText(p.name, parameters.getOpenFileName(name).toStdString());
      break;
    }
  }
  return values;
}

} // namespace molremesh::filters

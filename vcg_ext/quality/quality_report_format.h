// Human-readable table of QualityReport figures, shared by the CLI and the MeshLab plugin log.
//
// Several reports can be printed side by side (e.g. "input" and "output"), one column each.
#pragma once

#include <cmath>
#include <cstdio>
#include <functional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <vcg_ext/quality/mesh_quality.h>

namespace molremesh {

namespace detail {
inline std::string FormatNumber(double value, int decimals) {
  if (std::isinf(value)) return "inf";
  if (std::isnan(value)) return "n/a";
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
  return buffer;
}
inline std::string FormatCount(std::size_t value) {
  return std::to_string(value);
}
inline std::string FormatCountPercent(std::size_t count, double percent) {
  return std::to_string(count) + " (" + FormatNumber(percent, 2) + "%)";
}
} // namespace detail

using NamedReport = std::pair<std::string, QualityReport>;

/// One row per figure, one column per report. Lines end with '\n'.
inline std::string FormatQualityTable(const std::vector<NamedReport>& columns) {
  using detail::FormatCount;
  using detail::FormatCountPercent;
  using detail::FormatNumber;
  using Cell = std::function<std::string(const QualityReport&)>;
  const std::vector<std::pair<std::string, Cell>> rows = {
      {"vertices", [](const QualityReport& r) { return FormatCount(r.vertices); }},
      {"faces", [](const QualityReport& r) { return FormatCount(r.faces); }},
      {"edges", [](const QualityReport& r) { return FormatCount(r.edges); }},
      {"Qmin", [](const QualityReport& r) { return FormatNumber(r.qMin, 4); }},
      {"Qavg", [](const QualityReport& r) { return FormatNumber(r.qAvg, 4); }},
      {"min angle (deg)", [](const QualityReport& r) { return FormatNumber(r.angleMin, 2); }},
      {"mean min angle (deg)", [](const QualityReport& r) { return FormatNumber(r.meanMinAngle, 2); }},
      {"max angle (deg)", [](const QualityReport& r) { return FormatNumber(r.angleMax, 2); }},
      {"aspect ratio max", [](const QualityReport& r) { return FormatNumber(r.aspectRatioMax, 3); }},
      {"aspect ratio mean", [](const QualityReport& r) { return FormatNumber(r.aspectRatioMean, 3); }},
      {"V567 (% interior)", [](const QualityReport& r) { return FormatNumber(r.v567Percent, 2); }},
      {"irregular vertices",
       [](const QualityReport& r) { return FormatCount(r.interiorVertices - r.regularVertices); }},
      {"faces angle < 30",
       [](const QualityReport& r) { return FormatCountPercent(r.smallAngleFaces, r.smallAnglePercent); }},
      {"obtuse faces (>= 90)",
       [](const QualityReport& r) { return FormatCountPercent(r.obtuseFaces, r.obtusePercent); }},
      {"faces angle > 120",
       [](const QualityReport& r) { return FormatCountPercent(r.largeAngleFaces, r.largeAnglePercent); }},
      {"area", [](const QualityReport& r) { return FormatNumber(r.area, 3); }},
      {"volume", [](const QualityReport& r) { return FormatNumber(r.volume, 3); }},
      {"Euler characteristic", [](const QualityReport& r) { return std::to_string(r.euler); }},
      {"genus",
       [](const QualityReport& r) {
         return r.genus < 0 ? std::string("undefined") : std::to_string(r.genus);
       }},
      {"components", [](const QualityReport& r) { return FormatCount(r.components); }},
      {"boundary edges", [](const QualityReport& r) { return FormatCount(r.boundaryEdges); }},
      {"non-manifold edges", [](const QualityReport& r) { return FormatCount(r.nonManifoldEdges); }},
      {"non-manifold vertices", [](const QualityReport& r) { return FormatCount(r.nonManifoldVertices); }},
      {"unreferenced vertices", [](const QualityReport& r) { return FormatCount(r.unreferencedVertices); }},
      {"degenerate faces", [](const QualityReport& r) { return FormatCount(r.degenerateFaces); }},
      {"self-intersecting pairs",
       [](const QualityReport& r) {
         return r.selfIntersectionsComputed ? FormatCount(r.selfIntersectingPairs)
                                            : std::string("not computed");
       }},
  };

  std::size_t labelWidth = 0;
  for (const auto& row : rows) labelWidth = std::max(labelWidth, row.first.size());
  std::vector<std::vector<std::string>> cells(rows.size());
  std::vector<std::size_t> columnWidth;
  for (const auto& column : columns) columnWidth.push_back(column.first.size());
  for (std::size_t r = 0; r < rows.size(); ++r)
    for (std::size_t c = 0; c < columns.size(); ++c) {
      cells[r].push_back(rows[r].second(columns[c].second));
      columnWidth[c] = std::max(columnWidth[c], cells[r].back().size());
    }

  std::ostringstream out;
  auto pad = [](const std::string& text, std::size_t width, bool right) {
    const std::string fill(width > text.size() ? width - text.size() : 0, ' ');
    return right ? fill + text : text + fill;
  };
  out << pad("", labelWidth, false);
  for (std::size_t c = 0; c < columns.size(); ++c) out << "  " << pad(columns[c].first, columnWidth[c], true);
  out << '\n';
  for (std::size_t r = 0; r < rows.size(); ++r) {
    out << pad(rows[r].first, labelWidth, false);
    for (std::size_t c = 0; c < columns.size(); ++c) out << "  " << pad(cells[r][c], columnWidth[c], true);
    out << '\n';
  }
  return out.str();
}

inline std::string FormatQualityTable(const QualityReport& report, const std::string& title = "value") {
  return FormatQualityTable(std::vector<NamedReport>{{title, report}});
}

/// Valence histogram of interior vertices as one line: "3:0 4:12 5:300 ...".
inline std::string FormatValenceHistogram(const QualityReport& report) {
  std::ostringstream out;
  bool first = true;
  for (const auto& [valence, count] : report.valenceHistogram) {
    out << (first ? "" : " ") << valence << ':' << count;
    first = false;
  }
  return out.str();
}

} // namespace molremesh

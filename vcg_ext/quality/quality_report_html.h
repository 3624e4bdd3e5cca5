// The quality figures formatted for MeshLab's log pane, which renders each entry as rich text in a
// proportional font and collapses runs of spaces: the plain-text tables of quality_report_format.h
// lose their alignment there. The tables go into <pre> blocks (spaces kept, fixed-width font), and
// a color legend is a line per class with a colored square. The CLI and meshlabserver logs keep the
// plain text.
#pragma once

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include <vcg_ext/quality/quality_report_format.h>

namespace molremesh {

/// text with &, <, > and " replaced by their HTML entities.
inline std::string HtmlEscape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
    case '&':
      out += "&amp;";
      break;
    case '<':
      out += "&lt;";
      break;
    case '>':
      out += "&gt;";
      break;
    case '"':
      out += "&quot;";
      break;
    default:
      out += c;
    }
  }
  return out;
}

/// A plain-text block (lines ending with '\n') as one <pre> element: aligned in a rich-text view.
inline std::string PreformattedHtml(const std::string& text) {
  std::string body = text;
  while (!body.empty() && body.back() == '\n') body.pop_back();
  return "<pre>" + HtmlEscape(body) + "</pre>";
}

/// FormatQualityTable of the reports, as one <pre> element.
inline std::string FormatQualityTableHtml(const std::vector<NamedReport>& columns) {
  return PreformattedHtml(FormatQualityTable(columns));
}

/// The few figures that follow a run stage by stage, one row per report: faces, min and max
/// angle, V567, the shares of small-angle and obtuse faces, and the seconds of the stage (seconds
/// may be shorter than columns, e.g. no time for the input row). Plain text, lines end with '\n'.
inline std::string FormatStageTable(const std::vector<NamedReport>& rows,
                                    const std::vector<double>& seconds) {
  std::string out;
  char line[160];
  std::snprintf(line, sizeof line, "%-8s %8s %7s %7s %7s %7s %7s %7s\n", "stage", "faces", "min deg",
                "max deg", "V567 %", "<30 %", "obtuse%", "time s");
  out += line;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const QualityReport& r = rows[i].second;
    const std::string time = i < seconds.size() ? detail::FormatNumber(seconds[i], 2) : std::string("");
    std::snprintf(line, sizeof line, "%-8s %8zu %7s %7s %7s %7s %7s %7s\n", rows[i].first.c_str(), r.faces,
                  detail::FormatNumber(r.angleMin, 2).c_str(), detail::FormatNumber(r.angleMax, 2).c_str(),
                  detail::FormatNumber(r.v567Percent, 2).c_str(),
                  detail::FormatNumber(r.smallAnglePercent, 2).c_str(),
                  detail::FormatNumber(r.obtusePercent, 2).c_str(), time.c_str());
    out += line;
  }
  return out;
}

/// One class of a color legend.
struct LegendEntry {
  unsigned char red = 0, green = 0, blue = 0;
  std::string label; ///< what the color marks
  std::size_t count = 0;
};

/// "#rrggbb" of a legend entry.
inline std::string HtmlColor(const LegendEntry& entry) {
  char buffer[8];
  std::snprintf(buffer, sizeof buffer, "#%02x%02x%02x", entry.red, entry.green, entry.blue);
  return buffer;
}

/// A title line, then one line per entry: a square of its color, its count and its label, the
/// counts right-aligned in a <pre> block so they line up.
inline std::string FormatColorLegendHtml(const std::string& title, const std::vector<LegendEntry>& entries) {
  std::size_t width = 1;
  for (const auto& e : entries) width = std::max(width, std::to_string(e.count).size());
  std::string out = "<b>" + HtmlEscape(title) + "</b><pre>";
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const LegendEntry& e = entries[i];
    const std::string count = std::to_string(e.count);
    out += "<span style=\"color:" + HtmlColor(e) + "\">&#9608;&#9608;</span> " +
           std::string(width - count.size(), ' ') + count + "  " + HtmlEscape(e.label);
    if (i + 1 < entries.size()) out += "\n";
  }
  return out + "</pre>";
}

} // namespace molremesh

// The part of the filters' runs that does not depend on the host's mesh type.
#include "filter_runs.h"

namespace molremesh::filters {

void LogPipelineRun(const PipelineResult& result, const RunLog& log) {
  std::vector<NamedReport> columns{{"before", result.input}};
  std::vector<double> seconds{0.0};
  for (const auto& stage : result.stages) {
    columns.emplace_back(stage.name, stage.after);
    seconds.push_back(stage.seconds);
  }
  if (log.rich) {
    // The log pane is narrow: each stage's summary as one paragraph, the full table before and
    // after only, and the per-stage figures in a short table.
    for (const auto& stage : result.stages) {
      std::string paragraph;
      std::istringstream lines(stage.summary);
      for (std::string line; std::getline(lines, line);)
        if (!line.empty()) paragraph += (paragraph.empty() ? "" : "; ") + line;
      log.info("<b>" + HtmlEscape(stage.name) + "</b>: " + HtmlEscape(paragraph));
    }
    std::vector<NamedReport> beforeAfter{columns.front()};
    if (columns.size() > 1) beforeAfter.emplace_back("after", columns.back().second);
    log.info(FormatQualityTableHtml(beforeAfter));
    log.info(PreformattedHtml(FormatStageTable(columns, seconds)));
  } else {
    for (const auto& stage : result.stages) log.Text(stage.summary);
    log.Text(FormatQualityTable(columns));
  }
  log.info(StageTimesLine(result));
  // The layer takes the result either way (it is better than the input), but never in silence
  // when it misses a promise: the warnings say what and why.
  RunLog::Lines(log.warning, result.verdict.Lines("Warning: the result is "));
}

} // namespace molremesh::filters

// The quality figures formatted for MeshLab's log: the plain-text tables inside <pre> (escaped,
// aligned as in the terminal), the per-stage table and the color legend.
#include <gtest/gtest.h>

#include <vcg/complex/algorithms/create/platonic.h>

#include <sstream>
#include <string>
#include <vector>

#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/quality/quality_report_html.h>

using molremesh::MeshD;

namespace {
molremesh::QualityReport IcosahedronReport() {
  MeshD m;
  vcg::tri::Icosahedron(m);
  return molremesh::MeshQuality<MeshD>::Compute(m);
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}
} // namespace

TEST(QualityReportHtml, EscapesMarkup) {
  EXPECT_EQ(molremesh::HtmlEscape("a < b && c > \"d\""), "a &lt; b &amp;&amp; c &gt; &quot;d&quot;");
  EXPECT_EQ(molremesh::PreformattedHtml("x < 1\ny\n\n"), "<pre>x &lt; 1\ny</pre>");
}

TEST(QualityReportHtml, TableIsThePlainTableInOnePreElement) {
  const molremesh::QualityReport report = IcosahedronReport();
  const std::vector<molremesh::NamedReport> columns{{"before", report}, {"after", report}};
  const std::string html = molremesh::FormatQualityTableHtml(columns);
  ASSERT_EQ(html.rfind("<pre>", 0), 0u);
  ASSERT_EQ(html.substr(html.size() - 6), "</pre>");
  EXPECT_EQ(html.find("<pre>", 1), std::string::npos) << "one block";
  // The rows' "<" and ">" are escaped, and unescaping gives back the aligned plain text.
  std::string body = html.substr(5, html.size() - 11);
  EXPECT_EQ(body.find('<'), std::string::npos);
  EXPECT_NE(body.find("faces angle &lt; 30"), std::string::npos);
  for (const auto& [entity, character] : std::vector<std::pair<std::string, std::string>>{
           {"&lt;", "<"}, {"&gt;", ">"}, {"&quot;", "\""}, {"&amp;", "&"}})
    for (std::size_t at; (at = body.find(entity)) != std::string::npos;)
      body.replace(at, entity.size(), character);
  EXPECT_EQ(body + "\n", molremesh::FormatQualityTable(columns));
}

TEST(QualityReportHtml, StageTableHasOneAlignedRowPerReport) {
  const molremesh::QualityReport report = IcosahedronReport();
  const std::string text = molremesh::FormatStageTable(
      {{"before", report}, {"cvt", report}, {"valence", report}}, {0.0, 1.25, 0.5});
  const std::vector<std::string> lines = Lines(text);
  ASSERT_EQ(lines.size(), 4u) << text;
  for (const auto& line : lines) EXPECT_EQ(line.size(), lines[0].size()) << text;
  EXPECT_EQ(lines[2].rfind("cvt", 0), 0u);
  EXPECT_NE(lines[2].find(" 20 "), std::string::npos) << "the icosahedron's 20 faces";
  EXPECT_NE(lines[2].find("1.25"), std::string::npos) << "the stage's seconds";
  EXPECT_NE(lines[2].find("100.00"), std::string::npos) << "V567 of the icosahedron";
}

TEST(QualityReportHtml, LegendHasAColoredSwatchAndAlignedCountPerClass) {
  const std::string html = molremesh::FormatColorLegendHtml(
      "Face colors", {{213, 94, 0, "obtuse faces", 1234}, {0, 114, 178, "small-angle <30", 7}});
  EXPECT_EQ(html.rfind("<b>Face colors</b><pre>", 0), 0u) << html;
  EXPECT_NE(html.find("color:#d55e00"), std::string::npos);
  EXPECT_NE(html.find("color:#0072b2"), std::string::npos);
  EXPECT_NE(html.find(" 1234  obtuse faces"), std::string::npos) << html;
  EXPECT_NE(html.find("    7  small-angle &lt;30"), std::string::npos)
      << "counts right-aligned, labels escaped";
}

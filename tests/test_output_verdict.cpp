// OutputVerdict: what the pipeline promises of its output, checked on the output's report.
#include <gtest/gtest.h>

#include <vcg_ext/quality/output_verdict.h>

using namespace molremesh;

namespace {
/// A closed, valid, well-shaped output.
QualityReport GoodOutput() {
  QualityReport r;
  r.faces = 1000;
  r.interiorVertices = 502;
  r.v567Percent = 100.0;
  r.angleMin = 35.0;
  r.angleMax = 88.0;
  r.selfIntersectionsComputed = true;
  return r;
}

bool Mentions(const std::vector<std::string>& lines, const std::string& text) {
  for (const auto& line : lines)
    if (line.find(text) != std::string::npos) return true;
  return false;
}
} // namespace

TEST(OutputVerdict, AGoodOutputMeetsEveryTarget) {
  OutputTargets targets;
  targets.checkAngles = targets.checkValence = true;
  const OutputVerdict v = OutputVerdict::Of(GoodOutput(), targets);
  EXPECT_TRUE(v.Valid());
  EXPECT_TRUE(v.AllMet());
  EXPECT_TRUE(v.Lines("x: ").empty());
}

TEST(OutputVerdict, SelfIntersectionsMakeItInvalidAndTheUnrepairedTangleIsNamed) {
  QualityReport r = GoodOutput();
  r.selfIntersectingPairs = 158;
  OutputTargets targets;
  targets.unrepairedTangles = 1;
  const OutputVerdict v = OutputVerdict::Of(r, targets);
  EXPECT_FALSE(v.Valid());
  EXPECT_TRUE(Mentions(v.invalid, "158 self-intersecting face pairs"));
  EXPECT_TRUE(Mentions(v.invalid, "1 tangle of intersecting faces"));
  EXPECT_NE(v.Lines("p: ").find("p: not valid: 158"), std::string::npos);
  // Pairs sharing a vertex that overlap count as well.
  r.selfIntersectingPairs = 0;
  r.adjacentOverlapPairs = 2;
  EXPECT_FALSE(OutputVerdict::Of(r, OutputTargets()).Valid());
  // Not counted: nothing is claimed either way.
  r.selfIntersectionsComputed = false;
  EXPECT_TRUE(OutputVerdict::Of(r, OutputTargets()).Valid());
}

TEST(OutputVerdict, NonManifoldOrDegenerateOutputIsInvalid) {
  QualityReport r = GoodOutput();
  r.nonManifoldEdges = 1;
  EXPECT_FALSE(OutputVerdict::Of(r, OutputTargets()).Valid());
  r = GoodOutput();
  r.degenerateFaces = 3;
  const OutputVerdict v = OutputVerdict::Of(r, OutputTargets());
  EXPECT_FALSE(v.Valid());
  EXPECT_TRUE(Mentions(v.invalid, "3 degenerate faces"));
}

TEST(OutputVerdict, AnOpenOutputIsShortOfClosedAndSaysWhichLimitKeptTheHole) {
  QualityReport r = GoodOutput();
  r.boundaryEdges = 57;
  r.boundaryLoops = 2;
  OutputTargets targets;
  targets.unfilledHoles = 1;
  targets.largestUnfilledHoleEdges = 140;
  targets.maxHoleEdges = 100;
  OutputVerdict v = OutputVerdict::Of(r, targets);
  EXPECT_TRUE(v.Valid());
  EXPECT_FALSE(v.AllMet());
  EXPECT_TRUE(Mentions(v.shortOf, "not closed: 57 boundary edges in 2 loops"));
  EXPECT_TRUE(Mentions(v.shortOf, "hole size limit of 100 edges"));
  // A hole within the limit that stayed open had no valid fill.
  targets.largestUnfilledHoleEdges = 76;
  v = OutputVerdict::Of(r, targets);
  EXPECT_TRUE(Mentions(v.shortOf, "no valid fill"));
}

TEST(OutputVerdict, AngleAndValenceTargetsOnlyWhenTheirStagesRan) {
  QualityReport r = GoodOutput();
  r.angleMin = 13.3;
  r.angleMax = 138.4;
  r.v567Percent = 99.1;
  OutputTargets targets; // neither small-angle elimination nor valence optimization ran
  EXPECT_TRUE(OutputVerdict::Of(r, targets).AllMet());
  targets.checkAngles = true;
  targets.checkValence = true;
  const OutputVerdict v = OutputVerdict::Of(r, targets);
  EXPECT_TRUE(v.Valid());
  EXPECT_EQ(v.shortOf.size(), 3u);
  EXPECT_TRUE(Mentions(v.shortOf, "smallest angle 13.30 deg"));
  EXPECT_TRUE(Mentions(v.shortOf, "largest angle 138.40 deg"));
  EXPECT_TRUE(Mentions(v.shortOf, "V567 99.10 %"));
}

TEST(OutputVerdict, MissedAnglesNameTheVolumetricRebuildOnceUnlessItWasMadeOrTried) {
  QualityReport r = GoodOutput();
  r.angleMin = 13.3;
  r.angleMax = 138.4;
  OutputTargets targets;
  targets.checkAngles = true;
  auto advised = [](const OutputVerdict& v) {
    std::size_t n = 0;
    for (const auto& line : v.shortOf) n += line.find("volumetric rebuild") != std::string::npos;
    return n;
  };
  EXPECT_EQ(advised(OutputVerdict::Of(r, targets)), 1u); // on the last of the two angle lines
  r.angleMax = 88.0;
  EXPECT_EQ(advised(OutputVerdict::Of(r, targets)), 1u);
  targets.rebuildTried = true; // the pipeline ran on the rebuilt surface and did not keep it
  EXPECT_EQ(advised(OutputVerdict::Of(r, targets)), 0u);
  targets.rebuildTried = false;
  targets.rebuiltVolumetrically = true; // nothing thin is left to remove: no advice
  EXPECT_EQ(advised(OutputVerdict::Of(r, targets)), 0u);
  EXPECT_FALSE(OutputVerdict::Of(r, targets).AllMet());
}

// RemeshPipeline in process: the working frame of meshes far from the origin (CoordinateFrame), the
// target length as the output's mean edge length, a second run on an output changing it little, and
// a remesh asked for another length remeshed.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <string>

#include <vcg/complex/complex.h>
#include <vcg/complex/append.h>

#include <vcg_ext_instances/extern_mesh_d.h>
#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/io/mesh_io.h>
#include <vcg_ext/pipeline/coordinate_frame.h>
#include <vcg_ext/pipeline/remesh_pipeline.h>
#include <vcg_ext/quality/mesh_quality.h>

#include "remeshing_test_meshes.h"
#include "test_helpers.h"

using namespace molremesh;
using namespace molremesh::test;

namespace {

using Pipeline = RemeshPipeline<MeshD>;

/// Largest | |p - centre| - 1 | over the live vertices of m.
double LargestOffTheUnitSphere(const MeshD& m, const Point& centre) {
  double worst = 0;
  for (const auto& v : m.vert)
    if (!v.IsD()) worst = std::max(worst, std::fabs((PositionOf(&v) - centre).Norm() - 1.0));
  return worst;
}

} // namespace

TEST(CoordinateFrame, RecentresOnlyMeshesFarFromTheOriginAndMovesThemBackExactly) {
  MeshD near, far;
  Icosphere(near, 3, Point(50, -20, 30)); // as far as a molecule lies: left alone
  EXPECT_FALSE(CoordinateFrame<MeshD>::For(near).Recentres());
  Icosphere(far, 3, Point(1e7, 0, 5));
  const auto frame = CoordinateFrame<MeshD>::For(far);
  ASSERT_TRUE(frame.Recentres());
  EXPECT_EQ(frame.Offset()[0], 1e7);
  EXPECT_EQ(frame.Offset()[1], 0.0); // only the axes far from the origin move
  EXPECT_EQ(frame.Offset()[2], 0.0);
  MeshD copy;
  vcg::tri::Append<MeshD, MeshD>::MeshCopy(copy, far);
  frame.Enter(copy);
  for (const auto& v : copy.vert) EXPECT_LE(MaxAbs(PositionOf(&v)), 6.0);
  frame.Leave(copy);
  for (std::size_t i = 0; i < far.vert.size(); ++i) EXPECT_EQ(copy.vert[i].P(), far.vert[i].P());
  EXPECT_TRUE(frame.CoarseResolution(far).empty());
}

// A unit sphere at x = 1e15 took the CVT stage minutes (1e14: 28 s): every tolerance follows the
// coordinates' magnitude. In the recentred frame each offset takes about as long as at the origin,
// and an offset at which the doubles cannot resolve the edges is refused in one line.
TEST(RemeshPipeline, UnitSpheresFarFromTheOriginFinishFastWithAValidMeshOrOneClearError) {
  for (const double offset : {0.0, 1e7, 1e12, 1e15}) {
    SCOPED_TRACE("offset " + std::to_string(offset));
    const Point centre(offset, 0, 0);
    MeshD m;
    Icosphere(m, 4, centre); // 5120 faces, mean edge 0.055
    Pipeline::Params params;
    params.threads = 1;
    const auto start = std::chrono::steady_clock::now();
    const PipelineResult r = Pipeline::Do(m, params);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    EXPECT_LT(seconds, 60.0); // about a second at the origin on one core
    if (offset >= 1e15) {
      ASSERT_FALSE(r.ok);
      EXPECT_NE(r.message.find("only resolved to"), std::string::npos) << r.message;
      EXPECT_EQ(r.message.find('\n'), std::string::npos) << r.message;
      EXPECT_LT(LargestOffTheUnitSphere(m, centre), 1.0); // the input, unchanged
      continue;
    }
    ASSERT_TRUE(r.ok) << r.message;
    EXPECT_TRUE(r.verdict.AllMet()) << r.verdict.Lines("");
    const QualityReport& out = r.stages.back().after;
    ExpectTwoManifoldWithoutDegenerateFaces(out);
    ExpectNoSelfIntersection(out);
    EXPECT_EQ(out.components, 1u);
    EXPECT_EQ(out.genus, 0);
    EXPECT_GE(out.angleMin, 30.0);
    EXPECT_LT(out.angleMax, 90.0);
    EXPECT_GT(out.faces, 2000u);
    // Back where the input was: on its sphere (chords and the volume offset stay within 1 %).
    EXPECT_LT(LargestOffTheUnitSphere(m, centre), 0.01);
  }
}

// The target length is the output's mean edge length where the surface is smooth: a unit sphere
// remeshed at 0.1 (its input edges 0.055) has mean edge 0.1 within 10 %.
TEST(RemeshPipeline, MeanEdgeWithinTenPercentOfAnExplicitTargetOnASphere) {
  MeshD m;
  Icosphere(m, 4);
  Pipeline::Params params;
  params.targetEdgeLength = 0.1;
  const PipelineResult r = Pipeline::Do(m, params);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_TRUE(r.verdict.AllMet()) << r.verdict.Lines("");
  EXPECT_NEAR(r.stages.back().after.meanEdgeLength, 0.1, 0.01);
}

// Remeshing an output again with the same options changes it little: face count within 3 %, area
// within 0.1 %, the smallest angle not lower. By default the second run finds a remesh at L with the
// resolution RAR gives it and keeps it as it is (with the default target, L is the output's mean
// edge length, 0.8 L of the first run's: RAR's field capped at it used to add 30 % faces per run);
// with RAR's field scaled to a mean edge of L (meanEdgeAtTarget) the output's mean edge is L too.
TEST(RemeshPipeline, RemeshingItsOutputAgainChangesItLittle) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  MeshD input;
  std::string error;
  ASSERT_TRUE(LoadMesh(input, SharedMesh("bpti_1bpi_msms.ply"), error)) << error;
  for (const bool meanEdgeAtTarget : {false, true})
    for (const bool explicitTarget : {false, true}) {
      SCOPED_TRACE(std::string(meanEdgeAtTarget ? "field at a mean edge of L, " : "default field, ") +
                   (explicitTarget ? "explicit target" : "default target"));
      MeshD once, twice;
      vcg::tri::Append<MeshD, MeshD>::MeshCopy(once, input);
      Pipeline::Params params;
      params.rar.rar.meanEdgeAtTarget = meanEdgeAtTarget;
      const PipelineResult first = Pipeline::Do(once, params);
      ASSERT_TRUE(first.ok) << first.message;
      if (explicitTarget) params.targetEdgeLength = first.targetEdgeLength;
      vcg::tri::Append<MeshD, MeshD>::MeshCopy(twice, once);
      const PipelineResult second = Pipeline::Do(twice, params);
      ASSERT_TRUE(second.ok) << second.message;
      const QualityReport& a = first.stages.back().after;
      const QualityReport& b = second.stages.back().after;
      EXPECT_TRUE(second.verdict.AllMet()) << second.verdict.Lines("");
      EXPECT_NEAR(double(b.faces), double(a.faces), 0.03 * double(a.faces));
      EXPECT_NEAR(b.area, a.area, 0.001 * a.area);
      EXPECT_GE(b.angleMin, a.angleMin);
      if (meanEdgeAtTarget) {
        EXPECT_NEAR(a.meanEdgeLength, first.targetEdgeLength, 0.1 * first.targetEdgeLength);
      }
    }
}

// A remesh asked for a coarser mesh is remeshed, not kept: at 1.3 L it loses more than a fifth of
// its faces (the CVT stage resamples it), and at 0.8 L it gains more than a fifth.
TEST(RemeshPipeline, RemeshAskedForAnotherLengthIsRemeshed) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  MeshD once;
  std::string error;
  ASSERT_TRUE(LoadMesh(once, SharedMesh("bpti_1bpi_msms.ply"), error)) << error;
  const PipelineResult first = Pipeline::Do(once, Pipeline::Params());
  ASSERT_TRUE(first.ok) << first.message;
  const double faces = double(first.stages.back().after.faces);
  for (const double factor : {1.3, 0.8}) {
    SCOPED_TRACE("L x " + std::to_string(factor));
    MeshD twice;
    vcg::tri::Append<MeshD, MeshD>::MeshCopy(twice, once);
    Pipeline::Params params;
    params.targetEdgeLength = factor * first.targetEdgeLength;
    const PipelineResult second = Pipeline::Do(twice, params);
    ASSERT_TRUE(second.ok) << second.message;
    EXPECT_TRUE(second.verdict.AllMet()) << second.verdict.Lines("");
    const double ratio = double(second.stages.back().after.faces) / faces;
    if (factor > 1) {
      EXPECT_LT(ratio, 0.8);
    } else {
      EXPECT_GT(ratio, 1.2);
    }
  }
}

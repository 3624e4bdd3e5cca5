// The clean stage's volumetric fallback (vcg_ext/clean/volumetric_fallback.h): a surface the local
// steps leave broken is rebuilt from the union of what it encloses, cavities kept, and cleaned again;
// and the pipeline's second run on the rebuilt surface when the first one's angles miss their bounds.
// Linked with the volume layer (OpenVDB), as the CLI is.

#include <gtest/gtest.h>

#include <vcg_ext_instances/extern_mesh_d_volume.h>
#include <vcg_ext/clean/clean_raw_mesh.h>
#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/pipeline/remesh_pipeline.h>
#include <vcg_ext/quality/stage_summary.h>

#include <vcg/complex/algorithms/stat.h>
#include <vcg/complex/append.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "remeshing_test_meshes.h"

namespace {

using molremesh::MeshD;
using molremesh::Point;
using CleanStage = molremesh::CleanRawMesh<MeshD>;
using molremesh::QualityReport;

using Pipeline = molremesh::RemeshPipeline<MeshD>;

/// The pipeline on the mesh makeMesh builds into m: it runs and its output is valid.
template <class MakeMesh>
molremesh::PipelineResult RunPipeline(const MakeMesh& makeMesh, const Pipeline::Params& params, MeshD& m) {
  makeMesh(m);
  const molremesh::PipelineResult r = Pipeline::Do(m, params);
  EXPECT_TRUE(r.ok) << r.message;
  EXPECT_TRUE(r.verdict.Valid());
  return r;
}

/// The same vertices (bit for bit, in the same order) and as many faces.
void ExpectSameVertices(const MeshD& a, const MeshD& b) {
  ASSERT_EQ(a.vert.size(), b.vert.size());
  ASSERT_EQ(a.face.size(), b.face.size());
  for (std::size_t i = 0; i < a.vert.size(); ++i) ASSERT_EQ(a.vert[i].cP(), b.vert[i].cP());
}

/// Two interpenetrating balls of radius 10, 12 apart, the first holding a cavity of radius 2
/// (faces reversed: normals into the void), as one mesh.
void TwoBallsWithACavity(MeshD& m) {
  MeshD b, c;
  molremesh::test::Icosphere(m, 4, Point(0, 0, 0), Point(10, 10, 10));
  molremesh::test::Icosphere(b, 4, Point(12, 0, 0), Point(10, 10, 10));
  molremesh::test::Icosphere(c, 2, Point(-4, 0, 0), Point(2, 2, 2));
  for (auto& f : c.face) std::swap(f.V(1), f.V(2));
  vcg::tri::Append<MeshD, MeshD>::Mesh(m, b);
  vcg::tri::Append<MeshD, MeshD>::Mesh(m, c);
  vcg::tri::UpdateTopology<MeshD>::FaceFace(m);
  vcg::tri::UpdateTopology<MeshD>::VertexFace(m);
}

/// A ball of radius 10 (its volume into *ballVolume) and, apart from it, a closed slab 0.2 thick,
/// as one mesh with its FF and VF adjacency.
void BallAndSlab(MeshD& m, double* ballVolume = nullptr) {
  MeshD slab;
  molremesh::test::Icosphere(m, 4, Point(0, 0, 0), Point(10, 10, 10));
  if (ballVolume) *ballVolume = vcg::tri::Stat<MeshD>::ComputeMeshVolume(m);
  molremesh::test::Icosphere(slab, 3, Point(25, 0, 0), Point(3, 3, 0.1));
  vcg::tri::Append<MeshD, MeshD>::Mesh(m, slab);
  vcg::tri::UpdateTopology<MeshD>::FaceFace(m);
  vcg::tri::UpdateTopology<MeshD>::VertexFace(m);
}

/// The surface was rebuilt, and the rebuild cleaned into a closed, 2-manifold, coherently oriented
/// mesh with no degenerate face, no self-intersection and no defect left.
void ExpectAValidRebuild(const CleanStage::Result& r, MeshD& m) { // m: vcglib's check takes it non-const
  ASSERT_TRUE(r.fallback.available);
  ASSERT_TRUE(r.fallback.rebuilt) << r.fallback.message;
  EXPECT_EQ(r.reportAfter.boundaryEdges, 0u);
  EXPECT_EQ(r.reportAfter.nonManifoldEdges, 0u);
  EXPECT_EQ(r.reportAfter.nonManifoldVertices, 0u);
  EXPECT_EQ(r.reportAfter.degenerateFaces, 0u);
  EXPECT_EQ(r.reportAfter.selfIntersectingFaces, 0u);
  EXPECT_EQ(r.unrepairedTangles + r.unfilledHoles + r.nonOrientableComponents, 0u);
  EXPECT_TRUE(vcg::tri::Clean<MeshD>::IsCoherentlyOrientedMesh(m));
}

} // namespace

TEST(CleanFallback, InterpenetratingSheetsAreRebuiltAsTheirUnionWithTheCavityKept) {
  const double ball = 4.0 / 3.0 * molremesh::kPi * 1000.0;
  const double lens = molremesh::kPi * (40.0 + 12.0) * (20.0 - 12.0) * (20.0 - 12.0) / 12.0;
  const double cavity = 4.0 / 3.0 * molremesh::kPi * 8.0;
  const double expected = 2.0 * ball - lens - cavity;
  {
    MeshD m;
    TwoBallsWithACavity(m);
    const auto r = CleanStage::Do(m);
    ASSERT_TRUE(r.ok) << r.message;
    ASSERT_FALSE(r.fallback.trigger.empty()); // the local steps cannot untangle two closed sheets
    ExpectAValidRebuild(r, m);
    EXPECT_NEAR(r.reportAfter.volume, expected, 0.02 * expected);
    ASSERT_EQ(r.keptComponents.size(), 2u); // the union and the cavity
    EXPECT_GT(r.keptComponents[0].volume, 0);
    EXPECT_LT(r.keptComponents[1].volume, 0);
    EXPECT_NEAR(-r.keptComponents[1].volume, cavity, 0.1 * cavity);
    EXPECT_NE(molremesh::CleanRawMeshSummary(r).find("volumetric fallback: rebuilt"), std::string::npos);
  }
  {
    MeshD m;
    TwoBallsWithACavity(m);
    CleanStage::Params params;
    params.volumetricFallback = false;
    const auto r = CleanStage::Do(m, params);
    ASSERT_TRUE(r.ok) << r.message;
    EXPECT_FALSE(r.fallback.rebuilt);
    EXPECT_TRUE(r.fallback.trigger.empty()); // not looked at when off
    EXPECT_GT(r.reportAfter.selfIntersectingFaces, 0u);
  }
}

TEST(CleanFallback, RequestedRebuildOfAValidSurfaceDropsItsPartsThinnerThanTwoVoxels) {
  // A ball of radius 10 and, apart from it, a closed slab 0.2 thick: valid, so only the request
  // rebuilds it, at a voxel of half the mean edge (about 0.3), which leaves no room inside the slab.
  double ballVolume = 0;
  auto ballAndSlab = [&ballVolume](MeshD& m) { BallAndSlab(m, &ballVolume); };
  {
    MeshD m;
    ballAndSlab(m);
    const auto r = CleanStage::Do(m);
    ASSERT_TRUE(r.ok) << r.message;
    EXPECT_TRUE(r.fallback.trigger.empty());
    EXPECT_EQ(r.keptComponents.size(), 2u);
  }
  MeshD m;
  ballAndSlab(m);
  CleanStage::Params params;
  params.volumetricRebuild = true;
  const auto r = CleanStage::Do(m, params);
  ASSERT_TRUE(r.ok) << r.message;
  ExpectAValidRebuild(r, m);
  EXPECT_NE(r.fallback.trigger.find("volumetricRebuild"), std::string::npos);
  ASSERT_EQ(r.keptComponents.size(), 1u); // the slab is gone
  EXPECT_NEAR(r.keptComponents[0].volume, ballVolume, 0.01 * ballVolume);
  vcg::Box3<double> box;
  for (const auto& v : m.vert)
    if (!v.IsD()) box.Add(v.cP());
  EXPECT_LT(box.max[0], 10.5); // nothing left where the slab was
}

TEST(RebuildRetry, AnglesOutOfBoundsAtAThinSlabAreRemeshedAgainWithoutIt) {
  // The ball and slab above through the whole pipeline: no remesh at the ball's edge length keeps
  // the slab's rim within [30, 90] degrees, so the pipeline runs again on the rebuilt surface
  // (the run --volumetric-rebuild asks for) and keeps it; the ball alone is remeshed once.
  auto run = [](const Pipeline::Params& params, MeshD& m) {
    return RunPipeline([](MeshD& mesh) { BallAndSlab(mesh); }, params, m);
  };
  Pipeline::Params once;
  once.rebuildWhenAnglesMiss = false;
  MeshD first, retried, rebuilt;
  const auto a = run(once, first);
  const QualityReport& outA = a.stages.back().after;
  ASSERT_TRUE(outA.angleMin < 30.0 || outA.angleMax > 90.0) << outA.angleMin << " " << outA.angleMax;
  EXPECT_FALSE(a.rebuildRetry.tried);
  EXPECT_EQ(outA.components, 2u);

  const auto b = run(Pipeline::Params(), retried);
  EXPECT_TRUE(b.rebuildRetry.tried);
  EXPECT_TRUE(b.rebuildRetry.kept) << b.rebuildRetry.message;
  EXPECT_TRUE(b.rebuiltVolumetrically);
  const QualityReport& outB = b.stages.back().after;
  EXPECT_EQ(outB.components, 1u);
  EXPECT_GE(outB.angleMin, 30.0 - 1e-9);
  EXPECT_LE(outB.angleMax, 90.0 + 1e-9);
  EXPECT_EQ(outB.boundaryEdges, 0u);
  EXPECT_NE(b.rebuildRetry.message.find("kept"), std::string::npos);

  // The slab's area is about 4 % of the ball's: with a cap of 1 % on the area change the second
  // output is not kept, and the mesh is the first run's.
  Pipeline::Params capped;
  capped.retryMaxAreaChange = 0.01;
  MeshD notKept;
  const auto e = run(capped, notKept);
  EXPECT_TRUE(e.rebuildRetry.tried);
  EXPECT_FALSE(e.rebuildRetry.kept);
  EXPECT_NE(e.rebuildRetry.message.find("retryMaxAreaChange"), std::string::npos) << e.rebuildRetry.message;
  ExpectSameVertices(notKept, first);
  EXPECT_EQ(e.stages.back().after.components, 2u);

  Pipeline::Params rebuild;
  rebuild.clean.volumetricRebuild = true;
  const auto c = run(rebuild, rebuilt);
  EXPECT_FALSE(c.rebuildRetry.tried); // asked for already
  ExpectSameVertices(retried, rebuilt);

  MeshD ball;
  molremesh::test::Icosphere(ball, 4, Point(0, 0, 0), Point(10, 10, 10));
  vcg::tri::UpdateTopology<MeshD>::FaceFace(ball);
  vcg::tri::UpdateTopology<MeshD>::VertexFace(ball);
  const molremesh::PipelineResult d = Pipeline::Do(ball, Pipeline::Params());
  EXPECT_TRUE(d.ok) << d.message;
  EXPECT_FALSE(d.rebuildRetry.tried);
}

TEST(RebuildRetry, AnOpenDiscWhoseRebuildIsRefusedIsNotRemeshedAgain) {
  // A 100-gon fanned from one corner encloses no volume: its angles miss their bounds (its rim is
  // kept), the rebuild is refused, and the second run stops after its clean stage. The output is
  // the first run's.
  auto fan = [](MeshD& m) {
    constexpr int kCorners = 100;
    auto v = vcg::tri::Allocator<MeshD>::AddVertices(m, kCorners);
    for (int i = 0; i < kCorners; ++i, ++v)
      v->P() = Point(std::cos(2 * M_PI * i / kCorners), std::sin(2 * M_PI * i / kCorners), 0);
    for (int i = 1; i + 1 < kCorners; ++i)
      vcg::tri::Allocator<MeshD>::AddFace(m, &m.vert[0], &m.vert[i], &m.vert[i + 1]);
    vcg::tri::UpdateTopology<MeshD>::FaceFace(m);
    vcg::tri::UpdateTopology<MeshD>::VertexFace(m);
  };
  std::vector<std::string> lines;
  auto log = [&lines](const std::string& line) { lines.push_back(line); };
  MeshD retried, once;
  fan(retried);
  const molremesh::PipelineResult r = Pipeline::Do(retried, Pipeline::Params(), log);
  ASSERT_TRUE(r.ok) << r.message;
  const QualityReport& out = r.stages.back().after;
  ASSERT_TRUE(out.angleMin < 30.0 || out.angleMax > 90.0) << out.angleMin << " " << out.angleMax;
  EXPECT_TRUE(r.rebuildRetry.tried);
  EXPECT_FALSE(r.rebuildRetry.kept);
  EXPECT_NE(r.rebuildRetry.message.find("not remeshed again: the rebuild was refused"), std::string::npos)
      << r.rebuildRetry.message;
  EXPECT_EQ(std::count(lines.begin(), lines.end(), std::string("stage clean ...")), 2);
  EXPECT_EQ(std::count(lines.begin(), lines.end(), std::string("stage cvt ...")), 1);

  Pipeline::Params noRetry;
  noRetry.rebuildWhenAnglesMiss = false;
  fan(once);
  ASSERT_TRUE(Pipeline::Do(once, noRetry).ok);
  ExpectSameVertices(retried, once);
}

TEST(RebuildRetry, NarrowGapsMakeTheRunOnTheRebuiltSurfaceFirst) {
  // Two balls of radius 10, 0.1 apart: about 0.6 % of their area faces the other ball within half
  // the edge length, more than rebuildFirstGapShare. The run on the rebuilt surface (the balls
  // joined where they nearly touch) is made first and kept; it is the output --volumetric-rebuild
  // gives. When it is not kept (here: a 0.1 % cap on the area change), the run without the rebuild
  // follows and the output is the one the pipeline gives without the check.
  auto twoBalls = [](MeshD& m) {
    MeshD b;
    molremesh::test::Icosphere(m, 4, Point(-10.05, 0, 0), Point(10, 10, 10));
    molremesh::test::Icosphere(b, 4, Point(10.05, 0, 0), Point(10, 10, 10));
    vcg::tri::Append<MeshD, MeshD>::Mesh(m, b);
    vcg::tri::UpdateTopology<MeshD>::FaceFace(m);
    vcg::tri::UpdateTopology<MeshD>::VertexFace(m);
  };
  auto run = [&twoBalls](const Pipeline::Params& params, MeshD& m) {
    return RunPipeline(twoBalls, params, m);
  };
  MeshD checked, rebuilt;
  const auto a = run(Pipeline::Params(), checked);
  EXPECT_TRUE(a.rebuildRetry.first);
  EXPECT_TRUE(a.rebuildRetry.kept) << a.rebuildRetry.message;
  EXPECT_TRUE(a.rebuiltVolumetrically);
  EXPECT_NE(a.rebuildRetry.message.find("faces the surface again"), std::string::npos)
      << a.rebuildRetry.message;
  const QualityReport& out = a.stages.back().after;
  EXPECT_EQ(out.components, 1u);
  EXPECT_GE(out.angleMin, 30.0 - 1e-9);
  EXPECT_LE(out.angleMax, 90.0 + 1e-9);
  Pipeline::Params rebuild;
  rebuild.clean.volumetricRebuild = true;
  run(rebuild, rebuilt);
  ExpectSameVertices(checked, rebuilt);

  Pipeline::Params capped, cappedUnchecked;
  capped.retryMaxAreaChange = cappedUnchecked.retryMaxAreaChange = 0.001;
  cappedUnchecked.rebuildFirstGapShare = 0;
  MeshD notKept, unchecked;
  const auto b = run(capped, notKept);
  EXPECT_TRUE(b.rebuildRetry.first);
  EXPECT_FALSE(b.rebuildRetry.kept) << b.rebuildRetry.message;
  const auto c = run(cappedUnchecked, unchecked);
  EXPECT_FALSE(c.rebuildRetry.first);
  ExpectSameVertices(notKept, unchecked);
  EXPECT_EQ(b.stages.back().after.components, c.stages.back().after.components);
}

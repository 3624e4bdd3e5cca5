// ObtuseReduction (stage 5): obtuse triangles of a constructed sphere get fewer and less obtuse, the
// harsh real inputs (after small-angle elimination) lose most of their obtuse triangles without any
// new angle below 30 degrees, the remeshing invariants hold, refused inputs are left untouched and the
// output is deterministic; the crease pass leaves no more obtuse triangles than the rounds alone.
#include <gtest/gtest.h>

#include <vcg/complex/complex.h>

#include <cmath>
#include <string>
#include <vector>

#include <vcg_ext_instances/extern_mesh_d.h>
#include <vcg_ext/quality/mesh_quality.h>
#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/stages/obtuse_reduction.h>
#include <vcg_ext/quality/stage_summary.h>
#include <vcg_ext/pipeline/remesh_pipeline.h>

#include "local_stage_test_helpers.h"

using molremesh::MeshD;
using Obtuse = molremesh::ObtuseReduction<MeshD>;
using Quality = molremesh::MeshQuality<MeshD>;
using Reference = molremesh::ReferenceSurface<MeshD>;
using molremesh::test::ObtuseSphere;
using molremesh::test::SameMesh;

namespace {

/// The shared mesh `name` after the pipeline's stages clean (+ cvt) + small.
void LoadPrepared(MeshD& m, const std::string& name, bool cvt) {
  molremesh::test::LoadPrepared(m, name, cvt, {molremesh::PipelineStage::Small});
}

Obtuse::Params ParamsFor(const MeshD& m) {
  return molremesh::test::ParamsFor<Obtuse>(m);
}

} // namespace

TEST(ObtuseReduction, ReducesTheObtuseTrianglesOfAConstructedSphere) {
  MeshD m;
  ObtuseSphere(m);
  const molremesh::QualityReport before = Quality::Compute(m);
  ASSERT_GT(before.angleMax, 110.0);
  ASSERT_GT(before.obtuseFaces, 0u);
  Reference reference;
  ASSERT_TRUE(reference.Build(m));
  const Obtuse::Result r = Obtuse::Do(m, reference, ParamsFor(m));
  ASSERT_TRUE(r.ok) << r.message;
  const molremesh::QualityReport after = Quality::Compute(m);
  EXPECT_LT(after.angleMax, 90.0) << ObtuseReductionSummary(r);
  EXPECT_EQ(after.obtuseFaces, 0u) << ObtuseReductionSummary(r);
  EXPECT_GE(after.angleMin, std::min(before.angleMin, 30.0) - 1e-9);
  EXPECT_EQ(r.obtuseAfter, after.obtuseFaces);
  molremesh::test::ExpectTwoManifoldWithoutDegenerateFaces(after);
  molremesh::test::ExpectNoSelfIntersection(after);
  molremesh::test::ExpectComponentsClosedWithTheirGenus(before, after);
}

TEST(ObtuseReduction, PentagonInsertionAloneRemovesObtuseTriangles) {
  MeshD m;
  ObtuseSphere(m);
  const molremesh::QualityReport before = Quality::Compute(m);
  Reference reference;
  ASSERT_TRUE(reference.Build(m));
  Obtuse::Params p = ParamsFor(m);
  p.iterationsPerThreshold = 0; // no translation round: only the insertions (and one last round)
  const Obtuse::Result r = Obtuse::Do(m, reference, p);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_GT(r.insertions, 0u) << ObtuseReductionSummary(r);
  const molremesh::QualityReport after = Quality::Compute(m);
  EXPECT_LT(after.obtuseFaces, before.obtuseFaces);
  EXPECT_GE(after.angleMin, std::min(before.angleMin, 30.0) - 1e-9);
  molremesh::test::ExpectTwoManifoldWithoutDegenerateFaces(after);
  molremesh::test::ExpectNoSelfIntersection(after);
  molremesh::test::ExpectComponentsClosedWithTheirGenus(before, after);
}

// Where the vertex at the largest angle cannot move (here: locked, as on a region's border), the
// stage moves the two other corners of the triangle instead; the locked vertices stay put.
TEST(ObtuseReduction, TriangleWhoseObtuseCornerIsLockedIsReducedByItsOtherCorners) {
  MeshD m;
  ObtuseSphere(m);
  const molremesh::QualityReport before = Quality::Compute(m);
  ASSERT_GT(before.angleMax, 110.0);
  Obtuse::Params p = ParamsFor(m);
  p.pentagonInsertion = false; // translations only
  p.lockedVertices.assign(m.vert.size(), 0);
  std::vector<std::pair<std::size_t, vcg::Point3d>> locked;
  for (std::size_t fi = 0; fi < m.face.size(); fi += 97) { // the corners ObtuseSphere pushed
    const std::size_t vi = vcg::tri::Index(m, m.face[fi].V(0));
    p.lockedVertices[vi] = 1;
    locked.push_back({vi, vcg::Point3d::Construct(m.vert[vi].cP())});
  }
  Reference reference;
  ASSERT_TRUE(reference.Build(m));
  const Obtuse::Result r = Obtuse::Do(m, reference, p);
  ASSERT_TRUE(r.ok) << r.message;
  const molremesh::QualityReport after = Quality::Compute(m);
  EXPECT_LT(after.angleMax, 90.0) << ObtuseReductionSummary(r);
  EXPECT_EQ(after.obtuseFaces, 0u) << ObtuseReductionSummary(r);
  EXPECT_GE(after.angleMin, std::min(before.angleMin, 30.0) - 1e-9);
  for (const auto& [vi, position] : locked)
    EXPECT_EQ(vcg::Point3d::Construct(m.vert[vi].cP()), position) << "locked vertex " << vi << " moved";
  molremesh::test::ExpectTwoManifoldWithoutDegenerateFaces(after);
  molremesh::test::ExpectNoSelfIntersection(after);
}

TEST(ObtuseReduction, MeshWithoutObtuseAnglesIsLeftAsItIs) {
  MeshD m;
  molremesh::test::Icosphere(m, 4);
  molremesh::test::UpdateAdjacency(m);
  ASSERT_LT(Quality::Compute(m).angleMax, 90.0);
  const Obtuse::Result r = molremesh::test::ExpectScanOnly<Obtuse>(m);
  EXPECT_EQ(r.obtuseBefore, 0u);
}

TEST(ObtuseReduction, RefusedInputsAreLeftUntouched) {
  Reference sphereReference;
  {
    MeshD sphere;
    molremesh::test::Icosphere(sphere, 2);
    ASSERT_TRUE(sphereReference.Build(sphere));
  }
  // The fin has an obtuse triangle.
  molremesh::test::ExpectEmptyAndNonManifoldInputsRefused<Obtuse>(
      sphereReference, {{0, 0, 0}, {1, 0, 0}, {0.5, 0.1, 0}, {0, -1, 0}, {0, 0, 1}});

  MeshD obtuse;
  ObtuseSphere(obtuse);
  MeshD obtuseCopy;
  vcg::tri::Append<MeshD, MeshD>::MeshCopy(obtuseCopy, obtuse);
  Obtuse::Params bad = ParamsFor(obtuse);
  bad.thresholdsDeg = {};
  EXPECT_FALSE(Obtuse::Do(obtuse, sphereReference, bad).ok);
  bad.thresholdsDeg = {110, 40};
  EXPECT_FALSE(Obtuse::Do(obtuse, sphereReference, bad).ok);
  EXPECT_TRUE(SameMesh(obtuse, obtuseCopy));
  EXPECT_FALSE(Obtuse::Do(obtuse, Reference(), ParamsFor(obtuse)).ok);
  EXPECT_TRUE(SameMesh(obtuse, obtuseCopy));
}

TEST(ObtuseReduction, SameOutputForOneAndTwoThreadsAndForTheSameSeed) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  MeshD a;
  LoadPrepared(a, "galactose_grasp.ply", false);
  molremesh::test::ExpectSameOutputForOneAndTwoThreads<Obtuse>(a);
}

// --- Real meshes after small-angle elimination ------------------------------------------------------

struct RealCase {
  const char* mesh;
  bool cvt;
  double maxObtusePercent; ///< measured after the stage (README), with a margin
};

class ObtuseReductionReal : public ::testing::TestWithParam<RealCase> {};

TEST_P(ObtuseReductionReal, ReducesObtuseTrianglesWithoutSmallAnglesAndKeepsTheInvariants) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  const RealCase c = GetParam();
  molremesh::test::RealRun run;
  LoadPrepared(run.input, c.mesh, c.cvt);
  Obtuse::Result r;
  ASSERT_NO_FATAL_FAILURE(molremesh::test::RunOnCopy<Obtuse>(run, r));
  const molremesh::QualityReport &before = run.before, &after = run.after;
  EXPECT_LT(after.obtusePercent, before.obtusePercent) << ObtuseReductionSummary(r);
  EXPECT_LE(after.obtusePercent, c.maxObtusePercent) << ObtuseReductionSummary(r);
  EXPECT_LE(after.angleMax, before.angleMax);
  EXPECT_LE(after.smallAngleFaces, before.smallAngleFaces);
  EXPECT_GE(after.angleMin, std::min(before.angleMin, 30.0) - 1e-9);
  molremesh::test::ExpectLocalStageInvariants(run);
}

INSTANTIATE_TEST_SUITE_P(Meshes, ObtuseReductionReal,
                         ::testing::Values(RealCase{"lysozyme_Lys1_msms.ply", false, 7.5},
                                           RealCase{"galactose_grasp.ply", false, 5.5},
                                           RealCase{"bpti_1bpi_msms.ply", true, 0.2},
                                           RealCase{"ubiquitin_1UBQ_pymol_ses.ply", true, 0.1}),
                         [](const ::testing::TestParamInfo<RealCase>& param) {
                           std::string name = param.param.mesh;
                           name = name.substr(0, name.find('.'));
                           return name + (param.param.cvt ? "_clean_cvt_small" : "_clean_small");
                         });

TEST(ObtuseReduction, CreasePassLeavesNoMoreObtuseFacesThanTheRoundsAlone) {
  // EDTSurf's twisted hole after clean, CVT, valence, RAR and small: a few faces stay obtuse where
  // the surface folds within an edge length, and the default guards refuse every translation there.
  using Pipeline = molremesh::RemeshPipeline<MeshD>;
  MeshD m;
  std::string error;
  ASSERT_TRUE(molremesh::LoadMesh(m, molremesh::test::Fixture("edtsurf_twisted_hole.ply"), error)) << error;
  Pipeline::Params params;
  params.stages = {molremesh::PipelineStage::Clean,   molremesh::PipelineStage::Cvt,
                   molremesh::PipelineStage::Valence, molremesh::PipelineStage::Segment,
                   molremesh::PipelineStage::Rar,     molremesh::PipelineStage::Small};
  ASSERT_TRUE(Pipeline::Do(m, params).ok);
  molremesh::test::UpdateAdjacency(m);
  Reference reference;
  ASSERT_TRUE(reference.Build(m));
  const molremesh::QualityReport before = Quality::Compute(m);

  auto run = [&](bool crease, MeshD& out, Obtuse::Result& r) {
    vcg::tri::Append<MeshD, MeshD>::MeshCopy(out, m);
    molremesh::test::UpdateAdjacency(out);
    Obtuse::Params p = ParamsFor(out);
    if (!crease) p.creaseNormalDeviationDeg = 0;
    r = Obtuse::Do(out, reference, p);
    ASSERT_TRUE(r.ok) << r.message;
  };
  MeshD without, with;
  Obtuse::Result off, on;
  run(false, without, off);
  run(true, with, on);
  EXPECT_FALSE(off.creasePass);
  ASSERT_TRUE(on.creasePass) << ObtuseReductionSummary(on);
  EXPECT_LE(on.obtuseAfter, off.obtuseAfter) << ObtuseReductionSummary(on) << ObtuseReductionSummary(off);
  const molremesh::QualityReport after = Quality::Compute(with);
  EXPECT_GE(after.angleMin, std::min(before.angleMin, 30.0) - 1e-9);
  molremesh::test::ExpectTwoManifoldWithoutDegenerateFaces(after);
  molremesh::test::ExpectNoSelfIntersection(after);
  molremesh::test::ExpectComponentsClosedWithTheirGenus(before, after);
}

// LocalSmoothing (stage 6): the bad triangles (angle < 30 or >= 90 degrees) of a constructed sphere
// and of real meshes after stages 4 and 5 get fewer, with no new small angle and no larger largest
// angle, the remeshing invariants hold, refused inputs are left untouched, the output is deterministic.
#include <gtest/gtest.h>

#include <vcg/complex/complex.h>

#include <cmath>
#include <string>
#include <vector>

#include <vcg_ext_instances/extern_mesh_d.h>
#include <vcg_ext/stages/local_smoothing.h>
#include <vcg_ext/quality/stage_summary.h>
#include <vcg_ext/quality/mesh_quality.h>
#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/pipeline/remesh_pipeline.h>

#include "local_stage_test_helpers.h"

using molremesh::MeshD;
using Smoothing = molremesh::LocalSmoothing<MeshD>;
using Quality = molremesh::MeshQuality<MeshD>;
using Reference = molremesh::ReferenceSurface<MeshD>;
using molremesh::test::ObtuseSphere;
using molremesh::test::SameMesh;

namespace {

/// The shared mesh `name` after the pipeline's stages clean (+ cvt) + small + obtuse.
void LoadPrepared(MeshD& m, const std::string& name, bool cvt, bool obtuse = true) {
  std::vector<molremesh::PipelineStage> stages{molremesh::PipelineStage::Small};
  if (obtuse) stages.push_back(molremesh::PipelineStage::Obtuse);
  molremesh::test::LoadPrepared(m, name, cvt, stages);
}

Smoothing::Params ParamsFor(const MeshD& m) {
  return molremesh::test::ParamsFor<Smoothing>(m);
}

} // namespace

TEST(LocalSmoothing, ReducesTheBadTrianglesOfAConstructedSphere) {
  MeshD m;
  ObtuseSphere(m);
  const molremesh::QualityReport before = Quality::Compute(m);
  ASSERT_GT(before.obtuseFaces, 0u);
  Reference reference;
  ASSERT_TRUE(reference.Build(m));
  const Smoothing::Result r = Smoothing::Do(m, reference, ParamsFor(m));
  ASSERT_TRUE(r.ok) << r.message;
  const molremesh::QualityReport after = Quality::Compute(m);
  EXPECT_LT(r.badAfter, r.badBefore) << LocalSmoothingSummary(r);
  EXPECT_LT(after.obtuseFaces, before.obtuseFaces) << LocalSmoothingSummary(r);
  EXPECT_LE(after.smallAngleFaces, before.smallAngleFaces);
  EXPECT_LE(after.angleMax, before.angleMax);
  EXPECT_GE(after.angleMin, std::min(before.angleMin, 30.0) - 1e-9);
  molremesh::test::ExpectTwoManifoldWithoutDegenerateFaces(after);
  molremesh::test::ExpectNoSelfIntersection(after);
  molremesh::test::ExpectComponentsClosedWithTheirGenus(before, after);
}

TEST(LocalSmoothing, MeshWithoutBadTrianglesIsLeftAsItIs) {
  MeshD m;
  molremesh::test::Icosphere(m, 4);
  molremesh::test::UpdateAdjacency(m);
  const molremesh::QualityReport q = Quality::Compute(m);
  ASSERT_LT(q.angleMax, 90.0);
  ASSERT_GE(q.angleMin, 30.0);
  const Smoothing::Result r = molremesh::test::ExpectScanOnly<Smoothing>(m);
  EXPECT_EQ(r.badBefore, 0u);
}

TEST(LocalSmoothing, RefusedInputsAreLeftUntouched) {
  Reference sphereReference;
  {
    MeshD sphere;
    molremesh::test::Icosphere(sphere, 2);
    ASSERT_TRUE(sphereReference.Build(sphere));
  }
  // The fin has an obtuse triangle.
  molremesh::test::ExpectEmptyAndNonManifoldInputsRefused<Smoothing>(
      sphereReference, {{0, 0, 0}, {1, 0, 0}, {0.5, 0.1, 0}, {0, -1, 0}, {0, 0, 1}});

  MeshD obtuse;
  ObtuseSphere(obtuse);
  MeshD obtuseCopy;
  vcg::tri::Append<MeshD, MeshD>::MeshCopy(obtuseCopy, obtuse);
  Smoothing::Params bad = ParamsFor(obtuse);
  bad.maxAngleDeg = 50;
  EXPECT_FALSE(Smoothing::Do(obtuse, sphereReference, bad).ok);
  bad = ParamsFor(obtuse);
  bad.iterations = -1;
  EXPECT_FALSE(Smoothing::Do(obtuse, sphereReference, bad).ok);
  EXPECT_TRUE(SameMesh(obtuse, obtuseCopy));
  EXPECT_FALSE(Smoothing::Do(obtuse, Reference(), ParamsFor(obtuse)).ok);
  EXPECT_TRUE(SameMesh(obtuse, obtuseCopy));
}

TEST(LocalSmoothing, SameOutputForOneAndTwoThreadsAndForTheSameSeed) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  MeshD a;
  LoadPrepared(a, "lysozyme_Lys1_msms.ply", false);
  molremesh::test::ExpectSameOutputForOneAndTwoThreads<Smoothing>(a);
}

// --- Real meshes after small-angle elimination and obtuse reduction ---------------------------------
// (ubiquitin PyMOL after small-angle elimination only: the 25 obtuse faces of its 10 410 that obtuse
// reduction leaves, up to 95.4 degrees, are beyond smoothing's edits as well.)

struct RealCase {
  const char* mesh;
  bool cvt;
  bool obtuse = true; ///< obtuse reduction before smoothing
};

class LocalSmoothingReal : public ::testing::TestWithParam<RealCase> {};

TEST_P(LocalSmoothingReal, ReducesBadTrianglesWithoutNewSmallAnglesAndKeepsTheInvariants) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  const RealCase c = GetParam();
  molremesh::test::RealRun run;
  LoadPrepared(run.input, c.mesh, c.cvt, c.obtuse);
  Smoothing::Result r;
  ASSERT_NO_FATAL_FAILURE(molremesh::test::RunOnCopy<Smoothing>(run, r));
  const molremesh::QualityReport &before = run.before, &after = run.after;
  EXPECT_LE(r.badAfter, r.badBefore) << LocalSmoothingSummary(r);
  if (r.badBefore > 0) {
    EXPECT_LT(after.obtusePercent, before.obtusePercent) << LocalSmoothingSummary(r);
  }
  EXPECT_LE(after.smallAngleFaces, before.smallAngleFaces);
  EXPECT_GE(after.angleMin, std::min(before.angleMin, 30.0) - 1e-9);
  EXPECT_LE(after.angleMax, std::max(before.angleMax, 90.0));
  molremesh::test::ExpectLocalStageInvariants(run);
}

INSTANTIATE_TEST_SUITE_P(Meshes, LocalSmoothingReal,
                         ::testing::Values(RealCase{"lysozyme_Lys1_msms.ply", false},
                                           RealCase{"galactose_grasp.ply", false},
                                           RealCase{"bpti_1bpi_msms.ply", false},
                                           RealCase{"ubiquitin_1UBQ_pymol_ses.ply", false, false}),
                         [](const ::testing::TestParamInfo<RealCase>& param) {
                           std::string name = param.param.mesh;
                           name = name.substr(0, name.find('.'));
                           return name + (param.param.cvt ? "_clean_cvt_small" : "_clean_small") +
                                  (param.param.obtuse ? "_obtuse" : "");
                         });

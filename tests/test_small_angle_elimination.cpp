// SmallAngleElimination (stage 4): slivers on a constructed sphere disappear, the harsh real
// inputs (clean only, clean + CVT) keep no angle below 30 degrees, the remeshing invariants hold,
// refused inputs are left untouched, and the output is deterministic.
#include <gtest/gtest.h>

#include <vcg/complex/complex.h>

#include <cmath>
#include <string>
#include <vector>

#include <vcg_ext_instances/extern_mesh_d.h>
#include <vcg_ext/quality/mesh_quality.h>
#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/pipeline/remesh_pipeline.h>
#include <vcg_ext/stages/small_angle_elimination.h>

#include "local_stage_test_helpers.h"

using molremesh::MeshD;
using Small = molremesh::SmallAngleElimination<MeshD>;
using Quality = molremesh::MeshQuality<MeshD>;
using Reference = molremesh::ReferenceSurface<MeshD>;
using molremesh::test::SameMesh;

namespace {

/// The shared mesh `name` after the pipeline's stages (clean, or clean + cvt).
void LoadPrepared(MeshD& m, const std::string& name, bool cvt) {
  molremesh::test::LoadPrepared(m, name, cvt, {});
}

/// Unit icosphere with slivers: every vertex of a few faces is pulled most of the way toward a
/// neighbour (and put back on the sphere), which leaves angles of a few degrees.
void SliverSphere(MeshD& m) {
  molremesh::test::Icosphere(m, 3);
  molremesh::test::UpdateAdjacency(m);
  for (std::size_t fi = 0; fi < m.face.size(); fi += 97) {
    auto& f = m.face[fi];
    const vcg::Point3d a = f.P(0), b = f.P(1);
    f.V(0)->P() = (a + (b - a) * 0.85).Normalize();
  }
  molremesh::test::UpdateAdjacency(m);
}

Small::Params ParamsFor(const MeshD& m) {
  return molremesh::test::ParamsFor<Small>(m);
}

} // namespace

TEST(SmallAngleElimination, RemovesTheSliversOfAConstructedSphere) {
  MeshD m;
  SliverSphere(m);
  const molremesh::QualityReport before = Quality::Compute(m);
  ASSERT_LT(before.angleMin, 10.0);
  Reference reference;
  ASSERT_TRUE(reference.Build(m));
  const Small::Result r = Small::Do(m, reference, ParamsFor(m));
  ASSERT_TRUE(r.ok) << r.message;
  const molremesh::QualityReport after = Quality::Compute(m);
  EXPECT_EQ(after.smallAngleFaces, 0u) << SmallAngleEliminationSummary(r);
  EXPECT_GE(after.angleMin, 30.0 - 1e-9);
  EXPECT_EQ(r.smallFacesAfter, 0u);
  EXPECT_GT(r.smallFacesBefore, 0u);
  molremesh::test::ExpectTwoManifoldWithoutDegenerateFaces(after);
  molremesh::test::ExpectNoSelfIntersection(after);
  molremesh::test::ExpectComponentsClosedWithTheirGenus(before, after);
}

TEST(SmallAngleElimination, MeshWithoutSmallAnglesIsLeftAsItIs) {
  MeshD m;
  molremesh::test::Icosphere(m, 4);
  molremesh::test::UpdateAdjacency(m);
  ASSERT_GE(Quality::Compute(m).angleMin, 30.0);
  const Small::Result r = molremesh::test::ExpectScanOnly<Small>(m);
  EXPECT_EQ(r.smallFacesBefore, 0u);
}

TEST(SmallAngleElimination, RefusedInputsAreLeftUntouched) {
  Reference sphereReference;
  {
    MeshD sphere;
    molremesh::test::Icosphere(sphere, 2);
    ASSERT_TRUE(sphereReference.Build(sphere));
  }
  // The fin has a small angle.
  molremesh::test::ExpectEmptyAndNonManifoldInputsRefused<Small>(
      sphereReference, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0.5, 0.02, 1}});

  MeshD sliver;
  SliverSphere(sliver);
  MeshD sliverCopy;
  vcg::tri::Append<MeshD, MeshD>::MeshCopy(sliverCopy, sliver);
  Small::Params bad = ParamsFor(sliver);
  bad.minAngleDeg = 75; // no triangle can have every angle above 60 degrees
  EXPECT_FALSE(Small::Do(sliver, sphereReference, bad).ok);
  EXPECT_TRUE(SameMesh(sliver, sliverCopy));
  EXPECT_FALSE(Small::Do(sliver, Reference(), ParamsFor(sliver)).ok);
  EXPECT_TRUE(SameMesh(sliver, sliverCopy));
}

TEST(SmallAngleElimination, SameOutputForOneAndTwoThreadsAndForTheSameSeed) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  MeshD a;
  LoadPrepared(a, "lysozyme_Lys1_msms.ply", false);
  molremesh::test::ExpectSameOutputForOneAndTwoThreads<Small>(a);
}

// --- Real meshes: the harsh inputs the stage is for ------------------------------------------------

struct RealCase {
  const char* mesh;
  bool cvt;
};

class SmallAngleEliminationReal : public ::testing::TestWithParam<RealCase> {};

TEST_P(SmallAngleEliminationReal, LeavesNoAngleBelow30AndKeepsTheInvariants) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  const RealCase c = GetParam();
  molremesh::test::RealRun run;
  LoadPrepared(run.input, c.mesh, c.cvt);
  Small::Result r;
  ASSERT_NO_FATAL_FAILURE(molremesh::test::RunOnCopy<Small>(run, r));
  const molremesh::QualityReport& after = run.after;
  EXPECT_EQ(after.smallAngleFaces, 0u) << SmallAngleEliminationSummary(r);
  EXPECT_EQ(r.smallFacesAfter, after.smallAngleFaces);
  molremesh::test::ExpectLocalStageInvariants(run);
}

INSTANTIATE_TEST_SUITE_P(Meshes, SmallAngleEliminationReal,
                         ::testing::Values(RealCase{"lysozyme_Lys1_msms.ply", false},
                                           RealCase{"galactose_grasp.ply", false},
                                           RealCase{"ubiquitin_1UBQ_pymol_ses.ply", false},
                                           RealCase{"bpti_1bpi_msms.ply", true},
                                           RealCase{"ubiquitin_1UBQ_pymol_ses.ply", true}),
                         [](const ::testing::TestParamInfo<RealCase>& param) {
                           std::string name = param.param.mesh;
                           name = name.substr(0, name.find('.'));
                           return name + (param.param.cvt ? "_clean_cvt" : "_clean");
                         });

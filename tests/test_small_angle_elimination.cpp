// SmallAngleElimination (stage 4): slivers on a constructed sphere disappear, the harsh real
// inputs (clean only, clean + CVT) keep no angle below 30 degrees, the remeshing invariants hold,
// refused inputs are left untouched, and the output is deterministic.
#include <gtest/gtest.h>

#include <vcg/complex/complex.h>

#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include <vcg_ext/mesh_io.h>
#include <vcg_ext/mesh_quality.h>
#include <vcg_ext/mesh_types.h>
#include <vcg_ext/remesh_pipeline.h>
#include <vcg_ext/small_angle_elimination.h>

#include "remeshing_test_meshes.h"
#include "test_helpers.h"

using molremesh::MeshD;
using Small = molremesh::SmallAngleElimination<MeshD>;
using Quality = molremesh::MeshQuality<MeshD>;
using Reference = molremesh::ReferenceSurface<MeshD>;

namespace {

void UpdateAdjacency(MeshD& m) {
  vcg::tri::UpdateTopology<MeshD>::FaceFace(m);
  vcg::tri::UpdateTopology<MeshD>::VertexFace(m);
}

/// The shared mesh `name` after the pipeline's stages (clean, or clean + cvt).
void LoadPrepared(MeshD& m, const std::string& name, bool cvt) {
  std::string error;
  ASSERT_TRUE(molremesh::LoadMesh(m, molremesh::test::SharedMesh(name), error)) << error;
  molremesh::RemeshPipeline<MeshD>::Params params;
  params.stages = {molremesh::PipelineStage::Clean};
  if (cvt) params.stages.push_back(molremesh::PipelineStage::Cvt);
  params.measureEachStage = false;
  ASSERT_TRUE(molremesh::RemeshPipeline<MeshD>::Do(m, params).ok);
  UpdateAdjacency(m);
}

/// Unit icosphere with slivers: every vertex of a few faces is pulled most of the way toward a
/// neighbour (and put back on the sphere), which leaves angles of a few degrees.
void SliverSphere(MeshD& m) {
  molremesh::test::Icosphere(m, 3);
  UpdateAdjacency(m);
  for (std::size_t fi = 0; fi < m.face.size(); fi += 97) {
    auto& f = m.face[fi];
    const vcg::Point3d a = f.P(0), b = f.P(1);
    f.V(0)->P() = (a + (b - a) * 0.85).Normalize();
  }
  UpdateAdjacency(m);
}

Small::Params ParamsFor(const MeshD& m) {
  Small::Params p;
  p.targetEdgeLength = molremesh::test::MeanEdge(m);
  return p;
}

bool SameMesh(const MeshD& a, const MeshD& b) {
  if (a.vert.size() != b.vert.size() || a.face.size() != b.face.size()) return false;
  for (std::size_t i = 0; i < a.vert.size(); ++i)
    if (a.vert[i].cP() != b.vert[i].cP()) return false;
  for (std::size_t i = 0; i < a.face.size(); ++i)
    for (int k = 0; k < 3; ++k)
      if (vcg::tri::Index(a, a.face[i].cV(k)) != vcg::tri::Index(b, b.face[i].cV(k))) return false;
  return true;
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
  EXPECT_EQ(after.smallAngleFaces, 0u) << r.Summary();
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
  UpdateAdjacency(m);
  ASSERT_GE(Quality::Compute(m).angleMin, 30.0);
  MeshD copy;
  vcg::tri::Append<MeshD, MeshD>::MeshCopy(copy, m);
  Reference reference;
  ASSERT_TRUE(reference.Build(m));
  const auto t0 = std::chrono::steady_clock::now();
  const Small::Result r = Small::Do(m, reference, ParamsFor(m));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_EQ(r.smallFacesBefore, 0u);
  EXPECT_TRUE(SameMesh(m, copy));
  EXPECT_LT(seconds, 0.5);
}

TEST(SmallAngleElimination, RefusedInputsAreLeftUntouched) {
  Reference sphereReference;
  {
    MeshD sphere;
    molremesh::test::Icosphere(sphere, 2);
    ASSERT_TRUE(sphereReference.Build(sphere));
  }
  MeshD empty;
  EXPECT_FALSE(Small::Do(empty, sphereReference, Small::Params()).ok);

  // Three triangles on one edge, with a small angle: not 2-manifold.
  MeshD fin;
  molremesh::test::MakeMesh(fin, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0.5, 0.02, 1}},
                            {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}});
  UpdateAdjacency(fin);
  MeshD copy;
  vcg::tri::Append<MeshD, MeshD>::MeshCopy(copy, fin);
  const Small::Result r = Small::Do(fin, sphereReference, Small::Params());
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("manifold"), std::string::npos) << r.message;
  EXPECT_TRUE(SameMesh(fin, copy));

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
  MeshD a;
  LoadPrepared(a, "lysozyme_Lys1_msms.ply", false);
  Reference reference;
  ASSERT_TRUE(reference.Build(a));
  MeshD b, c;
  vcg::tri::Append<MeshD, MeshD>::MeshCopy(b, a);
  vcg::tri::Append<MeshD, MeshD>::MeshCopy(c, a);
  UpdateAdjacency(b);
  UpdateAdjacency(c);
  Small::Params p = ParamsFor(a);
  p.threads = 1;
  ASSERT_TRUE(Small::Do(a, reference, p).ok);
  ASSERT_TRUE(Small::Do(c, reference, p).ok);
  p.threads = 2;
  ASSERT_TRUE(Small::Do(b, reference, p).ok);
  EXPECT_TRUE(SameMesh(a, b));
  EXPECT_TRUE(SameMesh(a, c));
}

// --- Real meshes: the harsh inputs the stage is for ------------------------------------------------

struct RealCase {
  const char* mesh;
  bool cvt;
};

class SmallAngleEliminationReal : public ::testing::TestWithParam<RealCase> {};

TEST_P(SmallAngleEliminationReal, LeavesNoAngleBelow30AndKeepsTheInvariants) {
  const RealCase c = GetParam();
  MeshD input;
  LoadPrepared(input, c.mesh, c.cvt);
  Reference reference;
  ASSERT_TRUE(reference.Build(input));
  MeshD output;
  vcg::tri::Append<MeshD, MeshD>::MeshCopy(output, input);
  UpdateAdjacency(output);
  const molremesh::QualityReport before = Quality::Compute(input);
  const Small::Result r = Small::Do(output, reference, ParamsFor(input));
  ASSERT_TRUE(r.ok) << r.message;
  const molremesh::QualityReport after = Quality::Compute(output);
  EXPECT_EQ(after.smallAngleFaces, 0u) << r.Summary();
  EXPECT_EQ(r.smallFacesAfter, after.smallAngleFaces);
  molremesh::test::ExpectTwoManifoldWithoutDegenerateFaces(after);
  molremesh::test::ExpectNoSelfIntersection(after);
  molremesh::test::ExpectComponentsClosedWithTheirGenus(before, after);
  EXPECT_NEAR(after.volume / before.volume, 1.0, 0.005);
  molremesh::test::ExpectVerticesOnInput(output, input, 0.1 * before.meanEdgeLength);
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

// LocalSmoothing (stage 6): the bad triangles (angle < 30 or >= 90 degrees) of a constructed sphere
// and of real meshes after stages 4 and 5 get fewer, with no new small angle and no larger largest
// angle, the remeshing invariants hold, refused inputs are left untouched, the output is deterministic.
#include <gtest/gtest.h>

#include <vcg/complex/complex.h>

#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include <vcg_ext/local_smoothing.h>
#include <vcg_ext/mesh_io.h>
#include <vcg_ext/mesh_quality.h>
#include <vcg_ext/mesh_types.h>
#include <vcg_ext/remesh_pipeline.h>

#include "remeshing_test_meshes.h"
#include "test_helpers.h"

using molremesh::MeshD;
using Smoothing = molremesh::LocalSmoothing<MeshD>;
using Quality = molremesh::MeshQuality<MeshD>;
using Reference = molremesh::ReferenceSurface<MeshD>;

namespace {

void UpdateAdjacency(MeshD& m) {
  vcg::tri::UpdateTopology<MeshD>::FaceFace(m);
  vcg::tri::UpdateTopology<MeshD>::VertexFace(m);
}

/// The shared mesh `name` after the pipeline's stages clean (+ cvt) + small + obtuse.
void LoadPrepared(MeshD& m, const std::string& name, bool cvt) {
  std::string error;
  ASSERT_TRUE(molremesh::LoadMesh(m, molremesh::test::SharedMesh(name), error)) << error;
  molremesh::RemeshPipeline<MeshD>::Params params;
  params.stages = {molremesh::PipelineStage::Clean};
  if (cvt) params.stages.push_back(molremesh::PipelineStage::Cvt);
  params.stages.push_back(molremesh::PipelineStage::Small);
  params.stages.push_back(molremesh::PipelineStage::Obtuse);
  params.measureEachStage = false;
  ASSERT_TRUE(molremesh::RemeshPipeline<MeshD>::Do(m, params).ok);
  UpdateAdjacency(m);
}

/// Unit icosphere with obtuse triangles: one corner of a few faces is pushed most of the way
/// toward the midpoint of its opposite edge (and put back on the sphere).
void ObtuseSphere(MeshD& m) {
  molremesh::test::Icosphere(m, 3);
  UpdateAdjacency(m);
  for (std::size_t fi = 0; fi < m.face.size(); fi += 97) {
    auto& f = m.face[fi];
    const vcg::Point3d mid = (f.P(1) + f.P(2)) * 0.5;
    f.V(0)->P() = (f.P(0) + (mid - f.P(0)) * 0.6).Normalize();
  }
  UpdateAdjacency(m);
}

Smoothing::Params ParamsFor(const MeshD& m) {
  Smoothing::Params p;
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
  EXPECT_LT(r.badAfter, r.badBefore) << r.Summary();
  EXPECT_LT(after.obtuseFaces, before.obtuseFaces) << r.Summary();
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
  UpdateAdjacency(m);
  const molremesh::QualityReport q = Quality::Compute(m);
  ASSERT_LT(q.angleMax, 90.0);
  ASSERT_GE(q.angleMin, 30.0);
  MeshD copy;
  vcg::tri::Append<MeshD, MeshD>::MeshCopy(copy, m);
  Reference reference;
  ASSERT_TRUE(reference.Build(m));
  const auto t0 = std::chrono::steady_clock::now();
  const Smoothing::Result r = Smoothing::Do(m, reference, ParamsFor(m));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_EQ(r.badBefore, 0u);
  EXPECT_TRUE(SameMesh(m, copy));
  EXPECT_LT(seconds, 0.5);
}

TEST(LocalSmoothing, RefusedInputsAreLeftUntouched) {
  Reference sphereReference;
  {
    MeshD sphere;
    molremesh::test::Icosphere(sphere, 2);
    ASSERT_TRUE(sphereReference.Build(sphere));
  }
  MeshD empty;
  EXPECT_FALSE(Smoothing::Do(empty, sphereReference, Smoothing::Params()).ok);

  MeshD fin;
  molremesh::test::MakeMesh(fin, {{0, 0, 0}, {1, 0, 0}, {0.5, 0.1, 0}, {0, -1, 0}, {0, 0, 1}},
                            {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}});
  UpdateAdjacency(fin);
  MeshD copy;
  vcg::tri::Append<MeshD, MeshD>::MeshCopy(copy, fin);
  const Smoothing::Result r = Smoothing::Do(fin, sphereReference, Smoothing::Params());
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("manifold"), std::string::npos) << r.message;
  EXPECT_TRUE(SameMesh(fin, copy));

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
  MeshD a;
  LoadPrepared(a, "lysozyme_Lys1_msms.ply", false);
  Reference reference;
  ASSERT_TRUE(reference.Build(a));
  MeshD b, c;
  vcg::tri::Append<MeshD, MeshD>::MeshCopy(b, a);
  vcg::tri::Append<MeshD, MeshD>::MeshCopy(c, a);
  UpdateAdjacency(b);
  UpdateAdjacency(c);
  Smoothing::Params p = ParamsFor(a);
  p.threads = 1;
  ASSERT_TRUE(Smoothing::Do(a, reference, p).ok);
  ASSERT_TRUE(Smoothing::Do(c, reference, p).ok);
  p.threads = 2;
  ASSERT_TRUE(Smoothing::Do(b, reference, p).ok);
  EXPECT_TRUE(SameMesh(a, b));
  EXPECT_TRUE(SameMesh(a, c));
}

// --- Real meshes after small-angle elimination and obtuse reduction ---------------------------------

struct RealCase {
  const char* mesh;
  bool cvt;
};

class LocalSmoothingReal : public ::testing::TestWithParam<RealCase> {};

TEST_P(LocalSmoothingReal, ReducesBadTrianglesWithoutNewSmallAnglesAndKeepsTheInvariants) {
  const RealCase c = GetParam();
  MeshD input;
  LoadPrepared(input, c.mesh, c.cvt);
  Reference reference;
  ASSERT_TRUE(reference.Build(input));
  MeshD output;
  vcg::tri::Append<MeshD, MeshD>::MeshCopy(output, input);
  UpdateAdjacency(output);
  const molremesh::QualityReport before = Quality::Compute(input);
  const Smoothing::Result r = Smoothing::Do(output, reference, ParamsFor(input));
  ASSERT_TRUE(r.ok) << r.message;
  const molremesh::QualityReport after = Quality::Compute(output);
  EXPECT_LE(r.badAfter, r.badBefore) << r.Summary();
  if (r.badBefore > 0) {
    EXPECT_LT(after.obtusePercent, before.obtusePercent) << r.Summary();
  }
  EXPECT_LE(after.smallAngleFaces, before.smallAngleFaces);
  EXPECT_GE(after.angleMin, std::min(before.angleMin, 30.0) - 1e-9);
  EXPECT_LE(after.angleMax, std::max(before.angleMax, 90.0));
  molremesh::test::ExpectTwoManifoldWithoutDegenerateFaces(after);
  molremesh::test::ExpectNoSelfIntersection(after);
  molremesh::test::ExpectComponentsClosedWithTheirGenus(before, after);
  EXPECT_NEAR(after.volume / before.volume, 1.0, 0.005);
  molremesh::test::ExpectVerticesOnInput(output, input, 0.1 * before.meanEdgeLength);
}

INSTANTIATE_TEST_SUITE_P(
    Meshes, LocalSmoothingReal,
    ::testing::Values(RealCase{"lysozyme_Lys1_msms.ply", false}, RealCase{"galactose_grasp.ply", false},
                      RealCase{"bpti_1bpi_msms.ply", false}, RealCase{"ubiquitin_1UBQ_pymol_ses.ply", false}),
    [](const ::testing::TestParamInfo<RealCase>& param) {
      std::string name = param.param.mesh;
      name = name.substr(0, name.find('.'));
      return name + (param.param.cvt ? "_clean_cvt_small_obtuse" : "_clean_small_obtuse");
    });

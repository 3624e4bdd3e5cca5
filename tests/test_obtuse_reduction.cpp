// ObtuseReduction (stage 5): obtuse triangles of a constructed sphere get fewer and less obtuse, the
// harsh real inputs (after small-angle elimination) lose most of their obtuse triangles without any
// new angle below 30 degrees, the remeshing invariants hold, refused inputs are left untouched and the
// output is deterministic.
#include <gtest/gtest.h>

#include <vcg/complex/complex.h>

#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include <vcg_ext/mesh_io.h>
#include <vcg_ext/mesh_quality.h>
#include <vcg_ext/mesh_types.h>
#include <vcg_ext/obtuse_reduction.h>
#include <vcg_ext/remesh_pipeline.h>

#include "remeshing_test_meshes.h"
#include "test_helpers.h"

using molremesh::MeshD;
using Obtuse = molremesh::ObtuseReduction<MeshD>;
using Quality = molremesh::MeshQuality<MeshD>;
using Reference = molremesh::ReferenceSurface<MeshD>;

namespace {

void UpdateAdjacency(MeshD& m) {
  vcg::tri::UpdateTopology<MeshD>::FaceFace(m);
  vcg::tri::UpdateTopology<MeshD>::VertexFace(m);
}

/// The shared mesh `name` after the pipeline's stages clean (+ cvt) + small.
void LoadPrepared(MeshD& m, const std::string& name, bool cvt) {
  std::string error;
  ASSERT_TRUE(molremesh::LoadMesh(m, molremesh::test::SharedMesh(name), error)) << error;
  molremesh::RemeshPipeline<MeshD>::Params params;
  params.stages = {molremesh::PipelineStage::Clean};
  if (cvt) params.stages.push_back(molremesh::PipelineStage::Cvt);
  params.stages.push_back(molremesh::PipelineStage::Small);
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

Obtuse::Params ParamsFor(const MeshD& m) {
  Obtuse::Params p;
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
  EXPECT_LT(after.angleMax, 90.0) << r.Summary();
  EXPECT_EQ(after.obtuseFaces, 0u) << r.Summary();
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
  EXPECT_GT(r.insertions, 0u) << r.Summary();
  const molremesh::QualityReport after = Quality::Compute(m);
  EXPECT_LT(after.obtuseFaces, before.obtuseFaces);
  EXPECT_GE(after.angleMin, std::min(before.angleMin, 30.0) - 1e-9);
  molremesh::test::ExpectTwoManifoldWithoutDegenerateFaces(after);
  molremesh::test::ExpectNoSelfIntersection(after);
  molremesh::test::ExpectComponentsClosedWithTheirGenus(before, after);
}

TEST(ObtuseReduction, MeshWithoutObtuseAnglesIsLeftAsItIs) {
  MeshD m;
  molremesh::test::Icosphere(m, 4);
  UpdateAdjacency(m);
  ASSERT_LT(Quality::Compute(m).angleMax, 90.0);
  MeshD copy;
  vcg::tri::Append<MeshD, MeshD>::MeshCopy(copy, m);
  Reference reference;
  ASSERT_TRUE(reference.Build(m));
  const auto t0 = std::chrono::steady_clock::now();
  const Obtuse::Result r = Obtuse::Do(m, reference, ParamsFor(m));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_EQ(r.obtuseBefore, 0u);
  EXPECT_TRUE(SameMesh(m, copy));
  EXPECT_LT(seconds, 0.5);
}

TEST(ObtuseReduction, RefusedInputsAreLeftUntouched) {
  Reference sphereReference;
  {
    MeshD sphere;
    molremesh::test::Icosphere(sphere, 2);
    ASSERT_TRUE(sphereReference.Build(sphere));
  }
  MeshD empty;
  EXPECT_FALSE(Obtuse::Do(empty, sphereReference, Obtuse::Params()).ok);

  // Three triangles on one edge, one obtuse: not 2-manifold.
  MeshD fin;
  molremesh::test::MakeMesh(fin, {{0, 0, 0}, {1, 0, 0}, {0.5, 0.1, 0}, {0, -1, 0}, {0, 0, 1}},
                            {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}});
  UpdateAdjacency(fin);
  MeshD copy;
  vcg::tri::Append<MeshD, MeshD>::MeshCopy(copy, fin);
  const Obtuse::Result r = Obtuse::Do(fin, sphereReference, Obtuse::Params());
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("manifold"), std::string::npos) << r.message;
  EXPECT_TRUE(SameMesh(fin, copy));

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
  MeshD a;
  LoadPrepared(a, "galactose_grasp.ply", false);
  Reference reference;
  ASSERT_TRUE(reference.Build(a));
  MeshD b, c;
  vcg::tri::Append<MeshD, MeshD>::MeshCopy(b, a);
  vcg::tri::Append<MeshD, MeshD>::MeshCopy(c, a);
  UpdateAdjacency(b);
  UpdateAdjacency(c);
  Obtuse::Params p = ParamsFor(a);
  p.threads = 1;
  ASSERT_TRUE(Obtuse::Do(a, reference, p).ok);
  ASSERT_TRUE(Obtuse::Do(c, reference, p).ok);
  p.threads = 2;
  ASSERT_TRUE(Obtuse::Do(b, reference, p).ok);
  EXPECT_TRUE(SameMesh(a, b));
  EXPECT_TRUE(SameMesh(a, c));
}

// --- Real meshes after small-angle elimination ------------------------------------------------------

struct RealCase {
  const char* mesh;
  bool cvt;
  double maxObtusePercent; ///< measured after the stage (README), with a margin
};

class ObtuseReductionReal : public ::testing::TestWithParam<RealCase> {};

TEST_P(ObtuseReductionReal, ReducesObtuseTrianglesWithoutSmallAnglesAndKeepsTheInvariants) {
  const RealCase c = GetParam();
  MeshD input;
  LoadPrepared(input, c.mesh, c.cvt);
  Reference reference;
  ASSERT_TRUE(reference.Build(input));
  MeshD output;
  vcg::tri::Append<MeshD, MeshD>::MeshCopy(output, input);
  UpdateAdjacency(output);
  const molremesh::QualityReport before = Quality::Compute(input);
  const Obtuse::Result r = Obtuse::Do(output, reference, ParamsFor(input));
  ASSERT_TRUE(r.ok) << r.message;
  const molremesh::QualityReport after = Quality::Compute(output);
  EXPECT_LT(after.obtusePercent, before.obtusePercent) << r.Summary();
  EXPECT_LE(after.obtusePercent, c.maxObtusePercent) << r.Summary();
  EXPECT_LE(after.angleMax, before.angleMax);
  EXPECT_LE(after.smallAngleFaces, before.smallAngleFaces);
  EXPECT_GE(after.angleMin, std::min(before.angleMin, 30.0) - 1e-9);
  molremesh::test::ExpectTwoManifoldWithoutDegenerateFaces(after);
  molremesh::test::ExpectNoSelfIntersection(after);
  molremesh::test::ExpectComponentsClosedWithTheirGenus(before, after);
  EXPECT_NEAR(after.volume / before.volume, 1.0, 0.005);
  molremesh::test::ExpectVerticesOnInput(output, input, 0.1 * before.meanEdgeLength);
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

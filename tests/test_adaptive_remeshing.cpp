// AdaptiveRemeshing (RAR, Dunyach et al. 2013): the sizing field on shapes with known curvature,
// locked vertices, refused inputs, determinism, and the acceptance figures on a real molecule.
#include <gtest/gtest.h>

#include <vcg/complex/algorithms/create/platonic.h>
#include <vcg/complex/algorithms/refine.h>
#include <vcg/complex/algorithms/update/topology.h>
#include <vcg/complex/append.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <vcg_ext_instances/extern_mesh_d.h>
#include <vcg_ext/stages/adaptive_remeshing.h>
#include <vcg_ext/io/mesh_io.h>
#include <vcg_ext/quality/mesh_quality.h>
#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/pipeline/remesh_pipeline.h>
#include <vcg_ext/surface/surface_distance.h>

#include "remeshing_test_meshes.h"
#include "cgal_reference.h"
#include "test_helpers.h"

using molremesh::MeshD;
using Rar = molremesh::AdaptiveRemeshing<MeshD>;
using Quality = molremesh::MeshQuality<MeshD>;

namespace {

void UpdateAdjacency(MeshD& m) {
  vcg::tri::UpdateTopology<MeshD>::FaceFace(m);
  vcg::tri::UpdateTopology<MeshD>::VertexFace(m);
}

/// Icosphere of the given radius, `refinements` midpoint subdivisions.
void MakeSphere(MeshD& m, int refinements, double radius) {
  vcg::tri::Icosahedron(m);
  vcg::tri::UpdateTopology<MeshD>::FaceFace(m);
  for (int i = 0; i < refinements; ++i) vcg::tri::Refine(m, vcg::tri::MidPoint<MeshD>(&m));
  for (auto& v : m.vert) v.P() = v.P().Normalize() * radius;
  UpdateAdjacency(m);
}

/// n x n grid of unit squares in the z = 0 plane, two triangles each.
void MakeGrid(MeshD& m, int n) {
  m.Clear();
  vcg::tri::Allocator<MeshD>::AddVertices(m, std::size_t((n + 1) * (n + 1)));
  for (int y = 0; y <= n; ++y)
    for (int x = 0; x <= n; ++x) m.vert[std::size_t(y * (n + 1) + x)].P() = vcg::Point3d(x, y, 0);
  vcg::tri::Allocator<MeshD>::AddFaces(m, std::size_t(2 * n * n));
  std::size_t f = 0;
  auto at = [&](int x, int y) { return &m.vert[std::size_t(y * (n + 1) + x)]; };
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      m.face[f].V(0) = at(x, y), m.face[f].V(1) = at(x + 1, y), m.face[f].V(2) = at(x + 1, y + 1), ++f;
      m.face[f].V(0) = at(x, y), m.face[f].V(1) = at(x + 1, y + 1), m.face[f].V(2) = at(x, y + 1), ++f;
    }
  UpdateAdjacency(m);
}

/// The shared mesh `name`, cleaned by the pipeline's first stage.
void LoadCleaned(MeshD& m, const std::string& name) {
  std::string error;
  ASSERT_TRUE(molremesh::LoadMesh(m, molremesh::test::SharedMesh(name), error)) << error;
  molremesh::RemeshPipeline<MeshD>::Params params;
  params.stages = {molremesh::PipelineStage::Clean};
  params.measureEachStage = false;
  ASSERT_TRUE(molremesh::RemeshPipeline<MeshD>::Do(m, params).ok);
  UpdateAdjacency(m);
}

} // namespace

// --- Sizing field ---------------------------------------------------------------------------------

TEST(AdaptiveRemeshingSizing, CurvatureOfASphereIsOneOverItsRadius) {
  MeshD m;
  MakeSphere(m, 3, 2.0);
  for (const auto& v : m.vert) EXPECT_NEAR(Rar::MaxAbsCurvature(v), 0.5, 0.01);
}

TEST(AdaptiveRemeshingSizing, SphereGetsTheEdgeLengthOfItsToleranceEverywhere) {
  MeshD m;
  MakeSphere(m, 3, 1.0);
  Rar::Params params;
  params.approximationTolerance = 0.05; // eps = 0.005 for L0 = 0.1
  params.minLengthFactor = 0.5;
  params.maxLengthFactor = 3.0;
  const double L0 = 0.1, eps = 0.005;
  const double expected = std::sqrt(6.0 * eps / 1.0 - 3.0 * eps * eps); // kappa = 1
  const std::vector<double> sizing = Rar::ComputeSizing(m, L0, params, 2);
  ASSERT_EQ(sizing.size(), m.vert.size());
  for (const double L : sizing) EXPECT_NEAR(L, expected, 0.02 * expected);
}

TEST(AdaptiveRemeshingSizing, FlatRegionsGetTheLargestLengthAndCurvedOnesAreClamped) {
  MeshD grid;
  MakeGrid(grid, 6);
  Rar::Params params;
  params.minLengthFactor = 0.5;
  params.maxLengthFactor = 1.5;
  for (const double L : Rar::ComputeSizing(grid, 1.0, params, 1)) EXPECT_DOUBLE_EQ(L, 1.5);
  MeshD tiny; // radius far below the tolerance's: the minimum everywhere
  MakeSphere(tiny, 2, 0.01);
  for (const double L : Rar::ComputeSizing(tiny, 1.0, params, 1)) EXPECT_DOUBLE_EQ(L, 0.5);
}

// --- Behaviour on constructed meshes ----------------------------------------------------------

TEST(AdaptiveRemeshing, RefinesACoarseSphereToTheTargetLengths) {
  MeshD m;
  MakeSphere(m, 2, 1.0); // 320 faces, edges ~0.3
  Rar::Params params;
  params.targetEdgeLength = 0.1;
  params.minLengthFactor = params.maxLengthFactor = 1.0; // uniform L = 0.1
  params.iterations = 6;
  params.threads = 2;
  const Rar::Result r = Rar::Do(m, params);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_GT(r.facesOut, 8 * r.facesIn);
  const molremesh::QualityReport q = Quality::Compute(m);
  EXPECT_TRUE(q.isTwoManifold());
  EXPECT_EQ(q.genus, 0);
  EXPECT_EQ(q.boundaryEdges, 0u);
  EXPECT_EQ(q.selfIntersectingPairs, 0u);
  EXPECT_GT(q.meanEdgeLength, 0.8 * 0.1);
  EXPECT_LT(q.meanEdgeLength, 1.2 * 0.1);
  EXPECT_GE(q.angleMin, 30.0);
}

TEST(AdaptiveRemeshing, LockedVerticesNeverMoveAndTheirEdgesStay) {
  MeshD m;
  MakeSphere(m, 3, 1.0);
  molremesh::ReferenceSurface<MeshD> reference;
  ASSERT_TRUE(reference.Build(m));
  Rar::Params params;
  params.targetEdgeLength = 0.08; // finer than the sphere's ~0.15: many splits next to the locked half
  params.iterations = 3;
  molremesh::LocalRemeshingOps<MeshD> ops(m, reference, params.targetEdgeLength, params.guards, 2);
  ASSERT_TRUE(ops.Init(nullptr, true));
  std::vector<vcg::Point3d> before(m.vert.size());
  std::vector<std::pair<std::size_t, std::size_t>> lockedEdges;
  for (std::size_t i = 0; i < m.vert.size(); ++i) {
    before[i] = m.vert[i].P();
    ops.SetLocked(m.vert[i], m.vert[i].P()[2] > 0.1);
  }
  for (const auto& f : m.face)
    for (int e = 0; e < 3; ++e) {
      const std::size_t a = vcg::tri::Index(m, f.cV(e)), b = vcg::tri::Index(m, f.cV((e + 1) % 3));
      if (a < b && ops.IsLocked(m.vert[a]) && ops.IsLocked(m.vert[b])) lockedEdges.emplace_back(a, b);
    }
  std::vector<double> sizing = Rar::ComputeSizing(m, params.targetEdgeLength, params, 2);
  const molremesh::AdaptiveRemeshingStats stats = Rar::Remesh(ops, sizing, params, params.iterations, 2);
  EXPECT_GT(stats.splits, 100u);
  for (std::size_t i = 0; i < before.size(); ++i) {
    if (before[i][2] <= 0.1) continue;
    ASSERT_FALSE(m.vert[i].IsD()) << "locked vertex " << i << " was removed";
    EXPECT_EQ(m.vert[i].P(), before[i]) << "locked vertex " << i << " moved";
  }
  for (const auto& [a, b] : lockedEdges) {
    MeshD::FacePointer f = nullptr;
    int z = 0;
    EXPECT_TRUE(ops.FindEdge(&m.vert[a], &m.vert[b], f, z))
        << "edge " << a << "-" << b << " between locked vertices is gone";
  }
}

TEST(AdaptiveRemeshing, RefusedInputsAreLeftUntouched) {
  MeshD empty;
  EXPECT_FALSE(Rar::Do(empty).ok);

  // Three triangles on one edge: not 2-manifold.
  MeshD fin;
  vcg::tri::Allocator<MeshD>::AddVertices(fin, 5);
  fin.vert[0].P() = vcg::Point3d(0, 0, 0);
  fin.vert[1].P() = vcg::Point3d(1, 0, 0);
  fin.vert[2].P() = vcg::Point3d(0, 1, 0);
  fin.vert[3].P() = vcg::Point3d(0, -1, 0);
  fin.vert[4].P() = vcg::Point3d(0, 0, 1);
  vcg::tri::Allocator<MeshD>::AddFace(fin, &fin.vert[0], &fin.vert[1], &fin.vert[2]);
  vcg::tri::Allocator<MeshD>::AddFace(fin, &fin.vert[1], &fin.vert[0], &fin.vert[3]);
  vcg::tri::Allocator<MeshD>::AddFace(fin, &fin.vert[0], &fin.vert[1], &fin.vert[4]);
  UpdateAdjacency(fin);
  const Rar::Result r = Rar::Do(fin);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("manifold"), std::string::npos) << r.message;
  EXPECT_EQ(fin.fn, 3);
  EXPECT_EQ(fin.vert[4].P(), vcg::Point3d(0, 0, 1));

  MeshD sphere;
  MakeSphere(sphere, 1, 1.0);
  Rar::Params bad;
  bad.minLengthFactor = 2.0;
  bad.maxLengthFactor = 1.0;
  EXPECT_FALSE(Rar::Do(sphere, bad).ok);
  EXPECT_EQ(sphere.fn, 80);
}

TEST(AdaptiveRemeshing, SameOutputForOneAndTwoThreads) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  MeshD a;
  LoadCleaned(a, "galactose_grasp.ply");
  MeshD b;
  vcg::tri::Append<MeshD, MeshD>::MeshCopy(b, a);
  UpdateAdjacency(b);
  molremesh::ReferenceSurface<MeshD> reference;
  ASSERT_TRUE(reference.Build(a));
  Rar::Params params;
  params.iterations = 3;
  params.threads = 1;
  ASSERT_TRUE(Rar::Do(a, reference, params).ok);
  params.threads = 2;
  ASSERT_TRUE(Rar::Do(b, reference, params).ok);
  ASSERT_EQ(a.vert.size(), b.vert.size());
  ASSERT_EQ(a.face.size(), b.face.size());
  for (std::size_t i = 0; i < a.vert.size(); ++i) ASSERT_EQ(a.vert[i].P(), b.vert[i].P()) << "vertex " << i;
  for (std::size_t i = 0; i < a.face.size(); ++i)
    for (int k = 0; k < 3; ++k)
      ASSERT_EQ(vcg::tri::Index(a, a.face[i].V(k)), vcg::tri::Index(b, b.face[i].V(k))) << "face " << i;
}

// --- Acceptance figures on a real molecule (BPTI, MSMS), RAR straight on the cleaned input ----------

class AdaptiveRemeshingBpti : public ::testing::Test {
protected:
  static void SetUpTestSuite() {
    if (!molremesh::test::SharedDataFound()) return; // every test skips in SetUp
    input = new MeshD;
    output = new MeshD;
    before = new molremesh::QualityReport;
    after = new molremesh::QualityReport;
    result = new Rar::Result;
    LoadCleaned(*input, "bpti_1bpi_msms.ply");
    vcg::tri::Append<MeshD, MeshD>::MeshCopy(*output, *input);
    UpdateAdjacency(*output);
    molremesh::ReferenceSurface<MeshD> reference;
    ASSERT_TRUE(reference.Build(*input));
    *before = Quality::Compute(*input);
    Rar::Params params;
    params.iterations = 4;
    *result = Rar::Do(*output, reference, params);
    *after = Quality::Compute(*output);
  }
  void SetUp() override { MOLREMESH_SKIP_WITHOUT_SHARED_DATA(); }
  static void TearDownTestSuite() {
    delete input;
    delete output;
    delete before;
    delete after;
    delete result;
  }
  static MeshD* input;
  static MeshD* output;
  static molremesh::QualityReport* before;
  static molremesh::QualityReport* after;
  static Rar::Result* result;
};
MeshD* AdaptiveRemeshingBpti::input = nullptr;
MeshD* AdaptiveRemeshingBpti::output = nullptr;
molremesh::QualityReport* AdaptiveRemeshingBpti::before = nullptr;
molremesh::QualityReport* AdaptiveRemeshingBpti::after = nullptr;
Rar::Result* AdaptiveRemeshingBpti::result = nullptr;

TEST_F(AdaptiveRemeshingBpti, Succeeds) {
  ASSERT_TRUE(result->ok) << result->message;
}

TEST_F(AdaptiveRemeshingBpti, StaysTwoManifold) {
  molremesh::test::ExpectTwoManifoldWithoutDegenerateFaces(*after);
}

TEST_F(AdaptiveRemeshingBpti, CreatesNoSelfIntersection) {
  molremesh::test::ExpectNoSelfIntersection(*after);
}

TEST_F(AdaptiveRemeshingBpti, KeepsClosedComponentsClosedWithTheirGenus) {
  molremesh::test::ExpectComponentsClosedWithTheirGenus(*before, *after);
}

TEST_F(AdaptiveRemeshingBpti, KeepsTheVolumeWithinHalfAPercent) {
  EXPECT_NEAR(after->volume / before->volume, 1.0, 0.005);
}

TEST_F(AdaptiveRemeshingBpti, KeepsEveryVertexOnTheInput) {
  molremesh::test::ExpectVerticesOnInput(*output, *input, 0.1 * before->meanEdgeLength);
}

// CGAL's isotropic remeshing at the same target length (tests/data/cgal_reference.json, rounded):
// BPTI theta_min 36.0, Q_min 0.723, V567 98.69 %.
TEST_F(AdaptiveRemeshingBpti, AnglesQualityAndValencesAtLeastAsGoodAsCgal) {
  EXPECT_GE(after->angleMin, 36.0);
  EXPECT_GE(after->qMin, 0.723);
  EXPECT_GE(after->v567Percent, 98.69);
  // The figures above are CGAL's in the reference file, to the digits written.
  const nlohmann::json cgal = molremesh::test::CgalReference("bpti_1bpi_msms");
  ASSERT_FALSE(cgal.is_null()) << "no CGAL reference figures for bpti_1bpi_msms";
  EXPECT_EQ(molremesh::test::Rounded(cgal["angle_min_deg"].get<double>(), 1), 36.0);
  EXPECT_EQ(molremesh::test::Rounded(cgal["q_min"].get<double>(), 3), 0.723);
  EXPECT_EQ(molremesh::test::Rounded(cgal["v567_percent"].get<double>(), 2), 98.69);
}

// Snapping part of the way (Params::snapPartialShare): on galactose the input vertices the
// remeshed surface cuts off farthest are tips of small bumps where every full snap breaks the
// angle guard. Clean + CVT + segment + RAR with and without the partial moves: with them the
// Hausdorff distance to the input is smaller, no angle goes below the snap guard's 36 degrees and
// nothing else gets worse. Measured: 0.107 vs 0.135 L when the test was written; 0.097 vs 0.104 L
// since the CVT's intermediate Lloyd iterations project within the footpoint face (the run
// without partial moves starts closer, so the gain shrank from 21 % to 7 %).
TEST(AdaptiveRemeshing, PartialSnapsBringTheCutOffBumpTipsCloser) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  MeshD input;
  LoadCleaned(input, "galactose_grasp.ply");
  const double L = Quality::Compute(input).meanEdgeLength;
  auto remesh = [&](double partialShare, MeshD& out, molremesh::QualityReport& report) {
    vcg::tri::Append<MeshD, MeshD>::MeshCopy(out, input);
    UpdateAdjacency(out);
    molremesh::RemeshPipeline<MeshD>::Params params;
    params.stages = {molremesh::PipelineStage::Cvt, molremesh::PipelineStage::Segment,
                     molremesh::PipelineStage::Rar};
    params.measureEachStage = false;
    params.targetEdgeLength = L;
    params.rar.rar.snapPartialShare = partialShare;
    const auto r = molremesh::RemeshPipeline<MeshD>::Do(out, params);
    ASSERT_TRUE(r.ok) << r.message;
    report = Quality::Compute(out);
  };
  MeshD with, without;
  molremesh::QualityReport withReport, withoutReport;
  remesh(0.5, with, withReport);
  remesh(2.0, without, withoutReport); // a share above 1: no partial move
  const double dWith = molremesh::SurfaceDistance<MeshD, MeshD>::Symmetric(with, input).hausdorff / L;
  const double dWithout = molremesh::SurfaceDistance<MeshD, MeshD>::Symmetric(without, input).hausdorff / L;
  std::printf("[ figures  ] galactose Hausdorff/L with partial snaps %.3f, without %.3f\n", dWith, dWithout);
  EXPECT_LT(dWith, dWithout);
  EXPECT_GE(withReport.angleMin, std::min(36.0, withoutReport.angleMin));
  EXPECT_LE(withReport.angleMax, std::max(89.5, withoutReport.angleMax));
  molremesh::test::ExpectTwoManifoldWithoutDegenerateFaces(withReport);
  molremesh::test::ExpectNoSelfIntersection(withReport);
  molremesh::test::ExpectVerticesOnInput(with, input, 0.1 * L);
}

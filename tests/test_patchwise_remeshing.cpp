// PatchwiseRemeshing: locked borders, determinism across thread counts, nearby sheets in
// different patches, refused inputs, the pipeline's rar stage, and the acceptance figures of
// clean, cvt, segment, rar on a real molecule.
#include <gtest/gtest.h>

#include <vcg/complex/algorithms/create/platonic.h>
#include <vcg/complex/algorithms/refine.h>
#include <vcg/complex/algorithms/update/topology.h>
#include <vcg/complex/append.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <vcg_ext_instances/extern_mesh_d.h>
#include <vcg_ext/io/mesh_io.h>
#include <vcg_ext/quality/mesh_quality.h>
#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/stages/patchwise_remeshing.h>
#include <vcg_ext/stages/random_segmentation.h>
#include <vcg_ext/pipeline/remesh_pipeline.h>
#include <vcg_ext/surface/surface_distance.h>

#include "remeshing_test_meshes.h"
#include "cgal_reference.h"
#include "test_helpers.h"

using molremesh::MeshD;
using Patchwise = molremesh::PatchwiseRemeshing<MeshD>;
using Pipeline = molremesh::RemeshPipeline<MeshD>;
using Quality = molremesh::MeshQuality<MeshD>;
using Segmentation = molremesh::RandomSegmentation<MeshD>;

namespace {

using Point = vcg::Point3d;
using PointKey = std::array<double, 3>;

void UpdateAdjacency(MeshD& m) {
  vcg::tri::UpdateTopology<MeshD>::FaceFace(m);
  vcg::tri::UpdateTopology<MeshD>::VertexFace(m);
}

PointKey Key(const Point& p) {
  return {p[0], p[1], p[2]};
}

/// The shared mesh `name` after the pipeline's clean and cvt stages (few Lloyd iterations).
void LoadCvt(MeshD& m, const std::string& name, double& targetLength) {
  std::string error;
  ASSERT_TRUE(molremesh::LoadMesh(m, molremesh::test::SharedMesh(name), error)) << error;
  Pipeline::Params params;
  params.stages = {molremesh::PipelineStage::Clean, molremesh::PipelineStage::Cvt};
  params.cvt.iterations = 10;
  params.measureEachStage = false;
  const molremesh::PipelineResult r = Pipeline::Do(m, params);
  ASSERT_TRUE(r.ok) << r.message;
  targetLength = r.targetEdgeLength;
  UpdateAdjacency(m);
}

/// Border vertices (faces of two or more patches) and border edges, by position.
void Borders(const MeshD& m, const std::vector<int>& facePatch, std::set<PointKey>& vertices,
             std::set<std::pair<PointKey, PointKey>>& edges) {
  for (std::size_t fi = 0; fi < m.face.size(); ++fi) {
    const auto& f = m.face[fi];
    for (int e = 0; e < 3; ++e) {
      const std::size_t gi = vcg::tri::Index(m, f.cFFp(e));
      if (facePatch[gi] == facePatch[fi]) continue;
      const PointKey a = Key(f.cV(e)->cP()), b = Key(f.cV((e + 1) % 3)->cP());
      vertices.insert(a);
      vertices.insert(b);
      edges.insert(std::minmax(a, b));
    }
  }
}

bool SameMesh(const MeshD& a, const MeshD& b, std::string& why) {
  if (a.vert.size() != b.vert.size() || a.face.size() != b.face.size()) {
    why = "different element counts";
    return false;
  }
  for (std::size_t i = 0; i < a.vert.size(); ++i)
    if (a.vert[i].cP() != b.vert[i].cP()) {
      why = "vertex " + std::to_string(i) + " differs";
      return false;
    }
  for (std::size_t i = 0; i < a.face.size(); ++i)
    for (int k = 0; k < 3; ++k)
      if (vcg::tri::Index(a, a.face[i].cV(k)) != vcg::tri::Index(b, b.face[i].cV(k))) {
        why = "face " + std::to_string(i) + " differs";
        return false;
      }
  return true;
}

/// A small real molecule after clean + cvt, with a 6-patch segmentation and its reference.
struct Prepared {
  MeshD mesh;
  double L = 0;
  std::vector<int> facePatch;
  molremesh::ReferenceSurface<MeshD> reference;
};

void Prepare(Prepared& p, const std::string& name, int patches) {
  // The reference is the cleaned input, as in the pipeline.
  MeshD cleaned;
  std::string error;
  ASSERT_TRUE(molremesh::LoadMesh(cleaned, molremesh::test::SharedMesh(name), error)) << error;
  Pipeline::Params clean;
  clean.stages = {molremesh::PipelineStage::Clean};
  clean.measureEachStage = false;
  ASSERT_TRUE(Pipeline::Do(cleaned, clean).ok);
  ASSERT_TRUE(p.reference.Build(cleaned));
  LoadCvt(p.mesh, name, p.L);
  Segmentation::Params sp;
  sp.patchCount = patches;
  sp.seed = 7;
  const molremesh::SegmentationResult s = Segmentation::Do(p.mesh, sp);
  ASSERT_TRUE(s.ok);
  ASSERT_EQ(s.patchCount, patches);
  p.facePatch = s.facePatch;
}

} // namespace

TEST(PatchwiseRemeshing, PatchBordersAreBitIdenticalBeforeTheStripPass) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  Prepared p;
  Prepare(p, "ubiquitin_1UBQ_edtsurf_mc.ply", 6);
  std::set<PointKey> borderVertices;
  std::set<std::pair<PointKey, PointKey>> borderEdges;
  Borders(p.mesh, p.facePatch, borderVertices, borderEdges);
  ASSERT_GT(borderVertices.size(), 100u);

  Patchwise::Params params;
  params.rar.targetEdgeLength = p.L;
  params.rar.iterations = 3;
  params.finalPasses = false; // no strip pass, no volume offset, no final repair
  params.threads = 2;
  const Patchwise::Result r = Patchwise::Do(p.mesh, p.reference, p.facePatch, params);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_EQ(r.patches, 6);
  EXPECT_EQ(r.patchesFailed, 0u) << r.firstFailure;
  EXPECT_EQ(r.borderVertices, borderVertices.size());
  EXPECT_GT(r.patchStats.splits + r.patchStats.collapses, 100u); // the patches did change

  std::set<PointKey> vertices;
  std::set<std::pair<PointKey, PointKey>> edges;
  for (const auto& f : p.mesh.face)
    for (int e = 0; e < 3; ++e) {
      const PointKey a = Key(f.cV(e)->cP()), b = Key(f.cV((e + 1) % 3)->cP());
      vertices.insert(a);
      edges.insert(std::minmax(a, b));
    }
  std::size_t missingVertices = 0, missingEdges = 0;
  for (const PointKey& v : borderVertices) missingVertices += vertices.count(v) ? 0 : 1;
  for (const auto& e : borderEdges) missingEdges += edges.count(e) ? 0 : 1;
  EXPECT_EQ(missingVertices, 0u);
  EXPECT_EQ(missingEdges, 0u);
  const molremesh::QualityReport q = Quality::Compute(p.mesh);
  EXPECT_TRUE(q.isTwoManifold());
  EXPECT_EQ(q.boundaryEdges, 0u);
}

TEST(PatchwiseRemeshing, SameOutputForOneAndTwoThreads) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  Prepared p;
  Prepare(p, "lysozyme_Lys1_msms.ply", 5);
  MeshD copy;
  vcg::tri::Append<MeshD, MeshD>::MeshCopy(copy, p.mesh);
  UpdateAdjacency(copy);
  Patchwise::Params params;
  params.rar.targetEdgeLength = p.L;
  params.rar.iterations = 2;
  params.borderIterations = 2;
  params.threads = 1;
  const Patchwise::Result one = Patchwise::Do(p.mesh, p.reference, p.facePatch, params);
  params.threads = 2;
  const Patchwise::Result two = Patchwise::Do(copy, p.reference, p.facePatch, params);
  ASSERT_TRUE(one.ok) << one.message;
  ASSERT_TRUE(two.ok) << two.message;
  std::string why;
  EXPECT_TRUE(SameMesh(p.mesh, copy, why)) << why;
}

namespace {

/// Two concentric spheres, radius 1 (320 faces, edges ~0.13) and 1.001 (1280 faces, edges
/// ~0.066): 0.001 apart, far less than an edge. Coarsening the outer one to the inner one's
/// edge length sinks its chords by ~0.002, through the inner sphere, unless the intersection
/// test sees the inner sphere.
void MakeNestedSpheres(MeshD& m) {
  for (const auto& [radius, refinements] : {std::make_pair(1.0, 3), std::make_pair(1.001, 4)}) {
    MeshD s;
    vcg::tri::Icosahedron(s);
    vcg::tri::UpdateTopology<MeshD>::FaceFace(s);
    for (int i = 0; i < refinements; ++i) vcg::tri::Refine(s, vcg::tri::MidPoint<MeshD>(&s));
    for (auto& v : s.vert) v.P() = v.P().Normalize() * radius;
    vcg::tri::Append<MeshD, MeshD>::Mesh(m, s);
  }
  UpdateAdjacency(m);
}

/// lift: projections lifted half way toward the Phong surface (as in the pipeline) or onto the flat
/// triangles.
Patchwise::Result RemeshNestedSpheres(MeshD& m, int haloCells, bool lift = true) {
  MakeNestedSpheres(m);
  const molremesh::QualityReport before = Quality::Compute(m);
  EXPECT_EQ(before.components, 2u);
  EXPECT_EQ(before.selfIntersectingPairs + before.adjacentOverlapPairs, 0u);
  molremesh::ReferenceSurface<MeshD> reference;
  molremesh::ReferenceSurface<MeshD>::Params referenceParams;
  referenceParams.phongAlpha = lift ? 0.5 : 0.0;
  EXPECT_TRUE(reference.Build(m, referenceParams));
  Segmentation::Params sp;
  sp.patchCount = 8; // a patch never spans the two spheres (components)
  const molremesh::SegmentationResult s = Segmentation::Do(m, sp);
  Patchwise::Params params;
  params.rar.targetEdgeLength = 0.13;
  params.rar.minLengthFactor = params.rar.maxLengthFactor = 1.0;
  params.rar.iterations = 3;
  params.haloCells = haloCells;
  params.threads = 2;
  return Patchwise::Do(m, reference, s.facePatch, params);
}

void ExpectTwoSeparateClosedSpheres(const MeshD& m) {
  const molremesh::QualityReport after = Quality::Compute(m);
  EXPECT_EQ(after.selfIntersectingPairs, 0u);
  EXPECT_EQ(after.adjacentOverlapPairs, 0u);
  ASSERT_EQ(after.components, 2u); // never joined across the gap
  for (const auto& c : after.componentInfo) {
    EXPECT_TRUE(c.closed);
    EXPECT_EQ(c.genus, 0);
  }
}

} // namespace

TEST(PatchwiseRemeshing, NearbySheetsInDifferentPatchesNeverMeetOrJoin) {
  // On the flat reference the inner sphere's patches only coarsen onto its own triangles, so the
  // halo (the other patches' faces as obstacles) alone keeps every patch off the other sheet.
  MeshD m;
  const Patchwise::Result r = RemeshNestedSpheres(m, 3, false);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_GT(r.patchStats.collapses, 300u);
  EXPECT_GT(r.haloFaces, 0u);
  EXPECT_EQ(r.conflictPairs, 0u); // the other patches' faces were obstacles in every patch
  ExpectTwoSeparateClosedSpheres(m);
  // Lifted toward the Phong surface, both sheets move (the lift is larger than the 0.001 gap):
  // patches may then meet after stitching, and are redone against the others until they do not.
  MeshD lifted;
  const Patchwise::Result l = RemeshNestedSpheres(lifted, 3);
  ASSERT_TRUE(l.ok) << l.message;
  ExpectTwoSeparateClosedSpheres(lifted);
}

TEST(PatchwiseRemeshing, PatchesThatMeetAfterStitchingAreRedoneAgainstTheOthers) {
  MeshD m;
  const Patchwise::Result r = RemeshNestedSpheres(m, 0); // no obstacles in the parallel phase
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_GT(r.conflictPairs, 0u);
  EXPECT_GT(r.patchesRedone, 0u);
  EXPECT_EQ(r.patchesFrozen, 0u);
  ExpectTwoSeparateClosedSpheres(m);
}

TEST(PatchwiseRemeshing, RefusesASegmentationOfAnotherMesh) {
  MeshD m;
  vcg::tri::Icosahedron(m);
  UpdateAdjacency(m);
  molremesh::ReferenceSurface<MeshD> reference;
  ASSERT_TRUE(reference.Build(m));
  const std::vector<int> wrongSize(7, 0);
  const Patchwise::Result r = Patchwise::Do(m, reference, wrongSize);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("segmentation"), std::string::npos) << r.message;
  EXPECT_EQ(m.fn, 20);
  std::vector<int> unassigned(m.face.size(), 0);
  unassigned[3] = -1;
  EXPECT_FALSE(Patchwise::Do(m, reference, unassigned).ok);
  EXPECT_EQ(m.fn, 20);
}

TEST(PatchwiseRemeshing, RefusesNonManifoldInputAndLeavesItUntouched) {
  // Two tetrahedra sharing one vertex: a non-manifold vertex.
  MeshD m;
  vcg::tri::Tetrahedron(m);
  MeshD second;
  vcg::tri::Tetrahedron(second);
  for (auto& v : second.vert) v.P() = vcg::Point3d(2, 0, 0) - v.P();
  vcg::tri::Append<MeshD, MeshD>::Mesh(m, second);
  // Weld one vertex of the second onto the first's vertex 0 (same position), then drop it.
  const vcg::Point3d shift = m.vert[0].P() - m.vert[4].P();
  for (std::size_t i = 4; i < 8; ++i) m.vert[i].P() += shift;
  for (auto& f : m.face)
    for (int k = 0; k < 3; ++k)
      if (f.V(k) == &m.vert[4]) f.V(k) = &m.vert[0];
  vcg::tri::Allocator<MeshD>::DeleteVertex(m, m.vert[4]);
  UpdateAdjacency(m);
  ASSERT_FALSE(Quality::Compute(m).isTwoManifold());
  molremesh::ReferenceSurface<MeshD> reference;
  ASSERT_TRUE(reference.Build(m));
  std::vector<int> patches(m.face.size(), 0);
  for (std::size_t i = 4; i < m.face.size(); ++i) patches[i] = 1;
  const std::vector<vcg::Point3d> before = [&] {
    std::vector<vcg::Point3d> p;
    for (const auto& v : m.vert) p.push_back(v.P());
    return p;
  }();
  const Patchwise::Result r = Patchwise::Do(m, reference, patches);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("2-manifold"), std::string::npos) << r.message;
  EXPECT_EQ(m.fn, 8);
  for (std::size_t i = 0; i < m.vert.size(); ++i) EXPECT_EQ(m.vert[i].P(), before[i]);
}

TEST(PatchwiseRemeshing, PipelineRarStageSegmentsFirstWhenSegmentDidNotRun) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  MeshD m;
  std::string error;
  ASSERT_TRUE(molremesh::LoadMesh(m, molremesh::test::SharedMesh("galactose_grasp.ply"), error)) << error;
  Pipeline::Params params;
  std::vector<molremesh::PipelineStage> stages;
  ASSERT_TRUE(molremesh::ParseStageList("clean,rar", stages, error)) << error;
  params.stages = stages;
  params.rar.rar.iterations = 2;
  params.segment.patchCount = 3;
  const molremesh::PipelineResult r = Pipeline::Do(m, params);
  ASSERT_TRUE(r.ok) << r.message;
  ASSERT_EQ(r.stages.size(), 2u);
  EXPECT_EQ(r.stages[1].name, "rar");
  EXPECT_NE(r.stages[1].summary.find("segmented first: 3 patches"), std::string::npos) << r.stages[1].summary;
  EXPECT_TRUE(r.facePatch.empty()); // the faces changed: no stale segmentation
  EXPECT_TRUE(r.stages[1].after.isTwoManifold());
  EXPECT_EQ(r.stages[1].after.selfIntersectingPairs, 0u);
}

// A stage that fails puts the input back by default (what the plugin's layers rely on); a caller
// that drops the mesh on failure (the CLI) may skip that copy and gets the last completed stage's
// result, still a valid mesh.
TEST(PatchwiseRemeshing, PipelinePutsTheInputBackWhenAStageFailsUnlessToldNotTo) {
  MeshD input;
  molremesh::test::Icosphere(input, 4, Point(0, 0, 0), Point(10, 10, 10));
  MeshD speck; // 20 faces: under 1 % of the faces, so the clean stage removes it when told to
  molremesh::test::Icosphere(speck, 0, Point(30, 0, 0));
  molremesh::test::AppendMesh(input, speck);
  const int inputFaces = input.fn, inputVertices = input.vn;
  Pipeline::Params params;
  params.stages = {molremesh::PipelineStage::Clean, molremesh::PipelineStage::Cvt};
  params.cvt.iterations = -1; // the CVT stage refuses it, after the clean stage changed the mesh
  params.clean.minComponentFraction = 0.01; // the speck goes: the clean stage changes the mesh
  for (const bool restore : {true, false}) {
    SCOPED_TRACE(restore ? "restoreOnFailure" : "no restore");
    MeshD m;
    vcg::tri::Append<MeshD, MeshD>::MeshCopy(m, input);
    params.restoreOnFailure = restore;
    const molremesh::PipelineResult r = Pipeline::Do(m, params);
    ASSERT_FALSE(r.ok);
    EXPECT_NE(r.message.find("stage 'cvt' failed"), std::string::npos) << r.message;
    EXPECT_EQ(r.message.find("the mesh is unchanged") != std::string::npos, restore) << r.message;
    if (restore) {
      ASSERT_EQ(m.fn, inputFaces);
      ASSERT_EQ(m.vn, inputVertices);
      for (std::size_t i = 0; i < input.vert.size(); ++i) EXPECT_EQ(m.vert[i].cP(), input.vert[i].cP());
    } else {
      EXPECT_EQ(m.fn, inputFaces - 20); // the clean stage's result
      const molremesh::QualityReport after = Quality::Compute(m);
      EXPECT_TRUE(after.isTwoManifold());
      EXPECT_EQ(after.components, 1u);
    }
  }
}

// --- Acceptance figures: clean, cvt, segment, rar on 1UBQ (EDTSurf) --------------------------------

class PatchwiseRemeshingUbiquitin : public ::testing::Test {
protected:
  static void SetUpTestSuite() {
    if (!molremesh::test::SharedDataFound()) return; // every test skips in SetUp
    input = new MeshD;
    output = new MeshD;
    before = new molremesh::QualityReport;
    after = new molremesh::QualityReport;
    result = new molremesh::PipelineResult;
    std::string error;
    ASSERT_TRUE(
        molremesh::LoadMesh(*output, molremesh::test::SharedMesh("ubiquitin_1UBQ_edtsurf_mc.ply"), error));
    Pipeline::Params params;
    // The stages of this acceptance block (the pipeline's default now runs every stage).
    params.stages = {molremesh::PipelineStage::Clean, molremesh::PipelineStage::Cvt,
                     molremesh::PipelineStage::Segment, molremesh::PipelineStage::Rar};
    params.cvt.iterations = 10;
    params.segment.patchCount = 4;
    params.rar.rar.iterations = 3;
    params.threads = 2;
    params.measureEachStage = false;
    *result = Pipeline::Do(*output, params);
    // The cleaned input, to compare with.
    ASSERT_TRUE(
        molremesh::LoadMesh(*input, molremesh::test::SharedMesh("ubiquitin_1UBQ_edtsurf_mc.ply"), error));
    params.stages = {molremesh::PipelineStage::Clean};
    ASSERT_TRUE(Pipeline::Do(*input, params).ok);
    *before = Quality::Compute(*input);
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
  static molremesh::PipelineResult* result;
};
MeshD* PatchwiseRemeshingUbiquitin::input = nullptr;
MeshD* PatchwiseRemeshingUbiquitin::output = nullptr;
molremesh::QualityReport* PatchwiseRemeshingUbiquitin::before = nullptr;
molremesh::QualityReport* PatchwiseRemeshingUbiquitin::after = nullptr;
molremesh::PipelineResult* PatchwiseRemeshingUbiquitin::result = nullptr;

TEST_F(PatchwiseRemeshingUbiquitin, AllStagesSucceed) {
  ASSERT_TRUE(result->ok) << result->message;
  ASSERT_EQ(result->stages.size(), 4u);
  EXPECT_EQ(result->stages.back().name, "rar");
}

TEST_F(PatchwiseRemeshingUbiquitin, StaysTwoManifold) {
  molremesh::test::ExpectTwoManifoldWithoutDegenerateFaces(*after);
}

TEST_F(PatchwiseRemeshingUbiquitin, CreatesNoSelfIntersection) {
  molremesh::test::ExpectNoSelfIntersection(*after);
}

TEST_F(PatchwiseRemeshingUbiquitin, KeepsClosedComponentsClosedWithTheirGenus) {
  molremesh::test::ExpectComponentsClosedWithTheirGenus(*before, *after);
}

TEST_F(PatchwiseRemeshingUbiquitin, KeepsTheVolumeWithinHalfAPercent) {
  EXPECT_NEAR(after->volume / before->volume, 1.0, 0.005);
}

TEST_F(PatchwiseRemeshingUbiquitin, KeepsEveryVertexOnTheInput) {
  molremesh::test::ExpectVerticesOnInput(*output, *input, 0.1 * before->meanEdgeLength);
}

// CGAL's isotropic remeshing at the same target length (tests/data/cgal_reference.json, rounded):
// 1UBQ EDTSurf theta_min 22.0, Q_min 0.467, V567 99.18 %.
TEST_F(PatchwiseRemeshingUbiquitin, AnglesQualityAndValencesAtLeastAsGoodAsCgal) {
  EXPECT_GE(after->angleMin, 22.0);
  EXPECT_GE(after->qMin, 0.467);
  EXPECT_GE(after->v567Percent, 99.18);
  // The figures above are CGAL's in the reference file, to the digits written.
  const nlohmann::json cgal = molremesh::test::CgalReference("ubiquitin_1UBQ_edtsurf_mc");
  ASSERT_FALSE(cgal.is_null()) << "no CGAL reference figures for ubiquitin_1UBQ_edtsurf_mc";
  EXPECT_EQ(molremesh::test::Rounded(cgal["angle_min_deg"].get<double>(), 1), 22.0);
  EXPECT_EQ(molremesh::test::Rounded(cgal["q_min"].get<double>(), 3), 0.467);
  EXPECT_EQ(molremesh::test::Rounded(cgal["v567_percent"].get<double>(), 2), 99.18);
}

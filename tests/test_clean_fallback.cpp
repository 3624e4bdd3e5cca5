// The clean stage's volumetric fallback (vcg_ext/clean/volumetric_fallback.h): a surface the local
// steps leave broken is rebuilt from the union of what it encloses, cavities kept, and cleaned again.
// Linked with the volume layer (OpenVDB), as the CLI is.

#include <gtest/gtest.h>

#include <vcg_ext_instances/extern_mesh_d_volume.h>
#include <vcg_ext/clean/clean_raw_mesh.h>
#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/quality/stage_summary.h>

#include <vcg/complex/append.h>

#include <cmath>
#include <string>

#include "remeshing_test_meshes.h"

namespace {

using molremesh::MeshD;
using molremesh::Point;
using CleanStage = molremesh::CleanRawMesh<MeshD>;

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
    ASSERT_TRUE(r.fallback.available);
    ASSERT_TRUE(r.fallback.rebuilt) << r.fallback.message;
    EXPECT_EQ(r.reportAfter.boundaryEdges, 0u);
    EXPECT_EQ(r.reportAfter.nonManifoldEdges, 0u);
    EXPECT_EQ(r.reportAfter.nonManifoldVertices, 0u);
    EXPECT_EQ(r.reportAfter.degenerateFaces, 0u);
    EXPECT_EQ(r.reportAfter.selfIntersectingFaces, 0u);
    EXPECT_EQ(r.unrepairedTangles + r.unfilledHoles + r.nonOrientableComponents, 0u);
    EXPECT_TRUE(vcg::tri::Clean<MeshD>::IsCoherentlyOrientedMesh(m));
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

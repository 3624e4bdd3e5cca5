// The clean stage's volumetric fallback (vcg_ext/clean/volumetric_fallback.h): a surface the local
// steps leave broken is rebuilt from the union of what it encloses, cavities kept, and cleaned again.
// Linked with the volume layer (OpenVDB), as the CLI is.

#include <gtest/gtest.h>

#include <vcg_ext_instances/extern_mesh_d_volume.h>
#include <vcg_ext/clean/clean_raw_mesh.h>
#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/quality/stage_summary.h>

#include <vcg/complex/algorithms/stat.h>
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
  auto ballAndSlab = [&ballVolume](MeshD& m) {
    MeshD slab;
    molremesh::test::Icosphere(m, 4, Point(0, 0, 0), Point(10, 10, 10));
    ballVolume = vcg::tri::Stat<MeshD>::ComputeMeshVolume(m);
    molremesh::test::Icosphere(slab, 3, Point(25, 0, 0), Point(3, 3, 0.1));
    vcg::tri::Append<MeshD, MeshD>::Mesh(m, slab);
  };
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

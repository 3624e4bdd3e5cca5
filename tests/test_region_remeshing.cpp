// RegionRemeshing: a pocket of a real molecular surface is remeshed alone; every face outside it
// stays bit for bit, the pocket reaches the angle and valence bounds, nothing intersects and the
// surface stays closed. Bad masks are refused with the mesh untouched.
#include <gtest/gtest.h>

#include <vcg/complex/complex.h>

#include <vcg/complex/append.h>

#include <algorithm>
#include <cstdio>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <vcg_ext_instances/extern_mesh_d.h>
#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/geometry/triangle_angles.h>
#include <vcg_ext/pipeline/region_remeshing.h>
#include <vcg_ext/quality/mesh_quality.h>

#include "local_stage_test_helpers.h"
#include "test_helpers.h"

using molremesh::MeshD;
using Region = molremesh::RegionRemeshing<MeshD>;
using Quality = molremesh::MeshQuality<MeshD>;
using molremesh::test::SameMesh;

namespace {

/// The faces whose three corners lie within `radius` of vertex `center`.
std::vector<std::uint8_t> BallMask(const MeshD& m, std::size_t center, double radius) {
  const vcg::Point3d c = vcg::Point3d::Construct(m.vert[center].cP());
  std::vector<std::uint8_t> mask(m.face.size(), 0);
  for (std::size_t fi = 0; fi < m.face.size(); ++fi) {
    bool inside = true;
    for (int k = 0; k < 3; ++k)
      inside = inside && (vcg::Point3d::Construct(m.face[fi].cP(k)) - c).Norm() < radius;
    mask[fi] = inside ? 1 : 0;
  }
  return mask;
}

using Triangle = std::array<vcg::Point3d, 3>;
Triangle Corners(const MeshD::FaceType& f) {
  return {vcg::Point3d::Construct(f.cP(0)), vcg::Point3d::Construct(f.cP(1)),
          vcg::Point3d::Construct(f.cP(2))};
}

struct RegionFigures {
  double angleMin = 180, angleMax = 0;                 ///< faces of the region with no corner on its border
  double borderAngleMin = 180, borderAngleMax = 0;     ///< faces with a corner on the border
  std::size_t facesOffBorder = 0, obtuseOffBorder = 0; ///< faces with no corner on the border, obtuse ones
  std::size_t facesOnBorder = 0, badOnBorder = 0;      ///< faces with a corner on it, those out of [30, 90)
  std::size_t interiorVertices = 0, interiorV567 = 0;
};

/// Angles of the new region's faces and valences of its vertices that touch no outside face.
RegionFigures Measure(const MeshD& m, const std::vector<std::uint8_t>& mask) {
  RegionFigures fig;
  std::vector<int> valence(m.vert.size(), 0);
  std::vector<std::uint8_t> touchesOutside(m.vert.size(), 0), inRegion(m.vert.size(), 0);
  for (std::size_t fi = 0; fi < m.face.size(); ++fi) {
    const auto& f = m.face[fi];
    for (int k = 0; k < 3; ++k) {
      const std::size_t v = vcg::tri::Index(m, f.cV(k));
      ++valence[v];
      (mask[fi] ? inRegion : touchesOutside)[v] = 1;
    }
  }
  for (std::size_t fi = 0; fi < m.face.size(); ++fi) {
    const auto& f = m.face[fi];
    if (!mask[fi]) continue;
    double lo = 0, hi = 0;
    molremesh::TriangleAngleRange(molremesh::PositionOf(f.cV(0)), molremesh::PositionOf(f.cV(1)),
                                  molremesh::PositionOf(f.cV(2)), lo, hi);
    bool onBorder = false;
    for (int k = 0; k < 3; ++k) onBorder = onBorder || touchesOutside[vcg::tri::Index(m, f.cV(k))];
    double& low = onBorder ? fig.borderAngleMin : fig.angleMin;
    double& high = onBorder ? fig.borderAngleMax : fig.angleMax;
    low = std::min(low, lo);
    high = std::max(high, hi);
    if (!onBorder) ++fig.facesOffBorder, fig.obtuseOffBorder += hi >= 90.0 ? 1 : 0;
    if (onBorder) ++fig.facesOnBorder, fig.badOnBorder += lo < 30.0 || hi >= 90.0 ? 1 : 0;
  }
  for (std::size_t v = 0; v < m.vert.size(); ++v)
    if (inRegion[v] && !touchesOutside[v]) {
      ++fig.interiorVertices;
      fig.interiorV567 += valence[v] >= 5 && valence[v] <= 7 ? 1 : 0;
    }
  return fig;
}

class SharedMeshes : public ::testing::TestWithParam<std::string> {};

} // namespace

TEST_P(SharedMeshes, PocketRemeshedAloneWithinBounds) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  MeshD m;
  molremesh::test::LoadPrepared(m, GetParam(), false, {});
  const std::vector<std::uint8_t> mask = BallMask(m, m.vert.size() / 2, 8.0);
  std::vector<Triangle> outside;
  for (std::size_t fi = 0; fi < m.face.size(); ++fi)
    if (!mask[fi]) outside.push_back(Corners(m.face[fi]));
  const molremesh::QualityReport before = Quality::Compute(m);

  Region::Params params;
  params.faceMask = mask;
  const Region::Result r = Region::Do(m, params);
  ASSERT_TRUE(r.ok) << r.message;
  std::printf("%s: region %zu -> %zu faces, %zu border vertices, %zu halo faces, %d settling passes and %d "
              "border flips kept, %.2f s\n",
              GetParam().c_str(), r.regionFacesIn, r.regionFacesOut, r.borderVertices, r.haloFaces,
              r.settlingPassesKept, r.borderFlipsKept, r.seconds);

  // Outside: the same triangles, bit for bit, in the same order, first.
  ASSERT_EQ(r.faceMask.size(), m.face.size());
  ASSERT_EQ(std::size_t(std::count(r.faceMask.begin(), r.faceMask.end(), 0)), outside.size());
  for (std::size_t fi = 0; fi < outside.size(); ++fi) {
    ASSERT_FALSE(r.faceMask[fi]);
    ASSERT_TRUE(Corners(m.face[fi]) == outside[fi]) << "outside face " << fi << " changed";
  }
  const RegionFigures fig = Measure(m, r.faceMask);
  const molremesh::QualityReport after = Quality::Compute(m);
  std::printf("  region angles [%.3f, %.3f], obtuse %zu of %zu (faces on the border [%.2f, %.2f], bad %zu of "
              "%zu), interior V567 %zu/%zu, SI %zu (input %zu), border edges %zu\n",
              fig.angleMin, fig.angleMax, fig.obtuseOffBorder, fig.facesOffBorder, fig.borderAngleMin,
              fig.borderAngleMax, fig.badOnBorder, fig.facesOnBorder, fig.interiorV567, fig.interiorVertices,
              after.selfIntersectingPairs, before.selfIntersectingPairs, std::size_t(after.boundaryEdges));
  // The pipeline's bounds hold on every face away from the border (the faces on it keep the
  // input's border edges, slivers included): [30, 90) degrees and every interior vertex regular.
  // Lysozyme's pocket needs the border-wedge flips for its last obtuse face and the settling
  // passes for its last irregular vertex.
  EXPECT_GE(fig.angleMin, 30.0);
  EXPECT_LT(fig.angleMax, 90.0);
  EXPECT_EQ(fig.obtuseOffBorder, 0u);
  EXPECT_EQ(fig.interiorV567, fig.interiorVertices);
  EXPECT_EQ(after.selfIntersectingPairs, before.selfIntersectingPairs);
  EXPECT_EQ(after.boundaryEdges, 0u);
  EXPECT_EQ(after.nonManifoldEdges, 0u);
}

INSTANTIATE_TEST_SUITE_P(Pockets, SharedMeshes,
                         ::testing::Values("lysozyme_Lys1_msms.ply", "ubiquitin_1UBQ_pymol_ses.ply"));

// Lysozyme's pocket goes through the settling passes and a border-wedge flip: the same bytes with
// one thread and with two.
TEST(RegionRemeshing, SameResultForOneAndTwoThreads) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  MeshD input;
  molremesh::test::LoadPrepared(input, "lysozyme_Lys1_msms.ply", false, {});
  Region::Params params;
  params.faceMask = BallMask(input, input.vert.size() / 2, 8.0);
  MeshD results[2];
  for (int threads : {1, 2}) {
    MeshD& m = results[threads - 1];
    vcg::tri::Append<MeshD, MeshD>::MeshCopy(m, input);
    params.pipeline.threads = threads;
    const Region::Result r = Region::Do(m, params);
    ASSERT_TRUE(r.ok) << r.message;
    EXPECT_GT(r.borderFlipsKept, 0);
  }
  EXPECT_TRUE(SameMesh(results[0], results[1]));
}

TEST(RegionRemeshing, RefusesBadMasksAndLeavesTheMeshUntouched) {
  MeshD m;
  molremesh::test::Icosphere(m, 3);
  molremesh::test::UpdateAdjacency(m);
  MeshD copy;
  vcg::tri::Append<MeshD, MeshD>::MeshCopy(copy, m);
  Region::Params params;
  auto expectRefused = [&](const std::string& words) {
    const Region::Result r = Region::Do(m, params);
    EXPECT_FALSE(r.ok);
    EXPECT_NE(r.message.find(words), std::string::npos) << r.message;
    EXPECT_NE(r.message.find("unchanged"), std::string::npos) << r.message;
    EXPECT_TRUE(SameMesh(m, copy));
  };
  params.faceMask.assign(m.face.size(), 0);
  expectRefused("no face selected");
  params.faceMask.assign(m.face.size(), 1);
  expectRefused("full pipeline");
  params.faceMask.assign(m.face.size() - 1, 1);
  expectRefused("entries");
}

TEST(RegionRemeshing, RefusesARegionTouchingANonManifoldEdge) {
  MeshD m;
  molremesh::test::Icosphere(m, 2);
  // A fin: a third face on the edge of face 0.
  auto vi = vcg::tri::Allocator<MeshD>::AddVertices(m, 1);
  vi->P() = (m.face[0].P(0) + m.face[0].P(1)) * 0.5 * 1.5;
  auto fi = vcg::tri::Allocator<MeshD>::AddFaces(m, 1);
  fi->V(0) = m.face[0].V(1);
  fi->V(1) = m.face[0].V(0);
  fi->V(2) = &*vi;
  molremesh::test::UpdateAdjacency(m);
  MeshD copy;
  vcg::tri::Append<MeshD, MeshD>::MeshCopy(copy, m);
  Region::Params params;
  params.faceMask.assign(m.face.size(), 0);
  params.faceMask[0] = 1;
  const Region::Result r = Region::Do(m, params);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("unchanged"), std::string::npos) << r.message;
  EXPECT_TRUE(SameMesh(m, copy));
}

TEST(RegionRemeshing, RemeshesACapOfASphereAndKeepsTheRest) {
  MeshD m;
  molremesh::test::Icosphere(m, 3);
  molremesh::test::UpdateAdjacency(m);
  const std::vector<std::uint8_t> mask = BallMask(m, 0, 0.6);
  std::vector<Triangle> outside;
  for (std::size_t fi = 0; fi < m.face.size(); ++fi)
    if (!mask[fi]) outside.push_back(Corners(m.face[fi]));
  Region::Params params;
  params.faceMask = mask;
  params.pipeline.targetEdgeLength = 0.05; // finer than the sphere's: the cap gets more faces
  const Region::Result r = Region::Do(m, params);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_GT(r.regionFacesOut, r.regionFacesIn);
  for (std::size_t fi = 0; fi < outside.size(); ++fi) ASSERT_TRUE(Corners(m.face[fi]) == outside[fi]);
  const molremesh::QualityReport after = Quality::Compute(m);
  EXPECT_EQ(after.boundaryEdges, 0u);
  EXPECT_EQ(after.selfIntersectingPairs, 0u);
}

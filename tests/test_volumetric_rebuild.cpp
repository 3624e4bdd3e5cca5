// The volumetric layer: meshes to OpenVDB level sets and back, and the volumetric rebuild of broken
// surfaces (the boundary of the union of what they enclose, cavities kept).
#include <gtest/gtest.h>

#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/quality/mesh_quality.h>
#include <vcg_ext/volume/level_set_grid.h>

#include "remeshing_test_meshes.h"
#include "test_helpers.h"

#include <cmath>

using namespace molremesh;
using namespace molremesh::test;

namespace {

QualityReport Measure(const MeshD& m) {
  return MeshQuality<MeshD>::Compute(m);
}

void ExpectValidClosedSurface(const QualityReport& q) {
  EXPECT_GT(q.faces, 0u);
  EXPECT_EQ(q.boundaryEdges, 0u);
  EXPECT_EQ(q.nonManifoldEdges, 0u);
  EXPECT_EQ(q.nonManifoldVertices, 0u);
  EXPECT_EQ(q.degenerateFaces, 0u);
  EXPECT_EQ(q.selfIntersectingPairs, 0u);
  EXPECT_EQ(q.adjacentOverlapPairs, 0u);
}

} // namespace

TEST(VolumeLayer, MeshRoundTripsThroughALevelSetWithOutwardNormals) {
  MeshD sphere;
  Icosphere(sphere, 4, Point(1, 2, 3), Point(10, 10, 10));
  const double voxel = 0.25;
  const openvdb::FloatGrid::Ptr grid = FloodFilledLevelSet(ToVdbPolygons(sphere), voxel);
  EXPECT_LE(double(grid->memUsage()), SparseGridBytes(NarrowBandVoxels(Measure(sphere).area, voxel, 3.0)));
  MeshD back;
  ASSERT_GT(LevelSetToMesh(*grid, back), 0u);
  const QualityReport in = Measure(sphere), out = Measure(back);
  ExpectValidClosedSurface(out);
  EXPECT_EQ(out.components, 1u);
  EXPECT_GT(out.volume, 0.0); // outward normals
  EXPECT_NEAR(out.volume, in.volume, 0.005 * in.volume);
  EXPECT_NEAR(out.area, in.area, 0.01 * in.area);
}

TEST(VolumeLayer, QuadsAreSplitAlongTheirShorterDiagonal) {
  VdbPolygons p;
  p.points = {{0, 0, 0}, {4, 0, 0}, {4, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {3, 1, 1}, {0, 1, 1}};
  p.quads = {{0, 1, 2, 3}, {4, 5, 6, 7}};
  const std::vector<openvdb::Vec3I> t = TrianglesOf(p);
  ASSERT_EQ(t.size(), 4u);
  // Rectangle: both diagonals equal, the first split; skewed quad: 5-7 (length sqrt 2) is shorter.
  EXPECT_EQ(t[0], openvdb::Vec3I(0, 1, 2));
  EXPECT_EQ(t[1], openvdb::Vec3I(0, 2, 3));
  EXPECT_EQ(t[2], openvdb::Vec3I(4, 5, 7));
  EXPECT_EQ(t[3], openvdb::Vec3I(5, 6, 7));
}

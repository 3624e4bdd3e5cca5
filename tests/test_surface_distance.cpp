// Tests of vcg_ext/surface_distance.h: closest points on one triangle, known distances between
// constructed surfaces, agreement with brute force on a real molecular mesh, determinism.
#include <gtest/gtest.h>

#include <vcg/complex/algorithms/create/platonic.h>
#include <vcg/complex/algorithms/update/position.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <vector>

#include <vcg_ext/io/mesh_io.h>
#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/surface/surface_distance.h>

#include "test_helpers.h"

namespace {

using molremesh::MeshD;
using Distance = molremesh::SurfaceDistance<MeshD, MeshD>;
using molremesh::Point;
using molremesh::distance_detail::TriangleDistance2;

/// Flat square [0, size]^2 at height z, split into n x n cells of two triangles each.
void MakeGrid(MeshD& m, int n, double size, double z) {
  m.Clear();
  auto vi = vcg::tri::Allocator<MeshD>::AddVertices(m, std::size_t(n + 1) * (n + 1));
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i, ++vi) vi->P() = Point(size * i / n, size * j / n, z);
  auto at = [&](int i, int j) { return &m.vert[std::size_t(j) * (n + 1) + i]; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      vcg::tri::Allocator<MeshD>::AddFace(m, at(i, j), at(i + 1, j), at(i + 1, j + 1));
      vcg::tri::Allocator<MeshD>::AddFace(m, at(i, j), at(i + 1, j + 1), at(i, j + 1));
    }
}

/// Icosphere of the given radius (vcglib's Sphere: 20 * 4^subdivisions faces, on the unit sphere).
void MakeSphere(MeshD& m, double radius, int subdivisions) {
  m.Clear();
  vcg::tri::Sphere(m, subdivisions);
  vcg::tri::UpdatePosition<MeshD>::Scale(m, radius);
}

TEST(TriangleDistance, EveryVoronoiRegion) {
  const Point a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  Point q;
  EXPECT_DOUBLE_EQ(TriangleDistance2(Point(0.2, 0.2, 0.5), a, b, c, q), 0.25); // interior, above
  EXPECT_NEAR((q - Point(0.2, 0.2, 0)).Norm(), 0, 1e-15);
  EXPECT_DOUBLE_EQ(TriangleDistance2(Point(-1, -1, 0), a, b, c, q), 2.0);  // corner a
  EXPECT_DOUBLE_EQ(TriangleDistance2(Point(2, 0, 0), a, b, c, q), 1.0);    // corner b
  EXPECT_DOUBLE_EQ(TriangleDistance2(Point(0, 3, 0), a, b, c, q), 4.0);    // corner c
  EXPECT_DOUBLE_EQ(TriangleDistance2(Point(0.5, -2, 0), a, b, c, q), 4.0); // edge ab
  EXPECT_DOUBLE_EQ(TriangleDistance2(Point(-3, 0.5, 0), a, b, c, q), 9.0); // edge ca
  EXPECT_NEAR(TriangleDistance2(Point(1, 1, 0), a, b, c, q), 0.5, 1e-15);  // edge bc
  EXPECT_NEAR((q - Point(0.5, 0.5, 0)).Norm(), 0, 1e-15);
}

TEST(TriangleDistance, DegenerateTrianglesAreSegmentsOrPoints) {
  Point q;
  // Collinear corners: the segment from (0,0,0) to (2,0,0).
  EXPECT_DOUBLE_EQ(TriangleDistance2(Point(1, 1, 0), Point(0, 0, 0), Point(1, 0, 0), Point(2, 0, 0), q), 1.0);
  EXPECT_DOUBLE_EQ(TriangleDistance2(Point(3, 0, 0), Point(0, 0, 0), Point(2, 0, 0), Point(1, 0, 0), q), 1.0);
  // All corners equal: a point.
  const Point p(1, 2, 3);
  EXPECT_DOUBLE_EQ(TriangleDistance2(Point(1, 2, 5), p, p, p, q), 4.0);
  EXPECT_FALSE(std::isnan(q[0]));
}

TEST(SurfaceDistance, MeshAgainstItselfIsZero) {
  MeshD m;
  MakeSphere(m, 1.0, 3);
  const auto d = Distance::Symmetric(m, m);
  ASSERT_TRUE(d.ok) << d.message;
  EXPECT_LT(d.hausdorff, 1e-12);
  EXPECT_LT(d.aToB.mean, 1e-12);
  EXPECT_EQ(d.aToB.vertexSamples, m.vert.size());
  EXPECT_EQ(d.aToB.faceSamples, m.face.size());
}

TEST(SurfaceDistance, ConcentricSpheresAreOneTenthApart) {
  MeshD inner, outer;
  MakeSphere(inner, 1.0, 4); // 5120 faces, edges ~0.06: facets lie within ~0.001 of the sphere
  MakeSphere(outer, 1.1, 4);
  Distance::Params params;
  params.faceSamples = 20000;
  const auto d = Distance::Symmetric(inner, outer, params);
  ASSERT_TRUE(d.ok) << d.message;
  EXPECT_NEAR(d.hausdorff, 0.1, 0.003);
  EXPECT_NEAR(d.aToB.mean, 0.1, 0.003);
  EXPECT_NEAR(d.bToA.mean, 0.1, 0.003);
  // Vertices of the outer sphere are exactly 1.1 from the centre: at least 0.1 from the inner one.
  EXPECT_GE(d.bToA.vertexMax, 0.1 - 1e-12);
  EXPECT_LE(d.aToB.vertexMax, 0.1 + 1e-12); // inner vertices: at most 0.1 from the outer facets
}

TEST(SurfaceDistance, PlaneAndOffsetCopy) {
  MeshD plane, offset;
  MakeGrid(plane, 20, 1.0, 0.0);
  MakeGrid(offset, 7, 1.0, 0.25); // other tessellation, same square, 0.25 above
  const auto d = Distance::Symmetric(plane, offset);
  ASSERT_TRUE(d.ok) << d.message;
  EXPECT_NEAR(d.hausdorff, 0.25, 1e-12);
  EXPECT_NEAR(d.aToB.max, 0.25, 1e-12);
  EXPECT_NEAR(d.aToB.mean, 0.25, 1e-12);
  EXPECT_NEAR(d.bToA.mean, 0.25, 1e-12);
  EXPECT_NEAR(d.aToB.rms, 0.25, 1e-12);
}

TEST(SurfaceDistance, HalfPlaneIsOneSided) {
  MeshD full, half;
  MakeGrid(full, 10, 1.0, 0.0);
  MakeGrid(half, 10, 0.5, 0.0); // [0, 0.5]^2, inside the full square
  const auto d = Distance::Symmetric(full, half);
  ASSERT_TRUE(d.ok) << d.message;
  EXPECT_NEAR(d.bToA.max, 0.0, 1e-12);                  // the half square lies on the full one
  EXPECT_NEAR(d.aToB.vertexMax, std::sqrt(0.5), 1e-12); // corner (1,1) to corner (0.5,0.5)
  EXPECT_NEAR(d.hausdorff, std::sqrt(0.5), 1e-12);
  // Area-weighted mean of the distance of the unit square to the half-size corner square,
  // estimated by the face samples: 3/4 of the area is outside it, at a mean of ~0.26 from it.
  EXPECT_GT(d.aToB.faceMean, 0.15);
  EXPECT_LT(d.aToB.faceMean, 0.25);
}

TEST(SurfaceDistance, VertexDistancesMatchBruteForceOnRealMeshes) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  MeshD a, b;
  std::string error;
  ASSERT_TRUE(molremesh::LoadMesh(a, molremesh::test::SharedMesh("galactose_grasp.ply"), error)) << error;
  ASSERT_TRUE(molremesh::LoadMesh(b, molremesh::test::SharedMesh("bpti_1bpi_msms.ply"), error)) << error;
  // Bring the small molecule into BPTI's box so that queries are near, inside and far from it.
  vcg::tri::UpdateBounding<MeshD>::Box(a);
  vcg::tri::UpdateBounding<MeshD>::Box(b);
  vcg::tri::UpdatePosition<MeshD>::Translate(a, b.bbox.Center() - a.bbox.Center());
  const std::vector<double> fast = Distance::VertexDistances(a, b);
  ASSERT_EQ(fast.size(), a.vert.size());
  double largest = 0;
  for (std::size_t v = 0; v < a.vert.size(); ++v) {
    double best = std::numeric_limits<double>::infinity();
    Point q;
    for (const auto& f : b.face)
      best = std::min(best, TriangleDistance2(a.vert[v].cP(), f.cP(0), f.cP(1), f.cP(2), q));
    ASSERT_NEAR(fast[v], std::sqrt(best), 1e-12) << "vertex " << v;
    largest = std::max(largest, fast[v]);
  }
  EXPECT_GT(largest, 1.0); // the test did reach beyond the first ring of cells
  const auto d = Distance::OneSided(a, b);
  ASSERT_TRUE(d.ok);
  EXPECT_DOUBLE_EQ(d.vertexMax, largest);
}

TEST(SurfaceDistance, LargestSharedMeshInSeconds) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  MeshD m, moved;
  std::string error;
  ASSERT_TRUE(molremesh::LoadMesh(m, molremesh::test::SharedMesh("mtor_4JSV_edtsurf_vcmc.ply"), error))
      << error;
  ASSERT_TRUE(molremesh::LoadMesh(moved, molremesh::test::SharedMesh("mtor_4JSV_edtsurf_vcmc.ply"), error))
      << error;
  ASSERT_GT(m.face.size(), 500000u);
  const double shift = 0.05; // well under the mean edge length (0.66)
  vcg::tri::UpdatePosition<MeshD>::Translate(moved, Point(shift, 0, 0));
  const auto start = std::chrono::steady_clock::now();
  const auto self = Distance::Symmetric(m, m);
  const auto shifted = Distance::Symmetric(m, moved);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_TRUE(self.ok && shifted.ok);
  EXPECT_LT(self.hausdorff, 1e-9);
  // Every point of a translated copy is within the translation of the original surface, and
  // on a closed curved surface somewhere the distance reaches almost all of it.
  EXPECT_LE(shifted.hausdorff, shift + 1e-12);
  EXPECT_GT(shifted.hausdorff, 0.9 * shift);
  EXPECT_LT(seconds, 60.0) << "4 one-sided distances on 535k faces should take seconds, not minutes";
  RecordProperty("seconds", std::to_string(seconds));
}

TEST(SurfaceDistance, DeterministicForSeedAndThreads) {
  MeshD a, b;
  MakeSphere(a, 1.0, 3);
  MakeGrid(b, 13, 2.0, 0.1);
  Distance::Params params;
  params.faceSamples = 5000;
  const auto first = Distance::Symmetric(a, b, params);
  params.threads = 2;
  const auto second = Distance::Symmetric(a, b, params);
  ASSERT_TRUE(first.ok && second.ok);
  EXPECT_EQ(first.hausdorff, second.hausdorff);
  EXPECT_EQ(first.aToB.mean, second.aToB.mean);
  EXPECT_EQ(first.bToA.rms, second.bToA.rms);
  params.seed = 99;
  const auto other = Distance::Symmetric(a, b, params);
  EXPECT_NE(first.aToB.faceMean, other.aToB.faceMean);   // other samples...
  EXPECT_EQ(first.aToB.vertexMax, other.aToB.vertexMax); // ...same vertices
}

TEST(SurfaceDistance, FailuresAreReportedNotCrashed) {
  MeshD empty, sphere, cloud;
  MakeSphere(sphere, 1.0, 2);
  const auto toEmpty = Distance::OneSided(sphere, empty);
  EXPECT_FALSE(toEmpty.ok);
  EXPECT_FALSE(toEmpty.message.empty());
  EXPECT_FALSE(Distance::Symmetric(empty, sphere).ok);
  EXPECT_TRUE(Distance::VertexDistances(sphere, empty).empty());

  // A point cloud (no faces) is measured by its vertices.
  vcg::tri::Allocator<MeshD>::AddVertex(cloud, Point(0, 0, 2));
  vcg::tri::Allocator<MeshD>::AddVertex(cloud, Point(0, 0, 0));
  const auto fromCloud = Distance::OneSided(cloud, sphere);
  ASSERT_TRUE(fromCloud.ok) << fromCloud.message;
  EXPECT_EQ(fromCloud.vertexSamples, 2u);
  EXPECT_EQ(fromCloud.faceSamples, 0u);
  EXPECT_NEAR(fromCloud.max, 1.0, 1e-12); // (0,0,2) to the icosphere's pole vertex (0,0,1)

  // Deleted faces of B are not part of its surface.
  MeshD plane;
  MakeGrid(plane, 1, 1.0, 0.0);
  vcg::tri::Allocator<MeshD>::DeleteFace(plane, plane.face[1]); // keeps the (0,0) (1,0) (1,1) half
  MeshD probe;
  vcg::tri::Allocator<MeshD>::AddVertex(probe, Point(0, 1, 0));
  EXPECT_NEAR(Distance::OneSided(probe, plane).max, std::sqrt(0.5), 1e-12);
}

// A float mesh with nothing but coordinates and flags, as a minimal MeshLab-like type.
class VertexF;
class FaceF;
struct UsedTypesF : vcg::UsedTypes<vcg::Use<VertexF>::AsVertexType, vcg::Use<FaceF>::AsFaceType> {};
class VertexF : public vcg::Vertex<UsedTypesF, vcg::vertex::Coord3f, vcg::vertex::BitFlags> {};
class FaceF : public vcg::Face<UsedTypesF, vcg::face::VertexRef, vcg::face::BitFlags> {};
class MeshF : public vcg::tri::TriMesh<std::vector<VertexF>, std::vector<FaceF>> {};

TEST(SurfaceDistance, MixedFloatAndDoubleMeshes) {
  MeshF f;
  vcg::tri::Sphere(f, 3);
  MeshD d;
  MakeSphere(d, 1.2, 3);
  const auto r = molremesh::SurfaceDistance<MeshF, MeshD>::Symmetric(f, d);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_NEAR(r.hausdorff, 0.2, 0.01);
}

} // namespace

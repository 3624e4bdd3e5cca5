// Unit tests of molremesh::MeshQuality: known answers on small synthetic meshes, robustness on
// broken inputs, the self-intersection grid against brute force, and a real molecular surface.
#include <gtest/gtest.h>

#include <vcg_ext/quality/mesh_quality.h>
#include <vcg_ext/core/mesh_types.h>

#include <vcg/complex/algorithms/create/platonic.h>
#include <wrap/io_trimesh/import_ply.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <limits>
#include <random>
#include <tuple>
#include <vector>

#include "remeshing_test_meshes.h"
#include "test_helpers.h"

namespace {

using molremesh::MeshD;
using Quality = molremesh::MeshQuality<MeshD>;
using Point = vcg::Point3d;

constexpr double kPi = 3.14159265358979323846;
const double kInf = std::numeric_limits<double>::infinity();
const double kNaN = std::numeric_limits<double>::quiet_NaN();

// A float mesh shaped like MeshLab's CMeshO, to check that the templates work on float
// coordinates and give the same figures.
using molremesh::test::MeshF;
// Mesh from explicit points and index triples (indices may repeat: used for broken inputs).
using molremesh::test::MakeMesh;

/// n x n quads in the z = 0 plane, each split along the same diagonal (interior valence 6).
/// Quads for which skip(i, j) is true are left out.
template <class Skip>
void MakeGrid(MeshD& m, int n, Skip skip) {
  std::vector<Point> points;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) points.emplace_back(i, j, 0);
  std::vector<std::array<int, 3>> faces;
  auto id = [n](int i, int j) { return j * (n + 1) + i; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      if (skip(i, j)) continue;
      faces.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      faces.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  MakeMesh(m, points, faces);
}
void MakeGrid(MeshD& m, int n) {
  MakeGrid(m, n, [](int, int) { return false; });
}

/// Tetrahedron with outward orientation, translated by offset.
void AddTetrahedron(std::vector<Point>& points, std::vector<std::array<int, 3>>& faces, const Point& offset) {
  const int b = int(points.size());
  points.push_back(offset + Point(0, 0, 0));
  points.push_back(offset + Point(1, 0, 0));
  points.push_back(offset + Point(0, 1, 0));
  points.push_back(offset + Point(0, 0, 1));
  faces.push_back({b + 0, b + 2, b + 1});
  faces.push_back({b + 0, b + 1, b + 3});
  faces.push_back({b + 0, b + 3, b + 2});
  faces.push_back({b + 1, b + 2, b + 3});
}

/// Unit icosphere: icosahedron, midpoint-subdivided, projected to the unit sphere.
void MakeIcosphere(MeshD& m, int subdivisions) {
  molremesh::test::Icosphere(m, subdivisions);
}

int SumHistogram(const molremesh::QualityReport& r) {
  int sum = 0;
  for (const auto& entry : r.valenceHistogram) sum += int(entry.second);
  return sum;
}

// ----------------------------------------------------------------------------------------------
// Single triangles
// ----------------------------------------------------------------------------------------------

TEST(MeshQuality, EquilateralTriangle) {
  MeshD m;
  MakeMesh(m, {{0, 0, 0}, {1, 0, 0}, {0.5, std::sqrt(3.0) / 2, 0}}, {{0, 1, 2}});
  const auto r = Quality::Compute(m);
  EXPECT_EQ(r.vertices, 3u);
  EXPECT_EQ(r.referencedVertices, 3u);
  EXPECT_EQ(r.faces, 1u);
  EXPECT_EQ(r.edges, 3u);
  EXPECT_NEAR(r.qMin, 1.0, 1e-12);
  EXPECT_NEAR(r.qAvg, 1.0, 1e-12);
  EXPECT_NEAR(r.aspectRatioMax, 1.0, 1e-12);
  EXPECT_NEAR(r.aspectRatioMean, 1.0, 1e-12);
  EXPECT_NEAR(r.angleMin, 60.0, 1e-9);
  EXPECT_NEAR(r.angleMax, 60.0, 1e-9);
  EXPECT_NEAR(r.meanMinAngle, 60.0, 1e-9);
  EXPECT_EQ(r.smallAngleFaces, 0u);
  EXPECT_EQ(r.obtuseFaces, 0u);
  EXPECT_EQ(r.largeAngleFaces, 0u);
  EXPECT_NEAR(r.area, std::sqrt(3.0) / 4, 1e-12);
  EXPECT_EQ(r.boundaryEdges, 3u);
  EXPECT_EQ(r.boundaryLoops, 1u);
  EXPECT_EQ(r.nonManifoldEdges, 0u);
  EXPECT_EQ(r.nonManifoldVertices, 0u);
  EXPECT_EQ(r.euler, 1);
  EXPECT_EQ(r.genus, 0);
  ASSERT_EQ(r.components, 1u);
  EXPECT_TRUE(r.componentInfo[0].manifold);
  EXPECT_FALSE(r.componentInfo[0].closed);
  EXPECT_EQ(r.componentInfo[0].euler, 1);
  EXPECT_EQ(r.componentInfo[0].genus, 0);
  EXPECT_EQ(r.componentInfo[0].boundaryEdges, 3u);
  EXPECT_EQ(r.interiorVertices, 0u);
  EXPECT_DOUBLE_EQ(r.v567Percent, 100.0); // no interior vertex
  EXPECT_EQ(r.degenerateFaces, 0u);
  EXPECT_TRUE(r.selfIntersectionsComputed);
  EXPECT_EQ(r.selfIntersectingPairs, 0u);
  EXPECT_TRUE(r.isTwoManifold());

  const auto angles = Quality::FaceAngles(m.face[0]);
  for (double a : angles.degrees) EXPECT_NEAR(a, 60.0, 1e-9);
}

TEST(MeshQuality, RightIsoscelesTriangle) {
  MeshD m;
  MakeMesh(m, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}});
  const auto r = Quality::Compute(m);
  const double sqrt2 = std::sqrt(2.0), sqrt3 = std::sqrt(3.0);
  // A = 1/2, half perimeter s = (2 + sqrt 2) / 2, longest edge h = sqrt 2.
  const double s = (2 + sqrt2) / 2;
  EXPECT_NEAR(r.qMin, (6 / sqrt3) * 0.5 / (s * sqrt2), 1e-12);
  EXPECT_NEAR(r.qMin, sqrt3 * (sqrt2 - 1), 1e-12);
  // AR = abc / (8 (s-a)(s-b)(s-c)) = (1 + sqrt 2) / 2.
  EXPECT_NEAR(r.aspectRatioMax, 1 * 1 * sqrt2 / (8 * (s - 1) * (s - 1) * (s - sqrt2)), 1e-12);
  EXPECT_NEAR(r.aspectRatioMax, (1 + sqrt2) / 2, 1e-12);
  EXPECT_NEAR(r.angleMin, 45.0, 1e-9);
  EXPECT_NEAR(r.angleMax, 90.0, 1e-9);
  EXPECT_EQ(r.obtuseFaces, 1u); // max angle >= 90
  EXPECT_DOUBLE_EQ(r.obtusePercent, 100.0);
  EXPECT_EQ(r.largeAngleFaces, 0u);
  EXPECT_EQ(r.smallAngleFaces, 0u);
  EXPECT_NEAR(r.area, 0.5, 1e-15);

  const auto angles = Quality::FaceAngles(m.face[0]);
  EXPECT_NEAR(angles.degrees[0], 90.0, 1e-9);
  EXPECT_NEAR(angles.degrees[1], 45.0, 1e-9);
  EXPECT_NEAR(angles.degrees[2], 45.0, 1e-9);
  EXPECT_NEAR(angles.min(), 45.0, 1e-9);
  EXPECT_NEAR(angles.max(), 90.0, 1e-9);
}

TEST(MeshQuality, AngleThresholdsFollowParams) {
  // Isosceles, apex at the origin: the legs are 20 degrees off the x axis, so the angles are
  // 40 (apex), 70, 70.
  const double half = 70.0 * kPi / 180.0;
  MeshD m;
  MakeMesh(m, {{0, 0, 0}, {std::sin(half), -std::cos(half), 0}, {std::sin(half), std::cos(half), 0}},
           {{0, 1, 2}});
  const auto angles = Quality::FaceAngles(m.face[0]);
  EXPECT_NEAR(angles.degrees[0], 40.0, 1e-9);
  EXPECT_NEAR(angles.degrees[1], 70.0, 1e-9);
  EXPECT_NEAR(angles.degrees[2], 70.0, 1e-9);

  Quality::Params params;
  auto r = Quality::Compute(m, params);
  EXPECT_EQ(r.smallAngleFaces, 0u);
  EXPECT_EQ(r.obtuseFaces, 0u);
  params.smallAngle = 45;
  params.obtuseAngle = 70.0 - 1e-9; // the 70 degree angle counts
  params.largeAngle = 69.9;         // >
  r = Quality::Compute(m, params);
  EXPECT_EQ(r.smallAngleFaces, 1u);
  EXPECT_EQ(r.obtuseFaces, 1u);
  EXPECT_EQ(r.largeAngleFaces, 1u);
  params.largeAngle = 70.0 + 1e-9;
  r = Quality::Compute(m, params);
  EXPECT_EQ(r.largeAngleFaces, 0u);
}

TEST(MeshQuality, NeedleTriangleAnglesAreAccurate) {
  // A 1e-7 degree angle: acos would lose it entirely, atan2 keeps it.
  const double tiny = 1e-7 * kPi / 180.0;
  MeshD m;
  MakeMesh(m, {{0, 0, 0}, {1, 0, 0}, {std::cos(tiny), std::sin(tiny), 0}}, {{0, 1, 2}});
  Quality::Params params;
  params.degenerateAreaEpsilon = 0; // keep it non-degenerate
  const auto r = Quality::Compute(m, params);
  EXPECT_EQ(r.degenerateFaces, 0u);
  EXPECT_NEAR(r.angleMin, 1e-7, 1e-12);
  EXPECT_NEAR(r.angleMax, 90.0 - 0.5e-7, 1e-6);
  EXPECT_GT(r.aspectRatioMax, 1e6);
  EXPECT_TRUE(std::isfinite(r.aspectRatioMax));
}

// ----------------------------------------------------------------------------------------------
// Closed surfaces
// ----------------------------------------------------------------------------------------------

TEST(MeshQuality, Icosahedron) {
  MeshD m;
  vcg::tri::Icosahedron(m); // edge length 2
  const auto r = Quality::Compute(m);
  EXPECT_EQ(r.vertices, 12u);
  EXPECT_EQ(r.faces, 20u);
  EXPECT_EQ(r.edges, 30u);
  EXPECT_EQ(r.euler, 2);
  EXPECT_EQ(r.genus, 0);
  ASSERT_EQ(r.components, 1u);
  EXPECT_TRUE(r.componentInfo[0].closed);
  EXPECT_EQ(r.componentInfo[0].genus, 0);
  EXPECT_EQ(r.boundaryEdges, 0u);
  EXPECT_EQ(r.boundaryLoops, 0u);
  EXPECT_EQ(r.interiorVertices, 12u);
  EXPECT_DOUBLE_EQ(r.v567Percent, 100.0);
  ASSERT_EQ(r.valenceHistogram.size(), 1u);
  EXPECT_EQ(r.valenceHistogram.at(5), 12u);
  EXPECT_NEAR(r.qMin, 1.0, 1e-9);
  EXPECT_NEAR(r.area, 5 * std::sqrt(3.0) * 4, 1e-9);                  // 5 sqrt(3) a^2
  EXPECT_NEAR(r.volume, 5.0 / 12.0 * (3 + std::sqrt(5.0)) * 8, 1e-9); // 5/12 (3 + sqrt 5) a^3
  EXPECT_NEAR(r.meanEdgeLength, 2.0, 1e-12);
  EXPECT_EQ(r.selfIntersectingPairs, 0u);
  EXPECT_EQ(r.adjacentOverlapPairs, 0u);

  const auto valences = Quality::VertexValences(m);
  for (int v : valences) EXPECT_EQ(v, 5);
  for (bool b : Quality::VertexOnBorder(m)) EXPECT_FALSE(b);
}

TEST(MeshQuality, IcosphereMatchesTheSphere) {
  MeshD m;
  MakeIcosphere(m, 5); // 20 * 4^5 = 20480 faces
  const auto r = Quality::Compute(m);
  EXPECT_EQ(r.faces, 20480u);
  EXPECT_EQ(r.vertices, 10242u);
  EXPECT_EQ(r.euler, 2);
  EXPECT_EQ(r.genus, 0);
  ASSERT_EQ(r.components, 1u);
  EXPECT_TRUE(r.componentInfo[0].closed);
  EXPECT_EQ(r.boundaryEdges, 0u);
  EXPECT_EQ(r.nonManifoldEdges, 0u);
  EXPECT_EQ(r.nonManifoldVertices, 0u);
  EXPECT_NEAR(r.area, 4 * kPi, 0.01 * 4 * kPi);
  EXPECT_NEAR(r.volume, 4.0 / 3.0 * kPi, 0.01 * 4.0 / 3.0 * kPi);
  EXPECT_LT(r.area, 4 * kPi); // inscribed polyhedron
  EXPECT_DOUBLE_EQ(r.v567Percent, 100.0);
  EXPECT_EQ(r.interiorVertices, 10242u);
  ASSERT_EQ(r.valenceHistogram.size(), 2u);
  EXPECT_EQ(r.valenceHistogram.at(5), 12u);
  EXPECT_EQ(r.valenceHistogram.at(6), 10242u - 12u);
  EXPECT_EQ(SumHistogram(r), int(r.interiorVertices));
  EXPECT_EQ(r.degenerateFaces, 0u);
  EXPECT_GT(r.qMin, 0.7);
  EXPECT_GT(r.angleMin, 40.0);
  EXPECT_EQ(r.selfIntersectingPairs, 0u);
  EXPECT_EQ(r.adjacentOverlapPairs, 0u);
  EXPECT_EQ(r.selfIntersectingFaces, 0u);
}

TEST(MeshQuality, CoarseIcosphereIsCloseToo) {
  MeshD m;
  MakeIcosphere(m, 3);
  const auto r = Quality::Compute(m);
  EXPECT_NEAR(r.area, 4 * kPi, 0.02 * 4 * kPi);
  EXPECT_NEAR(r.volume, 4.0 / 3.0 * kPi, 0.03 * 4.0 / 3.0 * kPi);
  EXPECT_EQ(r.valenceHistogram.at(5), 12u);
  EXPECT_EQ(r.selfIntersectingPairs, 0u);
}

TEST(MeshQuality, InvertedOrientationGivesNegativeVolume) {
  MeshD m;
  vcg::tri::Icosahedron(m);
  for (auto& f : m.face) std::swap(f.V(1), f.V(2));
  const auto r = Quality::Compute(m);
  EXPECT_NEAR(r.volume, -5.0 / 12.0 * (3 + std::sqrt(5.0)) * 8, 1e-9);
}

TEST(MeshQuality, VolumeIsTranslationInvariant) {
  MeshD m;
  MakeIcosphere(m, 3);
  const auto ref = Quality::Compute(m);
  for (auto& v : m.vert) v.P() += Point(1e4, -2e4, 3e4);
  const auto moved = Quality::Compute(m);
  EXPECT_NEAR(moved.volume, ref.volume, 1e-9 * ref.volume);
  EXPECT_NEAR(moved.area, ref.area, 1e-9 * ref.area);
  EXPECT_EQ(moved.selfIntersectingPairs, 0u);
}

TEST(MeshQuality, TorusHasGenusOne) {
  MeshD m;
  vcg::tri::Torus(m, 3.0f, 1.0f, 24, 12);
  const auto r = Quality::Compute(m);
  EXPECT_EQ(r.faces, 2u * 24u * 12u);
  EXPECT_EQ(r.euler, 0);
  EXPECT_EQ(r.genus, 1);
  ASSERT_EQ(r.components, 1u);
  EXPECT_TRUE(r.componentInfo[0].closed);
  EXPECT_EQ(r.componentInfo[0].genus, 1);
  EXPECT_EQ(r.boundaryEdges, 0u);
  EXPECT_EQ(r.nonManifoldEdges, 0u);
  EXPECT_EQ(r.nonManifoldVertices, 0u);
  EXPECT_EQ(r.selfIntersectingPairs, 0u);
  EXPECT_EQ(r.adjacentOverlapPairs, 0u);
  // Smooth torus: volume 2 pi^2 R r^2, area 4 pi^2 R r. The coarse inscribed polyhedron (a 12-gon
  // cross-section swept along a 24-gon) falls short of both by a few percent.
  const double smoothVolume = 2 * kPi * kPi * 3, smoothArea = 4 * kPi * kPi * 3;
  EXPECT_LT(std::fabs(r.volume), smoothVolume);
  EXPECT_GT(std::fabs(r.volume), 0.9 * smoothVolume);
  EXPECT_LT(r.area, smoothArea);
  EXPECT_GT(r.area, 0.95 * smoothArea);
}

TEST(MeshQuality, TwoSpheresAreTwoComponentsSortedBySize) {
  MeshD m;
  MakeIcosphere(m, 2);
  MeshD big;
  MakeIcosphere(big, 3);
  for (auto& v : big.vert) v.P() += Point(5, 0, 0);
  vcg::tri::Append<MeshD, MeshD>::Mesh(m, big);
  const auto r = Quality::Compute(m);
  ASSERT_EQ(r.components, 2u);
  EXPECT_EQ(r.componentInfo[0].faces, 1280u); // largest first
  EXPECT_EQ(r.componentInfo[1].faces, 320u);
  EXPECT_EQ(r.componentInfo[0].euler, 2);
  EXPECT_EQ(r.componentInfo[1].euler, 2);
  EXPECT_EQ(r.euler, 4);
  EXPECT_EQ(r.genus, 0);
  EXPECT_EQ(r.selfIntersectingPairs, 0u);
}

// ----------------------------------------------------------------------------------------------
// Open surfaces
// ----------------------------------------------------------------------------------------------

TEST(MeshQuality, OpenGridPatch) {
  MeshD m;
  MakeGrid(m, 4);
  const auto r = Quality::Compute(m);
  EXPECT_EQ(r.vertices, 25u);
  EXPECT_EQ(r.faces, 32u);
  EXPECT_EQ(r.edges, 56u); // 2 * 4 * 5 axis edges + 16 diagonals
  EXPECT_EQ(r.boundaryEdges, 16u);
  EXPECT_EQ(r.boundaryLoops, 1u);
  EXPECT_EQ(r.euler, 1);
  EXPECT_EQ(r.genus, 0);
  ASSERT_EQ(r.components, 1u);
  EXPECT_FALSE(r.componentInfo[0].closed);
  EXPECT_TRUE(r.componentInfo[0].manifold);
  EXPECT_EQ(r.componentInfo[0].boundaryLoops, 1u);
  EXPECT_EQ(r.interiorVertices, 9u);
  EXPECT_EQ(r.valenceHistogram.at(6), 9u);
  EXPECT_DOUBLE_EQ(r.v567Percent, 100.0);
  EXPECT_NEAR(r.area, 16.0, 1e-12);
  EXPECT_NEAR(r.angleMin, 45.0, 1e-9);
  EXPECT_NEAR(r.angleMax, 90.0, 1e-9);
  EXPECT_EQ(r.obtuseFaces, 32u);
  // Coplanar neighbours two rings apart must not be reported as touching.
  EXPECT_EQ(r.selfIntersectingPairs, 0u);
  EXPECT_EQ(r.adjacentOverlapPairs, 0u);

  const auto border = Quality::VertexOnBorder(m);
  const auto valence = Quality::VertexValences(m);
  ASSERT_EQ(border.size(), 25u);
  for (int j = 0; j <= 4; ++j)
    for (int i = 0; i <= 4; ++i) {
      const bool onFrame = i == 0 || j == 0 || i == 4 || j == 4;
      EXPECT_EQ(border[j * 5 + i], onFrame) << i << "," << j;
      if (!onFrame) {
        EXPECT_EQ(valence[j * 5 + i], 6);
      }
    }
  EXPECT_EQ(valence[0], 3); // corner on the diagonal
  EXPECT_EQ(valence[4], 2); // corner off the diagonal
}

TEST(MeshQuality, AnnulusHasTwoBoundaryLoops) {
  MeshD m;
  MakeGrid(m, 5, [](int i, int j) { return i == 2 && j == 2; });
  const auto r = Quality::Compute(m);
  EXPECT_EQ(r.boundaryEdges, 20u + 4u);
  EXPECT_EQ(r.boundaryLoops, 2u);
  EXPECT_EQ(r.euler, 0);
  EXPECT_EQ(r.genus, 0); // (2 - 0 - 2) / 2
  EXPECT_EQ(r.nonManifoldVertices, 0u);
}

TEST(MeshQuality, DeletedElementsAreSkipped) {
  MeshD m;
  vcg::tri::Icosahedron(m);
  vcg::tri::Allocator<MeshD>::DeleteFace(m, m.face[3]);
  const auto r = Quality::Compute(m);
  EXPECT_EQ(r.faces, 19u);
  EXPECT_EQ(r.boundaryEdges, 3u);
  EXPECT_EQ(r.boundaryLoops, 1u);
  EXPECT_EQ(r.euler, 1);
  EXPECT_EQ(r.genus, 0);

  MeshD withDeletedVertex;
  vcg::tri::Icosahedron(withDeletedVertex);
  auto extra = vcg::tri::Allocator<MeshD>::AddVertices(withDeletedVertex, 1);
  extra->P() = Point(kNaN, 0, 0);
  vcg::tri::Allocator<MeshD>::DeleteVertex(withDeletedVertex, *extra);
  const auto r2 = Quality::Compute(withDeletedVertex);
  EXPECT_EQ(r2.vertices, 12u);
  EXPECT_EQ(r2.unreferencedVertices, 0u);
  EXPECT_EQ(r2.nonFiniteVertices, 0u);
}

// ----------------------------------------------------------------------------------------------
// Non-manifold inputs
// ----------------------------------------------------------------------------------------------

TEST(MeshQuality, NonManifoldEdge) {
  // Three triangles hinged on the edge (0, 1).
  MeshD m;
  MakeMesh(m, {{0, 0, 0}, {1, 0, 0}, {0.5, 1, 0}, {0.5, -1, 0}, {0.5, 0, 1}},
           {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}});
  const auto r = Quality::Compute(m);
  EXPECT_EQ(r.nonManifoldEdges, 1u);
  // The vertices of the non-manifold edge are not counted again (vcglib's convention).
  EXPECT_EQ(r.nonManifoldVertices, 0u);
  EXPECT_FALSE(r.isTwoManifold());
  EXPECT_EQ(r.boundaryEdges, 6u);
  EXPECT_EQ(r.boundaryLoops, 0u); // the boundary polylines end on the non-manifold edge
  ASSERT_EQ(r.components, 1u);
  EXPECT_FALSE(r.componentInfo[0].manifold);
  EXPECT_FALSE(r.componentInfo[0].closed);
  EXPECT_EQ(r.componentInfo[0].genus, -1);
  EXPECT_EQ(r.genus, -1);
  EXPECT_EQ(r.euler, 5 - 7 + 3);
  for (bool b : Quality::VertexOnBorder(m)) EXPECT_TRUE(b);
  EXPECT_EQ(r.interiorVertices, 0u);
}

TEST(MeshQuality, TetrahedraTouchingAtOneVertex) {
  std::vector<Point> points;
  std::vector<std::array<int, 3>> faces;
  AddTetrahedron(points, faces, Point(0, 0, 0));
  AddTetrahedron(points, faces, Point(1, 0, 0)); // its vertex 0 is the first one's vertex 1
  // Weld the coincident vertex: face indices 4 -> 1.
  for (auto& f : faces)
    for (int& v : f)
      if (v == 4) v = 1;
  MeshD m;
  MakeMesh(m, points, faces);
  const auto r = Quality::Compute(m);
  EXPECT_EQ(r.nonManifoldVertices, 1u);
  EXPECT_EQ(r.nonManifoldEdges, 0u);
  EXPECT_EQ(r.boundaryEdges, 0u);
  EXPECT_EQ(r.unreferencedVertices, 1u); // the welded-away vertex 4
  EXPECT_EQ(r.referencedVertices, 7u);
  EXPECT_EQ(r.components, 2u); // vertex contact does not join components
  // Each component on its own is a closed manifold: the pinch is where two components touch.
  for (const auto& c : r.componentInfo) {
    EXPECT_EQ(c.faces, 4u);
    EXPECT_TRUE(c.manifold);
    EXPECT_TRUE(c.closed);
    EXPECT_EQ(c.euler, 2);
    EXPECT_EQ(c.genus, 0);
  }
  EXPECT_EQ(r.genus, 0);
  EXPECT_EQ(r.euler, 7 - 12 + 8);
  EXPECT_FALSE(r.isTwoManifold());
  // The two tetrahedra only touch at the shared vertex.
  EXPECT_EQ(r.selfIntersectingPairs, 0u);
  EXPECT_EQ(r.adjacentOverlapPairs, 0u);
}

TEST(MeshQuality, BowtieKeepsBothBoundaryLoops) {
  // Two open triangles sharing only vertex 0: the pinch is non-manifold, and each fan pairs its own
  // two boundary edges, so the boundary still splits into two loops.
  MeshD m;
  MakeMesh(m, {{0, 0, 0}, {1, 1, 0}, {1, -1, 0}, {-1, 1, 0}, {-1, -1, 0}}, {{0, 2, 1}, {0, 3, 4}});
  const auto r = Quality::Compute(m);
  EXPECT_EQ(r.nonManifoldVertices, 1u);
  EXPECT_EQ(r.components, 2u);
  EXPECT_EQ(r.boundaryEdges, 6u);
  EXPECT_EQ(r.boundaryLoops, 2u);
  EXPECT_EQ(r.genus, 0); // two disks
  EXPECT_EQ(r.adjacentOverlapPairs, 0u);
}

TEST(MeshQuality, PinchWithinOneComponent) {
  // A 2 x 2 grid whose opposite corners (2,0) and (0,2) (off the split diagonal, so no edge is
  // duplicated) are welded: the welded vertex has two fans of the same component, so that
  // component is not a manifold and has no genus.
  MeshD m;
  MakeGrid(m, 2);
  for (auto& f : m.face)
    for (int i = 0; i < 3; ++i)
      if (f.V(i) == &m.vert[6]) f.V(i) = &m.vert[2];
  const auto r = Quality::Compute(m);
  EXPECT_EQ(r.nonManifoldVertices, 1u);
  EXPECT_EQ(r.nonManifoldEdges, 0u);
  EXPECT_EQ(r.unreferencedVertices, 1u);
  ASSERT_EQ(r.components, 1u);
  EXPECT_FALSE(r.componentInfo[0].manifold);
  EXPECT_EQ(r.componentInfo[0].genus, -1);
  EXPECT_EQ(r.genus, -1);
  EXPECT_EQ(r.boundaryEdges, 8u);
  EXPECT_EQ(r.boundaryLoops, 1u); // each fan pairs its own two boundary edges
  EXPECT_TRUE(Quality::VertexOnBorder(m)[2]);
}

// ----------------------------------------------------------------------------------------------
// Self-intersections
// ----------------------------------------------------------------------------------------------

TEST(MeshQuality, CrossingTrianglesSharingNoVertex) {
  MeshD m;
  MakeMesh(m, {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0.5, 0.5, -1}, {0.5, 0.5, 1}, {3, 3, 0.2}},
           {{0, 1, 2}, {3, 4, 5}});
  const auto r = Quality::Compute(m);
  EXPECT_EQ(r.selfIntersectingPairs, 1u);
  EXPECT_EQ(r.adjacentOverlapPairs, 0u);
  EXPECT_EQ(r.selfIntersectingFaces, 2u);
  EXPECT_EQ(r.components, 2u);

  Quality::Params params;
  params.computeSelfIntersections = false;
  const auto skipped = Quality::Compute(m, params);
  EXPECT_FALSE(skipped.selfIntersectionsComputed);
  EXPECT_EQ(skipped.selfIntersectingPairs, 0u);
}

/// n long triangles through one point: every face shares the grid cells around it with every
/// other, so the self-intersection count's candidate pairs grow as n^2.
void MakeStarSoup(MeshD& m, int n) {
  std::vector<Point> points;
  std::vector<std::array<int, 3>> faces;
  for (int i = 0; i < n; ++i) {
    const double a = 3.14159265358979 * i / n, c = std::cos(a), s = std::sin(a);
    points.insert(points.end(), {Point(c, s, -0.1), Point(-c, -s, 0.1), Point(0.01 * s, 0.01 * c, 1)});
    faces.push_back({3 * i, 3 * i + 1, 3 * i + 2});
  }
  MakeMesh(m, points, faces);
}

TEST(MeshQuality, SelfIntersectionCountIsSkippedBeyondItsBoundsWithTheReason) {
  MeshD m;
  MakeStarSoup(m, 4600); // over 4600^2 / 2 = 1.06e7 candidate pairs
  Quality::Params work;
  work.maxCandidatePairsPerFace = 0; // the bound is 10^7 pairs
  work.memoryLimitMB = -1;
  const auto overWork = Quality::Compute(m, work);
  EXPECT_FALSE(overWork.selfIntersectionsComputed);
  EXPECT_FALSE(overWork.selfIntersectionsSkippedForMemory);
  EXPECT_NE(
      overWork.selfIntersectionsSkipped.find("candidate pairs (4600 faces), more than its bound of 10000000"),
      std::string::npos)
      << overWork.selfIntersectionsSkipped;
  EXPECT_EQ(overWork.faces, 4600u); // the linear figures are all there
  EXPECT_GT(overWork.area, 0.0);

  Quality::Params memory;
  memory.maxCandidatePairsPerFace = -1;
  memory.memoryLimitMB = 100;
  const auto overMemory = Quality::Compute(m, memory);
  EXPECT_FALSE(overMemory.selfIntersectionsComputed);
  EXPECT_TRUE(overMemory.selfIntersectionsSkippedForMemory);
  EXPECT_NE(overMemory.selfIntersectionsSkipped.find("more than the 100 MB memory limit"), std::string::npos)
      << overMemory.selfIntersectionsSkipped;

  MeshD small;
  MakeStarSoup(small, 1000);
  const auto counted = Quality::Compute(small); // default bounds: 1.1e7 pairs allowed
  EXPECT_TRUE(counted.selfIntersectionsComputed) << counted.selfIntersectionsSkipped;
  EXPECT_TRUE(counted.selfIntersectionsSkipped.empty());
  EXPECT_GT(counted.selfIntersectingPairs, 1000u);
}

TEST(MeshQuality, DisjointTriangles) {
  MeshD m;
  MakeMesh(m, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 0.5}, {1, 0, 0.5}, {0, 1, 0.5}},
           {{0, 1, 2}, {3, 4, 5}});
  EXPECT_EQ(Quality::Compute(m).selfIntersectingPairs, 0u);
  // Near miss: the second triangle's plane crosses the first one's, but beyond its edge.
  MeshD nearMiss;
  MakeMesh(nearMiss, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.6, 0.6, -1}, {0.6, 0.6, 1}, {2, 2, 0}},
           {{0, 1, 2}, {3, 4, 5}});
  EXPECT_EQ(Quality::Compute(nearMiss).selfIntersectingPairs, 0u);
}

TEST(MeshQuality, CoplanarTriangles) {
  MeshD overlap;
  MakeMesh(overlap, {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0.5, 0.5, 0}, {3, 0.5, 0}, {0.5, 3, 0}},
           {{0, 1, 2}, {3, 4, 5}});
  EXPECT_EQ(Quality::Compute(overlap).selfIntersectingPairs, 1u);
  MeshD contained;
  MakeMesh(contained, {{0, 0, 0}, {4, 0, 0}, {0, 4, 0}, {0.5, 0.5, 0}, {1, 0.5, 0}, {0.5, 1, 0}},
           {{0, 1, 2}, {3, 4, 5}});
  EXPECT_EQ(Quality::Compute(contained).selfIntersectingPairs, 1u);
  MeshD apart;
  MakeMesh(apart, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {2, 1, 0}, {1, 2, 0}}, {{0, 1, 2}, {3, 4, 5}});
  EXPECT_EQ(Quality::Compute(apart).selfIntersectingPairs, 0u);
}

TEST(MeshQuality, TouchingAtDuplicatedVertexCountsAsIntersecting) {
  // Closed-set semantics: two faces whose distinct vertices 2 and 3 have the same position touch.
  MeshD m;
  MakeMesh(m, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 1, 0}, {1, 2, 0.5}, {-1, 2, 0.5}},
           {{0, 1, 2}, {3, 4, 5}});
  EXPECT_EQ(Quality::Compute(m).selfIntersectingPairs, 1u);
}

TEST(MeshQuality, SharedVertexOverlap) {
  // Both faces share vertex 0; the second one pierces the first away from it.
  MeshD crossing;
  MakeMesh(crossing, {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {1, 0.3, -1}, {0.3, 1, 1}}, {{0, 1, 2}, {0, 3, 4}});
  const auto r = Quality::Compute(crossing);
  EXPECT_EQ(r.adjacentOverlapPairs, 1u);
  EXPECT_EQ(r.selfIntersectingPairs, 0u);
  EXPECT_EQ(r.selfIntersectingFaces, 2u);
  // Coplanar folded fan: the second face lies inside the first one's corner.
  MeshD folded;
  MakeMesh(folded, {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {1, 0.2, 0}, {0.2, 1, 0}}, {{0, 1, 2}, {0, 3, 4}});
  EXPECT_EQ(Quality::Compute(folded).adjacentOverlapPairs, 1u);
  // A proper fan sector next to it: only the shared vertex in common.
  MeshD fan;
  MakeMesh(fan, {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {-2, 0, 0}, {0, -2, 0}}, {{0, 1, 2}, {0, 3, 4}});
  EXPECT_EQ(Quality::Compute(fan).adjacentOverlapPairs, 0u);
}

TEST(MeshQuality, DentedSphereSelfIntersects) {
  // Pushing one vertex through the opposite side makes its fan cross the far faces.
  MeshD m;
  MakeIcosphere(m, 3);
  m.vert[0].P() = -m.vert[0].P() * 1.3;
  const auto r = Quality::Compute(m);
  EXPECT_GT(r.selfIntersectingPairs, 0u);
  EXPECT_EQ(r.boundaryEdges, 0u);
}

TEST(MeshQuality, OverlappingSpheresIntersect) {
  MeshD m;
  MakeIcosphere(m, 3);
  MeshD other;
  MakeIcosphere(other, 3);
  for (auto& v : other.vert) v.P() += Point(1, 0, 0);
  vcg::tri::Append<MeshD, MeshD>::Mesh(m, other);
  const auto r = Quality::Compute(m);
  EXPECT_EQ(r.components, 2u);
  // Both unit spheres cross on a circle of radius sqrt(3)/2: about 2 pi 0.87 / 0.1 edge crossings.
  EXPECT_GT(r.selfIntersectingPairs, 50u);
  EXPECT_GT(r.selfIntersectingFaces, 50u);
}

TEST(MeshQuality, FarOutlierVertexKeepsTheGridUseful) {
  // One vertex sent 1e12 away: its six faces become huge slivers reaching back to the sphere. They
  // must neither make every other face "degenerate" (a mean-edge threshold would) nor coarsen the
  // grid until the whole sphere falls in one cell (quadratic): they are tested on their own.
  MeshD m;
  MakeIcosphere(m, 6); // 81920 faces
  const Point away = m.vert[0].P() * 1e12;
  m.vert[0].P() = away;
  const auto r = Quality::Compute(m);
  EXPECT_EQ(r.faces, 81920u);
  EXPECT_EQ(r.degenerateFaces, 0u); // the median edge length is not fooled by the outlier
  EXPECT_GT(r.meanEdgeLength, 1e6);
  EXPECT_LT(r.medianEdgeLength, 0.1);
  EXPECT_EQ(r.boundaryEdges, 0u);
  EXPECT_EQ(r.genus, 0);
  EXPECT_EQ(r.selfIntersectingPairs, 0u);
  EXPECT_EQ(r.adjacentOverlapPairs, 0u);
}

/// Counts by brute force with the same predicates, to check the grid neither misses nor repeats.
std::array<std::size_t, 2> BruteForceIntersections(const MeshD& m) {
  std::array<std::size_t, 2> counts{0, 0};
  for (std::size_t i = 0; i < m.face.size(); ++i)
    for (std::size_t j = i + 1; j < m.face.size(); ++j) {
      const auto& a = m.face[i];
      const auto& b = m.face[j];
      int shared = 0, ca = -1, cb = -1;
      for (int u = 0; u < 3; ++u)
        for (int w = 0; w < 3; ++w)
          if (a.cV(u) == b.cV(w)) ++shared, ca = u, cb = w;
      const auto ta = molremesh::MakePlanarTriangle(a.cP(0), a.cP(1), a.cP(2));
      const auto tb = molremesh::MakePlanarTriangle(b.cP(0), b.cP(1), b.cP(2));
      if (shared == 0 && molremesh::TrianglesIntersect(ta, tb)) ++counts[0];
      if (shared == 1 && molremesh::SharedCornerOverlap(ta, ca, tb, cb)) ++counts[1];
    }
  return counts;
}

TEST(MeshQuality, GridCountsMatchBruteForce) {
  // Random triangle soup with shared vertices and sizes from tiny to large, so faces span many
  // grid cells and many candidate pairs are seen in several cells.
  std::mt19937 rng(1234);
  std::uniform_real_distribution<double> coord(0.0, 10.0);
  std::uniform_int_distribution<int> pick(0, 199);
  std::vector<Point> points;
  for (int i = 0; i < 200; ++i) points.emplace_back(coord(rng), coord(rng), coord(rng) * 0.3);
  std::vector<std::array<int, 3>> faces;
  while (faces.size() < 400) {
    const int a = pick(rng);
    // Mostly local triangles (nearby indices are not nearby points, so pick by distance).
    int b = pick(rng), c = pick(rng);
    if (faces.size() % 3 != 0) {
      int best1 = -1, best2 = -1;
      double d1 = 1e300, d2 = 1e300;
      for (int k = 0; k < 200; ++k) {
        if (k == a) continue;
        const double d = (points[k] - points[a]).Norm() + std::uniform_real_distribution<double>(0, 2)(rng);
        if (d < d1)
          best2 = best1, d2 = d1, best1 = k, d1 = d;
        else if (d < d2)
          best2 = k, d2 = d;
      }
      b = best1;
      c = best2;
    }
    if (a == b || b == c || a == c) continue;
    faces.push_back({a, b, c});
  }
  MeshD m;
  MakeMesh(m, points, faces);
  const auto r = Quality::Compute(m);
  const auto brute = BruteForceIntersections(m);
  EXPECT_GT(brute[0], 0u);
  EXPECT_GT(brute[1], 0u);
  EXPECT_EQ(r.degenerateFaces, 0u);
  EXPECT_EQ(r.selfIntersectingPairs, brute[0]);
  EXPECT_EQ(r.adjacentOverlapPairs, brute[1]);
  // Deterministic.
  const auto again = Quality::Compute(m);
  EXPECT_EQ(again.selfIntersectingPairs, r.selfIntersectingPairs);
  EXPECT_EQ(again.adjacentOverlapPairs, r.adjacentOverlapPairs);
}

TEST(MeshQuality, OversizedFacesMatchBruteForce) {
  // Big tilted triangles slicing a fine sphere span hundreds of grid cells, so they take the
  // "oversized" path (tested against every face); two of them also cross each other.
  MeshD m;
  MakeIcosphere(m, 4);
  MeshD big;
  MakeMesh(big,
           {{-1.5, -1.5, -0.3},
            {1.5, -1.5, 0.3},
            {0, 1.5, 0},
            {-1.5, 0.2, -1.5},
            {1.5, -0.2, -1.5},
            {0, 0.1, 1.5},
            {-1.4, -1.4, 1.0},
            {1.4, 1.4, 1.0},
            {0, 0, -1.2}},
           {{0, 1, 2}, {3, 4, 5}, {6, 7, 8}});
  vcg::tri::Append<MeshD, MeshD>::Mesh(m, big);
  const auto r = Quality::Compute(m);
  const auto brute = BruteForceIntersections(m);
  EXPECT_GT(brute[0], 100u);
  EXPECT_EQ(r.selfIntersectingPairs, brute[0]);
  EXPECT_EQ(r.adjacentOverlapPairs, brute[1]);
}

TEST(MeshQuality, AliasedGridCellsDoNotRepeatPairs) {
  // Cell keys wrap every 2^21 cells per axis. Two self-intersecting copies exactly 2^21 cells
  // apart share their cell keys; each of their pairs must still be counted exactly once.
  MeshD single;
  MakeIcosphere(single, 2);
  single.vert[0].P() = -single.vert[0].P() * 1.3; // dent through the far side
  const auto one = Quality::Compute(single);
  ASSERT_GT(one.selfIntersectingPairs, 0u);
  const double cell = 2 * one.medianEdgeLength; // the grid's cell size (translation-invariant)
  MeshD pair;
  MakeIcosphere(pair, 2);
  pair.vert[0].P() = -pair.vert[0].P() * 1.3;
  MeshD copy;
  MakeIcosphere(copy, 2);
  copy.vert[0].P() = -copy.vert[0].P() * 1.3;
  for (auto& v : copy.vert) v.P() += Point(std::ldexp(cell, 21), 0, 0);
  vcg::tri::Append<MeshD, MeshD>::Mesh(pair, copy);
  const auto two = Quality::Compute(pair);
  EXPECT_EQ(two.selfIntersectingPairs, 2 * one.selfIntersectingPairs);
  EXPECT_EQ(two.adjacentOverlapPairs, 2 * one.adjacentOverlapPairs);
  const auto brute = BruteForceIntersections(pair);
  EXPECT_EQ(two.selfIntersectingPairs, brute[0]);
  EXPECT_EQ(two.adjacentOverlapPairs, brute[1]);
}

TEST(MeshQuality, FindSelfIntersectionsListsEachPairOnceWithItsKind) {
  // 0: a triangle in z = 0; 1: one crossing it (no shared vertex, away from 2); 2: one sharing
  // vertex 0 whose edge to vertex 6 lies inside triangle 0; 3: triangle 0 again (same vertices).
  using molremesh::FindSelfIntersections;
  using molremesh::IntersectingPair;
  const std::vector<Point> points{Point(0, 0, 0),      Point(2, 0, 0),     Point(0, 2, 0),
                                  Point(1.5, 0.1, -1), Point(1.5, 0.1, 1), Point(1.5, 0.3, 1),
                                  Point(1, 0.2, 0),    Point(0.2, 1, 0.5)};
  const std::vector<std::array<molremesh::Index, 3>> tris{{0, 1, 2}, {3, 4, 5}, {0, 6, 7}, {0, 1, 2}};
  auto sorted = [](std::vector<IntersectingPair> pairs) {
    std::vector<std::tuple<std::uint32_t, std::uint32_t, bool>> out;
    for (const auto& p : pairs) out.emplace_back(std::min(p.i, p.j), std::max(p.i, p.j), p.adjacent);
    std::sort(out.begin(), out.end());
    return out;
  };
  for (int threads : {1, 2}) {
    const auto without = sorted(FindSelfIntersections(tris, points, 1.0, threads));
    const auto with = sorted(FindSelfIntersections(tris, points, 1.0, threads, true));
    using T = std::tuple<std::uint32_t, std::uint32_t, bool>;
    // Triangle 1 crosses 0 and its copy 3; 2 overlaps 0 and 3 beyond their shared corner.
    const std::vector<T> expected{T{0, 1, false}, T{0, 2, true}, T{1, 3, false}, T{2, 3, true}};
    EXPECT_EQ(without, expected);
    std::vector<T> withDuplicates = expected;
    withDuplicates.push_back(T{0, 3, true});
    std::sort(withDuplicates.begin(), withDuplicates.end());
    EXPECT_EQ(with, withDuplicates);
  }
}

// ----------------------------------------------------------------------------------------------
// Broken inputs
// ----------------------------------------------------------------------------------------------

TEST(MeshQuality, DegenerateFaces) {
  MeshD m;
  MakeMesh(m, {{0, 0, 0}, {1, 0, 0}, {0.5, std::sqrt(3.0) / 2, 0}, {2, 0, 0}, {3, 0, 0}, {4, 0, 0}},
           {{0, 1, 2}, {0, 0, 1}, {3, 4, 5}});
  const auto r = Quality::Compute(m);
  EXPECT_EQ(r.faces, 3u);
  EXPECT_EQ(r.degenerateFaces, 2u);
  EXPECT_DOUBLE_EQ(r.qMin, 0.0);
  EXPECT_NEAR(r.qAvg, 1.0 / 3.0, 1e-12);
  EXPECT_DOUBLE_EQ(r.angleMin, 0.0);
  EXPECT_DOUBLE_EQ(r.angleMax, 180.0);
  EXPECT_NEAR(r.meanMinAngle, 20.0, 1e-9);
  EXPECT_EQ(r.aspectRatioMax, kInf);
  EXPECT_EQ(r.aspectRatioMean, kInf);
  EXPECT_NEAR(r.aspectRatioMeanNonDegenerate, 1.0, 1e-12);
  EXPECT_EQ(r.smallAngleFaces, 2u);
  EXPECT_EQ(r.obtuseFaces, 2u);
  EXPECT_EQ(r.largeAngleFaces, 2u);
  // The repeated-index face takes no part in topology; the collinear one does.
  EXPECT_EQ(r.edges, 6u);
  EXPECT_EQ(r.components, 2u);
  EXPECT_EQ(r.selfIntersectingPairs, 0u);

  const auto repeated = Quality::FaceAngles(m.face[1]);
  EXPECT_DOUBLE_EQ(repeated.min(), 0.0);
  EXPECT_DOUBLE_EQ(repeated.max(), 180.0);
  const auto collinear = Quality::FaceAngles(m.face[2]);
  EXPECT_DOUBLE_EQ(collinear.max(), 180.0);
}

TEST(MeshQuality, AllFacesDegenerate) {
  MeshD m;
  MakeMesh(m, {{0, 0, 0}, {1, 0, 0}}, {{0, 0, 1}, {1, 1, 1}});
  const auto r = Quality::Compute(m);
  EXPECT_EQ(r.degenerateFaces, 2u);
  EXPECT_EQ(r.edges, 0u);
  EXPECT_EQ(r.components, 0u);
  EXPECT_EQ(r.referencedVertices, 2u);
  EXPECT_DOUBLE_EQ(r.aspectRatioMeanNonDegenerate, 0.0);
}

TEST(MeshQuality, EmptyMesh) {
  const MeshD m;
  const auto r = Quality::Compute(m);
  EXPECT_EQ(r.vertices, 0u);
  EXPECT_EQ(r.faces, 0u);
  EXPECT_EQ(r.edges, 0u);
  EXPECT_EQ(r.components, 0u);
  EXPECT_EQ(r.boundaryEdges, 0u);
  EXPECT_EQ(r.degenerateFaces, 0u);
  EXPECT_EQ(r.selfIntersectingPairs, 0u);
  EXPECT_DOUBLE_EQ(r.qMin, 0.0);
  EXPECT_DOUBLE_EQ(r.qAvg, 0.0);
  EXPECT_DOUBLE_EQ(r.angleMin, 0.0);
  EXPECT_DOUBLE_EQ(r.angleMax, 0.0);
  EXPECT_DOUBLE_EQ(r.aspectRatioMax, 0.0);
  EXPECT_DOUBLE_EQ(r.area, 0.0);
  EXPECT_DOUBLE_EQ(r.volume, 0.0);
  EXPECT_EQ(r.euler, 0);
  EXPECT_EQ(r.genus, 0);
  EXPECT_TRUE(Quality::VertexValences(m).empty());
  EXPECT_TRUE(Quality::VertexOnBorder(m).empty());
}

TEST(MeshQuality, PointCloud) {
  MeshD m;
  MakeMesh(m, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {kNaN, 0, 0}}, {});
  const auto r = Quality::Compute(m);
  EXPECT_EQ(r.vertices, 4u);
  EXPECT_EQ(r.referencedVertices, 0u);
  EXPECT_EQ(r.unreferencedVertices, 4u);
  EXPECT_EQ(r.nonFiniteVertices, 1u);
  EXPECT_EQ(r.faces, 0u);
  EXPECT_EQ(r.edges, 0u);
  EXPECT_EQ(r.components, 0u);
  EXPECT_EQ(r.interiorVertices, 0u);
  EXPECT_DOUBLE_EQ(r.area, 0.0);
  EXPECT_DOUBLE_EQ(r.volume, 0.0);
  EXPECT_EQ(r.euler, 0);
  EXPECT_EQ(Quality::VertexValences(m), std::vector<int>(4, 0));
}

TEST(MeshQuality, NonFiniteVertex) {
  std::vector<Point> points;
  std::vector<std::array<int, 3>> faces;
  AddTetrahedron(points, faces, Point(0, 0, 0));
  points[3] = Point(kNaN, 0, 0);
  MeshD m;
  MakeMesh(m, points, faces);
  const auto r = Quality::Compute(m);
  EXPECT_EQ(r.nonFiniteVertices, 1u);
  EXPECT_EQ(r.degenerateFaces, 3u); // the three faces on vertex 3
  EXPECT_TRUE(std::isfinite(r.area));
  EXPECT_NEAR(r.area, 0.5, 1e-12); // only the face without vertex 3
  EXPECT_TRUE(std::isfinite(r.volume));
  EXPECT_TRUE(std::isfinite(r.meanEdgeLength));
  EXPECT_DOUBLE_EQ(r.qMin, 0.0);
  EXPECT_DOUBLE_EQ(r.angleMin, 0.0);
  EXPECT_EQ(r.selfIntersectingPairs, 0u);
  // Topology does not depend on coordinates.
  EXPECT_EQ(r.euler, 2);
  EXPECT_EQ(r.genus, 0);
  EXPECT_EQ(r.boundaryEdges, 0u);

  const auto angles = Quality::FaceAngles(m.face[1]);
  EXPECT_DOUBLE_EQ(angles.max(), 180.0);

  // Infinite coordinates too.
  MeshD inf;
  MakeMesh(inf, points, faces);
  inf.vert[3].P() = Point(0, kInf, 0);
  const auto ri = Quality::Compute(inf);
  EXPECT_EQ(ri.nonFiniteVertices, 1u);
  EXPECT_EQ(ri.degenerateFaces, 3u);
}

// ----------------------------------------------------------------------------------------------
// Float meshes (MeshLab's CMeshO)
// ----------------------------------------------------------------------------------------------

TEST(MeshQuality, FloatMeshGivesTheSameFigures) {
  MeshD md;
  MakeIcosphere(md, 3);
  MeshF mf;
  vcg::tri::Append<MeshF, MeshD>::MeshCopy(mf, md);
  // Same coordinates in both meshes: round the double ones to float.
  for (std::size_t i = 0; i < md.vert.size(); ++i) md.vert[i].P().Import(mf.vert[i].P());
  const auto rd = Quality::Compute(md);
  const auto rf = molremesh::MeshQuality<MeshF>::Compute(mf);
  EXPECT_EQ(rf.faces, rd.faces);
  EXPECT_EQ(rf.edges, rd.edges);
  EXPECT_EQ(rf.genus, rd.genus);
  EXPECT_EQ(rf.valenceHistogram, rd.valenceHistogram);
  EXPECT_DOUBLE_EQ(rf.qMin, rd.qMin);
  EXPECT_DOUBLE_EQ(rf.angleMin, rd.angleMin);
  EXPECT_DOUBLE_EQ(rf.area, rd.area);
  EXPECT_DOUBLE_EQ(rf.volume, rd.volume);
  EXPECT_EQ(rf.selfIntersectingPairs, rd.selfIntersectingPairs);
  const auto angles = molremesh::MeshQuality<MeshF>::FaceAngles(mf.face[0]);
  EXPECT_DOUBLE_EQ(angles.min(), Quality::FaceAngles(md.face[0]).min());
}

// ----------------------------------------------------------------------------------------------
// A real molecular surface
// ----------------------------------------------------------------------------------------------

TEST(MeshQuality, RealMoleculeBptiMsms) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  const char* path = MOLREMESH_SHARED_DATA_DIR "/meshes/bpti_1bpi_msms.ply";
  if (!std::ifstream(path).good()) GTEST_SKIP() << "missing " << path;
  MeshD m;
  ASSERT_EQ(vcg::tri::io::ImporterPLY<MeshD>::Open(m, path), 0) << path;
  const auto r = Quality::Compute(m);
  EXPECT_EQ(r.faces, std::size_t(m.fn));
  EXPECT_EQ(r.boundaryEdges, 0u);
  EXPECT_EQ(r.nonManifoldEdges, 0u);
  EXPECT_EQ(r.nonManifoldVertices, 0u);
  EXPECT_GE(r.components, 1u);
  EXPECT_GE(r.genus, 0);
  EXPECT_EQ(r.selfIntersectingPairs, 0u);
  EXPECT_GT(r.area, 0.0);
  EXPECT_GT(r.volume, 0.0); // outward orientation
  EXPECT_EQ(SumHistogram(r), int(r.interiorVertices));
  for (const auto& c : r.componentInfo) EXPECT_TRUE(c.closed);
}

// ----------------------------------------------------------------------------------------------
// Thread count: the figures are bit-identical whatever the number of worker threads
// ----------------------------------------------------------------------------------------------

/// Bit pattern of a double: equal figures must be equal to the last bit (and in the sign of zero).
std::uint64_t Bits(double value) {
  std::uint64_t bits;
  std::memcpy(&bits, &value, sizeof bits);
  return bits;
}

void ExpectSameReport(const molremesh::QualityReport& a, const molremesh::QualityReport& b) {
  EXPECT_EQ(a.vertices, b.vertices);
  EXPECT_EQ(a.referencedVertices, b.referencedVertices);
  EXPECT_EQ(a.unreferencedVertices, b.unreferencedVertices);
  EXPECT_EQ(a.nonFiniteVertices, b.nonFiniteVertices);
  EXPECT_EQ(a.faces, b.faces);
  EXPECT_EQ(a.edges, b.edges);
  for (const auto& [name, x, y] : std::vector<std::tuple<const char*, double, double>>{
           {"qMin", a.qMin, b.qMin},
           {"qAvg", a.qAvg, b.qAvg},
           {"angleMin", a.angleMin, b.angleMin},
           {"meanMinAngle", a.meanMinAngle, b.meanMinAngle},
           {"angleMax", a.angleMax, b.angleMax},
           {"aspectRatioMax", a.aspectRatioMax, b.aspectRatioMax},
           {"aspectRatioMean", a.aspectRatioMean, b.aspectRatioMean},
           {"aspectRatioMeanNonDegenerate", a.aspectRatioMeanNonDegenerate, b.aspectRatioMeanNonDegenerate},
           {"smallAnglePercent", a.smallAnglePercent, b.smallAnglePercent},
           {"obtusePercent", a.obtusePercent, b.obtusePercent},
           {"largeAnglePercent", a.largeAnglePercent, b.largeAnglePercent},
           {"v567Percent", a.v567Percent, b.v567Percent},
           {"area", a.area, b.area},
           {"volume", a.volume, b.volume},
           {"meanEdgeLength", a.meanEdgeLength, b.meanEdgeLength},
           {"medianEdgeLength", a.medianEdgeLength, b.medianEdgeLength}})
    EXPECT_EQ(Bits(x), Bits(y)) << name << ": " << x << " vs " << y;
  EXPECT_EQ(a.smallAngleFaces, b.smallAngleFaces);
  EXPECT_EQ(a.obtuseFaces, b.obtuseFaces);
  EXPECT_EQ(a.largeAngleFaces, b.largeAngleFaces);
  EXPECT_EQ(a.interiorVertices, b.interiorVertices);
  EXPECT_EQ(a.regularVertices, b.regularVertices);
  EXPECT_EQ(a.valenceHistogram, b.valenceHistogram);
  EXPECT_EQ(a.euler, b.euler);
  EXPECT_EQ(a.genus, b.genus);
  EXPECT_EQ(a.components, b.components);
  ASSERT_EQ(a.componentInfo.size(), b.componentInfo.size());
  for (std::size_t c = 0; c < a.componentInfo.size(); ++c) {
    const molremesh::ComponentInfo &x = a.componentInfo[c], &y = b.componentInfo[c];
    EXPECT_EQ(x.faces, y.faces) << "component " << c;
    EXPECT_EQ(x.boundaryEdges, y.boundaryEdges) << "component " << c;
    EXPECT_EQ(x.manifold, y.manifold) << "component " << c;
    EXPECT_EQ(x.closed, y.closed) << "component " << c;
    EXPECT_EQ(x.euler, y.euler) << "component " << c;
    EXPECT_EQ(x.genus, y.genus) << "component " << c;
    EXPECT_EQ(x.boundaryLoops, y.boundaryLoops) << "component " << c;
  }
  EXPECT_EQ(a.boundaryEdges, b.boundaryEdges);
  EXPECT_EQ(a.boundaryLoops, b.boundaryLoops);
  EXPECT_EQ(a.nonManifoldEdges, b.nonManifoldEdges);
  EXPECT_EQ(a.nonManifoldVertices, b.nonManifoldVertices);
  EXPECT_EQ(a.degenerateFaces, b.degenerateFaces);
  EXPECT_EQ(a.selfIntersectingPairs, b.selfIntersectingPairs);
  EXPECT_EQ(a.adjacentOverlapPairs, b.adjacentOverlapPairs);
  EXPECT_EQ(a.selfIntersectingFaces, b.selfIntersectingFaces);
  EXPECT_EQ(a.selfIntersectionsComputed, b.selfIntersectionsComputed);
}

/// Compute with 2 and 3 threads gives exactly the figures of 1 thread, with and without the
/// self-intersections.
void ExpectSameForAnyThreadCount(const MeshD& m) {
  for (const bool intersections : {true, false}) {
    Quality::Params params;
    params.computeSelfIntersections = intersections;
    params.threads = 1;
    const auto serial = Quality::Compute(m, params);
    for (const int threads : {2, 3}) {
      SCOPED_TRACE(testing::Message() << threads << " threads, self-intersections " << intersections);
      params.threads = threads;
      ExpectSameReport(Quality::Compute(m, params), serial);
    }
  }
}

TEST(MeshQuality, SameFiguresForAnyThreadCountOnARealMolecule) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  // The raw PyMOL surface of 1MAH: 56k faces with non-manifold edges, self-intersecting and
  // overlapping pairs and several components, so every part of the report has something to count.
  const char* path = MOLREMESH_SHARED_DATA_DIR "/meshes/ache_1MAH_pymol_ses.ply";
  if (!std::ifstream(path).good()) GTEST_SKIP() << "missing " << path;
  MeshD m;
  ASSERT_EQ(vcg::tri::io::ImporterPLY<MeshD>::Open(m, path), 0) << path;
  const auto r = Quality::Compute(m);
  EXPECT_GT(r.nonManifoldEdges, 0u);
  EXPECT_GT(r.selfIntersectingPairs + r.adjacentOverlapPairs, 0u);
  ExpectSameForAnyThreadCount(m);
}

TEST(MeshQuality, SameFiguresForAnyThreadCountWithOversizedAndNonFiniteFaces) {
  // A vertex sent far away (its faces take the "oversized" path of the grid), one made NaN
  // (degenerate faces) and a dent through the far side (self-intersections).
  MeshD m;
  MakeIcosphere(m, 5); // 20480 faces
  m.vert[0].P() = m.vert[0].P() * 1e12;
  m.vert[1].P() = Point(kNaN, 0, 0);
  m.vert[2].P() = -m.vert[2].P() * 1.3;
  const auto r = Quality::Compute(m);
  EXPECT_GT(r.degenerateFaces, 0u);
  EXPECT_GT(r.selfIntersectingPairs, 0u);
  ExpectSameForAnyThreadCount(m);
}

} // namespace

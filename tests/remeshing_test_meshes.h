// Constructed meshes and validity checks shared by the tests: the float mesh type MeshF and the
// mesh builders (test_mesh_quality, test_clean_raw_mesh and the remeshing-core tests), the
// invariants every remeshing stage keeps (the stage tests, see local_stage_test_helpers.h).
#pragma once

#include <gtest/gtest.h>

#include <vcg_ext/quality/mesh_quality.h>
#include <vcg_ext/surface/surface_distance.h>
#include <vcg_ext/core/mesh_types.h>

#include <vcg/complex/algorithms/clean.h>
#include <vcg/complex/algorithms/create/platonic.h>
#include <vcg/complex/append.h>

#include <array>
#include <cmath>
#include <algorithm>
#include <vector>

namespace molremesh::test {

using Point = vcg::Point3d;

// A float mesh shaped like MeshLab's CMeshO (float coordinates, FF/VF adjacency), to check that
// the templates work on it.
class VertexF;
class FaceF;
struct UsedTypesF : public vcg::UsedTypes<vcg::Use<VertexF>::AsVertexType, vcg::Use<FaceF>::AsFaceType> {};
class VertexF : public vcg::Vertex<UsedTypesF, vcg::vertex::Coord3f, vcg::vertex::Normal3f,
                                   vcg::vertex::BitFlags, vcg::vertex::VFAdj, vcg::vertex::Mark> {};
class FaceF : public vcg::Face<UsedTypesF, vcg::face::VertexRef, vcg::face::Normal3f, vcg::face::BitFlags,
                               vcg::face::FFAdj, vcg::face::VFAdj, vcg::face::Mark> {};
class MeshF : public vcg::tri::TriMesh<std::vector<VertexF>, std::vector<FaceF>> {};

/// Mesh from explicit points and index triples.
template <class Mesh>
void MakeMesh(Mesh& m, const std::vector<Point>& points, const std::vector<std::array<int, 3>>& faces) {
  m.Clear();
  if (!points.empty()) vcg::tri::Allocator<Mesh>::AddVertices(m, points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    m.vert[i].P() = typename Mesh::CoordType(points[i][0], points[i][1], points[i][2]);
  for (const auto& f : faces)
    vcg::tri::Allocator<Mesh>::AddFace(m, &m.vert[f[0]], &m.vert[f[1]], &m.vert[f[2]]);
}

/// Subdivided icosahedron (outward oriented), scaled per axis by radii and moved to center.
template <class Mesh>
void Icosphere(Mesh& m, int subdivisions, const Point& center = Point(0, 0, 0),
               const Point& radii = Point(1, 1, 1)) {
  m.Clear();
  vcg::tri::Sphere(m, subdivisions);
  vcg::tri::Allocator<Mesh>::CompactEveryVector(m);
  for (auto& v : m.vert)
    v.P() = typename Mesh::CoordType(center[0] + radii[0] * v.P()[0], center[1] + radii[1] * v.P()[1],
                                     center[2] + radii[2] * v.P()[2]);
}

/// Torus around the z axis: tube radius r at distance R from the axis.
template <class Mesh>
void Torus(Mesh& m, double R, double r, int ringDivisions, int tubeDivisions) {
  vcg::tri::Torus(m, float(R), float(r), ringDivisions, tubeDivisions);
}

/// n x n grid of size x size in the z = height plane, quads split along alternating diagonals.
template <class Mesh>
void Grid(Mesh& m, int n, double size, double height = 0.0) {
  std::vector<Point> points;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) points.emplace_back(size * i / n, size * j / n, height);
  std::vector<std::array<int, 3>> faces;
  auto id = [n](int i, int j) { return j * (n + 1) + i; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      if ((i + j) % 2 == 0) {
        faces.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
        faces.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
      } else {
        faces.push_back({id(i, j), id(i + 1, j), id(i, j + 1)});
        faces.push_back({id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
      }
    }
  MakeMesh(m, points, faces);
}

/// Appends src to dst (separate components).
template <class Mesh>
void AppendMesh(Mesh& dst, Mesh& src) {
  vcg::tri::Append<Mesh, Mesh>::Mesh(dst, src);
}

inline double MeanEdge(const MeshD& m) {
  typename MeshQuality<MeshD>::Params p;
  p.computeSelfIntersections = false;
  return MeshQuality<MeshD>::Compute(m, p).meanEdgeLength;
}

// Invariants every remeshing stage keeps (DESIGN-NOTES.md), as gtest expectations shared by the
// stage tests: before/after are the quality reports of the stage's input and output.
inline void ExpectTwoManifoldWithoutDegenerateFaces(const QualityReport& after) {
  EXPECT_TRUE(after.isTwoManifold());
  EXPECT_EQ(after.degenerateFaces, 0u);
}

inline void ExpectNoSelfIntersection(const QualityReport& after) {
  EXPECT_EQ(after.selfIntersectingPairs, 0u);
  EXPECT_EQ(after.adjacentOverlapPairs, 0u);
}

inline void ExpectComponentsClosedWithTheirGenus(const QualityReport& before, const QualityReport& after) {
  ASSERT_EQ(after.componentInfo.size(), before.componentInfo.size());
  for (std::size_t c = 0; c < before.componentInfo.size(); ++c) {
    EXPECT_EQ(after.componentInfo[c].closed, before.componentInfo[c].closed);
    EXPECT_EQ(after.componentInfo[c].genus, before.componentInfo[c].genus);
  }
}

/// Every vertex of output within maxDistance of the input surface.
inline void ExpectVerticesOnInput(const MeshD& output, const MeshD& input, double maxDistance) {
  const std::vector<double> d = SurfaceDistance<MeshD, MeshD>::VertexDistances(output, input, 2);
  double worst = 0;
  for (const double x : d)
    if (!std::isnan(x)) worst = std::max(worst, x);
  EXPECT_LT(worst, maxDistance);
}

} // namespace molremesh::test

// TinyComponentRegularization: closed components too small to be regular become icosahedra with
// every vertex of valence 5 and every angle in bounds, each keeping its side (body or cavity); the
// rest of the mesh, and the specks it cannot remake well, are left as they were.
#include <gtest/gtest.h>

#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/quality/mesh_quality.h>
#include <vcg_ext/stages/tiny_components.h>
#include <vcg_ext/volume/closed_components.h>

#include <vcg/complex/algorithms/create/platonic.h>
#include <vcg/complex/append.h>

#include <algorithm>
#include <vector>

#include "remeshing_test_meshes.h"

namespace {

using molremesh::MeshD;
using molremesh::QualityReport;
using Point = vcg::Point3d;
using Tiny = molremesh::TinyComponentRegularization<MeshD>;

/// The six-vertex octahedron of the given radii around c; `inward` turns it into a cavity.
void AppendOctahedron(MeshD& m, const Point& c, const Point& radii, bool inward) {
  MeshD o;
  vcg::tri::Octahedron(o);
  for (auto& v : o.vert) v.P() = c + Point(v.P()[0] * radii[0], v.P()[1] * radii[1], v.P()[2] * radii[2]);
  if (inward)
    for (auto& f : o.face) std::swap(f.V(1), f.V(2));
  vcg::tri::Append<MeshD, MeshD>::Mesh(m, o);
}

void AppendTetrahedron(MeshD& m, const Point& c, double size) {
  MeshD t;
  vcg::tri::Tetrahedron(t);
  for (auto& v : t.vert) v.P() = c + v.P() * size;
  vcg::tri::Append<MeshD, MeshD>::Mesh(m, t);
}

QualityReport Measure(MeshD& m) {
  vcg::tri::Allocator<MeshD>::CompactEveryVector(m);
  return molremesh::MeshQuality<MeshD>::Compute(m);
}

std::vector<double> SortedVolumes(const MeshD& m) {
  std::vector<double> v = molremesh::MeasureClosedComponents(m).volumes;
  std::sort(v.begin(), v.end());
  return v;
}

TEST(TinyComponents, SpecksAndTinyCavitiesBecomeRegularIcosahedraOnTheirOwnSide) {
  MeshD m;
  molremesh::test::Icosphere(m, 3, Point(0, 0, 0), Point(10, 10, 10));
  const std::size_t sphereVertices = std::size_t(m.vn);
  AppendOctahedron(m, Point(20, 0, 0), Point(1, 1.2, 0.9), false); // a speck outside
  AppendTetrahedron(m, Point(0, 20, 0), 0.5);                      // another
  AppendOctahedron(m, Point(0, 0, 3), Point(1, 0.9, 1.1), true);   // a cavity inside the sphere
  const std::vector<double> before = SortedVolumes(m);
  ASSERT_EQ(before.size(), 4u);

  const molremesh::TinyComponentResult r = Tiny::Do(m, Tiny::Params());
  EXPECT_EQ(r.tiny, 3u);
  EXPECT_EQ(r.remade, 3u);
  const QualityReport q = Measure(m);
  EXPECT_EQ(q.vertices, sphereVertices + 3 * 12);
  EXPECT_EQ(q.boundaryEdges, 0u);
  EXPECT_EQ(q.nonManifoldEdges, 0u);
  EXPECT_EQ(q.selfIntersectingPairs, 0u);
  EXPECT_EQ(q.components, 4u);
  EXPECT_GE(q.angleMin, 30.0);
  EXPECT_LE(q.angleMax, 90.0);
  EXPECT_EQ(q.regularVertices, q.vertices); // the sphere's 5s and 6s, the icosahedra's 5s
  const std::vector<double> after = SortedVolumes(m);
  ASSERT_EQ(after.size(), before.size());
  for (std::size_t i = 0; i < after.size(); ++i) // each keeps its side and its volume
    EXPECT_NEAR(after[i] / before[i], 1.0, 1e-9) << i;
}

TEST(TinyComponents, ARegularComponentAndASpeckTooFlatForAnIcosahedronAreLeftAsTheyWere) {
  MeshD m;
  vcg::tri::Icosahedron(m);                                        // 12 vertices, all regular
  AppendOctahedron(m, Point(10, 0, 0), Point(4, 0.3, 0.3), false); // a needle: no fit within bounds
  vcg::tri::Allocator<MeshD>::CompactEveryVector(m);
  std::vector<Point> before;
  for (const auto& v : m.vert) before.push_back(v.P());

  const molremesh::TinyComponentResult r = Tiny::Do(m, Tiny::Params());
  EXPECT_EQ(r.tiny, 1u); // the needle; the icosahedron has nothing to fix
  EXPECT_EQ(r.remade, 0u);
  ASSERT_EQ(m.vert.size(), before.size());
  for (std::size_t i = 0; i < before.size(); ++i) EXPECT_EQ(m.vert[i].P(), before[i]) << i;
  EXPECT_EQ(m.fn, 20 + 8);
}

TEST(TinyComponents, AnOpenComponentIsNotTouched) {
  MeshD m;
  vcg::tri::Octahedron(m);
  vcg::tri::Allocator<MeshD>::DeleteFace(m, m.face[0]); // open: F != 2V - 4
  const molremesh::TinyComponentResult r = Tiny::Do(m, Tiny::Params());
  EXPECT_EQ(r.tiny, 0u);
  EXPECT_EQ(m.fn, 7);
}

TEST(TinyComponents, ASpeckWithAFlippedFaceIsNotTouched) {
  MeshD m;
  vcg::tri::Octahedron(m);
  std::swap(m.face[0].V(1), m.face[0].V(2)); // closed, F = 2V - 4, but not consistently oriented
  const std::vector<Point> before = {m.vert[0].P(), m.vert[5].P()};
  const molremesh::TinyComponentResult r = Tiny::Do(m, Tiny::Params());
  EXPECT_EQ(r.tiny, 1u);
  EXPECT_EQ(r.remade, 0u);
  EXPECT_EQ(m.vn, 6);
  EXPECT_EQ(m.vert[0].P(), before[0]);
  EXPECT_EQ(m.vert[5].P(), before[1]);
}

} // namespace

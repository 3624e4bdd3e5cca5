// BadElementColoring on constructed meshes with known bad elements.
#include <gtest/gtest.h>

#include <vcg/complex/algorithms/create/platonic.h>

#include <vcg_ext/quality/bad_element_coloring.h>
#include <vcg_ext/core/mesh_types.h>

using molremesh::MeshD;
using Coloring = molremesh::BadElementColoring<MeshD>;

namespace {
/// A regular triangulated grid (valence 6 inside) of n x n quads, each split along the same diagonal.
void MakeGrid(MeshD& m, int n) {
  m.Clear();
  vcg::tri::Allocator<MeshD>::AddVertices(m, (n + 1) * (n + 1));
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) m.vert[j * (n + 1) + i].P() = vcg::Point3d(i, j, 0);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      vcg::tri::Allocator<MeshD>::AddFace(m, a, b, d);
      vcg::tri::Allocator<MeshD>::AddFace(m, a, d, c);
    }
}
} // namespace

TEST(BadElementColoring, RightTrianglesOfAGridAreObtuseAndRegularInsideVerticesAreNot) {
  MeshD m;
  MakeGrid(m, 4);
  const molremesh::BadElementCounts counts = Coloring::Do(m);
  // Every grid triangle is right-angled (90 deg counts as obtuse) with 45 deg angles (not small).
  EXPECT_EQ(counts.obtuseFaces, std::size_t(m.fn));
  EXPECT_EQ(counts.smallAngleFaces, 0u);
  EXPECT_EQ(counts.irregularVertices, 0u);
  for (const auto& f : m.face) {
    EXPECT_EQ(f.cC(), Coloring::ObtuseFaceColor());
    EXPECT_NEAR(f.cQ(), 45.0, 1e-9);
  }
  // The center vertex (2,2) has valence 6.
  EXPECT_EQ(m.vert[2 * 5 + 2].cQ(), 6.0);
  EXPECT_EQ(m.vert[2 * 5 + 2].cC(), Coloring::NeutralColor());
}

TEST(BadElementColoring, IcosahedronIsAllRegularAndNeutral) {
  MeshD m;
  vcg::tri::Icosahedron(m);
  const molremesh::BadElementCounts counts = Coloring::Do(m);
  EXPECT_EQ(counts.irregularVertices, 0u);
  EXPECT_EQ(counts.obtuseFaces, 0u);
  EXPECT_EQ(counts.smallAngleFaces, 0u);
  for (const auto& v : m.vert) EXPECT_EQ(v.cQ(), 5.0);
  for (const auto& f : m.face) EXPECT_EQ(f.cC(), Coloring::NeutralColor());
}

TEST(BadElementColoring, TetrahedronVerticesHaveValenceThreeAndAreRed) {
  MeshD m;
  vcg::tri::Tetrahedron(m);
  const molremesh::BadElementCounts counts = Coloring::Do(m);
  EXPECT_EQ(counts.irregularVertices, 4u);
  for (const auto& v : m.vert) EXPECT_EQ(v.cC(), Coloring::IrregularVertexColor());
}

TEST(BadElementColoring, SliverIsBothObtuseAndSmallSoMagenta) {
  MeshD m;
  vcg::tri::Allocator<MeshD>::AddVertices(m, 3);
  m.vert[0].P() = vcg::Point3d(0, 0, 0);
  m.vert[1].P() = vcg::Point3d(1, 0, 0);
  m.vert[2].P() = vcg::Point3d(0.5, 0.01, 0);
  vcg::tri::Allocator<MeshD>::AddFace(m, 0, 1, 2);
  const molremesh::BadElementCounts counts = Coloring::Do(m);
  EXPECT_EQ(counts.obtuseAndSmallFaces, 1u);
  EXPECT_EQ(counts.obtuseFaces, 1u);
  EXPECT_EQ(counts.smallAngleFaces, 1u);
  EXPECT_EQ(m.face[0].cC(), Coloring::ObtuseAndSmallFaceColor());
  // Border vertices are never called irregular.
  EXPECT_EQ(counts.irregularVertices, 0u);
}

TEST(BadElementColoring, ThresholdsAreParameters) {
  MeshD m;
  MakeGrid(m, 2);
  Coloring::Params params;
  params.obtuseAngle = 91.0; // right angles are no longer obtuse
  params.smallAngle = 50.0;  // 45 deg angles are now small
  const molremesh::BadElementCounts counts = Coloring::Do(m, params);
  EXPECT_EQ(counts.obtuseFaces, 0u);
  EXPECT_EQ(counts.smallAngleFaces, std::size_t(m.fn));
}

TEST(BadElementColoring, ColorBlindSafePaletteTellsLowAndHighValenceApartFromFaceClasses) {
  MeshD m;
  vcg::tri::Tetrahedron(m); // valence 3 everywhere, equilateral faces
  Coloring::Params params;
  params.palette = Coloring::ColorBlindSafePalette();
  const molremesh::BadElementCounts counts = Coloring::Do(m, params);
  EXPECT_EQ(counts.lowValenceVertices, 4u);
  EXPECT_EQ(counts.highValenceVertices, 0u);
  EXPECT_EQ(counts.irregularVertices, 4u);
  for (const auto& v : m.vert) EXPECT_EQ(v.cC(), params.palette.lowValenceVertex);
  for (const auto& f : m.face) EXPECT_EQ(f.cC(), params.palette.neutral);
  const molremesh::BadElementPalette& p = params.palette;
  for (const vcg::Color4b& vertexColor : {p.lowValenceVertex, p.highValenceVertex})
    for (const vcg::Color4b& faceColor : {p.obtuseFace, p.smallAngleFace, p.obtuseAndSmallFace, p.neutral})
      EXPECT_FALSE(vertexColor == faceColor);
  // The default palette keeps the colors of the named accessors.
  EXPECT_EQ(Coloring::DefaultPalette().obtuseFace, Coloring::ObtuseFaceColor());
  EXPECT_EQ(Coloring::DefaultPalette().lowValenceVertex, Coloring::IrregularVertexColor());
}

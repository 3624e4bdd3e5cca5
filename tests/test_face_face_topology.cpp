// UpdateFaceFaceTopology against vcglib's UpdateTopology::FaceFace: the same adjacency on manifold
// meshes (real ones included), borders pointing at themselves, a non-manifold edge as one ring
// through all its faces, deleted faces skipped, whatever the thread count. ElementCapacity: moving
// the element vectors keeps every reference and adjacency.
#include <gtest/gtest.h>

#include <vcg_ext/topology/face_face_topology.h>
#include <vcg_ext/io/mesh_io.h>
#include <vcg_ext/core/element_capacity.h>
#include <vcg_ext/core/mesh_types.h>

#include <array>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "remeshing_test_meshes.h"
#include "test_helpers.h"

namespace {

using molremesh::MeshD;
using Point = vcg::Point3d;
using Side = std::pair<std::size_t, int>; // (face index, side)

/// For every live face side: the side FFp/FFi points at.
std::vector<std::pair<Side, Side>> Links(const MeshD& m) {
  std::vector<std::pair<Side, Side>> links;
  for (std::size_t f = 0; f < m.face.size(); ++f) {
    if (m.face[f].IsD()) continue;
    for (int z = 0; z < 3; ++z)
      links.push_back({{f, z}, {std::size_t(vcg::tri::Index(m, m.face[f].cFFp(z))), m.face[f].cFFi(z)}});
  }
  return links;
}

/// The faces reached by walking the FF ring from side (f, z) until it closes.
std::set<std::size_t> Ring(const MeshD& m, std::size_t f, int z) {
  std::set<std::size_t> faces;
  const auto* face = &m.face[f];
  int side = z;
  for (std::size_t steps = 0; steps <= m.face.size(); ++steps) {
    faces.insert(std::size_t(vcg::tri::Index(m, face)));
    const auto* next = face->cFFp(side);
    const int nextSide = face->cFFi(side);
    face = next;
    side = nextSide;
    if (face == &m.face[f] && side == z) return faces;
  }
  ADD_FAILURE() << "the FF ring from face " << f << " side " << z << " does not close";
  return faces;
}

void ExpectSameAsVcg(MeshD& m) {
  vcg::tri::UpdateTopology<MeshD>::FaceFace(m);
  const auto expected = Links(m);
  for (auto& f : m.face)
    for (int z = 0; z < 3; ++z) f.FFp(z) = nullptr;
  EXPECT_EQ(molremesh::UpdateFaceFaceTopology(m), 0u);
  EXPECT_EQ(Links(m), expected);
}

} // namespace

TEST(FaceFaceTopology, SameAsVcgOnAClosedSphere) {
  MeshD m;
  molremesh::test::Icosphere(m, 3);
  ExpectSameAsVcg(m);
}

TEST(FaceFaceTopology, SameAsVcgOnAMolecularSurface) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  MeshD m;
  std::string error;
  ASSERT_TRUE(molremesh::LoadMesh(m, molremesh::test::SharedMesh("bpti_1bpi_msms.ply"), error)) << error;
  ExpectSameAsVcg(m);
}

TEST(FaceFaceTopology, BorderSidesPointAtThemselves) {
  MeshD m;
  molremesh::test::MakeMesh(m, {Point(0, 0, 0), Point(1, 0, 0), Point(0, 1, 0), Point(1, 1, 0)},
                            {{0, 1, 2}, {1, 3, 2}});
  ExpectSameAsVcg(m);
  EXPECT_EQ(m.face[0].FFp(0), &m.face[0]);
  EXPECT_EQ(m.face[0].FFi(0), 0);
  EXPECT_EQ(m.face[0].FFp(1), &m.face[1]); // side 1-2 is shared
}

TEST(FaceFaceTopology, NonManifoldEdgeIsOneRingThroughAllItsFaces) {
  // Three triangles on edge (0, 1).
  MeshD m;
  molremesh::test::MakeMesh(
      m, {Point(0, 0, 0), Point(1, 0, 0), Point(0.5, 1, 0), Point(0.5, -1, 0), Point(0.5, 0, 1)},
      {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}});
  EXPECT_EQ(molremesh::UpdateFaceFaceTopology(m), 1u); // the count tells CleanRawMesh to use vcglib's rings
  EXPECT_EQ(Ring(m, 0, 0), (std::set<std::size_t>{0, 1, 2}));
  EXPECT_EQ(Ring(m, 1, 0), (std::set<std::size_t>{0, 1, 2}));
}

TEST(FaceFaceTopology, DeletedFacesAreSkipped) {
  MeshD m;
  molremesh::test::MakeMesh(m, {Point(0, 0, 0), Point(1, 0, 0), Point(0, 1, 0), Point(1, 1, 0)},
                            {{0, 1, 2}, {1, 3, 2}});
  vcg::tri::Allocator<MeshD>::DeleteFace(m, m.face[1]);
  molremesh::UpdateFaceFaceTopology(m);
  EXPECT_EQ(m.face[0].FFp(1), &m.face[0]); // its neighbour is gone: now a border side
  EXPECT_EQ(m.face[0].FFi(1), 1);
}

TEST(FaceFaceTopology, AnyThreadCountGivesTheSameAdjacencyOnALargeMesh) {
  // 81920 faces: enough for the passes to be split among threads. Deleting every seventh face
  // leaves border sides and faces the passes must skip.
  MeshD m;
  molremesh::test::Icosphere(m, 6);
  ASSERT_GT(m.face.size(), 65536u);
  for (std::size_t f = 0; f < m.face.size(); f += 7) vcg::tri::Allocator<MeshD>::DeleteFace(m, m.face[f]);
  vcg::tri::UpdateTopology<MeshD>::FaceFace(m);
  const auto expected = Links(m);
  for (const int threads : {1, 2, 3, 4}) {
    for (auto& f : m.face)
      for (int z = 0; z < 3; ++z) f.FFp(z) = nullptr;
    EXPECT_EQ(molremesh::UpdateFaceFaceTopology(m, threads), 0u) << threads << " threads";
    EXPECT_EQ(Links(m), expected) << threads << " threads";
  }
}

namespace {

/// Every vertex's VF list as (face index, corner) pairs, and every face's corners as vertex indices.
std::vector<std::vector<Side>> VertexFaceLists(MeshD& m) {
  std::vector<std::vector<Side>> lists(m.vert.size());
  for (std::size_t v = 0; v < m.vert.size(); ++v)
    for (vcg::face::VFIterator<molremesh::FaceD> it(&m.vert[v]); !it.End(); ++it)
      lists[v].emplace_back(vcg::tri::Index(m, it.F()), it.I());
  return lists;
}

std::vector<std::array<std::size_t, 3>> Corners(const MeshD& m) {
  std::vector<std::array<std::size_t, 3>> corners;
  for (const auto& f : m.face)
    corners.push_back(
        {vcg::tri::Index(m, f.cV(0)), vcg::tri::Index(m, f.cV(1)), vcg::tri::Index(m, f.cV(2))});
  return corners;
}

} // namespace

TEST(ElementCapacity, ReallocatingTheVectorsKeepsEveryReferenceAndAdjacency) {
  using Capacity = molremesh::ElementCapacity<MeshD>;
  MeshD m;
  molremesh::test::Icosphere(m, 3);
  vcg::tri::UpdateTopology<MeshD>::FaceFace(m);
  vcg::tri::UpdateTopology<MeshD>::VertexFace(m);
  const auto links = Links(m);
  const auto lists = VertexFaceLists(m);
  const auto corners = Corners(m);
  const std::size_t faces = m.face.size(), vertices = m.vert.size();

  Capacity::Updater<MeshD::FacePointer> fu;
  MeshD::FacePointer held = &m.face[7];
  Capacity::ReserveFaces(m, 3 * faces, fu);
  ASSERT_TRUE(fu.NeedUpdate()); // the vector moved
  fu.Update(held);
  Capacity::Updater<MeshD::VertexPointer> vu;
  Capacity::ReserveVertices(m, 3 * vertices, vu);
  EXPECT_EQ(m.face.capacity(), 3 * faces); // exactly what was asked, no doubling
  EXPECT_EQ(m.vert.capacity(), 3 * vertices);
  EXPECT_EQ(held, &m.face[7]);
  EXPECT_EQ(Links(m), links);
  EXPECT_EQ(VertexFaceLists(m), lists);
  EXPECT_EQ(Corners(m), corners);

  Capacity::ShrinkToFit(m);
  EXPECT_EQ(m.face.capacity(), faces);
  EXPECT_EQ(m.vert.capacity(), vertices);
  EXPECT_EQ(Links(m), links);
  EXPECT_EQ(VertexFaceLists(m), lists);
  EXPECT_EQ(Corners(m), corners);

  Capacity::ReserveFaces(m, faces, fu); // enough room already: nothing moves
  EXPECT_FALSE(fu.NeedUpdate());
}

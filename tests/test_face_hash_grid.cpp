// FaceHashGrid::InsertAll against one Insert per face in index order: the stages rely on the grid
// visiting faces in the same order whichever way it was filled (the first intersecting partner a
// query reports decides which move is undone), so both must give the same answers, in order.
#include <gtest/gtest.h>

#include <vcg_ext/spatial/face_hash_grid.h>
#include <vcg_ext/io/mesh_io.h>
#include <vcg_ext/core/mesh_types.h>

#include <cstddef>
#include <string>
#include <vector>

#include "test_helpers.h"

namespace {

using molremesh::FaceHashGrid;
using molremesh::MeshD;
using Box = vcg::Box3d;

Box FaceBox(const MeshD& m, std::size_t f) {
  Box b;
  for (int k = 0; k < 3; ++k) b.Add(m.face[f].cP(k));
  return b;
}

/// Every query answer of both grids, in visiting order: the faces near each face (QueryFace) and
/// the faces touching a few boxes (Query).
void ExpectSameAnswers(const MeshD& m, const std::vector<bool>& skip, FaceHashGrid& a, FaceHashGrid& b) {
  FaceHashGrid::QueryMarks marksA, marksB;
  for (std::size_t f = 0; f < m.face.size(); ++f) {
    ASSERT_EQ(a.Contains(f), b.Contains(f)) << "face " << f;
    if (skip[f]) continue;
    std::vector<std::size_t> nearA, nearB;
    a.QueryFace(f, marksA, [&](std::size_t g) { nearA.push_back(g); });
    b.QueryFace(f, marksB, [&](std::size_t g) { nearB.push_back(g); });
    ASSERT_EQ(nearA, nearB) << "face " << f;
    ASSERT_FALSE(nearA.empty()) << "face " << f << " has no neighbour in the grid";
  }
  for (std::size_t f = 0; f < m.face.size(); f += 97) {
    Box box = FaceBox(m, f);
    box.Offset(3.0 * a.CellSize());
    std::vector<std::size_t> inA, inB;
    a.Query(box, marksA, [&](std::size_t g) { inA.push_back(g); });
    b.Query(box, marksB, [&](std::size_t g) { inB.push_back(g); });
    ASSERT_EQ(inA, inB) << "box around face " << f;
  }
}

// BPTI (6k faces) is filled in one block, 1MAH (over 8192 faces) in several.
class FaceHashGridBulk : public ::testing::TestWithParam<const char*> {};

TEST_P(FaceHashGridBulk, InsertAllGivesTheGridOfInsertsInIndexOrder) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  MeshD m;
  std::string error;
  ASSERT_TRUE(molremesh::LoadMesh(m, molremesh::test::SharedMesh(GetParam()), error)) << error;
  ASSERT_GT(m.face.size(), 1000u);
  // Some faces left out (as deleted faces are) and one face stretched over many cells (stored
  // without its inline cell slots).
  std::vector<bool> skip(m.face.size(), false);
  for (std::size_t f = 0; f < m.face.size(); f += 13) skip[f] = true;
  m.face[5].V(0)->P() += vcg::Point3d(8, 8, 8);

  Box all;
  for (const auto& v : m.vert) all.Add(v.cP());
  const double cell = 1.5;
  for (int threads : {1, 2, 3}) {
    FaceHashGrid one, bulk;
    one.Reset(cell, all.min);
    bulk.Reset(cell, all.min);
    one.Resize(m.face.size());
    for (std::size_t f = 0; f < m.face.size(); ++f)
      if (!skip[f]) one.Insert(f, FaceBox(m, f));
    bulk.InsertAll(
        m.face.size(),
        [&](std::size_t f, Box& box) {
          if (skip[f]) return false;
          box = FaceBox(m, f);
          return true;
        },
        threads);
    ExpectSameAnswers(m, skip, one, bulk);
    // Still a normal dynamic grid afterwards: moving a face updates both alike.
    const std::size_t moved = 7;
    m.face[moved].V(1)->P() += vcg::Point3d(2, 0, 0);
    for (std::size_t f = 0; f < m.face.size(); ++f) {
      if (skip[f] || (m.face[f].cV(0) != m.face[moved].cV(1) && m.face[f].cV(1) != m.face[moved].cV(1) &&
                      m.face[f].cV(2) != m.face[moved].cV(1)))
        continue;
      one.Update(f, FaceBox(m, f));
      bulk.Update(f, FaceBox(m, f));
    }
    ExpectSameAnswers(m, skip, one, bulk);
    m.face[moved].V(1)->P() -= vcg::Point3d(2, 0, 0);
  }
}

INSTANTIATE_TEST_SUITE_P(SharedMeshes, FaceHashGridBulk,
                         ::testing::Values("bpti_1bpi_msms.ply", "ache_1MAH_edtsurf_vcmc.ply"));

} // namespace

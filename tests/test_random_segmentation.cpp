// RandomSegmentation: complete, connected, deterministic patches.
#include <gtest/gtest.h>

#include <vcg/complex/algorithms/create/platonic.h>
#include <vcg/complex/algorithms/refine.h>
#include <vcg/complex/algorithms/update/topology.h>
#include <vcg/complex/append.h>

#include <map>
#include <set>

#include <vcg_ext/io/mesh_io.h>
#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/stages/random_segmentation.h>

#include "test_helpers.h"

using molremesh::MeshD;
using Segmentation = molremesh::RandomSegmentation<MeshD>;

namespace {
void MakeSphere(MeshD& m, int refinements) {
  vcg::tri::Icosahedron(m);
  vcg::tri::UpdateTopology<MeshD>::FaceFace(m);
  for (int i = 0; i < refinements; ++i) {
    vcg::tri::Refine(m, vcg::tri::MidPoint<MeshD>(&m));
  }
  for (auto& v : m.vert) v.P().Normalize();
  vcg::tri::UpdateTopology<MeshD>::FaceFace(m);
}

/// Number of edge-connected pieces of every patch.
std::map<int, int> PiecesPerPatch(const MeshD& m, const std::vector<int>& patch) {
  std::vector<bool> seen(m.face.size(), false);
  std::map<int, int> pieces;
  for (std::size_t start = 0; start < m.face.size(); ++start) {
    if (seen[start] || m.face[start].IsD()) continue;
    ++pieces[patch[start]];
    std::vector<std::size_t> stack{start};
    seen[start] = true;
    while (!stack.empty()) {
      const std::size_t fi = stack.back();
      stack.pop_back();
      for (int e = 0; e < 3; ++e) {
        const std::size_t gi = vcg::tri::Index(m, m.face[fi].cFFp(e));
        if (!seen[gi] && patch[gi] == patch[fi]) {
          seen[gi] = true;
          stack.push_back(gi);
        }
      }
    }
  }
  return pieces;
}
} // namespace

TEST(RandomSegmentation, EveryFaceInOneOfTheRequestedConnectedPatches) {
  MeshD m;
  MakeSphere(m, 5); // 20480 faces
  Segmentation::Params params;
  params.patchCount = 8;
  const molremesh::SegmentationResult s = Segmentation::Do(m, params);
  ASSERT_TRUE(s.ok);
  EXPECT_EQ(s.patchCount, 8);
  std::map<int, std::size_t> sizes;
  for (int p : s.facePatch) {
    ASSERT_GE(p, 0);
    ++sizes[p];
  }
  EXPECT_EQ(sizes.size(), 8u);
  for (const auto& [patch, pieces] : PiecesPerPatch(m, s.facePatch))
    EXPECT_EQ(pieces, 1) << "patch " << patch;
  const auto [smallest, largest] =
      std::minmax_element(sizes.begin(), sizes.end(), [](auto& a, auto& b) { return a.second < b.second; });
  // Round-robin growth keeps patches of comparable size.
  EXPECT_LT(double(largest->second) / double(smallest->second), 6.0);
  EXPECT_GT(s.borderEdges, 0u);
  EXPECT_GT(s.borderVertices, 0u);
}

TEST(RandomSegmentation, SameSeedSamePatchesOtherSeedOtherPatches) {
  MeshD m;
  MakeSphere(m, 4);
  Segmentation::Params params;
  params.patchCount = 6;
  params.seed = 42;
  const auto a = Segmentation::Do(m, params);
  const auto b = Segmentation::Do(m, params);
  EXPECT_EQ(a.facePatch, b.facePatch);
  params.seed = 43;
  const auto c = Segmentation::Do(m, params);
  EXPECT_NE(a.facePatch, c.facePatch);
}

TEST(RandomSegmentation, ComponentWithoutSeedGetsItsOwnPatch) {
  MeshD m;
  MakeSphere(m, 3);
  MeshD small;
  vcg::tri::Tetrahedron(small);
  vcg::tri::Append<MeshD, MeshD>::Mesh(m, small);
  vcg::tri::UpdateTopology<MeshD>::FaceFace(m);
  Segmentation::Params params;
  params.patchCount = 1;
  params.seed = 7;
  const auto s = Segmentation::Do(m, params);
  for (int p : s.facePatch) EXPECT_GE(p, 0);
  EXPECT_EQ(s.patchCount, 2);
}

TEST(RandomSegmentation, AutomaticCountOnARealMesh) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  MeshD m;
  std::string error;
  ASSERT_TRUE(molremesh::LoadMesh(m, molremesh::test::SharedMesh("lysozyme_Lys1_msms.ply"), error)) << error;
  vcg::tri::UpdateTopology<MeshD>::FaceFace(m);
  const auto s = Segmentation::Do(m);
  EXPECT_EQ(s.patchCount, Segmentation::DefaultPatchCount(m, Segmentation::Params()));
  EXPECT_GE(s.patchCount, 2);
  for (int p : s.facePatch) EXPECT_GE(p, 0);
}

TEST(RandomSegmentation, ColorsPatches) {
  MeshD m;
  MakeSphere(m, 2);
  Segmentation::Params params;
  params.patchCount = 3;
  const auto s = Segmentation::Do(m, params);
  Segmentation::ColorPatches(m, s);
  std::set<unsigned> colors;
  for (const auto& f : m.face) colors.insert(*reinterpret_cast<const unsigned*>(&f.cC()[0]));
  EXPECT_EQ(colors.size(), 3u);
}

TEST(RandomSegmentation, EmptyMeshIsRefused) {
  MeshD m;
  const auto s = Segmentation::Do(m);
  EXPECT_FALSE(s.ok);
  EXPECT_FALSE(s.message.empty());
}

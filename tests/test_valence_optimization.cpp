// Valence optimization (stage 2): constructed meshes with known irregular vertices end regular,
// through flips/collapses and through removal and refilling alone; holes that cannot be filled
// well leave the mesh no worse; real molecular meshes after clean + CVT reach V567 >= 99.8%
// with no new small angle and every remeshing invariant kept; polish's refills on the reference
// (strips at low-valence pit apexes, stars of high-valence saddle vertices) leave no more irregular
// vertices than polish without them.
#include <gtest/gtest.h>

#include <vcg/complex/complex.h>

#include <vcg_ext_instances/extern_mesh_d.h>
#include <vcg_ext/core/mesh_copy.h>
#include <vcg_ext/ops/local_remeshing_ops.h>
#include <vcg_ext/io/mesh_io.h>
#include <vcg_ext/pipeline/remesh_pipeline.h>
#include <vcg_ext/stages/valence_optimization.h>

#include <functional>
#include <map>
#include <utility>

#include "remeshing_test_meshes.h"
#include "test_helpers.h"

using namespace molremesh;
using namespace molremesh::test;

namespace {

using VO = ValenceOptimization<MeshD>;

/// Hexagonal patch of the regular triangular lattice (all interior vertices valence 6, boundary
/// vertices valence 3 or 4), radius R lattice steps around the origin, in the z = 0 plane.
void HexPatch(MeshD& m, int R) {
  std::vector<Point> points;
  std::vector<std::vector<int>> id(2 * R + 1, std::vector<int>(2 * R + 1, -1));
  for (int j = -R; j <= R; ++j)
    for (int i = -R; i <= R; ++i)
      if (std::abs(i + j) <= R) {
        id[i + R][j + R] = int(points.size());
        points.emplace_back(i + 0.5 * j, j * std::sqrt(3.0) / 2, 0);
      }
  auto at = [&](int i, int j) { return (std::abs(i) <= R && std::abs(j) <= R) ? id[i + R][j + R] : -1; };
  std::vector<std::array<int, 3>> faces;
  for (int j = -R; j < R; ++j)
    for (int i = -R; i < R; ++i) {
      const int a = at(i, j), b = at(i + 1, j), c = at(i, j + 1), d = at(i + 1, j + 1);
      if (a >= 0 && b >= 0 && c >= 0) faces.push_back({a, b, c});
      if (b >= 0 && d >= 0 && c >= 0) faces.push_back({b, d, c});
    }
  MakeMesh(m, points, faces);
  vcg::tri::UpdateTopology<MeshD>::FaceFace(m);
  vcg::tri::UpdateTopology<MeshD>::VertexFace(m);
}

/// Planar disk around a centre vertex of valence k: k sectors (centre, corner i, corner i+1) on
/// a regular k-gon of radius R, each subdivided into R x R rows of triangles, so every vertex but
/// the centre has the regular valence (6 inside, 3 or 4 on the rim).
void WheelDisk(MeshD& m, int k, int R) {
  std::vector<Point> points{Point(0, 0, 0)};
  std::map<std::array<int, 3>, int> index; // (ring, position along the ring, 0) -> vertex
  auto corner = [&](int i) {
    const double a = 2 * M_PI * i / k;
    return Point(R * std::cos(a), R * std::sin(a), 0);
  };
  // Ring r has k * r vertices; vertex j of ring r lies on sector j / r at fraction (j % r) / r.
  auto vertex = [&](int r, int j) -> int {
    if (r == 0) return 0;
    j = ((j % (k * r)) + k * r) % (k * r);
    const auto key = std::array<int, 3>{r, j, 0};
    const auto it = index.find(key);
    if (it != index.end()) return it->second;
    const int sector = j / r, step = j % r;
    const Point a = corner(sector) * (double(r) / R), b = corner(sector + 1) * (double(r) / R);
    points.push_back(a + (b - a) * (double(step) / r));
    index[key] = int(points.size()) - 1;
    return index[key];
  };
  std::vector<std::array<int, 3>> faces;
  for (int r = 0; r < R; ++r)
    for (int sector = 0; sector < k; ++sector) {
      // Strip between ring r and r + 1 inside this sector.
      for (int t = 0; t <= r; ++t) {
        const int inner = sector * r + t, outer = sector * (r + 1) + t;
        faces.push_back({vertex(r, inner), vertex(r + 1, outer), vertex(r + 1, outer + 1)});
        if (t < r) faces.push_back({vertex(r, inner), vertex(r + 1, outer + 1), vertex(r, inner + 1)});
      }
    }
  MakeMesh(m, points, faces);
  vcg::tri::UpdateTopology<MeshD>::FaceFace(m);
  vcg::tri::UpdateTopology<MeshD>::VertexFace(m);
}

int ValenceOf(const MeshD& m, const MeshD::VertexType* v) {
  int faces = 0;
  for (const auto& f : m.face)
    if (!f.IsD())
      for (int k = 0; k < 3; ++k) faces += f.cV(k) == v;
  return faces; // interior vertex: faces = edges
}

/// Flipping edge z of f keeps the planar (z = 0) mesh unfolded: both new faces counterclockwise.
bool FlipKeepsOrientation(const MeshD::FaceType& f, int z) {
  const MeshD::FaceType& g = *f.cFFp(z);
  const int w = f.cFFi(z);
  const auto &v0 = f.cP(z), &v1 = f.cP((z + 1) % 3), &v2 = f.cP((z + 2) % 3), &v3 = g.cP((w + 2) % 3);
  auto ccw = [](const vcg::Point3d& a, const vcg::Point3d& b, const vcg::Point3d& c) {
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]) > 1e-9;
  };
  return ccw(v0, v3, v2) && ccw(v1, v2, v3);
}

/// Changes the valence of the vertex nearest `where` to `target` by flips that keep the plane
/// unfolded: link edges flipped toward the vertex raise it, spokes flipped away lower it.
void ForceValence(MeshD& m, const Point& where, int target) {
  MeshD::VertexPointer c = &m.vert[0];
  for (auto& v : m.vert)
    if (vcg::Distance(v.P(), where) < vcg::Distance(c->P(), where)) c = &v;
  for (int guard = 0; guard < 40 && ValenceOf(m, c) != target; ++guard) {
    const bool raise = ValenceOf(m, c) < target;
    bool done = false;
    for (auto& f : m.face) {
      if (f.IsD() || done) continue;
      for (int k = 0; k < 3 && !done; ++k) {
        if (f.V(k) != c) continue;
        const int z = raise ? (k + 1) % 3 : k; // raise: the link edge opposite c; lower: a spoke
        if (f.FFp(z) == &f || !vcg::face::CheckFlipEdge(f, z) || !FlipKeepsOrientation(f, z)) continue;
        vcg::face::FlipEdge(f, z);
        vcg::tri::UpdateTopology<MeshD>::VertexFace(m);
        done = true;
      }
    }
    if (!done) break;
  }
  ASSERT_EQ(ValenceOf(m, c), target);
}

VO::Result RunStage(MeshD& m, const VO::Params& params) {
  ReferenceSurface<MeshD> reference;
  std::string error;
  EXPECT_TRUE(reference.Build(m, ReferenceSurface<MeshD>::Params(), &error)) << error;
  return VO::Do(m, reference, params);
}

QualityReport Quality(const MeshD& m) {
  return MeshQuality<MeshD>::Compute(m, MeshQuality<MeshD>::Params());
}

struct Case {
  int centre;    ///< valence of the centre vertex of a WheelDisk
  int neighbour; ///< 0, or the valence forced on a neighbour of the centre (an adjacent pair)
  bool flips;    ///< step 1 on; off = removal and refilling alone
};

class ConstructedIrregular : public ::testing::TestWithParam<Case> {};

} // namespace

TEST_P(ConstructedIrregular, EndsRegularWithoutNewBadAngles) {
  MeshD m;
  WheelDisk(m, GetParam().centre, 6);
  if (GetParam().neighbour) ForceValence(m, Point(1, 0, 0), GetParam().neighbour);
  const QualityReport before = Quality(m);
  ASSERT_GT(VO::Census(m).irregular, 0u);

  VO::Params params;
  params.flipsAndCollapses = GetParam().flips;
  const VO::Result r = RunStage(m, params);
  ASSERT_TRUE(r.ok) << r.message;
  const QualityReport after = Quality(m);
  EXPECT_EQ(VO::Census(m).irregular, 0u) << ValenceOptimizationSummary(r);
  EXPECT_LE(r.smallAnglesAfter, r.smallAnglesBefore) << ValenceOptimizationSummary(r);
  EXPECT_GE(after.angleMin, std::min(before.angleMin, 30.0) - 1e-9);
  ExpectTwoManifoldWithoutDegenerateFaces(after);
  ExpectNoSelfIntersection(after);
  ExpectComponentsClosedWithTheirGenus(before, after);
  if (!GetParam().flips) {
    EXPECT_GT(r.filledZero + r.filledOne + r.filledTwo, 0u) << ValenceOptimizationSummary(r);
  }
}

INSTANTIATE_TEST_SUITE_P(Valence, ConstructedIrregular,
                         ::testing::Values(Case{3, 0, true}, Case{4, 0, true}, Case{8, 0, true},
                                           Case{9, 0, true}, Case{10, 0, true}, Case{8, 4, true},
                                           Case{3, 0, false}, Case{4, 0, false}, Case{8, 0, false},
                                           Case{9, 0, false}, Case{10, 0, false}, Case{8, 4, false}),
                         [](const auto& p) {
                           std::string name = "V" + std::to_string(p.param.centre);
                           if (p.param.neighbour) name += "V" + std::to_string(p.param.neighbour);
                           return name + (p.param.flips ? "_FlipsCollapses" : "_RemoveRefill");
                         });

TEST(ValenceOptimization, ReplaceDiskRefusesWithoutChangeAndAppliesCleanly) {
  MeshD m;
  HexPatch(m, 3);
  ReferenceSurface<MeshD> reference;
  ASSERT_TRUE(reference.Build(m, ReferenceSurface<MeshD>::Params()));
  LocalOpsGuards guards;
  guards.minAngleDeg = 30;
  guards.noMoreBadFaces = true;
  LocalRemeshingOps<MeshD> ops(m, reference, 1.0, guards, 1);
  ASSERT_TRUE(ops.Init());
  MeshD::VertexPointer center = &m.vert[0];
  for (auto& v : m.vert)
    if (v.P().Norm() < center->P().Norm()) center = &v;
  std::vector<MeshD::FacePointer> star;
  for (vcg::face::VFIterator<MeshD::FaceType> it(center); !it.End(); ++it) star.push_back(it.F());
  std::vector<MeshD::VertexPointer> loop, interior;
  ASSERT_TRUE(ops.DiskBoundary(star, loop, interior));
  ASSERT_EQ(loop.size(), 6u);
  ASSERT_EQ(interior.size(), 1u);

  std::vector<Point> before;
  for (const auto& v : m.vert) before.push_back(vcg::Point3d(v.P()[0], v.P()[1], v.P()[2]));
  const int faces = m.fn;
  const std::size_t centreIndex = vcg::tri::Index(m, center);
  // A refused ReplaceDisk may make room (moving the elements): gather the disk again each time.
  auto gather = [&]() {
    star.clear();
    for (vcg::face::VFIterator<MeshD::FaceType> it(&m.vert[centreIndex]); !it.End(); ++it)
      star.push_back(it.F());
    ASSERT_TRUE(ops.DiskBoundary(star, loop, interior));
  };
  // A fan from a point far off the hole folds: refused, nothing changes.
  std::vector<std::array<int, 3>> fan;
  for (int i = 0; i < 6; ++i) fan.push_back({i, (i + 1) % 6, 6});
  EXPECT_FALSE(ops.ReplaceDisk(star, loop, {Point(5, 5, 0)}, fan));
  EXPECT_EQ(m.fn, faces);
  for (std::size_t i = 0; i < before.size(); ++i)
    EXPECT_EQ(vcg::Point3d(m.vert[i].P()[0], m.vert[i].P()[1], m.vert[i].P()[2]), before[i]);
  // A triangulation that does not cover the disk once is refused.
  gather();
  EXPECT_FALSE(ops.ReplaceDisk(star, loop, {}, {{0, 1, 2}}));
  // The fan from the centre is accepted and keeps the adjacency consistent.
  gather();
  std::vector<MeshD::VertexPointer> created;
  ASSERT_TRUE(ops.ReplaceDisk(star, loop, {Point(0.05, 0.02, 0)}, fan, &created));
  ASSERT_EQ(created.size(), 1u);
  EXPECT_EQ(m.fn, faces);
  EXPECT_EQ(LocalRemeshingOps<MeshD>::AdjacencyProblem(m), "");
  ops.Finish();
  EXPECT_TRUE(Quality(m).isTwoManifold());
}

TEST(ValenceOptimization, HoleWithoutFeasiblePointLeavesMeshNoWorse) {
  // A valence-10 vertex whose star is squeezed into a thin ellipse: no fill reaches 30 degrees.
  MeshD m;
  std::vector<Point> points{Point(0, 0, 0)};
  const int k = 10;
  for (int i = 0; i < k; ++i) {
    const double a = 2 * M_PI * i / k;
    points.emplace_back(6 * std::cos(a), 0.6 * std::sin(a), 0);
  }
  // Outer ring to make the rim vertices interior.
  for (int i = 0; i < k; ++i) {
    const double a = 2 * M_PI * (i + 0.5) / k;
    points.emplace_back(9 * std::cos(a), 3 * std::sin(a), 0);
  }
  std::vector<std::array<int, 3>> faces;
  for (int i = 0; i < k; ++i) {
    const int a = 1 + i, b = 1 + (i + 1) % k, o = 1 + k + i, o2 = 1 + k + (i + k - 1) % k;
    faces.push_back({0, a, b});
    faces.push_back({a, o, b});
    faces.push_back({a, o2, o});
  }
  MakeMesh(m, points, faces);
  vcg::tri::UpdateTopology<MeshD>::FaceFace(m);
  vcg::tri::UpdateTopology<MeshD>::VertexFace(m);
  const QualityReport before = Quality(m);
  const ValenceCensus censusBefore = VO::Census(m);
  VO::Params params;
  params.flipsAndCollapses = false;
  const VO::Result r = RunStage(m, params);
  ASSERT_TRUE(r.ok) << r.message;
  const QualityReport after = Quality(m);
  EXPECT_LE(VO::Census(m).irregular, censusBefore.irregular);
  EXPECT_LE(r.smallAnglesAfter, r.smallAnglesBefore) << ValenceOptimizationSummary(r);
  EXPECT_GE(after.angleMin, before.angleMin - 1e-9) << ValenceOptimizationSummary(r);
  ExpectTwoManifoldWithoutDegenerateFaces(after);
  ExpectNoSelfIntersection(after);
  ExpectComponentsClosedWithTheirGenus(before, after);
}

TEST(ValenceOptimization, BadInputLeavesMeshUntouched) {
  MeshD m;
  std::string error;
  ASSERT_TRUE(LoadMesh(m, Fixture("nonmanifold_fan.ply"), error)) << error;
  vcg::tri::UpdateTopology<MeshD>::FaceFace(m);
  vcg::tri::UpdateTopology<MeshD>::VertexFace(m);
  const int vn = m.vn, fn = m.fn;
  std::vector<vcg::Point3d> before;
  for (const auto& v : m.vert) before.push_back(vcg::Point3d(v.P()[0], v.P()[1], v.P()[2]));
  ReferenceSurface<MeshD> reference;
  ASSERT_TRUE(reference.Build(m, ReferenceSurface<MeshD>::Params()));
  const VO::Result r = VO::Do(m, reference, VO::Params());
  EXPECT_FALSE(r.ok);
  EXPECT_FALSE(r.message.empty());
  EXPECT_EQ(m.vn, vn);
  EXPECT_EQ(m.fn, fn);
  for (std::size_t i = 0; i < before.size(); ++i)
    EXPECT_EQ(vcg::Point3d(m.vert[i].P()[0], m.vert[i].P()[1], m.vert[i].P()[2]), before[i]);

  MeshD empty;
  EXPECT_FALSE(VO::Do(empty, reference, VO::Params()).ok);
}

namespace {
class ValenceOnSharedMesh : public ::testing::TestWithParam<std::string> {};
} // namespace

TEST_P(ValenceOnSharedMesh, ReachesV567WithAllInvariants) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  MeshD m;
  std::string error;
  ASSERT_TRUE(LoadMesh(m, SharedMesh(GetParam()), error)) << error;
  using Pipeline = RemeshPipeline<MeshD>;
  Pipeline::Params params;
  params.stages = {PipelineStage::Clean, PipelineStage::Cvt, PipelineStage::Valence};
  const PipelineResult r = Pipeline::Do(m, params);
  ASSERT_TRUE(r.ok) << r.message;
  ASSERT_EQ(r.stages.size(), 3u);
  const QualityReport& cleaned = r.stages[0].after;
  const QualityReport& cvt = r.stages[1].after;
  const QualityReport& after = r.stages[2].after;
  EXPECT_GE(after.v567Percent, 99.8) << r.stages[2].summary;
  EXPECT_GE(after.v567Percent, cvt.v567Percent);
  // No new angle below 30 degrees: no more faces with one, and the smallest angle no smaller
  // than it was or than 30.
  EXPECT_LE(after.smallAngleFaces, cvt.smallAngleFaces);
  EXPECT_GE(after.angleMin, std::min(cvt.angleMin, 30.0) - 1e-9);
  ExpectTwoManifoldWithoutDegenerateFaces(after);
  ExpectNoSelfIntersection(after);
  ExpectComponentsClosedWithTheirGenus(cleaned, after);
  EXPECT_NEAR(after.volume, cleaned.volume, 0.005 * std::fabs(cleaned.volume));
}

INSTANTIATE_TEST_SUITE_P(Meshes, ValenceOnSharedMesh,
                         ::testing::Values("bpti_1bpi_msms.ply", "lysozyme_Lys1_msms.ply",
                                           "galactose_grasp.ply", "ubiquitin_1UBQ_edtsurf_mc.ply",
                                           "ubiquitin_1UBQ_pymol_ses.ply", "ache_1MAH_edtsurf_vcmc.ply",
                                           "ache_1MAH_pymol_ses.ply", "ubiquitin_1UBQ_jmol.ply"),
                         [](const auto& p) {
                           std::string name = p.param.substr(0, p.param.find('.'));
                           for (char& c : name)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return name;
                         });

namespace {

/// Remeshes the shared mesh `name` at L up to polish, then runs polish from that mesh with a step
/// off and on (set(params, on) switches it); checks that the step leaves no more irregular
/// vertices and keeps every invariant, and returns polish's results without and with it.
std::pair<VO::Result, VO::Result>
PolishWithAndWithoutStep(const std::string& name, double L,
                         const std::function<void(VO::Params&, bool)>& set) {
  using Pipeline = RemeshPipeline<MeshD>;
  MeshD input, cleaned, m;
  std::string error;
  VO::Result off, on;
  EXPECT_TRUE(LoadMesh(input, SharedMesh(name), error)) << error;
  CopyTriangles(cleaned, input);
  CopyTriangles(m, input);
  Pipeline::Params params;
  params.targetEdgeLength = L;
  params.stages = {PipelineStage::Clean};
  EXPECT_TRUE(Pipeline::Do(cleaned, params).ok);
  params.stages = {PipelineStage::Clean, PipelineStage::Cvt,   PipelineStage::Valence, PipelineStage::Segment,
                   PipelineStage::Rar,   PipelineStage::Small, PipelineStage::Obtuse,  PipelineStage::Smooth};
  EXPECT_TRUE(Pipeline::Do(m, params).ok);
  ReferenceSurface<MeshD> reference;
  EXPECT_TRUE(reference.Build(cleaned, ReferenceSurface<MeshD>::Params(), &error)) << error;

  auto polish = [&](bool enabled, MeshD& out, VO::Result& r) {
    CopyTriangles(out, m);
    vcg::tri::UpdateTopology<MeshD>::FaceFace(out);
    vcg::tri::UpdateTopology<MeshD>::VertexFace(out);
    VO::Params p = params.polish;
    p.targetEdgeLength = params.targetEdgeLength;
    set(p, enabled);
    r = VO::Do(out, reference, p);
    EXPECT_TRUE(r.ok) << r.message;
  };
  MeshD without, with;
  polish(false, without, off);
  polish(true, with, on);
  EXPECT_LE(on.after.irregular, off.after.irregular) << ValenceOptimizationSummary(on);
  EXPECT_LE(on.largeAnglesAfter, on.largeAnglesBefore);
  EXPECT_LE(on.smallAnglesAfter, on.smallAnglesBefore);
  const QualityReport before = Quality(m), after = Quality(with);
  EXPECT_GE(after.angleMin, std::min(before.angleMin, 30.0) - 1e-9);
  EXPECT_LE(after.angleMax, std::max(before.angleMax, 90.0) + 1e-9);
  ExpectTwoManifoldWithoutDegenerateFaces(after);
  ExpectNoSelfIntersection(after);
  ExpectComponentsClosedWithTheirGenus(before, after);
  return {off, on};
}

/// Polish's refills on the reference (step 4) on and off, without step 5 after them.
void SetRefillsOnReference(VO::Params& p, bool on) {
  p.refillOnReference = on;
  p.relaxedFlips = false;
}

} // namespace

TEST(ValenceOptimization, StripRefillsInPolishLeaveNoMoreIrregularVertices) {
  // 1UBQ's EDTSurf surface remeshed at L = 0.9 A: before polish, a few vertices of valence 3 or 4
  // sit at pits no star refill mends; strips give them one more edge.
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  const VO::Result on =
      PolishWithAndWithoutStep("ubiquitin_1UBQ_edtsurf_mc.ply", 0.9, SetRefillsOnReference).second;
  EXPECT_GT(on.strips, 0u) << ValenceOptimizationSummary(on);
}

TEST(ValenceOptimization, StarRefillsOnTheReferenceLeaveNoMoreIrregularVertices) {
  // 1MAH's PyMOL surface remeshed at L = 0.9 A: at saddles between atom spheres a few vertices of
  // valence 8 or more keep their star, as the planar refill of it is refused once projected.
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  const VO::Result on =
      PolishWithAndWithoutStep("ache_1MAH_pymol_ses.ply", 0.9, SetRefillsOnReference).second;
  EXPECT_GT(on.starsOnReference, 0u) << ValenceOptimizationSummary(on);
}

TEST(ValenceOptimization, RelaxedFlipsInPolishLeaveFewerIrregularVertices) {
  // 1MAH's PyMOL surface remeshed at L = 0.9 A: after steps 1 to 4 some vertices of valence 4 or
  // 8 keep it because every flip that mends them leaves a face outside [30, 90] degrees; with
  // the vertices around the flip re-placed on the reference, some of them go through.
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto [off, on] = PolishWithAndWithoutStep(
      "ache_1MAH_pymol_ses.ply", 0.9, [](VO::Params& p, bool enabled) { p.relaxedFlips = enabled; });
  EXPECT_GT(on.relaxedFlips, 0u) << ValenceOptimizationSummary(on);
  EXPECT_LT(on.after.irregular, off.after.irregular) << ValenceOptimizationSummary(on);
}

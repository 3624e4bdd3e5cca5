// Tests of molremesh::CvtInitialization (Khan et al. 2020, stage 1): refusals, the Voronoi cell
// pieces, the acceptance figures on constructed and real molecular meshes (2-manifold, no
// self-intersection, closed components keep their genus, volume within 0.5%, vertices on the
// input, V567 >= 99%, better angles), sheets a fraction of an edge apart never joined, and
// bit-identical output for any thread count.
#include <gtest/gtest.h>

#include <vcg_ext_instances/extern_mesh_d.h>
#include <vcg_ext/stages/cvt_initialization.h>

#include "remeshing_test_meshes.h"
#include "test_helpers.h"

#include <vcg_ext/io/mesh_io.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <tuple>
#include <vector>

namespace {

using molremesh::ComponentInfo;
using molremesh::MeshD;
using molremesh::MeshQuality;
using molremesh::QualityReport;
using molremesh::ReferenceSurface;
using namespace molremesh::test;
using Cvt = molremesh::CvtInitialization<MeshD>;

QualityReport Measure(const MeshD& m) {
  return MeshQuality<MeshD>::Compute(m);
}

/// Components as (closed, genus), sorted: the topology CVT must keep.
std::vector<std::pair<bool, int>> Topology(const QualityReport& r) {
  std::vector<std::pair<bool, int>> t;
  for (const ComponentInfo& c : r.componentInfo) t.emplace_back(c.closed, c.genus);
  std::sort(t.begin(), t.end());
  return t;
}

/// Largest distance from a used vertex of m to the reference.
double MaxDistance(const MeshD& m, const ReferenceSurface<MeshD>& ref) {
  std::vector<char> used(m.vert.size(), 0);
  for (const auto& f : m.face)
    if (!f.IsD())
      for (int k = 0; k < 3; ++k) used[f.cV(k) - &m.vert[0]] = 1;
  double d = 0;
  for (std::size_t i = 0; i < m.vert.size(); ++i)
    if (!m.vert[i].IsD() && used[i]) d = std::max(d, ref.Distance(m.vert[i].cP()));
  return d;
}

/// Runs CVT on m and checks every acceptance figure against the input.
Cvt::Result RunAndCheck(MeshD& m, const Cvt::Params& params = Cvt::Params(), double minV567 = 99.0,
                        double minAngle = 25.0) {
  const QualityReport in = Measure(m);
  ReferenceSurface<MeshD> input;
  EXPECT_TRUE(input.Build(m));
  const Cvt::Result result = Cvt::Do(m, params);
  EXPECT_TRUE(result.ok) << result.message;
  if (!result.ok) return result;
  const QualityReport out = Measure(m);
  EXPECT_TRUE(out.isTwoManifold());
  EXPECT_EQ(out.selfIntersectingPairs, 0u);
  EXPECT_EQ(out.adjacentOverlapPairs, 0u);
  EXPECT_EQ(out.degenerateFaces, 0u);
  EXPECT_EQ(out.boundaryEdges, in.boundaryEdges == 0 ? 0u : out.boundaryEdges);
  EXPECT_EQ(Topology(out), Topology(in));
  if (in.boundaryEdges == 0) {
    EXPECT_NEAR(out.volume, in.volume, 0.005 * std::fabs(in.volume));
  }
  EXPECT_LE(MaxDistance(m, input), 0.1 * result.targetEdgeLength);
  EXPECT_GE(out.v567Percent, minV567);
  EXPECT_GE(out.angleMin, std::min(minAngle, 0.99 * std::max(in.angleMin, minAngle)));
  EXPECT_EQ(molremesh::LocalRemeshingOps<MeshD>::AdjacencyProblem(m), "");
  return result;
}

// --- Refusals ------------------------------------------------------------------------------------

TEST(CvtInitialization, RefusesBrokenInputsWithoutTouchingThem) {
  for (const char* name : {"empty.ply", "point_cloud.ply", "nan_vertex.ply", "nonmanifold_fan.ply"}) {
    MeshD m;
    std::string error;
    molremesh::LoadMesh(m, Fixture(name), error);
    const int vn = m.vn, fn = m.fn;
    auto bits = [&m] { // positions bit for bit (NaN included)
      std::vector<unsigned char> b(m.vert.size() * sizeof(Point));
      for (std::size_t i = 0; i < m.vert.size(); ++i)
        std::memcpy(&b[i * sizeof(Point)], &m.vert[i].P(), sizeof(Point));
      return b;
    };
    const auto before = bits();
    const Cvt::Result r = Cvt::Do(m);
    EXPECT_FALSE(r.ok) << name;
    EXPECT_NE(r.message.find("refused"), std::string::npos) << r.message;
    EXPECT_EQ(m.vn, vn);
    EXPECT_EQ(m.fn, fn);
    EXPECT_TRUE(bits() == before) << name;
  }
  MeshD m;
  std::string error;
  molremesh::LoadMesh(m, Fixture("nonmanifold_fan.ply"), error);
  EXPECT_NE(Cvt::Do(m).message.find("cleaning stage"), std::string::npos);
}

// --- Voronoi cell pieces -------------------------------------------------------------------------

TEST(CvtInitialization, CornerPiecesPartitionTheTriangle) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> u(-1, 1);
  int obtuse = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const std::array<Point, 3> p{Point(u(rng), u(rng), u(rng)), Point(u(rng), u(rng), u(rng)),
                                 Point(u(rng), u(rng), u(rng))};
    double total = 0;
    Point weighted(0, 0, 0);
    for (int k = 0; k < 3; ++k) {
      double area;
      Point w;
      Cvt::CornerPiece(p[k], p[(k + 1) % 3], p[(k + 2) % 3], area, w);
      EXPECT_GE(area, 0.0);
      total += area;
      weighted += w;
    }
    const double twiceArea = ((p[1] - p[0]) ^ (p[2] - p[0])).Norm();
    EXPECT_NEAR(total, twiceArea, 1e-9 * (1 + twiceArea));
    EXPECT_NEAR((weighted / total - (p[0] + p[1] + p[2]) / 3.0).Norm(), 0.0, 1e-9);
    for (int k = 0; k < 3; ++k) obtuse += (p[(k + 1) % 3] - p[k]) * (p[(k + 2) % 3] - p[k]) < 0;
  }
  EXPECT_GT(obtuse, 100); // obtuse corners (pieces cut by one bisector only) were exercised
}

TEST(CvtInitialization, FacePiecesAgreeWithCornerPieces) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 2000; ++trial) {
    const std::array<Point, 3> p{Point(u(rng), u(rng), u(rng)), Point(u(rng), u(rng), u(rng)),
                                 Point(u(rng), u(rng), u(rng))};
    std::array<double, 3> area;
    std::array<Point, 3> weighted;
    Cvt::FacePieces(p, area, weighted);
    for (int k = 0; k < 3; ++k) {
      double a;
      Point w;
      Cvt::CornerPiece(p[k], p[(k + 1) % 3], p[(k + 2) % 3], a, w);
      EXPECT_NEAR(area[k], a, 1e-12);
      EXPECT_NEAR((weighted[k] - w).Norm(), 0.0, 1e-12);
    }
  }
}

TEST(CvtInitialization, CellPieceOfAnEquilateralCornerIsAThird) {
  const Point a(0, 0, 0), b(1, 0, 0), c(0.5, std::sqrt(3.0) / 2, 0);
  double area;
  Point w;
  Cvt::CornerPiece(a, b, c, area, w);
  EXPECT_NEAR(area, std::sqrt(3.0) / 2 / 3, 1e-12); // twice the area over three
}

// --- Constructed meshes ----------------------------------------------------------------------------

TEST(CvtInitialization, SphereWithDefaultParameters) {
  MeshD m;
  Icosphere(m, 3);
  const Cvt::Result r = RunAndCheck(m);
  EXPECT_EQ(r.iterations, 42);
  EXPECT_GT(r.movesApplied, 0u);
}

TEST(CvtInitialization, TorusKeepsItsGenus) {
  MeshD m;
  Torus(m, 3.0, 1.0, 48, 16); // right triangles, valence 6: CVT must rebuild the triangles
  const QualityReport in = Measure(m);
  ASSERT_EQ(in.genus, 1);
  Cvt::Params p;
  p.iterations = 20;
  RunAndCheck(m, p, 98.0);
}

TEST(CvtInitialization, TorusWithANarrowHoleKeepsItsGenus) {
  // The inner sides of the tube face each other across the hole 0.2 edge lengths apart.
  MeshD m;
  const double L = 2 * 3.14159265358979323846 / 24;
  Torus(m, 1.0 + 0.1 * L, 1.0, 96, 24);
  Cvt::Params p;
  p.targetEdgeLength = L;
  p.iterations = 20;
  const QualityReport in = Measure(m);
  ASSERT_EQ(in.genus, 1);
  ASSERT_TRUE(Cvt::Do(m, p).ok);
  const QualityReport out = Measure(m);
  EXPECT_TRUE(out.isTwoManifold());
  EXPECT_EQ(out.genus, 1);
  EXPECT_EQ(out.components, 1u);
  EXPECT_EQ(out.boundaryEdges, 0u);
  EXPECT_EQ(out.selfIntersectingPairs, 0u);
  EXPECT_EQ(out.adjacentOverlapPairs, 0u);
}

TEST(CvtInitialization, TwoSpheresAFifthOfAnEdgeApartStaySeparate) {
  MeshD m, other;
  Icosphere(m, 3);
  const double L = MeanEdge(m);
  Icosphere(other, 3, Point(2.0 + 0.2 * L, 0, 0));
  AppendMesh(m, other);
  Cvt::Params p;
  p.targetEdgeLength = L;
  RunAndCheck(m, p);
  EXPECT_EQ(Measure(m).components, 2u);
}

TEST(CvtInitialization, TwoParallelSheetsAFifthOfAnEdgeApartStaySeparate) {
  // Flat ellipsoids stacked along z: their facing sides are nearly parallel over a wide area.
  MeshD m, other;
  Icosphere(m, 4, Point(0, 0, 0), Point(2.0, 2.0, 0.5));
  const double L = 1.5 * MeanEdge(m);
  Icosphere(other, 4, Point(0, 0, 1.0 + 0.2 * L), Point(2.0, 2.0, 0.5));
  AppendMesh(m, other);
  Cvt::Params p;
  p.targetEdgeLength = L;
  p.iterations = 20;
  RunAndCheck(m, p, 98.0);
  EXPECT_EQ(Measure(m).components, 2u);
}

TEST(CvtInitialization, OpenSurfaceKeepsItsBoundary) {
  MeshD m;
  Icosphere(m, 3);
  for (auto& f : m.face) // remove the lower half: a hemisphere with one boundary loop
    if ((f.V(0)->P() + f.V(1)->P() + f.V(2)->P())[2] < -0.05) vcg::tri::Allocator<MeshD>::DeleteFace(m, f);
  vcg::tri::Clean<MeshD>::RemoveUnreferencedVertex(m);
  vcg::tri::Allocator<MeshD>::CompactEveryVector(m);
  const QualityReport in = Measure(m);
  ASSERT_EQ(in.boundaryLoops, 1u);
  Cvt::Params p;
  p.iterations = 10;
  ASSERT_TRUE(Cvt::Do(m, p).ok);
  const QualityReport out = Measure(m);
  EXPECT_TRUE(out.isTwoManifold());
  EXPECT_EQ(out.boundaryLoops, 1u);
  EXPECT_EQ(out.genus, 0);
  EXPECT_EQ(out.selfIntersectingPairs, 0u);
  EXPECT_EQ(out.adjacentOverlapPairs, 0u);
}

TEST(CvtInitialization, TargetVertexCountAndEdgeLength) {
  MeshD m;
  Icosphere(m, 4); // 2562 vertices
  Cvt::Params p;
  p.targetVertexCount = 1000;
  p.iterations = 10;
  const Cvt::Result r = Cvt::Do(m, p);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_NEAR(double(m.vn), 1000.0, 10.0);
  const double L = r.targetEdgeLength;
  EXPECT_NEAR(MeanEdge(m), L, 0.05 * L);

  MeshD n;
  Icosphere(n, 4);
  const double mean = MeanEdge(n);
  Cvt::Params q;
  q.targetEdgeLength = 2.0 * mean;
  q.iterations = 10;
  ASSERT_TRUE(Cvt::Do(n, q).ok);
  EXPECT_NEAR(MeanEdge(n), 2.0 * mean, 0.1 * mean);
  EXPECT_NEAR(double(n.vn), 2562.0 / 4.0, 0.05 * 2562.0 / 4.0);
}

TEST(CvtInitialization, ExternalReferenceSurface) {
  MeshD fine, coarse;
  Icosphere(fine, 4);
  Icosphere(coarse, 2);
  ReferenceSurface<MeshD> ref;
  ASSERT_TRUE(ref.Build(fine));
  Cvt::Params p;
  p.iterations = 10;
  p.preserveVolume = false;
  const Cvt::Result r = Cvt::Do(coarse, ref, p);
  ASSERT_TRUE(r.ok) << r.message;
  EXPECT_LT(MaxDistance(coarse, ref), 1e-9);
  EXPECT_EQ(Measure(coarse).selfIntersectingPairs, 0u);
}

TEST(CvtInitialization, OutputDoesNotDependOnTheThreadCount) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  std::vector<std::vector<Point>> positions;
  std::vector<std::vector<std::array<long, 3>>> faces;
  for (const int threads : {1, 2, 3}) {
    MeshD m;
    std::string error;
    ASSERT_TRUE(molremesh::LoadMesh(m, SharedMesh("lysozyme_Lys1_msms.ply"), error)) << error;
    Cvt::Params p;
    p.threads = threads;
    p.iterations = 12;
    ASSERT_TRUE(Cvt::Do(m, p).ok);
    std::vector<Point> pos;
    for (const auto& v : m.vert) pos.push_back(v.P());
    std::vector<std::array<long, 3>> tri;
    for (const auto& f : m.face)
      tri.push_back({f.cV(0) - &m.vert[0], f.cV(1) - &m.vert[0], f.cV(2) - &m.vert[0]});
    positions.push_back(pos);
    faces.push_back(tri);
  }
  EXPECT_TRUE(positions[0] == positions[1]);
  EXPECT_TRUE(positions[0] == positions[2]);
  EXPECT_TRUE(faces[0] == faces[1]);
  EXPECT_TRUE(faces[0] == faces[2]);
}

TEST(CvtInitialization, FloatMeshAndProgressCallback) {
  MeshF m;
  Icosphere(m, 3);
  static std::vector<int> progress;
  progress.clear();
  molremesh::CvtInitialization<MeshF>::Params p;
  p.iterations = 10;
  const auto r = molremesh::CvtInitialization<MeshF>::Do(m, p, [](const int pos, const char*) {
    progress.push_back(pos);
    return true;
  });
  ASSERT_TRUE(r.ok) << r.message;
  const auto q = MeshQuality<MeshF>::Compute(m);
  EXPECT_TRUE(q.isTwoManifold());
  EXPECT_EQ(q.selfIntersectingPairs, 0u);
  EXPECT_EQ(q.genus, 0);
  EXPECT_GE(q.v567Percent, 98.0);
  ASSERT_FALSE(progress.empty());
  EXPECT_TRUE(std::is_sorted(progress.begin(), progress.end()));
  EXPECT_EQ(progress.back(), 100);
}

// --- Real molecular surfaces --------------------------------------------------------------------------

class RealMesh : public ::testing::TestWithParam<const char*> {};

TEST_P(RealMesh, AcceptanceFigures) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  MeshD m;
  std::string error;
  ASSERT_TRUE(molremesh::LoadMesh(m, SharedMesh(GetParam()), error)) << error;
  const QualityReport in = Measure(m);
  // These inputs are already clean: closed 2-manifolds without self-intersections.
  ASSERT_TRUE(in.isTwoManifold());
  ASSERT_EQ(in.boundaryEdges, 0u);
  ASSERT_EQ(in.selfIntersectingPairs, 0u);
  const Cvt::Result r = RunAndCheck(m);
  EXPECT_EQ(r.iterations, 42);
  const QualityReport out = Measure(m);
  EXPECT_GT(out.angleMin, in.angleMin);
  EXPECT_GE(out.angleMin, 25.0);
  EXPECT_LE(out.angleMax, 125.0);
  EXPECT_LT(out.obtusePercent, in.obtusePercent);
  EXPECT_NEAR(out.meanEdgeLength, r.targetEdgeLength, 0.05 * r.targetEdgeLength);
}

INSTANTIATE_TEST_SUITE_P(CvtInitialization, RealMesh,
                         ::testing::Values("bpti_1bpi_msms.ply", "lysozyme_Lys1_msms.ply",
                                           "galactose_grasp.ply", "ache_1MAH_edtsurf_vcmc.ply"));

} // namespace

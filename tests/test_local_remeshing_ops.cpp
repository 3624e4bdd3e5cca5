// Unit tests of molremesh::LocalRemeshingOps: each operation's effect on small constructed
// meshes, every guard refusing what it must (and a refused operation changing nothing), locks,
// the batch (Jacobi) moves, and random stress runs that must keep the mesh valid.
#include <gtest/gtest.h>

#include <vcg_ext_instances/extern_mesh_d.h>
#include <vcg_ext/ops/local_remeshing_ops.h>

#include "remeshing_test_meshes.h"
#include "test_helpers.h"

#include <vcg_ext/io/mesh_io.h>

#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace {

using molremesh::BatchMoveResult;
using molremesh::LocalOpsGuards;
using molremesh::LocalRemeshingOps;
using molremesh::MeshD;
using molremesh::MeshQuality;
using molremesh::OpRefusal;
using molremesh::QualityReport;
using molremesh::ReferenceSurface;
using namespace molremesh::test;

/// A mesh, its reference (a copy of itself) and the operations on it. The reference projects onto
/// its flat triangles (no Phong lift), so every projected point lies exactly on the copy.
template <class Mesh>
struct OpsSetup {
  Mesh m;
  ReferenceSurface<Mesh> ref;
  std::unique_ptr<LocalRemeshingOps<Mesh>> ops;
  double L = 0;

  void Start(const LocalOpsGuards& guards = LocalOpsGuards(), int threads = 1) {
    vcg::tri::UpdateTopology<Mesh>::FaceFace(m);
    typename ReferenceSurface<Mesh>::Params flat;
    flat.phongAlpha = 0;
    ASSERT_TRUE(ref.Build(m, flat));
    L = ref.MeanEdgeLength();
    ops = std::make_unique<LocalRemeshingOps<Mesh>>(m, ref, L, guards, threads);
    std::string error;
    ASSERT_TRUE(ops->Init(&error, true)) << error;
  }
  typename Mesh::FacePointer Edge(int a, int b, int& z) {
    typename Mesh::FacePointer f = nullptr;
    EXPECT_TRUE(ops->FindEdge(&m.vert[a], &m.vert[b], f, z));
    return f;
  }
};

/// Everything an operation could change, to check that a refused one changes nothing.
struct Snapshot {
  std::vector<Point> positions;
  std::vector<long> faceData; // vertex / FF / VF indices and flags of every face
  std::vector<long> vertexData;
  int vn = 0, fn = 0;

  template <class Mesh>
  explicit Snapshot(const Mesh& m) : vn(m.vn), fn(m.fn) {
    auto fi = [&](const typename Mesh::FaceType* f) { return f == nullptr ? -1L : long(f - &m.face[0]); };
    for (const auto& v : m.vert) {
      positions.emplace_back(v.cP()[0], v.cP()[1], v.cP()[2]);
      vertexData.push_back(v.IsD());
      vertexData.push_back(fi(v.cVFp()));
      vertexData.push_back(v.cVFi());
    }
    for (const auto& f : m.face) {
      faceData.push_back(f.IsD());
      if (f.IsD()) continue;
      for (int k = 0; k < 3; ++k) {
        faceData.push_back(long(f.cV(k) - &m.vert[0]));
        faceData.push_back(fi(f.cFFp(k)));
        faceData.push_back(f.cFFi(k));
        faceData.push_back(fi(f.cVFp(k)));
        faceData.push_back(f.cVFi(k));
      }
    }
  }
  bool operator==(const Snapshot& o) const {
    return positions == o.positions && faceData == o.faceData && vertexData == o.vertexData && vn == o.vn &&
           fn == o.fn;
  }
};

/// The mesh is a valid closed-or-open 2-manifold with consistent adjacency and no intersection.
template <class Mesh>
void ExpectValid(Mesh& m, int genus = -2, std::size_t components = 0) {
  EXPECT_EQ(LocalRemeshingOps<Mesh>::AdjacencyProblem(m), "");
  const QualityReport r = MeshQuality<Mesh>::Compute(m);
  EXPECT_TRUE(r.isTwoManifold());
  EXPECT_EQ(r.selfIntersectingPairs, 0u);
  EXPECT_EQ(r.adjacentOverlapPairs, 0u);
  EXPECT_EQ(r.degenerateFaces, 0u);
  if (genus >= -1) {
    EXPECT_EQ(r.genus, genus);
  }
  if (components > 0) {
    EXPECT_EQ(r.components, components);
  }
}

// --- Preconditions -----------------------------------------------------------------------------

TEST(LocalRemeshingOps, InitRefusesNonManifoldMisorientedAndRepeatedVertices) {
  std::string error;
  {
    MeshD m;
    ASSERT_TRUE(molremesh::LoadMesh(m, Fixture("nonmanifold_fan.ply"), error)) << error;
    EXPECT_FALSE(LocalRemeshingOps<MeshD>::PrepareTopology(m, &error));
    EXPECT_NE(error.find("non-manifold"), std::string::npos) << error;
  }
  {
    MeshD m;
    Icosphere(m, 1);
    std::swap(m.face[3].V(0), m.face[3].V(1)); // one face turned over
    EXPECT_FALSE(LocalRemeshingOps<MeshD>::PrepareTopology(m, &error));
    EXPECT_NE(error.find("oriented"), std::string::npos) << error;
  }
  {
    MeshD m;
    MakeMesh(m, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{0, 1, 2}});
    auto f = vcg::tri::Allocator<MeshD>::AddFaces(m, 1); // vcg's AddFace refuses a repeated vertex
    f->V(0) = &m.vert[0];
    f->V(1) = &m.vert[0];
    f->V(2) = &m.vert[1];
    EXPECT_FALSE(LocalRemeshingOps<MeshD>::PrepareTopology(m, &error));
    EXPECT_NE(error.find("repeated"), std::string::npos) << error;
  }
  {
    OpsSetup<MeshD> s;
    Icosphere(s.m, 1);
    s.Start();
    EXPECT_EQ(LocalRemeshingOps<MeshD>::AdjacencyProblem(s.m), "");
  }
}

// --- Split ---------------------------------------------------------------------------------------

TEST(LocalRemeshingOps, InitTakesKnownGlobalFootpointsAndSearchesTheRest) {
  // The reference is a finer sphere, so each vertex's footpoint takes a search. Footpoints handed
  // to Init (every other vertex, as ProjectGlobal finds them) are kept, the others searched.
  MeshD fine;
  Icosphere(fine, 3);
  ReferenceSurface<MeshD> ref;
  ASSERT_TRUE(ref.Build(fine));
  MeshD a, b;
  Icosphere(a, 1);
  Icosphere(b, 1);
  std::vector<int> known(b.vert.size(), -1);
  for (std::size_t i = 0; i < b.vert.size(); i += 2)
    known[i] = ref.ProjectGlobal(LocalRemeshingOps<MeshD>::ToPoint(b.vert[i].cP())).face;
  // Vertex 1's is a face the search would not find: Init takes what it is given, unchecked.
  known[1] =
      (ref.ProjectGlobal(LocalRemeshingOps<MeshD>::ToPoint(b.vert[1].cP())).face + 1) % int(ref.FaceCount());
  LocalRemeshingOps<MeshD> searched(a, ref, ref.MeanEdgeLength()), given(b, ref, ref.MeanEdgeLength());
  std::string error;
  ASSERT_TRUE(searched.Init(&error)) << error;
  ASSERT_TRUE(given.Init(&error, false, false, false, &known)) << error;
  EXPECT_EQ(given.Footpoint(b.vert[1]), known[1]);
  for (std::size_t i = 0; i < a.vert.size(); ++i) {
    EXPECT_GE(searched.Footpoint(a.vert[i]), 0);
    if (i != 1) {
      EXPECT_EQ(given.Footpoint(b.vert[i]), searched.Footpoint(a.vert[i])) << "vertex " << i;
    }
  }
}

TEST(LocalRemeshingOps, SplitInteriorAndBorderEdges) {
  OpsSetup<MeshD> s;
  Grid(s.m, 4, 4.0);
  s.Start();
  const int vn = s.m.vn, fn = s.m.fn;
  int z = 0;
  auto* f = s.Edge(6, 7, z); // interior horizontal edge (1,1)-(2,1)
  auto* v = s.ops->SplitEdge(f, z);
  ASSERT_NE(v, nullptr);
  EXPECT_EQ(s.m.vn, vn + 1);
  EXPECT_EQ(s.m.fn, fn + 2);
  EXPECT_NEAR((v->P() - Point(1.5, 1, 0)).Norm(), 0.0, 1e-12);
  EXPECT_EQ(s.ops->Valence(*v), 4);
  f = s.Edge(0, 1, z); // border edge
  v = s.ops->SplitEdge(f, z);
  ASSERT_NE(v, nullptr);
  EXPECT_EQ(s.m.fn, fn + 3);
  EXPECT_TRUE(s.ops->IsBoundaryVertex(*v));
  EXPECT_EQ(s.ops->Stats().splits, 2u);
  ExpectValid(s.m, 0, 1);
}

TEST(LocalRemeshingOps, SplitProjectsTheMidpointOntoTheReference) {
  OpsSetup<MeshD> s;
  Icosphere(s.m, 2);
  s.Start();
  int z = 0;
  auto* f = &s.m.face[10];
  z = 1;
  const Point mid = (f->V(z)->P() + f->V((z + 1) % 3)->P()) / 2.0;
  auto* v = s.ops->SplitEdge(f, z);
  ASSERT_NE(v, nullptr);
  EXPECT_LT(s.ref.Distance(v->P()), 1e-12);
  EXPECT_NEAR((v->P() - mid).Norm(), 0.0, 1e-12); // the midpoint already lies on the flat reference
  ExpectValid(s.m, 0, 1);
}

// --- Collapse ------------------------------------------------------------------------------------

TEST(LocalRemeshingOps, CollapseInteriorEdgeToItsMidpoint) {
  OpsSetup<MeshD> s;
  Grid(s.m, 4, 4.0);
  s.Start();
  const int vn = s.m.vn, fn = s.m.fn;
  int z = 0;
  auto* f = s.Edge(6, 7, z);
  ASSERT_TRUE(s.ops->CollapseEdge(f, z));
  EXPECT_EQ(s.m.vn, vn - 1);
  EXPECT_EQ(s.m.fn, fn - 2);
  const auto& survivor = s.m.vert[6].IsD() ? s.m.vert[7] : s.m.vert[6];
  EXPECT_NEAR((survivor.cP() - Point(1.5, 1, 0)).Norm(), 0.0, 1e-12);
  ExpectValid(s.m, 0, 1);
}

TEST(LocalRemeshingOps, CollapseRespectsTheLinkCondition) {
  { // Tetrahedron: every collapse would leave two faces glued back to back.
    OpsSetup<MeshD> s;
    vcg::tri::Tetrahedron(s.m);
    s.Start();
    for (int z = 0; z < 3; ++z) {
      EXPECT_FALSE(s.ops->CollapseEdge(&s.m.face[0], z));
      EXPECT_EQ(s.ops->LastRefusal(), OpRefusal::Topology);
    }
  }
  { // Triangular bipyramid: equator edges have a third common neighbour.
    OpsSetup<MeshD> s;
    MakeMesh(s.m, {{1, 0, 0}, {-0.5, 0.87, 0}, {-0.5, -0.87, 0}, {0, 0, 1}, {0, 0, -1}},
             {{0, 1, 3}, {1, 2, 3}, {2, 0, 3}, {1, 0, 4}, {2, 1, 4}, {0, 2, 4}});
    s.Start();
    int z = 0;
    auto* f = s.Edge(0, 1, z);
    const Snapshot before(s.m);
    EXPECT_FALSE(s.ops->CollapseEdge(f, z));
    EXPECT_EQ(s.ops->LastRefusal(), OpRefusal::Topology);
    EXPECT_TRUE(Snapshot(s.m) == before);
  }
  { // Octahedron: the link condition allows a collapse (the geometric guards are relaxed: this
    // coarse a polyhedron changes shape a lot) and leaves a valid bipyramid.
    OpsSetup<MeshD> s;
    vcg::tri::Octahedron(s.m);
    LocalOpsGuards relaxed;
    relaxed.minAngleDeg = 0;
    relaxed.maxNormalDeviationDeg = 180;
    relaxed.maxFoldAngleDeg = 180;
    s.Start(relaxed);
    EXPECT_TRUE(s.ops->CollapseEdge(&s.m.face[0], 0));
    EXPECT_EQ(s.m.vn, 5);
    EXPECT_EQ(s.m.fn, 6);
    ExpectValid(s.m, 0, 1);
  }
}

TEST(LocalRemeshingOps, CollapseRefusesTooLongNewEdges) {
  OpsSetup<MeshD> s;
  Grid(s.m, 4, 4.0);
  s.Start();
  int z = 0;
  auto* f = s.Edge(6, 7, z);
  EXPECT_FALSE(s.ops->CollapseEdge(f, z, 1.2));
  EXPECT_EQ(s.ops->LastRefusal(), OpRefusal::EdgeLength);
  EXPECT_TRUE(s.ops->CollapseEdge(f, z, 2.0));
}

// --- Flip ----------------------------------------------------------------------------------------

TEST(LocalRemeshingOps, FlipReplacesTheDiagonal) {
  OpsSetup<MeshD> s;
  Grid(s.m, 4, 4.0);
  s.Start();
  int z = 0;
  auto* f = s.Edge(6, 12, z); // diagonal of quad (1,1)
  ASSERT_NE(f, nullptr);
  ASSERT_TRUE(s.ops->FlipEdge(f, z));
  typename MeshD::FacePointer g = nullptr;
  EXPECT_FALSE(s.ops->FindEdge(&s.m.vert[6], &s.m.vert[12], g, z));
  EXPECT_TRUE(s.ops->FindEdge(&s.m.vert[7], &s.m.vert[11], g, z));
  ExpectValid(s.m, 0, 1);
  // Border edges and existing edges are refused.
  f = s.Edge(0, 1, z);
  EXPECT_FALSE(s.ops->FlipEdge(f, z));
  EXPECT_EQ(s.ops->LastRefusal(), OpRefusal::Boundary);
  OpsSetup<MeshD> t;
  vcg::tri::Tetrahedron(t.m);
  t.Start();
  EXPECT_FALSE(t.ops->FlipEdge(&t.m.face[0], 0));
  EXPECT_EQ(t.ops->LastRefusal(), OpRefusal::Topology);
}

TEST(LocalRemeshingOps, DelaunayAndValenceCriteria) {
  OpsSetup<MeshD> s;
  // Two triangles sharing a long edge with a very obtuse angle: not Delaunay.
  MakeMesh(s.m, {{0, 0, 0}, {4, 0, 0}, {2, 0.3, 0}, {2, -3, 0}}, {{0, 1, 2}, {1, 0, 3}});
  s.Start();
  EXPECT_FALSE(s.ops->IsDelaunay(s.m.face[0], 0));
  EXPECT_TRUE(s.ops->IsDelaunay(s.m.face[0], 1)); // border
  OpsSetup<MeshD> g;
  Grid(g.m, 4, 4.0);
  g.Start();
  int z = 0;
  auto* f = g.Edge(6, 12, z);
  // Interior vertices of this grid have valence 6 or 4/8; flipping changes the sum by an even amount.
  EXPECT_EQ(g.ops->FlipValenceGain(*f, z) % 2, 0);
}

// --- Locks -----------------------------------------------------------------------------------------

TEST(LocalRemeshingOps, LockedVerticesAndEdgesAreNeverTouched) {
  OpsSetup<MeshD> s;
  Grid(s.m, 4, 4.0);
  s.Start();
  s.ops->SetLocked(s.m.vert[6], true);
  EXPECT_TRUE(s.ops->IsLocked(s.m.vert[6]));
  const Snapshot before(s.m);
  EXPECT_FALSE(s.ops->RelocateVertex(&s.m.vert[6], Point(1.1, 1.1, 0)));
  EXPECT_EQ(s.ops->LastRefusal(), OpRefusal::Locked);
  EXPECT_TRUE(Snapshot(s.m) == before);
  // Collapse onto the locked end point: it stays in place.
  int z = 0;
  auto* f = s.Edge(6, 7, z);
  ASSERT_TRUE(s.ops->CollapseEdge(f, z));
  EXPECT_FALSE(s.m.vert[6].IsD());
  EXPECT_TRUE(s.m.vert[7].IsD());
  EXPECT_EQ(s.m.vert[6].P(), Point(1, 1, 0));
  // An edge between two locked vertices: no split, collapse or flip.
  s.ops->SetLocked(s.m.vert[11], true);
  f = s.Edge(6, 11, z);
  const Snapshot locked(s.m);
  EXPECT_EQ(s.ops->SplitEdge(f, z), nullptr);
  EXPECT_FALSE(s.ops->CollapseEdge(f, z));
  EXPECT_FALSE(s.ops->FlipEdge(f, z));
  EXPECT_EQ(s.ops->LastRefusal(), OpRefusal::Locked);
  EXPECT_TRUE(Snapshot(s.m) == locked);
  ExpectValid(s.m, 0, 1);
}

// --- Guards ----------------------------------------------------------------------------------------

TEST(LocalRemeshingOps, AngleGuardRefusesSmallAnglesUnlessTheyImprove) {
  OpsSetup<MeshD> s;
  Grid(s.m, 4, 4.0);
  s.Start();
  // Moving vertex (2,2) almost onto its neighbour (3,2) creates tiny angles.
  const Snapshot before(s.m);
  EXPECT_FALSE(s.ops->RelocateVertex(&s.m.vert[12], Point(2.97, 2.0, 0)));
  EXPECT_EQ(s.ops->LastRefusal(), OpRefusal::MinAngle);
  EXPECT_TRUE(Snapshot(s.m) == before);
  // With a looser guard the move happens; moving back then improves the worst angle and is
  // accepted under the strict guard too.
  LocalOpsGuards loose;
  loose.minAngleDeg = 0.1;
  s.ops->SetGuards(loose);
  ASSERT_TRUE(s.ops->RelocateVertex(&s.m.vert[12], Point(2.9, 2.0, 0)));
  s.ops->SetGuards(LocalOpsGuards());
  EXPECT_TRUE(s.ops->RelocateVertex(&s.m.vert[12], Point(2.5, 2.0, 0)));
  ExpectValid(s.m, 0, 1);
}

TEST(LocalRemeshingOps, FidelityGuardKeepsInputSpikes) {
  // A grid whose centre vertex (2, 2) is lifted into a spike; the reference is the grid itself.
  // Only the fidelity guard is on: collapsing an edge of the tip would cut the spike off.
  LocalOpsGuards guards;
  guards.minAngleDeg = 0;
  guards.maxNormalDeviationDeg = 180;
  guards.maxFoldAngleDeg = 180;
  auto spike = [](OpsSetup<MeshD>& s) {
    Grid(s.m, 4, 4.0);
    s.m.vert[12].P()[2] = 0.8;
  };
  {
    OpsSetup<MeshD> s;
    spike(s);
    guards.maxInputDistanceFactor = 0.25;
    s.Start(guards);
    const Snapshot before(s.m);
    int z = 0;
    EXPECT_FALSE(s.ops->CollapseEdge(s.Edge(12, 13, z), z));
    EXPECT_EQ(s.ops->LastRefusal(), OpRefusal::InputDistance);
    EXPECT_TRUE(Snapshot(s.m) == before);
    // Edits on the flat part away from the tip keep every input point on the mesh: allowed.
    EXPECT_TRUE(s.ops->FlipEdge(s.Edge(0, 6, z), z));
    ExpectValid(s.m, 0, 1);
  }
  {
    OpsSetup<MeshD> s;
    spike(s);
    guards.maxInputDistanceFactor = 0; // off: the same collapse goes through
    s.Start(guards);
    int z = 0;
    EXPECT_TRUE(s.ops->CollapseEdge(s.Edge(12, 13, z), z));
  }
}

TEST(LocalRemeshingOps, MovesThatFoldTheStarAreRefused) {
  OpsSetup<MeshD> s;
  Grid(s.m, 4, 4.0);
  LocalOpsGuards guards;
  guards.minAngleDeg = 0; // only the orientation checks
  s.Start(guards);
  const Snapshot before(s.m);
  // Across the neighbour (3,2): some faces of the star turn over.
  EXPECT_FALSE(s.ops->RelocateVertex(&s.m.vert[12], Point(3.3, 2.1, 0)));
  const OpRefusal r = s.ops->LastRefusal();
  EXPECT_TRUE(r == OpRefusal::Normal || r == OpRefusal::Fold || r == OpRefusal::Intersection) << int(r);
  EXPECT_TRUE(Snapshot(s.m) == before);
}

TEST(LocalRemeshingOps, NoOperationCreatesAnIntersection) {
  // Two parallel sheets 0.2 apart (a narrow crevice); the reference holds both.
  OpsSetup<MeshD> s;
  MeshD upper;
  Grid(s.m, 6, 6.0, 0.0);
  Grid(upper, 6, 6.0, 0.2);
  AppendMesh(s.m, upper);
  s.Start();
  // Lift a vertex of the lower sheet through the upper one (its footpoint stays on the lower).
  auto& v = s.m.vert[24]; // (3,3) on the lower sheet
  const int foot = s.ops->Footpoint(v);
  const Snapshot before(s.m);
  EXPECT_FALSE(s.ops->MoveVertexTo(&v, Point(3.0, 3.0, 0.35), foot));
  EXPECT_EQ(s.ops->LastRefusal(), OpRefusal::Intersection);
  EXPECT_TRUE(Snapshot(s.m) == before);
  // Just below the upper sheet is fine.
  EXPECT_TRUE(s.ops->MoveVertexTo(&v, Point(3.0, 3.0, 0.1), foot));
  ExpectValid(s.m, 0, 2);
}

// --- Stress ------------------------------------------------------------------------------------------

/// Random operations anywhere on the mesh; returns how many were applied.
template <class Mesh>
std::size_t RandomOperations(OpsSetup<Mesh>& s, int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::size_t applied = 0;
  for (int step = 0; step < count; ++step) {
    std::size_t fi;
    do {
      fi = rng() % s.m.face.size();
    } while (s.m.face[fi].IsD());
    const int z = int(rng() % 3);
    auto* f = &s.m.face[fi];
    bool ok = false;
    switch (rng() % 4) {
    case 0:
      ok = s.ops->SplitEdge(f, z) != nullptr;
      break;
    case 1:
      ok = s.ops->CollapseEdge(f, z, 2.0 * s.L);
      break;
    case 2:
      ok = s.ops->FlipEdge(f, z);
      break;
    default: {
      auto* v = f->V(z);
      const Point p(v->P()[0], v->P()[1], v->P()[2]);
      ok = s.ops->RelocateVertex(v, p + Point(u(rng), u(rng), u(rng)) * (0.5 * s.L));
    }
    }
    applied += ok;
  }
  return applied;
}

TEST(LocalRemeshingOps, RandomOperationsKeepASphereValid) {
  OpsSetup<MeshD> s;
  Icosphere(s.m, 3);
  s.Start();
  const std::size_t applied = RandomOperations(s, 20000, 1);
  EXPECT_GT(applied, 5000u);
  EXPECT_GT(s.ops->Stats().splits, 0u);
  EXPECT_GT(s.ops->Stats().collapses, 0u);
  EXPECT_GT(s.ops->Stats().flips, 0u);
  EXPECT_GT(s.ops->Stats().moves, 0u);
  ExpectValid(s.m, 0, 1);
  double farthest = 0;
  for (const auto& v : s.m.vert)
    if (!v.IsD()) farthest = std::max(farthest, s.ref.Distance(v.cP()));
  EXPECT_LT(farthest, 1e-9);
  s.ops->Finish();
  EXPECT_EQ(std::size_t(s.m.vn), s.m.vert.size());
  EXPECT_EQ(std::size_t(s.m.fn), s.m.face.size());
  ExpectValid(s.m, 0, 1);
}

TEST(LocalRemeshingOps, RandomOperationsNeverConnectTwoCloseSpheres) {
  OpsSetup<MeshD> s;
  MeshD other;
  Icosphere(s.m, 3);
  const double L = 1.1 * 0.18; // about the mean edge of a 3-times subdivided unit sphere
  Icosphere(other, 3, Point(2.0 + 0.2 * L, 0, 0));
  AppendMesh(s.m, other);
  s.Start();
  RandomOperations(s, 20000, 2);
  ExpectValid(s.m, 0, 2);
}

TEST(LocalRemeshingOps, FloatMeshesWork) {
  OpsSetup<MeshF> s;
  Icosphere(s.m, 2);
  s.Start();
  const std::size_t applied = RandomOperations(s, 5000, 3);
  EXPECT_GT(applied, 1000u);
  ExpectValid(s.m, 0, 1);
}

// --- Batch moves -------------------------------------------------------------------------------------

TEST(LocalRemeshingOps, JacobiMovesEndValidAndDeterministic) {
  std::vector<std::vector<Point>> results;
  for (const int threads : {1, 3}) {
    OpsSetup<MeshD> s;
    Icosphere(s.m, 3);
    s.Start(LocalOpsGuards(), threads);
    std::mt19937 rng(4);
    std::uniform_real_distribution<double> u(-1, 1);
    std::vector<std::uint32_t> vertices;
    std::vector<Point> targets, original;
    std::vector<int> feet;
    for (std::size_t i = 0; i < s.m.vert.size(); ++i) {
      const Point p = s.m.vert[i].P();
      original.push_back(p);
      // Large random moves: many would fold or tangle the mesh.
      const auto proj =
          s.ref.Project(p + Point(u(rng), u(rng), u(rng)) * (0.8 * s.L), s.ops->Footpoint(s.m.vert[i]));
      vertices.push_back(std::uint32_t(i));
      targets.push_back(proj.point);
      feet.push_back(proj.face);
    }
    const BatchMoveResult r = s.ops->MoveVerticesJacobi(vertices, targets, feet, threads);
    EXPECT_GT(r.applied, 0u);
    EXPECT_GT(r.rejected, 0u);
    EXPECT_EQ(r.applied + r.rejected, vertices.size());
    for (std::size_t i = 0; i < vertices.size(); ++i) {
      const Point p = s.m.vert[i].P();
      EXPECT_TRUE(p == original[i] || p == targets[i]);
    }
    ExpectValid(s.m, 0, 1);
    std::vector<Point> positions;
    for (const auto& v : s.m.vert) positions.push_back(v.P());
    results.push_back(positions);
  }
  EXPECT_TRUE(results[0] == results[1]);
}

TEST(LocalRemeshingOps, PendingMovesAreVerifiedBeforeAnyOtherOperation) {
  OpsSetup<MeshD> s;
  Grid(s.m, 6, 6.0);
  s.Start();
  auto& v = s.m.vert[24];
  ASSERT_TRUE(s.ops->MoveVertexUnchecked(&v, Point(4.2, 3.0, 0), s.ops->Footpoint(v))); // folds the star
  EXPECT_TRUE(s.ops->HasPendingMoves());
  int z = 0;
  auto* f = s.Edge(0, 1, z);
  s.ops->SplitEdge(f, z); // may reallocate m.vert: v is read again by index below
  EXPECT_FALSE(s.ops->HasPendingMoves());
  EXPECT_EQ(s.m.vert[24].P(), Point(3, 3, 0)); // put back
  ExpectValid(s.m, 0, 1);
}

TEST(LocalRemeshingOps, BatchSweepFindsAStarThatOverlapsItself) {
  // A hexagonal fan whose centre moves far past the rim, in its plane: the faces towards the far
  // rim edges then cross the faces towards the near ones, and all of these pairs share only the
  // centre. Only the intersection test may refuse here (angle, normal and fold guards off).
  LocalOpsGuards guards;
  guards.minAngleDeg = 0;
  guards.maxNormalDeviationDeg = 180;
  guards.maxFoldAngleDeg = 180;
  std::vector<Point> points{Point(0, 0, 0)};
  std::vector<std::array<int, 3>> faces;
  for (int i = 0; i < 6; ++i) {
    const double a = i * 3.14159265358979323846 / 3.0;
    points.emplace_back(std::cos(a), std::sin(a), 0);
    faces.push_back({0, 1 + i, 1 + (i + 1) % 6});
  }
  for (const int threads : {1, 2}) {
    OpsSetup<MeshD> s;
    MakeMesh(s.m, points, faces);
    s.Start(guards, threads);
    auto& centre = s.m.vert[0];
    ASSERT_TRUE(s.ops->MoveVertexUnchecked(&centre, Point(0.2, -2.5, 0), s.ops->Footpoint(centre)));
    const BatchMoveResult r = s.ops->VerifyPendingMoves(threads);
    EXPECT_EQ(r.rejected, 1u);
    EXPECT_EQ(centre.P(), Point(0, 0, 0));
    ExpectValid(s.m, -2, 1);
    // A move inside the rim is a simple fan again: accepted.
    ASSERT_TRUE(s.ops->MoveVertexUnchecked(&centre, Point(0.2, -0.3, 0.1), s.ops->Footpoint(centre)));
    EXPECT_EQ(s.ops->VerifyPendingMoves(threads).applied, 1u);
    EXPECT_EQ(centre.P(), Point(0.2, -0.3, 0.1));
  }
}

// --- A real mesh -------------------------------------------------------------------------------------

TEST(LocalRemeshingOps, RandomOperationsOnARealMolecularSurface) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  OpsSetup<MeshD> s;
  std::string error;
  ASSERT_TRUE(molremesh::LoadMesh(s.m, SharedMesh("bpti_1bpi_msms.ply"), error)) << error;
  s.Start();
  RandomOperations(s, 20000, 5);
  ExpectValid(s.m, 0, 1);
}

} // namespace

// Unit tests of molremesh::ReferenceSurface: closest points against brute force, the local
// projection that does not jump across narrow gaps, components and volumes, the Phong lift.
#include <gtest/gtest.h>

#include <vcg_ext/core/parallel_for.h>
#include <vcg_ext/surface/reference_surface.h>

#include "remeshing_test_meshes.h"
#include "test_helpers.h"

#include <vcg_ext/io/mesh_io.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace {

using molremesh::MeshD;
using molremesh::ReferenceSurface;
using molremesh::SurfaceProjection;
using molremesh::reference_detail::ClosestPointOnTriangle;
using namespace molremesh::test;
using Reference = ReferenceSurface<MeshD>;

/// Projection lifted by `alpha` toward the Phong surface (0: onto the flat triangles themselves,
/// for the tests of the walk).
Reference::Params LiftParams(double alpha) {
  Reference::Params params;
  params.phongAlpha = alpha;
  return params;
}
Reference::Params FlatParams() {
  return LiftParams(0);
}

/// A uniformly random unit vector (three draws in [-1, 1], normalized).
Point RandomDirection(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  Point d(u(rng), u(rng), u(rng));
  d.Normalize();
  return d;
}
constexpr double kPi = 3.14159265358979323846;

/// Closest point of the mesh by checking every face.
SurfaceProjection BruteForce(const Reference& ref, const Point& p) {
  SurfaceProjection best;
  for (std::size_t f = 0; f < ref.FaceCount(); ++f) {
    const Point q =
        ClosestPointOnTriangle(p, ref.Corner(int(f), 0), ref.Corner(int(f), 1), ref.Corner(int(f), 2));
    const double d = (q - p).Norm();
    if (d < best.distance) {
      best.distance = d;
      best.point = q;
      best.face = int(f);
    }
  }
  return best;
}

TEST(ClosestPointOnTriangle, MatchesDenseSampling) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 300; ++trial) {
    const Point a(u(rng), u(rng), u(rng)), b(u(rng), u(rng), u(rng)), c(u(rng), u(rng), u(rng));
    const Point p(2 * u(rng), 2 * u(rng), 2 * u(rng));
    const Point q = ClosestPointOnTriangle(p, a, b, c);
    // q lies on the triangle (barycentric coordinates in [0, 1]) ...
    const Point n = (b - a) ^ (c - a);
    EXPECT_NEAR((q - a) * n / n.Norm(), 0.0, 1e-12);
    // ... and no sample of the triangle is closer.
    const int steps = 60;
    for (int i = 0; i <= steps; ++i)
      for (int j = 0; i + j <= steps; ++j) {
        const Point s = a + (b - a) * (double(i) / steps) + (c - a) * (double(j) / steps);
        EXPECT_LE((q - p).Norm(), (s - p).Norm() + 1e-12);
      }
  }
}

TEST(ClosestPointOnTriangle, DegenerateTriangles) {
  const Point a(0, 0, 0), b(1, 0, 0), c(2, 0, 0); // collinear
  const Point q = ClosestPointOnTriangle(Point(1.5, 1, 0), a, b, c);
  EXPECT_NEAR((q - Point(1.5, 0, 0)).Norm(), 0.0, 1e-12);
  const Point r = ClosestPointOnTriangle(Point(0, 0, 3), a, a, a); // a single point
  EXPECT_NEAR((r - a).Norm(), 0.0, 1e-12);
}

TEST(ReferenceSurface, RefusesEmptyAndNonFinite) {
  MeshD empty;
  Reference ref;
  std::string error;
  EXPECT_FALSE(ref.Build(empty, Reference::Params(), &error));
  EXPECT_NE(error.find("no face"), std::string::npos);
  MeshD m;
  MakeMesh(m, {{0, 0, 0}, {1, 0, 0}, {0, std::nan(""), 0}}, {{0, 1, 2}});
  EXPECT_FALSE(ref.Build(m, Reference::Params(), &error));
  EXPECT_NE(error.find("NaN"), std::string::npos);
  EXPECT_TRUE(ref.Empty());
}

TEST(ReferenceSurface, GlobalProjectionMatchesBruteForce) {
  MeshD m;
  Icosphere(m, 3, Point(0.3, -0.2, 0.1), Point(2.0, 1.0, 1.5));
  Reference ref;
  ASSERT_TRUE(ref.Build(m));
  EXPECT_EQ(ref.FaceCount(), std::size_t(m.fn));
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-3, 3);
  for (int i = 0; i < 500; ++i) {
    const Point p(u(rng), u(rng), u(rng));
    const SurfaceProjection fast = ref.ProjectGlobal(p);
    const SurfaceProjection slow = BruteForce(ref, p);
    ASSERT_TRUE(fast.ok());
    EXPECT_NEAR(fast.distance, slow.distance, 1e-12);
    EXPECT_NEAR(ref.Distance(p), slow.distance, 1e-12);
  }
  // Far away from the mesh too.
  const Point far(100, -50, 30);
  EXPECT_NEAR(ref.Distance(far), BruteForce(ref, far).distance, 1e-9);
}

TEST(ReferenceSurface, VerticesProjectOntoThemselves) {
  MeshD m;
  Icosphere(m, 2);
  Reference ref;
  ASSERT_TRUE(ref.Build(m));
  for (std::size_t fi = 0; fi < m.face.size(); ++fi)
    for (int k = 0; k < 3; ++k) {
      const SurfaceProjection p = ref.Project(m.face[fi].V(k)->P(), ref.ReferenceFaceOf(fi));
      EXPECT_LT(p.distance, 1e-14);
    }
}

TEST(ReferenceSurface, LocalProjectionFindsTheClosestPointOnASmoothSurface) {
  MeshD m;
  Icosphere(m, 3);
  Reference ref;
  ASSERT_TRUE(ref.Build(m, FlatParams()));
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  const double L = ref.MeanEdgeLength();
  for (int i = 0; i < 500; ++i) {
    // A point near the sphere, with a hint a fraction of an edge away from its closest face.
    const Point dir = RandomDirection(rng);
    const Point p = dir * (1.0 + 0.1 * L * u(rng));
    const SurfaceProjection exact = BruteForce(ref, p);
    const Point nearby = dir + Point(u(rng), u(rng), u(rng)) * (0.5 * L);
    const int hint = ref.ProjectGlobal(nearby).face;
    const SurfaceProjection local = ref.Project(p, hint);
    EXPECT_NEAR(local.distance, exact.distance, 1e-12);
  }
}

TEST(ReferenceSurface, LocalProjectionDoesNotJumpAcrossANarrowGap) {
  // Two parallel sheets 0.2 edge lengths apart, facing each other (a crevice).
  MeshD m, upper;
  Grid(m, 10, 10.0, 0.0);
  Grid(upper, 10, 10.0, 0.2);
  for (auto& f : upper.face) std::swap(f.V(1), f.V(2)); // normals down, towards the lower sheet
  AppendMesh(m, upper);
  Reference ref;
  ASSERT_TRUE(ref.Build(m));
  ASSERT_EQ(ref.ComponentCount(), 2u);
  const int lowerFace = ref.ProjectGlobal(Point(5.3, 5.3, -1)).face;
  ASSERT_EQ(ref.Component(lowerFace), ref.Component(0));
  // A point closer to the upper sheet, projected from a footpoint on the lower one.
  const Point p(5.5, 5.4, 0.15);
  EXPECT_NE(ref.Component(ref.ProjectGlobal(p).face), ref.Component(lowerFace)); // a global query jumps
  const SurfaceProjection local = ref.Project(p, lowerFace);
  ASSERT_TRUE(local.ok());
  EXPECT_EQ(ref.Component(local.face), ref.Component(lowerFace));
  EXPECT_NEAR(local.point[2], 0.0, 1e-12);
  EXPECT_NEAR(local.distance, 0.15, 1e-12);
}

TEST(ReferenceSurface, LocalProjectionDoesNotCrossACreviceBottom) {
  // A narrow U-shaped crevice: two walls 0.2 apart joined by a bottom; a point near the far
  // wall, hinted on the near wall, stays on the near wall (the normals turn by 180 degrees).
  std::vector<Point> pts;
  std::vector<std::array<int, 3>> faces;
  const int n = 8;
  // Profile in the xz plane: near wall x = 0 (z from 4 down to 0), bottom, far wall x = 0.2.
  std::vector<Point> profile{{0, 0, 4},   {0, 0, 2},   {0, 0, 0},  {0.1, 0, -0.1},
                             {0.2, 0, 0}, {0.2, 0, 2}, {0.2, 0, 4}};
  for (int j = 0; j <= n; ++j)
    for (const Point& q : profile) pts.emplace_back(q[0], q[1] + 4.0 * j / n, q[2]);
  const int w = int(profile.size());
  for (int j = 0; j < n; ++j)
    for (int i = 0; i + 1 < w; ++i) {
      const int a = j * w + i, b = j * w + i + 1, c = (j + 1) * w + i + 1, d = (j + 1) * w + i;
      faces.push_back({a, d, b});
      faces.push_back({b, d, c});
    }
  MeshD m;
  MakeMesh(m, pts, faces);
  Reference ref;
  ASSERT_TRUE(ref.Build(m));
  const int nearWall = ref.ProjectGlobal(Point(-1, 2, 3)).face;
  ASSERT_NEAR(ref.Corner(nearWall, 0)[0], 0.0, 1e-12);
  const SurfaceProjection local = ref.Project(Point(0.15, 2.1, 2.5), nearWall);
  EXPECT_NEAR(local.point[0], 0.0, 1e-12);
  EXPECT_NEAR(ref.ProjectGlobal(Point(0.15, 2.1, 2.5)).point[0], 0.2, 1e-12);
}

TEST(ReferenceSurface, ParallelProjectionIsThreadSafeAndIdentical) {
  MeshD m;
  Icosphere(m, 4);
  Reference ref;
  ASSERT_TRUE(ref.Build(m));
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Point> queries(20000);
  std::vector<int> hints(queries.size());
  for (std::size_t i = 0; i < queries.size(); ++i) {
    const Point d = RandomDirection(rng);
    queries[i] = d * (1.0 + 0.02 * u(rng));
    hints[i] = ref.ProjectGlobal(d).face;
  }
  std::vector<SurfaceProjection> serial(queries.size()), parallel(queries.size());
  for (std::size_t i = 0; i < queries.size(); ++i) serial[i] = ref.Project(queries[i], hints[i]);
  std::vector<Reference::Scratch> scratch(4);
  molremesh::ParallelFor(
      queries.size(), 4,
      [&](std::size_t b, std::size_t e, int t) {
        for (std::size_t i = b; i < e; ++i) parallel[i] = ref.Project(queries[i], hints[i], scratch[t]);
      },
      64);
  for (std::size_t i = 0; i < queries.size(); ++i) {
    EXPECT_EQ(serial[i].face, parallel[i].face);
    EXPECT_EQ(serial[i].point, parallel[i].point);
  }
}

TEST(ReferenceSurface, ComponentsClosednessAndVolumes) {
  MeshD m, second, open;
  Icosphere(m, 4, Point(0, 0, 0), Point(1, 1, 1));
  Icosphere(second, 3, Point(5, 0, 0), Point(2, 2, 2));
  AppendMesh(m, second);
  Grid(open, 4, 1.0, 10.0);
  AppendMesh(m, open);
  Reference ref;
  ASSERT_TRUE(ref.Build(m));
  ASSERT_EQ(ref.ComponentCount(), 3u);
  const int unit = ref.Component(ref.ProjectGlobal(Point(0, 0, 2)).face);
  const int big = ref.Component(ref.ProjectGlobal(Point(5, 0, 3)).face);
  const int flat = ref.Component(ref.ProjectGlobal(Point(0.5, 0.5, 11)).face);
  EXPECT_TRUE(ref.ComponentClosed(unit));
  EXPECT_TRUE(ref.ComponentClosed(big));
  EXPECT_FALSE(ref.ComponentClosed(flat));
  // Inscribed polyhedra: a little below the sphere volumes.
  EXPECT_NEAR(ref.ComponentVolume(unit), 4.0 / 3.0 * kPi, 0.02 * 4.0 / 3.0 * kPi);
  EXPECT_LT(ref.ComponentVolume(unit), 4.0 / 3.0 * kPi);
  EXPECT_NEAR(ref.ComponentVolume(big), 4.0 / 3.0 * kPi * 8.0, 0.05 * 4.0 / 3.0 * kPi * 8.0);
}

TEST(ReferenceSurface, PhongLiftInterpolatesVerticesAndBulgesOutward) {
  MeshD m;
  Icosphere(m, 2);
  Reference ref;
  ASSERT_TRUE(ref.Build(m, LiftParams(0.75)));
  std::mt19937 rng(9);
  for (int i = 0; i < 200; ++i) {
    const Point d = RandomDirection(rng);
    const SurfaceProjection flat = ref.ProjectGlobal(d * 0.9);
    const SurfaceProjection lifted = ref.Project(d * 0.9, flat.face);
    // Inside the faces the lifted surface is outside the flat triangles and closer to the sphere.
    EXPECT_GE(lifted.point.Norm(), flat.point.Norm() - 1e-12);
    EXPECT_LE(std::fabs(lifted.point.Norm() - 1.0), std::fabs(flat.point.Norm() - 1.0) + 1e-12);
  }
  for (const auto& v : m.vert) { // vertices stay where they are
    const SurfaceProjection p = ref.Project(v.P(), ref.ProjectGlobal(v.P()).face);
    EXPECT_NEAR((p.point - v.P()).Norm(), 0.0, 1e-12);
  }
  // A flat sheet is not lifted.
  MeshD grid;
  Grid(grid, 4, 1.0);
  Reference flatRef;
  ASSERT_TRUE(flatRef.Build(grid, LiftParams(0.75)));
  const SurfaceProjection p = flatRef.Project(Point(0.37, 0.41, 0.3), 0);
  EXPECT_NEAR(p.point[2], 0.0, 1e-12);
}

TEST(ReferenceSurface, PhongLiftIsBoundedAndLeavesCreasesFlat) {
  MeshD m;
  Icosphere(m, 1);
  Reference::Params params = LiftParams(1);
  params.phongMaxLift = 0.01;
  Reference ref;
  ASSERT_TRUE(ref.Build(m, params));
  const double bound = params.phongMaxLift * ref.MeanEdgeLength();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  double largest = 0;
  for (int i = 0; i < 200; ++i) {
    const Point d = RandomDirection(rng);
    const SurfaceProjection flat = ref.ProjectGlobal(d * 0.9);
    const SurfaceProjection lifted = ref.Project(d * 0.9, flat.face);
    largest = std::max(largest, (lifted.point - flat.point).Norm());
  }
  EXPECT_LE(largest, bound * (1 + 1e-9));
  EXPECT_GT(largest, 0.99 * bound); // the sphere's lift reaches the bound inside its coarse faces

  // A tetrahedron: every corner normal is 70.5 degrees off the faces' normals, a crease
  // everywhere, so nothing is lifted.
  MeshD tetra;
  vcg::tri::Tetrahedron(tetra);
  Reference sharp;
  ASSERT_TRUE(sharp.Build(tetra, params));
  for (int i = 0; i < 100; ++i) {
    const Point p = Point(u(rng), u(rng), u(rng)) * 0.3;
    const SurfaceProjection flat = sharp.ProjectGlobal(p);
    const SurfaceProjection lifted = sharp.Project(p, flat.face);
    EXPECT_NEAR((lifted.point - flat.point).Norm(), 0.0, 1e-12);
  }
}

// The CVT's cheap step: the orthogonal projection onto the given face when it lands inside, else
// nothing; and Project without the lift (the CVT's intermediate iterations) is the flat closest point.
TEST(ReferenceSurface, ProjectInsideFaceAndUnliftedProjection) {
  MeshD m;
  Icosphere(m, 1);
  Reference ref;
  ASSERT_TRUE(ref.Build(m, LiftParams(1)));
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-1, 1);
  int inside = 0;
  for (int i = 0; i < 300; ++i) {
    const Point d = RandomDirection(rng);
    const Point p = d * (0.95 + 0.1 * (u(rng) + 1) / 2);
    const SurfaceProjection flat = ref.ProjectGlobal(p);
    ASSERT_TRUE(flat.ok());
    Reference::Scratch scratch;
    const SurfaceProjection unlifted = ref.Project(p, flat.face, scratch, /*lift=*/false);
    EXPECT_LT((unlifted.point - flat.point).Norm(), 1e-12);
    // On the face that holds the closest point, the cheap step agrees with it when the
    // orthogonal projection lands inside (the closest point is then interior), and refuses
    // otherwise (the closest point then lies on the face's border).
    const SurfaceProjection cheap = ref.ProjectInsideFace(p, flat.face);
    const SurfaceProjection fromCopy = Reference::ProjectInsideFace(p, ref.Record(flat.face), flat.face);
    EXPECT_EQ(fromCopy.ok(), cheap.ok());
    EXPECT_EQ(fromCopy.point, cheap.point);
    const Point n = ref.FaceNormal(flat.face);
    const Point q = p - n * ((p - ref.Corner(flat.face, 0)) * n);
    if (cheap.ok()) {
      ++inside;
      EXPECT_EQ(cheap.face, flat.face);
      EXPECT_LT((cheap.point - flat.point).Norm(), 1e-12);
      EXPECT_LT((cheap.point - q).Norm(), 1e-12);
    } else {
      EXPECT_GT((q - flat.point).Norm(), 1e-12) << "refused although the projection is the closest point";
    }
    // Beyond a corner of that face (and off its plane): refused.
    const Point centroid =
        (ref.Corner(flat.face, 0) + ref.Corner(flat.face, 1) + ref.Corner(flat.face, 2)) / 3.0;
    const Point beyond = ref.Corner(flat.face, 0) * 2.0 - centroid + n * 0.01;
    EXPECT_FALSE(ref.ProjectInsideFace(beyond, flat.face).ok());
    EXPECT_TRUE(ref.ProjectInsideFace(centroid + n * 0.01, flat.face).ok());
  }
  EXPECT_GT(inside, 150); // most points over a sphere's face project inside it
  EXPECT_FALSE(ref.ProjectInsideFace(Point(0, 0, 1), -1).ok());
  EXPECT_FALSE(ref.ProjectInsideFace(Point(0, 0, 1), int(ref.FaceCount())).ok());
}

TEST(ReferenceSurface, RealMeshLocalProjectionAgreesWithGlobalNearTheSurface) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  MeshD m;
  std::string error;
  ASSERT_TRUE(molremesh::LoadMesh(m, SharedMesh("bpti_1bpi_msms.ply"), error)) << error;
  Reference ref;
  ASSERT_TRUE(ref.Build(m, FlatParams()));
  const double L = ref.MeanEdgeLength();
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-1, 1);
  int agree = 0, total = 0;
  for (std::size_t fi = 0; fi < m.face.size(); fi += 7) {
    const auto& f = m.face[fi];
    const Point c = (f.cV(0)->cP() + f.cV(1)->cP() + f.cV(2)->cP()) / 3.0;
    const Point p = c + Point(u(rng), u(rng), u(rng)) * (0.05 * L);
    const SurfaceProjection local = ref.Project(p, ref.ReferenceFaceOf(fi));
    const SurfaceProjection global = ref.ProjectGlobal(p);
    EXPECT_GE(local.distance, global.distance - 1e-12);
    EXPECT_LE(local.distance, 0.1 * L);
    agree += std::fabs(local.distance - global.distance) < 1e-12;
    ++total;
  }
  EXPECT_GT(agree, total * 99 / 100);
}

} // namespace

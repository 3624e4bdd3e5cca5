// NarrowGaps (vcg_ext/surface/narrow_gaps.h): the share of a surface's area that sees the surface
// again within a reach in front of it.

#include <gtest/gtest.h>

#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/surface/narrow_gaps.h>

#include <vcg/complex/append.h>

#include <cmath>
#include <vector>

#include "remeshing_test_meshes.h"

namespace {

using molremesh::MeshD;
using molremesh::Point;
using Gaps = molremesh::NarrowGaps<MeshD>;

Gaps::Params Reach(double reach, int threads = 0) {
  Gaps::Params p;
  p.reach = reach;
  p.threads = threads;
  return p;
}

/// Two unit balls whose surfaces are `gap` apart on the x axis, the contact point at the origin.
void TwoBalls(MeshD& m, double gap) {
  MeshD b;
  molremesh::test::Icosphere(m, 5, Point(-1 - gap / 2, 0, 0));
  molremesh::test::Icosphere(b, 5, Point(1 + gap / 2, 0, 0));
  vcg::tri::Append<MeshD, MeshD>::Mesh(m, b);
}

} // namespace

TEST(NarrowGaps, AConvexSurfaceHasNoneAtAnyReach) {
  MeshD ball;
  molremesh::test::Icosphere(ball, 4);
  const auto r = Gaps::Measure(ball, Reach(10.0)); // five diameters
  EXPECT_GT(r.area, 12.0);
  EXPECT_EQ(r.narrowFaces, 0u);
  EXPECT_EQ(r.Share(), 0.0);
}

TEST(NarrowGaps, TwoBallsNearlyTouchingHaveAGapOnlyWhereTheyFaceEachOther) {
  MeshD m;
  TwoBalls(m, 0.1);
  EXPECT_EQ(Gaps::Measure(m, Reach(0.05)).narrowFaces, 0u); // narrower than the gap itself
  std::vector<unsigned char> narrow;
  const auto r = Gaps::Measure(m, Reach(0.3), &narrow);
  ASSERT_EQ(narrow.size(), m.face.size());
  // Near the contact the gap along the normal is about 0.1 + rho^2 (rho: the distance from the x
  // axis): within the reach up to rho ~ 0.45 on the two facing caps, beyond it from rho ~ 0.6 on.
  std::size_t near = 0;
  for (std::size_t f = 0; f < m.face.size(); ++f) {
    const auto& face = m.face[f];
    const Point c = (face.cP(0) + face.cP(1) + face.cP(2)) / 3.0;
    const double rho = std::hypot(c[1], c[2]);
    const bool facing = std::fabs(c[0]) < 0.5; // the caps toward the other ball
    if (facing && rho < 0.35) {
      EXPECT_TRUE(narrow[f]) << "rho " << rho;
      ++near;
    }
    if (!facing || rho > 0.6) EXPECT_FALSE(narrow[f]) << "rho " << rho << " x " << c[0];
  }
  EXPECT_GT(near, 20u);
  // Two caps of radius about 0.45 on two unit spheres: 2 x 2 pi (1 - cos(asin 0.45)) / 8 pi = 5.3 %.
  EXPECT_GT(r.Share(), 0.03);
  EXPECT_LT(r.Share(), 0.08);
}

TEST(NarrowGaps, SameResultForAnyThreadCount) {
  MeshD m;
  TwoBalls(m, 0.1);
  const auto one = Gaps::Measure(m, Reach(0.3, 1)), two = Gaps::Measure(m, Reach(0.3, 2));
  EXPECT_EQ(one.narrowFaces, two.narrowFaces);
  EXPECT_EQ(one.narrowArea, two.narrowArea); // the same bits
  EXPECT_EQ(one.area, two.area);
}

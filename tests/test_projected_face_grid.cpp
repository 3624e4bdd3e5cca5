// ProjectedFaceGrid: the candidates of a ray hold every triangle the ray crosses or grazes (the
// inside test of the clean stage's orientation counts crossings over them only), in increasing order.
#include <gtest/gtest.h>

#include <vcg_ext/spatial/projected_face_grid.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <random>
#include <vector>

namespace {

using molremesh::Point;
using molremesh::ProjectedFaceGrid;
using Triangle = std::array<Point, 3>;

/// True when the ray origin + t dir (t > 0) meets the triangle within the barycentric tolerance
/// of the orientation's crossing test (a graze counts).
bool Meets(const Triangle& t, const Point& origin, const Point& dir) {
  const Point e1 = t[1] - t[0], e2 = t[2] - t[0];
  const Point q = dir ^ e2;
  const double det = e1 * q;
  if (std::fabs(det) <= 1e-12 * e1.Norm() * e2.Norm()) return false;
  const Point s = origin - t[0];
  const double u = (s * q) / det;
  const Point r = s ^ e1;
  const double v = (dir * r) / det;
  return u >= -1e-9 && u <= 1 + 1e-9 && v >= -1e-9 && u + v <= 1 + 1e-9 && (e2 * r) / det > 0;
}

/// Triangles of every shape: small ones, long slivers, a few spanning the whole box.
std::vector<Triangle> RandomTriangles(std::mt19937_64& rng, std::size_t count) {
  std::uniform_real_distribution<double> coord(-10, 10), offset(-0.5, 0.5), sliver(-4, 4);
  std::vector<Triangle> out;
  for (std::size_t i = 0; i < count; ++i) {
    const Point a(coord(rng), coord(rng), coord(rng));
    if (i % 97 == 0) {
      out.push_back(
          {a, Point(coord(rng), coord(rng), coord(rng)), Point(coord(rng), coord(rng), coord(rng))});
    } else if (i % 7 == 0) {
      const Point b = a + Point(sliver(rng), sliver(rng), sliver(rng));
      out.push_back({a, b, (a + b) / 2 + Point(1e-4, -1e-4, 1e-4)});
    } else {
      out.push_back({a, a + Point(offset(rng), offset(rng), offset(rng)),
                     a + Point(offset(rng), offset(rng), offset(rng))});
    }
  }
  return out;
}

TEST(ProjectedFaceGrid, CandidatesHoldEveryTriangleTheRayMeetsInIncreasingOrder) {
  std::mt19937_64 rng(7);
  const std::vector<Triangle> tris = RandomTriangles(rng, 3000);
  std::uniform_real_distribution<double> coord(-12, 12), unit(-1, 1), weight(0, 1);
  for (const Point& dir :
       {Point(0.5773, 0.5774, 0.5775), Point(0.1, -0.9, 0.4243), Point(1, 0, 0), Point(0, 0, -1)}) {
    const Point d = dir / dir.Norm();
    const ProjectedFaceGrid grid(
        tris.size(), [&](std::size_t i) { return tris[i]; }, d);
    std::size_t met = 0;
    for (int q = 0; q < 4000; ++q) {
      // Origins anywhere, and on triangles' vertices and edges (grazing rays), behind them.
      Point origin(coord(rng), coord(rng), coord(rng));
      if (q % 2 == 1) {
        const Triangle& t = tris[std::size_t(weight(rng) * double(tris.size() - 1))];
        const double w = q % 4 == 1 ? 0.0 : weight(rng);
        origin = t[0] * (1 - w) + t[1] * w - d * (1 + 3 * weight(rng));
      }
      const auto range = grid.Candidates(origin);
      const std::vector<std::uint32_t> candidates(range.first, range.second);
      EXPECT_TRUE(std::is_sorted(candidates.begin(), candidates.end()));
      for (std::size_t i = 0; i < tris.size(); ++i) {
        if (!Meets(tris[i], origin, d)) continue;
        ++met;
        EXPECT_TRUE(std::binary_search(candidates.begin(), candidates.end(), std::uint32_t(i)))
            << "triangle " << i << " met by ray " << q << " is not a candidate";
      }
      EXPECT_LE(candidates.size(), tris.size());
    }
    EXPECT_GT(met, 1000u); // the rays do meet triangles, grazing ones included
  }
}

TEST(ProjectedFaceGrid, NoTrianglesNoCandidates) {
  const ProjectedFaceGrid grid(
      0, [](std::size_t) { return Triangle{}; }, Point(0, 0, 1));
  const auto range = grid.Candidates(Point(0, 0, 0));
  EXPECT_EQ(range.first, range.second);
}

} // namespace

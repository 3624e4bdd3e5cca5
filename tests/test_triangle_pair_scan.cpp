// TrianglePairScan against the all-pairs loop it replaces: the verification of a batch of moves
// must see every pair of faces whose boxes touch (one of them moved), whatever the cell size,
// the sorting and the thread count, or an intersection would slip through.
#include <gtest/gtest.h>

#include <vcg_ext/core/float_box.h>
#include <vcg_ext/spatial/triangle_pair_scan.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <utility>
#include <vector>

namespace {

using molremesh::TrianglePairScan;
using Point = vcg::Point3d;
using PairList = std::vector<std::pair<std::uint32_t, std::uint32_t>>;

struct Soup {
  std::vector<Point> vertices;
  std::vector<std::array<std::uint32_t, 3>> faces;
  std::vector<bool> live, moved;
};

/// Triangles on a shared vertex pool (so that many pairs share a vertex): each joins a vertex to
/// two of its nearest ones; 1 % join it to farther ones instead (they set the cell size, so
/// cells hold several triangles), and some are dead.
Soup RandomSoup(unsigned seed, std::size_t vertexCount, std::size_t faceCount) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> coord(0.0, 10.0), unit(0.0, 1.0);
  Soup s;
  for (std::size_t i = 0; i < vertexCount; ++i) s.vertices.emplace_back(coord(rng), coord(rng), coord(rng));
  std::uniform_int_distribution<std::uint32_t> pick(0, std::uint32_t(vertexCount - 1));
  std::vector<std::uint32_t> byDistance(vertexCount);
  for (std::size_t f = 0; f < faceCount; ++f) {
    const std::uint32_t a = pick(rng);
    for (std::uint32_t i = 0; i < vertexCount; ++i) byDistance[i] = i;
    std::sort(byDistance.begin(), byDistance.end(), [&](std::uint32_t x, std::uint32_t y) {
      return (s.vertices[x] - s.vertices[a]).SquaredNorm() < (s.vertices[y] - s.vertices[a]).SquaredNorm();
    });
    const int reach = unit(rng) < 0.01 ? 60 : 8; // byDistance[0] is a itself
    std::uniform_int_distribution<int> near(1, reach);
    const std::uint32_t b = byDistance[std::size_t(near(rng))];
    std::uint32_t c = b;
    while (c == b) c = byDistance[std::size_t(near(rng))];
    s.faces.push_back({a, b, c});
    s.live.push_back(unit(rng) > 0.05);
    s.moved.push_back(unit(rng) > 0.3);
  }
  return s;
}

vcg::Box3d BoxOf(const Soup& s, std::size_t f) {
  vcg::Box3d b;
  for (const std::uint32_t v : s.faces[f]) b.Add(s.vertices[v]);
  return b;
}

bool Touch(const vcg::Box3d& a, const vcg::Box3d& b) {
  for (int k = 0; k < 3; ++k)
    if (a.min[k] > b.max[k] || b.min[k] > a.max[k]) return false;
  return true;
}

bool ShareVertex(const std::array<std::uint32_t, 3>& a, const std::array<std::uint32_t, 3>& b) {
  for (const std::uint32_t x : a)
    if (x == b[0] || x == b[1] || x == b[2]) return true;
  return false;
}

/// The scan with "intersect" = "exact boxes touch": every pair it must consider comes out.
PairList ScanPairs(const Soup& s, int threads, bool skipShared) {
  TrianglePairScan scan;
  scan.Build(
      s.faces.size(), s.vertices.data(),
      [&](std::size_t i, TrianglePairScan::Triangle& t) {
        if (!s.live[i]) return;
        t.live = true;
        t.moved = s.moved[i];
        t.v = s.faces[i];
      },
      threads);
  PairList pairs;
  scan.FindPairs(
      threads,
      [&](std::uint32_t a, std::uint32_t b) {
        EXPECT_EQ(scan.Corners(a)[1], s.vertices[s.faces[a][1]]);
        return Touch(BoxOf(s, a), BoxOf(s, b));
      },
      pairs, skipShared);
  return pairs;
}

PairList BruteForcePairs(const Soup& s, bool skipShared) {
  PairList pairs;
  for (std::uint32_t i = 0; i < s.faces.size(); ++i) {
    if (!s.live[i]) continue;
    const vcg::Box3d bi = BoxOf(s, i);
    for (std::uint32_t j = i + 1; j < s.faces.size(); ++j) {
      if (!s.live[j] || (!s.moved[i] && !s.moved[j])) continue;
      if (skipShared && ShareVertex(s.faces[i], s.faces[j])) continue;
      if (Touch(bi, BoxOf(s, j))) pairs.emplace_back(i, j);
    }
  }
  return pairs;
}

TEST(TrianglePairScan, FindsEveryPairOfTouchingBoxesWithAMovedTriangle) {
  for (const unsigned seed : {1u, 2u, 3u}) {
    const Soup soup = RandomSoup(seed, 1500, 3000);
    for (const bool skipShared : {false, true}) {
      const PairList expected = BruteForcePairs(soup, skipShared);
      ASSERT_GT(expected.size(), 1000u) << "the soup should have many touching pairs";
      for (const int threads : {1, 3}) {
        EXPECT_EQ(ScanPairs(soup, threads, skipShared), expected)
            << "seed " << seed << ", skipShared " << skipShared << ", " << threads << " threads";
      }
    }
  }
}

TEST(TrianglePairScan, NoLiveTriangleGivesNoPair) {
  Soup soup = RandomSoup(4, 50, 100);
  std::fill(soup.live.begin(), soup.live.end(), false);
  EXPECT_TRUE(ScanPairs(soup, 2, true).empty());
}

} // namespace

namespace {

// The boxes of the scan and of the grids are rounded outward by an inline next-float step: it
// must be std::nextafter's, or a box could shrink below the true one and lose a pair.
TEST(FloatBox, OutwardStepsAreNextafter) {
  using molremesh::FloatBox;
  const float inf = std::numeric_limits<float>::infinity();
  std::vector<float> values{0.0f,
                            -0.0f,
                            std::numeric_limits<float>::denorm_min(),
                            -std::numeric_limits<float>::denorm_min(),
                            std::numeric_limits<float>::min(),
                            -std::numeric_limits<float>::min(),
                            std::numeric_limits<float>::max(),
                            -std::numeric_limits<float>::max(),
                            inf,
                            -inf,
                            1.0f,
                            -1.0f};
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> exponent(-40.0, 38.0), sign(-1.0, 1.0);
  for (int i = 0; i < 100000; ++i)
    values.push_back(float((sign(rng) < 0 ? -1.0 : 1.0) * std::pow(10.0, exponent(rng))));
  for (const float x : values) {
    const float down = FloatBox::NextDown(x), up = FloatBox::NextUp(x);
    const float wantDown = std::nextafter(x, -inf), wantUp = std::nextafter(x, inf);
    EXPECT_EQ(std::memcmp(&down, &wantDown, sizeof down), 0) << x;
    EXPECT_EQ(std::memcmp(&up, &wantUp, sizeof up), 0) << x;
  }
  // And a box rounded outward contains the double box.
  std::uniform_real_distribution<double> coord(-1e3, 1e3);
  for (int i = 0; i < 10000; ++i) {
    const vcg::Point3d a(coord(rng), coord(rng), coord(rng)), b(coord(rng), coord(rng), coord(rng));
    vcg::Box3d box;
    box.Add(a);
    box.Add(b);
    const FloatBox f = FloatBox::Outward(box);
    for (int k = 0; k < 3; ++k) {
      EXPECT_LE(double(f.lo[k]), box.min[k]);
      EXPECT_GE(double(f.hi[k]), box.max[k]);
    }
  }
}

} // namespace

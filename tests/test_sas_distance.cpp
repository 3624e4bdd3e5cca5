// SasBoundaryDistance: the depth of a point inside the solvent-accessible surface against the
// nearest of many points sampled on the exposed parts of the spheres (so the sphere patches, the
// crease circles where two spheres meet and the corners where three meet are all met).
#include <gtest/gtest.h>

#include <vcg_ext/volume/sas_distance.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

using namespace molremesh;

namespace {

Atom MakeAtom(const Point& p, double r) {
  Atom a;
  a.position = p;
  a.radius = r;
  return a;
}

/// The exposed points among n Fibonacci points on each sphere (radius r + probe).
std::vector<Point> ExposedSamples(const std::vector<Atom>& atoms, double probe, int n) {
  std::vector<Point> exposed;
  const double golden = 3.14159265358979323846 * (3.0 - std::sqrt(5.0));
  for (std::size_t i = 0; i < atoms.size(); ++i) {
    const double r = atoms[i].radius + probe;
    for (int k = 0; k < n; ++k) {
      const double z = 1.0 - 2.0 * (k + 0.5) / n, s = std::sqrt(1.0 - z * z), phi = golden * k;
      const Point y = atoms[i].position + Point(s * std::cos(phi), s * std::sin(phi), z) * r;
      bool buried = false;
      for (std::size_t j = 0; j < atoms.size() && !buried; ++j)
        buried = j != i && (y - atoms[j].position).Norm() < atoms[j].radius + probe;
      if (!buried) exposed.push_back(y);
    }
  }
  return exposed;
}

double NearestSample(const std::vector<Point>& samples, const Point& x) {
  double best = 1e300;
  for (const Point& y : samples) best = std::min(best, (y - x).Norm());
  return best;
}

TEST(SasBoundaryDistance, OneSphereIsItsRadiusLessTheDistanceFromTheCentre) {
  const SasBoundaryDistance depth({MakeAtom(Point(1, 2, 3), 1.5)}, 1.4, 3.0);
  Point gradient;
  EXPECT_NEAR(depth(Point(1.5, 2, 3), gradient), -(2.9 - 0.5), 1e-12);
  EXPECT_NEAR(gradient[0], 1.0, 1e-12);                                 // towards the nearest boundary point
  EXPECT_NEAR(depth(Point(5.4, 2, 3), gradient), 5.4 - 1 - 2.9, 1e-12); // outside: the ball distance
}

TEST(SasBoundaryDistance, TwoSpheresAtTheirCreaseCircle) {
  // Under the crease (on the axis, beside the radical plane) the nearest boundary point is on
  // the circle where the spheres meet, not on either sphere.
  const std::vector<Atom> atoms{MakeAtom(Point(0, 0, 0), 1.8), MakeAtom(Point(3.6, 0, 0), 1.6)};
  const double R1 = 3.2, R2 = 3.0, d = 3.6, along = (d * d + R1 * R1 - R2 * R2) / (2 * d);
  const double rho = std::sqrt(R1 * R1 - along * along);
  const SasBoundaryDistance depth(atoms, 1.4, 3.0);
  Point gradient;
  const Point x(along + 0.1, 0.5, 0);
  EXPECT_NEAR(depth(x, gradient), -std::sqrt(0.1 * 0.1 + (rho - 0.5) * (rho - 0.5)), 1e-12);
}

TEST(SasBoundaryDistance, ThreeSpheresUnderTheCornerWhereTheyMeet) {
  // Three equal spheres on an equilateral triangle meet at two corners on its axis; just below
  // the upper one, the nearest points of the three creases are buried in the third sphere.
  const double side = 4.0, R = 3.0, circumradius = side / std::sqrt(3.0);
  std::vector<Atom> atoms;
  for (int k = 0; k < 3; ++k) {
    const double angle = 2.0943951023931957 * k;
    atoms.push_back(
        MakeAtom(Point(circumradius * std::cos(angle), circumradius * std::sin(angle), 0), R - 1.4));
  }
  const double corner = std::sqrt(R * R - circumradius * circumradius);
  const SasBoundaryDistance depth(atoms, 1.4, 3.0);
  Point gradient;
  EXPECT_NEAR(depth(Point(0, 0, corner - 0.5), gradient), -0.5, 1e-12);
  EXPECT_NEAR(gradient[2], 1.0, 1e-12);
  EXPECT_NEAR(NearestSample(ExposedSamples(atoms, 1.4, 40000), Point(0, 0, corner - 0.5)), 0.5, 0.08);
}

TEST(SasBoundaryDistance, MatchesTheNearestExposedSampleInsideRandomClusters) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> coordinate(-2.5, 2.5), radius(1.0, 2.0);
  for (int cluster = 0; cluster < 6; ++cluster) {
    std::vector<Atom> atoms;
    for (int i = 0; i < 7; ++i)
      atoms.push_back(
          MakeAtom(Point(coordinate(random), coordinate(random), coordinate(random)), radius(random)));
    const double probe = 1.4, reach = 2.0;
    const std::vector<Point> samples = ExposedSamples(atoms, probe, 40000);
    const SasBoundaryDistance depth(atoms, probe, reach);
    std::uniform_real_distribution<double> inside(-4.0, 4.0);
    int tested = 0;
    for (int k = 0; k < 400; ++k) {
      const Point x(inside(random), inside(random), inside(random));
      Point gradient;
      const double value = depth(x, gradient);
      if (!(value < 0) || -value >= reach) continue; // outside, or deeper than the exact range
      ++tested;
      const double sampled = NearestSample(samples, x);
      // Exact never above the samples (they are boundary points), and within their spacing
      // (0.06 Å apart on a 3.4 Å sphere at 40000 points, sparser at a corner) of them.
      EXPECT_LE(-value, sampled + 1e-9) << "cluster " << cluster;
      EXPECT_GE(-value, sampled - 0.08) << "cluster " << cluster;
      // The gradient points at a boundary point at that distance.
      const Point y = x + gradient * -value;
      EXPECT_NEAR(NearestSample(samples, y), 0.0, 0.08);
    }
    EXPECT_GT(tested, 40) << "cluster " << cluster;
  }
}

} // namespace

// Distance between two triangulated surfaces: one-sided (A to B) and symmetric Hausdorff.
//
// SurfaceDistance<MeshA, MeshB> measures how far the surface of A is from the surface of B, as
// Metro (Cignoni, Rocchini, Scopigno 1998, "Metro: measuring error on simplified surfaces") does:
// the distance of a point to B is its distance to the closest point of B's faces (interior,
// edges or corners), and the one-sided distance A -> B is taken over a sample of A made of its
// vertices plus area-uniform random points on its faces. The symmetric Hausdorff distance is the
// larger of A -> B and B -> A. Any vcg triangle mesh works (float or double coordinates, no
// adjacency, no optional component needed); everything is computed in double precision, and
// neither mesh is modified.
//
// Conventions (the figures depend on them):
//  - Deleted vertices and faces are skipped. B's surface is its live faces whose three corners
//    are finite; zero-area faces count as their segments / points.
//  - A's vertex samples are the live, finite vertices referenced by a live face. When A has no
//    face at all (a point cloud), every live finite vertex is a sample instead.
//  - A's face samples are area-uniform over the live faces with finite corners, drawn from a
//    generator seeded with Params::seed: the same inputs and parameters always give the same
//    figures, whatever the number of threads.
//
// Closest points are found with a uniform grid over B's faces (each face registered in every cell
// its bounding box overlaps) searched in growing shells of cells around the query, pruning cells
// farther than the best distance so far; the search is exact, not approximate.
#pragma once

#include <vcg/complex/complex.h>

#include <vcg_ext/core/index.h>
#include <vcg_ext/core/parallel_for.h>
#include <vcg_ext/geometry/point.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <thread>
#include <vector>

namespace molremesh {

/// Distance from a sampled surface A to a surface B. All distances are in the meshes' units.
struct OneSidedDistance {
  bool ok = false;               ///< false when B has no usable face or A has no sample; figures are then 0
  std::string message;           ///< why ok is false
  std::size_t vertexSamples = 0; ///< A's vertices measured
  std::size_t faceSamples = 0;   ///< area-uniform points of A's faces measured
  double max = 0;                ///< largest distance over all samples (the one-sided Hausdorff distance)
  double mean = 0;               ///< mean over all samples (vertices and face samples alike)
  double rms = 0;                ///< root mean square over all samples
  double vertexMax = 0;          ///< largest distance of A's vertices to B
  double vertexMean = 0;         ///< mean distance of A's vertices to B
  double faceMax = 0;            ///< largest distance of the face samples to B
  double faceMean = 0;           ///< mean over the face samples: the area-weighted mean distance of A to B
  vcg::Point3d maxAt{0, 0, 0};   ///< the sample of A where max is reached (the first one on ties)
};

/// Distances both ways and their maximum.
struct SymmetricDistance {
  bool ok = false;
  std::string message;
  OneSidedDistance aToB, bToA;
  double hausdorff = 0; ///< max(aToB.max, bToA.max)
};

namespace distance_detail {

/// Squared distance of p to the closed segment ab (a == b allowed).
inline double SegmentDistance2(const Point& p, const Point& a, const Point& b, Point& closest) {
  const Point ab = b - a;
  const double len2 = ab.SquaredNorm();
  double t = len2 > 0 ? ((p - a) * ab) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  closest = a + ab * t;
  return (p - closest).SquaredNorm();
}

/// Squared distance of p to the closed triangle abc, and the closest point (Ericson, "Real-Time
/// Collision Detection", 5.1.5: Voronoi regions of the corners, edges and interior). Triangles
/// too thin for the barycentric solve are measured as their three segments.
inline double TriangleDistance2(const Point& p, const Point& a, const Point& b, const Point& c,
                                Point& closest) {
  const Point ab = b - a, ac = c - a, ap = p - a;
  const double abLen2 = ab.SquaredNorm(), acLen2 = ac.SquaredNorm(), bcLen2 = (c - b).SquaredNorm();
  const double cross2 = (ab ^ ac).SquaredNorm();
  const double longest2 = std::max({abLen2, acLen2, bcLen2});
  if (!(cross2 > 1e-24 * longest2 * longest2)) {
    Point q;
    double best = SegmentDistance2(p, a, b, closest);
    double d = SegmentDistance2(p, b, c, q);
    if (d < best) best = d, closest = q;
    d = SegmentDistance2(p, c, a, q);
    if (d < best) best = d, closest = q;
    return best;
  }
  const double d1 = ab * ap, d2 = ac * ap;
  if (d1 <= 0 && d2 <= 0) return (p - (closest = a)).SquaredNorm();
  const Point bp = p - b;
  const double d3 = ab * bp, d4 = ac * bp;
  if (d3 >= 0 && d4 <= d3) return (p - (closest = b)).SquaredNorm();
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    closest = a + ab * (d1 / (d1 - d3));
    return (p - closest).SquaredNorm();
  }
  const Point cp = p - c;
  const double d5 = ab * cp, d6 = ac * cp;
  if (d6 >= 0 && d5 <= d6) return (p - (closest = c)).SquaredNorm();
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    closest = a + ac * (d2 / (d2 - d6));
    return (p - closest).SquaredNorm();
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    closest = b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    return (p - closest).SquaredNorm();
  }
  const double denom = 1.0 / (va + vb + vc);
  closest = a + ab * (vb * denom) + ac * (vc * denom);
  return (p - closest).SquaredNorm();
}

/// A triangle soup in double precision with a uniform grid for exact closest-point queries.
///
/// One of the project's face grids, each kept for what it is asked: FaceHashGrid
/// (spatial/face_hash_grid.h) is dynamic, updated per local edit, and stores float boxes that may
/// report a few extra faces; TrianglePairScan (spatial/triangle_pair_scan.h) sorts all triangles
/// once to find intersecting pairs of moved faces; FindSelfIntersections
/// (spatial/self_intersections.h) hashes cells by wrapped keys for an all-pairs test. This one is
/// static, double precision and answers nearest-point queries, searching rings of cells outward;
/// its candidates and their order feed the distances, so it is not merged with the others.
/// Build once, then query from any number of threads (each with its own QueryScratch).
class TriangleGrid {
public:
  /// Per-thread scratch: remembers which faces the current query has already measured.
  struct QueryScratch {
    std::vector<std::uint32_t> stamp;
    std::uint32_t current = 0;
  };

  /// Result of one query. face is an index into the triangles given to Build (or -1 when empty).
  struct Hit {
    double distance = std::numeric_limits<double>::infinity();
    long long face = -1;
    Point closest{0, 0, 0};
  };

  /// Builds the grid over tris (indices into points; every corner must be finite), the per-face
  /// work on `threads` threads (the grid is the same for any count).
  void Build(std::vector<Point> points, std::vector<std::array<Index, 3>> tris, int threads = 1) {
    points_ = std::move(points);
    tris_ = std::move(tris);
    cellStart_.clear();
    cellFaces_.clear();
    if (tris_.empty()) return;
    const std::size_t n = tris_.size();
    threads = ResolveThreadCount(threads);

    // Bounding box (a min / max: the same for any split) and the side lengths, summed in face
    // order afterwards so that the mean edge, hence the cell size, never depends on the threads.
    std::vector<double> sides(3 * n);
    std::vector<vcg::Box3d> boxes(static_cast<std::size_t>(threads));
    ParallelFor(n, threads, [&](std::size_t begin, std::size_t end, int t) {
      for (std::size_t f = begin; f < end; ++f) {
        const auto& tri = tris_[f];
        for (int i = 0; i < 3; ++i) {
          boxes[std::size_t(t)].Add(points_[tri[i]]);
          sides[3 * f + std::size_t(i)] = (points_[tri[i]] - points_[tri[(i + 1) % 3]]).Norm();
        }
      }
    });
    vcg::Box3d box;
    for (const vcg::Box3d& b : boxes)
      if (!b.IsNull()) box.Add(b);
    double edgeSum = 0;
    for (const double side : sides) edgeSum += side;
    const double meanEdge = edgeSum / (3.0 * double(n));
    const double diag = box.Diag();
    // Cells about twice the mean edge long hold a handful of faces each on a surface; fewer
    // cells than ~8 per face keep memory linear when a few huge faces stretch the box.
    double cell = std::max({2.0 * meanEdge, diag * 1e-6, 1e-300});
    const double maxCells = std::max(8.0 * double(n), 4096.0);
    auto countCells = [&](double size) {
      double count = 1;
      for (int a = 0; a < 3; ++a) count *= std::floor(box.Dim()[a] / size) + 1;
      return count;
    };
    while (countCells(cell) > maxCells) cell *= 1.25;
    cellSize_ = cell;
    origin_ = box.min;
    for (int a = 0; a < 3; ++a) dims_[a] = int(std::floor(box.Dim()[a] / cell)) + 1;

    // Counting sort of (cell, face) pairs into CSR arrays: deterministic and compact. The cell
    // ranges are found on all threads, the counting and filling run in face order.
    const std::size_t cellCount = std::size_t(dims_[0]) * dims_[1] * dims_[2];
    std::vector<std::array<int, 6>> range(n);
    ParallelFor(n, threads, [&](std::size_t begin, std::size_t end, int) {
      for (std::size_t f = begin; f < end; ++f) {
        const auto& t = tris_[f];
        for (int a = 0; a < 3; ++a) {
          const double mn = std::min({points_[t[0]][a], points_[t[1]][a], points_[t[2]][a]});
          const double mx = std::max({points_[t[0]][a], points_[t[1]][a], points_[t[2]][a]});
          range[f][a] = CellCoord(mn, a);
          range[f][a + 3] = CellCoord(mx, a);
        }
      }
    });
    auto forEachCell = [&](const std::array<int, 6>& r, auto&& visit) {
      for (int z = r[2]; z <= r[5]; ++z)
        for (int y = r[1]; y <= r[4]; ++y)
          for (int x = r[0]; x <= r[3]; ++x) visit(CellId(x, y, z));
    };
    cellStart_.assign(cellCount + 1, 0);
    for (const auto& r : range) forEachCell(r, [&](std::size_t id) { ++cellStart_[id + 1]; });
    for (std::size_t i = 0; i < cellCount; ++i) cellStart_[i + 1] += cellStart_[i];
    cellFaces_.resize(cellStart_[cellCount]);
    std::vector<std::size_t> fill(cellStart_.begin(), cellStart_.end() - 1);
    for (std::size_t f = 0; f < n; ++f)
      forEachCell(range[f], [&](std::size_t id) { cellFaces_[fill[id]++] = Index(f); });
  }

  bool Empty() const { return tris_.empty(); }
  std::size_t FaceCount() const { return tris_.size(); }

  /// Exact closest point of the triangles to p.
  Hit Closest(const Point& p, QueryScratch& scratch) const {
    Hit hit;
    if (tris_.empty()) return hit;
    if (scratch.stamp.size() != tris_.size()) {
      scratch.stamp.assign(tris_.size(), 0);
      scratch.current = 0;
    }
    if (++scratch.current == 0) { // wrapped around: reset the stamps
      std::fill(scratch.stamp.begin(), scratch.stamp.end(), 0);
      scratch.current = 1;
    }
    std::array<int, 3> c;
    for (int a = 0; a < 3; ++a) c[a] = CellCoord(p[a], a);
    double best2 = std::numeric_limits<double>::infinity();
    const int maxRing = std::max({dims_[0], dims_[1], dims_[2]});
    for (int r = 0; r <= maxRing; ++r) {
      const int z0 = std::max(c[2] - r, 0), z1 = std::min(c[2] + r, dims_[2] - 1);
      const int y0 = std::max(c[1] - r, 0), y1 = std::min(c[1] + r, dims_[1] - 1);
      const int x0 = std::max(c[0] - r, 0), x1 = std::min(c[0] + r, dims_[0] - 1);
      for (int z = z0; z <= z1; ++z)
        for (int y = y0; y <= y1; ++y) {
          const bool fullRow = std::abs(z - c[2]) == r || std::abs(y - c[1]) == r;
          const int step = fullRow ? 1 : 2 * r;
          for (int x = fullRow ? x0 : c[0] - r; x <= x1; x += std::max(step, 1)) {
            if (x < x0) continue;
            VisitCell(x, y, z, p, best2, hit, scratch);
          }
        }
      // Everything not searched yet lies beyond one of the faces of the searched block that is
      // not on the grid's border; stop when the best distance is no farther than all of them.
      double unsearched = std::numeric_limits<double>::infinity();
      for (int a = 0; a < 3; ++a) {
        if (c[a] - r > 0) unsearched = std::min(unsearched, p[a] - (origin_[a] + (c[a] - r) * cellSize_));
        if (c[a] + r < dims_[a] - 1)
          unsearched = std::min(unsearched, origin_[a] + (c[a] + r + 1) * cellSize_ - p[a]);
      }
      if (unsearched == std::numeric_limits<double>::infinity()) break; // the whole grid was searched
      if (best2 <= unsearched * unsearched && unsearched >= 0) break;
    }
    hit.distance = std::sqrt(best2);
    return hit;
  }

private:
  int CellCoord(double x, int axis) const {
    const double t = std::floor((x - origin_[axis]) / cellSize_);
    if (!(t > 0)) return 0; // also NaN
    return int(std::min(t, double(dims_[axis] - 1)));
  }
  std::size_t CellId(int x, int y, int z) const { return (std::size_t(z) * dims_[1] + y) * dims_[0] + x; }

  void VisitCell(int x, int y, int z, const Point& p, double& best2, Hit& hit, QueryScratch& scratch) const {
    const std::size_t id = CellId(x, y, z);
    const std::size_t begin = cellStart_[id], end = cellStart_[id + 1];
    if (begin == end) return;
    // Skip the cell when its box is no closer than the best face found so far.
    double box2 = 0;
    const std::array<int, 3> xyz{x, y, z};
    for (int a = 0; a < 3; ++a) {
      const double lo = origin_[a] + xyz[a] * cellSize_, hi = lo + cellSize_;
      const double d = p[a] < lo ? lo - p[a] : (p[a] > hi ? p[a] - hi : 0.0);
      box2 += d * d;
    }
    if (box2 >= best2) return;
    for (std::size_t k = begin; k < end; ++k) {
      const Index f = cellFaces_[k];
      if (scratch.stamp[f] == scratch.current) continue;
      scratch.stamp[f] = scratch.current;
      const auto& t = tris_[f];
      Point q;
      const double d2 = TriangleDistance2(p, points_[t[0]], points_[t[1]], points_[t[2]], q);
      if (d2 < best2) {
        best2 = d2;
        hit.face = f;
        hit.closest = q;
      }
    }
  }

  std::vector<Point> points_;
  std::vector<std::array<Index, 3>> tris_;
  Point origin_{0, 0, 0};
  double cellSize_ = 1;
  std::array<int, 3> dims_{1, 1, 1};
  std::vector<std::size_t>
      cellStart_; ///< CSR: faces of cell i are cellFaces_[cellStart_[i] .. cellStart_[i+1])
  std::vector<Index> cellFaces_;
};

/// The live faces of m with three finite corners, as a triangle soup over m's vertex indices.
/// Vertex indices are those of m.vert; points holds every vertex (non-finite ones included).
template <class MeshType>
void ExtractTriangles(const MeshType& m, std::vector<Point>& points,
                      std::vector<std::array<Index, 3>>& tris) {
  points.resize(m.vert.size());
  for (std::size_t v = 0; v < m.vert.size(); ++v) points[v] = PositionOf(&m.vert[v]);
  tris.clear();
  if (m.vert.empty()) return;
  tris.reserve(m.face.size());
  for (const auto& f : m.face) {
    if (f.IsD()) continue;
    std::array<Index, 3> t;
    bool usable = true;
    for (int i = 0; i < 3 && usable; ++i) {
      const auto* v = f.cV(i);
      usable = v != nullptr && v >= &m.vert.front() && v <= &m.vert.back() && !v->IsD();
      if (usable) {
        t[i] = Index(v - &m.vert.front());
        usable = IsFinite(points[t[i]]);
      }
    }
    if (usable) tris.push_back(t);
  }
}

/// Deterministic 64-bit generator (SplitMix64) and doubles in [0, 1) from its top 53 bits: the
/// sample positions do not depend on the standard library's distributions.
class SampleRandom {
public:
  explicit SampleRandom(std::uint64_t seed) : state_(seed) {}
  std::uint64_t Next() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double Uniform() { return double(Next() >> 11) * (1.0 / 9007199254740992.0); }

private:
  std::uint64_t state_;
};

/// Distances of every query point to the grid, computed on `threads` threads.
inline std::vector<double> DistancesTo(const TriangleGrid& grid, const std::vector<Point>& queries,
                                       unsigned threads) {
  std::vector<double> out(queries.size(), 0.0);
  threads = std::max(1u, std::min<unsigned>(threads, unsigned(queries.size() / 1024 + 1)));
  auto work = [&](std::size_t begin, std::size_t end) {
    TriangleGrid::QueryScratch scratch;
    for (std::size_t i = begin; i < end; ++i) out[i] = grid.Closest(queries[i], scratch).distance;
  };
  if (threads == 1) {
    work(0, queries.size());
    return out;
  }
  std::vector<std::thread> pool;
  const std::size_t chunk = (queries.size() + threads - 1) / threads;
  for (unsigned t = 0; t < threads; ++t) {
    const std::size_t begin = std::min(queries.size(), t * chunk),
                      end = std::min(queries.size(), begin + chunk);
    pool.emplace_back(work, begin, end);
  }
  for (auto& th : pool) th.join();
  return out;
}

} // namespace distance_detail

template <class MeshA, class MeshB>
class SurfaceDistance {
public:
  struct Params {
    std::size_t faceSamples = 0; ///< area-uniform points drawn on A's faces; 0 = as many as A has faces
    std::uint64_t seed = 1;      ///< seed of the face sampling (same seed, same samples)
    unsigned threads = 1;        ///< threads for the closest-point queries (results do not depend on it)
  };

  /// Distance from A to B: max, mean and RMS over A's vertices plus Params::faceSamples
  /// area-uniform points on A's faces. ok is false (with a message) when B has no face with
  /// finite corners or A has nothing to sample.
  static OneSidedDistance OneSided(const MeshA& a, const MeshB& b, const Params& params = Params());

  /// Both one-sided distances and the symmetric Hausdorff distance max(A->B, B->A). The face
  /// samples of B use the same count rule as A's (0 = as many as B has faces) and seed + 1.
  static SymmetricDistance Symmetric(const MeshA& a, const MeshB& b, const Params& params = Params());

  /// Distance of each vertex of A to B, indexed like a.vert. Deleted and non-finite vertices get
  /// NaN; unreferenced ones are measured too. Empty when B has no usable face.
  static std::vector<double> VertexDistances(const MeshA& a, const MeshB& b, unsigned threads = 1);
};

// ------------------------------------------------------------------------------------------------
// Implementation
// ------------------------------------------------------------------------------------------------

template <class MeshA, class MeshB>
OneSidedDistance SurfaceDistance<MeshA, MeshB>::OneSided(const MeshA& a, const MeshB& b,
                                                         const Params& params) {
  using namespace distance_detail;
  OneSidedDistance result;

  std::vector<Point> bPoints;
  std::vector<std::array<Index, 3>> bTris;
  ExtractTriangles(b, bPoints, bTris);
  if (bTris.empty()) {
    result.message = "the second mesh has no face with finite corners";
    return result;
  }
  TriangleGrid grid;
  grid.Build(std::move(bPoints), std::move(bTris), int(std::max(1u, params.threads)));

  std::vector<Point> aPoints;
  std::vector<std::array<Index, 3>> aTris;
  ExtractTriangles(a, aPoints, aTris);

  // Vertex samples: referenced live finite vertices (every live finite one for a point cloud).
  std::vector<Point> queries;
  {
    std::vector<bool> use(a.vert.size(), aTris.empty());
    for (const auto& t : aTris)
      for (Index v : t) use[v] = true;
    for (std::size_t v = 0; v < a.vert.size(); ++v)
      if (use[v] && !a.vert[v].IsD() && IsFinite(aPoints[v])) queries.push_back(aPoints[v]);
  }
  result.vertexSamples = queries.size();

  // Face samples: pick a face with probability proportional to its area, then a uniform point
  // in it (square-root parametrisation of the barycentric coordinates).
  const std::size_t wanted = params.faceSamples > 0 ? params.faceSamples : aTris.size();
  std::vector<double> cumulativeArea;
  cumulativeArea.reserve(aTris.size());
  double total = 0;
  for (const auto& t : aTris) {
    total += 0.5 * ((aPoints[t[1]] - aPoints[t[0]]) ^ (aPoints[t[2]] - aPoints[t[0]])).Norm();
    cumulativeArea.push_back(total);
  }
  if (total > 0 && std::isfinite(total)) {
    SampleRandom random(params.seed);
    queries.reserve(queries.size() + wanted);
    for (std::size_t s = 0; s < wanted; ++s) {
      const double pick = random.Uniform() * total;
      std::size_t f = std::size_t(std::upper_bound(cumulativeArea.begin(), cumulativeArea.end(), pick) -
                                  cumulativeArea.begin());
      f = std::min(f, aTris.size() - 1);
      const double r1 = std::sqrt(random.Uniform()), r2 = random.Uniform();
      const auto& t = aTris[f];
      queries.push_back(aPoints[t[0]] * (1.0 - r1) + aPoints[t[1]] * (r1 * (1.0 - r2)) +
                        aPoints[t[2]] * (r1 * r2));
    }
    result.faceSamples = wanted;
  }
  if (queries.empty()) {
    result.message = "the first mesh has no finite vertex to measure";
    return result;
  }

  const std::vector<double> d = DistancesTo(grid, queries, params.threads);
  double sum = 0, sum2 = 0, vertexSum = 0, faceSum = 0;
  for (std::size_t i = 0; i < d.size(); ++i) {
    sum += d[i];
    sum2 += d[i] * d[i];
    if (d[i] > result.max) {
      result.max = d[i];
      result.maxAt = queries[i];
    }
    if (i < result.vertexSamples) {
      vertexSum += d[i];
      result.vertexMax = std::max(result.vertexMax, d[i]);
    } else {
      faceSum += d[i];
      result.faceMax = std::max(result.faceMax, d[i]);
    }
  }
  const double n = double(d.size());
  result.mean = sum / n;
  result.rms = std::sqrt(sum2 / n);
  if (result.vertexSamples > 0) result.vertexMean = vertexSum / double(result.vertexSamples);
  if (result.faceSamples > 0) result.faceMean = faceSum / double(result.faceSamples);
  result.ok = true;
  return result;
}

template <class MeshA, class MeshB>
SymmetricDistance SurfaceDistance<MeshA, MeshB>::Symmetric(const MeshA& a, const MeshB& b,
                                                           const Params& params) {
  SymmetricDistance result;
  result.aToB = OneSided(a, b, params);
  typename SurfaceDistance<MeshB, MeshA>::Params reverse;
  reverse.faceSamples = params.faceSamples;
  reverse.seed = params.seed + 1;
  reverse.threads = params.threads;
  result.bToA = SurfaceDistance<MeshB, MeshA>::OneSided(b, a, reverse);
  result.ok = result.aToB.ok && result.bToA.ok;
  if (!result.aToB.ok)
    result.message = "A to B: " + result.aToB.message;
  else if (!result.bToA.ok)
    result.message = "B to A: " + result.bToA.message;
  if (result.ok) result.hausdorff = std::max(result.aToB.max, result.bToA.max);
  return result;
}

template <class MeshA, class MeshB>
std::vector<double> SurfaceDistance<MeshA, MeshB>::VertexDistances(const MeshA& a, const MeshB& b,
                                                                   unsigned threads) {
  using namespace distance_detail;
  std::vector<Point> bPoints;
  std::vector<std::array<Index, 3>> bTris;
  ExtractTriangles(b, bPoints, bTris);
  if (bTris.empty()) return {};
  TriangleGrid grid;
  grid.Build(std::move(bPoints), std::move(bTris), int(std::max(1u, threads)));
  std::vector<Point> queries;
  std::vector<std::size_t> where;
  for (std::size_t v = 0; v < a.vert.size(); ++v) {
    const Point p = PositionOf(&a.vert[v]);
    if (a.vert[v].IsD() || !IsFinite(p)) continue;
    queries.push_back(p);
    where.push_back(v);
  }
  const std::vector<double> d = DistancesTo(grid, queries, threads);
  std::vector<double> out(a.vert.size(), std::numeric_limits<double>::quiet_NaN());
  for (std::size_t i = 0; i < d.size(); ++i) out[where[i]] = d[i];
  return out;
}

} // namespace molremesh

// Every intersecting pair among a set of triangles given by vertex indices: the self-intersection
// figure of the quality report and the tangle search of the cleaning stage.
#pragma once

#include <vcg/space/box3.h>

#include <vcg_ext/core/index.h>
#include <vcg_ext/core/parallel_for.h>
#include <vcg_ext/geometry/point.h>
#include <vcg_ext/geometry/triangle_intersection.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

namespace molremesh {

/// Closed box overlap (vcg::Box3::Collide is strict, which misses flat axis-aligned faces).
inline bool BoxesTouch(const vcg::Box3d& a, const vcg::Box3d& b) {
  for (int k = 0; k < 3; ++k)
    if (a.max[k] < b.min[k] || b.max[k] < a.min[k]) return false;
  return true;
}

struct IntersectionCounts {
  std::size_t disjointPairs = 0; ///< pairs sharing no vertex that intersect
  std::size_t adjacentPairs = 0; ///< pairs sharing one vertex that also meet elsewhere
  std::size_t faces = 0;         ///< faces in at least one such pair
};

/// An intersecting pair found by FindSelfIntersections: triangles i and j (i != j, in no
/// particular order), sharing one vertex (adjacent) or none.
struct IntersectingPair {
  Index i, j;
  bool adjacent;
};

namespace self_intersection_detail {

constexpr double kMaxSpan = 512; // cells a hashed face may cover
constexpr int kAxisBits = 21;    // 3 * 21 bits of cell key
constexpr std::int64_t kAxisMask = (std::int64_t(1) << kAxisBits) - 1;

/// Key of cell (x, y, z), each coordinate wrapped to kAxisBits bits; z is the most significant.
inline std::uint64_t WrappedKey(std::int64_t x, std::int64_t y, std::int64_t z) {
  return (std::uint64_t(z & kAxisMask) << (2 * kAxisBits)) | (std::uint64_t(y & kAxisMask) << kAxisBits) |
         std::uint64_t(x & kAxisMask);
}

/// The broad-phase grid: its cell size and the cells of every face.
struct FaceCells {
  double cell = 0;
  std::vector<std::array<std::int64_t, 3>> low; ///< lowest cell of each face, unwrapped
  std::vector<std::array<std::int64_t, 3>> high;
  std::vector<std::uint64_t> cellCount; ///< cells a face is hashed into: 0 when oversized
  std::vector<Index> oversized;
  std::uint64_t entries = 0; ///< sum of cellCount

  /// Calls visit(key) for every cell of (hashed) face i, z slowest.
  template <class Visit>
  void ForEachCell(std::size_t i, Visit&& visit) const {
    for (std::int64_t z = low[i][2]; z <= high[i][2]; ++z)
      for (std::int64_t y = low[i][1]; y <= high[i][1]; ++y)
        for (std::int64_t x = low[i][0]; x <= high[i][0]; ++x) visit(WrappedKey(x, y, z));
  }
};

/// Cell size and cell ranges: cells two median edge lengths wide, doubled while the hashed
/// entries plus the tests of the oversized faces exceed the budget.
inline FaceCells AssignCells(const std::vector<vcg::Box3d>& boxes, const vcg::Box3d& all, double medianEdge,
                             int threads) {
  const std::size_t n = boxes.size();
  const double maxExtent = std::max({all.DimX(), all.DimY(), all.DimZ()});
  FaceCells c;
  c.cell = 2.0 * medianEdge;
  if (!(c.cell > 0) || !std::isfinite(c.cell)) c.cell = maxExtent > 0 ? maxExtent : 1.0;
  const std::uint64_t budget = 32 * std::uint64_t(n) + (std::uint64_t(1) << 20);
  c.low.resize(n);
  c.high.resize(n);
  c.cellCount.resize(n);
  for (;;) {
    c.entries = 0;
    c.oversized.clear();
    // Cell coordinates must stay far inside int64.
    const bool fits = maxExtent / c.cell < 1e15;
    if (fits) {
      const double cell = c.cell;
      ParallelFor(n, threads, [&](std::size_t begin, std::size_t end, int) {
        for (std::size_t i = begin; i < end; ++i) {
          double span = 1;
          for (int a = 0; a < 3; ++a) {
            c.low[i][a] = std::int64_t(std::floor((boxes[i].min[a] - all.min[a]) / cell));
            c.high[i][a] = std::int64_t(std::floor((boxes[i].max[a] - all.min[a]) / cell));
            span *= double(c.high[i][a] - c.low[i][a] + 1);
          }
          c.cellCount[i] = span > kMaxSpan ? 0 : std::uint64_t(span);
        }
      });
      for (std::size_t i = 0; i < n; ++i) {
        if (c.cellCount[i] == 0) c.oversized.push_back(Index(i));
        c.entries += c.cellCount[i];
      }
    }
    if (fits && c.entries + std::uint64_t(c.oversized.size()) * n <= budget) break;
    c.cell *= 2.0;
  }
  return c;
}

/// The exact test of one candidate pair, after a box check; appends the pair to `out` when it
/// intersects (`adjacent` tells the kind).
struct PairTest {
  const std::vector<std::array<Index, 3>>& tris;
  const std::vector<vcg::Box3d>& boxes;
  const std::vector<PlanarTriangle>& planar;
  bool duplicatesIntersect;

  void operator()(Index i, Index j, std::vector<IntersectingPair>& out) const {
    if (!BoxesTouch(boxes[i], boxes[j])) return;
    int shared = 0, ci = -1, cj = -1;
    for (int u = 0; u < 3; ++u)
      for (int w = 0; w < 3; ++w)
        if (tris[i][u] == tris[j][w]) ++shared, ci = u, cj = w;
    if (shared == 3 && duplicatesIntersect) out.push_back({i, j, true});
    if (shared > 1) return;
    if (shared == 0 && TrianglesIntersect(planar[i], planar[j])) {
      out.push_back({i, j, false});
    } else if (shared == 1 && SharedCornerOverlap(planar[i], ci, planar[j], cj)) {
      out.push_back({i, j, true});
    }
  }
};

/// Oversized faces against everything (each oversized pair once, from its lower index).
inline void TestOversized(const FaceCells& cells, const PairTest& test, int threads,
                          std::vector<std::vector<IntersectingPair>>& hits) {
  const std::size_t n = cells.cellCount.size();
  for (Index o : cells.oversized)
    ParallelFor(n, threads, [&](std::size_t begin, std::size_t end, int thread) {
      for (std::size_t j = begin; j < end; ++j)
        if (j != o && (cells.cellCount[j] != 0 || j > o)) test(o, Index(j), hits[thread]);
    });
}

/// Hashed faces: (wrapped cell key, face) entries, sorted so that each cell's faces are
/// contiguous and ascending. Rather than one sort of millions of entries, a counting sort deals
/// them into buckets, slabs of z (the key's most significant part), and each bucket, small enough
/// to stay in cache, is sorted on its own, in parallel: the same order as one global sort, so the
/// cells are visited in the same spatially coherent order (a hashed order costs cache misses).
inline std::vector<std::pair<std::uint64_t, Index>> SortedCellEntries(const FaceCells& cells,
                                                                      const vcg::Box3d& all, int threads) {
  const std::size_t n = cells.cellCount.size();
  constexpr std::size_t kFaceBlock = 4096; // faces per block of the counting sort
  constexpr std::uint64_t kMaxBuckets = 1024;
  // Wrapped z of the cells: 0 .. zMax (low and high are >= 0 by construction).
  const std::uint64_t zMax =
      std::uint64_t(std::min<double>(double(kAxisMask), std::floor(all.DimZ() / cells.cell)));
  int zShift = 0;
  while ((zMax >> zShift) >= kMaxBuckets) ++zShift;
  const std::size_t buckets = std::size_t(zMax >> zShift) + 1;
  auto bucketOf = [&](std::uint64_t key) {
    return std::min(buckets - 1, std::size_t((key >> (2 * kAxisBits)) >> zShift));
  };
  const std::size_t blocks = (n + kFaceBlock - 1) / kFaceBlock;
  // cursor[b * buckets + k]: entries of face block b in bucket k, then where the first of them goes.
  std::vector<std::uint64_t> cursor(blocks * buckets, 0);
  auto countBlocks = [&](std::size_t bBegin, std::size_t bEnd, int) {
    for (std::size_t b = bBegin; b < bEnd; ++b)
      for (std::size_t i = b * kFaceBlock; i < std::min(n, (b + 1) * kFaceBlock); ++i)
        if (cells.cellCount[i] != 0)
          cells.ForEachCell(i, [&](std::uint64_t key) { ++cursor[b * buckets + bucketOf(key)]; });
  };
  ParallelFor(blocks, threads, countBlocks, 1);
  std::vector<std::uint64_t> bucketStart(buckets + 1);
  std::uint64_t placed = 0;
  for (std::size_t k = 0; k < buckets; ++k) {
    bucketStart[k] = placed;
    for (std::size_t b = 0; b < blocks; ++b) {
      const std::uint64_t count = cursor[b * buckets + k];
      cursor[b * buckets + k] = placed;
      placed += count;
    }
  }
  bucketStart[buckets] = placed;
  std::vector<std::pair<std::uint64_t, Index>> cellFaces(cells.entries);
  auto fillBlocks = [&](std::size_t bBegin, std::size_t bEnd, int) {
    for (std::size_t b = bBegin; b < bEnd; ++b)
      for (std::size_t i = b * kFaceBlock; i < std::min(n, (b + 1) * kFaceBlock); ++i)
        if (cells.cellCount[i] != 0)
          cells.ForEachCell(i, [&](std::uint64_t key) {
            cellFaces[cursor[b * buckets + bucketOf(key)]++] = {key, Index(i)};
          });
  };
  ParallelFor(blocks, threads, fillBlocks, 1);
  // A face is in a cell once (it spans fewer than 2^21 cells per axis): the entries are distinct.
  auto sortBuckets = [&](std::size_t kBegin, std::size_t kEnd, int) {
    for (std::size_t k = kBegin; k < kEnd; ++k)
      std::sort(cellFaces.begin() + std::ptrdiff_t(bucketStart[k]),
                cellFaces.begin() + std::ptrdiff_t(bucketStart[k + 1]));
  };
  ParallelFor(buckets, threads, sortBuckets, 1);
  return cellFaces;
}

/// Tests the pairs of every cell, each pair only in the cell holding the lowest corner of the
/// overlap of the two faces' cell ranges.
inline void TestCells(const std::vector<std::pair<std::uint64_t, Index>>& cellFaces, const FaceCells& cells,
                      const PairTest& test, int threads, std::vector<std::vector<IntersectingPair>>& hits) {
  std::vector<std::size_t> cellStart; // runs of equal keys, and the end
  for (std::size_t k = 0; k < cellFaces.size(); ++k)
    if (k == 0 || cellFaces[k].first != cellFaces[k - 1].first) cellStart.push_back(k);
  cellStart.push_back(cellFaces.size());
  const auto& low = cells.low;
  auto testCells = [&](std::size_t cBegin, std::size_t cEnd, int thread) {
    for (std::size_t c = cBegin; c < cEnd; ++c) {
      const std::size_t begin = cellStart[c], end = cellStart[c + 1];
      for (std::size_t s = begin; s < end; ++s) {
        const Index i = cellFaces[s].second;
        for (std::size_t r = s + 1; r < end; ++r) {
          const Index j = cellFaces[r].second;
          const std::uint64_t canonical = WrappedKey(
              std::max(low[i][0], low[j][0]), std::max(low[i][1], low[j][1]), std::max(low[i][2], low[j][2]));
          if (canonical == cellFaces[begin].first) test(i, j, hits[thread]);
        }
      }
    }
  };
  ParallelFor(cellStart.size() - 1, threads, testCells, 256); // cells hold few faces: smaller blocks
}

/// Pairs TestOversized and TestCells would look at: every oversized face against every face, and
/// the pairs of each cell's faces (a pair sharing several cells counted in each).
inline double CandidatePairs(const FaceCells& cells,
                             const std::vector<std::pair<std::uint64_t, Index>>& cellFaces) {
  double pairs = double(cells.oversized.size()) * double(cells.cellCount.size());
  for (std::size_t begin = 0; begin < cellFaces.size();) {
    std::size_t end = begin + 1;
    while (end < cellFaces.size() && cellFaces[end].first == cellFaces[begin].first) ++end;
    const double k = double(end - begin);
    pairs += k * (k - 1) / 2;
    begin = end;
  }
  return pairs;
}

} // namespace self_intersection_detail

/// All intersecting pairs among the given (finite) triangles, in no particular order: pairs
/// sharing no vertex that intersect, pairs sharing one vertex that also meet elsewhere, and,
/// with duplicatesIntersect, pairs with the same three vertices (reported as adjacent).
///
/// Broad phase: a uniform grid of cells two median edge lengths wide (the median, unlike the
/// mean, is not inflated by a few huge faces). Cells are hashed by wrapping their integer
/// coordinates to 21 bits per axis, so any extent fits in a 63-bit key; faces spanning more than
/// kMaxSpan cells ("oversized", e.g. the fan of one vertex sent far away) are not hashed but
/// tested against every face, and the cell size doubles while that or the hashed entries would
/// cost too much. Each pair is tested once, in the cell holding the lowest corner of the overlap
/// of the two cell ranges (no pair set needed; aliased cells cannot repeat a pair because a
/// hashed face spans fewer than 2^21 cells per axis).
///
/// Parallel on `threads` threads, yet deterministic: per-face data are computed into per-face
/// arrays, cells are tested in parallel into per-thread lists of intersecting pairs, and the
/// pairs are gathered from those lists. Every pair is tested exactly once whichever thread
/// tests it, so the counts do not depend on the thread count.
namespace self_intersection_detail {

/// The bounding box of every triangle, and in all the box of them all.
inline std::vector<vcg::Box3d> FaceBoxes(const std::vector<std::array<Index, 3>>& tris,
                                         const std::vector<Point>& points, int threads, vcg::Box3d& all) {
  std::vector<vcg::Box3d> boxes(tris.size());
  ParallelFor(tris.size(), threads, [&](std::size_t begin, std::size_t end, int) {
    for (std::size_t i = begin; i < end; ++i)
      for (Index v : tris[i]) boxes[i].Add(points[v]);
  });
  all.SetNull();
  for (const vcg::Box3d& box : boxes) all.Add(box);
  return boxes;
}

/// The broad phase of a search: boxes, grid cells and the faces of each cell, and the number of
/// candidate pairs the exact test would then run on.
struct BroadPhase {
  vcg::Box3d all;
  std::vector<vcg::Box3d> boxes;
  FaceCells cells;
  std::vector<std::pair<std::uint64_t, Index>> cellFaces;
  double candidatePairs = 0;

  BroadPhase(const std::vector<std::array<Index, 3>>& tris, const std::vector<Point>& points,
             double medianEdge, int threads)
      : boxes(FaceBoxes(tris, points, threads, all)), cells(AssignCells(boxes, all, medianEdge, threads)),
        cellFaces(SortedCellEntries(cells, all, threads)), candidatePairs(CandidatePairs(cells, cellFaces)) {}
};

} // namespace self_intersection_detail

/// The default bound of FindSelfIntersectionsWithin for n triangles: 10^7 candidate pairs plus
/// 1000 per triangle (molecular meshes have 22 to 43 per triangle; 10^8 pairs test in seconds).
constexpr double kMinCandidatePairBound = 1e7;
constexpr double kCandidatePairsPerTriangleBound = 1000;
inline double CandidatePairBound(std::size_t n, double perTriangle = kCandidatePairsPerTriangleBound) {
  return kMinCandidatePairBound + perTriangle * double(n);
}

/// What FindSelfIntersectionsWithin found: every intersecting pair, or none when the candidate
/// pairs of the broad phase exceed the caller's bound (then `searched` is false).
struct SelfIntersectionSearch {
  bool searched = false;
  double candidatePairs = 0; ///< pairs the exact test would run on (an upper bound: see below)
  std::vector<IntersectingPair> pairs;
};

/// FindSelfIntersections, but only when at most maxCandidatePairs pairs would be tested: the pairs
/// of faces sharing a cell (a pair sharing several cells counted in each) plus every oversized
/// face against every face. They are 22 to 43 per face on molecular meshes, and grow with the
/// square of the face count on a soup of overlapping polygons, where the test would run for
/// hours and its list of found pairs outgrow the memory. The count is known once the faces are
/// sorted into cells, before any pair is tested, so a refusal costs linear work and memory.
inline SelfIntersectionSearch FindSelfIntersectionsWithin(const std::vector<std::array<Index, 3>>& tris,
                                                          const std::vector<Point>& points, double medianEdge,
                                                          int threads, double maxCandidatePairs,
                                                          bool duplicatesIntersect = false) {
  using namespace self_intersection_detail;
  SelfIntersectionSearch search;
  const std::size_t n = tris.size();
  search.searched = true;
  if (n < 2) return search;
  threads = ResolveThreadCount(threads);

  const BroadPhase broad(tris, points, medianEdge, threads);
  search.candidatePairs = broad.candidatePairs;
  if (search.candidatePairs > maxCandidatePairs) {
    search.searched = false;
    return search;
  }
  std::vector<PlanarTriangle> planar(n);
  ParallelFor(n, threads, [&](std::size_t begin, std::size_t end, int) {
    for (std::size_t i = begin; i < end; ++i)
      planar[i] = MakePlanarTriangle(points[tris[i][0]], points[tris[i][1]], points[tris[i][2]]);
  });

  // Intersecting pairs found by each thread, gathered in thread order.
  const PairTest test{tris, broad.boxes, planar, duplicatesIntersect};
  std::vector<std::vector<IntersectingPair>> hits(static_cast<std::size_t>(threads));
  TestOversized(broad.cells, test, threads, hits);
  TestCells(broad.cellFaces, broad.cells, test, threads, hits);

  for (const std::vector<IntersectingPair>& list : hits)
    search.pairs.insert(search.pairs.end(), list.begin(), list.end());
  return search;
}

/// The candidate pairs FindSelfIntersections would test among the given triangles (see
/// FindSelfIntersectionsWithin), counted in linear work and memory, no pair tested.
inline double CountCandidatePairs(const std::vector<std::array<Index, 3>>& tris,
                                  const std::vector<Point>& points, double medianEdge, int threads) {
  if (tris.size() < 2) return 0;
  return self_intersection_detail::BroadPhase(tris, points, medianEdge, ResolveThreadCount(threads))
      .candidatePairs;
}

inline std::vector<IntersectingPair> FindSelfIntersections(const std::vector<std::array<Index, 3>>& tris,
                                                           const std::vector<Point>& points,
                                                           double medianEdge, int threads,
                                                           bool duplicatesIntersect = false) {
  return FindSelfIntersectionsWithin(tris, points, medianEdge, threads,
                                     std::numeric_limits<double>::infinity(), duplicatesIntersect)
      .pairs;
}

/// The counts of a list of intersecting pairs among `faces` triangles.
inline IntersectionCounts CountIntersectingPairs(const std::vector<IntersectingPair>& pairs,
                                                 std::size_t faces) {
  IntersectionCounts result;
  std::vector<bool> involved(faces, false);
  for (const IntersectingPair& hit : pairs) {
    ++(hit.adjacent ? result.adjacentPairs : result.disjointPairs);
    involved[hit.i] = involved[hit.j] = true;
  }
  result.faces = std::size_t(std::count(involved.begin(), involved.end(), true));
  return result;
}

} // namespace molremesh

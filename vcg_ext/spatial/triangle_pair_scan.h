// All intersecting pairs among many triangles at once, cache-friendly and in parallel.
//
// When most faces of a mesh have just moved (a Jacobi smoothing step), asking the dynamic grid
// "what is near this face?" face by face costs a cache miss per candidate. TrianglePairScan
// instead sorts the triangles by the grid cell holding their bounding box's lowest corner, in
// row-major order (cells as large as the largest box, so touching boxes sit in the same or in
// adjacent cells), copies what the first tests read (float boxes, moved flags, vertex ids) into
// contiguous arrays in that order, and tests each cell against itself and its 13 "forward"
// neighbours, which lie in 5 runs of the arrays. Only pairs with at least one triangle flagged
// `moved` are tested, and the few pairs that pass the box test go to the caller's exact test
// (the remeshing stages use local_ops_detail::FacesIntersect, MeshQuality's predicates).
// Deterministic: the pairs come out sorted.
#pragma once

#include <vcg/space/box3.h>
#include <vcg/space/point3.h>

#include <vcg_ext/core/float_box.h>
#include <vcg_ext/core/parallel_for.h>
#include <vcg_ext/core/radix_sort.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <utility>
#include <vector>

namespace molremesh {

class TrianglePairScan {
public:
  using Point = vcg::Point3d;

  /// Triangle i as the caller describes it to Build: its corners are vertices of the position
  /// array given to Build (which must outlive the scan's use).
  struct Triangle {
    std::array<std::uint32_t, 3> v{}; ///< vertex ids (shared corners are recognised by id)
    bool live = false;                ///< false: ignored
    bool moved = false;               ///< pairs of two unmoved triangles are not tested
  };

  /// Collects n triangles through fill(i, Triangle&) (called in parallel, once per i), their
  /// corners in `positions`, and sorts them into cells. The records stay small (ids and flags;
  /// normals apart), so that the passes reading them run from cache.
  template <class Fill>
  void Build(std::size_t n, const Point* positions, Fill&& fill, int threads);

  /// Triangle i as Build collected it.
  const Triangle& Input(std::size_t i) const { return input_[i]; }
  /// Its unit normal (zero when degenerate).
  const Point& Normal(std::size_t i) const { return normal_[i]; }
  /// Its corners.
  std::array<Point, 3> Corners(std::size_t i) const {
    const Triangle& t = input_[i];
    return {positions_[t.v[0]], positions_[t.v[1]], positions_[t.v[2]]};
  }
  const Point& Corner(std::size_t i, int k) const { return positions_[input_[i].v[k]]; }

  /// Pairs (i, j), i < j (indices as given to Build), that intersect and involve a moved triangle.
  /// intersect(i, j) decides a candidate pair (boxes touching). With skipSharedVertex, pairs with
  /// a common vertex id are never tested (the caller settles them star by star, where most are
  /// settled at once).
  template <class Intersect>
  void FindPairs(int threads, Intersect&& intersect,
                 std::vector<std::pair<std::uint32_t, std::uint32_t>>& out, bool skipSharedVertex = false);

private:
  struct Cell {
    std::uint64_t row;        // y + ny z
    std::uint32_t x;          // cell coordinate along the row
    std::uint32_t begin, end; // run in the sorted arrays
  };
  struct Row {
    std::uint64_t id;
    std::uint32_t first, last; // its cells, [first, last) in cells_
  };
  static std::uint64_t Hash(std::uint64_t k) {
    k ^= k >> 33;
    k *= 0xff51afd7ed558ccdULL;
    k ^= k >> 33;
    return k;
  }
  /// Index in rows_ of the row with this id, or -1.
  int FindRow(std::uint64_t id) const {
    const std::size_t mask = tableKeys_.size() - 1;
    for (std::size_t i = Hash(id) & mask;; i = (i + 1) & mask) {
      if (tableKeys_[i] == id) return int(tableRows_[i]);
      if (tableKeys_[i] == kEmpty) return -1;
    }
  }

  static constexpr std::uint64_t kEmpty = std::numeric_limits<std::uint64_t>::max();

  const Point* positions_ = nullptr;
  std::vector<Triangle> input_;
  std::vector<Point> normal_;
  std::vector<FloatBox> inputBox_;
  std::vector<std::uint64_t> keys_;
  std::vector<std::uint32_t> order_, tmp_;
  std::array<std::uint64_t, 3> dims_{}; // cells along x, y, z
  // What the box test reads, for the sorted triangles, one array per field, so that one
  // triangle is tested against a run of others with vector instructions: the boxes (rounded
  // outward to float), the moved flags (0 or -1) and the vertex ids.
  std::array<std::vector<float>, 3> sortedLo_, sortedHi_;
  std::vector<std::int32_t> sortedMoved_;
  std::array<std::vector<std::uint32_t>, 3> sortedIds_;
  std::vector<Cell> cells_;
  std::vector<Row> rows_;
  std::vector<std::uint64_t> tableKeys_;
  std::vector<std::uint32_t> tableRows_;
  std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> threadPairs_;
};

// ------------------------------------------------------------------------------------------------

template <class Fill>
void TrianglePairScan::Build(std::size_t n, const Point* positions, Fill&& fill, int threads) {
  positions_ = positions;
  input_.resize(n);
  normal_.resize(n);
  inputBox_.resize(n);
  ParallelFor(n, threads, [&](std::size_t begin, std::size_t end, int) {
    for (std::size_t i = begin; i < end; ++i) {
      Triangle& t = input_[i];
      t.live = false;
      t.moved = false;
      fill(i, t);
      if (!t.live) continue;
      const std::array<Point, 3> p = Corners(i);
      vcg::Box3d b;
      for (int k = 0; k < 3; ++k) b.Add(p[k]);
      const Point nn = (p[1] - p[0]) ^ (p[2] - p[0]);
      const double len = nn.Norm();
      normal_[i] = len > 0 ? nn / len : Point(0, 0, 0);
      inputBox_[i] = FloatBox::Outward(b);
    }
  });
  // Cell size: the largest box extent, so that touching boxes have min-corner cells at most
  // one apart on every axis.
  std::array<float, 3> lo{}, hi{};
  lo.fill(std::numeric_limits<float>::infinity());
  hi.fill(-std::numeric_limits<float>::infinity());
  float extent = 0;
  order_.clear();
  for (std::size_t i = 0; i < n; ++i) {
    if (!input_[i].live) continue;
    order_.push_back(std::uint32_t(i));
    const FloatBox& b = inputBox_[i];
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], b.lo[k]);
      hi[k] = std::max(hi[k], b.hi[k]);
      extent = std::max(extent, b.hi[k] - b.lo[k]);
    }
  }
  cells_.clear();
  rows_.clear();
  if (order_.empty()) return;
  double span = 0;
  for (int k = 0; k < 3; ++k) span = std::max(span, double(hi[k]) - double(lo[k]));
  double cell = double(extent) * (1.0 + 1e-6) + 1e-30;
  while (span / cell > double(0x1fffff - 2)) cell *= 2.0;
  const double inv = 1.0 / cell;
  for (int k = 0; k < 3; ++k) dims_[k] = std::uint64_t((double(hi[k]) - double(lo[k])) * inv) + 1;

  // Cells in row-major order (x fastest): the three cells x - 1 .. x + 1 of a row are
  // contiguous, so a triangle meets each neighbouring row in one run.
  keys_.resize(n);
  ParallelFor(order_.size(), threads, [&](std::size_t begin, std::size_t end, int) {
    for (std::size_t k = begin; k < end; ++k) {
      const std::uint32_t i = order_[k];
      std::array<std::uint64_t, 3> c{};
      for (int a = 0; a < 3; ++a)
        c[a] = std::min(dims_[a] - 1, std::uint64_t((double(inputBox_[i].lo[a]) - double(lo[a])) * inv));
      keys_[i] = (c[2] * dims_[1] + c[1]) * dims_[0] + c[0];
    }
  });
  // Stable, so triangles of one cell stay in index order.
  StableRadixSortByKey(order_, tmp_, [&](std::uint32_t i) { return keys_[i]; });
  for (int a = 0; a < 3; ++a) {
    sortedLo_[a].resize(order_.size());
    sortedHi_[a].resize(order_.size());
    sortedIds_[a].resize(order_.size());
  }
  sortedMoved_.resize(order_.size());
  ParallelFor(order_.size(), threads, [&](std::size_t begin, std::size_t end, int) {
    for (std::size_t k = begin; k < end; ++k) {
      const std::uint32_t i = order_[k];
      const FloatBox& box = inputBox_[i];
      for (int a = 0; a < 3; ++a) {
        sortedLo_[a][k] = box.lo[a];
        sortedHi_[a][k] = box.hi[a];
        sortedIds_[a][k] = input_[i].v[a];
      }
      sortedMoved_[k] = input_[i].moved ? -1 : 0;
    }
  });
  for (std::size_t k = 0; k < order_.size();) {
    std::size_t e = k;
    const std::uint64_t key = keys_[order_[k]];
    while (e < order_.size() && keys_[order_[e]] == key) ++e;
    const std::uint64_t row = key / dims_[0];
    if (rows_.empty() || rows_.back().id != row)
      rows_.push_back({row, std::uint32_t(cells_.size()), std::uint32_t(cells_.size())});
    cells_.push_back({row, std::uint32_t(key % dims_[0]), std::uint32_t(k), std::uint32_t(e)});
    rows_.back().last = std::uint32_t(cells_.size());
    k = e;
  }
  std::size_t tableSize = 16;
  while (tableSize < 2 * rows_.size()) tableSize *= 2;
  tableKeys_.assign(tableSize, kEmpty);
  tableRows_.assign(tableSize, 0);
  for (std::size_t r = 0; r < rows_.size(); ++r) {
    std::size_t i = Hash(rows_[r].id) & (tableSize - 1);
    while (tableKeys_[i] != kEmpty) i = (i + 1) & (tableSize - 1);
    tableKeys_[i] = rows_[r].id;
    tableRows_[i] = std::uint32_t(r);
  }
}

template <class Intersect>
void TrianglePairScan::FindPairs(int threads, Intersect&& intersect,
                                 std::vector<std::pair<std::uint32_t, std::uint32_t>>& out,
                                 bool skipSharedVertex) {
  out.clear();
  const int nThreads = ResolveThreadCount(threads);
  threadPairs_.resize(nThreads);
  for (auto& v : threadPairs_) v.clear();
  if (cells_.empty()) return;
  const std::uint64_t ny = dims_[1], nz = dims_[2];
  ParallelFor(
      cells_.size(), nThreads,
      [&](std::size_t begin, std::size_t end, int t) {
        auto& pairs = threadPairs_[t];
        const float *lx = sortedLo_[0].data(), *ly = sortedLo_[1].data(), *lz = sortedLo_[2].data();
        const float *hx = sortedHi_[0].data(), *hy = sortedHi_[1].data(), *hz = sortedHi_[2].data();
        const std::int32_t* moved = sortedMoved_.data();
        const std::uint32_t *v0 = sortedIds_[0].data(), *v1 = sortedIds_[1].data(),
                            *v2 = sortedIds_[2].data();
        // Triangle a against the run [b0, b1): the tests of a block of the run (boxes touching, one
        // of the two moved, and with skipShared no common vertex) go into a mask in one branch-free
        // loop over 32-bit lanes, so it vectorizes; then the few hits get the exact test.
        auto testRun = [&](std::uint32_t a, std::uint32_t b0, std::uint32_t b1, auto skipShared) {
          constexpr std::uint32_t kBlock = 32;
          const float alx = lx[a], aly = ly[a], alz = lz[a], ahx = hx[a], ahy = hy[a], ahz = hz[a];
          const std::int32_t aMoved = moved[a];
          const std::uint32_t a0 = v0[a], a1 = v1[a], a2 = v2[a];
          std::array<std::int32_t, kBlock> hit;
          for (std::uint32_t start = b0; start < b1; start += kBlock) {
            const std::uint32_t n = std::min(kBlock, b1 - start);
            for (std::uint32_t j = 0; j < n; ++j) {
              const std::uint32_t b = start + j;
              std::int32_t pass = -std::int32_t(alx <= hx[b]);
              pass &= -std::int32_t(lx[b] <= ahx);
              pass &= -std::int32_t(aly <= hy[b]);
              pass &= -std::int32_t(ly[b] <= ahy);
              pass &= -std::int32_t(alz <= hz[b]);
              pass &= -std::int32_t(lz[b] <= ahz);
              pass &= aMoved | moved[b];
              if constexpr (decltype(skipShared)::value) {
                const std::uint32_t b0v = v0[b], b1v = v1[b], b2v = v2[b];
                const std::int32_t shared =
                    std::int32_t(a0 == b0v) | std::int32_t(a0 == b1v) | std::int32_t(a0 == b2v) |
                    std::int32_t(a1 == b0v) | std::int32_t(a1 == b1v) | std::int32_t(a1 == b2v) |
                    std::int32_t(a2 == b0v) | std::int32_t(a2 == b1v) | std::int32_t(a2 == b2v);
                pass &= shared - 1;
              }
              hit[j] = pass;
            }
            for (std::uint32_t j = 0; j < n; ++j) {
              if (hit[j] == 0) continue;
              const std::uint32_t i = order_[a], k = order_[start + j];
              if (intersect(i, k)) pairs.emplace_back(std::min(i, k), std::max(i, k));
            }
          }
        };
        // Each pair of neighbouring cells is visited once, from the lower one in (z, y, x) order: a
        // cell meets itself and the next cell of its row, and the cells x - 1 .. x + 1 of the rows
        // (y + 1, z), (y - 1, z + 1), (y, z + 1) and (y + 1, z + 1). Cells are handled in row order,
        // so each neighbouring row is walked with a cursor that only moves forward.
        std::array<std::uint32_t, 4> cursor{}, last{};
        std::uint64_t currentRow = kEmpty;
        auto visit = [&](auto skipShared) {
          for (std::size_t c = begin; c < end; ++c) {
            const Cell& cell = cells_[c];
            if (cell.row != currentRow) {
              currentRow = cell.row;
              const std::uint64_t y = cell.row % ny, z = cell.row / ny;
              const std::array<std::array<std::int64_t, 2>, 4> near{
                  {{std::int64_t(y) + 1, std::int64_t(z)},
                   {std::int64_t(y) - 1, std::int64_t(z) + 1},
                   {std::int64_t(y), std::int64_t(z) + 1},
                   {std::int64_t(y) + 1, std::int64_t(z) + 1}}};
              for (int r = 0; r < 4; ++r) {
                cursor[r] = last[r] = 0;
                const auto [ry, rz] = near[r];
                if (ry < 0 || ry >= std::int64_t(ny) || rz >= std::int64_t(nz)) continue;
                const int found = FindRow(std::uint64_t(ry) + ny * std::uint64_t(rz));
                if (found < 0) continue;
                cursor[r] = rows_[found].first;
                last[r] = rows_[found].last;
              }
            }
            std::uint32_t ownEnd = cell.end;
            if (c + 1 < cells_.size() && cells_[c + 1].row == cell.row && cells_[c + 1].x == cell.x + 1)
              ownEnd = cells_[c + 1].end;
            for (std::uint32_t a = cell.begin; a < cell.end; ++a) testRun(a, a + 1, ownEnd, skipShared);
            for (int r = 0; r < 4; ++r) {
              while (cursor[r] < last[r] && std::uint64_t(cells_[cursor[r]].x) + 1 < cell.x) ++cursor[r];
              std::uint32_t stop = cursor[r];
              while (stop < last[r] && cells_[stop].x <= std::uint64_t(cell.x) + 1) ++stop;
              if (stop == cursor[r]) continue;
              const std::uint32_t runBegin = cells_[cursor[r]].begin, runEnd = cells_[stop - 1].end;
              for (std::uint32_t a = cell.begin; a < cell.end; ++a) testRun(a, runBegin, runEnd, skipShared);
            }
          }
        };
        if (skipSharedVertex)
          visit(std::true_type());
        else
          visit(std::false_type());
      },
      64);
  for (const auto& v : threadPairs_) out.insert(out.end(), v.begin(), v.end());
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
}

} // namespace molremesh

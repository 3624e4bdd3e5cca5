// All intersecting pairs among many triangles at once, cache-friendly and in parallel.
//
// When most faces of a mesh have just moved (a Jacobi smoothing step), asking the dynamic grid
// "what is near this face?" face by face costs a cache miss per candidate. TrianglePairScan
// instead sorts the triangles along a Morton curve of the grid cell holding their bounding box's
// lowest corner (cells as large as the largest box, so touching boxes sit in the same or in
// adjacent cells), copies what the box test reads (float boxes, vertex ids, moved flags) into
// contiguous arrays in that order, and tests each cell against itself and its 13 "forward"
// neighbours; the few pairs whose boxes touch read the full triangles where Build collected
// them. Only pairs with at least one triangle flagged `moved` are tested; a pair is reported
// when local_ops_detail::FacesIntersect says so (MeshQuality's predicates: no contact for faces
// sharing no vertex, no contact beyond the shared corner for faces sharing one).
// Deterministic: the pairs come out sorted.
#pragma once

#include <vcg/space/box3.h>
#include <vcg/space/point3.h>

#include <vcg_ext/float_box.h>
#include <vcg_ext/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

namespace molremesh {

class TrianglePairScan {
public:
  using Point = vcg::Point3d;

  /// Triangle i as the caller describes it to Build.
  struct Triangle {
    std::array<Point, 3> p;          ///< corners
    std::array<std::uint32_t, 3> v;  ///< vertex ids (shared corners are recognised by id)
    Point n;                         ///< unit normal (filled by Build)
    bool live = false;               ///< false: ignored
    bool moved = false;              ///< pairs of two unmoved triangles are not tested
  };

  /// Collects n triangles through fill(i, Triangle&) (called in parallel, once per i) and
  /// sorts them into cells.
  template <class Fill>
  void Build(std::size_t n, Fill&& fill, int threads);

  /// Triangle i as Build collected it, its unit normal included.
  const Triangle& Input(std::size_t i) const { return input_[i]; }

  /// Pairs (i, j), i < j (indices as given to Build), that intersect and involve a moved triangle.
  /// intersect(a, b) decides a candidate pair (boxes touching) from two Triangles. With
  /// skipSharedVertex, pairs with a common vertex id are never tested (the caller settles them
  /// star by star, where most are settled at once).
  template <class Intersect>
  void FindPairs(int threads, Intersect&& intersect,
                 std::vector<std::pair<std::uint32_t, std::uint32_t>>& out, bool skipSharedVertex = false);

private:
  struct Cell {
    std::uint64_t key;
    std::uint32_t begin, end; // run in the sorted arrays
  };
  static std::uint64_t Spread(std::uint64_t x) { // 21 bits -> every third bit
    x &= 0x1fffff;
    x = (x | x << 32) & 0x1f00000000ffffULL;
    x = (x | x << 16) & 0x1f0000ff0000ffULL;
    x = (x | x << 8) & 0x100f00f00f00f00fULL;
    x = (x | x << 4) & 0x10c30c30c30c30c3ULL;
    x = (x | x << 2) & 0x1249249249249249ULL;
    return x;
  }
  static std::uint32_t Compact(std::uint64_t x) { // every third bit -> 21 bits (Spread's inverse)
    x &= 0x1249249249249249ULL;
    x = (x ^ (x >> 2)) & 0x10c30c30c30c30c3ULL;
    x = (x ^ (x >> 4)) & 0x100f00f00f00f00fULL;
    x = (x ^ (x >> 8)) & 0x1f0000ff0000ffULL;
    x = (x ^ (x >> 16)) & 0x1f00000000ffffULL;
    x = (x ^ (x >> 32)) & 0x1fffff;
    return std::uint32_t(x);
  }
  static std::uint64_t Key(std::uint32_t x, std::uint32_t y, std::uint32_t z) {
    return Spread(x) | (Spread(y) << 1) | (Spread(z) << 2);
  }
  static std::uint64_t Hash(std::uint64_t k) {
    k ^= k >> 33;
    k *= 0xff51afd7ed558ccdULL;
    k ^= k >> 33;
    return k;
  }
  int FindCell(std::uint64_t key) const {
    const std::size_t mask = tableKeys_.size() - 1;
    for (std::size_t i = Hash(key) & mask;; i = (i + 1) & mask) {
      if (tableKeys_[i] == key) return int(tableCells_[i]);
      if (tableKeys_[i] == kEmpty) return -1;
    }
  }

  static constexpr std::uint64_t kEmpty = std::numeric_limits<std::uint64_t>::max();

  std::vector<Triangle> input_;
  std::vector<vcg::Box3d> inputBox_;
  std::vector<std::uint64_t> keys_;
  std::vector<std::uint32_t> order_, tmp_;
  // Boxes (rounded outward to float) and moved flags of the sorted triangles, one array per
  // bound, so that one triangle is tested against a run of others with vector instructions.
  std::array<std::vector<float>, 3> sortedLo_, sortedHi_;
  std::vector<std::uint8_t> sortedMoved_;
  std::vector<std::array<std::uint32_t, 3>> sortedIds_;
  std::vector<Cell> cells_;
  std::vector<std::uint64_t> tableKeys_;
  std::vector<std::uint32_t> tableCells_;
  std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> threadPairs_;
};

// ------------------------------------------------------------------------------------------------

template <class Fill>
void TrianglePairScan::Build(std::size_t n, Fill&& fill, int threads) {
  input_.resize(n);
  inputBox_.resize(n);
  ParallelFor(n, threads, [&](std::size_t begin, std::size_t end, int) {
    for (std::size_t i = begin; i < end; ++i) {
      Triangle& t = input_[i];
      t.live = false;
      t.moved = false;
      fill(i, t);
      vcg::Box3d b;
      if (t.live) {
        for (int k = 0; k < 3; ++k) b.Add(t.p[k]);
        const Point nn = (t.p[1] - t.p[0]) ^ (t.p[2] - t.p[0]);
        const double len = nn.Norm();
        t.n = len > 0 ? nn / len : Point(0, 0, 0);
      }
      inputBox_[i] = b;
    }
  });
  // Cell size: the largest box extent, so that touching boxes have min-corner cells at most
  // one apart on every axis.
  vcg::Box3d all;
  double extent = 0;
  std::size_t live = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!input_[i].live) continue;
    ++live;
    all.Add(inputBox_[i]);
    const Point d = inputBox_[i].Dim();
    extent = std::max({extent, d[0], d[1], d[2]});
  }
  cells_.clear();
  order_.clear();
  if (live == 0) return;
  const Point dim = all.Dim();
  double cell = extent * (1.0 + 1e-9) + 1e-300;
  while (std::max({dim[0], dim[1], dim[2]}) / cell > double(0x1fffff - 2)) cell *= 2.0;
  const double inv = 1.0 / cell;

  keys_.resize(n);
  order_.clear();
  for (std::size_t i = 0; i < n; ++i) {
    if (!input_[i].live) continue;
    const vcg::Box3d& b = inputBox_[i];
    keys_[i] = Key(std::uint32_t((b.min[0] - all.min[0]) * inv), std::uint32_t((b.min[1] - all.min[1]) * inv),
                   std::uint32_t((b.min[2] - all.min[2]) * inv));
    order_.push_back(std::uint32_t(i));
  }
  // LSD radix sort of the live indices by key (stable, so ties stay in index order).
  std::uint64_t maxKey = 0;
  for (const std::uint32_t i : order_) maxKey = std::max(maxKey, keys_[i]);
  tmp_.resize(order_.size());
  std::vector<std::uint32_t> count(1u << 16);
  for (int shift = 0; shift < 64 && (maxKey >> shift) != 0; shift += 16) {
    std::fill(count.begin(), count.end(), 0);
    for (const std::uint32_t i : order_) ++count[(keys_[i] >> shift) & 0xffff];
    std::uint32_t sum = 0;
    for (auto& c : count) {
      const std::uint32_t k = c;
      c = sum;
      sum += k;
    }
    for (const std::uint32_t i : order_) tmp_[count[(keys_[i] >> shift) & 0xffff]++] = i;
    order_.swap(tmp_);
  }
  // What the box test reads, contiguous in curve order, and the cells as runs.
  for (int a = 0; a < 3; ++a) {
    sortedLo_[a].resize(order_.size());
    sortedHi_[a].resize(order_.size());
  }
  sortedMoved_.resize(order_.size());
  sortedIds_.resize(order_.size());
  ParallelFor(order_.size(), threads, [&](std::size_t begin, std::size_t end, int) {
    for (std::size_t k = begin; k < end; ++k) {
      const std::uint32_t i = order_[k];
      const FloatBox box = FloatBox::Outward(inputBox_[i]);
      for (int a = 0; a < 3; ++a) {
        sortedLo_[a][k] = box.lo[a];
        sortedHi_[a][k] = box.hi[a];
      }
      sortedMoved_[k] = input_[i].moved ? 1 : 0;
      sortedIds_[k] = input_[i].v;
    }
  });
  for (std::size_t k = 0; k < order_.size();) {
    std::size_t e = k;
    while (e < order_.size() && keys_[order_[e]] == keys_[order_[k]]) ++e;
    cells_.push_back({keys_[order_[k]], std::uint32_t(k), std::uint32_t(e)});
    k = e;
  }
  std::size_t tableSize = 16;
  while (tableSize < 2 * cells_.size()) tableSize *= 2;
  tableKeys_.assign(tableSize, kEmpty);
  tableCells_.assign(tableSize, 0);
  for (std::size_t c = 0; c < cells_.size(); ++c) {
    std::size_t i = Hash(cells_[c].key) & (tableSize - 1);
    while (tableKeys_[i] != kEmpty) i = (i + 1) & (tableSize - 1);
    tableKeys_[i] = cells_[c].key;
    tableCells_[i] = std::uint32_t(c);
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
  // The 13 neighbour offsets with (dz, dy, dx) lexicographically positive: each pair of
  // neighbouring cells is visited once, from its lower cell.
  std::array<std::array<int, 3>, 13> offsets{};
  int count = 0;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx)
        if (dz > 0 || (dz == 0 && (dy > 0 || (dy == 0 && dx > 0)))) offsets[count++] = {dx, dy, dz};
  ParallelFor(cells_.size(), nThreads, [&](std::size_t begin, std::size_t end, int t) {
    auto& pairs = threadPairs_[t];
    const float *lx = sortedLo_[0].data(), *ly = sortedLo_[1].data(), *lz = sortedLo_[2].data();
    const float *hx = sortedHi_[0].data(), *hy = sortedHi_[1].data(), *hz = sortedHi_[2].data();
    const std::uint8_t* moved = sortedMoved_.data();
    // Boxes touching and one of the two moved: the exact tests.
    auto test = [&](std::uint32_t a, std::uint32_t b) {
      if (skipSharedVertex) {
        const std::array<std::uint32_t, 3>&ia = sortedIds_[a], &ib = sortedIds_[b];
        for (const std::uint32_t x : ia)
          if (x == ib[0] || x == ib[1] || x == ib[2]) return;
      }
      const std::uint32_t i = order_[a], j = order_[b];
      if (intersect(input_[i], input_[j])) {
        pairs.emplace_back(std::min(i, j), std::max(i, j));
      }
    };
    // Triangle a against the run [b0, b1): the box tests of a block of the run go into a mask
    // in one branch-free loop (all 32-bit lanes, so it vectorizes), then the few hits are tested.
    auto testRun = [&](std::uint32_t a, std::uint32_t b0, std::uint32_t b1) {
      constexpr std::uint32_t kBlock = 32;
      const float alx = lx[a], aly = ly[a], alz = lz[a], ahx = hx[a], ahy = hy[a], ahz = hz[a];
      const bool aMoved = moved[a] != 0;
      std::array<std::int32_t, kBlock> hit;
      for (std::uint32_t start = b0; start < b1; start += kBlock) {
        const std::uint32_t n = std::min(kBlock, b1 - start);
        for (std::uint32_t j = 0; j < n; ++j) {
          const std::uint32_t b = start + j;
          std::int32_t touch = -std::int32_t(alx <= hx[b]);
          touch &= -std::int32_t(lx[b] <= ahx);
          touch &= -std::int32_t(aly <= hy[b]);
          touch &= -std::int32_t(ly[b] <= ahy);
          touch &= -std::int32_t(alz <= hz[b]);
          touch &= -std::int32_t(lz[b] <= ahz);
          hit[j] = touch;
        }
        for (std::uint32_t j = 0; j < n; ++j)
          if (hit[j] != 0 && (aMoved || moved[start + j] != 0)) test(a, start + j);
      }
    };
    for (std::size_t c = begin; c < end; ++c) {
      const Cell& cell = cells_[c];
      for (std::uint32_t a = cell.begin; a < cell.end; ++a) testRun(a, a + 1, cell.end);
      const std::array<std::uint32_t, 3> xyz{Compact(cell.key), Compact(cell.key >> 1),
                                             Compact(cell.key >> 2)};
      for (const auto& o : offsets) {
        const long x = long(xyz[0]) + o[0], y = long(xyz[1]) + o[1], z = long(xyz[2]) + o[2];
        if (x < 0 || y < 0 || z < 0) continue;
        const int other = FindCell(Key(std::uint32_t(x), std::uint32_t(y), std::uint32_t(z)));
        if (other < 0) continue;
        const Cell& oc = cells_[other];
        for (std::uint32_t a = cell.begin; a < cell.end; ++a) testRun(a, oc.begin, oc.end);
      }
    }
  }, 64);
  for (const auto& v : threadPairs_) out.insert(out.end(), v.begin(), v.end());
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
}

} // namespace molremesh

// A dynamic uniform grid of face bounding boxes, hashed by cell, updated per edit.
//
// The remeshing stages ask "which faces are near these new triangles?" after every local edit,
// while the mesh changes under them; a static grid would have to be rebuilt each time. Here
// each face (by index) is registered in the cells its bounding box overlaps; Insert, Remove and
// Update cost O(cells touched), and only cells that ever held a face take memory (an
// open-addressing table maps the cell coordinates to a cell slot).
//
// Boxes are stored as FloatBoxes (float, rounded outward), so a stored box always contains the
// true one: queries may report a few more faces, never fewer. Each face remembers the cellSlots of its cells,
// so QueryFace (the faces near a face already in the grid) needs no hashing at all.
//
// Modifications are not thread-safe; the const queries are, while nobody modifies the grid,
// given one QueryMarks per thread.
#pragma once

#include <vcg/space/box3.h>

#include <vcg_ext/core/float_box.h>
#include <vcg_ext/core/parallel_for.h>
#include <vcg_ext/core/vector_growth.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

namespace molremesh {

class FaceHashGrid {
public:
  using Box = vcg::Box3d;

  /// Per-thread marks for the const box Query.
  class QueryMarks {
  public:
    QueryMarks() = default;

  private:
    friend class FaceHashGrid;
    std::vector<std::uint32_t> stamps_;
    std::uint32_t stamp_ = 0;
  };

  /// Empties the grid and sets the cell size and the origin of the cell coordinates.
  void Reset(double cellSize, const vcg::Point3d& origin) {
    cell_ = cellSize > 0 && std::isfinite(cellSize) ? cellSize : 1.0;
    inv_ = 1.0 / cell_;
    origin_ = origin;
    keys_.assign(1024, kEmpty);
    slots_.assign(1024, 0);
    cells_.clear();
    cellCoord_.clear();
    faces_.clear();
    ownMarks_ = QueryMarks();
    used_ = 0;
  }

  double CellSize() const { return cell_; }
  /// Makes room for face indices below n (cheap to call often).
  void Resize(std::size_t n) {
    if (faces_.size() < n) ResizeWithSlack(faces_, n);
  }
  bool Contains(std::size_t f) const { return f < faces_.size() && faces_[f].in; }
  /// The stored (outward rounded) box of face f.
  Box BoxOf(std::size_t f) const { return faces_[f].box.ToBox(); }

  void Insert(std::size_t f, const Box& box) {
    Resize(f + 1);
    SetEntry(faces_[f], box);
    LinkCells(f);
  }

  /// Inserts every face i < n for which boxOf(i, box) returns true (with its box) into an empty
  /// grid: the same grid as Insert(i, box) called in increasing i, so queries visit faces in the
  /// same order. Boxes and cell ranges are computed on `threads` threads (boxOf is called
  /// concurrently, once per i). A large grid is filled block by block (kInsertBlockFaces
  /// consecutive faces, whatever the thread count): each block finds its cells in a small table
  /// of its own, in parallel, so the grid's own (large, cache-missing) table is asked once per
  /// cell of a block instead of once per cell of a face; the blocks' faces then go into the cell
  /// lists in parallel, each block after the blocks before it, which leaves every list in
  /// increasing face order. Cell slot numbers differ from serial insertion's, but they are
  /// handles only: no answer depends on them.
  template <class BoxOf>
  void InsertAll(std::size_t n, BoxOf&& boxOf, int threads) {
    Resize(n);
    std::vector<std::uint32_t> start(n + 1, 0); // cells of face i: start[i] .. start[i + 1]
    ParallelFor(n, threads, [&](std::size_t begin, std::size_t end, int) {
      Box box;
      for (std::size_t i = begin; i < end; ++i) {
        FaceEntry& e = faces_[i];
        box.SetNull();
        if (!boxOf(i, box)) continue;
        start[i + 1] = SetEntry(e, box);
      }
    });
    for (std::size_t i = 0; i < n; ++i) start[i + 1] += start[i];
    const std::size_t blocks = (n + kInsertBlockFaces - 1) / kInsertBlockFaces;
    if (blocks <= 1) {
      for (std::size_t i = 0; i < n; ++i)
        if (faces_[i].in) LinkCells(i);
      return;
    }
    // 1. Each block's cells, numbered in the block in order of first use, with their face counts;
    //    entry k of face i (in cell order) gets its block cell number in local[start[i] + k].
    struct Block {
      std::vector<std::uint64_t> keys;                // block cell -> key
      std::vector<std::uint32_t> count, slot, offset; // faces, grid slot, first place in the list
    };
    std::vector<Block> block(blocks);
    std::vector<std::uint32_t> local(start[n]);
    ParallelFor(
        blocks, threads,
        [&](std::size_t bBegin, std::size_t bEnd, int) {
          std::vector<std::uint64_t> tableKeys;
          std::vector<std::uint32_t> tableIds;
          for (std::size_t b = bBegin; b < bEnd; ++b) {
            const std::size_t i0 = b * kInsertBlockFaces, i1 = std::min(n, i0 + kInsertBlockFaces);
            std::size_t size = 16;
            while (size < 2 * std::size_t(start[i1] - start[i0])) size *= 2;
            tableKeys.assign(size, kEmpty);
            tableIds.resize(size);
            Block& out = block[b];
            for (std::size_t i = i0; i < i1; ++i) {
              if (!faces_[i].in) continue;
              std::uint32_t* id = local.data() + start[i];
              ForEachCell(faces_[i].range, [&](int x, int y, int z) {
                const std::uint64_t key = Key(x, y, z);
                std::size_t t = Hash(key) & (size - 1);
                while (tableKeys[t] != key && tableKeys[t] != kEmpty) t = (t + 1) & (size - 1);
                if (tableKeys[t] == kEmpty) {
                  tableKeys[t] = key;
                  tableIds[t] = std::uint32_t(out.keys.size());
                  out.keys.push_back(key);
                  out.count.push_back(0);
                }
                ++out.count[tableIds[t]];
                *id++ = tableIds[t];
              });
            }
          }
        },
        1);
    // 2. Grid cells for the block cells, block after block; each block's place in each list.
    std::vector<std::uint32_t> listSize(cells_.size());
    for (std::size_t c = 0; c < cells_.size(); ++c) listSize[c] = std::uint32_t(cells_[c].size());
    for (Block& b : block) {
      b.slot.resize(b.keys.size());
      b.offset.resize(b.keys.size());
      for (std::size_t l = 0; l < b.keys.size(); ++l) {
        const std::uint64_t key = b.keys[l];
        const std::uint32_t slot = FindOrCreate(int(key >> 42) - kBias, int((key >> 21) & kAxisMask) - kBias,
                                                int(key & kAxisMask) - kBias);
        if (slot >= listSize.size()) listSize.resize(slot + 1, 0);
        b.slot[l] = slot;
        b.offset[l] = listSize[slot];
        listSize[slot] += b.count[l];
      }
    }
    ParallelFor(cells_.size(), threads, [&](std::size_t begin, std::size_t end, int) {
      for (std::size_t c = begin; c < end; ++c) cells_[c].resize(listSize[c]);
    });
    // 3. The faces into their lists and their cell slots, block by block in parallel.
    ParallelFor(
        blocks, threads,
        [&](std::size_t bBegin, std::size_t bEnd, int) {
          for (std::size_t b = bBegin; b < bEnd; ++b) {
            Block& bl = block[b];
            const std::size_t i0 = b * kInsertBlockFaces, i1 = std::min(n, i0 + kInsertBlockFaces);
            for (std::size_t i = i0; i < i1; ++i) {
              FaceEntry& e = faces_[i];
              if (!e.in) continue;
              for (std::uint32_t k = start[i]; k < start[i + 1]; ++k) {
                const std::uint32_t l = local[k];
                cells_[bl.slot[l]][bl.offset[l]++] = std::uint32_t(i);
                if (e.slotCount != kNoSlots) e.cellSlots[e.slotCount++] = bl.slot[l];
              }
            }
          }
        },
        1);
  }

  void Remove(std::size_t f) {
    if (!Contains(f)) return;
    FaceEntry& e = faces_[f];
    auto erase = [&](std::uint32_t slot) {
      std::vector<std::uint32_t>& list = cells_[slot];
      const auto it = std::find(list.begin(), list.end(), std::uint32_t(f));
      *it = list.back();
      list.pop_back();
    };
    if (e.slotCount != kNoSlots) {
      for (int i = 0; i < e.slotCount; ++i) erase(e.cellSlots[i]);
    } else {
      ForEachCell(e.range, [&](int x, int y, int z) { erase(std::uint32_t(Find(Key(x, y, z)))); });
    }
    e.in = false;
  }

  /// New box for a face already in the grid (or inserts it).
  void Update(std::size_t f, const Box& box) {
    if (!Contains(f)) {
      Insert(f, box);
      return;
    }
    std::array<int, 6> range{};
    RangeOf(box, range);
    if (range == faces_[f].range) {
      SetBox(faces_[f], box);
      return;
    }
    Remove(f);
    Insert(f, box);
  }

  /// Update for a face already in the grid whose box stays within the same cells: only the box
  /// changes, and calls for different faces may run concurrently. Returns false (and changes
  /// nothing) when the face is not in the grid or its cells change: then call Update.
  bool UpdateInPlace(std::size_t f, const Box& box) {
    if (!Contains(f)) return false;
    std::array<int, 6> range{};
    RangeOf(box, range);
    if (range != faces_[f].range) return false;
    SetBox(faces_[f], box);
    return true;
  }

  /// Calls visit(faceIndex) once for every face whose stored box touches `box` (closed boxes).
  template <class Visit>
  void Query(const Box& box, Visit&& visit) {
    Query(box, ownMarks_, visit);
  }
  /// Same, thread-safe with one QueryMarks per thread (while the grid is not modified).
  template <class Visit>
  void Query(const Box& box, QueryMarks& marks, Visit&& visit) const {
    if (marks.stamps_.size() < faces_.size()) marks.stamps_.resize(faces_.size(), 0);
    if (++marks.stamp_ == 0) {
      std::fill(marks.stamps_.begin(), marks.stamps_.end(), 0);
      marks.stamp_ = 1;
    }
    std::array<int, 6> r{};
    RangeOf(box, r);
    for (int z = r[2]; z <= r[5]; ++z)
      for (int y = r[1]; y <= r[4]; ++y)
        for (int x = r[0]; x <= r[3]; ++x) {
          const int c = Find(Key(x, y, z));
          if (c < 0) continue;
          for (const std::uint32_t g : cells_[c]) {
            if (marks.stamps_[g] == marks.stamp_) continue;
            marks.stamps_[g] = marks.stamp_;
            if (Touch(faces_[g], box)) visit(std::size_t(g));
          }
        }
  }

  /// Calls visit(g) once for every other face g whose stored box touches the stored box of face f
  /// (which must be in the grid). Faces sharing several cells with f are reported in one of them
  /// only (the cell at the lowest corner of the overlap of the two cell ranges), so no marks are
  /// needed. Thread-safe while the grid is not modified.
  template <class Visit>
  void QueryFace(std::size_t f, QueryMarks& marks, Visit&& visit) const {
    const FaceEntry& e = faces_[f];
    if (e.slotCount == kNoSlots) { // a large face: the general query
      Query(BoxOf(f), marks, [&](std::size_t g) {
        if (g != f) visit(g);
      });
      return;
    }
    for (int i = 0; i < e.slotCount; ++i) {
      const std::array<int, 3>& c = cellCoord_[e.cellSlots[i]];
      for (const std::uint32_t g : cells_[e.cellSlots[i]]) {
        if (g == f) continue;
        const FaceEntry& o = faces_[g];
        if (std::max(e.range[0], o.range[0]) != c[0] || std::max(e.range[1], o.range[1]) != c[1] ||
            std::max(e.range[2], o.range[2]) != c[2])
          continue;
        if (e.box.Touches(o.box)) visit(std::size_t(g));
      }
    }
  }

  static bool Touch(const Box& a, const Box& b) {
    return a.min[0] <= b.max[0] && b.min[0] <= a.max[0] && a.min[1] <= b.max[1] && b.min[1] <= a.max[1] &&
           a.min[2] <= b.max[2] && b.min[2] <= a.max[2];
  }

private:
  static constexpr std::uint64_t kEmpty = std::numeric_limits<std::uint64_t>::max();
  static constexpr int kBias = 1 << 20; ///< cell coordinates are clamped to [-2^20, 2^20)
  static constexpr int kInlineSlots = 8;
  static constexpr std::uint64_t kAxisMask = (std::uint64_t(1) << 21) - 1; ///< one coordinate of a Key
  static constexpr std::size_t kInsertBlockFaces =
      8192; ///< InsertAll's blocks: small enough for their tables to stay in cache
  static constexpr std::uint8_t kNoSlots = 0xff;

  struct FaceEntry {
    FloatBox box;               ///< rounded outward
    std::array<int, 6> range{}; ///< cell range: lo x y z, hi x y z
    std::array<std::uint32_t, kInlineSlots> cellSlots{};
    std::uint8_t slotCount = 0; ///< kNoSlots when the range has more cells than kInlineSlots
    bool in = false;
  };

  static void SetBox(FaceEntry& e, const Box& b) { e.box = FloatBox::Outward(b); }
  /// Box, cell range and slot mode of a face entering the grid (not yet in any cell list).
  /// Returns the number of cells of its range.
  std::uint32_t SetEntry(FaceEntry& e, const Box& box) const {
    SetBox(e, box);
    e.in = true;
    RangeOf(box, e.range);
    const std::uint32_t cells = std::uint32_t(e.range[3] - e.range[0] + 1) *
                                std::uint32_t(e.range[4] - e.range[1] + 1) *
                                std::uint32_t(e.range[5] - e.range[2] + 1);
    e.slotCount = cells <= kInlineSlots ? 0 : kNoSlots;
    return cells;
  }
  /// Appends face f (its entry set) to the lists of the cells of its range, creating cells.
  void LinkCells(std::size_t f) {
    FaceEntry& e = faces_[f];
    ForEachCell(e.range, [&](int x, int y, int z) {
      const std::uint32_t slot = FindOrCreate(x, y, z);
      cells_[slot].push_back(std::uint32_t(f));
      if (e.slotCount != kNoSlots) e.cellSlots[e.slotCount++] = slot;
    });
  }
  static bool Touch(const FaceEntry& e, const Box& b) { return e.box.Touches(b); }
  int CellCoord(double x, int axis) const {
    const double c = std::floor((x - origin_[axis]) * inv_);
    return int(std::clamp(c, double(-kBias), double(kBias - 1)));
  }
  void RangeOf(const Box& b, std::array<int, 6>& r) const {
    for (int k = 0; k < 3; ++k) {
      r[k] = CellCoord(b.min[k], k);
      r[k + 3] = CellCoord(b.max[k], k);
    }
  }
  /// Calls fn(x, y, z) for the cells of range r, z outermost, x innermost (Insert's order).
  template <class Fn>
  static void ForEachCell(const std::array<int, 6>& r, Fn&& fn) {
    for (int z = r[2]; z <= r[5]; ++z)
      for (int y = r[1]; y <= r[4]; ++y)
        for (int x = r[0]; x <= r[3]; ++x) fn(x, y, z);
  }
  static std::uint64_t Key(int x, int y, int z) {
    return (std::uint64_t(x + kBias) << 42) | (std::uint64_t(y + kBias) << 21) | std::uint64_t(z + kBias);
  }
  static std::uint64_t Hash(std::uint64_t k) { // splitmix64 finalizer
    k ^= k >> 30;
    k *= 0xbf58476d1ce4e5b9ULL;
    k ^= k >> 27;
    k *= 0x94d049bb133111ebULL;
    k ^= k >> 31;
    return k;
  }
  int Find(std::uint64_t key) const {
    const std::size_t mask = keys_.size() - 1;
    for (std::size_t i = Hash(key) & mask;; i = (i + 1) & mask) {
      if (keys_[i] == key) return int(slots_[i]);
      if (keys_[i] == kEmpty) return -1;
    }
  }
  std::uint32_t FindOrCreate(int x, int y, int z) {
    const std::uint64_t key = Key(x, y, z);
    if (2 * (used_ + 1) > keys_.size()) Grow();
    const std::size_t mask = keys_.size() - 1;
    for (std::size_t i = Hash(key) & mask;; i = (i + 1) & mask) {
      if (keys_[i] == key) return slots_[i];
      if (keys_[i] == kEmpty) {
        keys_[i] = key;
        slots_[i] = std::uint32_t(cells_.size());
        cells_.emplace_back();
        cellCoord_.push_back({x, y, z});
        ++used_;
        return slots_[i];
      }
    }
  }
  void Grow() {
    std::vector<std::uint64_t> oldKeys(keys_.size() * 2, kEmpty);
    std::vector<std::uint32_t> oldSlots(slots_.size() * 2, 0);
    oldKeys.swap(keys_);
    oldSlots.swap(slots_);
    const std::size_t mask = keys_.size() - 1;
    for (std::size_t j = 0; j < oldKeys.size(); ++j) {
      if (oldKeys[j] == kEmpty) continue;
      std::size_t i = Hash(oldKeys[j]) & mask;
      while (keys_[i] != kEmpty) i = (i + 1) & mask;
      keys_[i] = oldKeys[j];
      slots_[i] = oldSlots[j];
    }
  }

  double cell_ = 1, inv_ = 1;
  vcg::Point3d origin_{0, 0, 0};
  std::vector<std::uint64_t> keys_;
  std::vector<std::uint32_t> slots_;
  std::vector<std::vector<std::uint32_t>> cells_;
  std::vector<std::array<int, 3>> cellCoord_;
  std::vector<FaceEntry> faces_;
  QueryMarks ownMarks_;
  std::size_t used_ = 0;
};

} // namespace molremesh

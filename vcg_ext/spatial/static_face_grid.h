// A static uniform grid of face bounding boxes, hashed by cell: the static member of the face
// grid family (FaceHashGrid is the dynamic one, updated per edit; distance_detail::TriangleGrid
// holds a fixed triangle soup for distance queries).
//
// The faces present at construction are kept as one sorted (cell, face) array, which is compact
// and fast to build for a whole mesh; the few faces added later (by hole fills) go to a small map.
// Boxes are exact double boxes (closed tests), so Query returns exactly the live faces whose box
// touches the query box, in a deterministic order: faces too large to grid first, then cell by
// cell, construction-time faces of a cell before the ones added later. Deleted faces are skipped
// when queried, never removed. Not thread-safe (Query keeps visit marks).
#pragma once

#include <vcg/space/box3.h>

#include <vcg_ext/core/index.h>
#include <vcg_ext/geometry/point.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

namespace molremesh {

/// Uniform grid of face bounding boxes, hashed: the faces present at construction are kept as a
/// sorted (cell, face) array, faces added later in a small map; deleted faces are skipped when
/// queried.
template <class MeshType>
class StaticFaceGrid {
public:
  using Corners = std::array<Index, 3>; ///< vertex indices of a triangle

  StaticFaceGrid(const MeshType& m, double cell) : cell_(cell > 0 ? cell : 1.0) {
    for (Index f = 0; f < m.face.size(); ++f) {
      if (m.face[f].IsD()) continue;
      const vcg::Box3d box = Box(m, FaceCorners(m, m.face[f]));
      if (CellCount(box) > kMaxCells)
        big_.push_back(f);
      else
        ForCells(box, [&](std::uint64_t key) { sorted_.emplace_back(key, f); });
    }
    std::sort(sorted_.begin(), sorted_.end());
  }
  void Insert(const MeshType& m, Index f) {
    const vcg::Box3d box = Box(m, FaceCorners(m, m.face[f]));
    if (CellCount(box) > kMaxCells)
      big_.push_back(f);
    else
      ForCells(box, [&](std::uint64_t key) { added_[key].push_back(f); });
  }
  /// Live faces whose bounding box touches box (closed test), each once.
  void Query(const MeshType& m, const vcg::Box3d& box, std::vector<Index>& out) {
    out.clear();
    if (marks_.stamp.size() < m.face.size()) marks_.stamp.resize(m.face.size(), 0);
    ++marks_.current;
    Visit(m, box, [&](Index f) {
      if (marks_.stamp[f] == marks_.current) return;
      marks_.stamp[f] = marks_.current;
      out.push_back(f);
    });
  }
  /// Calls fn(f) for the live faces whose bounding box touches box, a face once per cell it shares
  /// with box (no visit marks: safe on many threads at once while nothing is inserted).
  template <class Fn>
  void Visit(const MeshType& m, const vcg::Box3d& box, Fn fn) const {
    auto consider = [&](Index f) {
      if (f >= m.face.size() || m.face[f].IsD()) return;
      const vcg::Box3d fb = Box(m, FaceCorners(m, m.face[f]));
      for (int a = 0; a < 3; ++a)
        if (fb.max[a] < box.min[a] || box.max[a] < fb.min[a]) return;
      fn(f);
    };
    for (Index f : big_) consider(f);
    if (CellCount(box) > kMaxCells) {
      for (Index f = 0; f < m.face.size(); ++f) consider(f);
      return;
    }
    ForCells(box, [&](std::uint64_t key) {
      auto it = std::lower_bound(sorted_.begin(), sorted_.end(), std::make_pair(key, Index(0)));
      for (; it != sorted_.end() && it->first == key; ++it) consider(it->second);
      if (const auto a = added_.find(key); a != added_.end())
        for (Index f : a->second) consider(f);
    });
  }
  /// Bounding box of triangle t, grown by margin on every side.
  static vcg::Box3d Box(const MeshType& m, const Corners& t, double margin = 0) {
    vcg::Box3d box;
    for (Index v : t) box.Add(PositionOf(&m.vert[v]));
    box.Offset(margin);
    return box;
  }

private:
  static Corners FaceCorners(const MeshType& m, const typename MeshType::FaceType& f) {
    return {Index(f.cV(0) - &m.vert[0]), Index(f.cV(1) - &m.vert[0]), Index(f.cV(2) - &m.vert[0])};
  }
  static constexpr double kMaxCells = 4096;
  double CellCount(const vcg::Box3d& box) const {
    double count = 1;
    for (int a = 0; a < 3; ++a) count *= std::floor(box.max[a] / cell_) - std::floor(box.min[a] / cell_) + 1;
    return count;
  }
  template <class Fn>
  void ForCells(const vcg::Box3d& box, Fn fn) const {
    const double inv = 1.0 / cell_;
    std::array<std::int64_t, 3> lo{}, hi{};
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::int64_t(std::floor(box.min[a] * inv));
      hi[a] = std::int64_t(std::floor(box.max[a] * inv));
    }
    for (std::int64_t x = lo[0]; x <= hi[0]; ++x)
      for (std::int64_t y = lo[1]; y <= hi[1]; ++y)
        for (std::int64_t z = lo[2]; z <= hi[2]; ++z)
          fn((std::uint64_t(x) * 73856093u) ^ (std::uint64_t(y) * 19349663u) ^
             (std::uint64_t(z) * 83492791u));
  }
  double cell_;
  std::vector<std::pair<std::uint64_t, Index>> sorted_;
  std::vector<Index> big_;
  std::unordered_map<std::uint64_t, std::vector<Index>> added_;
  struct Marks { // visit marks of Query
    std::vector<std::uint32_t> stamp;
    std::uint32_t current = 0;
  };
  Marks marks_;
};

} // namespace molremesh

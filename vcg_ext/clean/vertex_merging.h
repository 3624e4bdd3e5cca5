// Cleaning step: merge coincident vertices (vcg_ext/clean/).
//
// MergeCloseVertices maps every vertex within a radius of an earlier surviving vertex onto it, in
// index order, so the result does not depend on the spatial sort used to find the partners.
// Positions never change. No adjacency is needed or kept: rebuild it afterwards.
#pragma once

#include <vcg/complex/complex.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include <vcg_ext/clean/clean_mesh_access.h>
#include <vcg_ext/core/index.h>
#include <vcg_ext/geometry/point.h>

namespace molremesh {
namespace clean {

/// Maps every vertex within `radius` of an earlier surviving vertex onto it (in index order, so the
/// result is deterministic), re-references the faces and deletes the merged vertices. radius 0 (or
/// too small to grid) merges exact copies only. Positions are never changed.
template <class MeshType>
std::size_t MergeCloseVertices(MeshType& m, double radius, double cellSize) {
  const std::size_t n = m.vert.size();
  std::vector<Index> target(n, kNone);
  std::size_t merged = 0;
  if (!(radius > 1e-300)) {
    std::vector<Index> order;
    for (Index v = 0; v < n; ++v)
      if (!m.vert[v].IsD()) order.push_back(v);
    auto less = [&m](Index a, Index b) {
      const Point pa = PositionOf(&m.vert[a]), pb = PositionOf(&m.vert[b]);
      if (pa != pb) return pa < pb;
      return a < b;
    };
    std::sort(order.begin(), order.end(), less);
    for (std::size_t i = 1; i < order.size(); ++i) {
      if (PositionOf(&m.vert[order[i]]) != PositionOf(&m.vert[order[i - 1]])) continue;
      const Index keep = target[order[i - 1]] != kNone ? target[order[i - 1]] : order[i - 1];
      target[order[i]] = keep;
      ++merged;
    }
  } else {
    // Vertices sorted by their cell (cells of size >= radius): the merge partners of a vertex are in
    // its own cell or in a neighbouring cell closer than radius. Only earlier vertices that survive
    // are candidates, so the result is that of a scan in index order, independent of the sort.
    using Cell = std::array<std::int64_t, 3>;
    const double size = std::max(radius, cellSize);
    const double inv = 1.0 / size;
    std::vector<Cell> cell(n);
    std::vector<std::pair<Cell, Index>> sorted;
    sorted.reserve(n);
    for (Index v = 0; v < n; ++v) {
      if (m.vert[v].IsD()) continue;
      const Point p = PositionOf(&m.vert[v]);
      cell[v] = {std::int64_t(std::floor(p[0] * inv)), std::int64_t(std::floor(p[1] * inv)),
                 std::int64_t(std::floor(p[2] * inv))};
      sorted.emplace_back(cell[v], v);
    }
    std::sort(sorted.begin(), sorted.end());
    for (Index v = 0; v < n; ++v) {
      if (m.vert[v].IsD()) continue;
      const Point p = PositionOf(&m.vert[v]);
      Index best = kNone;
      double bestDistance = radius;
      std::array<std::int64_t, 3> lo{}, hi{};
      for (int a = 0; a < 3; ++a) {
        lo[a] = std::int64_t(std::floor((p[a] - radius) * inv)) - cell[v][a];
        hi[a] = std::int64_t(std::floor((p[a] + radius) * inv)) - cell[v][a];
      }
      for (std::int64_t dx = lo[0]; dx <= hi[0]; ++dx)
        for (std::int64_t dy = lo[1]; dy <= hi[1]; ++dy)
          for (std::int64_t dz = lo[2]; dz <= hi[2]; ++dz) {
            const Cell c{cell[v][0] + dx, cell[v][1] + dy, cell[v][2] + dz};
            auto it = std::lower_bound(sorted.begin(), sorted.end(), std::make_pair(c, Index(0)));
            for (; it != sorted.end() && it->first == c && it->second < v; ++it) {
              const Index w = it->second;
              if (target[w] != kNone) continue; // merged itself: not a survivor
              const double d = (PositionOf(&m.vert[w]) - p).Norm();
              if (d <= bestDistance && (best == kNone || d < bestDistance || w < best)) {
                best = w;
                bestDistance = d;
              }
            }
          }
      if (best != kNone) {
        target[v] = best;
        ++merged;
      }
    }
  }
  if (merged == 0) return 0;
  for (auto& f : m.face) {
    if (f.IsD()) continue;
    for (int k = 0; k < 3; ++k) {
      const Index t = target[VI(m, f, k)];
      if (t != kNone) f.V(k) = &m.vert[t];
    }
  }
  for (Index v = 0; v < n; ++v)
    if (target[v] != kNone) vcg::tri::Allocator<MeshType>::DeleteVertex(m, m.vert[v]);
  return merged;
}

} // namespace clean
} // namespace molremesh

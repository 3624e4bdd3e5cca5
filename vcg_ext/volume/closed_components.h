// The closed surfaces of a mesh and how they face: per edge-connected component its signed volume
// (positive: it bounds a body, normals outward; negative: it bounds a cavity inside a body, normals
// into the void), and the edges whose two faces run them the same way (inconsistent orientation).
#pragma once

#include <vcg_ext/core/index.h>
#include <vcg_ext/core/union_find.h>
#include <vcg_ext/geometry/point.h>

#include <vcg/complex/complex.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace molremesh {

struct ClosedComponents {
  std::vector<double> volumes;      ///< per component (through shared vertices), largest |volume| first
  std::size_t bodies = 0;           ///< components of positive volume
  std::size_t cavities = 0;         ///< components of negative volume
  std::size_t misorientedEdges = 0; ///< directed edges two faces use (orientation conflicts)
  std::size_t unpairedEdges = 0;    ///< directed edges whose reverse no face uses (open or non-manifold)
};

/// Components, their volumes and the orientation conflicts of the live faces of m.
template <class MeshType>
ClosedComponents MeasureClosedComponents(const MeshType& m) {
  ClosedComponents c;
  UnionFind sets(m.vert.size());
  std::vector<std::pair<std::uint64_t, std::uint64_t>> directed;
  for (const auto& f : m.face) {
    if (f.IsD()) continue;
    for (int k = 0; k < 3; ++k) {
      const std::uint64_t a = std::uint64_t(vcg::tri::Index(m, f.cV(k)));
      const std::uint64_t b = std::uint64_t(vcg::tri::Index(m, f.cV((k + 1) % 3)));
      sets.Unite(std::uint32_t(a), std::uint32_t(b));
      directed.emplace_back(a, b);
    }
  }
  std::sort(directed.begin(), directed.end());
  for (std::size_t i = 0; i < directed.size(); ++i) {
    if (i > 0 && directed[i] == directed[i - 1]) ++c.misorientedEdges;
    const std::pair<std::uint64_t, std::uint64_t> reverse(directed[i].second, directed[i].first);
    if (!std::binary_search(directed.begin(), directed.end(), reverse)) ++c.unpairedEdges;
  }
  std::vector<Index> componentOfRoot(m.vert.size(), kNoIndex);
  for (const auto& f : m.face) {
    if (f.IsD()) continue;
    const std::uint32_t root = sets.Find(std::uint32_t(vcg::tri::Index(m, f.cV(0))));
    if (componentOfRoot[root] == kNoIndex) {
      componentOfRoot[root] = Index(c.volumes.size());
      c.volumes.push_back(0);
    }
    const Point a = PositionOf(f.cV(0)), b = PositionOf(f.cV(1)), d = PositionOf(f.cV(2));
    c.volumes[componentOfRoot[root]] += a * (b ^ d) / 6.0;
  }
  std::stable_sort(c.volumes.begin(), c.volumes.end(),
                   [](double x, double y) { return std::abs(x) > std::abs(y); });
  for (double v : c.volumes) ++(v > 0 ? c.bodies : c.cavities);
  return c;
}

} // namespace molremesh

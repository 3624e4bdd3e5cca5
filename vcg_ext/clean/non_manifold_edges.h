// Cleaning step: make every edge manifold (vcg_ext/clean/).
//
// ResolveNonManifoldEdges keeps, on each edge with k > 2 faces, the flattest consistently oriented
// pair and deletes the k - 2 others (the holes this leaves are closed by the hole filling). No
// adjacency is needed or kept: rebuild it afterwards when anything was removed.
#pragma once

#include <vcg/complex/complex.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include <vcg_ext/clean/clean_mesh_access.h>
#include <vcg_ext/core/index.h>
#include <vcg_ext/geometry/point.h>

namespace molremesh {
namespace clean {

/// On every edge with k > 2 faces keeps the pair that is consistently oriented (opposite directions
/// along the edge) and the flattest (normals agreeing), and removes the k - 2 others. Edges are
/// processed in a fixed order and faces already removed no longer count, so a face removed for one
/// edge may make a later edge manifold. No adjacency needed.
template <class MeshType>
std::size_t ResolveNonManifoldEdges(MeshType& m) {
  struct Entry {
    std::uint64_t key;
    Index face;
    bool forward; // the face runs the edge from min to max vertex
    bool operator<(const Entry& o) const { return key != o.key ? key < o.key : face < o.face; }
  };
  std::vector<Entry> entries;
  entries.reserve(3 * std::size_t(m.fn));
  for (Index f = 0; f < m.face.size(); ++f) {
    if (m.face[f].IsD()) continue;
    for (int k = 0; k < 3; ++k) {
      const Index a = VI(m, m.face[f], k), b = VI(m, m.face[f], (k + 1) % 3);
      entries.push_back({EdgeKey(a, b), f, a < b});
    }
  }
  std::sort(entries.begin(), entries.end());
  std::size_t removed = 0;
  std::vector<Entry> group;
  for (std::size_t i = 0; i < entries.size();) {
    std::size_t j = i;
    while (j < entries.size() && entries[j].key == entries[i].key) ++j;
    if (j - i > 2) {
      group.clear();
      for (std::size_t k = i; k < j; ++k)
        if (!m.face[entries[k].face].IsD()) group.push_back(entries[k]);
      if (group.size() > 2) {
        std::size_t keepA = 0, keepB = 1;
        double bestScore = -std::numeric_limits<double>::infinity();
        for (std::size_t a = 0; a < group.size(); ++a)
          for (std::size_t b = a + 1; b < group.size(); ++b) {
            const Point na = FaceNormal(m, m.face[group[a].face]), nb = FaceNormal(m, m.face[group[b].face]);
            const bool consistent = group[a].forward != group[b].forward;
            const double score = (consistent ? 2.0 : 0.0) + (consistent ? na * nb : -(na * nb));
            if (score > bestScore) {
              bestScore = score;
              keepA = a;
              keepB = b;
            }
          }
        for (std::size_t a = 0; a < group.size(); ++a)
          if (a != keepA && a != keepB) {
            DeleteFace(m, group[a].face);
            ++removed;
          }
      }
    }
    i = j;
  }
  return removed;
}

} // namespace clean
} // namespace molremesh

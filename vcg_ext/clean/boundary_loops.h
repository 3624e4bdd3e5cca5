// Boundary loops of a coherently oriented mesh (vcg_ext/clean/): tracing a loop from one of its
// half-edges, checking that a loop found earlier is still open, and cutting a loop that passes
// several times through a vertex into simple loops ("lobes").
//
// TraceLoop needs fresh FF adjacency; the other two read only the faces.
#pragma once

#include <vcg/complex/complex.h>

#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <utility>
#include <vector>

#include <vcg_ext/clean/clean_mesh_access.h>
#include <vcg_ext/core/index.h>

namespace molremesh {
namespace clean {

/// A closed boundary polyline.
struct BoundaryLoop {
  std::vector<Index> verts; ///< verts[i] -> verts[i+1] is a boundary half-edge ...
  std::vector<Index> faces; ///< ... of face faces[i]
};

/// Cuts a loop at its repeated vertices into simple cycles ("lobes"). Each lobe is filled on its
/// own, which turns a pinch vertex (boundary passing twice) into a single manifold fan.
inline std::vector<BoundaryLoop> SplitIntoLobes(const BoundaryLoop& loop) {
  std::vector<BoundaryLoop> lobes;
  std::vector<std::pair<Index, Index>> path; // (start vertex, face) of the half-edges on the stack
  std::unordered_map<Index, std::size_t> at; // start vertex -> position on the stack
  const std::size_t n = loop.verts.size();
  for (std::size_t k = 0; k < n; ++k) {
    at[loop.verts[k]] = path.size();
    path.emplace_back(loop.verts[k], loop.faces[k]);
    const Index end = loop.verts[(k + 1) % n];
    const auto it = at.find(end);
    if (it == at.end()) continue;
    const std::size_t s = it->second;
    BoundaryLoop lobe;
    for (std::size_t i = s; i < path.size(); ++i) {
      lobe.verts.push_back(path[i].first);
      lobe.faces.push_back(path[i].second);
      at.erase(path[i].first);
    }
    path.resize(s);
    lobes.push_back(std::move(lobe));
  }
  if (!path.empty()) lobes.clear(); // cannot happen for a closed loop; be safe
  return lobes;
}

template <class MeshType>
class BoundaryLoops {
public:
  using FaceType = typename MeshType::FaceType;
  using VertexPointer = typename MeshType::VertexPointer;

  /// Follows the boundary from half-edge (f0, e0) to the next one around each end vertex within its
  /// fan (as vcglib's Pos::NextB), so a pinch vertex is passed once per fan. False when the loop does
  /// not close properly (inconsistent orientation around a non-orientable spot).
  static bool TraceLoop(MeshType& m, Index f0, int e0, std::vector<std::uint8_t>& visited,
                        BoundaryLoop& loop) {
    loop.verts.clear();
    loop.faces.clear();
    Index f = f0;
    int e = e0;
    const std::size_t maxSteps = 3 * m.face.size() + 3;
    for (std::size_t step = 0; step < maxSteps; ++step) {
      visited[f] |= std::uint8_t(1u << e);
      FaceType* F = &m.face[f];
      loop.verts.push_back(VI(m, *F, e));
      loop.faces.push_back(f);
      const VertexPointer v = F->V((e + 1) % 3);
      FaceType* g = F;
      int ge = (e + 1) % 3; // edge of g leaving v
      int guard = 0;
      while (!IsBorderEdge(*g, ge)) {
        FaceType* h = g->FFp(ge);
        const int he = g->FFi(ge);
        if (h->V((he + 1) % 3) != v) return false; // incoherent orientation
        g = h;
        ge = (he + 1) % 3;
        if (++guard > 100000 || (g == F && ge == (e + 1) % 3)) return false;
      }
      f = FI(m, g);
      e = ge;
      if (f == f0 && e == e0) return loop.verts.size() >= 3;
      if (visited[f] & (1u << e)) return false;
    }
    return false;
  }

  /// Whether every boundary half-edge of `loop` is still there: an earlier grown fill may have
  /// removed one of its faces or closed one of its sides.
  static bool LoopStillOpen(const MeshType& m, const BoundaryLoop& loop) {
    const std::size_t n = loop.verts.size();
    for (std::size_t i = 0; i < n; ++i) {
      const FaceType& f = m.face[loop.faces[i]];
      if (f.IsD()) return false;
      int e = 0;
      while (e < 3 && !(VI(m, f, e) == loop.verts[i] && VI(m, f, (e + 1) % 3) == loop.verts[(i + 1) % n]))
        ++e;
      if (e == 3 || !IsBorderEdge(f, e)) return false;
    }
    return true;
  }
};

} // namespace clean
} // namespace molremesh

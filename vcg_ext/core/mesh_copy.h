// Copies the triangles (live vertex positions and faces) of one vcg mesh type into another.
//
// The MeshLab plugin runs every stage on a double-precision copy of the layer and writes the
// result back only when the stage succeeded, so a failing stage can never leave a half-edited
// layer behind. Only geometry and connectivity travel: per-element colors, qualities and flags
// describe the old triangles and are meaningless after remeshing.
#pragma once

#include <vcg/complex/complex.h>

#include <vector>

namespace molremesh {

/// Replaces `to` with the live vertices and faces of `from` (compacted, order kept).
/// Unreferenced vertices are kept so a stage that refuses them sees them.
template <class MeshTo, class MeshFrom>
void CopyTriangles(MeshTo& to, const MeshFrom& from) {
  using ScalarTo = typename MeshTo::ScalarType;
  to.Clear();
  std::vector<int> newIndex(from.vert.size(), -1);
  int liveVertices = 0;
  for (std::size_t i = 0; i < from.vert.size(); ++i)
    if (!from.vert[i].IsD()) newIndex[i] = liveVertices++;
  auto vi = vcg::tri::Allocator<MeshTo>::AddVertices(to, liveVertices);
  for (std::size_t i = 0; i < from.vert.size(); ++i) {
    if (newIndex[i] < 0) continue;
    const auto& p = from.vert[i].cP();
    to.vert[std::size_t(newIndex[i])].P() =
        vcg::Point3<ScalarTo>(ScalarTo(p[0]), ScalarTo(p[1]), ScalarTo(p[2]));
  }
  (void)vi;
  int liveFaces = 0;
  for (const auto& f : from.face)
    if (!f.IsD()) ++liveFaces;
  auto fi = vcg::tri::Allocator<MeshTo>::AddFaces(to, liveFaces);
  for (const auto& f : from.face) {
    if (f.IsD()) continue;
    for (int k = 0; k < 3; ++k) fi->V(k) = &to.vert[std::size_t(newIndex[vcg::tri::Index(from, f.cV(k))])];
    ++fi;
  }
}

} // namespace molremesh

// Face-face adjacency in linear time.
//
// vcg::tri::UpdateTopology::FaceFace sorts one record per face side (1.5 M of them on a 500k-face
// mesh) with a general comparison sort; the pipeline rebuilds the adjacency before every stage
// and every local stage does it again in LocalRemeshingOps::PrepareTopology, and these sorts
// added up to about 3 s of a 4JSV run. UpdateFaceFaceTopology builds the same relation with
// ForEachEdgeSideGroup: a counting sort of the sides by their smaller vertex index, so only the
// few sides at one vertex are ever compared (ReferenceSurface builds its face adjacency with it
// too).
//
// The result follows vcglib's convention: the sides sharing one (unordered) vertex pair form a
// cycle through FFp/FFi (two faces point at each other, a border side points at its own face
// and side, three or more faces of a non-manifold edge form a ring, in ascending face order
// here, while vcglib's ring follows its own unstable sort: CleanRawMesh, which walks such rings,
// falls back to vcglib when UpdateFaceFaceTopology reports a non-manifold edge). Deleted faces are
// skipped and keep their old pointers, as in vcglib.
#pragma once

#include <vcg/complex/complex.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace molremesh {

/// One side (edge) of a triangle, as ForEachEdgeSideGroup hands it out.
struct EdgeSide {
  std::uint32_t other; ///< the larger vertex index of the side
  std::uint32_t face;  ///< the triangle's index
  int z;               ///< side number in its triangle (from corner z to corner z + 1)
  bool operator<(const EdgeSide& o) const {
    return other != o.other ? other < o.other : (face != o.face ? face < o.face : z < o.z);
  }
};

/// Groups the sides of triangles 0 .. faceCount - 1 by their (unordered) vertex pair in linear
/// time: a counting sort of the sides by their smaller vertex index, so only the few sides at
/// one vertex are ever compared. vertexOf(f, k) is corner k's vertex index (< vertexCount) of
/// triangle f; live(f) says whether triangle f takes part. Calls group(first, last) once per
/// vertex pair with its sides, sorted by triangle then side number; the groups come in order
/// of the smaller vertex, then the larger.
template <class VertexOf, class Live, class Group>
void ForEachEdgeSideGroup(std::size_t vertexCount, std::size_t faceCount, VertexOf&& vertexOf, Live&& live,
                          Group&& group) {
  std::vector<std::uint32_t> start(vertexCount + 1, 0);
  for (std::size_t f = 0; f < faceCount; ++f) {
    if (!live(f)) continue;
    for (int z = 0; z < 3; ++z) ++start[std::min(vertexOf(f, z), vertexOf(f, (z + 1) % 3)) + 1];
  }
  for (std::size_t v = 0; v < vertexCount; ++v) start[v + 1] += start[v];
  std::vector<EdgeSide> sides(start[vertexCount]);
  {
    std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
    for (std::size_t f = 0; f < faceCount; ++f) {
      if (!live(f)) continue;
      for (int z = 0; z < 3; ++z) {
        const std::uint32_t a = vertexOf(f, z), b = vertexOf(f, (z + 1) % 3);
        sides[fill[std::min(a, b)]++] = {std::max(a, b), std::uint32_t(f), z};
      }
    }
  }
  for (std::size_t v = 0; v < vertexCount; ++v) {
    const auto begin = sides.begin() + start[v], end = sides.begin() + start[v + 1];
    std::sort(begin, end);
    for (auto first = begin; first != end;) {
      auto last = first;
      while (last != end && last->other == first->other) ++last;
      group(first, last);
      first = last;
    }
  }
}

/// Builds the face-face adjacency of m (see the file comment). Returns the number of
/// non-manifold edges (three or more faces), whose rings are ordered by face index here.
template <class MeshType>
std::size_t UpdateFaceFaceTopology(MeshType& m) {
  const std::size_t nv = m.vert.size();
  if (nv == 0 || m.face.empty()) return 0;
  const auto* vertBegin = &m.vert[0];
  std::size_t nonManifoldEdges = 0;
  ForEachEdgeSideGroup(
      nv, m.face.size(), [&](std::size_t f, int k) { return std::uint32_t(m.face[f].cV(k) - vertBegin); },
      [&](std::size_t f) { return !m.face[f].IsD(); },
      [&](auto first, auto last) {
        if (last - first > 2) ++nonManifoldEdges;
        // Each side points at the next one of its group, the last back at the first.
        for (auto it = first; it != last; ++it) {
          const auto to = (it + 1 == last) ? first : it + 1;
          auto& f = m.face[it->face];
          f.FFp(it->z) = &m.face[to->face];
          f.FFi(it->z) = to->z;
        }
      });
  return nonManifoldEdges;
}

/// Face-face (UpdateFaceFaceTopology) and vertex-face adjacency of m: what the stages rebuild
/// after changing the faces.
template <class MeshType>
void UpdateAdjacency(MeshType& m) {
  UpdateFaceFaceTopology(m);
  vcg::tri::UpdateTopology<MeshType>::VertexFace(m);
}

} // namespace molremesh

// Face-face adjacency in linear time, on several threads.
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

#include <vcg_ext/core/parallel_for.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <numeric>
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
/// triangle f; live(f) says whether triangle f takes part. Calls group(first, last, thread) once
/// per vertex pair with its sides, sorted by triangle then side number.
///
/// With threads > 1 (and enough triangles) the three passes run in parallel: each thread counts
/// and places the sides of its own contiguous block of triangles, at offsets that put block t
/// after block t - 1 in every bucket, so the buckets hold what the serial pass would put there;
/// the groups of different smaller vertices then come in any order, concurrently, so group must
/// only write what belongs to its own sides (thread: 0 .. threads - 1, for per-thread sums).
/// Serially they come in order of the smaller vertex, then the larger.
template <class VertexOf, class Live, class Group>
void ForEachEdgeSideGroup(std::size_t vertexCount, std::size_t faceCount, VertexOf&& vertexOf, Live&& live,
                          Group&& group, int threads = 1) {
  constexpr std::size_t kMinFacesPerThread = 32768; // below this, threads cost more than they save
  threads = std::max(1, std::min(ResolveThreadCount(threads), int(faceCount / kMinFacesPerThread)));
  const std::size_t blocks = std::size_t(threads);
  auto blockBegin = [&](std::size_t b) { return faceCount * b / blocks; };
  // count[b][v + 1]: sides of block b whose smaller vertex is v; then where block b writes them.
  std::vector<std::vector<std::uint32_t>> count(blocks, std::vector<std::uint32_t>(vertexCount + 1, 0));
  ParallelFor(
      blocks, threads,
      [&](std::size_t begin, std::size_t end, int) {
        for (std::size_t b = begin; b < end; ++b)
          for (std::size_t f = blockBegin(b); f < blockBegin(b + 1); ++f) {
            if (!live(f)) continue;
            for (int z = 0; z < 3; ++z) ++count[b][std::min(vertexOf(f, z), vertexOf(f, (z + 1) % 3)) + 1];
          }
      },
      1);
  std::vector<std::uint32_t> start(vertexCount + 1, 0);
  for (std::size_t v = 0; v < vertexCount; ++v) {
    std::uint32_t at = start[v];
    for (std::size_t b = 0; b < blocks; ++b) {
      const std::uint32_t n = count[b][v + 1];
      count[b][v] = at; // block b's first slot in bucket v
      at += n;
    }
    start[v + 1] = at;
  }
  std::vector<EdgeSide> sides(start[vertexCount]);
  ParallelFor(
      blocks, threads,
      [&](std::size_t begin, std::size_t end, int) {
        for (std::size_t b = begin; b < end; ++b) {
          std::vector<std::uint32_t>& fill = count[b];
          for (std::size_t f = blockBegin(b); f < blockBegin(b + 1); ++f) {
            if (!live(f)) continue;
            for (int z = 0; z < 3; ++z) {
              const std::uint32_t a = vertexOf(f, z), c = vertexOf(f, (z + 1) % 3);
              sides[fill[std::min(a, c)]++] = {std::max(a, c), std::uint32_t(f), z};
            }
          }
        }
      },
      1);
  count = {};
  ParallelFor(
      vertexCount, threads,
      [&](std::size_t vBegin, std::size_t vEnd, int thread) {
        for (std::size_t v = vBegin; v < vEnd; ++v) {
          const auto begin = sides.begin() + start[v], end = sides.begin() + start[v + 1];
          std::sort(begin, end);
          for (auto first = begin; first != end;) {
            auto last = first;
            while (last != end && last->other == first->other) ++last;
            group(first, last, thread);
            first = last;
          }
        }
      },
      4096);
}

/// Builds the face-face adjacency of m (see the file comment). Returns the number of
/// non-manifold edges (three or more faces), whose rings are ordered by face index here.
template <class MeshType>
std::size_t UpdateFaceFaceTopology(MeshType& m, int threads = 0) {
  const std::size_t nv = m.vert.size();
  if (nv == 0 || m.face.empty()) return 0;
  const auto* vertBegin = &m.vert[0];
  std::vector<std::size_t> nonManifoldEdges(std::size_t(ResolveThreadCount(threads)), 0);
  ForEachEdgeSideGroup(
      nv, m.face.size(), [&](std::size_t f, int k) { return std::uint32_t(m.face[f].cV(k) - vertBegin); },
      [&](std::size_t f) { return !m.face[f].IsD(); },
      [&](auto first, auto last, int thread) {
        if (last - first > 2) ++nonManifoldEdges[std::size_t(thread)];
        // Each side points at the next one of its group, the last back at the first.
        for (auto it = first; it != last; ++it) {
          const auto to = (it + 1 == last) ? first : it + 1;
          auto& f = m.face[it->face];
          f.FFp(it->z) = &m.face[to->face];
          f.FFi(it->z) = to->z;
        }
      },
      threads);
  return std::accumulate(nonManifoldEdges.begin(), nonManifoldEdges.end(), std::size_t(0));
}

/// Face-face (UpdateFaceFaceTopology, on `threads` threads) and vertex-face adjacency of m: what
/// the stages rebuild after changing the faces.
template <class MeshType>
void UpdateAdjacency(MeshType& m, int threads = 0) {
  UpdateFaceFaceTopology(m, threads);
  vcg::tri::UpdateTopology<MeshType>::VertexFace(m);
}

} // namespace molremesh

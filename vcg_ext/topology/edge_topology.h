// The edge table of a triangle soup and its incidence relations, in compressed-row form: the
// topology MeshQuality measures. It needs no adjacency in the mesh and accepts any input:
// open, non-manifold, with faces whose vertex indices repeat (those take no part in it).
#pragma once

#include <vcg_ext/core/index.h>
#include <vcg_ext/core/parallel_for.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace molremesh {

/// Edge table and incidence relations of the proper faces (three distinct valid vertex indices).
struct EdgeTopology {
  std::size_t vertexCount = 0;                 ///< size of m.vert
  std::vector<std::array<Index, 3>> faces;     ///< live faces, in m.face order (compact numbering)
  std::vector<bool> proper;                    ///< three distinct valid vertex indices
  std::vector<std::uint64_t> edgeKeys;         ///< (min << 32 | max), sorted, one per distinct edge
  std::vector<Index> edgeFaceStart, edgeFaces; ///< faces of edge e: [start[e], start[e+1])
  std::vector<Index> vertEdgeStart, vertEdges; ///< edges at vertex v
  std::vector<Index> vertFaceStart, vertFaces; ///< proper faces at vertex v, ascending
  std::vector<bool> onNonManifoldEdge;         ///< per vertex
  std::vector<bool> onBorder;                  ///< per vertex: boundary or non-manifold edge

  Index EdgeV0(std::size_t e) const { return Index(edgeKeys[e] >> 32); }
  Index EdgeV1(std::size_t e) const { return Index(edgeKeys[e] & 0xffffffffu); }
  Index EdgeFaceCount(std::size_t e) const { return edgeFaceStart[e + 1] - edgeFaceStart[e]; }
};

namespace edge_topology_detail {

/// Each proper face side as (larger vertex, face), bucketed by its smaller vertex: the sides of
/// vertex v are sides[sideStart[v], sideStart[v + 1]). Faces are visited in ascending order, so
/// each bucket lists them ascending.
inline void BucketSides(const EdgeTopology& t, std::vector<Index>& sideStart,
                        std::vector<std::pair<Index, Index>>& sides) {
  const std::size_t nv = t.vertexCount;
  const std::size_t nf = t.faces.size();
  sideStart.assign(nv + 1, 0);
  for (std::size_t f = 0; f < nf; ++f) {
    if (!t.proper[f]) continue;
    for (int i = 0; i < 3; ++i) ++sideStart[std::min(t.faces[f][i], t.faces[f][(i + 1) % 3]) + 1];
  }
  for (std::size_t v = 0; v < nv; ++v) sideStart[v + 1] += sideStart[v];
  sides.resize(sideStart[nv]); // (larger vertex, face)
  std::vector<Index> fill(sideStart.begin(), sideStart.end() - 1);
  for (std::size_t f = 0; f < nf; ++f) {
    if (!t.proper[f]) continue;
    for (int i = 0; i < 3; ++i) {
      const Index a = t.faces[f][i], b = t.faces[f][(i + 1) % 3];
      sides[fill[std::min(a, b)]++] = {std::max(a, b), Index(f)};
    }
  }
}

/// edgeKeys, edgeFaceStart and edgeFaces from the bucketed sides (which it sorts per bucket).
/// Sorted, the sides of one bucket list the edges at their smaller vertex in ascending order,
/// each edge's faces ascending. edgesAt[v + 1] counts the edges of bucket v, then becomes the
/// number of the first edge of bucket v + 1.
inline void BuildEdges(EdgeTopology& t, const std::vector<Index>& sideStart,
                       std::vector<std::pair<Index, Index>>& sides, int threads) {
  const std::size_t nv = t.vertexCount;
  t.edgeFaces.resize(sides.size());
  std::vector<Index> edgesAt(nv + 1, 0);
  ParallelFor(nv, threads, [&](std::size_t vBegin, std::size_t vEnd, int) {
    for (std::size_t v = vBegin; v < vEnd; ++v) {
      std::sort(sides.begin() + sideStart[v], sides.begin() + sideStart[v + 1]); // (larger vertex, face)
      for (Index k = sideStart[v]; k < sideStart[v + 1]; ++k) {
        if (k == sideStart[v] || sides[k].first != sides[k - 1].first) ++edgesAt[v + 1];
        t.edgeFaces[k] = sides[k].second;
      }
    }
  });
  for (std::size_t v = 0; v < nv; ++v) edgesAt[v + 1] += edgesAt[v];
  const std::size_t ne = edgesAt[nv];
  t.edgeKeys.resize(ne);
  t.edgeFaceStart.resize(ne + 1);
  t.edgeFaceStart[ne] = Index(sides.size());
  ParallelFor(nv, threads, [&](std::size_t vBegin, std::size_t vEnd, int) {
    for (std::size_t v = vBegin; v < vEnd; ++v) {
      Index e = edgesAt[v];
      for (Index k = sideStart[v]; k < sideStart[v + 1]; ++k)
        if (k == sideStart[v] || sides[k].first != sides[k - 1].first) {
          t.edgeKeys[e] = (std::uint64_t(v) << 32) | sides[k].first;
          t.edgeFaceStart[e++] = k;
        }
    }
  });
}

/// Edges at each vertex, ascending (the edges are visited in ascending order).
inline void BuildVertexEdges(EdgeTopology& t) {
  const std::size_t nv = t.vertexCount;
  const std::size_t ne = t.edgeKeys.size();
  t.vertEdgeStart.assign(nv + 1, 0);
  for (std::size_t e = 0; e < ne; ++e) {
    ++t.vertEdgeStart[t.EdgeV0(e) + 1];
    ++t.vertEdgeStart[t.EdgeV1(e) + 1];
  }
  for (std::size_t v = 0; v < nv; ++v) t.vertEdgeStart[v + 1] += t.vertEdgeStart[v];
  t.vertEdges.resize(t.vertEdgeStart[nv]);
  std::vector<Index> fill(t.vertEdgeStart.begin(), t.vertEdgeStart.end() - 1);
  for (std::size_t e = 0; e < ne; ++e) {
    t.vertEdges[fill[t.EdgeV0(e)]++] = Index(e);
    t.vertEdges[fill[t.EdgeV1(e)]++] = Index(e);
  }
}

/// Proper faces at each vertex, ascending.
inline void BuildVertexFaces(EdgeTopology& t) {
  const std::size_t nv = t.vertexCount;
  const std::size_t nf = t.faces.size();
  t.vertFaceStart.assign(nv + 1, 0);
  for (std::size_t f = 0; f < nf; ++f)
    if (t.proper[f])
      for (Index v : t.faces[f]) ++t.vertFaceStart[v + 1];
  for (std::size_t v = 0; v < nv; ++v) t.vertFaceStart[v + 1] += t.vertFaceStart[v];
  t.vertFaces.resize(t.vertFaceStart[nv]);
  std::vector<Index> fill(t.vertFaceStart.begin(), t.vertFaceStart.end() - 1);
  for (std::size_t f = 0; f < nf; ++f)
    if (t.proper[f])
      for (Index v : t.faces[f]) t.vertFaces[fill[v]++] = Index(f);
}

/// onBorder and onNonManifoldEdge of every vertex.
inline void MarkBorderVertices(EdgeTopology& t) {
  const std::size_t nv = t.vertexCount;
  const std::size_t ne = t.edgeKeys.size();
  t.onNonManifoldEdge.assign(nv, false);
  t.onBorder.assign(nv, false);
  for (std::size_t e = 0; e < ne; ++e) {
    const Index count = t.EdgeFaceCount(e);
    if (count == 2) continue;
    for (Index v : {t.EdgeV0(e), t.EdgeV1(e)}) {
      t.onBorder[v] = true;
      if (count > 2) t.onNonManifoldEdge[v] = true;
    }
  }
}

} // namespace edge_topology_detail

/// Builds everything but `faces`/`proper`/`vertexCount`, which the caller fills.
///
/// Linear time: every table is filled by counting sort (bucket by vertex), which keeps the
/// faces and edges of one bucket in ascending order for free; only the few sides at one vertex
/// are sorted among themselves. The pipeline reports after every stage, and three general sorts
/// of 1.5 M entries each cost more there than all the other figures together. Those per-vertex
/// sorts, and the edges they give, run on `threads` threads: each vertex writes only its own part
/// of the tables, at offsets counted beforehand, so the tables do not depend on the thread count.
inline void BuildEdgeTopology(EdgeTopology& t, int threads) {
  using namespace edge_topology_detail;
  {
    std::vector<Index> sideStart;
    std::vector<std::pair<Index, Index>> sides;
    BucketSides(t, sideStart, sides);
    BuildEdges(t, sideStart, sides, threads);
  }
  BuildVertexEdges(t);
  BuildVertexFaces(t);
  MarkBorderVertices(t);
}

/// The live faces of m as vertex indices (kNoIndex for an invalid reference), and whether each is
/// proper.
template <class MeshType>
void ReadFaceIndices(const MeshType& m, std::vector<std::array<Index, 3>>& faces, std::vector<bool>& proper) {
  faces.reserve(m.face.size());
  proper.reserve(m.face.size());
  const auto* vertBegin = m.vert.empty() ? nullptr : &m.vert[0];
  for (const auto& f : m.face) {
    if (f.IsD()) continue;
    std::array<Index, 3> idx{kNoIndex, kNoIndex, kNoIndex};
    for (int i = 0; i < 3; ++i) {
      const auto* vp = f.cV(i);
      if (vp == nullptr || vertBegin == nullptr) continue;
      const std::ptrdiff_t k = vp - vertBegin;
      if (k >= 0 && std::size_t(k) < m.vert.size()) idx[i] = Index(k);
    }
    const bool valid = idx[0] != kNoIndex && idx[1] != kNoIndex && idx[2] != kNoIndex;
    faces.push_back(idx);
    proper.push_back(valid && idx[0] != idx[1] && idx[1] != idx[2] && idx[2] != idx[0]);
  }
}

/// Reads the live faces of m and builds their topology on `threads` threads.
template <class MeshType>
EdgeTopology ReadEdgeTopology(const MeshType& m, int threads) {
  EdgeTopology t;
  t.vertexCount = m.vert.size();
  ReadFaceIndices(m, t.faces, t.proper);
  BuildEdgeTopology(t, threads);
  return t;
}

} // namespace molremesh

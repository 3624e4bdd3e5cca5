// Element access and local queries shared by the cleaning steps (vcg_ext/clean/): face and vertex
// indices, a face's vertex triple, area and normal in double precision, vertex stars, border tests,
// face deletion, the adjacency rebuild, face components and the closed triangle/triangle conflict
// test of MeshQuality.
//
// Preconditions are stated per function. "Fresh VF (FF) adjacency" means vcglib's VF (FF) adjacency
// was rebuilt (RebuildTopology) after the last edit that changed face-vertex references; deleted
// faces may be in it and are skipped.
#pragma once

// complex.h first: vcglib's algorithm headers rely on it being included before them.
#include <vcg/complex/complex.h>
#include <vcg/complex/algorithms/update/topology.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include <vcg_ext/clean/hole_triangulation.h>
#include <vcg_ext/core/index.h>
#include <vcg_ext/geometry/point.h>
#include <vcg_ext/geometry/triangle_intersection.h>
#include <vcg_ext/topology/face_face_topology.h>

namespace molremesh {
namespace clean {

using Tri = std::array<Index, 3>; ///< a face as three vertex indices
constexpr Index kNone = kNoIndex;

template <class MeshType>
Index VI(const MeshType& m, const typename MeshType::FaceType& f, int k) {
  return Index(f.cV(k) - &m.vert[0]);
}
template <class MeshType>
Index FI(const MeshType& m, const typename MeshType::FaceType* f) {
  return Index(f - &m.face[0]);
}
template <class MeshType>
Tri FaceTri(const MeshType& m, const typename MeshType::FaceType& f) {
  return {VI(m, f, 0), VI(m, f, 1), VI(m, f, 2)};
}
inline std::uint64_t EdgeKey(Index a, Index b) {
  return (std::uint64_t(std::min(a, b)) << 32) | std::uint64_t(std::max(a, b));
}
template <class MeshType>
double FaceArea(const MeshType& m, const typename MeshType::FaceType& f) {
  return hole_triangulation::TriArea(PositionOf(&m.vert[VI(m, f, 0)]), PositionOf(&m.vert[VI(m, f, 1)]),
                                     PositionOf(&m.vert[VI(m, f, 2)]));
}
template <class MeshType>
Point FaceNormal(const MeshType& m, const typename MeshType::FaceType& f) {
  return hole_triangulation::UnitNormal(PositionOf(&m.vert[VI(m, f, 0)]), PositionOf(&m.vert[VI(m, f, 1)]),
                                        PositionOf(&m.vert[VI(m, f, 2)]));
}

/// Rebuilds FF and VF adjacency.
template <class MeshType>
void RebuildTopology(MeshType& m) {
  // The linear-time adjacency is vcglib's wherever an edge has at most two faces. On a
  // non-manifold edge vcglib orders the ring by its own sort, and the repairs here walk such
  // rings, so a mesh that has any keeps vcglib's construction (and the same cleaning).
  if (UpdateFaceFaceTopology(m) > 0) vcg::tri::UpdateTopology<MeshType>::FaceFace(m);
  vcg::tri::UpdateTopology<MeshType>::VertexFace(m);
}

/// Side e of f has no other face (needs fresh FF adjacency).
template <class FaceType>
bool IsBorderEdge(const FaceType& f, int e) {
  return f.cFFp(e) == &f;
}

template <class MeshType>
void DeleteFace(MeshType& m, Index f) {
  if (!m.face[f].IsD()) vcg::tri::Allocator<MeshType>::DeleteFace(m, m.face[f]);
}
template <class MeshType>
void UndeleteFace(MeshType& m, Index f) {
  if (m.face[f].IsD()) {
    m.face[f].ClearD();
    ++m.fn;
  }
}

/// Live faces around vertex v (needs fresh VF adjacency; deleted faces are skipped): (face, corner).
template <class MeshType>
void Star(MeshType& m, Index v, std::vector<std::pair<Index, int>>& out) {
  out.clear();
  for (vcg::face::VFIterator<typename MeshType::FaceType> it(&m.vert[v]); !it.End(); ++it)
    if (!it.F()->IsD()) out.emplace_back(FI(m, it.F()), it.I());
}
/// Distinct neighbours of v through live faces (needs fresh VF adjacency).
template <class MeshType>
void Neighbours(MeshType& m, Index v, std::vector<Index>& out) {
  out.clear();
  for (vcg::face::VFIterator<typename MeshType::FaceType> it(&m.vert[v]); !it.End(); ++it) {
    if (it.F()->IsD()) continue;
    out.push_back(VI(m, *it.F(), (it.I() + 1) % 3));
    out.push_back(VI(m, *it.F(), (it.I() + 2) % 3));
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
}
/// Whether a border edge of a live face ends at v (needs fresh FF and VF adjacency).
template <class MeshType>
bool HasBorderEdgeAt(MeshType& m, Index v) {
  for (vcg::face::VFIterator<typename MeshType::FaceType> it(&m.vert[v]); !it.End(); ++it) {
    if (it.F()->IsD()) continue;
    const int k = it.I();
    if (IsBorderEdge(*it.F(), k) || IsBorderEdge(*it.F(), (k + 2) % 3)) return true;
  }
  return false;
}
/// Whether a live face around a has b as a vertex (needs fresh VF adjacency).
template <class MeshType>
bool EdgeExistsInStar(MeshType& m, Index a, Index b) {
  for (vcg::face::VFIterator<typename MeshType::FaceType> it(&m.vert[a]); !it.End(); ++it)
    if (!it.F()->IsD())
      for (int k = 0; k < 3; ++k)
        if (it.F()->V(k) == &m.vert[b]) return true;
  return false;
}

/// Deletes the live vertices no live face uses. Returns how many. No adjacency needed.
template <class MeshType>
std::size_t RemoveUnreferencedVertices(MeshType& m) {
  std::vector<std::uint8_t> used(m.vert.size(), 0);
  for (const auto& f : m.face)
    if (!f.IsD())
      for (int k = 0; k < 3; ++k) used[VI(m, f, k)] = 1;
  std::size_t removed = 0;
  for (std::size_t v = 0; v < m.vert.size(); ++v)
    if (!m.vert[v].IsD() && !used[v]) {
      vcg::tri::Allocator<MeshType>::DeleteVertex(m, m.vert[v]);
      ++removed;
    }
  return removed;
}

/// Face components through shared edges, numbered in order of their lowest face (needs fresh FF
/// adjacency). label[f] is kNone for deleted faces.
template <class MeshType>
std::size_t LabelComponents(const MeshType& m, std::vector<Index>& label, std::vector<std::size_t>& size) {
  label.assign(m.face.size(), kNone);
  size.clear();
  std::vector<Index> stack;
  for (Index s = 0; s < m.face.size(); ++s) {
    if (m.face[s].IsD() || label[s] != kNone) continue;
    const Index c = Index(size.size());
    size.push_back(0);
    label[s] = c;
    stack.assign(1, s);
    while (!stack.empty()) {
      const Index f = stack.back();
      stack.pop_back();
      ++size[c];
      for (int e = 0; e < 3; ++e) {
        const auto* g = m.face[f].cFFp(e);
        const Index gi = FI(m, g);
        if (g->IsD() || label[gi] != kNone) continue;
        label[gi] = c;
        stack.push_back(gi);
      }
    }
  }
  return size.size();
}

/// Closed-triangle conflict as MeshQuality counts it: no shared vertex and the triangles meet, or
/// one shared vertex and they meet elsewhere too; three shared vertices (a duplicate) also conflict.
/// Two shared vertices (a shared edge) never conflict here: folds are the dihedral check's business.
template <class MeshType>
bool Conflict(const MeshType& m, const Tri& a, const Tri& b) {
  int shared = 0, ca = -1, cb = -1;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      if (a[i] == b[j]) ++shared, ca = i, cb = j;
  if (shared >= 3) return true;
  if (shared == 2) return false;
  const PlanarTriangle ta =
      MakePlanarTriangle(PositionOf(&m.vert[a[0]]), PositionOf(&m.vert[a[1]]), PositionOf(&m.vert[a[2]]));
  const PlanarTriangle tb =
      MakePlanarTriangle(PositionOf(&m.vert[b[0]]), PositionOf(&m.vert[b[1]]), PositionOf(&m.vert[b[2]]));
  if (shared == 0) return TrianglesIntersect(ta, tb);
  return SharedCornerOverlap(ta, ca, tb, cb);
}

} // namespace clean
} // namespace molremesh

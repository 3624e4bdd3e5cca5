// Cleaning steps on bad faces (vcg_ext/clean/): faces with a repeated vertex index, duplicate
// faces (same vertex set), and zero-area faces removed without opening a hole.
//
// RemoveIndexDegenerateFaces and RemoveDuplicateFaces need no adjacency. ZeroAreaFaces::Fix needs
// fresh FF and VF adjacency, an edge-manifold and coherently oriented mesh, and leaves the adjacency
// fresh: a "cap" (a vertex lying on the opposite edge) is removed by flipping that edge, which
// leaves the surface geometrically unchanged; a "needle" (a vanishing edge) by collapsing that edge
// onto one of its end points (link condition, no normal flip); a zero-area face on the boundary is
// simply dropped when that cannot pinch a vertex.
#pragma once

#include <vcg/complex/complex.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <utility>
#include <vector>

#include <vcg_ext/clean/clean_mesh_access.h>
#include <vcg_ext/clean/hole_triangulation.h>
#include <vcg_ext/core/index.h>
#include <vcg_ext/geometry/point.h>

namespace molremesh {
namespace clean {

/// Deletes the faces with a repeated vertex index. Returns how many.
template <class MeshType>
std::size_t RemoveIndexDegenerateFaces(MeshType& m) {
  std::size_t removed = 0;
  for (auto& f : m.face)
    if (!f.IsD() && (f.V(0) == f.V(1) || f.V(1) == f.V(2) || f.V(2) == f.V(0))) {
      vcg::tri::Allocator<MeshType>::DeleteFace(m, f);
      ++removed;
    }
  return removed;
}

/// Keeps the first face (in index order) of every set of faces with the same three vertices.
template <class MeshType>
std::size_t RemoveDuplicateFaces(MeshType& m) {
  std::vector<std::pair<Tri, Index>> keys;
  keys.reserve(m.face.size());
  for (Index f = 0; f < m.face.size(); ++f) {
    if (m.face[f].IsD()) continue;
    Tri t = FaceTri(m, m.face[f]);
    std::sort(t.begin(), t.end());
    keys.emplace_back(t, f);
  }
  std::sort(keys.begin(), keys.end());
  std::size_t removed = 0;
  for (std::size_t i = 1; i < keys.size(); ++i)
    if (keys[i].first == keys[i - 1].first) {
      DeleteFace(m, keys[i].second);
      ++removed;
    }
  return removed;
}

/// What ZeroAreaFaces::Fix did.
struct ZeroAreaFaceCounts {
  std::size_t removed = 0;   ///< zero-area faces removed (collapsed edges' faces, dropped border faces)
  std::size_t flipped = 0;   ///< zero-area faces made proper by flipping their longest edge
  std::size_t collapsed = 0; ///< vanishing edges collapsed
  std::size_t remaining = 0; ///< zero-area faces no safe edit could remove (left in place)
};

template <class MeshType>
class ZeroAreaFaces {
public:
  using FaceType = typename MeshType::FaceType;

  /// Passes over the zero-area faces; each pass edits an independent set (no edit touches a vertex
  /// marked by an earlier edit of the same pass, so the pass reads only valid adjacency), then the
  /// adjacency is rebuilt. Stops when none is left or a pass changes nothing.
  static void Fix(MeshType& m, double degenerateArea, ZeroAreaFaceCounts& r) {
    const int maxPasses = 50;
    std::vector<std::uint8_t> dirty;
    for (int pass = 0; pass < maxPasses; ++pass) {
      std::vector<Index> bad;
      for (Index f = 0; f < m.face.size(); ++f)
        if (!m.face[f].IsD() && FaceArea(m, m.face[f]) <= degenerateArea) bad.push_back(f);
      r.remaining = bad.size();
      if (bad.empty()) return;
      dirty.assign(m.vert.size(), 0);
      bool progress = false;
      for (Index f : bad) {
        const FaceType& F = m.face[f];
        if (F.IsD()) continue;
        const Tri t = FaceTri(m, F);
        if (dirty[t[0]] || dirty[t[1]] || dirty[t[2]]) continue;
        std::array<double, 3> len{};
        for (int k = 0; k < 3; ++k)
          len[k] = (PositionOf(&m.vert[t[(k + 1) % 3]]) - PositionOf(&m.vert[t[k]])).Norm();
        const int longest = int(std::max_element(len.begin(), len.end()) - len.begin());
        const int shortest = int(std::min_element(len.begin(), len.end()) - len.begin());
        const bool needle = len[shortest] < 1e-3 * len[longest];
        bool done = false;
        if (!needle) done = FlipCap(m, f, longest, degenerateArea, dirty, r);
        if (!done) done = CollapseEdge(m, f, shortest, degenerateArea, dirty, r);
        if (!done && needle) done = FlipCap(m, f, longest, degenerateArea, dirty, r);
        progress = progress || done;
      }
      RebuildTopology(m);
      if (!progress) break;
    }
    r.remaining = 0;
    for (const auto& f : m.face)
      if (!f.IsD() && FaceArea(m, f) <= degenerateArea) ++r.remaining;
  }

private:
  /// Face f = (a, b, c) with edge e = ab its longest edge and c (nearly) on it. Interior: flip ab into
  /// cd with the neighbour (b, a, d): the two new faces (c, a, d) and (c, d, b) cover exactly the
  /// neighbour, so the surface does not change. Boundary: drop f when c is an interior vertex.
  static bool FlipCap(MeshType& m, Index f, int e, double degenerateArea, std::vector<std::uint8_t>& dirty,
                      ZeroAreaFaceCounts& r) {
    FaceType& F = m.face[f];
    const Index a = VI(m, F, e), b = VI(m, F, (e + 1) % 3), c = VI(m, F, (e + 2) % 3);
    if (IsBorderEdge(F, e)) {
      if (HasBorderEdgeAt(m, c)) return false; // dropping f would pinch c
      DeleteFace(m, f);
      dirty[a] = dirty[b] = dirty[c] = 1;
      ++r.removed;
      return true;
    }
    FaceType* G = F.FFp(e);
    const int j = F.FFi(e);
    if (G->IsD() || G->FFp(j) != &F) return false;
    if (G->V(j) != &m.vert[b] || G->V((j + 1) % 3) != &m.vert[a]) return false; // not coherent
    const Index d = VI(m, *G, (j + 2) % 3);
    if (d == c || dirty[d]) return false;
    if (FaceArea(m, *G) <= degenerateArea)
      return false; // neighbour degenerate too: let another edit go first
    if (EdgeExistsInStar(m, c, d)) return false;
    const Point pa = PositionOf(&m.vert[a]), pb = PositionOf(&m.vert[b]), pc = PositionOf(&m.vert[c]),
                pd = PositionOf(&m.vert[d]);
    if (hole_triangulation::TriArea(pc, pa, pd) <= degenerateArea ||
        hole_triangulation::TriArea(pc, pd, pb) <= degenerateArea)
      return false;
    const Point ng = FaceNormal(m, *G);
    if (hole_triangulation::UnitNormal(pc, pa, pd) * ng <= 0 ||
        hole_triangulation::UnitNormal(pc, pd, pb) * ng <= 0)
      return false;
    F.V(0) = &m.vert[c];
    F.V(1) = &m.vert[a];
    F.V(2) = &m.vert[d];
    G->V(0) = &m.vert[c];
    G->V(1) = &m.vert[d];
    G->V(2) = &m.vert[b];
    dirty[a] = dirty[b] = dirty[c] = dirty[d] = 1;
    ++r.flipped;
    return true;
  }
  /// Collapses edge e of face f onto one of its end points (which keeps its position): the boundary
  /// one if only one is on the boundary. Checked: manifold edge, link condition, no pinch of the
  /// boundary, no face of the star degenerates or turns over.
  static bool CollapseEdge(MeshType& m, Index f, int e, double degenerateArea,
                           std::vector<std::uint8_t>& dirty, ZeroAreaFaceCounts& r) {
    const FaceType& F = m.face[f];
    Index u = VI(m, F, e), v = VI(m, F, (e + 1) % 3); // u is removed, v kept
    if (dirty[u] || dirty[v]) return false;
    const bool uBorder = HasBorderEdgeAt(m, u), vBorder = HasBorderEdgeAt(m, v);
    if (uBorder && !vBorder) std::swap(u, v);
    std::vector<std::pair<Index, int>> starU;
    Star(m, u, starU);
    std::vector<Index> edgeFaces, opposite;
    for (const auto& [g, k] : starU) {
      const FaceType& G = m.face[g];
      for (int i = 1; i < 3; ++i)
        if (VI(m, G, (k + i) % 3) == v) {
          edgeFaces.push_back(g);
          opposite.push_back(VI(m, G, (k + 3 - i) % 3));
        }
    }
    if (edgeFaces.empty() || edgeFaces.size() > 2) return false;
    const bool edgeBorder = edgeFaces.size() == 1;
    if (uBorder && vBorder && !edgeBorder) return false; // would pinch the boundary
    // Link condition: the common neighbours of u and v are exactly the opposite vertices.
    std::vector<Index> nu, nv, common;
    Neighbours(m, u, nu);
    Neighbours(m, v, nv);
    for (Index w : nu)
      if (dirty[w]) return false;
    for (Index w : nv)
      if (dirty[w]) return false;
    std::set_intersection(nu.begin(), nu.end(), nv.begin(), nv.end(), std::back_inserter(common));
    std::sort(opposite.begin(), opposite.end());
    if (common != opposite) return false;
    // Geometry of the faces that keep existing with u replaced by v.
    for (const auto& [g, k] : starU) {
      if (std::find(edgeFaces.begin(), edgeFaces.end(), g) != edgeFaces.end()) continue;
      const FaceType& G = m.face[g];
      const Point p1 = PositionOf(&m.vert[VI(m, G, (k + 1) % 3)]),
                  p2 = PositionOf(&m.vert[VI(m, G, (k + 2) % 3)]);
      const Point oldP = PositionOf(&m.vert[u]), newP = PositionOf(&m.vert[v]);
      if (hole_triangulation::TriArea(newP, p1, p2) <= degenerateArea) return false;
      const Point oldN = hole_triangulation::UnitNormal(oldP, p1, p2),
                  newN = hole_triangulation::UnitNormal(newP, p1, p2);
      if (hole_triangulation::TriArea(oldP, p1, p2) > degenerateArea && oldN * newN <= 0.1) return false;
    }
    for (Index g : edgeFaces) {
      DeleteFace(m, g);
      ++r.removed;
    }
    for (const auto& [g, k] : starU)
      if (!m.face[g].IsD()) m.face[g].V(k) = &m.vert[v];
    dirty[u] = dirty[v] = 1;
    for (Index w : nu) dirty[w] = 1;
    for (Index w : nv) dirty[w] = 1;
    ++r.collapsed;
    return true;
  }
};

} // namespace clean
} // namespace molremesh

// Cleaning steps on non-manifold vertices (vcg_ext/clean/): split a vertex whose faces form several
// fans into one vertex per fan, then separate each copy from its original where both kept faces
// (they sit at the same point, so their fans touch: a self-intersection).
//
// SplitNonManifoldVertices needs fresh FF and VF adjacency on an edge-manifold mesh and leaves it
// fresh. SeparateSplitCopies needs the same, coherently oriented, and draws on run.attemptsLeft
// (RegionRefill). Copies keep the position and attributes of the original; the only vertices ever
// moved are copies that cannot be separated otherwise.
#pragma once

#include <vcg/complex/complex.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <numeric>
#include <utility>
#include <vector>

#include <vcg_ext/clean/clean_mesh_access.h>
#include <vcg_ext/clean/clean_params.h>
#include <vcg_ext/clean/region_refill.h>
#include <vcg_ext/core/index.h>
#include <vcg_ext/geometry/point.h>
#include <vcg_ext/spatial/static_face_grid.h>

namespace molremesh {
namespace clean {

/// What SeparateSplitCopies did.
struct SplitSeparationCounts {
  std::size_t retriangulatedFans = 0;                 ///< copies whose fan was removed and refilled
  std::size_t fanFacesRemoved = 0, fanFacesAdded = 0; ///< faces of those retriangulations
  std::size_t moved = 0;                              ///< copies moved by 1% into their own fan instead
  std::size_t touching = 0; ///< copies left touching their original (neither worked)
};

template <class MeshType>
class NonManifoldVertices {
public:
  using FaceType = typename MeshType::FaceType;
  using VertexType = typename MeshType::VertexType;
  using FaceGrid = StaticFaceGrid<MeshType>;
  using CoordType = typename MeshType::CoordType;
  using Scalar = typename MeshType::ScalarType;

  /// Splits vertices whose faces form several fans (joined through edges at the vertex). With
  /// onlyClosedFans, only closed fans are split off (open fans of a boundary pinch stay together for
  /// the hole filling); otherwise every fan but the first gets its own vertex. Copies keep the
  /// position and attributes of the original. vcglib's Clean::SplitNonManifoldVertex is not used: it
  /// splits one fan per vertex and call and cannot tell closed fans from open ones.
  static std::vector<std::pair<Index, Index>> SplitNonManifoldVertices(MeshType& m, bool onlyClosedFans) {
    struct Split {
      Index vertex;
      std::vector<std::pair<Index, int>> corners; // (face, corner) moving to the copy
    };
    std::vector<Split> splits;
    std::vector<std::pair<Index, int>> star;
    std::vector<int> parent;
    for (Index v = 0; v < m.vert.size(); ++v) {
      if (m.vert[v].IsD()) continue;
      Star(m, v, star);
      if (star.size() < 2) continue;
      parent.resize(star.size());
      std::iota(parent.begin(), parent.end(), 0);
      auto find = [&parent](int x) {
        while (parent[x] != x) x = parent[x] = parent[parent[x]];
        return x;
      };
      auto local = [&star](Index face) {
        for (std::size_t i = 0; i < star.size(); ++i)
          if (star[i].first == face) return int(i);
        return -1;
      };
      std::vector<std::uint8_t> open(star.size(), 0);
      for (std::size_t i = 0; i < star.size(); ++i) {
        const FaceType& F = m.face[star[i].first];
        const int k = star[i].second;
        for (int e : {k, (k + 2) % 3}) {
          if (IsBorderEdge(F, e)) {
            open[i] = 1;
            continue;
          }
          const int j = local(FI(m, F.cFFp(e)));
          if (j >= 0) {
            const int a = find(int(i)), b = find(j);
            if (a != b) parent[std::max(a, b)] = std::min(a, b);
          }
        }
      }
      std::vector<int> roots;
      for (std::size_t i = 0; i < star.size(); ++i)
        if (find(int(i)) == int(i)) roots.push_back(int(i));
      if (roots.size() < 2) continue;
      std::vector<std::uint8_t> fanOpen(star.size(), 0);
      for (std::size_t i = 0; i < star.size(); ++i)
        if (open[i]) fanOpen[find(int(i))] = 1;
      std::size_t openFans = 0;
      for (int root : roots) openFans += fanOpen[root];
      // The fan that keeps the original vertex: the first open one, else the first.
      int keep = roots.front();
      for (int root : roots)
        if (fanOpen[root]) {
          keep = root;
          break;
        }
      if (onlyClosedFans && openFans == roots.size()) continue;
      for (int root : roots) {
        if (root == keep) continue;
        if (onlyClosedFans && fanOpen[root]) continue;
        Split s{v, {}};
        for (std::size_t i = 0; i < star.size(); ++i)
          if (find(int(i)) == root) s.corners.push_back(star[i]);
        splits.push_back(std::move(s));
      }
    }
    std::vector<std::pair<Index, Index>> made;
    if (splits.empty()) return made;
    const Index first = Index(m.vert.size());
    vcg::tri::Allocator<MeshType>::AddVertices(m, splits.size());
    for (std::size_t i = 0; i < splits.size(); ++i) {
      VertexType& copy = m.vert[first + i];
      copy.ImportData(m.vert[splits[i].vertex]);
      for (const auto& [face, corner] : splits[i].corners) m.face[face].V(corner) = &copy;
      made.emplace_back(splits[i].vertex, first + Index(i));
    }
    RebuildTopology(m);
    return made;
  }

  /// A split vertex and its copy sit at the same point: when both keep faces, their fans touch, which
  /// is a self-intersection. Remove the copy's fan (or else the original's) and refill the hole
  /// around it without the vertex, checked like any fill. When no refill is possible (the fan is a
  /// whole open component, say) move the copy (or else the original) a little into its own fan, as
  /// vcglib's SplitNonManifoldVertex does with its moveThreshold, if that creates no intersection and
  /// turns no face over. Otherwise they stay touching (counted).
  static void SeparateSplitCopies(MeshType& m, const std::vector<std::pair<Index, Index>>& pairs,
                                  CleanRunState& run, SplitSeparationCounts& r) {
    const double meanEdge = run.meanEdge;
    std::unique_ptr<FaceGrid> grid;
    std::vector<std::pair<Index, int>> starA, starB;
    for (const auto& [original, copy] : pairs) {
      Star(m, original, starA);
      Star(m, copy, starB);
      if (starA.empty() || starB.empty()) continue; // one side was removed (e.g. a small component)
      if (!grid) grid.reset(new FaceGrid(m, 2.0 * meanEdge));
      bool done = false;
      for (const auto* star : {&starB, &starA}) {
        std::vector<Index> fan;
        for (const auto& corner : *star) fan.push_back(corner.first);
        std::size_t removed = 0, added = 0;
        const std::vector<Index> split{original, copy};
        if (RegionRefill<MeshType>::Repair(m, fan, run, *grid, removed, added, &split)) {
          r.retriangulatedFans += 1;
          r.fanFacesRemoved += removed;
          r.fanFacesAdded += added;
          done = true;
          break;
        }
        Star(m, original, starA); // the failed attempt rebuilt the adjacency
      }
      if (!done) {
        for (const Index v : {copy, original}) {
          if (NudgeIntoFan(m, v, meanEdge, *grid)) {
            ++r.moved;
            done = true;
            break;
          }
        }
      }
      if (!done) ++r.touching;
    }
  }

private:
  /// Moves v by 1% of the way to the centroid of its fan's faces when no face of the fan degenerates,
  /// turns over or meets another face. Returns false (and leaves v where it was) otherwise.
  static bool NudgeIntoFan(MeshType& m, Index v, double meanEdge, FaceGrid& grid) {
    std::vector<std::pair<Index, int>> star;
    Star(m, v, star);
    if (star.empty()) return false;
    const Point old = PositionOf(&m.vert[v]);
    Point centroid(0, 0, 0);
    for (const auto& corner : star) {
      const Tri t = FaceTri(m, m.face[corner.first]);
      centroid += (PositionOf(&m.vert[t[0]]) + PositionOf(&m.vert[t[1]]) + PositionOf(&m.vert[t[2]])) / 3.0;
    }
    centroid /= double(star.size());
    std::vector<Point> oldNormals;
    for (const auto& corner : star) oldNormals.push_back(FaceNormal(m, m.face[corner.first]));
    const Point target = old + (centroid - old) * 0.01;
    m.vert[v].P() = CoordType(Scalar(target[0]), Scalar(target[1]), Scalar(target[2]));
    bool ok = PositionOf(&m.vert[v]) != old;
    std::vector<Index> candidates;
    for (std::size_t i = 0; i < star.size() && ok; ++i) {
      const Tri t = FaceTri(m, m.face[star[i].first]);
      if (FaceArea(m, m.face[star[i].first]) <= 1e-10 * meanEdge * meanEdge ||
          FaceNormal(m, m.face[star[i].first]) * oldNormals[i] < 0.9) {
        ok = false;
        break;
      }
      grid.Query(m, FaceGrid::Box(m, t, 1e-9 * meanEdge), candidates);
      for (Index g : candidates)
        if (g != star[i].first && Conflict(m, t, FaceTri(m, m.face[g]))) {
          ok = false;
          break;
        }
    }
    if (!ok) m.vert[v].P() = CoordType(Scalar(old[0]), Scalar(old[1]), Scalar(old[2]));
    return ok;
  }
};

} // namespace clean
} // namespace molremesh

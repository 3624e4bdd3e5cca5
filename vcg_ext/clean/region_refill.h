// Remove-and-refill of a face region (vcg_ext/clean/), the repair the tangle repair, the grown hole
// fills and the separation of split copies share: remove the region (grown by rings of faces when
// needed), fill every loop its removal opens (LoopFill), and keep the result only when every fill is
// valid, otherwise restore the faces. So a repair never opens a hole, never adds an intersection
// and never leaves a non-manifold vertex.
//
// Preconditions: fresh FF and VF adjacency, a coherently oriented edge-manifold mesh around the
// region, and a face grid holding every live face. Each try (ring) costs one of run.attemptsLeft and
// rebuilds the adjacency (O(faces)), so the attempts bound the step's time. Topology is fresh on
// return.
#pragma once

#include <vcg/complex/complex.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <unordered_set>
#include <utility>
#include <vector>

#include <vcg_ext/clean/boundary_loops.h>
#include <vcg_ext/clean/clean_mesh_access.h>
#include <vcg_ext/clean/clean_params.h>
#include <vcg_ext/clean/hole_triangulation.h>
#include <vcg_ext/clean/loop_fill.h>
#include <vcg_ext/core/index.h>
#include <vcg_ext/geometry/point.h>
#include <vcg_ext/spatial/static_face_grid.h>

namespace molremesh {
namespace clean {

template <class MeshType>
class RegionRefill {
public:
  using FaceType = typename MeshType::FaceType;
  using FaceGrid = StaticFaceGrid<MeshType>;
  using Fill = LoopFill<MeshType>;
  using FillContext = typename Fill::FillContext;

  /// Removes `seed` plus up to run.params.maxRepairGrowth rings of faces around it and refills;
  /// keeps the result only if every loop opened by the removal is filled validly. Tries growing
  /// rings. With reinsertExcept, the removed region's vertices that are not on the fill's boundary
  /// and not listed are put back into the fill (ReinsertVertices). On success adds the faces removed
  /// and added to facesRemoved and facesAdded.
  static bool Repair(MeshType& m, const std::vector<Index>& seed, CleanRunState& run, FaceGrid& grid,
                     std::size_t& facesRemoved, std::size_t& facesAdded,
                     const std::vector<Index>* reinsertExcept = nullptr) {
    for (Index f : seed)
      if (m.face[f].IsD()) return false;
    std::vector<Index> region = seed;
    for (int ring = 0; ring <= run.params.maxRepairGrowth; ++ring) {
      if (ring > 0 && !GrowByOneRing(m, region)) break;
      if (int(region.size()) > run.params.maxRepairRegionFaces || run.attemptsLeft <= 0) return false;
      --run.attemptsLeft;
      const std::vector<std::pair<Index, int>> seeds = HoleSides(m, region);
      if (seeds.empty()) return false; // a whole component: not a local tangle
      for (Index f : region) DeleteFace(m, f);
      RebuildTopology(m);
      FillContext ctx = Fill::MakeContext(run, &grid);
      std::vector<std::vector<Tri>> plans;
      if (PlanHoles(m, seeds, region.size(), run.params, ctx, plans)) {
        const std::size_t added = Commit(m, region, plans, ctx, reinsertExcept);
        RebuildTopology(m);
        facesRemoved += region.size();
        facesAdded += added;
        return true;
      }
      for (Index f : region) UndeleteFace(m, f);
      RebuildTopology(m);
    }
    return false;
  }

private:
  /// Adds the faces sharing a vertex with the region. False when there is none to add.
  static bool GrowByOneRing(MeshType& m, std::vector<Index>& region) {
    std::vector<std::pair<Index, int>> star;
    std::vector<Index> grown = region;
    for (Index f : region)
      for (int k = 0; k < 3; ++k) {
        Star(m, VI(m, m.face[f], k), star);
        for (const auto& sf : star) grown.push_back(sf.first);
      }
    std::sort(grown.begin(), grown.end());
    grown.erase(std::unique(grown.begin(), grown.end()), grown.end());
    if (grown.size() == region.size()) return false;
    region = std::move(grown);
    return true;
  }

  /// Half-edges (face, side) of the remaining mesh that will bound the hole left by the region.
  static std::vector<std::pair<Index, int>> HoleSides(const MeshType& m, const std::vector<Index>& region) {
    std::vector<std::uint8_t> inRegion(m.face.size(), 0);
    for (Index f : region) inRegion[f] = 1;
    std::vector<std::pair<Index, int>> seeds;
    for (Index f : region)
      for (int e = 0; e < 3; ++e) {
        const FaceType* g = m.face[f].cFFp(e);
        const Index gi = FI(m, g);
        if (!inRegion[gi]) seeds.emplace_back(gi, m.face[f].cFFi(e));
      }
    return seeds;
  }

  /// Traces the loops through the hole sides (the region already removed) and plans a fill of each.
  /// False when a loop cannot be traced, is too long, shares a vertex with an earlier loop, cannot be
  /// filled, or when fill triangles of different loops meet.
  static bool PlanHoles(MeshType& m, const std::vector<std::pair<Index, int>>& seeds, std::size_t regionSize,
                        const CleanRawMeshParams& params, FillContext& ctx,
                        std::vector<std::vector<Tri>>& plans) {
    std::vector<std::uint8_t> visited(m.face.size(), 0);
    bool ok = true;
    BoundaryLoop loop;
    std::unordered_set<Index> onEarlierLoops;
    for (const auto& [f, e] : seeds) {
      if (visited[f] & (1u << e)) continue;
      if (!IsBorderEdge(m.face[f], e) || !BoundaryLoops<MeshType>::TraceLoop(m, f, e, visited, loop) ||
          int(loop.verts.size()) > std::max(params.maxHoleEdges, 3 * int(regionSize) + 3)) {
        ok = false;
        break;
      }
      // A vertex on two loops would be left with two closed fans (a pinch): take a larger region.
      std::vector<Index> loopVerts = loop.verts;
      std::sort(loopVerts.begin(), loopVerts.end());
      loopVerts.erase(std::unique(loopVerts.begin(), loopVerts.end()), loopVerts.end());
      for (Index v : loopVerts)
        if (!onEarlierLoops.insert(v).second) ok = false;
      if (!ok) break;
      std::vector<Tri> plan;
      if (!Fill::PlanLoopFill(m, loop, ctx, plan)) {
        ok = false;
        break;
      }
      for (const Tri& t : plan)
        for (int k = 0; k < 3; ++k) ctx.addedEdges.insert(EdgeKey(t[k], t[(k + 1) % 3]));
      plans.push_back(std::move(plan));
    }
    if (!ok) return false;
    // Fill triangles of different loops must not meet either.
    std::vector<Tri> all;
    for (const auto& plan : plans) all.insert(all.end(), plan.begin(), plan.end());
    for (std::size_t a = 0; a < all.size() && ok; ++a)
      for (std::size_t b = 0; b < a && ok; ++b) ok = !Conflict(m, all[a], all[b]);
    return ok;
  }

  /// Adds the planned faces and, with reinsertExcept, puts the region's inner vertices back. Returns
  /// the faces added. The adjacency is left to rebuild.
  static std::size_t Commit(MeshType& m, const std::vector<Index>& region,
                            const std::vector<std::vector<Tri>>& plans, FillContext& ctx,
                            const std::vector<Index>* reinsertExcept) {
    ctx.addedEdges.clear();
    std::size_t added = 0;
    const Index firstAdded = Index(m.face.size());
    for (const auto& plan : plans) {
      Fill::CommitFill(m, plan, ctx);
      added += plan.size();
    }
    if (reinsertExcept) {
      std::vector<std::uint8_t> onLoop(m.vert.size(), 0);
      for (Index f = firstAdded; f < m.face.size(); ++f)
        for (int k = 0; k < 3; ++k) onLoop[VI(m, m.face[f], k)] = 1;
      std::vector<Index> inner;
      for (Index f : region)
        for (int k = 0; k < 3; ++k) {
          const Index v = VI(m, m.face[f], k);
          if (onLoop[v] ||
              std::find(reinsertExcept->begin(), reinsertExcept->end(), v) != reinsertExcept->end())
            continue;
          inner.push_back(v);
        }
      std::sort(inner.begin(), inner.end());
      inner.erase(std::unique(inner.begin(), inner.end()), inner.end());
      added += ReinsertVertices(m, inner, firstAdded, ctx);
    }
    return added;
  }

  /// Puts vertices of a removed region back into its fill, each into the fill face it lies closest
  /// above or below (split 1 -> 3), farthest first, when the three new faces are proper, keep the
  /// face's orientation and meet no other face. A fill without interior vertices is flat; this
  /// brings it back onto the surface it replaced. Returns the faces added.
  static std::size_t ReinsertVertices(MeshType& m, const std::vector<Index>& vertices, Index firstFill,
                                      FillContext& ctx) {
    std::size_t added = 0;
    std::vector<Index> near;
    std::vector<std::uint8_t> done(vertices.size(), 0);
    for (std::size_t round = 0; round < vertices.size(); ++round) {
      // The vertex farthest from the fill goes first.
      double bestDistance = -1;
      std::size_t bestVertex = vertices.size();
      Index bestFace = 0;
      for (std::size_t i = 0; i < vertices.size(); ++i) {
        if (done[i]) continue;
        const Point p = PositionOf(&m.vert[vertices[i]]);
        double nearest = std::numeric_limits<double>::infinity();
        Index face = 0;
        for (Index f = firstFill; f < m.face.size(); ++f) {
          if (m.face[f].IsD()) continue;
          const Tri t = FaceTri(m, m.face[f]);
          const std::array<Point, 3> c{PositionOf(&m.vert[t[0]]), PositionOf(&m.vert[t[1]]),
                                       PositionOf(&m.vert[t[2]])};
          const Point n = hole_triangulation::UnitNormal(c[0], c[1], c[2]);
          if (n == Point(0, 0, 0)) continue;
          bool inside = true; // p projects into the face
          for (int k = 0; k < 3; ++k)
            if (((c[(k + 1) % 3] - c[k]) ^ (p - c[k])) * n < 0) inside = false;
          if (!inside) continue;
          const double d = std::fabs((p - c[0]) * n);
          if (d < nearest) nearest = d, face = f;
        }
        if (nearest == std::numeric_limits<double>::infinity()) continue;
        if (nearest > bestDistance) bestDistance = nearest, bestVertex = i, bestFace = face;
      }
      if (bestVertex == vertices.size()) break;
      done[bestVertex] = 1;
      const Index v = vertices[bestVertex];
      const Tri t = FaceTri(m, m.face[bestFace]);
      const std::array<Tri, 3> split{Tri{t[0], t[1], v}, Tri{t[1], t[2], v}, Tri{t[2], t[0], v}};
      const Point n = FaceNormal(m, m.face[bestFace]);
      bool ok = true;
      for (const Tri& nt : split) { // proper, and within 60 degrees of the face it splits
        const Point a = PositionOf(&m.vert[nt[0]]), b = PositionOf(&m.vert[nt[1]]),
                    c = PositionOf(&m.vert[nt[2]]);
        if (!(hole_triangulation::TriArea(a, b, c) > ctx.minArea) ||
            hole_triangulation::UnitNormal(a, b, c) * n <= 0.5)
          ok = false;
      }
      if (!ok) continue;
      for (const Tri& nt : split) {
        ctx.grid->Query(m, FaceGrid::Box(m, nt, ctx.tol), near);
        for (Index g : near)
          if (g != bestFace && Conflict(m, nt, FaceTri(m, m.face[g]))) ok = false;
        if (!ok) break;
      }
      if (!ok) continue;
      FaceType& f = m.face[bestFace];
      f.V(2) = &m.vert[v];
      const Index first = Index(m.face.size());
      vcg::tri::Allocator<MeshType>::AddFaces(m, 2);
      for (int i = 0; i < 2; ++i) {
        FaceType& g = m.face[first + Index(i)];
        for (int k = 0; k < 3; ++k) g.V(k) = &m.vert[split[std::size_t(i) + 1][k]];
        for (int k = 0; k < 3; ++k) g.FFp(k) = &g, g.FFi(k) = k;
        ctx.grid->Insert(m, first + Index(i));
      }
      ctx.grid->Insert(m, bestFace);
      added += 2;
    }
    return added;
  }
};

} // namespace clean
} // namespace molremesh

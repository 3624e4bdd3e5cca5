// Cleaning step: close holes (vcg_ext/clean/). Every boundary loop with at most params.maxHoleEdges
// edges is filled with a minimum-weight triangulation (LoopFill over hole_triangulation.h: Liepa
// 2003, minimize the largest dihedral angle, then maximize the smallest triangle angle, then
// minimize the area; O(n^3) per loop). A loop that passes several times through a vertex is cut
// there into simple loops, each filled on its own. A loop that cannot be filled so (a twisted
// marching-cubes slit whose only fold-bounded triangulation crosses the mesh) is grown instead: its
// boundary faces, and up to params.maxRepairGrowth rings around them, are removed and the larger
// hole is refilled (RegionRefill, kept only when valid); a loop that still cannot be filled stays
// open and is counted. vcglib's Hole<> is not used: its ear cutting needs vertex normals, can leave
// a hole half filled, and checks intersections only against the faces around the hole, not against
// a nearby sheet.
//
// Preconditions: fresh FF and VF adjacency, a coherently oriented edge-manifold mesh. Leaves the
// adjacency fresh. Draws on run.attemptsLeft for the grown loops.
#pragma once

#include <vcg/complex/complex.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include <vcg_ext/clean/boundary_loops.h>
#include <vcg_ext/clean/clean_mesh_access.h>
#include <vcg_ext/clean/clean_params.h>
#include <vcg_ext/clean/loop_fill.h>
#include <vcg_ext/clean/region_refill.h>
#include <vcg_ext/core/index.h>
#include <vcg_ext/spatial/static_face_grid.h>

namespace molremesh {
namespace clean {

/// What HoleFilling::Run did.
struct HoleFillCounts {
  std::size_t closed = 0;               ///< boundary loops filled
  std::size_t facesAdded = 0;           ///< faces added to fill them
  std::size_t grown = 0;                ///< of the closed loops, those grown first
  std::size_t facesRemoved = 0;         ///< faces removed around them
  std::size_t unfilled = 0;             ///< boundary loops left open (too long, or no valid fill)
  std::size_t largestUnfilledEdges = 0; ///< edges of the longest loop left open
};

template <class MeshType>
class HoleFilling {
public:
  using FaceGrid = StaticFaceGrid<MeshType>;
  using Fill = LoopFill<MeshType>;
  using FillContext = typename Fill::FillContext;

  /// The step: fills the loops that can be filled as they are first, then grows the others (see the
  /// file comment).
  static void Run(MeshType& m, CleanRunState& run, HoleFillCounts& r) {
    const CleanRawMeshParams& params = run.params;
    std::vector<std::uint8_t> visited(m.face.size(), 0);
    std::vector<BoundaryLoop> loops;
    BoundaryLoop loop;
    for (Index f = 0; f < m.face.size(); ++f) {
      if (m.face[f].IsD()) continue;
      for (int e = 0; e < 3; ++e)
        if (IsBorderEdge(m.face[f], e) && !(visited[f] & (1u << e))) {
          if (BoundaryLoops<MeshType>::TraceLoop(m, f, e, visited, loop))
            loops.push_back(loop);
          else
            ++r.unfilled;
        }
    }
    if (loops.empty()) return;
    std::unique_ptr<FaceGrid> grid;
    FillContext ctx;
    bool changed = false;
    std::vector<const BoundaryLoop*> unfilled;
    for (const BoundaryLoop& l : loops) {
      const std::size_t edges = l.verts.size();
      if (int(edges) <= params.maxHoleEdges) {
        if (!grid) {
          grid.reset(new FaceGrid(m, 2.0 * run.meanEdge));
          ctx = Fill::MakeContext(run, grid.get());
        }
        std::vector<Tri> plan;
        if (Fill::PlanLoopFill(m, l, ctx, plan)) {
          Fill::CommitFill(m, plan, ctx);
          changed = true;
          ++r.closed;
          r.facesAdded += plan.size();
          continue;
        }
      }
      unfilled.push_back(&l);
    }
    if (changed) RebuildTopology(m);
    for (const BoundaryLoop* l : unfilled) {
      bool filled = false;
      if (int(l->verts.size()) <= params.maxHoleEdges) {
        // Its faces, each once (a face with two boundary sides is on the loop twice).
        std::vector<Index> seed = l->faces;
        std::sort(seed.begin(), seed.end());
        seed.erase(std::unique(seed.begin(), seed.end()), seed.end());
        std::size_t removed = 0, added = 0;
        if (BoundaryLoops<MeshType>::LoopStillOpen(m, *l) &&
            RegionRefill<MeshType>::Repair(m, seed, run, *grid, removed, added)) {
          filled = true;
          ++r.closed;
          ++r.grown;
          r.facesRemoved += removed;
          r.facesAdded += added;
        }
      }
      if (!filled) {
        ++r.unfilled;
        r.largestUnfilledEdges = std::max(r.largestUnfilledEdges, l->verts.size());
      }
    }
  }
};

} // namespace clean
} // namespace molremesh

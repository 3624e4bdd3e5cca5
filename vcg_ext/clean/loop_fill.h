// Filling one boundary loop (vcg_ext/clean/): plan a minimum-weight triangulation of each of its
// lobes (hole_triangulation.h, Liepa 2003) that passes every check against the mesh, then commit it.
//
// Every fill triangle is checked before anything is added: no existing edge is duplicated, no face
// becomes duplicate, no fold beyond params.maxFillDihedral, and it intersects no face of the mesh
// nor another fill triangle (Conflict, the closed-triangle test of MeshQuality's self-intersection
// count). A triangle that fails is forbidden and the triangulation recomputed. PlanLoopFill needs
// fresh VF adjacency apart from what the context records (faces added since the last rebuild are in
// ctx.grid and their edges in ctx.addedEdges) and modifies nothing; CommitFill adds the faces with
// self-referencing FF adjacency, valid until the next RebuildTopology. Each triangulation is paid
// for from the step's fill budget (CleanRunState::fillWorkLeft): a loop the budget cannot pay for is
// refused, which bounds the step's time whatever the loops' lengths and retries.
#pragma once

#include <vcg/complex/complex.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <unordered_set>
#include <vector>

#include <vcg_ext/clean/boundary_loops.h>
#include <vcg_ext/clean/clean_mesh_access.h>
#include <vcg_ext/clean/clean_params.h>
#include <vcg_ext/clean/hole_triangulation.h>
#include <vcg_ext/core/index.h>
#include <vcg_ext/geometry/point.h>
#include <vcg_ext/spatial/static_face_grid.h>

namespace molremesh {
namespace clean {

template <class MeshType>
class LoopFill {
public:
  using FaceType = typename MeshType::FaceType;
  using FaceGrid = StaticFaceGrid<MeshType>;

  /// State shared by the fills of one step: the grid of faces, and the edges and faces created since
  /// the VF adjacency was last rebuilt.
  struct FillContext {
    FaceGrid* grid = nullptr;
    std::unordered_set<std::uint64_t> addedEdges;
    double minArea = 0, maxDihedral = kPi, tol = 0;
    CleanRunState* run = nullptr; ///< the step's fill budget (fillWorkLeft); none when null
  };

  /// The context of the fills of one run step, registering new faces in `grid`.
  static FillContext MakeContext(CleanRunState& run, FaceGrid* grid) {
    FillContext ctx;
    ctx.grid = grid;
    ctx.run = &run;
    // Fill triangles must be clearly proper, far above the degenerate threshold.
    ctx.minArea = std::max(run.params.degenerateAreaEpsilon, 1e-8) * run.meanEdge * run.meanEdge;
    ctx.maxDihedral = run.params.maxFillDihedral * kPi / 180.0;
    ctx.tol = run.planeTolerance;
    return ctx;
  }

  /// Triangulates every lobe of the loop, validates the triangles against the mesh and against each
  /// other, and retries without a triangle that failed. Returns the mesh faces (oriented) to add, or
  /// false when the loop cannot be filled. Nothing is modified.
  static bool PlanLoopFill(MeshType& m, const BoundaryLoop& loop, const FillContext& ctx,
                           std::vector<Tri>& out) {
    out.clear();
    const std::vector<BoundaryLoop> lobes = SplitIntoLobes(loop);
    if (lobes.empty()) return false;
    std::vector<Index> candidates;
    for (const BoundaryLoop& lobe : lobes) {
      const int n = int(lobe.verts.size());
      if (n < 3) return false;
      std::vector<Point> p(n), outer(n);
      for (int i = 0; i < n; ++i) {
        p[i] = PositionOf(&m.vert[lobe.verts[i]]);
        outer[i] = FaceNormal(m, m.face[lobe.faces[i]]);
      }
      // Diagonals that already exist as mesh edges would become non-manifold.
      std::vector<std::uint8_t> ok(std::size_t(n) * n, 1);
      for (int i = 0; i < n; ++i)
        for (int j = i + 2; j < n; ++j)
          if (!(i == 0 && j == n - 1) && EdgeExists(m, ctx, lobe.verts[i], lobe.verts[j]))
            ok[std::size_t(i) * n + j] = 0;
      auto diagonalOk = [&ok, n](int i, int j) { return ok[std::size_t(i) * n + j] != 0; };
      std::unordered_set<std::uint64_t> forbidden;
      std::vector<std::array<int, 3>> local;
      bool accepted = false;
      const int maxAttempts = 4 * n + 16;
      for (int attempt = 0; attempt < maxAttempts && !accepted; ++attempt) {
        if (!DrawFillWork(ctx, n)) return false;
        if (!hole_triangulation::Triangulate(p, outer, diagonalOk, forbidden, ctx.minArea, ctx.maxDihedral,
                                             local)) {
          return false;
        }
        accepted = true;
        std::vector<Tri> mapped;
        for (const auto& t : local) mapped.push_back({lobe.verts[t[2]], lobe.verts[t[1]], lobe.verts[t[0]]});
        for (std::size_t a = 0; a < mapped.size() && accepted; ++a) {
          bool bad = false;
          // A triangle whose three sides are boundary sides duplicates an existing face when that
          // face is the only one around (an isolated triangle).
          if (n == 3) {
            for (Index f : lobe.faces) {
              Tri s = FaceTri(m, m.face[f]), t = mapped[a];
              std::sort(s.begin(), s.end());
              std::sort(t.begin(), t.end());
              if (s == t) return false;
            }
          }
          ctx.grid->Query(m, FaceGrid::Box(m, mapped[a], ctx.tol), candidates);
          for (Index g : candidates)
            if (Conflict(m, mapped[a], FaceTri(m, m.face[g]))) {
              bad = true;
              break;
            }
          for (std::size_t b = 0; b < a && !bad; ++b) bad = Conflict(m, mapped[a], mapped[b]);
          for (std::size_t b = 0; b < out.size() && !bad; ++b) bad = Conflict(m, mapped[a], out[b]);
          if (bad) {
            const auto& t = local[a];
            forbidden.insert((std::uint64_t(t[0]) * n + t[1]) * n + t[2]);
            accepted = false;
          }
        }
        if (accepted) out.insert(out.end(), mapped.begin(), mapped.end());
      }
      if (!accepted) return false;
    }
    // Lobes of one loop share at most their pinch vertices, but a diagonal could still repeat across
    // lobes (or repeat a side): every directed half-edge must be unique, or the edge is non-manifold.
    std::unordered_set<std::uint64_t> halfEdges;
    for (const Tri& t : out)
      for (int k = 0; k < 3; ++k)
        if (!halfEdges.insert((std::uint64_t(t[k]) << 32) | t[(k + 1) % 3]).second) return false;
    return true;
  }

  /// Adds the planned faces and registers them in the grid and the added-edge set.
  static void CommitFill(MeshType& m, const std::vector<Tri>& tris, FillContext& ctx) {
    if (tris.empty()) return;
    const Index first = Index(m.face.size());
    vcg::tri::Allocator<MeshType>::AddFaces(m, tris.size());
    for (std::size_t i = 0; i < tris.size(); ++i) {
      FaceType& f = m.face[first + i];
      for (int k = 0; k < 3; ++k) f.V(k) = &m.vert[tris[i][k]];
      for (int k = 0; k < 3; ++k) f.FFp(k) = &f, f.FFi(k) = k; // valid until the next rebuild
      ctx.grid->Insert(m, first + Index(i));
      for (int k = 0; k < 3; ++k) ctx.addedEdges.insert(EdgeKey(tris[i][k], tris[i][(k + 1) % 3]));
    }
  }

private:
  /// Takes the cost of one triangulation of an n-sided lobe (the candidate triangles it evaluates)
  /// from the step's budget; false, counted as a refusal, when the budget cannot pay for it.
  static bool DrawFillWork(const FillContext& ctx, int n) {
    if (!ctx.run || ctx.run->fillBudgetUnbounded) return true;
    const double cost = double(n) * double(n) * double(n) / 6.0;
    if (cost > ctx.run->fillWorkLeft) {
      ++ctx.run->fillBudgetRefusals;
      return false;
    }
    ctx.run->fillWorkLeft -= cost;
    return true;
  }

  static bool EdgeExists(MeshType& m, const FillContext& ctx, Index a, Index b) {
    return ctx.addedEdges.count(EdgeKey(a, b)) > 0 || EdgeExistsInStar(m, a, b);
  }
};

} // namespace clean
} // namespace molremesh

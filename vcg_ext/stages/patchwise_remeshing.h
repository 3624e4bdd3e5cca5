// Patch-wise remeshing (Khan et al. 2020, section 3.3): every patch of a segmentation is
// remeshed on its own with real-time adaptive remeshing (AdaptiveRemeshing), its border
// locked, all patches in parallel; the patches are stitched back by border vertex identity, and
// the strip around the borders is then unlocked and remeshed once more.
//
// PatchwiseRemeshing<MeshType>::Do(m, reference, facePatch, params):
//  1. sizing: the RAR target length of every vertex, from the curvature of the whole mesh;
//  2. patches: each patch becomes a mesh of its own: its faces, whose vertices shared with
//     another patch (border vertices) are locked, plus "halo" faces that are never edited:
//     every face of the other patches whose bounding box lies within Params::haloCells cells
//     (cells at least as large as the longest edge) of the patch. The halo is there for the
//     checks of LocalRemeshingOps: around a border vertex it completes the fan (valences, folds
//     across the border), and everywhere it is an obstacle for the intersection test, so a
//     patch never pushes a face through a sheet of another patch lying a fraction of an edge
//     length away. Vertices are only created or moved inside the patch's cells dilated by one,
//     so the halo always covers everything a new face can touch. Halo vertices whose faces do
//     not form a single fan (at the halo's outer rim) are split per fan. Every vertex's footpoint
//     on the reference is searched once, before the patches, and handed to each patch holding it
//     (as a patch vertex or in its halo). Each patch is remeshed
//     single-threaded; patches run in parallel (Params::threads) and their results depend only
//     on their input, so the output is bit-identical for any thread count;
//  3. stitching: border vertices come first in the stitched mesh (in the input's vertex
//     order), then the interior vertices of each patch in patch order; border edges are never
//     edited (both end points locked), so the patches glue into a 2-manifold;
//  4. verification: two patches remeshed at the same time only saw each other's old faces.
//     All pairs of faces of different patches are tested for intersection; for every patch
//     involved, its remeshing is undone and redone, one patch after the other, against the
//     stitched result with the others as obstacles (a second conflict freezes the patch at its
//     input faces). Every edit of a redone patch is checked against the current faces of all
//     the others, so no pair is left but those the input had (pairs between two unedited
//     patches are not conflicts);
//  5. the strip: the vertices within Params::borderRings rings of a border are unlocked and
//     RAR runs Params::borderIterations iterations on them, everything else locked, on the
//     whole stitched mesh (one intersection grid for everything);
//  6. AdaptiveRemeshing::Finalize on the whole mesh, nothing locked: the volume (when
//     rar.preserveVolume) and the repair pass once more (the strip's edits change the valences
//     just outside it).
// Topology (manifoldness, closed components, genus) is preserved because every edit is a
// guarded split, collapse, flip or move of LocalRemeshingOps.
#pragma once

#include <vcg/complex/append.h>
#include <vcg/complex/complex.h>

#include <vcg_ext/stages/adaptive_remeshing.h>
#include <vcg_ext/topology/face_face_topology.h>
#include <vcg_ext/spatial/face_hash_grid.h>
#include <vcg_ext/core/input_check.h>
#include <vcg_ext/ops/local_remeshing_ops.h>
#include <vcg_ext/core/parallel_for.h>
#include <vcg_ext/core/radix_sort.h>
#include <vcg_ext/surface/reference_surface.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <numeric>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace molremesh {

template <class MeshType>
class PatchwiseRemeshing {
public:
  using VertexType = typename MeshType::VertexType;
  using FaceType = typename MeshType::FaceType;
  using VertexPointer = typename MeshType::VertexPointer;
  using FacePointer = typename MeshType::FacePointer;
  using Rar = AdaptiveRemeshing<MeshType>;
  using Ops = LocalRemeshingOps<MeshType>;
  using Reference = ReferenceSurface<MeshType>;
  using Point = vcg::Point3d;

  struct Params {
    typename Rar::Params rar; ///< RAR of the patches and of the strip (its threads field is ignored)
    int borderRings = 3;      ///< strip width: vertices within this many rings of a patch border (0 = none)
    int borderIterations = 2; ///< RAR iterations of the strip pass
    int haloCells = 2;        ///< obstacle margin around each patch, in grid cells (>= the longest edge);
                              ///< 0 = no obstacles in the parallel phase, only the fans of the border
                              ///< vertices (the verification after stitching then redoes the patches
                              ///< that meet, with obstacles: for testing)
    bool finalPasses = true;  ///< strip pass and Finalize; false: stop after stitching, the borders exactly
                              ///< as the patch phase kept them (for testing)
    int threads = 0;          ///< worker threads; 0 = all cores (the result does not depend on it)
    /// If set, called on the calling thread with the share of the stage done (0..1) and the step
    /// ("patch 17/75", "strip around the patch borders"); for progress bars.
    std::function<void(double fraction, const std::string& step)> progress;
  };

  struct Result {
    bool ok = false;
    std::string message;                 ///< why it failed, or a one-line summary
    double targetEdgeLength = 0;         ///< L0
    double minSizing = 0, maxSizing = 0; ///< the sizing field, in units of L0
    int patches = 0;                     ///< patches remeshed
    std::size_t borderVertices = 0;      ///< vertices shared by two or more patches
    std::size_t stripVertices = 0;       ///< vertices unlocked for the strip pass
    std::size_t haloFaces = 0;           ///< obstacle faces given to the patches, summed
    std::size_t conflictPairs = 0;       ///< intersecting pairs between patches after the parallel phase
    std::size_t patchesRedone = 0;       ///< patches remeshed again because of a conflict
    std::size_t patchesFrozen = 0;       ///< patches left at their input faces (second conflict)
    std::size_t patchesFailed = 0;       ///< patches whose mesh LocalRemeshingOps refused (left as they were)
    std::string firstFailure;            ///< why the first of them was refused
    std::size_t verticesIn = 0, facesIn = 0, verticesOut = 0, facesOut = 0;
    AdaptiveRemeshingStats patchStats; ///< summed over the patches
    AdaptiveRemeshingStats stripStats;
  };

  /// Remeshes m in place. facePatch (indexed like m.face, -1 for deleted faces) gives the patch
  /// of every face, e.g. RandomSegmentation's result; patch ids need not be contiguous. m must
  /// be a 2-manifold, consistently oriented triangle mesh with FF and VF adjacency enabled and
  /// lie on `reference`. On failure m is left untouched and Result::message says why.
  static Result Do(MeshType& m, const Reference& reference, const std::vector<int>& facePatch,
                   const Params& params = Params(), vcg::CallBackPos* cb = nullptr);

private:
  /// A mesh the patches are cut from: the input, or a stitched result.
  struct Global {
    MeshType mesh;
    std::vector<int> facePatch;  ///< per face
    std::vector<int> borderId;   ///< per vertex: border vertex id, or -1
    std::vector<double> sizing;  ///< per vertex
    std::vector<int> globalFeet; ///< per vertex: ReferenceSurface::ProjectGlobal of its position
                                 ///< (searched once for all patches and halos), or empty
    std::vector<std::vector<std::uint32_t>> facesOfPatch; ///< per patch, increasing
  };
  /// Uniform grid of face bounding boxes (static), for the halo search.
  struct CellIndex {
    Point origin{0, 0, 0};
    double cell = 1;
    std::vector<std::pair<std::uint64_t, std::uint32_t>> entries; ///< (cell key, face), sorted
  };
  /// A patch's faces as they come out of its remeshing (or as they were).
  struct PatchResult {
    bool edited = false;
    bool failed = false;
    std::string error;                     ///< why LocalRemeshingOps refused the patch
    std::vector<Point> verts;              ///< interior vertices (not on a border)
    std::vector<double> sizing;            ///< of verts
    std::vector<std::array<int, 3>> faces; ///< corners: >= 0 index in verts, < 0 border id -(id + 1)
    std::size_t haloFaces = 0;
    AdaptiveRemeshingStats stats;
  };
  struct Context {
    const Reference* reference = nullptr;
    const Params* params = nullptr;
    double L0 = 1;
    std::vector<Point> borderPos;     ///< per border id
    std::vector<double> borderSizing; ///< per border id
    int haloCells = 2;
    double cell = 1; ///< of the halo grid
  };

  static std::uint64_t CellKey(long x, long y, long z) {
    constexpr long kBias = 1L << 20;
    auto c = [](long v) { return std::uint64_t(std::clamp(v + kBias, 0L, (1L << 21) - 1)); };
    return (c(x) << 42) | (c(y) << 21) | c(z);
  }
  static std::array<long, 3> CellOf(const CellIndex& index, const Point& p) {
    return {long(std::floor((p[0] - index.origin[0]) / index.cell)),
            long(std::floor((p[1] - index.origin[1]) / index.cell)),
            long(std::floor((p[2] - index.origin[2]) / index.cell))};
  }
  static void FaceCells(const CellIndex& index, const FaceType& f, std::vector<std::uint64_t>& out) {
    vcg::Box3d box;
    for (int k = 0; k < 3; ++k) box.Add(Ops::ToPoint(f.cV(k)->cP()));
    const auto lo = CellOf(index, box.min), hi = CellOf(index, box.max);
    for (long z = lo[2]; z <= hi[2]; ++z)
      for (long y = lo[1]; y <= hi[1]; ++y)
        for (long x = lo[0]; x <= hi[0]; ++x) out.push_back(CellKey(x, y, z));
  }
  static std::array<long, 3> KeyCoords(std::uint64_t key) {
    constexpr long kBias = 1L << 20;
    const std::uint64_t mask = (std::uint64_t(1) << 21) - 1;
    return {long((key >> 42) & mask) - kBias, long((key >> 21) & mask) - kBias, long(key & mask) - kBias};
  }
  /// The cells within Chebyshev distance `by` of the given (sorted, unique) cells, sorted
  /// (separable: one axis at a time).
  static void Dilate(const std::vector<std::uint64_t>& cells, int by, std::vector<std::uint64_t>& out) {
    out = cells;
    std::vector<std::uint64_t> next;
    for (int axis = 0; axis < 3; ++axis) {
      next.clear();
      next.reserve(out.size() * std::size_t(2 * by + 1));
      for (const std::uint64_t key : out) {
        auto c = KeyCoords(key);
        const long base = c[axis];
        for (long d = -by; d <= by; ++d) {
          c[axis] = base + d;
          next.push_back(CellKey(c[0], c[1], c[2]));
        }
      }
      std::sort(next.begin(), next.end());
      next.erase(std::unique(next.begin(), next.end()), next.end());
      out.swap(next);
    }
  }

  struct InputTopology {
    std::size_t badFaces = 0; ///< null or repeated vertex
    std::size_t nonManifoldEdges = 0, nonManifoldVertices = 0, misorientedEdges = 0, unreferencedVertices = 0;
    double meanEdgeLength = 0; ///< over face sides (interior edges twice)
  };
  /// The preconditions, from FF and VF adjacency (recomputed): cheaper than a full quality report.
  static InputTopology CheckTopology(MeshType& m);

  static void BuildCellIndex(const Global& g, double cell, int threads, CellIndex& index);
  static void IndexPatches(Global& g, int patchCount);
  static PatchResult OriginalPatch(const Global& g, int p);
  /// A patch and its halo as a small mesh: vertices by global index, faces with local corners.
  struct LocalPatch {
    std::vector<std::uint32_t> globalOf;   ///< per local vertex: patch ones, halo ones, fan copies
    std::vector<std::array<int, 3>> faces; ///< patch faces, then halo faces
    std::size_t nPatchVerts = 0, nPatchFaces = 0;
  };
  /// Remeshes patch p in a copy with haloCells cells of obstacle faces around it; the patch's
  /// own faces when that fails.
  static PatchResult RemeshPatch(const Global& g, const CellIndex& index, const Context& ctx, int p,
                                 int haloCells);
  /// The cells where patch p's vertices may go (allowed) and the faces of other patches around it.
  static std::vector<std::uint32_t> PatchRegion(const Global& g, const CellIndex& index, int p, int haloCells,
                                                std::vector<std::uint64_t>& allowed);
  static void BuildLocalFaces(const Global& g, const std::vector<std::uint32_t>& patchFaces,
                              const std::vector<std::uint32_t>& haloFaces, LocalPatch& lp);
  /// Halo vertices whose faces form several fans (at the halo's rim) get one copy per fan.
  static void SplitHaloFans(LocalPatch& lp);
  /// The remeshed patch's vertices and faces into r; false if a face uses a halo vertex.
  static bool ReadBack(const MeshType& local, const Global& g, const Context& ctx, const LocalPatch& lp,
                       const std::vector<double>& sizing, PatchResult& r);
  static void Stitch(const Context& ctx, const std::vector<PatchResult>& results, Global& out);
  /// Why m and facePatch cannot be remeshed ("" when they can); the patch count and L0.
  static std::string CheckInput(MeshType& m, const std::vector<int>& facePatch, const Params& params,
                                int& patchCount, double& L0);
  /// Step 1: the copy g0 of m with its segmentation, sizing field and patch lists; the border
  /// vertices into ctx.
  static void PrepareSizing(MeshType& m, const std::vector<int>& facePatch, int patchCount,
                            const Params& params, const typename Rar::Params& rarParams,
                            const Reference& reference, double L0, int threads, Global& g0, Context& ctx,
                            Result& result);
  /// Step 2: every patch remeshed on its own (borders locked), in parallel; the patches as they
  /// were into original.
  static void RemeshPatchesInParallel(Global& g0, Context& ctx, const Reference& reference, int patchCount,
                                      int threads, std::vector<PatchResult>& original,
                                      std::vector<PatchResult>& results);
  /// Steps 3 and 4: the patches stitched into g; patches whose faces meet another's are redone
  /// once, then left as they were.
  static void StitchAndVerify(const Context& ctx, std::vector<PatchResult>& results,
                              const std::vector<PatchResult>& original, int patchCount, double L0,
                              int threads, Global& g, Result& result);
  /// Empties m and frees its elements' memory (Clear keeps the vectors' capacity).
  static void ReleaseMesh(MeshType& m) {
    m.Clear();
    typename MeshType::VertContainer().swap(m.vert);
    typename MeshType::FaceContainer().swap(m.face);
  }
  /// Pairs of faces of different patches that intersect (LocalRemeshingOps' predicates), sorted.
  static std::vector<std::pair<std::uint32_t, std::uint32_t>> CrossPatchIntersections(const Global& g,
                                                                                      double L0, int threads);
  static AdaptiveRemeshingStats StripPass(Global& g, const Context& ctx, int threads, Result& result,
                                          std::string& error);
};

// ------------------------------------------------------------------------------------------------
// Implementation
// ------------------------------------------------------------------------------------------------

template <class MeshType>
typename PatchwiseRemeshing<MeshType>::InputTopology
PatchwiseRemeshing<MeshType>::CheckTopology(MeshType& m) {
  InputTopology t;
  for (const FaceType& f : m.face) {
    if (f.IsD()) continue;
    if (f.cV(0) == nullptr || f.cV(1) == nullptr || f.cV(2) == nullptr || f.cV(0) == f.cV(1) ||
        f.cV(1) == f.cV(2) || f.cV(2) == f.cV(0))
      ++t.badFaces;
  }
  if (t.badFaces > 0) return t;
  UpdateAdjacency(m);
  double edgeSum = 0;
  std::size_t sides = 0;
  for (FaceType& f : m.face) {
    if (f.IsD()) continue;
    for (int e = 0; e < 3; ++e) {
      edgeSum += (Ops::ToPoint(f.cV(e)->cP()) - Ops::ToPoint(f.cV((e + 1) % 3)->cP())).Norm();
      ++sides;
      const FaceType* g = f.cFFp(e);
      if (g == &f) continue;
      const int w = f.cFFi(e);
      if (g->cFFp(w) != &f)
        ++t.nonManifoldEdges; // three or more faces on the edge
      else if (g->cV(w) != f.cV((e + 1) % 3) || g->cV((w + 1) % 3) != f.cV(e))
        ++t.misorientedEdges;
    }
  }
  t.meanEdgeLength = sides > 0 ? edgeSum / double(sides) : 0.0;
  if (t.nonManifoldEdges > 0) return t; // the fans below need manifold edges
  auto indexIn = [](const FaceType* f, const VertexType* v) {
    return f->cV(0) == v ? 0 : f->cV(1) == v ? 1 : f->cV(2) == v ? 2 : -1;
  };
  for (VertexType& v : m.vert) {
    if (v.IsD()) continue;
    if (v.VFp() == nullptr) {
      ++t.unreferencedVertices;
      continue;
    }
    std::size_t inList = 0;
    for (vcg::face::VFIterator<FaceType> it(&v); !it.End(); ++it) ++inList;
    // The fan through FF from the first face, both ways when it meets the boundary.
    std::size_t inFan = 1;
    const FaceType* f0 = v.VFp();
    const FaceType* f = f0;
    int k = v.VFi();
    bool border = false;
    for (;;) {
      const FaceType* g = f->cFFp(k); // across (v, next)
      if (g == f) {
        border = true;
        break;
      }
      if (g == f0 || inFan > inList) break;
      k = indexIn(g, &v);
      if (k < 0) break;
      f = g;
      ++inFan;
    }
    if (border) {
      f = f0;
      k = v.VFi();
      for (;;) {
        const FaceType* g = f->cFFp((k + 2) % 3); // across (previous, v)
        if (g == f || inFan > inList) break;
        k = indexIn(g, &v);
        if (k < 0) break;
        f = g;
        ++inFan;
      }
    }
    if (inFan != inList) ++t.nonManifoldVertices;
  }
  return t;
}

template <class MeshType>
void PatchwiseRemeshing<MeshType>::IndexPatches(Global& g, int patchCount) {
  g.facesOfPatch.assign(std::size_t(patchCount), {});
  for (std::size_t fi = 0; fi < g.mesh.face.size(); ++fi)
    if (!g.mesh.face[fi].IsD() && g.facePatch[fi] >= 0)
      g.facesOfPatch[std::size_t(g.facePatch[fi])].push_back(std::uint32_t(fi));
}

template <class MeshType>
void PatchwiseRemeshing<MeshType>::BuildCellIndex(const Global& g, double cell, int threads,
                                                  CellIndex& index) {
  vcg::Box3d box;
  for (const auto& v : g.mesh.vert)
    if (!v.IsD()) box.Add(Ops::ToPoint(v.cP()));
  index.origin = box.min - Point(cell, cell, cell);
  index.cell = cell;
  // The entries of each block of faces on all threads, joined in face order; then a stable
  // radix sort by key, which leaves them sorted by (key, face) as a sort of the pairs would.
  constexpr std::size_t kBlock = 4096;
  const std::size_t nf = g.mesh.face.size(), blocks = (nf + kBlock - 1) / kBlock;
  std::vector<std::vector<std::pair<std::uint64_t, std::uint32_t>>> blockEntries(blocks);
  ParallelFor(
      blocks, threads,
      [&](std::size_t begin, std::size_t end, int) {
        std::vector<std::uint64_t> keys;
        for (std::size_t b = begin; b < end; ++b)
          for (std::size_t fi = b * kBlock; fi < std::min(nf, (b + 1) * kBlock); ++fi) {
            if (g.mesh.face[fi].IsD()) continue;
            keys.clear();
            FaceCells(index, g.mesh.face[fi], keys);
            for (const std::uint64_t k : keys) blockEntries[b].emplace_back(k, std::uint32_t(fi));
          }
      },
      1);
  auto& entries = index.entries;
  entries.clear();
  for (const auto& list : blockEntries) entries.insert(entries.end(), list.begin(), list.end());
  std::vector<std::pair<std::uint64_t, std::uint32_t>> scratch;
  StableRadixSortByKey(entries, scratch,
                       [](const std::pair<std::uint64_t, std::uint32_t>& e) { return e.first; });
}

template <class MeshType>
typename PatchwiseRemeshing<MeshType>::PatchResult
PatchwiseRemeshing<MeshType>::OriginalPatch(const Global& g, int p) {
  PatchResult r;
  std::vector<int> local(g.mesh.vert.size(), -1);
  for (const std::uint32_t fi : g.facesOfPatch[std::size_t(p)]) {
    const FaceType& f = g.mesh.face[fi];
    std::array<int, 3> corners{};
    for (int k = 0; k < 3; ++k) {
      const std::size_t vi = vcg::tri::Index(g.mesh, f.cV(k));
      if (g.borderId[vi] >= 0) {
        corners[k] = -(g.borderId[vi] + 1);
        continue;
      }
      if (local[vi] < 0) {
        local[vi] = int(r.verts.size());
        r.verts.push_back(Ops::ToPoint(f.cV(k)->cP()));
        r.sizing.push_back(g.sizing[vi]);
      }
      corners[k] = local[vi];
    }
    r.faces.push_back(corners);
  }
  return r;
}

template <class MeshType>
std::vector<std::uint32_t> PatchwiseRemeshing<MeshType>::PatchRegion(const Global& g, const CellIndex& index,
                                                                     int p, int haloCells,
                                                                     std::vector<std::uint64_t>& allowed) {
  const std::vector<std::uint32_t>& patchFaces = g.facesOfPatch[std::size_t(p)];
  std::vector<std::uint64_t> cells, halo;
  for (const std::uint32_t fi : patchFaces) FaceCells(index, g.mesh.face[fi], cells);
  std::sort(cells.begin(), cells.end());
  cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
  Dilate(cells, 1, allowed);
  std::vector<std::uint32_t> haloFaces;
  if (haloCells == 0) {
    // No obstacles: only the fans around the border vertices (what manifoldness needs).
    for (const std::uint32_t fi : patchFaces)
      for (int k = 0; k < 3; ++k) {
        VertexType* v = const_cast<VertexType*>(g.mesh.face[fi].cV(k));
        if (g.borderId[vcg::tri::Index(g.mesh, v)] < 0) continue;
        for (vcg::face::VFIterator<FaceType> it(v); !it.End(); ++it) {
          const std::size_t gi = vcg::tri::Index(g.mesh, it.F());
          if (g.facePatch[gi] != p) haloFaces.push_back(std::uint32_t(gi));
        }
      }
    std::sort(haloFaces.begin(), haloFaces.end());
    haloFaces.erase(std::unique(haloFaces.begin(), haloFaces.end()), haloFaces.end());
  } else {
    Dilate(cells, haloCells, halo);
    auto it = index.entries.begin();
    for (const std::uint64_t key : halo) {
      it = std::lower_bound(it, index.entries.end(), std::make_pair(key, std::uint32_t(0)));
      for (auto jt = it; jt != index.entries.end() && jt->first == key; ++jt)
        if (g.facePatch[jt->second] != p) haloFaces.push_back(jt->second);
    }
    std::sort(haloFaces.begin(), haloFaces.end());
    haloFaces.erase(std::unique(haloFaces.begin(), haloFaces.end()), haloFaces.end());
  }
  return haloFaces;
}

template <class MeshType>
void PatchwiseRemeshing<MeshType>::BuildLocalFaces(const Global& g,
                                                   const std::vector<std::uint32_t>& patchFaces,
                                                   const std::vector<std::uint32_t>& haloFaces,
                                                   LocalPatch& lp) {
  std::vector<std::uint32_t>& globalOf = lp.globalOf;
  std::vector<std::array<int, 3>>& faces = lp.faces;
  std::vector<std::uint32_t> patchVerts;
  for (const std::uint32_t fi : patchFaces)
    for (int k = 0; k < 3; ++k)
      patchVerts.push_back(std::uint32_t(vcg::tri::Index(g.mesh, g.mesh.face[fi].cV(k))));
  std::sort(patchVerts.begin(), patchVerts.end());
  patchVerts.erase(std::unique(patchVerts.begin(), patchVerts.end()), patchVerts.end());
  globalOf.assign(patchVerts.begin(), patchVerts.end());
  // Map global -> local with a sorted lookup for patch vertices and a small table for the halo.
  auto patchLocal = [&](std::uint32_t gv) -> int {
    const auto it = std::lower_bound(patchVerts.begin(), patchVerts.end(), gv);
    return (it != patchVerts.end() && *it == gv) ? int(it - patchVerts.begin()) : -1;
  };
  std::vector<std::pair<std::uint32_t, int>> haloLocal; // (global, local), sorted by global after filling
  faces.reserve(patchFaces.size() + haloFaces.size());
  for (const std::uint32_t fi : patchFaces) {
    std::array<int, 3> t{};
    for (int k = 0; k < 3; ++k)
      t[k] = patchLocal(std::uint32_t(vcg::tri::Index(g.mesh, g.mesh.face[fi].cV(k))));
    faces.push_back(t);
  }
  std::vector<std::uint32_t> haloVerts;
  for (const std::uint32_t fi : haloFaces)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t gv = std::uint32_t(vcg::tri::Index(g.mesh, g.mesh.face[fi].cV(k)));
      if (patchLocal(gv) < 0) haloVerts.push_back(gv);
    }
  std::sort(haloVerts.begin(), haloVerts.end());
  haloVerts.erase(std::unique(haloVerts.begin(), haloVerts.end()), haloVerts.end());
  for (const std::uint32_t gv : haloVerts) {
    haloLocal.emplace_back(gv, int(globalOf.size()));
    globalOf.push_back(gv);
  }
  for (const std::uint32_t fi : haloFaces) {
    std::array<int, 3> t{};
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t gv = std::uint32_t(vcg::tri::Index(g.mesh, g.mesh.face[fi].cV(k)));
      const int l = patchLocal(gv);
      if (l >= 0) {
        t[k] = l;
      } else {
        const auto it = std::lower_bound(haloLocal.begin(), haloLocal.end(), std::make_pair(gv, -1));
        t[k] = it->second;
      }
    }
    faces.push_back(t);
  }
  lp.nPatchVerts = patchVerts.size();
  lp.nPatchFaces = patchFaces.size();
}

template <class MeshType>
void PatchwiseRemeshing<MeshType>::SplitHaloFans(LocalPatch& lp) {
  std::vector<std::uint32_t>& globalOf = lp.globalOf;
  std::vector<std::array<int, 3>>& faces = lp.faces;
  const std::size_t nPatchVerts = lp.nPatchVerts, nPatchFaces = lp.nPatchFaces;
  const std::size_t nv = globalOf.size();
  std::vector<std::uint32_t> start(nv + 1, 0);
  for (std::size_t f = nPatchFaces; f < faces.size(); ++f)
    for (int k = 0; k < 3; ++k) ++start[std::size_t(faces[f][k]) + 1];
  for (std::size_t i = 0; i < nv; ++i) start[i + 1] += start[i];
  std::vector<std::pair<std::uint32_t, int>> corners(start[nv]); // (face, corner)
  std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
  for (std::size_t f = nPatchFaces; f < faces.size(); ++f)
    for (int k = 0; k < 3; ++k) corners[fill[std::size_t(faces[f][k])]++] = {std::uint32_t(f), k};
  std::vector<int> fan;
  for (std::size_t u = nPatchVerts; u < nv; ++u) {
    const std::uint32_t b = start[u], e = start[u + 1];
    const std::uint32_t n = e - b;
    if (n < 2) continue;
    fan.assign(n, -1);
    // Union-find over the corners of u: faces sharing an edge (u, w) are in one fan.
    std::vector<std::uint32_t> parent(n);
    std::iota(parent.begin(), parent.end(), 0u);
    auto find = [&](std::uint32_t x) {
      while (parent[x] != x) x = parent[x] = parent[parent[x]];
      return x;
    };
    for (std::uint32_t i = 0; i < n; ++i)
      for (std::uint32_t j = i + 1; j < n; ++j) {
        const auto [fi, ki] = corners[b + i];
        const auto [fj, kj] = corners[b + j];
        const int nextI = faces[fi][(ki + 1) % 3], prevI = faces[fi][(ki + 2) % 3];
        const int nextJ = faces[fj][(kj + 1) % 3], prevJ = faces[fj][(kj + 2) % 3];
        if (nextI == prevJ || prevI == nextJ) {
          const std::uint32_t ri = find(i), rj = find(j);
          if (ri != rj) parent[std::max(ri, rj)] = std::min(ri, rj);
        }
      }
    // Roots in increasing order; the first fan keeps u.
    std::vector<std::uint32_t> roots;
    for (std::uint32_t i = 0; i < n; ++i)
      if (find(i) == i) roots.push_back(i);
    for (std::size_t r = 1; r < roots.size(); ++r) {
      const int copy = int(globalOf.size());
      globalOf.push_back(globalOf[u]);
      for (std::uint32_t i = 0; i < n; ++i)
        if (find(i) == roots[r]) faces[corners[b + i].first][corners[b + i].second] = copy;
    }
  }
}

template <class MeshType>
bool PatchwiseRemeshing<MeshType>::ReadBack(const MeshType& local, const Global& g, const Context& ctx,
                                            const LocalPatch& lp, const std::vector<double>& sizing,
                                            PatchResult& r) {
  const std::vector<std::uint32_t>& globalOf = lp.globalOf;
  const std::size_t nPatchVerts = lp.nPatchVerts, nPatchFaces = lp.nPatchFaces;
  // Halo faces keep their slots [nPatchFaces, faces.size()); halo vertices theirs
  // [nPatchVerts, globalOf.size()): all their vertices are locked, so they are never edited.
  const std::size_t haloEnd = lp.faces.size();
  constexpr int kUnused = std::numeric_limits<int>::min();
  std::vector<int> out(local.vert.size(), kUnused);
  for (std::size_t i = 0; i < local.vert.size(); ++i) {
    const VertexType& v = local.vert[i];
    if (v.IsD() || v.cVFp() == nullptr) continue;
    const bool original = i < nPatchVerts;
    const bool haloVertex = i >= nPatchVerts && i < globalOf.size();
    if (haloVertex) continue;
    if (original && g.borderId[globalOf[i]] >= 0) {
      out[i] = -(g.borderId[globalOf[i]] + 1);
      continue;
    }
    out[i] = int(r.verts.size());
    r.verts.push_back(Ops::ToPoint(v.cP()));
    r.sizing.push_back(i < sizing.size() ? sizing[i] : ctx.L0);
  }
  for (std::size_t fi = 0; fi < local.face.size(); ++fi) {
    const FaceType& f = local.face[fi];
    if (f.IsD() || (fi >= nPatchFaces && fi < haloEnd)) continue;
    std::array<int, 3> t{};
    for (int k = 0; k < 3; ++k) {
      const std::size_t vi = vcg::tri::Index(local, f.cV(k));
      const bool haloVertex = vi >= nPatchVerts && vi < globalOf.size();
      if (haloVertex || out[vi] == kUnused) // cannot happen: patch faces only use patch vertices
        return false;
      t[k] = out[vi];
    }
    r.faces.push_back(t);
  }
  return true;
}

template <class MeshType>
typename PatchwiseRemeshing<MeshType>::PatchResult
PatchwiseRemeshing<MeshType>::RemeshPatch(const Global& g, const CellIndex& index, const Context& ctx, int p,
                                          int haloCells) {
  const std::vector<std::uint32_t>& patchFaces = g.facesOfPatch[std::size_t(p)];
  PatchResult fallback;
  auto fail = [&](const std::string& why) {
    fallback = OriginalPatch(g, p);
    fallback.failed = true;
    fallback.error = why;
    return fallback;
  };
  if (patchFaces.empty()) return OriginalPatch(g, p);

  // --- Region: the patch's cells, dilated once (where vertices may go) and haloCells times. ---
  std::vector<std::uint64_t> allowed;
  const std::vector<std::uint32_t> haloFaces = PatchRegion(g, index, p, haloCells, allowed);

  // --- Local mesh: patch vertices (increasing global index), then halo vertices. ---
  LocalPatch lp;
  BuildLocalFaces(g, patchFaces, haloFaces, lp);
  // Halo vertices whose faces form several fans (at the halo's rim) get one copy per fan.
  SplitHaloFans(lp);
  const std::vector<std::uint32_t>& globalOf = lp.globalOf;
  const std::vector<std::array<int, 3>>& faces = lp.faces;

  MeshType local;
  vcg::tri::Allocator<MeshType>::AddVertices(local, globalOf.size());
  for (std::size_t i = 0; i < globalOf.size(); ++i) local.vert[i].P() = g.mesh.vert[globalOf[i]].cP();
  vcg::tri::Allocator<MeshType>::AddFaces(local, faces.size());
  for (std::size_t f = 0; f < faces.size(); ++f)
    for (int k = 0; k < 3; ++k) local.face[f].V(k) = &local.vert[std::size_t(faces[f][k])];
  std::vector<double> sizing(globalOf.size());
  for (std::size_t i = 0; i < globalOf.size(); ++i) sizing[i] = g.sizing[globalOf[i]];

  // --- Remesh. ---
  auto rarParams = ctx.params->rar;
  rarParams.threads = 1;
  Ops ops(local, *ctx.reference, ctx.L0, rarParams.guards, 1);
  std::string error;
  std::vector<int> globalFeet;
  if (!g.globalFeet.empty()) {
    globalFeet.resize(globalOf.size());
    for (std::size_t i = 0; i < globalOf.size(); ++i) globalFeet[i] = g.globalFeet[globalOf[i]];
  }
  if (!ops.Init(&error, false, false, false, globalFeet.empty() ? nullptr : &globalFeet)) return fail(error);
  for (std::size_t i = 0; i < globalOf.size(); ++i)
    ops.SetLocked(local.vert[i], i >= lp.nPatchVerts || g.borderId[globalOf[i]] >= 0);
  auto inside = [&allowed, &index](const Point& q) {
    const auto c = CellOf(index, q);
    return std::binary_search(allowed.begin(), allowed.end(), CellKey(c[0], c[1], c[2]));
  };
  PatchResult r;
  r.edited = true;
  r.haloFaces = haloFaces.size();
  r.stats = Rar::Remesh(ops, sizing, rarParams, rarParams.iterations, 1, inside);

  // --- Read the result back (no compaction: indices below are the ops' ones). ---
  if (!ReadBack(local, g, ctx, lp, sizing, r)) return fail("a remeshed face uses a halo vertex");
  return r;
}

template <class MeshType>
void PatchwiseRemeshing<MeshType>::Stitch(const Context& ctx, const std::vector<PatchResult>& results,
                                          Global& out) {
  std::size_t nv = ctx.borderPos.size(), nf = 0;
  for (const PatchResult& r : results) {
    nv += r.verts.size();
    nf += r.faces.size();
  }
  out.mesh.Clear();
  vcg::tri::Allocator<MeshType>::AddVertices(out.mesh, nv);
  vcg::tri::Allocator<MeshType>::AddFaces(out.mesh, nf);
  out.sizing.assign(nv, ctx.L0);
  out.borderId.assign(nv, -1);
  out.facePatch.assign(nf, -1);
  for (std::size_t b = 0; b < ctx.borderPos.size(); ++b) {
    out.mesh.vert[b].P() = Ops::ToCoord(ctx.borderPos[b]);
    out.sizing[b] = ctx.borderSizing[b];
    out.borderId[b] = int(b);
  }
  std::size_t vbase = ctx.borderPos.size(), fcount = 0;
  for (std::size_t p = 0; p < results.size(); ++p) {
    const PatchResult& r = results[p];
    for (std::size_t i = 0; i < r.verts.size(); ++i) {
      out.mesh.vert[vbase + i].P() = Ops::ToCoord(r.verts[i]);
      out.sizing[vbase + i] = r.sizing[i];
    }
    for (const auto& t : r.faces) {
      FaceType& f = out.mesh.face[fcount];
      for (int k = 0; k < 3; ++k)
        f.V(k) = &out.mesh.vert[t[k] < 0 ? std::size_t(-t[k] - 1) : vbase + std::size_t(t[k])];
      out.facePatch[fcount] = int(p);
      ++fcount;
    }
    vbase += r.verts.size();
  }
  // Border vertices no face uses any more cannot exist (they are locked), but keep the mesh clean.
  UpdateAdjacency(out.mesh);
  IndexPatches(out, int(results.size()));
}

template <class MeshType>
std::vector<std::pair<std::uint32_t, std::uint32_t>>
PatchwiseRemeshing<MeshType>::CrossPatchIntersections(const Global& g, double L0, int threads) {
  const MeshType& m = g.mesh;
  FaceHashGrid grid;
  vcg::Box3d all;
  for (const auto& v : m.vert)
    if (!v.IsD()) all.Add(Ops::ToPoint(v.cP()));
  grid.Reset(L0, all.min);
  grid.InsertAll(
      m.face.size(),
      [&](std::size_t fi, vcg::Box3d& box) {
        const FaceType& f = m.face[fi];
        if (f.IsD()) return false;
        for (int k = 0; k < 3; ++k) box.Add(Ops::ToPoint(f.cV(k)->cP()));
        return true;
      },
      threads);
  const double maxAbs = std::max({std::fabs(all.min[0]), std::fabs(all.min[1]), std::fabs(all.min[2]),
                                  std::fabs(all.max[0]), std::fabs(all.max[1]), std::fabs(all.max[2])});
  const double margin = 1e-9 * (maxAbs + L0);
  const int nThreads = ResolveThreadCount(threads);
  std::vector<FaceHashGrid::QueryMarks> marks(static_cast<std::size_t>(nThreads));
  const std::size_t block = 4096;
  const std::size_t blocks = (m.face.size() + block - 1) / block;
  std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> found(blocks);
  ParallelFor(
      blocks, nThreads,
      [&](std::size_t b0, std::size_t b1, int t) {
        for (std::size_t b = b0; b < b1; ++b) {
          const std::size_t end = std::min(m.face.size(), (b + 1) * block);
          for (std::size_t fi = b * block; fi < end; ++fi) {
            const FaceType& f = m.face[fi];
            if (f.IsD()) continue;
            std::array<Point, 3> a;
            std::array<const VertexType*, 3> va{};
            for (int k = 0; k < 3; ++k) {
              a[k] = Ops::ToPoint(f.cV(k)->cP());
              va[k] = f.cV(k);
            }
            const Point na = local_ops_detail::UnitNormal(a);
            grid.QueryFace(fi, marks[std::size_t(t)], [&](std::size_t gi) {
              if (gi <= fi || g.facePatch[gi] == g.facePatch[fi]) return;
              const FaceType& h = m.face[gi];
              std::array<Point, 3> b2;
              std::array<const VertexType*, 3> vb{};
              for (int k = 0; k < 3; ++k) {
                b2[k] = Ops::ToPoint(h.cV(k)->cP());
                vb[k] = h.cV(k);
              }
              if (local_ops_detail::FacesIntersect(a, na, va, b2, local_ops_detail::UnitNormal(b2), vb,
                                                   margin))
                found[b].emplace_back(std::uint32_t(fi), std::uint32_t(gi));
            });
          }
        }
      },
      1);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  for (auto& list : found) pairs.insert(pairs.end(), list.begin(), list.end());
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

template <class MeshType>
AdaptiveRemeshingStats PatchwiseRemeshing<MeshType>::StripPass(Global& g, const Context& ctx, int threads,
                                                               Result& result, std::string& error) {
  MeshType& m = g.mesh;
  Ops ops(m, *ctx.reference, ctx.L0, ctx.params->rar.guards, threads);
  if (!ops.Init(&error)) return {};
  std::size_t& stripVertices = result.stripVertices;
  // Rings around the border vertices, breadth first over the one-rings.
  std::vector<int> ring(m.vert.size(), -1);
  std::vector<std::size_t> front, next;
  for (std::size_t i = 0; i < m.vert.size(); ++i)
    if (!m.vert[i].IsD() && g.borderId[i] >= 0) {
      ring[i] = 0;
      front.push_back(i);
    }
  for (int r = 1; r <= ctx.params->borderRings; ++r) {
    next.clear();
    for (const std::size_t vi : front)
      for (vcg::face::VFIterator<FaceType> it(&m.vert[vi]); !it.End(); ++it)
        for (int k = 1; k < 3; ++k) {
          const std::size_t w = vcg::tri::Index(m, it.F()->V((it.I() + k) % 3));
          if (ring[w] < 0) {
            ring[w] = r;
            next.push_back(w);
          }
        }
    std::sort(next.begin(), next.end());
    front.swap(next);
  }
  stripVertices = 0;
  for (std::size_t i = 0; i < m.vert.size(); ++i) {
    const bool inStrip = ring[i] >= 0;
    ops.SetLocked(m.vert[i], !inStrip);
    if (inStrip) ++stripVertices;
  }
  auto rarParams = ctx.params->rar;
  rarParams.threads = threads;
  AdaptiveRemeshingStats stats;
  if (ctx.params->borderRings > 0 && ctx.params->borderIterations > 0)
    stats = Rar::Remesh(ops, g.sizing, rarParams, ctx.params->borderIterations, threads);
  // Volume, then one more repair pass with nothing locked (the strip's edits change the
  // valences just outside it, the volume offset the shape of triangles on sharp creases).
  if (ctx.params->progress) ctx.params->progress(0.9, "restoring the volume, a last repair pass");
  stats.Add(Rar::Finalize(ops, g.sizing, rarParams, threads));
  ops.Finish();
  return stats;
}

template <class MeshType>
std::string PatchwiseRemeshing<MeshType>::CheckInput(MeshType& m, const std::vector<int>& facePatch,
                                                     const Params& params, int& patchCount, double& L0) {
  const InputCheck check = CheckTriangleMeshInput(m);
  if (!check.ok) return std::string("patch-wise remeshing refused: " + check.message);
  if (!vcg::tri::HasFFAdjacency(m) || !vcg::tri::HasVFAdjacency(m))
    return std::string("patch-wise remeshing refused: face-face and vertex-face adjacency must be enabled");
  if (facePatch.size() != m.face.size())
    return std::string("patch-wise remeshing refused: the segmentation has " +
                       std::to_string(facePatch.size()) + " entries for " + std::to_string(m.face.size()) +
                       " faces");
  patchCount = 0;
  for (std::size_t fi = 0; fi < m.face.size(); ++fi) {
    if (m.face[fi].IsD()) continue;
    if (facePatch[fi] < 0) return std::string("patch-wise remeshing refused: a face has no patch");
    patchCount = std::max(patchCount, facePatch[fi] + 1);
  }
  const auto& rp = params.rar;
  if (rp.iterations < 0 || params.borderIterations < 0 || params.borderRings < 0 || params.haloCells < 0)
    return std::string("patch-wise remeshing refused: negative iteration, ring or halo cell count");
  if (!(rp.minLengthFactor > 0) || rp.maxLengthFactor < rp.minLengthFactor ||
      !(rp.collapseFactor < rp.splitFactor))
    return std::string("patch-wise remeshing refused: need 0 < minLengthFactor <= maxLengthFactor and "
                       "collapseFactor < splitFactor");
  const InputTopology input = CheckTopology(m);
  if (input.badFaces > 0)
    return std::string(
        "patch-wise remeshing refused: the mesh has faces with a repeated or missing vertex; run the "
        "cleaning stage first");
  if (input.nonManifoldEdges > 0 || input.nonManifoldVertices > 0 || input.misorientedEdges > 0)
    return std::string("patch-wise remeshing refused: the mesh is not a consistently oriented 2-manifold (" +
                       std::to_string(input.nonManifoldEdges) + " non-manifold edges, " +
                       std::to_string(input.nonManifoldVertices) + " non-manifold vertices, " +
                       std::to_string(input.misorientedEdges) +
                       " misoriented edges); run the cleaning stage first");
  if (input.unreferencedVertices > 0)
    return std::string(
        "patch-wise remeshing refused: the mesh has unreferenced vertices; run the cleaning stage first");
  L0 = rp.targetEdgeLength > 0 ? rp.targetEdgeLength : input.meanEdgeLength;
  if (!(L0 > 0) || !std::isfinite(L0))
    return std::string("patch-wise remeshing refused: no valid target edge length");
  return {};
}

template <class MeshType>
void PatchwiseRemeshing<MeshType>::PrepareSizing(MeshType& m, const std::vector<int>& facePatch,
                                                 int patchCount, const Params& params,
                                                 const typename Rar::Params& rarParams,
                                                 const Reference& reference, double L0, int threads,
                                                 Global& g0, Context& ctx, Result& result) {
  vcg::tri::Append<MeshType, MeshType>::MeshCopy(g0.mesh, m);
  UpdateAdjacency(g0.mesh);
  // MeshCopy compacts: map the segmentation onto the copy's faces (same order, deleted skipped).
  g0.facePatch.clear();
  for (std::size_t fi = 0; fi < m.face.size(); ++fi)
    if (!m.face[fi].IsD()) g0.facePatch.push_back(facePatch[fi]);
  g0.sizing = Rar::ComputeSizing(g0.mesh, L0, rarParams, threads);
  {
    double lo = std::numeric_limits<double>::infinity(), hi = 0;
    for (const double s : g0.sizing) lo = std::min(lo, s), hi = std::max(hi, s);
    result.minSizing = lo / L0;
    result.maxSizing = hi / L0;
  }
  std::vector<int> vertPatch(g0.mesh.vert.size(), -1); // -1 none, -2 several
  for (std::size_t fi = 0; fi < g0.mesh.face.size(); ++fi)
    for (int k = 0; k < 3; ++k) {
      int& vp = vertPatch[vcg::tri::Index(g0.mesh, g0.mesh.face[fi].cV(k))];
      if (vp == -1)
        vp = g0.facePatch[fi];
      else if (vp != g0.facePatch[fi])
        vp = -2;
    }
  ctx.reference = &reference;
  ctx.params = &params;
  ctx.L0 = L0;
  ctx.haloCells = params.haloCells;
  g0.borderId.assign(g0.mesh.vert.size(), -1);
  for (std::size_t vi = 0; vi < g0.mesh.vert.size(); ++vi)
    if (vertPatch[vi] == -2) {
      g0.borderId[vi] = int(ctx.borderPos.size());
      ctx.borderPos.push_back(Ops::ToPoint(g0.mesh.vert[vi].cP()));
      ctx.borderSizing.push_back(g0.sizing[vi]);
    }
  result.borderVertices = ctx.borderPos.size();
  IndexPatches(g0, patchCount);
}

template <class MeshType>
void PatchwiseRemeshing<MeshType>::RemeshPatchesInParallel(Global& g0, Context& ctx,
                                                           const Reference& reference, int patchCount,
                                                           int threads, std::vector<PatchResult>& original,
                                                           std::vector<PatchResult>& results) {
  const auto& rp = ctx.params->rar;
  const double L0 = ctx.L0;
  double longest = 0;
  for (const FaceType& f : g0.mesh.face)
    for (int k = 0; k < 3; ++k)
      longest =
          std::max(longest, (Ops::ToPoint(f.cV(k)->cP()) - Ops::ToPoint(f.cV((k + 1) % 3)->cP())).Norm());
  ctx.cell = 1.05 * std::max(longest, rp.splitFactor * rp.maxLengthFactor * L0);
  original.assign(static_cast<std::size_t>(patchCount), PatchResult());
  results.assign(static_cast<std::size_t>(patchCount), PatchResult());
  // The footpoints every patch's LocalRemeshingOps::Init would search for its vertices and its
  // halo's, once per vertex instead of once per patch that holds it (about twice).
  g0.globalFeet.assign(g0.mesh.vert.size(), -1);
  ParallelFor(g0.mesh.vert.size(), threads, [&](std::size_t begin, std::size_t end, int) {
    for (std::size_t vi = begin; vi < end; ++vi) {
      const VertexType& v = g0.mesh.vert[vi];
      if (!v.IsD() && v.cVFp() != nullptr)
        g0.globalFeet[vi] = reference.ProjectGlobal(Ops::ToPoint(v.cP())).face;
    }
  });
  for (int p = 0; p < patchCount; ++p) original[std::size_t(p)] = OriginalPatch(g0, p);
  {
    CellIndex index;
    BuildCellIndex(g0, ctx.cell, threads, index);
    // Largest patches first for load balance; results go by patch id.
    std::vector<int> order(static_cast<std::size_t>(patchCount));
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
      return g0.facesOfPatch[std::size_t(a)].size() > g0.facesOfPatch[std::size_t(b)].size();
    });
    std::atomic<int> finished{0};
    ParallelFor(
        order.size(), threads,
        [&](std::size_t begin, std::size_t end, int thread) {
          for (std::size_t i = begin; i < end; ++i) {
            const int p = order[i];
            results[std::size_t(p)] = RemeshPatch(g0, index, ctx, p, ctx.haloCells);
            const int done = ++finished;
            // Thread 0 is the calling thread: a progress bar may only be touched from there.
            if (thread == 0 && ctx.params->progress)
              ctx.params->progress(0.05 + 0.7 * done / double(order.size()),
                                   "patch " + std::to_string(done) + "/" + std::to_string(order.size()));
          }
        },
        1);
  }
}

template <class MeshType>
void PatchwiseRemeshing<MeshType>::StitchAndVerify(const Context& ctx, std::vector<PatchResult>& results,
                                                   const std::vector<PatchResult>& original, int patchCount,
                                                   double L0, int threads, Global& g, Result& result) {
  Stitch(ctx, results, g);
  std::vector<char> frozen(static_cast<std::size_t>(patchCount), 0);
  for (int round = 0; round < 4; ++round) {
    const auto pairs = CrossPatchIntersections(g, L0, threads);
    std::vector<int> involved;
    for (const auto& [a, b] : pairs) {
      const int pa = g.facePatch[a], pb = g.facePatch[b];
      if (!results[std::size_t(pa)].edited && !results[std::size_t(pb)].edited) continue; // was in the input
      for (const int q : {pa, pb})
        if (results[std::size_t(q)].edited) involved.push_back(q);
    }
    if (round == 0) result.conflictPairs = pairs.size();
    std::sort(involved.begin(), involved.end());
    involved.erase(std::unique(involved.begin(), involved.end()), involved.end());
    if (involved.empty()) break;
    for (const int q : involved) results[std::size_t(q)] = original[std::size_t(q)];
    Stitch(ctx, results, g);
    if (round == 0) {
      // Redo each, one after the other, against everything else as it now is.
      for (const int q : involved) {
        CellIndex index;
        BuildCellIndex(g, ctx.cell, threads, index);
        results[std::size_t(q)] = RemeshPatch(g, index, ctx, q, std::max(ctx.haloCells, 1));
        ++result.patchesRedone;
        Stitch(ctx, results, g);
      }
    } else {
      for (const int q : involved)
        if (!frozen[std::size_t(q)]) {
          frozen[std::size_t(q)] = 1;
          ++result.patchesFrozen;
        }
    }
  }
  for (const PatchResult& r : results) {
    result.patchStats.Add(r.stats);
    result.haloFaces += r.haloFaces;
    if (r.failed && result.patchesFailed++ == 0) result.firstFailure = r.error;
  }
}

template <class MeshType>
typename PatchwiseRemeshing<MeshType>::Result
PatchwiseRemeshing<MeshType>::Do(MeshType& m, const Reference& reference, const std::vector<int>& facePatch,
                                 const Params& params, vcg::CallBackPos* cb) {
  Result result;
  auto finish = [&](bool ok, const std::string& message) {
    result.ok = ok;
    result.message = message;
    return result;
  };
  auto progress = [&](int percent, const char* what) {
    if (cb) cb(percent, what);
    if (params.progress) params.progress(percent / 100.0, std::string(what).substr(5)); // without "RAR: "
  };

  // --- Preconditions -----------------------------------------------------------------------------
  int patchCount = 0;
  double L0 = 0;
  if (std::string error = CheckInput(m, facePatch, params, patchCount, L0); !error.empty())
    return finish(false, error);
  const auto& rp = params.rar;
  result.targetEdgeLength = L0;
  result.verticesIn = std::size_t(m.vn);
  result.facesIn = std::size_t(m.fn);
  const int threads = ResolveThreadCount(params.threads);

  // --- 1. Sizing, border vertices --------------------------------------------------------------------
  progress(2, "RAR: sizing field");
  UpdateAdjacency(m);
  auto rarParams = rp;
  rarParams.targetEdgeLength = L0;
  Global g0;
  Context ctx;
  PrepareSizing(m, facePatch, patchCount, params, rarParams, reference, L0, threads, g0, ctx, result);

  // A single patch (or patches without shared vertices, i.e. one per component and component
  // count 1): plain RAR on the whole mesh with every thread.
  std::size_t nonEmpty = 0;
  for (const auto& list : g0.facesOfPatch) nonEmpty += list.empty() ? 0 : 1;
  Global stitched;
  MeshType* output = &g0.mesh;
  result.patches = int(nonEmpty);
  if (nonEmpty <= 1) {
    rarParams.threads = threads;
    Ops ops(g0.mesh, reference, L0, rarParams.guards, threads);
    std::string error;
    if (!ops.Init(&error)) return finish(false, "patch-wise remeshing refused: " + error);
    result.patchStats = Rar::Remesh(ops, g0.sizing, rarParams, rarParams.iterations, threads);
    result.patchStats.Add(Rar::Finalize(ops, g0.sizing, rarParams, threads));
    ops.Finish();
  } else {
    // --- 2. Patches in parallel ------------------------------------------------------------------------
    progress(5, "RAR: remeshing the patches");
    std::vector<PatchResult> original, results;
    RemeshPatchesInParallel(g0, ctx, reference, patchCount, threads, original, results);
    // From here on the stitched mesh and the patches' original faces (`original`) are all that is
    // read: the copy of the input goes before the strip pass's mesh grows, so that its memory is
    // reused there (on 4JSV about 90 MB less at the peak).
    ReleaseMesh(g0.mesh);

    // --- 3. Stitch; 4. verify and redo conflicting patches -------------------------------------
    Global& g = stitched;
    progress(76, "RAR: stitching the patches and checking their borders");
    StitchAndVerify(ctx, results, original, patchCount, L0, threads, g, result);

    // --- 5. The strip around the borders; 6. finalize ------------------------------------------
    if (params.finalPasses) {
      progress(80, "RAR: remeshing the strip around the patch borders");
      std::string error;
      result.stripStats = StripPass(g, ctx, threads, result, error);
      if (!error.empty()) return finish(false, "patch-wise remeshing failed in the strip pass: " + error);
    }
    output = &g.mesh;
  }

  // --- Result into m -------------------------------------------------------------------------------
  vcg::tri::Allocator<MeshType>::CompactEveryVector(*output);
  vcg::tri::Append<MeshType, MeshType>::MeshCopy(m, *output);
  UpdateAdjacency(m);
  if (vcg::tri::HasPerFaceNormal(m)) vcg::tri::UpdateNormal<MeshType>::PerFaceNormalized(m);
  if (vcg::tri::HasPerVertexNormal(m)) vcg::tri::UpdateNormal<MeshType>::PerVertexNormalized(m);
  result.verticesOut = std::size_t(m.vn);
  result.facesOut = std::size_t(m.fn);
  progress(100, "RAR: done");
  return finish(true, "patch-wise RAR: " + std::to_string(result.patches) + " patches, " +
                          std::to_string(result.verticesIn) + " -> " + std::to_string(result.verticesOut) +
                          " vertices");
}

} // namespace molremesh

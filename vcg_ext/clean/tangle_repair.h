// Cleaning step: repair local tangles (vcg_ext/clean/): regions of self-intersecting faces and of
// faces where the orientation cannot be made coherent, each removed and refilled (RegionRefill).
//
// TangleRepair<MeshType>::Run is the step's one entry point, so that another repair (a bounded
// fill planning, a volumetric fallback for the regions it cannot repair) replaces only this header.
// It first repairs the faces of self-intersecting pairs (MeshQuality's definition), then, re-orienting
// after each repair, the faces on both sides of an orientation conflict: a tangle often also makes
// its component non-orientable, and the seams where the orientation traversal met itself are no
// defect once it is gone. A tangle (plus up to params.maxRepairGrowth rings around it) is removed
// and its hole refilled; the repair is kept only when every refill is valid, otherwise the faces are
// restored.
//
// Preconditions: fresh FF and VF adjacency, an edge-manifold mesh oriented by
// Orientation::OrientCoherently (whose conflicts are passed in). Leaves the adjacency fresh and the
// conflicts those of the last re-orientation. Deterministic for any run.params.threads.
#pragma once

#include <vcg/complex/complex.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <numeric>
#include <optional>
#include <unordered_map>
#include <utility>
#include <vector>

#include <vcg_ext/clean/clean_mesh_access.h>
#include <vcg_ext/clean/clean_params.h>
#include <vcg_ext/clean/orientation.h>
#include <vcg_ext/clean/region_refill.h>
#include <vcg_ext/core/index.h>
#include <vcg_ext/core/parallel_for.h>
#include <vcg_ext/geometry/point.h>
#include <vcg_ext/spatial/self_intersections.h>
#include <vcg_ext/spatial/static_face_grid.h>

namespace molremesh {
namespace clean {

/// What TangleRepair::Run did.
struct TangleRepairCounts {
  std::size_t repaired = 0;   ///< tangles removed and refilled
  std::size_t unrepaired = 0; ///< intersecting regions with no valid refill (left as they are)
  std::size_t facesRemoved = 0, facesAdded = 0; ///< faces removed and added by the repairs
};

template <class MeshType>
class TangleRepair {
public:
  using FaceGrid = StaticFaceGrid<MeshType>;
  using Conflicts = std::vector<std::pair<Index, Index>>;

  /// The step: intersecting faces first, then up to 16 rounds over the orientation conflicts that
  /// remain, re-orienting after each (see the file comment). `flipped` is Orientation's per-face
  /// record, grown to the faces added.
  static void Run(MeshType& m, CleanRunState& run, std::vector<std::uint8_t>& flipped,
                  Conflicts& orientationConflicts, TangleRepairCounts& r) {
    RepairPass(m, run, true, {}, r);
    flipped.resize(m.face.size(), 0);
    Orientation<MeshType>::OrientCoherently(m, flipped, orientationConflicts);
    for (int round = 0; round < 16 && !orientationConflicts.empty(); ++round) {
      if (!RepairPass(m, run, false, orientationConflicts, r)) break;
      flipped.resize(m.face.size(), 0);
      Orientation<MeshType>::OrientCoherently(m, flipped, orientationConflicts);
    }
  }

private:
  /// Repairs the regions of FindRegions, smallest first. For orientation conflicts, stops at the
  /// first repair: the caller re-orients, and the other conflicts were often only where the
  /// traversal met itself around that one defect. Returns whether anything was repaired.
  static bool RepairPass(MeshType& m, CleanRunState& run, bool intersections,
                         const Conflicts& orientationConflicts, TangleRepairCounts& r) {
    bool searched = true;
    const std::vector<std::vector<Index>> regions =
        FindRegions(m, run, intersections, orientationConflicts, searched);
    if (!searched) { // too tangled to look for the pairs: one tangle left, for the fallback
      ++r.unrepaired;
      return false;
    }
    std::size_t repaired = 0;
    // The repairs' face grid, built once there is something to repair (from the faces as they are
    // now: nothing above has edited them).
    std::optional<FaceGrid> grid;
    if (!regions.empty()) grid.emplace(m, 2.0 * run.meanEdge);
    for (const std::vector<Index>& region : regions) {
      // An earlier repair may have taken some of these faces with it (its grown rings).
      std::vector<Index> live;
      for (Index f : region)
        if (!m.face[f].IsD()) live.push_back(f);
      if (live.empty()) continue;
      if (RegionRefill<MeshType>::Repair(m, live, run, *grid, r.facesRemoved, r.facesAdded)) {
        ++r.repaired;
        ++repaired;
        if (!intersections) return true;
      } else if (intersections) {
        ++r.unrepaired;
      }
    }
    return repaired > 0;
  }

  /// Regions to repair: faces of intersecting pairs (when `intersections`) and faces on both sides
  /// of an orientation conflict, grouped through those pairs and through shared edges; smallest
  /// first, ties in the order of their smallest face. `searched` is false when the intersecting
  /// pairs were not searched: more candidate pairs than CandidatePairBound (a soup of
  /// overlapping polygons, far beyond local repair).
  static std::vector<std::vector<Index>> FindRegions(const MeshType& m, const CleanRunState& run,
                                                     bool intersections,
                                                     const Conflicts& orientationConflicts, bool& searched) {
    searched = true;
    const double meanEdge = run.meanEdge;
    const CleanRawMeshParams& params = run.params;
    // Intersecting pairs, grouped into regions (union-find over faces).
    std::vector<Index> parent(m.face.size());
    std::iota(parent.begin(), parent.end(), Index(0));
    auto find = [&parent](Index x) {
      while (parent[x] != x) x = parent[x] = parent[parent[x]];
      return x;
    };
    std::vector<std::uint8_t> involved(m.face.size(), 0);
    if (intersections) {
      // All pairs at once with MeshQuality's parallel broad phase and Conflict's predicates
      // (faces on the same three vertices intersect). Each region's root is its smallest face,
      // so the regions do not depend on the order the pairs come in.
      std::vector<Tri> tris;
      std::vector<Index> faceOf;
      for (Index f = 0; f < m.face.size(); ++f) {
        if (m.face[f].IsD()) continue;
        tris.push_back(FaceTri(m, m.face[f]));
        faceOf.push_back(f);
      }
      std::vector<Point> points(m.vert.size());
      for (Index v = 0; v < m.vert.size(); ++v) points[v] = PositionOf(&m.vert[v]);
      const SelfIntersectionSearch search = FindSelfIntersectionsWithin(
          tris, points, meanEdge, ResolveThreadCount(params.threads), CandidatePairBound(tris.size()), true);
      searched = search.searched;
      for (const IntersectingPair& pair : search.pairs) {
        const Index f = faceOf[pair.i], g = faceOf[pair.j];
        involved[f] = involved[g] = 1;
        const Index a = find(f), b = find(g);
        if (a != b) parent[std::max(a, b)] = std::min(a, b);
      }
    }
    for (const auto& [f, g] : orientationConflicts) {
      if (m.face[f].IsD() || m.face[g].IsD()) continue;
      involved[f] = involved[g] = 1;
      const Index a = find(f), b = find(g);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
    // Faces of one tangle that share an edge belong to the same region too.
    for (Index f = 0; f < m.face.size(); ++f) {
      if (!involved[f]) continue;
      for (int e = 0; e < 3; ++e) {
        const Index g = FI(m, m.face[f].cFFp(e));
        if (involved[g]) {
          const Index a = find(f), b = find(g);
          if (a != b) parent[std::max(a, b)] = std::min(a, b);
        }
      }
    }
    // Regions in the order of their root (smallest face), then stably by size.
    std::unordered_map<Index, std::size_t> slot;
    std::vector<std::vector<Index>> regions;
    for (Index f = 0; f < m.face.size(); ++f)
      if (involved[f]) {
        const Index root = find(f);
        const auto it = slot.emplace(root, regions.size()).first;
        if (it->second == regions.size()) regions.emplace_back();
        regions[it->second].push_back(f);
      }
    std::stable_sort(
        regions.begin(), regions.end(),
        [](const std::vector<Index>& a, const std::vector<Index>& b) { return a.size() < b.size(); });
    return regions;
  }
};

} // namespace clean
} // namespace molremesh

// Random segmentation of a triangle mesh into patches (stage 3 of Khan et al. 2020).
//
// Patches are grown from randomly chosen seed faces by a breadth-first front over shared edges,
// one ring per seed in turn, so patches come out of similar size and compact. The edges between
// two patches form the locked borders of patch-wise remeshing. Every component gets at least one
// patch (a component with no seed is seeded too), so no face is left unassigned. The choice of
// seeds depends only on Params::seed: same mesh + seed -> same segmentation.
#pragma once

#include <vcg/complex/complex.h>

#include <algorithm>
#include <cstdint>
#include <deque>
#include <random>
#include <string>
#include <vector>

namespace molremesh {

struct SegmentationResult {
  bool ok = true;
  std::string message;
  std::vector<int> facePatch;     ///< patch id of every face (indexed like m.face); -1 for deleted faces
  int patchCount = 0;             ///< number of patches made
  std::size_t borderEdges = 0;    ///< edges whose two faces lie in different patches
  std::size_t borderVertices = 0; ///< vertices on such an edge
};

template <class MeshType>
class RandomSegmentation {
public:
  using FaceType = typename MeshType::FaceType;

  struct Params {
    int patchCount = 0;           ///< patches wanted; 0 = automatic (DefaultPatchCount)
    std::uint64_t seed = 1;       ///< random seed: same mesh + seed -> same patches
    int facesPerPatchAuto = 4000; ///< automatic count: one patch per this many faces ...
    int maxAutoPatches = 256;     ///< ... at most this many
  };

  /// The automatic patch count: enough patches to feed every core on large meshes, one on small ones.
  static int DefaultPatchCount(const MeshType& m, const Params& params) {
    const int byFaces = int(m.fn / std::max(1, params.facesPerPatchAuto));
    return std::clamp(byFaces, 1, std::max(1, params.maxAutoPatches));
  }

  /// Computes the segmentation. Requires face-face adjacency (vcg::tri::UpdateTopology::FaceFace);
  /// the mesh is not modified.
  static SegmentationResult Do(const MeshType& m, const Params& params = Params()) {
    SegmentationResult result;
    if (m.fn == 0) {
      result.ok = false;
      result.message = "the mesh has no faces";
      return result;
    }
    const int wanted =
        params.patchCount > 0 ? std::min(params.patchCount, m.fn) : DefaultPatchCount(m, params);
    const std::size_t faceCount = m.face.size();
    std::vector<int>& patch = result.facePatch;
    patch.assign(faceCount, -1);

    // Live faces in index order, shuffled with the seeded engine: the first `wanted` are the seeds.
    std::vector<std::size_t> live;
    live.reserve(m.fn);
    for (std::size_t i = 0; i < faceCount; ++i)
      if (!m.face[i].IsD()) live.push_back(i);
    std::mt19937_64 engine(params.seed);
    for (std::size_t i = live.size(); i > 1;
         --i) { // Fisher-Yates with our own draw: portable across libstdc++ versions
      const std::size_t j = std::size_t(engine() % i);
      std::swap(live[i - 1], live[j]);
    }

    std::vector<std::deque<std::size_t>> fronts;
    auto addSeed = [&](std::size_t face) {
      patch[face] = int(fronts.size());
      fronts.emplace_back(1, face);
    };
    for (int s = 0; s < wanted; ++s) addSeed(live[std::size_t(s)]);

    auto growAll = [&]() {
      bool grew = true;
      while (grew) {
        grew = false;
        for (std::size_t p = 0; p < fronts.size(); ++p) {
          // Advance this patch by one breadth-first ring.
          std::size_t ringSize = fronts[p].size();
          while (ringSize-- > 0) {
            const std::size_t fi = fronts[p].front();
            fronts[p].pop_front();
            const FaceType& f = m.face[fi];
            for (int e = 0; e < 3; ++e) {
              const FaceType* g = f.cFFp(e);
              if (g == nullptr || g == &f || g->IsD()) continue;
              const std::size_t gi = vcg::tri::Index(m, g);
              if (patch[gi] != -1) continue;
              patch[gi] = int(p);
              fronts[p].push_back(gi);
              grew = true;
            }
          }
        }
      }
    };
    growAll();
    // Components that received no seed: seed them in index order and grow again.
    for (std::size_t fi : live) {
      if (patch[fi] != -1) continue;
      addSeed(fi);
      growAll();
    }
    result.patchCount = int(fronts.size());

    std::vector<bool> borderVertex(m.vert.size(), false);
    for (std::size_t fi = 0; fi < faceCount; ++fi) {
      const FaceType& f = m.face[fi];
      if (f.IsD()) continue;
      for (int e = 0; e < 3; ++e) {
        const FaceType* g = f.cFFp(e);
        if (g == nullptr || g == &f) continue;
        const std::size_t gi = vcg::tri::Index(m, g);
        if (patch[gi] == patch[fi]) continue;
        if (fi < gi) ++result.borderEdges;
        borderVertex[vcg::tri::Index(m, f.cV0(e))] = true;
        borderVertex[vcg::tri::Index(m, f.cV1(e))] = true;
      }
    }
    result.borderVertices = std::size_t(std::count(borderVertex.begin(), borderVertex.end(), true));
    return result;
  }

  /// Writes a distinct color per patch into the per-face color (must be enabled).
  static void ColorPatches(MeshType& m, const SegmentationResult& segmentation) {
    vcg::tri::RequirePerFaceColor(m);
    const int n = std::max(1, segmentation.patchCount);
    for (std::size_t fi = 0; fi < m.face.size(); ++fi) {
      if (m.face[fi].IsD() || segmentation.facePatch[fi] < 0) continue;
      // Scatter spreads hues so neighbouring ids get distinguishable colors.
      m.face[fi].C() = vcg::Color4b::Scatter(n, segmentation.facePatch[fi]);
    }
  }
};

} // namespace molremesh

// Face-face adjacency in linear time.
//
// vcg::tri::UpdateTopology::FaceFace sorts one record per face side (1.5 M of them on a 500k-face
// mesh) with a general comparison sort; the pipeline rebuilds the adjacency before every stage
// and every local stage does it again in LocalRemeshingOps::PrepareTopology, and these sorts
// added up to about 3 s of a 4JSV run. UpdateFaceFaceTopology builds the same relation with a
// counting sort of the sides by their smaller vertex index, so only the few sides at one vertex
// are ever compared.
//
// The result follows vcglib's convention: the sides sharing one (unordered) vertex pair form a
// cycle through FFp/FFi (two faces point at each other, a border side points at its own face
// and side, three or more faces of a non-manifold edge form a ring, in ascending face order
// here). Deleted faces are skipped and keep their old pointers, as in vcglib.
#pragma once

#include <vcg/complex/complex.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace molremesh {

template <class MeshType>
void UpdateFaceFaceTopology(MeshType& m) {
  const std::size_t nv = m.vert.size();
  if (nv == 0 || m.face.empty()) return;
  const auto* vertBegin = &m.vert[0];
  auto index = [&](const typename MeshType::FaceType& f, int k) {
    return std::uint32_t(f.cV(k) - vertBegin);
  };

  struct Side {
    std::uint32_t other; ///< the larger vertex index of the side
    std::uint32_t face;
    int z; ///< side number in its face
    bool operator<(const Side& o) const {
      return other != o.other ? other < o.other : (face != o.face ? face < o.face : z < o.z);
    }
  };
  std::vector<std::uint32_t> start(nv + 1, 0);
  for (const auto& f : m.face) {
    if (f.IsD()) continue;
    for (int z = 0; z < 3; ++z) ++start[std::min(index(f, z), index(f, (z + 1) % 3)) + 1];
  }
  for (std::size_t v = 0; v < nv; ++v) start[v + 1] += start[v];
  std::vector<Side> sides(start[nv]);
  {
    std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
    for (std::size_t fi = 0; fi < m.face.size(); ++fi) {
      const auto& f = m.face[fi];
      if (f.IsD()) continue;
      for (int z = 0; z < 3; ++z) {
        const std::uint32_t a = index(f, z), b = index(f, (z + 1) % 3);
        sides[fill[std::min(a, b)]++] = {std::max(a, b), std::uint32_t(fi), z};
      }
    }
  }
  for (std::size_t v = 0; v < nv; ++v) {
    const auto begin = sides.begin() + start[v], end = sides.begin() + start[v + 1];
    std::sort(begin, end);
    for (auto group = begin; group != end;) {
      auto next = group;
      while (next != end && next->other == group->other) ++next;
      // Each side points at the next one of its group, the last back at the first.
      for (auto it = group; it != next; ++it) {
        const auto to = (it + 1 == next) ? group : it + 1;
        auto& f = m.face[it->face];
        f.FFp(it->z) = &m.face[to->face];
        f.FFi(it->z) = to->z;
      }
      group = next;
    }
  }
}

} // namespace molremesh

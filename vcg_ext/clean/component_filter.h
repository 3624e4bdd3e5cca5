// Cleaning step: the component policy (vcg_ext/clean/), which connected components of the surface
// are kept. Today: every component with fewer than a fraction of the faces is removed, except the
// largest one.
//
// This is the one entry point of the policy, so that another policy (keeping cavities, say) replaces
// only this header's function. Needs fresh FF adjacency; leaves FF and VF adjacency fresh.
#pragma once

#include <vcg/complex/complex.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <vcg_ext/clean/clean_mesh_access.h>
#include <vcg_ext/core/index.h>

namespace molremesh {
namespace clean {

/// What RemoveSmallComponents did.
struct ComponentFilterCounts {
  std::size_t removedComponents = 0; ///< components below the fraction
  std::size_t removedFaces = 0;      ///< their faces
};

/// Deletes the faces of every component (through shared edges) with fewer than fraction * m.fn
/// faces, never the largest one (the first of the largest in face order).
template <class MeshType>
void RemoveSmallComponents(MeshType& m, double fraction, ComponentFilterCounts& r) {
  std::vector<Index> label;
  std::vector<std::size_t> size;
  const std::size_t count = LabelComponents(m, label, size);
  if (count < 2) return;
  const std::size_t largest = std::size_t(std::max_element(size.begin(), size.end()) - size.begin());
  const double limit = fraction * double(m.fn);
  std::vector<std::uint8_t> remove(count, 0);
  for (std::size_t c = 0; c < count; ++c)
    if (c != largest && double(size[c]) < limit) {
      remove[c] = 1;
      ++r.removedComponents;
      r.removedFaces += size[c];
    }
  if (r.removedComponents == 0) return;
  for (Index f = 0; f < m.face.size(); ++f)
    if (!m.face[f].IsD() && remove[label[f]]) DeleteFace(m, f);
  RebuildTopology(m);
}

} // namespace clean
} // namespace molremesh

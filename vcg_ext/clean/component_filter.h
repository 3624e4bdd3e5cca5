// Cleaning step: the component policy (vcg_ext/clean/), which connected components of the surface
// are kept. Every component that encloses a volume stays by default: the outer surface, the
// cavities (buried voids of a molecular surface) and separate parts. Removed by default are only
// pieces that enclose no volume: fewer than 4 faces, or an enclosed volume of at most
// params.flatComponentVolume * (mean edge length)^3 (a few flat faces, a crack's slivers). Removing
// small components that do enclose a volume is explicit: params.minComponentVolume (cubic units of the
// mesh, A^3 for a molecular surface), params.minComponentFaces and params.minComponentFraction (of all
// faces). The largest component is never removed.
//
// The enclosed volume of a component is the absolute signed volume of its faces about its centroid
// (exact for a closed component, whatever its orientation; for an open one, the volume of the cone
// its faces span from there, zero for a flat piece). Needs fresh FF adjacency; leaves FF and VF
// adjacency fresh.
#pragma once

#include <vcg/complex/complex.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <vcg_ext/clean/clean_mesh_access.h>
#include <vcg_ext/clean/clean_params.h>
#include <vcg_ext/clean/clean_result.h>
#include <vcg_ext/core/index.h>
#include <vcg_ext/geometry/point.h>

namespace molremesh {
namespace clean {

/// What RemoveSmallComponents did.
struct ComponentFilterCounts {
  std::size_t removedComponents = 0;        ///< components removed by the policy
  std::size_t removedFaces = 0;             ///< their faces
  std::vector<CleanComponent> removed = {}; ///< each of them, in the order of its first face
};

/// One record per component of `label` (LabelComponents): faces, signed volume about its centroid
/// (positive when outward), closed or not. Needs fresh FF adjacency.
template <class MeshType>
std::vector<CleanComponent> DescribeComponents(const MeshType& m, const std::vector<Index>& label,
                                               std::size_t count) {
  std::vector<CleanComponent> c(count);
  std::vector<Point> centroid(count, Point(0, 0, 0));
  for (Index f = 0; f < m.face.size(); ++f) {
    if (m.face[f].IsD()) continue;
    CleanComponent& k = c[label[f]];
    ++k.faces;
    for (int e = 0; e < 3; ++e) {
      centroid[label[f]] += PositionOf(&m.vert[VI(m, m.face[f], e)]);
      if (IsBorderEdge(m.face[f], e)) k.closed = false;
    }
  }
  for (std::size_t i = 0; i < count; ++i)
    if (c[i].faces > 0) centroid[i] /= double(3 * c[i].faces);
  for (Index f = 0; f < m.face.size(); ++f) {
    if (m.face[f].IsD()) continue;
    const Tri t = FaceTri(m, m.face[f]);
    const Point o = centroid[label[f]];
    c[label[f]].volume += (PositionOf(&m.vert[t[0]]) - o) *
                          ((PositionOf(&m.vert[t[1]]) - o) ^ (PositionOf(&m.vert[t[2]]) - o)) / 6.0;
  }
  return c;
}

/// Why the policy removes component `c` (nullptr: it stays). `meanEdge` is the input's mean edge
/// length, `faces` the mesh's face count.
inline const char* ComponentRemovalReason(const CleanComponent& c, const CleanRawMeshParams& params,
                                          double meanEdge, std::size_t faces) {
  const double volume = std::fabs(c.volume);
  if (params.flatComponentVolume >= 0 &&
      (c.faces < 4 || volume <= params.flatComponentVolume * meanEdge * meanEdge * meanEdge))
    return "encloses no volume";
  if (volume < params.minComponentVolume) return "below minComponentVolume";
  if (int(c.faces) < params.minComponentFaces) return "below minComponentFaces";
  if (double(c.faces) < params.minComponentFraction * double(faces)) return "below minComponentFraction";
  return nullptr;
}

/// Deletes the faces of every component (through shared edges) the policy removes (see the file
/// comment), never the largest one (the first of the largest in face order).
template <class MeshType>
void RemoveSmallComponents(MeshType& m, const CleanRawMeshParams& params, double meanEdge,
                           ComponentFilterCounts& r) {
  std::vector<Index> label;
  std::vector<std::size_t> size;
  const std::size_t count = LabelComponents(m, label, size);
  if (count < 2) return;
  const std::size_t largest = std::size_t(std::max_element(size.begin(), size.end()) - size.begin());
  std::vector<CleanComponent> components = DescribeComponents(m, label, count);
  std::vector<std::uint8_t> remove(count, 0);
  for (std::size_t c = 0; c < count; ++c) {
    const char* reason = ComponentRemovalReason(components[c], params, meanEdge, std::size_t(m.fn));
    if (c == largest || reason == nullptr) continue;
    remove[c] = 1;
    components[c].reason = reason;
    r.removed.push_back(components[c]);
    ++r.removedComponents;
    r.removedFaces += size[c];
  }
  if (r.removedComponents == 0) return;
  for (Index f = 0; f < m.face.size(); ++f)
    if (!m.face[f].IsD() && remove[label[f]]) DeleteFace(m, f);
  RebuildTopology(m);
}

/// The components of the cleaned mesh, largest first (ties in the order of their first face).
template <class MeshType>
std::vector<CleanComponent> KeptComponents(const MeshType& m) {
  std::vector<Index> label;
  std::vector<std::size_t> size;
  const std::size_t count = LabelComponents(m, label, size);
  std::vector<CleanComponent> c = DescribeComponents(m, label, count);
  std::stable_sort(c.begin(), c.end(),
                   [](const CleanComponent& a, const CleanComponent& b) { return a.faces > b.faces; });
  return c;
}

} // namespace clean
} // namespace molremesh

// A vcg triangle mesh as OpenVDB's indexed polygons and back: the one place where vcg_ext's mesh
// types meet OpenVDB's (points as Vec3s, triangles as Vec3I, quads as Vec4I).
//
// OpenVDB's mesher (tools::volumeToMesh) returns quads and triangles over shared points. A quad is
// split along its shorter diagonal: of the two splits, that one has the larger smallest angle on
// the near-planar quads of a level set, and never the longer, near-degenerate diagonal of a thin
// quad. The split keeps the quad's winding, so both triangles face the same side. OpenVDB winds its
// polygons clockwise seen from the positive (outside) side of the level set; AppendVdbPolygons
// reverses them, so the mesh's normals point outward (towards positive values). Coordinates are
// floats on OpenVDB's side: ample for molecules (1e-7 relative, 1e-5 A on a 100 A protein).
#pragma once

#include <vcg/complex/algorithms/clean.h>
#include <vcg/complex/complex.h>

#include <vcg_ext/core/index.h>
#include <vcg_ext/geometry/point.h>

#include <openvdb/openvdb.h>

#include <cstddef>
#include <vector>

namespace molremesh {

/// Indexed polygons on OpenVDB's side.
struct VdbPolygons {
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> triangles;
  std::vector<openvdb::Vec4I> quads;
};

/// The live faces of m over its referenced vertices (deleted faces and vertices skipped; a
/// vertex only a deleted face uses is left out), in face order.
template <class MeshType>
VdbPolygons ToVdbPolygons(const MeshType& m) {
  VdbPolygons out;
  std::vector<Index> slot(m.vert.size(), kNoIndex);
  out.triangles.reserve(std::size_t(m.fn));
  for (const auto& f : m.face) {
    if (f.IsD()) continue;
    openvdb::Vec3I t;
    for (int k = 0; k < 3; ++k) {
      const std::size_t v = std::size_t(vcg::tri::Index(m, f.cV(k)));
      if (slot[v] == kNoIndex) {
        slot[v] = Index(out.points.size());
        const Point p = PositionOf(f.cV(k));
        out.points.emplace_back(float(p[0]), float(p[1]), float(p[2]));
      }
      t[k] = slot[v];
    }
    out.triangles.push_back(t);
  }
  return out;
}

namespace volume_detail {

inline float SquaredDistance(const openvdb::Vec3s& a, const openvdb::Vec3s& b) {
  return (a - b).lengthSqr();
}

/// The two triangles of quad q, split along its shorter diagonal, with q's winding.
inline void SplitQuad(const openvdb::Vec4I& q, const std::vector<openvdb::Vec3s>& points,
                      std::vector<openvdb::Vec3I>& triangles) {
  if (SquaredDistance(points[q[0]], points[q[2]]) <= SquaredDistance(points[q[1]], points[q[3]])) {
    triangles.emplace_back(q[0], q[1], q[2]);
    triangles.emplace_back(q[0], q[2], q[3]);
  } else {
    triangles.emplace_back(q[0], q[1], q[3]);
    triangles.emplace_back(q[1], q[2], q[3]);
  }
}

} // namespace volume_detail

/// The triangles of polygons: its triangles, then each quad split along its shorter diagonal.
inline std::vector<openvdb::Vec3I> TrianglesOf(const VdbPolygons& polygons) {
  std::vector<openvdb::Vec3I> triangles = polygons.triangles;
  triangles.reserve(polygons.triangles.size() + 2 * polygons.quads.size());
  for (const openvdb::Vec4I& q : polygons.quads) volume_detail::SplitQuad(q, polygons.points, triangles);
  return triangles;
}

/// Replaces m's content by the polygons of OpenVDB's mesher as triangles facing the positive side
/// of the level set (TrianglesOf, winding reversed). Points no polygon uses are not added; points
/// the mesher made twice at one position are merged (welded), and a triangle that merging
/// collapses is dropped. Returns the number of faces of m (m is compacted).
template <class MeshType>
std::size_t VdbPolygonsToMesh(const VdbPolygons& polygons, MeshType& m) {
  m.Clear();
  using CoordType = typename MeshType::CoordType;
  using ScalarType = typename MeshType::ScalarType;
  const std::vector<openvdb::Vec3I> triangles = TrianglesOf(polygons);
  std::vector<Index> slot(polygons.points.size(), kNoIndex);
  std::size_t used = 0;
  for (const openvdb::Vec3I& t : triangles)
    for (int k = 0; k < 3; ++k)
      if (slot[t[k]] == kNoIndex) slot[t[k]] = Index(used++);
  const std::size_t firstVertex = 0;
  vcg::tri::Allocator<MeshType>::AddVertices(m, used);
  for (std::size_t p = 0; p < polygons.points.size(); ++p) {
    if (slot[p] == kNoIndex) continue;
    const openvdb::Vec3s& q = polygons.points[p];
    m.vert[firstVertex + slot[p]].P() = CoordType(ScalarType(q[0]), ScalarType(q[1]), ScalarType(q[2]));
  }
  const std::size_t firstFace = 0;
  vcg::tri::Allocator<MeshType>::AddFaces(m, triangles.size());
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    auto& f = m.face[firstFace + i];
    const openvdb::Vec3I& t = triangles[i];
    f.V(0) = &m.vert[firstVertex + slot[t[0]]];
    f.V(1) = &m.vert[firstVertex + slot[t[2]]]; // reversed: outward normals
    f.V(2) = &m.vert[firstVertex + slot[t[1]]];
  }
  vcg::tri::Clean<MeshType>::RemoveDuplicateVertex(m);
  vcg::tri::Clean<MeshType>::RemoveDegenerateFace(m);
  vcg::tri::Clean<MeshType>::RemoveUnreferencedVertex(m);
  vcg::tri::Allocator<MeshType>::CompactEveryVector(m);
  return std::size_t(m.fn);
}

} // namespace molremesh

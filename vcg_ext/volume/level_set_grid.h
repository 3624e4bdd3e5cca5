// Level-set grids of meshes with OpenVDB: the grid-building helpers of the volumetric rebuild and
// of surfaces built from atoms. Distances are in world units (A); a level set is negative inside,
// positive outside, with a narrow band of halfWidth voxels on each side of the zero crossing.
#pragma once

#include <vcg_ext/volume/openvdb_mesh_adapter.h>

#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tools/VolumeToMesh.h>

#include <cmath>
#include <cstddef>
#include <vector>

namespace molremesh {

/// OpenVDB's one-time registration of its grid types; cheap and safe to call again.
inline void InitializeOpenVdb() {
  openvdb::initialize();
}

/// The transform of a grid of cubic voxels of edge voxelSize (> 0), voxel centers at integer
/// multiples of voxelSize.
inline openvdb::math::Transform::Ptr VoxelTransform(double voxelSize) {
  return openvdb::math::Transform::createLinearTransform(voxelSize);
}

/// Unsigned distance to the polygons within bandVoxels voxels of them (background: the band's
/// width in world units). Needs no closed or oriented input.
inline openvdb::FloatGrid::Ptr UnsignedDistanceGrid(const VdbPolygons& polygons, double voxelSize,
                                                    float bandVoxels) {
  InitializeOpenVdb();
  return openvdb::tools::meshToUnsignedDistanceField<openvdb::FloatGrid>(
      *VoxelTransform(voxelSize), polygons.points, polygons.triangles, polygons.quads, bandVoxels);
}

/// The distance to the polygons within outsideVoxels of them on the side OpenVDB's flood fill from
/// the grid's outside reaches and within insideVoxels on the other (a cavity counts as inside), signed
/// by that flood fill (callers that keep cavities sign it themselves). The values are OpenVDB's
/// point-to-polygon distances, as UnsignedDistanceGrid's (no renormalization, no removal of voxels
/// near crossing polygons), but a band needed on one side only costs that side: the rebuilt SAS
/// needs the probe's depth inside and nothing outside.
inline openvdb::FloatGrid::Ptr TwoSidedDistanceGrid(const VdbPolygons& polygons, double voxelSize,
                                                    float outsideVoxels, float insideVoxels) {
  InitializeOpenVdb();
  const openvdb::math::Transform::Ptr xform = VoxelTransform(voxelSize);
  std::vector<openvdb::Vec3s> points(polygons.points.size()); // in index space, as OpenVDB's own calls
  for (std::size_t i = 0; i < points.size(); ++i) points[i] = xform->worldToIndex(polygons.points[i]);
  std::vector<openvdb::Vec4I> primitives;
  primitives.reserve(polygons.triangles.size() + polygons.quads.size());
  for (const openvdb::Vec3I& t : polygons.triangles)
    primitives.emplace_back(t[0], t[1], t[2], openvdb::util::INVALID_IDX);
  primitives.insert(primitives.end(), polygons.quads.begin(), polygons.quads.end());
  const openvdb::tools::QuadAndTriangleDataAdapter<openvdb::Vec3s, openvdb::Vec4I> mesh(points, primitives);
  const int flags =
      openvdb::tools::DISABLE_INTERSECTING_VOXEL_REMOVAL | openvdb::tools::DISABLE_RENORMALIZATION;
  return openvdb::tools::meshToVolume<openvdb::FloatGrid>(mesh, *xform, outsideVoxels, insideVoxels, flags);
}

/// OpenVDB's signed narrow-band level set of the polygons: the sign by flood fill from outside,
/// so everything the outside cannot reach is inside; a cavity (a closed inner surface) is filled.
/// For a closed input whose cavities do not matter, or for building shapes; VolumetricRebuild
/// decides the sign itself to keep cavities.
inline openvdb::FloatGrid::Ptr FloodFilledLevelSet(const VdbPolygons& polygons, double voxelSize,
                                                   float halfWidthVoxels = 3.0f) {
  InitializeOpenVdb();
  return openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(
      *VoxelTransform(voxelSize), polygons.points, polygons.triangles, polygons.quads, halfWidthVoxels);
}

/// The isosurface of a level set as a triangle mesh with outward normals (towards values above
/// isovalue), replacing m's content; adaptivity 0 keeps one vertex per crossed voxel (OpenVDB's
/// volumeToMesh, quads split by VdbPolygonsToMesh). Returns the face count.
template <class MeshType>
std::size_t LevelSetToMesh(const openvdb::FloatGrid& grid, MeshType& m, double isovalue = 0.0,
                           double adaptivity = 0.0) {
  VdbPolygons polygons;
  openvdb::tools::volumeToMesh(grid, polygons.points, polygons.triangles, polygons.quads, isovalue,
                               adaptivity);
  return VdbPolygonsToMesh(polygons, m);
}

/// Voxels of the narrow band of halfWidthVoxels on each side of a surface of the given area:
/// the band is 2 halfWidth + 1 voxels thick.
inline double NarrowBandVoxels(double area, double voxelSize, double halfWidthVoxels) {
  if (!(voxelSize > 0) || !(area > 0)) return 0;
  return area / (voxelSize * voxelSize) * (2.0 * halfWidthVoxels + 1.0);
}

/// An upper estimate of the bytes of a sparse float grid with that many active voxels: OpenVDB's
/// 8^3 leaf nodes hold 4 bytes a voxel, active or not, and a curved band of 7 voxels fills about a
/// sixth of the leaves it crosses (27 bytes per band voxel on a sphere of 80 voxels); each of the
/// tree's top nodes (4096^3 voxels, up to 8 where a mesh spans the origin) costs about 0.5 MB.
inline double SparseGridBytes(double activeVoxels) {
  return 4.0 * 1024 * 1024 + activeVoxels * 32.0;
}

} // namespace molremesh

// Volumetric rebuild: a broken surface replaced by the boundary of the union of the regions it
// encloses, as a closed, outward-oriented, 2-manifold, self-intersection-free triangle mesh.
//
// For the surfaces the local clean-up cannot repair: triangle soups, interpenetrating or
// overlapping sheets, non-manifold edges, inconsistent or inward orientation, small open cracks.
// Cavities (closed inner sheets that bound a void) and separate parts are kept.
//
//   h   = voxel size (Params::voxelSize, or voxelFraction x the input's mean edge length)
//   udf = unsigned distance to the input's triangles in a narrow band (OpenVDB)
//   free space = voxels farther than the crack threshold from every triangle; its 6-connected
//         regions (cracks narrower than crackWidthVoxels do not connect two regions)
//   per region not touching the box's border: the generalized winding number w of the input at
//         its deepest voxel; the input's orientation sign s = sign(sum of w x region size)
//   region inside  <=>  s w > insideWinding  (a cavity has w ~ 0, overlapping bodies w >= 1)
//   the shell near the triangles joins the regions by a watershed of udf (they meet on the input)
//   a shell voxel of an outside region whose two neighbours along some axis are inside becomes
//         inside (Params::sealSlits): a slit of the outside thinner than a voxel is closed
//   phi = -udf inside, +udf outside; mesh = OpenVDB's mesher of phi = 0
//
// OpenVDB's own mesh-to-level-set conversion decides the sign by flood fill from outside, which
// fills every cavity (no path leads into it from outside); the winding number tells a cavity from a
// body by the orientation of the sheets around it, and counts overlapping bodies once.
//
// The run is refused, the mesh untouched and the reason in Result::message, when the input is
// empty or has no area, when its estimated memory exceeds the limit, when it encloses nothing,
// or when the mesher's output fails the validity checks. Deterministic: the labels and winding
// numbers do not depend on the thread count.
#pragma once

#include <vcg_ext/core/input_check.h>
#include <vcg_ext/geometry/mean_edge_length.h>
#include <vcg_ext/core/available_memory.h>
#include <vcg_ext/quality/mesh_quality.h>
#include <vcg_ext/volume/closed_components.h>
#include <vcg_ext/volume/level_set_grid.h>
#include <vcg_ext/volume/voxel_regions.h>
#include <vcg_ext/volume/winding_number.h>

#include <vcg/complex/append.h>

#include <openvdb/tools/SignedFloodFill.h>

#include <cmath>
#include <cstddef>
#include <sstream>
#include <string>
#include <vector>

namespace molremesh {

template <class MeshType>
class VolumetricRebuild {
public:
  struct Params {
    double voxelSize = 0;          ///< voxel edge (mesh units); 0 = voxelFraction x mean edge length
    double voxelFraction = 0.5;    ///< of the input's mean edge length, when voxelSize is 0
    double crackWidthVoxels = 2.0; ///< openings narrower than this many voxels are sealed
    double insideWinding = 0.5;    ///< a region is inside when its winding number exceeds it
    /// Close slits of the outside thinner than a voxel between two inside voxels. Such a slit
    /// (marching-cubes Gaussian surfaces of complexes have them, 0.1 A wide) keeps two sheets
    /// facing each other closer than any remesh at the target edge length can keep apart within
    /// the angle bounds, and no probe fits in it. Where a sealed slit was the only way into a
    /// pocket, the pocket stays outside the volume: a cavity.
    bool sealSlits = true;
    double memoryLimitMB = 0; ///< 0 = the memory available now; < 0 = no check
    int threads = 0;          ///< for the winding numbers and the checks; 0 = all cores
  };

  struct Result {
    bool ok = false;
    std::string message; ///< why the run was refused (empty when ok)
    std::size_t facesIn = 0, facesOut = 0;
    double volumeIn = 0, volumeOut = 0; ///< signed enclosed volumes (the input's as given)
    double areaIn = 0, areaOut = 0;
    double voxelSize = 0;
    std::size_t voxels = 0;  ///< of the dense box around the input
    double estimatedMB = 0;  ///< the memory estimate the limit was checked against
    std::size_t regions = 0; ///< free-space regions, inside ones
    std::size_t insideRegions = 0;
    std::size_t sealedSlitVoxels = 0; ///< outside shell voxels made inside (Params::sealSlits)
    int orientationSign = 0;          ///< +1: the input's sheets face outward; -1: inward
    std::size_t bodies = 0;           ///< closed components of the output bounding a body
    std::size_t cavities = 0;         ///< and bounding a cavity (normals into the void)
  };

  /// Replaces m by the rebuilt surface (see the top of the file); m's deleted elements are skipped.
  static Result Do(MeshType& m, const Params& params = Params());

private:
  struct Input {
    VdbPolygons polygons;  // what OpenVDB reads (float)
    TriangleSet triangles; // what the winding numbers read (double)
  };
  static Input ReadInput(const MeshType& m);
  static VoxelBox BoxAround(const VdbPolygons& polygons, double h, int pad);
  static double EstimateBytes(const VoxelBox& box, double area, double h, double bandVoxels,
                              std::size_t facesIn);
  static std::vector<char> InsideRegions(const VoxelRegions& regions, const Input& input, double h,
                                         const Params& params, Result& result);
  static openvdb::FloatGrid::Ptr SignedGrid(const openvdb::FloatGrid& udf, const VoxelRegions& regions,
                                            const std::vector<char>& inside, double h, const Params& params,
                                            Result& result);
  static std::string Validate(const MeshType& out, const Params& params, Result& result);
};

// ------------------------------------------------------------------------------------------------
// Implementation
// ------------------------------------------------------------------------------------------------

template <class MeshType>
typename VolumetricRebuild<MeshType>::Result VolumetricRebuild<MeshType>::Do(MeshType& m,
                                                                             const Params& params) {
  Result result;
  const InputCheck check = CheckTriangleMeshInput(m);
  if (!check.ok) return result.message = check.message, result;
  typename MeshQuality<MeshType>::Params measure;
  measure.computeSelfIntersections = false;
  const QualityReport in = MeshQuality<MeshType>::Compute(m, measure);
  result.facesIn = in.faces, result.volumeIn = in.volume, result.areaIn = in.area;
  const double mean = MeanEdgeLength(m, true);
  const double h = params.voxelSize > 0 ? params.voxelSize : params.voxelFraction * mean;
  result.voxelSize = h;
  if (!(in.area > 0) || !(h > 0) || !std::isfinite(h))
    return result.message = "the surface has no area (or no valid voxel size): nothing to rebuild", result;

  const double threshold = (0.56 * params.crackWidthVoxels + 0.1) * h;
  const double bandVoxels = std::ceil(threshold / h) + 2.0;
  Input input = ReadInput(m);
  const VoxelBox box = BoxAround(input.polygons, h, int(bandVoxels) + 2);
  result.voxels = box.Size();
  const double bytes = EstimateBytes(box, in.area, h, bandVoxels, in.faces);
  result.estimatedMB = bytes / (1024.0 * 1024.0);
  const double limit = params.memoryLimitMB > 0    ? params.memoryLimitMB * 1024.0 * 1024.0
                       : params.memoryLimitMB == 0 ? AvailableMemoryBytes()
                                                   : -1.0;
  if ((limit > 0 && bytes > limit) || box.Size() >= (std::size_t(1) << 32)) {
    std::ostringstream s;
    s << "the volumetric rebuild at voxel size " << h << " would need about "
      << std::round(result.estimatedMB) << " MB (" << box.Size()
      << " voxels around the input), more than the " << std::round(limit / (1024.0 * 1024.0))
      << " MB limit; a larger voxel size needs less (the "
      << "memory falls with its cube)";
    return result.message = s.str(), result;
  }

  const openvdb::FloatGrid::Ptr udf = UnsignedDistanceGrid(input.polygons, h, float(bandVoxels));
  VoxelRegions regions = LabelFreeSpace(*udf, box, float(threshold));
  const std::vector<char> inside = InsideRegions(regions, input, h, params, result);
  if (result.insideRegions == 0)
    return result.message = "the surface encloses no volume at voxel size " + std::to_string(h), result;
  FloodShell(*udf, regions);
  const openvdb::FloatGrid::Ptr phi = SignedGrid(*udf, regions, inside, h, params, result);
  regions = VoxelRegions();
  MeshType out;
  LevelSetToMesh(*phi, out);
  const std::string invalid = Validate(out, params, result);
  if (!invalid.empty()) return result.message = "the rebuilt surface is not valid: " + invalid, result;
  m.Clear();
  vcg::tri::Append<MeshType, MeshType>::MeshCopy(m, out);
  result.ok = true;
  return result;
}

template <class MeshType>
typename VolumetricRebuild<MeshType>::Input VolumetricRebuild<MeshType>::ReadInput(const MeshType& m) {
  Input input;
  input.polygons = ToVdbPolygons(m);
  std::vector<std::size_t> slot(m.vert.size(), std::size_t(-1));
  for (const auto& f : m.face) {
    if (f.IsD()) continue;
    std::array<std::size_t, 3> t;
    for (int k = 0; k < 3; ++k) {
      const std::size_t v = std::size_t(vcg::tri::Index(m, f.cV(k)));
      if (slot[v] == std::size_t(-1))
        slot[v] = input.triangles.points.size(), input.triangles.points.push_back(PositionOf(f.cV(k)));
      t[k] = slot[v];
    }
    input.triangles.triangles.push_back(t);
  }
  return input;
}

template <class MeshType>
VoxelBox VolumetricRebuild<MeshType>::BoxAround(const VdbPolygons& polygons, double h, int pad) {
  openvdb::math::Vec3d lo(polygons.points[0]), hi(polygons.points[0]);
  for (const openvdb::Vec3s& p : polygons.points)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], double(p[k])), hi[k] = std::max(hi[k], double(p[k]));
  VoxelBox box;
  for (int k = 0; k < 3; ++k) {
    box.min[k] = int(std::floor(lo[k] / h)) - pad;
    box.dims[k] = int(std::ceil(hi[k] / h)) + pad - box.min[k] + 1;
  }
  return box;
}

/// Dense labels (4 bytes a voxel), the distance grid and its signed copy, the watershed's front
/// (12 bytes a shell voxel), the input in double and float (100 bytes a face), and the mesher's
/// output: 3 faces per surface voxel (measured 3.0 on PyMOL surfaces), ~500 bytes each for its
/// polygons, the vcg mesh, its copy into the input mesh and the validity checks. What the rebuild
/// adds to the caller's memory; the peak resident memory of benchmarks/volumetric_rebuild, which
/// also holds the input soup and the process: 1MAH PyMOL SES (118k faces) estimate 469 MB, peak
/// 385 MB; 1HPV cavity-mode SES (18k faces) 72 MB, peak 102 MB.
template <class MeshType>
double VolumetricRebuild<MeshType>::EstimateBytes(const VoxelBox& box, double area, double h,
                                                  double bandVoxels, std::size_t facesIn) {
  const double band = NarrowBandVoxels(area, h, bandVoxels);
  const double surfaceVoxels = area / (h * h);
  return 4.0 * double(box.Size()) + 2.0 * SparseGridBytes(band) + 12.0 * band + 100.0 * double(facesIn) +
         500.0 * 3.0 * surfaceVoxels;
}

template <class MeshType>
std::vector<char> VolumetricRebuild<MeshType>::InsideRegions(const VoxelRegions& regions, const Input& input,
                                                             double h, const Params& params, Result& result) {
  std::vector<Point> queries;
  std::vector<std::size_t> enclosed;
  for (std::size_t r = 0; r < regions.RegionCount(); ++r) {
    if (regions.touchesBorder[r]) continue;
    const openvdb::Coord c = regions.box.CoordOf(regions.deepest[r]);
    queries.emplace_back(h * c.x(), h * c.y(), h * c.z());
    enclosed.push_back(r);
  }
  const std::vector<double> w = WindingNumbers(input.triangles, queries, params.threads);
  double weighted = 0;
  for (std::size_t i = 0; i < enclosed.size(); ++i) weighted += w[i] * double(regions.voxels[enclosed[i]]);
  result.orientationSign = weighted < 0 ? -1 : 1;
  std::vector<char> inside(regions.RegionCount(), 0);
  for (std::size_t i = 0; i < enclosed.size(); ++i)
    if (result.orientationSign * w[i] > params.insideWinding) inside[enclosed[i]] = 1, ++result.insideRegions;
  result.regions = regions.RegionCount();
  return inside;
}

/// -udf on inside voxels, +udf outside (never exactly 0: the mesher would put a vertex on a grid
/// point, shared by several cells), then OpenVDB's signed flood fill gives the voxels beyond the
/// band the sign of the band around them. A sealed slit voxel is decided on the labels alone, so
/// the result does not depend on the order of the voxels.
template <class MeshType>
openvdb::FloatGrid::Ptr VolumetricRebuild<MeshType>::SignedGrid(const openvdb::FloatGrid& udf,
                                                                const VoxelRegions& regions,
                                                                const std::vector<char>& inside, double h,
                                                                const Params& params, Result& result) {
  const auto isInside = [&](const openvdb::Coord& c) {
    return regions.box.Contains(c) && inside[std::size_t(regions.label[regions.box.IndexOf(c)])] != 0;
  };
  const auto betweenInside = [&](const openvdb::Coord& c) {
    for (int axis = 0; axis < 3; ++axis) {
      openvdb::Coord below = c, above = c;
      below[axis] -= 1, above[axis] += 1;
      if (isInside(below) && isInside(above)) return true;
    }
    return false;
  };
  const float floor = float(1e-3 * h);
  openvdb::FloatGrid::Ptr phi = udf.deepCopy();
  for (auto it = phi->beginValueOn(); it; ++it) {
    const float d = std::max(*it, floor);
    bool in = isInside(it.getCoord());
    if (!in && params.sealSlits && betweenInside(it.getCoord())) in = true, ++result.sealedSlitVoxels;
    it.setValue(in ? -d : d);
  }
  phi->setGridClass(openvdb::GRID_LEVEL_SET);
  openvdb::tools::signedFloodFill(phi->tree());
  return phi;
}

template <class MeshType>
std::string VolumetricRebuild<MeshType>::Validate(const MeshType& out, const Params& params, Result& result) {
  typename MeshQuality<MeshType>::Params measure;
  measure.threads = params.threads;
  const QualityReport q = MeshQuality<MeshType>::Compute(out, measure);
  const ClosedComponents c = MeasureClosedComponents(out);
  result.facesOut = q.faces, result.volumeOut = q.volume, result.areaOut = q.area;
  result.bodies = c.bodies, result.cavities = c.cavities;
  std::ostringstream s;
  if (q.faces == 0) s << "no faces; ";
  if (q.boundaryEdges) s << q.boundaryEdges << " boundary edges; ";
  if (q.nonManifoldEdges || q.nonManifoldVertices)
    s << q.nonManifoldEdges << " non-manifold edges and " << q.nonManifoldVertices << " vertices; ";
  if (q.degenerateFaces) s << q.degenerateFaces << " degenerate faces; ";
  if (q.selfIntersectingPairs || q.adjacentOverlapPairs)
    s << q.selfIntersectingPairs + q.adjacentOverlapPairs << " self-intersecting pairs; ";
  if (c.misorientedEdges) s << c.misorientedEdges << " inconsistently oriented edges; ";
  if (!(q.volume > 0)) s << "a non-positive enclosed volume; ";
  std::string text = s.str();
  if (!text.empty()) text.resize(text.size() - 2);
  return text;
}

} // namespace molremesh

// The free space around a surface, cut into regions: the voxels of a box farther than a threshold
// from every input triangle, grouped into 6-connected components, then every voxel nearer than the
// threshold (the shell around the triangles) given to a region by a watershed of the distance.
//
// The threshold seals openings: a crack of width w in a sheet lets no 6-connected path of free
// voxels through when every voxel next to the crack's plane is within the threshold of its rim,
// that is when threshold >= sqrt((w/2)^2 + (h/2)^2) for voxels of edge h; 0.56 w + 0.1 h covers it.
// The watershed floods the shell from the free regions in order of decreasing distance, so two
// regions meet where the distance is smallest: on the triangles, where the surface is.
//
// Single-threaded and in voxel order: the labels do not depend on the thread count.
#pragma once

#include <openvdb/openvdb.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <queue>
#include <vector>

namespace molremesh {

/// A dense box of voxels [min, min + dims) in a grid's index space; voxel v = x + dims.x (y + dims.y z).
struct VoxelBox {
  openvdb::Coord min;
  openvdb::Coord dims;
  std::size_t Size() const { return std::size_t(dims.x()) * std::size_t(dims.y()) * std::size_t(dims.z()); }
  std::size_t IndexOf(const openvdb::Coord& c) const {
    return std::size_t(c.x() - min.x()) +
           std::size_t(dims.x()) *
               (std::size_t(c.y() - min.y()) + std::size_t(dims.y()) * std::size_t(c.z() - min.z()));
  }
  openvdb::Coord CoordOf(std::size_t v) const {
    const std::size_t nx = std::size_t(dims.x()), ny = std::size_t(dims.y());
    return openvdb::Coord(min.x() + int(v % nx), min.y() + int(v / nx % ny), min.z() + int(v / (nx * ny)));
  }
  bool Contains(const openvdb::Coord& c) const {
    for (int k = 0; k < 3; ++k)
      if (c[k] < min[k] || c[k] >= min[k] + dims[k]) return false;
    return true;
  }
  /// The 6 face neighbours of v inside the box (fewer on the box's faces); returns their number.
  int Neighbours(std::size_t v, std::size_t out[6]) const {
    const openvdb::Coord c = CoordOf(v);
    const std::size_t stride[3] = {1, std::size_t(dims.x()), std::size_t(dims.x()) * std::size_t(dims.y())};
    int n = 0;
    for (int k = 0; k < 3; ++k) {
      if (c[k] > min[k]) out[n++] = v - stride[k];
      if (c[k] + 1 < min[k] + dims[k]) out[n++] = v + stride[k];
    }
    return n;
  }
  bool OnBorder(std::size_t v) const {
    const openvdb::Coord c = CoordOf(v);
    for (int k = 0; k < 3; ++k)
      if (c[k] == min[k] || c[k] + 1 == min[k] + dims[k]) return true;
    return false;
  }
};

/// Regions of the free space of a box (LabelFreeSpace), and after FloodShell of every voxel.
struct VoxelRegions {
  static constexpr std::int32_t kShell = -1; ///< a voxel near the triangles, not yet given a region
  VoxelBox box;
  std::vector<std::int32_t> label;  ///< per voxel of the box: its region, or kShell
  std::vector<std::size_t> voxels;  ///< per region: its free voxels
  std::vector<std::size_t> deepest; ///< per region: its free voxel farthest from the triangles
  std::vector<char> touchesBorder;  ///< per region: reaches the box's faces (the outside)
  std::size_t RegionCount() const { return voxels.size(); }
};

/// Free voxels of the box: those whose distance (udf: unsigned distance in world units,
/// background beyond its band) is at least threshold; their 6-connected components, in voxel order.
inline VoxelRegions LabelFreeSpace(const openvdb::FloatGrid& udf, const VoxelBox& box, float threshold) {
  constexpr std::int32_t kFree = -2;
  VoxelRegions r;
  r.box = box;
  r.label.assign(box.Size(), kFree);
  for (auto it = udf.cbeginValueOn(); it; ++it)
    if (*it < threshold && box.Contains(it.getCoord()))
      r.label[box.IndexOf(it.getCoord())] = VoxelRegions::kShell;
  auto distance = udf.getConstAccessor();
  std::vector<std::size_t> stack;
  std::size_t next[6];
  for (std::size_t seed = 0; seed < r.label.size(); ++seed) {
    if (r.label[seed] != kFree) continue;
    const std::int32_t id = std::int32_t(r.voxels.size());
    std::size_t count = 0, deepest = seed;
    float deepestValue = -1;
    bool border = false;
    r.label[seed] = id;
    stack.assign(1, seed);
    while (!stack.empty()) {
      const std::size_t v = stack.back();
      stack.pop_back();
      ++count;
      border = border || box.OnBorder(v);
      const float d = distance.getValue(box.CoordOf(v));
      if (d > deepestValue || (d == deepestValue && v < deepest)) deepestValue = d, deepest = v;
      for (int k = 0, n = box.Neighbours(v, next); k < n; ++k)
        if (r.label[next[k]] == kFree) r.label[next[k]] = id, stack.push_back(next[k]);
    }
    r.voxels.push_back(count);
    r.deepest.push_back(deepest);
    r.touchesBorder.push_back(border ? 1 : 0);
  }
  return r;
}

/// Gives every shell voxel a region: a watershed flooding the shell from the free voxels, the
/// voxel of largest distance first (ties: the smaller voxel index), each taking the region of the
/// neighbour that reached it first.
inline void FloodShell(const openvdb::FloatGrid& udf, VoxelRegions& r) {
  struct Entry {
    float distance;
    std::uint32_t voxel; // box sizes are checked below 2^32 voxels by the caller
    std::int32_t region;
    bool operator<(const Entry& o) const {
      return distance != o.distance ? distance < o.distance : voxel > o.voxel;
    }
  };
  constexpr std::int32_t kQueued = -3;
  auto distance = udf.getConstAccessor();
  std::priority_queue<Entry> front;
  std::size_t next[6];
  auto push = [&](std::size_t v, std::int32_t region) {
    r.label[v] = kQueued;
    front.push({distance.getValue(r.box.CoordOf(v)), std::uint32_t(v), region});
  };
  for (std::size_t v = 0; v < r.label.size(); ++v) {
    if (r.label[v] < 0) continue;
    for (int k = 0, n = r.box.Neighbours(v, next); k < n; ++k)
      if (r.label[next[k]] == VoxelRegions::kShell) push(next[k], r.label[v]);
  }
  while (!front.empty()) {
    const Entry e = front.top();
    front.pop();
    r.label[e.voxel] = e.region;
    for (int k = 0, n = r.box.Neighbours(e.voxel, next); k < n; ++k)
      if (r.label[next[k]] == VoxelRegions::kShell) push(next[k], e.region);
  }
}

} // namespace molremesh

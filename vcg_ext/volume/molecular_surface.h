// Molecular surfaces of a set of atoms as level sets on OpenVDB's sparse grid, extracted as a
// closed, outward-oriented vcg triangle mesh.
//
//   van der Waals  boundary of the union of the atom balls (radius r)
//   SAS            the same with r + probe (where the probe's centre can go)
//   SES            the SAS region eroded by the probe: the points deeper than the probe radius
//                  inside it (Connolly/Richards: the region no probe ball outside the atoms reaches)
//   Gaussian       phi(x) = sum_i exp(-d (|x - c_i|^2 / r_i^2 - 1)) at phi = level (TMSmesh's
//                  surface, a smooth approximation of the van der Waals union)
//
// Algorithm (SES): 1. rasterize the balls r + probe as a narrow-band signed distance field (the
// union is the minimum of the sphere distances, exact outside and near the surface); 2. rebuild the
// field from its zero isosurface (points projected onto the exact spheres) with an inner band wider
// than the probe, so values inside are true distances to the SAS boundary (the minimum of sphere
// distances underestimates the depth where balls overlap); 3. replace its values within two voxels
// of -probe, and within the probe's reach of every SAS vertex the extracted SAS missed, by the exact
// depth (sas_distance.h); 4. extract the isosurface at -probe and project its vertices onto the
// exact depth's level -probe; with minFeatureRadius > 0 the body is first opened by that ball
// (eroded by rho and dilated by rho through two swept distance fields), which drops necks and cusps
// thinner than rho. VdW and SAS extract step 1's field at 0; the Gaussian sums the atoms'
// terms over the voxels where each is above 1e-3 of the level; both project the vertices onto
// their exact field (atom_fields.h).
// Every closed component of the extraction is kept: an inner one bounds a cavity (its normals
// point into the cavity); keepCavities = false keeps only the components enclosing positive volume.
//
// The extraction is OpenVDB's mesher (vcg_ext/volume/level_set_grid.h): closed and free of
// self-intersections by construction, with the isosurface's sliver triangles; the remeshing
// pipeline fixes the angles afterwards. Determinism: the union is a minimum and the Gaussian sum
// runs in atom order, so the output does not depend on the thread count.
#pragma once

#include <vcg_ext/core/union_find.h>
#include <vcg_ext/geometry/point.h>
#include <vcg_ext/pipeline/memory_budget.h>
#include <vcg_ext/structure/atoms.h>
#include <vcg_ext/volume/atom_fields.h>
#include <vcg_ext/volume/level_set_grid.h>
#include <vcg_ext/volume/sas_distance.h>
#include <vcg_ext/volume/sphere_creases.h>

#include <openvdb/tools/FastSweeping.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tools/Morphology.h>
#include <openvdb/tools/ValueTransformer.h>
#include <openvdb/tools/ParticlesToLevelSet.h>
#include <openvdb/tools/SignedFloodFill.h>

#include <algorithm>
#include <chrono>
#include <functional>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

namespace molremesh {

enum class MolecularSurfaceKind { Ses, Sas, VanDerWaals, Gaussian };

inline const char* ToString(MolecularSurfaceKind kind) {
  switch (kind) {
  case MolecularSurfaceKind::Ses:
    return "ses";
  case MolecularSurfaceKind::Sas:
    return "sas";
  case MolecularSurfaceKind::VanDerWaals:
    return "vdw";
  case MolecularSurfaceKind::Gaussian:
    return "gaussian";
  }
  return "?";
}

struct MolecularSurfaceResult {
  bool ok = false;
  bool refusedForMemory = false; ///< the estimate was above the limit; nothing was built
  std::string message;           ///< why not, when !ok
  std::size_t atoms = 0;         ///< atoms with a positive radius that were used
  std::size_t faces = 0, vertices = 0;
  std::size_t components = 0;      ///< closed components of the output
  std::size_t cavities = 0;        ///< components enclosing negative volume (kept or removed)
  std::size_t removedCavities = 0; ///< removed by keepCavities = false
  double area = 0, volume = 0;     ///< of the output mesh, Å² and Å³ (cavities count negative)
  double estimatedMB = 0;          ///< the memory estimate checked before the run
  double seconds = 0;
};

namespace surface_detail {

/// The atoms as OpenVDB's particle list, each radius grown by `grow` (the probe for SAS/SES).
struct AtomParticles {
  using PosType = openvdb::Vec3R;
  const std::vector<Atom>* atoms;
  double grow;
  std::size_t size() const { return atoms->size(); }
  void getPos(std::size_t n, openvdb::Vec3R& xyz) const {
    const Point& p = (*atoms)[n].position;
    xyz = openvdb::Vec3R(p[0], p[1], p[2]);
  }
  void getPosRad(std::size_t n, openvdb::Vec3R& xyz, openvdb::Real& radius) const {
    getPos(n, xyz);
    radius = (*atoms)[n].radius + grow;
  }
};

/// Area and volume of a union of balls, over-estimated from its occupancy on a coarse grid: the
/// boundary faces of a staircase over-count a smooth surface's area by about 1.5.
struct CoarseUnion {
  double area = 0, volume = 0;
};
inline CoarseUnion CoarseUnionOfBalls(const std::vector<Atom>& atoms, double grow) {
  Point lo(1e300, 1e300, 1e300), hi(-1e300, -1e300, -1e300);
  double rmax = 0;
  for (const Atom& a : atoms)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], a.position[k]);
      hi[k] = std::max(hi[k], a.position[k]);
      rmax = std::max(rmax, a.radius + grow);
    }
  double cell = 1.0;
  auto cellsAlong = [&](int k) { return std::size_t((hi[k] - lo[k] + 2 * rmax) / cell) + 3; };
  while (double(cellsAlong(0)) * double(cellsAlong(1)) * double(cellsAlong(2)) > 5e7) cell *= 2;
  const std::size_t nx = cellsAlong(0), ny = cellsAlong(1), nz = cellsAlong(2);
  std::vector<unsigned char> inside(nx * ny * nz, 0);
  const Point origin = lo - Point(rmax + cell, rmax + cell, rmax + cell);
  for (const Atom& a : atoms) {
    const double r = a.radius + grow;
    int from[3], to[3];
    for (int k = 0; k < 3; ++k) {
      from[k] = int(std::floor((a.position[k] - r - origin[k]) / cell));
      to[k] = int(std::ceil((a.position[k] + r - origin[k]) / cell));
    }
    for (int i = from[0]; i <= to[0]; ++i)
      for (int j = from[1]; j <= to[1]; ++j)
        for (int l = from[2]; l <= to[2]; ++l) {
          const Point c = origin + Point(i + 0.5, j + 0.5, l + 0.5) * cell;
          if ((c - a.position).SquaredNorm() <= r * r) inside[(std::size_t(i) * ny + j) * nz + l] = 1;
        }
  }
  std::size_t boundaryFaces = 0, insideCells = 0;
  for (std::size_t i = 1; i + 1 < nx; ++i)
    for (std::size_t j = 1; j + 1 < ny; ++j)
      for (std::size_t l = 1; l + 1 < nz; ++l) {
        const std::size_t c = (i * ny + j) * nz + l;
        if (!inside[c]) continue;
        ++insideCells;
        boundaryFaces += !inside[c - ny * nz] + !inside[c + ny * nz] + !inside[c - nz] + !inside[c + nz] +
                         !inside[c - 1] + !inside[c + 1];
      }
  return {double(boundaryFaces) * cell * cell, double(insideCells) * cell * cell * cell};
}

/// Signed volume enclosed by each connected component of m (by shared vertices), and the
/// component of each face.
template <class MeshType>
std::vector<double> ComponentVolumes(const MeshType& m, std::vector<std::uint32_t>& faceComponent) {
  UnionFind sets(m.vert.size());
  for (const auto& f : m.face)
    if (!f.IsD()) {
      sets.Unite(std::uint32_t(vcg::tri::Index(m, f.cV(0))), std::uint32_t(vcg::tri::Index(m, f.cV(1))));
      sets.Unite(std::uint32_t(vcg::tri::Index(m, f.cV(0))), std::uint32_t(vcg::tri::Index(m, f.cV(2))));
    }
  std::vector<std::uint32_t> label(m.vert.size(), std::uint32_t(-1));
  std::vector<double> volumes;
  faceComponent.assign(m.face.size(), std::uint32_t(-1));
  for (std::size_t i = 0; i < m.face.size(); ++i) {
    const auto& f = m.face[i];
    if (f.IsD()) continue;
    const std::uint32_t root = sets.Find(std::uint32_t(vcg::tri::Index(m, f.cV(0))));
    if (label[root] == std::uint32_t(-1)) {
      label[root] = std::uint32_t(volumes.size());
      volumes.push_back(0);
    }
    faceComponent[i] = label[root];
    const Point a = PositionOf(f.cV(0)), b = PositionOf(f.cV(1)), c = PositionOf(f.cV(2));
    volumes[label[root]] += (a * (b ^ c)) / 6.0;
  }
  return volumes;
}

/// Gaussian density -phi on the grid (negative inside, background 0 outside), atoms in order.
inline openvdb::FloatGrid::Ptr NegatedGaussianDensity(const std::vector<Atom>& atoms, double voxel,
                                                      double decay, double level) {
  openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
  grid->setTransform(VoxelTransform(voxel));
  grid->setGridClass(openvdb::GRID_LEVEL_SET); // for the mesher: inside is below the isovalue
  auto accessor = grid->getAccessor();
  const double cutoff2 = 1.0 + std::log(1e3 / level) / decay; // term below 1e-3 level beyond it
  for (const Atom& a : atoms) {
    const double reach = a.radius * std::sqrt(cutoff2), invR2 = 1.0 / (a.radius * a.radius);
    openvdb::Coord from, to;
    for (int k = 0; k < 3; ++k) {
      from[k] = int(std::floor((a.position[k] - reach) / voxel));
      to[k] = int(std::ceil((a.position[k] + reach) / voxel));
    }
    openvdb::Coord ijk;
    for (ijk[0] = from[0]; ijk[0] <= to[0]; ++ijk[0])
      for (ijk[1] = from[1]; ijk[1] <= to[1]; ++ijk[1])
        for (ijk[2] = from[2]; ijk[2] <= to[2]; ++ijk[2]) {
          const Point x(ijk[0] * voxel, ijk[1] * voxel, ijk[2] * voxel);
          const double s2 = (x - a.position).SquaredNorm() * invR2;
          if (s2 > cutoff2) continue;
          accessor.setValue(ijk, accessor.getValue(ijk) - float(std::exp(-decay * (s2 - 1.0))));
        }
  }
  return grid;
}

/// The signed distance (negative inside) to the isosurface {grid == level}, within outsideVoxels of
/// it outside and insideVoxels inside (beyond: -insideVoxels and outsideVoxels, in voxels): the
/// isosurface's polygons, their points projected onto the level of `exact` (the field the
/// grid samples: the balls themselves, or the grid's own quadratic interpolation, since the
/// mesher's vertices sit off the level by up to h^2/8r), their unsigned distance field, signed by
/// the grid's own membership test (exact, unlike OpenVDB's levelSetRebuild, which signs by flood
/// fill from outside and drops the band around inner surfaces: every cavity would be filled).
/// Each call keeps to distances of a few voxels, where OpenVDB's distance field is exact.
template <class ExactField>
openvdb::FloatGrid::Ptr SignedDistanceToLevel(const openvdb::FloatGrid& grid, double level,
                                              const ExactField& exact, double h, float outsideVoxels,
                                              float insideVoxels, int threads) {
  VdbPolygons polygons;
  openvdb::tools::volumeToMesh(grid, polygons.points, polygons.triangles, polygons.quads, level, 0.0);
  ParallelFor(polygons.points.size(), threads, [&](std::size_t begin, std::size_t end, int) {
    for (std::size_t i = begin; i < end; ++i) {
      openvdb::Vec3s& q = polygons.points[i];
      const Point y = ProjectToLevel(Point(q[0], q[1], q[2]), exact, level, h);
      q = openvdb::Vec3s(float(y[0]), float(y[1]), float(y[2]));
    }
  });
  openvdb::FloatGrid::Ptr distance = TwoSidedDistanceGrid(polygons, h, outsideVoxels, insideVoxels);
  polygons = VdbPolygons();
  const float at = float(level);
  openvdb::tools::foreach (distance->beginValueOn(), [&](const openvdb::FloatGrid::ValueOnIter& it) {
    const float d = std::fabs(*it);
    it.setValue(grid.tree().getValue(it.getCoord()) < at ? -d : d);
  });
  distance->setGridClass(openvdb::GRID_LEVEL_SET);
  openvdb::tools::signedFloodFillWithValues(distance->tree(), float(outsideVoxels * h),
                                            float(-insideVoxels * h));
  return distance;
}

/// The values MakeExactNear replaces: those within `band` of `level`, and one voxel further down,
/// since the rebuilt depth errs on the deep side only.
struct ExactBand {
  float low, high;
  ExactBand(double level, double band, double h) : low(float(level - band - h)), high(float(level + band)) {}
  bool Holds(float value) const { return !(value < low || value > high); }
};

/// Replaces the values of `grid` in the band by the exact SAS depth (the rebuilt one
/// overestimates it under creases and corners by up to a voxel, see sas_distance.h). Elsewhere the
/// rebuilt values are short of the exact depth by at most the sagitta of the SAS mesh's chords (a
/// few hundredths of an Å), so a value plus half a voxel bounds the exact search, which then looks
/// at fewer spheres.
inline void MakeExactNear(openvdb::FloatGrid& grid, const SasBoundaryDistance& depth, const ExactBand& band) {
  const double h = grid.voxelSize()[0];
  const openvdb::math::Transform& xform = grid.transform();
  openvdb::tools::foreach (grid.beginValueOn(), [&](const openvdb::FloatGrid::ValueOnIter& it) {
    if (!band.Holds(*it)) return;
    const openvdb::Vec3d w = xform.indexToWorld(it.getCoord());
    Point gradient;
    it.setValue(float(depth.Depth(Point(w[0], w[1], w[2]), gradient, std::fabs(*it) + 0.5 * h)));
  });
}

/// Makes the grid exact around the SAS vertices it does not see: a pocket or channel of the SAS's
/// outside narrower than a voxel is missing from the extracted SAS, so the rebuilt depth puts such
/// a vertex deep inside although it is on the boundary, and the SES cavity or tunnel the probe
/// carves from there (probe-sized however small the pocket) is lost. A vertex counts as missed
/// when the grid puts it more than `missedDepth` deep; the voxels within the depth's reach of it
/// that are inactive (deeper than the band) or hold a rebuilt value below the band get the exact
/// depth where that is shallower (those in the band were made exact by MakeExactNear, those above
/// it are outside the SES either way). Returns the number of missed vertices.
inline std::size_t MakeExactAroundMissedVertices(openvdb::FloatGrid& grid,
                                                 const SasBoundaryDistance& sasDepth, const ExactBand& exact,
                                                 double missedDepth, int threads) {
  const double h = grid.voxelSize()[0];
  const openvdb::math::Transform& xform = grid.transform();
  std::vector<openvdb::Coord> voxels;
  std::size_t missed = 0;
  {
    openvdb::tools::GridSampler<openvdb::FloatGrid, openvdb::tools::BoxSampler> sample(grid);
    const int r = int(std::ceil(sasDepth.Reach() / h)) + 1;
    const double reach2 = (sasDepth.Reach() + h) * (sasDepth.Reach() + h);
    openvdb::FloatGrid::ConstAccessor values = grid.getConstAccessor();
    auto stillRebuiltDeep = [&](const openvdb::Coord& v) {
      float value;
      return !values.probeValue(v, value) || value < exact.low;
    };
    for (const Point& y : sasDepth.ExposedVertices()) {
      if (!(sample.wsSample(openvdb::Vec3d(y[0], y[1], y[2])) < -missedDepth)) continue;
      ++missed;
      const openvdb::Coord c = xform.worldToIndexCellCentered(openvdb::Vec3d(y[0], y[1], y[2]));
      for (int i = -r; i <= r; ++i)
        for (int j = -r; j <= r; ++j)
          for (int k = -r; k <= r; ++k) {
            const openvdb::Coord v = c.offsetBy(i, j, k);
            const openvdb::Vec3d w = xform.indexToWorld(v);
            if ((Point(w[0], w[1], w[2]) - y).SquaredNorm() <= reach2 && stillRebuiltDeep(v))
              voxels.push_back(v);
          }
    }
  }
  std::sort(voxels.begin(), voxels.end());
  voxels.erase(std::unique(voxels.begin(), voxels.end()), voxels.end());
  std::vector<float> depth(voxels.size());
  ParallelFor(voxels.size(), threads, [&](std::size_t begin, std::size_t end, int) {
    for (std::size_t n = begin; n < end; ++n) {
      const openvdb::Vec3d w = xform.indexToWorld(voxels[n]);
      Point gradient;
      depth[n] = float(sasDepth(Point(w[0], w[1], w[2]), gradient));
    }
  });
  openvdb::FloatGrid::Accessor access = grid.getAccessor();
  for (std::size_t n = 0; n < voxels.size(); ++n) // serial: a new voxel may allocate a leaf
    if (depth[n] > access.getValue(voxels[n])) access.setValue(voxels[n], depth[n]);
  return missed;
}

/// The SAS depth searched within `bound` first (exact all the same, see SasBoundaryDistance::Depth):
/// for projecting points known to be about that deep.
struct BoundedSasDepth {
  const SasBoundaryDistance& depth;
  double bound;
  double operator()(const Point& x, Point& gradient) const { return depth.Depth(x, gradient, bound); }
};

/// Voxels of distance kept on the side of a rebuilt level set nothing reads beyond the mesher's and
/// the quadratic sampler's reach (OpenVDB expands no band narrower than 2 voxels).
constexpr float kSideBandVoxels = 2.0f;

/// The opening by a ball of radius rho of the region {field < level}, as a signed distance grid
/// whose zero isosurface bounds it: the region eroded by rho (its signed distance below -rho), then
/// dilated by rho (the signed distance to the eroded region, below rho). Both distances are OpenVDB's
/// fast sweeping over the active voxels (first order, no polygons or mesh-to-volume; 4JSV: 8.6 s
/// against 22.3 s through SignedDistanceToLevel), first grown by kSideBandVoxels: the field's band ends two
/// voxels past the SES, less around a cavity whose SAS pocket is below the grid's resolution, and the islands
/// MakeExactAroundMissedVertices adds deep inside have no band at all; without the growth the distances stop
/// at the band's edge (4JSV: seven such cavities came out 2-16 % smaller). By the opening's definition a wall
/// thinner than 2 rho between a cavity and the outside or another cavity opens; one within about a voxel of
/// 2 rho opens or stays depending on where the voxels fall. The growth is done on `field` itself
/// (its values stay; only more of them become active): the sweep copies it anyway.
inline openvdb::FloatGrid::Ptr OpenedRegion(openvdb::FloatGrid& field, double level, double rho) {
  openvdb::tools::dilateActiveValues(field.tree(), int(kSideBandVoxels), openvdb::tools::NN_FACE_EDGE,
                                     openvdb::tools::EXPAND_TILES);
  openvdb::FloatGrid::Ptr region = openvdb::tools::sdfToSdf(field, float(level));
  openvdb::FloatGrid::Ptr opened = openvdb::tools::sdfToSdf(*region, float(-rho));
  region.reset();
  const float shift = float(rho);
  openvdb::tools::foreach (opened->beginValueOn(),
                           [shift](const openvdb::FloatGrid::ValueOnIter& it) { it.setValue(*it - shift); });
  return opened;
}

} // namespace surface_detail

/// Builds a molecular surface of a set of atoms (see the top of this file).
template <class MeshType>
class MolecularSurface {
public:
  struct Params {
    MolecularSurfaceKind kind = MolecularSurfaceKind::Ses;
    double probeRadius = 1.4;   ///< Å, a water molecule (SES, SAS)
    double gridSpacing = 0.4;   ///< Å, voxel edge: area within 0.5 % of a sphere's, see the README
    double gaussianDecay = 0.9; ///< d of the Gaussian surface (TMSmesh's default)
    double gaussianLevel = 1.0; ///< isolevel of the Gaussian surface (TMSmesh's default)
    bool keepCavities = true;   ///< false: only the components enclosing positive volume
    /// SAS, van der Waals: vertices on the creases where two spheres meet (SphereCreaseRefinement),
    /// whose chords otherwise cut the area short by about 7 % per Å of grid spacing.
    bool creaseVertices = true;
    /// Å, SES only: the body opened by a ball of this radius, which removes the necks and cusps
    /// thinner than it (the SES's near-singular spots, below the grid's resolution at half a voxel,
    /// where no remesh at a target length of 2.5 voxels can keep its angles); 0: the raw level set.
    double minFeatureRadius = 0.2;
    float halfWidthVoxels = 3.0; ///< narrow band on each side of the surface, voxels
    double memoryLimitMB = 0;    ///< 0: the memory available at the start; < 0: no check
    int threads = 0; ///< vertex projection threads, 0 = all cores (OpenVDB uses TBB's); output independent
    /// Called as each step starts: the fraction of the build done before it (by its share of the
    /// time on 4JSV's SES) and what the step does. Empty: no report.
    std::function<void(double fraction, const std::string& step)> progress;
  };

  /// Replaces m's content by the surface of the atoms. Preconditions (checked, a failed result
  /// leaves m empty): at least one atom with a positive finite radius, finite positions,
  /// gridSpacing > 0, probeRadius >= 0, decay and level > 0.
  static MolecularSurfaceResult Build(const std::vector<Atom>& atomsIn, MeshType& m, const Params& p) {
    const auto start = std::chrono::steady_clock::now();
    MolecularSurfaceResult r;
    m.Clear();
    std::vector<Atom> atoms;
    for (const Atom& a : atomsIn) {
      if (!IsFinite(a.position) || !std::isfinite(a.radius))
        return Fail(r, "an atom has a non-finite position or radius");
      if (a.radius > 0 || (p.kind == MolecularSurfaceKind::Sas || p.kind == MolecularSurfaceKind::Ses))
        atoms.push_back(a);
    }
    if (!(p.gridSpacing > 0) || !(p.probeRadius >= 0) || !(p.gaussianDecay > 0) || !(p.gaussianLevel > 0))
      return Fail(r, "grid spacing, decay and level must be > 0 and the probe radius >= 0");
    if (atoms.empty()) return Fail(r, "no atom with a positive radius");
    r.atoms = atoms.size();
    if (!CheckMemory(atoms, p, r)) return r;

    InitializeOpenVdb();
    Extract(atoms, p, m);
    if (m.fn == 0) return Fail(r, "the surface is empty (atoms smaller than the grid spacing?)");
    Finish(m, p, r);
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    r.ok = true;
    return r;
  }

private:
  static MolecularSurfaceResult& Fail(MolecularSurfaceResult& r, const std::string& why) {
    r.ok = false;
    r.message = why;
    return r;
  }

  /// Distance from an atom's centre, in radii, where its Gaussian term falls below 1e-3 of the level.
  static double GaussianReach(const Params& p) {
    return std::sqrt(1.0 + std::log(1e3 / p.gaussianLevel) / p.gaussianDecay);
  }

  /// Probe inner band of the SES rebuild, in voxels: the probe plus room for interpolation.
  /// Voxels on each side of the SES level where the rebuilt SAS depth is replaced by the exact one:
  /// the mesher and the opening's sweep read the voxels next to the level, and the missed-vertex
  /// test samples the depth near the SAS. Narrower, the output changes (at 1.25 voxels 1HPV's SES
  /// has 77,520 vertices, not 77,486).
  static constexpr double kExactBand = 2.0;
  /// Of a voxel: where a projection onto the exact SES depth stops (its first step lands on it).
  static constexpr double kExactTolerance = 1e-6;
  /// Of a voxel: how deep the rebuilt SAS depth may put a SAS vertex it sees (its flat triangles
  /// cut the vertex's concave corner off) before the vertex counts as missed.
  static constexpr double kMissedDepth = 1.0;

  static float InnerBandVoxels(const Params& p) { return float(p.probeRadius / p.gridSpacing) + 2.0f; }

  static bool CheckMemory(const std::vector<Atom>& atoms, const Params& p, MolecularSurfaceResult& r) {
    const bool grown = p.kind == MolecularSurfaceKind::Sas || p.kind == MolecularSurfaceKind::Ses;
    const double h = p.gridSpacing;
    const surface_detail::CoarseUnion sas =
        surface_detail::CoarseUnionOfBalls(atoms, grown ? p.probeRadius : 0.0);
    double gridBytes = SparseGridBytes(sas.area / (h * h) * (2.0 * p.halfWidthVoxels + 1));
    if (p.kind == MolecularSurfaceKind::Ses) // the rasterized and the rebuilt grid are alive together
      gridBytes += SparseGridBytes(sas.area / (h * h) * (2.0 * InnerBandVoxels(p) + 1));
    if (p.kind == MolecularSurfaceKind::Gaussian) { // dense leaves over every atom's reach
      double reach = 0;
      for (const Atom& a : atoms) reach = std::max(reach, a.radius * (GaussianReach(p) - 1));
      gridBytes =
          SparseGridBytes(0) + surface_detail::CoarseUnionOfBalls(atoms, reach).volume / (h * h * h) * 4.5;
    }
    const double faces = 2.0 * sas.area / (h * h); // the mesher's triangles (quads split in two)
    const double bytes = MemoryBudget::kBaseBytes + gridBytes + faces * 400.0;
    r.estimatedMB = bytes / (1024.0 * 1024.0);
    if (p.memoryLimitMB < 0) return true;
    const double limit =
        p.memoryLimitMB > 0 ? p.memoryLimitMB * 1024.0 * 1024.0 : MemoryBudget::AvailableBytes();
    if (!(limit > 0) || bytes <= limit) return true;
    std::ostringstream s;
    s.setf(std::ios::fixed);
    s.precision(0);
    s << "the surface would need about " << r.estimatedMB << " MB of memory at grid spacing " << p.gridSpacing
      << " Å (about " << faces << " faces), more than the " << limit / (1024.0 * 1024.0) << " MB "
      << (p.memoryLimitMB > 0 ? "memory limit" : "of memory available")
      << "; a larger grid spacing needs less (memory falls with its square)";
    r.refusedForMemory = true;
    Fail(r, s.str());
    return false;
  }

  /// The level set of the kind, extracted into m, its vertices projected onto the exact surface.
  static void Step(const Params& p, double fraction, const char* step) {
    if (p.progress) p.progress(fraction, step);
  }

  static void Extract(const std::vector<Atom>& atoms, const Params& p, MeshType& m) {
    using openvdb::FloatGrid;
    const double h = p.gridSpacing;
    if (p.kind == MolecularSurfaceKind::Gaussian) {
      Step(p, 0.0, "summing the atoms' Gaussian terms");
      FloatGrid::Ptr density =
          surface_detail::NegatedGaussianDensity(atoms, h, p.gaussianDecay, p.gaussianLevel);
      Step(p, 0.6, "extracting the isosurface");
      LevelSetToMesh(*density, m, -p.gaussianLevel);
      Step(p, 0.8, "projecting onto the Gaussian surface");
      ProjectVerticesToLevel(m, GaussianDensity(atoms, p.gaussianDecay, GaussianReach(p)), p.gaussianLevel,
                             h);
      return;
    }
    const double grow = p.kind == MolecularSurfaceKind::VanDerWaals ? 0.0 : p.probeRadius;
    Step(p, 0.0, "rasterizing the atoms");
    FloatGrid::Ptr grid = openvdb::createLevelSet<FloatGrid>(h, p.halfWidthVoxels);
    openvdb::tools::ParticlesToLevelSet<FloatGrid> raster(*grid);
    raster.setRmin(0.0); // hydrogens can be thinner than 1.5 voxels: rasterized all the same
    raster.rasterizeSpheres(surface_detail::AtomParticles{&atoms, grow});
    raster.finalize(true);
    openvdb::tools::signedFloodFill(grid->tree());
    const BallUnionDistance balls(atoms, grow, 2 * h);
    if (p.kind != MolecularSurfaceKind::Ses) {
      Step(p, 0.3, "extracting the isosurface");
      LevelSetToMesh(*grid, m, 0.0);
      Step(p, 0.5, "projecting onto the atom spheres");
      ProjectVerticesToLevel(m, balls, 0.0, h, p.threads);
      if (p.creaseVertices) {
        Step(p, 0.8, "vertices on the creases between spheres");
        typename SphereCreaseRefinement<MeshType>::Params crease;
        crease.threads = p.threads;
        SphereCreaseRefinement<MeshType>::Do(m, atoms, grow, crease);
      }
      return;
    }
    // The signed distance to the SAS, with true values inside down to the probe radius.
    Step(p, SesShare::kDistance, "the distance field inside the solvent-accessible surface");
    FloatGrid::Ptr exact = surface_detail::SignedDistanceToLevel(
        *grid, 0.0, balls, h, surface_detail::kSideBandVoxels, InnerBandVoxels(p), p.threads);
    grid.reset();
    const SasBoundaryDistance sasDepth(atoms, p.probeRadius, p.probeRadius + (kExactBand + 1) * h, p.threads);
    const surface_detail::ExactBand band(-p.probeRadius, kExactBand * h, h);
    surface_detail::MakeExactNear(*exact, sasDepth, band);
    surface_detail::MakeExactAroundMissedVertices(*exact, sasDepth, band, kMissedDepth * h, p.threads);
    const surface_detail::BoundedSasDepth nearSes{sasDepth, p.probeRadius + h};
    if (p.minFeatureRadius > 0) {
      Step(p, SesShare::kOpening, "opening necks and cusps thinner than the grid");
      FloatGrid::Ptr opened = surface_detail::OpenedRegion(*exact, -p.probeRadius, p.minFeatureRadius);
      exact.reset(); // read no more: the projection below uses the opening and sasDepth
      Step(p, SesShare::kExtraction, "extracting the isosurface");
      LevelSetToMesh(*opened, m, 0.0);
      Step(p, SesShare::kProjection, "projecting onto the solvent-excluded surface");
      // Onto the opening, then, since away from the removed features the opening is the SES
      // itself, a last short move onto it: that takes out the two re-distancings' inward bias (a few
      // hundredths of an Å) and stays within a quarter voxel of the opening where it differs. The
      // two moves are checked together (one test for flipped and crossing faces).
      const QuadraticGridField openedField(*opened);
      MoveVerticesKeepingValid(
          m,
          [&](const Point& x) {
            const Point onOpening = ProjectToLevel(x, openedField, 0.0, h);
            return ProjectToLevel(onOpening, nearSes, -p.probeRadius, 0.25 * h, 4, kExactTolerance * h);
          },
          p.threads);
      return;
    }
    Step(p, SesShare::kExtraction, "extracting the isosurface");
    LevelSetToMesh(*exact, m, -p.probeRadius);
    Step(p, SesShare::kProjection, "projecting onto the solvent-excluded surface");
    ProjectVerticesToLevel(m, nearSes, -p.probeRadius, h, p.threads, kExactTolerance * h);
  }

  /// Where the SES's steps start, as fractions of its build (4JSV's SES at 0.4 Å, 40.6 s on 2 threads:
  /// rasterizing 0.9 s, the distance field 23.8, the opening 8.6, the extraction 0.8, the
  /// projection 6.4).
  struct SesShare {
    static constexpr double kDistance = 0.021, kOpening = 0.608, kExtraction = 0.82, kProjection = 0.841;
  };

  /// Components, cavities (removed unless kept), area and volume.
  static void Finish(MeshType& m, const Params& p, MolecularSurfaceResult& r) {
    Step(p, 0.99, "components and cavities");
    std::vector<std::uint32_t> faceComponent;
    const std::vector<double> volumes = surface_detail::ComponentVolumes(m, faceComponent);
    r.components = volumes.size();
    for (double v : volumes) r.cavities += v < 0;
    if (!p.keepCavities && r.cavities > 0) {
      for (std::size_t i = 0; i < m.face.size(); ++i)
        if (!m.face[i].IsD() && volumes[faceComponent[i]] < 0)
          vcg::tri::Allocator<MeshType>::DeleteFace(m, m.face[i]);
      vcg::tri::Clean<MeshType>::RemoveUnreferencedVertex(m);
      vcg::tri::Allocator<MeshType>::CompactEveryVector(m);
      r.removedCavities = r.cavities;
      r.components -= r.cavities;
    }
    r.faces = std::size_t(m.fn);
    r.vertices = std::size_t(m.vn);
    for (const auto& f : m.face) {
      const Point a = PositionOf(f.cV(0)), b = PositionOf(f.cV(1)), c = PositionOf(f.cV(2));
      r.area += ((b - a) ^ (c - a)).Norm() / 2.0;
      r.volume += (a * (b ^ c)) / 6.0;
    }
  }
};

} // namespace molremesh

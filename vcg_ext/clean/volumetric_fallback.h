// Cleaning fallback (vcg_ext/clean/): when the local clean-up leaves a defect it cannot repair (a
// component that cannot be oriented, an unrepaired tangle, a hole left open, a self-intersecting
// pair), the whole surface is replaced by the boundary of the union of the regions it encloses
// (VolumetricRebuild, vcg_ext/volume/, OpenVDB): closed, 2-manifold, outward, self-intersection
// free, cavities and separate parts kept. The caller then re-runs the cheap clean steps on it.
//
// This is the one call site of the rebuild in the clean stage. The volume layer needs OpenVDB, which
// only the targets linking molremesh_openvdb see (they define MOLREMESH_HAVE_OPENVDB, on every
// translation unit of the target); elsewhere RebuildVolumetrically reports "not available" and
// changes nothing.
#pragma once

#include <cstddef>
#include <string>

#if defined(MOLREMESH_HAVE_OPENVDB)
#include <vcg_ext/volume/volumetric_rebuild.h>
#endif

namespace molremesh {
namespace clean {

/// Whether this translation unit has the volume layer (RebuildVolumetrically can rebuild).
#if defined(MOLREMESH_HAVE_OPENVDB)
inline constexpr bool kVolumetricRebuildAvailable = true;
#else
inline constexpr bool kVolumetricRebuildAvailable = false;
#endif

/// What RebuildVolumetrically did.
struct VolumetricFallbackOutcome {
  bool available = false; ///< built with the volume layer (OpenVDB)
  bool ok = false;        ///< the surface was replaced
  std::string message;    ///< why it was not (empty when ok)
  std::size_t facesIn = 0, facesOut = 0;
  double areaIn = 0, areaOut = 0;
  double voxelSize = 0;
};

/// Replaces m by its volumetric rebuild; m is unchanged unless the outcome is ok. m's FF/VF
/// adjacency must be rebuilt by the caller afterwards.
template <class MeshType>
VolumetricFallbackOutcome RebuildVolumetrically(MeshType& m, int threads) {
  VolumetricFallbackOutcome o;
#if defined(MOLREMESH_HAVE_OPENVDB)
  o.available = true;
  typename VolumetricRebuild<MeshType>::Params p;
  p.threads = threads;
  const auto r = VolumetricRebuild<MeshType>::Do(m, p);
  o.ok = r.ok;
  o.message = r.message;
  o.facesIn = r.facesIn, o.facesOut = r.facesOut;
  o.areaIn = r.areaIn, o.areaOut = r.areaOut;
  o.voxelSize = r.voxelSize;
#else
  (void)m;
  (void)threads;
  o.message = "not available: built without the volume layer (OpenVDB, target molremesh_openvdb)";
#endif
  return o;
}

} // namespace clean
} // namespace molremesh

// Explicit instantiations of the clean stage and the pipelines on MeshD (see extern_mesh_d.h);
// compiled once without and once with MOLREMESH_HAVE_OPENVDB, then with the volumetric rebuild the clean
// stage's fallback calls.
#if defined(MOLREMESH_HAVE_OPENVDB)
#include "extern_mesh_d_volume.h"
#else
#include "extern_mesh_d.h"
#endif

namespace molremesh {

template class CleanRawMesh<MeshD>;
template class CoordinateFrame<MeshD>;
template class RemeshPipeline<MeshD>;
template class RegionRemeshing<MeshD>;
#if defined(MOLREMESH_HAVE_OPENVDB)
template class VolumetricRebuild<MeshD>;
#endif

} // namespace molremesh

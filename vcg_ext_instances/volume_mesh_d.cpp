// Explicit instantiations of the molecular surface on MeshD (see extern_mesh_d_volume.h).
#include "extern_mesh_d_volume.h"

namespace molremesh {

template class MolecularSurface<MeshD>;
template class SphereCreaseRefinement<MeshD>;

} // namespace molremesh

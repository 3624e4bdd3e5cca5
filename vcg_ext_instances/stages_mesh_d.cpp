// Explicit instantiations of the stages, operations and measures on MeshD (see extern_mesh_d.h).
#include "extern_mesh_d.h"

namespace molremesh {

template class LocalRemeshingOps<MeshD>;
template class MeshQuality<MeshD>;
template class BadElementColoring<MeshD>;
template class CvtInitialization<MeshD>;
template class ValenceOptimization<MeshD>;
template class RandomSegmentation<MeshD>;
template class AdaptiveRemeshing<MeshD>;
template class PatchwiseRemeshing<MeshD>;
template class SmallAngleElimination<MeshD>;
template class ObtuseReduction<MeshD>;
template class LocalSmoothing<MeshD>;

} // namespace molremesh

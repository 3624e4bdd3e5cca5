#pragma once
// The volume layer's class templates on MeshD, declared as instantiated in vcg_ext_instances_openvdb
// (volume_mesh_d.cpp; the volumetric rebuild in pipeline_mesh_d.cpp, beside its caller), beside
// everything extern_mesh_d.h declares: for the targets that link OpenVDB. The molecular surface's
// build alone instantiates most of the OpenVDB tools it calls.
#include <vcg_ext_instances/extern_mesh_d.h>
#include <vcg_ext/volume/molecular_surface.h>
#include <vcg_ext/volume/sphere_creases.h>
#include <vcg_ext/volume/volumetric_rebuild.h>

namespace molremesh {

extern template class MolecularSurface<MeshD>;
extern template class SphereCreaseRefinement<MeshD>;
extern template class VolumetricRebuild<MeshD>;

} // namespace molremesh

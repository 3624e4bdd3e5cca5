#pragma once
// The vcg_ext class templates on MeshD, declared as instantiated elsewhere: a translation unit that
// includes this header (and links vcg_ext_instances or vcg_ext_instances_openvdb) does not compile
// them again. They are compiled once, in this folder's .cpp files, for the CLI and the tests; about
// two thirds of a pipeline test's compile time was their code generation, repeated in every test
// program. vcg_ext itself stays header-only: any other mesh type instantiates as before.
#include <vcg_ext/clean/clean_raw_mesh.h>
#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/ops/local_remeshing_ops.h>
#include <vcg_ext/pipeline/coordinate_frame.h>
#include <vcg_ext/pipeline/region_remeshing.h>
#include <vcg_ext/pipeline/remesh_pipeline.h>
#include <vcg_ext/quality/bad_element_coloring.h>
#include <vcg_ext/quality/mesh_quality.h>
#include <vcg_ext/stages/adaptive_remeshing.h>
#include <vcg_ext/stages/cvt_initialization.h>
#include <vcg_ext/stages/local_smoothing.h>
#include <vcg_ext/stages/obtuse_reduction.h>
#include <vcg_ext/stages/patchwise_remeshing.h>
#include <vcg_ext/stages/random_segmentation.h>
#include <vcg_ext/stages/small_angle_elimination.h>
#include <vcg_ext/stages/valence_optimization.h>

namespace molremesh {

// Stages, operations and measures: the same code with and without OpenVDB (stages_mesh_d.cpp).
extern template class LocalRemeshingOps<MeshD>;
extern template class MeshQuality<MeshD>;
extern template class BadElementColoring<MeshD>;
extern template class CvtInitialization<MeshD>;
extern template class ValenceOptimization<MeshD>;
extern template class RandomSegmentation<MeshD>;
extern template class AdaptiveRemeshing<MeshD>;
extern template class PatchwiseRemeshing<MeshD>;
extern template class SmallAngleElimination<MeshD>;
extern template class ObtuseReduction<MeshD>;
extern template class LocalSmoothing<MeshD>;

// The clean stage and what calls it: their code differs with MOLREMESH_HAVE_OPENVDB (the volumetric
// fallback), so pipeline_mesh_d.cpp is compiled once per variant and a target links the variant
// that matches its own definition.
extern template class CleanRawMesh<MeshD>;
extern template class CoordinateFrame<MeshD>;
extern template class RemeshPipeline<MeshD>;
extern template class RegionRemeshing<MeshD>;

} // namespace molremesh

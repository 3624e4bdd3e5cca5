// Setup and checks shared by the tests of the local stages (test_small_angle_elimination,
// test_obtuse_reduction, test_local_smoothing): the three stages have the same interface
// (Stage::Do(mesh, reference, params), Params::targetEdgeLength and threads, Result::ok and
// message), the same promises (a refused input is left untouched, the output does not depend on
// the thread count) and run on the same inputs (constructed spheres, real meshes after the
// pipeline's earlier stages), so each test file keeps only what is particular to its stage.
#pragma once

#include <gtest/gtest.h>

#include <vcg/complex/complex.h>

#include <vcg_ext/io/mesh_io.h>
#include <vcg_ext/quality/mesh_quality.h>
#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/surface/reference_surface.h>
#include <vcg_ext/pipeline/remesh_pipeline.h>

#include <array>
#include <chrono>
#include <string>
#include <vector>

#include "remeshing_test_meshes.h"
#include "test_helpers.h"

namespace molremesh::test {

inline void UpdateAdjacency(MeshD& m) {
  vcg::tri::UpdateTopology<MeshD>::FaceFace(m);
  vcg::tri::UpdateTopology<MeshD>::VertexFace(m);
}

/// The shared mesh `name` after the pipeline's stages clean, cvt (when `cvt`), then `after`: the
/// input a later stage sees in the pipeline.
inline void LoadPrepared(MeshD& m, const std::string& name, bool cvt,
                         const std::vector<PipelineStage>& after) {
  std::string error;
  ASSERT_TRUE(LoadMesh(m, SharedMesh(name), error)) << error;
  RemeshPipeline<MeshD>::Params params;
  params.stages = {PipelineStage::Clean};
  if (cvt) params.stages.push_back(PipelineStage::Cvt);
  params.stages.insert(params.stages.end(), after.begin(), after.end());
  params.measureEachStage = false;
  ASSERT_TRUE(RemeshPipeline<MeshD>::Do(m, params).ok);
  UpdateAdjacency(m);
}

/// Unit icosphere with obtuse triangles: one corner of a few faces is pushed most of the way
/// toward the midpoint of its opposite edge (and put back on the sphere).
inline void ObtuseSphere(MeshD& m) {
  Icosphere(m, 3);
  UpdateAdjacency(m);
  for (std::size_t fi = 0; fi < m.face.size(); fi += 97) {
    auto& f = m.face[fi];
    const vcg::Point3d mid = (f.P(1) + f.P(2)) * 0.5;
    f.V(0)->P() = (f.P(0) + (mid - f.P(0)) * 0.6).Normalize();
  }
  UpdateAdjacency(m);
}

/// Default parameters of Stage with L fixed to the mean edge length of m (as the pipeline does).
template <class Stage>
typename Stage::Params ParamsFor(const MeshD& m) {
  typename Stage::Params p;
  p.targetEdgeLength = MeanEdge(m);
  return p;
}

/// Same vertex positions (bit for bit) and the same faces in the same order.
inline bool SameMesh(const MeshD& a, const MeshD& b) {
  if (a.vert.size() != b.vert.size() || a.face.size() != b.face.size()) return false;
  for (std::size_t i = 0; i < a.vert.size(); ++i)
    if (a.vert[i].cP() != b.vert[i].cP()) return false;
  for (std::size_t i = 0; i < a.face.size(); ++i)
    for (int k = 0; k < 3; ++k)
      if (vcg::tri::Index(a, a.face[i].cV(k)) != vcg::tri::Index(b, b.face[i].cV(k))) return false;
  return true;
}

/// Runs Stage on m, which has nothing for it to do: the run succeeds, leaves m bit-identical and
/// is only a scan (well under half a second). Returns the result for the stage's own counts.
template <class Stage>
typename Stage::Result ExpectScanOnly(MeshD& m) {
  MeshD copy;
  vcg::tri::Append<MeshD, MeshD>::MeshCopy(copy, m);
  ReferenceSurface<MeshD> reference;
  EXPECT_TRUE(reference.Build(m));
  const auto t0 = std::chrono::steady_clock::now();
  const typename Stage::Result r = Stage::Do(m, reference, ParamsFor<Stage>(m));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_TRUE(r.ok) << r.message;
  EXPECT_TRUE(SameMesh(m, copy));
  EXPECT_LT(seconds, 0.5);
  return r;
}

/// The refusals every local stage makes with default parameters: an empty mesh, and a fin (three
/// triangles on the edge 0-1 of finPoints: not 2-manifold), which is left untouched with a message
/// that says why.
template <class Stage>
void ExpectEmptyAndNonManifoldInputsRefused(const ReferenceSurface<MeshD>& reference,
                                            const std::vector<vcg::Point3d>& finPoints) {
  MeshD empty;
  EXPECT_FALSE(Stage::Do(empty, reference, typename Stage::Params()).ok);
  MeshD fin;
  MakeMesh(fin, finPoints, {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}});
  UpdateAdjacency(fin);
  MeshD copy;
  vcg::tri::Append<MeshD, MeshD>::MeshCopy(copy, fin);
  const typename Stage::Result r = Stage::Do(fin, reference, typename Stage::Params());
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("manifold"), std::string::npos) << r.message;
  EXPECT_TRUE(SameMesh(fin, copy));
}

/// Runs Stage on three copies of the prepared mesh a (twice with one thread, once with two) and
/// expects the same output: no hidden randomness, no dependence on the thread count.
template <class Stage>
void ExpectSameOutputForOneAndTwoThreads(MeshD& a) {
  ReferenceSurface<MeshD> reference;
  ASSERT_TRUE(reference.Build(a));
  MeshD b, c;
  vcg::tri::Append<MeshD, MeshD>::MeshCopy(b, a);
  vcg::tri::Append<MeshD, MeshD>::MeshCopy(c, a);
  UpdateAdjacency(b);
  UpdateAdjacency(c);
  typename Stage::Params p = ParamsFor<Stage>(a);
  p.threads = 1;
  ASSERT_TRUE(Stage::Do(a, reference, p).ok);
  ASSERT_TRUE(Stage::Do(c, reference, p).ok);
  p.threads = 2;
  ASSERT_TRUE(Stage::Do(b, reference, p).ok);
  EXPECT_TRUE(SameMesh(a, b));
  EXPECT_TRUE(SameMesh(a, c));
}

/// A stage run on a copy of a prepared real mesh: the input, the output and both quality reports.
struct RealRun {
  MeshD input, output;
  QualityReport before, after;
};

/// Runs Stage with ParamsFor(input) on a copy of run.input (its own reference surface), fills
/// run.output and the reports; `result` gets the stage's result.
template <class Stage>
void RunOnCopy(RealRun& run, typename Stage::Result& result) {
  ReferenceSurface<MeshD> reference;
  ASSERT_TRUE(reference.Build(run.input));
  vcg::tri::Append<MeshD, MeshD>::MeshCopy(run.output, run.input);
  UpdateAdjacency(run.output);
  run.before = MeshQuality<MeshD>::Compute(run.input);
  result = Stage::Do(run.output, reference, ParamsFor<Stage>(run.input));
  ASSERT_TRUE(result.ok) << result.message;
  run.after = MeshQuality<MeshD>::Compute(run.output);
}

/// The invariants every local stage keeps on a real mesh (DESIGN-NOTES.md): 2-manifold, no
/// degenerate face, no self-intersection, components closed with their genus, the volume within
/// 0.5 %, every vertex within 0.1 L of the input surface.
inline void ExpectLocalStageInvariants(const RealRun& run) {
  ExpectTwoManifoldWithoutDegenerateFaces(run.after);
  ExpectNoSelfIntersection(run.after);
  ExpectComponentsClosedWithTheirGenus(run.before, run.after);
  EXPECT_NEAR(run.after.volume / run.before.volume, 1.0, 0.005);
  ExpectVerticesOnInput(run.output, run.input, 0.1 * run.before.meanEdgeLength);
}

} // namespace molremesh::test

// The memory budget: a run that cannot fit is refused before it starts, the mesh untouched, with a
// message that says how much it would need and why; the estimate lies above what a real run takes.
#include <gtest/gtest.h>

#include <sys/resource.h>

#include <vcg_ext_instances/extern_mesh_d.h>
#include <vcg_ext/pipeline/memory_budget.h>
#include <vcg_ext/io/mesh_io.h>
#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/pipeline/remesh_pipeline.h>

#include "remeshing_test_meshes.h"
#include "test_helpers.h"

using namespace molremesh;
using namespace molremesh::test;

namespace {

using Pipeline = RemeshPipeline<MeshD>;

void UnitSphere(MeshD& m, int subdivisions) {
  Icosphere(m, subdivisions);
  vcg::tri::UpdateTopology<MeshD>::FaceFace(m);
  vcg::tri::UpdateTopology<MeshD>::VertexFace(m);
}

std::vector<double> Coordinates(const MeshD& m) {
  std::vector<double> c;
  for (const auto& v : m.vert)
    for (int k = 0; k < 3; ++k) c.push_back(v.cP()[k]);
  return c;
}

} // namespace

TEST(MemoryBudget, UniformFaceCountOfASurface) {
  // An equilateral triangle of edge L has area sqrt(3)/4 L^2.
  EXPECT_NEAR(MemoryBudget::UniformFaces(std::sqrt(3.0) / 4.0 * 1000.0, 1.0), 1000.0, 1e-9);
  EXPECT_NEAR(MemoryBudget::UniformFaces(100.0, 0.5) / MemoryBudget::UniformFaces(100.0, 1.0), 4.0, 1e-12);
  EXPECT_EQ(MemoryBudget::UniformFaces(100.0, 0.0), 0.0);
  EXPECT_EQ(MemoryBudget::UniformFaces(std::nan(""), 1.0), 0.0);
  EXPECT_EQ(MemoryBudget::UniformFaces(std::numeric_limits<double>::infinity(), 1.0), 0.0);
}

TEST(MemoryBudget, EstimateGrowsWithTheLargestMeshOfTheRun) {
  const MemoryEstimate local = MemoryBudget::Estimate(100000, 50000, false, 1000.0, 0.001);
  EXPECT_EQ(local.facesOut, 0.0) << "no resampling stage: the output is about the input's size";
  const MemoryEstimate coarse = MemoryBudget::Estimate(100000, 50000, true, 1000.0, 1.0);
  const MemoryEstimate fine = MemoryBudget::Estimate(100000, 50000, true, 1000.0, 0.01);
  EXPECT_DOUBLE_EQ(coarse.bytes, local.bytes) << "3.5k output faces: the input dominates";
  EXPECT_GT(fine.facesOut, 1e7);
  EXPECT_GT(fine.bytes, 100 * coarse.bytes);
  const MemoryEstimate soup = MemoryBudget::Estimate(100000, 300000, false, 0, 0);
  EXPECT_GT(soup.bytes, local.bytes) << "an unwelded soup has three vertices per face";
}

TEST(MemoryBudget, CheckSaysHowMuchAndAgainstWhat) {
  const MemoryEstimate e = MemoryBudget::Estimate(1000, 500, true, 1000.0, 0.001);
  const std::string overLimit = MemoryBudget::Check(e, 100.0);
  EXPECT_NE(overLimit.find("the run would need about"), std::string::npos) << overLimit;
  EXPECT_NE(overLimit.find("more than the 100 MB memory limit"), std::string::npos) << overLimit;
  EXPECT_NE(overLimit.find("at target edge length 0.001 about"), std::string::npos) << overLimit;
  EXPECT_NE(MemoryBudget::Check(MemoryBudget::Estimate(1000, 500, true, 1000.0, 1e-5), 100.0)
                .find("at target edge length 1e-05 about"),
            std::string::npos);
  EXPECT_EQ(MemoryBudget::Check(e, -1.0), "") << "a negative limit turns the check off";
  EXPECT_EQ(MemoryBudget::Check(e, e.bytes / (1024.0 * 1024.0) + 1.0), "");
}

#if defined(__linux__)
TEST(MemoryBudget, AvailableMemoryIsKnownOnLinux) {
  const double available = MemoryBudget::AvailableBytes();
  EXPECT_GT(available, 16.0 * 1024 * 1024);
  EXPECT_LT(available, 1e15);
}
#endif

// A target edge length 10^4 times below the sphere's edges would make about 10^10 faces: refused
// with the default limit (the available memory) before any stage, the mesh bit-identical; with
// the check off the same parameters would start (not run here), so it is the check that refuses.
TEST(MemoryBudget, PipelineRefusesARunThatCannotFitAndLeavesTheMeshUntouched) {
  MeshD m;
  UnitSphere(m, 3);
  const std::vector<double> before = Coordinates(m);
  const int fn = m.fn;
  Pipeline::Params params;
  params.targetEdgeLength = 1e-5;
  const PipelineResult r = Pipeline::Do(m, params);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("refused: the run would need about"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("MB of memory available"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("the mesh is unchanged"), std::string::npos) << r.message;
  EXPECT_TRUE(r.stages.empty()) << "no stage ran";
  EXPECT_EQ(m.fn, fn);
  EXPECT_EQ(Coordinates(m), before);
  params.memoryLimitMB = -1;
  EXPECT_EQ(Pipeline::MemoryCheck(m, params), "");
  // Local stages make no new mesh: the same L is no reason to refuse them.
  params.memoryLimitMB = 0;
  params.stages = {PipelineStage::Small};
  EXPECT_EQ(Pipeline::MemoryCheck(m, params), "");
}

TEST(MemoryBudget, PipelineHonoursAnExplicitLimit) {
  MeshD m;
  UnitSphere(m, 3);
  Pipeline::Params params;
  params.memoryLimitMB = 1;
  const PipelineResult r = Pipeline::Do(m, params);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.message.find("more than the 1 MB memory limit"), std::string::npos) << r.message;
  params.memoryLimitMB = 4096;
  params.cvt.iterations = 2;
  EXPECT_TRUE(Pipeline::Do(m, params).ok);
}

// The estimate must lie above what a real run takes, or the check lets through runs that will be
// killed: the full pipeline on the 59k-face PyMOL surface of 1MAH, in this process (peak resident
// memory from getrusage, which also counts the test program itself).
TEST(MemoryBudget, EstimateLiesAboveTheMeasuredPeakOfARealRun) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  MeshD m;
  std::string error;
  ASSERT_TRUE(LoadMesh(m, SharedMesh("ache_1MAH_pymol_ses.ply"), error)) << error;
  vcg::tri::UpdateTopology<MeshD>::FaceFace(m);
  vcg::tri::UpdateTopology<MeshD>::VertexFace(m);
  Pipeline::Params params;
  params.restoreOnFailure = false; // as the CLI and the plugin run it
  const MemoryEstimate estimate = Pipeline::EstimateMemory(m, params);
  const PipelineResult r = Pipeline::Do(m, params);
  ASSERT_TRUE(r.ok) << r.message;
  rusage usage{};
  ASSERT_EQ(getrusage(RUSAGE_SELF, &usage), 0);
  const double peakBytes = double(usage.ru_maxrss) * 1024.0;
  EXPECT_LT(peakBytes, estimate.bytes)
      << "peak " << peakBytes / 1048576 << " MB, estimate " << estimate.bytes / 1048576 << " MB";
  // ... and not so far above that it refuses runs that fit.
  EXPECT_GT(2.5 * peakBytes, estimate.bytes)
      << "peak " << peakBytes / 1048576 << " MB, estimate " << estimate.bytes / 1048576 << " MB";
}

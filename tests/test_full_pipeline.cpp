// Acceptance of the full pipeline through the CLI on every shared mesh: every angle in
// [30, 120] degrees, V567 >= 99.8 %, no more obtuse triangles than CGAL's isotropic remeshing
// left on the same mesh (tests/data/cgal_reference.json), 0 self-intersections, 2-manifold,
// closed components closed with their genus, volume within 0.5 % of the cleaned input, every
// vertex within 0.1 L of the cleaned input, and TetGen (-pq1.4) meshes the output. Plus
// determinism: the same seed gives the same file, whatever the thread count.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <vcg_ext/io/mesh_io.h>
#include <vcg_ext/quality/mesh_quality.h>
#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/surface/surface_distance.h>

#include <fstream>
#include <set>
#include <string>

#include "remeshing_test_meshes.h"
#include "cgal_reference.h"
#include "test_helpers.h"

using namespace molremesh;
using namespace molremesh::test;

namespace {
const std::string kCli = MOLREMESH_CLI_PATH;

void Load(MeshD& m, const std::string& path) {
  std::string error;
  ASSERT_TRUE(LoadMesh(m, path, error)) << error;
}

class FullPipelineOnMesh : public ::testing::TestWithParam<std::string> {};
} // namespace

TEST_P(FullPipelineOnMesh, MeetsEveryAcceptanceFigure) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  const std::string name = GetParam();
  const std::string input = SharedMesh(name + ".ply");
  const auto dir = TempDir("full_" + name);
  const std::string output = (dir / "remeshed.ply").string();
  const std::string cleaned = (dir / "cleaned.ply").string();
  const std::string json = (dir / "stages.json").string();

  CommandResult r = molremesh::test::Run(Quote(kCli) + " remesh --quiet " + Quote(input) + " " +
                                         Quote(output) + " --json " + Quote(json));
  ASSERT_EQ(r.exitCode, 0) << r.out << r.err;
  const std::string remeshErrors = r.err;
  r = molremesh::test::Run(Quote(kCli) + " remesh --quiet --stages clean " + Quote(input) + " " +
                           Quote(cleaned));
  ASSERT_EQ(r.exitCode, 0) << r.out << r.err;
  std::ifstream jsonIn(json);
  const nlohmann::json stages = nlohmann::json::parse(jsonIn);
  const double L = stages["target_edge_length"].get<double>();
  ASSERT_GT(L, 0);
  // The tool's own verdict agrees with the figures checked below: every promise kept, no warning.
  EXPECT_TRUE(stages["verdict"]["all_targets_met"].get<bool>()) << stages["verdict"].dump();
  EXPECT_EQ(remeshErrors.find("warning"), std::string::npos) << remeshErrors;

  MeshD out, clean, raw;
  Load(out, output);
  Load(clean, cleaned);
  Load(raw, input);
  const QualityReport after = MeshQuality<MeshD>::Compute(out, MeshQuality<MeshD>::Params());
  const QualityReport before = MeshQuality<MeshD>::Compute(clean, MeshQuality<MeshD>::Params());

  // The paper's angle bound with no exception, and the valence target.
  EXPECT_GE(after.angleMin, 30.0);
  EXPECT_LE(after.angleMax, 120.0);
  EXPECT_GE(after.v567Percent, 99.8);
  // No more obtuse triangles than CGAL's isotropic remeshing leaves at the same target length.
  const nlohmann::json cgal = molremesh::test::CgalReference(name);
  ASSERT_FALSE(cgal.is_null()) << "no CGAL reference figures for " << name;
  EXPECT_LE(after.obtusePercent, cgal["obtuse_percent"].get<double>() + 1e-9);

  ExpectTwoManifoldWithoutDegenerateFaces(after);
  ExpectNoSelfIntersection(after);
  ExpectComponentsClosedWithTheirGenus(before, after);
  EXPECT_NEAR(after.volume, before.volume, 0.005 * std::fabs(before.volume));
  ExpectVerticesOnInput(out, clean, 0.1 * L);

  // Fidelity to what stage 0 kept: the surface stays within one target edge length of the cleaned
  // input both ways (cutting off a spike, as the valence pass did on 1UBQ Jmol before its
  // fidelity guard, reached 1.6 L; every mesh is at 0.72 L or less now).
  const SymmetricDistance toCleaned = SurfaceDistance<MeshD, MeshD>::Symmetric(out, clean);
  EXPECT_LE(toCleaned.hausdorff, 1.0 * L)
      << "Hausdorff distance to the cleaned input, in L: " << toCleaned.hausdorff / L;

  // Recorded beside the figures (compare with CGAL's in the reference): symmetric Hausdorff / L to
  // the raw input (it includes the components stage 0 drops and the holes it closes).
  const SymmetricDistance d = SurfaceDistance<MeshD, MeshD>::Symmetric(out, raw);
  RecordProperty("hausdorff_over_L", std::to_string(d.hausdorff / L));
  RecordProperty("cgal_hausdorff_over_L", std::to_string(cgal.value("hausdorff_over_L", -1.0)));
  // Hausdorff distance no larger than CGAL's, on the meshes where that is met. Not on the three whose
  // small components stage 0 drops (1MAH EDTSurf, 1MAH PyMOL, 4JSV: the distance to the raw input is
  // the dropped component's), nor the one whose open crack it patches (1UBQ EDTSurf); README lists
  // their figures. 1UBQ PyMOL joined the others when the pinch-fan refill kept the removed sheet.
  const std::set<std::string> hausdorffShortOf = {"ache_1MAH_edtsurf_vcmc", "ache_1MAH_pymol_ses",
                                                  "mtor_4JSV_edtsurf_vcmc", "ubiquitin_1UBQ_edtsurf_mc"};
  if (!hausdorffShortOf.count(name) && cgal.contains("hausdorff_over_L")) {
    EXPECT_LE(d.hausdorff / L, cgal["hausdorff_over_L"].get<double>());
  }
  std::cout << name << ": theta [" << after.angleMin << ", " << after.angleMax << "], V567 "
            << after.v567Percent << " %, obtuse " << after.obtusePercent << " %, Hausdorff "
            << d.hausdorff / L << " L (CGAL " << cgal.value("hausdorff_over_L", -1.0)
            << " L), to the cleaned input " << toCleaned.hausdorff / L << " L\n";

  // TetGen builds a tetrahedral mesh of the output.
  const std::string off = (dir / "remeshed.off").string();
  std::string error;
  ASSERT_TRUE(SaveMesh(out, off, error)) << error;
  r = molremesh::test::Run("timeout 1200 tetgen -pq1.4 -Q " + Quote(off));
  EXPECT_EQ(r.exitCode, 0) << r.out << r.err;
  const std::string ele = ReadFile(dir / "remeshed.1.ele");
  ASSERT_FALSE(ele.empty()) << "TetGen wrote no tetrahedra\n" << r.out << r.err;
  EXPECT_GT(std::stol(ele.substr(0, ele.find(' '))), 0L);
  std::filesystem::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(SharedMeshes, FullPipelineOnMesh,
                         ::testing::Values("ache_1MAH_edtsurf_vcmc", "ache_1MAH_pymol_ses", "bpti_1bpi_msms",
                                           "galactose_grasp", "hivprotease_1HPV_edtsurf_mc",
                                           "lysozyme_Lys1_msms", "mtor_4JSV_edtsurf_vcmc",
                                           "ubiquitin_1UBQ_edtsurf_mc", "ubiquitin_1UBQ_jmol",
                                           "ubiquitin_1UBQ_pymol_ses"),
                         [](const auto& p) { return std::string(p.param); });

TEST(FullPipeline, SameSeedSameOutputForAnyThreadCount) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  const std::string input = SharedMesh("lysozyme_Lys1_msms.ply");
  const auto dir = TempDir("full_determinism");
  std::vector<std::string> files;
  for (const char* threads : {"1", "2", "2"}) {
    files.push_back((dir / ("out" + std::to_string(files.size()) + ".ply")).string());
    const CommandResult r = molremesh::test::Run(Quote(kCli) + " remesh --quiet --seed 7 --threads " +
                                                 threads + " " + Quote(input) + " " + Quote(files.back()));
    ASSERT_EQ(r.exitCode, 0) << r.out << r.err;
  }
  const std::string first = ReadFile(files[0]);
  ASSERT_FALSE(first.empty());
  EXPECT_EQ(ReadFile(files[1]), first) << "1 vs 2 threads";
  EXPECT_EQ(ReadFile(files[2]), first) << "same run twice";
  // Another seed gives another segmentation, so (almost surely) another mesh.
  const std::string other = (dir / "other.ply").string();
  ASSERT_EQ(
      molremesh::test::Run(Quote(kCli) + " remesh --quiet --seed 8 " + Quote(input) + " " + Quote(other))
          .exitCode,
      0);
  EXPECT_NE(ReadFile(other), first);
  std::filesystem::remove_all(dir);
}

TEST(FullPipeline, BadInputsFailClearlyAndWriteNothing) {
  const auto dir = TempDir("full_bad");
  const auto allDegenerate = dir / "all_degenerate.ply";
  std::ofstream(allDegenerate)
      << "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
         "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
         "0 0 0\n1 0 0\n2 0 0\n3 0 0\n3 0 1 2\n3 1 2 3\n";
  std::vector<std::string> inputs = {allDegenerate.string()};
  for (const char* fixture : {"empty.ply", "point_cloud.ply", "nan_vertex.ply", "not_a_mesh.ply"})
    inputs.push_back(Fixture(fixture));
  for (const std::string& input : inputs) {
    const std::string out = (dir / "out.ply").string();
    const CommandResult r = molremesh::test::Run("timeout 120 " + Quote(kCli) + " remesh --quiet " +
                                                 Quote(input) + " " + Quote(out));
    EXPECT_EQ(r.exitCode, 2) << input << "\n" << r.err;
    EXPECT_NE(r.err.find("molremesh: error:"), std::string::npos) << input << "\n" << r.err;
    EXPECT_FALSE(std::filesystem::exists(out)) << input;
  }
  // A single open triangle is no surface to remesh: refused with a message.
  const auto triangle = dir / "single_triangle.ply";
  std::ofstream(triangle)
      << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
         "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
         "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  const std::string out = (dir / "triangle_out.ply").string();
  const CommandResult r = molremesh::test::Run("timeout 120 " + Quote(kCli) + " remesh --quiet " +
                                               Quote(triangle.string()) + " " + Quote(out));
  EXPECT_EQ(r.exitCode, 2) << r.err;
  EXPECT_NE(r.err.find("too few to remesh"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out));
  std::filesystem::remove_all(dir);
}

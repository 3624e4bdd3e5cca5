// Integration: our plugin inside Debian's real meshlabserver (sandboxed copy under Xvfb, see
// scripts/make_meshlabserver_sandbox.sh), running the shipped .mlx scripts on real molecular
// meshes. The colors and quality it saves must agree with the CLI's own counts on the input.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <regex>

#include <vcg_ext/bad_element_coloring.h>
#include <vcg_ext/mesh_quality.h>
#include <vcg_ext/mesh_types.h>
#include <wrap/io_trimesh/import_ply.h>

#include "test_helpers.h"

using namespace molremesh::test;
using molremesh::MeshD;

namespace {
const std::string kServer = MOLREMESH_MESHLABSERVER_WRAPPER;
const std::string kCli = MOLREMESH_CLI_PATH;
const std::string kScripts = MOLREMESH_MLX_DIR;

nlohmann::json CliReport(const std::string& mesh) {
  const CommandResult r = Run(Quote(kCli) + " report --json " + Quote(mesh));
  EXPECT_EQ(r.exitCode, 0) << r.err;
  return nlohmann::json::parse(r.out);
}

CommandResult Server(const std::string& args) {
  return Run(Quote(kServer) + " " + args);
}

// Meshes small enough to keep the suite quick, covering MSMS slivers, marching-cubes holes and
// non-manifold vertices, PyMOL self-intersections, GRASP obtuse triangles and several components.
const std::vector<std::string> kMeshes = {
    "bpti_1bpi_msms.ply",           "lysozyme_Lys1_msms.ply", "ubiquitin_1UBQ_edtsurf_mc.ply",
    "ubiquitin_1UBQ_pymol_ses.ply", "galactose_grasp.ply",    "ache_1MAH_edtsurf_vcmc.ply"};
} // namespace

TEST(MeshlabServer, ListsOurFilters) {
  const auto dir = TempDir("mls_list");
  const std::string dump = (dir / "filters.txt").string();
  const CommandResult r = Server("-d " + Quote(dump));
  const std::string text = ReadFile(dump);
  for (const char* name : {"Molecular Remesh: Quality Report", "Molecular Remesh: Color Bad Elements"})
    EXPECT_NE(text.find(name), std::string::npos) << name << "\n" << r.out << r.err;
  std::filesystem::remove_all(dir);
}

class MeshlabServerOnMesh : public ::testing::TestWithParam<std::string> {};

TEST_P(MeshlabServerOnMesh, ColorScriptMatchesCliCounts) {
  const std::string input = SharedMesh(GetParam());
  const auto dir = TempDir("mls_color");
  const std::string output = (dir / "colored.ply").string();
  const CommandResult r = Server("-i " + Quote(input) + " -o " + Quote(output) + " -m vc fc vq fq -s " +
                                 Quote(kScripts + "/color_bad_elements.mlx"));
  ASSERT_EQ(r.exitCode, 0) << r.out << r.err;

  MeshD mesh;
  int mask = vcg::tri::io::Mask::IOM_VERTCOLOR | vcg::tri::io::Mask::IOM_FACECOLOR |
             vcg::tri::io::Mask::IOM_VERTQUALITY | vcg::tri::io::Mask::IOM_FACEQUALITY;
  ASSERT_EQ(vcg::tri::io::ImporterPLY<MeshD>::Open(mesh, output.c_str(), mask), 0);
  ASSERT_TRUE(mask & vcg::tri::io::Mask::IOM_FACECOLOR) << "face colors were not saved";
  ASSERT_TRUE(mask & vcg::tri::io::Mask::IOM_VERTQUALITY) << "vertex quality was not saved";

  using Coloring = molremesh::BadElementColoring<MeshD>;
  std::size_t red = 0, blue = 0, magenta = 0, redVertices = 0;
  for (const auto& f : mesh.face) {
    red += f.cC() == Coloring::ObtuseFaceColor();
    blue += f.cC() == Coloring::SmallAngleFaceColor();
    magenta += f.cC() == Coloring::ObtuseAndSmallFaceColor();
  }
  const std::vector<int> valence = molremesh::MeshQuality<MeshD>::VertexValences(mesh);
  std::size_t qualityMismatches = 0;
  for (std::size_t i = 0; i < mesh.vert.size(); ++i) {
    redVertices += mesh.vert[i].cC() == Coloring::IrregularVertexColor();
    qualityMismatches += mesh.vert[i].cQ() != double(valence[i]);
  }
  EXPECT_EQ(qualityMismatches, 0u) << "vertex quality must be the valence";

  const nlohmann::json expected = CliReport(input);
  EXPECT_EQ(mesh.fn, expected["faces"].get<int>());
  EXPECT_EQ(red + magenta, expected["obtuse_faces"].get<std::size_t>());
  EXPECT_EQ(blue + magenta, expected["small_angle_faces"].get<std::size_t>());
  EXPECT_EQ(redVertices, expected["irregular_vertices"].get<std::size_t>());
  std::filesystem::remove_all(dir);
}

TEST_P(MeshlabServerOnMesh, QualityReportScriptLogsTheCliFigures) {
  const std::string input = SharedMesh(GetParam());
  const auto dir = TempDir("mls_report");
  const std::string logFile = (dir / "log.txt").string();
  const CommandResult r = Server("-l " + Quote(logFile) + " -i " + Quote(input) + " -s " +
                                 Quote(kScripts + "/quality_report.mlx"));
  ASSERT_EQ(r.exitCode, 0) << r.out << r.err;
  const std::string log = ReadFile(logFile) + r.out;
  const nlohmann::json expected = CliReport(input);
  auto row = [&log](const std::string& label) {
    std::smatch match;
    const std::regex pattern(label + R"(\s+(\S+))");
    return std::regex_search(log, match, pattern) ? match[1].str() : std::string("<missing>");
  };
  EXPECT_EQ(row("faces"), std::to_string(expected["faces"].get<int>())) << log;
  EXPECT_EQ(row("boundary edges"), std::to_string(expected["boundary_edges"].get<int>()));
  EXPECT_EQ(row("non-manifold vertices"), std::to_string(expected["non_manifold_vertices"].get<int>()));
  EXPECT_EQ(row("self-intersecting pairs"), std::to_string(expected["self_intersecting_pairs"].get<int>()));
  std::filesystem::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(SharedMeshes, MeshlabServerOnMesh, ::testing::ValuesIn(kMeshes),
                         [](const auto& testParam) {
                           std::string name = testParam.param.substr(0, testParam.param.find('.'));
                           for (char& c : name)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return name;
                         });

TEST(MeshlabServer, CleanThenCvtScriptsMatchTheCliPipeline) {
  // The defective marching-cubes mesh: cracks, non-manifold vertices, tiny components.
  const std::string input = SharedMesh("ubiquitin_1UBQ_edtsurf_mc.ply");
  const auto dir = TempDir("mls_cvt");
  const std::string viaServer = (dir / "server.ply").string();
  const std::string viaCli = (dir / "cli.ply").string();
  const CommandResult r = Server("-i " + Quote(input) + " -o " + Quote(viaServer) + " -s " +
                                 Quote(kScripts + "/clean_raw_mesh.mlx") + " -s " +
                                 Quote(kScripts + "/cvt_initialization.mlx"));
  ASSERT_EQ(r.exitCode, 0) << r.out << r.err;
  const CommandResult cli =
      molremesh::test::Run(Quote(kCli) + " remesh --quiet --stages clean,cvt " + Quote(input) + " " + Quote(viaCli));
  ASSERT_EQ(cli.exitCode, 0) << cli.err;

  const nlohmann::json server = CliReport(viaServer);
  const nlohmann::json direct = CliReport(viaCli);
  EXPECT_EQ(server["two_manifold"], true);
  EXPECT_EQ(server["boundary_edges"], 0);
  EXPECT_EQ(server["degenerate_faces"], 0);
  EXPECT_EQ(server["self_intersecting_pairs"], 0);
  EXPECT_EQ(server["genus"], direct["genus"]);
  EXPECT_EQ(server["faces"], direct["faces"]) << "the plugin and the CLI run the same pipeline";
  EXPECT_GE(server["angle_min_deg"].get<double>(), 30.0);
  EXPECT_GE(server["v567_percent"].get<double>(), 99.0);
  std::filesystem::remove_all(dir);
}

TEST(MeshlabServer, BadInputFailsWithOurMessageAndSavesNothing) {
  for (const auto& [fixture, message] : std::vector<std::pair<std::string, std::string>>{
           {"point_cloud.ply", "point cloud"}, {"nan_vertex.ply", "NaN"}}) {
    for (const char* script : {"quality_report.mlx", "color_bad_elements.mlx", "clean_raw_mesh.mlx",
                               "cvt_initialization.mlx", "random_segmentation.mlx", "patchwise_rar.mlx"}) {
      const auto dir = TempDir("mls_bad");
      const std::string output = (dir / "out.ply").string();
      const std::string logFile = (dir / "log.txt").string();
      const CommandResult r = Server("-l " + Quote(logFile) + " -i " + Quote(Fixture(fixture)) + " -o " +
                                     Quote(output) + " -s " + Quote(kScripts + "/" + script));
      // meshlabserver ends a failed script with exit(-1), i.e. status 255; a crash would be 128 + signal.
      EXPECT_EQ(r.exitCode, 255) << fixture << " " << script << "\n" << r.out << r.err;
      EXPECT_NE((ReadFile(logFile) + r.out + r.err).find(message), std::string::npos)
          << fixture << " " << script;
      EXPECT_FALSE(std::filesystem::exists(output)) << "a refused layer must not be saved";
      std::filesystem::remove_all(dir);
    }
  }
}

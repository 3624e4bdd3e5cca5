// The command-line tool on good and bad input: clear one-line errors, non-zero exit, no crash.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <initializer_list>
#include <numeric>
#include <random>
#include <vector>

#include <vcg_ext/io/mesh_io.h>
#include <wrap/io_trimesh/import_ply.h>
#include <vcg_ext/core/mesh_types.h>

#include "palette_counts.h"
#include "remeshing_test_meshes.h"
#include "test_helpers.h"

using namespace molremesh::test;

namespace {
const std::string kCli = MOLREMESH_CLI_PATH;

CommandResult Cli(const std::string& args) {
  return Run(Quote(kCli) + " " + args);
}

// A bad input must end with exit status 2 (not a signal, not success) and one error line
// naming the problem.
void ExpectInputError(const CommandResult& r, const std::string& expectedText) {
  EXPECT_EQ(r.exitCode, 2) << "stderr: " << r.err;
  EXPECT_NE(r.err.find("molremesh: error:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(expectedText), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

// A command-line mistake: exit status 1, one line "molremesh: error: ..." naming it, nothing on
// stdout, and no range printed in full double digits.
void ExpectUsageError(const CommandResult& r, const std::string& expectedText) {
  EXPECT_EQ(r.exitCode, 1) << "stderr: " << r.err;
  EXPECT_EQ(r.err.rfind("molremesh: error: ", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(expectedText), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("0.000000"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("179769"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

std::size_t LineCount(const std::string& text) {
  return std::size_t(std::count(text.begin(), text.end(), '\n'));
}

void ExpectMentions(const std::string& text, std::initializer_list<const char*> parts) {
  for (const char* part : parts) EXPECT_NE(text.find(part), std::string::npos) << part << "\n" << text;
}

nlohmann::json ReadJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}
} // namespace

TEST(Cli, MissingFile) {
  ExpectInputError(Cli("report /nonexistent/x.ply"), "no such file");
}
TEST(Cli, EmptyFile) {
  ExpectInputError(Cli("report " + Quote(Fixture("empty.ply"))), "the file is empty");
}
TEST(Cli, NotAMesh) {
  ExpectInputError(Cli("report " + Quote(Fixture("not_a_mesh.ply"))), "cannot read");
}
TEST(Cli, UnknownExtension) {
  ExpectInputError(Cli("report " + Quote(Fixture("../CMakeLists.txt"))), "unknown format");
}
TEST(Cli, PointCloud) {
  ExpectInputError(Cli("report " + Quote(Fixture("point_cloud.ply"))), "point cloud");
}
TEST(Cli, NanCoordinates) {
  ExpectInputError(Cli("report " + Quote(Fixture("nan_vertex.ply"))), "NaN");
}

TEST(Cli, UsageErrorExitsWithStatus1AndOneLine) {
  ExpectUsageError(Cli("report"), "input is required");
  ExpectUsageError(Cli(""), "a command is required (use report, color, remesh, surface)");
}

TEST(Cli, NonManifoldFanIsReportedNotRefused) {
  const CommandResult r = Cli("report --json " + Quote(Fixture("nonmanifold_fan.ply")));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["non_manifold_edges"], 1);
  EXPECT_GE(j["non_manifold_vertices"].get<int>(), 1);
  EXPECT_EQ(j["two_manifold"], false);
  EXPECT_TRUE(j["genus"].is_null());
}

TEST(Cli, DegenerateFacesAreReportedNotRefused) {
  const CommandResult r = Cli("report --json " + Quote(Fixture("degenerate_faces.ply")));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["degenerate_faces"], 2);
  EXPECT_EQ(j["faces"], 3);
}

TEST(Cli, ReportTableOnRealMesh) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  const CommandResult r = Cli("report " + Quote(SharedMesh("bpti_1bpi_msms.ply")));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  for (const char* row :
       {"Qmin", "V567", "obtuse faces", "genus", "self-intersecting pairs", "valence histogram"})
    EXPECT_NE(r.out.find(row), std::string::npos) << row;
}

TEST(Cli, ReportJsonOnRealMeshMatchesItsKnownDefects) {
  MOLREMESH_SKIP_WITHOUT_MESH("ubiquitin_1UBQ_edtsurf_mc.ply");
  // ubiquitin_1UBQ_edtsurf_mc.ply: per the data README, 36 boundary edges and 5 non-manifold vertices.
  const CommandResult r = Cli("report --json " + Quote(RealMesh("ubiquitin_1UBQ_edtsurf_mc.ply")));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["faces"], 11334);
  EXPECT_EQ(j["boundary_edges"], 36);
  EXPECT_EQ(j["non_manifold_vertices"], 5);
}

TEST(Cli, ReportIsTheSameForAnyThreadCount) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  // The raw 1MAH PyMOL surface has something for every figure (non-manifold edges, intersecting
  // pairs, several components); the report must not change by a digit with the thread count.
  const std::string in = Quote(SharedMesh("ache_1MAH_pymol_ses.ply"));
  const CommandResult one = Cli("report --json --threads 1 " + in);
  ASSERT_EQ(one.exitCode, 0) << one.err;
  for (const char* threads : {"2", "3"}) {
    const CommandResult many = Cli(std::string("report --json --threads ") + threads + " " + in);
    ASSERT_EQ(many.exitCode, 0) << many.err;
    EXPECT_EQ(many.out, one.out) << threads << " threads";
  }
}

TEST(Cli, ColorWritesPlyAndCountsMatchReport) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto dir = TempDir("cli_color");
  const std::string out = (dir / "colored.ply").string();
  const std::string in = SharedMesh("bpti_1bpi_msms.ply");
  const CommandResult color = Cli("color " + Quote(in) + " " + Quote(out));
  ASSERT_EQ(color.exitCode, 0) << color.err;
  const CommandResult report = Cli("report --json --no-self-intersections " + Quote(in));
  ASSERT_EQ(report.exitCode, 0) << report.err;
  const auto j = nlohmann::json::parse(report.out);
  EXPECT_NE(color.out.find("irregular vertices: " + std::to_string(j["irregular_vertices"].get<int>())),
            std::string::npos)
      << color.out;
  EXPECT_NE(color.out.find("obtuse faces (vermillion, or reddish purple): " +
                           std::to_string(j["obtuse_faces"].get<int>())),
            std::string::npos)
      << color.out;
  // The plugin's color-blind-safe colors: a face's color says its class, a vertex's its valence class.
  molremesh::MeshD colored;
  int mask = vcg::tri::io::Mask::IOM_VERTCOLOR | vcg::tri::io::Mask::IOM_FACECOLOR;
  ASSERT_EQ(vcg::tri::io::ImporterPLY<molremesh::MeshD>::Open(colored, out.c_str(), mask), 0);
  ASSERT_TRUE(mask & vcg::tri::io::Mask::IOM_FACECOLOR) << "face colors were not saved";
  const PaletteCounts counts =
      CountPaletteColors(colored, molremesh::BadElementColoring<molremesh::MeshD>::ColorBlindSafePalette());
  EXPECT_EQ(counts.obtuseFaces + counts.obtuseAndSmallFaces, j["obtuse_faces"].get<std::size_t>());
  EXPECT_EQ(counts.irregularVertices, j["irregular_vertices"].get<std::size_t>());
  std::filesystem::remove_all(dir);
}

TEST(Cli, ColorRefusesBadInputAndWritesNothing) {
  const auto dir = TempDir("cli_color_bad");
  const std::string out = (dir / "colored.ply").string();
  ExpectInputError(Cli("color " + Quote(Fixture("point_cloud.ply")) + " " + Quote(out)), "point cloud");
  EXPECT_FALSE(std::filesystem::exists(out));
  std::filesystem::remove_all(dir);
}

TEST(Cli, ReadsAndWritesPlyOffObjAndStl) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  // The segment stage leaves the geometry alone: a round trip through each format keeps the mesh.
  const auto dir = TempDir("cli_formats");
  const std::string in = SharedMesh("galactose_grasp.ply");
  const CommandResult original = Cli("report --json --no-self-intersections " + Quote(in));
  ASSERT_EQ(original.exitCode, 0) << original.err;
  const auto expected = nlohmann::json::parse(original.out);
  for (const char* extension : {"ply", "off", "obj", "stl"}) {
    const std::string out = (dir / (std::string("copy.") + extension)).string();
    const CommandResult write = Cli("remesh --quiet --stages segment " + Quote(in) + " " + Quote(out));
    ASSERT_EQ(write.exitCode, 0) << extension << ": " << write.err;
    const CommandResult read = Cli("report --json --no-self-intersections " + Quote(out));
    ASSERT_EQ(read.exitCode, 0) << extension << ": " << read.err;
    const auto j = nlohmann::json::parse(read.out);
    EXPECT_EQ(j["faces"], expected["faces"]) << extension;
    EXPECT_EQ(j["genus"], expected["genus"]) << extension;
    EXPECT_EQ(j["boundary_edges"], 0) << extension << ": STL's copies must be welded";
    EXPECT_NEAR(j["area"].get<double>(), expected["area"].get<double>(),
                1e-3 * expected["area"].get<double>());
  }
  std::filesystem::remove_all(dir);
}

TEST(Cli, RemeshRefusesBadInputAndUnknownStagesWritingNothing) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto dir = TempDir("cli_remesh_bad");
  const std::string out = (dir / "out.ply").string();
  ExpectInputError(Cli("remesh " + Quote(Fixture("nan_vertex.ply")) + " " + Quote(out)), "NaN");
  ExpectUsageError(
      Cli("remesh --stages clean,bogus " + Quote(SharedMesh("bpti_1bpi_msms.ply")) + " " + Quote(out)),
      "unknown stage 'bogus'");
  ExpectInputError(Cli("remesh --stages cvt " + Quote(Fixture("nonmanifold_fan.ply")) + " " + Quote(out)),
                   "stage 'cvt' failed");
  EXPECT_FALSE(std::filesystem::exists(out));
  std::filesystem::remove_all(dir);
}

// The clean stage's component threshold reaches the library: the EDTSurf 1MAH surface has two
// small closed components beside the protein's, of 314 faces (1.1 %) and 104 faces (0.4 %); by
// default (1 %) the smaller is removed (and counted), with --min-component-percent 0 both stay.
TEST(Cli, CleanComponentThresholdIsAnOption) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto dir = TempDir("cli_components");
  const std::string out = (dir / "out.ply").string();
  const std::string mesh = Quote(SharedMesh("ache_1MAH_edtsurf_vcmc.ply"));
  auto componentsAfterClean = [&](const std::string& options) {
    const CommandResult r = Cli("remesh --quiet --stages clean " + options + " " + mesh + " " + Quote(out));
    EXPECT_EQ(r.exitCode, 0) << r.err;
    const CommandResult report = Cli("report --json --no-self-intersections " + Quote(out));
    EXPECT_EQ(report.exitCode, 0) << report.err;
    return nlohmann::json::parse(report.out)["components"].get<int>();
  };
  // Its two cavities (314 and 104 faces) are kept by default and dropped only on request.
  EXPECT_EQ(componentsAfterClean(""), 3);
  EXPECT_EQ(componentsAfterClean("--min-component-percent 0"), 3);
  EXPECT_EQ(componentsAfterClean("--min-component-percent 1"), 2);
  const CommandResult bad = Cli("remesh --min-component-percent -1 " + mesh + " " + Quote(out));
  EXPECT_NE(bad.exitCode, 0);
  std::filesystem::remove_all(dir);
}

// The Phong lift of the projections is an option: on the GRASP galactose surface the lifted
// remesh keeps more of the input's area than the one on the flat triangles (measured: -0.18 % and
// -0.44 % of the raw area), and a share outside [0, 1] is refused.
TEST(Cli, SurfaceLiftIsAnOption) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto dir = TempDir("cli_surface_lift");
  const std::string out = (dir / "out.ply").string();
  const std::string mesh = Quote(SharedMesh("galactose_grasp.ply"));
  auto areaAfterRemesh = [&](const std::string& options) {
    const CommandResult r =
        Cli("remesh --quiet --stages clean,cvt,segment,rar " + options + " " + mesh + " " + Quote(out));
    EXPECT_EQ(r.exitCode, 0) << r.err;
    const CommandResult report = Cli("report --json " + Quote(out));
    EXPECT_EQ(report.exitCode, 0) << report.err;
    const nlohmann::json figures = nlohmann::json::parse(report.out);
    EXPECT_EQ(figures["self_intersecting_pairs"].get<int>(), 0);
    EXPECT_EQ(figures["two_manifold"].get<bool>(), true);
    return figures["area"].get<double>();
  };
  const CommandResult input = Cli("report --json --no-self-intersections " + mesh);
  ASSERT_EQ(input.exitCode, 0) << input.err;
  const double inputArea = nlohmann::json::parse(input.out)["area"].get<double>();
  const double lifted = areaAfterRemesh("");
  const double flat = areaAfterRemesh("--surface-lift 0");
  EXPECT_LT(std::abs(lifted - inputArea), std::abs(flat - inputArea));
  EXPECT_NE(Cli("remesh --surface-lift 1.5 " + mesh + " " + Quote(out)).exitCode, 0);
  std::filesystem::remove_all(dir);
}

// Two interpenetrating closed spheres form a tangle the clean stage's local steps cannot repair
// (no valid refill); its volumetric fallback rebuilds them as the boundary of their union, so the
// output is valid; with the fallback turned off it is written but invalid (exit status 3).
TEST(Cli, InterpenetratingSpheresAreRebuiltIntoAValidOutput) {
  const auto dir = TempDir("cli_invalid_output");
  molremesh::MeshD spheres, second;
  molremesh::test::Icosphere(spheres, 3);
  molremesh::test::Icosphere(second, 3, molremesh::test::Point(1.0, 0.13, 0.07));
  molremesh::test::AppendMesh(spheres, second);
  const std::string input = (dir / "two_spheres.off").string(), out = (dir / "out.ply").string(),
                    json = (dir / "out.json").string();
  std::string error;
  ASSERT_TRUE(molremesh::SaveMesh(spheres, input, error)) << error;
  const CommandResult r = Cli("remesh --quiet " + Quote(input) + " " + Quote(out) + " --json " + Quote(json));
  // The clean stage's volumetric fallback rebuilds the two interpenetrating spheres as their union:
  // the output is valid.
  EXPECT_EQ(r.exitCode, 0) << r.err;
  EXPECT_TRUE(std::filesystem::exists(out));
  const auto j = ReadJson(json);
  EXPECT_TRUE(j["verdict"]["valid"].get<bool>());
  // The figures agree: the written mesh has no intersecting pair.
  const auto report = nlohmann::json::parse(Cli("report --json " + Quote(out)).out);
  EXPECT_EQ(report["self_intersecting_pairs"].get<int>(), 0);
  // Without the fallback the tangle stays: the output is written, said to be invalid, exit status 3.
  const std::string invalidOut = (dir / "invalid.ply").string();
  const CommandResult kept =
      Cli("remesh --quiet --no-volumetric-fallback " + Quote(input) + " " + Quote(invalidOut));
  EXPECT_EQ(kept.exitCode, 3) << kept.err;
  EXPECT_TRUE(std::filesystem::exists(invalidOut));
  EXPECT_NE(kept.err.find("was written but is not a valid surface mesh"), std::string::npos) << kept.err;
  // The exit statuses are in the help text.
  EXPECT_NE(Cli("--help").out.find("3 output written but not a valid surface mesh"), std::string::npos);
  std::filesystem::remove_all(dir);
}

namespace {

/// A ball of radius 5 and, apart from it, a closed slab 0.1 thick, written to dir as an OFF file;
/// returns its path ("" when it could not be written).
std::string WriteBallAndSlab(const std::filesystem::path& dir) {
  molremesh::MeshD ball, slab;
  molremesh::test::Icosphere(ball, 3, molremesh::test::Point(0, 0, 0), molremesh::test::Point(5, 5, 5));
  molremesh::test::Icosphere(slab, 2, molremesh::test::Point(12, 0, 0), molremesh::test::Point(2, 2, 0.05));
  molremesh::test::AppendMesh(ball, slab);
  const std::string path = (dir / "ball_and_slab.off").string();
  std::string error;
  return molremesh::SaveMesh(ball, path, error) ? path : std::string();
}

} // namespace

// --volumetric-rebuild rebuilds a valid surface too: a slab far thinner than the mean edge, apart
// from a ball, is gone from the output; without the flag both stay.
TEST(Cli, VolumetricRebuildRemovesAPartThinnerThanTheEdges) {
  const auto dir = TempDir("cli_volumetric_rebuild");
  const std::string input = WriteBallAndSlab(dir), json = (dir / "out.json").string();
  ASSERT_FALSE(input.empty());
  auto componentsOut = [&](const std::string& flag) {
    const CommandResult r = Cli("remesh --quiet --stages clean " + flag + Quote(input) + " " +
                                Quote((dir / "out.ply").string()) + " --json " + Quote(json));
    EXPECT_EQ(r.exitCode, 0) << r.err;
    const auto j = ReadJson(json);
    EXPECT_TRUE(j["verdict"]["valid"].get<bool>());
    return j["output"]["components"].get<int>();
  };
  EXPECT_EQ(componentsOut(""), 2);
  EXPECT_EQ(componentsOut("--volumetric-rebuild "), 1);
  std::filesystem::remove_all(dir);
}

// By default a remesh whose angles miss [30, 90] degrees is made again from the rebuilt surface:
// the slab's rim keeps such angles, so the output is the ball alone and a note says so with both
// runs' figures; --no-rebuild-retry keeps the first remesh.
TEST(Cli, AnglesOutOfBoundsAreRemeshedAgainFromTheRebuiltSurfaceUnlessTurnedOff) {
  const auto dir = TempDir("cli_rebuild_retry");
  const std::string input = WriteBallAndSlab(dir), json = (dir / "out.json").string();
  ASSERT_FALSE(input.empty());
  auto remesh = [&](const std::string& flag) {
    const CommandResult r = Cli("remesh --quiet " + flag + Quote(input) + " " +
                                Quote((dir / "out.ply").string()) + " --json " + Quote(json));
    EXPECT_EQ(r.exitCode, 0) << r.err;
    return std::make_pair(r, ReadJson(json));
  };
  const auto [retried, j] = remesh("");
  EXPECT_TRUE(j["rebuild_retry"]["kept"].get<bool>()) << retried.err;
  EXPECT_FALSE(j["rebuild_retry"]["first"].get<bool>()); // made after the first run, not before
  EXPECT_EQ(j["output"]["components"].get<int>(), 1);
  EXPECT_GE(j["output"]["angle_min_deg"].get<double>(), 30.0 - 1e-9);
  EXPECT_LE(j["output"]["angle_max_deg"].get<double>(), 90.0 + 1e-9);
  EXPECT_NE(retried.err.find("note: "), std::string::npos) << retried.err;
  EXPECT_NE(retried.err.find("rebuilding the surface from a volume: kept"), std::string::npos) << retried.err;

  const auto [once, k] = remesh("--no-rebuild-retry ");
  EXPECT_FALSE(k["rebuild_retry"]["tried"].get<bool>());
  EXPECT_EQ(k["output"]["components"].get<int>(), 2);
  EXPECT_EQ(once.err.find("note: "), std::string::npos) << once.err;
  std::filesystem::remove_all(dir);
}

// One non-planar heptagon over seven vertices of an icosahedron: its fan of five triangles overlaps
// itself, which no local refill repairs, and it encloses no volume, so the volumetric rebuild has
// nothing to build. No valid surface can come of it: one error line, exit status 2, nothing written
// (only with the fallback turned off is the invalid remesh written, exit status 3).
TEST(Cli, ASelfOverlappingPolygonThatEnclosesNothingIsRefusedInOneLine) {
  const auto dir = TempDir("cli_enclosing_nothing");
  const std::string input = (dir / "heptagon.off").string(), out = (dir / "out.ply").string();
  const double a = 5.257311121191336, b = 8.5065080835204;
  std::ofstream(input) << "OFF\n7 1 0\n"
                       << -a << " " << b << " 0\n"
                       << a << " " << b << " 0\n"
                       << -a << " " << -b << " 0\n"
                       << a << " " << -b << " 0\n"
                       << "0 " << -a << " " << b << "\n"
                       << "0 " << a << " " << b << "\n"
                       << "0 " << -a << " " << -b << "\n"
                       << "7 0 1 2 3 4 5 6\n";
  const CommandResult r = Cli("remesh --quiet " + Quote(input) + " " + Quote(out));
  EXPECT_EQ(r.exitCode, 2) << r.err;
  EXPECT_EQ(r.err.rfind("molremesh: error: ", 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("encloses no volume"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(out));
  const CommandResult kept =
      Cli("remesh --quiet --no-volumetric-fallback " + Quote(input) + " " + Quote(out));
  EXPECT_EQ(kept.exitCode, 3) << kept.err;
  EXPECT_TRUE(std::filesystem::exists(out));
  std::filesystem::remove_all(dir);
}

// A hole longer than --max-hole-edges stays open: the output is valid (exit status 0) but not
// closed, and a warning says so and which limit kept the hole.
TEST(Cli, OpenOutputWarnsWhichLimitKeptTheHole) {
  const auto dir = TempDir("cli_open_output");
  molremesh::MeshD sphere;
  molremesh::test::Icosphere(sphere, 3);
  for (auto& f : sphere.face)
    if ((f.P(0)[2] + f.P(1)[2] + f.P(2)[2]) / 3 > 0.8)
      vcg::tri::Allocator<molremesh::MeshD>::DeleteFace(sphere, f);
  vcg::tri::Clean<molremesh::MeshD>::RemoveUnreferencedVertex(sphere);
  vcg::tri::Allocator<molremesh::MeshD>::CompactEveryVector(sphere);
  const std::string input = (dir / "open_sphere.off").string(), out = (dir / "out.ply").string(),
                    json = (dir / "out.json").string();
  std::string error;
  ASSERT_TRUE(molremesh::SaveMesh(sphere, input, error)) << error;
  const CommandResult r =
      Cli("remesh --quiet --max-hole-edges 4 " + Quote(input) + " " + Quote(out) + " --json " + Quote(json));
  EXPECT_EQ(r.exitCode, 0) << r.err;
  ExpectMentions(r.err, {"short of a target: not closed", "hole size limit of 4 edges"});
  EXPECT_EQ(r.err.find("not valid"), std::string::npos) << r.err;
  const auto j = ReadJson(json);
  EXPECT_TRUE(j["verdict"]["valid"].get<bool>());
  EXPECT_FALSE(j["verdict"]["all_targets_met"].get<bool>());
  // With the default limit the same hole is closed and every target is met, without a warning.
  const CommandResult closed = Cli("remesh --quiet " + Quote(input) + " " + Quote(out));
  EXPECT_EQ(closed.exitCode, 0) << closed.err;
  EXPECT_EQ(closed.err.find("warning"), std::string::npos) << closed.err;
  std::filesystem::remove_all(dir);
}

// A run that cannot fit in memory is refused before it starts (exit 2, nothing written) instead of
// growing until the kernel kills it: a target edge length 10^4 times below galactose's mean edge
// would make about 10^11 faces; --memory-limit sets the limit (1 MB: even galactose is over it) and
// -1 turns the check off.
TEST(Cli, RunBeyondTheMemoryLimitIsRefusedBeforeItStarts) {
  MOLREMESH_SKIP_WITHOUT_SHARED_DATA();
  const auto dir = TempDir("cli_memory");
  const std::string out = (dir / "out.ply").string();
  const std::string mesh = Quote(SharedMesh("galactose_grasp.ply"));
  const CommandResult tiny = Cli("remesh --quiet --target-length 0.0001 " + mesh + " " + Quote(out));
  ExpectInputError(tiny, "refused: the run would need about");
  ExpectMentions(tiny.err, {"MB of memory available", "output faces", "larger target edge length"});
  ExpectInputError(Cli("remesh --quiet --memory-limit 1 --stages clean,cvt " + mesh + " " + Quote(out)),
                   "more than the 1 MB memory limit");
  EXPECT_FALSE(std::filesystem::exists(out));
  const CommandResult unchecked = Cli(
      "remesh --quiet --memory-limit -1 --stages clean,cvt --cvt-iterations 2 " + mesh + " " + Quote(out));
  EXPECT_EQ(unchecked.exitCode, 0) << unchecked.err;
  EXPECT_TRUE(std::filesystem::exists(out));
  EXPECT_NE(Cli("remesh --memory-limit -2 " + mesh + " " + Quote(out)).exitCode, 0);
  std::filesystem::remove_all(dir);
}

// A header that declares more elements than the file holds (truncated, corrupt or hand-edited)
// made vcglib's importers allocate every declared element first: 2 * 10^9 faces ended in
// std::bad_alloc, a count just under the machine's memory would have been allocated and filled.
// Now the file's size is checked against the smallest size of what the header declares.
TEST(Cli, HeaderDeclaringMoreThanTheFileHoldsIsRefused) {
  const auto dir = TempDir("cli_header");
  const std::string triangle = "0 0 0\n1 0 0\n0 1 0\n";
  auto ply = [&](const std::string& name, const std::string& counts) {
    const std::string path = (dir / (name + ".ply")).string();
    std::ofstream(path) << "ply\nformat ascii 1.0\n"
                        << counts << "property list uchar int vertex_indices\nend_header\n"
                        << triangle << "3 0 1 2\n";
    return path;
  };
  const std::string vertexProps = "property float x\nproperty float y\nproperty float z\n";
  const std::string manyFaces =
      ply("many_faces", "element vertex 3\n" + vertexProps + "element face 2000000000\n");
  const std::string manyVertices =
      ply("many_vertices", "element vertex 300000000\n" + vertexProps + "element face 1\n");
  for (const std::string& path : {manyFaces, manyVertices}) {
    const CommandResult r = Cli("report " + Quote(path));
    ExpectInputError(r, "(truncated or corrupt)");
    ExpectMentions(r.err, {"its header declares", "but the file has"});
  }
  const std::string off = (dir / "many.off").string();
  std::ofstream(off) << "OFF\n3 1000000000 0\n" << triangle << "3 0 1 2\n";
  ExpectInputError(Cli("report " + Quote(off)), "declares 3 vertices and 1000000000 faces");
  // The same files with honest counts (and no newline after the last face) are read.
  const std::string honest = (dir / "honest.ply").string();
  std::ofstream(honest) << "ply\nformat ascii 1.0\nelement vertex 3\n"
                        << vertexProps
                        << "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                        << triangle << "3 0 1 2";
  EXPECT_EQ(Cli("report --no-self-intersections " + Quote(honest)).exitCode, 0);
  const std::string honestOff = (dir / "honest.off").string();
  std::ofstream(honestOff) << "OFF\n3 1 0\n" << triangle << "3 0 1 2";
  EXPECT_EQ(Cli("report --no-self-intersections " + Quote(honestOff)).exitCode, 0);
  std::filesystem::remove_all(dir);
}

// ------------------------------------------------------------------------------------------------
// The command-line contract: every value checked before any work, one line per mistake.
// ------------------------------------------------------------------------------------------------

TEST(CliArguments, UnknownCommandIsNamed) {
  ExpectUsageError(Cli("foo " + Quote(BundledMesh("lysozyme_Lys1_msms.ply"))),
                   "unknown command 'foo' (use report, color, remesh, surface)");
}

// Each value outside its range is refused up front with the option's name and a readable range:
// no stage runs, nothing is written (before, NaN took the default, seeds -1, 2^64 and 1e23 became
// 2^64 - 1, and --min-angle 0 or --obtuse-thresholds 180 failed a stage late).
TEST(CliArguments, ValuesOutOfRangeAreRefusedUpFront) {
  const auto dir = TempDir("cli_ranges");
  const std::string out = (dir / "out.ply").string();
  const std::string remesh =
      "remesh " + Quote(BundledMesh("lysozyme_Lys1_msms.ply")) + " " + Quote(out) + " ";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {remesh + "--target-length nan", "--target-length: 'nan' is not a finite number"},
      {remesh + "--target-length inf", "--target-length: 'inf' is not a finite number"},
      {remesh + "--target-length -1", "--target-length: -1 is not at least 0"},
      {remesh + "--seed -1", "--seed: '-1' is not a whole number in [0, 18446744073709551615]"},
      {remesh + "--seed 18446744073709551616", "--seed: '18446744073709551616' is not a whole number"},
      {remesh + "--seed 1e23", "--seed: '1e23' is not a whole number"},
      {remesh + "--min-angle 0", "--min-angle: 0 is not in (0, 59]"},
      {remesh + "--max-angle 200", "--max-angle: 200 is not in [61, 180]"},
      {remesh + "--obtuse-thresholds 110 180", "--obtuse-thresholds: 180 is not in [60, 180)"},
      {remesh + "--threads -1", "--threads: -1 is not in [0, 2147483647]"},
      {remesh + "--threads 1.5", "--threads: '1.5' is not a whole number in [0, 2147483647]"},
      {remesh + "--area-factor -1", "--area-factor: -1 is not at least 0"},
      {remesh + "--surface-lift 1.5", "--surface-lift: 1.5 is not in [0, 1]"},
      {remesh + "--memory-limit -2", "--memory-limit: -2 is not in [-1, 1e+12]"},
      {remesh + "--quiet --verbose", "--quiet excludes --verbose"},
      {remesh + "--stages clean,bogus", "--stages: unknown stage 'bogus'"},
      {"report --threads x " + Quote(BundledMesh("lysozyme_Lys1_msms.ply")),
       "--threads: 'x' is not a whole number"},
      {"report --memory-limit nan " + Quote(BundledMesh("lysozyme_Lys1_msms.ply")),
       "--memory-limit: 'nan' is not a finite number"},
      {"color --small-angle 70 " + Quote(BundledMesh("lysozyme_Lys1_msms.ply")) + " " + Quote(out),
       "--small-angle: 70 is not in [0, 60]"},
  };
  for (const auto& [args, message] : cases) {
    SCOPED_TRACE(args);
    ExpectUsageError(Cli(args), message);
  }
  EXPECT_FALSE(std::filesystem::exists(out));
  // The largest seed is a seed.
  EXPECT_EQ(Cli(remesh + "--quiet --stages segment --seed 18446744073709551615").exitCode, 0);
  std::filesystem::remove_all(dir);
}

// The output and --json paths are checked before any work, without destroying an existing file.
TEST(CliArguments, UnwritableOutputsAreRefusedBeforeAnyWork) {
  const auto dir = TempDir("cli_unwritable");
  const std::string in = Quote(BundledMesh("lysozyme_Lys1_msms.ply"));
  const std::string out = (dir / "out.ply").string();
  ExpectUsageError(Cli("remesh " + in + " /nonexistent/dir/out.ply"),
                   "cannot write the output '/nonexistent/dir/out.ply': No such file or directory");
  ExpectUsageError(Cli("remesh " + in + " " + Quote(dir.string())), "it is a directory");
  ExpectUsageError(Cli("remesh " + in + " " + Quote((dir / "out.xyz").string())), "unknown format");
  ExpectUsageError(Cli("remesh " + in + " " + Quote(out) + " --json /nonexistent/x.json"),
                   "cannot write the JSON file '/nonexistent/x.json'");
  ExpectUsageError(Cli("color " + in + " /nonexistent/dir/out.ply"), "cannot write the output");
  EXPECT_FALSE(std::filesystem::exists(out)) << "the probe leaves nothing behind";
  // An existing output survives a run that fails.
  std::ofstream(out) << "keep";
  ExpectInputError(Cli("remesh " + Quote(Fixture("nan_vertex.ply")) + " " + Quote(out)), "NaN");
  EXPECT_EQ(ReadFile(out), "keep");
  std::filesystem::remove_all(dir);
}

// A JSON file that cannot be written after the run is an error, not a silent exit 0.
TEST(CliArguments, JsonWriteFailureIsAnError) {
  if (!std::filesystem::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  const auto dir = TempDir("cli_json_full");
  const std::string out = (dir / "out.ply").string();
  const CommandResult r = Cli("remesh --stages segment " + Quote(BundledMesh("lysozyme_Lys1_msms.ply")) +
                              " " + Quote(out) + " --json /dev/full");
  EXPECT_EQ(r.exitCode, 2) << r.err;
  EXPECT_EQ(r.err, "molremesh: error: cannot write the JSON file '/dev/full' (" + out + " is written)\n");
  std::filesystem::remove_all(dir);
}

// More threads than the machine runs are clamped with a warning; the output is the same bytes.
TEST(CliArguments, ThreadCountsAreClampedWithAWarning) {
  const auto dir = TempDir("cli_threads");
  const std::string in = Quote(BundledMesh("lysozyme_Lys1_msms.ply"));
  const std::string one = (dir / "one.ply").string(), many = (dir / "many.ply").string();
  const CommandResult r1 =
      Cli("remesh --quiet --stages clean,cvt --cvt-iterations 3 --threads 1 " + in + " " + Quote(one));
  ASSERT_EQ(r1.exitCode, 0) << r1.err;
  const CommandResult rMany =
      Cli("remesh --quiet --stages clean,cvt --cvt-iterations 3 --threads 100000 " + in + " " + Quote(many));
  ASSERT_EQ(rMany.exitCode, 0) << rMany.err;
  EXPECT_EQ(LineCount(rMany.err), 1u) << rMany.err;
  ExpectMentions(rMany.err, {"molremesh: warning: --threads 100000 is more than 4 per core", "; using "});
  EXPECT_EQ(ReadFile(one), ReadFile(many));
  const CommandResult report = Cli("report --json --threads 100000 " + in);
  EXPECT_EQ(report.exitCode, 0) << report.err;
  EXPECT_EQ(report.out, Cli("report --json --threads 1 " + in).out);
  std::filesystem::remove_all(dir);
}

// Threads the system refuses to start (here: address space for their stacks) leave their work to
// the threads that run: the same figures, not std::terminate (exit 134 before).
TEST(CliArguments, ThreadsThatCannotStartAreNotAnAbort) {
  const std::string in = Quote(BundledMesh("lysozyme_Lys1_msms.ply"));
  auto limited = [&](const char* threads) {
    return molremesh::test::Run("bash -c \"ulimit -v 60000 && " + Quote(kCli) + " report --json --threads " +
                                threads + " " + in + "\"");
  };
  const CommandResult one = limited("1");
  if (one.exitCode != 0) GTEST_SKIP() << "60 MB of address space is too little for this build: " << one.err;
  const CommandResult eight = limited("8");
  EXPECT_EQ(eight.exitCode, 0) << eight.err;
  EXPECT_EQ(eight.out, one.out);
}

// The self-intersection count of `report` is checked against the memory budget: on a soup of
// overlapping triangles its candidate pairs grow with the square of the face count, so beyond the
// limit the figure is skipped with one warning (the other figures are printed); -1 turns it off.
TEST(CliArguments, ReportSkipsTheSelfIntersectionCountBeyondTheMemoryLimit) {
  const auto dir = TempDir("cli_report_budget");
  const std::string soup = (dir / "soup.off").string();
  const int n = 2000; // long triangles through one point: every pair overlaps
  {
    std::ofstream off(soup);
    off << "OFF\n" << 3 * n << ' ' << n << " 0\n";
    for (int i = 0; i < n; ++i) {
      const double a = 3.14159265358979 * i / n, c = std::cos(a), s = std::sin(a);
      off << c << ' ' << s << " -0.1\n"
          << -c << ' ' << -s << " 0.1\n"
          << 0.01 * s << ' ' << 0.01 * c << " 1\n";
    }
    for (int i = 0; i < n; ++i) off << "3 " << 3 * i << ' ' << 3 * i + 1 << ' ' << 3 * i + 2 << '\n';
  }
  const CommandResult skipped = Cli("report --json --memory-limit 100 " + Quote(soup));
  ASSERT_EQ(skipped.exitCode, 0) << skipped.err;
  EXPECT_EQ(LineCount(skipped.err), 1u) << skipped.err;
  ExpectMentions(skipped.err,
                 {"molremesh: warning: the self-intersection count would need up to", "candidate pairs",
                  "more than the 100 MB memory limit", "not counted", "--memory-limit MB sets the limit"});
  const auto partial = nlohmann::json::parse(skipped.out);
  EXPECT_EQ(partial["faces"], n);
  EXPECT_TRUE(partial["self_intersecting_pairs"].is_null());
  const CommandResult counted = Cli("report --json --memory-limit -1 " + Quote(soup));
  ASSERT_EQ(counted.exitCode, 0) << counted.err;
  EXPECT_TRUE(counted.err.empty()) << counted.err;
  EXPECT_GT(nlohmann::json::parse(counted.out)["self_intersecting_pairs"].get<int>(), n);
  // A molecular surface is counted under the default limit, without a warning.
  const CommandResult real = Cli("report --json " + Quote(BundledMesh("lysozyme_Lys1_msms.ply")));
  EXPECT_EQ(real.exitCode, 0);
  EXPECT_TRUE(real.err.empty()) << real.err;
  EXPECT_FALSE(nlohmann::json::parse(real.out)["self_intersecting_pairs"].is_null());
  EXPECT_NE(Cli("report --help").out.find("--memory-limit"), std::string::npos);
  std::filesystem::remove_all(dir);
}

// A 350 KB binary PLY of 320 random 255-gons: `report` and `remesh` ran for hours and took tens of
// GB (3.3e9 candidate pairs of faces). Now report skips the count with one warning, remesh refuses
// with one error line.
TEST(CliArguments, ASoupOfLargeOverlappingPolygonsIsAnsweredAtOnce) {
  const auto dir = TempDir("cli_polygon_soup");
  const std::string soup = (dir / "soup.ply").string();
  {
    std::mt19937 rng(29);
    std::uniform_real_distribution<float> coordinate(-10, 10);
    std::ofstream ply(soup, std::ios::binary);
    ply << "ply\nformat binary_little_endian 1.0\nelement vertex 2000\nproperty float x\nproperty float y\n"
           "property float z\nelement face 320\nproperty list uchar int vertex_indices\nend_header\n";
    for (int i = 0; i < 3 * 2000; ++i) {
      const float x = coordinate(rng);
      ply.write(reinterpret_cast<const char*>(&x), sizeof x);
    }
    std::vector<std::int32_t> order(2000);
    std::iota(order.begin(), order.end(), 0);
    for (int polygon = 0; polygon < 320; ++polygon) {
      std::shuffle(order.begin(), order.end(), rng);
      const unsigned char sides = 255;
      ply.write(reinterpret_cast<const char*>(&sides), 1);
      ply.write(reinterpret_cast<const char*>(order.data()), 255 * sizeof(std::int32_t));
    }
  }
  const CommandResult report = Cli("report --json " + Quote(soup));
  ASSERT_EQ(report.exitCode, 0) << report.err;
  EXPECT_EQ(LineCount(report.err), 1u) << report.err;
  ExpectMentions(report.err, {"molremesh: warning: the self-intersection count would test", "candidate pairs",
                              "more than its bound", "not counted"});
  EXPECT_EQ(nlohmann::json::parse(report.out)["faces"], 320 * 253);
  const CommandResult remesh = Cli("remesh --quiet " + Quote(soup) + " " + Quote((dir / "out.ply").string()));
  EXPECT_EQ(remesh.exitCode, 2);
  EXPECT_EQ(LineCount(remesh.err), 1u) << remesh.err;
  ExpectMentions(remesh.err, {"molremesh: error:", "the faces overlap beyond repair"});
  EXPECT_FALSE(std::filesystem::exists(dir / "out.ply"));
  std::filesystem::remove_all(dir);
}

// ------------------------------------------------------------------------------------------------
// Output levels of remesh, on the bundled lysozyme surface (runs from a clone alone).
// ------------------------------------------------------------------------------------------------

// Default: one summary line on stderr (no progress: stderr is not a terminal here), nothing on stdout.
TEST(CliOutputLevels, DefaultIsOneSummaryLine) {
  const auto dir = TempDir("cli_level_default");
  const std::string in = BundledMesh("lysozyme_Lys1_msms.ply"), out = (dir / "out.ply").string();
  const CommandResult r = Cli("remesh " + Quote(in) + " " + Quote(out));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_EQ(LineCount(r.err), 1u) << r.err;
  EXPECT_EQ(r.err.rfind("molremesh: " + in + " -> " + out + ": 14398 -> ", 0), 0u) << r.err;
  ExpectMentions(r.err,
                 {" faces, θmin 0.0° -> ", "θmax 176.3° -> ", "V567 93.17 % -> ", "SI 0 -> 0, ", " s\n"});
  // The figures are the output's: its face count is the one the report gives.
  const auto report = nlohmann::json::parse(Cli("report --json --no-self-intersections " + Quote(out)).out);
  EXPECT_NE(r.err.find("14398 -> " + std::to_string(report["faces"].get<int>()) + " faces"),
            std::string::npos);
  std::filesystem::remove_all(dir);
}

// --quiet: nothing at all on success; --verbose: progress, the per-stage table and the summaries;
// --json: the same file at every level.
TEST(CliOutputLevels, QuietPrintsNothingAndVerbosePrintsTheStageTables) {
  const auto dir = TempDir("cli_levels");
  const std::string in = Quote(BundledMesh("lysozyme_Lys1_msms.ply"));
  const std::string stages = "--stages clean,cvt,valence --cvt-iterations 3 ";
  auto run = [&](const std::string& level) {
    const std::string out = Quote((dir / "out.ply").string()),
                      json = Quote((dir / (level + ".json")).string());
    return Cli("remesh " + stages + level + " " + in + " " + out + " --json " + json);
  };
  const CommandResult quiet = run("--quiet");
  ASSERT_EQ(quiet.exitCode, 0) << quiet.err;
  EXPECT_TRUE(quiet.out.empty()) << quiet.out;
  EXPECT_TRUE(quiet.err.empty()) << quiet.err;
  const CommandResult verbose = run("--verbose");
  ASSERT_EQ(verbose.exitCode, 0) << verbose.err;
  ExpectMentions(verbose.out, {"Remeshed ", "V567", "stage times (s): clean=", "-- clean:", "-- valence:"});
  ExpectMentions(verbose.err, {"molremesh: stage clean", "molremesh: stage valence", " -> "});
  auto withoutTimes = [](nlohmann::json j) {
    j.erase("seconds");
    for (auto& stage : j["stages"]) stage.erase("seconds");
    return j;
  };
  const auto quietJson = withoutTimes(ReadJson((dir / "--quiet.json").string()));
  EXPECT_EQ(quietJson, withoutTimes(ReadJson((dir / "--verbose.json").string())));
  EXPECT_EQ(quietJson["stages"].size(), 3u);
  std::filesystem::remove_all(dir);
}

// A fresh clone with no ../shared beside it: the bundled data are there (under 2 MB) and the
// demo's CLI part (report, color, full pipeline on each bundled mesh) runs on them.
TEST(CliFromAClone, DemoRunsOnTheBundledData) {
  if (std::system("git --version >/dev/null 2>&1") != 0) GTEST_SKIP() << "git not found";
  const auto dir = TempDir("cli_clone");
  const auto clone = dir / "molremesh";
  ASSERT_FALSE(std::filesystem::exists(dir / "shared"));
  const CommandResult cloned =
      molremesh::test::Run("git clone -q " + Quote(MOLREMESH_SOURCE_DIR) + " " + Quote(clone.string()));
  ASSERT_EQ(cloned.exitCode, 0) << cloned.err;
  std::uintmax_t bytes = 0;
  for (const auto& entry : std::filesystem::directory_iterator(clone / "data")) bytes += entry.file_size();
  EXPECT_LT(bytes, 2u << 20);
  const auto out = dir / "demo_output";
  const CommandResult demo =
      molremesh::test::Run("MOLREMESH=" + Quote(kCli) + " OUT_DIR=" + Quote(out.string()) + " bash " +
                           Quote((clone / "scripts" / "demo.sh").string()) + " --cli-only");
  ASSERT_EQ(demo.exitCode, 0) << demo.out << demo.err;
  for (const char* mesh : {"lysozyme_Lys1_msms", "ubiquitin_1UBQ_edtsurf_mc"}) {
    ExpectMentions(demo.out, {"quality report (CLI)", "V567", "irregular vertices: "});
    for (const char* suffix : {"_colored.ply", "_remeshed.ply", "_remeshed.json", "_remeshed_colored.ply"})
      EXPECT_TRUE(std::filesystem::exists(out / (std::string(mesh) + suffix))) << mesh << suffix;
    const auto j = ReadJson((out / (std::string(mesh) + "_remeshed.json")).string());
    EXPECT_TRUE(j["verdict"]["valid"].get<bool>()) << mesh;
  }
  // One summary line per remesh run, and no warning.
  EXPECT_EQ(LineCount(demo.err), 2u) << demo.err;
  EXPECT_EQ(demo.err.find("warning"), std::string::npos) << demo.err;
  std::filesystem::remove_all(dir);
}

// remesh --region: the listed faces of a sphere are remeshed alone; every other face comes out
// first, with the same corners, in the same order; bad region files are refused writing nothing.
TEST(Cli, RegionRemeshKeepsTheOtherFacesAndRefusesBadFaceLists) {
  const auto dir = TempDir("cli_region");
  const std::string in = (dir / "sphere.ply").string(), out = (dir / "out.ply").string();
  molremesh::MeshD sphere;
  Icosphere(sphere, 3);
  std::string error;
  ASSERT_TRUE(molremesh::SaveMesh(sphere, in, error)) << error;
  molremesh::MeshD input;
  ASSERT_TRUE(molremesh::LoadMesh(input, in, error)) << error;
  std::vector<bool> inRegion(input.face.size(), false);
  {
    std::ofstream region(dir / "region.txt");
    for (std::size_t fi = 0; fi < input.face.size(); ++fi)
      if (input.face[fi].cP(0)[2] > 0.7 && input.face[fi].cP(1)[2] > 0.7 && input.face[fi].cP(2)[2] > 0.7) {
        inRegion[fi] = true;
        region << fi << (fi % 2 ? "\n" : " ");
      }
  }
  const CommandResult r = Cli("remesh " + Quote(in) + " " + Quote(out) + " --target-length 0.05 --region " +
                              Quote((dir / "region.txt").string()));
  ASSERT_EQ(r.exitCode, 0) << r.err;
  ExpectMentions(r.err, {"region", "border vertices kept"});
  molremesh::MeshD output;
  ASSERT_TRUE(molremesh::LoadMesh(output, out, error)) << error;
  std::size_t kept = 0;
  for (std::size_t fi = 0; fi < input.face.size(); ++fi) {
    if (inRegion[fi]) continue;
    ASSERT_LT(kept, output.face.size());
    for (int k = 0; k < 3; ++k) ASSERT_TRUE(output.face[kept].cP(k) == input.face[fi].cP(k)) << "face " << fi;
    ++kept;
  }
  EXPECT_GT(output.face.size(), input.face.size()); // the cap at a finer target length
  std::filesystem::remove(out);

  auto withList = [&](const std::string& list) {
    std::ofstream(dir / "list.txt") << list;
    return Cli("remesh " + Quote(in) + " " + Quote(out) + " --region " + Quote((dir / "list.txt").string()));
  };
  ExpectUsageError(withList("1 2 x"), "not a face index");
  ExpectUsageError(withList("3 -4"), "not a face index");
  ExpectUsageError(withList("5 7 5"), "listed twice");
  ExpectUsageError(withList(""), "lists no face");
  ExpectInputError(withList("0 99999"), "out of range");
  ExpectUsageError(
      Cli("remesh " + Quote(in) + " " + Quote(out) + " --region " + Quote((dir / "none.txt").string())),
      "cannot read");
  EXPECT_FALSE(std::filesystem::exists(out));
  std::filesystem::remove_all(dir);
}

// Small helpers shared by the test programs: paths to data and running a command.
#pragma once

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <sys/wait.h>

/// First statement of a test on the shared meshes: skips it, saying why, when they are missing.
#define MOLREMESH_SKIP_WITHOUT_SHARED_DATA()                                                                 \
  if (!::molremesh::test::SharedDataFound())                                                                 \
  GTEST_SKIP() << "shared data not found at " MOLREMESH_SHARED_DATA_DIR                                      \
                  "/meshes: this test needs the real molecular meshes (configure MOLREMESH_SHARED_DATA_DIR)"

/// First statement of a test on the real mesh `name`: skips it, saying why, when neither the
/// repository's data/ nor the shared data has it.
#define MOLREMESH_SKIP_WITHOUT_MESH(name)                                                                    \
  if (!std::filesystem::exists(::molremesh::test::RealMesh(name)))                                           \
  GTEST_SKIP() << "shared data not found at " MOLREMESH_SHARED_DATA_DIR                                      \
                  "/meshes: this test needs the real molecular meshes (configure MOLREMESH_SHARED_DATA_DIR)"

namespace molremesh::test {

inline std::string SharedMesh(const std::string& name) {
  return std::string(MOLREMESH_SHARED_DATA_DIR) + "/meshes/" + name;
}
/// A mesh bundled with the repository (data/): there in every clone.
inline std::string BundledMesh(const std::string& name) {
  return std::string(MOLREMESH_BUNDLED_DATA_DIR) + "/" + name;
}
/// A real mesh: its bundled copy when data/ has one (the same bytes), else the shared one.
inline std::string RealMesh(const std::string& name) {
  const std::string bundled = BundledMesh(name);
  return std::filesystem::exists(bundled) ? bundled : SharedMesh(name);
}
inline std::string SharedStructure(const std::string& name) {
  return std::string(MOLREMESH_SHARED_DATA_DIR) + "/structures/" + name;
}
/// Whether the shared molecular meshes are there; the tests on them skip when they are not.
inline bool SharedDataFound() {
  return std::filesystem::is_directory(std::string(MOLREMESH_SHARED_DATA_DIR) + "/meshes");
}
inline std::string Fixture(const std::string& name) {
  return std::string(MOLREMESH_TEST_DATA_DIR) + "/" + name;
}

/// A fresh empty folder under the system temp dir, removed by the caller when it wants.
inline std::filesystem::path TempDir(const std::string& tag) {
  auto dir =
      std::filesystem::temp_directory_path() / ("molremesh_test_" + tag + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

struct CommandResult {
  int exitCode = -1;    ///< exit status, or 128 + signal number when killed by a signal
  std::string out, err; ///< captured stdout and stderr
};

inline std::string ReadFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

/// Runs a shell command line, capturing stdout and stderr in files next to nothing else.
inline CommandResult Run(const std::string& commandLine) {
  static int counter = 0;
  const auto dir = std::filesystem::temp_directory_path();
  const std::string stem = "molremesh_cmd_" + std::to_string(::getpid()) + "_" + std::to_string(counter++);
  const auto outPath = dir / (stem + ".out");
  const auto errPath = dir / (stem + ".err");
  const std::string full = commandLine + " >" + outPath.string() + " 2>" + errPath.string();
  const int status = std::system(full.c_str());
  CommandResult result;
  if (status != -1 && WIFEXITED(status))
    result.exitCode = WEXITSTATUS(status);
  else if (status != -1 && WIFSIGNALED(status))
    result.exitCode = 128 + WTERMSIG(status);
  result.out = ReadFile(outPath);
  result.err = ReadFile(errPath);
  std::filesystem::remove(outPath);
  std::filesystem::remove(errPath);
  return result;
}

inline std::string Quote(const std::string& s) {
  return "'" + s + "'";
}

} // namespace molremesh::test

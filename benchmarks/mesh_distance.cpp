// mesh_distance: surface distance between two meshes, as JSON, for the benchmark runner.
//
//   mesh_distance A B [--samples N] [--seed S] [--threads T]
//       one-sided distances A->B and B->A (vertices plus N area-uniform samples per side;
//       default N = the side's face count) and the symmetric Hausdorff distance
//   mesh_distance --stats A
//       only the size figures of A (counts, mean edge length, bounding-box diagonal, area)
//
// Independent of the molremesh CLI on purpose: the benchmark must measure other tools' outputs
// with a yardstick that does not change when the CLI does. Exit status 0 on success, 2 when a
// mesh cannot be read or measured, 1 for usage errors; the message is one line on stderr.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdlib>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include <vcg_ext/io/mesh_io.h>
#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/surface/surface_distance.h>

namespace {

using molremesh::MeshD;
using Distance = molremesh::SurfaceDistance<MeshD, MeshD>;

constexpr const char* kUsage = "usage: mesh_distance A B [--samples N] [--seed S] [--threads T]\n"
                               "       mesh_distance --stats A\n";

/// Counts and sizes of m. The mean edge length is over distinct undirected edges of faces with
/// three distinct vertices and finite corners, as in `molremesh report`.
nlohmann::json Stats(const MeshD& m, const std::string& path) {
  using molremesh::IsFinite;
  std::vector<std::pair<std::size_t, std::size_t>> edges;
  std::size_t faces = 0;
  double area = 0;
  vcg::Box3d box;
  for (const auto& f : m.face) {
    if (f.IsD()) continue;
    ++faces;
    std::array<std::size_t, 3> v;
    for (int i = 0; i < 3; ++i) v[i] = std::size_t(vcg::tri::Index(m, f.cV(i)));
    if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]) continue;
    for (int i = 0; i < 3; ++i)
      edges.emplace_back(std::min(v[i], v[(i + 1) % 3]), std::max(v[i], v[(i + 1) % 3]));
    const auto &p0 = f.cP(0), &p1 = f.cP(1), &p2 = f.cP(2);
    if (IsFinite(p0) && IsFinite(p1) && IsFinite(p2)) area += 0.5 * ((p1 - p0) ^ (p2 - p0)).Norm();
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  double sum = 0;
  std::size_t counted = 0;
  for (const auto& [a, b] : edges) {
    const auto &pa = m.vert[a].cP(), &pb = m.vert[b].cP();
    if (!IsFinite(pa) || !IsFinite(pb)) continue;
    sum += (pa - pb).Norm();
    ++counted;
  }
  std::size_t vertices = 0;
  for (const auto& v : m.vert)
    if (!v.IsD()) {
      ++vertices;
      if (IsFinite(v.cP())) box.Add(v.cP());
    }
  return {{"file", path},
          {"vertices", vertices},
          {"faces", faces},
          {"edges", edges.size()},
          {"mean_edge_length", counted > 0 ? sum / double(counted) : 0.0},
          {"bbox_diagonal", box.IsNull() ? 0.0 : box.Diag()},
          {"area", area}};
}

nlohmann::json ToJson(const molremesh::OneSidedDistance& d) {
  return {{"max", d.max},
          {"mean", d.mean},
          {"rms", d.rms},
          {"vertex_max", d.vertexMax},
          {"vertex_mean", d.vertexMean},
          {"face_sample_max", d.faceMax},
          {"face_sample_mean", d.faceMean},
          {"vertex_samples", d.vertexSamples},
          {"face_samples", d.faceSamples},
          {"max_at", {d.maxAt[0], d.maxAt[1], d.maxAt[2]}}};
}

bool Load(MeshD& m, const std::string& path) {
  std::string error;
  if (molremesh::LoadMesh(m, path, error)) return true;
  std::cerr << "mesh_distance: error: " << error << '\n';
  return false;
}

std::size_t ParseCount(const std::string& flag, const char* text) {
  char* end = nullptr;
  const unsigned long long value = std::strtoull(text, &end, 10);
  if (end == text || *end != '\0') {
    std::cerr << "mesh_distance: error: " << flag << " needs a non-negative integer, got '" << text << "'\n"
              << kUsage;
    std::exit(1);
  }
  return std::size_t(value);
}

} // namespace

int main(int argc, char** argv) {
  std::vector<std::string> files;
  bool statsOnly = false;
  Distance::Params params;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto next = [&]() -> const char* {
      if (i + 1 >= argc) {
        std::cerr << "mesh_distance: error: " << arg << " needs a value\n" << kUsage;
        std::exit(1);
      }
      return argv[++i];
    };
    if (arg == "--stats")
      statsOnly = true;
    else if (arg == "--samples")
      params.faceSamples = ParseCount(arg, next());
    else if (arg == "--seed")
      params.seed = ParseCount(arg, next());
    else if (arg == "--threads")
      params.threads = unsigned(std::max<std::size_t>(1, ParseCount(arg, next())));
    else if (arg == "-h" || arg == "--help") {
      std::cout << kUsage;
      return 0;
    } else if (!arg.empty() && arg[0] == '-') {
      std::cerr << "mesh_distance: error: unknown option " << arg << '\n' << kUsage;
      return 1;
    } else
      files.push_back(arg);
  }
  if (files.size() != (statsOnly ? 1u : 2u)) {
    std::cerr << kUsage;
    return 1;
  }

  MeshD a, b;
  if (!Load(a, files[0])) return 2;
  nlohmann::json out;
  out["a"] = Stats(a, files[0]);
  if (!statsOnly) {
    if (!Load(b, files[1])) return 2;
    out["b"] = Stats(b, files[1]);
    const auto start = std::chrono::steady_clock::now();
    const molremesh::SymmetricDistance d = Distance::Symmetric(a, b, params);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!d.ok) {
      std::cerr << "mesh_distance: error: " << d.message << '\n';
      return 2;
    }
    out["a_to_b"] = ToJson(d.aToB);
    out["b_to_a"] = ToJson(d.bToA);
    out["hausdorff"] = d.hausdorff;
    out["seconds"] = seconds;
  }
  std::cout << out.dump(2) << '\n';
  return 0;
}

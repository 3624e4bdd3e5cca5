// Runs the volumetric rebuild on one mesh file and prints its figures as JSON (the broken-surface
// measurements of docs/design.md): usage volumetric_rebuild IN [OUT] [--voxel H] [--threads N]
// [--defects-only] (only the input's defects, welded: no rebuild).
#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/io/mesh_io.h>
#include <vcg_ext/quality/mesh_quality.h>
#include <vcg_ext/volume/volumetric_rebuild.h>

#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdlib>
#include <iostream>
#include <string>

int main(int argc, char** argv) {
  using namespace molremesh;
  std::string in, out;
  bool defectsOnly = false;
  VolumetricRebuild<MeshD>::Params params;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--voxel" && i + 1 < argc)
      params.voxelSize = std::atof(argv[++i]);
    else if (a == "--threads" && i + 1 < argc)
      params.threads = std::atoi(argv[++i]);
    else if (a == "--defects-only")
      defectsOnly = true;
    else if (in.empty())
      in = a;
    else
      out = a;
  }
  if (in.empty()) {
    std::cerr << "usage: volumetric_rebuild IN [OUT] [--voxel H] [--threads N] [--defects-only]\n";
    return 2;
  }
  MeshD m;
  std::string error;
  if (!LoadMesh(m, in, error)) {
    std::cerr << "volumetric_rebuild: " << error << "\n";
    return 1;
  }
  // The input's defects as a welded mesh (a PyMOL OBJ is a soup: every corner its own vertex).
  nlohmann::json defects;
  {
    MeshD welded;
    vcg::tri::Append<MeshD, MeshD>::MeshCopy(welded, m);
    vcg::tri::Clean<MeshD>::RemoveDuplicateVertex(welded);
    vcg::tri::Allocator<MeshD>::CompactEveryVector(welded);
    MeshQuality<MeshD>::Params p;
    p.threads = params.threads;
    const QualityReport q = MeshQuality<MeshD>::Compute(welded, p);
    const ClosedComponents c = MeasureClosedComponents(welded);
    defects = {{"faces", q.faces},
               {"non_manifold_edges", q.nonManifoldEdges},
               {"non_manifold_vertices", q.nonManifoldVertices},
               {"boundary_edges", q.boundaryEdges},
               {"degenerate_faces", q.degenerateFaces},
               {"si_pairs", q.selfIntersectingPairs},
               {"adjacent_overlap_pairs", q.adjacentOverlapPairs},
               {"misoriented_edges", c.misorientedEdges},
               {"components", q.components},
               {"volume", q.volume},
               {"area", q.area}};
  }
  if (defectsOnly) {
    std::cout << nlohmann::json{{"input", in}, {"input_welded", defects}}.dump() << "\n";
    return 0;
  }
  const auto start = std::chrono::steady_clock::now();
  const VolumetricRebuild<MeshD>::Result r = VolumetricRebuild<MeshD>::Do(m, params);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  nlohmann::json j = {{"input", in},
                      {"ok", r.ok},
                      {"message", r.message},
                      {"seconds", seconds},
                      {"faces_in", r.facesIn},
                      {"faces_out", r.facesOut},
                      {"volume_in", r.volumeIn},
                      {"volume_out", r.volumeOut},
                      {"area_in", r.areaIn},
                      {"area_out", r.areaOut},
                      {"voxel_size", r.voxelSize},
                      {"voxels", r.voxels},
                      {"estimated_mb", r.estimatedMB},
                      {"regions", r.regions},
                      {"inside_regions", r.insideRegions},
                      {"sealed_slit_voxels", r.sealedSlitVoxels},
                      {"orientation_sign", r.orientationSign},
                      {"bodies", r.bodies},
                      {"cavities", r.cavities}};
  j["input_welded"] = defects;
  if (r.ok) {
    const QualityReport q = MeshQuality<MeshD>::Compute(m);
    const ClosedComponents c = MeasureClosedComponents(m);
    j["output"] = {{"boundary_edges", q.boundaryEdges},
                   {"non_manifold_edges", q.nonManifoldEdges},
                   {"non_manifold_vertices", q.nonManifoldVertices},
                   {"degenerate_faces", q.degenerateFaces},
                   {"si_pairs", q.selfIntersectingPairs + q.adjacentOverlapPairs},
                   {"misoriented_edges", c.misorientedEdges},
                   {"components", q.components},
                   {"genus", q.genus},
                   {"angle_min", q.angleMin},
                   {"angle_max", q.angleMax},
                   {"component_volumes", c.volumes}};
  }
  std::cout << j.dump() << "\n";
  if (r.ok && !out.empty() && !SaveMesh(m, out, error)) {
    std::cerr << "volumetric_rebuild: " << error << "\n";
    return 1;
  }
  return r.ok ? 0 : 3;
}

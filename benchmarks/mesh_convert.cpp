// mesh_convert IN OUT: rewrites a mesh in the format of OUT's extension (.ply, .off, .obj, .stl)
// with LoadMesh and vcglib's writer, geometry and faces only. The benchmark runner uses it to hand
// TetGen an ASCII OFF whatever wrote the mesh. Exit status 0, or 2 with one line on stderr.
#include <iostream>
#include <string>

#include <vcg_ext/io/mesh_io.h>
#include <vcg_ext/core/mesh_types.h>

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: mesh_convert IN OUT\n";
    return 1;
  }
  molremesh::MeshD m;
  std::string error;
  if (!molremesh::LoadMesh(m, argv[1], error) || !molremesh::SaveMesh(m, argv[2], error)) {
    std::cerr << "mesh_convert: error: " << error << '\n';
    return 2;
  }
  return 0;
}

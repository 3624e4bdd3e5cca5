// libFuzzer target for one mesh reader, chosen at compile time by MOLREMESH_FUZZ_FORMAT (Ply, Off,
// Stl, Obj or Wrl). A reader must either refuse the bytes with a one-line message or give a mesh whose
// every index is in range; the sanitizers catch everything else.
#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/io/obj_reader.h>
#include <vcg_ext/io/off_reader.h>
#include <vcg_ext/io/ply_reader.h>
#include <vcg_ext/io/stl_reader.h>
#include <vcg_ext/io/wrl_reader.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#define MOLREMESH_READER_CLASS_(format) molremesh::format##Reader
#define MOLREMESH_READER_CLASS(format) MOLREMESH_READER_CLASS_(format)

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  molremesh::RawMesh raw;
  std::string error;
  if (!MOLREMESH_READER_CLASS(MOLREMESH_FUZZ_FORMAT)::Read(bytes, raw, error)) {
    if (error.empty() || error.find('\n') != std::string::npos) std::abort(); // one clear line
    return 0;
  }
  for (const auto& t : raw.triangles)
    for (int i : t)
      if (i < 0 || std::size_t(i) >= raw.points.size()) std::abort();
  molremesh::MeshD m;
  molremesh::BuildMeshFromRaw(m, raw);
  return 0;
}

// Counts the elements of a mesh written by BadElementColoring by the palette class their color is:
// the tests read back colored files (CLI, meshlabserver) and compare with the quality report.
#pragma once

#include <vcg_ext/core/mesh_types.h>
#include <vcg_ext/quality/bad_element_coloring.h>

#include <cstddef>

namespace molremesh::test {

struct PaletteCounts {
  std::size_t obtuseFaces = 0;         ///< obtuse only
  std::size_t smallAngleFaces = 0;     ///< small-angle only
  std::size_t obtuseAndSmallFaces = 0; ///< both
  std::size_t irregularVertices = 0;   ///< valence below 5 or above 7
};

inline PaletteCounts CountPaletteColors(const MeshD& m, const BadElementPalette& palette) {
  PaletteCounts c;
  for (const auto& f : m.face) {
    c.obtuseFaces += f.cC() == palette.obtuseFace;
    c.smallAngleFaces += f.cC() == palette.smallAngleFace;
    c.obtuseAndSmallFaces += f.cC() == palette.obtuseAndSmallFace;
  }
  for (const auto& v : m.vert)
    c.irregularVertices += v.cC() == palette.lowValenceVertex || v.cC() == palette.highValenceVertex;
  return c;
}

} // namespace molremesh::test

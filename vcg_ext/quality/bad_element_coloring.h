// Colors the elements the paper calls bad, for inspection in MeshLab or any PLY viewer.
//
// Per vertex: quality = valence; color red for interior vertices whose valence is not 5, 6 or 7
// (border vertices are never called irregular, as in the V567 figure of the quality report).
// Per face: quality = minimal angle in degrees; color red when obtuse, blue when it has an
// angle below the small-angle threshold, magenta when both (a sliver can be both), neutral
// gray otherwise. Counts of each class are returned so callers can log them. Params::palette
// sets the colors: DefaultPalette() is the one above; ColorBlindSafePalette() gives vertex and face
// classes distinct hues (Okabe-Ito colors) and vertices of too low and too high valence their own.
#pragma once

#include <vcg/complex/complex.h>

#include <cstddef>

#include <vcg_ext/quality/mesh_quality.h>

namespace molremesh {

struct BadElementCounts {
  std::size_t irregularVertices = 0;   ///< red vertices
  std::size_t obtuseFaces = 0;         ///< red or magenta faces
  std::size_t smallAngleFaces = 0;     ///< blue or magenta faces
  std::size_t obtuseAndSmallFaces = 0; ///< magenta faces
  std::size_t lowValenceVertices = 0;  ///< irregular vertices of valence below 5
  std::size_t highValenceVertices = 0; ///< irregular vertices of valence above 7
};

/// The colors of the classes of BadElementColoring.
struct BadElementPalette {
  vcg::Color4b neutral{200, 200, 200, 255};
  vcg::Color4b lowValenceVertex{255, 0, 0, 255};  ///< interior valence below 5
  vcg::Color4b highValenceVertex{255, 0, 0, 255}; ///< interior valence above 7
  vcg::Color4b obtuseFace{255, 0, 0, 255};
  vcg::Color4b smallAngleFace{0, 0, 255, 255};
  vcg::Color4b obtuseAndSmallFace{255, 0, 255, 255};
};

template <class MeshType>
class BadElementColoring {
public:
  struct Params {
    double smallAngle = 30.0;  ///< degrees; a face with an angle below it is blue
    double obtuseAngle = 90.0; ///< degrees; a face whose max angle is >= it is red
    BadElementPalette palette = DefaultPalette();
  };

  /// Red irregular vertices, red obtuse, blue small-angle, magenta both, gray the rest.
  static BadElementPalette DefaultPalette() { return BadElementPalette(); }
  /// Okabe-Ito colors, told apart with the common color-vision deficiencies: faces vermillion
  /// (obtuse), blue (small angle), reddish purple (both); vertices bluish green (valence below 5)
  /// and yellow (above 7); light gray the rest. No vertex class shares a hue with a face class.
  static BadElementPalette ColorBlindSafePalette() {
    BadElementPalette p;
    p.neutral = vcg::Color4b(210, 210, 210, 255);
    p.lowValenceVertex = vcg::Color4b(0, 158, 115, 255);
    p.highValenceVertex = vcg::Color4b(240, 228, 66, 255);
    p.obtuseFace = vcg::Color4b(213, 94, 0, 255);
    p.smallAngleFace = vcg::Color4b(0, 114, 178, 255);
    p.obtuseAndSmallFace = vcg::Color4b(204, 121, 167, 255);
    return p;
  }

  static const vcg::Color4b& IrregularVertexColor() {
    static const vcg::Color4b c(255, 0, 0, 255);
    return c;
  }
  static const vcg::Color4b& NeutralColor() {
    static const vcg::Color4b c(200, 200, 200, 255);
    return c;
  }
  static const vcg::Color4b& ObtuseFaceColor() {
    static const vcg::Color4b c(255, 0, 0, 255);
    return c;
  }
  static const vcg::Color4b& SmallAngleFaceColor() {
    static const vcg::Color4b c(0, 0, 255, 255);
    return c;
  }
  static const vcg::Color4b& ObtuseAndSmallFaceColor() {
    static const vcg::Color4b c(255, 0, 255, 255);
    return c;
  }

  /// Writes per-vertex and per-face color and quality. Requires those four attributes to be
  /// enabled; touches nothing else (no geometry, no flags, no topology).
  static BadElementCounts Do(MeshType& m, const Params& params = Params()) {
    vcg::tri::RequirePerVertexColor(m);
    vcg::tri::RequirePerVertexQuality(m);
    vcg::tri::RequirePerFaceColor(m);
    vcg::tri::RequirePerFaceQuality(m);
    using Quality = MeshQuality<MeshType>;
    using ScalarQ = typename MeshType::VertexType::QualityType;
    using FaceScalarQ = typename MeshType::FaceType::QualityType;

    BadElementCounts counts;
    const std::vector<int> valence = Quality::VertexValences(m);
    const std::vector<bool> onBorder = Quality::VertexOnBorder(m);
    for (std::size_t i = 0; i < m.vert.size(); ++i) {
      auto& v = m.vert[i];
      if (v.IsD()) continue;
      v.Q() = ScalarQ(valence[i]);
      // Unreferenced vertices (valence 0) are not part of the surface: leave them neutral.
      const bool interior = valence[i] > 0 && !onBorder[i];
      const bool low = interior && valence[i] < 5, high = interior && valence[i] > 7;
      v.C() = low    ? params.palette.lowValenceVertex
              : high ? params.palette.highValenceVertex
                     : params.palette.neutral;
      if (low || high) ++counts.irregularVertices;
      if (low) ++counts.lowValenceVertices;
      if (high) ++counts.highValenceVertices;
    }
    for (auto& f : m.face) {
      if (f.IsD()) continue;
      const TriangleAngles angles = Quality::FaceAngles(f);
      const bool obtuse = angles.max() >= params.obtuseAngle;
      const bool small = angles.min() < params.smallAngle;
      f.Q() = FaceScalarQ(angles.min());
      if (obtuse && small) {
        f.C() = params.palette.obtuseAndSmallFace;
        ++counts.obtuseAndSmallFaces;
      } else if (obtuse) {
        f.C() = params.palette.obtuseFace;
      } else if (small) {
        f.C() = params.palette.smallAngleFace;
      } else {
        f.C() = params.palette.neutral;
      }
      if (obtuse) ++counts.obtuseFaces;
      if (small) ++counts.smallAngleFaces;
    }
    return counts;
  }
};

} // namespace molremesh

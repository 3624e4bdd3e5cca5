// Colors the elements the paper calls bad, for inspection in MeshLab or any PLY viewer.
//
// Per vertex: quality = valence; color red for interior vertices whose valence is not 5, 6 or 7
// (border vertices are never called irregular, as in the V567 figure of the quality report).
// Per face: quality = minimal angle in degrees; color red when obtuse, blue when it has an
// angle below the small-angle threshold, magenta when both (a sliver can be both), neutral
// gray otherwise. Counts of each class are returned so callers can log them.
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
};

template <class MeshType>
class BadElementColoring {
public:
  struct Params {
    double smallAngle = 30.0;  ///< degrees; a face with an angle below it is blue
    double obtuseAngle = 90.0; ///< degrees; a face whose max angle is >= it is red
  };

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
      const bool irregular = valence[i] > 0 && !onBorder[i] && (valence[i] < 5 || valence[i] > 7);
      v.C() = irregular ? IrregularVertexColor() : NeutralColor();
      if (irregular) ++counts.irregularVertices;
    }
    for (auto& f : m.face) {
      if (f.IsD()) continue;
      const TriangleAngles angles = Quality::FaceAngles(f);
      const bool obtuse = angles.max() >= params.obtuseAngle;
      const bool small = angles.min() < params.smallAngle;
      f.Q() = FaceScalarQ(angles.min());
      if (obtuse && small) {
        f.C() = ObtuseAndSmallFaceColor();
        ++counts.obtuseAndSmallFaces;
      } else if (obtuse) {
        f.C() = ObtuseFaceColor();
      } else if (small) {
        f.C() = SmallAngleFaceColor();
      } else {
        f.C() = NeutralColor();
      }
      if (obtuse) ++counts.obtuseFaces;
      if (small) ++counts.smallAngleFaces;
    }
    return counts;
  }
};

} // namespace molremesh

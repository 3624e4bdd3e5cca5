// Narrow gaps of a surface: the share of its area whose face sees the surface again in front of it
// (along its outward normal) within a short reach: a crevice between atom spheres, a pinched void,
// two parts nearly touching. A remesh at edge length L cannot keep every angle within bounds where
// such a gap is much narrower than L (its moves there are refused by the intersection guards), and
// the volumetric rebuild seals it. The pipeline asks this before remeshing (remesh_pipeline.h).
//
// Each live face casts a ray from its centroid along its unit normal and looks for a crossing, within
// the reach, with a face that shares no vertex with it (its neighbours meet it at distance 0 at every
// crease). Only the outward side is probed: on the molecular surfaces measured (docs/pipeline.md)
// parts thinner than the reach behind a face (PyMOL's fins) did not tell the inputs whose angles miss
// from the others; narrow gaps did. Faces are found in a uniform grid of face boxes; each face's
// answer depends only on the mesh, so the result is the same for any thread count.
#pragma once

#include <vcg_ext/core/index.h>
#include <vcg_ext/core/parallel_for.h>
#include <vcg_ext/geometry/point.h>
#include <vcg_ext/spatial/static_face_grid.h>

#include <vcg/space/box3.h>

#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

namespace molremesh {

/// What NarrowGaps measured. Areas in the mesh's units squared.
struct NarrowGapsResult {
  double area = 0;       ///< of the live, non-degenerate faces
  double narrowArea = 0; ///< of the faces that see the surface again in front of them within the reach
  std::size_t narrowFaces = 0;
  double Share() const { return area > 0 ? narrowArea / area : 0.0; } ///< 0-1
};

template <class MeshType>
class NarrowGaps {
public:
  struct Params {
    double reach = 0; ///< how far each ray looks (mesh units); must be > 0
    int threads = 0;  ///< 0 = all cores
  };

  /// Measures m (faces and vertices; no adjacency needed; deleted elements skipped). Precondition:
  /// params.reach > 0 (otherwise the result is all zero). perFace, when given, receives 1 for each
  /// face in a narrow gap, 0 for the others (indexed like m.face).
  static NarrowGapsResult Measure(const MeshType& m, const Params& params,
                                  std::vector<unsigned char>* perFace = nullptr) {
    NarrowGapsResult result;
    std::vector<unsigned char> own;
    std::vector<unsigned char>& narrow = perFace ? *perFace : own;
    narrow.assign(m.face.size(), 0);
    if (!(params.reach > 0) || m.face.empty()) return result;
    const StaticFaceGrid<MeshType> grid(m, 2 * params.reach);
    std::vector<double> area(m.face.size(), 0.0);
    ParallelFor(m.face.size(), params.threads, [&](std::size_t begin, std::size_t end, int) {
      for (std::size_t f = begin; f < end; ++f) Probe(m, grid, Index(f), params.reach, area[f], narrow[f]);
    });
    for (std::size_t f = 0; f < m.face.size(); ++f) { // serial sums: the same bits for any thread count
      result.area += area[f];
      if (narrow[f]) result.narrowArea += area[f], ++result.narrowFaces;
    }
    return result;
  }

private:
  static void Probe(const MeshType& m, const StaticFaceGrid<MeshType>& grid, Index f, double reach,
                    double& area, unsigned char& narrow) {
    const auto& face = m.face[f];
    if (face.IsD()) return;
    const Point a = PositionOf(face.cV(0)), b = PositionOf(face.cV(1)), c = PositionOf(face.cV(2));
    Point normal = (b - a) ^ (c - a);
    const double twiceArea = normal.Norm();
    if (!(twiceArea > 0)) return;
    area = 0.5 * twiceArea;
    normal /= twiceArea;
    const Point centre = (a + b + c) / 3.0;
    vcg::Box3d box;
    box.Add(centre);
    box.Add(centre + normal * reach);
    grid.Visit(m, box, [&](Index g) {
      if (!narrow && !SharesVertex(face, m.face[g]) && Crosses(m.face[g], centre, normal, reach)) narrow = 1;
    });
  }
  static bool SharesVertex(const typename MeshType::FaceType& f, const typename MeshType::FaceType& g) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (f.cV(i) == g.cV(j)) return true;
    return false;
  }
  /// Whether the ray origin + t direction, 0 < t <= reach, crosses triangle g (Moller-Trumbore).
  static bool Crosses(const typename MeshType::FaceType& g, const Point& origin, const Point& direction,
                      double reach) {
    const Point p0 = PositionOf(g.cV(0));
    const Point e1 = PositionOf(g.cV(1)) - p0, e2 = PositionOf(g.cV(2)) - p0;
    const Point q = direction ^ e2;
    const double det = e1 * q;
    if (std::fabs(det) < std::numeric_limits<double>::min()) return false; // parallel
    const Point s = origin - p0;
    const double u = (s * q) / det;
    if (u < 0 || u > 1) return false;
    const Point r = s ^ e1;
    const double v = (direction * r) / det;
    if (v < 0 || u + v > 1) return false;
    const double t = (e2 * r) / det;
    return t > 0 && t <= reach;
  }
};

} // namespace molremesh

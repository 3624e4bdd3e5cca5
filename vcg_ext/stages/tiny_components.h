// Closed components too small to be regular, remade as icosahedra.
//
// Why: on a closed genus-0 surface the valences sum to 6V - 12, so a component of fewer than 12
// vertices has a vertex of valence below 5 whatever its triangles are. Van der Waals and Gaussian
// surfaces of structures with ions, waters and loose hydrogens hold many such specks (1MAH's EDTSurf
// van der Waals surface after remeshing: 131 components under 20 faces, with 585 of its 1243
// irregular vertices), and no flip or collapse can help them. An icosahedron has 12 vertices of
// valence 5 and angles of 60°. A speck that is star-shaped around its centroid becomes one whose
// vertices lie where the icosahedron's 12 directions from the centroid meet the speck, grown about
// the centroid to the speck's volume; the speck is kept as it was when an angle of the new faces
// falls outside [minAngle, maxAngle], the growth would exceed a half, or a new face crosses another
// part of the mesh.
#pragma once

#include <vcg_ext/core/index.h>
#include <vcg_ext/core/union_find.h>
#include <vcg_ext/geometry/point.h>
#include <vcg_ext/geometry/triangle_angles.h>
#include <vcg_ext/geometry/triangle_intersection.h>

#include <vcg/complex/complex.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace molremesh {

struct TinyComponentResult {
  std::size_t tiny = 0;   ///< closed genus-0 components remade when they can be (see Params)
  std::size_t remade = 0; ///< of them, remade as icosahedra
};

template <class MeshType>
class TinyComponentRegularization {
public:
  struct Params {
    double minAngle = 30; ///< degrees: every angle of an icosahedron kept is at least this
    double maxAngle = 90; ///< degrees: and at most this
    /// Components of 12 up to this many vertices are remade too when one of their vertices is
    /// irregular or an angle is out of bounds (below 12 vertices: always).
    std::size_t maxVertices = 30;
  };

  /// Remakes the tiny components of m (see the top of this file). Preconditions: m's live faces
  /// closed and consistently oriented (the pipeline's output); other components are not touched.
  /// Leaves deleted elements in m (compact it after) and invalidates its adjacency.
  static TinyComponentResult Do(MeshType& m, const Params& p) {
    TinyComponentResult r;
    std::vector<std::vector<std::size_t>> facesOf = TinyComponents(m, p);
    r.tiny = facesOf.size();
    std::vector<std::array<Point, 12>> corners(facesOf.size());
    std::vector<bool> remake(facesOf.size(), false), cavity(facesOf.size(), false);
    for (std::size_t c = 0; c < facesOf.size(); ++c) {
      bool inward = false;
      remake[c] = Icosahedron(m, facesOf[c], p, corners[c], inward);
      cavity[c] = inward;
    }
    DropCrossings(m, facesOf, corners, remake);
    for (std::size_t c = 0; c < facesOf.size(); ++c)
      if (remake[c]) {
        Replace(m, facesOf[c], corners[c], cavity[c]);
        ++r.remade;
      }
    return r;
  }

private:
  using Face = std::array<int, 3>;

  static const std::array<Point, 12>& Directions() {
    static const std::array<Point, 12> d = [] {
      const double g = (1.0 + std::sqrt(5.0)) / 2.0;
      std::array<Point, 12> v = {Point(-1, g, 0), Point(1, g, 0), Point(-1, -g, 0), Point(1, -g, 0),
                                 Point(0, -1, g), Point(0, 1, g), Point(0, -1, -g), Point(0, 1, -g),
                                 Point(g, 0, -1), Point(g, 0, 1), Point(-g, 0, -1), Point(-g, 0, 1)};
      for (Point& x : v) x /= x.Norm();
      return v;
    }();
    return d;
  }

  /// The icosahedron's faces, each turned so its normal points away from the centre.
  static const std::array<Face, 20>& Faces() {
    static const std::array<Face, 20> f = [] {
      std::array<Face, 20> t = {{{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                 {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                 {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                 {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}}};
      const std::array<Point, 12>& d = Directions();
      for (Face& x : t)
        if (((d[x[1]] - d[x[0]]) ^ (d[x[2]] - d[x[0]])) * (d[x[0]] + d[x[1]] + d[x[2]]) < 0)
          std::swap(x[1], x[2]);
      return t;
    }();
    return f;
  }

  /// The faces of each closed genus-0 component (F = 2V - 4) of fewer than 12 vertices, or of up
  /// to maxVertices with an irregular vertex or an angle out of bounds.
  static std::vector<std::vector<std::size_t>> TinyComponents(const MeshType& m, const Params& p) {
    UnionFind sets(m.vert.size());
    std::vector<int> valence(m.vert.size(), 0);
    for (const auto& f : m.face)
      if (!f.IsD())
        for (int k = 0; k < 3; ++k) {
          ++valence[std::size_t(vcg::tri::Index(m, f.cV(k)))];
          if (k > 0)
            sets.Unite(std::uint32_t(vcg::tri::Index(m, f.cV(0))),
                       std::uint32_t(vcg::tri::Index(m, f.cV(k))));
        }
    std::vector<std::size_t> faces(m.vert.size(), 0), verts(m.vert.size(), 0);
    std::vector<bool> flawed(m.vert.size(), false);
    for (std::size_t v = 0; v < m.vert.size(); ++v)
      if (valence[v] > 0) {
        const std::uint32_t root = sets.Find(std::uint32_t(v));
        ++verts[root];
        if (valence[v] < 5 || valence[v] > 7) flawed[root] = true;
      }
    for (const auto& f : m.face) {
      if (f.IsD()) continue;
      const std::uint32_t root = sets.Find(std::uint32_t(vcg::tri::Index(m, f.cV(0))));
      ++faces[root];
      if (verts[root] <= p.maxVertices &&
          !AnglesWithin(PositionOf(f.cV(0)), PositionOf(f.cV(1)), PositionOf(f.cV(2)), p))
        flawed[root] = true;
    }
    std::vector<Index> slot(m.vert.size(), kNoIndex);
    std::vector<std::vector<std::size_t>> facesOf;
    for (std::size_t i = 0; i < m.face.size(); ++i) {
      if (m.face[i].IsD()) continue;
      const std::uint32_t root = sets.Find(std::uint32_t(vcg::tri::Index(m, m.face[i].cV(0))));
      const bool small = verts[root] < 12 || (verts[root] <= p.maxVertices && flawed[root]);
      if (!small || faces[root] + 4 != 2 * verts[root]) continue;
      if (slot[root] == kNoIndex) {
        slot[root] = Index(facesOf.size());
        facesOf.emplace_back();
      }
      facesOf[slot[root]].push_back(i);
    }
    return facesOf;
  }

  static bool AnglesWithin(const Point& a, const Point& b, const Point& c, const Params& p) {
    return AngleMargin(a, b, c, p) >= 0;
  }

  /// The icosahedron of a component: false when it is not star-shaped around its centroid or an
  /// angle would leave the bounds.
  static bool Icosahedron(const MeshType& m, const std::vector<std::size_t>& faces, const Params& p,
                          std::array<Point, 12>& corner, bool& cavity) {
    if (!ClosedAndOriented(m, faces)) return false;
    // The centroid of the enclosed solid (sum of the tetrahedra to the first corner), which lies
    // in the kernel of more bent specks than the mean of the corners does.
    const Point apex = PositionOf(m.face[faces[0]].cV(0));
    Point centre(0, 0, 0);
    double volume = 0;
    for (std::size_t i : faces) {
      const auto& f = m.face[i];
      const Point a = PositionOf(f.cV(0)) - apex, b = PositionOf(f.cV(1)) - apex,
                  c = PositionOf(f.cV(2)) - apex;
      const double v = a * (b ^ c);
      volume += v;
      centre += (a + b + c) * (v / 4.0);
    }
    if (!(std::fabs(volume) > 0)) return false;
    centre = apex + centre / volume;
    cavity = volume < 0;
    const double side = cavity ? -1.0 : 1.0; // a cavity's normals point at its centre
    for (std::size_t i : faces) {
      const auto& f = m.face[i];
      const Point a = PositionOf(f.cV(0)), b = PositionOf(f.cV(1)), c = PositionOf(f.cV(2));
      if (!(side * (((b - a) ^ (c - a)) * (a - centre)) > 0)) return false;
    }
    double best = -1;
    for (int turn = 0; turn < kTurns; ++turn) { // the icosahedron turned, its best-shaped fit kept
      std::array<Point, 12> fit;
      for (int k = 0; k < 12; ++k) {
        const Point d = Turned(Directions()[k], turn);
        double reach = 0;
        for (std::size_t i : faces) reach = std::max(reach, RayHit(m.face[i], centre, d));
        if (!(reach > 0)) return false;
        fit[k] = centre + d * reach;
      }
      double margin = 180;
      for (const Face& f : Faces())
        margin = std::min(margin, AngleMargin(fit[f[0]], fit[f[1]], fit[f[2]], p));
      if (margin > best) {
        best = margin;
        corner = fit;
      }
    }
    if (!(best >= 0)) return false;
    // Inscribed in the speck, the icosahedron holds less volume (a tetrahedron's: 36 %); grown about
    // the centre to the speck's volume it keeps its angles. A speck it would have to grow by more
    // than kMaxGrowth (a needle, a flake) stays as it is.
    double icosahedron = 0;
    for (const Face& f : Faces())
      icosahedron += (corner[f[0]] - centre) * ((corner[f[1]] - centre) ^ (corner[f[2]] - centre));
    const double growth = std::cbrt(std::fabs(volume) / icosahedron);
    if (!(growth <= kMaxGrowth)) return false;
    for (Point& x : corner) x = centre + (x - centre) * std::max(1.0, growth);
    return true;
  }

  /// The most an icosahedron may grow about its centre to hold its speck's volume.
  static constexpr double kMaxGrowth = 1.5;

  /// Turns of the icosahedron tried: the first is none, the others about axes spread over the
  /// sphere by a golden-angle spiral, each by a multiple of the golden angle.
  static constexpr int kTurns = 24;

  static Point Turned(const Point& d, int turn) {
    if (turn == 0) return d;
    const double golden = M_PI * (3.0 - std::sqrt(5.0)), z = 1.0 - (turn + 0.5) * 2.0 / kTurns;
    const double rho = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = turn * golden;
    const Point axis(rho * std::cos(phi), rho * std::sin(phi), z);
    const double angle = std::fmod(turn * golden, 2.0 * M_PI);
    return d * std::cos(angle) + (axis ^ d) * std::sin(angle) + axis * ((axis * d) * (1.0 - std::cos(angle)));
  }

  /// Degrees by which the triangle's angles keep within the bounds (negative: out of them).
  static double AngleMargin(const Point& a, const Point& b, const Point& c, const Params& p) {
    double lo = 0, hi = 0;
    TriangleAngleRange(a, b, c, lo, hi);
    const double margin = std::min(lo - p.minAngle, p.maxAngle - hi);
    return std::isfinite(margin) ? margin : -1;
  }

  /// Every directed edge of the faces used once and its reverse once (F = 2V - 4 alone does not
  /// rule out a non-manifold speck).
  static bool ClosedAndOriented(const MeshType& m, const std::vector<std::size_t>& faces) {
    std::vector<std::pair<const void*, const void*>> edges;
    for (std::size_t i : faces)
      for (int k = 0; k < 3; ++k) edges.emplace_back(m.face[i].cV(k), m.face[i].cV((k + 1) % 3));
    std::sort(edges.begin(), edges.end());
    for (std::size_t e = 0; e < edges.size(); ++e) {
      if (e > 0 && edges[e] == edges[e - 1]) return false;
      if (!std::binary_search(edges.begin(), edges.end(), std::make_pair(edges[e].second, edges[e].first)))
        return false;
    }
    return true;
  }

  /// Where the ray from o along unit d meets the face (its distance), or 0.
  template <class FaceType>
  static double RayHit(const FaceType& f, const Point& o, const Point& d) {
    const Point a = PositionOf(f.cV(0)), e1 = PositionOf(f.cV(1)) - a, e2 = PositionOf(f.cV(2)) - a;
    const Point q = d ^ e2;
    const double det = e1 * q;
    if (std::fabs(det) < 1e-300) return 0;
    const Point s = o - a;
    const double u = (s * q) / det;
    if (u < 0 || u > 1) return 0;
    const Point t = s ^ e1;
    const double v = (d * t) / det;
    if (v < 0 || u + v > 1) return 0;
    const double distance = (e2 * t) / det;
    return distance > 0 ? distance : 0;
  }

  /// Unmarks the icosahedra a face of another component (or another new icosahedron) crosses.
  static void DropCrossings(const MeshType& m, const std::vector<std::vector<std::size_t>>& facesOf,
                            const std::vector<std::array<Point, 12>>& corner, std::vector<bool>& remake) {
    std::vector<Index> componentOfFace(m.face.size(), kNoIndex);
    for (std::size_t c = 0; c < facesOf.size(); ++c)
      for (std::size_t i : facesOf[c]) componentOfFace[i] = Index(c);
    std::vector<std::pair<Point, Point>> box(facesOf.size());
    double cell = 0;
    for (std::size_t c = 0; c < facesOf.size(); ++c) {
      box[c] = {corner[c][0], corner[c][0]};
      for (const Point& x : corner[c])
        for (int k = 0; k < 3; ++k) {
          box[c].first[k] = std::min(box[c].first[k], x[k]);
          box[c].second[k] = std::max(box[c].second[k], x[k]);
        }
      if (remake[c])
        cell = std::max({cell, box[c].second[0] - box[c].first[0], box[c].second[1] - box[c].first[1],
                         box[c].second[2] - box[c].first[2]});
    }
    if (!(cell > 0)) return;
    auto key = [cell](const Point& x, int k) { return long(std::floor(x[k] / cell)); };
    std::vector<std::pair<std::array<long, 3>, Index>> cells;
    for (std::size_t c = 0; c < facesOf.size(); ++c)
      if (remake[c])
        for (long i = key(box[c].first, 0); i <= key(box[c].second, 0); ++i)
          for (long j = key(box[c].first, 1); j <= key(box[c].second, 1); ++j)
            for (long k = key(box[c].first, 2); k <= key(box[c].second, 2); ++k)
              cells.push_back({{i, j, k}, Index(c)});
    std::sort(cells.begin(), cells.end());
    std::vector<bool> crossed(facesOf.size(), false);
    auto crosses = [&](std::size_t c, const PlanarTriangle& t) {
      for (const Face& f : Faces())
        if (TrianglesIntersect(MakePlanarTriangle(corner[c][f[0]], corner[c][f[1]], corner[c][f[2]]), t))
          return true;
      return false;
    };
    for (std::size_t i = 0; i < m.face.size(); ++i) {
      if (m.face[i].IsD()) continue;
      const Point a = PositionOf(m.face[i].cV(0)), b = PositionOf(m.face[i].cV(1)),
                  d = PositionOf(m.face[i].cV(2));
      for (const std::array<long, 3>& c : FaceCells(a, b, d, key))
        for (auto it = std::lower_bound(cells.begin(), cells.end(), std::make_pair(c, Index(0)));
             it != cells.end() && it->first == c; ++it)
          if (componentOfFace[i] != it->second && !crossed[it->second] &&
              crosses(it->second, MakePlanarTriangle(a, b, d)))
            crossed[it->second] = true;
    }
    for (std::size_t c = 0; c < facesOf.size(); ++c) // two new icosahedra against each other
      for (std::size_t e = c + 1; e < facesOf.size(); ++e)
        if (remake[c] && remake[e] && Overlap(box[c], box[e]))
          for (const Face& f : Faces())
            if (crosses(c, MakePlanarTriangle(corner[e][f[0]], corner[e][f[1]], corner[e][f[2]])))
              crossed[c] = crossed[e] = true;
    for (std::size_t c = 0; c < facesOf.size(); ++c) remake[c] = remake[c] && !crossed[c];
  }

  template <class Key>
  static std::vector<std::array<long, 3>> FaceCells(const Point& a, const Point& b, const Point& c,
                                                    const Key& key) {
    std::vector<std::array<long, 3>> cells;
    long lo[3], hi[3];
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min({key(a, k), key(b, k), key(c, k)});
      hi[k] = std::max({key(a, k), key(b, k), key(c, k)});
    }
    for (long i = lo[0]; i <= hi[0]; ++i)
      for (long j = lo[1]; j <= hi[1]; ++j)
        for (long k = lo[2]; k <= hi[2]; ++k) cells.push_back({i, j, k});
    return cells;
  }

  static bool Overlap(const std::pair<Point, Point>& a, const std::pair<Point, Point>& b) {
    for (int k = 0; k < 3; ++k)
      if (a.first[k] > b.second[k] || b.first[k] > a.second[k]) return false;
    return true;
  }

  /// The component's faces and vertices deleted, the icosahedron added with the component's
  /// orientation (a cavity's normals towards its centre).
  static void Replace(MeshType& m, const std::vector<std::size_t>& faces, const std::array<Point, 12>& corner,
                      bool cavity) {
    for (std::size_t i : faces) {
      auto& f = m.face[i];
      for (int k = 0; k < 3; ++k)
        if (!f.V(k)->IsD()) vcg::tri::Allocator<MeshType>::DeleteVertex(m, *f.V(k));
      vcg::tri::Allocator<MeshType>::DeleteFace(m, f);
    }
    using CoordType = typename MeshType::CoordType;
    using ScalarType = typename MeshType::ScalarType;
    auto v = vcg::tri::Allocator<MeshType>::AddVertices(m, 12);
    for (int k = 0; k < 12; ++k)
      (v + k)->P() = CoordType(ScalarType(corner[k][0]), ScalarType(corner[k][1]), ScalarType(corner[k][2]));
    for (const Face& t : Faces()) {
      const int b = cavity ? t[2] : t[1], c = cavity ? t[1] : t[2];
      vcg::tri::Allocator<MeshType>::AddFace(m, &*(v + t[0]), &*(v + b), &*(v + c));
    }
  }
};

} // namespace molremesh

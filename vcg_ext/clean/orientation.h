// Cleaning steps on orientation (vcg_ext/clean/): coherent orientation of every component, the
// count of components that cannot be oriented, and the outward orientation of closed components.
//
// Orientation<MeshType>::OrientCoherently needs fresh FF adjacency on an edge-manifold mesh;
// OrientOutward needs fresh FF adjacency. Both leave the adjacency fresh. `flipped` is indexed by
// face and must have at least m.face.size() entries: each face whose orientation they reverse has
// its entry toggled, so the caller can count the input faces reversed an odd number of times.
#pragma once

#include <vcg/complex/complex.h>
#include <vcg/space/box3.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include <vcg_ext/clean/clean_mesh_access.h>
#include <vcg_ext/clean/component_filter.h>
#include <vcg_ext/core/index.h>
#include <vcg_ext/geometry/point.h>
#include <vcg_ext/spatial/projected_face_grid.h>

namespace molremesh {
namespace clean {

template <class MeshType>
class Orientation {
public:
  using FaceType = typename MeshType::FaceType;

  /// Traversal over manifold edges; a neighbour seen the wrong way round is flipped
  /// (vcg::face::SwapEdge keeps FF consistent). When more than half of a component was flipped, the
  /// whole component is flipped back so the input's majority orientation wins. Pairs of faces that
  /// stay incoherent (the component is not orientable as it is) are returned in `conflicts`. vcglib's
  /// Clean::OrientCoherentlyMesh is not used because it stops at the first non-orientable component.
  static void OrientCoherently(MeshType& m, std::vector<std::uint8_t>& flipped,
                               std::vector<std::pair<Index, Index>>& conflicts) {
    conflicts.clear();
    std::vector<std::uint8_t> seen(m.face.size(), 0);
    std::vector<Index> component, queue;
    bool changed = false;
    for (Index s = 0; s < m.face.size(); ++s) {
      if (m.face[s].IsD() || seen[s]) continue;
      component.clear();
      queue.assign(1, s);
      seen[s] = 1;
      std::size_t flips = 0;
      bool orientable = true;
      while (!queue.empty()) {
        const Index f = queue.back();
        queue.pop_back();
        component.push_back(f);
        FaceType& F = m.face[f];
        for (int e = 0; e < 3; ++e) {
          if (IsBorderEdge(F, e)) continue;
          FaceType* g = F.FFp(e);
          if (g->FFp(F.FFi(e)) != &F) continue; // not a manifold edge
          const Index gi = FI(m, g);
          if (!Coherent(F, e)) {
            if (!seen[gi]) {
              vcg::face::SwapEdge<FaceType, true>(*g, 0);
              flipped[gi] ^= 1;
              ++flips;
              changed = true;
            } else {
              orientable = false;
              conflicts.emplace_back(std::min(f, gi), std::max(f, gi));
            }
          }
          if (!seen[gi]) {
            seen[gi] = 1;
            queue.push_back(gi);
          }
        }
      }
      if (orientable && 2 * flips > component.size()) {
        for (Index f : component) {
          vcg::face::SwapEdge<FaceType, false>(m.face[f], 0);
          flipped[f] ^= 1;
        }
        changed = true;
      }
    }
    std::sort(conflicts.begin(), conflicts.end());
    conflicts.erase(std::unique(conflicts.begin(), conflicts.end()), conflicts.end());
    if (changed) RebuildTopology(m);
  }

  /// Components still holding one of the `conflicts` OrientCoherently returned (needs fresh FF
  /// adjacency).
  static std::size_t CountNonOrientableComponents(const MeshType& m,
                                                  const std::vector<std::pair<Index, Index>>& conflicts) {
    std::vector<Index> label;
    std::vector<std::size_t> size;
    LabelComponents(m, label, size);
    std::vector<std::uint8_t> bad(size.size(), 0);
    for (const auto& conflict : conflicts)
      if (!m.face[conflict.first].IsD()) bad[label[conflict.first]] = 1;
    return std::size_t(std::count(bad.begin(), bad.end(), 1));
  }

  /// What OrientOutward did.
  struct OutwardResult {
    std::size_t flippedComponents = 0;    ///< closed components whose orientation was reversed
    std::vector<CleanComponent> interior; ///< components removed for lying inside the union
    std::size_t interiorFaces = 0;        ///< their faces
  };

  /// Turns every closed component outward: positive volume, except, with cavitiesInward, the
  /// cavities of a molecular surface, whose normals point into the void (negative volume).
  /// A nested component's input orientation tells a cavity from an overlapping piece: the region
  /// the surface bounds is the union of what its pieces enclose (winding number w >= 1, each
  /// component counted with the sign of its input volume; the outermost ones positive, the whole
  /// mesh reversed first when it faces inward). A component is on that region's boundary when w is
  /// 0 on one side and at least 1 on the other: a cavity is oriented against its surroundings, an
  /// island in a cavity with them. With removeInterior, a closed component with w >= 1 on both
  /// sides (a piece oriented as its container, as PyMOL leaves inside its SES) is removed, and one
  /// with w <= 0 on both sides too; without it, nested components are oriented by the parity of
  /// their nesting depth whatever their input orientation.
  static OutwardResult OrientOutward(MeshType& m, bool cavitiesInward, bool removeInterior,
                                     std::vector<std::uint8_t>& flipped) {
    OutwardResult result;
    std::vector<Index> label;
    std::vector<std::size_t> size;
    const std::size_t count = LabelComponents(m, label, size);
    const Components c = Describe(m, label, count);
    std::vector<std::vector<std::size_t>> containers =
        cavitiesInward ? AllContainers(m, c) : std::vector<std::vector<std::size_t>>(count);
    // The orientation of the whole mesh: that of its outermost components' total volume.
    double outermost = 0;
    for (std::size_t k = 0; k < count; ++k)
      if (c.info[k].closed && containers[k].empty()) outermost += c.info[k].volume;
    const double whole = outermost < 0 ? -1.0 : 1.0;
    auto sign = [&](std::size_t k) {
      return containers[k].empty() ? 1 : (whole * c.info[k].volume > 0 ? 1 : -1);
    };
    std::vector<std::uint8_t> remove(count, 0);
    bool changed = false;
    for (std::size_t k = 0; k < count; ++k) {
      if (!c.info[k].closed || c.info[k].volume == 0) continue;
      int w = 0; // the winding number around k, from the other components
      for (std::size_t d : containers[k]) w += sign(d);
      bool wantPositive = containers[k].size() % 2 == 0;
      if (removeInterior && !containers[k].empty()) {
        if ((w >= 1) == (w + sign(k) >= 1)) {
          remove[k] = 1;
          continue;
        }
        wantPositive = w <= 0;
      }
      if ((c.info[k].volume > 0) == wantPositive) continue;
      for (Index f : c.faces[k]) {
        std::swap(m.face[f].V(1), m.face[f].V(2));
        flipped[f] ^= 1;
      }
      ++result.flippedComponents;
      changed = true;
    }
    for (std::size_t k = 0; k < count; ++k) {
      if (!remove[k]) continue;
      CleanComponent removed = c.info[k];
      removed.reason = "inside the union (oriented as the region around it)";
      result.interior.push_back(removed);
      result.interiorFaces += removed.faces;
      for (Index f : c.faces[k]) DeleteFace(m, f);
      changed = true;
    }
    if (changed) RebuildTopology(m);
    return result;
  }

private:
  /// Per component: its faces and bounding box, and DescribeComponents' record (closed or not,
  /// signed volume about its centroid).
  struct Components {
    std::vector<std::vector<Index>> faces;
    std::vector<vcg::Box3d> box;
    std::vector<CleanComponent> info;
  };

  static Components Describe(const MeshType& m, const std::vector<Index>& label, std::size_t count) {
    Components c;
    c.faces.resize(count);
    c.box.resize(count);
    for (Index f = 0; f < m.face.size(); ++f) {
      if (m.face[f].IsD()) continue;
      c.faces[label[f]].push_back(f);
      for (int i = 0; i < 3; ++i) c.box[label[f]].Add(PositionOf(&m.vert[VI(m, m.face[f], i)]));
    }
    c.info = DescribeComponents(m, label, count);
    return c;
  }

  /// Per closed component k with a non-zero volume: the components that enclose it, those whose
  /// box holds k's and inside which a point of k (the centroid of its largest face) lies by a vote
  /// of rays. Containers may be open (a hole left unfilled): the vote over several rays tolerates a
  /// ray escaping through a small hole. A container asked about many components has its faces
  /// bucketed along each ray direction first (ProjectedFaceGrid), so that each ray is tested
  /// against the faces in its shadow only; the votes are the same.
  static std::vector<std::vector<std::size_t>> AllContainers(const MeshType& m, const Components& c) {
    static const std::array<Point, 5> directions{Point(0.5773, 0.5774, 0.5775),
                                                 Point(-0.7071, 0.4082, 0.5774), Point(0.1, -0.9, 0.4243),
                                                 Point(-0.3, -0.2, -0.9327), Point(0.8, 0.1, -0.5916)};
    const std::size_t count = c.faces.size();
    std::vector<Point> origin(count);
    // Per candidate container: the components inside its box.
    std::vector<std::vector<std::size_t>> asked(count);
    for (std::size_t k = 0; k < count; ++k) {
      if (!c.info[k].closed || c.info[k].volume == 0) continue;
      origin[k] = ProbePoint(m, c.faces[k]);
      for (std::size_t d = 0; d < count; ++d)
        if (d != k && !c.faces[d].empty() && c.box[d].IsIn(c.box[k].min) && c.box[d].IsIn(c.box[k].max))
          asked[d].push_back(k);
    }
    std::vector<std::vector<std::size_t>> containers(count);
    std::vector<int> inside(count), outside(count);
    for (std::size_t d = 0; d < count; ++d) {
      if (asked[d].empty()) continue;
      const bool bucket = asked[d].size() * c.faces[d].size() > kBruteForceRayTests;
      for (const Point& raw : directions) {
        const Point dir = raw / raw.Norm();
        if (!bucket) {
          for (std::size_t k : asked[d])
            Vote(RayParity(m, c.faces[d].data(), c.faces[d].data() + c.faces[d].size(), origin[k], dir),
                 inside[k], outside[k]);
          continue;
        }
        const ProjectedFaceGrid grid(
            c.faces[d].size(), [&](std::size_t i) { return Corners(m, c.faces[d][i]); }, dir);
        std::vector<Index> near;
        for (std::size_t k : asked[d]) {
          const auto range = grid.Candidates(origin[k]);
          near.clear();
          for (const std::uint32_t* i = range.first; i != range.second; ++i) near.push_back(c.faces[d][*i]);
          Vote(RayParity(m, near.data(), near.data() + near.size(), origin[k], dir), inside[k], outside[k]);
        }
      }
      for (std::size_t k : asked[d]) {
        if (inside[k] > outside[k]) containers[k].push_back(d);
        inside[k] = outside[k] = 0;
      }
    }
    return containers;
  }

  /// Above this many ray-face tests, a container's faces are bucketed per direction.
  static constexpr std::size_t kBruteForceRayTests = std::size_t(1) << 20;

  enum class Crossing { Even, Odd, Ambiguous };

  static void Vote(Crossing crossing, int& inside, int& outside) {
    if (crossing != Crossing::Ambiguous) (crossing == Crossing::Odd ? inside : outside) += 1;
  }

  /// The centroid of the largest face of a component.
  static Point ProbePoint(const MeshType& m, const std::vector<Index>& faces) {
    Index probe = faces.front();
    double bestArea = -1;
    for (Index f : faces) {
      const double a = FaceArea(m, m.face[f]);
      if (a > bestArea) bestArea = a, probe = f;
    }
    const std::array<Point, 3> t = Corners(m, probe);
    return (t[0] + t[1] + t[2]) / 3.0;
  }

  static std::array<Point, 3> Corners(const MeshType& m, Index f) {
    const Tri t = FaceTri(m, m.face[f]);
    return {PositionOf(&m.vert[t[0]]), PositionOf(&m.vert[t[1]]), PositionOf(&m.vert[t[2]])};
  }

  static bool Coherent(const FaceType& f, int e) {
    const FaceType* g = f.cFFp(e);
    const int ge = f.cFFi(e);
    return g->cV(ge) == f.cV((e + 1) % 3) && g->cV((ge + 1) % 3) == f.cV(e);
  }
  /// Parity of the crossings of the ray origin + t dir (t > 0) with the faces [first, last);
  /// ambiguous when the ray grazes an edge or a vertex (the vote then ignores this direction).
  static Crossing RayParity(const MeshType& m, const Index* first, const Index* last, const Point& origin,
                            const Point& dir) {
    bool odd = false;
    for (const Index* f = first; f != last; ++f) {
      const std::array<Point, 3> t = Corners(m, *f);
      const Point e1 = t[1] - t[0], e2 = t[2] - t[0];
      const Point q = dir ^ e2;
      const double det = e1 * q;
      const double scale = e1.Norm() * e2.Norm();
      if (std::fabs(det) <= 1e-12 * scale) continue; // parallel: cannot cross transversally
      const double inv = 1.0 / det;
      const Point s = origin - t[0];
      const double u = (s * q) * inv;
      if (u < -1e-9 || u > 1 + 1e-9) continue;
      const Point rr = s ^ e1;
      const double v = (dir * rr) * inv;
      if (v < -1e-9 || u + v > 1 + 1e-9) continue;
      const double t0 = (e2 * rr) * inv;
      if (t0 <= 0) continue;
      if (u < 1e-9 || v < 1e-9 || u + v > 1 - 1e-9) return Crossing::Ambiguous;
      odd = !odd;
    }
    return odd ? Crossing::Odd : Crossing::Even;
  }
};

} // namespace clean
} // namespace molremesh

// Vertices on the creases of a union of spheres (the solvent-accessible and van der Waals
// surfaces), where two spheres meet.
//
// Every vertex of the extracted mesh lies on a sphere, but an edge whose ends lie on two different
// spheres bridges the concave crease between them with a straight chord above it: the mesh's area
// falls short by an amount linear in the edge length (1UBQ's SAS: -3.0 % at a 0.4 Å grid, -1.5 %
// at 0.2). Splitting each such edge at the point of the two spheres' intersection circle where it
// crosses their radical plane turns the chord into two, each on one sphere, which leaves the
// quadratic error of a convex sphere patch. A split can leave new bridging edges (to a third
// sphere), hence a few passes. A split vertex that would flip or degenerate a face, or make two
// faces cross, is refused and the refinement redone without it (of a spoilt face's moved corners,
// the one that moved farthest); what is still spoilt after the last attempt goes back onto its
// edge (the mesh is then the unsplit surface, subdivided flat, there).
#pragma once

#include <vcg_ext/core/index.h>
#include <vcg_ext/geometry/mean_edge_length.h>
#include <vcg_ext/geometry/point.h>
#include <vcg_ext/spatial/self_intersections.h>
#include <vcg_ext/structure/atoms.h>
#include <vcg_ext/volume/atom_fields.h>

#include <vcg/complex/complex.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace molremesh {

template <class MeshType>
class SphereCreaseRefinement {
public:
  struct Params {
    int passes = 3;          ///< rounds of splitting: a split can leave edges that bridge another crease
    int attempts = 3;        ///< refinements from scratch, each without the moves that spoilt a face before
    double tolerance = 1e-3; ///< Å: a vertex this close to a sphere lies on it
    int threads = 0;         ///< of the crossing test, 0 = all cores; the output does not depend on it
  };
  struct Result {
    std::size_t splitEdges = 0;      ///< edges split at a crease
    std::size_t snappedVertices = 0; ///< vertices moved onto a crease passing next to them
    std::size_t refused = 0;         ///< moves left out for spoiling a face (flipped, needle, crossing)
    std::size_t flattened = 0;       ///< split or snapped vertices put back after the last attempt
  };

  /// Splits m's edges that bridge a crease of the union of the atoms' spheres (radius r + grow).
  /// Precondition: m's vertices were projected onto the spheres (ProjectVerticesToLevel); those
  /// that are not on one are left alone. m keeps its vertices; new ones are appended.
  static Result Do(MeshType& m, const std::vector<Atom>& atoms, double grow, const Params& p = {}) {
    const double meanEdge = MeanEdgeLength(m);
    PointSet refused;
    for (int attempt = 1;; ++attempt) {
      Refinement r(atoms, grow, p, refused);
      r.Load(m);
      for (int pass = 0; pass < p.passes && r.SplitPass(); ++pass) {
      }
      const std::vector<Point> spoilt = r.SpoilingMoves(meanEdge);
      if (spoilt.empty() || attempt >= p.attempts) {
        if (!spoilt.empty()) r.FlattenBadSplits(meanEdge);
        r.result.refused = refused.size();
        r.Store(m);
        return r.result;
      }
      refused.insert(spoilt.begin(), spoilt.end());
    }
  }

private:
  using Triangle = std::array<Index, 3>;
  using Owners = std::vector<Index>;                   ///< atoms whose sphere a vertex lies on
  static constexpr double kNeedleCos = -0.98480775301; ///< cos 170 degrees

  /// Positions of moves, exactly: a move is made again in a later attempt at the same position
  /// (the computation does not change), and not at all once refused.
  struct PointHash {
    std::size_t operator()(const Point& x) const {
      std::uint64_t h = 0;
      for (int k = 0; k < 3; ++k) {
        std::uint64_t bits;
        std::memcpy(&bits, &x[k], sizeof bits);
        h = (h ^ bits) * 0x100000001b3ull;
      }
      return std::size_t(h ^ (h >> 29));
    }
  };
  using PointSet = std::unordered_set<Point, PointHash>;

  /// Where a moved vertex came from, for putting it back: a split vertex from its edge (u, v) at
  /// parameter t; a vertex snapped onto a crease passing next to it from its own position.
  struct Split {
    Index vertex, u, v;
    double t;
    bool snapped;
    Point original;
  };

  struct Refinement {
    Refinement(const std::vector<Atom>& a, double g, const Params& params, const PointSet& no)
        : atoms(a), grow(g), p(params), refused(no), cells(a, MaxAtomRadius(a) + g + 1.0), balls(a, g, 1.0) {}

    void Load(const MeshType& m) {
      points.resize(m.vert.size());
      for (std::size_t v = 0; v < m.vert.size(); ++v) points[v] = PositionOf(&m.vert[v]);
      owners.resize(points.size());
      for (std::size_t v = 0; v < points.size(); ++v)
        if (!m.vert[v].IsD()) owners[v] = OwnersAt(points[v]);
      for (const auto& f : m.face)
        if (!f.IsD()) {
          tris.push_back({Index(vcg::tri::Index(m, f.cV(0))), Index(vcg::tri::Index(m, f.cV(1))),
                          Index(vcg::tri::Index(m, f.cV(2)))});
          rootNormals.push_back(Normal(tris.back()));
          rootLargestCos.push_back(LargestAngleCos(tris.back()));
        }
      roots.resize(tris.size());
      for (std::size_t i = 0; i < tris.size(); ++i) roots[i] = Index(i);
    }

    /// Splits every bridging edge once; false when there was none.
    bool SplitPass() {
      std::unordered_map<std::uint64_t, Index> splitOf;
      for (const Triangle& t : tris)
        for (int k = 0; k < 3; ++k) {
          const Index u = std::min(t[k], t[(k + 1) % 3]), v = std::max(t[k], t[(k + 1) % 3]);
          const std::uint64_t key = (std::uint64_t(u) << 32) | v;
          if (splitOf.count(key)) continue;
          const Index s = SplitEdge(u, v);
          if (s != kNoIndex) splitOf.emplace(key, s);
        }
      if (splitOf.empty()) return false;
      auto at = [&](Index a, Index b) {
        const auto it = splitOf.find((std::uint64_t(std::min(a, b)) << 32) | std::max(a, b));
        return it == splitOf.end() ? kNoIndex : it->second;
      };
      std::vector<Triangle> next;
      std::vector<Index> nextRoots;
      for (std::size_t i = 0; i < tris.size(); ++i) {
        const Triangle& t = tris[i];
        const std::size_t before = next.size();
        Subdivide(t, {at(t[0], t[1]), at(t[1], t[2]), at(t[2], t[0])}, next);
        nextRoots.insert(nextRoots.end(), next.size() - before, roots[i]);
      }
      tris.swap(next);
      roots.swap(nextRoots);
      return true;
    }

    /// The crossing pairs of faces. The mesh did not cross itself before, so only faces with a
    /// moved vertex can, and only with faces near them: the test runs on those (the faces with a
    /// cell of a grid of twice the mean edge in common with a moved face).
    std::vector<std::pair<Index, Index>> Crossings(double meanEdge) const {
      std::vector<bool> moved(points.size(), false);
      for (const Split& s : splits) moved[s.vertex] = true;
      const double cell = 2 * meanEdge;
      auto cellsOf = [&](const Triangle& t, auto&& visit) {
        long lo[3], hi[3];
        for (int k = 0; k < 3; ++k) {
          const double a = std::min({points[t[0]][k], points[t[1]][k], points[t[2]][k]});
          const double b = std::max({points[t[0]][k], points[t[1]][k], points[t[2]][k]});
          lo[k] = long(std::floor(a / cell));
          hi[k] = long(std::floor(b / cell));
        }
        for (long x = lo[0]; x <= hi[0]; ++x)
          for (long y = lo[1]; y <= hi[1]; ++y)
            for (long z = lo[2]; z <= hi[2]; ++z)
              visit((std::uint64_t(x & 0x1FFFFF) << 42) | (std::uint64_t(y & 0x1FFFFF) << 21) |
                    std::uint64_t(z & 0x1FFFFF));
      };
      std::unordered_set<std::uint64_t> near;
      for (const Triangle& t : tris)
        if (moved[t[0]] || moved[t[1]] || moved[t[2]])
          cellsOf(t, [&](std::uint64_t key) { near.insert(key); });
      std::vector<Triangle> local;
      std::vector<Index> globalOf;
      for (std::size_t i = 0; i < tris.size(); ++i) {
        bool in = false;
        cellsOf(tris[i], [&](std::uint64_t key) { in = in || near.count(key) > 0; });
        if (!in) continue;
        local.push_back(tris[i]);
        globalOf.push_back(Index(i));
      }
      std::vector<std::pair<Index, Index>> pairs;
      for (const IntersectingPair& pair : FindSelfIntersections(local, points, meanEdge, p.threads))
        pairs.emplace_back(globalOf[pair.i], globalOf[pair.j]);
      return pairs;
    }

    /// Where the moves are that spoil a face: per face that is not Acceptable, the position of its
    /// corner that moved farthest; when all are, those of every moved corner of crossing faces.
    std::vector<Point> SpoilingMoves(double meanEdge) {
      recordOf.assign(points.size(), kNoIndex);
      for (std::size_t r = 0; r < splits.size(); ++r) recordOf[splits[r].vertex] = Index(r);
      std::vector<bool> bad(points.size(), false);
      auto mark = [&](const Triangle& t) {
        for (Index v : t)
          if (recordOf[v] != kNoIndex) bad[v] = true;
      };
      bool any = false;
      for (std::size_t i = 0; i < tris.size(); ++i)
        if (!Acceptable(i)) {
          MarkFarthestMove(tris[i], bad);
          any = true;
        }
      if (!any)
        for (const auto& [i, j] : Crossings(meanEdge)) {
          mark(tris[i]);
          mark(tris[j]);
        }
      std::vector<Point> spoilt;
      for (const Split& s : splits)
        if (bad[s.vertex]) spoilt.push_back(points[s.vertex]);
      return spoilt;
    }

    /// Marks the moved corner of t that moved farthest from where it came from (its edge, or its
    /// own position when snapped). A face with two moved corners is mostly spoilt by the one that
    /// moved far; refusing both left about twice as many creases bridged (1UBQ's SAS: 1698 refused
    /// moves against 895, area -1.16 % against -0.86 % of freesasa's). The other is refused in a
    /// later attempt if the face is still spoilt.
    void MarkFarthestMove(const Triangle& t, std::vector<bool>& bad) const {
      Index farthest = kNoIndex;
      double largest = -1;
      for (Index v : t) {
        if (recordOf[v] == kNoIndex) continue;
        const Split& s = splits[recordOf[v]];
        const Point from = s.snapped ? s.original : points[s.u] + (points[s.v] - points[s.u]) * s.t;
        const double distance = (points[v] - from).Norm();
        if (distance > largest) largest = distance, farthest = v;
      }
      if (farthest != kNoIndex) bad[farthest] = true;
    }

    /// Puts back the moved vertices of faces turned against (or collapsed from) the face they came
    /// from, or made needles, and of crossing faces, until none is left; all put back, the mesh is
    /// the unsplit surface (subdivided flat), which was valid.
    void FlattenBadSplits(double meanEdge) {
      flat.assign(points.size(), false);
      recordOf.assign(points.size(), kNoIndex);
      for (std::size_t r = 0; r < splits.size(); ++r) recordOf[splits[r].vertex] = Index(r);
      for (int crossingTests = 0;;) {
        for (int round = 0; round < 20; ++round) { // the local check is cheap: until it holds
          bool changed = false;
          for (std::size_t i = 0; i < tris.size(); ++i)
            if (!Acceptable(i)) changed |= MarkFlat(tris[i]);
          if (!changed) break;
          PutBackFlat();
        }
        bool changed = false;
        for (const auto& [i, j] : Crossings(meanEdge)) changed |= MarkFlat(tris[i]) | MarkFlat(tris[j]);
        if (!changed) break;
        if (++crossingTests == 3) { // the crossing test is not: past a few, all go back (valid)
          std::fill(flat.begin(), flat.end(), true);
          PutBackFlat();
          break;
        }
        PutBackFlat();
      }
      result.flattened = std::size_t(
          std::count_if(splits.begin(), splits.end(), [&](const Split& s) { return bool(flat[s.vertex]); }));
    }

    /// Face i faces the side the face it came from faces, and is no needle (largest angle over 170
    /// degrees) unless that face was.
    bool Acceptable(std::size_t i) const {
      const Point n = Normal(tris[i]), n0 = rootNormals[roots[i]];
      if (!(n * n0 > 0)) return false;
      return LargestAngleCos(tris[i]) > std::min(kNeedleCos, rootLargestCos[roots[i]]);
    }

    double LargestAngleCos(const Triangle& t) const {
      double cosine = 1;
      for (int k = 0; k < 3; ++k) {
        const Point a = points[t[(k + 1) % 3]] - points[t[k]], b = points[t[(k + 2) % 3]] - points[t[k]];
        const double ab = a.Norm() * b.Norm();
        cosine = std::min(cosine, ab > 0 ? (a * b) / ab : -1.0);
      }
      return cosine;
    }

    void Store(MeshType& m) const {
      using CoordType = typename MeshType::CoordType;
      using ScalarType = typename MeshType::ScalarType;
      const std::size_t first = m.vert.size();
      vcg::tri::Allocator<MeshType>::AddVertices(m, points.size() - first);
      for (const Split& s : splits) // the new vertices and the snapped ones
        m.vert[s.vertex].P() = CoordType(ScalarType(points[s.vertex][0]), ScalarType(points[s.vertex][1]),
                                         ScalarType(points[s.vertex][2]));
      for (auto& f : m.face)
        if (!f.IsD()) vcg::tri::Allocator<MeshType>::DeleteFace(m, f);
      vcg::tri::Allocator<MeshType>::CompactFaceVector(m);
      auto face = vcg::tri::Allocator<MeshType>::AddFaces(m, tris.size());
      for (const Triangle& t : tris) {
        for (int k = 0; k < 3; ++k) face->V(k) = &m.vert[t[k]];
        ++face;
      }
    }

    /// The atoms whose sphere x lies on; none when x is inside a sphere (not on the surface).
    Owners OwnersAt(const Point& x) const {
      Owners on;
      bool buried = false;
      cells.ForNear(x, [&](const Atom& a) {
        const double value = (x - a.position).Norm() - (a.radius + grow);
        if (value < -p.tolerance) buried = true;
        if (std::fabs(value) <= p.tolerance) on.push_back(Index(&a - atoms.data()));
      });
      if (buried) on.clear();
      std::sort(on.begin(), on.end());
      return on;
    }

    /// The split vertex of edge (u, v), added, or kNoIndex when the edge bridges no crease or one
    /// of its ends was snapped onto the crease instead.
    Index SplitEdge(Index u, Index v) {
      const Owners &a = owners[u], &b = owners[v];
      if (a.empty() || b.empty()) return kNoIndex;
      for (Index x : a)
        if (std::binary_search(b.begin(), b.end(), x)) return kNoIndex; // both on one sphere
      const double length = (points[v] - points[u]).Norm();
      double bestDistance = 1e300, bestT = 0;
      Point best(0, 0, 0);
      for (Index i : a)
        for (Index j : b) {
          Point y;
          double t = 0;
          if (!CreasePoint(points[u], points[v], i, j, y, t)) continue;
          const double d = (y - (points[u] + (points[v] - points[u]) * t)).Norm();
          if (d < bestDistance) {
            bestDistance = d;
            best = y;
            bestT = t;
          }
        }
      if (!(bestDistance <= length)) return SplitAtUnion(u, v);
      if (bestT < 0.1 || bestT > 0.9) { // a split would leave a sliver: move the nearer end instead
        Snap(bestT < 0.5 ? u : v, best);
        return kNoIndex;
      }
      return AddSplit(u, v, bestT, best);
    }

    /// Where no crease point of the ends' spheres is on the surface (a third sphere covers it),
    /// the midpoint projected onto the union: its new edges then bridge creases of that sphere.
    Index SplitAtUnion(Index u, Index v) {
      const Point mid = (points[u] + points[v]) * 0.5;
      const Point y = ProjectToLevel(mid, balls, 0.0, (points[v] - points[u]).Norm());
      const Owners on = OwnersAt(y);
      if (on.empty()) return kNoIndex;
      for (Index x : on)
        if (std::binary_search(owners[u].begin(), owners[u].end(), x) ||
            std::binary_search(owners[v].begin(), owners[v].end(), x))
          return kNoIndex; // no third sphere: the crease is too far from the edge
      return AddSplit(u, v, 0.5, y);
    }

    Index AddSplit(Index u, Index v, double t, const Point& y) {
      if (refused.count(y)) return kNoIndex;
      const Index s = Index(points.size());
      points.push_back(y);
      owners.push_back(OwnersAt(y));
      splits.push_back({s, u, v, t, false, y});
      ++result.splitEdges;
      return s;
    }

    void Snap(Index v, const Point& y) {
      if (snappedVertices.count(v) || refused.count(y)) return;
      snappedVertices.insert(v);
      splits.push_back({v, v, v, 0.0, true, points[v]});
      points[v] = y;
      owners[v] = OwnersAt(y);
      ++result.snappedVertices;
    }

    /// The point y of the circle where spheres i and j meet above the point at t where segment
    /// (pu, pv) crosses their radical plane; false when there is none or it is inside another sphere.
    bool CreasePoint(const Point& pu, const Point& pv, Index i, Index j, Point& y, double& t) const {
      const Point ci = atoms[i].position, cj = atoms[j].position;
      const double ri = atoms[i].radius + grow, rj = atoms[j].radius + grow, d = (cj - ci).Norm();
      if (!(d > 0) || d >= ri + rj || d <= std::fabs(ri - rj)) return false;
      const Point axis = (cj - ci) / d;
      const double along = (d * d + ri * ri - rj * rj) / (2 * d), rho2 = ri * ri - along * along;
      if (!(rho2 > 0)) return false;
      const Point centre = ci + axis * along;
      const double fu = (pu - centre) * axis, fv = (pv - centre) * axis;
      if (!(fu * fv <= 0) || fu == fv) return false;
      t = fu / (fu - fv);
      const Point x = pu + (pv - pu) * t;
      Point radial = x - axis * ((x - centre) * axis) - centre;
      if (!(radial.Norm() > 1e-12)) return false;
      y = centre + radial * (std::sqrt(rho2) / radial.Norm());
      const Owners on = OwnersAt(y);
      return std::binary_search(on.begin(), on.end(), i) && std::binary_search(on.begin(), on.end(), j);
    }

    /// The triangles of t with its split edges' vertices s (kNoIndex: not split), appended.
    void Subdivide(const Triangle& t, const std::array<Index, 3>& s, std::vector<Triangle>& out) const {
      const int count = int(s[0] != kNoIndex) + int(s[1] != kNoIndex) + int(s[2] != kNoIndex);
      if (count == 0) {
        out.push_back(t);
        return;
      }
      if (count == 3) {
        out.push_back({t[0], s[0], s[2]});
        out.push_back({s[0], t[1], s[1]});
        out.push_back({s[2], s[1], t[2]});
        out.push_back({s[0], s[1], s[2]});
        return;
      }
      // Rotate so that edge 0 (t0, t1) is split and, with two, edge 1 (t1, t2) is the other.
      int k = 0;
      if (count == 1)
        while (s[k] == kNoIndex) ++k;
      else
        while (s[k] == kNoIndex || s[(k + 1) % 3] == kNoIndex) ++k;
      const Index a = t[k], b = t[(k + 1) % 3], c = t[(k + 2) % 3], sab = s[k], sbc = s[(k + 1) % 3];
      if (count == 1) {
        out.push_back({a, sab, c});
        out.push_back({sab, b, c});
        return;
      }
      out.push_back({sab, b, sbc});
      // The quad (a, sab, sbc, c) by its shorter diagonal.
      if ((points[a] - points[sbc]).SquaredNorm() <= (points[sab] - points[c]).SquaredNorm()) {
        out.push_back({a, sab, sbc});
        out.push_back({a, sbc, c});
      } else {
        out.push_back({a, sab, c});
        out.push_back({sab, sbc, c});
      }
    }

    /// Marks t's moved vertices to be put back, and the moved ends of the edges they split (so
    /// that each lands on the unsplit surface); false if all were marked already.
    bool MarkFlat(const Triangle& t) {
      bool marked = false;
      std::vector<Index> stack(t.begin(), t.end());
      while (!stack.empty()) {
        const Index v = stack.back();
        stack.pop_back();
        if (recordOf[v] == kNoIndex || flat[v]) continue;
        flat[v] = marked = true;
        const Split& s = splits[recordOf[v]];
        if (!s.snapped) stack.insert(stack.end(), {s.u, s.v});
      }
      return marked;
    }

    /// Puts the marked vertices back: snapped ones where they were, then split ones onto their
    /// edges in the order they were made (one made on an edge of another lands on that edge).
    void PutBackFlat() {
      for (const Split& s : splits)
        if (flat[s.vertex] && s.snapped) points[s.vertex] = s.original;
      for (const Split& s : splits)
        if (flat[s.vertex] && !s.snapped) points[s.vertex] = points[s.u] + (points[s.v] - points[s.u]) * s.t;
    }

    Point Normal(const Triangle& t) const {
      return (points[t[1]] - points[t[0]]) ^ (points[t[2]] - points[t[0]]);
    }

    const std::vector<Atom>& atoms;
    double grow;
    Params p;
    const PointSet& refused;
    AtomCells cells;
    BallUnionDistance balls;
    std::unordered_set<Index> snappedVertices;
    std::vector<Point> points;
    std::vector<Owners> owners;
    std::vector<Triangle> tris;
    std::vector<Index> roots;       ///< per triangle: the face of the input it lies in
    std::vector<Point> rootNormals; ///< per face of the input
    std::vector<Split> splits;
    std::vector<double> rootLargestCos; ///< per face of the input: cosine of its largest angle
    std::vector<Index> recordOf;        ///< per vertex: its entry in splits, or kNoIndex
    std::vector<bool> flat;             ///< per vertex: moved, and put back
    Result result;
  };
};

} // namespace molremesh

// Mesh quality metrics of Khan et al. 2020 (Table 2) plus the validity figures molremesh keeps.
//
// MeshQuality<MeshType>::Compute(m, params) measures any vcg triangle mesh (float or double
// coordinates) without modifying it and without requiring adjacency: topology is derived from
// a sorted edge table, so non-manifold and open inputs are measured too. All geometry is
// evaluated in double precision, so MeshLab's float CMeshO and the CLI's double mesh give the
// same figures for the same file. The work runs on params.threads threads, yet every figure is
// the same to the last bit for any thread count: per-element results are computed in parallel,
// and sums of doubles are taken serially in element order.
//
// Conventions (the figures depend on them, so they are stated once here):
//  - Deleted vertices and faces are skipped. A face with a repeated vertex index (or a null /
//    out-of-range vertex reference) is "index-degenerate": it is counted in `faces` and
//    `degenerateFaces` but takes no part in the topology (edges, Euler, components, boundary,
//    manifoldness), because it is not a 2-simplex. Every other face is a "proper" face.
//  - A face is degenerate when it is index-degenerate, has a non-finite corner, or its area is
//    <= degenerateAreaEpsilon * (median edge length)^2. The median, not the mean: one vertex sent
//    far away would inflate the mean enough to call every face of the mesh degenerate. Degenerate faces count
//    as angles {0, 0, 180}, Q = 0, AR = +inf and are left out of area, volume and self-intersections.
//  - Components are connected through shared edges: faces touching only at a vertex belong to
//    different components. That vertex is a non-manifold vertex of the mesh, but each component
//    is judged on its own: it is non-manifold only if it has a non-manifold edge or holds two or
//    more fans of one vertex. So two closed spheres touching at a point report
//    nonManifoldVertices = 1 (isTwoManifold() false) yet genus 0 + 0.
//  - A non-manifold vertex is one whose incident faces form more than one fan, fans being joined
//    through the manifold (two-face) edges at the vertex. As in vcglib's
//    Clean::CountNonManifoldVertexFF, vertices on a non-manifold edge are not counted again as
//    non-manifold vertices: the edge already reports the defect.
//  - Self-intersections treat triangles as closed sets: faces that merely touch (e.g. at two
//    distinct vertices with the same position) intersect, as in vcglib's Clean::SelfIntersections.
#pragma once

#include <vcg/complex/complex.h>

#include <vcg_ext/core/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <map>
#include <numeric>
#include <utility>
#include <vector>

namespace molremesh {

/// Angles of one triangle in degrees, and how it classifies. A face whose corners coincide or
/// whose vertex indices repeat has undefined angles: it is reported as {0, 0, 180}.
struct TriangleAngles {
  std::array<double, 3> degrees{0.0, 0.0, 180.0}; ///< angle at corner i, in degrees
  double min() const;
  double max() const;
};

/// Per connected component (faces connected through shared edges).
struct ComponentInfo {
  std::size_t faces = 0;
  std::size_t boundaryEdges = 0;
  bool manifold = true; ///< no non-manifold edge or vertex in the component on its own: a vertex
                        ///< where different components touch (one fan each) does not count
  bool closed = false;  ///< manifold and no boundary edge
  int euler = 0;        ///< V - E + F of the component
  int genus = -1;       ///< (2 - euler - boundary loops) / 2; -1 when not manifold (or not orientable:
                        ///< an odd 2 - euler - loops)
  std::size_t boundaryLoops = 0; ///< closed boundary polylines of the component
};

/// Every figure the quality report prints. Angles are in degrees, percentages in [0, 100].
struct QualityReport {
  // Element counts
  std::size_t vertices = 0;             ///< live vertices (not deleted)
  std::size_t referencedVertices = 0;   ///< vertices used by at least one face
  std::size_t unreferencedVertices = 0; ///< vertices used by no face
  std::size_t nonFiniteVertices = 0;    ///< vertices with a NaN or infinite coordinate
  std::size_t faces = 0;                ///< live faces
  std::size_t edges = 0;                ///< distinct undirected edges (of proper faces)

  // Triangle shape (degenerate faces included: they count as angle 0/180, Q = 0, AR = inf)
  double qMin = 0, qAvg = 0;                      ///< Q = (6/sqrt 3) A / (p h); 1 for equilateral
  double angleMin = 0, meanMinAngle = 0;          ///< smallest angle; mean of per-face minimal angles
  double angleMax = 0;                            ///< largest angle
  double aspectRatioMax = 0, aspectRatioMean = 0; ///< AR = abc / (8 (s-a)(s-b)(s-c)); 1 for equilateral
  double aspectRatioMeanNonDegenerate = 0;        ///< mean AR over the non-degenerate faces only (finite)
  std::size_t smallAngleFaces = 0;                ///< faces with an angle < params.smallAngle
  std::size_t obtuseFaces = 0;                    ///< faces with max angle >= params.obtuseAngle
  std::size_t largeAngleFaces = 0;                ///< faces with an angle > params.largeAngle
  double smallAnglePercent = 0, obtusePercent = 0, largeAnglePercent = 0;

  // Valence of interior vertices (not on a boundary or non-manifold edge)
  std::size_t interiorVertices = 0;
  std::size_t regularVertices = 0;             ///< interior with valence 5, 6 or 7
  double v567Percent = 0;                      ///< 100 * regular / interior (100 when there is none)
  std::map<int, std::size_t> valenceHistogram; ///< valence -> number of interior vertices

  // Geometry
  double area = 0;             ///< total surface area
  double volume = 0;           ///< signed enclosed volume (divergence theorem); meaningful when closed
  double meanEdgeLength = 0;   ///< mean length of the distinct edges with finite end points
  double medianEdgeLength = 0; ///< median of the same lengths (the scale of degenerateAreaEpsilon)

  // Topology and validity
  int euler = 0;              ///< V - E + F over referenced vertices
  int genus = -1;             ///< sum of component genera; -1 when any component is non-manifold
  std::size_t components = 0; ///< connected components (through shared edges)
  std::vector<ComponentInfo> componentInfo; ///< one entry per component, largest first
  std::size_t boundaryEdges = 0;            ///< edges with exactly one face
  std::size_t boundaryLoops = 0;            ///< closed boundary polylines (manifold parts only)
  std::size_t nonManifoldEdges = 0;         ///< edges with more than two faces
  std::size_t nonManifoldVertices = 0;      ///< vertices whose face fan is not one edge-connected fan
  std::size_t degenerateFaces = 0;          ///< repeated vertex index or (near) zero area
  std::size_t selfIntersectingPairs = 0;    ///< pairs of faces sharing no vertex that intersect
  std::size_t adjacentOverlapPairs = 0;     ///< pairs sharing exactly one vertex that meet elsewhere too
  std::size_t selfIntersectingFaces = 0;    ///< faces in at least one of the two kinds of pairs above
  bool selfIntersectionsComputed = false;

  bool isTwoManifold() const { return nonManifoldEdges == 0 && nonManifoldVertices == 0; }
};

/// What MeshQuality reads of a mesh, copied in one pass: the figures can then be computed from it
/// later, or on another thread, while the mesh itself goes on changing.
struct QualityCapture {
  std::size_t vertexCount = 0;                     ///< size of m.vert
  std::vector<std::array<std::uint32_t, 3>> faces; ///< live faces, in m.face order; an invalid
                                                   ///< vertex reference is UINT32_MAX
  std::vector<bool> proper;                        ///< per face: three distinct valid vertex indices
  std::vector<vcg::Point3d> points;                ///< per vertex (deleted ones too), in double
  std::vector<bool> live;                          ///< per vertex: not deleted
};

template <class MeshType>
class MeshQuality {
public:
  struct Params {
    double smallAngle = 30.0;             ///< degrees; faces with an angle below it are "small"
    double obtuseAngle = 90.0;            ///< degrees; faces whose max angle is >= it are obtuse
    double largeAngle = 120.0;            ///< degrees; faces with an angle above it are "large"
    bool computeSelfIntersections = true; ///< the only super-linear part; grid accelerated
    double degenerateAreaEpsilon = 1e-12; ///< relative to squared median edge length
    int threads = 0;                      ///< worker threads; 0 = all cores (the figures do not depend on it)
  };

  /// Measures m. m is not modified; deleted elements are skipped.
  static QualityReport Compute(const MeshType& m, const Params& params = Params()) {
    return Compute(Capture(m), params);
  }
  /// What Compute reads of m (a linear copy), and the figures of such a copy: Compute(Capture(m))
  /// is Compute(m), to the last bit.
  static QualityCapture Capture(const MeshType& m);
  static QualityReport Compute(QualityCapture capture, const Params& params);

  /// Angles of face f (double precision). Without the mesh there is no mean edge length, so a
  /// face is degenerate here when its area is <= Params().degenerateAreaEpsilon * (longest edge)^2.
  static TriangleAngles FaceAngles(const typename MeshType::FaceType& f);

  /// Valence (number of distinct incident edges) of every vertex, indexed like m.vert.
  static std::vector<int> VertexValences(const MeshType& m);

  /// Per vertex: true when it lies on a boundary or a non-manifold edge, indexed like m.vert.
  static std::vector<bool> VertexOnBorder(const MeshType& m);
};

// ------------------------------------------------------------------------------------------------
// Implementation
// ------------------------------------------------------------------------------------------------

inline double TriangleAngles::min() const {
  return std::min({degrees[0], degrees[1], degrees[2]});
}
inline double TriangleAngles::max() const {
  return std::max({degrees[0], degrees[1], degrees[2]});
}

namespace quality_detail {

using Point = vcg::Point3d;
using Index = std::uint32_t;
constexpr Index kNoIndex = std::numeric_limits<Index>::max();
constexpr double kPi = 3.14159265358979323846;

inline bool IsFinite(const Point& p) {
  return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
}

/// Union-find with path halving; the smaller index becomes the root so results are independent
/// of the union order (the reports must be deterministic).
class UnionFind {
public:
  explicit UnionFind(std::size_t n = 0) : parent_(n) { std::iota(parent_.begin(), parent_.end(), Index(0)); }
  Index Find(Index x) {
    while (parent_[x] != x) {
      parent_[x] = parent_[parent_[x]];
      x = parent_[x];
    }
    return x;
  }
  void Unite(Index a, Index b) {
    a = Find(a);
    b = Find(b);
    if (a == b) return;
    if (a < b)
      parent_[b] = a;
    else
      parent_[a] = b;
  }

private:
  std::vector<Index> parent_;
};

// --- Triangle shape ------------------------------------------------------------------------------

struct TriangleShape {
  bool degenerate = true;
  double area = 0;
  double q = 0;
  double aspectRatio = std::numeric_limits<double>::infinity();
  std::array<double, 3> angles{0.0, 0.0, 180.0};
};

/// Shape of the triangle (p0, p1, p2); degenerate when the area is <= degenerateArea or a corner
/// is not finite. The area is returned even for degenerate (finite) triangles.
inline TriangleShape ShapeOf(const Point& p0, const Point& p1, const Point& p2, double degenerateArea) {
  TriangleShape s;
  if (!IsFinite(p0) || !IsFinite(p1) || !IsFinite(p2)) return s;
  const std::array<Point, 3> p{p0, p1, p2};
  std::array<double, 3> len{}; // len[i] = edge opposite corner i
  for (int i = 0; i < 3; ++i) len[i] = (p[(i + 2) % 3] - p[(i + 1) % 3]).Norm();
  s.area = 0.5 * ((p1 - p0) ^ (p2 - p0)).Norm();
  if (!(s.area > degenerateArea) || !std::isfinite(s.area)) return s;

  s.degenerate = false;
  const double halfPerimeter = 0.5 * (len[0] + len[1] + len[2]);
  const double longest = std::max({len[0], len[1], len[2]});
  s.q = (6.0 / std::sqrt(3.0)) * s.area / (halfPerimeter * longest);
  // (s-a)(s-b)(s-c) = A^2 / s (Heron): avoids the cancellation of s-a on needle triangles.
  s.aspectRatio = len[0] * len[1] * len[2] * halfPerimeter / (8.0 * s.area * s.area);
  for (int i = 0; i < 3; ++i) {
    // atan2(|u x v|, u.v) stays accurate near 0 and 180 degrees, where acos loses digits.
    const Point u = p[(i + 1) % 3] - p[i];
    const Point v = p[(i + 2) % 3] - p[i];
    s.angles[i] = std::atan2((u ^ v).Norm(), u * v) * (180.0 / kPi);
  }
  return s;
}

// --- Triangle / triangle intersection -------------------------------------------------------------
//
// Both tests reduce to "closed segment meets closed triangle": two triangles meet iff an edge of
// one meets the other (the intersection is convex and its extreme points lie on edges). Plane
// sides are signed distances snapped to 0 within rounding noise, so that exactly coplanar inputs
// (flat patches) take the 2D branch instead of a numerically meaningless line crossing.

/// Triangle with its plane and the axis dropped to project it to 2D.
struct PlanarTriangle {
  std::array<Point, 3> p;
  Point unitNormal;
  int axisU = 0, axisV = 1; ///< coordinates kept by the 2D projection
};

inline PlanarTriangle MakePlanarTriangle(const Point& a, const Point& b, const Point& c) {
  PlanarTriangle t;
  t.p = {a, b, c};
  const Point n = (b - a) ^ (c - a);
  const double len = n.Norm();
  t.unitNormal = len > 0 ? n / len : Point(0, 0, 0);
  int drop = 0;
  if (std::fabs(n[1]) > std::fabs(n[drop])) drop = 1;
  if (std::fabs(n[2]) > std::fabs(n[drop])) drop = 2;
  t.axisU = (drop + 1) % 3;
  t.axisV = (drop + 2) % 3;
  return t;
}

inline double Orient2D(const Point& a, const Point& b, const Point& c, int u, int v) {
  return (b[u] - a[u]) * (c[v] - a[v]) - (b[v] - a[v]) * (c[u] - a[u]);
}

/// Closed point-in-triangle test in the triangle's 2D projection.
inline bool PointInTriangle2D(const PlanarTriangle& t, const Point& x) {
  const double d0 = Orient2D(t.p[0], t.p[1], x, t.axisU, t.axisV);
  const double d1 = Orient2D(t.p[1], t.p[2], x, t.axisU, t.axisV);
  const double d2 = Orient2D(t.p[2], t.p[0], x, t.axisU, t.axisV);
  return (d0 >= 0 && d1 >= 0 && d2 >= 0) || (d0 <= 0 && d1 <= 0 && d2 <= 0);
}

/// Closed segment/segment test in 2D (coordinates u, v).
inline bool SegmentsMeet2D(const Point& p, const Point& q, const Point& a, const Point& b, int u, int v) {
  const double o1 = Orient2D(p, q, a, u, v), o2 = Orient2D(p, q, b, u, v);
  const double o3 = Orient2D(a, b, p, u, v), o4 = Orient2D(a, b, q, u, v);
  if ((o1 > 0 && o2 > 0) || (o1 < 0 && o2 < 0)) return false;
  if ((o3 > 0 && o4 > 0) || (o3 < 0 && o4 < 0)) return false;
  if ((o1 == 0 && o2 == 0) || (o3 == 0 && o4 == 0)) {
    // Collinear: the segments meet iff their extents overlap on both axes.
    for (int axis : {u, v})
      if (std::max(p[axis], q[axis]) < std::min(a[axis], b[axis]) ||
          std::max(a[axis], b[axis]) < std::min(p[axis], q[axis]))
        return false;
  }
  return true;
}

inline double MaxAbs(const Point& p) {
  return std::max({std::fabs(p[0]), std::fabs(p[1]), std::fabs(p[2])});
}

/// Signed distance of x from the plane of t, snapped to 0 when it is within rounding noise, so
/// that exactly coplanar inputs (flat patches) take the 2D branch. It is measured from the corner
/// nearest to x: measuring from a far corner (a fan around a vertex sent far away) would lose to
/// cancellation all the digits that tell neighbouring faces apart. The snap threshold scales with
/// the magnitude of the coordinates involved, which bounds their rounding error; erring small
/// is safe (a missed snap only costs the exact 2D answer, never invents an intersection).
inline double PlaneDistance(const PlanarTriangle& t, const Point& x) {
  int nearest = 0;
  double best = (x - t.p[0]).SquaredNorm();
  for (int k = 1; k < 3; ++k) {
    const double d2 = (x - t.p[k]).SquaredNorm();
    if (d2 < best) best = d2, nearest = k;
  }
  const double d = t.unitNormal * (x - t.p[nearest]);
  const double tol = 1e-13 * (MaxAbs(x) + MaxAbs(t.p[nearest]));
  return std::fabs(d) <= tol ? 0.0 : d;
}

/// Closed segment pq against closed triangle t.
inline bool SegmentMeetsTriangle(const Point& p, const Point& q, const PlanarTriangle& t) {
  const double dp = PlaneDistance(t, p), dq = PlaneDistance(t, q);
  if ((dp > 0 && dq > 0) || (dp < 0 && dq < 0)) return false;
  if (dp == 0 && dq == 0) {
    if (PointInTriangle2D(t, p) || PointInTriangle2D(t, q)) return true;
    for (int i = 0; i < 3; ++i)
      if (SegmentsMeet2D(p, q, t.p[i], t.p[(i + 1) % 3], t.axisU, t.axisV)) return true;
    return false;
  }
  // Exactly one crossing point of the plane; it is inside the segment by the sign test.
  const Point x = p + (q - p) * (dp / (dp - dq));
  return PointInTriangle2D(t, x);
}

/// True when every vertex of `other` is strictly on the same side of t's plane.
inline bool StrictlyOnOneSide(const PlanarTriangle& t, const PlanarTriangle& other) {
  const double d0 = PlaneDistance(t, other.p[0]);
  const double d1 = PlaneDistance(t, other.p[1]);
  const double d2 = PlaneDistance(t, other.p[2]);
  return (d0 > 0 && d1 > 0 && d2 > 0) || (d0 < 0 && d1 < 0 && d2 < 0);
}

/// Closed triangle/triangle intersection (for faces sharing no vertex).
inline bool TrianglesIntersect(const PlanarTriangle& a, const PlanarTriangle& b) {
  if (StrictlyOnOneSide(a, b) || StrictlyOnOneSide(b, a)) return false;
  for (int i = 0; i < 3; ++i) {
    if (SegmentMeetsTriangle(b.p[i], b.p[(i + 1) % 3], a)) return true;
    if (SegmentMeetsTriangle(a.p[i], a.p[(i + 1) % 3], b)) return true;
  }
  return false;
}

/// Triangles sharing exactly the corner a.p[ca] == b.p[cb]: true when they meet anywhere else.
/// Their intersection is a convex set containing the shared corner; it holds another point iff
/// the edge opposite the shared corner of one triangle meets the other (that edge does not
/// contain the shared corner, so the trivial contact is never reported).
inline bool SharedCornerOverlap(const PlanarTriangle& a, int ca, const PlanarTriangle& b, int cb) {
  return SegmentMeetsTriangle(a.p[(ca + 1) % 3], a.p[(ca + 2) % 3], b) ||
         SegmentMeetsTriangle(b.p[(cb + 1) % 3], b.p[(cb + 2) % 3], a);
}

// --- Topology ------------------------------------------------------------------------------------

/// Edge table and incidence relations of the proper faces, in compressed-row form.
struct Topology {
  std::size_t vertexCount = 0;                 ///< size of m.vert
  std::vector<std::array<Index, 3>> faces;     ///< live faces, in m.face order (compact numbering)
  std::vector<bool> proper;                    ///< three distinct valid vertex indices
  std::vector<std::uint64_t> edgeKeys;         ///< (min << 32 | max), sorted, one per distinct edge
  std::vector<Index> edgeFaceStart, edgeFaces; ///< faces of edge e: [start[e], start[e+1])
  std::vector<Index> vertEdgeStart, vertEdges; ///< edges at vertex v
  std::vector<Index> vertFaceStart, vertFaces; ///< proper faces at vertex v, ascending
  std::vector<bool> onNonManifoldEdge;         ///< per vertex
  std::vector<bool> onBorder;                  ///< per vertex: boundary or non-manifold edge

  Index EdgeV0(std::size_t e) const { return Index(edgeKeys[e] >> 32); }
  Index EdgeV1(std::size_t e) const { return Index(edgeKeys[e] & 0xffffffffu); }
  Index EdgeFaceCount(std::size_t e) const { return edgeFaceStart[e + 1] - edgeFaceStart[e]; }
};

/// Builds everything but `faces`/`proper`/`vertexCount`, which the caller fills.
///
/// Linear time: every table is filled by counting sort (bucket by vertex), which keeps the
/// faces and edges of one bucket in ascending order for free; only the few sides at one vertex
/// are sorted among themselves. The pipeline reports after every stage, and three general sorts
/// of 1.5 M entries each cost more there than all the other figures together. Those per-vertex
/// sorts, and the edges they give, run on `threads` threads: each vertex writes only its own part
/// of the tables, at offsets counted beforehand, so the tables do not depend on the thread count.
inline void BuildTopology(Topology& t, int threads) {
  const std::size_t nv = t.vertexCount;
  const std::size_t nf = t.faces.size();

  // Each proper face side as (larger vertex, face), bucketed by its smaller vertex; faces are
  // visited in ascending order, so each bucket lists them ascending.
  std::vector<Index> sideStart(nv + 1, 0);
  for (std::size_t f = 0; f < nf; ++f) {
    if (!t.proper[f]) continue;
    for (int i = 0; i < 3; ++i) ++sideStart[std::min(t.faces[f][i], t.faces[f][(i + 1) % 3]) + 1];
  }
  for (std::size_t v = 0; v < nv; ++v) sideStart[v + 1] += sideStart[v];
  std::vector<std::pair<Index, Index>> sides(sideStart[nv]); // (larger vertex, face)
  {
    std::vector<Index> fill(sideStart.begin(), sideStart.end() - 1);
    for (std::size_t f = 0; f < nf; ++f) {
      if (!t.proper[f]) continue;
      for (int i = 0; i < 3; ++i) {
        const Index a = t.faces[f][i], b = t.faces[f][(i + 1) % 3];
        sides[fill[std::min(a, b)]++] = {std::max(a, b), Index(f)};
      }
    }
  }
  // Sorted, the sides of one bucket list the edges at their smaller vertex in ascending order,
  // each edge's faces ascending. edgesAt[v + 1] counts the edges of bucket v, then becomes the
  // number of the first edge of bucket v + 1.
  t.edgeFaces.resize(sides.size());
  std::vector<Index> edgesAt(nv + 1, 0);
  ParallelFor(nv, threads, [&](std::size_t vBegin, std::size_t vEnd, int) {
    for (std::size_t v = vBegin; v < vEnd; ++v) {
      std::sort(sides.begin() + sideStart[v], sides.begin() + sideStart[v + 1]); // (larger vertex, face)
      for (Index k = sideStart[v]; k < sideStart[v + 1]; ++k) {
        if (k == sideStart[v] || sides[k].first != sides[k - 1].first) ++edgesAt[v + 1];
        t.edgeFaces[k] = sides[k].second;
      }
    }
  });
  for (std::size_t v = 0; v < nv; ++v) edgesAt[v + 1] += edgesAt[v];
  const std::size_t ne = edgesAt[nv];
  t.edgeKeys.resize(ne);
  t.edgeFaceStart.resize(ne + 1);
  t.edgeFaceStart[ne] = Index(sides.size());
  ParallelFor(nv, threads, [&](std::size_t vBegin, std::size_t vEnd, int) {
    for (std::size_t v = vBegin; v < vEnd; ++v) {
      Index e = edgesAt[v];
      for (Index k = sideStart[v]; k < sideStart[v + 1]; ++k)
        if (k == sideStart[v] || sides[k].first != sides[k - 1].first) {
          t.edgeKeys[e] = (std::uint64_t(v) << 32) | sides[k].first;
          t.edgeFaceStart[e++] = k;
        }
    }
  });
  sides = std::vector<std::pair<Index, Index>>();

  // Edges at each vertex, ascending (the edges are visited in ascending order).
  t.vertEdgeStart.assign(nv + 1, 0);
  for (std::size_t e = 0; e < ne; ++e) {
    ++t.vertEdgeStart[t.EdgeV0(e) + 1];
    ++t.vertEdgeStart[t.EdgeV1(e) + 1];
  }
  for (std::size_t v = 0; v < nv; ++v) t.vertEdgeStart[v + 1] += t.vertEdgeStart[v];
  t.vertEdges.resize(t.vertEdgeStart[nv]);
  {
    std::vector<Index> fill(t.vertEdgeStart.begin(), t.vertEdgeStart.end() - 1);
    for (std::size_t e = 0; e < ne; ++e) {
      t.vertEdges[fill[t.EdgeV0(e)]++] = Index(e);
      t.vertEdges[fill[t.EdgeV1(e)]++] = Index(e);
    }
  }

  // Proper faces at each vertex, ascending.
  t.vertFaceStart.assign(nv + 1, 0);
  for (std::size_t f = 0; f < nf; ++f)
    if (t.proper[f])
      for (Index v : t.faces[f]) ++t.vertFaceStart[v + 1];
  for (std::size_t v = 0; v < nv; ++v) t.vertFaceStart[v + 1] += t.vertFaceStart[v];
  t.vertFaces.resize(t.vertFaceStart[nv]);
  {
    std::vector<Index> fill(t.vertFaceStart.begin(), t.vertFaceStart.end() - 1);
    for (std::size_t f = 0; f < nf; ++f)
      if (t.proper[f])
        for (Index v : t.faces[f]) t.vertFaces[fill[v]++] = Index(f);
  }

  t.onNonManifoldEdge.assign(nv, false);
  t.onBorder.assign(nv, false);
  for (std::size_t e = 0; e < ne; ++e) {
    const Index count = t.EdgeFaceCount(e);
    if (count == 2) continue;
    for (Index v : {t.EdgeV0(e), t.EdgeV1(e)}) {
      t.onBorder[v] = true;
      if (count > 2) t.onNonManifoldEdge[v] = true;
    }
  }
}

/// The live faces of m as vertex indices (kNoIndex for an invalid reference), and whether each is
/// proper.
template <class MeshType>
void ReadFaces(const MeshType& m, std::vector<std::array<Index, 3>>& faces, std::vector<bool>& proper) {
  faces.reserve(m.face.size());
  proper.reserve(m.face.size());
  const auto* vertBegin = m.vert.empty() ? nullptr : &m.vert[0];
  for (const auto& f : m.face) {
    if (f.IsD()) continue;
    std::array<Index, 3> idx{kNoIndex, kNoIndex, kNoIndex};
    for (int i = 0; i < 3; ++i) {
      const auto* vp = f.cV(i);
      if (vp == nullptr || vertBegin == nullptr) continue;
      const std::ptrdiff_t k = vp - vertBegin;
      if (k >= 0 && std::size_t(k) < m.vert.size()) idx[i] = Index(k);
    }
    const bool valid = idx[0] != kNoIndex && idx[1] != kNoIndex && idx[2] != kNoIndex;
    faces.push_back(idx);
    proper.push_back(valid && idx[0] != idx[1] && idx[1] != idx[2] && idx[2] != idx[0]);
  }
}

/// Reads the live faces of m into t and builds the topology on `threads` threads.
template <class MeshType>
Topology ReadTopology(const MeshType& m, int threads) {
  Topology t;
  t.vertexCount = m.vert.size();
  ReadFaces(m, t.faces, t.proper);
  BuildTopology(t, threads);
  return t;
}

// --- Self-intersections ----------------------------------------------------------------------------

/// Closed box overlap (vcg::Box3::Collide is strict, which misses flat axis-aligned faces).
inline bool BoxesTouch(const vcg::Box3d& a, const vcg::Box3d& b) {
  for (int k = 0; k < 3; ++k)
    if (a.max[k] < b.min[k] || b.max[k] < a.min[k]) return false;
  return true;
}

struct IntersectionCounts {
  std::size_t disjointPairs = 0; ///< pairs sharing no vertex that intersect
  std::size_t adjacentPairs = 0; ///< pairs sharing one vertex that also meet elsewhere
  std::size_t faces = 0;         ///< faces in at least one such pair
};

/// An intersecting pair found by FindSelfIntersections: triangles i and j (i != j, in no
/// particular order), sharing one vertex (adjacent) or none.
struct IntersectingPair {
  Index i, j;
  bool adjacent;
};

/// All intersecting pairs among the given (finite) triangles, in no particular order: pairs
/// sharing no vertex that intersect, pairs sharing one vertex that also meet elsewhere, and,
/// with duplicatesIntersect, pairs with the same three vertices (reported as adjacent).
///
/// Broad phase: a uniform grid of cells two median edge lengths wide (the median, unlike the
/// mean, is not inflated by a few huge faces). Cells are hashed by wrapping their integer
/// coordinates to 21 bits per axis, so any extent fits in a 63-bit key; faces spanning more than
/// kMaxSpan cells ("oversized", e.g. the fan of one vertex sent far away) are not hashed but
/// tested against every face, and the cell size doubles while that or the hashed entries would
/// cost too much. Each pair is tested once, in the cell holding the lowest corner of the overlap
/// of the two cell ranges (no pair set needed; aliased cells cannot repeat a pair because a
/// hashed face spans fewer than 2^21 cells per axis).
///
/// Parallel on `threads` threads, yet deterministic: per-face data are computed into per-face
/// arrays, cells are tested in parallel into per-thread lists of intersecting pairs, and the
/// pairs are gathered from those lists. Every pair is tested exactly once whichever thread
/// tests it, so the counts do not depend on the thread count.
inline std::vector<IntersectingPair> FindSelfIntersections(const std::vector<std::array<Index, 3>>& tris,
                                                           const std::vector<Point>& points,
                                                           double medianEdge, int threads,
                                                           bool duplicatesIntersect = false) {
  std::vector<IntersectingPair> result;
  const std::size_t n = tris.size();
  if (n < 2) return result;
  threads = ResolveThreadCount(threads);

  std::vector<vcg::Box3d> boxes(n);
  ParallelFor(n, threads, [&](std::size_t begin, std::size_t end, int) {
    for (std::size_t i = begin; i < end; ++i)
      for (Index v : tris[i]) boxes[i].Add(points[v]);
  });
  vcg::Box3d all;
  for (const vcg::Box3d& box : boxes) all.Add(box);

  constexpr double kMaxSpan = 512; // cells a hashed face may cover
  constexpr int kAxisBits = 21;    // 3 * 21 bits of cell key
  constexpr std::int64_t kAxisMask = (std::int64_t(1) << kAxisBits) - 1;
  const double maxExtent = std::max({all.DimX(), all.DimY(), all.DimZ()});
  double cell = 2.0 * medianEdge;
  if (!(cell > 0) || !std::isfinite(cell)) cell = maxExtent > 0 ? maxExtent : 1.0;
  const std::uint64_t budget = 32 * std::uint64_t(n) + (std::uint64_t(1) << 20);

  std::vector<std::array<std::int64_t, 3>> low(n); // lowest cell of each face, unwrapped
  std::vector<std::array<std::int64_t, 3>> high(n);
  std::vector<std::uint64_t> cellCount(n); // cells a face is hashed into: 0 when oversized
  std::vector<Index> oversizedList;
  std::uint64_t entries = 0;
  for (;;) {
    entries = 0;
    oversizedList.clear();
    // Cell coordinates must stay far inside int64.
    const bool fits = maxExtent / cell < 1e15;
    if (fits) {
      ParallelFor(n, threads, [&](std::size_t begin, std::size_t end, int) {
        for (std::size_t i = begin; i < end; ++i) {
          double span = 1;
          for (int a = 0; a < 3; ++a) {
            low[i][a] = std::int64_t(std::floor((boxes[i].min[a] - all.min[a]) / cell));
            high[i][a] = std::int64_t(std::floor((boxes[i].max[a] - all.min[a]) / cell));
            span *= double(high[i][a] - low[i][a] + 1);
          }
          cellCount[i] = span > kMaxSpan ? 0 : std::uint64_t(span);
        }
      });
      for (std::size_t i = 0; i < n; ++i) {
        if (cellCount[i] == 0) oversizedList.push_back(Index(i));
        entries += cellCount[i];
      }
    }
    if (fits && entries + std::uint64_t(oversizedList.size()) * n <= budget) break;
    cell *= 2.0;
  }

  std::vector<PlanarTriangle> planar(n);
  ParallelFor(n, threads, [&](std::size_t begin, std::size_t end, int) {
    for (std::size_t i = begin; i < end; ++i)
      planar[i] = MakePlanarTriangle(points[tris[i][0]], points[tris[i][1]], points[tris[i][2]]);
  });

  // Intersecting pairs found by each thread; `adjacent` tells the kind.
  using Hit = IntersectingPair;
  std::vector<std::vector<Hit>> hits(static_cast<std::size_t>(threads));
  auto testPair = [&](Index i, Index j, std::vector<Hit>& out) {
    if (!BoxesTouch(boxes[i], boxes[j])) return;
    int shared = 0, ci = -1, cj = -1;
    for (int u = 0; u < 3; ++u)
      for (int w = 0; w < 3; ++w)
        if (tris[i][u] == tris[j][w]) ++shared, ci = u, cj = w;
    if (shared == 3 && duplicatesIntersect) out.push_back({i, j, true});
    if (shared > 1) return;
    if (shared == 0 && TrianglesIntersect(planar[i], planar[j])) {
      out.push_back({i, j, false});
    } else if (shared == 1 && SharedCornerOverlap(planar[i], ci, planar[j], cj)) {
      out.push_back({i, j, true});
    }
  };

  // Oversized faces against everything (each oversized pair once, from its lower index).
  for (Index o : oversizedList)
    ParallelFor(n, threads, [&](std::size_t begin, std::size_t end, int thread) {
      for (std::size_t j = begin; j < end; ++j)
        if (j != o && (cellCount[j] != 0 || j > o)) testPair(o, Index(j), hits[thread]);
    });

  // Hashed faces: (wrapped cell key, face) entries, sorted so that each cell's faces are
  // contiguous and ascending. Rather than one sort of millions of entries, a counting sort deals
  // them into buckets, slabs of z (the key's most significant part), and each bucket, small enough
  // to stay in cache, is sorted on its own, in parallel: the same order as one global sort, so the
  // cells are visited in the same spatially coherent order (a hashed order costs cache misses).
  auto wrappedKey = [&](std::int64_t x, std::int64_t y, std::int64_t z) {
    return (std::uint64_t(z & kAxisMask) << (2 * kAxisBits)) | (std::uint64_t(y & kAxisMask) << kAxisBits) |
           std::uint64_t(x & kAxisMask);
  };
  auto forEachCell = [&](std::size_t i, auto&& visit) {
    for (std::int64_t z = low[i][2]; z <= high[i][2]; ++z)
      for (std::int64_t y = low[i][1]; y <= high[i][1]; ++y)
        for (std::int64_t x = low[i][0]; x <= high[i][0]; ++x) visit(wrappedKey(x, y, z));
  };
  constexpr std::size_t kFaceBlock = 4096; // faces per block of the counting sort
  constexpr std::uint64_t kMaxBuckets = 1024;
  // Wrapped z of the cells: 0 .. zMax (low and high are >= 0 by construction).
  const std::uint64_t zMax =
      std::uint64_t(std::min<double>(double(kAxisMask), std::floor(all.DimZ() / cell)));
  int zShift = 0;
  while ((zMax >> zShift) >= kMaxBuckets) ++zShift;
  const std::size_t buckets = std::size_t(zMax >> zShift) + 1;
  auto bucketOf = [&](std::uint64_t key) {
    return std::min(buckets - 1, std::size_t((key >> (2 * kAxisBits)) >> zShift));
  };
  const std::size_t blocks = (n + kFaceBlock - 1) / kFaceBlock;
  // cursor[b * buckets + k]: entries of face block b in bucket k, then where the first of them goes.
  std::vector<std::uint64_t> cursor(blocks * buckets, 0);
  auto countBlocks = [&](std::size_t bBegin, std::size_t bEnd, int) {
    for (std::size_t b = bBegin; b < bEnd; ++b)
      for (std::size_t i = b * kFaceBlock; i < std::min(n, (b + 1) * kFaceBlock); ++i)
        if (cellCount[i] != 0)
          forEachCell(i, [&](std::uint64_t key) { ++cursor[b * buckets + bucketOf(key)]; });
  };
  ParallelFor(blocks, threads, countBlocks, 1);
  std::vector<std::uint64_t> bucketStart(buckets + 1);
  std::uint64_t placed = 0;
  for (std::size_t k = 0; k < buckets; ++k) {
    bucketStart[k] = placed;
    for (std::size_t b = 0; b < blocks; ++b) {
      const std::uint64_t count = cursor[b * buckets + k];
      cursor[b * buckets + k] = placed;
      placed += count;
    }
  }
  bucketStart[buckets] = placed;
  std::vector<std::pair<std::uint64_t, Index>> cellFaces(entries);
  auto fillBlocks = [&](std::size_t bBegin, std::size_t bEnd, int) {
    for (std::size_t b = bBegin; b < bEnd; ++b)
      for (std::size_t i = b * kFaceBlock; i < std::min(n, (b + 1) * kFaceBlock); ++i)
        if (cellCount[i] != 0)
          forEachCell(i, [&](std::uint64_t key) {
            cellFaces[cursor[b * buckets + bucketOf(key)]++] = {key, Index(i)};
          });
  };
  ParallelFor(blocks, threads, fillBlocks, 1);
  // A face is in a cell once (it spans fewer than 2^21 cells per axis): the entries are distinct.
  auto sortBuckets = [&](std::size_t kBegin, std::size_t kEnd, int) {
    for (std::size_t k = kBegin; k < kEnd; ++k)
      std::sort(cellFaces.begin() + std::ptrdiff_t(bucketStart[k]),
                cellFaces.begin() + std::ptrdiff_t(bucketStart[k + 1]));
  };
  ParallelFor(buckets, threads, sortBuckets, 1);

  std::vector<std::size_t> cellStart; // runs of equal keys, and the end
  for (std::size_t k = 0; k < cellFaces.size(); ++k)
    if (k == 0 || cellFaces[k].first != cellFaces[k - 1].first) cellStart.push_back(k);
  cellStart.push_back(cellFaces.size());
  auto testCells = [&](std::size_t cBegin, std::size_t cEnd, int thread) {
    for (std::size_t c = cBegin; c < cEnd; ++c) {
      const std::size_t begin = cellStart[c], end = cellStart[c + 1];
      for (std::size_t s = begin; s < end; ++s) {
        const Index i = cellFaces[s].second;
        for (std::size_t r = s + 1; r < end; ++r) {
          const Index j = cellFaces[r].second;
          const std::uint64_t canonical = wrappedKey(
              std::max(low[i][0], low[j][0]), std::max(low[i][1], low[j][1]), std::max(low[i][2], low[j][2]));
          if (canonical == cellFaces[begin].first) testPair(i, j, hits[thread]);
        }
      }
    }
  };
  ParallelFor(cellStart.size() - 1, threads, testCells, 256); // cells hold few faces: smaller blocks

  for (const std::vector<Hit>& list : hits) result.insert(result.end(), list.begin(), list.end());
  return result;
}

/// Counts intersecting pairs among the given (non-degenerate, finite) triangles
/// (FindSelfIntersections).
inline IntersectionCounts CountSelfIntersections(const std::vector<std::array<Index, 3>>& tris,
                                                 const std::vector<Point>& points, double medianEdge,
                                                 int threads) {
  IntersectionCounts result;
  std::vector<bool> involved(tris.size(), false);
  for (const IntersectingPair& hit : FindSelfIntersections(tris, points, medianEdge, threads)) {
    ++(hit.adjacent ? result.adjacentPairs : result.disjointPairs);
    involved[hit.i] = involved[hit.j] = true;
  }
  result.faces = std::size_t(std::count(involved.begin(), involved.end(), true));
  return result;
}

} // namespace quality_detail

template <class MeshType>
TriangleAngles MeshQuality<MeshType>::FaceAngles(const typename MeshType::FaceType& f) {
  using quality_detail::Point;
  TriangleAngles result;
  for (int i = 0; i < 3; ++i)
    if (f.cV(i) == nullptr || f.cV(i) == f.cV((i + 1) % 3)) return result;
  std::array<Point, 3> p;
  for (int i = 0; i < 3; ++i) {
    const auto& c = f.cV(i)->cP();
    p[i] = Point(double(c[0]), double(c[1]), double(c[2]));
  }
  double longest = 0;
  for (int i = 0; i < 3; ++i) longest = std::max(longest, (p[(i + 1) % 3] - p[i]).Norm());
  const auto shape =
      quality_detail::ShapeOf(p[0], p[1], p[2], Params().degenerateAreaEpsilon * longest * longest);
  result.degrees = shape.angles;
  return result;
}

template <class MeshType>
std::vector<int> MeshQuality<MeshType>::VertexValences(const MeshType& m) {
  const quality_detail::Topology t = quality_detail::ReadTopology(m, 0);
  std::vector<int> valence(m.vert.size(), 0);
  for (std::size_t v = 0; v < valence.size(); ++v)
    valence[v] = int(t.vertEdgeStart[v + 1] - t.vertEdgeStart[v]);
  return valence;
}

template <class MeshType>
std::vector<bool> MeshQuality<MeshType>::VertexOnBorder(const MeshType& m) {
  return quality_detail::ReadTopology(m, 0).onBorder;
}

template <class MeshType>
QualityCapture MeshQuality<MeshType>::Capture(const MeshType& m) {
  QualityCapture c;
  c.vertexCount = m.vert.size();
  quality_detail::ReadFaces(m, c.faces, c.proper);
  c.points.resize(c.vertexCount);
  c.live.resize(c.vertexCount);
  for (std::size_t v = 0; v < c.vertexCount; ++v) {
    const auto& p = m.vert[v].cP();
    c.points[v] = vcg::Point3d(double(p[0]), double(p[1]), double(p[2]));
    c.live[v] = !m.vert[v].IsD();
  }
  return c;
}

template <class MeshType>
QualityReport MeshQuality<MeshType>::Compute(QualityCapture capture, const Params& params) {
  using namespace quality_detail;
  QualityReport r;
  Topology t;
  t.vertexCount = capture.vertexCount;
  t.faces = std::move(capture.faces);
  t.proper = std::move(capture.proper);
  BuildTopology(t, params.threads);
  const std::size_t nv = t.vertexCount;
  const std::size_t nf = t.faces.size();
  const std::size_t ne = t.edgeKeys.size();

  // --- Vertices --------------------------------------------------------------------------------
  const std::vector<Point> points = std::move(capture.points);
  const std::vector<bool> live = std::move(capture.live);
  std::vector<bool> finite(nv, false), referenced(nv, false);
  for (std::size_t v = 0; v < nv; ++v) {
    finite[v] = IsFinite(points[v]);
    if (live[v]) {
      ++r.vertices;
      if (!finite[v]) ++r.nonFiniteVertices;
    }
  }
  for (const auto& f : t.faces)
    for (Index v : f)
      if (v != kNoIndex) referenced[v] = true;
  for (std::size_t v = 0; v < nv; ++v)
    if (live[v] && referenced[v]) ++r.referencedVertices;
  r.unreferencedVertices = r.vertices - r.referencedVertices;
  r.faces = nf;
  r.edges = ne;

  // --- Edges: boundary / non-manifold counts, mean length ------------------------------------
  std::vector<double> edgeLengths;
  edgeLengths.reserve(ne);
  for (std::size_t e = 0; e < ne; ++e) {
    const Index count = t.EdgeFaceCount(e);
    if (count == 1) ++r.boundaryEdges;
    if (count > 2) ++r.nonManifoldEdges;
    const Index a = t.EdgeV0(e), b = t.EdgeV1(e);
    if (finite[a] && finite[b]) edgeLengths.push_back((points[a] - points[b]).Norm());
  }
  if (!edgeLengths.empty()) {
    r.meanEdgeLength =
        std::accumulate(edgeLengths.begin(), edgeLengths.end(), 0.0) / double(edgeLengths.size());
    const auto middle = edgeLengths.begin() + std::ptrdiff_t(edgeLengths.size() / 2);
    std::nth_element(edgeLengths.begin(), middle, edgeLengths.end());
    r.medianEdgeLength = *middle;
  }
  edgeLengths = std::vector<double>();

  // --- Components through shared edges -------------------------------------------------------
  UnionFind faceSets(nf);
  for (std::size_t e = 0; e < ne; ++e)
    for (Index k = t.edgeFaceStart[e] + 1; k < t.edgeFaceStart[e + 1]; ++k)
      faceSets.Unite(t.edgeFaces[t.edgeFaceStart[e]], t.edgeFaces[k]);
  // Numbered by their lowest face, which is also the union-find root.
  std::vector<Index> componentOf(nf, kNoIndex);
  std::vector<ComponentInfo> comps;
  for (std::size_t f = 0; f < nf; ++f) {
    if (!t.proper[f]) continue;
    const Index root = faceSets.Find(Index(f));
    if (root == f) {
      componentOf[f] = Index(comps.size());
      comps.emplace_back();
    } else {
      componentOf[f] = componentOf[root];
    }
    ++comps[componentOf[f]].faces;
  }

  // --- Vertex fans: non-manifold vertices and the pairing of boundary edges into loops ---------
  // At a vertex whose edges are all manifold or boundary, the incident faces split into fans
  // joined through two-face edges; an open fan has exactly two boundary edges, which are
  // consecutive edges of one boundary loop. Boundary edges at vertices where this does not hold
  // (non-manifold edges) are "broken" and their polylines are not counted as loops.
  // The vertices are judged in parallel. What concerns shared records (a component made
  // non-manifold, a boundary edge broken, two boundary edges linked) is collected per thread and
  // applied afterwards; applying it does not depend on the order (flags, and a union-find whose
  // roots are the smallest members), so neither does the result on the thread count.
  std::vector<char> nonManifoldVertex(nv, 0); // char, not bool: written concurrently
  UnionFind boundaryLinks(ne);
  std::vector<bool> brokenBoundary(ne, false);
  {
    struct FanScratch {
      std::vector<Index> localParent;
      std::vector<std::pair<Index, Index>> fanBoundary; // (fan root, boundary edge)
      std::vector<Index> fanComponents;
      std::vector<Index> nonManifoldComponents, broken; // to apply afterwards
      std::vector<std::pair<Index, Index>> links;       // boundary edges to unite afterwards
    };
    std::vector<FanScratch> scratch(std::size_t(ResolveThreadCount(params.threads)));
    ParallelFor(nv, params.threads, [&](std::size_t vBegin, std::size_t vEnd, int thread) {
      FanScratch& own = scratch[std::size_t(thread)];
      std::vector<Index>& localParent = own.localParent;
      std::vector<std::pair<Index, Index>>& fanBoundary = own.fanBoundary;
      std::vector<Index>& fanComponents = own.fanComponents;
      for (std::size_t v = vBegin; v < vEnd; ++v) {
        const Index fBegin = t.vertFaceStart[v], fEnd = t.vertFaceStart[v + 1];
        if (fBegin == fEnd) continue;
        const Index eBegin = t.vertEdgeStart[v], eEnd = t.vertEdgeStart[v + 1];
        if (t.onNonManifoldEdge[v]) {
          for (Index k = eBegin; k < eEnd; ++k)
            if (t.EdgeFaceCount(t.vertEdges[k]) == 1) own.broken.push_back(t.vertEdges[k]);
          continue;
        }
        const auto facesBegin = t.vertFaces.begin() + fBegin, facesEnd = t.vertFaces.begin() + fEnd;
        auto local = [&](Index f) { return Index(std::lower_bound(facesBegin, facesEnd, f) - facesBegin); };
        localParent.resize(fEnd - fBegin);
        std::iota(localParent.begin(), localParent.end(), Index(0));
        auto find = [&](Index x) {
          while (localParent[x] != x) x = localParent[x] = localParent[localParent[x]];
          return x;
        };
        fanBoundary.clear();
        for (Index k = eBegin; k < eEnd; ++k) {
          const Index e = t.vertEdges[k];
          const Index* ef = &t.edgeFaces[t.edgeFaceStart[e]];
          if (t.EdgeFaceCount(e) == 2) {
            const Index a = find(local(ef[0])), b = find(local(ef[1]));
            if (a != b) localParent[std::max(a, b)] = std::min(a, b);
          }
        }
        std::size_t fans = 0;
        for (Index i = 0; i < localParent.size(); ++i)
          if (find(i) == i) ++fans;
        if (fans > 1) {
          nonManifoldVertex[v] = 1;
          // Two fans of the same component make that component non-manifold; fans of different
          // components only mean the components touch there (each is manifold on its own).
          fanComponents.clear();
          for (Index i = 0; i < localParent.size(); ++i)
            if (find(i) == i) fanComponents.push_back(componentOf[t.vertFaces[fBegin + i]]);
          std::sort(fanComponents.begin(), fanComponents.end());
          for (std::size_t i = 1; i < fanComponents.size(); ++i)
            if (fanComponents[i] == fanComponents[i - 1])
              own.nonManifoldComponents.push_back(fanComponents[i]);
        }
        for (Index k = eBegin; k < eEnd; ++k) {
          const Index e = t.vertEdges[k];
          if (t.EdgeFaceCount(e) == 1)
            fanBoundary.emplace_back(find(local(t.edgeFaces[t.edgeFaceStart[e]])), e);
        }
        std::sort(fanBoundary.begin(), fanBoundary.end());
        for (std::size_t i = 0; i < fanBoundary.size();) {
          std::size_t j = i;
          while (j < fanBoundary.size() && fanBoundary[j].first == fanBoundary[i].first) ++j;
          if (j - i == 2)
            own.links.emplace_back(fanBoundary[i].second, fanBoundary[i + 1].second);
          else
            for (std::size_t k = i; k < j; ++k) own.broken.push_back(fanBoundary[k].second);
          i = j;
        }
      }
    });
    for (const FanScratch& own : scratch) {
      for (Index c : own.nonManifoldComponents) comps[c].manifold = false;
      for (Index e : own.broken) brokenBoundary[e] = true;
      for (const auto& [a, b] : own.links) boundaryLinks.Unite(a, b);
    }
  }
  for (std::size_t v = 0; v < nv; ++v)
    if (nonManifoldVertex[v]) ++r.nonManifoldVertices;

  std::vector<long long> compVertices(comps.size(), 0), compEdges(comps.size(), 0);
  for (std::size_t e = 0; e < ne; ++e) {
    const Index c = componentOf[t.edgeFaces[t.edgeFaceStart[e]]];
    ++compEdges[c];
    if (t.EdgeFaceCount(e) == 1) ++comps[c].boundaryEdges;
    if (t.EdgeFaceCount(e) > 2) comps[c].manifold = false;
  }
  std::size_t topologyVertices = 0;
  {
    std::vector<Index> vertexComps;
    for (std::size_t v = 0; v < nv; ++v) {
      const Index fBegin = t.vertFaceStart[v], fEnd = t.vertFaceStart[v + 1];
      if (fBegin == fEnd) continue;
      ++topologyVertices;
      vertexComps.clear();
      for (Index k = fBegin; k < fEnd; ++k) vertexComps.push_back(componentOf[t.vertFaces[k]]);
      std::sort(vertexComps.begin(), vertexComps.end());
      vertexComps.erase(std::unique(vertexComps.begin(), vertexComps.end()), vertexComps.end());
      for (Index c : vertexComps) ++compVertices[c];
    }
  }
  // Boundary loops: classes of linked boundary edges without a broken edge.
  {
    std::vector<bool> classBroken(ne, false);
    for (std::size_t e = 0; e < ne; ++e)
      if (t.EdgeFaceCount(e) == 1 && brokenBoundary[e]) classBroken[boundaryLinks.Find(Index(e))] = true;
    for (std::size_t e = 0; e < ne; ++e)
      if (t.EdgeFaceCount(e) == 1 && boundaryLinks.Find(Index(e)) == e && !classBroken[e]) {
        ++r.boundaryLoops;
        ++comps[componentOf[t.edgeFaces[t.edgeFaceStart[e]]]].boundaryLoops;
      }
  }
  r.euler = int(topologyVertices) - int(ne) + int(std::count(t.proper.begin(), t.proper.end(), true));
  r.genus = 0;
  for (std::size_t c = 0; c < comps.size(); ++c) {
    ComponentInfo& info = comps[c];
    info.euler = int(compVertices[c] - compEdges[c] + (long long)info.faces);
    info.closed = info.manifold && info.boundaryEdges == 0;
    const int twiceGenus = 2 - info.euler - int(info.boundaryLoops);
    info.genus = (info.manifold && twiceGenus >= 0 && twiceGenus % 2 == 0) ? twiceGenus / 2 : -1;
    if (info.genus < 0)
      r.genus = -1;
    else if (r.genus >= 0)
      r.genus += info.genus;
  }
  std::stable_sort(comps.begin(), comps.end(),
                   [](const ComponentInfo& a, const ComponentInfo& b) { return a.faces > b.faces; });
  r.components = comps.size();
  r.componentInfo = std::move(comps);

  // --- Valence of interior vertices ----------------------------------------------------------
  for (std::size_t v = 0; v < nv; ++v) {
    const int valence = int(t.vertEdgeStart[v + 1] - t.vertEdgeStart[v]);
    if (!live[v] || valence == 0 || t.onBorder[v]) continue;
    ++r.interiorVertices;
    ++r.valenceHistogram[valence];
    if (valence >= 5 && valence <= 7) ++r.regularVertices;
  }
  r.v567Percent =
      r.interiorVertices > 0 ? 100.0 * double(r.regularVertices) / double(r.interiorVertices) : 100.0;

  // --- Triangle shape, area, volume -----------------------------------------------------------
  Point centroid(0, 0, 0);
  std::size_t centroidCount = 0;
  for (std::size_t v = 0; v < nv; ++v)
    if (live[v] && referenced[v] && finite[v]) {
      centroid += points[v];
      ++centroidCount;
    }
  if (centroidCount > 0) centroid /= double(centroidCount);

  const double degenerateArea = params.degenerateAreaEpsilon * r.medianEdgeLength * r.medianEdgeLength;
  const double infinity = std::numeric_limits<double>::infinity();
  double qSum = 0, minAngleSum = 0, arSum = 0, arSumNonDegenerate = 0, volumeSum = 0;
  r.qMin = infinity;
  r.angleMin = infinity;
  r.angleMax = -infinity;
  r.aspectRatioMax = 0;
  std::vector<std::array<Index, 3>> candidates; // non-degenerate faces, for self-intersections
  candidates.reserve(nf);
  {
    // The shapes (three atan2 each) are computed in parallel, one record per face of a window of
    // faces; the sums are then taken serially in face order, so they are the same to the last bit
    // for any thread count. A reused window, because records for the whole mesh would cost more
    // in page faults than the parallel loop saves.
    struct FaceFigures {
      double q, minAngle, maxAngle, aspectRatio, area, volume;
      bool degenerate, counted; ///< counted: finite corners, the area and volume terms count
    };
    constexpr std::size_t kWindow = std::size_t(1) << 15;
    std::vector<FaceFigures> figures(std::min(nf, kWindow));
    for (std::size_t first = 0; first < nf; first += kWindow) {
      const std::size_t count = std::min(kWindow, nf - first);
      ParallelFor(count, params.threads, [&](std::size_t begin, std::size_t end, int) {
        for (std::size_t f = first + begin; f < first + end; ++f) {
          FaceFigures& x = figures[f - first];
          TriangleShape shape;
          x.counted = false;
          x.volume = 0;
          if (t.proper[f]) {
            const auto& tri = t.faces[f];
            shape = ShapeOf(points[tri[0]], points[tri[1]], points[tri[2]], degenerateArea);
            if (finite[tri[0]] && finite[tri[1]] && finite[tri[2]]) {
              x.counted = true;
              x.volume =
                  (points[tri[0]] - centroid) * ((points[tri[1]] - centroid) ^ (points[tri[2]] - centroid));
            }
          }
          if (shape.degenerate) {
            shape.angles = {0.0, 0.0, 180.0};
            shape.q = 0;
            shape.aspectRatio = infinity;
          }
          x.q = shape.q;
          x.minAngle = std::min({shape.angles[0], shape.angles[1], shape.angles[2]});
          x.maxAngle = std::max({shape.angles[0], shape.angles[1], shape.angles[2]});
          x.aspectRatio = shape.aspectRatio;
          x.area = shape.area;
          x.degenerate = shape.degenerate;
        }
      });
      for (std::size_t f = first; f < first + count; ++f) {
        const FaceFigures& x = figures[f - first];
        if (t.proper[f]) {
          if (x.counted) {
            r.area += x.area;
            volumeSum += x.volume;
          }
          if (!x.degenerate) candidates.push_back(t.faces[f]);
        }
        if (x.degenerate) {
          ++r.degenerateFaces;
        } else {
          arSumNonDegenerate += x.aspectRatio;
        }
        qSum += x.q;
        minAngleSum += x.minAngle;
        arSum += x.aspectRatio;
        r.qMin = std::min(r.qMin, x.q);
        r.angleMin = std::min(r.angleMin, x.minAngle);
        r.angleMax = std::max(r.angleMax, x.maxAngle);
        r.aspectRatioMax = std::max(r.aspectRatioMax, x.aspectRatio);
        if (x.minAngle < params.smallAngle) ++r.smallAngleFaces;
        if (x.maxAngle >= params.obtuseAngle) ++r.obtuseFaces;
        if (x.maxAngle > params.largeAngle) ++r.largeAngleFaces;
      }
    }
  }
  r.volume = volumeSum / 6.0;
  if (nf > 0) {
    const double count = double(nf);
    r.qAvg = qSum / count;
    r.meanMinAngle = minAngleSum / count;
    r.aspectRatioMean = arSum / count;
    r.smallAnglePercent = 100.0 * double(r.smallAngleFaces) / count;
    r.obtusePercent = 100.0 * double(r.obtuseFaces) / count;
    r.largeAnglePercent = 100.0 * double(r.largeAngleFaces) / count;
  } else {
    r.qMin = r.angleMin = r.angleMax = 0;
  }
  const std::size_t nonDegenerate = nf - r.degenerateFaces;
  r.aspectRatioMeanNonDegenerate = nonDegenerate > 0 ? arSumNonDegenerate / double(nonDegenerate) : 0.0;

  // --- Self-intersections ----------------------------------------------------------------------
  if (params.computeSelfIntersections) {
    const IntersectionCounts counts =
        CountSelfIntersections(candidates, points, r.medianEdgeLength, params.threads);
    r.selfIntersectingPairs = counts.disjointPairs;
    r.adjacentOverlapPairs = counts.adjacentPairs;
    r.selfIntersectingFaces = counts.faces;
    r.selfIntersectionsComputed = true;
  }
  return r;
}

} // namespace molremesh

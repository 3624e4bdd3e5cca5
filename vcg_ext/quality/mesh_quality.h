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
//
// Bounded work: every figure is linear in the mesh but the self-intersection count, whose
// candidate pairs are 22 to 43 per face on molecular meshes but grow with the square of the face
// count on a soup of overlapping polygons (a 350 KB PLY of 320 random 255-gons: 3.3e9 pairs,
// hours of tests and up to 110 GB of found pairs). The count is skipped, with the reason in
// QualityReport::selfIntersectionsSkipped, when its pairs exceed Params::maxCandidatePairsPerFace
// per face (plus 10^7), or when, charging each candidate pair as found (36 bytes) besides 600
// bytes per face and 400 per vertex, it might not fit in Params::memoryLimitMB. Measured peak of
// `report` (2 threads): 4JSV 274 MB, 1HPV 196 MB, lysozyme 12 MB; without the count 147, 109, 9 MB.
#pragma once

#include <vcg/complex/complex.h>

#include <vcg_ext/core/available_memory.h>
#include <vcg_ext/core/index.h>
#include <vcg_ext/core/parallel_for.h>
#include <vcg_ext/core/union_find.h>
#include <vcg_ext/geometry/point.h>
#include <vcg_ext/geometry/triangle_shape.h>
#include <vcg_ext/spatial/self_intersections.h>
#include <vcg_ext/topology/edge_topology.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <map>
#include <numeric>
#include <sstream>
#include <string>
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
  std::string selfIntersectionsSkipped;           ///< why the count was skipped by its bounds ("" otherwise)
  bool selfIntersectionsSkippedForMemory = false; ///< skipped by the memory bound (not the work bound)

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
    /// Bound of the count's candidate pairs: 10^7 plus this many per face (22-43 on molecular
    /// meshes); < 0 = no bound.
    double maxCandidatePairsPerFace = kCandidatePairsPerTriangleBound;
    double memoryLimitMB = 0; ///< the count's memory bound: 0 = the memory available now, < 0 = none
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

// The steps of MeshQuality::Compute, in the order it runs them. Each fills its part of the report
// and returns what later steps read.

/// Per vertex: finite coordinates; used by at least one face.
struct VertexFlags {
  std::vector<bool> finite, referenced;
};

/// Live, non-finite, referenced and unreferenced vertex counts.
inline VertexFlags CountVertices(const EdgeTopology& t, const std::vector<Point>& points,
                                 const std::vector<bool>& live, QualityReport& r) {
  const std::size_t nv = t.vertexCount;
  VertexFlags flags;
  flags.finite.assign(nv, false);
  flags.referenced.assign(nv, false);
  for (std::size_t v = 0; v < nv; ++v) {
    flags.finite[v] = IsFinite(points[v]);
    if (live[v]) {
      ++r.vertices;
      if (!flags.finite[v]) ++r.nonFiniteVertices;
    }
  }
  for (const auto& f : t.faces)
    for (Index v : f)
      if (v != kNoIndex) flags.referenced[v] = true;
  for (std::size_t v = 0; v < nv; ++v)
    if (live[v] && flags.referenced[v]) ++r.referencedVertices;
  r.unreferencedVertices = r.vertices - r.referencedVertices;
  return flags;
}

/// Boundary and non-manifold edge counts, mean and median length of the edges with finite ends.
inline void MeasureEdges(const EdgeTopology& t, const std::vector<Point>& points,
                         const std::vector<bool>& finite, QualityReport& r) {
  const std::size_t ne = t.edgeKeys.size();
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
}

/// Connected components through shared edges, numbered by their lowest face (which is also the
/// union-find root); `info` holds their face counts, the rest is filled by later steps.
struct Components {
  std::vector<Index> componentOf; ///< per face; kNoIndex for a face that is not proper
  std::vector<ComponentInfo> info;
};

inline Components LabelComponents(const EdgeTopology& t) {
  const std::size_t nf = t.faces.size();
  const std::size_t ne = t.edgeKeys.size();
  UnionFind faceSets(nf);
  for (std::size_t e = 0; e < ne; ++e)
    for (Index k = t.edgeFaceStart[e] + 1; k < t.edgeFaceStart[e + 1]; ++k)
      faceSets.Unite(t.edgeFaces[t.edgeFaceStart[e]], t.edgeFaces[k]);
  Components c;
  c.componentOf.assign(nf, kNoIndex);
  for (std::size_t f = 0; f < nf; ++f) {
    if (!t.proper[f]) continue;
    const Index root = faceSets.Find(Index(f));
    if (root == f) {
      c.componentOf[f] = Index(c.info.size());
      c.info.emplace_back();
    } else {
      c.componentOf[f] = c.componentOf[root];
    }
    ++c.info[c.componentOf[f]].faces;
  }
  return c;
}

/// What the judging of the vertex fans of one thread leaves to apply afterwards, and its reused
/// buffers.
struct FanScratch {
  std::vector<Index> localParent;
  std::vector<std::pair<Index, Index>> fanBoundary; // (fan root, boundary edge)
  std::vector<Index> fanComponents;
  std::vector<Index> nonManifoldComponents, broken; // to apply afterwards
  std::vector<std::pair<Index, Index>> links;       // boundary edges to unite afterwards
};

/// Judges the fans of vertex v (which has faces and no non-manifold edge): marks it non-manifold
/// when it has more than one fan, and pairs the two boundary edges of each open fan.
inline void JudgeVertexFan(const EdgeTopology& t, std::size_t v, const std::vector<Index>& componentOf,
                           FanScratch& own, std::vector<char>& nonManifoldVertex) {
  std::vector<Index>& localParent = own.localParent;
  std::vector<std::pair<Index, Index>>& fanBoundary = own.fanBoundary;
  std::vector<Index>& fanComponents = own.fanComponents;
  const Index fBegin = t.vertFaceStart[v], fEnd = t.vertFaceStart[v + 1];
  const Index eBegin = t.vertEdgeStart[v], eEnd = t.vertEdgeStart[v + 1];
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
      if (fanComponents[i] == fanComponents[i - 1]) own.nonManifoldComponents.push_back(fanComponents[i]);
  }
  for (Index k = eBegin; k < eEnd; ++k) {
    const Index e = t.vertEdges[k];
    if (t.EdgeFaceCount(e) == 1) fanBoundary.emplace_back(find(local(t.edgeFaces[t.edgeFaceStart[e]])), e);
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

/// Boundary edges linked into polylines by the vertex fans; a polyline with a broken edge is not
/// a loop.
struct BoundaryLinks {
  UnionFind links;
  std::vector<bool> broken;
};

/// Vertex fans: non-manifold vertices and the pairing of boundary edges into loops.
/// At a vertex whose edges are all manifold or boundary, the incident faces split into fans
/// joined through two-face edges; an open fan has exactly two boundary edges, which are
/// consecutive edges of one boundary loop. Boundary edges at vertices where this does not hold
/// (non-manifold edges) are "broken" and their polylines are not counted as loops.
/// The vertices are judged in parallel. What concerns shared records (a component made
/// non-manifold, a boundary edge broken, two boundary edges linked) is collected per thread and
/// applied afterwards; applying it does not depend on the order (flags, and a union-find whose
/// roots are the smallest members), so neither does the result on the thread count.
inline BoundaryLinks JudgeVertexFans(const EdgeTopology& t, Components& components, int threads,
                                     QualityReport& r) {
  const std::size_t nv = t.vertexCount;
  const std::size_t ne = t.edgeKeys.size();
  std::vector<char> nonManifoldVertex(nv, 0); // char, not bool: written concurrently
  BoundaryLinks boundary{UnionFind(ne), std::vector<bool>(ne, false)};
  std::vector<FanScratch> scratch(std::size_t(ResolveThreadCount(threads)));
  ParallelFor(nv, threads, [&](std::size_t vBegin, std::size_t vEnd, int thread) {
    FanScratch& own = scratch[std::size_t(thread)];
    for (std::size_t v = vBegin; v < vEnd; ++v) {
      if (t.vertFaceStart[v] == t.vertFaceStart[v + 1]) continue;
      if (t.onNonManifoldEdge[v]) {
        for (Index k = t.vertEdgeStart[v]; k < t.vertEdgeStart[v + 1]; ++k)
          if (t.EdgeFaceCount(t.vertEdges[k]) == 1) own.broken.push_back(t.vertEdges[k]);
        continue;
      }
      JudgeVertexFan(t, v, components.componentOf, own, nonManifoldVertex);
    }
  });
  for (const FanScratch& own : scratch) {
    for (Index c : own.nonManifoldComponents) components.info[c].manifold = false;
    for (Index e : own.broken) boundary.broken[e] = true;
    for (const auto& [a, b] : own.links) boundary.links.Unite(a, b);
  }
  for (std::size_t v = 0; v < nv; ++v)
    if (nonManifoldVertex[v]) ++r.nonManifoldVertices;
  return boundary;
}

/// Per component: its edges (in compEdges), boundary edges, and non-manifold edges.
inline std::vector<long long> CountComponentEdges(const EdgeTopology& t, Components& components) {
  std::vector<long long> compEdges(components.info.size(), 0);
  for (std::size_t e = 0; e < t.edgeKeys.size(); ++e) {
    const Index c = components.componentOf[t.edgeFaces[t.edgeFaceStart[e]]];
    ++compEdges[c];
    if (t.EdgeFaceCount(e) == 1) ++components.info[c].boundaryEdges;
    if (t.EdgeFaceCount(e) > 2) components.info[c].manifold = false;
  }
  return compEdges;
}

/// Per component: its vertices (a vertex where components touch counts in each). Returns the
/// vertices with at least one proper face.
inline std::size_t CountComponentVertices(const EdgeTopology& t, const Components& components,
                                          std::vector<long long>& compVertices) {
  compVertices.assign(components.info.size(), 0);
  std::size_t topologyVertices = 0;
  std::vector<Index> vertexComps;
  for (std::size_t v = 0; v < t.vertexCount; ++v) {
    const Index fBegin = t.vertFaceStart[v], fEnd = t.vertFaceStart[v + 1];
    if (fBegin == fEnd) continue;
    ++topologyVertices;
    vertexComps.clear();
    for (Index k = fBegin; k < fEnd; ++k) vertexComps.push_back(components.componentOf[t.vertFaces[k]]);
    std::sort(vertexComps.begin(), vertexComps.end());
    vertexComps.erase(std::unique(vertexComps.begin(), vertexComps.end()), vertexComps.end());
    for (Index c : vertexComps) ++compVertices[c];
  }
  return topologyVertices;
}

/// Boundary loops: classes of linked boundary edges without a broken edge.
inline void CountBoundaryLoops(const EdgeTopology& t, BoundaryLinks& boundary, Components& components,
                               QualityReport& r) {
  const std::size_t ne = t.edgeKeys.size();
  std::vector<bool> classBroken(ne, false);
  for (std::size_t e = 0; e < ne; ++e)
    if (t.EdgeFaceCount(e) == 1 && boundary.broken[e]) classBroken[boundary.links.Find(Index(e))] = true;
  for (std::size_t e = 0; e < ne; ++e)
    if (t.EdgeFaceCount(e) == 1 && boundary.links.Find(Index(e)) == e && !classBroken[e]) {
      ++r.boundaryLoops;
      ++components.info[components.componentOf[t.edgeFaces[t.edgeFaceStart[e]]]].boundaryLoops;
    }
}

/// Euler characteristic and genus of the mesh and of each component; the components go into the
/// report, largest first.
inline void FinishTopology(const EdgeTopology& t, Components& components,
                           const std::vector<long long>& compVertices,
                           const std::vector<long long>& compEdges, std::size_t topologyVertices,
                           QualityReport& r) {
  std::vector<ComponentInfo>& comps = components.info;
  r.euler = int(topologyVertices) - int(t.edgeKeys.size()) +
            int(std::count(t.proper.begin(), t.proper.end(), true));
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
}

/// Components, their manifoldness, boundary loops, Euler characteristic and genus.
inline void MeasureTopology(const EdgeTopology& t, int threads, QualityReport& r) {
  Components components = LabelComponents(t);
  BoundaryLinks boundary = JudgeVertexFans(t, components, threads, r);
  const std::vector<long long> compEdges = CountComponentEdges(t, components);
  std::vector<long long> compVertices;
  const std::size_t topologyVertices = CountComponentVertices(t, components, compVertices);
  CountBoundaryLoops(t, boundary, components, r);
  FinishTopology(t, components, compVertices, compEdges, topologyVertices, r);
}

/// Valence histogram of the interior vertices (live, with edges, on no boundary or non-manifold
/// edge) and the share of valences 5, 6 and 7.
inline void MeasureValence(const EdgeTopology& t, const std::vector<bool>& live, QualityReport& r) {
  for (std::size_t v = 0; v < t.vertexCount; ++v) {
    const int valence = int(t.vertEdgeStart[v + 1] - t.vertEdgeStart[v]);
    if (!live[v] || valence == 0 || t.onBorder[v]) continue;
    ++r.interiorVertices;
    ++r.valenceHistogram[valence];
    if (valence >= 5 && valence <= 7) ++r.regularVertices;
  }
  r.v567Percent =
      r.interiorVertices > 0 ? 100.0 * double(r.regularVertices) / double(r.interiorVertices) : 100.0;
}

/// Mean of the live, referenced, finite vertices: the origin of the volume terms.
inline Point VolumeOrigin(const std::vector<Point>& points, const std::vector<bool>& live,
                          const VertexFlags& flags) {
  Point centroid(0, 0, 0);
  std::size_t centroidCount = 0;
  for (std::size_t v = 0; v < flags.finite.size(); ++v)
    if (live[v] && flags.referenced[v] && flags.finite[v]) {
      centroid += points[v];
      ++centroidCount;
    }
  if (centroidCount > 0) centroid /= double(centroidCount);
  return centroid;
}

/// The shape figures of one face, computed in parallel before they are summed in face order.
struct FaceFigures {
  double q, minAngle, maxAngle, aspectRatio, area, volume;
  bool degenerate, counted; ///< counted: finite corners, the area and volume terms count
};

inline FaceFigures FaceFiguresOf(const EdgeTopology& t, std::size_t f, const std::vector<Point>& points,
                                 const std::vector<bool>& finite, const Point& centroid,
                                 double degenerateArea) {
  FaceFigures x;
  TriangleShape shape;
  x.counted = false;
  x.volume = 0;
  if (t.proper[f]) {
    const auto& tri = t.faces[f];
    shape = ShapeOf(points[tri[0]], points[tri[1]], points[tri[2]], degenerateArea);
    if (finite[tri[0]] && finite[tri[1]] && finite[tri[2]]) {
      x.counted = true;
      x.volume = (points[tri[0]] - centroid) * ((points[tri[1]] - centroid) ^ (points[tri[2]] - centroid));
    }
  }
  if (shape.degenerate) {
    shape.angles = {0.0, 0.0, 180.0};
    shape.q = 0;
    shape.aspectRatio = std::numeric_limits<double>::infinity();
  }
  x.q = shape.q;
  x.minAngle = std::min({shape.angles[0], shape.angles[1], shape.angles[2]});
  x.maxAngle = std::max({shape.angles[0], shape.angles[1], shape.angles[2]});
  x.aspectRatio = shape.aspectRatio;
  x.area = shape.area;
  x.degenerate = shape.degenerate;
  return x;
}

/// Running sums of the shape figures, taken in face order.
struct ShapeSums {
  double q = 0, minAngle = 0, aspectRatio = 0, aspectRatioNonDegenerate = 0, volume = 0;
};

/// Adds face f's figures to the sums, extremes and counts; a non-degenerate proper face becomes a
/// self-intersection candidate.
template <class Params>
void AddFaceFigures(const EdgeTopology& t, std::size_t f, const FaceFigures& x, const Params& params,
                    ShapeSums& sums, std::vector<std::array<Index, 3>>& candidates, QualityReport& r) {
  if (t.proper[f]) {
    if (x.counted) {
      r.area += x.area;
      sums.volume += x.volume;
    }
    if (!x.degenerate) candidates.push_back(t.faces[f]);
  }
  if (x.degenerate) {
    ++r.degenerateFaces;
  } else {
    sums.aspectRatioNonDegenerate += x.aspectRatio;
  }
  sums.q += x.q;
  sums.minAngle += x.minAngle;
  sums.aspectRatio += x.aspectRatio;
  r.qMin = std::min(r.qMin, x.q);
  r.angleMin = std::min(r.angleMin, x.minAngle);
  r.angleMax = std::max(r.angleMax, x.maxAngle);
  r.aspectRatioMax = std::max(r.aspectRatioMax, x.aspectRatio);
  if (x.minAngle < params.smallAngle) ++r.smallAngleFaces;
  if (x.maxAngle >= params.obtuseAngle) ++r.obtuseFaces;
  if (x.maxAngle > params.largeAngle) ++r.largeAngleFaces;
}

/// Volume, means and percentages from the sums over all nf faces.
inline void FinishShapeFigures(const ShapeSums& sums, std::size_t nf, QualityReport& r) {
  r.volume = sums.volume / 6.0;
  if (nf > 0) {
    const double count = double(nf);
    r.qAvg = sums.q / count;
    r.meanMinAngle = sums.minAngle / count;
    r.aspectRatioMean = sums.aspectRatio / count;
    r.smallAnglePercent = 100.0 * double(r.smallAngleFaces) / count;
    r.obtusePercent = 100.0 * double(r.obtuseFaces) / count;
    r.largeAnglePercent = 100.0 * double(r.largeAngleFaces) / count;
  } else {
    r.qMin = r.angleMin = r.angleMax = 0;
  }
  const std::size_t nonDegenerate = nf - r.degenerateFaces;
  r.aspectRatioMeanNonDegenerate =
      nonDegenerate > 0 ? sums.aspectRatioNonDegenerate / double(nonDegenerate) : 0.0;
}

/// Triangle shape, area, volume and degenerate faces. Returns the non-degenerate proper faces, the
/// candidates for self-intersections.
///
/// The shapes (three atan2 each) are computed in parallel, one record per face of a window of
/// faces; the sums are then taken serially in face order, so they are the same to the last bit
/// for any thread count. A reused window, because records for the whole mesh would cost more
/// in page faults than the parallel loop saves.
template <class Params>
std::vector<std::array<Index, 3>> MeasureShapes(const EdgeTopology& t, const std::vector<Point>& points,
                                                const std::vector<bool>& live, const VertexFlags& flags,
                                                const Params& params, QualityReport& r) {
  const std::size_t nf = t.faces.size();
  const Point centroid = VolumeOrigin(points, live, flags);
  const double degenerateArea = params.degenerateAreaEpsilon * r.medianEdgeLength * r.medianEdgeLength;
  const double infinity = std::numeric_limits<double>::infinity();
  ShapeSums sums;
  r.qMin = infinity;
  r.angleMin = infinity;
  r.angleMax = -infinity;
  r.aspectRatioMax = 0;
  std::vector<std::array<Index, 3>> candidates;
  candidates.reserve(nf);
  constexpr std::size_t kWindow = std::size_t(1) << 15;
  std::vector<FaceFigures> figures(std::min(nf, kWindow));
  for (std::size_t first = 0; first < nf; first += kWindow) {
    const std::size_t count = std::min(kWindow, nf - first);
    ParallelFor(count, params.threads, [&](std::size_t begin, std::size_t end, int) {
      for (std::size_t f = first + begin; f < first + end; ++f)
        figures[f - first] = FaceFiguresOf(t, f, points, flags.finite, centroid, degenerateArea);
    });
    for (std::size_t f = first; f < first + count; ++f)
      AddFaceFigures(t, f, figures[f - first], params, sums, candidates, r);
  }
  FinishShapeFigures(sums, nf, r);
  return candidates;
}

} // namespace quality_detail

template <class MeshType>
TriangleAngles MeshQuality<MeshType>::FaceAngles(const typename MeshType::FaceType& f) {
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
  const auto shape = ShapeOf(p[0], p[1], p[2], Params().degenerateAreaEpsilon * longest * longest);
  result.degrees = shape.angles;
  return result;
}

template <class MeshType>
std::vector<int> MeshQuality<MeshType>::VertexValences(const MeshType& m) {
  const EdgeTopology t = ReadEdgeTopology(m, 0);
  std::vector<int> valence(m.vert.size(), 0);
  for (std::size_t v = 0; v < valence.size(); ++v)
    valence[v] = int(t.vertEdgeStart[v + 1] - t.vertEdgeStart[v]);
  return valence;
}

template <class MeshType>
std::vector<bool> MeshQuality<MeshType>::VertexOnBorder(const MeshType& m) {
  return ReadEdgeTopology(m, 0).onBorder;
}

template <class MeshType>
QualityCapture MeshQuality<MeshType>::Capture(const MeshType& m) {
  QualityCapture c;
  c.vertexCount = m.vert.size();
  ReadFaceIndices(m, c.faces, c.proper);
  c.points.resize(c.vertexCount);
  c.live.resize(c.vertexCount);
  for (std::size_t v = 0; v < c.vertexCount; ++v) {
    const auto& p = m.vert[v].cP();
    c.points[v] = vcg::Point3d(double(p[0]), double(p[1]), double(p[2]));
    c.live[v] = !m.vert[v].IsD();
  }
  return c;
}

namespace quality_detail {

/// The self-intersection count's bound on candidate pairs (see the file comment), and why a
/// count over it is skipped.
struct SelfIntersectionBound {
  static constexpr double kBaseBytes = 64.0 * 1024 * 1024; ///< the process and fixed-size parts
  static constexpr double kBytesPerFace = 600.0;           ///< the mesh, its figures and the grid
  static constexpr double kBytesPerVertex = 400.0;
  static constexpr double kBytesPerPair = 36.0; ///< a found pair, in per-thread lists and gathered

  double maxCandidatePairs = std::numeric_limits<double>::infinity();
  double workPairs = std::numeric_limits<double>::infinity();   ///< the work bound
  double memoryPairs = std::numeric_limits<double>::infinity(); ///< the memory bound
  double limitBytes = 0, fixedBytes = 0;                        ///< of the memory bound (0: none)
  bool explicitLimit = false;

  /// Whether a count of candidatePairs is skipped for the work bound (else for memory).
  bool ForWork(double candidatePairs) const { return candidatePairs > workPairs; }

  std::string Why(double candidatePairs, std::size_t faces) const {
    std::ostringstream s;
    s.setf(std::ios::fixed);
    s.precision(0);
    if (!ForWork(candidatePairs)) {
      s << "the self-intersection count would need up to "
        << std::round((fixedBytes + kBytesPerPair * candidatePairs) / 1048576.0) << " MB of memory ("
        << double(faces) << " faces, " << candidatePairs << " candidate pairs), more than the "
        << std::round(limitBytes / 1048576.0) << " MB "
        << (explicitLimit ? "memory limit" : "of memory available");
    } else {
      s << "the self-intersection count would test " << candidatePairs << " candidate pairs ("
        << double(faces) << " faces), more than its bound of " << workPairs << " (10^7 + "
        << (workPairs - kMinCandidatePairBound) / std::max<double>(1, double(faces))
        << " per face; molecular meshes need 22 to 43 per face)";
    }
    return s.str();
  }
};

template <class Params>
SelfIntersectionBound BoundSelfIntersections(const Params& params, std::size_t faces, std::size_t vertices) {
  SelfIntersectionBound b;
  if (params.maxCandidatePairsPerFace >= 0)
    b.workPairs = CandidatePairBound(faces, params.maxCandidatePairsPerFace);
  if (params.memoryLimitMB >= 0) {
    b.explicitLimit = params.memoryLimitMB > 0;
    b.limitBytes = b.explicitLimit ? params.memoryLimitMB * 1048576.0 : AvailableMemoryBytes();
    b.fixedBytes = SelfIntersectionBound::kBaseBytes + SelfIntersectionBound::kBytesPerFace * double(faces) +
                   SelfIntersectionBound::kBytesPerVertex * double(vertices);
    if (b.limitBytes > 0)
      b.memoryPairs = std::max(0.0, (b.limitBytes - b.fixedBytes) / SelfIntersectionBound::kBytesPerPair);
  }
  b.maxCandidatePairs = std::min(b.workPairs, b.memoryPairs);
  return b;
}

} // namespace quality_detail

template <class MeshType>
QualityReport MeshQuality<MeshType>::Compute(QualityCapture capture, const Params& params) {
  using namespace quality_detail;
  QualityReport r;
  EdgeTopology t;
  t.vertexCount = capture.vertexCount;
  t.faces = std::move(capture.faces);
  t.proper = std::move(capture.proper);
  BuildEdgeTopology(t, params.threads);
  const std::vector<Point> points = std::move(capture.points);
  const std::vector<bool> live = std::move(capture.live);

  const VertexFlags flags = CountVertices(t, points, live, r);
  r.faces = t.faces.size();
  r.edges = t.edgeKeys.size();
  MeasureEdges(t, points, flags.finite, r);
  MeasureTopology(t, params.threads, r);
  MeasureValence(t, live, r);
  const std::vector<std::array<Index, 3>> candidates = MeasureShapes(t, points, live, flags, params, r);
  if (params.computeSelfIntersections) {
    const SelfIntersectionBound bound = BoundSelfIntersections(params, r.faces, t.vertexCount);
    const SelfIntersectionSearch search = FindSelfIntersectionsWithin(
        candidates, points, r.medianEdgeLength, params.threads, bound.maxCandidatePairs);
    if (search.searched) {
      const IntersectionCounts counts = CountIntersectingPairs(search.pairs, candidates.size());
      r.selfIntersectingPairs = counts.disjointPairs;
      r.adjacentOverlapPairs = counts.adjacentPairs;
      r.selfIntersectingFaces = counts.faces;
      r.selfIntersectionsComputed = true;
    } else {
      r.selfIntersectionsSkipped = bound.Why(search.candidatePairs, r.faces);
      r.selfIntersectionsSkippedForMemory = !bound.ForWork(search.candidatePairs);
    }
  }
  return r;
}

} // namespace molremesh

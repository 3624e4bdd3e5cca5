// Mesh quality metrics of Khan et al. 2020 (Table 2) plus the validity figures molremesh keeps.
//
// MeshQuality<MeshType>::Compute(m, params) measures any vcg triangle mesh (float or double
// coordinates) without modifying it and without requiring adjacency: topology is derived from
// a sorted edge table, so non-manifold and open inputs are measured too. All geometry is
// evaluated in double precision, so MeshLab's float CMeshO and the CLI's double mesh give the
// same figures for the same file.
#pragma once

#include <array>
#include <cstddef>
#include <map>
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
  bool manifold = true; ///< no non-manifold edge or vertex in the component
  bool closed = false;  ///< manifold and no boundary edge
  int euler = 0;        ///< V - E + F of the component
  int genus = -1;       ///< (2 - euler - boundary loops) / 2; -1 when not manifold
};

/// Every figure the quality report prints. Angles are in degrees, percentages in [0, 100].
struct QualityReport {
  // Element counts
  std::size_t vertices = 0;             ///< live vertices (not deleted)
  std::size_t referencedVertices = 0;   ///< vertices used by at least one face
  std::size_t unreferencedVertices = 0; ///< vertices used by no face
  std::size_t nonFiniteVertices = 0;    ///< vertices with a NaN or infinite coordinate
  std::size_t faces = 0;                ///< live faces
  std::size_t edges = 0;                ///< distinct undirected edges

  // Triangle shape (degenerate faces included: they count as angle 0/180, Q = 0, AR = inf)
  double qMin = 0, qAvg = 0;                   ///< Q = (6/sqrt 3) A / (p h); 1 for equilateral
  double angleMin = 0, meanMinAngle = 0;       ///< smallest angle; mean of per-face minimal angles
  double angleMax = 0;                         ///< largest angle
  double aspectRatioMax = 0, aspectRatioMean = 0; ///< AR = abc / (8 (s-a)(s-b)(s-c)); 1 for equilateral
  std::size_t smallAngleFaces = 0;             ///< faces with an angle < params.smallAngle
  std::size_t obtuseFaces = 0;                 ///< faces with max angle >= params.obtuseAngle
  std::size_t largeAngleFaces = 0;             ///< faces with an angle > params.largeAngle
  double smallAnglePercent = 0, obtusePercent = 0, largeAnglePercent = 0;

  // Valence of interior vertices (not on a boundary or non-manifold edge)
  std::size_t interiorVertices = 0;
  std::size_t regularVertices = 0;         ///< interior with valence 5, 6 or 7
  double v567Percent = 0;                  ///< 100 * regular / interior (100 when there is none)
  std::map<int, std::size_t> valenceHistogram; ///< valence -> number of interior vertices

  // Geometry
  double area = 0;   ///< total surface area
  double volume = 0; ///< signed enclosed volume (divergence theorem); meaningful when closed

  // Topology and validity
  int euler = 0;                      ///< V - E + F over referenced vertices
  int genus = -1;                     ///< sum of component genera; -1 when any component is non-manifold
  std::size_t components = 0;         ///< connected components (through shared edges)
  std::vector<ComponentInfo> componentInfo; ///< one entry per component, largest first
  std::size_t boundaryEdges = 0;      ///< edges with exactly one face
  std::size_t boundaryLoops = 0;      ///< closed boundary polylines (manifold parts only)
  std::size_t nonManifoldEdges = 0;   ///< edges with more than two faces
  std::size_t nonManifoldVertices = 0;///< vertices whose face fan is not one edge-connected fan
  std::size_t degenerateFaces = 0;    ///< repeated vertex index or (near) zero area
  std::size_t selfIntersectingPairs = 0; ///< pairs of faces sharing no vertex that intersect
  bool selfIntersectionsComputed = false;

  bool isTwoManifold() const { return nonManifoldEdges == 0 && nonManifoldVertices == 0; }
};

template <class MeshType>
class MeshQuality {
public:
  struct Params {
    double smallAngle = 30.0;            ///< degrees; faces with an angle below it are "small"
    double obtuseAngle = 90.0;           ///< degrees; faces whose max angle is >= it are obtuse
    double largeAngle = 120.0;           ///< degrees; faces with an angle above it are "large"
    bool computeSelfIntersections = true;///< the only super-linear part; grid accelerated
    double degenerateAreaEpsilon = 1e-12;///< relative to squared mean edge length
  };

  /// Measures m. m is not modified; deleted elements are skipped.
  static QualityReport Compute(const MeshType& m, const Params& params = Params());

  /// Angles of face f (double precision).
  static TriangleAngles FaceAngles(const typename MeshType::FaceType& f);

  /// Valence (number of distinct incident edges) of every vertex, indexed like m.vert.
  static std::vector<int> VertexValences(const MeshType& m);

  /// Per vertex: true when it lies on a boundary or a non-manifold edge, indexed like m.vert.
  static std::vector<bool> VertexOnBorder(const MeshType& m);
};

} // namespace molremesh

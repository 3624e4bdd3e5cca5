// The input surface every remeshing stage projects onto, kept alive for the whole pipeline.
//
// ReferenceSurface<MeshType> copies the live faces of a vcg triangle mesh into double precision
// arrays, with face-to-face adjacency (through shared edges) and a static uniform grid. Stages
// move and create vertices on the working mesh and bring them back onto this surface with
// Project(point, hintFace): the closest point *near the previous footpoint*, found by walking
// the reference faces around hintFace, never by a global query. Molecular surfaces have sheets
// a fraction of an edge length apart (crevices between atoms); a global closest-point query
// would snap a vertex that drifted into such a crevice onto the facing sheet and tear the
// working mesh across the gap. The walk only crosses faces that touch the ball around the
// point whose radius is the distance to the hint, and only faces whose normal agrees with the
// hint face's, so it stays on the sheet the vertex came from.
//
// It also knows its connected components (closed or not, with their enclosed volumes), which
// the stages use to restore each component's volume.
//
// Project can lift the closest point of the flat triangles part of the way (Params::phongAlpha,
// off by default here, 0.5 in RemeshPipeline's runs from CVT through RAR) toward the Phong
// tessellation of the input: the curved surface through the input vertices
// with their normals. Vertices placed on the flat triangles lie on chords of the molecular
// surface, so a remesh whose edges are chords of those chords loses area twice; the lift puts
// the new vertices back toward the curved surface the input samples (area change on the shared
// meshes: 1HPV -0.57 -> -0.30 %, 1UBQ PyMOL -2.10 -> -0.83 %). The lift is bounded
// (Params::phongMaxLift) because on sliver-ridden inputs the vertex normals are poor and an
// unbounded lift leaves vertices up to 0.37 L off the input, and it fades out on faces with a
// corner normal far from the face normal (Params::phongSmoothDeg, phongCreaseDeg): at creases,
// fins and sliver fans the Phong surface describes nothing real.
//
// Thread safety: after Build, every const member is safe to call concurrently provided each
// thread passes its own Scratch to Project (the overload without Scratch uses an internal one
// and is not thread-safe).
#pragma once

#include <vcg/complex/complex.h>

#include <vcg_ext/topology/face_face_topology.h>
#include <vcg_ext/core/float_box.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace molremesh {

/// Result of a projection onto a ReferenceSurface.
struct SurfaceProjection {
  vcg::Point3d point{0, 0, 0};  ///< closest point found on the reference
  vcg::Point3d normal{0, 0, 0}; ///< unit normal of the reference face holding it (0 if degenerate)
  int face = -1;                ///< reference face holding it; -1 when nothing was found
  double distance = std::numeric_limits<double>::infinity(); ///< |query - point|
  bool ok() const { return face >= 0; }
};

namespace reference_detail {

using Point = vcg::Point3d;

/// Closest point of triangle (a, b, c) to p (Ericson, Real-Time Collision Detection, 5.1.5),
/// with a segment fallback for degenerate triangles where the barycentric solve is undefined.
inline Point ClosestPointOnSegment(const Point& p, const Point& a, const Point& b) {
  const Point ab = b - a;
  const double len2 = ab.SquaredNorm();
  if (!(len2 > 0)) return a;
  const double t = std::clamp(((p - a) * ab) / len2, 0.0, 1.0);
  return a + ab * t;
}

inline Point ClosestPointOnTriangle(const Point& p, const Point& a, const Point& b, const Point& c) {
  const Point ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab * ap, d2 = ac * ap;
  if (d1 <= 0 && d2 <= 0) return a;
  const Point bp = p - b;
  const double d3 = ab * bp, d4 = ac * bp;
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
  const Point cp = p - c;
  const double d5 = ab * cp, d6 = ac * cp;
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const double sum = va + vb + vc;
  if (!(std::fabs(sum) > 0) || !std::isfinite(1.0 / sum)) {
    // Degenerate (collinear) triangle: the closest point lies on one of its edges.
    Point best = ClosestPointOnSegment(p, a, b);
    for (const Point& q : {ClosestPointOnSegment(p, b, c), ClosestPointOnSegment(p, c, a)})
      if ((q - p).SquaredNorm() < (best - p).SquaredNorm()) best = q;
    return best;
  }
  const double inv = 1.0 / sum;
  return a + ab * (vb * inv) + ac * (vc * inv);
}

/// Squared distance from p to the closed box [lo, hi] (0 inside).
template <class Corner>
double SquaredDistanceToBox(const Point& p, const Corner& lo, const Corner& hi) {
  double d2 = 0;
  for (int k = 0; k < 3; ++k) {
    const double d = std::max({double(lo[k]) - p[k], 0.0, p[k] - double(hi[k])});
    d2 += d * d;
  }
  return d2;
}
inline double SquaredDistanceToBox(const Point& p, const vcg::Box3d& b) {
  return SquaredDistanceToBox(p, b.min, b.max);
}
/// For a float box: never more than for the double box it was rounded outward from.
inline double SquaredDistanceToBox(const Point& p, const FloatBox& b) {
  return SquaredDistanceToBox(p, b.lo, b.hi);
}

} // namespace reference_detail

template <class MeshType>
class ReferenceSurface {
public:
  using Point = vcg::Point3d;

  struct Params {
    double searchRadius =
        0; ///< Project never looks farther than this from the query; 0 = 3 x mean edge length
    double maxNormalAngleDeg =
        90; ///< Project skips faces whose normal is farther than this from the hint face's
    int maxVisitedFaces = 4096;  ///< bound on the faces one Project call examines
    double gridCellFactor = 2.0; ///< global grid cell size, in mean edge lengths
    double phongAlpha = 0.0;     ///< Project lifts toward the Phong tessellation of the input, blended by
                                 ///< this factor (0: the flat triangles themselves, 1: the Phong surface;
                                 ///< RemeshPipeline sets 0.5 for runs from CVT through RAR)
    double phongMaxLift = 0.05;  ///< bound on the lift's length, in mean edge lengths of the input
                                 ///< (0: unbounded)
    double phongSmoothDeg = 30;  ///< full lift on faces whose corner normals all lie within this angle
    double phongCreaseDeg = 60;  ///< of the face normal, none when one lies this far (a crease, a fin,
                                 ///< a sliver fan: the Phong surface means nothing there); linear between
  };

  /// Per-thread working memory of Project (visited marks). Cheap to keep, costly to create per call.
  class Scratch {
  public:
    Scratch() = default;

  private:
    friend class ReferenceSurface;
    std::vector<std::uint32_t> visited_;
    std::uint32_t stamp_ = 0;
    std::vector<int> stack_;
  };

  ReferenceSurface() = default;
  ReferenceSurface(const ReferenceSurface&) = delete;
  ReferenceSurface& operator=(const ReferenceSurface&) = delete;

  /// Copies the live faces of m (deleted faces and faces with a null or repeated vertex are
  /// skipped) and builds the adjacency and the grid. m is not modified and may be destroyed
  /// afterwards. Returns false with a message when m has no usable face or a non-finite
  /// coordinate on a face.
  bool Build(const MeshType& m, const Params& params = Params(), std::string* error = nullptr);

  bool Empty() const { return faceCount_ == 0; }
  std::size_t FaceCount() const { return faceCount_; }
  double MeanEdgeLength() const { return meanEdge_; }
  double Area() const { return area_; }
  const vcg::Box3d& BoundingBox() const { return box_; }
  const Params& GetParams() const { return params_; }

  /// Corner i of reference face f.
  const Point& Corner(int f, int i) const { return faces_[f].p[i]; }
  /// The distinct vertices of the reference (each once, in the order of their first face) and,
  /// for each, one reference face holding it.
  std::size_t VertexCount() const { return vertices_.size(); }
  const Point& Vertex(std::size_t i) const { return vertices_[i]; }
  int VertexFace(std::size_t i) const { return vertexFace_[i]; }
  /// The corners of reference face f as indices of Vertex().
  const std::array<std::uint32_t, 3>& FaceVertices(int f) const { return faceVertices_[f]; }
  /// Calls visit(f) once for every reference face whose bounding box touches `box` (a walk over
  /// the grid cells the box overlaps). Thread-safe with one Scratch per thread.
  template <class Visit>
  void ForEachFaceInBox(const vcg::Box3d& box, Scratch& scratch, Visit&& visit) const;
  /// Unit normal of reference face f (0 for a degenerate face).
  const Point& FaceNormal(int f) const { return faces_[f].n; }
  /// Connected components (through shared edges): count, the component of face f, whether it
  /// is closed (every edge has exactly two faces) and its signed enclosed volume (meaningful
  /// when closed; positive for outward-oriented faces).
  std::size_t ComponentCount() const { return componentVolume_.size(); }
  int Component(int f) const { return component_[f]; }
  bool ComponentClosed(int c) const { return componentClosed_[c]; }
  double ComponentVolume(int c) const { return componentVolume_[c]; }
  /// Index in m.face of the face reference face f was copied from.
  std::size_t SourceFace(int f) const { return sourceFace_[f]; }
  /// Reference face copied from m.face[i], or -1 (deleted or index-degenerate face, or out of range).
  int ReferenceFaceOf(std::size_t meshFaceIndex) const {
    return meshFaceIndex < referenceOf_.size() ? referenceOf_[meshFaceIndex] : -1;
  }

  /// Closest point of the reference near p, found by a walk from hintFace (see the file
  /// comment). hintFace < 0 falls back to ProjectGlobal. Thread-safe with one Scratch per thread.
  /// lift = false: the closest point of the flat triangles, whatever Params::phongAlpha says.
  SurfaceProjection Project(const Point& p, int hintFace, Scratch& scratch, bool lift = true) const;
  /// Same, with an internal scratch: not thread-safe.
  SurfaceProjection Project(const Point& p, int hintFace) const { return Project(p, hintFace, ownScratch_); }

  /// What the reference keeps of a face: corners and unit normal, 96 bytes. The projections read
  /// a face's record at random, once per vertex and iteration, so its size is what they wait
  /// for; a caller that reads the same face again and again may keep a copy (Record).
  struct FaceRecord {
    std::array<Point, 3> p{Point(0, 0, 0), Point(0, 0, 0), Point(0, 0, 0)}; ///< corners
    Point n{0, 0, 0};                                                       ///< unit normal, 0 if degenerate
    /// The exact bounding box, recomputed where needed (the float box is kept apart).
    vcg::Box3d Box() const {
      vcg::Box3d b;
      for (const Point& c : p) b.Add(c);
      return b;
    }
  };
  /// The record of reference face f.
  const FaceRecord& Record(int f) const { return faces_[f]; }

  /// The orthogonal projection of p onto the plane of face f when it falls inside f (returned on
  /// f, not lifted), else a failed projection. No search, so not always the closest point: a
  /// cheap step for iterated moves whose final positions get a proper Project. Thread-safe.
  SurfaceProjection ProjectInsideFace(const Point& p, int f) const {
    if (f < 0 || std::size_t(f) >= faceCount_) return SurfaceProjection();
    return ProjectInsideFace(p, faces_[f], f);
  }
  /// The same from a copy of face f's record.
  static SurfaceProjection ProjectInsideFace(const Point& p, const FaceRecord& face, int f) {
    SurfaceProjection r;
    if (!(face.n.SquaredNorm() > 0)) return r;
    const Point q = p - face.n * ((p - face.p[0]) * face.n);
    std::array<double, 3> b{};
    if (!Barycentrics(q, face, b) || b[0] < 0 || b[1] < 0 || b[2] < 0) return r;
    r.point = q;
    r.normal = face.n;
    r.face = f;
    r.distance = (q - p).Norm();
    return r;
  }

  /// Globally closest point of the reference (grid search). Thread-safe.
  SurfaceProjection ProjectGlobal(const Point& p) const;
  /// Distance from p to the reference (global). Thread-safe.
  double Distance(const Point& p) const { return ProjectGlobal(p).distance; }

private:
  /// q (a point of face f) moved onto the Phong-tessellated surface, blended by phongAlpha.
  Point Lift(const Point& q, int f) const;
  /// Barycentric coordinates of q (a point in the plane of the face) from the sub-triangle areas
  /// along the face's normal: negative outside the face. False for a degenerate face.
  static bool Barycentrics(const Point& q, const FaceRecord& face, std::array<double, 3>& b) {
    const Point n = (face.p[1] - face.p[0]) ^ (face.p[2] - face.p[0]);
    const double n2 = n.SquaredNorm();
    if (!(n2 > 0)) return false;
    for (int k = 0; k < 3; ++k) b[k] = ((face.p[(k + 1) % 3] - q) ^ (face.p[(k + 2) % 3] - q)) * n / n2;
    return true;
  }

  SurfaceProjection ClosestOnFace(const Point& p, int f) const {
    SurfaceProjection r;
    const FaceRecord& face = faces_[f];
    r.point = reference_detail::ClosestPointOnTriangle(p, face.p[0], face.p[1], face.p[2]);
    r.normal = face.n;
    r.face = f;
    r.distance = (r.point - p).Norm();
    return r;
  }
  void BuildAdjacency(const std::vector<std::array<std::uint32_t, 3>>& tris);
  void BuildGrid();
  /// The grid cells box b overlaps, clamped to the grid: {x0, y0, z0, x1, y1, z1}, inclusive.
  std::array<int, 6> CellRange(const vcg::Box3d& b) const {
    std::array<int, 6> r{};
    for (int k = 0; k < 3; ++k) {
      r[k] = std::clamp(int(std::floor((b.min[k] - box_.min[k]) / cell_)), 0, dims_[k] - 1);
      r[k + 3] = std::clamp(int(std::floor((b.max[k] - box_.min[k]) / cell_)), 0, dims_[k] - 1);
    }
    return r;
  }
  /// A fresh visit mark in s (sized for this surface).
  void NewVisit(Scratch& s) const {
    if (s.visited_.size() != faceCount_) {
      s.visited_.assign(faceCount_, 0);
      s.stamp_ = 0;
    }
    if (++s.stamp_ == 0) { // wrapped: clear the marks once every 2^32 calls
      std::fill(s.visited_.begin(), s.visited_.end(), 0);
      s.stamp_ = 1;
    }
  }

  Params params_;
  std::size_t faceCount_ = 0;
  std::vector<FaceRecord> faces_;
  /// Each face's box rounded outward to float: Project's walk rejects most faces it looks at by
  /// their box, and this array is a sixth of faces_, so the rejections mostly hit the cache.
  std::vector<FloatBox> compactBox_;
  std::vector<Point> vertexNormals_; ///< unit normal of each Vertex() (Phong lift only)
  std::vector<float> liftWeight_;    ///< each face's share of the lift, from its corner normals (Phong only)
  std::vector<std::uint32_t> neighborStart_, neighbors_; ///< faces sharing an edge, CSR
  std::vector<std::size_t> sourceFace_;
  std::vector<int> component_;
  std::vector<double> componentVolume_;
  std::vector<bool> componentClosed_;
  std::vector<int> referenceOf_;
  std::vector<Point> vertices_;
  std::vector<int> vertexFace_;
  std::vector<std::array<std::uint32_t, 3>> faceVertices_;
  double meanEdge_ = 0, area_ = 0, searchRadius_ = 0, cosMaxNormalAngle_ = 0;
  vcg::Box3d box_;

  // Static uniform grid, CSR over dense cells.
  double cell_ = 1;
  std::array<int, 3> dims_{1, 1, 1};
  std::vector<std::uint32_t> cellStart_, cellFaces_;

  mutable Scratch ownScratch_;
};

// ------------------------------------------------------------------------------------------------
// Implementation
// ------------------------------------------------------------------------------------------------

template <class MeshType>
bool ReferenceSurface<MeshType>::Build(const MeshType& m, const Params& params, std::string* error) {
  params_ = params;
  faces_.clear();
  compactBox_.clear();
  vertexNormals_.clear();
  liftWeight_.clear();
  sourceFace_.clear();
  referenceOf_.assign(m.face.size(), -1);
  box_.SetNull();
  area_ = 0;
  faceCount_ = 0;

  const auto* vertBegin = m.vert.empty() ? nullptr : &m.vert[0];
  std::vector<std::array<std::uint32_t, 3>> tris;
  tris.reserve(m.face.size());
  faces_.reserve(m.face.size()); // face records are large: growing by copies cost more than the fill
  sourceFace_.reserve(m.face.size());
  double edgeSum = 0;
  std::size_t edgeCount = 0;
  for (std::size_t i = 0; i < m.face.size(); ++i) {
    const auto& f = m.face[i];
    if (f.IsD() || f.cV(0) == nullptr || f.cV(1) == nullptr || f.cV(2) == nullptr) continue;
    if (f.cV(0) == f.cV(1) || f.cV(1) == f.cV(2) || f.cV(2) == f.cV(0)) continue;
    FaceRecord face;
    std::array<std::uint32_t, 3> tri{};
    for (int k = 0; k < 3; ++k) {
      const auto& c = f.cV(k)->cP();
      face.p[k] = Point(double(c[0]), double(c[1]), double(c[2]));
      if (!std::isfinite(face.p[k][0]) || !std::isfinite(face.p[k][1]) || !std::isfinite(face.p[k][2])) {
        if (error) *error = "the reference surface has a vertex with a NaN or infinite coordinate";
        faces_.clear();
        return false;
      }
      tri[k] = std::uint32_t(f.cV(k) - vertBegin);
    }
    const Point n = (face.p[1] - face.p[0]) ^ (face.p[2] - face.p[0]);
    const double len = n.Norm();
    face.n = len > 0 ? n / len : Point(0, 0, 0);
    area_ += 0.5 * len;
    for (int k = 0; k < 3; ++k) edgeSum += (face.p[(k + 1) % 3] - face.p[k]).Norm();
    edgeCount += 3;
    box_.Add(face.Box());
    referenceOf_[i] = int(faces_.size());
    sourceFace_.push_back(i);
    faces_.push_back(face);
    tris.push_back(tri);
  }
  faceCount_ = faces_.size();
  compactBox_.resize(faceCount_);
  for (std::size_t f = 0; f < faceCount_; ++f) compactBox_[f] = FloatBox::Outward(faces_[f].Box());
  {
    std::vector<int> seen(m.vert.size(), -1);
    vertices_.clear();
    vertexFace_.clear();
    faceVertices_.resize(faceCount_);
    for (std::size_t f = 0; f < faceCount_; ++f)
      for (int k = 0; k < 3; ++k) {
        if (seen[tris[f][k]] < 0) {
          seen[tris[f][k]] = int(vertices_.size());
          vertices_.push_back(faces_[f].p[k]);
          vertexFace_.push_back(int(f));
        }
        faceVertices_[f][k] = std::uint32_t(seen[tris[f][k]]);
      }
  }
  if (params_.phongAlpha > 0 && faceCount_ > 0) {
    // Angle-weighted vertex normals.
    vertexNormals_.assign(vertices_.size(), Point(0, 0, 0));
    for (std::size_t f = 0; f < faceCount_; ++f)
      for (int k = 0; k < 3; ++k) {
        const Point u = faces_[f].p[(k + 1) % 3] - faces_[f].p[k],
                    w = faces_[f].p[(k + 2) % 3] - faces_[f].p[k];
        vertexNormals_[faceVertices_[f][k]] += faces_[f].n * std::atan2((u ^ w).Norm(), u * w);
      }
    for (auto& n : vertexNormals_) {
      const double len = n.Norm();
      if (len > 0) n /= len;
    }
    const double cosSmooth = std::cos(params_.phongSmoothDeg * 3.14159265358979323846 / 180.0),
                 cosCrease = std::cos(params_.phongCreaseDeg * 3.14159265358979323846 / 180.0);
    liftWeight_.resize(faceCount_);
    for (std::size_t f = 0; f < faceCount_; ++f) {
      double worst = 1;
      for (int k = 0; k < 3; ++k) worst = std::min(worst, vertexNormals_[faceVertices_[f][k]] * faces_[f].n);
      const double w =
          cosSmooth > cosCrease ? (worst - cosCrease) / (cosSmooth - cosCrease) : double(worst >= cosSmooth);
      liftWeight_[f] = faces_[f].n.SquaredNorm() > 0 ? float(std::clamp(w, 0.0, 1.0)) : 0.0f;
    }
  }
  if (faceCount_ == 0) {
    if (error) *error = "the reference surface has no face";
    return false;
  }
  // Interior edges are counted twice, boundary edges once: close enough for a length scale.
  meanEdge_ = edgeSum / double(edgeCount);
  if (!(meanEdge_ > 0)) meanEdge_ = std::max(box_.Diag(), 1.0);
  searchRadius_ = params_.searchRadius > 0 ? params_.searchRadius : 3.0 * meanEdge_;
  cosMaxNormalAngle_ = std::cos(params_.maxNormalAngleDeg * 3.14159265358979323846 / 180.0);
  BuildAdjacency(tris);
  BuildGrid();
  return true;
}

template <class MeshType>
void ReferenceSurface<MeshType>::BuildAdjacency(const std::vector<std::array<std::uint32_t, 3>>& tris) {
  // Faces sharing an edge are mutual neighbours (all of them on a non-manifold edge).
  std::uint32_t vertexCount = 0;
  for (const auto& t : tris) vertexCount = std::max({vertexCount, t[0] + 1, t[1] + 1, t[2] + 1});
  std::vector<std::uint8_t> onOddEdge(faceCount_, 0);         // on an edge without exactly two faces
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs; // (face, neighbour)
  pairs.reserve(tris.size() * 3);
  ForEachEdgeSideGroup(
      vertexCount, tris.size(), [&](std::size_t f, int k) { return tris[f][k]; },
      [](std::size_t) { return true; },
      [&](auto first, auto last, int) { // serial: pairs grows in group order
        if (last - first != 2)
          for (auto a = first; a != last; ++a) onOddEdge[a->face] = 1;
        for (auto a = first; a != last; ++a)
          for (auto b = first; b != last; ++b)
            if (a->face != b->face) pairs.emplace_back(a->face, b->face);
      });
  // CSR of the neighbours, each face's list sorted and without repeats.
  neighborStart_.assign(faceCount_ + 1, 0);
  for (const auto& pr : pairs) ++neighborStart_[pr.first + 1];
  for (std::size_t f = 0; f < faceCount_; ++f) neighborStart_[f + 1] += neighborStart_[f];
  neighbors_.resize(pairs.size());
  {
    std::vector<std::uint32_t> fill(neighborStart_.begin(), neighborStart_.end() - 1);
    for (const auto& [f, g] : pairs) neighbors_[fill[f]++] = g;
  }
  std::size_t kept = 0;
  for (std::size_t f = 0; f < faceCount_; ++f) {
    const auto first = neighbors_.begin() + neighborStart_[f],
               last = neighbors_.begin() + neighborStart_[f + 1];
    std::sort(first, last);
    const auto end = std::unique(first, last);
    neighborStart_[f] = std::uint32_t(kept);
    for (auto it = first; it != end; ++it) neighbors_[kept++] = *it;
  }
  neighborStart_[faceCount_] = std::uint32_t(kept);
  neighbors_.resize(kept);

  // Components through shared edges (numbered by their lowest face), closedness, volume.
  component_.assign(faceCount_, -1);
  componentVolume_.clear();
  componentClosed_.clear();
  const Point origin = box_.Center();
  std::vector<int> stack;
  for (std::size_t f0 = 0; f0 < faceCount_; ++f0) {
    if (component_[f0] >= 0) continue;
    const int c = int(componentVolume_.size());
    componentVolume_.push_back(0.0);
    componentClosed_.push_back(true);
    component_[f0] = c;
    stack.assign(1, int(f0));
    while (!stack.empty()) {
      const int f = stack.back();
      stack.pop_back();
      const FaceRecord& face = faces_[f];
      componentVolume_[c] += ((face.p[0] - origin) * ((face.p[1] - origin) ^ (face.p[2] - origin))) / 6.0;
      if (onOddEdge[f]) componentClosed_[c] = false;
      for (std::uint32_t k = neighborStart_[f]; k < neighborStart_[f + 1]; ++k)
        if (component_[neighbors_[k]] < 0) {
          component_[neighbors_[k]] = c;
          stack.push_back(int(neighbors_[k]));
        }
    }
  }
}

template <class MeshType>
void ReferenceSurface<MeshType>::BuildGrid() {
  const Point extent = box_.Dim();
  cell_ = params_.gridCellFactor * meanEdge_;
  if (!(cell_ > 0)) cell_ = std::max({extent[0], extent[1], extent[2], 1.0});
  // Keep the dense cell array within a few entries per face.
  for (;;) {
    double cells = 1;
    for (int k = 0; k < 3; ++k) cells *= std::floor(extent[k] / cell_) + 1.0;
    if (cells <= 8.0 * double(faceCount_) + 1024.0) break;
    cell_ *= 1.5;
  }
  for (int k = 0; k < 3; ++k) dims_[k] = int(std::floor(extent[k] / cell_)) + 1;
  const std::size_t cellCount = std::size_t(dims_[0]) * dims_[1] * dims_[2];
  cellStart_.assign(cellCount + 1, 0);
  for (const FaceRecord& f : faces_) {
    const std::array<int, 6> r = CellRange(f.Box());
    for (int z = r[2]; z <= r[5]; ++z)
      for (int y = r[1]; y <= r[4]; ++y)
        for (int x = r[0]; x <= r[3]; ++x) ++cellStart_[(std::size_t(z) * dims_[1] + y) * dims_[0] + x + 1];
  }
  for (std::size_t c = 0; c < cellCount; ++c) cellStart_[c + 1] += cellStart_[c];
  cellFaces_.resize(cellStart_[cellCount]);
  std::vector<std::uint32_t> fill(cellStart_.begin(), cellStart_.end() - 1);
  for (std::size_t fi = 0; fi < faceCount_; ++fi) {
    const std::array<int, 6> r = CellRange(faces_[fi].Box());
    for (int z = r[2]; z <= r[5]; ++z)
      for (int y = r[1]; y <= r[4]; ++y)
        for (int x = r[0]; x <= r[3]; ++x)
          cellFaces_[fill[(std::size_t(z) * dims_[1] + y) * dims_[0] + x]++] = std::uint32_t(fi);
  }
}

template <class MeshType>
vcg::Point3d ReferenceSurface<MeshType>::Lift(const Point& q, int f) const {
  if (!(params_.phongAlpha > 0) || !(liftWeight_[f] > 0)) return q;
  const FaceRecord& face = faces_[f];
  std::array<double, 3> b{};
  if (!Barycentrics(q, face, b)) return q;
  for (double& bk : b) bk = std::max(0.0, bk);
  const double sum = b[0] + b[1] + b[2];
  if (!(sum > 0)) return q;
  // Phong tessellation: the barycentric blend of q's projections onto the corners' tangent planes.
  Point phong(0, 0, 0);
  for (int k = 0; k < 3; ++k) {
    const Point& vn = vertexNormals_[faceVertices_[f][k]];
    phong += (q - vn * ((q - face.p[k]) * vn)) * (b[k] / sum);
  }
  Point lift = (phong - q) * (params_.phongAlpha * liftWeight_[f]);
  const double maxLift = params_.phongMaxLift * meanEdge_;
  if (maxLift > 0) {
    const double len = lift.Norm();
    if (len > maxLift) lift *= maxLift / len;
  }
  return q + lift;
}

template <class MeshType>
SurfaceProjection ReferenceSurface<MeshType>::ProjectGlobal(const Point& p) const {
  SurfaceProjection best;
  if (faceCount_ == 0) return best;
  std::array<int, 3> center{};
  for (int k = 0; k < 3; ++k)
    center[k] = std::clamp(int(std::floor((p[k] - box_.min[k]) / cell_)), 0, dims_[k] - 1);
  const int maxShell = std::max({dims_[0], dims_[1], dims_[2]});
  for (int s = 0; s <= maxShell; ++s) {
    std::array<int, 3> lo{}, hi{};
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::max(center[k] - s, 0);
      hi[k] = std::min(center[k] + s, dims_[k] - 1);
    }
    for (int z = lo[2]; z <= hi[2]; ++z)
      for (int y = lo[1]; y <= hi[1]; ++y)
        for (int x = lo[0]; x <= hi[0]; ++x) {
          // Only the cells of shell s (Chebyshev distance s from the center).
          if (std::max({std::abs(x - center[0]), std::abs(y - center[1]), std::abs(z - center[2])}) != s)
            continue;
          const std::size_t c = (std::size_t(z) * dims_[1] + y) * dims_[0] + x;
          for (std::uint32_t k = cellStart_[c]; k < cellStart_[c + 1]; ++k) {
            const int f = int(cellFaces_[k]);
            if (reference_detail::SquaredDistanceToBox(p, faces_[f].Box()) >= best.distance * best.distance)
              continue;
            const SurfaceProjection candidate = ClosestOnFace(p, f);
            if (candidate.distance < best.distance || (candidate.distance == best.distance && f < best.face))
              best = candidate;
          }
        }
    // Every face not yet seen lies outside the searched block of cells: stop when the best
    // point is closer than the block's walls that still have cells beyond them.
    double wall = std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k) {
      if (lo[k] > 0) wall = std::min(wall, p[k] - (box_.min[k] + lo[k] * cell_));
      if (hi[k] < dims_[k] - 1) wall = std::min(wall, box_.min[k] + (hi[k] + 1) * cell_ - p[k]);
    }
    if (best.ok() && best.distance <= wall) break;
  }
  return best;
}

template <class MeshType>
template <class Visit>
void ReferenceSurface<MeshType>::ForEachFaceInBox(const vcg::Box3d& box, Scratch& s, Visit&& visit) const {
  // Closed boxes: a face parallel to a coordinate plane has a flat box (vcg's Collide is strict).
  auto touch = [](const vcg::Box3d& a, const vcg::Box3d& b) {
    for (int k = 0; k < 3; ++k)
      if (a.min[k] > b.max[k] || b.min[k] > a.max[k]) return false;
    return true;
  };
  if (faceCount_ == 0 || box.IsNull() || !touch(box, box_)) return;
  NewVisit(s);
  const std::array<int, 6> r = CellRange(box);
  for (int z = r[2]; z <= r[5]; ++z)
    for (int y = r[1]; y <= r[4]; ++y)
      for (int x = r[0]; x <= r[3]; ++x) {
        const std::size_t c = (std::size_t(z) * dims_[1] + y) * dims_[0] + x;
        for (std::uint32_t k = cellStart_[c]; k < cellStart_[c + 1]; ++k) {
          const std::uint32_t f = cellFaces_[k];
          if (s.visited_[f] == s.stamp_) continue;
          s.visited_[f] = s.stamp_;
          if (touch(faces_[f].Box(), box)) visit(int(f));
        }
      }
}

template <class MeshType>
SurfaceProjection ReferenceSurface<MeshType>::Project(const Point& p, int hintFace, Scratch& s,
                                                      bool lift) const {
  lift = lift && params_.phongAlpha > 0;
  if (hintFace < 0 || std::size_t(hintFace) >= faceCount_) {
    SurfaceProjection global = ProjectGlobal(p);
    if (global.ok() && lift) {
      global.point = Lift(global.point, global.face);
      global.distance = (global.point - p).Norm();
    }
    return global;
  }
  NewVisit(s);
  SurfaceProjection best = ClosestOnFace(p, hintFace);
  const Point& hintNormal = faces_[hintFace].n;
  const bool filterNormals = hintNormal.SquaredNorm() > 0;
  // Faces are expanded while they touch the ball around p of radius d(p, hint) (capped by the
  // search radius): the closest point of this sheet lies in it, and faces beyond it do not.
  const double radius = std::min(best.distance, searchRadius_);
  const double radius2 = radius * radius * (1.0 + 1e-12) + 1e-300;
  s.stack_.clear();
  s.stack_.push_back(hintFace);
  s.visited_[hintFace] = s.stamp_;
  int visitedCount = 1;
  while (!s.stack_.empty() && visitedCount < params_.maxVisitedFaces) {
    const int f = s.stack_.back();
    s.stack_.pop_back();
    for (std::uint32_t k = neighborStart_[f]; k < neighborStart_[f + 1]; ++k) {
      const int g = int(neighbors_[k]);
      if (s.visited_[g] == s.stamp_) continue;
      s.visited_[g] = s.stamp_;
      ++visitedCount;
      const FaceRecord& face = faces_[g];
      // The float box contains the exact one, so it rejects only faces the exact test rejects.
      if (reference_detail::SquaredDistanceToBox(p, compactBox_[g]) > radius2) continue;
      if (filterNormals && face.n.SquaredNorm() > 0 && face.n * hintNormal < cosMaxNormalAngle_) continue;
      if (reference_detail::SquaredDistanceToBox(p, face.Box()) > radius2) continue;
      const SurfaceProjection candidate = ClosestOnFace(p, g);
      if (candidate.distance * candidate.distance > radius2) continue;
      if (candidate.distance < best.distance) best = candidate;
      s.stack_.push_back(g);
    }
  }
  if (lift) {
    best.point = Lift(best.point, best.face);
    best.distance = (best.point - p).Norm();
  }
  return best;
}

} // namespace molremesh

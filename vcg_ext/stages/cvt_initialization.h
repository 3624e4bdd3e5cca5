// Stage 1 of Khan et al. 2020: centroidal Voronoi tessellation (CVT) initialization.
//
// CvtInitialization<MeshType>::Do turns a clean molecular surface into a CVT-like triangulation
// with target edge length L: the vertices are the sites of a centroidal Voronoi tessellation
// restricted to the input surface and the triangles are its dual (Delaunay) triangulation.
//
// Instead of computing a restricted Voronoi diagram and rebuilding connectivity from it (which
// breaks on molecular surfaces: sheets a fraction of L apart get connected across the gap, and
// boundary or non-manifold cells appear), the input triangulation itself is evolved, and its
// connectivity only ever changes through the guarded local operations of LocalRemeshingOps:
//  1. sampling: edges longer than 4/3 L are split and edges shorter than 4/5 L collapsed, a few
//     passes; then, one round per Lloyd iteration during the first third of them, the vertex
//     count is brought to the one a uniform CVT of edge L has on this area,
//     V = 2 A / (sqrt(3) L^2), by splitting the longest / collapsing the shortest edges;
//  2. Lloyd relaxation (Params::iterations, 42 as in the paper): every vertex moves to the
//     centroid of its Voronoi cell, projected back onto the input near the vertex's previous
//     footpoint (in the intermediate iterations simply onto the plane of that footpoint's face
//     when it lands inside it: the closest point nearly always, and a point of the input in any
//     case; the last iteration searches properly and lifts, see Params::fullProjectionIterations);
//     after each verification (below) edges are flipped until the triangulation is Delaunay again;
//  3. volume restoration: vertices on the input's flat triangles cut convex regions short, so
//     each closed component is finally offset along its normals (at most 0.05 L by default) to
//     enclose the input's volume again.
// Since splits, collapses (link condition) and flips preserve the topology of a 2-manifold, the
// output is manifold, each closed component stays closed with its genus, and two sheets are
// never joined across a gap; every edit is also checked for folds, angles and intersections.
//
// The Voronoi cell of a vertex is approximated on its one-ring: in each incident triangle, the
// part closer to the vertex than to the triangle's two other corners (the triangle clipped by
// the two perpendicular bisectors). The cell centroid is the area-weighted mean of these
// polygons' centroids. This is exact for the Delaunay triangulation of non-obtuse triangles,
// stays well defined for obtuse ones (where the circumcentre-based cell pieces would have
// negative area), and uses only the current triangulation's connectivity, so a cell can never
// leak onto a nearby sheet.
//
// Speed, parallelism and determinism: the cell centroids are accumulated face by face (each
// thread owns a range of vertices) and projected in parallel, Jacobi style, from the positions
// at the start of the iteration. The moves are applied at once and verified every
// Params::verifyEvery iterations (and always before any other edit) by
// LocalRemeshingOps::VerifyPendingMoves: every changed face is checked in parallel (angles,
// normals, folds, and one sweep over all faces for intersecting pairs); vertices of failing
// faces go back to their last verified position. Every step writes per-element results or runs
// in a fixed order, so the output is bit-identical for any thread count.
#pragma once

#include <vcg/complex/complex.h>

#include <vcg_ext/core/input_check.h>
#include <vcg_ext/ops/local_remeshing_ops.h>
#include <vcg_ext/core/parallel_for.h>
#include <vcg_ext/geometry/mean_edge_length.h>
#include <vcg_ext/quality/quality_report_format.h>
#include <vcg_ext/surface/reference_surface.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

namespace molremesh {

template <class MeshType>
class CvtInitialization {
public:
  using VertexType = typename MeshType::VertexType;
  using FaceType = typename MeshType::FaceType;
  using VertexPointer = typename MeshType::VertexPointer;
  using FacePointer = typename MeshType::FacePointer;
  using Ops = LocalRemeshingOps<MeshType>;
  using Point = vcg::Point3d;

  struct Params {
    double targetEdgeLength = 0; ///< L; 0 = the input's mean edge length
    std::size_t targetVertexCount =
        0;                          ///< > 0: L = sqrt(2 A / (sqrt(3) V)) for the input area A (overrides L)
    int iterations = 42;            ///< Lloyd iterations (Khan et al.'s default)
    int samplingPasses = 4;         ///< split / collapse passes before the Lloyd iterations
    double splitFactor = 4.0 / 3.0; ///< sampling splits edges longer than this x L
    double collapseFactor = 4.0 / 5.0;   ///< sampling collapses edges shorter than this x L
    bool matchVertexCount = true;        ///< then split / collapse to the vertex count of a CVT with edge L
    double vertexCountTolerance = 0.005; ///< relative; the count is matched within it
    bool delaunayFlips = true;           ///< flip to Delaunay after every verification of the Lloyd moves
    double maxFlipsPerVertex = 2.0;      ///< bound on the flips of one Delaunay restoration, per vertex
    double minMoveFactor = 1e-6; ///< Lloyd moves shorter than this x L (along the input's tangent plane)
                                 ///< are skipped: the site has converged (no projection, no move)
    int verifyEvery = 6;         ///< Lloyd iterations between two verifications + Delaunay flip passes
                                 ///< (the first two and the last iteration are always verified; after
                                 ///< the first few, most sites move less than 0.01 L per iteration)
    /// The last this many Lloyd iterations project each centroid onto the input with the
    /// closest-point search (and the lift of the reference's params). The earlier ones move it
    /// within its site's footpoint face when it projects inside it (nearly always: the moves are
    /// small), else search without the lift: the intermediate sites only need to lie on the input.
    int fullProjectionIterations = 1;
    int threads = 0;               ///< worker threads; 0 = all cores (the result does not depend on it)
    LocalOpsGuards guards;         ///< thresholds of the local operations
    bool preserveVolume = true;    ///< finally offset each closed component along its vertex normals so
                                   ///< that it encloses the input's volume again (see RestoreVolume)
    double maxVolumeOffset = 0.05; ///< bound on that offset, in units of L (keeps vertices near the input)
    typename ReferenceSurface<MeshType>::Params reference; ///< for the reference built by Do(m, params)
    /// If set, called on the calling thread at each sampling pass, Lloyd iteration and the volume
    /// restoration with the share of the stage done (0..1) and the step ("Lloyd iteration 17/42").
    std::function<void(double fraction, const std::string& step)> progress;
  };

  struct Result {
    bool ok = false;
    std::string message;         ///< why it failed, or a one-line summary
    double targetEdgeLength = 0; ///< L actually used
    std::size_t verticesIn = 0, facesIn = 0, verticesOut = 0, facesOut = 0;
    std::size_t splits = 0, collapses = 0, flips = 0; ///< applied operations (all phases)
    std::size_t movesApplied = 0;                     ///< Lloyd vertex moves made
    std::size_t movesRejected = 0;     ///< vertices put back to their last verified position (or refused)
    int verifications = 0;             ///< verification + flip passes of the Lloyd phase
    std::size_t refusedOperations = 0; ///< all refused single operations (splits, collapses, flips)
    LocalOpsStats operations;          ///< counts of the local operations, refusals by reason
    int iterations = 0;                ///< Lloyd iterations done
    double lastMeanMove = 0;           ///< mean Lloyd displacement of the last iteration, in units of L
    double volumeOffset = 0;           ///< largest |normal offset| of the volume restoration, in units of L
  };

  /// Remeshes m in place. m must be a 2-manifold, consistently oriented triangle mesh with
  /// FF and VF adjacency enabled (MeshLab: MM_FACEFACETOPO | MM_VERTFACETOPO); the reference
  /// surface is a copy of m taken on entry. Refused inputs (empty, point cloud, NaN, non-manifold,
  /// misoriented) are left untouched and reported in Result::message.
  static Result Do(MeshType& m, const Params& params = Params(), vcg::CallBackPos* cb = nullptr) {
    return Run(m, nullptr, params, cb);
  }

  /// Same, projecting onto a reference surface the caller keeps (e.g. the cleaned input kept
  /// for the whole pipeline). m must lie on (or very near) it.
  static Result Do(MeshType& m, const ReferenceSurface<MeshType>& reference, const Params& params = Params(),
                   vcg::CallBackPos* cb = nullptr) {
    return Run(m, &reference, params, cb);
  }

  /// Area (x2) and area-weighted centroid (x2) of the part of triangle (p0, p1, p2) closer to p0
  /// than to p1 and p2: the triangle clipped by the two perpendicular bisectors through p0.
  static void CornerPiece(const Point& p0, const Point& p1, const Point& p2, double& area, Point& weighted);

  /// CornerPiece of all three corners of triangle p at once (corner k is p[k]): a non-obtuse
  /// triangle's circumcentre and the three sub-triangle areas are computed once and shared.
  static void FacePieces(const std::array<Point, 3>& p, std::array<double, 3>& area,
                         std::array<Point, 3>& weighted);

private:
  struct EdgeCandidate {
    double length2;
    std::uint32_t a, b; // vertex indices, a < b
    std::uint64_t key;  // Morton code of the midpoint (spatial order)
  };

  /// A copy of a footpoint face's record, kept per vertex: the sites are visited in vertex order,
  /// their footpoint faces at random, and a site keeps its footpoint over many iterations, so
  /// reading the copy (in order) instead of the reference's record saves a cache miss per site and
  /// iteration.
  struct FootRecord {
    int face = -1;
    typename ReferenceSurface<MeshType>::FaceRecord record;
  };
  /// The buffers of the Lloyd iterations, kept from one iteration to the next.
  struct Lloyd {
    std::vector<typename ReferenceSurface<MeshType>::Scratch> scratch; ///< per thread
    std::vector<std::uint32_t> movable;                                ///< the sites that may move
    std::vector<Point> position;                                       ///< per vertex
    std::vector<Point> target;                                         ///< per movable site
    std::vector<int> targetFoot;                                       ///< per movable site
    std::vector<double> moveLength;                                    ///< squared, per movable site
    std::vector<double> cellArea;                                      ///< per vertex (x2)
    std::vector<Point> cellWeighted;                                   ///< per vertex (x2)
    std::vector<FootRecord> footRecord;                                ///< per vertex
    std::vector<std::vector<std::array<std::uint32_t, 3>>>
        ownerFaces;                                             ///< corners of the faces each owner sums
    std::size_t ownerFacesTopology = 0, ownerFacesVertices = 0; ///< edit count and vertex count when made
  };

  static Result Run(MeshType& m, const ReferenceSurface<MeshType>* external, const Params& params,
                    vcg::CallBackPos* cb);
  /// Why m cannot be remeshed ("" when it can); prepares its adjacency for LocalRemeshingOps.
  static std::string CheckInput(MeshType& m, const Params& params);
  /// Params::targetEdgeLength, or m's mean edge length, or the one that gives
  /// Params::targetVertexCount vertices on the reference.
  static double TargetEdgeLength(const MeshType& m, const ReferenceSurface<MeshType>& reference,
                                 const Params& params);
  /// Splits and collapses toward edges of L (with Delaunay flips) until nothing changes.
  static void Sample(Ops& ops, const Params& params, double L, int threads, std::vector<EdgeCandidate>& edges,
                     vcg::CallBackPos* cb);
  /// Splits or collapses toward the wanted vertex count, beyond the tolerance.
  static void MatchVertexCount(Ops& ops, const MeshType& m, const Params& params, double L, double wanted,
                               std::vector<EdgeCandidate>& edges);
  /// Area and area-weighted centroid of every vertex's Voronoi cell.
  static void CellCentroids(const MeshType& m, Ops& ops, int threads, Lloyd& s);
  /// The sites that may move and where to: their cell centroids projected onto the reference.
  static void MoveTargets(const MeshType& m, Ops& ops, const ReferenceSurface<MeshType>& reference,
                          int threads, double minMove2, bool fullProjection, Lloyd& s);
  /// Moves the sites (unverified); returns the sum of the move lengths.
  static double ApplyMoves(Ops& ops, MeshType& m, double minMove2, const Lloyd& s, std::size_t& applied,
                           std::size_t& rejected);
  static void Progress(vcg::CallBackPos* cb, double fraction, const char* what) {
    if (cb != nullptr) cb(int(std::clamp(fraction, 0.0, 1.0) * 100.0), what);
  }
  static std::size_t LiveVertices(const MeshType& m) {
    std::size_t n = 0;
    for (const auto& v : m.vert)
      if (!v.IsD() && v.cVFp() != nullptr) ++n;
    return n;
  }
  /// Edges with length^2 above (longer = true) or below the threshold: longest / shortest first,
  /// or, when cell > 0, along a Morton curve of their midpoints (cells of that size), so that
  /// consecutive edits touch the same memory.
  static void CollectEdges(const MeshType& m, double threshold2, bool longer, double cell,
                           std::vector<EdgeCandidate>& out);
  /// advanced, when set, hears the share of the candidate edges gone through, every few thousand.
  static std::size_t SplitPass(Ops& ops, double threshold, std::size_t limit,
                               std::vector<EdgeCandidate>& edges,
                               const std::function<void(double)>& advanced = {});
  static std::size_t CollapsePass(Ops& ops, double threshold, double maxNewEdge, std::size_t limit,
                                  std::vector<EdgeCandidate>& edges,
                                  const std::function<void(double)>& advanced = {});
  /// Calls advanced every 4096 candidates (a progress bar's step of a long serial pass).
  static void Advance(const std::function<void(double)>& advanced, std::size_t i, std::size_t n) {
    if (advanced && i % 4096 == 4095) advanced(double(i + 1) / double(n));
  }
  /// Flips non-Delaunay edges (guarded) until none is left or the flip budget is spent: all
  /// edges are tested in parallel, then a work list is processed serially; each flip queues the
  /// four edges around it.
  static std::size_t DelaunayFlips(Ops& ops, int threads, double maxFlipsPerVertex);
  /// Vertices on the input's flat triangles enclose less volume than the input where the
  /// surface is convex (longer chords cut more off). Each closed component is offset along its
  /// (area-weighted) vertex normals by delta = (V_input - V) / A, twice (the second pass removes
  /// the curvature term), through the verified batch move. Returns the largest |delta|.
  static double RestoreVolume(Ops& ops, const ReferenceSurface<MeshType>& reference, double maxOffset,
                              int threads);
};

// ------------------------------------------------------------------------------------------------
// Implementation
// ------------------------------------------------------------------------------------------------

template <class MeshType>
void CvtInitialization<MeshType>::CornerPiece(const Point& p0, const Point& p1, const Point& p2, double& area,
                                              Point& weighted) {
  std::array<Point, 8> poly{}, clipped{};
  int n = 3;
  poly[0] = p0;
  poly[1] = p1;
  poly[2] = p2;
  for (const Point* q : {&p1, &p2}) {
    const Point dir = *q - p0;
    const Point mid = (p0 + *q) * 0.5;
    int m = 0;
    for (int i = 0; i < n; ++i) {
      const Point& a = poly[i];
      const Point& b = poly[(i + 1) % n];
      const double da = (a - mid) * dir, db = (b - mid) * dir;
      if (da <= 0) clipped[m++] = a;
      if ((da < 0 && db > 0) || (da > 0 && db < 0)) clipped[m++] = a + (b - a) * (da / (da - db));
    }
    n = m;
    std::copy(clipped.begin(), clipped.begin() + n, poly.begin());
  }
  area = 0;
  weighted = Point(0, 0, 0);
  for (int i = 1; i + 1 < n; ++i) {
    const double twice = ((poly[i] - poly[0]) ^ (poly[i + 1] - poly[0])).Norm();
    area += twice;
    weighted += (poly[0] + poly[i] + poly[i + 1]) * (twice / 3.0);
  }
}

template <class MeshType>
void CvtInitialization<MeshType>::FacePieces(const std::array<Point, 3>& p, std::array<double, 3>& area,
                                             std::array<Point, 3>& weighted) {
  const Point e01 = p[1] - p[0], e02 = p[2] - p[0], e12 = p[2] - p[1];
  const Point n = e01 ^ e02;
  const double n2 = n.SquaredNorm();
  if (e01 * e02 >= 0 && e01 * e12 <= 0 && e02 * e12 >= 0 && n2 > 0) {
    // The circumcentre c splits the triangle into six right triangles, mirror images in pairs
    // across each side's perpendicular bisector: (p_k, m_k,k+1, c) and (p_k+1, c, m_k,k+1) have
    // the same (doubled) area s[k]. Corner k's piece is (p_k, m_k,k+1, c) + (p_k, c, m_k-1,k).
    const Point c = p[0] + ((e02 ^ n) * e01.SquaredNorm() + (n ^ e01) * e02.SquaredNorm()) / (2.0 * n2);
    const std::array<Point, 3> mid{(p[0] + p[1]) * 0.5, (p[1] + p[2]) * 0.5, (p[2] + p[0]) * 0.5};
    const double inv = 1.0 / std::sqrt(n2);
    std::array<double, 3> s{};
    for (int k = 0; k < 3; ++k) s[k] = std::max(0.0, ((mid[k] - p[k]) ^ (c - p[k])) * n * inv);
    for (int k = 0; k < 3; ++k) {
      const int prev = (k + 2) % 3;
      area[k] = s[k] + s[prev];
      weighted[k] = (p[k] + mid[k] + c) * (s[k] / 3.0) + (p[k] + c + mid[prev]) * (s[prev] / 3.0);
    }
    return;
  }
  for (int k = 0; k < 3; ++k) CornerPiece(p[k], p[(k + 1) % 3], p[(k + 2) % 3], area[k], weighted[k]);
}

template <class MeshType>
void CvtInitialization<MeshType>::CollectEdges(const MeshType& m, double threshold2, bool longer, double cell,
                                               std::vector<EdgeCandidate>& out) {
  out.clear();
  for (const auto& f : m.face) {
    if (f.IsD()) continue;
    for (int e = 0; e < 3; ++e) {
      const FaceType* g = f.cFFp(e);
      if (g != &f && g < &f) continue; // each interior edge once
      const double l2 = (Ops::ToPoint(f.cV(e)->cP()) - Ops::ToPoint(f.cV((e + 1) % 3)->cP())).SquaredNorm();
      if (longer ? l2 > threshold2 : l2 < threshold2) {
        std::uint32_t a = std::uint32_t(vcg::tri::Index(m, f.cV(e)));
        std::uint32_t b = std::uint32_t(vcg::tri::Index(m, f.cV((e + 1) % 3)));
        if (b < a) std::swap(a, b);
        out.push_back({l2, a, b, 0});
      }
    }
  }
  if (cell > 0 && !out.empty()) {
    auto spread = [](std::uint64_t x) { // 21 bits -> every third bit
      x &= 0x1fffff;
      x = (x | x << 32) & 0x1f00000000ffffULL;
      x = (x | x << 16) & 0x1f0000ff0000ffULL;
      x = (x | x << 8) & 0x100f00f00f00f00fULL;
      x = (x | x << 4) & 0x10c30c30c30c30c3ULL;
      x = (x | x << 2) & 0x1249249249249249ULL;
      return x;
    };
    vcg::Box3d box;
    for (const auto& v : m.vert)
      if (!v.IsD()) box.Add(Ops::ToPoint(v.cP()));
    for (EdgeCandidate& e : out) {
      const Point mid = (Ops::ToPoint(m.vert[e.a].cP()) + Ops::ToPoint(m.vert[e.b].cP())) * 0.5;
      for (int k = 0; k < 3; ++k)
        e.key |= spread(std::uint64_t(std::clamp((mid[k] - box.min[k]) / cell, 0.0, double(0x1fffff)))) << k;
    }
    std::sort(out.begin(), out.end(), [](const EdgeCandidate& x, const EdgeCandidate& y) {
      return std::tie(x.key, x.a, x.b) < std::tie(y.key, y.a, y.b);
    });
    return;
  }
  std::sort(out.begin(), out.end(), [longer](const EdgeCandidate& x, const EdgeCandidate& y) {
    if (x.length2 != y.length2) return longer ? x.length2 > y.length2 : x.length2 < y.length2;
    return std::tie(x.a, x.b) < std::tie(y.a, y.b);
  });
}

template <class MeshType>
std::size_t CvtInitialization<MeshType>::SplitPass(Ops& ops, double threshold, std::size_t limit,
                                                   std::vector<EdgeCandidate>& edges,
                                                   const std::function<void(double)>& advanced) {
  MeshType& m = ops.Mesh();
  const bool all = limit == std::numeric_limits<std::size_t>::max();
  CollectEdges(m, threshold * threshold, true, all ? 2.0 * ops.TargetEdgeLength() : 0.0, edges);
  std::size_t done = 0;
  for (std::size_t i = 0; i < edges.size(); ++i) {
    const EdgeCandidate& e = edges[i];
    if (done >= limit) break;
    Advance(advanced, i, edges.size());
    FacePointer f = nullptr;
    int z = 0;
    // Indices stay valid while vertices are added; pointers are fetched afresh every time.
    if (!ops.FindEdge(&m.vert[e.a], &m.vert[e.b], f, z)) continue;
    const double l2 = (Ops::ToPoint(f->V(z)->cP()) - Ops::ToPoint(f->V((z + 1) % 3)->cP())).SquaredNorm();
    if (!(l2 > threshold * threshold)) continue;
    if (ops.SplitEdge(f, z) != nullptr) ++done;
  }
  return done;
}

template <class MeshType>
std::size_t CvtInitialization<MeshType>::CollapsePass(Ops& ops, double threshold, double maxNewEdge,
                                                      std::size_t limit, std::vector<EdgeCandidate>& edges,
                                                      const std::function<void(double)>& advanced) {
  MeshType& m = ops.Mesh();
  const bool all = limit == std::numeric_limits<std::size_t>::max();
  CollectEdges(m, threshold * threshold, false, all ? 2.0 * ops.TargetEdgeLength() : 0.0, edges);
  std::size_t done = 0;
  for (std::size_t i = 0; i < edges.size(); ++i) {
    const EdgeCandidate& e = edges[i];
    if (done >= limit) break;
    Advance(advanced, i, edges.size());
    if (m.vert[e.a].IsD() || m.vert[e.b].IsD()) continue;
    FacePointer f = nullptr;
    int z = 0;
    if (!ops.FindEdge(&m.vert[e.a], &m.vert[e.b], f, z)) continue;
    const double l2 = (Ops::ToPoint(f->V(z)->cP()) - Ops::ToPoint(f->V((z + 1) % 3)->cP())).SquaredNorm();
    if (!(l2 < threshold * threshold)) continue;
    if (ops.CollapseEdge(f, z, maxNewEdge)) ++done;
  }
  return done;
}

template <class MeshType>
std::size_t CvtInitialization<MeshType>::DelaunayFlips(Ops& ops, int threads, double maxFlipsPerVertex) {
  MeshType& m = ops.Mesh();
  std::vector<std::uint8_t> bad(m.face.size(), 0);
  ParallelFor(m.face.size(), threads, [&](std::size_t begin, std::size_t end, int) {
    for (std::size_t i = begin; i < end; ++i) {
      const FaceType& f = m.face[i];
      if (f.IsD()) continue;
      for (int e = 0; e < 3; ++e) {
        const FaceType* g = f.cFFp(e);
        if (g != &f && &f < g && !ops.IsDelaunay(f, e)) bad[i] |= std::uint8_t(1u << e);
      }
    }
  });
  std::vector<std::pair<std::uint32_t, std::uint32_t>> queue; // edges as vertex index pairs
  for (std::size_t i = 0; i < m.face.size(); ++i)
    for (int e = 0; e < 3; ++e)
      if (bad[i] & (1u << e))
        queue.emplace_back(std::uint32_t(vcg::tri::Index(m, m.face[i].cV(e))),
                           std::uint32_t(vcg::tri::Index(m, m.face[i].cV((e + 1) % 3))));
  const std::size_t budget = std::size_t(maxFlipsPerVertex * double(m.vn)) + 16;
  std::size_t flips = 0;
  for (std::size_t head = 0; head < queue.size() && flips < budget; ++head) {
    const auto [a, b] = queue[head];
    FacePointer f = nullptr;
    int z = 0;
    if (!ops.FindEdge(&m.vert[a], &m.vert[b], f, z) || ops.IsDelaunay(*f, z)) continue;
    // The quad around the edge, before the flip: its four sides may stop being Delaunay.
    FacePointer g = f->FFp(z);
    const std::uint32_t c = std::uint32_t(vcg::tri::Index(m, f->V((z + 2) % 3)));
    const std::uint32_t d = std::uint32_t(vcg::tri::Index(m, g->V((f->FFi(z) + 2) % 3)));
    if (!ops.FlipEdge(f, z)) continue;
    ++flips;
    for (const auto& side :
         {std::make_pair(a, c), std::make_pair(c, b), std::make_pair(b, d), std::make_pair(d, a)})
      queue.push_back(side);
  }
  return flips;
}

template <class MeshType>
double CvtInitialization<MeshType>::RestoreVolume(Ops& ops, const ReferenceSurface<MeshType>& reference,
                                                  double maxOffset, int threads) {
  MeshType& m = ops.Mesh();
  ops.VerifyPendingMoves(threads);
  // Components of the working mesh through FF, each with the reference component it lies on.
  std::vector<int> component(m.face.size(), -1);
  std::vector<int> refComponent;
  std::vector<bool> closed;
  std::vector<int> stack;
  for (std::size_t f0 = 0; f0 < m.face.size(); ++f0) {
    if (m.face[f0].IsD() || component[f0] >= 0) continue;
    const int c = int(refComponent.size());
    refComponent.push_back(reference.Component(ops.Footpoint(*m.face[f0].cV(0))));
    closed.push_back(true);
    component[f0] = c;
    stack.assign(1, int(f0));
    while (!stack.empty()) {
      FaceType& f = m.face[stack.back()];
      stack.pop_back();
      for (int e = 0; e < 3; ++e) {
        FaceType* g = f.FFp(e);
        if (g == &f) {
          closed[c] = false;
          continue;
        }
        const std::size_t gi = vcg::tri::Index(m, g);
        if (component[gi] < 0) {
          component[gi] = c;
          stack.push_back(int(gi));
        }
      }
    }
  }
  const std::size_t nc = refComponent.size();
  const Point origin = reference.BoundingBox().Center();
  double largest = 0;
  std::vector<double> volume(nc), area(nc), delta(nc), offset(nc, 0.0);
  std::vector<Point> normal(m.vert.size());
  std::vector<int> vertexComponent(m.vert.size(), -1);
  for (int pass = 0; pass < 2; ++pass) {
    std::fill(volume.begin(), volume.end(), 0.0);
    std::fill(area.begin(), area.end(), 0.0);
    std::fill(normal.begin(), normal.end(), Point(0, 0, 0));
    for (std::size_t fi = 0; fi < m.face.size(); ++fi) {
      const FaceType& f = m.face[fi];
      if (f.IsD()) continue;
      const Point p0 = Ops::ToPoint(f.cV(0)->cP()), p1 = Ops::ToPoint(f.cV(1)->cP()),
                  p2 = Ops::ToPoint(f.cV(2)->cP());
      const Point cross = (p1 - p0) ^ (p2 - p0);
      const int c = component[fi];
      volume[c] += ((p0 - origin) * ((p1 - origin) ^ (p2 - origin))) / 6.0;
      area[c] += 0.5 * cross.Norm();
      for (int k = 0; k < 3; ++k) {
        const std::size_t vi = vcg::tri::Index(m, f.cV(k));
        normal[vi] += cross;
        vertexComponent[vi] = c;
      }
    }
    for (std::size_t c = 0; c < nc; ++c) {
      const int rc = refComponent[c];
      const bool usable = closed[c] && rc >= 0 && reference.ComponentClosed(rc) && area[c] > 0;
      const double wanted = usable ? (reference.ComponentVolume(rc) - volume[c]) / area[c] : 0.0;
      // The total offset of a component stays within maxOffset.
      const double total = std::clamp(offset[c] + wanted, -maxOffset, maxOffset);
      delta[c] = total - offset[c];
      offset[c] = total;
      largest = std::max(largest, std::fabs(total));
    }
    for (std::size_t vi = 0; vi < m.vert.size(); ++vi) {
      VertexType& v = m.vert[vi];
      if (v.IsD() || v.VFp() == nullptr || vertexComponent[vi] < 0 || delta[vertexComponent[vi]] == 0)
        continue;
      const double len = normal[vi].Norm();
      if (!(len > 0)) continue;
      const Point p = Ops::ToPoint(v.cP());
      ops.MoveVertexUnchecked(&v, p + normal[vi] * (delta[vertexComponent[vi]] / len), ops.Footpoint(v));
    }
    ops.VerifyPendingMoves(threads);
  }
  return largest;
}

template <class MeshType>
std::string CvtInitialization<MeshType>::CheckInput(MeshType& m, const Params& params) {
  const InputCheck check = CheckTriangleMeshInput(m);
  if (!check.ok) return check.message;
  if (!vcg::tri::HasFFAdjacency(m) || !vcg::tri::HasVFAdjacency(m))
    return "face-face and vertex-face adjacency must be enabled";
  if (params.iterations < 0) return "negative iteration count";
  std::string error;
  if (!Ops::PrepareTopology(m, &error)) return error;
  return {};
}

template <class MeshType>
double CvtInitialization<MeshType>::TargetEdgeLength(const MeshType& m,
                                                     const ReferenceSurface<MeshType>& reference,
                                                     const Params& params) {
  double L = params.targetEdgeLength > 0 ? params.targetEdgeLength : MeanEdgeLength(m);
  if (params.targetVertexCount > 0)
    L = std::sqrt(2.0 * reference.Area() / (std::sqrt(3.0) * double(params.targetVertexCount)));
  return L;
}

template <class MeshType>
void CvtInitialization<MeshType>::Sample(Ops& ops, const Params& params, double L, int threads,
                                         std::vector<EdgeCandidate>& edges, vcg::CallBackPos* cb) {
  const std::size_t unlimited = std::numeric_limits<std::size_t>::max();
  const double splitLength = params.splitFactor * L, collapseLength = params.collapseFactor * L;
  const int passes = std::max(1, params.samplingPasses);
  // Shares of the stage: the setup before the first pass (reference surface, guards) 2 %, the
  // first pass, which does most of the edits, 12 %, the other passes 6 % together; within a pass
  // the splits half, the collapses a third, the flips the rest.
  auto step = [&](int pass, int part, double within, const char* what) {
    const double begin = pass == 0 ? 0.02 : 0.14 + 0.06 * (pass - 1) / std::max(1, passes - 1);
    const double end = pass == 0 ? 0.14 : 0.14 + 0.06 * pass / std::max(1, passes - 1);
    const double partBegin[3] = {0.0, 0.5, 5.0 / 6.0}, partEnd[3] = {0.5, 5.0 / 6.0, 1.0};
    const double inPass = partBegin[part] + (partEnd[part] - partBegin[part]) * within;
    const double fraction = begin + (end - begin) * inPass;
    Progress(cb, fraction, "CVT: sampling");
    if (params.progress)
      params.progress(fraction, "sampling pass " + std::to_string(pass + 1) + "/" + std::to_string(passes) +
                                    ": " + what);
  };
  for (int pass = 0; pass < params.samplingPasses; ++pass) {
    step(pass, 0, 0.0, "splits");
    std::size_t changed = SplitPass(ops, splitLength, unlimited, edges,
                                    [&](double within) { step(pass, 0, within, "splits"); });
    step(pass, 1, 0.0, "collapses");
    changed += CollapsePass(ops, collapseLength, splitLength, unlimited, edges,
                            [&](double within) { step(pass, 1, within, "collapses"); });
    step(pass, 2, 0.0, "flips");
    if (params.delaunayFlips) DelaunayFlips(ops, threads, params.maxFlipsPerVertex);
    if (changed == 0) break;
  }
}

template <class MeshType>
void CvtInitialization<MeshType>::MatchVertexCount(Ops& ops, const MeshType& m, const Params& params,
                                                   double L, double wanted,
                                                   std::vector<EdgeCandidate>& edges) {
  const double splitLength = params.splitFactor * L;
  const double have = double(LiveVertices(m));
  const double tolerance = std::max(1.0, params.vertexCountTolerance * wanted);
  if (std::fabs(have - wanted) <= tolerance) return;
  if (have < wanted)
    SplitPass(ops, L, std::size_t(wanted - have), edges);
  else
    CollapsePass(ops, L, splitLength, std::size_t(have - wanted), edges);
}

template <class MeshType>
void CvtInitialization<MeshType>::CellCentroids(const MeshType& m, Ops& ops, int threads, Lloyd& s) {
  // Cell centroids, accumulated face by face: each thread owns a range of vertices and sums,
  // in face order, the faces with a corner it owns, so each vertex's sum runs in face order
  // whatever the thread count. The owners' face lists (with the corners, compact) are made
  // again only when the connectivity changed (splits, collapses and flips), not per iteration.
  const std::size_t nv = m.vert.size();
  s.position.resize(nv);
  ParallelFor(nv, threads, [&](std::size_t begin, std::size_t end, int) {
    for (std::size_t i = begin; i < end; ++i) s.position[i] = Ops::ToPoint(m.vert[i].cP());
  });
  const std::size_t owners = std::size_t(threads);
  const std::size_t topologyNow = ops.Stats().splits + ops.Stats().collapses + ops.Stats().flips;
  if (s.ownerFaces.empty() || topologyNow != s.ownerFacesTopology || s.ownerFacesVertices != nv) {
    s.ownerFaces.resize(owners);
    ParallelFor(
        owners, threads,
        [&](std::size_t begin, std::size_t end, int) {
          for (std::size_t owner = begin; owner < end; ++owner) {
            const std::uint32_t lo = std::uint32_t(nv * owner / owners),
                                hi = std::uint32_t(nv * (owner + 1) / owners);
            std::vector<std::array<std::uint32_t, 3>>& list = s.ownerFaces[owner];
            list.clear();
            for (const FaceType& f : m.face) {
              if (f.IsD()) continue;
              const std::array<std::uint32_t, 3> vi{std::uint32_t(vcg::tri::Index(m, f.cV(0))),
                                                    std::uint32_t(vcg::tri::Index(m, f.cV(1))),
                                                    std::uint32_t(vcg::tri::Index(m, f.cV(2)))};
              if ((vi[0] >= lo && vi[0] < hi) || (vi[1] >= lo && vi[1] < hi) || (vi[2] >= lo && vi[2] < hi))
                list.push_back(vi);
            }
          }
        },
        1);
    s.ownerFacesTopology = topologyNow;
    s.ownerFacesVertices = nv;
  }
  s.cellArea.assign(nv, 0.0);
  s.cellWeighted.assign(nv, Point(0, 0, 0));
  ParallelFor(
      owners, threads,
      [&](std::size_t begin, std::size_t end, int) {
        for (std::size_t owner = begin; owner < end; ++owner) {
          const std::uint32_t lo = std::uint32_t(nv * owner / owners),
                              hi = std::uint32_t(nv * (owner + 1) / owners);
          for (const std::array<std::uint32_t, 3>& vi : s.ownerFaces[owner]) {
            std::array<double, 3> area;
            std::array<Point, 3> weighted;
            FacePieces({s.position[vi[0]], s.position[vi[1]], s.position[vi[2]]}, area, weighted);
            for (int k = 0; k < 3; ++k) {
              if (vi[k] < lo || vi[k] >= hi) continue;
              s.cellArea[vi[k]] += area[k];
              s.cellWeighted[vi[k]] += weighted[k];
            }
          }
        }
      },
      1);
}

template <class MeshType>
void CvtInitialization<MeshType>::MoveTargets(const MeshType& m, Ops& ops,
                                              const ReferenceSurface<MeshType>& reference, int threads,
                                              double minMove2, bool fullProjection, Lloyd& s) {
  const std::size_t nv = m.vert.size();
  s.movable.clear();
  for (std::size_t i = 0; i < nv; ++i) {
    const VertexType& v = m.vert[i];
    if (v.IsD() || v.cVFp() == nullptr || !(s.cellArea[i] > 0) || ops.IsLocked(v) || ops.IsBoundaryVertex(v))
      continue;
    s.movable.push_back(std::uint32_t(i));
  }
  s.footRecord.resize(nv);
  s.target.resize(s.movable.size());
  s.targetFoot.resize(s.movable.size());
  s.moveLength.resize(s.movable.size());
  ParallelFor(s.movable.size(), threads, [&](std::size_t begin, std::size_t end, int t) {
    for (std::size_t i = begin; i < end; ++i) {
      const std::uint32_t vi = s.movable[i];
      const Point c = s.cellWeighted[vi] / s.cellArea[vi];
      // Converged (the centroid is within minMove of the site along the input's tangent
      // plane; its offset along the normal is the cell's curvature): no projection, no move.
      const int foot = ops.Footpoint(m.vert[vi]);
      FootRecord& footCopy = s.footRecord[vi];
      if (foot >= 0 && footCopy.face != foot) {
        footCopy.face = foot;
        footCopy.record = reference.Record(foot);
      }
      Point shift = c - s.position[vi];
      if (foot >= 0) shift -= footCopy.record.n * (shift * footCopy.record.n);
      if (!(shift.SquaredNorm() > minMove2)) {
        s.target[i] = s.position[vi];
        s.targetFoot[i] = -1;
        s.moveLength[i] = 0.0;
        continue;
      }
      SurfaceProjection proj;
      if (!fullProjection && foot >= 0)
        proj = ReferenceSurface<MeshType>::ProjectInsideFace(c, footCopy.record, foot);
      if (!proj.ok()) proj = reference.Project(c, foot, s.scratch[t], /*lift=*/fullProjection);
      s.target[i] = proj.point;
      s.targetFoot[i] = proj.face;
      s.moveLength[i] = proj.ok() ? (proj.point - s.position[vi]).SquaredNorm() : 0.0;
    }
  });
}

template <class MeshType>
double CvtInitialization<MeshType>::ApplyMoves(Ops& ops, MeshType& m, double minMove2, const Lloyd& s,
                                               std::size_t& applied, std::size_t& rejected) {
  double moveSum = 0;
  for (std::size_t i = 0; i < s.movable.size(); ++i) {
    if (!(s.moveLength[i] > minMove2) || s.targetFoot[i] < 0) continue;
    moveSum += std::sqrt(s.moveLength[i]);
    if (ops.MoveVertexUnchecked(&m.vert[s.movable[i]], s.target[i], s.targetFoot[i]))
      ++applied;
    else
      ++rejected;
  }
  return moveSum;
}

template <class MeshType>
typename CvtInitialization<MeshType>::Result
CvtInitialization<MeshType>::Run(MeshType& m, const ReferenceSurface<MeshType>* external,
                                 const Params& params, vcg::CallBackPos* cb) {
  Result result;
  auto finish = [&](bool ok, const std::string& message) {
    result.ok = ok;
    result.message = message;
    return result;
  };

  // --- Preconditions (nothing is touched before they pass) ------------------------------------
  if (const std::string error = CheckInput(m, params); !error.empty())
    return finish(false, "CVT initialization refused: " + error);
  result.verticesIn = std::size_t(m.vn);
  result.facesIn = std::size_t(m.fn);

  std::unique_ptr<ReferenceSurface<MeshType>> own;
  const ReferenceSurface<MeshType>* reference = external;
  if (reference == nullptr) {
    own = std::make_unique<ReferenceSurface<MeshType>>();
    std::string error;
    if (!own->Build(m, params.reference, &error))
      return finish(false, "CVT initialization refused: " + error);
    reference = own.get();
  }

  const double L = TargetEdgeLength(m, *reference, params);
  if (!(L > 0) || !std::isfinite(L))
    return finish(false, "CVT initialization refused: no valid target edge length");
  result.targetEdgeLength = L;

  Ops ops(m, *reference, L, params.guards, params.threads);
  {
    std::string error;
    // Each vertex's own face is tried as its footpoint first (Init checks it by position), so a
    // reference built from m itself costs no closest-point search.
    if (!ops.Init(&error, true, true)) return finish(false, "CVT initialization refused: " + error);
  }

  // --- 1. Sampling ------------------------------------------------------------------------------
  const int threads = ResolveThreadCount(params.threads);
  std::vector<EdgeCandidate> edges;
  Sample(ops, params, L, threads, edges, cb);
  // Vertex count of a uniform CVT with edge L: each vertex owns a hexagon of area sqrt(3)/2 L^2.
  const double wanted = 2.0 * reference->Area() / (std::sqrt(3.0) * L * L);

  // --- 2. Lloyd iterations ----------------------------------------------------------------------
  Lloyd lloyd;
  lloyd.scratch.resize(std::size_t(threads));
  const double minMove2 = params.minMoveFactor * L * params.minMoveFactor * L;
  std::size_t applied = 0, rejected = 0;
  for (int it = 0; it < params.iterations; ++it) {
    // The iterations take 20-97 % of the stage, the volume restoration after them the rest.
    const double fraction = 0.2 + 0.77 * it / std::max(1, params.iterations);
    Progress(cb, fraction, "CVT: Lloyd relaxation");
    if (params.progress)
      params.progress(fraction,
                      "Lloyd iteration " + std::to_string(it + 1) + "/" + std::to_string(params.iterations));
    if (params.matchVertexCount && it < std::max(1, params.iterations / 3))
      MatchVertexCount(ops, m, params, L, wanted, edges);
    const bool fullProjection = it >= params.iterations - params.fullProjectionIterations;
    CellCentroids(m, ops, threads, lloyd);
    MoveTargets(m, ops, *reference, threads, minMove2, fullProjection, lloyd);

    // Converged sites (and failed projections) stay; the others move, verified every few
    // iterations (a failing vertex goes back to its last verified position).
    const double moveSum = ApplyMoves(ops, m, minMove2, lloyd, applied, rejected);
    result.lastMeanMove = lloyd.movable.empty() ? 0.0 : moveSum / double(lloyd.movable.size()) / L;
    const bool last = it + 1 == params.iterations;
    const bool verify = last || it < 2 || params.verifyEvery <= 1 || (it + 1) % params.verifyEvery == 0;
    if (verify) {
      const BatchMoveResult checked = ops.VerifyPendingMoves(threads);
      rejected += checked.rejected;
      ++result.verifications;
    }
    if (verify && params.delaunayFlips) DelaunayFlips(ops, threads, params.maxFlipsPerVertex);
    result.iterations = it + 1;
  }
  if (params.matchVertexCount && params.iterations == 0) MatchVertexCount(ops, m, params, L, wanted, edges);

  if (params.preserveVolume) {
    Progress(cb, 0.97, "CVT: restoring the volume");
    if (params.progress) params.progress(0.97, "restoring the volume");
    result.volumeOffset = RestoreVolume(ops, *reference, params.maxVolumeOffset * L, threads) / L;
  }

  const LocalOpsStats& stats = ops.Stats();
  result.splits = stats.splits;
  result.collapses = stats.collapses;
  result.flips = stats.flips;
  result.movesApplied = applied;
  result.movesRejected = rejected;
  result.refusedOperations = stats.Refused();
  result.operations = stats;
  ops.Finish();
  result.verticesOut = std::size_t(m.vn);
  result.facesOut = std::size_t(m.fn);
  Progress(cb, 1.0, "CVT: done");
  return finish(true, "CVT initialization: " + std::to_string(result.verticesIn) + " -> " +
                          std::to_string(result.verticesOut) + " vertices, L = " + std::to_string(L) + ", " +
                          std::to_string(result.iterations) + " Lloyd iterations");
}

} // namespace molremesh

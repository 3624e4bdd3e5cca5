// Region remeshing: the remeshing stages run on a selected set of faces only; every face and
// vertex outside the selection, and the selection's border, stay bit for bit as they were.
//
// RegionRemeshing<MeshType>::Do(m, params), params.faceMask selecting the region (per m.face):
//  1. checks: a compact, valid triangle mesh; a mask of m.face.size() entries that selects some
//     faces but not all (the whole mesh is the full pipeline's job);
//  2. the submesh: the region's faces plus a halo that is never edited: every outside face
//     sharing a vertex with the region (it completes the fans of the border vertices, so the
//     valence and fold checks see the whole star) and every outside face whose bounding box lies
//     within two target lengths of the region's (obstacles for the intersection test: another
//     sheet of the surface close by). Outside vertices whose halo faces form several fans get one
//     copy per fan, so the submesh is 2-manifold. Every vertex but the region's interior ones
//     (whose whole star is selected) is locked, so no edit moves, removes or joins them, and a
//     halo face (three locked corners) is never touched;
//  3. the stages of params.pipeline.stages that work on an open, partly locked mesh run on the
//     submesh, in pipeline order: RAR (iterations and repair; no volume restoration, which moves
//     whole components), valence, small, obtuse, smooth, polish. Clean, CVT and segmentation do
//     not apply to a region and are skipped. The reference surface is built from the whole
//     input, so the region stays on the surface around it. Then up to Params::settlingPasses
//     passes of the same stages without RAR while the region falls short of the bounds, each kept
//     only when it leaves fewer irregular interior vertices and bad faces off the border; then
//     up to Params::borderFlips flips of an edge from a locked vertex with thin faces in its wedge,
//     each settled by the stages and kept on the same terms (and no new fold or crossing);
//  4. stitching: the region's faces are removed from a copy of m with its interior vertices; the
//     submesh's faces that are not halo are appended, their locked corners welded to the vertices
//     they were copied from (same coordinates, checked), new vertices appended;
//  5. verification: no face of the new region intersects another face, the result is
//     edge-manifold and has as many border edges as the input (closed stays closed).
// On any refusal or failed check m is untouched and Result::message says why.
// Deterministic: same input, mask and seed give the same bytes at any thread count.
#pragma once

#include <vcg/complex/algorithms/clean.h>
#include <vcg/complex/append.h>
#include <vcg/complex/complex.h>

#include <vcg_ext/core/index.h>
#include <vcg_ext/core/input_check.h>
#include <vcg_ext/core/union_find.h>
#include <vcg_ext/geometry/mean_edge_length.h>
#include <vcg_ext/geometry/triangle_angles.h>
#include <vcg_ext/geometry/point.h>
#include <vcg_ext/pipeline/remesh_pipeline.h>
#include <vcg_ext/spatial/self_intersections.h>
#include <vcg_ext/topology/face_face_topology.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace molremesh {

template <class MeshType>
class RegionRemeshing {
public:
  using Pipeline = RemeshPipeline<MeshType>;
  using Rar = AdaptiveRemeshing<MeshType>;
  using Ops = LocalRemeshingOps<MeshType>;
  using Reference = ReferenceSurface<MeshType>;

  struct Params {
    /// The stages and their parameters, as for the full pipeline; only RAR, valence, small, obtuse,
    /// smooth and polish run (RAR's rar.rar part), targetEdgeLength 0 = the whole mesh's mean edge length.
    typename Pipeline::Params pipeline;
    std::vector<std::uint8_t> faceMask; ///< per m.face: nonzero = in the region
    double haloMargin = 2.0; ///< obstacle margin around the region's bounding box, in target lengths
    /// Extra passes of the local stages (all but RAR) while the region still has an irregular
    /// interior vertex or a face off its border outside the angle bounds; a pass is kept only when
    /// it leaves fewer of both. Near a locked border the stages block each other: the valence
    /// refill (max angle 120) fixes a valence that polish (max angle 90) may not, and the angle
    /// stages then settle the refill's new angles.
    int settlingPasses = 2;
    /// Flips tried at the border while a face off it stays out of bounds (when the obtuse and polish
    /// stages are in the list: they settle the flips). A locked vertex near such a face whose wedge
    /// inside the region holds thin faces gives one up: its edge into the region with the smallest
    /// angles beside it is flipped and the stages without RAR run again; the flip is kept only when
    /// it leaves fewer irregular interior vertices and bad faces off the border, no new fold and no
    /// new intersecting pair. Two faces of 30-33 degrees in a 63-degree wedge pin the free vertices
    /// beside them; one face of 63 degrees leaves them room.
    int borderFlips = 8;
  };

  struct Result {
    bool ok = false;
    std::string message;         ///< why it refused, or a one-line summary
    double targetEdgeLength = 0; ///< L used
    std::size_t regionFacesIn = 0, regionFacesOut = 0;
    std::size_t borderVertices = 0;          ///< region vertices with an outside face (kept)
    std::size_t haloFaces = 0;               ///< outside faces given to the stages as never-edited context
    std::size_t newRegionIntersections = 0;  ///< pairs with a new face (0 when ok)
    std::vector<std::string> stageSummaries; ///< "name: summary" per stage run
    int settlingPassesKept = 0;              ///< extra passes of the local stages that were kept
    int borderFlipsKept = 0;                 ///< border-wedge flips that were kept
    std::vector<std::uint8_t> faceMask;      ///< per face of the result: the new region (appended last)
    double seconds = 0;
  };

  /// Remeshes the faces of m selected by params.faceMask. m needs FF and VF adjacency enabled
  /// (they are recomputed). On failure m is unchanged.
  static Result Do(MeshType& m, const Params& params) {
    const auto start = std::chrono::steady_clock::now();
    Result r;
    if (std::string why = Check(m, params, r); !why.empty()) return Fail(r, why);
    UpdateAdjacency(m);
    const double L =
        params.pipeline.targetEdgeLength > 0 ? params.pipeline.targetEdgeLength : MeanEdgeLength(m);
    if (!(L > 0) || !std::isfinite(L)) return Fail(r, "no valid target edge length");
    r.targetEdgeLength = L;
    Reference reference;
    typename Reference::Params referenceParams = params.pipeline.reference;
    referenceParams.phongAlpha = 0; // the region must meet the untouched faces on the input itself
    std::string error;
    if (!reference.Build(m, referenceParams, &error)) return Fail(r, "reference surface: " + error);

    Submesh sub;
    BuildSubmesh(m, params, L, sub, r);
    if (std::string why = RunStages(sub, reference, params, L, r); !why.empty()) return Fail(r, why);

    MeshType out;
    if (std::string why = Stitch(m, params.faceMask, sub, out, r); !why.empty()) return Fail(r, why);
    if (std::string why = Verify(m, out, r); !why.empty()) return Fail(r, why);
    vcg::tri::Append<MeshType, MeshType>::MeshCopy(m, out);
    UpdateAdjacency(m);
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    r.ok = true;
    r.message = "region remeshed: " + std::to_string(r.regionFacesIn) + " -> " +
                std::to_string(r.regionFacesOut) + " faces, " + std::to_string(r.borderVertices) +
                " border vertices kept";
    return r;
  }

private:
  /// The region with its halo, as a mesh of its own. The locked vertices are known by their
  /// positions (no edit moves them, and a new vertex never lands exactly on one: that would be a
  /// degenerate face), the halo faces by their corners; element flags would not do, as an edit
  /// may copy them from the element it splits.
  using Key = std::array<double, 3>;
  struct Submesh {
    MeshType mesh;
    std::map<Key, std::size_t> lockedOrigin;        ///< locked vertex position -> its vertex in m
    std::set<std::array<std::size_t, 3>> haloFaces; ///< sorted corners (in m) of the halo faces
  };
  static Key KeyOf(const typename MeshType::VertexType& v) {
    return {double(v.cP()[0]), double(v.cP()[1]), double(v.cP()[2])};
  }
  /// The vertex of m that submesh vertex v is, when it is a locked one; -1 otherwise.
  static std::int64_t OriginOf(const Submesh& sub, const typename MeshType::VertexType& v) {
    const auto it = sub.lockedOrigin.find(KeyOf(v));
    return it == sub.lockedOrigin.end() ? -1 : std::int64_t(it->second);
  }
  static bool IsHaloFace(const Submesh& sub, const typename MeshType::FaceType& f) {
    std::array<std::size_t, 3> c{};
    for (int k = 0; k < 3; ++k) {
      const std::int64_t o = OriginOf(sub, *f.cV(k));
      if (o < 0) return false;
      c[std::size_t(k)] = std::size_t(o);
    }
    std::sort(c.begin(), c.end());
    return sub.haloFaces.count(c) > 0;
  }

  static Result Fail(Result& r, const std::string& why) {
    r.ok = false;
    r.message = "region remeshing refused: " + why + " (the mesh is unchanged)";
    return r;
  }

  static std::string Check(const MeshType& m, const Params& params, Result& r) {
    const InputCheck check = CheckTriangleMeshInput(m);
    if (!check.ok) return check.message;
    if (m.fn != int(m.face.size()) || m.vn != int(m.vert.size())) return "the mesh has deleted elements";
    if (params.faceMask.size() != m.face.size())
      return "the face mask has " + std::to_string(params.faceMask.size()) + " entries for " +
             std::to_string(m.face.size()) + " faces";
    r.regionFacesIn = std::size_t(
        std::count_if(params.faceMask.begin(), params.faceMask.end(), [](std::uint8_t b) { return b != 0; }));
    if (r.regionFacesIn == 0) return "no face selected";
    if (r.regionFacesIn == m.face.size()) return "every face is selected: run the full pipeline instead";
    return {};
  }

  /// Which faces of m go into the submesh: the region, then the halo, in face order.
  static std::vector<std::size_t> SubmeshFaces(const MeshType& m, const Params& params, double L,
                                               std::vector<std::uint8_t>& isHalo) {
    std::vector<std::uint8_t> regionVertex(m.vert.size(), 0);
    vcg::Box3d box;
    for (std::size_t fi = 0; fi < m.face.size(); ++fi)
      if (params.faceMask[fi])
        for (int k = 0; k < 3; ++k) {
          regionVertex[vcg::tri::Index(m, m.face[fi].cV(k))] = 1;
          box.Add(vcg::Point3d::Construct(m.face[fi].cV(k)->cP()));
        }
    box.Offset(params.haloMargin * L);
    std::vector<std::size_t> faces;
    isHalo.clear();
    for (std::size_t fi = 0; fi < m.face.size(); ++fi) {
      const auto& f = m.face[fi];
      bool take = params.faceMask[fi] != 0, halo = !take;
      if (halo) {
        vcg::Box3d fb;
        for (int k = 0; k < 3; ++k) {
          take = take || regionVertex[vcg::tri::Index(m, f.cV(k))];
          fb.Add(vcg::Point3d::Construct(f.cV(k)->cP()));
        }
        take = take || BoxesTouch(fb, box);
      }
      if (!take) continue;
      faces.push_back(fi);
      isHalo.push_back(halo ? 1 : 0);
    }
    return faces;
  }

  /// Builds sub: corners of one outside vertex are one submesh vertex per fan (joined across the
  /// submesh's edges), a region vertex is one submesh vertex.
  static void BuildSubmesh(const MeshType& m, const Params& params, double L, Submesh& sub, Result& r) {
    std::vector<std::uint8_t> isHalo;
    const std::vector<std::size_t> faces = SubmeshFaces(m, params, L, isHalo);
    std::vector<std::uint8_t> inRegionStar(m.vert.size(), 0), outsideStar(m.vert.size(), 0);
    for (std::size_t fi = 0; fi < m.face.size(); ++fi)
      for (int k = 0; k < 3; ++k)
        (params.faceMask[fi] ? inRegionStar : outsideStar)[vcg::tri::Index(m, m.face[fi].cV(k))] = 1;
    auto vertexOf = [&](std::size_t i, int k) {
      return std::size_t(vcg::tri::Index(m, m.face[faces[i]].cV(k)));
    };
    UnionFind corners(3 * faces.size());
    std::map<std::pair<std::size_t, std::size_t>, std::size_t> firstCornerOfVertex; // region vertices
    std::map<std::pair<std::size_t, std::size_t>, std::pair<std::size_t, int>> edgeSide;
    for (std::size_t i = 0; i < faces.size(); ++i)
      for (int k = 0; k < 3; ++k) {
        const std::size_t a = vertexOf(i, k), b = vertexOf(i, (k + 1) % 3);
        if (inRegionStar[a]) {
          auto [it, added] = firstCornerOfVertex.emplace(std::make_pair(a, a), 3 * i + std::size_t(k));
          if (!added) corners.Unite(std::uint32_t(it->second), std::uint32_t(3 * i + std::size_t(k)));
        }
        auto [it, added] = edgeSide.emplace(std::minmax(a, b), std::make_pair(i, k));
        if (added) continue;
        // The same edge in two submesh faces: join the corners of its end points.
        const auto [j, l] = it->second;
        for (const std::size_t v : {a, b})
          for (int x = 0; x < 3; ++x)
            for (int y = 0; y < 3; ++y)
              if (vertexOf(i, x) == v && vertexOf(j, y) == v)
                corners.Unite(std::uint32_t(3 * i + std::size_t(x)), std::uint32_t(3 * j + std::size_t(y)));
        (void)l;
      }
    MeshType& s = sub.mesh;
    std::vector<std::int64_t> vertexOfClass(3 * faces.size(), -1);
    std::vector<std::size_t> originOfVertex;
    for (std::size_t c = 0; c < 3 * faces.size(); ++c) {
      const std::uint32_t root = corners.Find(std::uint32_t(c));
      if (vertexOfClass[root] >= 0) continue;
      vertexOfClass[root] = std::int64_t(originOfVertex.size());
      originOfVertex.push_back(vertexOf(c / 3, int(c % 3)));
    }
    auto vi = vcg::tri::Allocator<MeshType>::AddVertices(s, originOfVertex.size());
    (void)vi;
    for (std::size_t v = 0; v < originOfVertex.size(); ++v) {
      const std::size_t o = originOfVertex[v];
      s.vert[v].P() = m.vert[o].cP();
      s.vert[v].ClearFlags();
      if (outsideStar[o]) s.vert[v].SetS(); // border or halo: locked
    }
    vcg::tri::Allocator<MeshType>::AddFaces(s, faces.size());
    for (std::size_t i = 0; i < faces.size(); ++i) {
      s.face[i].ClearFlags();
      for (int k = 0; k < 3; ++k)
        s.face[i].V(k) =
            &s.vert[std::size_t(vertexOfClass[corners.Find(std::uint32_t(3 * i + std::size_t(k)))])];
      if (isHalo[i]) s.face[i].SetS(), ++r.haloFaces;
    }
    UpdateAdjacency(s);
    // A region vertex on a border of the input is locked too (only a border collapse could remove it).
    for (auto& f : s.face)
      for (int k = 0; k < 3; ++k)
        if (vcg::face::IsBorder(f, k)) f.V(k)->SetS(), f.V((k + 1) % 3)->SetS();
    for (std::size_t i = 0; i < faces.size(); ++i)
      if (isHalo[i]) {
        std::array<std::size_t, 3> c{vertexOf(i, 0), vertexOf(i, 1), vertexOf(i, 2)};
        std::sort(c.begin(), c.end());
        sub.haloFaces.insert(c);
      }
    for (std::size_t v = 0; v < s.vert.size(); ++v) {
      if (s.vert[v].IsS()) sub.lockedOrigin.emplace(KeyOf(s.vert[v]), originOfVertex[v]);
      if (inRegionStar[originOfVertex[v]] && outsideStar[originOfVertex[v]]) ++r.borderVertices;
    }
  }

  static std::vector<std::uint8_t> LockedVertices(const Submesh& sub) {
    const MeshType& s = sub.mesh;
    std::vector<std::uint8_t> locked(s.vert.size(), 0);
    for (std::size_t v = 0; v < s.vert.size(); ++v)
      locked[v] = !s.vert[v].IsD() && OriginOf(sub, s.vert[v]) >= 0;
    return locked;
  }

  static bool Runs(const Params& params, PipelineStage stage) {
    const auto& stages = params.pipeline.stages;
    return std::find(stages.begin(), stages.end(), stage) != stages.end();
  }

  /// RAR's iterations and repair on s with its locked vertices kept (no Finalize: it unlocks
  /// everything and offsets whole components).
  static std::string RunRar(Submesh& sub, const Reference& reference, const Params& params, double L,
                            std::string& summary) {
    auto rarParams = params.pipeline.rar.rar;
    if (rarParams.targetEdgeLength <= 0) rarParams.targetEdgeLength = L;
    const int threads = params.pipeline.threads;
    MeshType& s = sub.mesh;
    Ops ops(s, reference, rarParams.targetEdgeLength, rarParams.guards, threads);
    std::string error;
    if (!ops.Init(&error)) return "rar: " + error;
    LockVertices(ops, LockedVertices(sub));
    std::vector<double> sizing = Rar::ComputeSizing(s, rarParams.targetEdgeLength, rarParams, threads);
    const AdaptiveRemeshingStats stats = Rar::Remesh(ops, sizing, rarParams, rarParams.iterations, threads);
    ops.Finish();
    UpdateAdjacency(s);
    summary = std::to_string(stats.iterations) + " iterations";
    return {};
  }

  template <class Stage, class StageParams>
  static std::string RunLocal(Submesh& sub, const Reference& reference, StageParams p, const Params& params,
                              double L, std::string& summary) {
    if (p.targetEdgeLength <= 0) p.targetEdgeLength = L;
    p.threads = params.pipeline.threads;
    p.seed = params.pipeline.seed;
    p.lockedVertices = LockedVertices(sub);
    MeshType& s = sub.mesh;
    const auto result = Stage::Do(s, reference, p);
    if (!result.ok) return result.message.empty() ? std::string("failed") : result.message;
    vcg::tri::Allocator<MeshType>::CompactEveryVector(s);
    UpdateAdjacency(s);
    summary = result.message;
    return {};
  }

  /// An edge (b, x) from a locked vertex b into the region, to be flipped: face fi, edge z; by the
  /// smaller of the angles at b beside it.
  struct WedgeEdge {
    double angleDeg;
    std::size_t fi;
    int z;
    bool operator<(const WedgeEdge& o) const {
      return angleDeg < o.angleDeg || (angleDeg == o.angleDeg && fi < o.fi);
    }
  };

  static double AngleAt(const typename MeshType::FaceType& f, int k) {
    const Point a = PositionOf(f.cV(k)), b = PositionOf(f.cV((k + 1) % 3)), c = PositionOf(f.cV((k + 2) % 3));
    return vcg::math::ToDeg(vcg::Angle(b - a, c - a));
  }

  /// The edges (b, x), b locked and x free, both faces not halo, with b next to a corner of a bad
  /// face off the border; thinnest first, those with an angle at b below 40 degrees.
  static std::vector<WedgeEdge> WedgeEdges(const Submesh& sub, const Params& params) {
    const MeshType& s = sub.mesh;
    const std::vector<std::uint8_t> locked = LockedVertices(sub);
    std::vector<std::uint8_t> nearBad(s.vert.size(), 0);
    for (const auto& f : s.face) {
      if (f.IsD() || locked[vcg::tri::Index(s, f.cV(0))] || locked[vcg::tri::Index(s, f.cV(1))] ||
          locked[vcg::tri::Index(s, f.cV(2))])
        continue;
      if (!OutOfBounds(f, params)) continue;
      for (int k = 0; k < 3; ++k)
        for (vcg::face::VFIterator<typename MeshType::FaceType> it(
                 const_cast<typename MeshType::VertexType*>(f.cV(k)));
             !it.End(); ++it)
          for (int j = 0; j < 3; ++j) nearBad[vcg::tri::Index(s, it.F()->cV(j))] = 1;
    }
    std::vector<WedgeEdge> edges;
    for (std::size_t fi = 0; fi < s.face.size(); ++fi) {
      const auto& f = s.face[fi];
      if (f.IsD() || IsHaloFace(sub, f)) continue;
      for (int z = 0; z < 3; ++z) {
        const std::size_t b = vcg::tri::Index(s, f.cV(z)), x = vcg::tri::Index(s, f.cV((z + 1) % 3));
        const auto* g = f.cFFp(z);
        if (!locked[b] || locked[x] || !nearBad[b] || g == &f || IsHaloFace(sub, *g)) continue;
        const double angle = std::min(AngleAt(f, z), AngleAt(*g, (f.cFFi(z) + 1) % 3));
        if (angle < 40.0) edges.push_back({angle, fi, z});
      }
    }
    std::sort(edges.begin(), edges.end());
    return edges;
  }

  /// The intersecting face pairs of s (its faces indexed as in s.face, which is compact).
  static std::vector<IntersectingPair> SelfIntersections(const MeshType& s, double L) {
    std::vector<std::array<Index, 3>> tris(s.face.size());
    std::vector<Point> points(s.vert.size());
    for (std::size_t v = 0; v < s.vert.size(); ++v) points[v] = PositionOf(&s.vert[v]);
    for (std::size_t fi = 0; fi < s.face.size(); ++fi)
      for (int k = 0; k < 3; ++k) tris[fi][std::size_t(k)] = Index(vcg::tri::Index(s, s.face[fi].cV(k)));
    return FindSelfIntersections(tris, points, L, 0);
  }

  /// Edges whose two faces' normals differ by more than 120 degrees: folds, which the intersection
  /// test does not see (the two faces share the edge).
  static std::size_t FoldedEdges(const MeshType& s) {
    std::size_t folds = 0;
    for (const auto& f : s.face) {
      if (f.IsD()) continue;
      const Point n = FaceNormal(f);
      for (int z = 0; z < 3; ++z) {
        const auto* g = f.cFFp(z);
        if (g == &f || g < &f) continue; // each edge once
        const Point m = FaceNormal(*g);
        const double nm = n.Norm() * m.Norm();
        folds += !(nm > 0) || (n * m) / nm < -0.5;
      }
    }
    return folds;
  }
  static Point FaceNormal(const typename MeshType::FaceType& f) {
    const Point a = PositionOf(f.cV(0));
    return (PositionOf(f.cV(1)) - a) ^ (PositionOf(f.cV(2)) - a);
  }

  /// Border-wedge flips (Params::borderFlips), each kept only when it improves the shortfall.
  static std::string RelieveBorderWedges(Submesh& sub, const Reference& reference, const Params& params,
                                         double L, Result& r) {
    // Only with the stages that settle a flip (a smoothing run, say, changes no connectivity).
    if (!Runs(params, PipelineStage::Obtuse) || !Runs(params, PipelineStage::Polish)) return {};
    Shortfall left = MeasureShortfall(sub, params);
    if (left.badFaces == 0) return {};
    const std::size_t pairs = SelfIntersections(sub.mesh, L).size(), folds = FoldedEdges(sub.mesh);
    int tried = 0;
    while (left.badFaces > 0 && tried < params.borderFlips) {
      bool kept = false;
      for (const WedgeEdge& e : WedgeEdges(sub, params)) {
        if (tried >= params.borderFlips) break;
        auto& f = sub.mesh.face[e.fi];
        if (!vcg::face::CheckFlipEdge(f, e.z) ||
            !vcg::face::CheckFlipEdgeNormal(f, e.z, float(vcg::math::ToRad(60.0))))
          continue;
        ++tried;
        MeshType before;
        vcg::tri::Append<MeshType, MeshType>::MeshCopy(before, sub.mesh);
        vcg::face::FlipEdge(f, e.z);
        UpdateAdjacency(sub.mesh);
        Result passResult;
        if (std::string why = RunPass(sub, reference, params, L, false, passResult); !why.empty()) return why;
        const Shortfall after = MeasureShortfall(sub, params);
        if (after.Improves(left) && FoldedEdges(sub.mesh) <= folds &&
            SelfIntersections(sub.mesh, L).size() <= pairs) {
          left = after;
          kept = true;
          ++r.borderFlipsKept;
          break;
        }
        vcg::tri::Append<MeshType, MeshType>::MeshCopy(sub.mesh, before);
        UpdateAdjacency(sub.mesh);
      }
      if (!kept) break;
    }
    return {};
  }

  /// The region's shortfall against the bounds: interior vertices (unlocked) of a valence other
  /// than 5, 6 or 7, and faces with no locked corner with an angle below the small-angle bound or
  /// at or above polish's max angle.
  struct Shortfall {
    std::size_t irregular = 0, badFaces = 0;
    bool None() const { return irregular == 0 && badFaces == 0; }
    bool Improves(const Shortfall& o) const {
      return irregular <= o.irregular && badFaces <= o.badFaces &&
             irregular + badFaces < o.irregular + o.badFaces;
    }
  };
  /// An angle below the small-angle bound, or at or above polish's max angle.
  static bool OutOfBounds(const typename MeshType::FaceType& f, const Params& params) {
    double lo = 0, hi = 0;
    FaceAngleRange(f, lo, hi);
    return lo < params.pipeline.small.minAngleDeg || hi >= params.pipeline.polish.maxAngleDeg;
  }
  static Shortfall MeasureShortfall(const Submesh& sub, const Params& params) {
    const MeshType& s = sub.mesh;
    const std::vector<std::uint8_t> locked = LockedVertices(sub);
    std::vector<int> valence(s.vert.size(), 0);
    Shortfall out;
    for (const auto& f : s.face) {
      if (f.IsD()) continue;
      bool free = true;
      for (int k = 0; k < 3; ++k) {
        const std::size_t v = vcg::tri::Index(s, f.cV(k));
        ++valence[v];
        free = free && !locked[v];
      }
      if (!free) continue;
      out.badFaces += OutOfBounds(f, params);
    }
    for (std::size_t v = 0; v < s.vert.size(); ++v)
      out.irregular += !locked[v] && valence[v] > 0 && (valence[v] < 5 || valence[v] > 7);
    return out;
  }

  /// The stages, then the settling passes (Params::settlingPasses).
  static std::string RunStages(Submesh& s, const Reference& reference, const Params& params, double L,
                               Result& r) {
    if (std::string why = RunPass(s, reference, params, L, true, r); !why.empty()) return why;
    Shortfall left = MeasureShortfall(s, params);
    for (int pass = 0; pass < params.settlingPasses && !left.None(); ++pass) {
      MeshType before;
      vcg::tri::Append<MeshType, MeshType>::MeshCopy(before, s.mesh);
      Result passResult;
      if (std::string why = RunPass(s, reference, params, L, false, passResult); !why.empty()) return why;
      const Shortfall after = MeasureShortfall(s, params);
      if (!after.Improves(left)) {
        vcg::tri::Append<MeshType, MeshType>::MeshCopy(s.mesh, before);
        UpdateAdjacency(s.mesh);
        break;
      }
      left = after;
      ++r.settlingPassesKept;
      for (const std::string& line : passResult.stageSummaries)
        r.stageSummaries.push_back("settling pass " + std::to_string(pass + 1) + ", " + line);
    }
    return RelieveBorderWedges(s, reference, params, L, r);
  }

  /// The stages of params.pipeline.stages that apply to a region, in order (RAR only when withRar).
  static std::string RunPass(Submesh& s, const Reference& reference, const Params& params, double L,
                             bool withRar, Result& r) {
    const auto& pp = params.pipeline;
    for (const PipelineStage stage : pp.stages) {
      std::string summary, error;
      switch (stage) {
      case PipelineStage::Clean:
      case PipelineStage::Cvt:
      case PipelineStage::Segment:
        continue; // whole-mesh stages: not for a region
      case PipelineStage::Rar:
        if (!withRar) continue;
        error = RunRar(s, reference, params, L, summary);
        break;
      case PipelineStage::Valence:
        error = RunLocal<ValenceOptimization<MeshType>>(s, reference, pp.valence, params, L, summary);
        break;
      case PipelineStage::Small:
        error = RunLocal<SmallAngleElimination<MeshType>>(s, reference, pp.small, params, L, summary);
        break;
      case PipelineStage::Obtuse:
        error = RunLocal<ObtuseReduction<MeshType>>(s, reference, pp.obtuse, params, L, summary);
        break;
      case PipelineStage::Smooth:
        error = RunLocal<LocalSmoothing<MeshType>>(s, reference, pp.smooth, params, L, summary);
        break;
      case PipelineStage::Polish:
        error = RunLocal<ValenceOptimization<MeshType>>(s, reference, pp.polish, params, L, summary);
        break;
      }
      if (!error.empty()) return std::string("stage '") + StageName(stage) + "' failed: " + error;
      r.stageSummaries.push_back(std::string(StageName(stage)) + ": " + summary);
    }
    return {};
  }

  /// out = m without the region's faces and interior vertices, then the submesh's new faces.
  static std::string Stitch(const MeshType& m, const std::vector<std::uint8_t>& mask, const Submesh& sub,
                            MeshType& out, Result& r) {
    const MeshType& s = sub.mesh;
    std::vector<std::uint8_t> used(m.vert.size(), 0);
    for (std::size_t fi = 0; fi < m.face.size(); ++fi)
      if (!mask[fi])
        for (int k = 0; k < 3; ++k) used[vcg::tri::Index(m, m.face[fi].cV(k))] = 1;
    // Kept vertices in m's order, then the submesh's free vertices in its order.
    std::vector<std::int64_t> outOfM(m.vert.size(), -1);
    std::size_t kept = 0;
    for (std::size_t v = 0; v < m.vert.size(); ++v)
      if (used[v]) outOfM[v] = std::int64_t(kept++);
    std::vector<std::int64_t> outOfSub(s.vert.size(), -1);
    std::vector<std::uint8_t> isNew(s.vert.size(), 0);
    std::size_t added = 0;
    for (std::size_t v = 0; v < s.vert.size(); ++v) {
      if (s.vert[v].IsD()) continue;
      const std::int64_t o = OriginOf(sub, s.vert[v]);
      if (o < 0) {
        isNew[v] = 1;
        outOfSub[v] = std::int64_t(kept + added++);
      } else {
        outOfSub[v] = outOfM[std::size_t(o)]; // -1 for a halo vertex no kept face uses: checked below
      }
    }
    vcg::tri::Allocator<MeshType>::AddVertices(out, kept + added);
    for (std::size_t v = 0; v < m.vert.size(); ++v)
      if (outOfM[v] >= 0) out.vert[std::size_t(outOfM[v])].ImportData(m.vert[v]);
    for (std::size_t v = 0; v < s.vert.size(); ++v)
      if (isNew[v]) {
        out.vert[std::size_t(outOfSub[v])].ImportData(s.vert[v]);
        out.vert[std::size_t(outOfSub[v])].ClearFlags();
      }
    std::vector<std::array<std::size_t, 3>> faces;
    for (std::size_t fi = 0; fi < m.face.size(); ++fi)
      if (!mask[fi])
        faces.push_back({std::size_t(outOfM[vcg::tri::Index(m, m.face[fi].cV(0))]),
                         std::size_t(outOfM[vcg::tri::Index(m, m.face[fi].cV(1))]),
                         std::size_t(outOfM[vcg::tri::Index(m, m.face[fi].cV(2))])});
    const std::size_t outside = faces.size();
    for (const auto& f : s.face) {
      if (f.IsD() || IsHaloFace(sub, f)) continue;
      std::array<std::size_t, 3> c{};
      for (int k = 0; k < 3; ++k) {
        const std::int64_t o = outOfSub[std::size_t(vcg::tri::Index(s, f.cV(k)))];
        if (o < 0) return "a new face uses a vertex outside the region";
        c[std::size_t(k)] = std::size_t(o);
      }
      faces.push_back(c);
    }
    vcg::tri::Allocator<MeshType>::AddFaces(out, faces.size());
    std::size_t outsideIndex = 0;
    for (std::size_t fi = 0; fi < m.face.size(); ++fi)
      if (!mask[fi]) out.face[outsideIndex++].ImportData(m.face[fi]);
    for (std::size_t i = 0; i < faces.size(); ++i) {
      if (i >= outside) out.face[i].ClearFlags();
      for (int k = 0; k < 3; ++k) out.face[i].V(k) = &out.vert[faces[i][std::size_t(k)]];
    }
    r.regionFacesOut = faces.size() - outside;
    r.faceMask.assign(faces.size(), 0);
    std::fill(r.faceMask.begin() + std::ptrdiff_t(outside), r.faceMask.end(), std::uint8_t(1));
    return {};
  }

  static std::size_t BorderEdges(MeshType& mesh) {
    std::size_t n = 0;
    for (auto& f : mesh.face)
      for (int k = 0; k < 3; ++k) n += vcg::face::IsBorder(f, k) ? 1 : 0;
    return n;
  }

  /// The new region meets nothing, the result is edge-manifold with the input's border.
  static std::string Verify(MeshType& m, MeshType& out, Result& r) {
    UpdateAdjacency(out);
    if (vcg::tri::Clean<MeshType>::CountNonManifoldEdgeFF(out) > 0)
      return "the stitched mesh is not edge-manifold";
    if (BorderEdges(out) != BorderEdges(m))
      return "the stitched mesh does not close up along the region's border";
    for (const IntersectingPair& hit : SelfIntersections(out, r.targetEdgeLength))
      if (r.faceMask[hit.i] || r.faceMask[hit.j]) ++r.newRegionIntersections;
    if (r.newRegionIntersections > 0)
      return std::to_string(r.newRegionIntersections) + " intersecting pairs with a face of the new region";
    return {};
  }
};

} // namespace molremesh

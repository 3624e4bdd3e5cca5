// What the local stages (small-angle elimination, obtuse reduction, local smoothing) share: around
// their Do() the guards they start from, the checks before any edit, the run of their edits
// through LocalRemeshingOps and the timing of their Result; inside their sessions the small
// geometric pieces they all evaluate the same way (the shape of a vertex star, the two triangles
// of a flip, the shortest edge of a face, a tangent basis, which vertices are free to move). Their
// algorithms stay in their own headers, so the three refuse the same inputs with the same words,
// time themselves the same way and measure a star with one piece of code.
#pragma once

#include <vcg_ext/ops/local_remeshing_ops.h>
#include <vcg_ext/topology/face_face_topology.h>
#include <vcg_ext/surface/reference_surface.h>
#include <vcg_ext/geometry/triangle_angles.h>
#include <vcg_ext/geometry/mean_edge_length.h>
#include <vcg_ext/geometry/point.h>

#include <vcg/simplex/face/pos.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace molremesh {

/// LocalOpsGuards with the given angle bounds and every other guard at its default.
inline LocalOpsGuards GuardsWithAngleBounds(double minAngleDeg, double maxAngleDeg) {
  LocalOpsGuards g;
  g.minAngleDeg = minAngleDeg;
  g.maxAngleDeg = maxAngleDeg;
  return g;
}

/// Sets the fields every local stage's Result has (ok, message) and returns
/// a copy of it: the stages return through this on success and on every refusal.
template <class Result>
Result FinishStage(Result& r, bool ok, const std::string& message) {
  r.ok = ok;
  r.message = message;
  return r;
}

/// The checks a local stage makes after its own parameter checks, in this order: the reference is
/// not empty, m's adjacency is prepared for LocalRemeshingOps (PrepareTopology), and the target
/// edge length L is usable (targetEdgeLength, or when it is not positive the mean edge length of
/// m). Returns false with `why` (the reason, without the stage's name) when the stage must refuse;
/// m is then left as it was but for its recomputed adjacency.
template <class MeshType>
bool PrepareLocalStage(MeshType& m, const ReferenceSurface<MeshType>& reference, double targetEdgeLength,
                       double& L, std::string& why) {
  if (reference.Empty()) {
    why = "the reference surface is empty";
    return false;
  }
  if (!LocalRemeshingOps<MeshType>::PrepareTopology(m, &why)) return false;
  L = targetEdgeLength;
  if (!(L > 0)) L = MeanEdgeLength(m);
  if (!(L > 0) || !std::isfinite(L)) {
    why = "no valid target edge length";
    return false;
  }
  return true;
}

/// The shape of the star of v (the faces around it, from the VF adjacency) with v moved to q:
/// Shape::Add(q, next corner, previous corner, bound) for each face, in VF order.
template <class Shape, class FaceType, class VertexType, class Bound>
Shape StarShapeAt(const VertexType* v, const Point& q, const Bound& bound) {
  Shape s;
  for (vcg::face::VFIterator<FaceType> it(const_cast<VertexType*>(v)); !it.End(); ++it)
    s.Add(q, PositionOf(it.F()->cV((it.I() + 1) % 3)), PositionOf(it.F()->cV((it.I() + 2) % 3)), bound);
  return s;
}

/// Index z of the shortest edge (z, z+1) of f; the first one on ties.
template <class FaceType>
int ShortestEdgeIndex(const FaceType& f) {
  int z = 0;
  double shortest = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 3; ++k) {
    const double l = (PositionOf(f.cV(k)) - PositionOf(f.cV((k + 1) % 3))).SquaredNorm();
    if (l < shortest) shortest = l, z = k;
  }
  return z;
}

/// The corners around edge z of f and its neighbour g across it: {f's V(z), f's V(z+1), f's
/// corner opposite the edge, g's corner opposite the edge}. f must not be a border along z.
template <class FaceType>
std::array<Point, 4> EdgeQuad(const FaceType& f, int z) {
  const FaceType* g = f.cFFp(z);
  const int w = f.cFFi(z);
  return {PositionOf(f.cV(z)), PositionOf(f.cV((z + 1) % 3)), PositionOf(f.cV((z + 2) % 3)),
          PositionOf(g->cV((w + 2) % 3))};
}

/// The shapes of the two triangles of quad q (EdgeQuad) before and after flipping its edge.
template <class Shape, class Bound>
void FlipShapes(const std::array<Point, 4>& q, const Bound& bound, Shape& before, Shape& after) {
  before.Add(q[0], q[1], q[2], bound);
  before.Add(q[1], q[0], q[3], bound);
  after.Add(q[0], q[3], q[2], bound);
  after.Add(q[1], q[2], q[3], bound);
}

/// Whether a local stage may move or delete v: alive, in a face, neither locked nor on a border.
template <class Ops, class VertexType>
bool IsFreeVertex(Ops& ops, VertexType& v) {
  return !(v.IsD() || v.VFp() == nullptr || ops.IsLocked(v) || ops.IsBoundaryVertex(v));
}

/// Locks the vertices flagged in `locked` (indexed like the ops' mesh; empty = none).
template <class Ops>
void LockVertices(Ops& ops, const std::vector<std::uint8_t>& locked) {
  auto& m = ops.Mesh();
  for (std::size_t i = 0; i < locked.size() && i < m.vert.size(); ++i)
    if (locked[i]) ops.SetLocked(m.vert[i], true);
}

/// The local stages' last resort for the faces still bad after their rounds, which usually straddle a
/// sharp crease: when normalDeg relaxes the normal guard of `guards` and stillBad() is true, runs
/// rounds() once more with the normal guard at normalDeg (below 90, so no face turns over) and the
/// fold guard at least foldDeg, then restores `guards`. Returns whether the pass ran.
template <class Ops, class StillBad, class Rounds>
bool RunCreasePass(Ops& ops, const LocalOpsGuards& guards, double normalDeg, double foldDeg,
                   StillBad&& stillBad, Rounds&& rounds) {
  if (!(normalDeg > guards.maxNormalDeviationDeg) || !stillBad()) return false;
  LocalOpsGuards crease = guards;
  crease.maxNormalDeviationDeg = normalDeg;
  crease.maxFoldAngleDeg = std::max(crease.maxFoldAngleDeg, foldDeg);
  ops.SetGuards(crease);
  rounds();
  ops.SetGuards(guards);
  return true;
}

/// Runs a local stage's edits on m: LocalRemeshingOps with `guards` (lazy footpoints) and the
/// vertices flagged in `locked` locked, then body(ops), then the number of edits the guards refused into
/// `refused`, the ops' Finish and the adjacency recomputed. False with `error` when the ops cannot start (m
/// untouched).
template <class MeshType, class Body>
bool RunLocalEdits(MeshType& m, const ReferenceSurface<MeshType>& reference, double L,
                   const LocalOpsGuards& guards, int threads, const std::vector<std::uint8_t>& locked,
                   std::string& error, std::size_t& refused, Body&& body) {
  LocalRemeshingOps<MeshType> ops(m, reference, L, guards, threads);
  if (!ops.Init(&error, false, true, /*lazyFootpoints=*/true)) return false;
  LockVertices(ops, locked);
  body(ops);
  refused = ops.Stats().Refused();
  ops.Finish();
  UpdateAdjacency(m);
  return true;
}

} // namespace molremesh

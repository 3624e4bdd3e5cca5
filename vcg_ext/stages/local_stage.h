// What the local stages (small-angle elimination, obtuse reduction, local smoothing) share around
// their Do(): the guards they start from, the checks before any edit and the timing of their
// Result. Their algorithms stay in their own headers; this is only the common frame, so the three
// refuse the same inputs with the same words and time themselves the same way.
#pragma once

#include <vcg_ext/ops/local_remeshing_ops.h>
#include <vcg_ext/surface/reference_surface.h>
#include <vcg_ext/geometry/triangle_angles.h>
#include <vcg_ext/geometry/mean_edge_length.h>

#include <chrono>
#include <cmath>
#include <string>

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

} // namespace molremesh

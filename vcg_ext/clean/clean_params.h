// The settings of CleanRawMesh (vcg_ext/clean/clean_raw_mesh.h) and the run state its steps share.
#pragma once

namespace molremesh {

/// CleanRawMesh<MeshType>::Params: the cleaning's settings, with their defaults.
struct CleanRawMeshParams {
  double mergeTolerance = 1e-6; ///< merge vertices closer than this * mean edge length (0: exact copies only)
  double degenerateAreaEpsilon =
      1e-12;              ///< zero-area face: area <= this * (mean edge length)^2 (MeshQuality's definition)
  int maxHoleEdges = 100; ///< close boundary loops with at most this many edges (1UBQ EDTSurf's crack: 29)
  double minComponentFraction =
      0.01; ///< remove components with fewer than this fraction of the faces (not the largest)
  bool repairTangles = true;      ///< remove and refill local tangles (self-intersecting faces, orientation
                                  ///< conflicts); a repair is kept only if its refill is valid
  int maxRepairGrowth = 2;        ///< rings of faces added around a tangle when its first refill fails
  int maxRepairRegionFaces = 200; ///< larger tangles are left alone
  int maxRepairAttempts = 64; ///< remove-and-refill attempts in all (each rebuilds the adjacency, O(faces))
  bool orientCavitiesInward = true; ///< cavity components (nested in another closed one) get negative volume
  bool measureSelfIntersections = true; ///< count self-intersecting faces before and after (grid accelerated)
  double maxFillDihedral = 150.0; ///< degrees; a fill triangle never folds more than this against a neighbour
  int threads = 0;                ///< worker threads of the tangle search and the before/after
                                  ///< measurements; 0 = all cores (same result)
};

namespace clean {

/// What the remove-and-refill steps (split-copy separation, tangle repair, grown holes) share during
/// one cleaning run: the settings, the length scales fixed after measuring the input, and the
/// remaining budget of remove-and-refill attempts, which they draw from in the order they run.
struct CleanRunState {
  const CleanRawMeshParams& params;
  double meanEdge = 0;       ///< MeshQuality's mean edge length of the input (the tolerances' unit)
  double planeTolerance = 0; ///< snap distance of the plane-side tests (see PlaneTolerance)
  int attemptsLeft = 0;      ///< remove-and-refill attempts left (params.maxRepairAttempts at the start)
};

} // namespace clean
} // namespace molremesh

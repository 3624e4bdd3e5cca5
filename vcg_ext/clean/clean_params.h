// The settings of CleanRawMesh (vcg_ext/clean/clean_raw_mesh.h) and the run state its steps share.
#pragma once

#include <cstddef>
#include <functional>
#include <string>

namespace molremesh {

/// CleanRawMesh<MeshType>::Params: the cleaning's settings, with their defaults.
/// How CleanRawMesh reads a closed component nested inside others (CleanRawMeshParams).
enum class NestedComponents { Auto, Union, Parity };

struct CleanRawMeshParams {
  double mergeTolerance = 1e-6; ///< merge vertices closer than this * mean edge length (0: exact copies only)
  double degenerateAreaEpsilon =
      1e-12;              ///< zero-area face: area <= this * (mean edge length)^2 (MeshQuality's definition)
  int maxHoleEdges = 100; ///< close boundary loops with at most this many edges (1UBQ EDTSurf's crack: 29)
  double minComponentFraction = 0; ///< opt-in: remove components with fewer than this fraction of all the
                                   ///< faces (not the largest); 0 keeps them (cavities, separate parts)
  double minComponentVolume = 0;   ///< opt-in: remove components enclosing less than this volume (cubic
                                   ///< units of the mesh: A^3), not the largest; 0 keeps them
  int minComponentFaces = 0;       ///< opt-in: remove components with fewer faces (not the largest)
  double flatComponentVolume =
      0.01; ///< components with fewer than 4 faces or enclosing at most this * (mean edge length)^3
            ///< enclose no volume (flat or sliver pieces) and are removed (not the largest); < 0 keeps them
  bool repairTangles = true;      ///< remove and refill local tangles (self-intersecting faces, orientation
                                  ///< conflicts); a repair is kept only if its refill is valid
  int maxRepairGrowth = 2;        ///< rings of faces added around a tangle when its first refill fails
  int maxRepairRegionFaces = 200; ///< larger tangles are left alone
  int maxRepairAttempts = 64; ///< remove-and-refill attempts in all (each rebuilds the adjacency, O(faces))
  double fillWorkPerFace =
      50; ///< budget of the fill planning of each remove-and-refill or hole-filling step, in candidate
          ///< triangles evaluated (an n-sided loop costs n^3 / 6 per triangulation, retries included) per
          ///< input face, never below kMinFillWork; a fill past it is refused and its region or loop left
          ///< as it is (counted in fillBudgetRefusals), so no step grows super-linearly. 0 = unbounded
  bool volumetricFallback = true; ///< rebuild the whole surface volumetrically when the local steps
                                  ///< leave a defect, then clean the rebuild (volumetric_fallback.h)
  /// Opt-in: rebuild the whole surface volumetrically (step 13) even when the local steps leave no
  /// defect. The rebuild (voxel half the input's mean edge) keeps no part thinner than about two
  /// voxels: the fins, tubes, necks and pinched voids of coarse marching-cubes and Gaussian surfaces
  /// that no remesh at L keeps within the angle bounds go, and crevices as narrow are sealed.
  bool volumetricRebuild = false;
  bool orientCavitiesInward = true; ///< cavity components (nested in another closed one) get negative volume
  /// How a closed component nested in others is read (step 11, orientation.h): Union removes one
  /// oriented as the region around it (a piece inside the union, not a cavity); Parity makes every
  /// odd-depth one a cavity whatever its orientation; Auto is Union for a triangle soup whose sheets
  /// overlap (PyMOL's OBJ and WRL exports: cavities written inward, same-oriented pieces inside the
  /// body) and Parity otherwise (EDTSurf, MSMS: every component written outward, cavities included).
  NestedComponents nestedComponents = NestedComponents::Auto;
  bool measureSelfIntersections = true; ///< count self-intersecting faces before and after (grid accelerated)
  double maxFillDihedral = 150.0; ///< degrees; a fill triangle never folds more than this against a neighbour
  int threads = 0;                ///< worker threads of the tangle search and the before/after
                                  ///< measurements; 0 = all cores (same result)
  /// If set, called on the calling thread at each step with the share of the cleaning done (0..1)
  /// and the step ("Closing holes"); for progress bars, like the callback of Do.
  std::function<void(double fraction, const std::string& step)> progress;
};

namespace clean {

/// The smallest fill budget of a step, whatever the mesh's size (about a second of planning): small
/// meshes keep the fills of long loops that a per-face budget alone would refuse.
constexpr double kMinFillWork = 5e6;

/// What the remove-and-refill steps (split-copy separation, tangle repair, grown holes) share during
/// one cleaning run: the settings, the length scales fixed after measuring the input, and the
/// remaining budget of remove-and-refill attempts, which they draw from in the order they run.
struct CleanRunState {
  const CleanRawMeshParams& params;
  double meanEdge = 0;       ///< MeshQuality's mean edge length of the input (the tolerances' unit)
  double planeTolerance = 0; ///< snap distance of the plane-side tests (see PlaneTolerance)
  int attemptsLeft = 0;      ///< remove-and-refill attempts left (params.maxRepairAttempts at the start)
  double fillWorkLeft = 0;   ///< fill planning budget left in the current step (see ResetFillBudget)
  bool fillBudgetUnbounded = false;   ///< params.fillWorkPerFace == 0
  std::size_t fillBudgetRefusals = 0; ///< fills refused because the budget of their step ran out
};

/// Gives the step about to run its own fill budget: params.fillWorkPerFace per face of the input,
/// at least kMinFillWork.
inline void ResetFillBudget(CleanRunState& run, std::size_t inputFaces) {
  run.fillBudgetUnbounded = !(run.params.fillWorkPerFace > 0);
  run.fillWorkLeft = run.params.fillWorkPerFace * double(inputFaces);
  if (run.fillWorkLeft < kMinFillWork) run.fillWorkLeft = kMinFillWork;
}

} // namespace clean
} // namespace molremesh

// What the guarded local edits check and what they report: the refusal reasons, the guard
// thresholds, the counters of LocalRemeshingOps and the outcome of a batch move.
#pragma once

#include <array>
#include <cstddef>

namespace molremesh {

/// Why an operation was refused. Counted per reason in LocalOpsStats::refused.
enum class OpRefusal : int {
  None = 0,
  Locked,        ///< touches a locked vertex or edge
  Boundary,      ///< boundary vertex relocation, boundary edge flip, boundary vertex removal off the border
  Topology,      ///< link condition, ear, valence, existing edge
  Degenerate,    ///< a new face would have (nearly) zero area
  MinAngle,      ///< angle guard (smallest angle)
  MaxAngle,      ///< angle guard (largest angle)
  Normal,        ///< a new face deviates from the reference normal
  Fold,          ///< two adjacent faces would fold onto each other
  EdgeLength,    ///< a collapse would create an edge longer than allowed
  Intersection,  ///< a new face would intersect another face
  InputDistance, ///< an input point near the region would end too far from the mesh
  Count
};

/// Thresholds of the checks every operation runs (see the file comment for their meaning).
struct LocalOpsGuards {
  double minAngleDeg = 10.0;  ///< new angles below it only if the region's smallest angle improves
  double maxAngleDeg = 180.0; ///< new angles above it only if the region's largest angle improves (180 = off)
  double maxNormalDeviationDeg = 75.0; ///< new face normal vs reference normal at its corners
  double maxFoldAngleDeg = 120.0;      ///< angle between the normals of two adjacent faces
  double minAreaFactor = 1e-8;         ///< faces with area below factor * L^2 are never created
  bool checkIntersections = true;      ///< refuse edits that would create an intersecting pair
  /// Also refuse edits that leave more faces with an angle below minAngleDeg (above
  /// maxAngleDeg) than the faces they replace had: an improving edit may then not spread a bad
  /// angle over more faces. For stages that promise "no new angle below the guard".
  bool noMoreBadFaces = false;
  double gridCellFactor = 1.0; ///< intersection grid cell size, in target edge lengths
  /// Fidelity to the input (0 = off): an edit may not leave a point of the input near the edited
  /// region (a reference vertex or face centroid within inputReachFactor x L of it) farther than
  /// this x L from the mesh, unless the point was at least as far before. Chords of collapses and
  /// refills otherwise cut off the input's spikes and cusps, which sets the Hausdorff distance.
  double maxInputDistanceFactor = 0.0;
  double inputReachFactor = 1.5; ///< how far around the region input points are examined, x L
};

/// Outcome of LocalRemeshingOps::MoveVerticesJacobi.
struct BatchMoveResult {
  std::size_t applied = 0;  ///< vertices now at their target
  std::size_t rejected = 0; ///< vertices left where they were (refused or reverted)
  int rounds = 0;           ///< verification rounds
};

/// What the operations did since the object was created (or ResetStats).
struct LocalOpsStats {
  std::size_t splits = 0, collapses = 0, flips = 0, moves = 0, replacements = 0;
  std::array<std::size_t, std::size_t(OpRefusal::Count)> refused{}; ///< by OpRefusal
  std::size_t Refused() const {
    std::size_t n = 0;
    for (std::size_t r : refused) n += r;
    return n;
  }
};

} // namespace molremesh

// Memory budget of a pipeline run: refuse a run that cannot fit before it starts.
//
// A huge input, or a target edge length far below the input's (a typo of a unit, say), makes the
// pipeline build millions of faces. Left alone, the run grows until the kernel kills the process:
// for the CLI a crash with nothing written, for MeshLab the loss of the whole session. Instead,
// MemoryBudget::Estimate predicts the run's peak resident memory from the input's size and the
// face count the target edge length implies, and MemoryBudget::Check compares it with a limit
// (by default the memory available now), so the caller can refuse with a clear message and leave
// the mesh untouched.
//
// The model is linear, fitted to the peak resident memory (ru_maxrss) of full-pipeline runs on 2
// threads: kBaseBytes, plus kBytesPerFace per face of the largest mesh of the run (the input, or
// the output the target edge length implies), plus kBytesPerInputVertex per input vertex (an
// unwelded OBJ soup has three per face until the clean stage merges them). Measured peak of the
// CLI (1 and 2 threads) -> estimate: raw SES level sets of 1UBQ (9.8k and 44k faces) 56 -> 81 and
// 102 -> 138 MB, of 1HPV (148k) 262 -> 315, of 4JSV (465k, 1.29M, 2.56M) 627 -> 852, 1650 -> 2245
// and 3276 -> 4405; EDTSurf 1HPV (378k) 546 -> 708, 4JSV (535k) 735 -> 985 (825 in the slowest of
// several runs: glibc's arenas vary); 1MAH PyMOL (60k) 136 to 170 (its peak varies that much
// between runs, for the same reason) -> 178, whose output has 1.58 times the faces of a uniform
// mesh at L and so bounds kBytesPerFace from below (1300 gave 167, under a 170 MB run); a 1UBQ PyMOL
// soup (49k faces, 146k vertices) 124 -> 193: above every peak, by 5 to 45 %. The other estimates
// above were made at 1300 bytes per face and are now 150 bytes per output face higher. It is an
// estimate: a run just under the limit may still need more, one just over may fit; a limit < 0
// turns the check off.
//
#pragma once

#include <vcg_ext/core/available_memory.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <sstream>
#include <string>

namespace molremesh {

struct MemoryEstimate {
  double facesIn = 0;          ///< faces of the input
  double verticesIn = 0;       ///< vertices of the input
  double facesOut = 0;         ///< faces the target edge length implies (0: no resampling stage)
  double targetEdgeLength = 0; ///< the L they were counted for
  double bytes = 0;            ///< predicted peak resident memory of the run
  double candidatePairs = 0;   ///< report: pairs the self-intersection count tests (0: not counted)
};

class MemoryBudget {
public:
  static constexpr double kBaseBytes = 64.0 * 1024 * 1024; ///< the process and fixed-size parts
  static constexpr double kBytesPerFace = 1450.0;          ///< per face of the largest mesh of the run
  static constexpr double kBytesPerInputVertex = 400.0;    ///< soups: one per corner until merged
  /// RAR's sizing field goes down to 0.6 L on curved parts, so the output has more faces than a
  /// uniform mesh with edge L: measured 0.98-1.21 times as many on the meshes above, up to 1.66 on
  /// coarse small ones (lysozyme MSMS at its own mean edge), where the base dominates.
  static constexpr double kAdaptiveFaceFactor = 1.3;

  /// Faces of a uniform mesh with edge length L on a surface of the given area; 0 when either is
  /// not a positive finite number (a mesh with NaN coordinates is the input check's to refuse).
  static double UniformFaces(double area, double L) {
    if (!(L > 0) || !(area > 0)) return 0;
    const double faces = area / (std::sqrt(3.0) / 4.0 * L * L);
    return std::isfinite(faces) ? faces : 0.0;
  }

  /// Peak of a run on an input of facesIn faces and verticesIn vertices; resamples: whether a
  /// stage builds a new mesh at edge length L (CVT, RAR), of the given input area.
  static MemoryEstimate Estimate(std::size_t facesIn, std::size_t verticesIn, bool resamples, double area,
                                 double L) {
    MemoryEstimate e;
    e.facesIn = double(facesIn);
    e.verticesIn = double(verticesIn);
    e.targetEdgeLength = L;
    e.facesOut = resamples ? kAdaptiveFaceFactor * UniformFaces(area, L) : 0.0;
    e.bytes =
        kBaseBytes + kBytesPerFace * std::max(e.facesIn, e.facesOut) + kBytesPerInputVertex * e.verticesIn;
    return e;
  }

  /// Bytes this process may still allocate (see AvailableMemoryBytes).
  static double AvailableBytes() { return AvailableMemoryBytes(); }

  /// "" when the run fits under limitMB (0 = the available memory, < 0 = no check), else why not.
  static std::string Check(const MemoryEstimate& e, double limitMB) {
    const double limit = LimitBytes(limitMB);
    if (!(limit > 0) || e.bytes <= limit) return {};
    std::ostringstream s;
    s.setf(std::ios::fixed);
    s.precision(0);
    s << "the run would need about " << Megabytes(e.bytes) << " MB of memory (input " << e.facesIn
      << " faces";
    if (e.facesOut > e.facesIn) {
      s.unsetf(std::ios::fixed); // 4 significant digits, whatever the scale of L
      s.precision(4);
      s << "; at target edge length " << e.targetEdgeLength;
      s.setf(std::ios::fixed);
      s.precision(0);
      s << " about " << e.facesOut << " output faces";
    }
    s << "), more than the " << Megabytes(limit) << " MB "
      << (limitMB > 0 ? "memory limit" : "of memory available") << "; a larger target edge length makes "
      << "fewer faces (the face count falls with its square)";
    return s.str();
  }

private:
  /// The limit in bytes for limitMB (0 = the available memory); 0 for no check.
  static double LimitBytes(double limitMB) {
    if (limitMB < 0) return 0;
    return limitMB > 0 ? limitMB * 1024.0 * 1024.0 : AvailableBytes();
  }

  static double Megabytes(double bytes) { return std::round(bytes / (1024.0 * 1024.0)); }
};

} // namespace molremesh

// Local smoothing (Khan et al. 2020, section 3.6): Laplacian and local RAR on the triangles still bad.
// STUB: interface only, the algorithm is not written yet (Do refuses and leaves the mesh untouched).
#pragma once

#include <vcg/complex/complex.h>

#include <vcg_ext/reference_surface.h>

#include <cstdint>
#include <string>

namespace molremesh {

template <class MeshType>
class LocalSmoothing {
public:
  using Reference = ReferenceSurface<MeshType>;
  struct Params {
    double targetEdgeLength = 0; ///< L; 0 = mean edge length of the mesh
    int threads = 0;             ///< 0 = all cores (the output does not depend on it)
    std::uint64_t seed = 1;      ///< seed of every random choice
  };
  struct Result {
    bool ok = false;
    std::string message; ///< why it failed
    std::string Summary() const { return message; }
  };
  /// Runs the stage on m (a 2-manifold, closed or not, lying on reference). On failure m is
  /// left untouched and Result::message says why.
  static Result Do(MeshType& m, const Reference& reference, const Params& params) {
    (void)m;
    (void)reference;
    (void)params;
    Result r;
    r.message = "not implemented yet";
    return r;
  }
};

} // namespace molremesh

// The index type of vertices and faces in the flat arrays the algorithms build from a vcg mesh.
//
// 32 bits: half the memory of size_t in the large per-element tables, and enough for any molecular
// surface (4 billion elements). kNoIndex marks a missing or invalid reference.
#pragma once

#include <cstdint>
#include <limits>

namespace molremesh {

using Index = std::uint32_t;
constexpr Index kNoIndex = std::numeric_limits<Index>::max();

} // namespace molremesh

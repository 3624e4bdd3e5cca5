// Growing a std::vector by an eighth instead of doubling it.
//
// std::vector::resize doubles the capacity when it runs out. For the per-element arrays that grow
// with a mesh (one entry per face or vertex, up to millions), a doubling leaves up to half of the
// array unused at the run's peak; growing by an eighth keeps the excess under 12.5 % at the cost
// of about eight copies instead of one per doubling of the size (still amortized constant time).
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace molremesh {

/// v.resize(n, value), with the capacity grown to at most max(n, 9/8 of the size) when it must grow.
template <class T, class Allocator>
void ResizeWithSlack(std::vector<T, Allocator>& v, std::size_t n, const T& value = T()) {
  if (n > v.capacity()) v.reserve(std::max(n, v.size() + v.size() / 8));
  v.resize(n, value);
}

} // namespace molremesh

// Union-find (disjoint sets) over dense indices, deterministic whatever the order of the unions.
#pragma once

#include <cstddef>
#include <cstdint>
#include <numeric>
#include <vector>

namespace molremesh {

/// Union-find with path halving; the smaller index becomes the root so results are independent
/// of the union order (the reports must be deterministic).
class UnionFind {
public:
  explicit UnionFind(std::size_t n = 0) : parent_(n) {
    std::iota(parent_.begin(), parent_.end(), std::uint32_t(0));
  }
  std::uint32_t Find(std::uint32_t x) {
    while (parent_[x] != x) {
      parent_[x] = parent_[parent_[x]];
      x = parent_[x];
    }
    return x;
  }
  void Unite(std::uint32_t a, std::uint32_t b) {
    a = Find(a);
    b = Find(b);
    if (a == b) return;
    if (a < b)
      parent_[b] = a;
    else
      parent_[a] = b;
  }

private:
  std::vector<std::uint32_t> parent_;
};

} // namespace molremesh

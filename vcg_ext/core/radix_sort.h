// A stable LSD radix sort by a 64-bit key, for the large spatial sorts of the stages.
//
// The grids of the remeshing stages sort hundreds of thousands of cell keys at a time; a radix
// sort does it in a few linear passes, and being stable it keeps items with equal keys in the
// order they came in (face order, say), so the result is the same as sorting by (key, position).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace molremesh {

/// Sorts items by key(item) (a std::uint64_t), stably, 16 bits per pass; the passes over digits
/// that are the same in every key are skipped. scratch is working memory (any content).
template <class T, class Key>
void StableRadixSortByKey(std::vector<T>& items, std::vector<T>& scratch, Key&& key) {
  if (items.size() < 2) return;
  const std::uint64_t first = key(items.front());
  std::uint64_t varying = 0; // the key bits that differ between items
  for (const T& item : items) varying |= key(item) ^ first;
  scratch.resize(items.size());
  std::vector<std::size_t> count(std::size_t(1) << 16);
  for (int shift = 0; shift < 64; shift += 16) {
    if (((varying >> shift) & 0xffff) == 0) continue;
    std::fill(count.begin(), count.end(), 0);
    for (const T& item : items) ++count[(key(item) >> shift) & 0xffff];
    std::size_t sum = 0;
    for (std::size_t& c : count) {
      const std::size_t here = c;
      c = sum;
      sum += here;
    }
    for (const T& item : items) scratch[count[(key(item) >> shift) & 0xffff]++] = item;
    items.swap(scratch);
  }
}

} // namespace molremesh

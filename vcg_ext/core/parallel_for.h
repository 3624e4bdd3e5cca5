// A minimal deterministic parallel loop on std::thread.
//
// ParallelFor(n, threads, body) calls body(begin, end, thread) on blocks of [0, n). Blocks are
// handed out dynamically for load balance, so which thread runs which block varies between
// runs: the result is deterministic only when body writes nothing but per-index outputs (and
// per-thread scratch passed by the thread index). All molremesh parallel loops follow that
// rule, which makes their output bit-identical for any thread count.
//
// A thread the system refuses to start (std::system_error: too many threads, no memory for a
// stack) is not an error of the loop: the threads already running, the calling thread among them,
// take the blocks it would have taken, so the loop finishes with the same result on fewer threads
// instead of leaving joinable threads behind (std::terminate).
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <system_error>
#include <thread>
#include <vector>

namespace molremesh {

/// Number of worker threads for a `threads` parameter: 0 means the hardware concurrency.
inline int ResolveThreadCount(int threads) {
  if (threads > 0) return threads;
  const unsigned hw = std::thread::hardware_concurrency();
  return hw > 0 ? int(hw) : 1;
}

/// Calls body(begin, end, threadIndex) over [0, n) in blocks of `block` indices, on `threads`
/// threads (resolved by ResolveThreadCount; the calling thread is thread 0).
template <class Body>
void ParallelFor(std::size_t n, int threads, Body&& body, std::size_t block = 1024) {
  if (n == 0) return;
  threads = std::max(1, std::min(ResolveThreadCount(threads), int((n + block - 1) / block)));
  if (threads == 1) {
    body(std::size_t(0), n, 0);
    return;
  }
  std::atomic<std::size_t> next{0};
  auto worker = [&](int t) {
    for (;;) {
      const std::size_t begin = next.fetch_add(block);
      if (begin >= n) break;
      body(begin, std::min(n, begin + block), t);
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(threads - 1);
  for (int t = 1; t < threads; ++t) {
    try {
      pool.emplace_back(worker, t);
    } catch (const std::system_error&) {
      break; // run on the threads that started
    }
  }
  worker(0);
  for (auto& th : pool) th.join();
}

} // namespace molremesh

// Block-parallel loops for measurements whose result must not depend on the
// thread count: each block writes only its own slot, and the caller sums the
// slots in block order afterwards.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <thread>
#include <vector>

namespace meshstream {

// Runs body(b) for every b in [0, blocks) on `threads` threads (0: one per
// core), the calling thread included; blocks are handed out one at a time.
template <class Body>
void for_each_block(size_t blocks, unsigned threads, const Body& body) {
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  threads = static_cast<unsigned>(std::min<size_t>(threads, blocks));
  if (threads <= 1) {
    for (size_t b = 0; b < blocks; ++b) body(b);
    return;
  }
  std::atomic<size_t> next{0};
  auto worker = [&] {
    for (size_t b = next++; b < blocks; b = next++) body(b);
  };
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < threads; ++t) pool.emplace_back(worker);
  worker();
  for (std::thread& t : pool) t.join();
}

}  // namespace meshstream

// Wall-clock medians for the codec benchmark: the machines are shared, so
// every figure is the median of repeated runs.
#pragma once

#include <algorithm>
#include <chrono>
#include <vector>

namespace meshstream::bench {

// Runs `fn` `runs` times (at least once) and returns the median duration in
// seconds.
template <class Fn>
double median_seconds(int runs, Fn&& fn) {
  std::vector<double> times;
  for (int r = 0; r < std::max(1, runs); ++r) {
    const auto start = std::chrono::steady_clock::now();
    fn();
    times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  std::sort(times.begin(), times.end());
  const size_t n = times.size();
  return n % 2 ? times[n / 2] : 0.5 * (times[n / 2 - 1] + times[n / 2]);
}

inline double median(std::vector<double> values) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

}  // namespace meshstream::bench

// Timing for the codec benchmark. The machines are shared and busy, so
// throughput is measured in the calling thread's CPU time (time the thread
// was descheduled for someone else's build does not count), as the median of
// repeated runs, and peers are run interleaved so both see the same machine.
#pragma once

#include <time.h>

#include <algorithm>
#include <vector>

namespace meshstream::bench {

// CPU seconds consumed by the calling thread so far.
inline double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Thread CPU seconds spent in one call of fn.
template <class Fn>
double cpu_seconds(Fn&& fn) {
  const double start = thread_cpu_seconds();
  fn();
  return thread_cpu_seconds() - start;
}

inline double median(std::vector<double> values) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// Runs `fn` `runs` times (at least once); the median thread CPU seconds.
template <class Fn>
double median_seconds(int runs, Fn&& fn) {
  std::vector<double> times;
  for (int r = 0; r < std::max(1, runs); ++r) times.push_back(cpu_seconds(fn));
  return median(times);
}

}  // namespace meshstream::bench

// Per-connection pacing (--rate): a token bucket refilled at `rate` bytes
// per second holding at most `burst` bytes. Sending n bytes takes n tokens;
// when the bucket goes into debt the sender waits until it is paid back, so
// the long-run rate is `rate` and bursts never exceed `burst`.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstddef>

namespace meshstream::server {

class TokenBucket {
 public:
  using Clock = std::chrono::steady_clock;

  // rate 0 = unlimited (take() never asks to wait). Starts full.
  TokenBucket(double rate_bytes_per_s, double burst_bytes, Clock::time_point now)
      : rate_(rate_bytes_per_s), burst_(burst_bytes), tokens_(burst_bytes), last_(now) {}

  // Takes `bytes` tokens at `now` and returns how long to wait before
  // sending them (zero when the bucket had enough). O(1).
  Clock::duration take(size_t bytes, Clock::time_point now) {
    if (rate_ <= 0) return Clock::duration::zero();
    const double elapsed = std::chrono::duration<double>(now - last_).count();
    last_ = now;
    tokens_ = std::min(burst_, tokens_ + elapsed * rate_) - double(bytes);
    if (tokens_ >= 0) return Clock::duration::zero();
    return std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(-tokens_ / rate_));
  }

 private:
  double rate_;
  double burst_;
  double tokens_;
  Clock::time_point last_;
};

}  // namespace meshstream::server

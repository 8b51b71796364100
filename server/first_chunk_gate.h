// First chunks before bulk: while any stream on the server has been requested
// but has not had its first chunk written, the chunks of streams already in
// bulk transfer wait (up to a bounded hold), so a new viewer's coarse model
// is not queued behind everyone else's detail. Under a burst of N requests
// all N first chunks leave before bulk resumes; one request arriving during
// bulk pauses bulk for about one turn of the worker's queue.
//
// Shared by all worker threads (the clients of every worker share the same
// network and often the same machine, so bulk on one worker delays the first
// chunks of the other). Counting is lock-free; each worker parks its bulk
// writers on its own timer, and the gate wakes every worker when the last
// starting stream has written its first chunk.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <optional>
#include <vector>

namespace meshstream::server {

class FirstChunkGate {
 public:
  using Clock = std::chrono::steady_clock;

  // `max_hold`: the longest bulk chunks wait for the first chunks of one
  // burst (counted from the burst's first request, so new requests arriving
  // all the time cannot starve bulk transfer); zero disables the hold.
  explicit FirstChunkGate(Clock::duration max_hold) : max_hold_(max_hold) {}
  FirstChunkGate(const FirstChunkGate&) = delete;
  FirstChunkGate& operator=(const FirstChunkGate&) = delete;

  // Registers a callback run (from any thread) when bulk may go again; it
  // must only post to its worker. Call before any worker runs.
  void add_waker(std::function<void()> wake) { wakers_.push_back(std::move(wake)); }

  // A stream was requested; its first chunk is not written yet. Any thread.
  void stream_starting(Clock::time_point now) {
    if (starting_.fetch_add(1, std::memory_order_acq_rel) == 0) {
      deadline_.store((now + max_hold_).time_since_epoch().count(), std::memory_order_release);
    }
  }
  // Its first chunk is written (or the stream or session ended before). Any thread.
  void stream_started() {
    if (starting_.fetch_sub(1, std::memory_order_acq_rel) == 1 &&
        wakers_on_.load(std::memory_order_acquire)) {
      for (const auto& wake : wakers_) wake();
    }
  }

  // When a bulk chunk (not a stream's first) may be written at `now`:
  // nullopt = now; else wait until the returned time or a wake, then ask again.
  std::optional<Clock::time_point> hold_bulk_until(Clock::time_point now) const {
    if (max_hold_ <= Clock::duration::zero()) return std::nullopt;
    if (starting_.load(std::memory_order_acquire) <= 0) return std::nullopt;
    const Clock::time_point deadline{Clock::duration(deadline_.load(std::memory_order_acquire))};
    if (now >= deadline) return std::nullopt;
    return deadline;
  }

  // Stops calling the wakers (the workers are stopping: sessions destroyed
  // with their io_context must not post to it). Call once no worker runs.
  void stop_waking() { wakers_on_.store(false, std::memory_order_release); }

  // Streams whose first chunk is not written yet (all workers).
  int64_t starting() const { return starting_.load(std::memory_order_acquire); }

 private:
  const Clock::duration max_hold_;
  std::atomic<int64_t> starting_{0};
  std::atomic<Clock::rep> deadline_{0};
  std::vector<std::function<void()>> wakers_;
  std::atomic<bool> wakers_on_{true};
};

}  // namespace meshstream::server

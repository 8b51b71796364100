// The server's counters for `--metrics` (/metrics, Prometheus text format),
// updated from every worker thread: atomics only, no lock on the streaming
// path. The metric names here are the contract of docs/deploy.md.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <string>

#include "proto/meshstream.pb.h"

namespace meshstream::server {

// How a stream ended: a StreamEnd reason, or the connection closed (client
// gone, server stopped, write failed) while it ran.
enum class StreamOutcome { kComplete, kBudget, kCancelled, kInterrupted };
constexpr size_t kStreamOutcomes = 4;

struct ServerMetrics {
  std::atomic<uint64_t> sessions_total{0};  // connections accepted and served (not rejected)
  std::atomic<uint64_t> bytes_sent{0};      // stream bytes sent in chunks
  std::array<std::atomic<uint64_t>, kStreamOutcomes> streams{};
  // Error frames sent, by v1::Error::Code (BUSY counts rejected connections).
  std::array<std::atomic<uint64_t>, v1::Error::Code_ARRAYSIZE> errors{};

  void count_stream(StreamOutcome outcome) {
    streams[static_cast<size_t>(outcome)].fetch_add(1, std::memory_order_relaxed);
  }
  void count_error(v1::Error::Code code) {
    if (code >= 0 && code < v1::Error::Code_ARRAYSIZE)
      errors[static_cast<size_t>(code)].fetch_add(1, std::memory_order_relaxed);
  }
};

// What the catalog holds, by state (ModelState: queued for the encoder,
// encoding, ready, failed).
struct ModelCounts {
  uint64_t queued = 0;
  uint64_t encoding = 0;
  uint64_t ready = 0;
  uint64_t failed = 0;
};

// The Prometheus text exposition (format 0.0.4) of `metrics`, the open
// sessions and `models`: every family with # HELP and # TYPE, every label
// value listed (zeros too, so a rate() never starts from a missing series).
std::string render_prometheus(const ServerMetrics& metrics, int64_t open_sessions,
                              const ModelCounts& models);

}  // namespace meshstream::server

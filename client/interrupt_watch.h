// Ctrl-C (SIGINT) and SIGTERM as a request to end cleanly: a thread of its
// own waits for them and calls back, so the client can stop the stream,
// write the done event and final.ply of what arrived, and exit 128 +
// signal, instead of dying mid-line. A second signal exits at once (the
// same code), for when the clean end itself would wait (an open window).
#pragma once

#include <signal.h>

#include <atomic>
#include <functional>
#include <thread>

namespace meshstream::client {

class InterruptWatch {
 public:
  // Blocks SIGINT and SIGTERM in the calling thread and every thread it
  // starts later (so only the watcher receives them): create it before
  // any other thread. `on_signal` runs on the watcher's thread.
  explicit InterruptWatch(std::function<void(int signal)> on_signal);
  // Stops the watcher and restores the signal mask.
  ~InterruptWatch();
  InterruptWatch(const InterruptWatch&) = delete;
  InterruptWatch& operator=(const InterruptWatch&) = delete;

  // The first signal that arrived, or 0.
  int signal() const { return signal_.load(); }

 private:
  void watch();

  std::function<void(int)> on_signal_;
  sigset_t watched_{}, previous_{};
  std::atomic<bool> done_{false};
  std::atomic<int> signal_{0};
  std::thread thread_;
};

}  // namespace meshstream::client

#include "client/interrupt_watch.h"

#include <pthread.h>
#include <unistd.h>

#include <ctime>

namespace meshstream::client {

InterruptWatch::InterruptWatch(std::function<void(int)> on_signal)
    : on_signal_(std::move(on_signal)) {
  sigemptyset(&watched_);
  sigaddset(&watched_, SIGINT);
  sigaddset(&watched_, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &watched_, &previous_);
  thread_ = std::thread([this] { watch(); });
}

InterruptWatch::~InterruptWatch() {
  done_ = true;
  if (thread_.joinable()) thread_.join();
  pthread_sigmask(SIG_SETMASK, &previous_, nullptr);
}

void InterruptWatch::watch() {
  // Polls so that the destructor can end the wait (100 ms at most).
  const timespec tick{0, 100 * 1000 * 1000};
  while (!done_) {
    const int sig = sigtimedwait(&watched_, nullptr, &tick);
    if (sig <= 0) continue;  // timeout or EINTR
    int none = 0;
    if (!signal_.compare_exchange_strong(none, sig)) ::_exit(128 + signal_.load());
    if (on_signal_) on_signal_(sig);
  }
}

}  // namespace meshstream::client

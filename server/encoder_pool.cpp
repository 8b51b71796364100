#include "server/encoder_pool.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace meshstream::server {

using Clock = std::chrono::steady_clock;

unsigned EncoderPool::default_encoders() {
  const unsigned cores = std::thread::hardware_concurrency();
  return cores > 1 ? cores - 1 : 1;
}

EncoderPool::EncoderPool(ModelRegistry& registry, unsigned encoders, CatalogLog log)
    : registry_(registry), log_(std::move(log)) {
  if (encoders == 0) encoders = default_encoders();
  for (unsigned i = 0; i < encoders; ++i) threads_.emplace_back([this] { work(); });
}

EncoderPool::~EncoderPool() {
  if (!stop(std::chrono::milliseconds(0)).empty()) {
    // An encode still runs: the process is about to exit (stop's contract);
    // joining would wait for it.
    for (auto& t : threads_) t.detach();
    return;
  }
  for (auto& t : threads_) {
    if (t.joinable()) t.join();
  }
}

void EncoderPool::submit(EncodeTask task, std::shared_ptr<const CatalogModel> previous) {
  ModelStatus status;
  status.name = task.name;
  status.source = task.source;
  status.origin = task.origin;
  status.state = ModelState::kQueued;
  status.model = std::move(previous);
  const uint64_t generation = registry_.put(std::move(status));
  std::lock_guard lock(mutex_);
  if (stopping_) return;
  queue_.push_back(Queued{std::move(task), generation});
  changed_.notify_one();
}

void EncoderPool::when_idle(std::function<void()> callback) {
  std::unique_lock lock(mutex_);
  if (queue_.empty() && busy_ == 0) {
    lock.unlock();
    callback();
    return;
  }
  idle_callback_ = std::move(callback);
}

std::vector<std::string> EncoderPool::stop(std::chrono::milliseconds grace) {
  std::unique_lock lock(mutex_);
  stopping_ = true;
  queue_.clear();
  changed_.notify_all();
  changed_.wait_for(lock, grace, [&] { return busy_ == 0; });
  std::vector<std::string> left;
  const auto snapshot = registry_.snapshot();
  for (const std::string& name : running_) {
    auto found = snapshot->find(name);
    char line[64];
    std::snprintf(line, sizeof line, " (%.0f %%)",
                  found == snapshot->end() ? 0.0 : found->second.percent);
    left.push_back(name + line);
  }
  return left;
}

void EncoderPool::work() {
  std::unique_lock lock(mutex_);
  while (true) {
    changed_.wait(lock, [&] { return stopping_ || !queue_.empty(); });
    if (stopping_) return;
    Queued item = std::move(queue_.front());
    queue_.pop_front();
    ++busy_;
    running_.push_back(item.task.name);
    lock.unlock();
    run_one(item);
    lock.lock();
    running_.erase(std::find(running_.begin(), running_.end(), item.task.name));
    finished_one_locked(lock);
  }
}

void EncoderPool::finished_one_locked(std::unique_lock<std::mutex>& lock) {
  --busy_;
  changed_.notify_all();
  if (busy_ == 0 && queue_.empty() && idle_callback_) {
    auto callback = std::move(idle_callback_);
    idle_callback_ = nullptr;
    lock.unlock();
    callback();
    lock.lock();
  }
}

void EncoderPool::run_one(Queued& item) {
  const EncodeTask& task = item.task;
  const uint64_t generation = item.generation;
  // Replaced or withdrawn while it waited: nothing to do.
  if (!registry_.update(task.name, generation, [](ModelStatus& s) {
        s.state = ModelState::kEncoding;
        s.percent = 0;
      })) {
    return;
  }
  auto say = [&](CatalogLogLevel level, const std::string& line) {
    std::lock_guard lock(log_mutex_);
    log_(level, line);
  };
  const auto start = Clock::now();
  // Log lines at each tenth of the way and at each new stage, not at every
  // callback; the registry follows every whole percent.
  int logged_tenth = -1;
  std::string logged_stage;
  int shown_percent = -1;
  std::string shown_stage;
  const EncodeProgressCallback progress = [&](const EncodeProgress& p) {
    const double percent = std::clamp(p.fraction, 0.0, 1.0) * 100.0;
    const int whole = static_cast<int>(std::floor(percent));
    if (whole != shown_percent || p.stage != shown_stage) {
      shown_percent = whole;
      shown_stage = std::string(p.stage);
      registry_.update(task.name, generation, [&](ModelStatus& s) {
        s.percent = percent;
        s.stage = shown_stage;
      });
    }
    // Quick encodes (under a second) get only their "ready" line.
    const int tenth = whole / 10;
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    if (whole < 100 && elapsed >= 1.0 && (tenth > logged_tenth || p.stage != logged_stage)) {
      logged_tenth = tenth;
      logged_stage = std::string(p.stage);
      char line[128];
      std::snprintf(line, sizeof line, "%d %% (%s) after %.1f s", whole, logged_stage.c_str(),
                    elapsed);
      say(CatalogLogLevel::kInfo, "encoding " + task.name + " (" + task.origin + "): " + line);
    }
  };
  bool from_cache = false;
  Result<CatalogModel> model = task.run(progress, from_cache);
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  if (!model) {
    const std::string reason = model.error().message;  // errors name the input
    if (registry_.update(task.name, generation, [&](ModelStatus& s) {
          s.state = ModelState::kFailed;
          s.reason = reason;
          s.model = nullptr;  // its file is no longer what the old stream came from
        })) {
      say(CatalogLogLevel::kWarn, "failed " + task.name + ": " + reason);
    }
    return;
  }
  auto ready = std::make_shared<const CatalogModel>(std::move(*model));
  if (!registry_.update(task.name, generation, [&](ModelStatus& s) {
        s.state = ModelState::kReady;
        s.percent = 100;
        s.stage.clear();
        s.model = ready;
      })) {
    return;  // replaced or withdrawn while it encoded
  }
  char facts[256];
  std::snprintf(facts, sizeof facts, "%s %s: %u vertices, %zu bytes, %zu records in %.2f s",
                from_cache ? "from cache" : "encoded", task.origin.c_str(),
                ready->index.header.vertex_count, ready->stream().size(),
                ready->index.records.size(), seconds);
  say(CatalogLogLevel::kInfo, "ready " + task.name + ": " + facts);
  if (ready->compact.coded.empty()) {
    say(CatalogLogLevel::kWarn, task.name + ": its record index cannot be coded compactly (" +
                                    ready->compact.refused + "); its headers carry the arrays");
  }
}

}  // namespace meshstream::server

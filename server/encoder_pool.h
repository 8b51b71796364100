// The server's background encoders: a bounded pool of threads that turn
// queued models (mesh files, demo models) into streams while the server
// serves. Each task's entry in the ModelRegistry goes queued -> encoding
// (with its percent, from EncodeOptions::progress) -> ready or failed, and
// the log gets a line at each tenth of the way and one when it ends.
#pragma once

#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "common/base/result.h"
#include "common/codec/encode_progress.h"
#include "server/catalog.h"
#include "server/model_registry.h"

namespace meshstream::server {

struct EncodeTask {
  std::string name;    // catalog name
  std::string source;  // "mesh" or "demo"
  std::string origin;  // file path or demo description, for messages
  // Runs on an encoder thread: the model, or why not (naming the input).
  // Sets `from_cache` when the stream came from the cache, not an encode.
  std::function<Result<CatalogModel>(const EncodeProgressCallback& progress, bool& from_cache)> run;
};

class EncoderPool {
 public:
  // One encoder per core less one (the io threads need one), at least one.
  static unsigned default_encoders();

  // `encoders` = 0: default_encoders(). `log` gets the progress lines; it
  // is called from the encoder threads, one at a time.
  EncoderPool(ModelRegistry& registry, unsigned encoders, CatalogLog log);
  ~EncoderPool();  // stop(0)
  EncoderPool(const EncoderPool&) = delete;
  EncoderPool& operator=(const EncoderPool&) = delete;

  unsigned encoders() const { return static_cast<unsigned>(threads_.size()); }

  // Lists task.name as queued and encodes it when an encoder is free, in
  // submission order. `previous`, if set, is the stream still served under
  // that name until this one is ready (a changed file). A later put or
  // remove of the name in the registry makes the task moot: it is skipped,
  // or its result dropped.
  void submit(EncodeTask task, std::shared_ptr<const CatalogModel> previous = nullptr);

  // Calls `callback` once, as soon as no task is queued or running (at
  // once, on this thread, when none is; else on the encoder thread that
  // finished the last one).
  void when_idle(std::function<void()> callback);

  // No more tasks: drops the queued ones and waits up to `grace` for the
  // running ones. Returns "name (NN %)" for each encode still running after
  // that (an encode cannot be interrupted: the caller then exits without
  // waiting for it).
  std::vector<std::string> stop(std::chrono::milliseconds grace);

 private:
  struct Queued {
    EncodeTask task;
    uint64_t generation;
  };
  void work();
  void run_one(Queued& item);
  // Called with mutex_ held.
  void finished_one_locked(std::unique_lock<std::mutex>& lock);

  ModelRegistry& registry_;
  CatalogLog log_;
  std::mutex log_mutex_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Queued> queue_;
  std::vector<std::string> running_;  // names being encoded now
  size_t busy_ = 0;
  bool stopping_ = false;
  std::function<void()> idle_callback_;
  std::vector<std::thread> threads_;
};

}  // namespace meshstream::server

// Keeps the ModelRegistry in step with a --models folder while the server
// runs: a file added is listed and encoded, a file changed is re-encoded
// (its previous stream served until the new one is ready), a file removed
// is withdrawn (running streams of it finish). Woken by inotify where it
// works, else by polling; a file is taken only once its size and
// modification time have stayed the same for `settle` (a file still being
// copied is not encoded half-written), except at the first scan. Names
// follow scan_models_folder (models_folder.h). One thread.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <thread>

#include "server/catalog.h"
#include "server/encoder_pool.h"
#include "server/model_registry.h"
#include "server/models_folder.h"

namespace meshstream::server {

enum class WatchMode {
  kAuto,  // inotify, polling where it is missing or fails
  kPoll,  // polling only (network file systems, where inotify misses changes)
  kOff,   // the first scan only
};

struct FolderWatchOptions {
  std::string dir;
  std::string cache_dir;  // for encode_cached; empty = no cache
  WatchMode mode = WatchMode::kAuto;
  std::chrono::milliseconds poll_interval{1000};  // polling, and the longest inotify sleep
  std::chrono::milliseconds settle{1000};         // unchanged this long before it is taken
  // Names the watcher leaves alone (the demo models'): a file that would be
  // served under one is skipped with a warning.
  std::set<std::string> reserved;
};

class FolderWatcher {
 public:
  FolderWatcher(FolderWatchOptions options, ModelRegistry& registry, EncoderPool& pool,
                CatalogLog log);
  ~FolderWatcher();  // stop()
  FolderWatcher(const FolderWatcher&) = delete;
  FolderWatcher& operator=(const FolderWatcher&) = delete;

  // Lists every model file the folder holds now as queued, before the
  // server announces its port, so a client that asks at once hears
  // NOT_READY, not UNKNOWN_MODEL. A directory listing; no file is read.
  void list_initial();
  // Starts the thread. `first_scan_done` runs once on it after the first
  // scan has listed (and submitted) everything the folder held.
  void start(std::function<void()> first_scan_done);
  // Ends the thread (within one wake-up). Idempotent.
  void stop();
  void reserve(const std::string& name);

 private:
  struct FileVersion {
    std::string path;
    bool hcs = false;
    int64_t size = -1;
    int64_t mtime_ns = -1;
    bool operator==(const FileVersion&) const = default;
  };
  struct Seen {
    FileVersion version;
    std::chrono::steady_clock::time_point since;  // unchanged since then
  };

  void run();
  // One pass: list, compare, submit, withdraw. Returns how long until a
  // file that is still settling should be looked at again (max() = none).
  std::chrono::steady_clock::duration reconcile(bool first);
  void take(const std::string& name, const FileVersion& version, bool first);
  void warn_once(const std::string& line);
  bool open_inotify();
  // Sleeps until a folder event, stop() or `timeout`.
  void wait(std::chrono::steady_clock::duration timeout);

  FolderWatchOptions options_;
  ModelRegistry& registry_;
  EncoderPool& pool_;
  CatalogLog log_;
  std::function<void()> first_scan_done_;

  std::map<std::string, FileVersion> taken_;  // name -> the file version submitted
  std::map<std::string, Seen> seen_;          // path -> last observed version
  std::set<std::string> warned_;              // warnings already logged (once each)
  std::set<std::string> prelisted_;           // names list_initial() registered
  std::mutex reserved_mutex_;
  int inotify_fd_ = -1;
  int wake_pipe_[2] = {-1, -1};
  std::atomic<bool> stopping_{false};
  std::thread thread_;
};

}  // namespace meshstream::server

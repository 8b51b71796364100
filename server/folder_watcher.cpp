#include "server/folder_watcher.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/inotify.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>

#include "server/model_sources.h"

namespace meshstream::server {
namespace {

using Clock = std::chrono::steady_clock;

// After an inotify event, more usually follow (a copy writes in many
// steps): gather them for this long before looking at the folder.
constexpr auto kEventQuiet = std::chrono::milliseconds(100);

}  // namespace

FolderWatcher::FolderWatcher(FolderWatchOptions options, ModelRegistry& registry, EncoderPool& pool,
                             CatalogLog log)
    : options_(std::move(options)), registry_(registry), pool_(pool), log_(std::move(log)) {}

FolderWatcher::~FolderWatcher() {
  stop();
  if (inotify_fd_ >= 0) ::close(inotify_fd_);
  for (int fd : wake_pipe_) {
    if (fd >= 0) ::close(fd);
  }
}

void FolderWatcher::reserve(const std::string& name) {
  std::lock_guard lock(reserved_mutex_);
  options_.reserved.insert(name);
}

void FolderWatcher::list_initial() {
  auto scan = scan_models_folder(options_.dir);
  if (!scan) return;  // the first scan says why
  for (const auto* files : {&scan->hcs, &scan->meshes}) {
    for (const ModelFile& file : *files) {
      registry_.put(ModelStatus{file.name, files == &scan->hcs ? "hcs" : "mesh", file.path,
                                ModelState::kQueued, 0, "", "", nullptr, 0});
      prelisted_.insert(file.name);
    }
  }
}

void FolderWatcher::start(std::function<void()> first_scan_done) {
  first_scan_done_ = std::move(first_scan_done);
  if (::pipe2(wake_pipe_, O_CLOEXEC | O_NONBLOCK) != 0) wake_pipe_[0] = wake_pipe_[1] = -1;
  thread_ = std::thread([this] { run(); });
}

void FolderWatcher::stop() {
  if (!thread_.joinable()) return;
  stopping_ = true;
  if (wake_pipe_[1] >= 0) {
    const char byte = 1;
    (void)!::write(wake_pipe_[1], &byte, 1);
  }
  thread_.join();
}

bool FolderWatcher::open_inotify() {
  inotify_fd_ = ::inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
  if (inotify_fd_ < 0) {
    log_(CatalogLogLevel::kWarn, "cannot watch " + options_.dir + " with inotify (" +
                                     std::strerror(errno) + "); looking at it every " +
                                     std::to_string(options_.poll_interval.count()) + " ms");
    return false;
  }
  const uint32_t mask = IN_CREATE | IN_DELETE | IN_MODIFY | IN_CLOSE_WRITE | IN_MOVED_FROM |
                        IN_MOVED_TO | IN_ATTRIB | IN_DELETE_SELF | IN_MOVE_SELF;
  if (::inotify_add_watch(inotify_fd_, options_.dir.c_str(), mask) < 0) {
    log_(CatalogLogLevel::kWarn, "cannot watch " + options_.dir + " with inotify (" +
                                     std::strerror(errno) + "); looking at it every " +
                                     std::to_string(options_.poll_interval.count()) + " ms");
    ::close(inotify_fd_);
    inotify_fd_ = -1;
    return false;
  }
  return true;
}

void FolderWatcher::wait(Clock::duration timeout) {
  const auto drain = [](int fd) {
    char buffer[4096];
    while (::read(fd, buffer, sizeof buffer) > 0) {
    }
  };
  pollfd fds[2] = {{wake_pipe_[0], POLLIN, 0}, {inotify_fd_, POLLIN, 0}};
  const nfds_t count = inotify_fd_ >= 0 ? 2 : 1;
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(timeout).count();
  const int ready = ::poll(fds, count, static_cast<int>(std::clamp<int64_t>(ms, 0, 60000)));
  if (ready <= 0 || stopping_) return;
  if (count == 2 && (fds[1].revents & POLLIN)) {
    // Gather the burst: wait until the folder has been quiet for a moment
    // (bounded, so a file written without pause is still looked at).
    const auto until = Clock::now() + 10 * kEventQuiet;
    drain(inotify_fd_);
    while (!stopping_ && Clock::now() < until) {
      pollfd more[2] = {{wake_pipe_[0], POLLIN, 0}, {inotify_fd_, POLLIN, 0}};
      if (::poll(more, 2, static_cast<int>(kEventQuiet.count())) <= 0) break;
      drain(inotify_fd_);
    }
  }
}

void FolderWatcher::warn_once(const std::string& line) {
  if (warned_.insert(line).second) log_(CatalogLogLevel::kWarn, line);
}

void FolderWatcher::run() {
  const bool inotify = options_.mode == WatchMode::kAuto && open_inotify();
  Clock::duration next = reconcile(true);
  if (first_scan_done_) first_scan_done_();
  if (options_.mode == WatchMode::kOff) return;
  log_(CatalogLogLevel::kInfo,
       "watching " + options_.dir + " for new, changed and removed files (" +
           (inotify ? std::string("inotify")
                    : "polling every " + std::to_string(options_.poll_interval.count()) + " ms") +
           ")");
  while (!stopping_) {
    wait(std::min<Clock::duration>(options_.poll_interval, next));
    if (stopping_) break;
    next = reconcile(false);
  }
}

Clock::duration FolderWatcher::reconcile(bool first) {
  const auto now = Clock::now();
  Clock::duration next = Clock::duration::max();
  auto scan = scan_models_folder(options_.dir);
  if (!scan) {
    warn_once(scan.error().message);
    return next;
  }
  for (const SkippedEntry& skipped : scan->skipped) {
    warn_once("skipped " + skipped.path + ": " + skipped.reason);
  }
  for (const NameClash& clash : scan->clashes) warn_once(describe(clash));

  std::map<std::string, FileVersion> wanted;  // name -> file as it is now
  auto want = [&](const std::vector<ModelFile>& files, bool hcs) {
    std::lock_guard lock(reserved_mutex_);
    for (const ModelFile& file : files) {
      struct stat st {};
      if (::stat(file.path.c_str(), &st) != 0) continue;  // gone since the listing
      if (options_.reserved.count(file.name)) {
        warn_once("skipped " + file.path + ": model name '" + file.name +
                  "' is taken by a demo model");
        continue;
      }
      wanted[file.name] = FileVersion{file.path, hcs, static_cast<int64_t>(st.st_size),
                                      int64_t(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec};
    }
  };
  want(scan->hcs, true);
  want(scan->meshes, false);

  // Listed by list_initial() but gone (or skipped) by the first scan.
  for (const std::string& name : prelisted_) {
    if (!wanted.count(name)) registry_.remove(name);
  }
  prelisted_.clear();
  // Withdraw what is gone (or now served from another file of that name).
  for (auto it = taken_.begin(); it != taken_.end();) {
    auto w = wanted.find(it->first);
    if (w != wanted.end() && w->second.path == it->second.path) {
      ++it;
      continue;
    }
    registry_.remove(it->first);
    log_(CatalogLogLevel::kInfo,
         "withdrawn " + it->first + ": " + it->second.path +
             (w == wanted.end() ? " was removed" : " no longer has that name"));
    it = taken_.erase(it);
  }

  // Follow each file's size and time; take it once they have settled.
  std::map<std::string, Seen> seen;
  for (const auto& [name, version] : wanted) {
    auto old = seen_.find(version.path);
    seen[version.path] =
        old != seen_.end() && old->second.version == version ? old->second : Seen{version, now};
  }
  seen_ = std::move(seen);
  for (const auto& [name, version] : wanted) {
    auto taken = taken_.find(name);
    if (taken != taken_.end() && taken->second == version) continue;
    const Seen& s = seen_[version.path];
    const auto settled_at = s.since + options_.settle;
    if (!first && now < settled_at) {
      next = std::min<Clock::duration>(next, settled_at - now);
      continue;
    }
    take(name, version, first);
  }
  return next;
}

void FolderWatcher::take(const std::string& name, const FileVersion& version, bool first) {
  std::shared_ptr<const CatalogModel> previous;
  const bool changed = taken_.count(name) != 0;
  if (changed) {
    const auto snapshot = registry_.snapshot();
    if (auto found = snapshot->find(name); found != snapshot->end()) previous = found->second.model;
    log_(CatalogLogLevel::kInfo,
         "changed " + version.path + ": re-encoding " + name +
             (previous ? " (its previous stream is served until then)" : ""));
  } else if (!first) {
    // (At the first scan every file is new: the encoders' lines say enough.)
    log_(CatalogLogLevel::kInfo, "new file " + version.path + ": listing it as " + name);
  }
  taken_[name] = version;
  const ModelFile file{version.path, name};
  if (!version.hcs) {
    pool_.submit(mesh_file_task(file, options_.cache_dir), std::move(previous));
    return;
  }
  // A .hcs is only read and checked (O(bytes), fast): here, not in the
  // pool, so it never waits behind an encode.
  ModelStatus status{
      name, "hcs", version.path, ModelState::kEncoding, 0, "checking", "", std::move(previous), 0};
  const uint64_t generation = registry_.put(std::move(status));
  auto model = load_hcs_file(file);
  if (!model) {
    const std::string reason = model.error().message;
    registry_.update(name, generation, [&](ModelStatus& s) {
      s.state = ModelState::kFailed;
      s.reason = reason;
      s.stage.clear();
      s.model = nullptr;
    });
    log_(CatalogLogLevel::kWarn, "failed " + name + ": " + reason);
    return;
  }
  auto ready = std::make_shared<const CatalogModel>(std::move(*model));
  registry_.update(name, generation, [&](ModelStatus& s) {
    s.state = ModelState::kReady;
    s.percent = 100;
    s.stage.clear();
    s.model = ready;
  });
  log_(CatalogLogLevel::kInfo, "ready " + name + ": checked " + version.path + ": " +
                                   std::to_string(ready->index.header.vertex_count) +
                                   " vertices, " + std::to_string(ready->stream().size()) +
                                   " bytes, " + std::to_string(ready->index.records.size()) +
                                   " records");
  if (ready->compact.coded.empty()) {
    log_(CatalogLogLevel::kWarn, name + ": its record index cannot be coded compactly (" +
                                     ready->compact.refused + "); its headers carry the arrays");
  }
}

}  // namespace meshstream::server

// The models a server offers while it runs: a thread-safe, changeable set
// in which every model has a state (queued, encoding with its percent,
// ready, failed with the reason). Readers take an immutable snapshot
// (a shared_ptr swapped under a mutex), so a session that streams a model
// keeps its bytes alive however the set changes meanwhile; writers (the
// encoder pool, the folder watcher) replace the snapshot, copy on write.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "proto/framing.h"
#include "server/catalog.h"

namespace meshstream::server {

enum class ModelState { kQueued, kEncoding, kReady, kFailed };

// "queued", "encoding", "ready", "failed": the words of the log, --list and
// the metrics.
const char* state_name(ModelState state);

struct ModelStatus {
  std::string name;    // what clients ask for
  std::string source;  // "hcs", "mesh" or "demo"
  std::string origin;  // file path or demo description, for messages
  ModelState state = ModelState::kQueued;
  double percent = 0;  // kEncoding: 0..100
  std::string stage;   // kEncoding: the encoder's stage
  std::string reason;  // kFailed: why, naming the input
  // The stream served: set when kReady, and while a changed file is queued
  // or re-encoded (its previous stream, served until the new one is ready).
  std::shared_ptr<const CatalogModel> model;
  // Which submission this entry is (ModelRegistry::put): an encode whose
  // entry was replaced or removed meanwhile finds another generation and
  // drops its result.
  uint64_t generation = 0;
};

// One immutable view of the set, sorted by name.
using ModelSnapshot = std::map<std::string, ModelStatus, std::less<>>;

struct StateCounts {
  size_t queued = 0, encoding = 0, ready = 0, failed = 0;
  size_t total() const { return queued + encoding + ready + failed; }
};

class ModelRegistry {
 public:
  ModelRegistry();

  // The current set; never null. O(1), one lock.
  std::shared_ptr<const ModelSnapshot> snapshot() const;

  // Inserts or replaces the entry for status.name, under a new generation
  // (returned). O(models).
  uint64_t put(ModelStatus status);
  // Applies `change` to the entry of `name` when its generation is still
  // `generation`; false (nothing changed) when it was replaced or removed.
  bool update(std::string_view name, uint64_t generation,
              const std::function<void(ModelStatus&)>& change);
  // Withdraws `name`; false when absent. Sessions streaming it keep their
  // snapshot (and its bytes) until they finish.
  bool remove(std::string_view name);

  // How many models are in each state (for logs and metrics).
  StateCounts counts() const;

 private:
  mutable std::mutex mutex_;
  std::shared_ptr<const ModelSnapshot> current_;
  uint64_t next_generation_ = 1;
};

StateCounts count_states(const ModelSnapshot& snapshot);

// The wire form of one entry (ModelInfo, proto/meshstream.proto): counts of
// the stream served (if any), state, percent, stage, reason.
v1::ModelInfo model_info(const ModelStatus& status);
// A ModelList frame of every entry, sorted by name.
std::vector<uint8_t> model_list_frame(const ModelSnapshot& snapshot);

}  // namespace meshstream::server

// The hand-over between the network thread (which feeds stream bytes into
// the incremental decoder as they arrive) and the display pipeline thread
// (which takes the newest decoded mesh whenever it is ready for another
// one). Latest wins: the network side never waits for the pipeline; the
// changes of every record applied meanwhile accumulate and are handed over
// together, so the pipeline copies only what changed into its own mirror.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "common/base/result.h"
#include "common/codec/decoder.h"
#include "common/mesh/mesh.h"

namespace meshstream::client {

// What changed in the decoded mesh since the pipeline last took it.
struct MeshChanges {
  bool full = false;               // everything (the base mesh arrived)
  std::vector<uint32_t> vertices;  // added vertices (may repeat)
  std::vector<uint32_t> faces;     // faces created or rewritten (may repeat)
  // Existing vertices that only moved (plane records, RecordDelta::
  // moved_vertices; may repeat): their positions changed, no face changed
  // its corners, so the faces around them changed shape only.
  std::vector<uint32_t> moved;
  void clear() {
    full = false;
    vertices.clear();
    faces.clear();
    moved.clear();
  }
};

// How the stream ended (set once by the network side).
struct StreamOutcome {
  bool ok = true;
  std::string reason;               // "complete", "budget" (ok) ...
  Error error{ErrorCode::kIo, ""};  // when !ok
};

// One take: the state of the decoder at that moment.
struct TakenUpdate {
  uint32_t records_decoded = 0;
  uint64_t bytes_decoded = 0;   // stream offset at the end of the last applied record
  uint64_t bytes_received = 0;  // stream bytes received so far (may be mid-record)
  uint32_t updates = 0;         // records applied since the previous take
  double decode_ms = 0;         // decoder time for those records
  bool ended = false;           // no further records will come
};

class DecodedStream {
 public:
  // ---- network side (one thread)
  // Feeds bytes at stream offset `offset` (must continue the stream);
  // applies completed records and records their changes. Never waits for
  // the pipeline, except at the barrier record (see set_barrier).
  Result<uint32_t> feed(std::span<const uint8_t> bytes);
  // Prepares for bytes starting at `offset` after a reconnect (a record
  // boundary the decoder reached, or 0).
  Status resume_at(uint64_t offset);
  // The last feed error left the decoded mesh untouched (bytes altered in
  // transit): reconnecting and resuming may succeed.
  bool error_is_recoverable() const;
  uint64_t resume_offset() const;
  uint32_t records_decoded() const;
  // From the stream's own index once its prefix arrived: (total bytes,
  // records); nullopt before.
  std::optional<std::pair<uint64_t, uint32_t>> index_summary() const;
  uint64_t bytes_received() const;
  void set_bytes_received(uint64_t offset);
  void finish(StreamOutcome outcome);
  // The network thread stops after applying record `record` until the
  // pipeline has taken it, so that exact state gets displayed (for
  // --snapshot-at). Call before streaming.
  void set_barrier(std::optional<uint32_t> record);

  // ---- pipeline side (one thread)
  // Blocks until there is something to take, the stream ended, a poke() or
  // stop(); returns false after stop().
  // `outcome_seen`: the caller already handled the end (do not wake for it).
  bool wait(uint64_t seen_pokes, bool outcome_seen, std::chrono::milliseconds max_wait);
  bool has_pending() const;
  // Copies what changed into `mirror` (which must hold the previous take)
  // and appends the changes to `changes`.
  TakenUpdate take(Mesh& mirror, MeshChanges& changes);
  std::optional<StreamOutcome> outcome() const;

  // ---- either side
  void poke();  // wake the pipeline (options changed)
  uint64_t pokes() const;
  void stop();  // wake and release everyone for good
  bool stopped() const;

 private:
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  IncrementalDecoder decoder_;
  MeshChanges pending_;
  uint32_t pending_updates_ = 0;
  double pending_decode_ms_ = 0;
  uint32_t taken_records_ = 0;
  uint64_t bytes_received_ = 0;
  std::optional<uint32_t> barrier_;
  std::optional<StreamOutcome> outcome_;
  uint64_t pokes_ = 0;
  bool stopped_ = false;
};

}  // namespace meshstream::client

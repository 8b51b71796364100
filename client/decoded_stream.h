// The hand-over between the network thread (which feeds stream bytes into
// the incremental decoder as they arrive) and the display pipeline thread
// (which takes the newest decoded mesh whenever it is ready for another
// one). Latest wins: the network side never waits for the pipeline; the
// changes of every record applied meanwhile accumulate and are handed over
// together, so the pipeline copies only what changed into the mesh it gives
// its next frame (a FrameMeshPool mesh, or a mirror of its own).
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "common/base/result.h"
#include "common/codec/decoder.h"
#include "common/mesh/mesh.h"

namespace meshstream::client {

class FrameMeshPool;

// What changed in the decoded mesh since the pipeline last took it.
struct MeshChanges {
  bool full = false;               // everything (the base mesh arrived)
  std::vector<uint32_t> vertices;  // added vertices (may repeat)
  std::vector<uint32_t> faces;     // faces created or rewritten (may repeat)
  // Existing vertices that only moved (plane records, RecordDelta::
  // moved_vertices; may repeat): their positions changed, no face changed
  // its corners, so the faces around them changed shape only.
  std::vector<uint32_t> moved;
  // Records arrived that may have changed the other arrays (normals,
  // colours, texture coordinates, materials: surface_attributes.h), or
  // that changed the textures (texture records, RecordDelta::
  // textures_changed). `full` implies both.
  bool attributes = false;
  bool textures = false;
  void clear() {
    full = false;
    vertices.clear();
    faces.clear();
    moved.clear();
    attributes = false;
    textures = false;
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

// One record the decoder applied, as the stream's own index describes it
// (the decoder checked the record against it): for `record` events.
struct AppliedRecord {
  uint32_t index = 0;
  uint64_t end_offset = 0;  // stream bytes up to the end of this record
  uint64_t bytes = 0;       // since the previous record's end (record 0: the
                            // container prefix and the base mesh)
  uint32_t vertices = 0;    // decoded mesh after this record (cumulative)
  uint32_t faces = 0;
  double decode_ms = 0;  // decoder time (shared evenly by the records of one feed)
};
using RecordObserver = std::function<void(const AppliedRecord&)>;

class DecodedStream {
 public:
  // ---- network side (one thread)
  // Feeds the next bytes of the stream (they must continue where the last
  // feed, or resume_at, left off); applies completed records and records
  // their changes. Never waits for the pipeline, except at a barrier record
  // (see set_barriers).
  Result<uint32_t> feed(std::span<const uint8_t> bytes);
  // Called by feed for every record it applies, in order, on the network
  // thread, before the pipeline can take that record (so a consumer sees a
  // record reported before any display update that shows it). Runs under
  // this object's lock: keep it short, and do not call back into it. Set
  // before streaming.
  void on_record(RecordObserver observer);
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
  // The stream's own header once its prefix arrived (the encoder's ASA
  // guidance is in it: asa_guidance.h); nullopt before.
  std::optional<StreamHeader> stream_header() const;
  uint64_t bytes_received() const;
  void set_bytes_received(uint64_t offset);
  void finish(StreamOutcome outcome);
  // The network thread stops after applying any of `records` until the
  // pipeline has taken that state, so that exact record gets displayed (for
  // --snapshot-at, --out-every and --out-at: which records are shown then
  // does not depend on timing). Call before streaming.
  void set_barriers(std::vector<uint32_t> records);
  void set_barrier(std::optional<uint32_t> record);  // one record, or none

  // ---- pipeline side (one thread)
  // Blocks until there is something to take, the stream ended, a poke() or
  // stop(); returns false after stop().
  // `outcome_seen`: the caller already handled the end (do not wake for it).
  bool wait(uint64_t seen_pokes, bool outcome_seen, std::chrono::milliseconds max_wait);
  bool has_pending() const;
  // Copies what changed into `mirror` (which must hold the previous take)
  // and appends the changes to `changes`.
  TakenUpdate take(Mesh& mirror, MeshChanges& changes);
  // The same without a mirror: `mesh` becomes a mesh of `pool` equal to the
  // decoded mesh, brought up to date with only what changed since it was
  // last given out where the pool can (frame_mesh_pool.h). The pipeline's
  // way: no private copy of the whole mesh besides the frames' own.
  TakenUpdate take(FrameMeshPool& pool, std::shared_ptr<const Mesh>& mesh, MeshChanges& changes);
  std::optional<StreamOutcome> outcome() const;

  // ---- either side
  void poke();  // wake the pipeline (options changed)
  uint64_t pokes() const;
  void stop();  // wake and release everyone for good
  bool stopped() const;

 private:
  // Calls record_observer_ for the `applied` records after the first
  // `before` (mutex_ held).
  void report_records(uint32_t before, uint32_t applied, double ms);
  // The bookkeeping of a take (mutex_ held): appends pending_ to `changes`,
  // clears it and says what was taken.
  TakenUpdate hand_over_pending(MeshChanges& changes);

  mutable std::mutex mutex_;
  std::condition_variable changed_;
  IncrementalDecoder decoder_;
  MeshChanges pending_;
  uint32_t pending_updates_ = 0;
  double pending_decode_ms_ = 0;
  uint32_t taken_records_ = 0;
  uint64_t bytes_received_ = 0;
  std::vector<uint32_t> barriers_;  // sorted, unique
  RecordObserver record_observer_;
  std::optional<StreamOutcome> outcome_;
  uint64_t pokes_ = 0;
  bool stopped_ = false;
};

}  // namespace meshstream::client

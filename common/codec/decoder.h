// Incremental decoding of an `.hcs` stream: feed bytes in pieces of any size
// (a network read may end anywhere); each record is applied as soon as its
// last byte arrives. The decoder never trusts its input: a bad stream yields
// an error and leaves the last good mesh intact.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "common/base/result.h"
#include "common/codec/budget.h"
#include "common/codec/container.h"
#include "common/mesh/mesh.h"

namespace meshstream {

// Which vertices and faces one record changed, so a post-processor (ASA) can
// redo only that region. Indices refer to the mesh after the record.
struct RecordDelta {
  uint32_t record = 0;
  std::vector<uint32_t> added_vertices;
  std::vector<uint32_t> touched_faces;  // faces created or rewritten
  bool full_rebuild = false;            // e.g. the base mesh: everything changed
  // Existing vertices whose position changed (a plane record of an embedded
  // stream sharpened them): refresh their positions and the faces around
  // them. Empty for records that only insert. A plane record's delta also
  // sets full_rebuild, so a consumer that predates this field refreshes
  // everything (correct, slower); one that knows it can take a delta with
  // moved vertices and no added vertices as a position update of exactly
  // those vertices (no face changes its corners).
  std::vector<uint32_t> moved_vertices;
  // A texture record: mesh().textures changed (a texture arrived, or a
  // larger level of it replaced the one shown). No vertex or face changed.
  bool textures_changed = false;
};

// What the decoder keeps of the decoded mesh as records arrive.
enum class DecodedMeshUpkeep {
  // mesh() is the mesh after the last applied record, updated by each
  // record's changes only, and stays the last good mesh after an error: for
  // consumers that show or hand over the mesh while it streams.
  kEveryRecord,
  // No output mesh while decoding: mesh() stays empty and release_mesh()
  // builds the mesh once, from the decoder's own state (its triangles are
  // moved out, not copied). For one-shot decodes that write the mesh at the
  // end (the decode tool, decode_hcs): no second copy of the triangles is
  // written record by record, and none is held in memory. Its deltas list
  // no vertices or faces and say full_rebuild (nothing tracks the changes).
  kOnRelease,
};

class IncrementalDecoder {
 public:
  explicit IncrementalDecoder(DecodedMeshUpkeep upkeep = DecodedMeshUpkeep::kEveryRecord);
  ~IncrementalDecoder();
  IncrementalDecoder(IncrementalDecoder&&) noexcept;
  IncrementalDecoder& operator=(IncrementalDecoder&&) noexcept;

  // Appends bytes and applies every record they complete. Returns how many
  // records were applied by this call. After an error, further feeds fail
  // with the same error; mesh() keeps the last good state.
  Result<uint32_t> feed(std::span<const uint8_t> bytes);

  // Null until magic, header and index have arrived.
  const StreamIndex* index() const;
  // Records applied so far (0 until the base mesh is complete).
  uint32_t records_decoded() const;
  // Bytes consumed up to the end of the last applied record: the offset to
  // resume from after a lost connection.
  uint64_t resume_offset() const;
  // True once every record of the stream is applied.
  bool finished() const;

  // The current mesh: dequantized positions and triangles (kEveryRecord;
  // empty with kOnRelease), and the textures received so far (each the
  // largest level of it that arrived: a small preview first, the original
  // image at last; texture_record.h).
  const Mesh& mesh() const;
  // The mesh after the last applied record, moved out of the decoder, which
  // is spent afterwards (further feeds fail). kTruncated before the base
  // mesh; with kOnRelease, the feed's error after a record failed to apply
  // (its half-applied state holds no good mesh; a checksum failure, found
  // before applying, still leaves one). O(mesh) with kOnRelease (positions
  // dequantized once), O(1) with kEveryRecord.
  Result<Mesh> release_mesh();
  // What each record the last feed() applied changed, in order: one delta a
  // record, empty when that call completed none (feed clears them first).
  const std::vector<RecordDelta>& last_deltas() const;
  // Per texture of mesh().textures: whether the level shown is the
  // original image (else a smaller level of the pyramid).
  const std::vector<bool>& textures_original() const;

  // True after an error that left the decoded state untouched: a record
  // that failed its checksum (checked before it is applied) or a damaged
  // index. Bytes altered in transit are such errors; fetching them again
  // from resume_offset() may succeed.
  bool error_is_recoverable() const;

  // Applies one record given alone, as a ranged request delivers it
  // (StreamRequest.records: the server sends what it is asked, in any
  // order). Needs the index (the container prefix fed first). Refuses,
  // without changing anything, a record already applied, one past the last,
  // bytes that are not the record's size, and a record before its needs: a
  // record of today's streams needs every record before it, so only record
  // records_decoded() applies. Otherwise as feed() of exactly those bytes
  // (a checksum failure is recoverable). Returns 1.
  Result<uint32_t> feed_record(uint32_t record, std::span<const uint8_t> bytes);

  // The caller feeds no bytes past `end` (a prefix it measures, the base
  // alone): the arrays are reserved for the records that end within it, not
  // for the whole stream. Capacity only: bytes past it still decode.
  void expect_prefix(uint64_t end);

  // Starts over from a resume offset: the caller feeds bytes starting at
  // `offset`, which must be a record boundary this decoder has reached.
  // Clears a recoverable error; any other error is returned again.
  Status resume_at(uint64_t offset);

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// Decodes a whole stream (or the prefix given). Convenience over
// IncrementalDecoder for tools and tests.
Result<Mesh> decode_hcs(std::span<const uint8_t> stream);

// The prefix length (a record boundary) to decode for a budget, following
// HCS's decoder controls. DecodeBudget is the shared Budget
// (common/codec/budget.h), the name kept for the codec's callers.
using DecodeBudget = Budget;
// The largest record boundary within the budget (at least the base mesh).
// kPercentBytes is kBytes of floor(total * P / 100), as the server counts
// the wire's Budget.percent. Values outside budget_problem's rule are not
// refused here (a ratio <= 0 gives the base mesh). O(records).
uint64_t prefix_for_budget(const StreamIndex& index, const DecodeBudget& budget);

}  // namespace meshstream

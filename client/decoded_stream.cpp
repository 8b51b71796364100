#include "client/decoded_stream.h"

#include <algorithm>

#include "client/frame_mesh_pool.h"
#include "client/surface_attributes.h"

namespace meshstream::client {

using Clock = std::chrono::steady_clock;

Result<uint32_t> DecodedStream::feed(std::span<const uint8_t> bytes) {
  std::unique_lock lock(mutex_);
  // Decoding runs under the lock: the pipeline only holds it to copy the
  // (small) changes, never while running ASA.
  const auto start = Clock::now();
  const uint32_t before = decoder_.records_decoded();
  auto applied = decoder_.feed(bytes);
  const double ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  if (!applied) return applied;
  if (*applied == 0) return applied;
  if (record_observer_) report_records(before, *applied, ms);
  for (const RecordDelta& d : decoder_.last_deltas()) {
    // A plane record's delta sets full_rebuild for consumers that predate
    // moved_vertices; with no vertex added and no face touched it is a
    // position update of exactly the moved vertices (decoder.h).
    const bool moves_only =
        !d.moved_vertices.empty() && d.added_vertices.empty() && d.touched_faces.empty();
    if (d.full_rebuild && !moves_only) {
      pending_.clear();
      pending_.full = true;
    } else if (!pending_.full) {
      pending_.vertices.insert(pending_.vertices.end(), d.added_vertices.begin(),
                               d.added_vertices.end());
      pending_.faces.insert(pending_.faces.end(), d.touched_faces.begin(), d.touched_faces.end());
      pending_.moved.insert(pending_.moved.end(), d.moved_vertices.begin(), d.moved_vertices.end());
    }
    pending_.attributes = true;
    pending_.textures = pending_.textures || d.textures_changed;
  }
  // Past one entry per face, copying the whole mesh is cheaper than the
  // list (and the list would grow without bound behind a slow pipeline).
  if (!pending_.full && pending_.faces.size() + pending_.vertices.size() + pending_.moved.size() >
                            decoder_.mesh().triangles.size()) {
    pending_.clear();
    pending_.full = true;
  }
  if (pending_.full) pending_.attributes = pending_.textures = true;
  pending_updates_ += *applied;
  pending_decode_ms_ += ms;
  lock.unlock();
  changed_.notify_all();
  // A barrier among the records just applied: wait until the pipeline took
  // this state (it holds that record, and no later one).
  const uint32_t after = before + *applied;
  const auto barrier = std::lower_bound(barriers_.begin(), barriers_.end(), before);
  if (barrier != barriers_.end() && *barrier < after) {
    lock.lock();
    changed_.wait(lock, [&] { return stopped_ || taken_records_ >= after; });
  }
  return applied;
}

void DecodedStream::report_records(uint32_t before, uint32_t applied, double ms) {
  const StreamIndex* index = decoder_.index();
  for (uint32_t i = before; i < before + applied; ++i) {
    AppliedRecord r;
    r.index = i;
    r.decode_ms = ms / applied;
    if (index && i < index->records.size()) {
      const RecordEntry& e = index->records[i];
      r.end_offset = e.offset + e.size;
      r.bytes = i == 0 ? r.end_offset : e.size;
      r.vertices = e.vertices;
      r.faces = e.faces;
    }
    if (i + 1 == before + applied) {  // the newest: the mesh itself
      r.end_offset = decoder_.resume_offset();
      r.vertices = decoder_.mesh().vertex_count();
      r.faces = decoder_.mesh().face_count();
    }
    record_observer_(r);
  }
}

void DecodedStream::on_record(RecordObserver observer) {
  std::lock_guard lock(mutex_);
  record_observer_ = std::move(observer);
}

Status DecodedStream::resume_at(uint64_t offset) {
  std::lock_guard lock(mutex_);
  bytes_received_ = offset;
  return decoder_.resume_at(offset);
}

bool DecodedStream::error_is_recoverable() const {
  std::lock_guard lock(mutex_);
  return decoder_.error_is_recoverable();
}

uint64_t DecodedStream::resume_offset() const {
  std::lock_guard lock(mutex_);
  return decoder_.resume_offset();
}

uint32_t DecodedStream::records_decoded() const {
  std::lock_guard lock(mutex_);
  return decoder_.records_decoded();
}

std::optional<StreamHeader> DecodedStream::stream_header() const {
  std::lock_guard lock(mutex_);
  const StreamIndex* index = decoder_.index();
  if (!index) return std::nullopt;
  return index->header;
}

std::optional<std::pair<uint64_t, uint32_t>> DecodedStream::index_summary() const {
  std::lock_guard lock(mutex_);
  const StreamIndex* index = decoder_.index();
  if (!index) return std::nullopt;
  return std::make_pair(index->total_bytes(), static_cast<uint32_t>(index->records.size()));
}

uint64_t DecodedStream::bytes_received() const {
  std::lock_guard lock(mutex_);
  return bytes_received_;
}

void DecodedStream::set_bytes_received(uint64_t offset) {
  std::lock_guard lock(mutex_);
  bytes_received_ = offset;
}

void DecodedStream::finish(StreamOutcome outcome) {
  {
    std::lock_guard lock(mutex_);
    if (!outcome_) outcome_ = std::move(outcome);
  }
  changed_.notify_all();
}

void DecodedStream::set_barriers(std::vector<uint32_t> records) {
  std::sort(records.begin(), records.end());
  records.erase(std::unique(records.begin(), records.end()), records.end());
  std::lock_guard lock(mutex_);
  barriers_ = std::move(records);
}

void DecodedStream::set_barrier(std::optional<uint32_t> record) {
  set_barriers(record ? std::vector<uint32_t>{*record} : std::vector<uint32_t>{});
}

bool DecodedStream::wait(uint64_t seen_pokes, bool outcome_seen,
                         std::chrono::milliseconds max_wait) {
  std::unique_lock lock(mutex_);
  changed_.wait_for(lock, max_wait, [&] {
    return stopped_ || pending_updates_ > 0 || (outcome_.has_value() && !outcome_seen) ||
           pokes_ != seen_pokes;
  });
  return !stopped_;
}

bool DecodedStream::has_pending() const {
  std::lock_guard lock(mutex_);
  return pending_updates_ > 0;
}

TakenUpdate DecodedStream::take(Mesh& mirror, MeshChanges& changes) {
  TakenUpdate u;
  {
    std::lock_guard lock(mutex_);
    const Mesh& m = decoder_.mesh();
    if (pending_.full) {
      mirror.positions = m.positions;
      mirror.triangles = m.triangles;
    } else {
      mirror.positions.resize(m.positions.size());
      mirror.triangles.resize(m.triangles.size());
      for (uint32_t v : pending_.vertices) mirror.positions[v] = m.positions[v];
      for (uint32_t v : pending_.moved) mirror.positions[v] = m.positions[v];
      for (uint32_t f : pending_.faces) mirror.triangles[f] = m.triangles[f];
    }
    if (pending_.full || pending_.attributes)
      copy_surface_attributes(m, mirror, pending_.full || pending_.textures);
    u = hand_over_pending(changes);
  }
  changed_.notify_all();  // releases a network thread waiting at the barrier
  return u;
}

TakenUpdate DecodedStream::take(FrameMeshPool& pool, std::shared_ptr<const Mesh>& mesh,
                                MeshChanges& changes) {
  TakenUpdate u;
  {
    std::lock_guard lock(mutex_);
    // The final size as the stream's index gives it, bounded as the
    // decoder bounds its own reservation (decoder.cpp: every inserted vertex
    // costs well over a bit), so a hostile index cannot make us reserve
    // gigabytes.
    if (const StreamIndex* index = decoder_.index(); index && !index->records.empty()) {
      const uint64_t plausible = uint64_t(index->header.base_vertex_count) + 8 * bytes_received_;
      const RecordEntry& last = index->records.back();
      pool.expect(static_cast<uint32_t>(std::min<uint64_t>(last.vertices, plausible)),
                  static_cast<uint32_t>(std::min<uint64_t>(
                      last.faces, 2 * plausible + uint64_t(index->header.base_face_count))));
    }
    // pending_ is what changed in the decoder's mesh since the last take:
    // the pool's meshes follow it by those changes alone.
    mesh = pool.share(decoder_.mesh(), pending_);
    u = hand_over_pending(changes);
  }
  changed_.notify_all();  // releases a network thread waiting at the barrier
  return u;
}

TakenUpdate DecodedStream::hand_over_pending(MeshChanges& changes) {
  TakenUpdate u;
  if (pending_.full) {
    changes.clear();
    changes.full = true;
  } else if (!changes.full) {
    changes.vertices.insert(changes.vertices.end(), pending_.vertices.begin(),
                            pending_.vertices.end());
    changes.faces.insert(changes.faces.end(), pending_.faces.begin(), pending_.faces.end());
    changes.moved.insert(changes.moved.end(), pending_.moved.begin(), pending_.moved.end());
  }
  changes.attributes = changes.attributes || pending_.attributes || pending_.full;
  changes.textures = changes.textures || pending_.textures || pending_.full;
  pending_.clear();
  u.records_decoded = decoder_.records_decoded();
  u.bytes_decoded = decoder_.resume_offset();
  u.bytes_received = bytes_received_;
  u.updates = pending_updates_;
  u.decode_ms = pending_decode_ms_;
  u.ended = outcome_.has_value();
  pending_updates_ = 0;
  pending_decode_ms_ = 0;
  taken_records_ = u.records_decoded;
  return u;
}

std::optional<StreamOutcome> DecodedStream::outcome() const {
  std::lock_guard lock(mutex_);
  return outcome_;
}

void DecodedStream::poke() {
  {
    std::lock_guard lock(mutex_);
    ++pokes_;
  }
  changed_.notify_all();
}

uint64_t DecodedStream::pokes() const {
  std::lock_guard lock(mutex_);
  return pokes_;
}

void DecodedStream::stop() {
  {
    std::lock_guard lock(mutex_);
    stopped_ = true;
  }
  changed_.notify_all();
}

bool DecodedStream::stopped() const {
  std::lock_guard lock(mutex_);
  return stopped_;
}

}  // namespace meshstream::client

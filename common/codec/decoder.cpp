// Incremental decoder: see decoder.h. Bytes are buffered only until the
// record they belong to is complete; each complete record is checked against
// its CRC (version 3: its trailer), decoded without the trailer, applied,
// and its bytes dropped.
#include "common/codec/decoder.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <string>
#include <utility>

#include "common/codec/attribute_codec.h"
#include "common/codec/base_coder.h"
#include "common/codec/quantize.h"
#include "common/codec/refinement_codec.h"
#include "common/codec/stream_format.h"
#include "common/codec/texture_record.h"

namespace meshstream {

namespace {

// QuantGrid::dequantize's arithmetic with its step computed once instead of
// per vertex (same doubles, same floats).
struct Dequantizer {
  explicit Dequantizer(const QuantGrid& grid) : step(grid.step()), lo(grid.bounds.min) {}
  Vec3f operator()(Vec3i q) const {
    return Vec3f{static_cast<float>(double(lo.x) + q.x * step),
                 static_cast<float>(double(lo.y) + q.y * step),
                 static_cast<float>(double(lo.z) + q.z * step)};
  }
  double step;
  Vec3f lo;
};

}  // namespace

struct IncrementalDecoder::State {
  std::vector<uint8_t> buffer;  // stream bytes [buffer_start, stream_pos)
  uint64_t buffer_start = 0;
  uint64_t stream_pos = 0;
  std::optional<StreamIndex> index;
  QuantGrid grid;
  uint32_t records_done = 0;
  std::optional<RefinementState> refine;
  AttributeDecoder attributes;  // attribute_codec.h: active once record 1 carried them
  DecodedMeshUpkeep upkeep = DecodedMeshUpkeep::kEveryRecord;
  Mesh mesh;  // kEveryRecord: the output, record by record
  std::vector<RecordDelta> deltas;
  std::optional<Error> error;
  RefinementFormatInfo format;  // of the stream, from its header (check_header)
  int base_shift = 0;
  // The error left the decoded state as it was (damaged index, a record
  // that failed its checksum before being applied): fetching the bytes again
  // may succeed, so resume_at clears it.
  bool error_recoverable = false;
  // Texture records (texture_record.h): the textures so far, the level of
  // each and whether it is the original (nothing may follow it).
  std::vector<Texture> textures;
  std::vector<uint32_t> texture_level;
  std::vector<bool> texture_original;

  uint32_t reserved_vertices = 0;    // the vertex count the arrays were last reserved for
  uint64_t prefix_end = UINT64_MAX;  // the caller feeds no bytes past this (expect_prefix)

  // The counts after the last record that ends within the caller's prefix
  // (expect_prefix): the whole stream's unless one was set.
  std::pair<uint32_t, uint32_t> final_counts() const {
    const StreamHeader& h = index->header;
    if (prefix_end >= index->total_bytes()) return {h.vertex_count, h.face_count};
    const auto& records = index->records;
    const auto after = std::upper_bound(
        records.begin(), records.end(), prefix_end,
        [](uint64_t end, const RecordEntry& r) { return end < r.offset + r.size; });
    if (after == records.begin()) return {h.base_vertex_count, h.base_face_count};
    return {std::prev(after)->vertices, std::prev(after)->faces};
  }

  // Reserves the per-vertex and per-face arrays for the final size (of the
  // caller's prefix, expect_prefix), but never more than the bytes received
  // so far could describe (every inserted vertex costs well over a bit):
  // neither a hostile header nor a hostile index (records claiming a
  // gigabyte each that never come) can make us allocate gigabytes. A whole
  // stream fed at once reserves its final size with the base. A streamed
  // one reserves again as its bytes arrive (feed), in steps of at least
  // twice the last one or straight to the final size, instead of letting
  // every array grow by doubling: that copied them about twice over and
  // faulted in their pages twice, work an offline decode never does.
  void reserve_for_received() {
    const StreamHeader& h = index->header;
    const auto [final_vertices, final_faces] = final_counts();
    const uint64_t received = std::min<uint64_t>(index->total_bytes(), stream_pos);
    const uint64_t plausible = uint64_t(h.base_vertex_count) + 8 * received;
    const uint32_t nv = static_cast<uint32_t>(std::min<uint64_t>(final_vertices, plausible));
    if (nv <= reserved_vertices ||
        (nv < final_vertices && uint64_t(nv) < 2 * uint64_t(reserved_vertices)))
      return;
    const uint32_t nf =
        static_cast<uint32_t>(std::min<uint64_t>(final_faces, 2 * plausible + h.base_face_count));
    reserved_vertices = nv;
    refine->mesh.reserve(nv, nf);
    refine->vertices.reserve(nv);
    refine->vertex_layer.reserve(nv);
    refine->vertex_shift.reserve(nv);
    // The successive-approximation state (28 bytes a vertex).
    if (format.embedded) refine->geometry.reserve(nv);
    if (upkeep == DecodedMeshUpkeep::kEveryRecord) {
      mesh.positions.reserve(nv);
      mesh.triangles.reserve(nf);
    }
  }

  uint64_t consumed_end() const {
    if (!index) return 0;
    if (records_done == 0) return index->payload_offset;
    const RecordEntry& r = index->records[records_done - 1];
    return r.offset + r.size;
  }

  // Bytes fed next start at `offset`, a record boundary reached: whatever
  // the buffer held is dropped and a recoverable error cleared.
  void restart_at(uint64_t offset) {
    error.reset();
    error_recoverable = false;
    buffer.clear();
    buffer_start = offset;
    stream_pos = offset;
  }

  // `e` with the record it concerns named first.
  Error about_record(uint32_t i, const Error& e) const {
    return Error{e.code, "record " + std::to_string(i) + " of " +
                             std::to_string(index->records.size()) + ": " + e.message};
  }

  Status check_header() {
    const StreamHeader& h = index->header;
    if (h.quant_bits < kMinQuantBits || h.quant_bits > kMaxQuantBits) {
      return make_error(ErrorCode::kCorrupt, "stream header has quantization bits " +
                                                 std::to_string(h.quant_bits) + " (8..20 allowed)");
    }
    if (!known_base_coder(h.base_coder)) {
      return make_error(ErrorCode::kUnsupported,
                        "unknown base mesh coder " + std::to_string(h.base_coder));
    }
    const auto known =
        h.extra.empty() ? std::nullopt : RefinementFormatInfo::from_header_byte(h.extra[0]);
    if (!known) return make_error(ErrorCode::kUnsupported, "unknown refinement record format");
    format = *known;
    if (h.structure_coder != kStructureCoderRange || h.geometry_coder != format.geometry_coder()) {
      return make_error(ErrorCode::kUnsupported, "unknown refinement coder ids");
    }
    base_shift = 0;
    if (format.embedded) {
      if (h.extra.size() < 2 || h.extra[1] > kMaxBaseShift || h.extra[1] >= h.quant_bits) {
        return make_error(ErrorCode::kCorrupt, "stream header has no valid base shift");
      }
      base_shift = h.extra[1];
    }
    for (float f : {h.bounds.min.x, h.bounds.min.y, h.bounds.min.z, h.bounds.max.x, h.bounds.max.y,
                    h.bounds.max.z}) {
      if (!std::isfinite(f))
        return make_error(ErrorCode::kCorrupt, "stream bounding box is not finite");
    }
    const RecordEntry& r0 = index->records[0];
    if (r0.vertices != h.base_vertex_count || r0.faces != h.base_face_count) {
      return make_error(ErrorCode::kCorrupt, "base record counts differ from the header's");
    }
    // Every refinement adds vertices, and one or two faces per vertex.
    for (size_t i = 1; i < index->records.size(); ++i) {
      const RecordEntry& r = index->records[i];
      const RecordEntry& q = index->records[i - 1];
      const uint64_t added = uint64_t(r.vertices) - q.vertices;
      if (uint64_t(r.faces) < uint64_t(q.faces) + added ||
          uint64_t(r.faces) > uint64_t(q.faces) + 2 * added) {
        return make_error(ErrorCode::kCorrupt, "record " + std::to_string(i) +
                                                   " counts break 1..2 faces per added vertex");
      }
    }
    grid.bounds = h.bounds;
    grid.bits = h.quant_bits;
    return {};
  }

  uint32_t known_attribute_vertices = 0;  // kEveryRecord: vertices whose values mesh has
  uint32_t geometry_records = 0;          // structure and plane records applied
  bool attributes_final = false;          // the final attribute record came

  // The base's attributes, before any geometry record (only texture records
  // may come between it and the base); a values record, after geometry
  // records, with the exact values of the vertices inserted since the last
  // one; or the remaining vertices' values, after every geometry record
  // (only texture records may follow).
  Status apply_attribute_record(std::span<const uint8_t> payload) {
    const StreamHeader& h = index->header;
    const uint8_t part = payload.size() >= 2 ? payload[1] : 0xFF;
    if (part == kAttributePartBase) {
      if (geometry_records > 0)
        return make_error(ErrorCode::kParse, "base attribute record after a geometry record");
      if (auto s = attributes.read_base(payload, refine->mesh); !s) return s;
    } else if (part == kAttributePartValues || part == kAttributePartValuesLateNormals) {
      if (attributes_final)
        return make_error(ErrorCode::kParse, "attribute values record after the final one");
      if (auto s = attributes.read_values(payload, refine->mesh); !s) return s;
    } else if (part == kAttributePartLowBits) {
      if (attributes_final)
        return make_error(ErrorCode::kParse, "attribute low-bits record after the final one");
      if (auto s = attributes.read_low_bits(payload); !s) return s;
    } else if (part == kAttributePartNormals) {
      if (attributes_final)
        return make_error(ErrorCode::kParse, "attribute normals record after the final one");
      if (refine->mesh.vertex_count() != h.vertex_count ||
          refine->mesh.face_slot_count() != h.face_count)
        return make_error(ErrorCode::kParse, "normals record before the mesh is complete");
      if (auto s = attributes.read_normals(payload, refine->mesh); !s) return s;
    } else {
      if (attributes_final) return make_error(ErrorCode::kParse, "a second final attribute record");
      if (refine->mesh.vertex_count() != h.vertex_count ||
          refine->mesh.face_slot_count() != h.face_count)
        return make_error(ErrorCode::kParse, "final attribute record before the mesh is complete");
      if (auto s = attributes.read_final(payload, refine->mesh); !s) return s;
      attributes_final = true;
    }
    if (upkeep == DecodedMeshUpkeep::kEveryRecord) {
      attributes.preview(refine->mesh);
      attributes.refresh_normal_previews(refine->mesh);
      attributes.write_mesh(refine->mesh, mesh);
      known_attribute_vertices = refine->mesh.vertex_count();
    }
    return {};
  }

  // A texture record: checked (texture_record.h), then its image replaces
  // the texture's smaller level. Levels of a texture only grow, textures
  // are numbered in order of arrival, and the record adds nothing else.
  Status apply_texture_record(uint32_t i, std::span<const uint8_t> payload, RecordDelta& delta) {
    const RecordEntry& rec = index->records[i];
    const RecordEntry& before = index->records[i - 1];
    if (rec.vertices != before.vertices || rec.faces != before.faces) {
      return make_error(ErrorCode::kParse, "texture record where the index says the mesh grows");
    }
    auto level = read_texture_record(payload);
    if (!level) return tl::unexpected(level.error());
    const uint32_t t = level->texture;
    const std::string what = "texture " + std::to_string(t) + " (\"" + level->name + "\") level " +
                             std::to_string(level->level);
    if (t > textures.size()) {
      return make_error(ErrorCode::kParse, what + ": textures " + std::to_string(textures.size()) +
                                               ".." + std::to_string(t - 1) +
                                               " have not come yet (textures come in order)");
    }
    if (t < textures.size()) {
      if (texture_original[t]) {
        return make_error(ErrorCode::kParse, what + ": comes after the original image");
      }
      if (level->level <= texture_level[t]) {
        return make_error(ErrorCode::kParse,
                          what + ": level " + std::to_string(texture_level[t]) + " came already");
      }
      if (level->name != textures[t].name) {
        return make_error(ErrorCode::kParse,
                          what + ": an earlier level is named \"" + textures[t].name + "\"");
      }
    } else {
      textures.emplace_back();
      texture_level.push_back(0);
      texture_original.push_back(false);
    }
    textures[t].name = level->name;
    textures[t].mime_type = mime_type_of(level->format);
    textures[t].bytes = std::move(level->bytes);
    texture_level[t] = level->level;
    texture_original[t] = level->original;
    if (upkeep == DecodedMeshUpkeep::kEveryRecord) {
      mesh.textures = textures;
      // The materials' indices of textures that had not come are valid now.
      attributes.write_materials(mesh);
    }
    delta.textures_changed = true;
    return {};
  }

  Status apply_record(uint32_t i, std::span<const uint8_t> payload) {
    const RecordEntry& rec = index->records[i];
    const StreamHeader& h = index->header;
    auto where = [&](const Error& e) { return tl::unexpected(about_record(i, e)); };
    // The caller (feed) has checked the record's CRC-32.
    RecordDelta delta;
    delta.record = i;
    if (i == 0) {
      const int coarse_bits = h.quant_bits - base_shift;
      auto base = decode_base(h.base_coder, payload, rec.vertices, rec.faces, coarse_bits);
      if (!base) return where(base.error());
      auto state =
          RefinementState::from_coarse_base(base->positions, base->faces, h.quant_bits, base_shift);
      if (!state) return where(state.error());
      refine = std::move(*state);
      refine->format = format;
      mesh = Mesh{};
      reserved_vertices = 0;
      reserve_for_received();
      if (upkeep == DecodedMeshUpkeep::kEveryRecord) {
        mesh.positions.resize(base->positions.size());
        for (size_t v = 0; v < base->positions.size(); ++v) {
          mesh.positions[v] = grid.dequantize(refine->mesh.positions()[v]);
        }
        mesh.triangles = base->faces;
      }
      delta.full_rebuild = true;
      if (upkeep == DecodedMeshUpkeep::kEveryRecord) {
        delta.added_vertices.resize(base->positions.size());
        for (uint32_t v = 0; v < delta.added_vertices.size(); ++v) delta.added_vertices[v] = v;
        delta.touched_faces.resize(base->faces.size());
        for (uint32_t f = 0; f < delta.touched_faces.size(); ++f) delta.touched_faces[f] = f;
      }
    } else if (!payload.empty() && payload[0] == kRecordAttributes) {
      if (auto s = apply_attribute_record(payload); !s) return where(s.error());
      delta.full_rebuild = true;
    } else if (!payload.empty() && payload[0] == kRecordTexture) {
      if (auto st = apply_texture_record(i, payload, delta); !st) return where(st.error());
    } else {
      if (attributes_final) {
        return where({ErrorCode::kParse, "a geometry record after the final attribute record"});
      }
      ++geometry_records;
      AppliedRecord applied;
      // Without an output mesh nobody follows the changes: the lists would
      // only grow (a whole stream fed at once keeps every record's delta).
      applied.record_changes = upkeep == DecodedMeshUpkeep::kEveryRecord;
      if (auto s = apply_refinement_record(*refine, payload, rec.vertices, rec.faces, applied);
          !s) {
        return where(s.error());
      }
      if (refine->layer > h.layer_count) {
        return where({ErrorCode::kCorrupt,
                      "more layers than the header's " + std::to_string(h.layer_count)});
      }
      if (upkeep == DecodedMeshUpkeep::kEveryRecord) {
        const auto& positions = refine->mesh.positions();
        const Dequantizer dequantize(grid);
        for (uint32_t v : applied.added_vertices) {
          if (v >= mesh.positions.size()) mesh.positions.resize(v + 1);
          mesh.positions[v] = dequantize(positions[v]);
        }
        for (uint32_t v : applied.moved_vertices) mesh.positions[v] = dequantize(positions[v]);
        mesh.triangles.resize(refine->mesh.face_slot_count());
        for (uint32_t f : applied.touched_faces) mesh.triangles[f] = refine->mesh.faces()[f];
        if (attributes.active()) {
          // Inserted vertices show their predicted values until the last record.
          const uint32_t known = known_attribute_vertices;
          attributes.preview(refine->mesh);
          attributes.update_mesh(refine->mesh, known, applied.touched_faces, mesh);
          known_attribute_vertices = refine->mesh.vertex_count();
        }
      }
      delta.added_vertices = std::move(applied.added_vertices);
      delta.touched_faces = std::move(applied.touched_faces);
      delta.moved_vertices = std::move(applied.moved_vertices);
      // Plane records: see RecordDelta; no lists: nothing says what changed.
      delta.full_rebuild = !delta.moved_vertices.empty() || !applied.record_changes;
    }
    deltas.push_back(std::move(delta));
    return {};
  }
};

IncrementalDecoder::IncrementalDecoder(DecodedMeshUpkeep upkeep)
    : state_(std::make_unique<State>()) {
  state_->upkeep = upkeep;
}
IncrementalDecoder::~IncrementalDecoder() = default;
IncrementalDecoder::IncrementalDecoder(IncrementalDecoder&&) noexcept = default;
IncrementalDecoder& IncrementalDecoder::operator=(IncrementalDecoder&&) noexcept = default;

Result<uint32_t> IncrementalDecoder::feed(std::span<const uint8_t> bytes) {
  State& s = *state_;
  if (s.error) return tl::unexpected(*s.error);
  s.deltas.clear();
  // After resume_at, bytes of records already applied are skipped.
  const uint64_t done = s.consumed_end();
  if (s.index && s.stream_pos < done) {
    const uint64_t skip = std::min<uint64_t>(bytes.size(), done - s.stream_pos);
    bytes = bytes.subspan(skip);
    s.stream_pos += skip;
    if (s.buffer.empty()) s.buffer_start = s.stream_pos;
  }
  s.buffer.insert(s.buffer.end(), bytes.begin(), bytes.end());
  s.stream_pos += bytes.size();

  if (!s.index) {
    auto index = read_stream_index(s.buffer);
    if (!index) {
      if (index.error().code == ErrorCode::kTruncated) return 0u;
      s.error = index.error();
      s.error_recoverable = s.error->code == ErrorCode::kCorrupt;
      return tl::unexpected(*s.error);
    }
    s.index = std::move(*index);
    if (auto st = s.check_header(); !st) {
      s.error = st.error();
      s.index.reset();
      return tl::unexpected(*s.error);
    }
  }

  if (s.refine) s.reserve_for_received();
  uint32_t applied = 0;
  size_t drop = 0;  // buffer bytes before the next record
  while (s.records_done < s.index->records.size()) {
    const RecordEntry& rec = s.index->records[s.records_done];
    if (s.stream_pos < rec.offset + rec.size) break;
    if (s.buffer_start > rec.offset) {
      s.error =
          Error{ErrorCode::kInvalidArgument, "bytes of record " + std::to_string(s.records_done) +
                                                 " were skipped (resume offset past it)"};
      return tl::unexpected(*s.error);
    }
    const size_t at = static_cast<size_t>(rec.offset - s.buffer_start);
    const std::span<const uint8_t> record_bytes(s.buffer.data() + at, rec.size);
    if (!record_intact(rec, record_bytes)) {
      // Checked before anything is applied, so the state stays good.
      s.error = s.about_record(
          s.records_done, {ErrorCode::kCorrupt, "checksum mismatch (corrupt or altered bytes)"});
      s.error_recoverable = true;
      return tl::unexpected(*s.error);
    }
    // Version 3 records end in their CRC: the decoders see the payload only.
    if (auto st = s.apply_record(s.records_done, record_payload(rec, record_bytes)); !st) {
      s.error = st.error();
      return tl::unexpected(*s.error);
    }
    ++s.records_done;
    ++applied;
    drop = at + rec.size;
  }
  if (drop > 0) {
    s.buffer.erase(s.buffer.begin(), s.buffer.begin() + drop);
    s.buffer_start += drop;
  }
  return applied;
}

const StreamIndex* IncrementalDecoder::index() const {
  return state_->index ? &*state_->index : nullptr;
}
uint32_t IncrementalDecoder::records_decoded() const { return state_->records_done; }
uint64_t IncrementalDecoder::resume_offset() const { return state_->consumed_end(); }

void IncrementalDecoder::expect_prefix(uint64_t end) { state_->prefix_end = end; }
bool IncrementalDecoder::finished() const {
  return state_->index && state_->records_done == state_->index->records.size();
}
const Mesh& IncrementalDecoder::mesh() const { return state_->mesh; }

Result<Mesh> IncrementalDecoder::release_mesh() {
  State& s = *state_;
  if (s.records_done == 0) {
    return make_error(ErrorCode::kTruncated, "no mesh decoded: the base mesh has not arrived");
  }
  Mesh out;
  if (s.upkeep == DecodedMeshUpkeep::kEveryRecord) {
    out = std::move(s.mesh);
  } else {
    if (!s.refine) return make_error(ErrorCode::kInvalidArgument, "the decoded mesh was released");
    if (s.error && !s.error_recoverable) return tl::unexpected(*s.error);
    const auto& q = s.refine->mesh.positions();
    out.positions.resize(q.size());
    const Dequantizer dequantize(s.grid);
    for (size_t v = 0; v < q.size(); ++v) out.positions[v] = dequantize(q[v]);
    // Before the attributes: the materials keep the indices of textures held.
    out.textures = std::move(s.textures);
    // Attributes need the faces still in the decoder's table.
    s.attributes.preview(s.refine->mesh);
    s.attributes.refresh_normal_previews(s.refine->mesh);
    s.attributes.write_mesh(s.refine->mesh, out);
    // The decoder only inserts, so every face slot is a live face.
    out.triangles = s.refine->mesh.release_faces();
  }
  s.refine.reset();
  s.mesh = Mesh{};
  s.error = Error{ErrorCode::kInvalidArgument, "the decoded mesh was released"};
  s.error_recoverable = false;
  return out;
}
const std::vector<RecordDelta>& IncrementalDecoder::last_deltas() const { return state_->deltas; }
const std::vector<bool>& IncrementalDecoder::textures_original() const {
  return state_->texture_original;
}

bool IncrementalDecoder::error_is_recoverable() const {
  return state_->error && state_->error_recoverable;
}

Result<uint32_t> IncrementalDecoder::feed_record(uint32_t record, std::span<const uint8_t> bytes) {
  State& s = *state_;
  if (s.error && !s.error_recoverable) return tl::unexpected(*s.error);
  if (!s.index) {
    return make_error(ErrorCode::kInvalidArgument,
                      "record " + std::to_string(record) + ": the stream's index has not arrived");
  }
  const auto count = static_cast<uint32_t>(s.index->records.size());
  const std::string name = "record " + std::to_string(record) + " of " + std::to_string(count);
  if (record >= count) return make_error(ErrorCode::kInvalidArgument, name + ": no such record");
  if (record < s.records_done) {
    return make_error(ErrorCode::kInvalidArgument, name + ": already applied");
  }
  if (record > s.records_done) {
    return make_error(ErrorCode::kInvalidArgument,
                      name + ": needs record" + (record - s.records_done > 1 ? "s " : " ") +
                          std::to_string(s.records_done) +
                          (record - s.records_done > 1 ? " to " + std::to_string(record - 1) : "") +
                          " first (a record needs every record before it)");
  }
  const RecordEntry& rec = s.index->records[record];
  if (bytes.size() != rec.size) {
    return make_error(ErrorCode::kInvalidArgument, name + ": is " + std::to_string(rec.size) +
                                                       " bytes, given " +
                                                       std::to_string(bytes.size()));
  }
  s.restart_at(rec.offset);  // partial bytes the buffer held are dropped: this record is whole
  return feed(bytes);
}

Status IncrementalDecoder::resume_at(uint64_t offset) {
  State& s = *state_;
  if (s.error && !s.error_recoverable) return tl::unexpected(*s.error);
  bool boundary = offset == 0;
  if (s.index) {
    boundary = boundary || offset == s.index->payload_offset;
    for (uint32_t i = 0; i < s.records_done && !boundary; ++i) {
      boundary = offset == s.index->records[i].offset + s.index->records[i].size;
    }
  }
  if (!boundary || offset > s.consumed_end()) {
    return make_error(ErrorCode::kInvalidArgument,
                      "cannot resume at byte " + std::to_string(offset) +
                          ": not a record boundary this decoder has reached");
  }
  s.restart_at(offset);
  return {};
}

Result<Mesh> decode_hcs(std::span<const uint8_t> stream) {
  IncrementalDecoder decoder(DecodedMeshUpkeep::kOnRelease);
  auto fed = decoder.feed(stream);
  if (!fed) return tl::unexpected(fed.error());
  if (decoder.records_decoded() == 0) {
    return make_error(ErrorCode::kTruncated, "stream of " + std::to_string(stream.size()) +
                                                 " bytes ends before its base mesh is complete");
  }
  return decoder.release_mesh();
}

uint64_t prefix_for_budget(const StreamIndex& index, const DecodeBudget& budget) {
  if (index.records.empty()) return index.payload_offset;
  auto end_of = [&](size_t i) { return index.records[i].offset + index.records[i].size; };
  if (budget.kind == DecodeBudget::Kind::kAll) return index.total_bytes();
  const double total = double(index.total_bytes());
  size_t best = 0;
  for (size_t i = 0; i < index.records.size(); ++i) {
    bool fits = false;
    switch (budget.kind) {
      case DecodeBudget::Kind::kBytes:
        fits = double(end_of(i)) <= budget.value;
        break;
      case DecodeBudget::Kind::kVertices:
        fits = double(index.records[i].vertices) <= budget.value;
        break;
      case DecodeBudget::Kind::kPercentVertices:
        fits = double(index.records[i].vertices) <=
               budget.value / 100.0 * double(index.header.vertex_count) + 1e-9;
        break;
      case DecodeBudget::Kind::kPercentBytes:
        fits = double(end_of(i)) <= std::floor(total * budget.value / 100.0);
        break;
      case DecodeBudget::Kind::kRatio:
        fits = budget.value > 0 && double(end_of(i)) <= total / budget.value + 1e-9;
        break;
      case DecodeBudget::Kind::kAll:
        fits = true;
        break;
    }
    if (fits) best = i;
  }
  return end_of(best);
}

}  // namespace meshstream

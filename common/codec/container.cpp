#include "common/codec/container.h"

#include <cstring>

#include "common/codec/byte_io.h"
#include "common/codec/crc32.h"
#include "common/codec/record_index_coder.h"

namespace meshstream {
namespace {

constexpr size_t kIndexEntryBytes = 24;
// The header fields this version writes, in order; `extra` follows.
constexpr size_t kHeaderFixedBytes = 4 * 4 + 6 * 4 + 4 + 4;

}  // namespace

std::vector<uint8_t> encode_stream_header(const StreamHeader& h) {
  std::vector<uint8_t> out;
  put_u32(out, h.vertex_count);
  put_u32(out, h.face_count);
  put_u32(out, h.base_vertex_count);
  put_u32(out, h.base_face_count);
  put_f32(out, h.bounds.min.x);
  put_f32(out, h.bounds.min.y);
  put_f32(out, h.bounds.min.z);
  put_f32(out, h.bounds.max.x);
  put_f32(out, h.bounds.max.y);
  put_f32(out, h.bounds.max.z);
  out.push_back(h.quant_bits);
  out.push_back(h.base_coder);
  out.push_back(h.structure_coder);
  out.push_back(h.geometry_coder);
  put_u32(out, h.layer_count);
  out.insert(out.end(), h.extra.begin(), h.extra.end());
  return out;
}

namespace {

// Magic, version, flags, header and its CRC: the same in every version.
std::vector<uint8_t> write_magic_and_header(uint16_t version, const StreamHeader& header) {
  std::vector<uint8_t> head = encode_stream_header(header);
  std::vector<uint8_t> out(kContainerMagic, kContainerMagic + 4);
  put_u16(out, version);
  put_u16(out, 0);
  put_u32(out, static_cast<uint32_t>(head.size()));
  out.insert(out.end(), head.begin(), head.end());
  put_u32(out, crc32(0, head.data(), head.size()));
  return out;
}

}  // namespace

std::vector<uint8_t> write_container_prefix(const StreamHeader& header,
                                            std::vector<RecordEntry>& records) {
  std::vector<uint8_t> out = write_magic_and_header(2, header);
  // Version 2 index: count, byte length, then per record varint size,
  // varint vertices added, zigzag varint (2 x vertices added - faces added),
  // u32 CRC (about 8 bytes instead of 24:
  // an embedded stream has hundreds of records and the index comes first).
  std::vector<uint8_t> entries;
  uint32_t prev_v = 0, prev_f = 0;
  for (const RecordEntry& r : records) {
    // Faces added are close to twice the vertices added (2 per interior
    // vertex, 1 per boundary vertex, 0 for a plane record): code the
    // difference, zigzag-signed (a base of higher genus has more).
    const int64_t dv = int64_t(r.vertices) - prev_v, df = int64_t(r.faces) - prev_f;
    const int64_t gap = 2 * dv - df;
    put_varint(entries, r.size);
    put_varint(entries, static_cast<uint32_t>(dv));
    put_varint(entries, static_cast<uint32_t>(gap >= 0 ? 2 * gap : -2 * gap - 1));
    put_u32(entries, r.crc32);
    prev_v = r.vertices;
    prev_f = r.faces;
  }
  const size_t index_start = out.size();  // the index checksum covers count and length too
  put_u32(out, static_cast<uint32_t>(records.size()));
  put_u32(out, static_cast<uint32_t>(entries.size()));
  out.insert(out.end(), entries.begin(), entries.end());
  put_u32(out, crc32(0, out.data() + index_start, out.size() - index_start));
  uint64_t offset = out.size();
  for (RecordEntry& r : records) {
    r.offset = offset;
    offset += r.size;
  }
  return out;
}

Result<WrittenContainer> write_container(const StreamHeader& header,
                                         std::span<const std::vector<uint8_t>> payloads,
                                         std::span<const RecordCounts> counts) {
  if (payloads.size() != counts.size()) {
    return make_error(ErrorCode::kInvalidArgument,
                      "write_container: " + std::to_string(payloads.size()) + " payloads but " +
                          std::to_string(counts.size()) + " record counts");
  }
  if (encode_stream_header(header).size() > kMaxHeaderBytes) {
    return make_error(ErrorCode::kInvalidArgument, "write_container: header too large");
  }
  WrittenContainer out;
  out.records.resize(payloads.size());
  for (size_t i = 0; i < payloads.size(); ++i) {
    if (payloads[i].size() > kMaxRecordBytes - kRecordTrailerBytes) {
      return make_error(ErrorCode::kInvalidArgument,
                        "write_container: record " + std::to_string(i) + " is over 1 GiB");
    }
    RecordEntry& r = out.records[i];
    r.size = static_cast<uint32_t>(payloads[i].size() + kRecordTrailerBytes);
    r.vertices = counts[i].vertices;
    r.faces = counts[i].faces;
    r.crc32 = crc32(0, payloads[i].data(), payloads[i].size());
    r.crc_trailer = true;
  }
  if (!out.records.empty() && (out.records.back().vertices != header.vertex_count ||
                               out.records.back().faces != header.face_count)) {
    return make_error(ErrorCode::kInvalidArgument,
                      "write_container: the last record's counts differ from the header's");
  }
  auto coded = encode_record_index(out.records);  // refuses empty lists and decreasing counts
  if (!coded)
    return tl::unexpected(Error{coded.error().code, "write_container: " + coded.error().message});

  out.bytes = write_magic_and_header(3, header);
  const size_t index_start = out.bytes.size();  // the index checksum covers count and length too
  put_u32(out.bytes, static_cast<uint32_t>(out.records.size()));
  put_u32(out.bytes, static_cast<uint32_t>(coded->size()));
  out.bytes.insert(out.bytes.end(), coded->begin(), coded->end());
  put_u32(out.bytes, crc32(0, out.bytes.data() + index_start, out.bytes.size() - index_start));
  out.payload_offset = out.bytes.size();
  uint64_t total = out.payload_offset;
  for (const RecordEntry& r : out.records) total += r.size;
  out.bytes.reserve(total);
  for (size_t i = 0; i < payloads.size(); ++i) {
    out.records[i].offset = out.bytes.size();
    out.bytes.insert(out.bytes.end(), payloads[i].begin(), payloads[i].end());
    put_u32(out.bytes, out.records[i].crc32);
  }
  return out;
}

namespace {

// kTruncated unless `in` holds at least `bytes`: feed more and call again.
Status need_bytes(std::span<const uint8_t> in, size_t bytes) {
  if (in.size() < bytes) {
    return make_error(ErrorCode::kTruncated, "stream ends after " + std::to_string(in.size()) +
                                                 " bytes, inside its header or record index");
  }
  return {};
}

// Phase 1: magic, version, flags and the header's size (the first 12 bytes).
Status read_preamble(std::span<const uint8_t> in, uint16_t& version, uint32_t& header_size) {
  if (auto s = need_bytes(in, 12); !s) return s;
  if (std::memcmp(in.data(), kContainerMagic, 4) != 0) {
    return make_error(ErrorCode::kParse, "not an .hcs stream (bad magic bytes)");
  }
  version = get_u16(in.data() + 4);
  if (version < 1 || version > kContainerVersion) {
    return make_error(ErrorCode::kUnsupported, "unsupported .hcs version " +
                                                   std::to_string(version) + " (this build reads " +
                                                   std::to_string(kContainerVersion) + ")");
  }
  // No flags are defined yet; a set one means a feature this build lacks.
  if (get_u16(in.data() + 6) != 0) {
    return make_error(ErrorCode::kUnsupported, ".hcs stream uses flags this build does not know");
  }
  header_size = get_u32(in.data() + 8);
  if (header_size < kHeaderFixedBytes || header_size > kMaxHeaderBytes) {
    return make_error(ErrorCode::kParse,
                      "implausible .hcs header size " + std::to_string(header_size));
  }
  return {};
}

// Phase 2: the header's bytes, checked against their CRC, as fields. Waits
// (kTruncated) also for the record count after the CRC.
Status read_header(std::span<const uint8_t> in, uint32_t header_size, StreamHeader& hd) {
  if (auto s = need_bytes(in, 12 + size_t(header_size) + 8); !s) return s;
  const uint8_t* h = in.data() + 12;
  if (crc32(0, h, header_size) != get_u32(h + header_size)) {
    return make_error(ErrorCode::kCorrupt, ".hcs header checksum mismatch");
  }
  hd.vertex_count = get_u32(h);
  hd.face_count = get_u32(h + 4);
  hd.base_vertex_count = get_u32(h + 8);
  hd.base_face_count = get_u32(h + 12);
  hd.bounds.min = {get_f32(h + 16), get_f32(h + 20), get_f32(h + 24)};
  hd.bounds.max = {get_f32(h + 28), get_f32(h + 32), get_f32(h + 36)};
  hd.quant_bits = h[40];
  hd.base_coder = h[41];
  hd.structure_coder = h[42];
  hd.geometry_coder = h[43];
  hd.layer_count = get_u32(h + 44);
  hd.extra.assign(h + kHeaderFixedBytes, h + header_size);
  return {};
}

// Where an index starts (its u32 record count, which the index CRC covers
// too) and how many records it lists.
struct IndexStart {
  size_t count_at = 0;
  uint32_t record_count = 0;
};

// The tail every version's index shares: wait until the index (ending at
// `index_end`) and its u32 CRC are all there, check that CRC, and note
// that record 0 starts right after it. Every version allocates the entries
// only after this: a hostile count costs no memory before.
Status check_index_crc(std::span<const uint8_t> in, const IndexStart& at, size_t index_end,
                       StreamIndex& index) {
  if (auto s = need_bytes(in, index_end + 4); !s) return s;
  if (crc32(0, in.data() + at.count_at, index_end - at.count_at) !=
      get_u32(in.data() + index_end)) {
    return make_error(ErrorCode::kCorrupt, ".hcs record index checksum mismatch");
  }
  index.payload_offset = index_end + 4;
  return {};
}

// Version 1: fixed 24-byte entries (u64 offset, u32 size, vertices, faces,
// CRC).
Status read_index_v1(std::span<const uint8_t> in, const IndexStart& at, StreamIndex& index) {
  const size_t entries_at = at.count_at + 4;
  const size_t index_end = entries_at + size_t(at.record_count) * kIndexEntryBytes;
  if (auto s = check_index_crc(in, at, index_end, index); !s) return s;
  index.records.resize(at.record_count);
  for (uint32_t i = 0; i < at.record_count; ++i) {
    const uint8_t* e = in.data() + entries_at + size_t(i) * kIndexEntryBytes;
    RecordEntry& r = index.records[i];
    r.offset = get_u64(e);
    r.size = get_u32(e + 8);
    r.vertices = get_u32(e + 12);
    r.faces = get_u32(e + 16);
    r.crc32 = get_u32(e + 20);
  }
  return {};
}

// Version 2: u32 length, then per record varint size, varint vertices
// added, zigzag varint (2 x vertices added - faces added), u32 CRC.
Status read_index_v2(std::span<const uint8_t> in, const IndexStart& at, StreamIndex& index) {
  if (auto s = need_bytes(in, at.count_at + 8); !s) return s;
  const uint32_t record_count = at.record_count;
  const uint32_t index_bytes = get_u32(in.data() + at.count_at + 4);
  if (index_bytes < 7ull * record_count || index_bytes > 19ull * record_count) {  // 3 varints + CRC
    return make_error(ErrorCode::kParse,
                      "implausible record index length " + std::to_string(index_bytes));
  }
  const size_t entries_at = at.count_at + 8;
  const size_t index_end = entries_at + index_bytes;
  if (auto s = check_index_crc(in, at, index_end, index); !s) return s;
  index.records.resize(record_count);
  const std::span<const uint8_t> entries = in.first(index_end);  // pos counts from the stream start
  size_t pos = entries_at;
  uint64_t offset = index.payload_offset, vertices = 0, faces = 0;
  for (uint32_t i = 0; i < record_count; ++i) {
    RecordEntry& r = index.records[i];
    uint32_t size = 0, dv = 0, zigzag = 0;
    if (!get_varint(entries, pos, size) || !get_varint(entries, pos, dv) ||
        !get_varint(entries, pos, zigzag) || pos + 4 > index_end) {
      return make_error(ErrorCode::kParse,
                        "record index entry " + std::to_string(i) + " is malformed");
    }
    const int64_t gap = zigzag & 1 ? -(int64_t(zigzag) + 1) / 2 : int64_t(zigzag) / 2;
    const int64_t df = 2 * int64_t(dv) - gap;
    if (df < 0)
      return make_error(ErrorCode::kParse, "record " + std::to_string(i) + " removes faces");
    vertices += dv;
    faces += uint64_t(df);
    if (vertices > UINT32_MAX || faces > UINT32_MAX) {
      return make_error(ErrorCode::kParse, "record " + std::to_string(i) + " counts overflow");
    }
    r.offset = offset;
    r.size = size;
    r.vertices = static_cast<uint32_t>(vertices);
    r.faces = static_cast<uint32_t>(faces);
    r.crc32 = get_u32(in.data() + pos);
    pos += 4;
    offset += size;
  }
  if (pos != index_end) return make_error(ErrorCode::kParse, "record index has trailing bytes");
  return {};
}

// Version 3: u32 length, then the range-coded index (record_index_coder.h);
// each record's CRC is its trailer, filled in for the records inside `in`.
Status read_index_v3(std::span<const uint8_t> in, const IndexStart& at, StreamIndex& index) {
  if (auto s = need_bytes(in, at.count_at + 8); !s) return s;
  const uint32_t record_count = at.record_count;
  // Bounds before waiting for the bytes: a hostile length is an error
  // now, not a wait for gigabytes.
  const uint32_t index_bytes = get_u32(in.data() + at.count_at + 4);
  if (index_bytes == 0 || index_bytes > uint64_t(kMaxIndexBytesPerRecord) * record_count ||
      record_count > uint64_t(kMaxRecordsPerIndexByte) * index_bytes) {
    return make_error(ErrorCode::kParse, "implausible record index length " +
                                             std::to_string(index_bytes) + " for " +
                                             std::to_string(record_count) + " records");
  }
  const size_t entries_at = at.count_at + 8;
  const size_t index_end = entries_at + index_bytes;
  if (auto s = check_index_crc(in, at, index_end, index); !s) return s;
  auto records =
      decode_record_index(in.subspan(entries_at, index_bytes), record_count, index.payload_offset);
  if (!records) return tl::unexpected(records.error());
  index.records = std::move(*records);
  for (RecordEntry& r : index.records) {
    if (r.offset + r.size > in.size()) break;  // contiguous: the rest lie beyond too
    r.crc32 = get_u32(in.data() + r.offset + r.size - kRecordTrailerBytes);
  }
  return {};
}

// Last phase, any version: records follow each other from the end of the
// index, vertex counts never decrease and the last counts are the header's.
Status check_records(const StreamIndex& index) {
  uint64_t expected_offset = index.payload_offset;
  for (uint32_t i = 0; i < index.records.size(); ++i) {
    const RecordEntry& r = index.records[i];
    if (r.offset != expected_offset) {
      return make_error(ErrorCode::kParse, "record " + std::to_string(i) +
                                               " does not start where record " +
                                               std::to_string(i == 0 ? 0 : i - 1) + " ends");
    }
    if (i > 0 && (r.vertices < index.records[i - 1].vertices)) {
      return make_error(ErrorCode::kParse,
                        "record " + std::to_string(i) + " has fewer vertices than the one before");
    }
    expected_offset += r.size;
  }
  if (index.records.back().vertices != index.header.vertex_count ||
      index.records.back().faces != index.header.face_count) {
    return make_error(ErrorCode::kParse, "the last record's counts do not match the header's");
  }
  return {};
}

}  // namespace

Result<StreamIndex> read_stream_index(std::span<const uint8_t> in) {
  StreamIndex index;
  uint32_t header_size = 0;
  if (auto s = read_preamble(in, index.version, header_size); !s) return tl::unexpected(s.error());
  if (auto s = read_header(in, header_size, index.header); !s) return tl::unexpected(s.error());

  IndexStart at;
  at.count_at = 12 + size_t(header_size) + 4;
  at.record_count = get_u32(in.data() + at.count_at);
  if (at.record_count == 0 || at.record_count > kMaxRecords) {
    return make_error(ErrorCode::kParse,
                      "implausible record count " + std::to_string(at.record_count));
  }
  const Status entries = index.version == 1   ? read_index_v1(in, at, index)
                         : index.version == 3 ? read_index_v3(in, at, index)
                                              : read_index_v2(in, at, index);
  if (!entries) return tl::unexpected(entries.error());
  if (auto s = check_records(index); !s) return tl::unexpected(s.error());
  return index;
}

bool record_intact(const RecordEntry& record, std::span<const uint8_t> bytes) {
  if (bytes.size() != record.size) return false;
  if (!record.crc_trailer) return crc32(0, bytes.data(), bytes.size()) == record.crc32;
  if (bytes.size() < kRecordTrailerBytes) return false;
  const size_t payload = bytes.size() - kRecordTrailerBytes;
  return crc32(0, bytes.data(), payload) == get_u32(bytes.data() + payload);
}

std::span<const uint8_t> record_payload(const RecordEntry& record, std::span<const uint8_t> bytes) {
  if (!record.crc_trailer) return bytes;
  return bytes.first(bytes.size() >= kRecordTrailerBytes ? bytes.size() - kRecordTrailerBytes : 0);
}

}  // namespace meshstream

#include "client/stream_facts.h"

#include "common/codec/container.h"
#include "common/codec/record_index_coder.h"

namespace meshstream::client {
namespace {

StreamFacts header_values(const v1::StreamHeader& h) {
  StreamFacts f;
  f.model = h.model();
  f.total_bytes = h.total_bytes();
  f.start_offset = h.start_offset();
  f.end_offset = h.end_offset();
  f.payload_offset = h.payload_offset();
  f.end_record = h.end_record();
  f.vertices = h.vertices();
  f.faces = h.faces();
  f.base_vertices = h.base_vertices();
  f.base_faces = h.base_faces();
  f.quant_bits = h.quant_bits();
  return f;
}

// The four arrays, read exactly as before the compact form existed.
void read_arrays(const v1::RecordIndex& r, uint64_t payload_offset, StreamFacts& f) {
  f.records_total = static_cast<uint32_t>(r.sizes_size());
  uint64_t at = payload_offset;
  for (int i = 0; i < r.sizes_size(); ++i) {
    at += r.sizes(i);
    f.record_end.push_back(at);
    f.record_vertices.push_back(i < r.vertices_size() ? r.vertices(i) : 0);
    f.record_faces.push_back(i < r.faces_size() ? r.faces(i) : 0);
  }
}

Status read_coded(const v1::RecordIndex& r, const v1::StreamHeader& h, StreamFacts& f) {
  const std::string what =
      "model '" + h.model().substr(0, 128) + "': the server's compact record index";
  auto corrupt = [&](const std::string& problem) {
    return make_error(ErrorCode::kCorrupt, what + " " + problem);
  };
  if (r.sizes_size() || r.vertices_size() || r.faces_size() || r.crc32_size()) {
    return corrupt("comes with the record arrays too (a header carries one form)");
  }
  if (r.count() == 0)
    return corrupt("has " + std::to_string(r.coded().size()) + " coded bytes but no record count");
  if (r.count() > kMaxRecords) {
    return corrupt("announces " + std::to_string(r.count()) +
                   " records, more than a stream may hold (" + std::to_string(kMaxRecords) + ")");
  }
  const auto* bytes = reinterpret_cast<const uint8_t*>(r.coded().data());
  auto entries = decode_record_index(std::span<const uint8_t>(bytes, r.coded().size()), r.count(),
                                     h.payload_offset());
  if (!entries) {
    return make_error(ErrorCode::kParse, what + " does not decode to " + std::to_string(r.count()) +
                                             " records: " + entries.error().message);
  }
  const RecordEntry& last = entries->back();
  if (last.offset + last.size != h.total_bytes()) {
    return corrupt("ends at byte " + std::to_string(last.offset + last.size) +
                   " but the header's total_bytes is " + std::to_string(h.total_bytes()));
  }
  if (h.end_record() > r.count()) {
    return corrupt("holds " + std::to_string(r.count()) +
                   " records but the header's end_record is " + std::to_string(h.end_record()));
  }
  if (last.vertices != h.vertices() || last.faces != h.faces()) {
    return corrupt("ends with " + std::to_string(last.vertices) + " vertices and " +
                   std::to_string(last.faces) + " faces but the header says " +
                   std::to_string(h.vertices()) + " and " + std::to_string(h.faces()));
  }
  f.records_total = r.count();
  f.record_end.reserve(entries->size());
  f.record_vertices.reserve(entries->size());
  f.record_faces.reserve(entries->size());
  for (const RecordEntry& e : *entries) {
    f.record_end.push_back(e.offset + e.size);
    f.record_vertices.push_back(e.vertices);
    f.record_faces.push_back(e.faces);
  }
  return {};
}

}  // namespace

Result<StreamFacts> facts_from_header(const v1::StreamHeader& header) {
  StreamFacts f = header_values(header);
  const v1::RecordIndex& r = header.records();
  if (r.count() == 0 && r.coded().empty()) {
    read_arrays(r, header.payload_offset(), f);
    return f;
  }
  if (auto s = read_coded(r, header, f); !s) return tl::unexpected(std::move(s.error()));
  return f;
}

}  // namespace meshstream::client

// `meshstream info IN.hcs [--json]`: the stream's header, base mesh, every
// record (bytes, vertices, faces) and totals, read from the index alone
// (nothing is decoded, as the server does).
#include <cstdio>
#include <fstream>
#include <iostream>
#include <iterator>
#include <nlohmann/json.hpp>

#include "common/codec/base_coder.h"
#include "common/codec/container.h"
#include "common/codec/refinement_codec.h"
#include "tools/commands.h"

namespace meshstream::tools {
namespace {

const char* base_coder_name(uint8_t id) {
  switch (id) {
    case kBaseCoderOwn:
      return "own";
    case kBaseCoderDraco:
      return "draco-edgebreaker";
  }
  return "unknown";
}

// "base", "structure", "plane" (bit planes of positions), or "?" when the
// file is cut short before the record.
const char* record_kind(const std::vector<uint8_t>& bytes, const RecordEntry& r, size_t i) {
  if (i == 0) return "base";
  if (r.offset >= bytes.size() || r.size == 0) return "?";
  return bytes[r.offset] == kRecordPlane ? "plane" : "structure";
}

}  // namespace

int run_info_hcs(const std::string& path, bool json) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return report_failure(Error{ErrorCode::kIo, path + ": cannot open"});
  std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)),
                             std::istreambuf_iterator<char>());
  auto index = read_stream_index(bytes);
  if (!index) return report_failure(std::move(index.error()).with_context(path));
  const StreamHeader& h = index->header;
  const uint64_t total = index->total_bytes();
  const bool complete = bytes.size() >= total;
  const double bpv = h.vertex_count ? 8.0 * double(total) / h.vertex_count : 0.0;
  if (json) {
    nlohmann::json records = nlohmann::json::array();
    for (size_t i = 0; i < index->records.size(); ++i) {
      const RecordEntry& r = index->records[i];
      records.push_back({{"index", i},
                         {"offset", r.offset},
                         {"bytes", r.size},
                         {"vertices", r.vertices},
                         {"faces", r.faces},
                         {"kind", record_kind(bytes, r, i)}});
    }
    nlohmann::json out = {{"path", path},
                          {"vertices", h.vertex_count},
                          {"faces", h.face_count},
                          {"total_bytes", total},
                          {"file_bytes", bytes.size()},
                          {"complete", complete},
                          {"bits_per_vertex", bpv},
                          {"quant_bits", h.quant_bits},
                          {"bounds",
                           {{"min", {h.bounds.min.x, h.bounds.min.y, h.bounds.min.z}},
                            {"max", {h.bounds.max.x, h.bounds.max.y, h.bounds.max.z}}}},
                          {"layers", h.layer_count},
                          {"header_and_index_bytes", index->payload_offset},
                          {"base",
                           {{"vertices", h.base_vertex_count},
                            {"faces", h.base_face_count},
                            {"bytes", index->records[0].size},
                            {"coder", base_coder_name(h.base_coder)}}},
                          {"coders",
                           {{"base", h.base_coder},
                            {"structure", h.structure_coder},
                            {"geometry", h.geometry_coder}}},
                          {"records", records}};
    std::cout << out.dump() << "\n";
    return 0;
  }
  std::printf("%s: .hcs stream, %u vertices, %u faces, %llu bytes (%.2f bits/vertex)%s\n",
              path.c_str(), h.vertex_count, h.face_count, static_cast<unsigned long long>(total),
              bpv, complete ? "" : " -- file is cut short");
  std::printf("quantization: %u bits over [%g %g %g] - [%g %g %g]\n", h.quant_bits, h.bounds.min.x,
              h.bounds.min.y, h.bounds.min.z, h.bounds.max.x, h.bounds.max.y, h.bounds.max.z);
  std::printf("header + index: %llu bytes; %u layers; coders: base %s, structure %u, geometry %u\n",
              static_cast<unsigned long long>(index->payload_offset), h.layer_count,
              base_coder_name(h.base_coder), h.structure_coder, h.geometry_coder);
  std::printf("base mesh: %u vertices, %u faces, %u bytes\n", h.base_vertex_count,
              h.base_face_count, index->records[0].size);
  std::printf("%8s %12s %10s %10s %10s  %s\n", "record", "offset", "bytes", "vertices", "faces",
              "kind");
  size_t planes = 0;
  for (size_t i = 0; i < index->records.size(); ++i) {
    const RecordEntry& r = index->records[i];
    const char* kind = record_kind(bytes, r, i);
    planes += std::string(kind) == "plane" ? 1 : 0;
    std::printf("%8zu %12llu %10u %10u %10u  %s\n", i, static_cast<unsigned long long>(r.offset),
                r.size, r.vertices, r.faces, kind);
  }
  std::printf("plane records (bit planes of positions): %zu\n", planes);
  std::printf("total: %zu records, %llu bytes\n", index->records.size(),
              static_cast<unsigned long long>(total));
  return 0;
}

}  // namespace meshstream::tools

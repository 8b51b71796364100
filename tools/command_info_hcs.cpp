// `meshstream info IN.hcs [--records] [--json]`: the stream's header, base
// mesh and a summary of its records (with --records, every record's offset,
// bytes, vertices, faces and kind; --json always has them), read from the
// index alone (nothing is decoded, as the server does). A file cut short is
// said so on the second line: how many records are complete, which one is
// partial, how many are missing.
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "common/codec/asa_guidance.h"
#include "common/codec/attribute_codec.h"
#include "common/codec/base_coder.h"
#include "common/codec/container.h"
#include "common/codec/refinement_codec.h"
#include "common/codec/texture_record.h"
#include "tools/commands.h"
#include "tools/hcs_file.h"

namespace meshstream::tools {
namespace {

const char* base_coder_name(uint8_t id) {
  switch (id) {
    case kBaseCoderOwn:
      return "own";
    case kBaseCoderDraco:
      return "draco-edgebreaker";
    case kBaseCoderTraversal:
      return "traversal";
  }
  return "unknown";
}

// "base", "structure", "plane" (bit planes of positions), "texture" (an
// image level, texture_record.h), or nullptr when the record's first byte
// is not in the file (it is cut short).
const char* record_kind(const std::vector<uint8_t>& bytes, const RecordEntry& r, size_t i) {
  if (i == 0) return "base";
  if (r.offset >= bytes.size() || r.size == 0) return nullptr;
  if (bytes[r.offset] == kRecordAttributes) return "attributes";
  if (bytes[r.offset] == kRecordTexture) return "texture";
  return bytes[r.offset] == kRecordPlane ? "plane" : "structure";
}

// Bytes of each part of the stream: "positions" (plane records: the bits of
// positions sent after their vertices), "connectivity" (the base and the
// structure records: connectivity with the coarse position residuals of the
// inserted vertices), each attribute and its seams ("normals", "texcoords",
// "colors", "materials", "extra", "seams", "layout"; textures are
// texture_bytes), records counted
// with their CRC trailers and read from the file's records that are whole.
nlohmann::json part_bytes(const std::vector<uint8_t>& bytes, const StreamIndex& index,
                          const FileCoverage& in_file) {
  uint64_t positions = 0, connectivity = 0;
  std::span<const uint8_t> base_attributes, final_attributes;
  std::vector<std::span<const uint8_t>> values_attributes;
  for (size_t i = 0; i < index.records.size() && i < in_file.complete_records; ++i) {
    const RecordEntry& r = index.records[i];
    const char* kind = record_kind(bytes, r, i);
    const std::string k = kind ? kind : "";
    auto payload = record_payload(r, std::span<const uint8_t>(bytes.data() + r.offset, r.size));
    if (k == "texture") continue;  // texture_bytes
    if (k == "plane") {
      positions += r.size;
    } else if (k == "attributes") {
      const uint8_t part = payload.size() > 1 ? payload[1] : kAttributePartFinal;
      if (part == kAttributePartBase)
        base_attributes = payload;
      else if (is_values_part(part))
        values_attributes.push_back(payload);
      else
        final_attributes = payload;
    } else {
      connectivity += r.size;
    }
  }
  nlohmann::json out = {{"positions", positions}, {"connectivity", connectivity}};
  if (!base_attributes.empty()) {
    auto parts = attribute_record_parts(base_attributes, values_attributes, final_attributes);
    if (parts) {
      for (const auto& [name, n] : *parts) out[name] = n;
    } else {
      out["attribute_error"] = parts.error().message;
    }
  }
  return out;
}

// The texture records of the file: per texture its levels (record, level,
// size, pixels); a level whose record is not whole in the file, or that
// does not read, is listed with its bytes and an "error".
nlohmann::json texture_summary(const std::vector<uint8_t>& bytes, const StreamIndex& index,
                               uint64_t& texture_bytes) {
  nlohmann::json textures = nlohmann::json::array();
  texture_bytes = 0;
  for (size_t i = 1; i < index.records.size(); ++i) {
    const RecordEntry& r = index.records[i];
    const char* kind = record_kind(bytes, r, i);
    if (!kind || std::string(kind) != "texture") continue;
    texture_bytes += r.size;
    nlohmann::json level = {{"record", i}, {"bytes", r.size}};
    uint32_t texture = 0;
    if (r.offset + r.size <= bytes.size()) {
      auto read = read_texture_record(record_payload(r, {bytes.data() + r.offset, r.size}));
      if (read) {
        texture = read->texture;
        level["level"] = read->level;
        level["width"] = read->width;
        level["height"] = read->height;
        level["format"] = read->format == ImageFormat::kJpeg ? "jpeg" : "png";
        level["original"] = read->original;
        while (textures.size() <= texture) textures.push_back({{"index", textures.size()}});
        textures[texture]["name"] = read->name;
      } else {
        level["error"] = read.error().message;
      }
    } else {
      level["error"] = "not whole in the file";
    }
    while (textures.size() <= texture) textures.push_back({{"index", textures.size()}});
    textures[texture]["bytes"] = textures[texture].value("bytes", uint64_t(0)) + r.size;
    textures[texture]["levels"].push_back(level);
  }
  return textures;
}

// Whether record i is whole in the file, begun, or absent.
const char* record_presence(const FileCoverage& in_file, size_t i) {
  if (i < in_file.complete_records) return "complete";
  if (i == in_file.complete_records && in_file.partial_record) return "partial";
  return "missing";
}

}  // namespace

int run_info_hcs(const std::string& path, bool json, bool list_records) {
  auto file = read_whole_file(path);
  if (!file) return report_failure(file.error());
  const std::vector<uint8_t>& bytes = *file;
  auto index = read_stream_index(bytes);
  if (!index) return report_failure(std::move(index.error()).with_context(path));
  const StreamHeader& h = index->header;
  const uint64_t total = index->total_bytes();
  const FileCoverage in_file = coverage_of(*index, bytes.size());
  const double bpv = h.vertex_count ? 8.0 * double(total) / h.vertex_count : 0.0;
  size_t structure = 0, planes = 0, texture_records = 0, unknown = 0;  // kinds after the base
  for (size_t i = 1; i < index->records.size(); ++i) {
    const char* kind = record_kind(bytes, index->records[i], i);
    if (!kind) {
      ++unknown;
      continue;
    }
    const std::string k = kind;
    (k == "plane" ? planes : k == "texture" ? texture_records : structure) += 1;
  }
  uint64_t texture_bytes = 0;
  const nlohmann::json textures = texture_summary(bytes, *index, texture_bytes);
  if (json) {
    nlohmann::json records = nlohmann::json::array();
    for (size_t i = 0; i < index->records.size(); ++i) {
      const RecordEntry& r = index->records[i];
      const char* kind = record_kind(bytes, r, i);
      records.push_back({{"index", i},
                         {"offset", r.offset},
                         {"bytes", r.size},
                         {"vertices", r.vertices},
                         {"faces", r.faces},
                         {"kind", kind ? nlohmann::json(kind) : nlohmann::json(nullptr)},
                         {"in_file", record_presence(in_file, i)}});
    }
    nlohmann::json out = {{"path", path},
                          {"vertices", h.vertex_count},
                          {"faces", h.face_count},
                          {"total_bytes", total},
                          {"file_bytes", bytes.size()},
                          {"complete", !in_file.cut_short()},
                          {"complete_records", in_file.complete_records},
                          {"partial_record", in_file.partial_record},
                          {"missing_records", in_file.missing_records()},
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
                          {"parts", part_bytes(bytes, *index, in_file)},
                          {"texture_bytes", texture_bytes},
                          {"textures", textures},
                          {"records", records}};
    std::cout << out.dump() << "\n";
    return 0;
  }
  std::printf("%s: .hcs stream, %u vertices, %u faces, %llu bytes (%.2f bits/vertex)\n",
              path.c_str(), h.vertex_count, h.face_count, static_cast<unsigned long long>(total),
              bpv);
  if (in_file.cut_short()) {
    std::string partial, decodable;
    if (in_file.partial_record) {
      partial = "record " + std::to_string(in_file.complete_records) + " partial, ";
    }
    decodable = in_file.complete_records == 0
                    ? "too short to decode: the base mesh (record 0) is not whole"
                    : "decode stops after record " + std::to_string(in_file.complete_records - 1);
    std::printf(
        "file cut short: %llu of %llu bytes, %u of %u records complete (%s%u missing); %s\n",
        static_cast<unsigned long long>(in_file.file_bytes),
        static_cast<unsigned long long>(in_file.stream_bytes), in_file.complete_records,
        in_file.records, partial.c_str(), in_file.missing_records(), decodable.c_str());
  }
  std::printf("quantization: %u bits over [%g %g %g] - [%g %g %g]\n", h.quant_bits, h.bounds.min.x,
              h.bounds.min.y, h.bounds.min.z, h.bounds.max.x, h.bounds.max.y, h.bounds.max.z);
  std::printf("header + index: %llu bytes; %u layers; coders: base %s, structure %u, geometry %u\n",
              static_cast<unsigned long long>(index->payload_offset), h.layer_count,
              base_coder_name(h.base_coder), h.structure_coder, h.geometry_coder);
  if (auto guidance = read_asa_guidance(h, uint32_t(index->records.size())); !guidance) {
    std::printf("ASA guidance: refused (%s)\n", guidance.error().message.c_str());
  } else if (!*guidance) {
    std::printf("ASA guidance: none (the client shows the prefixes as decoded)\n");
  } else {
    std::string groups;
    for (const AsaGuidanceGroup& g : (*guidance)->groups)
      groups += (groups.empty() ? "" : ", ") + std::string("from record ") +
                std::to_string(g.first_record) + " " + asa_choice_label(g.choice);
    std::printf("ASA guidance: %s\n", groups.c_str());
  }
  std::printf("base mesh: %u vertices, %u faces, %u bytes\n", h.base_vertex_count,
              h.base_face_count, index->records[0].size);
  std::string not_in_file;
  if (unknown > 0) not_in_file = "; " + std::to_string(unknown) + " not in the file, kind unknown";
  std::string texture_part;
  if (texture_records > 0) texture_part = ", " + std::to_string(texture_records) + " texture";
  std::printf("records: %u (base, %zu structure, %zu plane: bit planes of positions%s%s)%s\n",
              in_file.records, structure, planes, texture_part.c_str(), not_in_file.c_str(),
              list_records ? "" : "; --records lists them");
  for (const auto& t : textures) {
    std::printf("texture %u \"%s\": %llu bytes in %zu levels\n", t["index"].get<unsigned>(),
                t.value("name", std::string("?")).c_str(),
                static_cast<unsigned long long>(t.value("bytes", uint64_t(0))),
                t.contains("levels") ? t["levels"].size() : size_t(0));
  }
  if (!list_records) return 0;
  // The "in file" column only when there is something to say.
  const bool presence = in_file.cut_short();
  std::printf("%8s %12s %10s %10s %10s  %-9s%s\n", "record", "offset", "bytes", "vertices", "faces",
              "kind", presence ? "  in file" : "");
  for (size_t i = 0; i < index->records.size(); ++i) {
    const RecordEntry& r = index->records[i];
    const char* kind = record_kind(bytes, r, i);
    std::printf("%8zu %12llu %10u %10u %10u  %-9s%s%s\n", i,
                static_cast<unsigned long long>(r.offset), r.size, r.vertices, r.faces,
                kind ? kind : "-", presence ? "  " : "",
                presence ? record_presence(in_file, i) : "");
  }
  return 0;
}

}  // namespace meshstream::tools

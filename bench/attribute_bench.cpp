// attribute_bench (issue 18, point 5): every model of ../shared/models that
// Draco's reader takes, our stream against Draco at the same quantization
// (positions 12 bits, normals 8, texture coordinates 12, colours 8:
// `draco_encoder -qp 12 -qn 8 -qt 12 -qg 8`, through the library so glTF
// files go the same way), total bytes and bytes per attribute, decode time
// (median of 5), exactness of our full-rate decode, and what locking the
// seam vertices costs (our stream with and without the attributes).
//
// Draco's cost of an attribute: its bytes with every attribute minus its
// bytes without that one. Ours: the attribute's sections of the attribute
// records, plus the seam bits when it is per corner (counted again for each
// per-corner attribute: conservative). Inputs: each model read by
// draco::ReadMeshFromFile, welded by position (Draco's points split at
// seams), attributes per vertex where every corner of a vertex agrees, else
// per corner; the mesh then cleaned as import does (clean_mesh). Only the
// first normal, texture coordinate and colour attribute are compared (Draco
// is given the same: SheenCloth's tangents and second UV set are left out of
// both).
//
// Usage: attribute_bench [MODELS_DIR] [--out FILE.md] [--report-dir DIR]
//                        [--base-color-bits B] (EncodeOptions::base_color_bits)
#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/io/mesh_io.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "bench/model_files.h"
#include "bench/peers/draco_attribute_mesh.h"
#include "common/codec/attribute_codec.h"
#include "common/codec/container.h"
#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "common/codec/quantize.h"
#include "common/mesh/import.h"
#include "tests/codec/attribute_test_util.h"

namespace {

using namespace meshstream;

// Edges of the input mesh with an end at a vertex the encoder locks: the
// upper bound on the seam-pattern bits a re-triangulated patch would code
// (one bit per such edge, Draco's seam-bit bound). The locked set is the
// encoder's own (plan_attributes: both ends of every edge across which a
// per-corner channel's quantized values differ), on the positions
// quantized as the encoder quantizes them.
uint64_t edges_touching_seams(const Mesh& m, const EncodeOptions& options) {
  auto grid = make_grid(m, options.quant_bits);
  if (!grid) return 0;
  const std::vector<Vec3i> q = quantize_positions(m, *grid);
  auto plan = plan_attributes(m, q, {options.quant_normal, options.quant_uv, options.quant_color});
  if (!plan || plan->locked.empty()) return 0;
  const std::vector<uint8_t>& locked = plan->locked;
  std::vector<std::pair<uint32_t, uint32_t>> edges;
  for (const Triangle& t : m.triangles)
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = t[k], b = t[(k + 1) % 3];
      if (locked[a] || locked[b]) edges.emplace_back(std::min(a, b), std::max(a, b));
    }
  std::sort(edges.begin(), edges.end());
  return uint64_t(std::unique(edges.begin(), edges.end()) - edges.begin());
}

// The encoder's locked vertices by how many seam edges meet there (an edge
// is a seam where a per-corner channel's quantized values differ across it
// at either end): 1 (a seam ends), 2 (inside a seam path: the vertices a
// collapse along the path could remove) and 3 or more (where seams meet).
// For docs/seam-pattern-coding.md.
std::array<uint32_t, 3> locked_by_seam_edges(const Mesh& m, const EncodeOptions& options) {
  std::array<uint32_t, 3> out{};
  auto grid = make_grid(m, options.quant_bits);
  if (!grid) return out;
  const std::vector<Vec3i> q = quantize_positions(m, *grid);
  auto plan = plan_attributes(m, q, {options.quant_normal, options.quant_uv, options.quant_color});
  if (!plan || plan->locked.empty()) return out;
  // Per undirected edge, its corners (face, k) where the edge starts at k.
  std::map<std::pair<uint32_t, uint32_t>, std::vector<std::pair<uint32_t, int>>> edges;
  for (uint32_t f = 0; f < m.triangles.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = m.triangles[f][k], b = m.triangles[f][(k + 1) % 3];
      edges[{std::min(a, b), std::max(a, b)}].push_back({f, k});
    }
  auto same_at = [&](uint32_t c1, uint32_t c2) {
    for (size_t ch = 0; ch < plan->layout.channels.size(); ++ch) {
      const AttributeChannel& c = plan->layout.channels[ch];
      if (!c.per_corner) continue;
      const uint32_t n = c.components();
      for (uint32_t i = 0; i < n; ++i)
        if (plan->input_values[ch][size_t(c1) * n + i] !=
            plan->input_values[ch][size_t(c2) * n + i])
          return false;
    }
    return true;
  };
  std::vector<uint32_t> degree(m.vertex_count(), 0);
  for (const auto& [e, sides] : edges) {
    if (sides.size() != 2) continue;
    const auto [f1, k1] = sides[0];
    const auto [f2, k2] = sides[1];
    // The corner at vertex e.first on each side, and at e.second.
    auto corner_at = [&](uint32_t f, int k, uint32_t v) {
      return m.triangles[f][k] == v ? 3 * f + k : 3 * f + (k + 1) % 3;
    };
    const bool seam = !same_at(corner_at(f1, k1, e.first), corner_at(f2, k2, e.first)) ||
                      !same_at(corner_at(f1, k1, e.second), corner_at(f2, k2, e.second));
    if (seam) ++degree[e.first], ++degree[e.second];
  }
  for (uint32_t v = 0; v < m.vertex_count(); ++v)
    if (plan->locked[v] && degree[v] > 0) ++out[std::min<uint32_t>(degree[v], 3) - 1];
  return out;
}

// Bytes of a stream's records of one type after the base (kRecordTexture,
// kRecordAttributes: the records' sizes), to leave out of the geometry.
uint64_t record_bytes(const std::vector<uint8_t>& stream, const StreamIndex& index, uint8_t type) {
  uint64_t bytes = 0;
  for (size_t i = 1; i < index.records.size(); ++i)
    if (stream[index.records[i].offset] == type) bytes += index.records[i].size;
  return bytes;
}

// One row of the first-display table: the bytes up to the first display
// with attributes (the base record and record 1, the header and index
// before them not shown) and record 1's payload by part.
std::string first_display_row(const std::string& name, const std::vector<uint8_t>& stream,
                              const StreamIndex& index, uint64_t plain_first) {
  if (index.records.size() < 2 || stream[index.records[1].offset] != kRecordAttributes)
    return "| " + name + " | no attribute record 1 |\n";
  const RecordEntry& r = index.records[1];
  auto parts = attribute_record_parts(
      record_payload(r, std::span<const uint8_t>(stream).subspan(r.offset, r.size)), {}, {});
  if (!parts) return "| " + name + " | record 1: " + parts.error().message + " |\n";
  auto part = [&](const char* k) -> unsigned long long {
    return parts->count(k) ? parts->at(k) : 0;
  };
  const uint64_t first = r.offset + r.size;
  char row[512];
  std::snprintf(row, sizeof row,
                "| %s | %llu | %llu | %llu | %llu | %llu | %llu | %llu | %llu | %llu / %llu (%.2f) "
                "|\n",
                name.c_str(), (unsigned long long)index.records[0].size, (unsigned long long)r.size,
                part("layout"), part("seams"), part("normals"), part("texcoords"), part("colors"),
                part("materials"), (unsigned long long)first, (unsigned long long)plain_first,
                plain_first ? double(first) / plain_first : 0.0);
  return row;
}

// One row of the seam table: the default stream (seam vertices locked)
// against EncodeOptions::measure_unlocked_seams (geometry records only).
// Geometry: the stream without its attribute and texture records.
std::string seam_row(const std::string& name, const Mesh& mesh, EncodeOptions options,
                     const StreamIndex& locked, uint64_t locked_geometry,
                     uint64_t attribute_records, uint64_t locked_first) {
  options.measure_unlocked_seams = true;
  auto unlocked = encode_hcs(mesh, options);
  if (!unlocked)
    return "| " + name + " | unlocked encode failed: " + unlocked.error().message + " |\n";
  auto index = read_stream_index(*unlocked);
  if (!index) return "| " + name + " | unlocked index: " + index.error().message + " |\n";
  const uint64_t unlocked_geometry =
      unlocked->size() - record_bytes(*unlocked, *index, kRecordTexture);
  const uint64_t base = index->records[0].offset + index->records[0].size;
  const uint64_t bits = edges_touching_seams(mesh, options);
  // First display unlocked: its base plus record 1 of the locked stream
  // (an optimistic stand-in: record 1 grows with the base) plus the bits.
  const uint64_t record1 = locked.records.size() > 1
                               ? locked_first - (locked.records[0].offset + locked.records[0].size)
                               : 0;
  char row[512];
  std::snprintf(row, sizeof row,
                "| %s | %u / %u | %llu / %llu | %llu / %llu | %llu / %llu | %llu (%llu B) |\n",
                name.c_str(), locked.header.base_vertex_count, index->header.base_vertex_count,
                (unsigned long long)locked_first,
                (unsigned long long)(base + record1 + (bits + 7) / 8),
                (unsigned long long)locked_geometry, (unsigned long long)unlocked_geometry,
                (unsigned long long)(locked_geometry + attribute_records),
                (unsigned long long)(unlocked_geometry + attribute_records + (bits + 7) / 8),
                (unsigned long long)bits, (unsigned long long)((bits + 7) / 8));
  return row;
}

}  // namespace

namespace fs = std::filesystem;
using namespace meshstream;
using meshstream::bench::draco_bytes;
using meshstream::bench::draco_only;
using meshstream::bench::to_mesh;

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

template <class F>
double median_ms(F&& f, int runs = 5) {
  std::vector<double> t;
  for (int i = 0; i < runs; ++i) {
    const auto a = std::chrono::steady_clock::now();
    f();
    t.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - a).count());
  }
  return median(t);
}

}  // namespace

int main(int argc, char** argv) {
  // The models folder: the argument, else default_models_dir().
  std::string dir = meshstream::bench::default_models_dir(), out_path, report_dir;
  int base_color_bits = EncodeOptions{}.base_color_bits;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--base-color-bits" && i + 1 < argc)
      base_color_bits = std::atoi(argv[++i]);
    else if (a == "--out" && i + 1 < argc)
      out_path = argv[++i];
    else if (a == "--report-dir" && i + 1 < argc)  // bench/run's convention
      report_dir = argv[++i];
    else
      dir = a;
  }
  if (out_path.empty() && !report_dir.empty()) out_path = report_dir + "/attributes.md";
  const std::vector<fs::path> files = meshstream::bench::model_files(dir);
  std::string first_table =
      "| model | base record | record 1 | layout | seams | normals | texcoords | colors | "
      "materials | first display / without attributes "
      "|\n|---|---|---|---|---|---|---|---|---|---|\n";
  std::string seam_table =
      "| model | base vertices locked / unlocked | first display | geometry | total | seam-pattern "
      "bits |\n|---|---|---|---|---|---|\n";
  std::string table =
      "| model | vertices | attributes | ours total | Draco total | ratio | ours geometry | Draco "
      "geometry | normals ours/Draco | uv ours/Draco | colors ours/Draco | seams | locked vertices "
      "| "
      "geometry without attributes (base vertices) | first display: bytes with attributes / "
      "without | exact | decode ms ours / Draco |\n"
      "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const fs::path& file : files) {
    auto read = draco::ReadMeshFromFile(file.string());
    const std::string name = fs::relative(file, dir).string();
    if (!read.ok()) {
      std::printf("%s: Draco cannot read it: %s\n", name.c_str(), read.status().error_msg());
      table += "| " + name + " | not read by Draco: " + read.status().error_msg_string() + " |\n";
      continue;
    }
    const draco::Mesh& dm = *read.value();
    std::string kinds;
    Mesh mesh = to_mesh(dm, kinds);
    if (auto cleaned = clean_mesh(mesh); !cleaned) {
      table += "| " + name + " | clean failed: " + cleaned.error().message + " |\n";
      continue;
    }
    if (auto s = check_attribute_counts(mesh); !s) {
      table += "| " + name + " | " + s.error().message + " |\n";
      continue;
    }
    EncodeOptions options;
    options.base_color_bits = base_color_bits;
    EncodeReport report;
    auto stream = encode_hcs(mesh, options, &report);
    if (!stream) {
      std::printf("%s: encode failed: %s\n", name.c_str(), stream.error().message.c_str());
      table += "| " + name + " | encode failed: " + stream.error().message + " |\n";
      continue;
    }
    Mesh plain = mesh;
    plain.normals.clear();
    plain.texcoords.clear();
    plain.colors.clear();
    plain.corner_normals = {};
    plain.corner_texcoords = {};
    plain.corner_colors = {};
    auto plain_stream = encode_hcs(plain, options);
    const auto plain_index =
        plain_stream ? read_stream_index(*plain_stream)
                     : Result<StreamIndex>(tl::unexpected(Error{ErrorCode::kInternal, ""}));
    auto index = read_stream_index(*stream);
    uint64_t attribute_total = 0;
    for (const auto& [k, n] : report.attribute_bytes) attribute_total += n;
    // Attribute records with their index entries and trailers: the stream
    // minus the records' payload sections counted above is ours geometry.
    const uint64_t attribute_records = record_bytes(*stream, *index, kRecordAttributes);
    const uint64_t ours_total = stream->size();
    // Textures excluded (Draco's geometry has none either).
    const uint64_t ours_geometry =
        ours_total - attribute_records - record_bytes(*stream, *index, kRecordTexture);
    // The first display with attributes: through record 1 (record 0 when
    // the stream has none); without: the plain stream's base.
    const size_t shown =
        index->records.size() > 1 && (*stream)[index->records[1].offset] == kRecordAttributes ? 1
                                                                                              : 0;
    const uint64_t first_display = index->records[shown].offset + index->records[shown].size;
    const uint64_t plain_first =
        plain_index ? plain_index->records[0].offset + plain_index->records[0].size : 0;
    Result<Mesh> decoded = decode_hcs(*stream);
    const bool exact = decoded && testing::faces_of(*decoded) ==
                                      testing::faces_of(testing::expected_mesh(mesh, options));
    const double ours_ms = median_ms([&] { (void)decode_hcs(*stream); });

    const std::vector<draco::GeometryAttribute::Type> all = {draco::GeometryAttribute::NORMAL,
                                                             draco::GeometryAttribute::TEX_COORD,
                                                             draco::GeometryAttribute::COLOR};
    std::vector<uint8_t> draco_stream;
    const size_t draco_all = draco_bytes(*draco_only(dm, {}), &draco_stream);
    const size_t draco_geometry = draco_bytes(*draco_only(dm, all));
    const double draco_ms = median_ms([&] {
      draco::DecoderBuffer b;
      b.Init(reinterpret_cast<const char*>(draco_stream.data()), draco_stream.size());
      draco::Decoder d;
      (void)d.DecodeMeshFromBuffer(&b);
    });
    auto draco_cost = [&](draco::GeometryAttribute::Type t) -> long {
      if (!dm.GetNamedAttribute(t)) return -1;
      return long(draco_all) - long(draco_bytes(*draco_only(dm, {t})));
    };
    const uint64_t seams =
        report.attribute_bytes.count("seams") ? report.attribute_bytes["seams"] : 0;
    auto ours_cost = [&](const char* part, bool per_corner) -> long {
      if (!report.attribute_bytes.count(part)) return -1;
      return long(report.attribute_bytes[part] + (per_corner ? seams : 0));
    };
    auto cell = [](long ours, long draco) {
      if (ours < 0 && draco < 0) return std::string("-");
      char b[96];
      std::snprintf(b, sizeof b, "%ld / %ld (%.2f)", ours, draco,
                    draco > 0 ? double(ours) / draco : 0.0);
      return std::string(b);
    };
    char row[1024];
    std::snprintf(row, sizeof row,
                  "| %s | %u | %s | %llu | %zu | %.3f | %llu | %zu | %s | %s | %s | %llu | %u | "
                  "%zu (%u) | %llu / %llu (%.2f) | %s | %.2f / %.2f |\n",
                  name.c_str(), mesh.vertex_count(), kinds.c_str(), (unsigned long long)ours_total,
                  draco_all, draco_all ? double(ours_total) / draco_all : 0.0,
                  (unsigned long long)ours_geometry, draco_geometry,
                  cell(ours_cost("normals", !mesh.corner_normals.empty()),
                       draco_cost(draco::GeometryAttribute::NORMAL))
                      .c_str(),
                  cell(ours_cost("texcoords", !mesh.corner_texcoords.empty()),
                       draco_cost(draco::GeometryAttribute::TEX_COORD))
                      .c_str(),
                  cell(ours_cost("colors", !mesh.corner_colors.empty()),
                       draco_cost(draco::GeometryAttribute::COLOR))
                      .c_str(),
                  (unsigned long long)seams, report.attribute_locked_vertices,
                  plain_stream ? plain_stream->size() : 0,
                  plain_index ? plain_index->header.base_vertex_count : 0,
                  (unsigned long long)first_display, (unsigned long long)plain_first,
                  plain_first ? double(first_display) / plain_first : 0.0, exact ? "yes" : "NO",
                  ours_ms, draco_ms);
    std::printf("%s", row);
    std::printf("  base vertices with attributes %u, without %u\n", index->header.base_vertex_count,
                plain_index ? plain_index->header.base_vertex_count : 0);
    if (!mesh.corner_normals.empty() || !mesh.corner_texcoords.empty()) {
      const auto by = locked_by_seam_edges(mesh, options);
      std::printf("  locked vertices by seam edges met: 1: %u, 2: %u, 3 or more: %u\n", by[0],
                  by[1], by[2]);
    }
    // Where the base's coarse values become exact: the end of the low-bits
    // record (record 1 when there is none).
    uint64_t exact_base = first_display;
    for (const RecordEntry& r : index->records) {
      const auto p = record_payload(r, std::span<const uint8_t>(*stream).subspan(r.offset, r.size));
      if (p.size() > 1 && p[0] == kRecordAttributes && p[1] == kAttributePartLowBits)
        exact_base = r.offset + r.size;
    }
    std::printf("  base values exact at %llu bytes (first display %llu, stream %llu)\n",
                (unsigned long long)exact_base, (unsigned long long)first_display,
                (unsigned long long)ours_total);
    table += row;
    first_table += first_display_row(name, *stream, *index, plain_first);
    seam_table +=
        seam_row(name, mesh, options, *index, ours_geometry, attribute_records, first_display);
  }
  std::printf("\n%s", table.c_str());
  std::printf("\n%s", first_table.c_str());
  std::printf("\n%s", seam_table.c_str());
  if (!out_path.empty())
    std::ofstream(out_path) << (report_dir.empty()
                                    ? ""
                                    : "## Attributes against Draco (attribute_bench)\n\n")
                            << table;
  return 0;
}

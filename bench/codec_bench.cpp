// Codec benchmark (issues 3 and 5): for each real mesh, in one run,
//   1. Draco's single-rate size at 12 bits (levels 7 and 10) and its decode
//      speed on its own level-7 file;
//   2. our full .hcs size (embedded stream and issue I's ordering), encode
//      and decode speed, granularity, stream parts, the encoder's model
//      checked at every prefix;
//   3. the rate-distortion curves of both orderings (record boundaries)
//      against the LOD chain a user would build instead (meshoptimizer +
//      Draco).
// Writes bench/report/codec.md, codec_rd.csv and codec_rd.svg (report.h,
// svg_plot.h).
//
//   codec_bench --report-dir DIR [--meshes a.off,b.ply] [--quick]
//               [--mesh-dir DIR] [--samples N]
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "bench/codec/measurements.h"
#include "bench/codec/rate_distortion.h"
#include "bench/codec/report.h"
#include "bench/codec/svg_plot.h"
#include "bench/codec/timing.h"
#include "bench/peers/draco_peer.h"
#include "bench/real_mesh_list.h"
#include "common/codec/container.h"
#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "common/mesh/import.h"
#include "common/metrics/distance.h"
#include "tests/test_meshes.h"

namespace meshstream::bench {
namespace {

// A quick run: a scan, a CAD part and a casting.
const std::vector<std::string> kQuickMeshes = {"bunny.off", "fandisk.off", "casting.off"};

struct Settings {
  std::string mesh_dir;
  // Ours (embedded); the issue-I peer is the same with embedded = false.
  // One thread: the encode times are the calling thread's CPU time, which
  // would miss work done on the encoder's candidate threads.
  EncodeOptions encode = [] {
    EncodeOptions o;
    o.threads = 1;
    return o;
  }();
  bool peer = true;
  int quant_bits = 12;
  int decode_runs = 7;
  int encode_runs = 3;
  int curve_points = 24;
  uint32_t samples = 50000;
};

void measure_draco(const Mesh& mesh, const Settings& s, MeshMeasurements& m,
                   std::vector<uint8_t>& level7) {
  auto d7 = draco_encode(mesh, s.quant_bits, 7);
  auto d10 = draco_encode(mesh, s.quant_bits, 10);
  if (!d7 || !d10) {
    m.draco_error = (!d7 ? d7.error() : d10.error()).message;
    return;
  }
  if (draco_decode_only(*d7) == 0) {
    m.draco_error = "Draco could not decode its own level-7 file";
    return;
  }
  level7 = *d7;
  m.draco7_bytes = d7->size();
  m.draco10_bytes = d10->size();
}

uint32_t vertices_at_ratio20(const StreamIndex& index, uint64_t& bytes) {
  DecodeBudget ratio20;
  ratio20.kind = DecodeBudget::Kind::kRatio;
  ratio20.value = 20;
  bytes = prefix_for_budget(index, ratio20);
  uint32_t vertices = 0;
  for (const RecordEntry& r : index.records) {
    if (r.offset + r.size <= bytes) vertices = r.vertices;
  }
  return vertices;
}

// True when IncrementalDecoder's mesh at every record boundary hashes to
// what the encoder's model said.
bool prefixes_match_model(const std::vector<uint8_t>& stream, const StreamIndex& index,
                          const EncodeReport& report) {
  if (report.records.size() != index.records.size()) return false;
  IncrementalDecoder decoder;
  uint64_t fed = 0;
  for (size_t i = 0; i < index.records.size(); ++i) {
    const uint64_t end = index.records[i].offset + index.records[i].size;
    if (!decoder.feed(std::span<const uint8_t>(stream.data() + fed, end - fed))) return false;
    fed = end;
    if (position_hash(decoder.mesh().positions) != report.records[i].position_hash) return false;
  }
  return true;
}

// Returns the stream (empty when the encoder or decoder failed; the reason is
// in m.ours_error).
std::vector<uint8_t> measure_ours(const Mesh& mesh, const Settings& s, MeshMeasurements& m) {
  EncodeOptions options = s.encode;
  options.quant_bits = s.quant_bits;
  Result<std::vector<uint8_t>> stream = make_error(ErrorCode::kUnsupported, "not run");
  std::vector<double> encode_times;
  for (int r = 0; r < s.encode_runs; ++r) {
    encode_times.push_back(cpu_seconds([&] { stream = encode_hcs(mesh, options); }));
    if (!stream) {
      m.ours_error = "encode_hcs: " + stream.error().message;
      return {};
    }
  }
  m.ours_bytes = stream->size();
  m.ours_encode_vps = m.vertices / median(encode_times);
  auto index = read_stream_index(*stream);
  if (!index) {
    m.ours_error = "read_stream_index: " + index.error().message;
    return {};
  }
  m.ours_records = static_cast<uint32_t>(index->records.size());
  m.ours_base_bytes =
      index->records.empty() ? 0 : index->records[0].offset + index->records[0].size;
  m.ours_vertices_at_ratio20 = vertices_at_ratio20(*index, m.ours_bytes_at_ratio20);
  for (size_t i = 1; i < index->records.size(); ++i)
    m.ours_largest_record = std::max<uint64_t>(m.ours_largest_record, index->records[i].size);
  // The encoder's model and stream statistics (one more encode, not timed).
  EncodeReport report;
  auto again = encode_hcs(mesh, options, &report);
  if (again && *again == *stream) {
    m.ours_structure_bytes = report.structure_bytes;
    m.ours_plane_bytes = report.plane_bytes_coded;
    m.ours_plane_raw_bytes = report.plane_bits_raw / 8;
    m.ours_plane_plain_bytes = report.plane_bytes_plain;
    m.ours_base_shift = report.base_shift;
    m.ours_distortion_estimate = report.ordering.distortion_estimate;
    for (const EncodedRecord& r : report.records) m.ours_plane_records += r.plane ? 1 : 0;
    m.ours_model_matches = prefixes_match_model(*stream, *index, report);
  }
  auto decoded = decode_hcs(*stream);
  if (!decoded) {
    m.ours_error = "decode_hcs: " + decoded.error().message;
    return {};
  }
  m.ours_counts_match =
      decoded->vertex_count() == mesh.vertex_count() && decoded->face_count() == mesh.face_count();
  return *stream;
}

// Issue I's ordering as the peer: every position exact at insertion.
std::vector<uint8_t> measure_plain(const Mesh& mesh, const Settings& s, MeshMeasurements& m) {
  EncodeOptions options = s.encode;
  options.quant_bits = s.quant_bits;
  options.embedded = false;
  auto stream = encode_hcs(mesh, options);
  if (!stream) {
    m.plain_error = stream.error().message;
    return {};
  }
  m.plain_bytes = stream->size();
  auto index = read_stream_index(*stream);
  if (!index) {
    m.plain_error = index.error().message;
    return {};
  }
  m.plain_records = static_cast<uint32_t>(index->records.size());
  uint64_t bytes = 0;
  m.plain_vertices_at_ratio20 = vertices_at_ratio20(*index, bytes);
  return *stream;
}

// Draco's decode of its own level-7 file and our decode_hcs of the whole
// stream, interleaved run by run so both see the same (shared) machine.
void measure_decode_speeds(const std::vector<uint8_t>& draco7, const std::vector<uint8_t>& stream,
                           const Settings& s, MeshMeasurements& m) {
  std::vector<double> draco_times, our_times;
  uint32_t draco_points = 0, our_vertices = 0;
  for (int r = 0; r < s.decode_runs; ++r) {
    if (!draco7.empty()) {
      draco_times.push_back(cpu_seconds([&] { draco_points = draco_decode_only(draco7); }));
    }
    if (!stream.empty()) {
      our_times.push_back(cpu_seconds([&] {
        auto decoded = decode_hcs(stream);
        our_vertices = decoded ? decoded->vertex_count() : 0;
      }));
    }
  }
  if (!draco_times.empty()) m.draco_decode_vps = draco_points / median(draco_times);
  if (!our_times.empty()) m.ours_decode_vps = our_vertices / median(our_times);
}

void measure_rate_distortion(const Mesh& mesh, const std::vector<uint8_t>& stream,
                             const std::vector<uint8_t>& plain, const Settings& s,
                             MeshMeasurements& m) {
  DistanceOptions options;
  options.samples = s.samples;
  auto original = PreparedSurface::prepare(mesh, options);
  if (!original) {
    m.rd_error = original.error().message;
    return;
  }
  auto chain = lod_chain_curve(mesh, s.quant_bits, *original);
  if (!chain) {
    m.rd_error = chain.error().message;
    return;
  }
  m.chain_curve = *chain;
  if (!stream.empty()) {
    auto index = read_stream_index(stream);
    std::vector<uint64_t> budgets;
    for (const RdPoint& p : *chain) budgets.push_back(p.bytes);
    auto curve = our_curve(stream, choose_prefixes(*index, s.curve_points, budgets), *original);
    if (!curve) {
      m.rd_error = "ours: " + curve.error().message;
    } else {
      m.ours_curve = *curve;
      for (size_t i = 1; i < m.ours_curve.size(); ++i) {
        const double before = m.ours_curve[i - 1].rms;
        if (before > 0)
          m.ours_worst_rms_rise = std::max(m.ours_worst_rms_rise, m.ours_curve[i].rms / before - 1);
      }
    }
  }
  if (!plain.empty()) {
    auto index = read_stream_index(plain);
    std::vector<uint64_t> budgets;
    for (const RdPoint& p : *chain) budgets.push_back(p.bytes);
    auto curve = our_curve(plain, choose_prefixes(*index, s.curve_points, budgets), *original);
    if (curve) {
      m.plain_curve = *curve;
    } else {
      m.plain_error = "rate-distortion: " + curve.error().message;
    }
  }
  m.at_chain = compare_at_chain(m.chain_curve, m.ours_curve, m.faces);
  m.plain_at_chain = compare_at_chain(m.chain_curve, m.plain_curve, m.faces);
}

MeshMeasurements measure_mesh(const std::string& name, const Settings& s) {
  MeshMeasurements m;
  m.name = name;
  auto imported = import_mesh(s.mesh_dir + "/" + name);
  if (!imported) {
    m.error = imported.error().message;
    std::printf("%-16s import failed: %s\n", name.c_str(), m.error.c_str());
    return m;
  }
  const Mesh& mesh = imported->mesh;
  m.vertices = mesh.vertex_count();
  m.faces = mesh.face_count();

  std::vector<uint8_t> draco7;
  measure_draco(mesh, s, m, draco7);
  const std::vector<uint8_t> stream = measure_ours(mesh, s, m);
  const std::vector<uint8_t> plain = s.peer ? measure_plain(mesh, s, m) : std::vector<uint8_t>{};
  measure_decode_speeds(draco7, stream, s, m);
  std::printf("%-16s V %7u  Draco L7 %6.2f bpv  L10 %6.2f bpv  decode %6.2f Mv/s\n", name.c_str(),
              m.vertices, m.bpv(m.draco7_bytes), m.bpv(m.draco10_bytes), m.draco_decode_vps / 1e6);
  if (m.ours_error.empty()) {
    std::printf(
        "%-16s ours %6.2f bpv (%.2f x L7, issue I %.2f bpv)  encode %6.3f Mv/s  decode %6.2f Mv/s  "
        "%u records (%u plane), largest %.2f %%, ratio 20: %.1f %% of vertices, model %s\n",
        name.c_str(), m.bpv(m.ours_bytes), double(m.ours_bytes) / m.draco7_bytes,
        m.bpv(m.plain_bytes), m.ours_encode_vps / 1e6, m.ours_decode_vps / 1e6, m.ours_records,
        m.ours_plane_records, 100.0 * m.ours_largest_record / m.ours_bytes,
        100.0 * m.ours_vertices_at_ratio20 / m.vertices,
        m.ours_model_matches ? "matches" : "DIFFERS");
  } else {
    std::printf("%-16s ours n/a: %s\n", name.c_str(), m.ours_error.c_str());
  }
  std::fflush(stdout);

  measure_rate_distortion(mesh, stream, plain, s, m);
  for (size_t i = 0; i < m.at_chain.size(); ++i) {
    const ChainComparison& c = m.at_chain[i];
    std::printf("%-16s chain %-4s %9llu B  rms %.3g  H %.3g", name.c_str(), c.label.c_str(),
                static_cast<unsigned long long>(c.chain.bytes), c.chain.rel_rms,
                c.chain.rel_hausdorff);
    if (c.ours) {
      std::printf("   ours %8llu B rms %.3g (x%.2f) H %.3g (x%.2f)",
                  static_cast<unsigned long long>(c.ours->bytes), c.ours->rel_rms,
                  c.ours->rms / c.chain.rms, c.ours->rel_hausdorff,
                  c.ours->hausdorff / c.chain.hausdorff);
    }
    if (i < m.plain_at_chain.size() && m.plain_at_chain[i].ours) {
      const RdPoint& p = *m.plain_at_chain[i].ours;
      std::printf("   issue I rms x%.2f", p.rms / c.chain.rms);
    }
    std::printf("\n");
  }
  if (!m.rd_error.empty())
    std::printf("%-16s rate-distortion: %s\n", name.c_str(), m.rd_error.c_str());
  std::fflush(stdout);
  return m;
}

}  // namespace
}  // namespace meshstream::bench

int main(int argc, char** argv) {
  using namespace meshstream::bench;
  CLI::App app{"codec benchmark: .hcs vs Draco and a meshoptimizer LOD chain"};
  std::string report_dir = "bench/report";
  std::string mesh_list;
  bool quick = false;
  Settings settings;
  settings.mesh_dir = meshstream::testing::test_mesh_dir();
  app.add_option("--report-dir", report_dir, "where codec.md, codec_rd.csv, codec_rd.svg go");
  app.add_option("--meshes", mesh_list,
                 "comma-separated mesh file names (default: every real mesh)");
  app.add_flag("--quick", quick, "three meshes, fewer runs and curve points");
  app.add_option("--mesh-dir", settings.mesh_dir, "folder of the test meshes");
  app.add_option("--samples", settings.samples, "area samples per direction for distances");
  app.add_option("--base-shift", settings.encode.base_shift,
                 "EncodeOptions::base_shift (default automatic)");
  app.add_option("--base-vertices", settings.encode.target_base_vertices,
                 "EncodeOptions::target_base_vertices");
  app.add_option("--record-bytes", settings.encode.record_bytes,
                 "EncodeOptions::record_bytes (0 automatic)");
  bool no_peer = false;
  app.add_flag("--no-peer", no_peer, "skip issue I's ordering (faster)");
  CLI11_PARSE(app, argc, argv);
  settings.peer = !no_peer;

  if (settings.mesh_dir.empty() || !std::filesystem::is_directory(settings.mesh_dir)) {
    std::fprintf(stderr,
                 "codec_bench: test meshes not found (set MESHSTREAM_TEST_MESHES or --mesh-dir)\n");
    return 1;
  }
  if (quick) {
    settings.decode_runs = 3;
    settings.encode_runs = 1;
    settings.curve_points = 10;
  }
  std::vector<std::string> names =
      mesh_list.empty() ? (quick ? kQuickMeshes : kRealMeshes) : split_commas(mesh_list);

  std::vector<MeshMeasurements> all;
  for (const std::string& name : names) all.push_back(measure_mesh(name, settings));

  std::filesystem::create_directories(report_dir);
  const std::filesystem::path dir(report_dir);
  write_csv(dir / "codec_rd.csv", all);
  ReportSettings rs;
  rs.quant_bits = settings.quant_bits;
  rs.samples = settings.samples;
  rs.decode_runs = settings.decode_runs;
  rs.encode_runs = settings.encode_runs;
  rs.curve_points = settings.curve_points;
  rs.quick = quick;
  if (write_svg_plot(dir / "codec_rd.svg", all)) {
    rs.plot_file = "codec_rd.svg";
  } else {
    rs.plot_note = "no curve to plot";
  }
  write_markdown(dir / "codec.md", all, rs);
  std::printf("wrote %s/codec.md, codec_rd.csv%s\n", report_dir.c_str(),
              rs.plot_file.empty() ? "" : ", codec_rd.svg");
  return 0;
}

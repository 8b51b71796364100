// Decimation benchmark (issue 5): how good are the coarse meshes our layered
// decimation (common/codec/decimate.h) gives the stream, per vertex and per
// byte, against meshoptimizer's simplifier (the LOD chain's coarse meshes).
//
// For every real mesh, in one run:
//   - meshopt_simplify to 1/64, 1/16, 1/4 of the indices (bench/peers/
//     meshopt_lod.h), quantized on the original's 12-bit grid: its vertex
//     count and RMS distance to the quantized original;
//   - the same levels Draco-coded (level 7, as the codec bench's chain),
//     bytes cumulative: the chain's bytes and RMS;
//   - our default stream (encode_hcs), decoded by one IncrementalDecoder at
//     the prefix with at most meshopt's vertex count (prefix_for_budget,
//     vertices) and at the prefix within the chain's bytes (bytes);
//   - full stream bits per vertex, base size, layers, encode CPU time.
// Distances: RdMeasure::relative_rms (common/codec/rd_measure.h: fixed area
// samples on the original, quadrature points on the shown mesh, symmetric
// RMS over the bounding-box diagonal): cheap and low-noise, so small
// differences between decimations are visible.
// "Per vertex" compares RMS x vertices (on a surface the RMS of a good
// approximation falls about as 1/V), so a prefix a few vertices short of
// meshopt's count is not unfairly judged.
//
//   decimation_bench --report-dir DIR [--meshes a.off,b.ply] [--fast]
//                    [--samples N] [--csv FILE] [--baseline FILE]
// --fast fixes EncodeOptions::plane_calibration = 1 (skips the encoder's
// measured choice: for iterating; reports use the default). --csv writes the
// per-mesh numbers; --baseline reads such a file and puts its medians and
// per-mesh equal-bytes ratios beside this run's ("before / after").
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "bench/codec/timing.h"
#include "bench/peers/draco_peer.h"
#include "bench/peers/meshopt_lod.h"
#include "bench/real_mesh_list.h"
#include "common/codec/container.h"
#include "common/codec/decimate.h"
#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "common/codec/quantize.h"
#include "common/codec/rd_measure.h"
#include "common/mesh/import.h"
#include "tests/test_meshes.h"

namespace meshstream::bench {
namespace {

constexpr double kFractions[3] = {1.0 / 64, 1.0 / 16, 1.0 / 4};
const char* const kLabels[3] = {"1/64", "1/16", "1/4"};

struct Level {
  uint32_t meshopt_vertices = 0;
  double meshopt_rms = 0;      // meshopt's mesh on our grid
  uint64_t chain_bytes = 0;    // cumulative Draco bytes up to this level
  double chain_rms = 0;        // the Draco-decoded level
  uint32_t ours_vertices = 0;  // prefix with at most meshopt_vertices
  double ours_rms = 0;
  uint64_t ours_bytes_at_chain = 0;  // prefix within chain_bytes
  uint32_t ours_vertices_at_chain = 0;
  double ours_rms_at_chain = 0;
  // decimate_layers alone down to meshopt_vertices (exact grid positions,
  // no stream): the decimation's own quality, without the coding order.
  uint32_t decimated_vertices = 0;
  double decimated_rms = 0;
  double decimated_ratio() const {
    return meshopt_rms > 0 && meshopt_vertices > 0
               ? decimated_rms * decimated_vertices / (meshopt_rms * meshopt_vertices)
               : 0;
  }
  // ours RMS x V over meshopt's RMS x V.
  double per_vertex_ratio() const {
    return meshopt_rms > 0 && meshopt_vertices > 0
               ? ours_rms * ours_vertices / (meshopt_rms * meshopt_vertices)
               : 0;
  }
  // Our header, index and base alone exceed the chain's bytes: the point is
  // lost (as in the codec bench), not a win measured on the base.
  bool lost() const { return ours_bytes_at_chain > chain_bytes; }
  double bytes_ratio() const {
    if (lost()) return std::numeric_limits<double>::infinity();
    return chain_rms > 0 ? ours_rms_at_chain / chain_rms : 0;
  }
};

struct MeshRow {
  std::string name;
  std::string error;
  uint32_t vertices = 0;
  uint64_t stream_bytes = 0;
  uint64_t base_bytes = 0;
  uint32_t base_vertices = 0;
  uint32_t layers = 0;
  double encode_seconds = 0;
  Level levels[3];
  // Geometric mean of ours / chain RMS over kCurveBudgets log-spaced byte
  // budgets from the chain's 1/64 to its 1/4 point (the chain's RMS
  // interpolated log-log between its points; budgets where our base alone
  // is over are skipped): one point can land just before or after a
  // group of plane records, the curve cannot.
  double curve_ratio = 0;
  double decimate_seconds = 0;  // decimate_layers alone, default options
  double bpv() const { return vertices ? 8.0 * stream_bytes / vertices : 0; }
};
constexpr int kCurveBudgets = 9;

struct Settings {
  std::string mesh_dir;
  bool fast = false;
  uint32_t samples = 20000;
};

Mesh on_grid(const Mesh& mesh, const QuantGrid& grid) {
  Mesh out = mesh;
  for (Vec3f& p : out.positions) p = grid.dequantize(grid.quantize(p));
  return out;
}

MeshRow measure_mesh(const std::string& name, const Settings& s) {
  MeshRow row;
  row.name = name;
  auto imported = import_mesh(s.mesh_dir + "/" + name);
  if (!imported) {
    row.error = "import: " + imported.error().message;
    return row;
  }
  const Mesh& mesh = imported->mesh;
  row.vertices = mesh.vertex_count();
  auto grid = make_grid(mesh, 12);
  if (!grid) {
    row.error = grid.error().message;
    return row;
  }
  const Mesh reference = on_grid(mesh, *grid);
  RdMeasureOptions mo;
  mo.samples = s.samples;
  auto measure = RdMeasure::prepare(reference, mo);
  if (!measure) {
    row.error = measure.error().message;
    return row;
  }

  uint64_t cumulative = 0;
  for (int i = 0; i < 3; ++i) {
    Level& l = row.levels[i];
    const Mesh lod = simplify_lod(mesh, kFractions[i]);
    l.meshopt_vertices = lod.vertex_count();
    l.meshopt_rms = measure->relative_rms(on_grid(lod, *grid));
    auto file = draco_encode(lod, 12, 7);
    if (!file) {
      row.error = "draco: " + file.error().message;
      return row;
    }
    cumulative += file->size();
    l.chain_bytes = cumulative;
    auto shown = draco_decode(*file);
    if (!shown) {
      row.error = "draco: " + shown.error().message;
      return row;
    }
    l.chain_rms = measure->relative_rms(*shown);
  }

  const std::vector<Vec3i> q = quantize_positions(mesh, *grid);
  for (Level& l : row.levels) {
    auto editable = EditableMesh::build(q, mesh.triangles);
    if (!editable) {
      row.error = "editable: " + editable.error().message;
      return row;
    }
    DecimateOptions dopt;
    dopt.target_vertices = l.meshopt_vertices;
    dopt.max_base_share = 0;  // exactly meshopt's count, even on small meshes
    const DecimationResult dec = decimate_layers(std::move(*editable), dopt);
    Mesh coarse;
    std::vector<uint32_t> id(q.size(), 0);
    for (uint32_t v : dec.base_vertices) {
      id[v] = coarse.vertex_count();
      coarse.positions.push_back(grid->dequantize(q[v]));
    }
    for (const Triangle& t : dec.base_faces)
      coarse.triangles.push_back({id[t[0]], id[t[1]], id[t[2]]});
    l.decimated_vertices = coarse.vertex_count();
    l.decimated_rms = measure->relative_rms(coarse);
  }

  {
    auto editable = EditableMesh::build(q, mesh.triangles);
    if (editable) {
      row.decimate_seconds =
          cpu_seconds([&] { decimate_layers(std::move(*editable), DecimateOptions{}); });
    }
  }

  EncodeOptions options;
  options.threads = 1;  // encode_seconds is this thread's CPU time
  if (s.fast) options.plane_calibration = 1;
  Result<std::vector<uint8_t>> stream = make_error(ErrorCode::kUnsupported, "not run");
  row.encode_seconds = cpu_seconds([&] { stream = encode_hcs(mesh, options); });
  if (!stream) {
    row.error = "encode: " + stream.error().message;
    return row;
  }
  row.stream_bytes = stream->size();
  auto index = read_stream_index(*stream);
  if (!index || index->records.empty()) {
    row.error = "index unreadable";
    return row;
  }
  row.base_bytes = index->records[0].offset + index->records[0].size;
  row.base_vertices = index->records[0].vertices;
  row.layers = index->header.layer_count;

  // Every prefix we need, measured in increasing order by one decoder.
  std::map<uint64_t, std::pair<uint32_t, double>> at;  // prefix -> vertices, rms
  uint64_t vertex_prefix[3], byte_prefix[3];
  for (int i = 0; i < 3; ++i) {
    vertex_prefix[i] = prefix_for_budget(
        *index,
        DecodeBudget{DecodeBudget::Kind::kVertices, double(row.levels[i].meshopt_vertices)});
    byte_prefix[i] = prefix_for_budget(
        *index, DecodeBudget{DecodeBudget::Kind::kBytes, double(row.levels[i].chain_bytes)});
    at[vertex_prefix[i]] = {};
    at[byte_prefix[i]] = {};
  }
  uint64_t curve_prefix[kCurveBudgets];
  double curve_chain_rms[kCurveBudgets];
  double curve_budget[kCurveBudgets];
  {
    const double lo = std::log(double(row.levels[0].chain_bytes)),
                 hi = std::log(double(row.levels[2].chain_bytes));
    for (int j = 0; j < kCurveBudgets; ++j) {
      const double lb = lo + (hi - lo) * j / (kCurveBudgets - 1);
      // The chain's RMS at lb, log-log between its two neighbouring points.
      const int seg = std::log(double(row.levels[1].chain_bytes)) < lb ? 1 : 0;
      const double b0 = std::log(double(row.levels[seg].chain_bytes)),
                   b1 = std::log(double(row.levels[seg + 1].chain_bytes));
      const double r0 = std::log(row.levels[seg].chain_rms),
                   r1 = std::log(row.levels[seg + 1].chain_rms);
      curve_chain_rms[j] = std::exp(b1 > b0 ? r0 + (r1 - r0) * (lb - b0) / (b1 - b0) : r0);
      curve_budget[j] = std::exp(lb);
      curve_prefix[j] =
          prefix_for_budget(*index, DecodeBudget{DecodeBudget::Kind::kBytes, curve_budget[j]});
      at[curve_prefix[j]] = {};
    }
  }
  IncrementalDecoder decoder;
  uint64_t fed = 0;
  for (auto& [prefix, result] : at) {
    if (prefix > fed) {
      auto applied = decoder.feed(std::span<const uint8_t>(stream->data() + fed, prefix - fed));
      if (!applied) {
        row.error = "decode: " + applied.error().message;
        return row;
      }
      fed = prefix;
    }
    result = {decoder.mesh().vertex_count(), measure->relative_rms(decoder.mesh())};
  }
  double log_sum = 0;
  int counted = 0;
  for (int j = 0; j < kCurveBudgets; ++j) {
    if (double(curve_prefix[j]) > curve_budget[j]) continue;
    log_sum += std::log(at[curve_prefix[j]].second / curve_chain_rms[j]);
    ++counted;
  }
  row.curve_ratio = counted ? std::exp(log_sum / counted) : std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) {
    Level& l = row.levels[i];
    std::tie(l.ours_vertices, l.ours_rms) = at[vertex_prefix[i]];
    l.ours_bytes_at_chain = byte_prefix[i];
    std::tie(l.ours_vertices_at_chain, l.ours_rms_at_chain) = at[byte_prefix[i]];
  }
  return row;
}

double median_of(const std::vector<MeshRow>& rows, auto&& value) {
  std::vector<double> v;
  for (const MeshRow& r : rows)
    if (r.error.empty()) v.push_back(value(r));
  return median(v);
}
// The largest finite value (lost points are counted apart).
double worst_of(const std::vector<MeshRow>& rows, auto&& value) {
  double w = 0;
  for (const MeshRow& r : rows)
    if (r.error.empty() && std::isfinite(value(r))) w = std::max(w, value(r));
  return w;
}
int lost_points(const std::vector<MeshRow>& rows, int level) {
  int n = 0;
  for (const MeshRow& r : rows) n += r.error.empty() && r.levels[level].lost();
  return n;
}

// CSV: one line per mesh, name then the numbers the report needs.
void write_csv(const std::string& path, const std::vector<MeshRow>& rows) {
  std::ofstream out(path);
  out << "mesh,vertices,stream_bytes,base_bytes,base_vertices,layers,encode_s,curve_ratio,decimate_"
         "s";
  for (int i = 0; i < 3; ++i)
    out << ",mo_v" << i << ",mo_rms" << i << ",chain_bytes" << i << ",chain_rms" << i << ",ours_v"
        << i << ",ours_rms" << i << ",ours_bytes_at_chain" << i << ",ours_v_at_chain" << i
        << ",ours_rms_at_chain" << i << ",dec_v" << i << ",dec_rms" << i;
  out << "\n";
  for (const MeshRow& r : rows) {
    if (!r.error.empty()) continue;
    out << r.name << ',' << r.vertices << ',' << r.stream_bytes << ',' << r.base_bytes << ','
        << r.base_vertices << ',' << r.layers << ',' << r.encode_seconds << ',' << r.curve_ratio
        << ',' << r.decimate_seconds;
    for (const Level& l : r.levels)
      out << ',' << l.meshopt_vertices << ',' << l.meshopt_rms << ',' << l.chain_bytes << ','
          << l.chain_rms << ',' << l.ours_vertices << ',' << l.ours_rms << ','
          << l.ours_bytes_at_chain << ',' << l.ours_vertices_at_chain << ',' << l.ours_rms_at_chain
          << ',' << l.decimated_vertices << ',' << l.decimated_rms;
    out << "\n";
  }
}

std::vector<MeshRow> read_csv(const std::string& path) {
  std::vector<MeshRow> rows;
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    std::string cell;
    std::vector<std::string> c;
    while (std::getline(ss, cell, ',')) c.push_back(cell);
    if (c.size() < 9 + 33) continue;
    MeshRow r;
    r.name = c[0];
    r.vertices = std::stoul(c[1]);
    r.stream_bytes = std::stoull(c[2]);
    r.base_bytes = std::stoull(c[3]);
    r.base_vertices = std::stoul(c[4]);
    r.layers = std::stoul(c[5]);
    r.encode_seconds = std::stod(c[6]);
    r.curve_ratio = std::stod(c[7]);
    r.decimate_seconds = std::stod(c[8]);
    for (int i = 0; i < 3; ++i) {
      const size_t o = 9 + 11 * i;
      Level& l = r.levels[i];
      l.meshopt_vertices = std::stoul(c[o]);
      l.meshopt_rms = std::stod(c[o + 1]);
      l.chain_bytes = std::stoull(c[o + 2]);
      l.chain_rms = std::stod(c[o + 3]);
      l.ours_vertices = std::stoul(c[o + 4]);
      l.ours_rms = std::stod(c[o + 5]);
      l.ours_bytes_at_chain = std::stoull(c[o + 6]);
      l.ours_vertices_at_chain = std::stoul(c[o + 7]);
      l.ours_rms_at_chain = std::stod(c[o + 8]);
      l.decimated_vertices = std::stoul(c[o + 9]);
      l.decimated_rms = std::stod(c[o + 10]);
    }
    rows.push_back(r);
  }
  return rows;
}

std::string fmt(const char* f, double v) {
  if (std::isinf(v)) return "lost";
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

void write_markdown(const std::string& path, const std::vector<MeshRow>& rows,
                    const std::vector<MeshRow>& before, const Settings& s) {
  std::ofstream out(path);
  out << "## Decimation: coarse meshes per vertex and per byte\n\n";
  out << "`bench/decimation_bench` (one run, every real mesh, 12 bits, "
      << (s.fast ? "plane_calibration = 1" : "default EncodeOptions")
      << "). Our decoded prefix against "
      << "meshoptimizer's `meshopt_simplify` at 1/64, 1/16 and 1/4 of the indices (the codec "
         "bench's LOD "
      << "chain). *Per vertex*: our prefix with at most meshopt's vertex count, (RMS x vertices) "
         "ours over "
      << "meshopt's (both on the original's grid). *Equal bytes*: our prefix within the chain's "
         "cumulative "
      << "Draco bytes, RMS ours over chain. RMS: symmetric, over the bounding-box diagonal, "
      << "`RdMeasure::relative_rms` with " << s.samples
      << " area samples (common/codec/rd_measure.h).\n\n";
  std::map<std::string, const MeshRow*> old;
  for (const MeshRow& r : before) old[r.name] = &r;
  out << "| mesh | V | bits/V | base V (bytes) | layers | encode s | decimate s |";
  for (const char* l : kLabels) out << " " << l << " per vertex | " << l << " equal bytes |";
  out << " curve 1/64-1/4 |\n|---|---|---|---|---|---|---|---|";
  for (int i = 0; i < 3; ++i) out << "---|---|";
  out << "\n";
  for (const MeshRow& r : rows) {
    if (!r.error.empty()) {
      out << "| " << r.name << " | failed: " << r.error << " |\n";
      continue;
    }
    const MeshRow* b = old.count(r.name) ? old[r.name] : nullptr;
    out << "| " << r.name << " | " << r.vertices << " | " << fmt("%.2f", r.bpv());
    if (b) out << " (" << fmt("%.2f", b->bpv()) << ")";
    out << " | " << r.base_vertices << " (" << r.base_bytes << ") | " << r.layers << " | "
        << fmt("%.2f", r.encode_seconds) << " | " << fmt("%.3f", r.decimate_seconds) << " |";
    for (int i = 0; i < 3; ++i) {
      const Level& l = r.levels[i];
      out << " " << fmt("%.2f", l.per_vertex_ratio());
      if (b) out << " (" << fmt("%.2f", b->levels[i].per_vertex_ratio()) << ")";
      out << " | " << fmt("%.2f", l.bytes_ratio());
      if (b) out << " (" << fmt("%.2f", b->levels[i].bytes_ratio()) << ")";
      out << " |";
    }
    out << " " << fmt("%.2f", r.curve_ratio);
    if (b) out << " (" << fmt("%.2f", b->curve_ratio) << ")";
    out << " |\n";
  }
  out << "\n"
      << (before.empty() ? "" : "In parentheses: the baseline run (before this decimation). ")
      << "Ratios below 1: ours better. *lost*: our header, index and base alone exceed the chain's "
         "bytes "
      << "(counted as worse than any ratio in the medians; the worst rows are over the points not "
         "lost). "
      << "*curve*: geometric mean of ours / chain RMS at " << kCurveBudgets
      << " log-spaced byte budgets from the "
      << "chain's 1/64 to its 1/4 point (chain interpolated log-log; budgets below our base "
         "skipped): less "
      << "sensitive than one point to where a run of plane records falls. *decimate s*: "
         "decimate_layers "
      << "alone (default options), thread CPU; *encode s*: the whole encode_hcs, one run.\n\n";
  out << "| summary | bits/V | encode s | decimate s |";
  for (const char* l : kLabels) out << " " << l << " per vertex | " << l << " equal bytes |";
  out << " curve 1/64-1/4 |\n|---|---|---|---|---|";
  for (int i = 0; i < 3; ++i) out << "---|---|";
  out << "\n";
  auto summary = [&](const std::string& label, const std::vector<MeshRow>& set) {
    if (set.empty()) return;
    out << "| " << label << " median | "
        << fmt("%.2f", median_of(set, [](const MeshRow& r) { return r.bpv(); })) << " | "
        << fmt("%.2f", median_of(set, [](const MeshRow& r) { return r.encode_seconds; })) << " | "
        << fmt("%.3f", median_of(set, [](const MeshRow& r) { return r.decimate_seconds; })) << " |";
    for (int i = 0; i < 3; ++i) {
      out << " "
          << fmt("%.2f",
                 median_of(set, [i](const MeshRow& r) { return r.levels[i].per_vertex_ratio(); }))
          << " | "
          << fmt("%.2f",
                 median_of(set, [i](const MeshRow& r) { return r.levels[i].bytes_ratio(); }))
          << " |";
    }
    out << " " << fmt("%.2f", median_of(set, [](const MeshRow& r) { return r.curve_ratio; }))
        << " |";
    out << "\n| " << label << " worst | "
        << fmt("%.2f", worst_of(set, [](const MeshRow& r) { return r.bpv(); })) << " | "
        << fmt("%.2f", worst_of(set, [](const MeshRow& r) { return r.encode_seconds; })) << " | "
        << fmt("%.3f", worst_of(set, [](const MeshRow& r) { return r.decimate_seconds; })) << " |";
    for (int i = 0; i < 3; ++i) {
      out << " "
          << fmt("%.2f",
                 worst_of(set, [i](const MeshRow& r) { return r.levels[i].per_vertex_ratio(); }))
          << " | "
          << fmt("%.2f", worst_of(set, [i](const MeshRow& r) { return r.levels[i].bytes_ratio(); }))
          << " |";
    }
    out << " " << fmt("%.2f", worst_of(set, [](const MeshRow& r) { return r.curve_ratio; }))
        << " |";
    out << "\n| " << label << " lost points | | | |";
    for (int i = 0; i < 3; ++i) out << " | " << lost_points(set, i) << " |";
    out << " |\n";
  };
  summary("this run", rows);
  summary("baseline", before);
  out << "\nAbsolute values (this run): meshopt V / RMS, ours V / RMS at that count, chain bytes / "
         "RMS, "
         "ours V / RMS within those bytes.\n\n";
  out << "| mesh | level | meshopt V | meshopt RMS | ours V | ours RMS | chain bytes | chain RMS | "
         "ours V "
         "(bytes) | ours RMS |\n|---|---|---|---|---|---|---|---|---|---|\n";
  for (const MeshRow& r : rows) {
    if (!r.error.empty()) continue;
    for (int i = 0; i < 3; ++i) {
      const Level& l = r.levels[i];
      out << "| " << r.name << " | " << kLabels[i] << " | " << l.meshopt_vertices << " | "
          << fmt("%.3g", l.meshopt_rms) << " | " << l.ours_vertices << " | "
          << fmt("%.3g", l.ours_rms) << " | " << l.chain_bytes << " | " << fmt("%.3g", l.chain_rms)
          << " | " << l.ours_vertices_at_chain << " (" << l.ours_bytes_at_chain << ") | "
          << fmt("%.3g", l.ours_rms_at_chain) << " |\n";
    }
  }
}

}  // namespace
}  // namespace meshstream::bench

int main(int argc, char** argv) {
  using namespace meshstream::bench;
  CLI::App app{"decimation benchmark: our coarse prefixes vs meshoptimizer's simplifier"};
  std::string report_dir = "bench/report", mesh_list, csv, baseline;
  Settings s;
  s.mesh_dir = meshstream::testing::test_mesh_dir();
  app.add_option("--report-dir", report_dir, "where decimation.md goes");
  app.add_option("--meshes", mesh_list,
                 "comma-separated mesh file names (default: every real mesh)");
  app.add_option("--mesh-dir", s.mesh_dir, "folder of the test meshes");
  app.add_option("--samples", s.samples, "area samples on the original (RdMeasure)");
  app.add_flag("--fast", s.fast, "plane_calibration = 1 (skip the encoder's measured choice)");
  app.add_option("--csv", csv, "also write the per-mesh numbers here");
  app.add_option("--baseline", baseline, "a --csv file of an earlier run, shown beside this one");
  CLI11_PARSE(app, argc, argv);
  if (s.mesh_dir.empty() || !std::filesystem::is_directory(s.mesh_dir)) {
    std::fprintf(
        stderr,
        "decimation_bench: test meshes not found (set MESHSTREAM_TEST_MESHES or --mesh-dir)\n");
    return 1;
  }
  const std::vector<std::string> names = mesh_list.empty() ? kRealMeshes : split_commas(mesh_list);
  std::vector<MeshRow> rows;
  for (const std::string& name : names) {
    rows.push_back(measure_mesh(name, s));
    const MeshRow& r = rows.back();
    if (!r.error.empty()) {
      std::printf("%-16s failed: %s\n", name.c_str(), r.error.c_str());
      continue;
    }
    std::printf("%-16s V %6u %5.2f bpv base %4u V %5llu B layers %3u encode %5.2f s |",
                name.c_str(), r.vertices, r.bpv(), r.base_vertices,
                (unsigned long long)r.base_bytes, r.layers, r.encode_seconds);
    for (const Level& l : r.levels)
      std::printf(" dec %.2f perV %.2f bytes %.2f%s |", l.decimated_ratio(), l.per_vertex_ratio(),
                  l.bytes_ratio(), l.lost() ? "*" : "");
    std::printf(" curve %.2f dec %.3f s\n", r.curve_ratio, r.decimate_seconds);
    std::fflush(stdout);
  }
  std::vector<MeshRow> before;
  if (!baseline.empty()) before = read_csv(baseline);
  if (!csv.empty()) write_csv(csv, rows);
  std::filesystem::create_directories(report_dir);
  write_markdown(report_dir + "/decimation.md", rows, before, s);
  auto med = [&](int i, bool bytes) {
    return median_of(rows, [i, bytes](const MeshRow& r) {
      return bytes ? r.levels[i].bytes_ratio() : r.levels[i].per_vertex_ratio();
    });
  };
  std::printf("median decimated %.3f %.3f %.3f\n",
              median_of(rows, [](const MeshRow& r) { return r.levels[0].decimated_ratio(); }),
              median_of(rows, [](const MeshRow& r) { return r.levels[1].decimated_ratio(); }),
              median_of(rows, [](const MeshRow& r) { return r.levels[2].decimated_ratio(); }));
  std::printf("median per vertex %.3f %.3f %.3f  equal bytes %.3f %.3f %.3f  bpv %.3f\n",
              med(0, false), med(1, false), med(2, false), med(0, true), med(1, true), med(2, true),
              median_of(rows, [](const MeshRow& r) { return r.bpv(); }));
  std::printf("wrote %s/decimation.md\n", report_dir.c_str());
  return 0;
}

// Where the structure bytes go: the ideal coded bits (-log2 p per coded
// bit, RangeEncoder's cost sink, EncodeReport::structure_bits) of each
// symbol class of the refinement records — patch counts, valences, start
// ranks, open-edge choices, coarse residuals — per inserted vertex, on every
// real mesh, with the full stream size and the time to decode it, for
// refinement format 2 (the peer) and format 3 (what the encoder writes),
// side by side in one process: the measurement behind format 3's models
// (docs/hcs-format.md, "Entropy coder"). Decode times are paired: the two
// streams of a mesh are decoded alternately.
//
//   structure_bits_bench [--report-dir DIR] [--fixed] [--decode-runs N] [--only NAME]
//
// --fixed encodes with plane calibration 3 only (no measured choice: about
// 4x faster, for quick experiments); the report is written only without it.
// Decode time: the median of N whole-stream decodes of each (default 5).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "common/mesh/import.h"

namespace {

using namespace meshstream;

// The 13 real models of ../shared/meshes/MANIFEST.md.
const char* const kMeshes[] = {"bun_zipper.ply", "bunny.off", "bunny.stl",       "armadillo.obj",
                               "fandisk.off",    "crank.off", "casting.off",     "mask.off",
                               "hemisphere.off", "skull.obj", "maneki-neko.off", "dragon_res2.ply",
                               "dragon_res3.ply"};

std::string mesh_dir() {
  if (const char* env = std::getenv("MESHSTREAM_TEST_MESHES"); env && *env) return env;
  // Beside the repository, found from this file's path (no CMake definition needed).
  return (std::filesystem::path(__FILE__).parent_path().parent_path() / ".." / "shared" / "meshes")
      .string();
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

struct Row {
  std::string name;
  uint32_t vertices = 0;
  size_t bytes = 0;
  StructureBits bits;
  double decode_ms = 0;
};

double structure_total(const StructureBits& b) {
  return b.count + b.valence + b.rank + b.open_edge;
}

void add(StructureBits& total, const StructureBits& b) {
  total.count += b.count;
  total.valence += b.valence;
  total.rank += b.rank;
  total.open_edge += b.open_edge;
  total.residual += b.residual;
  total.insertions += b.insertions;
  total.walk_steps += b.walk_steps;
}

std::string bits_cells(const StructureBits& b) {
  const double m = std::max<uint64_t>(1, b.insertions);
  char line[256];
  std::snprintf(line, sizeof line, "%.3f | %.3f | %.3f | %.3f | %.3f | %.2f", b.count / m,
                b.valence / m, b.rank / m, b.open_edge / m, structure_total(b) / m, b.residual / m);
  return line;
}

}  // namespace

int main(int argc, char** argv) {
  std::string report_dir, only;
  bool fixed = false;
  int decode_runs = 5;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--report-dir" && i + 1 < argc) {
      report_dir = argv[++i];
    } else if (a == "--fixed") {
      fixed = true;
    } else if (a == "--decode-runs" && i + 1 < argc) {
      decode_runs = std::max(0, std::atoi(argv[++i]));
    } else if (a == "--only" && i + 1 < argc) {
      only = argv[++i];
    } else {
      std::fprintf(stderr,
                   "usage: %s [--report-dir DIR] [--fixed] [--decode-runs N] [--only NAME]\n",
                   argv[0]);
      return 2;
    }
  }
  std::vector<Row> rows[2];  // format 2, format 3
  for (const char* name : kMeshes) {
    if (!only.empty() && only != name) continue;
    const std::string path = mesh_dir() + "/" + name;
    if (!std::filesystem::exists(path)) {
      std::fprintf(stderr, "skipping %s: not found\n", path.c_str());
      continue;
    }
    auto imported = import_mesh(path);
    if (!imported) {
      std::fprintf(stderr, "%s: %s\n", name, imported.error().message.c_str());
      return 1;
    }
    std::vector<uint8_t> streams[2];
    for (int f = 0; f < 2; ++f) {
      EncodeOptions options;
      if (fixed) options.plane_calibration = 3.0;
      options.refinement_format =
          f == 0 ? RefinementFormat::kEmbedded : RefinementFormat::kEmbeddedFastStart;
      EncodeReport report;
      auto stream = encode_hcs(imported->mesh, options, &report);
      if (!stream) {
        std::fprintf(stderr, "%s: %s\n", name, stream.error().message.c_str());
        return 1;
      }
      rows[f].push_back(
          Row{name, imported->mesh.vertex_count(), stream->size(), report.structure_bits, 0});
      streams[f] = std::move(*stream);
    }
    std::vector<double> ms[2];
    for (int r = 0; r < decode_runs; ++r) {
      for (int f = 0; f < 2; ++f) {
        const auto t0 = std::chrono::steady_clock::now();
        auto decoded = decode_hcs(streams[f]);
        const auto t1 = std::chrono::steady_clock::now();
        if (!decoded) {
          std::fprintf(stderr, "%s: decode failed: %s\n", name, decoded.error().message.c_str());
          return 1;
        }
        ms[f].push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
      }
    }
    for (int f = 0; f < 2; ++f) {
      Row& row = rows[f].back();
      row.decode_ms = median(ms[f]);
      const StructureBits& b = row.bits;
      const double n = std::max<uint64_t>(1, b.insertions);
      std::printf(
          "f%d %-16s v=%6u bytes=%8zu  per inserted vertex: count %.3f valence %.3f rank %.3f open "
          "%.3f "
          "residual %.3f | steps/ins %.2f decode %.2f ms\n",
          f == 0 ? 2 : 3, name, row.vertices, row.bytes, b.count / n, b.valence / n, b.rank / n,
          b.open_edge / n, b.residual / n, double(b.walk_steps) / n, row.decode_ms);
    }
    std::fflush(stdout);
  }
  StructureBits total[2];
  std::vector<double> size_ratio, time_ratio;
  for (int f = 0; f < 2; ++f)
    for (const Row& r : rows[f]) add(total[f], r.bits);
  for (size_t i = 0; i < rows[0].size(); ++i) {
    size_ratio.push_back(double(rows[1][i].bytes) / double(rows[0][i].bytes));
    if (rows[0][i].decode_ms > 0) time_ratio.push_back(rows[1][i].decode_ms / rows[0][i].decode_ms);
  }
  for (int f = 0; f < 2; ++f) {
    const StructureBits& t = total[f];
    const double n = std::max<uint64_t>(1, t.insertions);
    std::printf(
        "ALL f%d: count %.3f valence %.3f rank %.3f open %.3f residual %.3f structure %.3f "
        "bits/inserted vertex\n",
        f == 0 ? 2 : 3, t.count / n, t.valence / n, t.rank / n, t.open_edge / n, t.residual / n,
        structure_total(t) / n);
  }
  std::printf(
      "format 3 / format 2: stream size median %.4f (min %.4f, max %.4f), decode time median "
      "%.3f\n",
      median(size_ratio),
      size_ratio.empty() ? 0 : *std::min_element(size_ratio.begin(), size_ratio.end()),
      size_ratio.empty() ? 0 : *std::max_element(size_ratio.begin(), size_ratio.end()),
      median(time_ratio));
  if (report_dir.empty() || fixed || !only.empty()) return 0;
  std::filesystem::create_directories(report_dir);
  std::ofstream out(report_dir + "/structure_bits.md");
  out << "## Structure bits (refinement records, per symbol class)\n\n"
      << "`bench/structure_bits_bench`, default encoder options, every real mesh: ideal coded bits "
         "(-log2 p "
         "of every range-coded bit) of each symbol class of the refinement records per inserted "
         "vertex, for "
         "refinement format 2 (the peer: the same records through format 2's models) and format 3 "
         "(written "
         "by default: models that learn fast at first, valence also by the apex's free faces, "
         "start rank by "
         "the number of candidate runs and the best score's lead). Decode: median of "
      << decode_runs << " whole-stream decodes, the two formats alternating.\n\n"
      << "| symbols, bits per inserted vertex (pooled) | count | valence | rank | open edge | "
         "structure | residual |\n"
      << "|---|---|---|---|---|---|---|\n"
      << "| format 2 | " << bits_cells(total[0]) << " |\n"
      << "| format 3 | " << bits_cells(total[1]) << " |\n\n"
      << "| mesh | vertices | format 2 bytes | format 3 bytes | ratio | format 3 count / valence / "
         "rank / residual "
         "bits | decode ms f2 | decode ms f3 |\n"
      << "|---|---|---|---|---|---|---|---|\n";
  char line[512];
  for (size_t i = 0; i < rows[0].size(); ++i) {
    const Row& a2 = rows[0][i];
    const Row& a3 = rows[1][i];
    const double m = std::max<uint64_t>(1, a3.bits.insertions);
    std::snprintf(line, sizeof line,
                  "| %s | %u | %zu | %zu | %.4f | %.2f / %.2f / %.2f / %.2f | %.1f | %.1f |\n",
                  a2.name.c_str(), a2.vertices, a2.bytes, a3.bytes,
                  double(a3.bytes) / double(a2.bytes), a3.bits.count / m, a3.bits.valence / m,
                  a3.bits.rank / m, a3.bits.residual / m, a2.decode_ms, a3.decode_ms);
    out << line;
  }
  std::snprintf(line, sizeof line,
                "\nFormat 3 / format 2: stream size median %.4f (min %.4f, max %.4f); decode time "
                "median %.3f.\n",
                median(size_ratio), *std::min_element(size_ratio.begin(), size_ratio.end()),
                *std::max_element(size_ratio.begin(), size_ratio.end()), median(time_ratio));
  out << line;
  return 0;
}

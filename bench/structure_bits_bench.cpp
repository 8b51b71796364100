// Where the structure bytes go: the ideal coded bits (-log2 p per coded
// bit, RangeEncoder's cost sink, EncodeReport::structure_bits) of each
// symbol class of the refinement records — patch counts, valences, start
// ranks, open-edge choices, coarse residuals — per inserted vertex, on every
// real mesh, with the full stream size and the time to decode it. The
// measurement behind the context models of refinement format 3
// (docs/hcs-format.md, "Entropy coder").
//
//   structure_bits_bench [--report-dir DIR] [--fixed] [--decode-runs N] [--only NAME]
//
// --fixed encodes with plane calibration 3 only (no measured choice: about
// 4x faster, for quick experiments); the report is written only without it.
// Decode time: the median of N whole-stream decodes (default 5).
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
const char* const kMeshes[] = {"bun_zipper.ply", "bunny.off",    "bunny.stl",      "armadillo.obj", "fandisk.off",
                               "crank.off",      "casting.off",  "mask.off",       "hemisphere.off", "skull.obj",
                               "maneki-neko.off", "dragon_res2.ply", "dragon_res3.ply"};

std::string mesh_dir() {
  if (const char* env = std::getenv("MESHSTREAM_TEST_MESHES"); env && *env) return env;
  // Beside the repository, found from this file's path (no CMake definition needed).
  return (std::filesystem::path(__FILE__).parent_path().parent_path() / ".." / "shared" / "meshes").string();
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
      std::fprintf(stderr, "usage: %s [--report-dir DIR] [--fixed] [--decode-runs N] [--only NAME]\n", argv[0]);
      return 2;
    }
  }
  std::vector<Row> rows;
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
    EncodeOptions options;
    if (fixed) options.plane_calibration = 3.0;
    EncodeReport report;
    auto stream = encode_hcs(imported->mesh, options, &report);
    if (!stream) {
      std::fprintf(stderr, "%s: %s\n", name, stream.error().message.c_str());
      return 1;
    }
    Row row{name, imported->mesh.vertex_count(), stream->size(), report.structure_bits, 0};
    std::vector<double> ms;
    for (int r = 0; r < decode_runs; ++r) {
      const auto t0 = std::chrono::steady_clock::now();
      auto decoded = decode_hcs(*stream);
      const auto t1 = std::chrono::steady_clock::now();
      if (!decoded) {
        std::fprintf(stderr, "%s: decode failed: %s\n", name, decoded.error().message.c_str());
        return 1;
      }
      ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    }
    row.decode_ms = median(ms);
    const StructureBits& b = row.bits;
    const double n = std::max<uint64_t>(1, b.insertions);
    std::printf("%-16s v=%6u bytes=%8zu  per inserted vertex: count %.3f valence %.3f rank %.3f open %.3f "
                "residual %.3f | steps/ins %.2f decode %.2f ms\n",
                name, row.vertices, row.bytes, b.count / n, b.valence / n, b.rank / n, b.open_edge / n,
                b.residual / n, double(b.walk_steps) / n, row.decode_ms);
    std::fflush(stdout);
    rows.push_back(row);
  }
  StructureBits total;
  for (const Row& r : rows) {
    total.count += r.bits.count;
    total.valence += r.bits.valence;
    total.rank += r.bits.rank;
    total.open_edge += r.bits.open_edge;
    total.residual += r.bits.residual;
    total.insertions += r.bits.insertions;
    total.walk_steps += r.bits.walk_steps;
  }
  const double n = std::max<uint64_t>(1, total.insertions);
  std::printf("ALL: count %.3f valence %.3f rank %.3f open %.3f residual %.3f structure %.3f bits/inserted vertex\n",
              total.count / n, total.valence / n, total.rank / n, total.open_edge / n, total.residual / n,
              (total.count + total.valence + total.rank + total.open_edge) / n);
  if (report_dir.empty() || fixed || !only.empty()) return 0;
  std::filesystem::create_directories(report_dir);
  std::ofstream out(report_dir + "/structure_bits.md");
  out << "## Structure bits (refinement records, per symbol class)\n\n"
      << "`bench/structure_bits_bench`: ideal coded bits (-log2 p of every range-coded bit) of each symbol "
         "class of the refinement records, per inserted vertex, default encoder options; whole stream bytes; "
         "median of " << decode_runs << " whole-stream decodes.\n\n"
      << "| mesh | vertices | stream bytes | count | valence | rank | open edge | structure | residual | walk steps / insertion | decode ms |\n"
      << "|---|---|---|---|---|---|---|---|---|---|---|\n";
  char line[512];
  for (const Row& r : rows) {
    const StructureBits& b = r.bits;
    const double m = std::max<uint64_t>(1, b.insertions);
    std::snprintf(line, sizeof line, "| %s | %u | %zu | %.2f | %.2f | %.2f | %.3f | %.2f | %.2f | %.2f | %.1f |\n",
                  r.name.c_str(), r.vertices, r.bytes, b.count / m, b.valence / m, b.rank / m, b.open_edge / m,
                  (b.count + b.valence + b.rank + b.open_edge) / m, b.residual / m, double(b.walk_steps) / m,
                  r.decode_ms);
    out << line;
  }
  std::snprintf(line, sizeof line, "| all (pooled) | | | %.2f | %.2f | %.2f | %.3f | %.2f | %.2f | %.2f | |\n",
                total.count / n, total.valence / n, total.rank / n, total.open_edge / n,
                (total.count + total.valence + total.rank + total.open_edge) / n, total.residual / n,
                double(total.walk_steps) / n);
  out << line;
  return 0;
}

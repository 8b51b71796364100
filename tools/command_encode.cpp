// `meshstream encode IN -o OUT.hcs [--quant-bits 12] [--base-vertices N]
//   [--record-bytes N] [--base-shift B] [--layer-candidates S] [--no-bit-planes] [--threads N]
//   [--quant-normal 8] [--quant-uv 12] [--quant-color 8] [--progress | --no-progress]`:
// import and clean a mesh, encode it into one progressive .hcs stream
// (common/codec/encoder.h), write it, and say what was made.
#include <cstdio>
#include <fstream>
#include <optional>
#include <string>

#include "common/codec/container.h"
#include "common/codec/encoder.h"
#include "common/mesh/import.h"
#include "tools/commands.h"
#include "tools/progress_bar.h"

namespace meshstream::tools {
namespace {

struct EncodeArgs {
  std::string input, output;
  int quant_bits = EncodeOptions{}.quant_bits;
  uint32_t base_vertices = EncodeOptions{}.target_base_vertices;
  uint32_t record_bytes = EncodeOptions{}.record_bytes;
  double layer_candidates = EncodeOptions{}.layer_candidate_share;
  std::optional<int> base_shift;  // empty: automatic
  bool no_bit_planes = false;
  bool no_asa_guidance = false;
  bool old_flag = false;  // --issue1-order, the old name of --no-bit-planes
  uint32_t threads = EncodeOptions{}.threads;
  int quant_normal = EncodeOptions{}.quant_normal;
  int quant_uv = EncodeOptions{}.quant_uv;
  int quant_color = EncodeOptions{}.quant_color;
  int base_color_bits = EncodeOptions{}.base_color_bits;
  bool progress = false, no_progress = false;  // neither: a bar when stderr is a terminal
};

int run_encode(const EncodeArgs& args) {
  if (args.old_flag)
    std::fprintf(stderr, "meshstream encode: --issue1-order is deprecated, use --no-bit-planes\n");
  ProgressBar bar(stderr,
                  !args.no_progress && (args.progress || ProgressBar::stderr_is_terminal()));
  bar.show_stage("reading " + args.input);
  auto imported = import_mesh(args.input);
  if (!imported) {
    bar.finish();
    return report_failure(imported.error());
  }
  // What import could not carry (or changed), never dropped in silence.
  for (const std::string& note : imported->report.notes)
    std::fprintf(stderr, "meshstream encode: %s: warning: %s\n", args.input.c_str(), note.c_str());
  EncodeOptions options;
  options.quant_bits = args.quant_bits;
  options.target_base_vertices = args.base_vertices;
  options.record_bytes = args.record_bytes;
  options.layer_candidate_share = args.layer_candidates;
  options.base_shift = args.base_shift;
  options.embedded = !(args.no_bit_planes || args.old_flag);
  options.threads = args.threads;
  options.asa_guidance = !args.no_asa_guidance;
  options.quant_normal = args.quant_normal;
  options.quant_uv = args.quant_uv;
  options.quant_color = args.quant_color;
  options.base_color_bits = args.base_color_bits;
  options.progress = [&bar](const EncodeProgress& p) { bar.update(p.stage, p.fraction); };
  auto bytes = encode_hcs(imported->mesh, options);
  bar.finish();
  if (!bytes) return report_failure(std::move(bytes.error()).with_context(args.input));
  // What the stream does not carry is said, never dropped in silence.
  for (const std::string& w : encode_warnings(imported->mesh))
    std::fprintf(stderr, "meshstream encode: %s: warning: %s\n", args.input.c_str(), w.c_str());
  std::ofstream out(args.output, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes->data()),
            static_cast<std::streamsize>(bytes->size()));
  out.close();
  if (!out) return report_failure(Error{ErrorCode::kIo, args.output + ": cannot write the stream"});
  auto index = read_stream_index(*bytes);
  if (!index) return report_failure(std::move(index.error()).with_context(args.output));
  const uint32_t v = imported->mesh.vertex_count();
  std::printf(
      "%s: %u vertices, %u faces -> %s: %zu bytes (%.2f bits/vertex), base %u vertices, "
      "%u layers, %zu records\n",
      args.input.c_str(), v, imported->mesh.face_count(), args.output.c_str(), bytes->size(),
      v ? 8.0 * double(bytes->size()) / v : 0.0, index->header.base_vertex_count,
      index->header.layer_count, index->records.size());
  return 0;
}

}  // namespace

void add_encode_command(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand("encode", "Encode a mesh into a progressive .hcs stream");
  auto args = std::make_shared<EncodeArgs>();
  cmd->add_option("input", args->input, "mesh file (PLY, OBJ, STL, OFF, DRC)")->required();
  cmd->add_option("-o,--output", args->output, "the .hcs stream to write")->required();
  cmd->add_option("--quant-bits", args->quant_bits, "position quantization bits (8..20)")
      ->check(CLI::Range(8, 20))
      ->capture_default_str();
  cmd->add_option("--quant-normal", args->quant_normal,
                  "normal quantization bits per octahedral coordinate (2..16)")
      ->check(CLI::Range(2, 16))
      ->capture_default_str();
  cmd->add_option("--quant-uv", args->quant_uv,
                  "texture coordinate quantization bits (2..16), one grid over their box")
      ->check(CLI::Range(2, 16))
      ->capture_default_str();
  cmd->add_option("--quant-color", args->quant_color,
                  "colour quantization bits per channel (2..16; 8 keeps 8-bit colours exact)")
      ->check(CLI::Range(2, 16))
      ->capture_default_str();
  cmd->add_option(
         "--base-color-bits", args->base_color_bits,
         "the base mesh's colours in the first attribute record on this many bits per channel "
         "(2..quant-color - 1; their low bits follow in a record of their own); 0: exact")
      ->check(CLI::Range(0, 15))
      ->capture_default_str();
  cmd->add_option("--base-vertices", args->base_vertices,
                  "stop decimating at about this many vertices")
      ->check(CLI::Range(4u, 1u << 30))
      ->capture_default_str();
  cmd->add_option(
         "--record-bytes", args->record_bytes,
         "close a refinement record at about this size (0: automatic, at least min(n/50, 200) "
         "records, none above 2 % of the stream)")
      ->check(CLI::Range(0u, 1u << 26))
      ->capture_default_str();
  cmd->add_option("--layer-candidates", args->layer_candidates,
                  "each decimation layer removes vertices from this cheapest share of its "
                  "candidates, (0, 1]: larger makes fewer, larger layers")
      ->check(CLI::Validator(
          [](std::string& text) {
            // 0 takes no vertex at all: a usage error (exit 2), like 1.5.
            const double share = std::strtod(text.c_str(), nullptr);
            return share > 0 && share <= 1 ? std::string() : "share " + text + " is not in (0, 1]";
          },
          "(0, 1]"))
      ->capture_default_str();
  cmd->add_option("--base-shift", args->base_shift,
                  "low bits of the base positions sent later as bit planes, 0..12 (default: "
                  "automatic, quant bits - 8: an 8-bit base)")
      ->check(CLI::Range(0, 12));
  cmd->add_flag("--no-bit-planes", args->no_bit_planes,
                "every position exact when its vertex arrives: no plane records, structure "
                "records in decimation order (the peer benchmarks compare against)");
  cmd->add_flag("--no-asa-guidance", args->no_asa_guidance,
                "write no ASA guidance (by default the encoder measures which ASA setting, or "
                "none, brings each part of the stream closest to the original; the client's "
                "--asa auto follows it and shows a stream without it as decoded)");
  cmd->add_option("--threads", args->threads,
                  "threads for decimation, the closest-point hierarchies and the measurement "
                  "of the candidate record orderings (0: one per core); the stream is the same "
                  "for every count")
      ->check(CLI::Range(0u, 1024u))
      ->capture_default_str();
  cmd->add_flag("--progress", args->progress,
                "a progress bar on stderr (stage, percent, time left), also when "
                "stderr is not a terminal (the default shows it only there)");
  cmd->add_flag("--no-progress", args->no_progress,
                "no progress bar, even on a terminal (wins over --progress)");
  // The old name, hidden from --help; still accepted (scripts, older notes).
  cmd->add_flag("--issue1-order", args->old_flag, "")->group("");
  cmd->callback([args, &exit_code] { exit_code = run_encode(*args); });
}

}  // namespace meshstream::tools

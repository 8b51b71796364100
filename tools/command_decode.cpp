// `meshstream decode IN.hcs -o OUT.ply|.obj [--bytes N | --vertices N |
// --percent P | --ratio CR]`: decode the whole stream or the prefix a budget
// selects (HCS's decoder controls; --ratio 20 = 1/20 of the stream) and
// write the mesh.
#include <cstdio>
#include <fstream>
#include <iterator>
#include <string>

#include "common/codec/decoder.h"
#include "common/mesh/export.h"
#include "tools/commands.h"

namespace meshstream::tools {
namespace {

struct DecodeArgs {
  std::string input, output;
  double bytes = -1, vertices = -1, percent = -1, ratio = -1;
};

Result<std::vector<uint8_t>> read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return make_error(ErrorCode::kIo, path + ": cannot open");
  std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)),
                             std::istreambuf_iterator<char>());
  if (in.bad()) return make_error(ErrorCode::kIo, path + ": read error");
  return bytes;
}

int run_decode(const DecodeArgs& args) {
  auto bytes = read_file(args.input);
  if (!bytes) return report_failure(bytes.error());
  auto index = read_stream_index(*bytes);
  if (!index) return report_failure(std::move(index.error()).with_context(args.input));
  DecodeBudget budget;
  if (args.bytes >= 0) budget = {DecodeBudget::Kind::kBytes, args.bytes};
  if (args.vertices >= 0) budget = {DecodeBudget::Kind::kVertices, args.vertices};
  if (args.percent >= 0) budget = {DecodeBudget::Kind::kPercentVertices, args.percent};
  if (args.ratio >= 0) budget = {DecodeBudget::Kind::kRatio, args.ratio};
  const uint64_t prefix = std::min<uint64_t>(prefix_for_budget(*index, budget), bytes->size());
  if (prefix < index->total_bytes() && budget.kind == DecodeBudget::Kind::kAll) {
    return report_failure(Error{ErrorCode::kTruncated, args.input + ": stream is cut short (" +
                                                           std::to_string(bytes->size()) + " of " +
                                                           std::to_string(index->total_bytes()) +
                                                           " bytes)"});
  }
  IncrementalDecoder decoder;
  auto fed = decoder.feed(std::span<const uint8_t>(bytes->data(), prefix));
  if (!fed) return report_failure(std::move(fed.error()).with_context(args.input));
  if (decoder.records_decoded() == 0) {
    return report_failure(
        Error{ErrorCode::kTruncated, args.input + ": the base mesh is incomplete"});
  }
  if (auto s = write_mesh(decoder.mesh(), args.output); !s) return report_failure(s.error());
  std::printf("%s: decoded %u of %zu records (%llu of %llu bytes): %u vertices, %u faces -> %s\n",
              args.input.c_str(), decoder.records_decoded(), index->records.size(),
              static_cast<unsigned long long>(prefix),
              static_cast<unsigned long long>(index->total_bytes()), decoder.mesh().vertex_count(),
              decoder.mesh().face_count(), args.output.c_str());
  return 0;
}

}  // namespace

void add_decode_command(CLI::App& app, int& exit_code) {
  auto* cmd =
      app.add_subcommand("decode", "Decode an .hcs stream (or the prefix a budget selects)");
  auto args = std::make_shared<DecodeArgs>();
  cmd->add_option("input", args->input, ".hcs stream")->required();
  cmd->add_option("-o,--output", args->output, "mesh to write (.ply or .obj)")->required();
  auto* b = cmd->add_option("--bytes", args->bytes, "decode at most this many bytes")
                ->check(CLI::NonNegativeNumber);
  auto* v = cmd->add_option("--vertices", args->vertices, "decode at most this many vertices")
                ->check(CLI::NonNegativeNumber);
  auto* p =
      cmd->add_option("--percent", args->percent, "decode at most this percentage of the vertices")
          ->check(CLI::Range(0.0, 100.0));
  auto* r = cmd->add_option("--ratio", args->ratio, "decode 1/CR of the stream (CR >= 1)")
                ->check(CLI::Range(1.0, 1e12));
  b->excludes(v)->excludes(p)->excludes(r);
  v->excludes(p)->excludes(r);
  p->excludes(r);
  cmd->callback([args, &exit_code] { exit_code = run_decode(*args); });
}

}  // namespace meshstream::tools

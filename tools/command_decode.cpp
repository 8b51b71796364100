// `meshstream decode IN.hcs -o OUT.ply|.obj|.stl|.off|.glb|.gltf [--bytes N | --vertices
// N | --percent P | --percent-bytes P | --ratio CR]`: decode the whole
// stream or the prefix a budget selects (HCS's decoder controls; --ratio 20
// = 1/20 of the stream) and write the mesh.
//
// A file cut short (a partial download) decodes what it holds, as a
// progressive format should: every record up to the last complete one,
// with a warning on stderr naming how much was missing, exit 0. Its header,
// index and base mesh must be whole (else exit 1 naming which); a record
// whose checksum fails is an error (exit 1) as in a whole file.
#include <cstdio>
#include <string>

#include "common/cli/budget_options.h"
#include "common/codec/decoder.h"
#include "common/mesh/export.h"
#include "tools/commands.h"
#include "tools/hcs_file.h"

namespace meshstream::tools {
namespace {

struct DecodeArgs {
  std::string input, output;
  Budget budget;
};

int run_decode(const DecodeArgs& args) {
  auto bytes = read_whole_file(args.input);
  if (!bytes) return report_failure(bytes.error());
  auto index = read_stream_index(*bytes);
  if (!index) return report_failure(std::move(index.error()).with_context(args.input));
  const FileCoverage in_file = coverage_of(*index, bytes->size());
  if (in_file.complete_records == 0) {
    const RecordEntry& base = index->records.at(0);
    return report_failure(Error{
        ErrorCode::kTruncated,
        args.input + ": file ends inside the base mesh (" + std::to_string(bytes->size()) +
            " of the " + std::to_string(base.offset + base.size) +
            " bytes up to its end; the header, the record index and the base mesh must be whole "
            "to decode anything)"});
  }
  // Where the budget ends in the whole stream, and what of it the file holds.
  const uint64_t wanted = prefix_for_budget(*index, args.budget);
  const uint64_t available = std::min<uint64_t>(wanted, bytes->size());
  // The mesh is built once, for writing, not kept up to date per record.
  IncrementalDecoder decoder(DecodedMeshUpkeep::kOnRelease);
  auto fed = decoder.feed(std::span<const uint8_t>(bytes->data(), available));
  if (!fed) return report_failure(std::move(fed.error()).with_context(args.input));
  const uint32_t records = decoder.records_decoded();
  const uint64_t decoded_bytes = decoder.resume_offset();
  auto mesh = decoder.release_mesh();
  if (!mesh) return report_failure(std::move(mesh.error()).with_context(args.input));
  if (auto s = write_mesh(*mesh, args.output); !s) return report_failure(s.error());
  for (const std::string& lost : export_losses(*mesh, args.output))
    std::fprintf(stderr, "meshstream decode: %s: warning: not stored: %s\n", args.output.c_str(),
                 lost.c_str());
  std::printf("%s: decoded %u of %zu records (%llu of %llu bytes): %u vertices, %u faces -> %s\n",
              args.input.c_str(), records, index->records.size(),
              static_cast<unsigned long long>(decoded_bytes),
              static_cast<unsigned long long>(index->total_bytes()), mesh->vertex_count(),
              mesh->face_count(), args.output.c_str());
  if (available < wanted) {
    std::string budget_note;
    if (args.budget.kind != Budget::Kind::kAll) {
      budget_note = "; the budget selects " +
                    std::to_string(coverage_of(*index, wanted).complete_records) + " records";
    }
    std::fprintf(stderr,
                 "meshstream: warning: %s: file is cut short: it has %llu of %llu bytes: decoded "
                 "%u of %u records%s\n",
                 args.input.c_str(), static_cast<unsigned long long>(in_file.file_bytes),
                 static_cast<unsigned long long>(in_file.stream_bytes), records, in_file.records,
                 budget_note.c_str());
  }
  return 0;
}

}  // namespace

void add_decode_command(CLI::App& app, int& exit_code) {
  auto* cmd =
      app.add_subcommand("decode",
                         "Decode an .hcs stream (or the prefix a budget selects; a file cut "
                         "short decodes up to its last complete record, with a warning)");
  auto args = std::make_shared<DecodeArgs>();
  cmd->add_option("input", args->input, ".hcs stream")->required();
  cmd->add_option("-o,--output", args->output,
                  "mesh to write (.ply, .obj, .stl, .off, .glb or .gltf)")
      ->required()
      ->check(mesh_output_validator());
  // The budget rule of every program: common/cli/budget_options.h.
  cli::add_budget_options(
      *cmd, args->budget,
      {Budget::Kind::kBytes, Budget::Kind::kVertices, Budget::Kind::kPercentVertices,
       Budget::Kind::kPercentBytes, Budget::Kind::kRatio});
  cmd->callback([args, &exit_code] { exit_code = run_decode(*args); });
}

}  // namespace meshstream::tools

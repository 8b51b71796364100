// `meshstream info IN [--records] [--json]`: a mesh file's facts
// (command_info_mesh.cpp) or an .hcs stream's (command_info_hcs.cpp).
#include <cstring>
#include <fstream>

#include "common/codec/container.h"
#include "tools/commands.h"

namespace meshstream::tools {
namespace {

// An .hcs stream: its magic, or (a file cut inside the magic) a name ending
// in .hcs, so that a truncated stream is reported as one.
bool looks_like_stream(const std::string& path) {
  char magic[4] = {};
  std::ifstream in(path, std::ios::binary);
  in.read(magic, 4);
  if (in.gcount() == 4) return std::memcmp(magic, kContainerMagic, 4) == 0;
  return path.size() >= 4 && path.compare(path.size() - 4, 4, ".hcs") == 0;
}

}  // namespace

void add_info_command(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand("info", "Facts about a mesh file or an .hcs stream");
  auto path = std::make_shared<std::string>();
  auto json = std::make_shared<bool>(false);
  auto records = std::make_shared<bool>(false);
  cmd->add_option("input", *path, "mesh file (PLY, OBJ, STL, OFF, DRC) or .hcs stream")->required();
  cmd->add_flag("--records", *records,
                ".hcs: also list every record (offset, bytes, vertices, faces, kind)");
  cmd->add_flag("--json", *json, "print one JSON object instead of text (.hcs: with every record)");
  cmd->callback([path, json, records, &exit_code] {
    exit_code = looks_like_stream(*path) ? run_info_hcs(*path, *json, *records)
                                         : run_info_mesh(*path, *json);
  });
}

}  // namespace meshstream::tools

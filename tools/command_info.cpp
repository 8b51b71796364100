#include <cstring>
#include <fstream>

#include "common/codec/container.h"
#include "tools/commands.h"

namespace meshstream::tools {

void add_info_command(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand("info", "Facts about a mesh file or an .hcs stream");
  auto path = std::make_shared<std::string>();
  auto json = std::make_shared<bool>(false);
  cmd->add_option("input", *path, "mesh file (PLY, OBJ, STL, OFF, DRC) or .hcs stream")->required();
  cmd->add_flag("--json", *json, "print one JSON object instead of text");
  cmd->callback([path, json, &exit_code] {
    char magic[4] = {};
    std::ifstream in(*path, std::ios::binary);
    in.read(magic, 4);
    const bool is_stream = in.gcount() == 4 && std::memcmp(magic, kContainerMagic, 4) == 0;
    exit_code = is_stream ? run_info_hcs(*path, *json) : run_info_mesh(*path, *json);
  });
}

}  // namespace meshstream::tools

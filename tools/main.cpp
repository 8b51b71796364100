// meshstream: offline tools over mesh files and .hcs streams.
#include <iostream>

#include "common/base/heap.h"
#include "common/cli/version.h"
#include "common/mesh/export.h"
#include "tools/commands.h"

int main(int argc, char** argv) {
  meshstream::keep_heap_tight();  // peak RSS of encodes (heap.h)
  using namespace meshstream::tools;
  CLI::App app{"meshstream: encode, decode, inspect, subdivide and compare meshes"};
  app.require_subcommand(1);
  meshstream::cli::add_version_flag(app, "meshstream");
  int exit_code = 0;
  add_info_command(app, exit_code);
  add_encode_command(app, exit_code);
  add_decode_command(app, exit_code);
  add_subdivide_command(app, exit_code);
  add_compare_command(app, exit_code);
  add_generate_command(app, exit_code);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    std::cerr << "meshstream: " << e.what() << " (see --help)\n";
    return 2;
  }
  return exit_code;
}

namespace meshstream::tools {

CLI::Validator mesh_output_validator() {
  return CLI::Validator(
      [](std::string& path) {
        Status writable = check_mesh_output_path(path);
        return writable ? std::string() : writable.error().message;
      },
      "MESH", "mesh output");
}

int report_failure(const Error& error) {
  std::cerr << "meshstream: " << error.message << "\n";
  return 1;
}

}  // namespace meshstream::tools

#include "tools/commands.h"

namespace meshstream::tools {

// Placeholder until the owning module lands: says so instead of pretending.
void add_encode_command(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand("encode", "(not implemented yet)");
  cmd->allow_extras();
  cmd->callback([&exit_code] {
    exit_code = report_failure(Error{ErrorCode::kUnsupported, "'encode' is not implemented yet"});
  });
}

}  // namespace meshstream::tools

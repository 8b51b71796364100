#include "tools/commands.h"

namespace meshstream::tools {

// Placeholder until the owning module lands: says so instead of pretending.
void add_decode_command(CLI::App& app, int& exit_code) {
  auto* cmd = app.add_subcommand("decode", "(not implemented yet)");
  cmd->allow_extras();
  cmd->callback([&exit_code] {
    exit_code = report_failure(Error{ErrorCode::kUnsupported, "'decode' is not implemented yet"});
  });
}

}  // namespace meshstream::tools

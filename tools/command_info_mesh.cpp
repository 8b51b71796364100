#include "tools/commands.h"

namespace meshstream::tools {

int run_info_mesh(const std::string& path, bool json) {
  return report_failure(Error{ErrorCode::kUnsupported, path + ": mesh info is not implemented yet"});
}

}  // namespace meshstream::tools

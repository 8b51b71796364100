#include "tools/commands.h"

namespace meshstream::tools {

int run_info_hcs(const std::string& path, bool json) {
  return report_failure(Error{ErrorCode::kUnsupported, path + ": .hcs info is not implemented yet"});
}

}  // namespace meshstream::tools

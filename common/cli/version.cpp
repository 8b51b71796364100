#include "common/cli/version.h"

#include "common/codec/encoder.h"
#include "proto/framing.h"

#ifndef MESHSTREAM_VERSION
#error "MESHSTREAM_VERSION comes from CMake's project(VERSION) (common/cli/CMakeLists.txt)"
#endif

namespace meshstream::cli {

std::string version_line(std::string_view program) {
  return std::string(program) + " " + MESHSTREAM_VERSION + " (encoder version " +
         std::to_string(kEncoderVersion) + ", protocol version " +
         std::to_string(proto::kProtocolVersion) + ")";
}

void add_version_flag(CLI::App& app, std::string_view program) {
  app.set_version_flag("--version", version_line(program),
                       "print the program, project, encoder and protocol versions and exit");
}

}  // namespace meshstream::cli

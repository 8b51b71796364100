// Running the Khronos glTF validator (tests/tools/gltf_validate.mjs, npm
// gltf-validator installed by scripts/lib.sh ms_gltf_validator) on a file
// from a test: exit status (0: no errors) and what it printed.
#pragma once

#include <sys/wait.h>

#include <cstdio>
#include <string>
#include <utility>

namespace meshstream::testing {

inline std::pair<int, std::string> run_gltf_validator(const std::string& modules,
                                                      const std::string& path) {
  const std::string script = std::string(MESHSTREAM_SOURCE_DIR) + "/tests/tools/gltf_validate.mjs";
  const std::string command = "node '" + script + "' '" + modules + "' '" + path + "' 2>&1";
  FILE* pipe = ::popen(command.c_str(), "r");
  std::string out;
  char buffer[4096];
  while (pipe && fgets(buffer, sizeof buffer, pipe)) out += buffer;
  const int status = pipe ? ::pclose(pipe) : -1;
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

}  // namespace meshstream::testing

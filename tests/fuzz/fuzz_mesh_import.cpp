// Fuzz target: mesh import (OBJ, PLY, OFF, STL), what the server runs on
// every file dropped into --models. The first input byte picks the format
// (the file extension), the rest is the file's content, written to a
// private temporary file because import_mesh reads paths. Checked: never a
// crash, out-of-bounds read or UB; a successful import is a valid mesh.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include "common/mesh/import.h"
#include "common/mesh/mesh.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace meshstream;
  if (size < 1) return 0;
  static const char* const kExtensions[] = {".obj", ".ply", ".off", ".stl"};
  const std::string path =
      "/tmp/meshstream-fuzz-import-" + std::to_string(::getpid()) + kExtensions[data[0] % 4];
  if (std::FILE* f = std::fopen(path.c_str(), "wb")) {
    if (size > 1) std::fwrite(data + 1, 1, size - 1, f);
    std::fclose(f);
  } else {
    return 0;
  }
  ImportOptions options;
  options.repair_nonmanifold = (data[0] & 4) == 0;  // both paths: repair and refuse
  auto imported = import_mesh(path, options);
  std::remove(path.c_str());
  if (imported && !validate_arrays(imported->mesh)) __builtin_trap();
  return 0;
}

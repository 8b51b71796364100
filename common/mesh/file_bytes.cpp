// The whole of a mesh file in memory, for the text and PLY readers.
#include <cstdio>

#include "common/mesh/mesh_readers.h"

namespace meshstream {

Result<std::string> read_file_bytes(const std::string& path) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) return make_error(ErrorCode::kIo, "cannot open the file for reading");
  std::string bytes;
  if (std::fseek(file, 0, SEEK_END) == 0) {
    const long size = std::ftell(file);
    if (size > 0) bytes.reserve(static_cast<size_t>(size));
    std::rewind(file);
  }
  char buffer[1 << 16];
  size_t got = 0;
  while ((got = std::fread(buffer, 1, sizeof buffer, file)) > 0) bytes.append(buffer, got);
  const bool failed = std::ferror(file) != 0;
  std::fclose(file);
  if (failed) return make_error(ErrorCode::kIo, "read failed");
  return bytes;
}

}  // namespace meshstream

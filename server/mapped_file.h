// A read-only memory map of a whole file, shared by every session that
// streams it (the page cache holds the bytes once, however many clients).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "common/base/result.h"

namespace meshstream::server {

// Immutable bytes of one model's stream: a mapped file or an owned buffer
// (demo models, freshly encoded meshes when no cache is writable).
class StreamBytes {
 public:
  virtual ~StreamBytes() = default;
  virtual std::span<const uint8_t> bytes() const = 0;
};

// Maps `path` read-only. kIo when it cannot be opened or mapped, kInvalidArgument
// for an empty file. O(1); pages are read lazily by the kernel.
Result<std::shared_ptr<const StreamBytes>> map_file(const std::string& path);

// Wraps an owned buffer.
std::shared_ptr<const StreamBytes> own_bytes(std::vector<uint8_t> bytes);

}  // namespace meshstream::server

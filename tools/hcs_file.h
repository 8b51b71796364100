// An .hcs file as the tool reads it: the bytes, and how much of the stream
// its index describes the file holds. A file cut short (a partial download)
// still has a usable prefix: every record that ends within it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/base/result.h"
#include "common/codec/container.h"

namespace meshstream::tools {

// The whole file. kIo naming the path when it cannot be read.
Result<std::vector<uint8_t>> read_whole_file(const std::string& path);

// How the file's bytes cover the stream its index describes.
struct FileCoverage {
  uint64_t file_bytes = 0;
  uint64_t stream_bytes = 0;      // index.total_bytes()
  uint32_t records = 0;           // in the index
  uint32_t complete_records = 0;  // records [0, complete_records) end within the file
  bool partial_record = false;    // record complete_records starts within the file
  bool cut_short() const { return file_bytes < stream_bytes; }
  uint32_t missing_records() const { return records - complete_records - (partial_record ? 1 : 0); }
};
FileCoverage coverage_of(const StreamIndex& index, uint64_t file_bytes);

}  // namespace meshstream::tools

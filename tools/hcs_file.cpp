#include "tools/hcs_file.h"

#include <fstream>
#include <iterator>

namespace meshstream::tools {

Result<std::vector<uint8_t>> read_whole_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return make_error(ErrorCode::kIo, path + ": cannot open");
  std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)),
                             std::istreambuf_iterator<char>());
  if (in.bad()) return make_error(ErrorCode::kIo, path + ": read error");
  return bytes;
}

FileCoverage coverage_of(const StreamIndex& index, uint64_t file_bytes) {
  FileCoverage c;
  c.file_bytes = file_bytes;
  c.stream_bytes = index.total_bytes();
  c.records = static_cast<uint32_t>(index.records.size());
  // Records are in stream order, so the complete ones are a prefix.
  while (c.complete_records < c.records) {
    const RecordEntry& r = index.records[c.complete_records];
    if (r.offset + r.size > file_bytes) break;
    ++c.complete_records;
  }
  c.partial_record =
      c.complete_records < c.records && index.records[c.complete_records].offset < file_bytes;
  return c;
}

}  // namespace meshstream::tools

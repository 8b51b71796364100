#include "proto/framing.h"

#include <cstring>
#include <stdexcept>

namespace meshstream::proto {

void append_varint(std::vector<uint8_t>& out, uint64_t value) {
  while (value >= 0x80) {
    out.push_back(static_cast<uint8_t>(value | 0x80));
    value >>= 7;
  }
  out.push_back(static_cast<uint8_t>(value));
}

size_t varint_size(uint64_t value) {
  size_t n = 1;
  while (value >= 0x80) {
    value >>= 7;
    ++n;
  }
  return n;
}

void append_frame(const google::protobuf::MessageLite& message, std::vector<uint8_t>& out) {
  const size_t size = message.ByteSizeLong();
  if (size > UINT32_MAX) throw std::length_error("meshstream frame larger than 4 GiB");
  append_varint(out, size);
  const size_t at = out.size();
  out.resize(at + size);
  message.SerializeWithCachedSizesToArray(out.data() + at);
}

std::vector<uint8_t> encode_frame(const google::protobuf::MessageLite& message) {
  std::vector<uint8_t> out;
  out.reserve(message.ByteSizeLong() + kMaxVarint32Bytes);
  append_frame(message, out);
  return out;
}

namespace {

uint8_t* put_varint(uint8_t* p, uint64_t value) {
  while (value >= 0x80) {
    *p++ = static_cast<uint8_t>(value | 0x80);
    value >>= 7;
  }
  *p++ = static_cast<uint8_t>(value);
  return p;
}

// Wire tags: (field number << 3) | wire type; 0 = varint, 2 = length-delimited.
constexpr uint8_t kTagServerChunk = (4 << 3) | 2;   // ServerMessage.chunk
constexpr uint8_t kTagChunkOffset = (1 << 3) | 0;   // Chunk.offset
constexpr uint8_t kTagChunkRecords = (2 << 3) | 0;  // Chunk.records_complete
constexpr uint8_t kTagChunkData = (3 << 3) | 2;     // Chunk.data

}  // namespace

ChunkFrameHead encode_chunk_frame_head(uint64_t offset, uint32_t records_complete,
                                       size_t data_size) {
  // proto3 omits fields holding their default value, and so do we, so the
  // bytes match the generated serializer exactly.
  size_t chunk_size = 0;
  if (offset != 0) chunk_size += 1 + varint_size(offset);
  if (records_complete != 0) chunk_size += 1 + varint_size(records_complete);
  if (data_size != 0) chunk_size += 1 + varint_size(data_size) + data_size;
  const size_t frame_size = 1 + varint_size(chunk_size) + chunk_size;

  ChunkFrameHead head;
  uint8_t* p = head.bytes;
  p = put_varint(p, frame_size);
  *p++ = kTagServerChunk;
  p = put_varint(p, chunk_size);
  if (offset != 0) {
    *p++ = kTagChunkOffset;
    p = put_varint(p, offset);
  }
  if (records_complete != 0) {
    *p++ = kTagChunkRecords;
    p = put_varint(p, records_complete);
  }
  if (data_size != 0) {
    *p++ = kTagChunkData;
    p = put_varint(p, data_size);
  }
  head.size = static_cast<size_t>(p - head.bytes);
  return head;
}

void FrameSplitter::feed(std::span<const uint8_t> bytes) {
  if (error_) return;
  // Compact before growing, so the buffer holds at most one partial frame
  // plus this feed.
  if (consumed_ > 0 && (consumed_ == buffer_.size() || consumed_ >= buffer_.size() / 2)) {
    buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<ptrdiff_t>(consumed_));
    consumed_ = 0;
  }
  buffer_.insert(buffer_.end(), bytes.begin(), bytes.end());
}

Result<std::optional<std::span<const uint8_t>>> FrameSplitter::next() {
  if (error_) return tl::unexpected(*error_);
  const uint8_t* p = buffer_.data() + consumed_;
  const size_t available = buffer_.size() - consumed_;
  uint64_t length = 0;
  size_t prefix = 0;
  bool complete = false;
  for (; prefix < available && prefix < kMaxVarint32Bytes; ++prefix) {
    length |= uint64_t(p[prefix] & 0x7f) << (7 * prefix);
    if ((p[prefix] & 0x80) == 0) {
      complete = true;
      ++prefix;
      break;
    }
  }
  if (!complete) {
    if (available >= kMaxVarint32Bytes) {
      error_ = Error{ErrorCode::kParse, "frame length prefix is longer than 5 bytes"};
      return tl::unexpected(*error_);
    }
    // Even a partial prefix can already be too large: the bits so far only grow.
    if (length > max_frame_bytes_) {
      error_ = Error{ErrorCode::kLimit, "frame length prefix exceeds the limit of " +
                                            std::to_string(max_frame_bytes_) + " bytes"};
      return tl::unexpected(*error_);
    }
    return std::optional<std::span<const uint8_t>>{};
  }
  if (length > UINT32_MAX) {
    error_ = Error{ErrorCode::kParse, "frame length prefix does not fit 32 bits"};
    return tl::unexpected(*error_);
  }
  if (length > max_frame_bytes_) {
    error_ = Error{ErrorCode::kLimit, "frame of " + std::to_string(length) +
                                          " bytes exceeds the limit of " +
                                          std::to_string(max_frame_bytes_) + " bytes"};
    return tl::unexpected(*error_);
  }
  if (available - prefix < length) return std::optional<std::span<const uint8_t>>{};
  consumed_ += prefix + length;
  return std::optional<std::span<const uint8_t>>(std::span<const uint8_t>(p + prefix, length));
}

}  // namespace meshstream::proto

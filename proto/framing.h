// Frames on a meshstream connection: each protobuf message is preceded by its
// length as a varint32 (protobuf's delimited format; the protocol itself is
// specified in proto/meshstream.proto). One implementation shared by the
// server, the client and the fuzzers.
//
//   std::vector<uint8_t> bytes = encode_frame(message);   // to send
//   FrameReader<v1::ServerMessage> reader(kMaxServerFrameBytes);
//   reader.feed(received);                                 // as bytes arrive
//   while (true) {
//     auto m = reader.next();          // Result<optional<ServerMessage>>
//     if (!m) { /* bad stream: m.error() */ break; }
//     if (!*m) break;                  // need more bytes
//     handle(**m);
//   }
#pragma once

#include <google/protobuf/message_lite.h>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "common/base/result.h"
#include "proto/meshstream.pb.h"

namespace meshstream::proto {

namespace v1 = ::meshstream::v1;

// The protocol version of proto/meshstream.proto (Hello.protocol_version).
inline constexpr uint32_t kProtocolVersion = 1;
// Default limit for client frames at the server (requests are tiny).
inline constexpr uint32_t kDefaultMaxClientFrameBytes = 64 * 1024;
// Server frames never exceed this (a header with a large record index is
// the biggest); clients refuse longer ones.
inline constexpr uint32_t kMaxServerFrameBytes = 64u << 20;
// Longest varint32 encoding.
inline constexpr size_t kMaxVarint32Bytes = 5;

// Appends `value` as a base-128 varint (at most 10 bytes). O(1).
void append_varint(std::vector<uint8_t>& out, uint64_t value);
// Bytes append_varint writes for `value`.
size_t varint_size(uint64_t value);

// Serializes `message` preceded by its length as a varint32. Allocates the
// result; the message must be smaller than 4 GiB (a programming error
// otherwise: throws std::length_error).
std::vector<uint8_t> encode_frame(const google::protobuf::MessageLite& message);
// The same, appended to `out` (no new buffer when `out` has room).
void append_frame(const google::protobuf::MessageLite& message, std::vector<uint8_t>& out);

// Zero-copy chunk frames: the bytes of a complete frame holding
// ServerMessage{chunk: Chunk{offset, records_complete, data}} are
// `head` followed by the `data_size` data bytes themselves, so a server can
// send data straight from its memory map (scatter-gather write). The head is
// byte-identical to what the generated serializer writes. O(1), no
// allocation.
struct ChunkFrameHead {
  uint8_t bytes[32];
  size_t size = 0;
};
ChunkFrameHead encode_chunk_frame_head(uint64_t offset, uint32_t records_complete,
                                       size_t data_size);

// Splits a byte stream into frame payloads without parsing them. Refuses a
// length prefix above `max_frame_bytes` as soon as the prefix itself has
// arrived (before buffering or allocating for the frame), a varint longer
// than 5 bytes. A zero length is a valid (empty) frame. After an error every later call returns
// the same error. Memory: at most max_frame_bytes + one feed buffered.
class FrameSplitter {
 public:
  explicit FrameSplitter(size_t max_frame_bytes) : max_frame_bytes_(max_frame_bytes) {}

  // Appends received bytes (copied).
  void feed(std::span<const uint8_t> bytes);

  // The next complete frame's payload (valid until the next feed/next call),
  // nullopt when more bytes are needed, kLimit for an oversized length,
  // kParse for a malformed varint.
  Result<std::optional<std::span<const uint8_t>>> next();

  // Bytes received but not yet returned as frames.
  size_t buffered() const { return buffer_.size() - consumed_; }
  size_t max_frame_bytes() const { return max_frame_bytes_; }

 private:
  size_t max_frame_bytes_;
  std::vector<uint8_t> buffer_;
  size_t consumed_ = 0;
  std::optional<Error> error_;
};

// Parses frames into `Message` (v1::ClientMessage or v1::ServerMessage).
// Errors: as FrameSplitter, plus kParse when a frame's bytes do not parse
// as `Message`.
template <class Message>
class FrameReader {
 public:
  explicit FrameReader(size_t max_frame_bytes) : splitter_(max_frame_bytes) {}

  void feed(std::span<const uint8_t> bytes) { splitter_.feed(bytes); }

  // The next complete message, nullopt when more bytes are needed.
  Result<std::optional<Message>> next() {
    auto frame = splitter_.next();
    if (!frame) return tl::unexpected(frame.error());
    if (!*frame) return std::optional<Message>{};
    Message message;
    if (!message.ParseFromArray((*frame)->data(), static_cast<int>((*frame)->size()))) {
      return make_error(ErrorCode::kParse, "frame of " + std::to_string((*frame)->size()) +
                                               " bytes is not a valid " + message.GetTypeName());
    }
    return std::optional<Message>(std::move(message));
  }

  size_t buffered() const { return splitter_.buffered(); }

 private:
  FrameSplitter splitter_;
};

using ClientFrameReader = FrameReader<v1::ClientMessage>;
using ServerFrameReader = FrameReader<v1::ServerMessage>;

}  // namespace meshstream::proto

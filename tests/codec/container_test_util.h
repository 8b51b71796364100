// Checks every container version's tests share (container.h).
#pragma once

#include <gtest/gtest.h>

#include <cstddef>
#include <cstdint>
#include <span>

#include "common/codec/container.h"

namespace meshstream::testing {

// Every prefix of `stream` shorter than its magic, header and index (its
// first `payload_offset` bytes) reads as kTruncated, never as bad data: a
// client that has received that much must wait for more. O(payload_offset^2).
inline void expect_every_short_prefix_truncated(std::span<const uint8_t> stream,
                                                uint64_t payload_offset) {
  for (size_t n = 0; n < payload_offset; ++n) {
    auto index = read_stream_index(stream.first(n));
    ASSERT_FALSE(index) << "prefix " << n;
    EXPECT_EQ(index.error().code, ErrorCode::kTruncated) << "prefix " << n;
  }
}

}  // namespace meshstream::testing

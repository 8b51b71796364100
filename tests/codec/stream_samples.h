// The stream fixtures of tests/codec/data (streams written by earlier
// encoder versions, kept so that they go on decoding).
#pragma once

#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace meshstream::testing {

// The bytes of fixture `name`; a failed expectation (and no bytes) when it
// cannot be read.
inline std::vector<uint8_t> read_sample(const std::string& name) {
  std::ifstream in(std::string(MESHSTREAM_SOURCE_DIR) + "/tests/codec/data/" + name,
                   std::ios::binary);
  EXPECT_TRUE(in) << name;
  return std::vector<uint8_t>{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace meshstream::testing

// An 8-bit RGBA image, top row first, and PNG files of it (libpng).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/base/result.h"

namespace meshstream::client {

struct RgbaImage {
  int width = 0;
  int height = 0;
  std::vector<uint8_t> rgba;  // width * height * 4 bytes, row 0 at the top

  const uint8_t* pixel(int x, int y) const {
    return &rgba[(static_cast<size_t>(y) * width + x) * 4];
  }
};

// Writes an RGBA PNG. kInvalidArgument for an image whose buffer does not
// match its size; kIo naming the path when it cannot be written. O(pixels).
Status write_png(const std::string& path, const RgbaImage& image);

// Reads any PNG libpng understands, converted to 8-bit RGBA. kIo when the
// file cannot be opened, kParse naming the path when it is not a valid PNG.
Result<RgbaImage> read_png(const std::string& path);

// Reverses the row order in place (OpenGL reads bottom row first).
void flip_rows(RgbaImage& image);

}  // namespace meshstream::client

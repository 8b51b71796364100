// Pixel statistics the viewer tests assert on.
#pragma once

#include <algorithm>
#include <cstdlib>
#include <string>

#include "client/viewer/rgba_image.h"

namespace meshstream::client::testing {

inline bool same_pixel(const uint8_t* a, const uint8_t* b, int tolerance = 6) {
  return std::abs(a[0] - b[0]) <= tolerance && std::abs(a[1] - b[1]) <= tolerance &&
         std::abs(a[2] - b[2]) <= tolerance;
}

struct Coverage {
  size_t foreground = 0;  // pixels unlike the top-left (background) pixel
  int min_x = 0, min_y = 0, max_x = -1, max_y = -1;
};

inline Coverage foreground_coverage(const RgbaImage& image) {
  Coverage c;
  c.min_x = image.width;
  c.min_y = image.height;
  const uint8_t* background = image.pixel(0, 0);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      if (same_pixel(image.pixel(x, y), background)) continue;
      ++c.foreground;
      c.min_x = std::min(c.min_x, x);
      c.max_x = std::max(c.max_x, x);
      c.min_y = std::min(c.min_y, y);
      c.max_y = std::max(c.max_y, y);
    }
  }
  return c;
}

// Keeps a test's picture for a person to look at when
// $MESHSTREAM_VIEWER_TEST_IMAGES names a folder.
inline void keep_for_inspection(const RgbaImage& image, const std::string& name) {
  if (const char* dir = std::getenv("MESHSTREAM_VIEWER_TEST_IMAGES"); dir && *dir) {
    (void)write_png(std::string(dir) + "/" + name + ".png", image);
  }
}

inline size_t differing_pixels(const RgbaImage& a, const RgbaImage& b) {
  if (a.width != b.width || a.height != b.height) return static_cast<size_t>(a.width) * a.height;
  size_t count = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) count += same_pixel(a.pixel(x, y), b.pixel(x, y)) ? 0 : 1;
  return count;
}

// Pixels whose colour is strongly orange (the ASA "target" colour) or green
// (bisected), however lit.
inline size_t orange_pixels(const RgbaImage& image) {
  size_t count = 0;
  for (size_t i = 0; i + 3 < image.rgba.size(); i += 4) {
    int r = image.rgba[i], g = image.rgba[i + 1], b = image.rgba[i + 2];
    count += (r > 80 && r > g + 25 && g > b + 25) ? 1 : 0;
  }
  return count;
}

inline size_t green_pixels(const RgbaImage& image) {
  size_t count = 0;
  for (size_t i = 0; i + 3 < image.rgba.size(); i += 4) {
    int r = image.rgba[i], g = image.rgba[i + 1], b = image.rgba[i + 2];
    count += (g > 60 && g > r + 30 && g > b + 30) ? 1 : 0;
  }
  return count;
}

}  // namespace meshstream::client::testing

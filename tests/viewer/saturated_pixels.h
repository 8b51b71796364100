// Counting the saturated pixels of a picture by hue: what tells a textured
// or coloured rendering from a grey one (textured_render_test,
// textured_stream_test).
#pragma once

#include <algorithm>
#include <array>
#include <cstdlib>

#include "client/viewer/rgba_image.h"

namespace meshstream::client::testing {

// Pixels by the checker colour they are nearest to in hue (red, green,
// blue, yellow), counting only clearly saturated ones (max - min channel
// above `min_spread` of 255): grey shading and the background count nowhere.
inline std::array<int, 4> saturated_by_hue(const RgbaImage& image, int min_spread = 60) {
  std::array<int, 4> counts{};
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const uint8_t* p = image.pixel(x, y);
      const int r = p[0], g = p[1], b = p[2];
      if (std::max({r, g, b}) - std::min({r, g, b}) <= min_spread) continue;
      if (r > 2 * b && g > 2 * b && std::abs(r - g) < (r + g) / 4)
        ++counts[3];  // yellow: red and green, no blue
      else if (r >= g && r >= b)
        ++counts[0];
      else if (g >= r && g >= b)
        ++counts[1];
      else
        ++counts[2];
    }
  }
  return counts;
}

inline int saturated_total(const std::array<int, 4>& hues) {
  return hues[0] + hues[1] + hues[2] + hues[3];
}

}  // namespace meshstream::client::testing

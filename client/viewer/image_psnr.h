// Peak signal-to-noise ratio of two pictures of the same size, over the RGB
// channels of every pixel: 10 log10(255^2 / MSE). Identical pictures give
// infinity; a size mismatch gives 0. For comparing snapshots (view-dependent
// ASA against whole-mesh ASA) in tests and benchmarks.
#pragma once

#include <cmath>
#include <cstddef>
#include <limits>

#include "client/viewer/rgba_image.h"

namespace meshstream::client {

inline double psnr_rgb(const RgbaImage& a, const RgbaImage& b) {
  if (a.width != b.width || a.height != b.height || a.rgba.size() != b.rgba.size() ||
      a.rgba.empty())
    return 0;
  double sum = 0;
  for (size_t i = 0; i < a.rgba.size(); i += 4) {
    for (size_t k = 0; k < 3; ++k) {
      const double d = static_cast<double>(a.rgba[i + k]) - static_cast<double>(b.rgba[i + k]);
      sum += d * d;
    }
  }
  const double mse = sum / (3.0 * static_cast<double>(a.rgba.size() / 4));
  if (mse == 0) return std::numeric_limits<double>::infinity();
  return 10.0 * std::log10(255.0 * 255.0 / mse);
}

}  // namespace meshstream::client

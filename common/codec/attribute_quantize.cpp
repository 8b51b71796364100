// See attribute_quantize.h.
#include "common/codec/attribute_quantize.h"

#include <algorithm>
#include <cmath>

namespace meshstream {

namespace {
int32_t max_of(int bits) { return (int32_t(1) << bits) - 1; }
}  // namespace

std::array<int32_t, 2> quantize_direction(double x, double y, double z, int bits) {
  const double l1 = std::abs(x) + std::abs(y) + std::abs(z);
  double u = 0, v = 0;
  if (l1 > 0 && std::isfinite(l1)) {
    u = x / l1;
    v = y / l1;
    if (z < 0) {
      const double fu = (1 - std::abs(v)) * (u < 0 ? -1 : 1);
      const double fv = (1 - std::abs(u)) * (v < 0 ? -1 : 1);
      u = fu;
      v = fv;
    }
  }
  const int32_t m = max_of(bits);
  auto to_grid = [m](double c) {
    return std::clamp<int32_t>(static_cast<int32_t>(std::lround((c + 1) * 0.5 * m)), 0, m);
  };
  return {to_grid(u), to_grid(v)};
}

std::array<int32_t, 2> quantize_normal(Vec3f n, int bits) {
  return quantize_direction(n.x, n.y, n.z, bits);
}

Vec3f dequantize_normal(std::array<int32_t, 2> q, int bits) {
  const double m = max_of(bits);
  double u = q[0] / m * 2 - 1, v = q[1] / m * 2 - 1;
  double z = 1 - std::abs(u) - std::abs(v);
  if (z < 0) {
    const double fu = (1 - std::abs(v)) * (u < 0 ? -1 : 1);
    const double fv = (1 - std::abs(u)) * (v < 0 ? -1 : 1);
    u = fu;
    v = fv;
  }
  const double len = std::sqrt(u * u + v * v + z * z);
  return Vec3f{float(u / len), float(v / len), float(z / len)};
}

TexcoordGrid make_texcoord_grid(const Vec2f* values, size_t count, int bits) {
  TexcoordGrid g;
  g.bits = bits;
  if (count == 0) return g;
  Vec2f lo = values[0], hi = values[0];
  for (size_t i = 1; i < count; ++i) {
    lo.x = std::min(lo.x, values[i].x);
    lo.y = std::min(lo.y, values[i].y);
    hi.x = std::max(hi.x, values[i].x);
    hi.y = std::max(hi.y, values[i].y);
  }
  g.min = lo;
  const double extent = std::max(double(hi.x) - lo.x, double(hi.y) - lo.y);
  g.step = extent > 0 ? extent / max_of(bits) : 1.0;
  return g;
}

std::array<int32_t, 2> quantize_texcoord(const TexcoordGrid& g, Vec2f t) {
  const int32_t m = max_of(g.bits);
  auto axis = [&](float value, float lo) {
    return std::clamp<int32_t>(static_cast<int32_t>(std::lround((double(value) - lo) / g.step)), 0,
                               m);
  };
  return {axis(t.x, g.min.x), axis(t.y, g.min.y)};
}

Vec2f dequantize_texcoord(const TexcoordGrid& g, std::array<int32_t, 2> q) {
  return Vec2f{float(double(g.min.x) + q[0] * g.step), float(double(g.min.y) + q[1] * g.step)};
}

int32_t quantize_color_channel(float c, int bits) {
  const int32_t m = max_of(bits);
  const double v = std::isfinite(c) ? std::clamp(double(c), 0.0, 1.0) : 0.0;
  return static_cast<int32_t>(std::lround(v * m));
}

float dequantize_color_channel(int32_t q, int bits) { return float(double(q) / max_of(bits)); }

}  // namespace meshstream

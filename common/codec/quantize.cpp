// Grid quantization: see quantize.h. Dequantization is min + q * step in
// double, rounded to float once, so encoder (quantized_reference) and decoder
// give identical floats.
#include "common/codec/quantize.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace meshstream {

double QuantGrid::step() const {
  const double extent =
      std::max({double(bounds.max.x) - bounds.min.x, double(bounds.max.y) - bounds.min.y,
                double(bounds.max.z) - bounds.min.z});
  return extent > 0 ? extent / double(max_coordinate()) : 0.0;
}

Vec3i QuantGrid::quantize(Vec3f p) const {
  const double s = step();
  Vec3i q;
  for (int a = 0; a < 3; ++a) {
    const double v = s > 0 ? (double(p[a]) - double(bounds.min[a])) / s : 0.0;
    q[a] = static_cast<int32_t>(std::clamp(std::llround(v), 0LL, (long long)max_coordinate()));
  }
  return q;
}

Vec3f QuantGrid::dequantize(Vec3i q) const {
  const double s = step();
  return {static_cast<float>(double(bounds.min.x) + q.x * s),
          static_cast<float>(double(bounds.min.y) + q.y * s),
          static_cast<float>(double(bounds.min.z) + q.z * s)};
}

Result<QuantGrid> make_grid(const Mesh& mesh, int bits) {
  if (bits < kMinQuantBits || bits > kMaxQuantBits) {
    return make_error(ErrorCode::kInvalidArgument,
                      "quantization bits must be 8..20, got " + std::to_string(bits));
  }
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    const Vec3f& p = mesh.positions[v];
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      return make_error(ErrorCode::kInvalidMesh,
                        "vertex " + std::to_string(v) + " has a non-finite coordinate");
    }
  }
  QuantGrid grid;
  grid.bounds = bounding_box(mesh);
  grid.bits = bits;
  return grid;
}

std::vector<Vec3i> quantize_positions(const Mesh& mesh, const QuantGrid& grid) {
  std::vector<Vec3i> out(mesh.positions.size());
  for (size_t v = 0; v < out.size(); ++v) out[v] = grid.quantize(mesh.positions[v]);
  return out;
}

}  // namespace meshstream

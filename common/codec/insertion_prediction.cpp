// Insertion prediction and coarse residuals: see insertion_prediction.h.
#include "common/codec/insertion_prediction.h"

namespace meshstream {

void encode_coarse_residual(RefinementModels& models, RangeEncoder& enc, const ResidualContext& ctx,
                            Vec3i actual, Vec3i predicted, int shift, VertexGeometry& out) {
  const int bucket = std::max(ctx.scale - shift, 0);
  out = VertexGeometry{};
  out.anchor = predicted;
  out.shift = static_cast<uint8_t>(shift);
  out.normal_axis = static_cast<uint8_t>(ctx.axis[0]);
  for (int role = 0; role < 3; ++role) {
    const int a = ctx.axis[role];
    const int32_t r = actual[a] - predicted[a];
    const uint32_t mag = uint32_t(std::abs(r)) >> shift;
    int32_t q = r < 0 ? -int32_t(mag) : int32_t(mag);
    out.mag[a] = mag;
    if (mag > 0 && r < 0) out.negative |= uint8_t(1u << a);
    if (role == 0 && ctx.flip) q = -q;
    models.residual[bucket][role].encode(enc, q);
  }
}

bool decode_coarse_residual(RefinementModels& models, RangeDecoder& dec, const ResidualContext& ctx,
                            Vec3i predicted, int shift, int32_t max_coordinate,
                            VertexGeometry& out) {
  return decode_residual_inline(models, dec, ctx, predicted, shift, max_coordinate, out);
}

void predict_insertion(const RefinementState& s, const std::vector<uint32_t>& ring, int min_shift,
                       InsertionPrediction& out) {
  predict_insertion_inline(s, ring, min_shift, out);
}
}  // namespace meshstream

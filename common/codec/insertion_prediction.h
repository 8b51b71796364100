// A vertex's position at insertion: the prediction from its ring and the
// residual's context (both sides compute them alike, integer-exact), and the
// coarse residual coded against that prediction.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <utility>
#include <vector>

#include "common/codec/embedded_geometry.h"
#include "common/codec/range_coder.h"
#include "common/codec/refinement_state.h"
#include "common/codec/structure_models.h"

namespace meshstream {

// How a residual is modelled: `scale` (log2 of the ring's mean L1 edge
// length on the grid) picks the model set; the axes are taken in order of
// the ring normal's components, largest first (role 0 is the axis closest to
// the normal: its residual is the curvature offset, the other two are
// tangential slip), and role 0's sign is flipped when the normal points down
// that axis so "outward" is always the same symbol. Integer-exact: the
// normal is a sum of integer cross products.
struct ResidualContext {
  int scale = 0;
  int axis[3] = {0, 1, 2};
  bool flip = false;
};
// What both sides know of a vertex inserted into `ring` before its
// residual: `predicted`, the rounded average of the ring's positions (exact
// integers); `ctx`, its residual context; `shift`, the precision it starts
// with: the coarsest of its ring vertices' (a finer residual would be below
// the prediction's own uncertainty), at least the record's `min_shift`. One
// function for the encoder and the decoder, so they cannot disagree. O(k).
struct InsertionPrediction {
  Vec3i predicted;
  ResidualContext ctx;
  int shift = 0;
};
void predict_insertion(const RefinementState& s, const std::vector<uint32_t>& ring, int min_shift,
                       InsertionPrediction& out);
// The residual of an inserted vertex at insertion, with its `shift` low
// bits left to plane records: per role the value sign * (|r| >> shift)
// through the model of scale bucket max(scale - shift, 0). `out` becomes the
// vertex's geometry (anchor = predicted). shift 0 codes exactly as format 1.
void encode_coarse_residual(RefinementModels& models, RangeEncoder& enc, const ResidualContext& ctx,
                            Vec3i actual, Vec3i predicted, int shift, VertexGeometry& out);
// Returns false when the decoded residual cannot belong to a grid position
// (shift 0: the position leaves the grid [0, max_coordinate]).
bool decode_coarse_residual(RefinementModels& models, RangeDecoder& dec, const ResidualContext& ctx,
                            Vec3i predicted, int shift, int32_t max_coordinate,
                            VertexGeometry& out);

// The decoder's bodies of decode_coarse_residual and predict_insertion,
// forced inline into the structure record reader's loop so its range
// decoder stays in registers (MESHSTREAM_DECODE_INLINE, range_coder.h).
MESHSTREAM_DECODE_INLINE bool decode_residual_inline(RefinementModels& models, RangeDecoder& dec,
                                                     const ResidualContext& ctx, Vec3i predicted,
                                                     int shift, int32_t max_coordinate,
                                                     VertexGeometry& out) {
  const int bucket = std::max(ctx.scale - shift, 0);
  out = VertexGeometry{};
  out.anchor = predicted;
  out.shift = static_cast<uint8_t>(shift);
  out.normal_axis = static_cast<uint8_t>(ctx.axis[0]);
  for (int role = 0; role < 3; ++role) {
    const int a = ctx.axis[role];
    int64_t q = models.residual[bucket][role].decode(dec);
    if (role == 0 && ctx.flip) q = -q;
    const int64_t mag = q < 0 ? -q : q;
    if ((mag << shift) > int64_t(max_coordinate)) return false;
    if (shift == 0) {
      const int64_t value = int64_t(predicted[a]) + q;
      if (value < 0 || value > max_coordinate) return false;
    }
    out.mag[a] = static_cast<uint32_t>(mag);
    if (q < 0) out.negative |= uint8_t(1u << a);
  }
  return true;
}

// predict_insertion (refinement_codec.h), forced inline into the decoder's
// record loop. One pass over the ring: the sums run in ring order, and the
// normal skips only the two cross products that are zero (those with the
// apex itself, whose offset from the apex is 0). The divisions by k are
// 32-bit when the dividends fit (they do for grid coordinates < 2^20 and
// k <= 16), which gives the same quotients as the 64-bit ones.
MESHSTREAM_DECODE_INLINE void predict_insertion_inline(const RefinementState& s,
                                                       const std::vector<uint32_t>& ring,
                                                       int min_shift, InsertionPrediction& out) {
  const Vec3i* p = s.mesh.positions().data();
  const uint8_t* vertex_shift = s.vertex_shift.data();
  const size_t k = ring.size();
  const Vec3i o = p[ring[0]];
  int64_t sx = o.x, sy = o.y, sz = o.z;
  int shift = std::max<int>(min_shift, vertex_shift[ring[0]]);
  int64_t total = 0;
  int64_t n0 = 0, n1 = 0, n2 = 0;
  int64_t px = 0, py = 0, pz = 0;  // the previous ring vertex's offset from the apex
  Vec3i a = o;
  for (size_t i = 1; i < k; ++i) {
    const uint32_t u = ring[i];
    const Vec3i b = p[u];
    sx += b.x;
    sy += b.y;
    sz += b.z;
    shift = std::max<int>(shift, vertex_shift[u]);
    total +=
        std::abs(int64_t(a.x) - b.x) + std::abs(int64_t(a.y) - b.y) + std::abs(int64_t(a.z) - b.z);
    const int64_t dx = int64_t(b.x) - o.x, dy = int64_t(b.y) - o.y, dz = int64_t(b.z) - o.z;
    n0 += py * dz - pz * dy;
    n1 += pz * dx - px * dz;
    n2 += px * dy - py * dx;
    px = dx;
    py = dy;
    pz = dz;
    a = b;
  }
  total +=
      std::abs(int64_t(a.x) - o.x) + std::abs(int64_t(a.y) - o.y) + std::abs(int64_t(a.z) - o.z);

  const int64_t sum[3] = {sx, sy, sz};
  const int64_t kk = static_cast<int64_t>(k);
  for (int c = 0; c < 3; ++c) {
    const int64_t num = sum[c] + kk / 2;
    out.predicted[c] = num >= 0 && num <= int64_t(UINT32_MAX)
                           ? static_cast<int32_t>(uint32_t(num) / uint32_t(k))
                           : static_cast<int32_t>(num / kk);
  }
  const uint64_t mean = (uint64_t(total) <= UINT32_MAX ? uint64_t(uint32_t(total) / uint32_t(k))
                                                       : uint64_t(total) / k) +
                        1;
  ResidualContext& ctx = out.ctx;
  ctx = ResidualContext{};
  // log2 of the mean L1 edge length, in integers: octave buckets (finer
  // buckets measured slightly worse: too little data per model).
  ctx.scale = std::clamp(63 - __builtin_clzll(mean), 0, kScaleContexts - 1);
  // Axes by |normal component|, largest first; ties keep axis order.
  const int64_t n[3] = {n0, n1, n2};
  const int64_t m[3] = {std::abs(n0), std::abs(n1), std::abs(n2)};
  auto before = [&](int x, int y) { return m[x] > m[y] || (m[x] == m[y] && x < y); };
  int* ax = ctx.axis;
  if (before(ax[1], ax[0])) std::swap(ax[0], ax[1]);
  if (before(ax[2], ax[1])) std::swap(ax[1], ax[2]);
  if (before(ax[1], ax[0])) std::swap(ax[0], ax[1]);
  ctx.flip = n[ctx.axis[0]] < 0;
  out.shift = shift;
}

}  // namespace meshstream

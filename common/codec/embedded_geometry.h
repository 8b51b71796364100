// Successive-approximation geometry (HCS's "attribute data", Li & Kuo 1998):
// a vertex's position is known to the decoder only as precisely as the bit
// planes of its residual received so far, most significant first, and
// sharpens as later plane records arrive.
//
// Per vertex both sides keep a VertexGeometry: the anchor (the prediction
// the residual is relative to, fixed at insertion, made from what the
// decoder knew then), the known high part of the residual per axis and the
// number of low bits still unknown (`shift`). Inserted vertices use a
// sign-magnitude (dead-zone) quantizer: |r| >> shift and, once that is
// non-zero, the sign; base vertices have an unsigned offset in [0, 2^shift)
// below their coarse grid point. The reconstruction (reconstruct()) is a pure
// integer function of that state, so the encoder's model and the decoder's
// mesh agree bit for bit at every record boundary.
//
// A plane step lowers a vertex's shift by one: per axis, a refinement bit
// when the axis is already significant, otherwise a significance bit
// followed by the sign when it becomes significant. The bits go through a
// context-adaptive binary arithmetic coder (the range coder's adaptive bit
// models) with contexts from the plane, the axis's role (the axis closest to
// the ring normal at insertion, a tangential axis, or a base vertex), how
// many axes of the vertex are significant, and whether the previous vertex
// of the record (a surface neighbour: ids of a batch are inserted around the
// same walk vertices) became significant on this axis in the same plane.
#pragma once

#include <cstdint>
#include <cstdlib>

#include "common/codec/quantize.h"
#include "common/codec/range_coder.h"

namespace meshstream {

inline constexpr uint8_t kBaseVertexAxis = 3;  // VertexGeometry::normal_axis of a base vertex
inline constexpr int kMaxShift = 20;

struct VertexGeometry {
  Vec3i anchor;
  uint32_t mag[3] = {0, 0, 0};  // inserted: |r| >> shift; base: r >> shift
  uint8_t shift = 0;            // low residual bits still unknown
  uint8_t negative = 0;         // bit a: axis a's residual is negative (known once mag[a] > 0)
  uint8_t normal_axis = 0;      // 0..2, or kBaseVertexAxis
};

// The position the decoder shows: anchor plus the middle of the residual's
// known interval (0 for an inserted axis not yet significant), clamped to
// the grid [0, max_coordinate]. Exact when shift == 0.
inline Vec3i reconstruct(const VertexGeometry& g, int32_t max_coordinate) {
  Vec3i out;
  const int64_t half = ((int64_t(1) << g.shift) - 1) >> 1;
  for (int a = 0; a < 3; ++a) {
    int64_t v = g.anchor[a];
    if (g.normal_axis == kBaseVertexAxis) {
      v += (int64_t(g.mag[a]) << g.shift) + half;
    } else if (g.mag[a] > 0) {
      const int64_t off = (int64_t(g.mag[a]) << g.shift) + half;
      v += (g.negative >> a) & 1 ? -off : off;
    }
    out[a] = static_cast<int32_t>(v < 0 ? 0 : v > max_coordinate ? max_coordinate : v);
  }
  return out;
}

// Adaptive models of the plane bits (persist across records).
struct GeometryModels {
  // [min(plane, 7)][role: 0 normal axis, 1 tangential, 2 base]
  // [state: 0..5 significance (significant axes 0..2 x previous vertex's
  //  axis became significant in this plane), 6 first refinement bit, 7 later]
  BitModel plane[8][3][8];
  BitModel sign[3];  // by role
};

inline int axis_role(const VertexGeometry& g, int a) {
  return g.normal_axis == kBaseVertexAxis ? 2 : (a == g.normal_axis ? 0 : 1);
}

// Encoder side of a plane step: knows the true residual (inserted: signed;
// base: the unsigned offset below the coarse point).
struct PlaneBitWriter {
  RangeEncoder& enc;
  Vec3i residual;
  uint32_t bit(BitModel& m, int axis, int below) {
    const uint32_t b = (uint32_t(std::abs(residual[axis])) >> below) & 1u;
    enc.encode_bit(m, b);
    return b;
  }
  uint32_t sign(BitModel& m, int axis) {
    const uint32_t b = residual[axis] < 0 ? 1u : 0u;
    enc.encode_bit(m, b);
    return b;
  }
};

struct PlaneBitReader {
  RangeDecoder& dec;
  uint32_t bit(BitModel& m, int, int) { return dec.decode_bit(m); }
  uint32_t sign(BitModel& m, int) { return dec.decode_bit(m); }
};

// One plane step of vertex g (precondition: g.shift > 0). `prev_new` (bit a:
// the previous vertex of this record became significant on axis a in this
// step) is read and replaced by this vertex's. Returns false when the
// decoded magnitude could not belong to a grid position (hostile bytes).
template <class Io>
bool plane_step(GeometryModels& m, Io& io, VertexGeometry& g, uint8_t& prev_new,
                int32_t max_coordinate) {
  const int below = g.shift - 1;
  const int plane = below < 7 ? below : 7;
  const bool base = g.normal_axis == kBaseVertexAxis;
  int significant = 0;
  if (!base)
    for (int a = 0; a < 3; ++a) significant += g.mag[a] > 0 ? 1 : 0;
  uint8_t now_new = 0;
  for (int a = 0; a < 3; ++a) {
    const int role = axis_role(g, a);
    uint32_t state;
    if (base || g.mag[a] > 0) {
      state = g.mag[a] == 1 ? 6 : 7;
    } else {
      state = uint32_t(significant > 2 ? 2 : significant) * 2 + ((prev_new >> a) & 1);
    }
    const uint32_t b = io.bit(m.plane[plane][role][state], a, below);
    if (!base && g.mag[a] == 0 && b) {
      const uint32_t s = io.sign(m.sign[role], a);
      g.negative = static_cast<uint8_t>((g.negative & ~(1u << a)) | (s << a));
      now_new |= uint8_t(1u << a);
    }
    g.mag[a] = g.mag[a] * 2 + b;
    if ((int64_t(g.mag[a]) << below) > int64_t(max_coordinate)) return false;
  }
  g.shift = static_cast<uint8_t>(below);
  prev_new = now_new;
  return true;
}

}  // namespace meshstream

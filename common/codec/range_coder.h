// Adaptive binary range coder (the carry-propagating coder of LZMA, Igor
// Pavlov, public domain; described in G. N. N. Martin, "Range encoding", 1979)
// with adaptive bit models, bit trees for small alphabets, and an adaptive
// Exp-Golomb integer coder built from them.
//
// Why this coder: every refinement symbol (patch counts, ring offsets,
// valences) and every residual is a small integer with a skewed, drifting
// distribution; adaptive binary models learn it in a few dozen symbols and the
// coder is fast (one multiply per bit). The decoder never reads outside its
// span: bytes past the end read as zero and are counted, so a truncated or
// corrupt record decodes to garbage symbols that the caller range-checks, and
// `overrun()` reports that the input ran out.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace meshstream {

#define MESHSTREAM_MODEL_INLINE [[gnu::always_inline]] inline

// Probability of a 0 bit in units of 1/2048 (11 bits, as LZMA).
struct BitModel {
  uint16_t p = 1024;
};

// A bit model whose adaptation slows as it learns (refinement format 3):
// the first 2 bits move the probability by 1/4 of the error, the next 4 by
// 1/8, the next 8 by 1/16, then by 1/32 as BitModel: a fixed 1/32 learns
// the many sparsely used contexts slowly (small meshes), a faster fixed rate
// loses on large ones (the rates measured: docs/hcs-format.md, "Entropy
// coder").
// `state` holds the probability of a 0 in its low 11 bits (as BitModel's p)
// and the number of bits seen, saturating at 14, in its top bits: the same
// 2 bytes as a BitModel (a wider model measured slower to decode).
struct FastStartBitModel {
  uint16_t state = 1024;
};
inline constexpr uint32_t kFastStartSeenShift = 11;
inline constexpr uint32_t kFastStartSeenMax = 14;
// Adaptation shift of a FastStartBitModel that has seen `n` bits (n <= 14).
inline constexpr uint32_t fast_start_rate(uint32_t n) {
  return 2 + (n >= 2) + (n >= 6) + (n >= 14);
}
// The model's state after coding a 0 / a 1 (one function per bit, so the
// decoder updates inside the branch that found the bit).
MESHSTREAM_MODEL_INLINE uint16_t fast_start_after0(uint32_t state) {
  const uint32_t p = state & 2047u;
  if (state >= (kFastStartSeenMax << kFastStartSeenShift)) {
    // Learned (most bits of a large mesh): BitModel's update, which keeps
    // p within 11 bits, so the count bits above stay as they are.
    return static_cast<uint16_t>(state + ((2048u - p) >> 5));
  }
  const uint32_t n = state >> kFastStartSeenShift;  // < kFastStartSeenMax
  return static_cast<uint16_t>((p + ((2048u - p) >> fast_start_rate(n))) |
                               ((n + 1) << kFastStartSeenShift));
}
MESHSTREAM_MODEL_INLINE uint16_t fast_start_after1(uint32_t state) {
  const uint32_t p = state & 2047u;
  if (state >= (kFastStartSeenMax << kFastStartSeenShift))
    return static_cast<uint16_t>(state - (p >> 5));
  const uint32_t n = state >> kFastStartSeenShift;
  return static_cast<uint16_t>((p - (p >> fast_start_rate(n))) | ((n + 1) << kFastStartSeenShift));
}
MESHSTREAM_MODEL_INLINE uint16_t fast_start_next(uint32_t state, uint32_t bit) {
  return bit == 0 ? fast_start_after0(state) : fast_start_after1(state);
}

class RangeEncoder {
 public:
  void encode_bit(BitModel& model, uint32_t bit);
  void encode_bit(FastStartBitModel& model, uint32_t bit);
  // Equiprobable bits, most significant first (count <= 32).
  void encode_direct(uint32_t value, int count);
  // Ends the stream; returns the bytes. The encoder is spent afterwards.
  std::vector<uint8_t> finish();
  size_t bytes_so_far() const { return out_.size() + cache_size_; }
  // Measurement only: while set, every coded bit adds its ideal cost
  // (-log2 of the probability the model gave it; 1 per direct bit) to
  // *sink, so an encoder can tell which symbols the bytes went to. Costs one
  // branch per bit when unset. nullptr stops counting.
  void set_cost_sink(double* sink) { cost_sink_ = sink; }

 private:
  // Codes `bit` where a 0 has probability p0 / 2048 (both model kinds).
  void encode_with_probability(uint32_t p0, uint32_t bit);
  void shift_low();
  uint64_t low_ = 0;
  uint32_t range_ = 0xFFFFFFFFu;
  uint8_t cache_ = 0;
  uint64_t cache_size_ = 1;
  bool first_ = true;  // the first byte LZMA emits is always 0: we drop it
  std::vector<uint8_t> out_;
  double* cost_sink_ = nullptr;
};

// The decoder side is defined here, inline: a record's decoding loop can
// then keep the coder's state in registers (range, code and input position
// stored to memory and reloaded for every bit were a fifth of the cost of a
// bit), which needs every use of the decoder inlined into it.
#define MESHSTREAM_DECODE_INLINE [[gnu::always_inline]] inline

class RangeDecoder {
 public:
  MESHSTREAM_DECODE_INLINE explicit RangeDecoder(std::span<const uint8_t> in) : in_(in) {
    for (int i = 0; i < 4; ++i) code_ = (code_ << 8) | next_byte();
  }
  // Inline: it runs for every coded bit.
  MESHSTREAM_DECODE_INLINE uint32_t decode_bit(BitModel& model) {
    const uint32_t bound = (range_ >> 11) * model.p;
    uint32_t bit;
    if (code_ < bound) {
      range_ = bound;
      model.p = static_cast<uint16_t>(model.p + ((2048u - model.p) >> 5));
      bit = 0;
    } else {
      code_ -= bound;
      range_ -= bound;
      model.p = static_cast<uint16_t>(model.p - (model.p >> 5));
      bit = 1;
    }
    normalize();
    return bit;
  }
  MESHSTREAM_DECODE_INLINE uint32_t decode_bit(FastStartBitModel& model) {
    const uint32_t bound = (range_ >> 11) * (model.state & 2047u);
    uint32_t bit;
    if (code_ < bound) {
      range_ = bound;
      model.state = fast_start_after0(model.state);
      bit = 0;
    } else {
      code_ -= bound;
      range_ -= bound;
      model.state = fast_start_after1(model.state);
      bit = 1;
    }
    normalize();
    return bit;
  }
  MESHSTREAM_DECODE_INLINE uint32_t decode_direct(int count) {
    uint32_t value = 0;
    for (int i = 0; i < count; ++i) {
      range_ >>= 1;
      uint32_t bit = 0;
      if (code_ >= range_) {
        code_ -= range_;
        bit = 1;
      }
      value = (value << 1) | bit;
      normalize();
    }
    return value;
  }
  // Bytes requested past the end of the input. A correct stream needs at
  // most 8 of them: the decoder looks 4 bytes ahead and the encoder drops up
  // to 4 trailing zero bytes of its flush.
  size_t overrun() const { return overrun_; }
  bool exhausted_badly() const { return overrun_ > 8; }
  // Input bytes read so far (not counting the zeros past the end). After the
  // last symbol of a block this equals the block's length exactly (the
  // decoder reads as many bytes as the encoder wrote, the dropped trailing
  // zeros being the overrun): a reader can refuse trailing bytes.
  size_t consumed() const { return pos_; }

 private:
  // One byte in at most per coded bit: a range of at least 2^24 before the
  // bit leaves at least 2^24 * 31 / 2048 > 2^16 after it (every model's
  // probability stays within [31, 2017] / 2048: the updates by 1/32 of the
  // error stop there, and a FastStartBitModel's 14 faster first steps cannot get
  // that far from 1024), and a direct bit halves it, so one shift restores
  // 2^24. An `if` instead of LZMA's `while` saves a test per bit.
  MESHSTREAM_DECODE_INLINE void normalize() {
    if (range_ < (1u << 24)) {
      range_ <<= 8;
      code_ = (code_ << 8) | next_byte();
    }
  }
  uint8_t next_byte() {
    if (pos_ < in_.size()) return in_[pos_++];
    ++overrun_;
    return 0;
  }
  std::span<const uint8_t> in_;
  size_t pos_ = 0;
  size_t overrun_ = 0;
  uint32_t range_ = 0xFFFFFFFFu;
  uint32_t code_ = 0;
};

// A symbol of `Bits` bits coded MSB first through a binary tree of adaptive
// models (2^Bits - 1 models): an adaptive model of a 2^Bits alphabet.
template <int Bits, class Model = BitModel>
struct BitTreeModel {
  Model nodes[1u << Bits];
  void encode(RangeEncoder& enc, uint32_t symbol) {
    uint32_t m = 1;
    for (int i = Bits - 1; i >= 0; --i) {
      uint32_t bit = (symbol >> i) & 1u;
      enc.encode_bit(nodes[m], bit);
      m = (m << 1) | bit;
    }
  }
  MESHSTREAM_DECODE_INLINE uint32_t decode(RangeDecoder& dec) {
    uint32_t m = 1;
    for (int i = 0; i < Bits; ++i) m = (m << 1) | dec.decode_bit(nodes[m]);
    return m - (1u << Bits);
  }
};

// Adaptive Exp-Golomb for unsigned integers up to 2^32 - 1: the bit length
// (0..32) through a 5-level bit tree (31 escapes to 31 or 32), then the two bits below the leading
// one through models indexed by the length, then the rest as equiprobable bits.
template <class Model>
struct AdaptiveUIntModelT {
  BitTreeModel<5, Model> length;
  Model high[33][4];
  void encode(RangeEncoder& enc, uint32_t value);
  MESHSTREAM_DECODE_INLINE uint32_t decode(RangeDecoder& dec) {
    uint32_t len = length.decode(dec);
    if (len == 31) len += dec.decode_direct(1);
    uint64_t v = 1;
    int rest = static_cast<int>(len);
    uint32_t ctx = 1;
    for (int i = 0; i < 2 && rest > 0; ++i) {
      --rest;
      uint32_t bit = dec.decode_bit(high[len][ctx]);
      v = (v << 1) | bit;
      ctx = (ctx << 1 | bit) & 3u;
    }
    if (rest > 0) v = (v << rest) | dec.decode_direct(rest);
    return static_cast<uint32_t>(v - 1);  // v <= 2^33 - 1 only if corrupt; wraps harmlessly
  }
};
using AdaptiveUIntModel = AdaptiveUIntModelT<BitModel>;
using FastStartUIntModel = AdaptiveUIntModelT<FastStartBitModel>;

// Signed integers: zero flag, sign, then magnitude - 1 as above.
template <class Model>
struct AdaptiveIntModelT {
  Model zero;
  Model sign;
  AdaptiveUIntModelT<Model> magnitude;
  void encode(RangeEncoder& enc, int32_t value);
  // Decodes a value; the caller range-checks it.
  MESHSTREAM_DECODE_INLINE int64_t decode(RangeDecoder& dec) {
    if (dec.decode_bit(zero) == 0) return 0;
    const bool negative = dec.decode_bit(sign) != 0;
    const int64_t mag = int64_t(magnitude.decode(dec)) + 1;
    return negative ? -mag : mag;
  }
};
using AdaptiveIntModel = AdaptiveIntModelT<BitModel>;
using FastStartIntModel = AdaptiveIntModelT<FastStartBitModel>;

}  // namespace meshstream

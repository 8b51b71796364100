// Range coder: see range_coder.h. The arithmetic is LZMA's rc (public
// domain): 32-bit range, 64-bit low with a cache byte for carry propagation,
// 11-bit probabilities adapted by 1/32 of the error per bit.
#include "common/codec/range_coder.h"

#include <cmath>

namespace meshstream {
namespace {

// Keep in step with RangeDecoder::decode_bit in the header.
constexpr uint32_t kTop = 1u << 24;
constexpr int kModelBits = 11;
constexpr int kMoveBits = 5;

}  // namespace

void RangeEncoder::shift_low() {
  if (static_cast<uint32_t>(low_) < 0xFF000000u || (low_ >> 32) != 0) {
    uint8_t temp = cache_;
    do {
      uint8_t byte = static_cast<uint8_t>(temp + static_cast<uint8_t>(low_ >> 32));
      if (first_) {
        first_ = false;  // always 0; the decoder starts as if it had read it
      } else {
        out_.push_back(byte);
      }
      temp = 0xFF;
    } while (--cache_size_ != 0);
    cache_ = static_cast<uint8_t>(low_ >> 24);
  }
  ++cache_size_;
  low_ = (low_ & 0x00FFFFFFu) << 8;
}

void RangeEncoder::encode_with_probability(uint32_t p0, uint32_t bit) {
  const uint32_t bound = (range_ >> kModelBits) * p0;
  if (cost_sink_) {
    const double p = double(p0) / double(1u << kModelBits);
    *cost_sink_ -= std::log2(bit == 0 ? p : 1.0 - p);
  }
  if (bit == 0) {
    range_ = bound;
  } else {
    low_ += bound;
    range_ -= bound;
  }
  while (range_ < kTop) {
    range_ <<= 8;
    shift_low();
  }
}

void RangeEncoder::encode_bit(BitModel& model, uint32_t bit) {
  encode_with_probability(model.p, bit);
  if (bit == 0) {
    model.p = static_cast<uint16_t>(model.p + (((1u << kModelBits) - model.p) >> kMoveBits));
  } else {
    model.p = static_cast<uint16_t>(model.p - (model.p >> kMoveBits));
  }
}

void RangeEncoder::encode_bit(FastStartBitModel& model, uint32_t bit) {
  encode_with_probability(model.state & ((1u << kModelBits) - 1), bit);
  model.state = fast_start_next(model.state, bit);
}

void RangeEncoder::encode_direct(uint32_t value, int count) {
  if (cost_sink_) *cost_sink_ += count;
  for (int i = count - 1; i >= 0; --i) {
    range_ >>= 1;
    if ((value >> i) & 1u) low_ += range_;
    while (range_ < kTop) {
      range_ <<= 8;
      shift_low();
    }
  }
}

std::vector<uint8_t> RangeEncoder::finish() {
  // Any value in [low, low + range) decodes to the same symbols: take the one
  // with the most trailing zero bytes, flush, and drop those zeros (the
  // decoder reads zeros past the end). Saves about 3 bytes per record.
  for (int bytes = 4; bytes >= 1; --bytes) {
    const uint64_t mask = (uint64_t(1) << (8 * bytes)) - 1;
    const uint64_t x = (low_ + mask) & ~mask;
    if (x < low_ + range_) {
      low_ = x;
      break;
    }
  }
  for (int i = 0; i < 5; ++i) shift_low();
  // At most 4: a run of near-certain symbols also ends in zero bytes, and
  // the decoder refuses a block that reads more than 8 bytes past its end.
  for (int dropped = 0; dropped < 4 && !out_.empty() && out_.back() == 0; ++dropped)
    out_.pop_back();
  return std::move(out_);
}

template <class Model>
void AdaptiveUIntModelT<Model>::encode(RangeEncoder& enc, uint32_t value) {
  const uint64_t v = uint64_t(value) + 1;  // >= 1, so it has a leading one
  int len = 0;
  while ((v >> len) > 1) ++len;  // v in [2^len, 2^(len+1))
  if (len < 31) {
    length.encode(enc, static_cast<uint32_t>(len));
  } else {
    length.encode(enc, 31);
    enc.encode_direct(static_cast<uint32_t>(len - 31), 1);
  }
  int rest = len;
  // Up to two bits below the leading one through models: most of the
  // information about the shape of the distribution lives there.
  uint32_t ctx = 1;
  for (int i = 0; i < 2 && rest > 0; ++i) {
    --rest;
    uint32_t bit = static_cast<uint32_t>((v >> rest) & 1u);
    enc.encode_bit(high[len][ctx], bit);
    ctx = (ctx << 1 | bit) & 3u;
  }
  if (rest > 0) enc.encode_direct(static_cast<uint32_t>(v & ((uint64_t(1) << rest) - 1)), rest);
}

template <class Model>
void AdaptiveIntModelT<Model>::encode(RangeEncoder& enc, int32_t value) {
  enc.encode_bit(zero, value == 0 ? 0 : 1);
  if (value == 0) return;
  enc.encode_bit(sign, value < 0 ? 1 : 0);
  const uint32_t mag =
      value < 0 ? static_cast<uint32_t>(-int64_t(value)) : static_cast<uint32_t>(value);
  magnitude.encode(enc, mag - 1);
}

template struct AdaptiveUIntModelT<BitModel>;
template struct AdaptiveUIntModelT<FastStartBitModel>;
template struct AdaptiveIntModelT<BitModel>;
template struct AdaptiveIntModelT<FastStartBitModel>;

}  // namespace meshstream

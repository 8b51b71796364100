// Version-3 record index coding: see record_index_coder.h. The encoder and
// the decoder share IndexModels and Predictor, so both sides predict from
// the same state by construction.
#include "common/codec/record_index_coder.h"

#include <algorithm>
#include <string>

#include "common/codec/range_coder.h"

namespace meshstream {
namespace {

enum Kind { kBase = 0, kStructure = 1, kPlane = 2 };

struct IndexModels {
  BitModel plane[2];  // context: the previous record was a plane record
  AdaptiveUIntModel base_size;
  AdaptiveUIntModel base_vertices;
  AdaptiveIntModel size_delta[3];   // by kind (the base's is unused)
  AdaptiveIntModel vertices_delta;  // structure records
  AdaptiveIntModel gap[3];          // by kind
};

// What both sides know before a record: the previous size of each kind, and
// decayed sums of the vertices and bytes of recent vertex-carrying records
// (their ratio predicts a structure record's vertices from its size: records
// are closed by size, vertices per byte drift slowly over the layers).
struct Predictor {
  uint64_t last_size[3] = {0, 0, 0};
  uint64_t recent_vertices = 0;
  uint64_t recent_bytes = 0;

  // size x recent_vertices / recent_bytes, rounded; capped at 2^32 (any
  // larger prediction is as useless as it is hostile). size <= 2^30.
  uint64_t predict_vertices(uint64_t size) const {
    if (recent_bytes == 0) return 0;
    const uint64_t q = recent_vertices / recent_bytes, r = recent_vertices % recent_bytes;
    if (q > (uint64_t(1) << 33)) return uint64_t(1) << 32;
    // size * q <= 2^63; size * r < 2^30 * 2^34.
    const uint64_t p = size * q + (size * r + recent_bytes / 2) / recent_bytes;
    return p > (uint64_t(1) << 32) ? uint64_t(1) << 32 : p;
  }
  void update(Kind kind, uint64_t size, uint64_t vertices_added) {
    // A structure record under half the previous one is a layer's short
    // last record: the next record is full size again, so the reference
    // stays (2.8 % smaller indexes over the 13 real meshes).
    if (!(kind == kStructure && size < last_size[kind] / 2)) last_size[kind] = size;
    if (kind == kPlane) return;
    // Decay 1/8 per record: about the last eight records count. Both sums
    // stay below 8 x 2^32 and 8 x 2^30.
    recent_vertices = recent_vertices - (recent_vertices >> 3) + vertices_added;
    recent_bytes = recent_bytes - (recent_bytes >> 3) + size;
  }
};

Error bad_entry(uint32_t i, const std::string& what) {
  return Error{ErrorCode::kParse, "record index entry " + std::to_string(i) + ": " + what};
}

// AdaptiveIntModel's own encode takes int32; its format (zero flag, sign,
// magnitude - 1 as an unsigned Exp-Golomb) and its decode hold magnitudes
// up to 2^32. Same bits as AdaptiveIntModel::encode for int32 values.
constexpr int64_t kWide = int64_t(1) << 32;
void encode_wide(AdaptiveIntModel& m, RangeEncoder& enc, int64_t value) {
  enc.encode_bit(m.zero, value == 0 ? 0 : 1);
  if (value == 0) return;
  enc.encode_bit(m.sign, value < 0 ? 1 : 0);
  m.magnitude.encode(enc, static_cast<uint32_t>((value < 0 ? -value : value) - 1));
}

}  // namespace

Result<std::vector<uint8_t>> encode_record_index(std::span<const RecordEntry> records) {
  if (records.empty() || records.size() > kMaxRecords) {
    return make_error(ErrorCode::kInvalidArgument,
                      "a record index holds 1.." + std::to_string(kMaxRecords) + " records, not " +
                          std::to_string(records.size()));
  }
  IndexModels m;
  Predictor pred;
  RangeEncoder enc;
  uint32_t prev_vertices = 0, prev_faces = 0;
  bool prev_plane = false;
  for (size_t i = 0; i < records.size(); ++i) {
    const RecordEntry& r = records[i];
    auto refuse = [&](const std::string& what) {
      return make_error(ErrorCode::kInvalidArgument, "record " + std::to_string(i) + ": " + what);
    };
    if (r.size < kRecordTrailerBytes || r.size > kMaxRecordBytes)
      return refuse("size outside 4 bytes .. 1 GiB");
    if (r.vertices < prev_vertices || r.faces < prev_faces) return refuse("counts decrease");
    const int64_t dv = int64_t(r.vertices) - prev_vertices;
    const int64_t gap = 2 * dv - (int64_t(r.faces) - prev_faces);
    if (gap < -kWide || gap > kWide) return refuse("faces added far from twice the vertices added");
    Kind kind = kBase;
    if (i == 0) {
      m.base_size.encode(enc, r.size - kRecordTrailerBytes);
      m.base_vertices.encode(enc, static_cast<uint32_t>(dv));
    } else {
      kind = dv == 0 ? kPlane : kStructure;
      enc.encode_bit(m.plane[prev_plane], kind == kPlane);
      // Sizes are at most 2^30: the difference fits.
      m.size_delta[kind].encode(
          enc, static_cast<int32_t>(int64_t(r.size) - int64_t(pred.last_size[kind])));
      // Prediction in [0, 2^32], dv in [1, 2^32): |delta| <= 2^32.
      if (kind == kStructure)
        encode_wide(m.vertices_delta, enc, dv - int64_t(pred.predict_vertices(r.size)));
    }
    encode_wide(m.gap[kind], enc, gap);
    pred.update(kind, r.size, static_cast<uint64_t>(dv));
    prev_plane = kind == kPlane;
    prev_vertices = r.vertices;
    prev_faces = r.faces;
  }
  std::vector<uint8_t> out = enc.finish();
  // The reader requires at least one byte; a zero byte the coder dropped
  // may always be put back (the decoder reads zeros past the end anyway).
  if (out.empty()) out.push_back(0);
  if (out.size() > uint64_t(kMaxIndexBytesPerRecord) * records.size() ||
      records.size() > uint64_t(kMaxRecordsPerIndexByte) * out.size()) {
    return make_error(ErrorCode::kInvalidArgument,
                      "record index of " + std::to_string(records.size()) + " records codes to " +
                          std::to_string(out.size()) + " bytes, outside what a reader accepts");
  }
  return out;
}

Result<std::vector<RecordEntry>> decode_record_index(std::span<const uint8_t> coded, uint32_t count,
                                                     uint64_t payload_offset) {
  if (count == 0 || count > kMaxRecords || coded.empty() ||
      coded.size() > uint64_t(kMaxIndexBytesPerRecord) * count ||
      count > uint64_t(kMaxRecordsPerIndexByte) * coded.size()) {
    return make_error(ErrorCode::kParse, "implausible record index: " + std::to_string(count) +
                                             " records in " + std::to_string(coded.size()) +
                                             " bytes");
  }
  IndexModels m;
  Predictor pred;
  RangeDecoder dec(coded);
  // Grown as entries decode: a hostile count with garbage bytes fails within
  // a few entries, before memory for the count is taken.
  std::vector<RecordEntry> records;
  records.reserve(std::min<uint32_t>(count, 1u << 12));
  uint64_t offset = payload_offset, vertices = 0, faces = 0;
  bool prev_plane = false;
  // A correct index never needs more than the 4 zero bytes the encoder
  // drops; stop at once when a hostile one does (bits from nothing).
  constexpr size_t kDroppedZeros = 4;
  for (uint32_t i = 0; i < count; ++i) {
    Kind kind = kBase;
    int64_t size = 0, dv = 0;
    if (i == 0) {
      size = int64_t(m.base_size.decode(dec)) + kRecordTrailerBytes;
      dv = m.base_vertices.decode(dec);
    } else {
      kind = dec.decode_bit(m.plane[prev_plane]) ? kPlane : kStructure;
      size = int64_t(pred.last_size[kind]) + m.size_delta[kind].decode(dec);
    }
    if (size < int64_t(kRecordTrailerBytes) || size > int64_t(kMaxRecordBytes)) {
      return tl::unexpected(
          bad_entry(i, "size " + std::to_string(size) + " outside 4 bytes .. 1 GiB"));
    }
    if (kind == kStructure) {
      dv = int64_t(pred.predict_vertices(uint64_t(size))) + m.vertices_delta.decode(dec);
      if (dv < 1 || dv > int64_t(UINT32_MAX)) {
        return tl::unexpected(bad_entry(i, "adds " + std::to_string(dv) + " vertices"));
      }
    }
    const int64_t df = 2 * dv - m.gap[kind].decode(dec);
    if (df < 0) return tl::unexpected(bad_entry(i, "removes faces"));
    if (dec.overrun() > kDroppedZeros)
      return tl::unexpected(bad_entry(i, "the index bytes end inside it"));
    vertices += uint64_t(dv);
    faces += uint64_t(df);
    if (vertices > UINT32_MAX || faces > UINT32_MAX)
      return tl::unexpected(bad_entry(i, "counts overflow"));
    RecordEntry& r = records.emplace_back();
    r.offset = offset;
    r.size = static_cast<uint32_t>(size);
    r.vertices = static_cast<uint32_t>(vertices);
    r.faces = static_cast<uint32_t>(faces);
    r.crc32 = 0;
    r.crc_trailer = true;
    offset += uint64_t(size);
    pred.update(kind, uint64_t(size), uint64_t(dv));
    prev_plane = kind == kPlane;
  }
  if (dec.consumed() != coded.size()) {
    return make_error(
        ErrorCode::kParse,
        "record index has " + std::to_string(coded.size() - dec.consumed()) + " trailing bytes");
  }
  return records;
}

}  // namespace meshstream

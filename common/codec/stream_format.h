// The numbers an `.hcs` stream is written with and read by: coder ids,
// refinement record formats, record flags and versions. Encoder and decoder
// both include this header, so neither leans on the other for the format
// (as Draco's compression_shared.h). The layout itself: container.h,
// refinement_codec.h and docs/hcs-format.md.
#pragma once

#include <cstdint>
#include <optional>

namespace meshstream {

// Container format version (container.h); versions 1 and 2 (index CRCs,
// bare payloads) are still read.
inline constexpr uint16_t kContainerVersion = 3;

// Bumped whenever the bytes an encoder writes for the same input change, so
// caches keyed by (content hash, encoder version) stay correct. What each
// bump changed: docs/hcs-format.md ("Encoder versions").
inline constexpr uint32_t kEncoderVersion = 17;

// Which coder made record 0, the base mesh (header `base_coder`,
// base_coder.h).
inline constexpr uint8_t kBaseCoderOwn = 1;    // own range-coded deltas
inline constexpr uint8_t kBaseCoderDraco = 2;  // Draco's edgebreaker on grid integers
// Breadth-first face traversal, parallelogram-predicted positions (encoder
// version 9 on; what replaced kBaseCoderOwn, which is still read).
inline constexpr uint8_t kBaseCoderTraversal = 3;

// Ids written in the stream header (`structure_coder`, `geometry_coder`).
inline constexpr uint8_t kStructureCoderRange = 1;  // adaptive binary range coder
// Ring average + range-coded residual (refinement format 1).
inline constexpr uint8_t kGeometryCoderRangeAverage = 1;
// Ring average, coarse residual + context-coded bit planes (formats 2, 3).
inline constexpr uint8_t kGeometryCoderEmbedded = 2;

// The refinement record formats: header extra[0].
enum class RefinementFormat : uint8_t {
  // Every position exact at insertion: no shift field in the record
  // header, no plane records.
  kExactInsertion = 1,
  // Successive-approximation positions (embedded_geometry.h): records carry
  // the coarsest shift of their insertions, plane records send the low
  // bits later; header extra[1] is the base shift.
  kEmbedded = 2,
  // Format 2's records, the structure symbols (counts, valences, start
  // ranks, open edges) through fast-start models with finer valence and
  // start-rank contexts (refinement_codec.h). What the encoder writes.
  kEmbeddedFastStart = 3,
};
// The same numbers as header bytes.
inline constexpr uint8_t kRefinementFormatPlain = uint8_t(RefinementFormat::kExactInsertion);
inline constexpr uint8_t kRefinementFormatEmbedded = uint8_t(RefinementFormat::kEmbedded);
// The format the encoder writes by default.
inline constexpr uint8_t kRefinementFormat = uint8_t(RefinementFormat::kEmbeddedFastStart);

// What a refinement format means for the coders, described once: built from
// the header byte, read wherever the records differ by format.
struct RefinementFormatInfo {
  RefinementFormat format = RefinementFormat::kEmbeddedFastStart;
  // Structure records' headers carry a min shift, plane records may occur,
  // the stream header carries a base shift (extra[1]) and names
  // kGeometryCoderEmbedded.
  bool embedded = true;
  // Structure symbols through FastStartBitModel models and the format-3
  // contexts (RefinementModels); else BitModel and format 2's contexts.
  bool fast_start_structure_models = true;

  uint8_t header_byte() const { return static_cast<uint8_t>(format); }
  uint8_t geometry_coder() const {
    return embedded ? kGeometryCoderEmbedded : kGeometryCoderRangeAverage;
  }
  // The format of header byte extra[0]; nullopt for a byte no format has.
  static constexpr std::optional<RefinementFormatInfo> from_header_byte(uint8_t byte) {
    switch (byte) {
      case uint8_t(RefinementFormat::kExactInsertion):
        return RefinementFormatInfo{RefinementFormat::kExactInsertion, false, false};
      case uint8_t(RefinementFormat::kEmbedded):
        return RefinementFormatInfo{RefinementFormat::kEmbedded, true, false};
      case uint8_t(RefinementFormat::kEmbeddedFastStart):
        return RefinementFormatInfo{RefinementFormat::kEmbeddedFastStart, true, true};
      default:
        return std::nullopt;
    }
  }
};

// The largest base shift (header extra[1] of an embedded stream: low bits of
// the base positions left to plane records); it must also stay below the
// stream's quantization bits.
inline constexpr int kMaxBaseShift = 12;

// The largest valence of a vertex a structure record inserts (the decoder
// refuses larger ones); the encoder removes no vertex of higher valence
// (decimate.h's kMaxRemovalValence must not exceed it).
inline constexpr uint32_t kMaxInsertedValence = 16;

// Flags: the first payload byte of a refinement record. A structure record
// has 0 or kRecordStartsLayer, a plane record exactly kRecordPlane.
inline constexpr uint8_t kRecordStartsLayer = 1;
inline constexpr uint8_t kRecordPlane = 2;
// Records beside the geometry, told apart by this first byte too: the
// attribute records (attribute_codec.h: record 1 the base's values, values
// records after geometry records the inserted vertices', the last record the
// rest and the extra attributes) and the texture records
// (texture_record.h: pyramid levels of Mesh::textures).
inline constexpr uint8_t kRecordAttributes = 4;
inline constexpr uint8_t kRecordTexture = 8;

}  // namespace meshstream

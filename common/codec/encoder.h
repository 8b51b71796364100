// Encoding a mesh into one progressive `.hcs` stream (container.h for the
// layout): quantize, decimate layer by layer (decimate.h), code the base mesh
// (base_choice.h), then refinement records from coarse to fine. An embedded
// stream (the default) also sends positions by successive approximation (bit
// planes, embedded_geometry.h) and orders structure and plane records by
// estimated distortion decrease per byte (record_schedule.h,
// docs/hcs-format.md).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/base/result.h"
#include "common/codec/decimate.h"
#include "common/codec/encode_progress.h"
#include "common/codec/stream_format.h"
#include "common/mesh/mesh.h"

namespace meshstream {

// How a vertex's error enters the record ordering's distortion estimate
// (distortion_estimate.h). The numbers are what the benchmarks print.
enum class DistortionEstimate : uint8_t {
  // Automatic balance: measured among the candidates (kOrderingCandidates);
  // a fixed balance: displacement.
  kAutomatic = 0,
  kDisplacement = 1,     // the displacement from its true position
  kSurfaceDistance = 2,  // the squared distance to the original surface
};

struct EncodeOptions {
  int quant_bits = 12;                  // 8..20, grid over the bounding box
  uint32_t target_base_vertices = 300;  // stop decimating at about this many
  // Each decimation layer draws its independent set from this cheapest
  // share of its candidates (DecimateOptions::candidate_share): larger
  // shares make fewer, larger layers. (0, 1], else kInvalidArgument.
  // `meshstream encode --layer-candidates`.
  double layer_candidate_share = kDefaultCandidateShare;
  // Close a refinement record at about this size; 0 = automatic (sized
  // for min(n / 50, 200) boundaries and no record beyond the base above 2 %
  // of the stream; re-encoded with smaller records when missed).
  uint32_t record_bytes = 0;
  bool allow_draco_base = true;  // false: always the own base coder (tests)
  // true: successive-approximation positions (plane records send their low
  // bits later) and records ordered by estimated distortion drop per byte.
  // false: no bit planes: every position exact when its vertex arrives,
  // structure records only, in decimation order (the peer the benchmarks
  // compare against; `meshstream encode --no-bit-planes`).
  bool embedded = true;
  // Low bits of the base positions sent later as plane records, 0 ..
  // kMaxBaseShift (else kInvalidArgument) and at most quant_bits - 1;
  // empty = automatic: quant_bits - 8, an 8-bit base (docs/hcs-format.md).
  // Embedded only.
  std::optional<int> base_shift;
  // How much the record ordering's distortion estimate values plane
  // records against structure records (record_schedule.h). 0 = automatic: the
  // streams of the kOrderingCandidates are decoded at log-spaced budgets and
  // the one with the smallest measured surface distance to the original
  // wins (rd_measure.h; 5 distance measurements a candidate). The first
  // candidate is encoded whole, the others only as far as the measurement
  // decodes them (1/8 of the first one's size), and a winner other than the
  // first is then encoded whole (docs/hcs-format.md, "Record order and
  // size"). A fixed balance encodes once. Embedded only.
  double plane_calibration = 0;
  // The automatic choice as it was before issue 15's encoder work, kept as
  // the peer the benchmarks compare against: every candidate encoded whole
  // and measured at budgets relative to the first one's size (about twice
  // the encode time, and the peak memory of two encodes at once).
  bool measure_whole_candidates = false;
  // How a vertex's error enters that estimate. Embedded only; a value
  // outside the enum is kInvalidArgument.
  DistortionEstimate distortion_estimate = DistortionEstimate::kAutomatic;
  // Low residual bits of inserted vertices left to plane records (at least;
  // a vertex is never sharper than its ring). Embedded only; 0 measured best
  // (docs/hcs-format.md, "Record order and size"), the others are kept for
  // experiments.
  int insertion_shift = 0;
  // Threads: the decimation's removal costs, the closest-point queries and
  // the hierarchy builds (TriangleBvh::build) on this many (0 = one per
  // core), and the automatic ordering's candidates and their measurement
  // each on its own thread unless 1 (then one after the other). The
  // stream is the same for every count.
  uint32_t threads = 0;
  // Refinement record format written: kEmbeddedFastStart (what decoders
  // expect today) or kEmbedded (format 2's models, kept as the peer
  // benchmarks compare against: same records, slower-learning models).
  // kExactInsertion and anything else is kInvalidArgument.
  RefinementFormat refinement_format = RefinementFormat::kEmbeddedFastStart;
  // Called as the encode advances (encode_progress.h); empty = no calls. It
  // does not change the stream.
  EncodeProgressCallback progress;
  // Measure which ASA post-processing brings each group of prefixes closest
  // to the original and write it into the header (asa_guidance.h; the
  // client's `--asa auto`). false: no guidance block (`meshstream encode
  // --no-asa-guidance`); the client then shows the prefixes as decoded.
  bool asa_guidance = true;
  // Attribute quantization (attribute_quantize.h), 2..16 bits, else
  // kInvalidArgument: normals per octahedral coordinate, texture coordinates
  // per axis over their box, colours per channel on [0, 1] (8: 8-bit colours
  // come back exactly). `meshstream encode --quant-normal/--quant-uv/--quant-color`.
  int quant_normal = 8;
  int quant_uv = 12;
  int quant_color = 8;
  // Record 1's grid for the base's colours (version 15): 0 = exact in
  // record 1 (the default); 2 .. quant_color - 1 bits per channel = coarse
  // there, the low bits in a low-bits record after it (AttributeOptions::
  // base_color_bits; bench/REPORT.md weighs the first display against the
  // total). `meshstream encode --base-color-bits`.
  int base_color_bits = 0;
  // Texture coordinates shared by several wedges of a vertex coded once
  // (version 16, kWedgeRepeat); false: every wedge's value coded (version
  // 15's cost, for measuring).
  bool wedge_repeat = true;
  // The locality experiment (issue 17, docs/view-dependent-records.md):
  // 0 = off (the default; the stream is unchanged). Else each decimation
  // layer keeps the borders of a grid of cells of at least about this many
  // of its vertices (one grid a level of layers, locality_cells.h), so every
  // patch lies inside one cell; kMinLocalityCellVertices ..
  // kMaxLocalityCellVertices, else kInvalidArgument. The stream is an
  // ordinary stream; only the decimation is restricted.
  uint32_t locality_cell_vertices = 0;
  // With locality cells: layers that start with fewer than this share of
  // the vertices (0..1, else kInvalidArgument) lock nothing (CellLevels);
  // 0 = cells down to the coarsest level.
  double locality_unlocked_share = 0;
  // Measurement only (issue 18, bench/REPORT.md "Seams: locking against an
  // uncoded seam pattern"): true decimates as if there were no seams (seam
  // vertices not locked) and writes the geometry records alone, without
  // attribute records: this stream cannot carry the seams, it only bounds
  // what coding a re-triangulated patch's seam pattern could save. false
  // (the default) leaves the stream unchanged.
  bool measure_unlocked_seams = false;
};

// The record orderings the automatic choice tries (EncodeOptions): each
// candidate's stream is measured and the best kept; the first is encoded
// first and settles the record size. Why these two (the surface distance
// wins on CAD parts, displacement on some scans) and which balances were
// dropped: docs/hcs-format.md, "Record order and size".
struct RecordOrdering {
  double plane_calibration;
  DistortionEstimate distortion_estimate;  // kDisplacement or kSurfaceDistance
};
inline constexpr RecordOrdering kOrderingCandidates[] = {
    {1.0, DistortionEstimate::kDisplacement}, {1.0, DistortionEstimate::kSurfaceDistance}};

// What the encoder assumed about each record (tests and the benchmark).
struct EncodedRecord {
  bool plane = false;     // a plane record (else base or structure)
  uint32_t vertices = 0;  // mesh vertices after the record
  uint32_t bytes = 0;     // payload size
  // FNV-1a of the dequantized float positions (bit patterns, vertex order)
  // the decoder must show after this record.
  uint64_t position_hash = 0;
  // The encoder's estimate of the squared surface distance removed by the
  // record (grid units^2 x area), used to order records.
  double distortion_drop = 0;
};
// Ideal coded bits (-log2 p of each range-coded bit, RangeEncoder's cost
// sink) of the structure records' symbol classes, summed over the stream,
// and the events they describe: where the structure bytes go.
struct StructureBits {
  double count = 0;          // patch counts (walk steps with free faces)
  double valence = 0;        // k of each inserted vertex
  double rank = 0;           // start ranks
  double open_edge = 0;      // boundary re-entry choices
  double residual = 0;       // coarse position residuals at insertion
  uint64_t walk_steps = 0;   // all walk steps
  uint64_t count_steps = 0;  // walk steps that coded a count
  uint64_t insertions = 0;
  uint64_t open_choices = 0;  // patches that coded an open-edge choice
};

struct EncodeReport {
  std::vector<EncodedRecord> records;
  StructureBits structure_bits;
  uint64_t plane_bits_raw = 0;     // plane bits and signs, uncoded (one bit each)
  uint64_t plane_bytes_coded = 0;  // their context-coded payload (range-coded blocks)
  // The same bits through a plain coder, for comparison: adaptive
  // binary models by plane only (no axis role, significance or neighbour
  // contexts), one block per record.
  uint64_t plane_bytes_plain = 0;
  uint64_t structure_bytes = 0;  // structure records
  uint32_t base_shift = 0;
  // The record ordering the stream was written with (the measured choice's
  // winner when automatic).
  RecordOrdering ordering{0, DistortionEstimate::kAutomatic};
  // Bytes of the attribute records' parts ("layout", "seams", "normals",
  // "texcoords", "colors", "materials", "extra"; attribute_codec.h).
  std::map<std::string, uint64_t> attribute_bytes;
  // Vertices kept out of decimation because a seam or a material border
  // passes through them.
  uint32_t attribute_locked_vertices = 0;
  // What the stream does not carry (encode_warnings).
  std::vector<std::string> warnings;
};

// The data of `mesh` an encode does not carry, one message each (empty when
// everything is carried): `meshstream encode` prints them, the server logs them.
std::vector<std::string> encode_warnings(const Mesh& mesh);

// Encodes a clean manifold mesh (see import.h). kInvalidArgument for bad
// options, kNonManifold / kInvalidMesh for a mesh the codec cannot take;
// kInternal is a bug of the encoder (its replay of the decoder disagreed).
Result<std::vector<uint8_t>> encode_hcs(const Mesh& mesh, const EncodeOptions& options = {});
// The same, also filling `report` (costs O(vertices) per record for the hashes).
Result<std::vector<uint8_t>> encode_hcs(const Mesh& mesh, const EncodeOptions& options,
                                        EncodeReport* report);

// FNV-1a over the bit patterns of the positions, in vertex order: what
// EncodedRecord::position_hash holds for a decoder's mesh().
uint64_t position_hash(const std::vector<Vec3f>& positions);

// The mesh an exact decoder must give back: positions snapped to the
// quantization grid (dequantized), same triangles.
Result<Mesh> quantized_reference(const Mesh& mesh, int quant_bits);

}  // namespace meshstream

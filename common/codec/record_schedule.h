// Record scheduling: one stream for one record ordering and record size.
// After the base, the next record is whichever promises the larger
// estimated distortion drop per byte (distortion_estimate.h): the next
// structure record of the walk (structure_writer.h) or one plane step of
// the best plane group (plane_groups.h). The search over orderings and
// record sizes (encoder.cpp) calls this once per candidate.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "common/base/result.h"
#include "common/codec/decimate.h"
#include "common/codec/encoder.h"
#include "common/codec/quantize.h"
#include "common/metrics/bvh.h"

namespace meshstream {

struct EncodedStream {
  std::vector<uint8_t> bytes;
  size_t largest_refinement = 0;
  size_t records = 0;
  uint64_t payload_offset = 0;       // bytes of magic, header and index
  std::vector<uint32_t> to_decoder;  // input vertex id -> the decoder's id
};

// Encodes `mesh` (quantized to `q` on `grid`, decimated to `dec`) with
// records of about `record_bytes`, plane records weighted by
// `plane_calibration` against structure records, and vertex errors
// measured against `surface` (grid units) when given, else as
// displacement. Fills `report` when given. Thread-safe for concurrent
// calls that share the read-only inputs. Cost: O(V log V) plus one
// closest-point query per estimated vertex error with a surface.
// `stop_after_bytes` > 0 stops after the first record that brings the
// records' bytes (trailers counted) to at least that many: the stream is
// then a prefix, record for record the full stream's, whose header names
// the mesh the prefix shows (for measuring orderings, encoder.cpp); its
// cost is about that share of a full encode. `release` (optional) is &dec
// for the decimation's last encode: each layer is freed once written (the
// stream is the same; dec keeps its layer count, the layers are empty).
Result<EncodedStream> encode_once(const Mesh& mesh, const QuantGrid& grid,
                                  const std::vector<Vec3i>& q,
                                  const std::vector<Vec3f>& input_normals,
                                  const DecimationResult& dec, const EncodeOptions& options,
                                  uint32_t record_bytes, double plane_calibration,
                                  EncodeReport* report, const TriangleBvh* surface,
                                  const std::function<void(double)>& progress = {},
                                  uint64_t stop_after_bytes = 0,
                                  DecimationResult* release = nullptr);

}  // namespace meshstream

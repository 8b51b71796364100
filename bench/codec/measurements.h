// What the codec benchmark measures for one mesh; filled by rate_distortion.h
// and codec_bench.cpp, written out by report.h.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/codec/encoder.h"

namespace meshstream::bench {

// One point of a rate-distortion curve: a mesh a client can show after
// receiving `bytes`, and its distance to the original (metrics/distance.h,
// relative values over the original's bounding-box diagonal).
struct RdPoint {
  uint64_t bytes = 0;
  uint32_t vertices = 0;
  uint32_t faces = 0;
  double rms = 0, hausdorff = 0;
  double rel_rms = 0, rel_hausdorff = 0;
};

// One step of the LOD chain and our stream at the same byte budget.
struct ChainComparison {
  std::string label;              // "1/64", ..., "full"
  uint32_t target_faces = 0;      // what the simplifier was asked for
  RdPoint chain;                  // cumulative bytes of the chain up to this LOD
  std::optional<RdPoint> ours;    // our largest prefix within chain.bytes
  bool ours_over_budget = false;  // our base mesh alone is larger than the budget
};

struct MeshMeasurements {
  std::string name;
  uint32_t vertices = 0, faces = 0;
  std::string error;  // import failed: nothing else is valid

  // Draco single-rate, 12 bits.
  uint64_t draco7_bytes = 0, draco10_bytes = 0;
  double draco_decode_vps = 0;  // of its own level-7 file
  std::string draco_error;

  // Ours (empty ours_error == valid).
  std::string ours_error;
  uint64_t ours_bytes = 0;
  uint32_t ours_records = 0;
  uint64_t ours_base_bytes = 0;
  double ours_encode_vps = 0, ours_decode_vps = 0;
  bool ours_counts_match = false;         // full decode has the input's vertex and face counts
  uint32_t ours_vertices_at_ratio20 = 0;  // in the prefix of 1/20 of the stream (HCS's ratio 20)
  uint64_t ours_bytes_at_ratio20 = 0;

  // Embedded stream details (issue 5).
  uint64_t ours_structure_bytes = 0, ours_plane_bytes = 0, ours_plane_raw_bytes = 0;
  uint64_t ours_plane_plain_bytes = 0;  // the plane bits through a plain coder (EncodeReport)
  uint32_t ours_plane_records = 0;
  uint64_t ours_largest_record = 0;  // beyond the base
  uint32_t ours_base_shift = 0;
  // The ordering the encoder's measured choice kept.
  DistortionEstimate ours_distortion_estimate = DistortionEstimate::kAutomatic;
  // Prefix equals the encoder's model at every record boundary (hashes).
  bool ours_model_matches = false;
  // RMS along the measured curve: the largest rise between consecutive
  // points, relative to the earlier one.
  double ours_worst_rms_rise = 0;

  // Issue I's ordering (EncodeOptions::embedded = false), same run.
  std::string plain_error;
  uint64_t plain_bytes = 0;
  uint32_t plain_records = 0;
  uint32_t plain_vertices_at_ratio20 = 0;
  std::vector<RdPoint> plain_curve;
  std::vector<ChainComparison> plain_at_chain;

  std::vector<RdPoint> ours_curve;
  std::vector<RdPoint> chain_curve;
  std::vector<ChainComparison> at_chain;
  std::string rd_error;

  double bpv(uint64_t bytes) const { return vertices ? 8.0 * bytes / vertices : 0; }
};

}  // namespace meshstream::bench

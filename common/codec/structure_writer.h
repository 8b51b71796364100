// Structure records (refinement_codec.h for their symbols): the vertices
// of one decimation layer put back, a run of the layer's walk per record.
//
// The records are written by replaying the decoder: the writer keeps a
// RefinementState built from the base exactly as the decoder will decode
// it, names every patch in that state's terms and applies it with the same
// function the decoder uses. Encoder and decoder therefore agree on every
// face slot and ring start by construction. Each record also carries the
// distortion estimate's drop (distortion_estimate.h) for the schedule.
#pragma once

#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "common/base/result.h"
#include "common/codec/decimate.h"
#include "common/codec/distortion_estimate.h"
#include "common/codec/encoder.h"
#include "common/codec/refinement_codec.h"
#include "common/codec/stream_format.h"

namespace meshstream {

// A record as the schedule collects it before the container is written.
struct WrittenRecord {
  std::vector<uint8_t> payload;
  uint32_t vertices = 0, faces = 0;  // mesh vertices and face slots after it
  bool plane = false;                // a plane record (else base or structure)
  double drop = 0;                   // estimated distortion it removes
};

// Structure records of one layer at a time, in the walk's order.
class StructureWriter {
 public:
  // `state` is the decoder's state the records are replayed on and `truth`
  // the encoder's knowledge of it (both grow with every inserted vertex);
  // `format` the refinement format written; `bits` (optional) receives the
  // cost of each symbol class.
  StructureWriter(RefinementState& state, EncoderTruth& truth, RefinementFormatInfo format,
                  StructureBits* bits)
      : s_(state), t_(truth), format_(format), bits_(bits) {
    s_.models.use_fast_start_models = format.fast_start_structure_models;
  }

  // Whether the layer started last still has vertices to put back.
  bool layer_open() const { return remaining_ > 0; }

  // Starts the next layer (the previous one must be written out).
  // `layer` is in input vertex ids and must outlive the layer;
  // `to_decoder` maps their ring vertices (all restored before the layer
  // starts) to decoder ids. Only the mapped rings are copied, flat.
  void start_layer(const DecimationLayer& layer, const std::vector<uint32_t>& to_decoder);

  // Writes the next record of the open layer, about `target` bytes.
  // `inserted` gets (input id, decoder id) of every vertex it put back.
  // kInternal when the replay disagrees with the decimation (a bug, not
  // bad input).
  Status write_record(uint32_t target, int min_shift, WrittenRecord& out,
                      std::vector<std::pair<uint32_t, uint32_t>>& inserted);

 private:
  // The phases of a walk step. The walk's next vertex u, skipping the ones
  // this layer inserted.
  Status next_walk_vertex(uint32_t& u);
  // The removals with apex u, by their first face in u's star (order_).
  Status find_patches_at(uint32_t u);
  // Codes how many patches u gets among its free faces.
  Status code_patch_count(RangeEncoder& enc, uint32_t u, uint32_t& free_faces);
  // Codes patch j of u: valence, start rank, open edge, coarse residual.
  Status code_patch(RangeEncoder& enc, uint32_t u, uint32_t j, int min_shift, uint32_t& free_left);
  // Inserts the coded patches as the decoder will; returns their estimated
  // distortion drop.
  double apply_patches(std::vector<std::pair<uint32_t, uint32_t>>& inserted);

  RefinementState& s_;
  EncoderTruth& t_;
  RefinementFormatInfo format_;
  StructureBits* bits_;
  // Removal i's ring in decoder ids.
  std::span<const uint32_t> ring(uint32_t i) const {
    return {ring_ids_.data() + ring_start_[i], ring_start_[i + 1] - ring_start_[i]};
  }

  const std::vector<Removal>* removals_ = nullptr;
  std::vector<uint32_t> ring_ids_, ring_start_;  // the rings of removals_, flat
  size_t remaining_ = 0;
  bool starts_layer_ = false;
  uint32_t layer_vertices_ = 0;
  std::vector<uint32_t> first_, next_, open_edges_, candidates_, star_ring_, star_corners_;
  std::vector<std::pair<uint32_t, uint32_t>> order_;  // (r, removal)
  std::vector<ResolvedPatch> patches_;
  std::vector<VertexGeometry> geometry_;
  std::vector<uint8_t> used_;
  std::vector<int64_t> scores_;
};

}  // namespace meshstream

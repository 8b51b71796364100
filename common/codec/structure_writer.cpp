// Structure record writer: see structure_writer.h.
#include "common/codec/structure_writer.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace meshstream {

void StructureWriter::start_layer(const DecimationLayer& layer,
                                  const std::vector<uint32_t>& to_decoder) {
  const std::vector<Removal>& removals = layer.removals;
  removals_ = &removals;
  ring_ids_.clear();
  ring_start_.clear();
  for (const Removal& r : removals) {
    ring_start_.push_back(static_cast<uint32_t>(ring_ids_.size()));
    for (uint32_t u : layer.ring(r)) ring_ids_.push_back(to_decoder[u]);
  }
  ring_start_.push_back(static_cast<uint32_t>(ring_ids_.size()));
  const uint32_t n = s_.mesh.vertex_count();
  first_.assign(n, kNone);
  next_.assign(removals.size(), kNone);
  for (uint32_t i = 0; i < removals.size(); ++i) {
    const uint32_t apex = ring(i)[0];
    next_[i] = first_[apex];
    first_[apex] = i;
  }
  s_.layer += 1;
  s_.cursor = s_.order_head;
  s_.last_count = 0;
  remaining_ = removals.size();
  starts_layer_ = true;
  layer_vertices_ = n;
}

Status StructureWriter::write_record(uint32_t target, int min_shift, WrittenRecord& out,
                                     std::vector<std::pair<uint32_t, uint32_t>>& inserted) {
  RangeEncoder enc;
  uint32_t walk_steps = 0, insertions = 0;
  double drop = 0;
  while (remaining_ > 0) {
    uint32_t u = kNone;
    if (auto st = next_walk_vertex(u); !st) return st;
    ++walk_steps;
    if (bits_) ++bits_->walk_steps;
    if (auto st = find_patches_at(u); !st) return st;
    const uint32_t count = static_cast<uint32_t>(order_.size());
    uint32_t free_faces = 0;
    if (auto st = code_patch_count(enc, u, free_faces); !st) return st;
    patches_.resize(count);
    geometry_.resize(count);
    uint32_t free_left = free_faces;
    for (uint32_t j = 0; j < count; ++j) {
      if (auto st = code_patch(enc, u, j, min_shift, free_left); !st) return st;
    }
    enc.set_cost_sink(nullptr);
    drop += apply_patches(inserted);
    insertions += count;
    remaining_ -= count;
    if (enc.bytes_so_far() >= target) break;
  }
  out = WrittenRecord{};
  write_record_header({starts_layer_, walk_steps, insertions, uint32_t(min_shift)}, out.payload,
                      format_);
  starts_layer_ = false;
  std::vector<uint8_t> coded = enc.finish();
  out.payload.insert(out.payload.end(), coded.begin(), coded.end());
  out.vertices = s_.mesh.vertex_count();
  out.faces = s_.mesh.face_slot_count();
  out.drop = drop;
  return {};
}

Status StructureWriter::next_walk_vertex(uint32_t& u) {
  while (s_.cursor != kNone && s_.vertices[s_.cursor].layer == s_.layer)
    s_.cursor = s_.vertices[s_.cursor].next;
  if (s_.cursor == kNone)
    return make_error(ErrorCode::kInternal, "encoder replay: the walk ended with " +
                                                std::to_string(remaining_) + " patches of layer " +
                                                std::to_string(s_.layer) + " left");
  u = s_.cursor;
  s_.cursor = s_.vertices[u].next;
  return {};
}

Status StructureWriter::find_patches_at(uint32_t u) {
  s_.mesh.star(u, star_ring_, star_corners_);
  const uint32_t ring_size = static_cast<uint32_t>(star_ring_.size());
  const uint32_t faces = static_cast<uint32_t>(star_corners_.size());
  order_.clear();
  for (uint32_t i = u < layer_vertices_ ? first_[u] : kNone; i != kNone; i = next_[i]) {
    const Removal& r = (*removals_)[i];
    const std::span<const uint32_t> r_ring = ring(i);
    uint32_t pos = kNone;
    for (uint32_t f = 0; f < faces; ++f) {
      if (star_ring_[f] == r_ring[1] && star_ring_[(f + 1) % ring_size] == r_ring[2]) pos = f;
    }
    if (pos == kNone)
      return make_error(ErrorCode::kInternal, "encoder replay: the patch of input vertex " +
                                                  std::to_string(r.vertex) +
                                                  " not found at its apex " + std::to_string(u));
    order_.push_back({pos, i});
  }
  std::sort(order_.begin(), order_.end());
  return {};
}

Status StructureWriter::code_patch_count(RangeEncoder& enc, uint32_t u, uint32_t& free_faces) {
  const uint32_t faces = static_cast<uint32_t>(star_corners_.size());
  const uint32_t count = static_cast<uint32_t>(order_.size());
  RefinementModels& m = s_.models;
  free_faces = mark_taken_faces(s_, star_ring_, faces, used_);
  if (free_faces != free_face_count(s_, u)) {
    return make_error(ErrorCode::kInternal,
                      "encoder replay: free face counts disagree at vertex " + std::to_string(u));
  }
  if (free_faces > 0) {
    if (bits_) {
      ++bits_->count_steps;
      enc.set_cost_sink(&bits_->count);
    }
    if (m.use_fast_start_models) {
      fast_start_count_model(s_, u, free_faces).encode(enc, std::min(count, 3u));
      if (count >= 3) m.fast_start_patch_count_extra.encode(enc, count - 3);
    } else {
      m.patch_count[count_context(s_, u, free_faces)].encode(enc, std::min(count, 3u));
      if (count >= 3) m.patch_count_extra.encode(enc, count - 3);
    }
  } else if (count > 0) {
    return make_error(ErrorCode::kInternal, "encoder replay: vertex " + std::to_string(u) +
                                                " has patches but no free faces");
  }
  s_.last_count = count;
  return {};
}

Status StructureWriter::code_patch(RangeEncoder& enc, uint32_t u, uint32_t j, int min_shift,
                                   uint32_t& free_left) {
  const uint32_t ring_size = static_cast<uint32_t>(star_ring_.size());
  const uint32_t faces = static_cast<uint32_t>(star_corners_.size());
  RefinementModels& m = s_.models;
  const Removal& r = (*removals_)[order_[j].second];
  const std::span<const uint32_t> r_ring = ring(order_[j].second);
  const uint32_t k = static_cast<uint32_t>(r_ring.size());
  // Valence.
  if (bits_) {
    ++bits_->insertions;
    enc.set_cost_sink(&bits_->valence);
  }
  if (m.use_fast_start_models) {
    fast_start_valence_model(s_, ring_size, free_left).encode(enc, k - 3);
  } else {
    m.valence[std::min(ring_size, 12u)].encode(enc, k - 3);
  }
  free_left = free_left >= k - 2 ? free_left - (k - 2) : 0;
  // Start rank among the candidate first faces.
  rank_patch_starts(s_.mesh, u, star_ring_, used_, k, candidates_, scores_);
  const auto it = std::find(candidates_.begin(), candidates_.end(), order_[j].first);
  if (it == candidates_.end())
    return make_error(ErrorCode::kInternal, "encoder replay: the patch of input vertex " +
                                                std::to_string(r.vertex) +
                                                " starts at no candidate face");
  if (bits_) enc.set_cost_sink(&bits_->rank);
  const uint32_t rank = static_cast<uint32_t>(it - candidates_.begin());
  if (format_.fast_start_structure_models) {
    const size_t c = candidates_.size();
    encode_start_rank_in_context(
        m, enc, start_rank_context(k, c, scores_[0], c > 1 ? scores_[1] : -1), c, rank);
  } else {
    encode_start_rank(m, enc, k, rank);
  }
  for (uint32_t f = 0; f + 2 < k; ++f) used_[(order_[j].first + f) % faces] = 1;
  if (!resolve_patch(s_.mesh, u, star_ring_, star_corners_, order_[j].first, k, patches_[j]) ||
      !std::ranges::equal(patches_[j].ring, r_ring)) {
    return make_error(ErrorCode::kInternal, "encoder replay: the patch of input vertex " +
                                                std::to_string(r.vertex) +
                                                " does not resolve to its ring");
  }
  // Open edge of a boundary patch.
  patch_boundary_edges(s_.mesh, patches_[j], open_edges_);
  if (!open_edges_.empty()) {
    uint32_t choice = 0;
    for (uint32_t e = 0; e < open_edges_.size(); ++e)
      if (open_edges_[e] == r.open()) choice = e + 1;
    if (r.open() != kNone && choice == 0)
      return make_error(ErrorCode::kInternal, "encoder replay: the open edge of input vertex " +
                                                  std::to_string(r.vertex) +
                                                  "'s boundary patch is not on the boundary");
    if (bits_) {
      ++bits_->open_choices;
      enc.set_cost_sink(&bits_->open_edge);
    }
    if (m.use_fast_start_models) {
      m.fast_start_open_edge.encode(enc, choice);
    } else {
      m.open_edge.encode(enc, choice);
    }
  } else if (r.open() != kNone) {
    return make_error(ErrorCode::kInternal, "encoder replay: the boundary patch of input vertex " +
                                                std::to_string(r.vertex) +
                                                " has no boundary edges");
  }
  // Coarse residual of the new vertex against its prediction.
  InsertionPrediction prediction;
  predict_insertion(s_, patches_[j].ring, min_shift, prediction);
  const int shift = format_.embedded ? prediction.shift : 0;
  if (bits_) enc.set_cost_sink(&bits_->residual);
  encode_coarse_residual(m, enc, prediction.ctx, t_.input_position[r.vertex], prediction.predicted,
                         shift, geometry_[j]);
  return {};
}

double StructureWriter::apply_patches(std::vector<std::pair<uint32_t, uint32_t>>& inserted) {
  const uint32_t count = static_cast<uint32_t>(order_.size());
  const uint32_t vertices_before = s_.mesh.vertex_count();
  double drop = 0;
  for (uint32_t j = 0; j < count; ++j) {
    const Removal& r = (*removals_)[order_[j].second];
    const Vec3i position = t_.input_position[r.vertex];
    const VertexGeometry& g = geometry_[j];
    // Distortion estimate: before, the true point lies off the fan by
    // about its normal offset from the prediction; after, by the error of
    // its reconstruction; both spread over the patch as a hat (integral
    // of a hat of height h over area A: A h^2 / 6).
    const double area = ring_area(s_.mesh.positions(), patches_[j].ring);
    const Vec3i pred = g.anchor;
    const Vec3i recon = reconstruct(g, s_.max_coordinate);
    double before = 0;
    if (t_.surface) {
      before = fan_distance2(s_.mesh.positions(), patches_[j].ring, position);
    } else {  // its offset along the input's normal there
      const double dn = dot(to_double(position - pred), to_double(t_.input_normal[r.vertex]));
      before = dn * dn;
    }
    const uint32_t v = apply_patch(s_, patches_[j], r.open(), g, nullptr);
    inserted.push_back({r.vertex, v});
    t_.input_of.push_back(r.vertex);
    t_.weight.push_back(area * std::sqrt(double(vertices_before + count)));
    drop += area * (before - vertex_error2(t_, v, recon)) / 6.0;
  }
  return drop;
}

}  // namespace meshstream

// Encoder: quantize -> layered decimation -> base mesh -> refinement records
// -> container. See encoder.h, refinement_codec.h and docs/hcs-format.md.
//
// The refinement records are written by replaying the decoder: the encoder
// keeps a RefinementState built from the base exactly as the decoder will
// decode it, names every patch in that state's terms and applies it with the
// same function the decoder uses. Encoder and decoder therefore agree on
// every face slot and ring start by construction.
#include "common/codec/encoder.h"

#include <algorithm>
#include <optional>
#include <string>
#include <unordered_map>

#include "common/codec/base_coder.h"
#include "common/codec/container.h"
#include "common/codec/crc32.h"
#include "common/codec/decimate.h"
#include "common/codec/quantize.h"
#include "common/codec/refinement_codec.h"

namespace meshstream {
namespace {

uint64_t position_key(Vec3i p) {
  return uint64_t(uint32_t(p.x)) | uint64_t(uint32_t(p.y)) << 21 | uint64_t(uint32_t(p.z)) << 42;
}

struct ChosenBase {
  uint8_t coder = kBaseCoderOwn;
  std::vector<uint8_t> bytes;
  BaseMesh decoded;                 // what the decoder will start from
  std::vector<uint32_t> to_input;   // decoded vertex -> input vertex id
};

// Own coder, with vertices in order of first use by the faces (a cheap
// spatially coherent order for the walk).
ChosenBase code_base_own(const DecimationResult& dec, const std::vector<Vec3i>& q, int bits) {
  ChosenBase out;
  std::unordered_map<uint32_t, uint32_t> id;
  for (const Triangle& t : dec.base_faces) {
    for (uint32_t v : t) {
      if (id.emplace(v, static_cast<uint32_t>(out.to_input.size())).second) out.to_input.push_back(v);
    }
  }
  for (uint32_t v : dec.base_vertices) {
    if (id.emplace(v, static_cast<uint32_t>(out.to_input.size())).second) out.to_input.push_back(v);
  }
  BaseMesh base;
  for (uint32_t v : out.to_input) base.positions.push_back(q[v]);
  for (const Triangle& t : dec.base_faces) base.faces.push_back({id[t[0]], id[t[1]], id[t[2]]});
  out.bytes = encode_base_own(base);
  out.decoded = std::move(base);
  out.coder = kBaseCoderOwn;
  return out;
}

// Draco, accepted only when its decode gives back exactly our base; the
// decoded order becomes the base order. Empty optional otherwise.
std::optional<ChosenBase> code_base_draco(const DecimationResult& dec, const std::vector<Vec3i>& q,
                                          int bits) {
  BaseMesh base;
  std::unordered_map<uint32_t, uint32_t> id;
  for (uint32_t v : dec.base_vertices) {
    id.emplace(v, static_cast<uint32_t>(base.positions.size()));
    base.positions.push_back(q[v]);
  }
  for (const Triangle& t : dec.base_faces) base.faces.push_back({id[t[0]], id[t[1]], id[t[2]]});
  auto bytes = encode_base_draco(base);
  if (!bytes) return std::nullopt;
  auto decoded = decode_base_draco(*bytes, static_cast<uint32_t>(base.positions.size()),
                                   static_cast<uint32_t>(base.faces.size()), bits);
  if (!decoded) return std::nullopt;
  // Map Draco's vertices back to ours (base ids): by position where it is
  // unique; vertices sharing a grid point are resolved through faces whose
  // other two corners are already mapped (a directed edge names one face in
  // a manifold mesh). Then the oriented faces must match id for id.
  const uint32_t n = static_cast<uint32_t>(base.positions.size());
  if (decoded->positions.size() != n || decoded->faces.size() != base.faces.size()) return std::nullopt;
  std::unordered_map<uint64_t, std::vector<uint32_t>> by_position;
  for (uint32_t v = 0; v < n; ++v) by_position[position_key(base.positions[v])].push_back(v);
  std::vector<uint32_t> map(n, kNone);  // decoded -> base
  std::vector<uint8_t> taken(n, 0);
  for (uint32_t d = 0; d < n; ++d) {
    auto it = by_position.find(position_key(decoded->positions[d]));
    if (it == by_position.end()) return std::nullopt;
    if (it->second.size() == 1) {
      map[d] = it->second[0];
      if (taken[map[d]]++) return std::nullopt;
    }
  }
  auto edge_key = [](uint32_t a, uint32_t b) { return uint64_t(a) << 32 | b; };
  std::unordered_map<uint64_t, uint32_t> third;  // directed edge -> opposite vertex (base ids)
  for (const Triangle& t : base.faces)
    for (int i = 0; i < 3; ++i) third[edge_key(t[i], t[(i + 1) % 3])] = t[(i + 2) % 3];
  for (bool progress = true; progress;) {
    progress = false;
    for (const Triangle& t : decoded->faces) {
      for (int i = 0; i < 3; ++i) {
        const uint32_t a = t[i], b = t[(i + 1) % 3], c = t[(i + 2) % 3];
        if (map[c] != kNone || map[a] == kNone || map[b] == kNone) continue;
        auto it = third.find(edge_key(map[a], map[b]));
        if (it == third.end() || taken[it->second] || !(base.positions[it->second] == decoded->positions[c])) {
          continue;
        }
        map[c] = it->second;
        taken[it->second] = 1;
        progress = true;
      }
    }
  }
  for (uint32_t d = 0; d < n; ++d)
    if (map[d] == kNone) return std::nullopt;
  auto oriented = [](Triangle t) {
    while (t[0] > t[1] || t[0] > t[2]) std::rotate(t.begin(), t.begin() + 1, t.end());
    return t;
  };
  std::vector<Triangle> ours, theirs;
  for (const Triangle& t : base.faces) ours.push_back(oriented(t));
  for (const Triangle& t : decoded->faces) theirs.push_back(oriented({map[t[0]], map[t[1]], map[t[2]]}));
  std::sort(ours.begin(), ours.end());
  std::sort(theirs.begin(), theirs.end());
  if (ours != theirs) return std::nullopt;
  ChosenBase out;
  out.to_input.resize(n);
  for (uint32_t d = 0; d < n; ++d) out.to_input[d] = dec.base_vertices[map[d]];
  out.coder = kBaseCoderDraco;
  out.bytes = std::move(*bytes);
  out.decoded = std::move(*decoded);
  return out;
}

class RecordWriter {
 public:
  RecordWriter(RefinementState& state, uint32_t record_bytes) : s_(state), record_bytes_(record_bytes) {}

  struct Finished {
    std::vector<uint8_t> payload;
    uint32_t vertices = 0, faces = 0;
  };
  std::vector<Finished> records;
  std::vector<std::pair<uint32_t, uint32_t>> inserted;  // (input id, decoder id)

  // Writes one layer; `removals` are in decoder vertex ids.
  Status write_layer(const std::vector<Removal>& removals) {
    const uint32_t n = s_.mesh.vertex_count();
    first_.assign(n, kNone);
    next_.assign(removals.size(), kNone);
    for (uint32_t i = 0; i < removals.size(); ++i) {
      const uint32_t apex = removals[i].ring[0];
      next_[i] = first_[apex];
      first_[apex] = i;
    }
    s_.layer += 1;
    s_.cursor = s_.order_head;
    s_.last_count = 0;
    size_t remaining = removals.size();
    begin_record(true);
    std::vector<uint32_t> star_ring, star_corners, at_apex;
    std::vector<std::pair<uint32_t, uint32_t>> order;  // (r, removal)
    std::vector<ResolvedPatch> patches;
    while (remaining > 0) {
      while (s_.cursor != kNone && s_.vertices[s_.cursor].layer == s_.layer) s_.cursor = s_.vertices[s_.cursor].next;
      if (s_.cursor == kNone) return make_error(ErrorCode::kInvalidMesh, "internal: walk ended with patches left");
      const uint32_t u = s_.cursor;
      s_.cursor = s_.vertices[u].next;
      ++walk_steps_;
      s_.mesh.star(u, star_ring, star_corners);
      const uint32_t ring_size = static_cast<uint32_t>(star_ring.size());
      const uint32_t faces = static_cast<uint32_t>(star_corners.size());
      order.clear();
      for (uint32_t i = u < n ? first_[u] : kNone; i != kNone; i = next_[i]) {
        const Removal& r = removals[i];
        uint32_t pos = kNone;
        for (uint32_t f = 0; f < faces; ++f) {
          if (star_ring[f] == r.ring[1] && star_ring[(f + 1) % ring_size] == r.ring[2]) pos = f;
        }
        if (pos == kNone) return make_error(ErrorCode::kInvalidMesh, "internal: patch not found at its apex");
        order.push_back({pos, i});
      }
      std::sort(order.begin(), order.end());
      const uint32_t count = static_cast<uint32_t>(order.size());
      RefinementModels& m = s_.models;
      const uint32_t free_faces = mark_taken_faces(s_, star_ring, faces, used_);
      if (free_faces != free_face_count(s_, u)) {
        return make_error(ErrorCode::kInvalidMesh, "internal: free face counts disagree");
      }
      if (free_faces > 0) {
        m.patch_count[count_context(s_, u, free_faces)].encode(enc_, std::min(count, 3u));
        if (count >= 3) m.patch_count_extra.encode(enc_, count - 3);
      } else if (count > 0) {
        return make_error(ErrorCode::kInvalidMesh, "internal: patch at a vertex without free faces");
      }
      s_.last_count = count;
      patches.resize(count);
      for (uint32_t j = 0; j < count; ++j) {
        const Removal& r = removals[order[j].second];
        const uint32_t k = static_cast<uint32_t>(r.ring.size());
        m.valence[std::min(ring_size, 12u)].encode(enc_, k - 3);
        rank_patch_starts(s_.mesh, u, star_ring, used_, k, candidates_);
        const auto it = std::find(candidates_.begin(), candidates_.end(), order[j].first);
        if (it == candidates_.end()) return make_error(ErrorCode::kInvalidMesh, "internal: patch start not a candidate");
        encode_start_rank(m, enc_, k, static_cast<uint32_t>(it - candidates_.begin()));
        for (uint32_t f = 0; f + 2 < k; ++f) used_[(order[j].first + f) % faces] = 1;
        if (!resolve_patch(s_.mesh, u, star_ring, star_corners, order[j].first, k, patches[j]) ||
            patches[j].ring != r.ring) {
          return make_error(ErrorCode::kInvalidMesh, "internal: patch does not resolve to its ring");
        }
        patch_boundary_edges(s_.mesh, patches[j], open_edges_);
        if (!open_edges_.empty()) {
          uint32_t choice = 0;
          for (uint32_t e = 0; e < open_edges_.size(); ++e)
            if (open_edges_[e] == r.open) choice = e + 1;
          if (r.open != kNone && choice == 0)
            return make_error(ErrorCode::kInvalidMesh, "internal: open edge of a boundary patch not on the boundary");
          m.open_edge.encode(enc_, choice);
        } else if (r.open != kNone) {
          return make_error(ErrorCode::kInvalidMesh, "internal: boundary patch without boundary edges");
        }
        const Vec3i pred = predict_position(s_.mesh, patches[j].ring);
        encode_residual(m, enc_, residual_context(s_.mesh, patches[j].ring), r.position, pred);
      }
      for (uint32_t j = 0; j < count; ++j) {
        const Removal& r = removals[order[j].second];
        const uint32_t v = apply_patch(s_, patches[j], r.open, r.position, nullptr);
        inserted.push_back({r.vertex, v});
      }
      insertions_ += count;
      remaining -= count;
      if (remaining == 0) {
        end_record();
      } else if (enc_.bytes_so_far() >= record_bytes_) {
        end_record();
        begin_record(false);
      }
    }
    return {};
  }

 private:
  void begin_record(bool starts_layer) {
    enc_ = RangeEncoder();
    starts_layer_ = starts_layer;
    walk_steps_ = 0;
    insertions_ = 0;
  }
  void end_record() {
    Finished f;
    write_record_header({starts_layer_, walk_steps_, insertions_}, f.payload);
    std::vector<uint8_t> coded = enc_.finish();
    f.payload.insert(f.payload.end(), coded.begin(), coded.end());
    f.vertices = s_.mesh.vertex_count();
    f.faces = s_.mesh.face_slot_count();
    records.push_back(std::move(f));
  }

  RefinementState& s_;
  uint32_t record_bytes_;
  RangeEncoder enc_;
  bool starts_layer_ = false;
  uint32_t walk_steps_ = 0, insertions_ = 0;
  std::vector<uint32_t> first_, next_, open_edges_, candidates_;
  std::vector<uint8_t> used_;
};

}  // namespace

Result<Mesh> quantized_reference(const Mesh& mesh, int quant_bits) {
  auto grid = make_grid(mesh, quant_bits);
  if (!grid) return tl::unexpected(grid.error());
  Mesh out;
  out.triangles = mesh.triangles;
  out.positions.resize(mesh.positions.size());
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    out.positions[v] = grid->dequantize(grid->quantize(mesh.positions[v]));
  }
  return out;
}

Result<std::vector<uint8_t>> encode_hcs(const Mesh& mesh, const EncodeOptions& options) {
  auto grid = make_grid(mesh, options.quant_bits);
  if (!grid) return tl::unexpected(grid.error());
  if (auto s = validate_arrays(mesh); !s) return tl::unexpected(s.error());
  if (mesh.triangles.empty()) return make_error(ErrorCode::kInvalidMesh, "mesh has no triangles");
  std::vector<Vec3i> q = quantize_positions(mesh, *grid);
  auto editable = EditableMesh::build(q, mesh.triangles);
  if (!editable) return tl::unexpected(editable.error());

  DecimateOptions dopt;
  dopt.target_vertices = options.target_base_vertices;
  DecimationResult dec = decimate_layers(std::move(*editable), dopt);

  ChosenBase base = code_base_own(dec, q, grid->bits);
  if (options.allow_draco_base) {
    if (auto draco = code_base_draco(dec, q, grid->bits); draco && draco->bytes.size() < base.bytes.size()) {
      base = std::move(*draco);
    }
  }
  auto state = RefinementState::from_base(base.decoded.positions, base.decoded.faces, grid->bits);
  if (!state) return tl::unexpected(state.error());

  // Input id -> decoder id, growing as the replay inserts vertices.
  std::vector<uint32_t> to_decoder(mesh.vertex_count(), kNone);
  for (uint32_t d = 0; d < base.to_input.size(); ++d) to_decoder[base.to_input[d]] = d;

  RecordWriter writer(*state, std::max<uint32_t>(options.record_bytes, 64));
  std::vector<Removal> layer_dec;
  for (size_t li = dec.layers.size(); li-- > 0;) {
    const std::vector<Removal>& layer = dec.layers[li];
    layer_dec = layer;
    for (Removal& r : layer_dec) {
      for (uint32_t& u : r.ring) u = to_decoder[u];
    }
    writer.inserted.clear();
    if (auto s = writer.write_layer(layer_dec); !s) return tl::unexpected(s.error());
    for (const auto& [input, decoded] : writer.inserted) to_decoder[input] = decoded;
  }

  StreamHeader header;
  header.vertex_count = mesh.vertex_count();
  header.face_count = mesh.face_count();
  header.base_vertex_count = static_cast<uint32_t>(base.decoded.positions.size());
  header.base_face_count = static_cast<uint32_t>(base.decoded.faces.size());
  header.bounds = grid->bounds;
  header.quant_bits = static_cast<uint8_t>(grid->bits);
  header.base_coder = base.coder;
  header.structure_coder = kStructureCoderRange;
  header.geometry_coder = kGeometryCoderRangeAverage;
  header.layer_count = static_cast<uint32_t>(dec.layers.size());
  header.extra = {kRefinementFormat};

  std::vector<RecordEntry> entries;
  std::vector<const std::vector<uint8_t>*> payloads;
  RecordEntry e0;
  e0.size = static_cast<uint32_t>(base.bytes.size());
  e0.vertices = header.base_vertex_count;
  e0.faces = header.base_face_count;
  e0.crc32 = crc32(0, base.bytes.data(), base.bytes.size());
  entries.push_back(e0);
  payloads.push_back(&base.bytes);
  for (const auto& r : writer.records) {
    RecordEntry e;
    e.size = static_cast<uint32_t>(r.payload.size());
    e.vertices = r.vertices;
    e.faces = r.faces;
    e.crc32 = crc32(0, r.payload.data(), r.payload.size());
    entries.push_back(e);
    payloads.push_back(&r.payload);
  }
  if (entries.back().vertices != header.vertex_count || entries.back().faces != header.face_count) {
    return make_error(ErrorCode::kInvalidMesh, "internal: the records do not rebuild the whole mesh");
  }
  std::vector<uint8_t> out = write_container_prefix(header, entries);
  for (const auto* p : payloads) out.insert(out.end(), p->begin(), p->end());
  return out;
}

}  // namespace meshstream

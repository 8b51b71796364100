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
#include <cmath>
#include <cstring>
#include <functional>
#include <future>
#include <limits>
#include <optional>
#include <string>
#include <thread>
#include <unordered_map>

#include "common/codec/base_coder.h"
#include "common/codec/container.h"
#include "common/codec/crc32.h"
#include "common/codec/decimate.h"
#include "common/codec/quantize.h"
#include "common/codec/rd_measure.h"
#include "common/codec/refinement_codec.h"
#include "common/metrics/bvh.h"
#include "common/metrics/closest_point.h"

namespace meshstream {
namespace {

uint64_t position_key(Vec3i p) {
  return uint64_t(uint32_t(p.x)) | uint64_t(uint32_t(p.y)) << 21 | uint64_t(uint32_t(p.z)) << 42;
}

struct ChosenBase {
  uint8_t coder = kBaseCoderOwn;
  std::vector<uint8_t> bytes;
  BaseMesh decoded;                // what the decoder will start from
  std::vector<uint32_t> to_input;  // decoded vertex -> input vertex id
};

// Own coder, with vertices in order of first use by the faces (a cheap
// spatially coherent order for the walk).
ChosenBase code_base_own(const DecimationResult& dec, const std::vector<Vec3i>& q, int bits) {
  ChosenBase out;
  std::unordered_map<uint32_t, uint32_t> id;
  for (const Triangle& t : dec.base_faces) {
    for (uint32_t v : t) {
      if (id.emplace(v, static_cast<uint32_t>(out.to_input.size())).second)
        out.to_input.push_back(v);
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
  if (decoded->positions.size() != n || decoded->faces.size() != base.faces.size())
    return std::nullopt;
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
        if (it == third.end() || taken[it->second] ||
            !(base.positions[it->second] == decoded->positions[c])) {
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
  for (const Triangle& t : decoded->faces)
    theirs.push_back(oriented({map[t[0]], map[t[1]], map[t[2]]}));
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

// What only the encoder knows about each decoder vertex: its true position
// (and residual against its anchor) and the weight of its error in the
// distortion estimate; and, by input id, unit normals of the original.
struct EncoderTruth {
  std::vector<Vec3i> position;
  std::vector<Vec3i> residual;
  // Star area when the vertex got its geometry x sqrt(vertex count then):
  // the area its error spreads over shrinks as the mesh refines around it;
  // area(now) ~ weight / sqrt(vertices now) measured better than 1 / n
  // (refinement is not uniform: flat regions stay coarse) or no decay.
  std::vector<double> weight;
  std::vector<Vec3f> input_normal;  // by input id
  // The original surface in grid units; when set, a vertex's error is its
  // distance to that surface instead of its displacement from its truth.
  const TriangleBvh* surface = nullptr;
  // Per vertex, the surface errors of the last two positions asked about
  // (a group's next plane is evaluated again when the group grows, and its
  // "after" becomes the next evaluation's "before"), and the triangle found
  // last, which starts the next search nearby.
  struct CachedError {
    Vec3i position[2];
    double error2[2] = {-1, -1};
    uint32_t triangle = TriangleBvh::kNoHint;
  };
  std::vector<CachedError> cached;
};

// Squared error of a displaced vertex for the distortion estimate. The
// whole vector counts: weighting tangential slip down (it mostly slides the
// surface within itself) measured worse on CAD meshes, where a vertex on a
// crease slides across the other face.
double displacement_error2(Vec3i recon, Vec3i truth) {
  const double e[3] = {double(recon.x) - truth.x, double(recon.y) - truth.y,
                       double(recon.z) - truth.z};
  return e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
}

Vec3d grid_point(Vec3i p) { return {double(p.x), double(p.y), double(p.z)}; }

// Decoder vertex v's squared error when shown at `recon`: its distance to
// the original surface, or (no surface) its displacement from its true
// position. Surface answers are remembered (EncoderTruth::cached).
double vertex_error2(EncoderTruth& t, uint32_t v, Vec3i recon) {
  if (!t.surface) return displacement_error2(recon, t.position[v]);
  if (recon == t.position[v]) return 0;  // an original vertex lies on the original surface
  if (t.cached.size() <= v) t.cached.resize(v + 1);
  EncoderTruth::CachedError& c = t.cached[v];
  for (int i = 0; i < 2; ++i)
    if (c.error2[i] >= 0 && c.position[i] == recon) return c.error2[i];
  const ClosestHit hit = t.surface->closest(grid_point(recon), c.triangle);
  c.triangle = hit.triangle;
  c.position[1] = c.position[0];
  c.error2[1] = c.error2[0];
  c.position[0] = recon;
  c.error2[0] = hit.squared_distance;
  return hit.squared_distance;
}

// Squared distance from `p` to the fan of `ring` (ring[0], ring[i], ring[i+1]):
// the faces a patch replaces.
double fan_distance2(const std::vector<Vec3i>& pos, const std::vector<uint32_t>& ring, Vec3i p) {
  const Vec3d q = grid_point(p);
  double best = std::numeric_limits<double>::infinity();
  const Vec3d a = grid_point(pos[ring[0]]);
  for (size_t i = 1; i + 1 < ring.size(); ++i) {
    const Vec3d c =
        closest_point_on_triangle(q, a, grid_point(pos[ring[i]]), grid_point(pos[ring[i + 1]]));
    const double dx = c.x - q.x, dy = c.y - q.y, dz = c.z - q.z;
    best = std::min(best, dx * dx + dy * dy + dz * dz);
  }
  return best;
}

// Area of the fan/star polygon `ring` (sum of triangle areas from ring[0]).
double ring_area(const std::vector<Vec3i>& p, const std::vector<uint32_t>& ring) {
  double total = 0;
  const Vec3i o = p[ring[0]];
  for (size_t i = 1; i + 1 < ring.size(); ++i) {
    const Vec3i a = p[ring[i]], b = p[ring[i + 1]];
    const double ax = a.x - o.x, ay = a.y - o.y, az = a.z - o.z;
    const double bx = b.x - o.x, by = b.y - o.y, bz = b.z - o.z;
    const double cx = ay * bz - az * by, cy = az * bx - ax * bz, cz = ax * by - ay * bx;
    total += 0.5 * std::sqrt(cx * cx + cy * cy + cz * cz);
  }
  return total;
}

struct Finished {
  std::vector<uint8_t> payload;
  uint32_t vertices = 0, faces = 0;
  bool plane = false;
  double drop = 0;
};

// Structure records of one layer at a time, by replaying the decoder (see
// the file comment). Each record is a run of the layer's walk.
class StructureWriter {
 public:
  // `bits` (optional) receives the cost of each symbol class.
  StructureWriter(RefinementState& state, EncoderTruth& truth, uint8_t format, StructureBits* bits)
      : s_(state), t_(truth), format_(format), bits_(bits) {
    s_.models.v_models = format >= 3;
  }

  bool layer_open() const { return remaining_ > 0; }

  // `removals` are in decoder vertex ids.
  void start_layer(std::vector<Removal> removals) {
    removals_ = std::move(removals);
    const uint32_t n = s_.mesh.vertex_count();
    first_.assign(n, kNone);
    next_.assign(removals_.size(), kNone);
    for (uint32_t i = 0; i < removals_.size(); ++i) {
      const uint32_t apex = removals_[i].ring[0];
      next_[i] = first_[apex];
      first_[apex] = i;
    }
    s_.layer += 1;
    s_.cursor = s_.order_head;
    s_.last_count = 0;
    remaining_ = removals_.size();
    starts_layer_ = true;
    layer_vertices_ = n;
  }

  // Writes the next record of the open layer, about `target` bytes.
  // `inserted` gets (input id, decoder id) of every vertex it put back.
  Status write_record(uint32_t target, int min_shift, Finished& out,
                      std::vector<std::pair<uint32_t, uint32_t>>& inserted) {
    RangeEncoder enc;
    uint32_t walk_steps = 0, insertions = 0;
    double drop = 0;
    const uint32_t n = layer_vertices_;
    while (remaining_ > 0) {
      while (s_.cursor != kNone && s_.vertices[s_.cursor].layer == s_.layer)
        s_.cursor = s_.vertices[s_.cursor].next;
      if (s_.cursor == kNone)
        return make_error(ErrorCode::kInvalidMesh, "internal: walk ended with patches left");
      const uint32_t u = s_.cursor;
      s_.cursor = s_.vertices[u].next;
      ++walk_steps;
      if (bits_) ++bits_->walk_steps;
      s_.mesh.star(u, star_ring_, star_corners_);
      const uint32_t ring_size = static_cast<uint32_t>(star_ring_.size());
      const uint32_t faces = static_cast<uint32_t>(star_corners_.size());
      order_.clear();
      for (uint32_t i = u < n ? first_[u] : kNone; i != kNone; i = next_[i]) {
        const Removal& r = removals_[i];
        uint32_t pos = kNone;
        for (uint32_t f = 0; f < faces; ++f) {
          if (star_ring_[f] == r.ring[1] && star_ring_[(f + 1) % ring_size] == r.ring[2]) pos = f;
        }
        if (pos == kNone)
          return make_error(ErrorCode::kInvalidMesh, "internal: patch not found at its apex");
        order_.push_back({pos, i});
      }
      std::sort(order_.begin(), order_.end());
      const uint32_t count = static_cast<uint32_t>(order_.size());
      RefinementModels& m = s_.models;
      const uint32_t free_faces = mark_taken_faces(s_, star_ring_, faces, used_);
      if (free_faces != free_face_count(s_, u)) {
        return make_error(ErrorCode::kInvalidMesh, "internal: free face counts disagree");
      }
      if (free_faces > 0) {
        if (bits_) {
          ++bits_->count_steps;
          enc.set_cost_sink(&bits_->count);
        }
        if (m.v_models) {
          count_model3(s_, u, free_faces).encode(enc, std::min(count, 3u));
          if (count >= 3) m.patch_count_extra3.encode(enc, count - 3);
        } else {
          m.patch_count[count_context(s_, u, free_faces)].encode(enc, std::min(count, 3u));
          if (count >= 3) m.patch_count_extra.encode(enc, count - 3);
        }
      } else if (count > 0) {
        return make_error(ErrorCode::kInvalidMesh,
                          "internal: patch at a vertex without free faces");
      }
      s_.last_count = count;
      patches_.resize(count);
      uint32_t free_left = free_faces;
      geometry_.resize(count);
      for (uint32_t j = 0; j < count; ++j) {
        const Removal& r = removals_[order_[j].second];
        const uint32_t k = static_cast<uint32_t>(r.ring.size());
        if (bits_) {
          ++bits_->insertions;
          enc.set_cost_sink(&bits_->valence);
        }
        if (m.v_models) {
          valence_model3(s_, ring_size, free_left).encode(enc, k - 3);
        } else {
          m.valence[std::min(ring_size, 12u)].encode(enc, k - 3);
        }
        free_left = free_left >= k - 2 ? free_left - (k - 2) : 0;
        rank_patch_starts(s_.mesh, u, star_ring_, used_, k, candidates_, scores_);
        const auto it = std::find(candidates_.begin(), candidates_.end(), order_[j].first);
        if (it == candidates_.end())
          return make_error(ErrorCode::kInvalidMesh, "internal: patch start not a candidate");
        if (bits_) enc.set_cost_sink(&bits_->rank);
        const uint32_t rank = static_cast<uint32_t>(it - candidates_.begin());
        if (format_ >= 3) {
          const size_t c = candidates_.size();
          encode_start_rank3(m, enc, start_rank_context(k, c, scores_[0], c > 1 ? scores_[1] : -1),
                             c, rank);
        } else {
          encode_start_rank(m, enc, k, rank);
        }
        for (uint32_t f = 0; f + 2 < k; ++f) used_[(order_[j].first + f) % faces] = 1;
        if (!resolve_patch(s_.mesh, u, star_ring_, star_corners_, order_[j].first, k,
                           patches_[j]) ||
            patches_[j].ring != r.ring) {
          return make_error(ErrorCode::kInvalidMesh,
                            "internal: patch does not resolve to its ring");
        }
        patch_boundary_edges(s_.mesh, patches_[j], open_edges_);
        if (!open_edges_.empty()) {
          uint32_t choice = 0;
          for (uint32_t e = 0; e < open_edges_.size(); ++e)
            if (open_edges_[e] == r.open) choice = e + 1;
          if (r.open != kNone && choice == 0)
            return make_error(ErrorCode::kInvalidMesh,
                              "internal: open edge of a boundary patch not on the boundary");
          if (bits_) {
            ++bits_->open_choices;
            enc.set_cost_sink(&bits_->open_edge);
          }
          if (m.v_models) {
            m.open_edge3.encode(enc, choice);
          } else {
            m.open_edge.encode(enc, choice);
          }
        } else if (r.open != kNone) {
          return make_error(ErrorCode::kInvalidMesh,
                            "internal: boundary patch without boundary edges");
        }
        InsertionPrediction prediction;
        predict_insertion(s_, patches_[j].ring, min_shift, prediction);
        const int shift = format_ >= 2 ? prediction.shift : 0;
        if (bits_) enc.set_cost_sink(&bits_->residual);
        encode_coarse_residual(m, enc, prediction.ctx, r.position, prediction.predicted, shift,
                               geometry_[j]);
      }
      enc.set_cost_sink(nullptr);
      const uint32_t vertices_before = s_.mesh.vertex_count();
      for (uint32_t j = 0; j < count; ++j) {
        const Removal& r = removals_[order_[j].second];
        const VertexGeometry& g = geometry_[j];
        // Distortion estimate: before, the true point lies off the fan by
        // about its normal offset from the prediction; after, by the error of
        // its reconstruction; both spread over the patch as a hat (integral
        // of a hat of height h over area A: A h^2 / 6).
        const double area = ring_area(s_.mesh.positions(), patches_[j].ring);
        const Vec3f nrm = t_.input_normal[r.vertex];
        const Vec3i pred = g.anchor;
        const double d[3] = {double(r.position.x) - pred.x, double(r.position.y) - pred.y,
                             double(r.position.z) - pred.z};
        const double dn = d[0] * nrm.x + d[1] * nrm.y + d[2] * nrm.z;
        const Vec3i recon = reconstruct(g, s_.max_coordinate);
        const double before =
            t_.surface ? fan_distance2(s_.mesh.positions(), patches_[j].ring, r.position) : dn * dn;
        const uint32_t v = apply_patch(s_, patches_[j], r.open, g, nullptr);
        inserted.push_back({r.vertex, v});
        t_.position.push_back(r.position);
        t_.residual.push_back(
            {r.position.x - pred.x, r.position.y - pred.y, r.position.z - pred.z});
        t_.weight.push_back(area * std::sqrt(double(vertices_before + count)));
        drop += area * (before - vertex_error2(t_, v, recon)) / 6.0;
      }
      insertions += count;
      remaining_ -= count;
      if (enc.bytes_so_far() >= target) break;
    }
    out = Finished{};
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

 private:
  RefinementState& s_;
  EncoderTruth& t_;
  uint8_t format_;
  StructureBits* bits_;
  std::vector<Removal> removals_;
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

// A plane step's true bits without coding them (for estimates).
struct PlaneBitOracle {
  Vec3i residual;
  uint32_t bit(BitModel&, int axis, int below) {
    return (uint32_t(std::abs(residual[axis])) >> below) & 1u;
  }
  uint32_t sign(BitModel&, int axis) { return residual[axis] < 0 ? 1u : 0u; }
};

// Issue I's kind of coder for plane bits (EncodeReport::plane_bytes_plain):
// one adaptive model per plane and one for signs, persisting across records
// like the context models.
struct PlainPlaneModels {
  BitModel bit[kMaxShift + 1];
  BitModel sign;
};

// PlaneBitWriter's bits through the plain models instead of the context ones.
struct PlainPlaneWriter {
  PlaneBitWriter writer;
  PlainPlaneModels& m;
  uint32_t bit(BitModel&, int axis, int below) { return writer.bit(m.bit[below], axis, below); }
  uint32_t sign(BitModel&, int axis) { return writer.sign(m.sign, axis); }
};

// Bytes of the next plane step of vertices [first, first + count) through
// the plain coder (the state is not changed; `models` learn).
size_t plain_plane_bytes(const RefinementState& s, const EncoderTruth& t, uint32_t first,
                         uint32_t count, PlainPlaneModels& models) {
  RangeEncoder enc;
  GeometryModels unused;
  uint8_t prev_new = 0;
  for (uint32_t v = first; v < first + count; ++v) {
    VertexGeometry geo = s.geometry[v];
    if (geo.shift == 0) continue;
    PlainPlaneWriter io{{enc, t.residual[v]}, models};
    plane_step(unused, io, geo, prev_new, s.max_coordinate);
  }
  return enc.finish().size();
}

// A run of vertex ids refined together by plane records (a batch).
struct PlaneGroup {
  uint32_t first = 0, count = 0;
  bool started = false;    // a plane record was written for it
  uint32_t pending = 0;    // vertices with shift > 0
  int top_plane = 0;       // largest shift - 1 among them
  double scaled_drop = 0;  // estimated drop of its next plane x vertex count
};

void evaluate_group(const RefinementState& s, EncoderTruth& t, PlaneGroup& g) {
  g.pending = 0;
  g.top_plane = 0;
  g.scaled_drop = 0;
  GeometryModels scratch;  // the oracle ignores models
  for (uint32_t v = g.first; v < g.first + g.count; ++v) {
    VertexGeometry geo = s.geometry[v];
    if (geo.shift == 0) continue;
    ++g.pending;
    g.top_plane = std::max(g.top_plane, geo.shift - 1);
    const Vec3i before = s.mesh.positions()[v];
    PlaneBitOracle io{t.residual[v]};
    uint8_t prev_new = 0;
    plane_step(scratch, io, geo, prev_new, s.max_coordinate);
    const Vec3i after = reconstruct(geo, s.max_coordinate);
    g.scaled_drop += t.weight[v] * (vertex_error2(t, v, before) - vertex_error2(t, v, after)) / 6.0;
  }
}

// Area-weighted vertex normals of the (quantized) input, unit length.
std::vector<Vec3f> vertex_normals(const std::vector<Vec3i>& q, const std::vector<Triangle>& faces) {
  std::vector<Vec3f> n(q.size(), Vec3f{0, 0, 0});
  for (const Triangle& t : faces) {
    const Vec3i a = q[t[0]], b = q[t[1]], c = q[t[2]];
    const double ux = b.x - a.x, uy = b.y - a.y, uz = b.z - a.z;
    const double wx = c.x - a.x, wy = c.y - a.y, wz = c.z - a.z;
    const Vec3f cr{float(uy * wz - uz * wy), float(uz * wx - ux * wz), float(ux * wy - uy * wx)};
    for (uint32_t v : t) n[v] = n[v] + cr;
  }
  for (Vec3f& x : n) {
    const float len = std::sqrt(x.x * x.x + x.y * x.y + x.z * x.z);
    x = len > 0 ? Vec3f{x.x / len, x.y / len, x.z / len} : Vec3f{0, 0, 1};
  }
  return n;
}

struct EncodedStream {
  std::vector<uint8_t> bytes;
  size_t largest_refinement = 0;
  size_t records = 0;
};

Result<EncodedStream> encode_once(const Mesh& mesh, const QuantGrid& grid,
                                  const std::vector<Vec3i>& q, const DecimationResult& dec,
                                  const EncodeOptions& options, uint32_t record_bytes,
                                  double plane_calibration, EncodeReport* report,
                                  const TriangleBvh* surface) {
  const int bits = grid.bits;
  const uint8_t format = options.refinement_format == 0
                             ? kRefinementFormat
                             : static_cast<uint8_t>(options.refinement_format);
  const int base_shift = options.embedded
                             ? std::clamp(options.base_shift < 0 ? bits - 8 : options.base_shift, 0,
                                          std::min(kMaxBaseShift, bits - 1))
                             : 0;
  std::vector<Vec3i> coarse(q.size());
  for (size_t v = 0; v < q.size(); ++v)
    for (int a = 0; a < 3; ++a) coarse[v][a] = q[v][a] >> base_shift;

  ChosenBase base = code_base_own(dec, coarse, bits - base_shift);
  if (options.allow_draco_base) {
    if (auto draco = code_base_draco(dec, coarse, bits - base_shift);
        draco && draco->bytes.size() < base.bytes.size()) {
      base = std::move(*draco);
    }
  }
  auto state = RefinementState::from_coarse_base(base.decoded.positions, base.decoded.faces, bits,
                                                 base_shift);
  if (!state) return tl::unexpected(state.error());
  state->format = format;
  const uint32_t base_n = static_cast<uint32_t>(base.decoded.positions.size());

  // Encoder-side truth, in decoder ids.
  EncoderTruth truth;
  truth.input_normal = vertex_normals(q, mesh.triangles);
  truth.surface = surface;
  {
    std::vector<double> star_area(base_n, 0.0);
    for (const Triangle& f : base.decoded.faces) {
      const double a = ring_area(state->mesh.positions(), {f[0], f[1], f[2]});
      for (uint32_t v : f) star_area[v] += a;
    }
    for (uint32_t d = 0; d < base_n; ++d) {
      const uint32_t in = base.to_input[d];
      truth.position.push_back(q[in]);
      const Vec3i anchor = state->geometry[d].anchor;
      truth.residual.push_back({q[in].x - anchor.x, q[in].y - anchor.y, q[in].z - anchor.z});
      truth.weight.push_back(star_area[d] * std::sqrt(double(base_n)));
    }
  }
  // Input id -> decoder id, growing as the replay inserts vertices.
  std::vector<uint32_t> to_decoder(mesh.vertex_count(), kNone);
  for (uint32_t d = 0; d < base.to_input.size(); ++d) to_decoder[base.to_input[d]] = d;

  std::vector<Finished> records;
  Finished base_record;
  base_record.payload = base.bytes;
  base_record.vertices = base_n;
  base_record.faces = static_cast<uint32_t>(base.decoded.faces.size());
  records.push_back(std::move(base_record));

  auto hash_state = [&](const RefinementState& s) {
    std::vector<Vec3f> p(s.mesh.vertex_count());
    for (uint32_t v = 0; v < p.size(); ++v) p[v] = grid.dequantize(s.mesh.positions()[v]);
    return position_hash(p);
  };
  if (report) {
    report->records.clear();
    report->base_shift = static_cast<uint32_t>(base_shift);
    report->ordering = {plane_calibration, surface ? 2 : 1};
    report->plane_bits_raw = report->plane_bytes_coded = report->plane_bytes_plain =
        report->structure_bytes = 0;
    report->structure_bits = StructureBits{};
    report->records.push_back({false, base_n, uint32_t(base.bytes.size()), hash_state(*state), 0});
  }

  // Plane groups: about a record's worth of plane bits each.
  const uint32_t group_vertices = std::max<uint32_t>(16, record_bytes * 8 / 4);
  std::vector<PlaneGroup> groups;
  auto add_range = [&](uint32_t first, uint32_t count) {
    while (count > 0) {
      if (!groups.empty() && !groups.back().started &&
          groups.back().first + groups.back().count == first &&
          groups.back().count < group_vertices) {
        const uint32_t take = std::min(count, group_vertices - groups.back().count);
        groups.back().count += take;
        first += take;
        count -= take;
        evaluate_group(*state, truth, groups.back());
        continue;
      }
      PlaneGroup g;
      g.first = first;
      g.count = std::min(count, group_vertices);
      first += g.count;
      count -= g.count;
      evaluate_group(*state, truth, g);
      groups.push_back(g);
    }
  };
  add_range(0, base_n);

  StructureWriter writer(*state, truth, format, report ? &report->structure_bits : nullptr);
  size_t next_layer = dec.layers.size();  // layers restore from the last one
  double structure_slope = std::numeric_limits<double>::infinity();
  double plane_bits_per_step[kMaxShift + 1];
  std::fill(std::begin(plane_bits_per_step), std::end(plane_bits_per_step), 3.0);
  std::vector<std::pair<uint32_t, uint32_t>> inserted;
  PlainPlaneModels plain_models;
  const double record_overhead = 6.0;  // header and range coder flush, bytes

  while (true) {
    const bool structure_left = writer.layer_open() || next_layer > 0;
    // The best plane group by estimated drop per byte.
    int best = -1;
    double best_slope = -std::numeric_limits<double>::infinity();
    const double n_now = state->mesh.vertex_count();
    for (size_t i = 0; i < groups.size(); ++i) {
      const PlaneGroup& g = groups[i];
      if (g.pending == 0) continue;
      const double bytes = g.pending * plane_bits_per_step[g.top_plane] / 8.0 + record_overhead;
      // The calibration corrects the proxy's balance of plane steps against
      // structure; measured per mesh (see EncodeOptions::plane_calibration).
      double slope = plane_calibration * g.scaled_drop / std::sqrt(n_now) / bytes;
      if (!std::isfinite(slope)) slope = 0;
      if (best < 0 || slope > best_slope) {
        best_slope = slope;
        best = static_cast<int>(i);
      }
    }
    if (structure_left && (best < 0 || structure_slope >= best_slope)) {
      if (!writer.layer_open()) {
        --next_layer;
        std::vector<Removal> layer = dec.layers[next_layer];
        for (Removal& r : layer)
          for (uint32_t& u : r.ring) u = to_decoder[u];
        writer.start_layer(std::move(layer));
      }
      const uint32_t first_new = state->mesh.vertex_count();
      Finished f;
      inserted.clear();
      if (auto st = writer.write_record(
              record_bytes, options.embedded ? options.insertion_shift : 0, f, inserted);
          !st)
        return tl::unexpected(st.error());
      for (const auto& [input, decoded] : inserted) to_decoder[input] = decoded;
      structure_slope =
          std::isfinite(f.drop) ? std::max(f.drop, 0.0) / double(f.payload.size()) : 0.0;
      if (report) {
        report->structure_bytes += f.payload.size();
        report->records.push_back(
            {false, f.vertices, uint32_t(f.payload.size()), hash_state(*state), f.drop});
      }
      records.push_back(std::move(f));
      add_range(first_new, state->mesh.vertex_count() - first_new);
      continue;
    }
    if (best < 0) break;
    PlaneGroup& g = groups[best];
    Finished f;
    f.plane = true;
    const uint32_t steps = g.pending;
    const int plane = g.top_plane;
    uint64_t sign_bits = 0;  // for the raw comparison: signs sent on becoming significant
    for (uint32_t v = g.first; v < g.first + g.count; ++v) {
      const VertexGeometry& geo = state->geometry[v];
      if (geo.shift == 0 || geo.normal_axis == kBaseVertexAxis) continue;
      for (int a = 0; a < 3; ++a)
        sign_bits +=
            geo.mag[a] == 0 && ((uint32_t(std::abs(truth.residual[v][a])) >> (geo.shift - 1)) & 1u);
    }
    if (report)
      report->plane_bytes_plain += plain_plane_bytes(*state, truth, g.first, g.count, plain_models);
    f.payload = write_plane_record(*state, g.first, g.count, truth.residual);
    f.vertices = state->mesh.vertex_count();
    f.faces = state->mesh.face_slot_count();
    f.drop = g.scaled_drop / std::sqrt(n_now);
    const size_t head = 1 + (g.first >= 128 ? 3 : 1) + (g.count >= 128 ? 2 : 1);
    const double coded_bits =
        8.0 * (double(f.payload.size()) - double(std::min(head, f.payload.size())));
    plane_bits_per_step[plane] =
        0.7 * plane_bits_per_step[plane] + 0.3 * coded_bits / std::max(1u, steps);
    g.started = true;
    if (report) {
      report->plane_bits_raw += 3ull * steps + sign_bits;
      report->plane_bytes_coded += f.payload.size() - std::min(head, f.payload.size());
      report->records.push_back(
          {true, f.vertices, uint32_t(f.payload.size()), hash_state(*state), f.drop});
    }
    evaluate_group(*state, truth, g);
    records.push_back(std::move(f));
  }

  StreamHeader header;
  header.vertex_count = mesh.vertex_count();
  header.face_count = mesh.face_count();
  header.base_vertex_count = base_n;
  header.base_face_count = static_cast<uint32_t>(base.decoded.faces.size());
  header.bounds = grid.bounds;
  header.quant_bits = static_cast<uint8_t>(bits);
  header.base_coder = base.coder;
  header.structure_coder = kStructureCoderRange;
  header.geometry_coder = kGeometryCoderEmbedded;
  header.layer_count = static_cast<uint32_t>(dec.layers.size());
  header.extra = {format, static_cast<uint8_t>(base_shift)};

  // Container version 3: compact index, each record's CRC-32 in a trailer.
  EncodedStream out;
  std::vector<std::vector<uint8_t>> payloads;
  std::vector<RecordCounts> counts;
  payloads.reserve(records.size());
  counts.reserve(records.size());
  for (Finished& r : records) {
    counts.push_back({r.vertices, r.faces});
    payloads.push_back(std::move(r.payload));
  }
  if (counts.back().vertices != header.vertex_count || counts.back().faces != header.face_count) {
    return make_error(ErrorCode::kInvalidMesh,
                      "internal: the records do not rebuild the whole mesh");
  }
  auto written = write_container(header, payloads, counts);
  if (!written) return tl::unexpected(written.error());
  // Record sizes as the index has them (with the trailer): the granularity
  // bound is about what a client receives.
  for (size_t i = 1; i < written->records.size(); ++i) {
    out.largest_refinement = std::max<size_t>(out.largest_refinement, written->records[i].size);
  }
  out.records = written->records.size();
  out.bytes = std::move(written->bytes);
  return out;
}

}  // namespace

uint64_t position_hash(const std::vector<Vec3f>& positions) {
  uint64_t h = 1469598103934665603ull;
  for (const Vec3f& p : positions) {
    for (float f : {p.x, p.y, p.z}) {
      uint32_t b;
      std::memcpy(&b, &f, 4);
      for (int i = 0; i < 4; ++i) {
        h ^= (b >> (8 * i)) & 0xFF;
        h *= 1099511628211ull;
      }
    }
  }
  return h;
}

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
  return encode_hcs(mesh, options, nullptr);
}

Result<std::vector<uint8_t>> encode_hcs(const Mesh& mesh, const EncodeOptions& options,
                                        EncodeReport* report) {
  if (options.refinement_format != 0 && options.refinement_format != kRefinementFormatEmbedded &&
      options.refinement_format != kRefinementFormat) {
    return make_error(ErrorCode::kInvalidArgument, "refinement format " +
                                                       std::to_string(options.refinement_format) +
                                                       " cannot be written (2 or 3)");
  }
  if (options.distortion_estimate < 0 || options.distortion_estimate > 2) {
    return make_error(
        ErrorCode::kInvalidArgument,
        "distortion estimate " + std::to_string(options.distortion_estimate) + " is not 0, 1 or 2");
  }
  auto grid = make_grid(mesh, options.quant_bits);
  if (!grid) return tl::unexpected(grid.error());
  if (auto s = validate_arrays(mesh); !s) return tl::unexpected(s.error());
  if (mesh.triangles.empty()) return make_error(ErrorCode::kInvalidMesh, "mesh has no triangles");
  std::vector<Vec3i> q = quantize_positions(mesh, *grid);
  auto editable = EditableMesh::build(q, mesh.triangles);
  if (!editable) return tl::unexpected(editable.error());

  DecimateOptions dopt;
  dopt.target_vertices = options.target_base_vertices;
  const DecimationResult dec = decimate_layers(std::move(*editable), dopt);
  // The orderings to encode: every candidate that agrees with the fixed
  // options, or the one the options fix.
  const bool measured = options.embedded && options.plane_calibration <= 0;
  std::vector<RecordOrdering> orderings;
  if (measured) {
    for (const RecordOrdering& c : kOrderingCandidates)
      if (options.distortion_estimate == 0 || options.distortion_estimate == c.distortion_estimate)
        orderings.push_back(c);
  } else {
    orderings.push_back({options.plane_calibration, options.distortion_estimate == 2 ? 2 : 1});
  }
  // The original in grid units, for the surface-distance estimate.
  TriangleBvh grid_surface;
  if (std::any_of(orderings.begin(), orderings.end(),
                  [](const RecordOrdering& o) { return o.distortion_estimate == 2; })) {
    Mesh grid_mesh;
    grid_mesh.triangles = mesh.triangles;
    grid_mesh.positions.reserve(q.size());
    for (const Vec3i& p : q) grid_mesh.positions.push_back({float(p.x), float(p.y), float(p.z)});
    grid_surface = TriangleBvh::build(grid_mesh);
  }
  auto surface_for = [&](const RecordOrdering& o) {
    return o.distortion_estimate == 2 ? &grid_surface : nullptr;
  };

  // Granularity (issue II): at least min(n / 50, 200) record boundaries and
  // no refinement record above 2 % of the stream. Automatic record sizes
  // start from an estimate of the stream (about 20 bits per vertex) and
  // shrink when the result misses either bound.
  const uint32_t n = mesh.vertex_count();
  const bool automatic = options.record_bytes == 0;
  const double estimate = 20.0 * n / 8.0;
  // Plane records add to the count; each record costs an index entry (about
  // 1.5 bytes, container 3) and a 4-byte CRC trailer.
  const double wanted = std::max(50.0, 1.1 * std::min<double>(n / 50, 200));
  const size_t wanted_records = std::min<size_t>(n / 50, 200) + 1;  // + the base
  auto granular = [&](const EncodedStream& e) {
    return e.records >= wanted_records &&
           double(e.largest_refinement) <= 0.02 * double(e.bytes.size());
  };
  uint32_t record_bytes = automatic
                              ? static_cast<uint32_t>(std::clamp(estimate / wanted, 32.0, 8192.0))
                              : std::max<uint32_t>(options.record_bytes, 16);
  auto encode_candidate = [&](size_t i, uint32_t bytes, EncodeReport* candidate_report) {
    return encode_once(mesh, *grid, q, dec, options, bytes, orderings[i].plane_calibration,
                       candidate_report, surface_for(orderings[i]));
  };
  // The other candidates run on their own threads (they share only
  // read-only inputs) at the first record size while the first candidate
  // settles the record size; one that settles elsewhere is encoded again.
  const bool parallel =
      orderings.size() > 1 && options.threads != 1 && std::thread::hardware_concurrency() > 1;
  const uint32_t first_record_bytes = record_bytes;
  std::vector<EncodeReport> candidate_reports(orderings.size());
  auto report_of = [&](size_t i) { return report ? &candidate_reports[i] : nullptr; };
  std::vector<std::future<Result<EncodedStream>>> early;  // destroyed (joined) before what it reads
  if (parallel) {
    for (size_t i = 1; i < orderings.size(); ++i)
      early.push_back(
          std::async(std::launch::async, encode_candidate, i, first_record_bytes, report_of(i)));
  }
  EncodedStream chosen;
  for (int attempt = 0;; ++attempt) {
    auto encoded = encode_candidate(0, record_bytes, report);
    if (!encoded) return tl::unexpected(encoded.error());
    chosen = std::move(*encoded);
    if (!automatic || granular(chosen) || attempt >= 3 || record_bytes <= 16) break;
    record_bytes = std::max<uint32_t>(16, static_cast<uint32_t>(record_bytes * 0.75));
  }
  if (orderings.size() < 2) return std::move(chosen.bytes);
  std::vector<EncodedStream> candidates(orderings.size());
  for (size_t i = 1; i < orderings.size(); ++i) {
    auto candidate =
        parallel ? early[i - 1].get() : encode_candidate(i, record_bytes, report_of(i));
    if (parallel && record_bytes != first_record_bytes)
      candidate = encode_candidate(i, record_bytes, report_of(i));
    if (!candidate) return tl::unexpected(candidate.error());
    candidates[i] = std::move(*candidate);
  }

  // Rate-distortion by measurement (rd_measure.h): the other orderings at
  // the same record size, judged at the same byte budgets by the surface
  // distance of their decoded prefixes to the original (in parallel too).
  Mesh reference;  // the quantized original, from the positions already quantized
  reference.triangles = mesh.triangles;
  reference.positions.reserve(q.size());
  for (const Vec3i& p : q) reference.positions.push_back(grid->dequantize(p));
  auto measure = RdMeasure::prepare(reference);
  if (!measure) return tl::unexpected(measure.error());
  const uint64_t reference_bytes = chosen.bytes.size();
  auto score_of = [&](const std::vector<uint8_t>& bytes) -> Result<double> {
    auto curve = measure->curve(bytes, reference_bytes);
    if (!curve) return tl::unexpected(curve.error());
    return RdMeasure::score(*curve);
  };
  std::vector<std::future<Result<double>>> other_scores;  // joined before `measure` goes
  for (size_t i = 1; i < orderings.size(); ++i) {
    other_scores.push_back(std::async(parallel ? std::launch::async : std::launch::deferred,
                                      score_of, std::cref(candidates[i].bytes)));
  }
  auto chosen_score = score_of(chosen.bytes);
  if (!chosen_score) return tl::unexpected(chosen_score.error());
  for (size_t i = 1; i < orderings.size(); ++i) {
    auto score = other_scores[i - 1].get();
    if (!score) return tl::unexpected(score.error());
    if (automatic && granular(chosen) && !granular(candidates[i])) continue;
    if (*score < *chosen_score) {
      chosen_score = *score;
      chosen = std::move(candidates[i]);
      if (report) *report = std::move(candidate_reports[i]);
    }
  }
  return std::move(chosen.bytes);
}

}  // namespace meshstream

// The structure record reader: see structure_record_reader.h, and
// refinement_codec.h for the layout.
#include "common/codec/structure_record_reader.h"

#include <string>
#include <vector>

#include "common/codec/byte_io.h"
#include "common/codec/insertion_prediction.h"
#include "common/codec/patch_geometry.h"
#include "common/codec/plane_record.h"
#include "common/codec/record_header.h"
#include "common/codec/structure_contexts.h"
#include "common/codec/structure_models.h"

namespace meshstream {

namespace {

Status bad(const std::string& what) { return make_error(ErrorCode::kCorrupt, what); }

// Format 3's decoder side of the start: the candidates are scored first
// (their number and the lead of the best score are the rank's context),
// then the rank is read (nothing for a single candidate) and its start
// picked, the best by a linear scan. kNone when the rank is out of range.
template <class DecodeRank>
MESHSTREAM_DECODE_INLINE uint32_t score_then_select_patch_start(
    const EditableMesh& mesh, uint32_t apex, const std::vector<uint32_t>& star_ring,
    const std::vector<uint8_t>& used, uint32_t k, StartScratch& scratch, DecodeRank&& decode_rank,
    uint32_t& rank) {
  scratch.prepare(static_cast<uint32_t>(used.size()));
  const size_t n = score_patch_starts_raw(mesh, apex, star_ring, used, k, scratch);
  const uint32_t* starts = scratch.start;
  if (n == 0) {
    rank = 0;
    return kNone;
  }
  // The best (first of the largest: ties keep the smaller r, as the stable
  // sort orders them) and the second best score.
  size_t best = 0;
  int64_t second = -1;
  for (size_t i = 1; i < n; ++i) {
    const int64_t sc = scratch.score[i];
    if (sc > scratch.score[best]) {
      second = scratch.score[best];
      best = i;
    } else if (sc > second) {
      second = sc;
    }
  }
  rank = n > 1 ? decode_rank(start_rank_context(k, n, scratch.score[best], second)) : 0;
  if (rank >= n) return kNone;
  if (rank == 0) return starts[best];
  sort_patch_starts(scratch.start, n, scratch.score);
  return scratch.start[rank];
}

}  // namespace

// The range-coded block of a structure record, after its header: one
// instance per model family (kFastStartModels: format 3's models and
// contexts, RefinementFormatInfo::fast_start_structure_models), so the
// decoding loop, inlined whole, holds no per-symbol format branches.
// One function of 160 lines on purpose: its phases per walk step are the
// next walk vertex, its patch count, its star (prefetched), each patch
// (valence, start rank, open edge, residual), then applying them. As
// forced-inline functions (next_walk_vertex, decode_patch_count,
// load_star, decode_patch) the same code measured 2.9-3.7 % more decoder
// instructions (callgrind, dragon_res2: 458.7 M -> 471.9 M with decode_patch
// returning a bool, 475.5 M with a Status), so the phases stay marked by
// the comments inside.
template <bool kFastStartModels>
Status decode_structure_block(RefinementState& state, std::span<const uint8_t> block,
                              const RecordHeader& h, uint32_t expected_vertices,
                              uint32_t expected_faces, AppliedRecord& applied) {
  RangeDecoder dec(block);
  RefinementModels& m = state.models;
  EditableMesh& mesh = state.mesh;
  std::vector<uint32_t> star_ring, star_corners;
  std::vector<ResolvedPatch> patches;
  std::vector<VertexGeometry> positions;
  std::vector<uint32_t> opens, open_edges, candidates;
  std::vector<uint8_t> used_faces;
  StartScratch start_scratch;
  uint32_t inserted = 0;
  // On error the state is left half-applied: the caller discards it (the
  // decoder's output mesh is only updated after a record succeeds).
  auto fail = [&](const std::string& what) -> Status { return bad(what); };

  for (uint32_t step = 0; step < h.walk_steps; ++step) {
    while (state.cursor != kNone && state.vertices[state.cursor].layer == state.layer) {
      state.cursor = state.vertices[state.cursor].next;
    }
    if (state.cursor == kNone) return fail("refinement walk runs past the last vertex");
    const uint32_t u = state.cursor;
    state.cursor = state.vertices[u].next;
    // The order list jumps around memory: start loading what the next two
    // walk vertices need while this one is decoded (the entry and start
    // corner of the one after next, the first star face of the next, whose
    // entry and corner were asked for one step ago).
    if (state.cursor != kNone) {
      const uint32_t after = state.vertices[state.cursor].next;
      if (after != kNone) {
        __builtin_prefetch(&state.vertices[after]);
        mesh.prefetch_vertex(after);
      }
      mesh.prefetch_first_face(state.cursor);
    }
    const uint32_t free_faces = free_face_count(state, u);
    uint32_t count = 0;
    if (free_faces > 0) {
      if constexpr (kFastStartModels) {
        count = fast_start_count_model(state, u, free_faces).decode(dec);
        if (count == 3) count += m.fast_start_patch_count_extra.decode(dec);
      } else {
        count = m.patch_count[count_context(state, u, free_faces)].decode(dec);
        if (count == 3) count += m.patch_count_extra.decode(dec);
      }
    }
    state.last_count = count;
    if (count == 0) continue;
    mesh.star(u, star_ring, star_corners);
    // Positions (patch scores), start corners (insert_vertex) and entries
    // (apply_patch) of the ring are read after some bits are decoded: ask
    // for them now.
    for (uint32_t r : star_ring) {
      mesh.prefetch_vertex(r);
      __builtin_prefetch(&state.vertices[r]);
    }
    // So are the faces beyond the star's outer edges (insert_vertex links
    // the new faces to them), which are also in the stars of the ring
    // vertices the walk visits next. Their corners sit next to what star()
    // just read, so asking costs no wait.
    for (uint32_t c : star_corners) {
      const uint32_t o = mesh.opposite(c);
      if (o != kNone) mesh.prefetch_corner(o);
    }
    const uint32_t ring_size = static_cast<uint32_t>(star_ring.size());
    const uint32_t faces = static_cast<uint32_t>(star_corners.size());
    if (mark_taken_faces(state, star_ring, faces, used_faces) != free_faces) {
      // Both counts come from the state apply_patch keeps, whatever the
      // input: a mismatch is a bug here, not a bad stream.
      return make_error(ErrorCode::kInternal,
                        "free face counts disagree at vertex " + std::to_string(u));
    }
    if (count > free_faces || inserted + count > h.insertions) {
      return fail("vertex " + std::to_string(u) + " claims " + std::to_string(count) +
                  " patches, more than it or the record holds");
    }
    // Grown, never shrunk: a patch's ring and corner vectors keep their
    // storage from one walk vertex to the next (resizing down and up again
    // freed and reallocated them). Only the first `count` entries are used.
    if (patches.size() < count) {
      patches.resize(count);
      positions.resize(count);
      opens.resize(count);
    }
    uint32_t free_left = free_faces;
    for (uint32_t i = 0; i < count; ++i) {
      uint32_t k;
      if constexpr (kFastStartModels) {
        k = fast_start_valence_model(state, ring_size, free_left).decode(dec) + 3;
      } else {
        k = m.valence[std::min(ring_size, 12u)].decode(dec) + 3;
      }
      uint32_t rank = 0, r = kNone;
      if constexpr (!kFastStartModels) {
        // The rank depends only on k, so it is read first: the decoder then
        // needs only the start of that rank, most often the best one (a
        // linear scan), not the whole ordered list the encoder searches.
        rank = decode_start_rank_inline(m, dec, k);
        r = select_patch_start(mesh, u, star_ring, used_faces, k, rank, candidates);
      } else {
        r = score_then_select_patch_start(
            mesh, u, star_ring, used_faces, k, start_scratch,
            [&](uint32_t context) __attribute__((always_inline)) {
              return decode_start_rank_in_context_inline(m, dec, context);
            },
            rank);
      }
      free_left = free_left >= k - 2 ? free_left - (k - 2) : 0;
      if (r == kNone) {
        return fail("patch " + std::to_string(i) + " at vertex " + std::to_string(u) +
                    " (valence " + std::to_string(k) + ", start rank " + std::to_string(rank) +
                    ") does not fit its star of " + std::to_string(faces) + " faces");
      }
      if (!resolve_patch(mesh, u, star_ring, star_corners, r, k, patches[i])) {
        return fail("patch " + std::to_string(i) + " at vertex " + std::to_string(u) +
                    " does not fit");
      }
      for (uint32_t j = 0, f = r; j + 2 < k; ++j, f = f + 1 == faces ? 0 : f + 1) used_faces[f] = 1;
      opens[i] = kNone;
      patch_boundary_edges(mesh, patches[i], open_edges);
      if (!open_edges.empty()) {
        uint32_t choice;
        if constexpr (kFastStartModels) {
          choice = m.fast_start_open_edge.decode(dec);
        } else {
          choice = m.open_edge.decode(dec);
        }
        if (choice > open_edges.size()) {
          return fail("patch at vertex " + std::to_string(u) + " re-enters boundary edge " +
                      std::to_string(choice) + " of " + std::to_string(open_edges.size()));
        }
        if (choice > 0) opens[i] = open_edges[choice - 1];
      }
      InsertionPrediction prediction;
      predict_insertion_inline(state, patches[i].ring, static_cast<int>(h.min_shift), prediction);
      if (!decode_residual_inline(m, dec, prediction.ctx, prediction.predicted, prediction.shift,
                                  state.max_coordinate, positions[i])) {
        return fail("vertex position outside the quantization grid at vertex " + std::to_string(u));
      }
    }
    if (dec.exhausted_badly()) return fail("refinement record data ends early");
    std::vector<uint32_t>* touched = applied.record_changes ? &applied.touched_faces : nullptr;
    for (uint32_t i = 0; i < count; ++i) {
      const uint32_t v = apply_patch(state, patches[i], opens[i], positions[i], touched);
      if (touched) applied.added_vertices.push_back(v);
    }
    inserted += count;
  }
  if (inserted != h.insertions) {
    return fail("refinement record holds " + std::to_string(inserted) +
                " insertions, its header says " + std::to_string(h.insertions));
  }
  if (dec.exhausted_badly()) return fail("refinement record data ends early");
  if (mesh.vertex_count() != expected_vertices || mesh.face_slot_count() != expected_faces) {
    return fail("refinement record yields " + std::to_string(mesh.vertex_count()) +
                " vertices and " + std::to_string(mesh.face_slot_count()) +
                " faces, the index says " + std::to_string(expected_vertices) + " and " +
                std::to_string(expected_faces));
  }
  return {};
}

Status apply_refinement_record(RefinementState& state, std::span<const uint8_t> payload,
                               uint32_t expected_vertices, uint32_t expected_faces,
                               AppliedRecord& applied) {
  applied.added_vertices.clear();
  applied.touched_faces.clear();
  applied.moved_vertices.clear();
  if (payload.empty()) return bad("empty refinement record");
  const uint8_t flags = payload[0];
  if (flags == kRecordPlane) {
    if (auto st = apply_plane_record(state, payload, applied); !st) return st;
    if (state.mesh.vertex_count() != expected_vertices ||
        state.mesh.face_slot_count() != expected_faces) {
      return bad("plane record where the index says the mesh grows");
    }
    return {};
  }
  if (flags > 1) return bad("unknown refinement record flags " + std::to_string(flags));
  size_t pos = 1;
  RecordHeader h;
  h.starts_layer = flags & 1;
  if (!get_varint(payload, pos, h.walk_steps) || !get_varint(payload, pos, h.insertions)) {
    return bad("refinement record header is cut short or malformed");
  }
  if (state.format.embedded) {
    if (!get_varint(payload, pos, h.min_shift))
      return bad("refinement record header is cut short or malformed");
    if (h.min_shift > kMaxShift)
      return bad("refinement record shift " + std::to_string(h.min_shift) + " too large");
  }
  const uint32_t vertices_before = state.mesh.vertex_count();
  // Each insertion needs at least one walk step's worth of bits; refuse
  // counts that could not fit before allocating for them.
  if (h.walk_steps > vertices_before) {
    return bad("refinement record walks " + std::to_string(h.walk_steps) +
               " vertices but the mesh has " + std::to_string(vertices_before));
  }
  if (h.insertions > 64 * static_cast<uint64_t>(payload.size())) {
    return bad("refinement record claims " + std::to_string(h.insertions) +
               " insertions, more than its size allows");
  }
  if (h.starts_layer) {
    state.layer += 1;
    state.cursor = state.order_head;
    state.last_count = 0;
  } else if (state.layer == 0) {
    return bad("first refinement record does not start a layer");
  }

  const std::span<const uint8_t> block = payload.subspan(pos);
  return state.format.fast_start_structure_models
             ? decode_structure_block<true>(state, block, h, expected_vertices, expected_faces,
                                            applied)
             : decode_structure_block<false>(state, block, h, expected_vertices, expected_faces,
                                             applied);
}
}  // namespace meshstream

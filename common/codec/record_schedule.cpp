// Record scheduling: see record_schedule.h.
#include "common/codec/record_schedule.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "common/codec/base_choice.h"
#include "common/codec/container.h"
#include "common/codec/distortion_estimate.h"
#include "common/codec/plane_groups.h"
#include "common/codec/refinement_codec.h"
#include "common/codec/structure_writer.h"

namespace meshstream {

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

  ChosenBase base = choose_base(dec, coarse, bits - base_shift, options.allow_draco_base);
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

  std::vector<WrittenRecord> records;
  WrittenRecord base_record;
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
      WrittenRecord f;
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
    WrittenRecord f;
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
  for (WrittenRecord& r : records) {
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

}  // namespace meshstream

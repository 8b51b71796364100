// Record scheduling: see record_schedule.h.
#include "common/codec/record_schedule.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <string>
#include <utility>

#include "common/codec/base_choice.h"
#include "common/codec/container.h"
#include "common/codec/distortion_estimate.h"
#include "common/codec/plane_groups.h"
#include "common/codec/refinement_codec.h"
#include "common/codec/structure_writer.h"

namespace meshstream {
namespace {

// Low bits of the base positions left to plane records: automatic is an
// 8-bit base; none for a stream without bit planes.
int effective_base_shift(const EncodeOptions& options, int bits) {
  if (!options.embedded) return 0;
  return std::clamp(options.base_shift.value_or(bits - 8), 0, std::min(kMaxBaseShift, bits - 1));
}

// The grid points with their low `shift` bits dropped: what the base coder
// sends.
std::vector<Vec3i> coarse_positions(const std::vector<Vec3i>& q, int shift) {
  std::vector<Vec3i> coarse(q.size());
  for (size_t v = 0; v < q.size(); ++v)
    for (int a = 0; a < 3; ++a) coarse[v][a] = q[v][a] >> shift;
  return coarse;
}

// Encoder-side truth of the base vertices, in decoder ids: their input ids
// (so their true positions), and star areas as the weights. `whole`: room
// for every vertex of the mesh at once (a prefix encode grows as it goes).
EncoderTruth base_truth(const Mesh& mesh, const std::vector<Vec3i>& q,
                        const std::vector<Vec3f>& input_normals, const ChosenBase& base,
                        const RefinementState& state, const TriangleBvh* surface, bool whole) {
  const uint32_t base_n = static_cast<uint32_t>(base.decoded.positions.size());
  EncoderTruth truth;
  truth.input_position = q;
  truth.input_normal = input_normals;
  truth.surface = surface;
  // Every vertex gets an entry as the records restore it: room for all at
  // once for a whole stream (growth by doubling kept up to twice this, and
  // a copy while it grew); a prefix grows them as far as it goes.
  const uint32_t n = whole ? mesh.vertex_count() : 0;
  truth.input_of.reserve(n);
  truth.weight.reserve(n);
  if (surface) truth.cached.reserve(n);
  std::vector<double> star_area(base_n, 0.0);
  for (const Triangle& f : base.decoded.faces) {
    const double a = ring_area(state.mesh.positions(), {f[0], f[1], f[2]});
    for (uint32_t v : f) star_area[v] += a;
  }
  for (uint32_t d = 0; d < base_n; ++d) {
    const uint32_t in = base.to_input[d];
    truth.input_of.push_back(in);
    truth.weight.push_back(star_area[d] * std::sqrt(double(base_n)));
  }
  return truth;
}

// Chooses and writes every record after the base (see record_schedule.h).
class RecordScheduler {
 public:
  struct Inputs {
    const QuantGrid& grid;
    const DecimationResult& dec;
    const EncodeOptions& options;
    uint32_t record_bytes;
    double plane_calibration;
    EncodeReport* report;  // optional
    // Optional: called after each record with the share of the mesh's
    // vertices restored so far (0..1).
    const std::function<void(double)>& progress;
    uint32_t total_vertices;
    uint64_t stop_after_bytes = 0;        // encode_once's: 0 = the whole mesh
    DecimationResult* release = nullptr;  // encode_once's: &dec, or none
  };

  // `state` is the decoder's state after the base, `truth` the encoder's
  // knowledge of it; `to_decoder` maps input ids of the base vertices to
  // decoder ids (kNone elsewhere). `records` receives the records.
  RecordScheduler(const Inputs& in, RefinementFormatInfo format, RefinementState& state,
                  EncoderTruth& truth, std::vector<uint32_t> to_decoder,
                  std::vector<WrittenRecord>& records)
      : in_(in),
        state_(state),
        truth_(truth),
        to_decoder_(std::move(to_decoder)),
        records_(records),
        group_vertices_(std::max<uint32_t>(16, in.record_bytes * 8 / 4)),
        writer_(state, truth, format, in.report ? &in.report->structure_bits : nullptr),
        next_layer_(in.dec.layers.size()) {
    std::fill(std::begin(plane_bits_per_step_), std::end(plane_bits_per_step_), 3.0);
  }

  // FNV-1a of the positions the decoder shows now (EncodedRecord).
  uint64_t hash_state() const {
    std::vector<Vec3f> p(state_.mesh.vertex_count());
    for (uint32_t v = 0; v < p.size(); ++v) p[v] = in_.grid.dequantize(state_.mesh.positions()[v]);
    return position_hash(p);
  }

  // Until every layer is put back and every position exact: the next
  // structure record while its drop per byte is at least the best plane
  // group's, else that group's next plane.
  Status run() {
    add_plane_groups(0, state_.mesh.vertex_count());
    while (!prefix_done()) {
      const bool structure_left = writer_.layer_open() || next_layer_ > 0;
      const double n_now = state_.mesh.vertex_count();
      double best_slope = -std::numeric_limits<double>::infinity();
      const int best = best_plane_group(n_now, best_slope);
      if (structure_left && (best < 0 || structure_slope_ >= best_slope)) {
        if (auto st = write_structure_record(); !st) return st;
        if (in_.progress) in_.progress(n_now / std::max(1u, in_.total_vertices));
        continue;
      }
      if (best < 0) break;
      write_plane_step(groups_[best], n_now);
    }
    return {};
  }

  // True once a prefix encode has its bytes (Inputs::stop_after_bytes);
  // trailers counted, as the container sizes records.
  bool prefix_done() const {
    return in_.stop_after_bytes > 0 && refinement_bytes_ >= in_.stop_after_bytes;
  }

  // The input -> decoder vertex map once the replay is done.
  std::vector<uint32_t> take_to_decoder() { return std::move(to_decoder_); }

 private:
  // Plane groups: about a record's worth of plane bits each. New ids join
  // the last group while it has not been sent and has room.
  void add_plane_groups(uint32_t first, uint32_t count) {
    while (count > 0) {
      if (!groups_.empty() && !groups_.back().started &&
          groups_.back().first + groups_.back().count == first &&
          groups_.back().count < group_vertices_) {
        const uint32_t take = std::min(count, group_vertices_ - groups_.back().count);
        groups_.back().count += take;
        first += take;
        count -= take;
        evaluate_group(state_, truth_, groups_.back());
        continue;
      }
      PlaneGroup g;
      g.first = first;
      g.count = std::min(count, group_vertices_);
      first += g.count;
      count -= g.count;
      evaluate_group(state_, truth_, g);
      groups_.push_back(g);
    }
  }

  // The plane group with the best estimated drop per byte (-1 when no
  // group has a plane left); `best_slope` receives that drop per byte.
  int best_plane_group(double n_now, double& best_slope) const {
    int best = -1;
    for (size_t i = 0; i < groups_.size(); ++i) {
      const PlaneGroup& g = groups_[i];
      if (g.pending == 0) continue;
      const double bytes = g.pending * plane_bits_per_step_[g.top_plane] / 8.0 + kRecordOverhead;
      // The calibration corrects the proxy's balance of plane steps against
      // structure; measured per mesh (see EncodeOptions::plane_calibration).
      double slope = in_.plane_calibration * g.scaled_drop / std::sqrt(n_now) / bytes;
      if (!std::isfinite(slope)) slope = 0;
      if (best < 0 || slope > best_slope) {
        best_slope = slope;
        best = static_cast<int>(i);
      }
    }
    return best;
  }

  // The next structure record, opening the next layer (the last decimated
  // first) when the current one is done.
  Status write_structure_record() {
    if (!writer_.layer_open()) {
      // The layer written last is done with (the writer holds only the
      // open one): freed when this is the decimation's last encode.
      if (in_.release && next_layer_ < in_.release->layers.size())
        in_.release->layers[next_layer_] = DecimationLayer{};
      --next_layer_;
      writer_.start_layer(in_.dec.layers[next_layer_], to_decoder_);
    }
    const uint32_t first_new = state_.mesh.vertex_count();
    WrittenRecord f;
    inserted_.clear();
    const int min_shift = in_.options.embedded ? in_.options.insertion_shift : 0;
    if (auto st = writer_.write_record(in_.record_bytes, min_shift, f, inserted_); !st) return st;
    for (const auto& [input, decoded] : inserted_) to_decoder_[input] = decoded;
    structure_slope_ =
        std::isfinite(f.drop) ? std::max(f.drop, 0.0) / double(f.payload.size()) : 0.0;
    if (in_.report) {
      in_.report->structure_bytes += f.payload.size();
      in_.report->records.push_back(
          {false, f.vertices, uint32_t(f.payload.size()), hash_state(), f.drop});
    }
    refinement_bytes_ += f.payload.size() + 4;
    records_.push_back(std::move(f));
    add_plane_groups(first_new, state_.mesh.vertex_count() - first_new);
    return {};
  }

  // One plane step of group `g`; learns the plane's coded bits per step.
  void write_plane_step(PlaneGroup& g, double n_now) {
    EncodeReport* report = in_.report;
    WrittenRecord f;
    f.plane = true;
    const uint32_t steps = g.pending;
    const int plane = g.top_plane;
    uint64_t sign_bits = 0;  // for the raw comparison: signs sent on becoming significant
    // The group's true residuals (the truth keeps positions, not residuals).
    residuals_.clear();
    for (uint32_t v = g.first; v < g.first + g.count; ++v) {
      const VertexGeometry& geo = state_.geometry[v];
      const Vec3i residual = truth_.position(v) - geo.anchor;
      residuals_.push_back(residual);
      if (geo.shift == 0 || geo.normal_axis == kBaseVertexAxis) continue;
      for (int a = 0; a < 3; ++a)
        sign_bits += geo.mag[a] == 0 && ((uint32_t(std::abs(residual[a])) >> (geo.shift - 1)) & 1u);
    }
    if (report)
      report->plane_bytes_plain +=
          plain_plane_bytes(state_, truth_, g.first, g.count, plain_models_);
    f.payload = write_plane_record(state_, g.first, g.count, residuals_);
    f.vertices = state_.mesh.vertex_count();
    f.faces = state_.mesh.face_slot_count();
    f.drop = g.scaled_drop / std::sqrt(n_now);
    const size_t head = 1 + (g.first >= 128 ? 3 : 1) + (g.count >= 128 ? 2 : 1);
    const double coded_bits =
        8.0 * (double(f.payload.size()) - double(std::min(head, f.payload.size())));
    plane_bits_per_step_[plane] =
        0.7 * plane_bits_per_step_[plane] + 0.3 * coded_bits / std::max(1u, steps);
    g.started = true;
    if (report) {
      report->plane_bits_raw += 3ull * steps + sign_bits;
      report->plane_bytes_coded += f.payload.size() - std::min(head, f.payload.size());
      report->records.push_back(
          {true, f.vertices, uint32_t(f.payload.size()), hash_state(), f.drop});
    }
    evaluate_group(state_, truth_, g);
    refinement_bytes_ += f.payload.size() + 4;
    records_.push_back(std::move(f));
  }

  static constexpr double kRecordOverhead = 6.0;  // header and range coder flush, bytes

  const Inputs& in_;
  RefinementState& state_;
  EncoderTruth& truth_;
  std::vector<uint32_t> to_decoder_;  // input id -> decoder id, growing with the replay
  std::vector<WrittenRecord>& records_;
  const uint32_t group_vertices_;
  std::vector<PlaneGroup> groups_;
  StructureWriter writer_;
  size_t next_layer_;  // layers restore from the last one
  double structure_slope_ = std::numeric_limits<double>::infinity();
  // Coded bits per plane step, by plane, learned from the records written.
  double plane_bits_per_step_[kMaxShift + 1];
  std::vector<std::pair<uint32_t, uint32_t>> inserted_;
  std::vector<Vec3i> residuals_;  // write_plane_step's, reused
  PlainPlaneModels plain_models_;
  uint64_t refinement_bytes_ = 0;  // records after the base, trailers counted
};

// The container (version 3: compact index, each record's CRC-32 in a
// trailer) around `records`, and the sizes the granularity check needs.
Result<EncodedStream> write_stream(const StreamHeader& header, std::vector<WrittenRecord> records) {
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
    return make_error(ErrorCode::kInternal,
                      "encoder: the records rebuild " + std::to_string(counts.back().vertices) +
                          " vertices and " + std::to_string(counts.back().faces) + " faces, not " +
                          std::to_string(header.vertex_count) + " and " +
                          std::to_string(header.face_count));
  }
  auto written = write_container(header, payloads, counts);
  if (!written) return tl::unexpected(written.error());
  // Record sizes as the index has them (with the trailer): the granularity
  // bound is about what a client receives.
  for (size_t i = 1; i < written->records.size(); ++i) {
    out.largest_refinement = std::max<size_t>(out.largest_refinement, written->records[i].size);
  }
  out.records = written->records.size();
  out.payload_offset = written->payload_offset;
  out.bytes = std::move(written->bytes);
  return out;
}

}  // namespace

Result<EncodedStream> encode_once(const Mesh& mesh, const QuantGrid& grid,
                                  const std::vector<Vec3i>& q,
                                  const std::vector<Vec3f>& input_normals,
                                  const DecimationResult& dec, const EncodeOptions& options,
                                  uint32_t record_bytes, double plane_calibration,
                                  EncodeReport* report, const TriangleBvh* surface,
                                  const std::function<void(double)>& progress,
                                  uint64_t stop_after_bytes, DecimationResult* release) {
  // The base: coarse positions, the smaller coder, the decoder's state.
  const int bits = grid.bits;
  // check_options let only writable formats through.
  const RefinementFormatInfo format =
      *RefinementFormatInfo::from_header_byte(uint8_t(options.refinement_format));
  const int base_shift = effective_base_shift(options, bits);
  const ChosenBase base = choose_base(dec, coarse_positions(q, base_shift), bits - base_shift,
                                      options.allow_draco_base);
  auto state = RefinementState::from_coarse_base(base.decoded.positions, base.decoded.faces, bits,
                                                 base_shift);
  if (!state) return tl::unexpected(state.error());
  state->format = format;
  // The replay of a whole stream ends at the whole mesh: its arrays sized
  // for it once (a prefix grows them as far as it goes).
  if (stop_after_bytes == 0) {
    state->mesh.reserve(mesh.vertex_count(), mesh.face_count());
    state->vertices.reserve(mesh.vertex_count());
    state->vertex_layer.reserve(mesh.vertex_count());
    state->vertex_shift.reserve(mesh.vertex_count());
    state->geometry.reserve(mesh.vertex_count());
  }
  const uint32_t base_n = static_cast<uint32_t>(base.decoded.positions.size());
  const uint32_t base_faces = static_cast<uint32_t>(base.decoded.faces.size());

  EncoderTruth truth =
      base_truth(mesh, q, input_normals, base, *state, surface, stop_after_bytes == 0);
  std::vector<uint32_t> to_decoder(mesh.vertex_count(), kNone);
  for (uint32_t d = 0; d < base.to_input.size(); ++d) to_decoder[base.to_input[d]] = d;

  std::vector<WrittenRecord> records;
  WrittenRecord base_record;
  base_record.payload = base.bytes;
  base_record.vertices = base_n;
  base_record.faces = base_faces;
  records.push_back(std::move(base_record));

  // The records after the base.
  const RecordScheduler::Inputs inputs{grid,
                                       dec,
                                       options,
                                       record_bytes,
                                       plane_calibration,
                                       report,
                                       progress,
                                       mesh.vertex_count(),
                                       stop_after_bytes,
                                       release};
  RecordScheduler scheduler(inputs, format, *state, truth, std::move(to_decoder), records);
  if (report) {
    report->records.clear();
    report->base_shift = static_cast<uint32_t>(base_shift);
    report->ordering = {plane_calibration, surface ? DistortionEstimate::kSurfaceDistance
                                                   : DistortionEstimate::kDisplacement};
    report->plane_bits_raw = report->plane_bytes_coded = report->plane_bytes_plain =
        report->structure_bytes = 0;
    report->structure_bits = StructureBits{};
    report->records.push_back(
        {false, base_n, uint32_t(base.bytes.size()), scheduler.hash_state(), 0});
  }
  if (auto st = scheduler.run(); !st) return tl::unexpected(st.error());

  StreamHeader header;
  header.vertex_count = mesh.vertex_count();
  header.face_count = mesh.face_count();
  if (stop_after_bytes > 0) {  // a prefix: the mesh its last record shows
    header.vertex_count = records.back().vertices;
    header.face_count = records.back().faces;
  }
  header.base_vertex_count = base_n;
  header.base_face_count = base_faces;
  header.bounds = grid.bounds;
  header.quant_bits = static_cast<uint8_t>(bits);
  header.base_coder = base.coder;
  header.structure_coder = kStructureCoderRange;
  header.geometry_coder = kGeometryCoderEmbedded;
  header.layer_count = static_cast<uint32_t>(dec.layers.size());
  header.extra = {format.header_byte(), static_cast<uint8_t>(base_shift)};
  auto out = write_stream(header, std::move(records));
  if (out) out->to_decoder = scheduler.take_to_decoder();
  return out;
}

}  // namespace meshstream

// Encoder entry point: option checks, quantization, decimation, and the
// search over record orderings and record sizes; each candidate stream is
// written by the record schedule (record_schedule.h). See encoder.h and
// docs/hcs-format.md.
#include "common/codec/encoder.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <future>
#include <string>
#include <thread>

#include "common/codec/asa_guidance.h"
#include "common/codec/attribute_codec.h"
#include "common/codec/decimate.h"
#include "common/codec/distortion_estimate.h"
#include "common/codec/editable_mesh.h"
#include "common/codec/locality_cells.h"
#include "common/codec/quantize.h"
#include "common/codec/rd_measure.h"
#include "common/codec/record_schedule.h"
#include "common/codec/texture_stream.h"
#include "common/metrics/bvh.h"

namespace meshstream {

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

namespace {

Status check_options(const EncodeOptions& options) {
  if (options.refinement_format != RefinementFormat::kEmbedded &&
      options.refinement_format != RefinementFormat::kEmbeddedFastStart) {
    return make_error(ErrorCode::kInvalidArgument,
                      "refinement format " + std::to_string(int(options.refinement_format)) +
                          " cannot be written (2 or 3)");
  }
  if (options.distortion_estimate != DistortionEstimate::kAutomatic &&
      options.distortion_estimate != DistortionEstimate::kDisplacement &&
      options.distortion_estimate != DistortionEstimate::kSurfaceDistance) {
    return make_error(ErrorCode::kInvalidArgument,
                      "distortion estimate " + std::to_string(int(options.distortion_estimate)) +
                          " is not 0 (automatic), 1 (displacement) or 2 (surface distance)");
  }
  if (options.locality_cell_vertices != 0 &&
      (options.locality_cell_vertices < kMinLocalityCellVertices ||
       options.locality_cell_vertices > kMaxLocalityCellVertices)) {
    return make_error(ErrorCode::kInvalidArgument,
                      "locality cell vertices " + std::to_string(options.locality_cell_vertices) +
                          " is not 0 (off) or " + std::to_string(kMinLocalityCellVertices) + ".." +
                          std::to_string(kMaxLocalityCellVertices));
  }
  if (!(options.locality_unlocked_share >= 0 && options.locality_unlocked_share <= 1)) {
    return make_error(ErrorCode::kInvalidArgument,
                      "locality unlocked share " + std::to_string(options.locality_unlocked_share) +
                          " is not in 0..1");
  }
  if (!(options.layer_candidate_share > 0 && options.layer_candidate_share <= 1)) {
    return make_error(ErrorCode::kInvalidArgument,
                      "layer candidate share " + std::to_string(options.layer_candidate_share) +
                          " is not in (0, 1]");
  }
  if (options.base_shift && (*options.base_shift < 0 || *options.base_shift > kMaxBaseShift)) {
    return make_error(ErrorCode::kInvalidArgument,
                      "base shift " + std::to_string(*options.base_shift) + " is not 0.." +
                          std::to_string(kMaxBaseShift));
  }
  return {};
}

// The orderings to encode: every candidate that agrees with the fixed
// options, or the one the options fix.
std::vector<RecordOrdering> orderings_to_try(const EncodeOptions& options) {
  const bool measured = options.embedded && options.plane_calibration <= 0;
  std::vector<RecordOrdering> orderings;
  if (measured) {
    for (const RecordOrdering& c : kOrderingCandidates)
      if (options.distortion_estimate == DistortionEstimate::kAutomatic ||
          options.distortion_estimate == c.distortion_estimate)
        orderings.push_back(c);
  } else {
    orderings.push_back({options.plane_calibration,
                         options.distortion_estimate == DistortionEstimate::kSurfaceDistance
                             ? DistortionEstimate::kSurfaceDistance
                             : DistortionEstimate::kDisplacement});
  }
  return orderings;
}

// The original in grid units, for the surface-distance estimate.
Mesh grid_mesh(const Mesh& mesh, const std::vector<Vec3i>& q) {
  Mesh grid;
  grid.triangles = mesh.triangles;
  grid.positions.reserve(q.size());
  for (const Vec3i& p : q) grid.positions.push_back(vec3_cast<float>(p));
  return grid;
}
TriangleBvh grid_surface(const Mesh& mesh, const std::vector<Vec3i>& q, unsigned threads) {
  return TriangleBvh::build(grid_mesh(mesh, q), threads);
}
// `surface` (a hierarchy over the mesh's triangles in any positions)
// moved to the grid units again: the tree over the original is built once
// per encode and refitted for each use (the same distances as a build).
Status to_grid_units(TriangleBvh& surface, const Mesh& mesh, const std::vector<Vec3i>& q) {
  return surface.refit(grid_mesh(mesh, q));
}

// Granularity (docs/hcs-format.md): at least min(n / 50, 200) record
// boundaries and no refinement record above 2 % of the stream. Automatic
// record sizes start from an estimate of the stream (about 20 bits per
// vertex) and shrink when the result misses either bound.
struct RecordSizing {
  bool automatic = true;
  size_t wanted_records = 0;  // the base included
  uint32_t first_bytes = 0;   // the record size tried first

  RecordSizing(uint32_t n, const EncodeOptions& options) {
    automatic = options.record_bytes == 0;
    const double estimate = 20.0 * n / 8.0;
    // Plane records add to the count; each record costs an index entry
    // (about 1.5 bytes, container 3) and a 4-byte CRC trailer.
    const double wanted = std::max(50.0, 1.1 * std::min<double>(n / 50, 200));
    wanted_records = std::min<size_t>(n / 50, 200) + 1;
    first_bytes = automatic ? static_cast<uint32_t>(std::clamp(estimate / wanted, 32.0, 8192.0))
                            : std::max<uint32_t>(options.record_bytes, 16);
  }

  bool granular(const EncodedStream& e) const {
    return e.records >= wanted_records &&
           double(e.largest_refinement) <= 0.02 * double(e.bytes.size());
  }
};

// Progress of one encode (encode_progress.h): stages, each a span of the
// whole, and shares within them, reported from the calling thread only,
// never decreasing, at most about every 0.2 % (a few hundred calls).
class ProgressTracker {
 public:
  explicit ProgressTracker(const EncodeProgressCallback& callback) : callback_(callback) {}

  // Enters `name`, which spans [lo, hi] of the encode.
  void stage(std::string_view name, double lo, double hi) {
    name_ = name;
    lo_ = lo;
    hi_ = hi;
    emit(lo, true);
  }
  // The share of the current stage done (0..1).
  void within(double share) { emit(lo_ + (hi_ - lo_) * std::clamp(share, 0.0, 1.0), false); }
  // within() as a function for the stages' own loops; empty without a callback.
  std::function<void(double)> within_function() {
    if (!callback_) return {};
    return [this](double share) { within(share); };
  }

 private:
  void emit(double fraction, bool stage_changed) {
    if (!callback_) return;
    fraction = std::max(fraction, last_);
    if (!stage_changed && fraction < last_ + 0.002) return;
    last_ = fraction;
    callback_(EncodeProgress{name_, fraction});
  }

  const EncodeProgressCallback& callback_;
  std::string_view name_;
  double lo_ = 0, hi_ = 0, last_ = 0;
};

// The candidate streams, one per ordering, all at the record size the
// first one settles on; reports[0] is the caller's report.
struct CandidateStreams {
  std::vector<EncodedStream> streams;
  std::vector<EncodeReport> reports;  // [i > 0] when a report is wanted
  uint32_t record_bytes = 0;          // the record size settled on
};

// Encodes every ordering (encode(i, record_bytes, report) for ordering i).
// The first one settles the record size (smaller records while an automatic
// size misses the granularity bound, at most three times); the others run
// on their own threads (they share only read-only inputs) at the first
// record size meanwhile, and one that settles elsewhere is encoded again.
template <class EncodeCandidate>
Result<CandidateStreams> encode_candidates(const EncodeCandidate& encode, size_t count,
                                           const RecordSizing& sizing, bool parallel,
                                           EncodeReport* report,
                                           const std::function<void(double)>& progress) {
  // Progress follows the first candidate (on this thread); the others, on
  // their own threads, run alongside. One after the other, each gets an
  // equal share.
  const std::function<void(double)> no_progress;
  auto progress_of = [&](size_t i) -> std::function<void(double)> {
    if (!progress) return {};
    if (parallel) {
      if (i > 0) return {};
      return progress;
    }
    return [&progress, i, count](double share) { progress((double(i) + share) / double(count)); };
  };
  CandidateStreams out;
  out.streams.resize(count);
  out.reports.resize(count);
  auto report_of = [&](size_t i) { return report ? &out.reports[i] : nullptr; };
  std::vector<std::future<Result<EncodedStream>>> early;  // destroyed (joined) before what it reads
  if (parallel) {
    for (size_t i = 1; i < count; ++i)
      early.push_back(
          std::async(std::launch::async, encode, i, sizing.first_bytes, report_of(i), no_progress));
  }
  uint32_t record_bytes = sizing.first_bytes;
  for (int attempt = 0;; ++attempt) {
    auto encoded = encode(0, record_bytes, report, progress_of(0));
    if (!encoded) return tl::unexpected(encoded.error());
    out.streams[0] = std::move(*encoded);
    if (!sizing.automatic || sizing.granular(out.streams[0]) || attempt >= 3 || record_bytes <= 16)
      break;
    record_bytes = std::max<uint32_t>(16, static_cast<uint32_t>(record_bytes * 0.75));
  }
  out.record_bytes = record_bytes;
  for (size_t i = 1; i < count; ++i) {
    auto candidate =
        parallel ? early[i - 1].get() : encode(i, record_bytes, report_of(i), progress_of(i));
    if (parallel && record_bytes != sizing.first_bytes)
      candidate = encode(i, record_bytes, report_of(i), no_progress);
    if (!candidate) return tl::unexpected(candidate.error());
    out.streams[i] = std::move(*candidate);
  }
  return out;
}

// Rate-distortion by measurement (rd_measure.h): the index of the stream
// whose decoded prefixes lie closest to the original (the quantized one,
// from the positions already quantized), all judged at the same byte
// budgets (fractions of the first stream's size). A stream that misses the
// granularity bound the current choice meets cannot win; with
// `others_are_prefixes` (the streams after the first are prefixes,
// encode_once's stop_after_bytes) the caller judges that on the winner's
// whole stream. The other streams are measured on their own threads when
// `parallel`; each measurement's queries run on `query_threads`
// (RdMeasureOptions::threads).
constexpr double kPrepareShare = 0.3;

Result<size_t> measured_best(const Mesh& mesh, const QuantGrid& grid, const std::vector<Vec3i>& q,
                             const std::vector<EncodedStream>& streams, const RecordSizing& sizing,
                             bool parallel, ProgressTracker& progress,
                             bool others_are_prefixes = false, unsigned query_threads = 1,
                             TriangleBvh* hierarchy = nullptr) {
  Mesh reference;
  reference.triangles = mesh.triangles;
  reference.positions.reserve(q.size());
  for (const Vec3i& p : q) reference.positions.push_back(grid.dequantize(p));
  RdMeasureOptions measure_options;
  measure_options.threads = query_threads;
  TriangleBvh given;
  if (hierarchy && !hierarchy->empty()) {
    if (auto st = hierarchy->refit(reference); !st) return tl::unexpected(st.error());
    given = std::move(*hierarchy);
  }
  auto measure = RdMeasure::prepare(reference, measure_options, std::move(given));
  if (!measure) return tl::unexpected(measure.error());
  // The hierarchy goes back to the caller however the measurement ends.
  struct GiveBack {
    TriangleBvh* to;
    Result<RdMeasure>& from;
    ~GiveBack() {
      if (to) *to = std::move(*from).take_hierarchy();
    }
  } give_back{hierarchy, measure};
  // About a third of the measuring is this preparation (a hierarchy over
  // the whole original); the curves share the rest.
  progress.within(kPrepareShare);
  const uint64_t reference_bytes = streams[0].bytes.size();
  const std::function<void(double)> no_progress;
  const std::function<void(double)> first_progress = [&](double share) {
    const double streams_after = parallel ? 1.0 : double(streams.size());
    progress.within(kPrepareShare + (1 - kPrepareShare) * share / streams_after);
  };
  auto score_of = [&](const EncodedStream& stream,
                      const std::function<void(double)>& on_budget) -> Result<double> {
    // A prefix (shorter index than the first, whole stream's) is cut as
    // its whole stream would be, whose index is about as long.
    const uint64_t shortfall = streams[0].payload_offset > stream.payload_offset
                                   ? streams[0].payload_offset - stream.payload_offset
                                   : 0;
    auto curve = measure->curve(stream.bytes, reference_bytes, on_budget, shortfall);
    if (!curve) return tl::unexpected(curve.error());
    return RdMeasure::score(*curve);
  };
  std::vector<std::future<Result<double>>> other_scores;  // joined before `measure` goes
  for (size_t i = 1; i < streams.size(); ++i) {
    other_scores.push_back(std::async(parallel ? std::launch::async : std::launch::deferred,
                                      score_of, std::cref(streams[i]), std::cref(no_progress)));
  }
  auto best_score = score_of(streams[0], first_progress);
  if (!best_score) return tl::unexpected(best_score.error());
  size_t best = 0;
  for (size_t i = 1; i < streams.size(); ++i) {
    auto score = other_scores[i - 1].get();
    if (!score) return tl::unexpected(score.error());
    if (!others_are_prefixes && sizing.automatic && sizing.granular(streams[best]) &&
        !sizing.granular(streams[i]))
      continue;
    if (*score < *best_score) {
      best_score = *score;
      best = i;
    }
  }
  return best;
}

}  // namespace

std::vector<std::string> encode_warnings(const Mesh& mesh) {
  // Everything a Mesh holds travels now: positions, faces, attributes with
  // their seams, materials and extra attributes (attribute records) and the
  // images (texture records). What import could not put into the Mesh is
  // import's warning (CleanReport::notes). A field added to Mesh that the
  // stream does not carry must be named here.
  (void)mesh;
  return {};
}

namespace {

// The geometry stream `bytes` (candidate `stream`) with the attribute
// records added (attribute_codec.h), and the report's records to match.
Result<std::vector<uint8_t>> with_attributes(const AttributePlan& plan, const Mesh& mesh,
                                             const std::vector<Vec3i>& q, EncodedStream& stream,
                                             EncodeReport* report) {
  if (plan.empty()) return std::move(stream.bytes);
  std::vector<uint32_t> to_input(stream.to_decoder.size(), kNone);
  for (uint32_t v = 0; v < stream.to_decoder.size(); ++v) {
    if (stream.to_decoder[v] >= to_input.size())
      return make_error(ErrorCode::kInternal, "encoder: a vertex has no decoder id");
    to_input[stream.to_decoder[v]] = v;
  }
  AttributeParts parts;
  std::vector<AttributeRecordPlace> places;
  auto bytes = add_attribute_records(plan, mesh, q, stream.bytes, to_input, &parts, &places);
  if (!bytes) return bytes;
  if (report) {
    report->attribute_bytes = parts;
    report->attribute_locked_vertices = plan.locked_count;
    // Each attribute record shows the mesh of the record before it.
    for (const AttributeRecordPlace& p : places) {
      if (p.record == 0 || p.record > report->records.size()) break;
      EncodedRecord r = report->records[p.record - 1];
      r.plane = false;
      r.bytes = p.bytes;
      r.distortion_drop = 0;
      report->records.insert(report->records.begin() + p.record, r);
    }
  }
  return bytes;
}

// The stream without ASA guidance: decimation, record coding, the measured
// choice of ordering, attributes and textures. Everything it builds (the
// decimation's layers, replays, hierarchies) is freed when it returns, so
// the guidance, measured after it, does not add to its peak.
Result<std::vector<uint8_t>> encode_records(const Mesh& mesh, const EncodeOptions& options,
                                            EncodeReport* report,
                                            TriangleBvh* surface_out = nullptr) {
  if (auto st = check_options(options); !st) return tl::unexpected(st.error());
  // Quantize and decimate once for every candidate.
  auto grid = make_grid(mesh, options.quant_bits);
  if (!grid) return tl::unexpected(grid.error());
  if (auto s = validate_arrays(mesh); !s) return tl::unexpected(s.error());
  if (mesh.triangles.empty()) return make_error(ErrorCode::kInvalidMesh, "mesh has no triangles");
  std::vector<Vec3i> q = quantize_positions(mesh, *grid);
  auto plan = plan_attributes(mesh, q,
                              {options.quant_normal, options.quant_uv, options.quant_color,
                               options.base_color_bits, options.wedge_repeat});
  if (!plan) return tl::unexpected(plan.error());
  auto editable = EditableMesh::build(q, mesh.triangles);
  if (!editable) return tl::unexpected(editable.error());
  // The stages' shares of the whole, from their times on a 0.8M-triangle
  // scan on two cores (import is the caller's).
  std::vector<RecordOrdering> orderings = orderings_to_try(options);
  const bool measuring = orderings.size() > 1;
  const bool on_prefixes = measuring && !options.measure_whole_candidates;
  const double decimated_at = measuring ? 0.3 : 0.35, coded_at = measuring ? 0.8 : 1.0;
  // On prefixes: the first candidate, the measurement, then (when another
  // wins, which cannot be known before) its whole encode in what is left.
  const double first_coded_at = 0.72, measured_at = 0.85;
  ProgressTracker progress(options.progress);
  progress.stage("decimating", 0.0, decimated_at);
  DecimateOptions dopt;
  dopt.target_vertices = options.target_base_vertices;
  dopt.candidate_share = options.layer_candidate_share;
  dopt.threads = options.threads;
  dopt.progress = progress.within_function();
  if (!options.measure_unlocked_seams) dopt.locked = plan->locked;
  if (options.locality_cell_vertices > 0) {
    dopt.layer_locks = [levels = CellLevels(options.locality_cell_vertices,
                                            unlocked_for_share(static_cast<uint32_t>(q.size()),
                                                               options.locality_unlocked_share)),
                        bits = options.quant_bits](uint32_t, const EditableMesh& m,
                                                   std::vector<uint8_t>& l) mutable {
      lock_cell_borders(m, levels.next(live_vertices(m)), bits, l);
    };
  }
  DecimationResult dec = decimate_layers(std::move(*editable), dopt);

  // The candidates.
  auto uses_surface = [](const RecordOrdering& o) {
    return o.distortion_estimate == DistortionEstimate::kSurfaceDistance;
  };
  // (on prefixes, built when a candidate that needs it is encoded)
  TriangleBvh surface;
  if (on_prefixes ? uses_surface(orderings[0])
                  : std::any_of(orderings.begin(), orderings.end(), uses_surface))
    surface = grid_surface(mesh, q, options.threads);
  // The hierarchy over the original goes to the caller (the ASA guidance
  // measures against the same triangles) whichever way this returns, with
  // its triangle hints (dropped for the winner's encode, below).
  struct HandOut {
    TriangleBvh* to;
    TriangleBvh& from;
    ~HandOut() {
      if (!to) return;
      from.restore_triangle_hints();
      *to = std::move(from);
    }
  } hand_out{surface_out, surface};
  // The input's normals, for the displacement estimate only: computed when
  // a candidate uses it, freed before a surface-distance winner's encode
  // (12 bytes a vertex beside the surface hierarchy at the peak).
  std::vector<Vec3f> input_normals;
  if (!std::all_of(orderings.begin(), orderings.end(), uses_surface))
    input_normals = vertex_normals(q, mesh.triangles);
  auto encode_candidate = [&](size_t i, uint32_t bytes, EncodeReport* candidate_report,
                              const std::function<void(double)>& candidate_progress,
                              uint64_t stop_after_bytes = 0, bool last = false) {
    const RecordOrdering& o = orderings[i];
    return encode_once(mesh, *grid, q, input_normals, dec, options, bytes, o.plane_calibration,
                       candidate_report, uses_surface(o) ? &surface : nullptr, candidate_progress,
                       stop_after_bytes, last ? &dec : nullptr);
  };
  const RecordSizing sizing(mesh.vertex_count(), options);
  const bool parallel =
      measuring && options.threads != 1 && std::thread::hardware_concurrency() > 1;
  // The chosen geometry stream with the attribute and texture records added.
  auto finish = [&](EncodedStream& stream) -> Result<std::vector<uint8_t>> {
    auto out = options.measure_unlocked_seams
                   ? Result<std::vector<uint8_t>>(std::move(stream.bytes))
                   : with_attributes(*plan, mesh, q, stream, report);
    if (report) report->warnings = encode_warnings(mesh);
    if (!out) return out;
    // Textures go in after: the record order and sizes above are the geometry's.
    auto textured = add_texture_records(std::move(*out), mesh.textures);
    progress.stage("done", 1.0, 1.0);
    return textured;
  };
  if (on_prefixes) {
    // The first candidate whole (it settles the record size, as before),
    // the others only as far as the measurement decodes them, at that record
    // size; a winner other than the first is then encoded whole. One
    // encode at a time: the peak holds one replay.
    progress.stage("coding records", decimated_at, first_coded_at);
    // (The surface the others need is built after it: built beside the
    // first's replay, its hierarchy raised dragon_x1's peak by a quarter.)
    auto first =
        encode_candidates(encode_candidate, 1, sizing, false, report, progress.within_function());
    if (!first) return tl::unexpected(first.error());
    progress.stage("measuring", first_coded_at, measured_at);
    const RdMeasureOptions measured{};
    const auto stop = static_cast<uint64_t>(
        std::ceil(measured.last_fraction * double(first->streams[0].bytes.size())));
    std::vector<EncodedStream> streams;
    streams.push_back(std::move(first->streams[0]));
    if (surface.empty() && std::any_of(orderings.begin() + 1, orderings.end(), uses_surface))
      surface = grid_surface(mesh, q, options.threads);
    for (size_t i = 1; i < orderings.size(); ++i) {
      auto prefix = encode_candidate(i, first->record_bytes, nullptr, {}, stop);
      if (!prefix) return tl::unexpected(prefix.error());
      streams.push_back(std::move(*prefix));
    }
    // The measurement's hierarchy over the original is the surface's,
    // refitted to the dequantized positions (and back to grid units for a
    // winner that needs it): one build per encode.
    // One stream after the other, each measured on every thread: the peak
    // holds one decoded prefix and its hierarchy.
    auto best = measured_best(mesh, *grid, q, streams, sizing, false, progress, true,
                              options.threads, &surface);
    if (!best) return tl::unexpected(best.error());
    if (*best == 0) return finish(streams[0]);
    progress.stage("coding the winner", measured_at, 1.0);
    if (uses_surface(orderings[*best])) {
      // (Not `= {}`: that assigns an empty list and keeps the capacity.)
      std::vector<Vec3f>().swap(input_normals);
      if (surface.empty()) {
        surface = grid_surface(mesh, q, options.threads);
      } else if (auto st = to_grid_units(surface, mesh, q); !st) {
        return tl::unexpected(st.error());
      }
      // The cache's hints are slots (vertex_error2): the triangle-to-slot
      // map is not needed while the replay is alive.
      surface.drop_triangle_hints();
    }
    // The prefixes are measured: only the first stream may still be needed,
    // and its vertex map only for attribute records (4 bytes a vertex).
    streams.resize(1);
    if (options.measure_unlocked_seams || plan->empty())
      std::vector<uint32_t>().swap(streams[0].to_decoder);
    EncodeReport winner_report;
    // The decimation's last encode: its layers go as they are written.
    auto winner = encode_candidate(*best, first->record_bytes, report ? &winner_report : nullptr,
                                   progress.within_function(), 0, true);
    if (!winner) return tl::unexpected(winner.error());
    if (sizing.automatic && sizing.granular(streams[0]) && !sizing.granular(*winner))
      return finish(streams[0]);
    if (report) *report = std::move(winner_report);
    return finish(*winner);
  }

  auto candidates = encode_candidates(encode_candidate, orderings.size(), sizing, parallel, report,
                                      progress.within_function());
  if (!candidates) return tl::unexpected(candidates.error());
  if (!measuring) return finish(candidates->streams[0]);
  // The peer (EncodeOptions::measure_whole_candidates). What the
  // measurement does not need goes before it builds its own hierarchy over
  // the original: the peak is then one such hierarchy.
  surface = TriangleBvh{};
  dec = DecimationResult{};

  // The measured choice among them.
  progress.stage("measuring", coded_at, 1.0);
  auto best = measured_best(mesh, *grid, q, candidates->streams, sizing, parallel, progress);
  if (!best) return tl::unexpected(best.error());
  if (report && *best > 0) *report = std::move(candidates->reports[*best]);
  return finish(candidates->streams[*best]);
}

}  // namespace

Result<std::vector<uint8_t>> encode_hcs(const Mesh& mesh, const EncodeOptions& options) {
  return encode_hcs(mesh, options, nullptr);
}

Result<std::vector<uint8_t>> encode_hcs(const Mesh& mesh, const EncodeOptions& options,
                                        EncodeReport* report) {
  if (!options.asa_guidance) return encode_records(mesh, options, report);
  // The records' stages take the first share of the progress bar, the
  // guidance its own stage after them (its measured share on the real
  // meshes, bench/REPORT.md).
  constexpr double kRecordsShare = 0.85;
  EncodeOptions records_options = options;
  if (options.progress)
    records_options.progress = [&options](const EncodeProgress& p) {
      if (p.stage != "done") options.progress({p.stage, p.fraction * kRecordsShare});
    };
  // The records' hierarchy over the original serves the guidance too,
  // refitted to the original's own positions (the same distances as a
  // hierarchy built over them).
  TriangleBvh original_hierarchy;
  auto stream = encode_records(mesh, records_options, report, &original_hierarchy);
  if (!stream) return stream;
  if (!original_hierarchy.empty())
    if (auto st = original_hierarchy.refit(mesh); !st) return tl::unexpected(st.error());
  // The ASA guidance last: it names records by their final numbers.
  ProgressTracker progress(options.progress);
  progress.stage("measuring ASA guidance", kRecordsShare, 1.0);
  AsaGuidanceOptions guidance_options;
  guidance_options.progress = progress.within_function();
  guidance_options.threads = options.threads;
  guidance_options.original_hierarchy = &original_hierarchy;
  auto guidance = measure_asa_guidance(mesh, *stream, guidance_options);
  if (!guidance) return tl::unexpected(guidance.error());
  auto out = with_asa_guidance(*stream, *guidance);
  progress.stage("done", 1.0, 1.0);
  return out;
}

}  // namespace meshstream

#include "common/codec/rd_measure.h"

#include <algorithm>
#include <cmath>

#include "common/codec/container.h"
#include "common/codec/decoder.h"

namespace meshstream {

Result<RdMeasure> RdMeasure::prepare(const Mesh& original, const RdMeasureOptions& options) {
  return prepare(original, options, TriangleBvh{});
}

Result<RdMeasure> RdMeasure::prepare(const Mesh& original, const RdMeasureOptions& options,
                                     TriangleBvh hierarchy) {
  if (original.triangles.empty())
    return make_error(ErrorCode::kInvalidArgument,
                      "rate-distortion measure: mesh has no triangles");
  if (!hierarchy.empty() && hierarchy.triangle_count() != original.face_count())
    return make_error(ErrorCode::kInvalidArgument,
                      "rate-distortion measure: the hierarchy is over another mesh");
  RdMeasure m;
  m.options_ = options;
  const SurfaceSamples area =
      sample_surface_area(original, std::max<uint32_t>(options.samples, 1), 1);
  m.cell_area_ = area.area / std::max<uint32_t>(options.samples, 1);
  // The original never changes, so fixed area samples serve (and cost less
  // than a point per triangle of a large original).
  m.original_samples_.points.assign(area.points.begin(), area.points.begin() + area.area_count);
  m.original_samples_.weights.assign(area.area_count,
                                     area.area / std::max<uint32_t>(area.area_count, 1));
  m.original_samples_.area = area.area;
  m.original_bvh_ =
      hierarchy.empty() ? TriangleBvh::build(original, options.threads) : std::move(hierarchy);
  m.diagonal_ = bounding_box(original).diagonal();
  return m;
}

Result<std::vector<RdPoint>> RdMeasure::curve(std::span<const uint8_t> stream,
                                              uint64_t reference_bytes,
                                              const std::function<void(double)>& progress,
                                              uint64_t index_shortfall) const {
  auto index = read_stream_index(stream);
  if (!index) return tl::unexpected(index.error());
  std::vector<RdPoint> points;
  const uint32_t n = std::max<uint32_t>(options_.budgets, 1);
  const double lo = std::log(options_.first_fraction * double(reference_bytes));
  const double hi = std::log(options_.last_fraction * double(reference_bytes));
  auto point_at = [&](uint32_t i) {
    RdPoint p;
    p.budget = static_cast<uint64_t>(std::exp(n == 1 ? hi : lo + (hi - lo) * i / (n - 1)));
    const double within = std::max(0.0, double(p.budget) - double(index_shortfall));
    p.bytes = prefix_for_budget(*index, DecodeBudget{DecodeBudget::Kind::kBytes, within});
    return p;
  };
  IncrementalDecoder decoder;
  // The largest prefix measured, not the stream, is what the decoder holds.
  decoder.expect_prefix(point_at(n - 1).bytes);
  uint64_t fed = 0;
  for (uint32_t i = 0; i < n; ++i) {
    RdPoint p = point_at(i);
    if (p.bytes > fed) {
      auto applied = decoder.feed(stream.subspan(fed, p.bytes - fed));
      if (!applied) return tl::unexpected(applied.error());
      fed = p.bytes;
    }
    const Mesh& shown = decoder.mesh();
    p.vertices = shown.vertex_count();
    if (shown.triangles.empty())
      return make_error(ErrorCode::kInvalidMesh,
                        "rate-distortion measure: decoded prefix has no triangles");
    p.relative_rms = relative_rms(shown);
    points.push_back(p);
    if (progress) progress(double(i + 1) / n);
  }
  return points;
}

double RdMeasure::relative_rms(const Mesh& shown) const {
  const unsigned threads = options_.threads;
  const double to_shown =
      weighted_rms_distance(original_samples_, TriangleBvh::build(shown, threads), threads);
  const double to_original =
      weighted_rms_distance(quadrature_samples(shown, cell_area_), original_bvh_, threads);
  return diagonal_ > 0 ? std::max(to_shown, to_original) / diagonal_ : 0;
}

double RdMeasure::score(const std::vector<RdPoint>& points) {
  if (points.empty()) return 0;
  double sum = 0;
  for (const RdPoint& p : points) sum += std::log(std::max(p.relative_rms, 1e-9));
  return sum / double(points.size());
}

}  // namespace meshstream

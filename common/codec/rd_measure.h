// Measured rate-distortion of an encoded stream: the surface distance of
// its decoded prefixes to the original, by which the encoder judges its
// record orderings (not by its proxy alone).
//
// The encoder's record ordering uses a per-vertex distortion proxy (fast,
// local, see distortion_estimate.h) whose balance between structure records (new
// vertices) and plane records (sharper positions) depends on the mesh: a
// CAD part and a scan want different mixes. The encoder therefore encodes a
// few balances, decodes each stream at log-spaced byte budgets, measures the
// symmetric RMS surface distance of every decoded prefix to the original and
// keeps the stream with the lowest mean log RMS: the area under its
// log-bytes / log-RMS curve, the plot the codec benchmark draws.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "common/base/result.h"
#include "common/mesh/mesh.h"
#include "common/metrics/bvh.h"
#include "common/metrics/surface_quadrature.h"
#include "common/metrics/surface_sampling.h"

namespace meshstream {

struct RdMeasureOptions {
  // Area samples on the original (fixed for all prefixes); the prefixes get
  // quadrature points (surface_quadrature.h: fixed points per triangle, at
  // least one each) at the same density, so the small differences between
  // candidates are not drowned in sampling noise.
  // 4000 samples and 5 budgets up to 1/8 of the stream: the balance matters
  // most early, and the measurement stays about as costly as one encode.
  uint32_t samples = 4000;
  uint32_t budgets =
      5;  // log-spaced budgets between first_fraction and last_fraction of the stream
  double first_fraction = 1.0 / 64;
  double last_fraction = 1.0 / 8;
  // Threads for the closest-point queries of each measurement (0 = one per
  // core); the results are the same for every count.
  unsigned threads = 1;
};

// One measured point of a stream's curve.
struct RdPoint {
  uint64_t budget = 0;  // bytes allowed
  uint64_t bytes =
      0;  // the prefix decoded: largest record boundary within the budget (at least the base)
  uint32_t vertices = 0;
  double relative_rms = 0;  // symmetric RMS over the original's bounding-box diagonal
};

// The original surface, prepared once for many streams.
class RdMeasure {
 public:
  // kInvalidArgument for a mesh without triangles. O(F log F + samples).
  static Result<RdMeasure> prepare(const Mesh& original, const RdMeasureOptions& options = {});
  // The same with `hierarchy`, a hierarchy over `original` (its triangles
  // and positions: TriangleBvh::refit), used instead of building one;
  // empty: built. The measurement is the same.
  static Result<RdMeasure> prepare(const Mesh& original, const RdMeasureOptions& options,
                                   TriangleBvh hierarchy);
  // The hierarchy over the original, handed back (the measure is then
  // done with).
  TriangleBvh take_hierarchy() && { return std::move(original_bvh_); }

  // Decodes `stream` at the budgets (fractions of `reference_bytes`, the
  // same for every candidate so their curves are compared at equal bytes)
  // and measures each prefix. `index_shortfall`: for a stream that is
  // itself a prefix (encode_once's stop_after_bytes), how many bytes its
  // header and index are shorter than its whole stream's would be; the
  // budgets then cut it where they would cut the whole stream. Fails with the decoder's error on a
  // stream it cannot decode. Cost: one decode plus, per budget, a hierarchy over the prefix and 2 x
  // samples closest-point queries. `progress`, when set, is called after each budget with the share
  // of the budgets done.
  Result<std::vector<RdPoint>> curve(std::span<const uint8_t> stream, uint64_t reference_bytes,
                                     const std::function<void(double)>& progress = {},
                                     uint64_t index_shortfall = 0) const;

  // The symmetric RMS distance of `shown` (e.g. one decoded prefix) to the
  // original, over the original's bounding-box diagonal. Precondition:
  // shown has triangles, indices in range. Cost: a hierarchy over `shown`
  // and samples + max(faces, samples) closest-point queries.
  double relative_rms(const Mesh& shown) const;

  // Mean natural log of the points' RMS (lower is better). A zero RMS
  // counts as 1e-9 of the diagonal.
  static double score(const std::vector<RdPoint>& points);

 private:
  WeightedSamples original_samples_;
  double cell_area_ = 0;
  TriangleBvh original_bvh_;
  double diagonal_ = 0;
  RdMeasureOptions options_;
};

}  // namespace meshstream

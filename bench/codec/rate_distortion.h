// Rate-distortion curves for the codec benchmark: our stream cut at record
// boundaries, and the LOD chain a user would build instead (meshoptimizer's
// simplifier, each level Draco-coded, downloaded one after the other).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "bench/codec/measurements.h"
#include "bench/peers/draco_peer.h"
#include "bench/peers/meshopt_lod.h"
#include "common/base/result.h"
#include "common/codec/container.h"
#include "common/codec/decoder.h"
#include "common/metrics/distance.h"

namespace meshstream::bench {

// Distance of what a client shows after `bytes` to the original.
inline Result<RdPoint> rd_point(const PreparedSurface& original, const Mesh& shown,
                                uint64_t bytes) {
  auto prepared = PreparedSurface::prepare(shown, original.options());
  if (!prepared) return tl::unexpected(prepared.error());
  const SurfaceDistance d = surface_distance(original, *prepared);
  RdPoint p;
  p.bytes = bytes;
  p.vertices = shown.vertex_count();
  p.faces = shown.face_count();
  p.rms = d.rms;
  p.hausdorff = d.hausdorff;
  p.rel_rms = d.relative_rms();
  p.rel_hausdorff = d.relative_hausdorff();
  return p;
}

// About `count` record boundaries (stream prefix lengths), log-spaced in
// bytes from the end of the base mesh to the whole stream, plus the prefixes
// that the given byte budgets select. Sorted, unique.
inline std::vector<uint64_t> choose_prefixes(const StreamIndex& index, int count,
                                             const std::vector<uint64_t>& budgets) {
  std::vector<uint64_t> ends;
  for (const RecordEntry& r : index.records) ends.push_back(r.offset + r.size);
  std::vector<uint64_t> chosen;
  if (ends.empty()) return chosen;
  const double first = static_cast<double>(ends.front()), last = static_cast<double>(ends.back());
  for (int i = 0; i < count; ++i) {
    const double target =
        count > 1 ? first * std::pow(last / first, double(i) / (count - 1)) : last;
    auto it = std::upper_bound(ends.begin(), ends.end(), static_cast<uint64_t>(target + 0.5));
    chosen.push_back(it == ends.begin() ? ends.front() : *(it - 1));
  }
  chosen.push_back(ends.back());
  for (uint64_t budget : budgets) {
    DecodeBudget b;
    b.kind = DecodeBudget::Kind::kBytes;
    b.value = static_cast<double>(budget);
    chosen.push_back(prefix_for_budget(index, b));
  }
  std::sort(chosen.begin(), chosen.end());
  chosen.erase(std::unique(chosen.begin(), chosen.end()), chosen.end());
  return chosen;
}

// Feeds the stream to one IncrementalDecoder up to each prefix in turn (a
// client receiving it) and measures the mesh it holds there.
inline Result<std::vector<RdPoint>> our_curve(std::span<const uint8_t> stream,
                                              const std::vector<uint64_t>& prefixes,
                                              const PreparedSurface& original) {
  std::vector<RdPoint> curve;
  IncrementalDecoder decoder;
  uint64_t fed = 0;
  for (uint64_t prefix : prefixes) {
    if (prefix > stream.size()) break;
    auto applied = decoder.feed(stream.subspan(fed, prefix - fed));
    if (!applied)
      return tl::unexpected(
          std::move(applied.error()).with_context("stream prefix " + std::to_string(prefix)));
    fed = prefix;
    if (decoder.resume_offset() != prefix) {
      return make_error(ErrorCode::kCorrupt,
                        "decoder stopped at byte " + std::to_string(decoder.resume_offset()) +
                            ", not at the record boundary " + std::to_string(prefix));
    }
    auto point = rd_point(original, decoder.mesh(), prefix);
    if (!point)
      return tl::unexpected(
          std::move(point.error()).with_context("prefix " + std::to_string(prefix)));
    curve.push_back(*point);
  }
  return curve;
}

struct LodLevel {
  std::string label;
  double fraction;
};
inline const std::vector<LodLevel>& lod_levels() {
  static const std::vector<LodLevel> levels = {
      {"1/64", 1.0 / 64}, {"1/16", 1.0 / 16}, {"1/4", 1.0 / 4}, {"full", 1.0}};
  return levels;
}

// The LOD chain: simplify to each fraction of the indices, Draco-code it
// (12 bits, level 7, edgebreaker), decode it as the client would, and count
// bytes cumulatively (the client downloads each level in turn).
inline Result<std::vector<RdPoint>> lod_chain_curve(const Mesh& mesh, int quant_bits,
                                                    const PreparedSurface& original) {
  std::vector<RdPoint> curve;
  uint64_t cumulative = 0;
  for (const LodLevel& level : lod_levels()) {
    const Mesh lod = simplify_lod(mesh, level.fraction);
    auto file = draco_encode(lod, quant_bits, 7);
    if (!file) return tl::unexpected(std::move(file.error()).with_context("LOD " + level.label));
    cumulative += file->size();
    auto shown = draco_decode(*file);
    if (!shown) return tl::unexpected(std::move(shown.error()).with_context("LOD " + level.label));
    auto point = rd_point(original, *shown, cumulative);
    if (!point) return tl::unexpected(std::move(point.error()).with_context("LOD " + level.label));
    curve.push_back(*point);
  }
  return curve;
}

// Our point at each chain step: the largest measured prefix within the
// chain's cumulative bytes (choose_prefixes put exactly that prefix in).
inline std::vector<ChainComparison> compare_at_chain(const std::vector<RdPoint>& chain,
                                                     const std::vector<RdPoint>& ours,
                                                     uint32_t original_faces) {
  std::vector<ChainComparison> out;
  for (size_t i = 0; i < chain.size(); ++i) {
    ChainComparison c;
    c.label = i < lod_levels().size() ? lod_levels()[i].label : std::to_string(i);
    if (i < lod_levels().size()) {
      c.target_faces = static_cast<uint32_t>(3 * original_faces * lod_levels()[i].fraction) / 3;
    }
    c.chain = chain[i];
    for (const RdPoint& p : ours) {
      if (p.bytes <= chain[i].bytes) c.ours = p;
    }
    if (!c.ours && !ours.empty()) {
      c.ours = ours.front();  // the base mesh: the least we can show
      c.ours_over_budget = true;
    }
    out.push_back(c);
  }
  return out;
}

}  // namespace meshstream::bench

#include "common/metrics/distance.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>
#include <thread>
#include <vector>

namespace meshstream {
namespace {

// Samples are processed in fixed chunks and the partial sums added in chunk
// order, so the result is the same bit for bit whatever the thread count.
constexpr uint32_t kChunk = 2048;

struct ChunkResult {
  double max = 0;
  double sum = 0;     // of distances, over the samples that count for the mean
  double sum_sq = 0;  // of squared distances, same samples
};

Status check_mesh(const Mesh& mesh, const char* which) {
  if (mesh.triangles.empty()) {
    return make_error(ErrorCode::kInvalidArgument,
                      std::string("surface distance: ") + which + " has no triangle");
  }
  const uint32_t n = mesh.vertex_count();
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    for (uint32_t v : mesh.triangles[f]) {
      if (v >= n) {
        return make_error(ErrorCode::kInvalidMesh, std::string("surface distance: ") + which +
                                                       " triangle " + std::to_string(f) +
                                                       " refers to vertex " + std::to_string(v) +
                                                       " of " + std::to_string(n));
      }
      const Vec3f& p = mesh.positions[v];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
        return make_error(ErrorCode::kInvalidMesh, std::string("surface distance: ") + which +
                                                       " vertex " + std::to_string(v) +
                                                       " has a non-finite coordinate");
      }
    }
  }
  return {};
}

uint32_t worker_count(uint32_t requested, size_t chunks) {
  uint32_t n = requested;
  if (n == 0) n = std::clamp(std::thread::hardware_concurrency(), 1u, 8u);
  return static_cast<uint32_t>(std::clamp<size_t>(chunks, 1, n));
}

}  // namespace

OneSidedDistance one_sided_distance(const SurfaceSamples& from, const TriangleBvh& to,
                                    uint32_t threads) {
  const size_t total = from.points.size();
  const size_t chunks = (total + kChunk - 1) / kChunk;
  // Mean and RMS estimate the surface integral from the area samples; the
  // vertices and midpoints would over-weight finely tessellated regions.
  const bool area_only = from.area_count > 0;
  std::vector<ChunkResult> results(chunks);
  std::atomic<size_t> next_chunk{0};

  auto work = [&] {
    for (size_t c; (c = next_chunk.fetch_add(1)) < chunks;) {
      ChunkResult r;
      uint32_t hint = TriangleBvh::kNoHint;  // reset per chunk: results never depend on scheduling
      const size_t end = std::min(total, (c + 1) * kChunk);
      for (size_t i = c * kChunk; i < end; ++i) {
        const ClosestHit hit = to.closest(from.points[i], hint);
        hint = hit.triangle;
        const double d = std::sqrt(hit.squared_distance);
        r.max = std::max(r.max, d);
        if (!area_only || i < from.area_count) {
          r.sum += d;
          r.sum_sq += hit.squared_distance;
        }
      }
      results[c] = r;
    }
  };
  const uint32_t workers = worker_count(threads, chunks);
  std::vector<std::thread> pool;
  for (uint32_t t = 1; t < workers; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();

  OneSidedDistance out;
  double sum = 0, sum_sq = 0;
  for (const ChunkResult& r : results) {
    out.max = std::max(out.max, r.max);
    sum += r.sum;
    sum_sq += r.sum_sq;
  }
  const size_t counted = area_only ? from.area_count : total;
  if (counted > 0) {
    out.mean = sum / counted;
    out.rms = std::sqrt(sum_sq / counted);
  }
  return out;
}

Result<PreparedSurface> PreparedSurface::prepare(const Mesh& mesh, const DistanceOptions& options) {
  if (auto ok = check_mesh(mesh, "mesh"); !ok) return tl::unexpected(ok.error());
  PreparedSurface s;
  s.samples_ = sample_surface(mesh, options.samples, options.seed);
  s.bvh_ = TriangleBvh::build(mesh);
  s.diagonal_ = bounding_box(mesh).diagonal();
  s.options_ = options;
  return s;
}

SurfaceDistance surface_distance(const PreparedSurface& a, const PreparedSurface& b) {
  SurfaceDistance d;
  const uint32_t threads = a.options().threads;
  d.a_to_b = one_sided_distance(a.samples(), b.bvh(), threads);
  d.b_to_a = one_sided_distance(b.samples(), a.bvh(), threads);
  d.hausdorff = std::max(d.a_to_b.max, d.b_to_a.max);
  d.rms = std::max(d.a_to_b.rms, d.b_to_a.rms);
  d.diagonal = a.diagonal();
  return d;
}

Result<SurfaceDistance> surface_distance(const Mesh& a, const Mesh& b,
                                         const DistanceOptions& options) {
  if (auto ok = check_mesh(a, "mesh A"); !ok) return tl::unexpected(ok.error());
  if (auto ok = check_mesh(b, "mesh B"); !ok) return tl::unexpected(ok.error());
  auto pa = PreparedSurface::prepare(a, options);
  auto pb = PreparedSurface::prepare(b, options);
  return surface_distance(*pa, *pb);
}

}  // namespace meshstream

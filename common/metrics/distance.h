// Surface-to-surface distances: Hausdorff and RMS, by area-weighted sampling
// of each surface and closest-point queries against the other through a
// bounding-volume hierarchy.
#pragma once

#include <cstdint>

#include "common/base/result.h"
#include "common/mesh/mesh.h"
#include "common/metrics/bvh.h"
#include "common/metrics/surface_sampling.h"

namespace meshstream {

struct DistanceOptions {
  uint32_t samples = 200000;  // per direction, spread by area (vertices always included)
  uint64_t seed = 1;          // sampling is deterministic for a seed
  // Worker threads for the queries; 0 = the machine's cores (at most 8).
  // The result does not depend on it.
  uint32_t threads = 0;
};

struct OneSidedDistance {
  double max = 0;  // Hausdorff from A to B
  double mean = 0;
  double rms = 0;
};

struct SurfaceDistance {
  OneSidedDistance a_to_b, b_to_a;
  double hausdorff = 0;  // max of both directions
  double rms = 0;        // the larger of the two RMS values
  double diagonal = 0;   // A's bounding-box diagonal
  double relative_hausdorff() const { return diagonal > 0 ? hausdorff / diagonal : 0; }
  double relative_rms() const { return diagonal > 0 ? rms / diagonal : 0; }
};

// Symmetric distance between the surfaces of `a` and `b`. Each direction
// samples one surface (options.samples points by area, plus every vertex and
// edge midpoint; see surface_sampling.h) and finds the exact closest point of
// the other through a TriangleBvh. max is over all samples; mean and RMS are
// over the area samples (over all samples when options.samples is 0).
// Deterministic for a seed, whatever the thread count.
// kInvalidArgument when either mesh has no triangle; kInvalidMesh for an
// index out of range or a non-finite coordinate (degenerate triangles are
// fine). Cost O((S + V + E) log F) per direction.
Result<SurfaceDistance> surface_distance(const Mesh& a, const Mesh& b,
                                         const DistanceOptions& options = {});

// A mesh prepared for repeated distance queries (e.g. one original against
// many decoded prefixes): its samples and its hierarchy, built once.
class PreparedSurface {
 public:
  // Same checks and errors as surface_distance. O(F log F + S).
  static Result<PreparedSurface> prepare(const Mesh& mesh, const DistanceOptions& options = {});

  const SurfaceSamples& samples() const { return samples_; }
  const TriangleBvh& bvh() const { return bvh_; }
  double diagonal() const { return diagonal_; }
  const DistanceOptions& options() const { return options_; }

 private:
  SurfaceSamples samples_;
  TriangleBvh bvh_;
  double diagonal_ = 0;
  DistanceOptions options_;
};

// surface_distance over prepared meshes (threads from a's options). The
// result equals surface_distance(a_mesh, b_mesh, options) for the same
// options.
SurfaceDistance surface_distance(const PreparedSurface& a, const PreparedSurface& b);

// One direction: from the samples of `from` to the surface in `to`.
// Precondition: !to.empty(). Deterministic whatever `threads`.
OneSidedDistance one_sided_distance(const SurfaceSamples& from, const TriangleBvh& to,
                                    uint32_t threads = 0);

}  // namespace meshstream

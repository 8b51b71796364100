// Surface-to-surface distances: Hausdorff and RMS, by area-weighted sampling
// of each surface and closest-point queries against the other through a
// bounding-volume hierarchy.
#pragma once

#include <cstdint>

#include "common/base/result.h"
#include "common/mesh/mesh.h"

namespace meshstream {

struct DistanceOptions {
  uint32_t samples = 200000;  // per direction, spread by area (vertices always included)
  uint64_t seed = 1;          // sampling is deterministic for a seed
};

struct OneSidedDistance {
  double max = 0;   // Hausdorff from A to B
  double mean = 0;
  double rms = 0;
};

struct SurfaceDistance {
  OneSidedDistance a_to_b, b_to_a;
  double hausdorff = 0;       // max of both directions
  double rms = 0;             // the larger of the two RMS values
  double diagonal = 0;        // A's bounding-box diagonal
  double relative_hausdorff() const { return diagonal > 0 ? hausdorff / diagonal : 0; }
  double relative_rms() const { return diagonal > 0 ? rms / diagonal : 0; }
};

// kInvalidArgument when either mesh has no triangle.
Result<SurfaceDistance> surface_distance(const Mesh& a, const Mesh& b, const DistanceOptions& options = {});

}  // namespace meshstream

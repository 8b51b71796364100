// Deterministic point samples of a triangle surface, for surface distances.
#pragma once

#include <cstdint>
#include <vector>

#include "common/mesh/mesh.h"
#include "common/mesh/vec.h"

namespace meshstream {

struct SurfaceSamples {
  // points[0, area_count) are spread by area (an unbiased estimate of the
  // surface integral: mean and RMS are taken over these); the rest are every
  // referenced vertex and every edge midpoint, where the largest deviations
  // of a piecewise-linear surface tend to be, and count toward the maximum.
  std::vector<Vec3d> points;
  uint32_t area_count = 0;
  double area = 0;  // total surface area
};

// `area_samples` points by systematic sampling along the cumulative triangle
// area (one random offset, then equal steps: every triangle gets the floor or
// the ceiling of its expected share), each placed uniformly inside its
// triangle; then the vertices and unique edge midpoints. The same mesh, count
// and seed give the same points on every machine (own RNG, no std
// distributions). Zero-area triangles get no area samples.
// Precondition: indices in range. O(V + F log F + area_samples).
SurfaceSamples sample_surface(const Mesh& mesh, uint32_t area_samples, uint64_t seed);

// The area samples of sample_surface only (the same points, area_count of
// them, and the area), without the vertices and edge midpoints: for
// measures that use only the area-weighted part, at O(F) memory less.
SurfaceSamples sample_surface_area(const Mesh& mesh, uint32_t area_samples, uint64_t seed);

}  // namespace meshstream

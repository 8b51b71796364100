// Closest-point primitives for distance queries: point to triangle, point to
// segment, point to axis-aligned box. All in double precision.
#pragma once

#include "common/mesh/vec.h"

namespace meshstream {

// The point of segment [a, b] closest to p; a when a == b. O(1).
Vec3d closest_point_on_segment(Vec3d p, Vec3d a, Vec3d b);

// The point of triangle abc closest to p, by Voronoi-region tests
// (C. Ericson, Real-Time Collision Detection, 2005, section 5.1.5).
// A degenerate (zero-area or needle) triangle is handled as the closest of its
// three edges, so the result is finite for any finite input. O(1).
Vec3d closest_point_on_triangle(Vec3d p, Vec3d a, Vec3d b, Vec3d c);

// Squared distance from p to the box [lo, hi]; 0 inside. Computed as the sum
// of squared per-axis gaps, in the same order as squared_length, so for any
// point q inside the box the result never exceeds squared_length(p - q) even
// after rounding (the pruning in bvh.cpp relies on that). O(1).
double squared_distance_to_box(Vec3d p, Vec3d lo, Vec3d hi);

}  // namespace meshstream

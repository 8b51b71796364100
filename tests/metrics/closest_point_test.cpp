#include "common/metrics/closest_point.h"

#include <gtest/gtest.h>

#include <cmath>

namespace meshstream {
namespace {

const Vec3d a{0, 0, 0}, b{2, 0, 0}, c{0, 2, 0};

void expect_point(Vec3d got, Vec3d want) {
  EXPECT_NEAR(got.x, want.x, 1e-15);
  EXPECT_NEAR(got.y, want.y, 1e-15);
  EXPECT_NEAR(got.z, want.z, 1e-15);
}

TEST(ClosestPointOnTriangle, InteriorProjectsAlongTheNormal) {
  expect_point(closest_point_on_triangle({0.5, 0.25, 3}, a, b, c), {0.5, 0.25, 0});
  expect_point(closest_point_on_triangle({0.5, 0.25, -1}, a, b, c), {0.5, 0.25, 0});
}

TEST(ClosestPointOnTriangle, EachVertexRegionGivesTheVertex) {
  expect_point(closest_point_on_triangle({-1, -1, 1}, a, b, c), a);
  expect_point(closest_point_on_triangle({3, -0.5, 0}, a, b, c), b);
  expect_point(closest_point_on_triangle({-0.5, 3, 2}, a, b, c), c);
}

TEST(ClosestPointOnTriangle, EachEdgeRegionGivesThePerpendicularFoot) {
  expect_point(closest_point_on_triangle({1, -3, 0}, a, b, c), {1, 0, 0});  // ab
  expect_point(closest_point_on_triangle({-3, 1, 5}, a, b, c), {0, 1, 0});  // ac
  expect_point(closest_point_on_triangle({2, 2, 0}, a, b, c), {1, 1, 0});   // bc
}

TEST(ClosestPointOnTriangle, DegenerateTrianglesBehaveLikeSegments) {
  // Collinear corners: the triangle is the segment from (0,0,0) to (2,0,0).
  expect_point(closest_point_on_triangle({1, 1, 0}, a, {1, 0, 0}, b), {1, 0, 0});
  // All three corners equal.
  expect_point(closest_point_on_triangle({5, 5, 5}, b, b, b), b);
  // Two equal corners.
  expect_point(closest_point_on_triangle({1, -1, 0}, a, a, b), {1, 0, 0});
}

TEST(SquaredDistanceToBox, ZeroInsideAndAxisGapsOutside) {
  EXPECT_EQ(squared_distance_to_box({0.5, 0.5, 0.5}, {0, 0, 0}, {1, 1, 1}), 0.0);
  EXPECT_EQ(squared_distance_to_box({2, 0.5, 0.5}, {0, 0, 0}, {1, 1, 1}), 1.0);
  EXPECT_EQ(squared_distance_to_box({2, -1, 3}, {0, 0, 0}, {1, 1, 1}), 1.0 + 1.0 + 4.0);
}

}  // namespace
}  // namespace meshstream

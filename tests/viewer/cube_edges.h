// A cube and the shade of a picture of it on both sides of each visible
// edge: how the crease tests tell a sharp edge from a blended one, in
// process (render_offscreen) and through the real client (--snapshot).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <utility>
#include <vector>

#include "client/viewer/camera.h"
#include "client/viewer/offscreen.h"
#include "client/viewer/rgba_image.h"
#include "common/mesh/mesh.h"

namespace meshstream::client::testing {

// The unit cube, 8 shared corners, 12 outward-facing triangles.
inline Mesh make_cube() {
  Mesh m;
  for (int i = 0; i < 8; ++i) {
    m.positions.push_back(
        {static_cast<float>(i & 1), static_cast<float>((i >> 1) & 1), static_cast<float>(i >> 2)});
  }
  // Each side as a quad (a, b, c, d) counter-clockwise seen from outside.
  const uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    m.triangles.push_back({q[0], q[1], q[2]});
    m.triangles.push_back({q[0], q[2], q[3]});
  }
  return m;
}

inline int luma(const RgbaImage& image, int x, int y) {
  const uint8_t* p = image.pixel(x, y);
  return (299 * p[0] + 587 * p[1] + 114 * p[2]) / 1000;
}

struct EdgeShades {
  int side_a = 0, side_b = 0;  // brightness just inside each of the two sides
};

// For every edge of `cube` whose two sides both face the camera: the
// brightness of `image` a little inside each side, next to the edge's
// midpoint. `image` must be a default view of the whole cube (the camera
// render_offscreen frames, rebuilt here; the client's --snapshot uses it).
inline std::vector<EdgeShades> shades_beside_visible_edges(const Mesh& cube,
                                                           const RgbaImage& image) {
  const OffscreenRequest defaults;
  OrbitCamera camera;
  camera.yaw = defaults.yaw;
  camera.pitch = defaults.pitch;
  const int width = image.width, height = image.height;
  const float aspect = static_cast<float>(width) / static_cast<float>(height);
  camera.frame(cube, aspect, defaults.fill);
  const Mat4 m = mat4_multiply(camera.projection(aspect), camera.view());
  auto pixel_of = [&](Vec3f p) {
    const float x = m[0] * p.x + m[4] * p.y + m[8] * p.z + m[12];
    const float y = m[1] * p.x + m[5] * p.y + m[9] * p.z + m[13];
    const float w = m[3] * p.x + m[7] * p.y + m[11] * p.z + m[15];
    return std::pair<int, int>{static_cast<int>((x / w + 1) / 2 * static_cast<float>(width)),
                               static_cast<int>((1 - y / w) / 2 * static_cast<float>(height))};
  };
  std::vector<EdgeShades> shades;
  for (uint32_t f = 0; f < cube.face_count(); ++f) {
    for (uint32_t g = f + 1; g < cube.face_count(); ++g) {
      const Vec3f nf = face_normal(cube, f), ng = face_normal(cube, g);
      if (dot(nf, ng) > 0.5f) continue;  // same side of the cube
      std::vector<uint32_t> shared;
      for (uint32_t a : cube.triangles[f])
        for (uint32_t b : cube.triangles[g])
          if (a == b) shared.push_back(a);
      if (shared.size() != 2) continue;
      const Vec3f mid = (cube.positions[shared[0]] + cube.positions[shared[1]]) * 0.5f;
      if (dot(nf, camera.eye() - mid) <= 0 || dot(ng, camera.eye() - mid) <= 0) continue;
      // 3 % of the side into each face: on a cube, into face f is away
      // from the other face's normal.
      const auto [xa, ya] = pixel_of(mid - ng * 0.03f);
      const auto [xb, yb] = pixel_of(mid - nf * 0.03f);
      shades.push_back({luma(image, xa, ya), luma(image, xb, yb)});
    }
  }
  return shades;
}

// The largest difference between the two sides of one edge.
inline int largest_edge_step(const std::vector<EdgeShades>& edges) {
  int step = 0;
  for (const EdgeShades& e : edges) step = std::max(step, std::abs(e.side_a - e.side_b));
  return step;
}

}  // namespace meshstream::client::testing

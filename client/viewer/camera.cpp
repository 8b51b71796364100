#include "client/viewer/camera.h"

#include <algorithm>
#include <cmath>

namespace meshstream::client {

Mat4 mat4_multiply(const Mat4& a, const Mat4& b) {
  Mat4 r{};
  for (int c = 0; c < 4; ++c) {
    for (int row = 0; row < 4; ++row) {
      float s = 0;
      for (int k = 0; k < 4; ++k) s += a[k * 4 + row] * b[c * 4 + k];
      r[c * 4 + row] = s;
    }
  }
  return r;
}

Mat4 mat4_perspective(float fovy, float aspect, float n, float f) {
  float t = 1.0f / std::tan(fovy / 2);
  Mat4 m{};
  m[0] = t / aspect;
  m[5] = t;
  m[10] = (f + n) / (n - f);
  m[11] = -1;
  m[14] = 2 * f * n / (n - f);
  return m;
}

Mat4 mat4_look_at(Vec3f eye, Vec3f target, Vec3f up) {
  Vec3f f = normalized(target - eye);
  Vec3f s = normalized(cross(f, up));
  Vec3f u = cross(s, f);
  Mat4 m{};
  m[0] = s.x;
  m[4] = s.y;
  m[8] = s.z;
  m[1] = u.x;
  m[5] = u.y;
  m[9] = u.z;
  m[2] = -f.x;
  m[6] = -f.y;
  m[10] = -f.z;
  m[12] = -dot(s, eye);
  m[13] = -dot(u, eye);
  m[14] = dot(f, eye);
  m[15] = 1;
  return m;
}

Vec3f OrbitCamera::eye() const {
  Vec3f dir{std::cos(pitch) * std::sin(yaw), std::sin(pitch), std::cos(pitch) * std::cos(yaw)};
  return target + dir * distance;
}

Vec3f OrbitCamera::right() const { return {std::cos(yaw), 0, -std::sin(yaw)}; }

Vec3f OrbitCamera::up() const {
  Vec3f to_eye = normalized(eye() - target);
  return cross(to_eye, right());
}

Mat4 OrbitCamera::view() const { return mat4_look_at(eye(), target, Vec3f{0, 1, 0}); }

Mat4 OrbitCamera::projection(float aspect) const {
  // Near and far planes hug the scene so depth precision stays useful at any
  // model scale.
  float z_far = distance + 2 * scene_radius;
  return mat4_perspective(fovy, aspect, near_plane(), z_far);
}

float OrbitCamera::near_plane() const {
  return std::max(distance - 2 * scene_radius, distance * 0.01f);
}

void OrbitCamera::look_from(const AsaCamera& c, const Mesh& mesh) {
  target = c.target;
  const Vec3f offset = c.eye - c.target;
  distance = std::max(length(offset), 1e-12f);
  const Vec3f dir = offset / distance;
  pitch = std::clamp(std::asin(std::clamp(dir.y, -1.0f, 1.0f)), -1.55f, 1.55f);
  yaw = std::atan2(dir.x, dir.z);
  fovy = c.fov_degrees * 3.14159265358979f / 180.0f;
  scene_radius = 1e-6f;
  if (!mesh.positions.empty()) {
    const BoundingBox box = bounding_box(mesh);
    scene_radius =
        std::max(box.diagonal() / 2 + length((box.min + box.max) * 0.5f - target), 1e-6f);
  }
}

AsaCamera OrbitCamera::asa_camera(int width, int height) const {
  AsaCamera c;
  c.eye = eye();
  c.target = target;
  c.fov_degrees = fovy * 180.0f / 3.14159265358979f;
  c.width = std::max(width, 1);
  c.height = std::max(height, 1);
  return c;
}

void OrbitCamera::orbit(float dx, float dy) {
  yaw -= dx * 0.008f;
  pitch = std::clamp(pitch + dy * 0.008f, -1.55f, 1.55f);
}

void OrbitCamera::pan(float dx, float dy, float viewport_height) {
  // One pixel moves the target by the world size of a pixel at its depth.
  float world_per_pixel = 2 * distance * std::tan(fovy / 2) / std::max(viewport_height, 1.0f);
  target += right() * (-dx * world_per_pixel) + up() * (dy * world_per_pixel);
}

void OrbitCamera::zoom(float steps) {
  distance =
      std::clamp(distance * std::pow(0.88f, steps), scene_radius * 0.02f, scene_radius * 50.0f);
}

void OrbitCamera::frame(const Mesh& mesh, float aspect, float fill) {
  if (mesh.positions.empty()) {
    target = {0, 0, 0};
    scene_radius = 1;
    distance = 3;
    return;
  }
  BoundingBox box = bounding_box(mesh);
  target = (box.min + box.max) * 0.5f;
  scene_radius = std::max(box.diagonal() / 2, 1e-6f);
  float half_fov = std::min(fovy / 2, std::atan(std::tan(fovy / 2) * aspect));
  distance = scene_radius / std::sin(half_fov);

  // The bounding sphere over-estimates most shapes: project the vertices and
  // scale and shift so their screen extent is exactly `fill` of the view.
  for (int round = 0; round < 3; ++round) {
    Mat4 view_projection = mat4_multiply(projection(aspect), view());
    float lo_x = 1e30f, hi_x = -1e30f, lo_y = 1e30f, hi_y = -1e30f;
    for (const Vec3f& p : mesh.positions) {
      const Mat4& m = view_projection;
      float x = m[0] * p.x + m[4] * p.y + m[8] * p.z + m[12];
      float y = m[1] * p.x + m[5] * p.y + m[9] * p.z + m[13];
      float w = m[3] * p.x + m[7] * p.y + m[11] * p.z + m[15];
      if (w <= 1e-9f) continue;
      lo_x = std::min(lo_x, x / w);
      hi_x = std::max(hi_x, x / w);
      lo_y = std::min(lo_y, y / w);
      hi_y = std::max(hi_y, y / w);
    }
    if (lo_x > hi_x) break;
    float extent = std::max((hi_x - lo_x) / 2, (hi_y - lo_y) / 2);
    if (extent <= 0) break;
    // Shift the target by the screen-space offset of the extent's centre.
    float cx = (lo_x + hi_x) / 2, cy = (lo_y + hi_y) / 2;
    float half_height_world = distance * std::tan(fovy / 2);
    target += right() * (cx * half_height_world * aspect) + up() * (cy * half_height_world);
    distance *= extent / fill;
  }
}

}  // namespace meshstream::client

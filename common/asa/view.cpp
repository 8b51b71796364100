// The camera of view-dependent ASA: checks, the command-line form, the
// snapshot framing and the per-edge test's precomputed frame. See view.h.
#include "common/asa/view.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

namespace meshstream {
namespace {

bool finite(Vec3f v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

constexpr float kDegrees = static_cast<float>(std::numbers::pi) / 180.0f;

// Right and up of a camera looking along `forward` (unit): Y up, or Z when
// the view is (nearly) vertical.
void camera_frame(Vec3f forward, Vec3f& right, Vec3f& up) {
  Vec3f world_up{0, 1, 0};
  if (std::fabs(forward.y) > 0.999f) world_up = {0, 0, 1};
  right = normalized(cross(forward, world_up));
  up = cross(right, forward);
}

}  // namespace

Status check_camera(const AsaCamera& c) {
  if (!finite(c.eye) || !finite(c.target))
    return make_error(ErrorCode::kInvalidArgument, "camera eye and target must be finite numbers");
  if (c.eye == c.target)
    return make_error(ErrorCode::kInvalidArgument,
                      "camera eye and target are the same point (" + format_camera(c) + ")");
  if (!std::isfinite(c.fov_degrees) || c.fov_degrees <= 0 || c.fov_degrees >= 180) {
    char text[64];
    std::snprintf(text, sizeof text, "%g", c.fov_degrees);
    return make_error(
        ErrorCode::kInvalidArgument,
        std::string("camera field of view must be in (0, 180) degrees (got ") + text + ")");
  }
  if (c.width < 1 || c.height < 1)
    return make_error(ErrorCode::kInvalidArgument, "camera image size must be at least 1x1");
  return {};
}

Status check_view(const AsaView& v) {
  if (!v.enabled) return {};
  if (auto ok = check_camera(v.camera); !ok) return ok;
  if (!std::isfinite(v.pixel_tolerance) || v.pixel_tolerance <= 0)
    return make_error(ErrorCode::kInvalidArgument, "pixel tolerance must be above 0");
  if (!std::isfinite(v.frustum_margin) || v.frustum_margin < 0)
    return make_error(ErrorCode::kInvalidArgument, "frustum margin must be 0 or more");
  if (!std::isfinite(v.backface_margin) || std::fabs(v.backface_margin) > 1)
    return make_error(ErrorCode::kInvalidArgument, "back-face margin must be in [-1, 1]");
  return {};
}

Status parse_camera(const std::string& text, AsaCamera& camera) {
  std::vector<float> numbers;
  const char* p = text.data();
  const char* end = p + text.size();
  auto bad = [&](const std::string& why) {
    return make_error(ErrorCode::kInvalidArgument, "--camera " + text + ": " + why);
  };
  while (p <= end) {
    const char* comma = std::find(p, end, ',');
    float value = 0;
    const char* start = p;
    while (start < comma && *start == ' ') ++start;
    if (start < comma && *start == '+') ++start;
    auto [ptr, ec] = std::from_chars(start, comma, value);
    if (ec != std::errc() || ptr != comma || start == comma) {
      std::string why = "'";
      why.append(p, comma);
      why += "' is not a number";
      return bad(why);
    }
    numbers.push_back(value);
    p = comma + 1;
  }
  if (numbers.size() != 6 && numbers.size() != 7)
    return bad("expected EX,EY,EZ,TX,TY,TZ[,FOV_DEG] (6 or 7 numbers), got " +
               std::to_string(numbers.size()));
  AsaCamera c = camera;
  c.eye = {numbers[0], numbers[1], numbers[2]};
  c.target = {numbers[3], numbers[4], numbers[5]};
  c.fov_degrees = numbers.size() == 7 ? numbers[6] : 45.0f;
  if (auto ok = check_camera(c); !ok) return bad(ok.error().message);
  camera = c;
  return {};
}

std::string format_camera(const AsaCamera& c) {
  char text[256];
  std::snprintf(text, sizeof text, "%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g", c.eye.x, c.eye.y, c.eye.z,
                c.target.x, c.target.y, c.target.z, c.fov_degrees);
  return text;
}

AsaCamera fit_camera(const Mesh& mesh, int width, int height, bool snap) {
  // The viewer's OrbitCamera::frame with its starting yaw, pitch and field
  // of view (client/viewer/camera.cpp), so a snapshot framed there and the
  // camera ASA refines for are the same.
  constexpr float kYaw = 0.6f, kPitch = 0.35f, kFovy = 0.6f, kFill = 0.85f;
  AsaCamera camera;
  camera.width = width;
  camera.height = height;
  camera.fov_degrees = kFovy / kDegrees;
  const float aspect = static_cast<float>(width) / static_cast<float>(std::max(height, 1));
  const Vec3f dir{std::cos(kPitch) * std::sin(kYaw), std::sin(kPitch),
                  std::cos(kPitch) * std::cos(kYaw)};
  const Vec3f right{std::cos(kYaw), 0, -std::sin(kYaw)};
  const Vec3f up = cross(dir, right);
  if (mesh.positions.empty()) {
    camera.target = {0, 0, 0};
    camera.eye = dir * 3.0f;
    return camera;
  }
  const BoundingBox box = bounding_box(mesh);
  Vec3f target = (box.min + box.max) * 0.5f;
  const float radius = std::max(box.diagonal() / 2, 1e-6f);
  const float half_fov = std::min(kFovy / 2, std::atan(std::tan(kFovy / 2) * aspect));
  float distance = radius / std::sin(half_fov);
  const float t = 1.0f / std::tan(kFovy / 2);
  for (int round = 0; round < 3; ++round) {
    const Vec3f eye = target + dir * distance;
    float lo_x = 1e30f, hi_x = -1e30f, lo_y = 1e30f, hi_y = -1e30f;
    for (const Vec3f& p : mesh.positions) {
      const Vec3f rel = p - eye;
      const float w = -dot(dir, rel);
      if (w <= 1e-9f) continue;
      const float x = t / aspect * dot(right, rel) / w, y = t * dot(up, rel) / w;
      lo_x = std::min(lo_x, x);
      hi_x = std::max(hi_x, x);
      lo_y = std::min(lo_y, y);
      hi_y = std::max(hi_y, y);
    }
    if (lo_x > hi_x) break;
    const float extent = std::max((hi_x - lo_x) / 2, (hi_y - lo_y) / 2);
    if (extent <= 0) break;
    const float cx = (lo_x + hi_x) / 2, cy = (lo_y + hi_y) / 2;
    const float half_height_world = distance * std::tan(kFovy / 2);
    target += right * (cx * half_height_world * aspect) + up * (cy * half_height_world);
    distance *= extent / kFill;
  }
  if (snap && distance > 0 && std::isfinite(distance)) {
    // Snap the target to a grid and the distance up to it, the grid a power
    // of two between 1/128 and 1/64 of the distance: records that barely
    // change the framing give the very same camera bits, so they cause no
    // view change at all (every tiny move would flip the edges near the
    // tolerance all over the mesh). Depends on this mesh alone.
    const float step = std::exp2(std::floor(std::log2(distance / 128)));
    target = {std::round(target.x / step) * step, std::round(target.y / step) * step,
              std::round(target.z / step) * step};
    distance = std::ceil(distance / step) * step;
  }
  camera.target = target;
  camera.eye = target + dir * distance;
  return camera;
}

float facing_sign_of(const Mesh& mesh) {
  if (mesh.positions.empty()) return 1;
  const BoundingBox box = bounding_box(mesh);
  const Vec3f o = (box.min + box.max) * 0.5f;
  double volume = 0;
  for (const Triangle& t : mesh.triangles) {
    const Vec3f a = mesh.positions[t[0]] - o, b = mesh.positions[t[1]] - o,
                c = mesh.positions[t[2]] - o;
    volume += static_cast<double>(dot(a, cross(b, c)));
  }
  return volume < 0 ? -1.0f : 1.0f;
}

namespace asa {

ViewTest::ViewTest(const AsaView& view) {
  const AsaCamera& c = view.camera;
  eye_ = c.eye;
  forward_ = normalized(c.target - c.eye);
  camera_frame(forward_, right_, up_);
  const float aspect = static_cast<float>(c.width) / static_cast<float>(std::max(c.height, 1));
  const float tan_half = std::tan(c.fov_degrees * kDegrees / 2);
  tan_y_ = tan_half * (1 + view.frustum_margin);
  tan_x_ = tan_half * aspect * (1 + view.frustum_margin);
  // Distance from the plane x = z tan: (x - z tan) / sqrt(1 + tan^2).
  inv_x_ = 1.0f / std::sqrt(1 + tan_x_ * tan_x_);
  inv_y_ = 1.0f / std::sqrt(1 + tan_y_ * tan_y_);
  focal_px_ = static_cast<float>(c.height) / (2 * tan_half);
  tolerance_ = view.pixel_tolerance;
  backface_ = view.backface_margin;
  sign_ = view.facing_sign < 0 ? -1.0f : 1.0f;
  cull_ = view.cull_back_faces;
}

}  // namespace asa
}  // namespace meshstream

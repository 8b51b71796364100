// An orbit camera around a target point (Y up), and the little matrix math
// the renderer needs. Column-major 4x4 matrices, as OpenGL expects them.
#pragma once

#include <array>
#include <vector>

#include "common/asa/view.h"
#include "common/mesh/mesh.h"

namespace meshstream::client {

using Mat4 = std::array<float, 16>;  // column-major: m[col * 4 + row]

Mat4 mat4_multiply(const Mat4& a, const Mat4& b);
Mat4 mat4_perspective(float fovy_radians, float aspect, float z_near, float z_far);
Mat4 mat4_look_at(Vec3f eye, Vec3f target, Vec3f up);

class OrbitCamera {
 public:
  // Looks at the model's bounding sphere from the default three-quarter view
  // direction, then tightens the distance and target so the projection of
  // every vertex fills `fill` (0..1) of the smaller viewport side and is
  // centred. An empty mesh resets to the unit sphere. O(V) per refinement
  // round (three rounds).
  void frame(const Mesh& mesh, float aspect, float fill = 0.85f);

  // Looks from camera.eye at camera.target with its field of view (pitch
  // clamped as orbit() does; the image size is the caller's); the near and
  // far planes enclose `mesh`.
  void look_from(const AsaCamera& camera, const Mesh& mesh);
  // This camera for view-dependent ASA on a width x height image.
  AsaCamera asa_camera(int width, int height) const;

  // Mouse gestures in pixels of a viewport `height` pixels tall.
  void orbit(float dx_pixels, float dy_pixels);
  void pan(float dx_pixels, float dy_pixels, float viewport_height);
  void zoom(float wheel_steps);  // positive: closer

  Vec3f eye() const;
  Mat4 view() const;
  Mat4 projection(float aspect) const;
  float near_plane() const;  // the projection's near distance

  Vec3f target{0, 0, 0};
  float distance = 3;
  float yaw = 0.6f;     // radians around +Y
  float pitch = 0.35f;  // radians above the horizon
  float fovy = 0.6f;    // vertical field of view, radians
  float scene_radius = 1;

 private:
  Vec3f right() const;
  Vec3f up() const;
};

}  // namespace meshstream::client

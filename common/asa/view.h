// View-dependent ASA (docs/algorithms.md section 3.1): with a camera, an
// edge the flatness rule would refine is refined only where it matters on
// screen. The test looks at the edge alone (its two faces' normals and its
// bounding sphere), so both faces of an edge always agree, and the closure
// keeps the mesh conforming exactly as without a camera.
//
// An edge matters when all three hold:
//  * size: the projected diameter of its bounding sphere (centre the
//    midpoint, radius half its length) exceeds pixel_tolerance pixels, as
//    OpenSubdiv's adaptive tessellation measures an edge;
//  * frustum: the sphere touches the view frustum widened by frustum_margin
//    (a share of the half-extent on each side) and is not behind the eye;
//  * facing: not both faces turned away from the eye by more than
//    backface_margin (cosine); the silhouette band stays refined.
#pragma once

#include <cmath>
#include <string>

#include "common/base/result.h"
#include "common/mesh/mesh.h"

namespace meshstream {

// A pinhole camera on a width x height image, Y up unless the view is
// vertical (then Z is up).
struct AsaCamera {
  Vec3f eye{0, 0, 3};
  Vec3f target{0, 0, 0};
  float fov_degrees = 45;  // vertical field of view
  int width = 1024;
  int height = 768;
};

struct AsaView {
  bool enabled = false;  // false: today's whole-mesh ASA
  AsaCamera camera;
  float pixel_tolerance = 2;     // edges whose projected size is at or below this stay
  float frustum_margin = 0.15f;  // share of the half-view added on each side
  float backface_margin = 0.25f;
  bool cull_back_faces = true;
  // +1: faces are wound counter-clockwise seen from outside (the usual);
  // -1: the mesh winds them inward, so "facing away" flips. The caller sets
  // it for the whole mesh (facing_sign_of), so a region subdivided on its
  // own (incremental.h) judges faces as the whole mesh does.
  float facing_sign = 1;
};

// Usage checks for a camera given by a user: kInvalidArgument naming the
// problem (eye equal to target, field of view outside (0, 180), a size or a
// position that is not finite).
Status check_camera(const AsaCamera& camera);
Status check_view(const AsaView& view);

// "EX,EY,EZ,TX,TY,TZ[,FOV_DEG]" (fov default 45) into camera.eye, target
// and fov_degrees; width and height are left alone. kInvalidArgument naming
// the text when it is not 6 or 7 numbers or the camera is malformed.
Status parse_camera(const std::string& text, AsaCamera& camera);
// The --camera form of a camera; floats round-trip exactly (9 digits).
std::string format_camera(const AsaCamera& camera);

// The snapshot camera: the viewer's default framing of `mesh` (the
// three-quarter view OrbitCamera starts with, distance and target tightened
// so the projected vertices fill 85 % of the smaller image side), vertical
// field of view 0.6 rad. O(V) x 3. With `snap`, the target is rounded to a
// grid of about 1/100 of the distance and the distance up to it, so that
// meshes whose framing differs by less than that (a stream's consecutive
// records) get bit-identical cameras and view-dependent ASA redoes nothing
// for the camera.
AsaCamera fit_camera(const Mesh& mesh, int width, int height, bool snap = false);

// -1 when the mesh's faces enclose negative signed volume about its
// bounding-box centre (wound inward), else +1. O(F).
float facing_sign_of(const Mesh& mesh);

namespace asa {

// The per-edge test of an AsaView, with the camera's frame precomputed.
class ViewTest {
 public:
  explicit ViewTest(const AsaView& view);

  // The edge a-b, between faces with unit normals n1 and n2 (n2 = n1 on a
  // boundary), is worth splitting on screen.
  // False only when no edge of length at most `longest` whose midpoint
  // lies within `radius` of `centre` can matter (size or frustum; facing
  // is left to the edges): matters() would say false for every one of
  // them. Conservative by a margin above the tests' rounding, so a group
  // of edges (incremental.h's blocks) can be skipped at once.
  bool may_matter(Vec3f centre, float radius, float longest) const {
    const float h = 0.5f * longest;
    const Vec3f rel = centre - eye_;
    const float dist = length(rel);
    const float eps = 1e-5f * (dist + radius + h);  // far above float rounding of the terms
    const float reach = radius + h + eps;
    const float near = dist - reach;
    if (!(near > 0)) return true;
    if (longest * focal_px_ * 1.0001f <= tolerance_ * near) return false;
    const float z = dot(rel, forward_), x = dot(rel, right_), y = dot(rel, up_);
    if (z + reach < 0) return false;
    // The side distances are 1-Lipschitz: no midpoint is nearer by more
    // than the radius.
    if ((std::fabs(x) - z * tan_x_) * inv_x_ > reach) return false;
    if ((std::fabs(y) - z * tan_y_) * inv_y_ > reach) return false;
    return true;
  }

  bool matters(Vec3f a, Vec3f b, Vec3f n1, Vec3f n2) const {
    const Vec3f c{(a.x + b.x) * 0.5f, (a.y + b.y) * 0.5f, (a.z + b.z) * 0.5f};
    const float r = 0.5f * length(b - a);
    const Vec3f rel = c - eye_;
    const float dist = length(rel);
    if (dist <= r) return true;  // the eye is inside the sphere
    // Size: 2r pixels-per-unit at the sphere's nearest distance.
    if (2 * r * focal_px_ <= tolerance_ * (dist - r)) return false;
    // Frustum: the sphere against the four widened side planes, and not
    // wholly behind the eye.
    const float z = dot(rel, forward_), x = dot(rel, right_), y = dot(rel, up_);
    if (z < -r) return false;
    if ((std::fabs(x) - z * tan_x_) * inv_x_ > r) return false;
    if ((std::fabs(y) - z * tan_y_) * inv_y_ > r) return false;
    if (cull_) {
      // Facing: (eye - c) . n < -margin |eye - c| for both faces.
      const float limit = backface_ * dist;
      if (-dot(rel, n1) * sign_ < -limit && -dot(rel, n2) * sign_ < -limit) return false;
    }
    return true;
  }

 private:
  Vec3f eye_, forward_, right_, up_;
  float tan_x_ = 1, tan_y_ = 1, inv_x_ = 1, inv_y_ = 1;
  float focal_px_ = 1, tolerance_ = 2, backface_ = 0.25f, sign_ = 1;
  bool cull_ = true;
};

}  // namespace asa
}  // namespace meshstream

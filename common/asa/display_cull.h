// What the renderer needs of a display mesh for one camera: the faces that
// can show on screen, and a one-ring skirt around them so that the
// renderer's shading normals (crease_normals.h: averaged over each vertex's
// faces) are the same as for the whole mesh. The picture does not change:
//
//  * frustum: a face wholly outside one side plane of a square pyramid that
//    contains the view cone widened by `angle_degrees` (apex pulled back so
//    that it holds every eye within `eye_radius` of the camera's) is never
//    rasterized by any camera the cull is valid for;
//  * back faces: the renderer draws both sides (no GL_CULL_FACE, two-sided
//    lighting), so a back face of an open surface can be seen. A face is
//    left out only when it is hidden for certain: its component is closed
//    (every edge used as often in each direction; checked with a 64-bit
//    hash sum, so a false "closed" needs a hash collision), the eye is
//    outside the component's bounding box and the near plane cuts none of it,
//    and the face's plane passes the eye by more than `eye_radius` on its
//    inner side (inner: the side the component's signed volume says). A
//    ray from such an eye enters the solid through a front face first.
//    Self-intersecting closed meshes (inside-out pockets) are the case the
//    argument does not cover.
//
// A cull is valid for any camera whose eye lies within eye_radius of the
// cull's, whose view cone lies in the widened cone, and whose near plane is
// nearer than near_limit (valid_for): the viewer checks before each frame
// and culls again when its camera has left.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "common/asa/subdivide.h"
#include "common/asa/view.h"
#include "common/mesh/mesh.h"

namespace meshstream {

struct CullMargins {
  float angle_degrees = 8.0f;  // added to the view cone's half-angle
  float eye_share = 0.1f;      // eye_radius = this x the camera's eye-target distance
};

// Per closed component facts of one display mesh, reused by every cull of
// that mesh (the viewer culls the frame's mesh again as its camera moves).
struct DisplayTopology {
  std::vector<uint32_t> face_component;  // per face; kOpen: not closed (or no volume)
  struct Component {
    BoundingBox box;
    float sign = 1;  // +1: outward normals wound counter-clockwise
  };
  std::vector<Component> closed;  // indexed by face_component
  static constexpr uint32_t kOpen = 0xFFFFFFFFu;
};

// O(V + F) (a union-find over the vertices, three passes over the faces).
std::shared_ptr<const DisplayTopology> analyze_display_topology(const Mesh& mesh);

struct CullRegion {
  bool everything = true;  // nothing was left out: valid for any camera
  Vec3f eye{};
  float eye_radius = 0;
  Vec3f apex{}, axis{0, 0, -1};  // the widened cone
  float cone_half_angle = 0;     // radians
  float near_limit = 0;          // a near plane at or beyond this may cut a culled solid
};

struct CulledDisplay {
  std::shared_ptr<const Mesh> mesh;                        // what the renderer draws
  std::shared_ptr<const std::vector<FaceKind>> face_kind;  // per face of `mesh`; may be null
  CullRegion region;
  uint32_t visible_faces = 0;  // before the skirt
  uint32_t frustum_culled = 0, back_culled = 0;
};

// The faces of `mesh` the camera (and any camera within the margins) can
// see, plus their skirt, with the vertices they use renumbered in order and
// every attribute carried (per vertex, per corner, face materials, extra
// attributes; materials and textures shared). `near_plane`: the renderer's
// near distance for this camera (0: it encloses the mesh, as the snapshot's
// does). When nothing would be left out, `mesh` is returned as is. O(V + F).
CulledDisplay cull_display(const std::shared_ptr<const Mesh>& mesh,
                           const std::shared_ptr<const std::vector<FaceKind>>& face_kind,
                           const DisplayTopology& topology, const AsaCamera& camera,
                           float near_plane = 0, const CullMargins& margins = {});

// The cull shows every face `camera` (near plane at `near_plane`) can see.
bool cull_valid_for(const CullRegion& region, const AsaCamera& camera, float near_plane);

}  // namespace meshstream

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
//    left out only when it is hidden for certain: its component bounds a
//    solid once its holes are capped (SourceTopology), the eye is outside
//    the component's bounding box and the near plane cuts none of it, the
//    face's plane passes the eye by more than `eye_radius` on its inner side
//    (inner: the side the component's signed volume says), and no line from
//    an eye within eye_radius through one of the component's hole balls
//    comes near the face. A ray from such an eye enters the solid through a
//    front face or a cap first; through a front face, the back face behind
//    it is hidden. Self-intersecting meshes (inside-out pockets, a cap
//    cutting the surface) are what the argument does not cover.
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
  // eye_radius = this x the camera's eye-target distance. Every hole's cone
  // widens with it (on the 107-hole dragon_res2, 0.1 kept 98 % of the
  // display, 0.03 82 %, 0.01 70 %), while the window culls again when its
  // eye has moved this far (0.6 degrees of orbit at 0.01: an orbit of a
  // degree or more a frame culls again each frame whatever this is).
  float eye_share = 0.01f;
};

// Per component facts of a manifold source mesh (the decoded mesh ASA
// refines; a display mesh keeps its vertices' indices): which components
// bound a solid once each boundary loop is capped by a fan from its centroid,
// which way they wind, and their holes (a ball around each loop, widened by
// twice its longest edge so that it holds the loop ASA's boundary rules
// make of it). A component with an edge used twice the same way, a boundary
// vertex on two loops, or (nearly) no volume is unusable.
struct SourceTopology {
  static constexpr uint32_t kNone = 0xFFFFFFFFu;
  std::vector<uint32_t> vertex_component;  // per source vertex
  struct Hole {
    Vec3f centre;
    float radius = 0;
  };
  struct Component {
    bool usable = false;
    float sign = 1;  // +1: outward normals wound counter-clockwise
    uint32_t first_hole = 0, holes = 0;
  };
  std::vector<Component> components;
  std::vector<Hole> holes;  // by component
};

// O(V + F): a union-find over the vertices, the directed edges per vertex.
std::shared_ptr<const SourceTopology> analyze_source_topology(const Mesh& source);

// The same per face of a display mesh made from that source (its first
// vertices are the source's), reused by every cull of that mesh (the viewer
// culls the frame's mesh again as its camera moves).
struct DisplayTopology {
  static constexpr uint32_t kOpen = 0xFFFFFFFFu;
  std::vector<uint32_t> face_component;  // per face; kOpen: no solid to hide behind
  struct Component {
    BoundingBox box;  // of the display's vertices
    float sign = 1;
    uint32_t first_hole = 0, holes = 0;
  };
  std::vector<Component> closed;  // indexed by face_component
  std::vector<SourceTopology::Hole> holes;
};

// O(V + F) of the display (a few passes giving each new vertex the
// component of a face it shares with an old one).
std::shared_ptr<const DisplayTopology> analyze_display_topology(const Mesh& display,
                                                                const SourceTopology& source);
// A mesh that is its own source.
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

// The one renderer behind the window and the off-screen snapshots: indexed
// triangles with smooth per-vertex normals, a single-pass wireframe overlay
// (a geometry shader gives every fragment its window-space distance to the
// triangle's edges; Bærentzen, Nielsen, Gjøl, Larsen, "Two methods for
// antialiased wireframe drawing with hidden line removal", SCCG 2008) and
// three colour modes. Per-face labels (what ASA did) live in a texture
// buffer indexed by gl_PrimitiveID, so vertices are never duplicated.
//
// Every method needs the GL context the renderer was created in to be
// current on the calling thread.
#pragma once

#include <cstdint>
#include <vector>

#include "client/viewer/camera.h"
#include "client/viewer/gl_functions.h"
#include "common/asa/subdivide.h"
#include "common/base/result.h"
#include "common/mesh/mesh.h"

namespace meshstream::client {

enum class ColorMode : int {
  kShaded = 0,    // one material colour, lit
  kAsaKinds = 1,  // untouched grey-blue, ASA target orange, bisected (closure) green
  kDistance = 2,  // per-vertex distance ramp, blue (0) to red (distance_max)
};

struct RenderStyle {
  ColorMode coloring = ColorMode::kShaded;
  bool wireframe = false;
  float wire_width_px = 1.0f;
  float distance_max = 1.0f;  // the distance shown in full red
  Vec3f background{0.16f, 0.17f, 0.19f};
};

class MeshRenderer {
 public:
  // Compiles the shaders. kUnsupported with the compiler log when the
  // context cannot (e.g. no geometry shaders). Cost: a shader compile.
  static Result<MeshRenderer> create(const GlFunctions& gl);

  MeshRenderer() = default;
  MeshRenderer(MeshRenderer&& other) noexcept;
  MeshRenderer& operator=(MeshRenderer&& other) noexcept;
  MeshRenderer(const MeshRenderer&) = delete;
  MeshRenderer& operator=(const MeshRenderer&) = delete;
  ~MeshRenderer();  // frees the GL objects (context must be current)

  // Replaces the drawn mesh: sends positions, normals (the mesh's own when it
  // has one per vertex, else area-weighted ones computed here) and indices to
  // the GPU (O(V + F), one copy each).
  // `face_kind` (may be null or of the wrong size: then every face shows as
  // untouched) labels each face. Distances are reset to zero. Precondition:
  // indices in range (validate untrusted meshes first).
  void upload(const Mesh& mesh, const std::vector<FaceKind>* face_kind);

  // Per-vertex distances for ColorMode::kDistance; ignored unless the size
  // equals the uploaded vertex count. O(V).
  void upload_distances(const std::vector<float>& distances);

  // Clears the bound framebuffer (colour and depth) to the style's
  // background and draws the mesh into a `width` x `height` viewport.
  void draw(const OrbitCamera& camera, int width, int height, const RenderStyle& style) const;

  uint32_t vertex_count() const { return vertex_count_; }
  uint32_t triangle_count() const { return triangle_count_; }
  bool has_distances() const { return has_distances_; }

 private:
  void release();

  GlFunctions gl_{};
  bool created_ = false;
  GLuint program_ = 0;
  GLuint vao_ = 0;
  GLuint position_buffer_ = 0, normal_buffer_ = 0, distance_buffer_ = 0, index_buffer_ = 0;
  GLuint face_kind_buffer_ = 0, face_kind_texture_ = 0;
  uint32_t vertex_count_ = 0, triangle_count_ = 0;
  bool has_distances_ = false;
  struct Uniforms {
    GLint view = -1, projection = -1, viewport = -1, coloring = -1, wireframe = -1, wire_width = -1,
          distance_max = -1, face_kind = -1;
  } uniforms_;
};

}  // namespace meshstream::client

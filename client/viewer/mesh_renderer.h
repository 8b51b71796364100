// The one renderer behind the window and the off-screen snapshots: indexed
// triangles with per-vertex normals split at creases (crease_normals.h, so
// machined parts keep their sharp edges), a single-pass wireframe overlay
// (a geometry shader gives every fragment its window-space distance to the
// triangle's edges; Bærentzen, Nielsen, Gjøl, Larsen, "Two methods for
// antialiased wireframe drawing with hidden line removal", SCCG 2008) and
// three colour modes. Per-face labels (what ASA did) live in a texture
// buffer indexed by gl_PrimitiveID (the split keeps every face's index), so
// vertices are duplicated only where a crease needs two normals.
//
// Every method needs the GL context the renderer was created in to be
// current on the calling thread.
#pragma once

#include <cstdint>
#include <vector>

#include "client/viewer/camera.h"
#include "client/viewer/crease_normals.h"
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

// How ColorMode::kShaded shows a mesh with colours or a texture.
enum class SurfaceMode : int {
  kLit = 0,        // base colour x texture, lit
  kBaseColor = 1,  // the vertex / material colour alone, unlit
  kTexture = 2,    // the texture alone, unlit
};

struct RenderStyle {
  ColorMode coloring = ColorMode::kShaded;
  SurfaceMode surface = SurfaceMode::kLit;
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

  // Replaces the drawn mesh: sends positions, normals and indices to the GPU.
  // Normals are split where two faces bend more than `crease_degrees` apart
  // (<= 0: kDefaultShadingCreaseDegrees; see split_normals_at_creases: the
  // mesh's own normals are kept where nothing splits). O(V + F log d), one
  // copy of each array.
  // `face_kind` (may be null or of the wrong size: then every face shows as
  // untouched) labels each face. Distances are reset to zero. Precondition:
  // indices in range (validate untrusted meshes first).
  void upload(const Mesh& mesh, const std::vector<FaceKind>* face_kind,
              float crease_degrees = 0.0f);

  // Colours and textures (ColorMode::kShaded): per-vertex or per-corner
  // colours times the material's base colour factor, per-vertex or
  // per-corner texture coordinates, and each face's material's base colour
  // texture: faces are drawn in groups, one draw call per texture (faces
  // whose material has none in a group without), each image decoded with
  // stb_image and kept while its bytes stay the same. With any per-corner
  // attribute or several materials every corner gets its own drawn vertex.
  // has_texture: some face shows a texture; texture_groups: the draw calls.
  // O(F) to group the faces.
  bool has_colors() const { return has_colors_; }
  bool has_texture() const { return has_texture_; }
  size_t texture_groups() const { return groups_.size(); }

  // Per-vertex distances for ColorMode::kDistance; ignored unless the size
  // equals the uploaded mesh's vertex count (copies made at creases take
  // their vertex's distance). O(V).
  void upload_distances(const std::vector<float>& distances);

  // Clears the bound framebuffer (colour and depth) to the style's
  // background and draws the mesh into a `width` x `height` viewport.
  void draw(const OrbitCamera& camera, int width, int height, const RenderStyle& style) const;

  uint32_t vertex_count() const { return vertex_count_; }  // of the uploaded mesh
  uint32_t drawn_vertex_count() const {
    return corner_vertex_.empty() ? vertex_count_ + uint32_t(copied_from_.size())
                                  : uint32_t(corner_vertex_.size());
  }
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
  GLuint color_buffer_ = 0, uv_buffer_ = 0;
  bool has_colors_ = false, has_texture_ = false;
  // One GL texture per mesh texture (by index), with the hash of the bytes
  // it holds (0: none or an image that does not decode).
  struct GpuTexture {
    GLuint id = 0;
    uint64_t key = 0;
  };
  std::vector<GpuTexture> textures_;
  // Consecutive faces of the index buffer (faces sorted by the texture they
  // show) drawn with one texture; texture -1: none.
  struct DrawGroup {
    uint32_t first_face = 0, faces = 0;
    int32_t texture = -1;
  };
  std::vector<DrawGroup> groups_;
  // Per drawn vertex, the mesh vertex it shows, when corners are drawn
  // apart (empty otherwise: the drawn vertices are the mesh's, then the
  // crease copies).
  std::vector<uint32_t> corner_vertex_;
  // Decodes texture t of `mesh` into textures_[t] unless its bytes are
  // already there; whether it holds an image.
  bool upload_texture(const Mesh& mesh, size_t t);
  uint32_t vertex_count_ = 0, triangle_count_ = 0;
  std::vector<uint32_t> copied_from_;  // the vertex each crease copy repeats
  bool has_distances_ = false;
  struct Uniforms {
    GLint view = -1, projection = -1, viewport = -1, coloring = -1, wireframe = -1, wire_width = -1,
          distance_max = -1, face_kind = -1, has_color = -1, has_texture = -1, surface = -1,
          base_texture = -1, first_face = -1;
  } uniforms_;
};

}  // namespace meshstream::client

#include "client/viewer/mesh_renderer.h"

#include <stb_image.h>

#include <algorithm>
#include <cstring>
#include <memory>
#include <string>
#include <utility>

#include "client/viewer/mesh_shaders.h"

namespace meshstream::client {
namespace {

Result<GLuint> compile(const GlFunctions& gl, GLenum type, const char* source, const char* what) {
  GLuint shader = gl.CreateShader(type);
  gl.ShaderSource(shader, 1, &source, nullptr);
  gl.CompileShader(shader);
  GLint ok = 0;
  gl.GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    gl.GetShaderInfoLog(shader, sizeof log, nullptr, log);
    gl.DeleteShader(shader);
    return make_error(ErrorCode::kUnsupported,
                      std::string("the ") + what + " shader does not compile: " + log);
  }
  return shader;
}

// FNV-1a over the bytes and their count: whether a texture changed.
uint64_t bytes_key(const std::vector<uint8_t>& bytes) {
  uint64_t h = 1469598103934665603ull ^ bytes.size();
  for (uint8_t b : bytes) h = (h ^ b) * 1099511628211ull;
  return h | 1;  // never 0 (0: no texture)
}

// The texture face f shows: the base colour texture of its material (of
// material 0 when faces have none), else texture 0 when there is no
// material; -1 for none or an index out of range.
int32_t face_texture(const Mesh& mesh, uint32_t f) {
  int32_t t = -1;
  if (!mesh.materials.empty()) {
    uint32_t m = f < mesh.face_materials.size() ? mesh.face_materials[f] : 0;
    if (m < mesh.materials.size()) t = mesh.materials[m].base_color_texture;
  } else if (!mesh.textures.empty()) {
    t = 0;
  }
  return t >= 0 && size_t(t) < mesh.textures.size() ? t : -1;
}

// The material colour factor of face f (white without materials).
Vec4f material_color(const Mesh& mesh, uint32_t f) {
  if (mesh.materials.empty()) return {1, 1, 1, 1};
  uint32_t m = f < mesh.face_materials.size() ? mesh.face_materials[f] : 0;
  return m < mesh.materials.size() ? mesh.materials[m].base_color : Vec4f{1, 1, 1, 1};
}

Vec4f times(Vec4f a, Vec4f b) { return {a.x * b.x, a.y * b.y, a.z * b.z, a.w * b.w}; }

}  // namespace

Result<MeshRenderer> MeshRenderer::create(const GlFunctions& gl) {
  MeshRenderer r;
  r.gl_ = gl;
  auto vs = compile(gl, GL_VERTEX_SHADER, shaders::kVertex, "vertex");
  if (!vs) return tl::unexpected(vs.error());
  auto gs = compile(gl, GL_GEOMETRY_SHADER, shaders::kGeometry, "geometry");
  if (!gs) {
    gl.DeleteShader(*vs);
    return tl::unexpected(gs.error());
  }
  auto fs = compile(gl, GL_FRAGMENT_SHADER, shaders::kFragment, "fragment");
  if (!fs) {
    gl.DeleteShader(*vs);
    gl.DeleteShader(*gs);
    return tl::unexpected(fs.error());
  }
  GLuint program = gl.CreateProgram();
  gl.AttachShader(program, *vs);
  gl.AttachShader(program, *gs);
  gl.AttachShader(program, *fs);
  gl.LinkProgram(program);
  gl.DeleteShader(*vs);
  gl.DeleteShader(*gs);
  gl.DeleteShader(*fs);
  GLint ok = 0;
  gl.GetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    gl.GetProgramInfoLog(program, sizeof log, nullptr, log);
    gl.DeleteProgram(program);
    return make_error(ErrorCode::kUnsupported, std::string("the shaders do not link: ") + log);
  }
  r.program_ = program;
  r.created_ = true;
  Uniforms& u = r.uniforms_;
  u.view = gl.GetUniformLocation(program, "u_view");
  u.projection = gl.GetUniformLocation(program, "u_projection");
  u.viewport = gl.GetUniformLocation(program, "u_viewport");
  u.coloring = gl.GetUniformLocation(program, "u_coloring");
  u.wireframe = gl.GetUniformLocation(program, "u_wireframe");
  u.wire_width = gl.GetUniformLocation(program, "u_wire_width");
  u.distance_max = gl.GetUniformLocation(program, "u_distance_max");
  u.face_kind = gl.GetUniformLocation(program, "u_face_kind");
  u.has_color = gl.GetUniformLocation(program, "u_has_color");
  u.has_texture = gl.GetUniformLocation(program, "u_has_texture");
  u.surface = gl.GetUniformLocation(program, "u_surface");
  u.base_texture = gl.GetUniformLocation(program, "u_base_texture");
  u.first_face = gl.GetUniformLocation(program, "u_first_face");

  gl.GenVertexArrays(1, &r.vao_);
  GLuint buffers[7];
  gl.GenBuffers(7, buffers);
  r.position_buffer_ = buffers[0];
  r.normal_buffer_ = buffers[1];
  r.distance_buffer_ = buffers[2];
  r.index_buffer_ = buffers[3];
  r.face_kind_buffer_ = buffers[4];
  r.color_buffer_ = buffers[5];
  r.uv_buffer_ = buffers[6];
  gl.GenTextures(1, &r.face_kind_texture_);

  gl.BindVertexArray(r.vao_);
  const GLuint per_vertex[5] = {r.position_buffer_, r.normal_buffer_, r.distance_buffer_,
                                r.color_buffer_, r.uv_buffer_};
  const GLint sizes[5] = {3, 3, 1, 4, 2};
  for (GLuint i = 0; i < 5; ++i) {
    gl.BindBuffer(GL_ARRAY_BUFFER, per_vertex[i]);
    gl.EnableVertexAttribArray(i);
    gl.VertexAttribPointer(i, sizes[i], GL_FLOAT, GL_FALSE, 0, nullptr);
  }
  gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, r.index_buffer_);  // recorded in the VAO
  gl.BindVertexArray(0);
  gl.BindBuffer(GL_ARRAY_BUFFER, 0);
  return r;
}

MeshRenderer::MeshRenderer(MeshRenderer&& other) noexcept { *this = std::move(other); }

MeshRenderer& MeshRenderer::operator=(MeshRenderer&& other) noexcept {
  if (this != &other) {
    release();
    gl_ = other.gl_;
    created_ = std::exchange(other.created_, false);
    program_ = other.program_;
    vao_ = other.vao_;
    position_buffer_ = other.position_buffer_;
    normal_buffer_ = other.normal_buffer_;
    distance_buffer_ = other.distance_buffer_;
    index_buffer_ = other.index_buffer_;
    face_kind_buffer_ = other.face_kind_buffer_;
    face_kind_texture_ = other.face_kind_texture_;
    color_buffer_ = other.color_buffer_;
    uv_buffer_ = other.uv_buffer_;
    textures_ = std::move(other.textures_);
    groups_ = std::move(other.groups_);
    has_colors_ = other.has_colors_;
    has_texture_ = other.has_texture_;
    corner_vertex_ = std::move(other.corner_vertex_);
    vertex_count_ = other.vertex_count_;
    copied_from_ = std::move(other.copied_from_);
    triangle_count_ = other.triangle_count_;
    has_distances_ = other.has_distances_;
    uniforms_ = other.uniforms_;
  }
  return *this;
}

MeshRenderer::~MeshRenderer() { release(); }

void MeshRenderer::release() {
  if (!created_) return;
  created_ = false;
  GLuint buffers[7] = {position_buffer_,  normal_buffer_, distance_buffer_, index_buffer_,
                       face_kind_buffer_, color_buffer_,  uv_buffer_};
  gl_.DeleteBuffers(7, buffers);
  gl_.DeleteTextures(1, &face_kind_texture_);
  for (const GpuTexture& t : textures_) gl_.DeleteTextures(1, &t.id);
  textures_.clear();
  gl_.DeleteVertexArrays(1, &vao_);
  gl_.DeleteProgram(program_);
}

void MeshRenderer::upload(const Mesh& mesh, const std::vector<FaceKind>* face_kind,
                          float crease_degrees) {
  vertex_count_ = mesh.vertex_count();
  triangle_count_ = mesh.face_count();
  ShadingMesh shading = split_normals_at_creases(mesh, shading_crease_degrees(crease_degrees));
  copied_from_ = std::move(shading.copied_from);
  auto send = [&](GLenum target, GLuint buffer, size_t bytes, const void* data) {
    gl_.BindBuffer(target, buffer);
    gl_.BufferData(target, static_cast<GLsizeiptr>(bytes), data, GL_STATIC_DRAW);
  };
  const uint32_t F = mesh.face_count();
  const bool per_corner = !mesh.corner_colors.empty() || !mesh.corner_texcoords.empty() ||
                          !mesh.corner_normals.empty() || mesh.materials.size() > 1;
  const bool colors =
      !mesh.colors.empty() || !mesh.corner_colors.empty() || !mesh.materials.empty();
  std::vector<Vec4f> drawn_colors;
  std::vector<Vec2f> drawn_uvs;
  corner_vertex_.clear();
  if (per_corner) {
    // Every corner its own drawn vertex: positions and crease normals of
    // its (split) vertex, its own colour, texture coordinate and normal.
    std::vector<Vec3f> positions(3 * size_t(F)), normals(3 * size_t(F));
    drawn_colors.assign(3 * size_t(F), Vec4f{1, 1, 1, 1});
    drawn_uvs.assign(3 * size_t(F), Vec2f{0, 0});
    corner_vertex_.resize(3 * size_t(F));
    for (uint32_t f = 0; f < F; ++f) {
      const Vec4f factor = material_color(mesh, f);
      for (int k = 0; k < 3; ++k) {
        const size_t c = 3 * size_t(f) + k;
        const uint32_t v = mesh.triangles[f][k];
        const uint32_t drawn = shading.triangles[f][k];
        corner_vertex_[c] = v;
        positions[c] = shading.positions[drawn];
        normals[c] = mesh.corner_normals.empty() ? shading.normals[drawn]
                                                 : normalized(mesh.corner_normals.at_corner(c));
        Vec4f color = !mesh.corner_colors.empty() ? mesh.corner_colors.at_corner(c)
                      : !mesh.colors.empty()      ? mesh.colors[v]
                                                  : Vec4f{1, 1, 1, 1};
        drawn_colors[c] = times(color, factor);
        if (!mesh.corner_texcoords.empty())
          drawn_uvs[c] = mesh.corner_texcoords.at_corner(c);
        else if (!mesh.texcoords.empty())
          drawn_uvs[c] = mesh.texcoords[v];
      }
    }
    shading.positions = std::move(positions);
    shading.normals = std::move(normals);
    for (uint32_t f = 0; f < F; ++f) shading.triangles[f] = {3 * f, 3 * f + 1, 3 * f + 2};
  } else {
    // The mesh's vertices, then the crease copies, each with its vertex's values.
    const Vec4f factor = material_color(mesh, 0);
    const size_t n = shading.positions.size();
    drawn_colors.assign(n, factor);
    drawn_uvs.assign(n, Vec2f{0, 0});
    auto source = [&](size_t i) {
      return i < vertex_count_ ? uint32_t(i) : copied_from_[i - vertex_count_];
    };
    for (size_t i = 0; i < n; ++i) {
      const uint32_t v = source(i);
      if (!mesh.colors.empty()) drawn_colors[i] = times(mesh.colors[v], factor);
      if (!mesh.texcoords.empty()) drawn_uvs[i] = mesh.texcoords[v];
    }
  }
  has_colors_ = colors;
  send(GL_ARRAY_BUFFER, position_buffer_, shading.positions.size() * sizeof(Vec3f),
       shading.positions.data());
  send(GL_ARRAY_BUFFER, normal_buffer_, shading.normals.size() * sizeof(Vec3f),
       shading.normals.data());
  send(GL_ARRAY_BUFFER, color_buffer_, drawn_colors.size() * sizeof(Vec4f), drawn_colors.data());
  send(GL_ARRAY_BUFFER, uv_buffer_, drawn_uvs.size() * sizeof(Vec2f), drawn_uvs.data());
  // Faces grouped by the texture they show (stable: each group keeps the
  // mesh's face order), one draw call per group.
  const bool uvs = !mesh.texcoords.empty() || !mesh.corner_texcoords.empty();
  std::vector<int32_t> shown(F, -1);
  if (uvs) {
    std::vector<int8_t> decoded(mesh.textures.size(), -1);  // -1 not tried, 0 no, 1 yes
    for (uint32_t f = 0; f < F; ++f) {
      const int32_t t = face_texture(mesh, f);
      if (t < 0) continue;
      if (decoded[size_t(t)] < 0) decoded[size_t(t)] = upload_texture(mesh, size_t(t)) ? 1 : 0;
      if (decoded[size_t(t)] == 1) shown[f] = t;
    }
  }
  std::vector<uint32_t> order(F);
  for (uint32_t f = 0; f < F; ++f) order[f] = f;
  std::stable_sort(order.begin(), order.end(),
                   [&](uint32_t a, uint32_t b) { return shown[a] < shown[b]; });
  groups_.clear();
  has_texture_ = false;
  for (uint32_t i = 0; i < F; ++i) {
    const int32_t t = shown[order[i]];
    if (groups_.empty() || groups_.back().texture != t) groups_.push_back({i, 0, t});
    ++groups_.back().faces;
    has_texture_ = has_texture_ || t >= 0;
  }
  std::vector<Triangle> drawn_triangles(F);
  for (uint32_t i = 0; i < F; ++i) drawn_triangles[i] = shading.triangles[order[i]];
  std::vector<float> zeros(shading.positions.size(), 0.0f);
  send(GL_ARRAY_BUFFER, distance_buffer_, zeros.size() * sizeof(float), zeros.data());
  has_distances_ = false;
  gl_.BindBuffer(GL_ARRAY_BUFFER, 0);
  gl_.BindVertexArray(vao_);
  send(GL_ELEMENT_ARRAY_BUFFER, index_buffer_, drawn_triangles.size() * sizeof(Triangle),
       drawn_triangles.data());
  gl_.BindVertexArray(0);

  // A texture buffer may not be empty on every driver: keep at least one texel.
  std::vector<uint8_t> kinds(std::max<size_t>(triangle_count_, 1), 0);
  if (face_kind != nullptr && face_kind->size() == triangle_count_) {
    // In drawn order: the shader reads the label at u_first_face + primitive.
    for (size_t i = 0; i < face_kind->size(); ++i)
      kinds[i] = static_cast<uint8_t>((*face_kind)[order[i]]);
  }
  send(GL_TEXTURE_BUFFER, face_kind_buffer_, kinds.size(), kinds.data());
  gl_.BindTexture(GL_TEXTURE_BUFFER, face_kind_texture_);
  gl_.TexBuffer(GL_TEXTURE_BUFFER, GL_R8UI, face_kind_buffer_);
  gl_.BindTexture(GL_TEXTURE_BUFFER, 0);
  gl_.BindBuffer(GL_TEXTURE_BUFFER, 0);
}

bool MeshRenderer::upload_texture(const Mesh& mesh, size_t t) {
  if (textures_.size() < mesh.textures.size()) textures_.resize(mesh.textures.size());
  GpuTexture& gpu = textures_[t];
  const std::vector<uint8_t>& bytes = mesh.textures[t].bytes;
  const uint64_t key = bytes_key(bytes);
  if (key == gpu.key) return true;
  int w = 0, h = 0, n = 0;
  std::unique_ptr<uint8_t, void (*)(void*)> pixels(
      bytes.size() < size_t(INT32_MAX)
          ? stbi_load_from_memory(bytes.data(), int(bytes.size()), &w, &h, &n, 4)
          : nullptr,
      stbi_image_free);
  // An image that does not decode shows untextured (the decoder has
  // checked its headers; a broken body is the only way here).
  gpu.key = pixels ? key : 0;
  if (!pixels) return false;
  if (gpu.id == 0) gl_.GenTextures(1, &gpu.id);
  // Rows top first in the file, texture coordinate v = 0 at the bottom
  // (glTF's v points down: its importers flip v when they read it).
  gl_.BindTexture(GL_TEXTURE_2D, gpu.id);
  gl_.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
  std::vector<uint8_t> flipped(size_t(w) * h * 4);
  for (int y = 0; y < h; ++y)
    std::memcpy(&flipped[size_t(h - 1 - y) * w * 4], pixels.get() + size_t(y) * w * 4,
                size_t(w) * 4);
  gl_.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_RGBA, GL_UNSIGNED_BYTE, flipped.data());
  gl_.GenerateMipmap(GL_TEXTURE_2D);
  gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
  gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
  gl_.BindTexture(GL_TEXTURE_2D, 0);
  return true;
}

void MeshRenderer::upload_distances(const std::vector<float>& distances) {
  if (distances.size() != vertex_count_) return;
  std::vector<float> drawn;
  if (!corner_vertex_.empty()) {
    drawn.resize(corner_vertex_.size());
    for (size_t i = 0; i < drawn.size(); ++i) drawn[i] = distances[corner_vertex_[i]];
  } else {
    drawn.reserve(distances.size() + copied_from_.size());
    drawn.assign(distances.begin(), distances.end());
    for (uint32_t v : copied_from_) drawn.push_back(distances[v]);
  }
  gl_.BindBuffer(GL_ARRAY_BUFFER, distance_buffer_);
  gl_.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(drawn.size() * sizeof(float)),
                 drawn.data(), GL_STATIC_DRAW);
  gl_.BindBuffer(GL_ARRAY_BUFFER, 0);
  has_distances_ = true;
}

void MeshRenderer::draw(const OrbitCamera& camera, int width, int height,
                        const RenderStyle& style) const {
  gl_.Viewport(0, 0, width, height);
  gl_.ClearColor(style.background.x, style.background.y, style.background.z, 1.0f);
  gl_.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  if (!created_ || triangle_count_ == 0 || width <= 0 || height <= 0) return;
  gl_.Enable(GL_DEPTH_TEST);
  gl_.DepthFunc(GL_LESS);
  gl_.Disable(GL_CULL_FACE);
  gl_.Disable(GL_BLEND);
  gl_.UseProgram(program_);
  float aspect = static_cast<float>(width) / static_cast<float>(height);
  Mat4 view = camera.view();
  Mat4 projection = camera.projection(aspect);
  gl_.UniformMatrix4fv(uniforms_.view, 1, GL_FALSE, view.data());
  gl_.UniformMatrix4fv(uniforms_.projection, 1, GL_FALSE, projection.data());
  gl_.Uniform2f(uniforms_.viewport, static_cast<float>(width), static_cast<float>(height));
  gl_.Uniform1i(uniforms_.coloring, static_cast<int>(style.coloring));
  gl_.Uniform1i(uniforms_.wireframe, style.wireframe ? 1 : 0);
  gl_.Uniform1f(uniforms_.wire_width, style.wire_width_px);
  gl_.Uniform1f(uniforms_.distance_max, style.distance_max);
  gl_.ActiveTexture(GL_TEXTURE0);
  gl_.BindTexture(GL_TEXTURE_BUFFER, face_kind_texture_);
  gl_.Uniform1i(uniforms_.face_kind, 0);
  gl_.Uniform1i(uniforms_.has_color, has_colors_ ? 1 : 0);
  gl_.Uniform1i(uniforms_.surface, static_cast<int>(style.surface));
  gl_.Uniform1i(uniforms_.base_texture, 1);
  gl_.BindVertexArray(vao_);
  for (const DrawGroup& g : groups_) {
    const bool textured = g.texture >= 0;
    gl_.Uniform1i(uniforms_.has_texture, textured ? 1 : 0);
    gl_.Uniform1i(uniforms_.first_face, static_cast<GLint>(g.first_face));
    gl_.ActiveTexture(GL_TEXTURE1);
    gl_.BindTexture(GL_TEXTURE_2D, textured ? textures_[size_t(g.texture)].id : 0);
    gl_.ActiveTexture(GL_TEXTURE0);
    gl_.DrawElements(GL_TRIANGLES, static_cast<GLsizei>(g.faces * 3), GL_UNSIGNED_INT,
                     reinterpret_cast<const void*>(size_t(g.first_face) * sizeof(Triangle)));
  }
  gl_.BindVertexArray(0);
  gl_.BindTexture(GL_TEXTURE_BUFFER, 0);
  gl_.ActiveTexture(GL_TEXTURE1);
  gl_.BindTexture(GL_TEXTURE_2D, 0);
  gl_.ActiveTexture(GL_TEXTURE0);
  gl_.UseProgram(0);
  gl_.Disable(GL_DEPTH_TEST);
}

}  // namespace meshstream::client

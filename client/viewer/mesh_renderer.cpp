#include "client/viewer/mesh_renderer.h"

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

  gl.GenVertexArrays(1, &r.vao_);
  GLuint buffers[5];
  gl.GenBuffers(5, buffers);
  r.position_buffer_ = buffers[0];
  r.normal_buffer_ = buffers[1];
  r.distance_buffer_ = buffers[2];
  r.index_buffer_ = buffers[3];
  r.face_kind_buffer_ = buffers[4];
  gl.GenTextures(1, &r.face_kind_texture_);

  gl.BindVertexArray(r.vao_);
  const GLuint per_vertex[3] = {r.position_buffer_, r.normal_buffer_, r.distance_buffer_};
  const GLint sizes[3] = {3, 3, 1};
  for (GLuint i = 0; i < 3; ++i) {
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
  GLuint buffers[5] = {position_buffer_, normal_buffer_, distance_buffer_, index_buffer_,
                       face_kind_buffer_};
  gl_.DeleteBuffers(5, buffers);
  gl_.DeleteTextures(1, &face_kind_texture_);
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
  send(GL_ARRAY_BUFFER, position_buffer_, shading.positions.size() * sizeof(Vec3f),
       shading.positions.data());
  send(GL_ARRAY_BUFFER, normal_buffer_, shading.normals.size() * sizeof(Vec3f),
       shading.normals.data());
  std::vector<float> zeros(shading.positions.size(), 0.0f);
  send(GL_ARRAY_BUFFER, distance_buffer_, zeros.size() * sizeof(float), zeros.data());
  has_distances_ = false;
  gl_.BindBuffer(GL_ARRAY_BUFFER, 0);
  gl_.BindVertexArray(vao_);
  send(GL_ELEMENT_ARRAY_BUFFER, index_buffer_, shading.triangles.size() * sizeof(Triangle),
       shading.triangles.data());
  gl_.BindVertexArray(0);

  // A texture buffer may not be empty on every driver: keep at least one texel.
  std::vector<uint8_t> kinds(std::max<size_t>(triangle_count_, 1), 0);
  if (face_kind != nullptr && face_kind->size() == triangle_count_) {
    for (size_t f = 0; f < face_kind->size(); ++f) kinds[f] = static_cast<uint8_t>((*face_kind)[f]);
  }
  send(GL_TEXTURE_BUFFER, face_kind_buffer_, kinds.size(), kinds.data());
  gl_.BindTexture(GL_TEXTURE_BUFFER, face_kind_texture_);
  gl_.TexBuffer(GL_TEXTURE_BUFFER, GL_R8UI, face_kind_buffer_);
  gl_.BindTexture(GL_TEXTURE_BUFFER, 0);
  gl_.BindBuffer(GL_TEXTURE_BUFFER, 0);
}

void MeshRenderer::upload_distances(const std::vector<float>& distances) {
  if (distances.size() != vertex_count_) return;
  std::vector<float> drawn;
  drawn.reserve(distances.size() + copied_from_.size());
  drawn.assign(distances.begin(), distances.end());
  for (uint32_t v : copied_from_) drawn.push_back(distances[v]);
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
  gl_.BindVertexArray(vao_);
  gl_.DrawElements(GL_TRIANGLES, static_cast<GLsizei>(triangle_count_ * 3), GL_UNSIGNED_INT,
                   nullptr);
  gl_.BindVertexArray(0);
  gl_.BindTexture(GL_TEXTURE_BUFFER, 0);
  gl_.UseProgram(0);
  gl_.Disable(GL_DEPTH_TEST);
}

}  // namespace meshstream::client

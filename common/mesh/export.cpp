// PLY, OBJ, OFF and binary STL writers. Coordinates are written so that reading them back
// gives the same float bits: binary PLY stores the floats themselves, text
// formats use the shortest decimal that round-trips (std::to_chars), which a
// correctly rounding reader (strtof, from_chars, Draco's parser for
// ordinary decimals) maps back to the same float. Binary STL stores the
// floats too, but three per triangle corner: a reader welds them back into
// shared vertices (ours does, by bit-identical position).
#include "common/mesh/export.h"

#include <algorithm>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "common/mesh/corner_data.h"
#include "common/mesh/texture_files.h"

namespace meshstream {
namespace {

struct FileCloser {
  void operator()(std::FILE* f) const {
    if (f) std::fclose(f);
  }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

// Buffered writer: formats into a string, flushes in large blocks.
class Writer {
 public:
  explicit Writer(std::FILE* file) : file_(file) { buffer_.reserve(kBlock + 256); }
  void text(const char* s) {
    buffer_ += s;
    maybe_flush();
  }
  void text(const std::string& s) {
    buffer_ += s;
    maybe_flush();
  }
  void number(float x) {
    char tmp[32];
    auto [end, ec] = std::to_chars(tmp, tmp + sizeof(tmp), x);
    buffer_.append(tmp, end);
  }
  void number(uint32_t x) {
    char tmp[16];
    auto [end, ec] = std::to_chars(tmp, tmp + sizeof(tmp), x);
    buffer_.append(tmp, end);
  }
  void raw(const void* data, size_t size) {
    if (size >= kBlock) {  // a whole array: straight to the file, not through the buffer
      flush();
      if (std::fwrite(data, 1, size, file_) != size) ok_ = false;
      return;
    }
    buffer_.append(static_cast<const char*>(data), size);
    maybe_flush();
  }
  void put(char c) { buffer_.push_back(c); }
  // "x y z" (a position or a normal) and "u v", shortest round-trip floats:
  // the text writers' vertex fields.
  void numbers(const Vec3f& v) { number(v.x), put(' '), number(v.y), put(' '), number(v.z); }
  void numbers(const Vec2f& v) { number(v.x), put(' '), number(v.y); }
  // "3 a b c\n": a triangle of the PLY and OFF text bodies.
  void triangle_line(const Triangle& t) {
    text("3 ");
    number(t[0]), put(' '), number(t[1]), put(' '), number(t[2]), put('\n');
  }
  bool finish() {
    flush();
    return ok_ && std::fflush(file_) == 0;
  }
  void maybe_flush() {
    if (buffer_.size() >= kBlock) flush();
  }

 private:
  void flush() {
    if (!buffer_.empty() &&
        std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size()) {
      ok_ = false;
    }
    buffer_.clear();
  }
  static constexpr size_t kBlock = 1 << 20;
  std::FILE* file_;
  std::string buffer_;
  bool ok_ = true;
};

Status open_for_writing(const std::string& path, File& file) {
  file.reset(std::fopen(path.c_str(), "wb"));
  if (!file) {
    return make_error(ErrorCode::kIo, path + ": cannot open for writing: " + std::strerror(errno));
  }
  return {};
}

Status check_writable(const Mesh& mesh, const std::string& path) {
  if (auto status = validate_arrays(mesh); !status) {
    return make_error(ErrorCode::kInvalidMesh,
                      path + ": refusing to write: " + status.error().message);
  }
  return {};
}

uint8_t to_byte(float c) {
  const float clamped = std::clamp(std::isnan(c) ? 0.0f : c, 0.0f, 1.0f);
  return static_cast<uint8_t>(std::lround(clamped * 255.0f));
}

std::string lower_extension(const std::string& path) {
  const size_t dot = path.find_last_of('.');
  const size_t slash = path.find_last_of('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return {};
  std::string ext = path.substr(dot + 1);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

// A name usable as a file name and an MTL/usemtl token: no blanks, no
// folders. Materials keep their names where they are already safe.
std::string safe_name(const std::string& name, const std::string& fallback) {
  std::string out;
  for (char c : name) {
    const unsigned char u = static_cast<unsigned char>(c);
    out += (std::isalnum(u) || c == '_' || c == '-' || c == '.') ? c : '_';
  }
  if (out.empty() || out == "." || out == "..") out = fallback;
  return out;
}

}  // namespace

std::string material_file_name(const Mesh& mesh, uint32_t m) {
  if (m >= mesh.materials.size()) return "material" + std::to_string(m);
  std::string name = safe_name(mesh.materials[m].name, "material" + std::to_string(m));
  // Unique: a later material with the same safe name gets its index.
  for (uint32_t k = 0; k < m; ++k) {
    if (safe_name(mesh.materials[k].name, "material" + std::to_string(k)) == name)
      return name + "_" + std::to_string(m);
  }
  return name;
}

std::vector<std::string> texture_file_names(const Mesh& mesh, const std::string& prefix) {
  std::vector<std::string> names;
  for (size_t t = 0; t < mesh.textures.size(); ++t) {
    const Texture& texture = mesh.textures[t];
    std::string stem = safe_name(std::filesystem::path(texture.name).stem().string(),
                                 "texture" + std::to_string(t));
    std::string name = prefix + stem + texture_extension(texture);
    if (std::find(names.begin(), names.end(), name) != names.end())
      name = prefix + stem + "_" + std::to_string(t) + texture_extension(texture);
    names.push_back(name);
  }
  return names;
}

Status write_file_bytes(const std::string& path, const void* data, size_t size) {
  File file;
  if (auto status = open_for_writing(path, file); !status) return status;
  if (size > 0 && std::fwrite(data, 1, size, file.get()) != size)
    return make_error(ErrorCode::kIo, path + ": write failed (disk full?)");
  if (std::fflush(file.get()) != 0) return make_error(ErrorCode::kIo, path + ": write failed");
  return {};
}

Result<std::string> write_material_files(const Mesh& mesh, const std::string& obj_path) {
  const std::filesystem::path obj(obj_path);
  const std::string stem = obj.stem().string();
  const std::string library = safe_name(stem, "mesh") + ".mtl";
  const std::filesystem::path folder = obj.parent_path();
  const std::vector<std::string> images = texture_file_names(mesh, safe_name(stem, "mesh") + "_");
  for (size_t t = 0; t < mesh.textures.size(); ++t) {
    const Texture& texture = mesh.textures[t];
    if (auto s = write_file_bytes((folder / images[t]).string(), texture.bytes.data(),
                                  texture.bytes.size());
        !s) {
      return tl::unexpected(s.error());
    }
  }
  std::string mtl = "# written by meshstream: base colour (Kd, d) and its texture (map_Kd)\n";
  for (uint32_t m = 0; m < mesh.materials.size(); ++m) {
    const Material& material = mesh.materials[m];
    char line[160];
    std::snprintf(line, sizeof line, "Kd %.9g %.9g %.9g\nd %.9g\n", material.base_color.x,
                  material.base_color.y, material.base_color.z, material.base_color.w);
    mtl += "\nnewmtl " + material_file_name(mesh, m) + "\n" + line;
    const int32_t t = material.base_color_texture;
    if (t >= 0 && static_cast<size_t>(t) < images.size()) mtl += "map_Kd " + images[t] + "\n";
    if (material.normal_texture >= 0 &&
        static_cast<size_t>(material.normal_texture) < images.size())
      mtl += "norm " + images[material.normal_texture] + "\n";
  }
  if (auto s = write_file_bytes((folder / library).string(), mtl.data(), mtl.size()); !s)
    return tl::unexpected(s.error());
  return library;
}

namespace {

// PLY's name of an extra attribute's component type.
const char* ply_type(ExtraAttribute::ComponentType type) {
  switch (type) {
    case ExtraAttribute::ComponentType::kInt8:
      return "char";
    case ExtraAttribute::ComponentType::kUint8:
      return "uchar";
    case ExtraAttribute::ComponentType::kInt16:
      return "short";
    case ExtraAttribute::ComponentType::kUint16:
      return "ushort";
    case ExtraAttribute::ComponentType::kUint32:
      return "uint";
    case ExtraAttribute::ComponentType::kFloat32:
      return "float";
  }
  return "float";
}

}  // namespace

std::vector<std::string> ply_extra_property_names(const ExtraAttribute& e) {
  // A property name is one token; the ones PLY readers take for positions,
  // normals, colours and texture coordinates are not reused.
  static const char* const kTaken[] = {"x",     "y",    "z",     "nx", "ny", "nz", "red",
                                       "green", "blue", "alpha", "u",  "v",  "s",  "t"};
  std::string stem = safe_name(e.name, "extra");
  if (std::find(std::begin(kTaken), std::end(kTaken), stem) != std::end(kTaken))
    stem = "extra_" + stem;
  std::vector<std::string> names;
  for (uint32_t i = 0; i < e.components; ++i)
    names.push_back(e.components == 1 ? stem : stem + "_" + std::to_string(i));
  return names;
}

namespace {

// What a per-vertex format loses of `mesh`, for its header comment: the
// seam splits and what it cannot store at all.
std::string per_vertex_comment(const Mesh& original, const SplitMesh* split) {
  std::string c;
  if (split != nullptr && split->split_copies > 0)
    c += "comment " + std::to_string(split->split_copies) +
         " vertices added: per-corner attributes (seams) split into per-vertex copies\n";
  for (const ExtraAttribute& e : original.extra_attributes) {
    const auto names = ply_extra_property_names(e);
    c += "comment extra attribute " + e.name + ": properties " + names.front() +
         (names.size() > 1 ? ".." + names.back() : std::string()) +
         (e.normalized ? " (normalized integers)" : "") + "\n";
  }
  if (!original.materials.empty())
    c += "comment materials and textures not stored (use OBJ or glTF)\n";
  return c;
}

// The extra attributes as per-vertex bytes (split_seams' vertex_extras).
struct VertexExtras {
  const std::vector<ExtraAttribute>* attributes = nullptr;
  const std::vector<std::vector<uint8_t>>* bytes = nullptr;
  size_t count() const { return attributes ? attributes->size() : 0; }
};

Status write_ply_vertices(const Mesh& mesh, const std::string& path, PlyEncoding encoding,
                          const std::string& comment, VertexExtras extras = {});

}  // namespace

Status write_ply(const Mesh& mesh, const std::string& path, PlyEncoding encoding) {
  if (auto status = check_writable(mesh, path); !status) return status;
  if (!has_corner_data(mesh))
    return write_ply_vertices(mesh, path, encoding, per_vertex_comment(mesh, nullptr));
  const SplitMesh split = split_seams(mesh);
  return write_ply_vertices(split.mesh, path, encoding, per_vertex_comment(mesh, &split),
                            {&mesh.extra_attributes, &split.vertex_extras});
}

namespace {

// One component of an extra attribute as PLY text.
void write_component(Writer& out, ExtraAttribute::ComponentType type, const uint8_t* bytes) {
  switch (type) {
    case ExtraAttribute::ComponentType::kInt8:
      out.text(std::to_string(int(int8_t(bytes[0]))));
      return;
    case ExtraAttribute::ComponentType::kUint8:
      out.number(uint32_t{bytes[0]});
      return;
    case ExtraAttribute::ComponentType::kInt16: {
      int16_t x;
      std::memcpy(&x, bytes, 2);
      out.text(std::to_string(int(x)));
      return;
    }
    case ExtraAttribute::ComponentType::kUint16: {
      uint16_t x;
      std::memcpy(&x, bytes, 2);
      out.number(uint32_t{x});
      return;
    }
    case ExtraAttribute::ComponentType::kUint32: {
      uint32_t x;
      std::memcpy(&x, bytes, 4);
      out.number(x);
      return;
    }
    case ExtraAttribute::ComponentType::kFloat32: {
      float x;
      std::memcpy(&x, bytes, 4);
      out.number(x);
      return;
    }
  }
}

Status write_ply_vertices(const Mesh& mesh, const std::string& path, PlyEncoding encoding,
                          const std::string& comment, VertexExtras extras) {
  File file;
  if (auto status = open_for_writing(path, file); !status) return status;
  Writer out(file.get());
  const bool binary = encoding == PlyEncoding::kBinary;
  const bool normals = !mesh.normals.empty();
  const bool colors = !mesh.colors.empty();
  const bool texcoords = !mesh.texcoords.empty();
  out.text(std::string("ply\nformat ") + (binary ? "binary_little_endian" : "ascii") +
           " 1.0\ncomment written by meshstream\n");
  out.text(comment);
  out.text("element vertex " + std::to_string(mesh.vertex_count()) + "\n");
  out.text("property float x\nproperty float y\nproperty float z\n");
  if (normals) out.text("property float nx\nproperty float ny\nproperty float nz\n");
  if (colors) {
    out.text(
        "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n");
  }
  if (texcoords) out.text("property float u\nproperty float v\n");
  for (size_t e = 0; e < extras.count(); ++e) {
    const ExtraAttribute& attribute = (*extras.attributes)[e];
    for (const std::string& name : ply_extra_property_names(attribute))
      out.text(std::string("property ") + ply_type(attribute.component_type) + " " + name + "\n");
  }
  out.text("element face " + std::to_string(mesh.face_count()) + "\n");
  out.text("property list uchar int vertex_indices\nend_header\n");

  static_assert(std::endian::native == std::endian::little,
                "binary PLY writer assumes little-endian");
  if (binary && !normals && !colors && !texcoords) {
    // The common case (a decoded mesh without attributes): the positions
    // are already the vertex records, and the faces are packed 13 bytes at a
    // time into one block, instead of an append with its size checks per
    // element (35 instructions a vertex or face: most of a decode's output
    // cost).
    static_assert(sizeof(Vec3f) == 12 && sizeof(Triangle) == 12, "packed PLY records");
    out.raw(mesh.positions.data(), 12 * size_t(mesh.vertex_count()));
    constexpr size_t kFacesPerBlock = 1 << 17;  // 1.7 MB blocks, written directly
    // On the heap (writers may run on small stacks), no bigger than the mesh.
    std::vector<uint8_t> block(13 * std::min(kFacesPerBlock, mesh.triangles.size()));
    for (size_t first = 0; first < mesh.triangles.size(); first += kFacesPerBlock) {
      const size_t n = std::min(kFacesPerBlock, mesh.triangles.size() - first);
      uint8_t* at = block.data();
      for (size_t i = 0; i < n; ++i, at += 13) {
        const Triangle& t = mesh.triangles[first + i];
        at[0] = 3;
        std::memcpy(at + 1, &t[0], 4);  // three fixed-size copies: inlined as stores
        std::memcpy(at + 5, &t[1], 4);
        std::memcpy(at + 9, &t[2], 4);
      }
      out.raw(block.data(), 13 * n);
    }
    if (!out.finish()) return make_error(ErrorCode::kIo, path + ": write failed (disk full?)");
    return {};
  }
  for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    if (binary) {
      out.raw(&mesh.positions[v], 12);
      if (normals) out.raw(&mesh.normals[v], 12);
      if (colors) {
        const Vec4f& c = mesh.colors[v];
        const uint8_t rgba[4] = {to_byte(c.x), to_byte(c.y), to_byte(c.z), to_byte(c.w)};
        out.raw(rgba, 4);
      }
      if (texcoords) out.raw(&mesh.texcoords[v], 8);
      for (size_t e = 0; e < extras.count(); ++e) {
        const size_t size = element_size((*extras.attributes)[e]);
        out.raw((*extras.bytes)[e].data() + size_t(v) * size, size);
      }
      continue;
    }
    out.numbers(mesh.positions[v]);
    if (normals) out.put(' '), out.numbers(mesh.normals[v]);
    if (colors) {
      const Vec4f& c = mesh.colors[v];
      for (float x : {c.x, c.y, c.z, c.w}) out.put(' '), out.number(uint32_t{to_byte(x)});
    }
    if (texcoords) out.put(' '), out.numbers(mesh.texcoords[v]);
    for (size_t e = 0; e < extras.count(); ++e) {
      const ExtraAttribute& attribute = (*extras.attributes)[e];
      const size_t size = component_size(attribute.component_type);
      const uint8_t* element = (*extras.bytes)[e].data() + size_t(v) * element_size(attribute);
      for (uint32_t i = 0; i < attribute.components; ++i) {
        out.put(' ');
        write_component(out, attribute.component_type, element + i * size);
      }
    }
    out.put('\n');
    out.maybe_flush();
  }
  for (const Triangle& t : mesh.triangles) {
    if (binary) {
      uint8_t record[13];
      record[0] = 3;
      std::memcpy(record + 1, t.data(), 12);
      out.raw(record, sizeof(record));
      continue;
    }
    out.triangle_line(t);
  }
  if (!out.finish()) return make_error(ErrorCode::kIo, path + ": write failed (disk full?)");
  return {};
}

}  // namespace

Status write_obj(const Mesh& mesh, const std::string& path) {
  if (auto status = check_writable(mesh, path); !status) return status;
  // Materials first: the MTL file and the images beside the OBJ.
  std::string library;
  if (!mesh.materials.empty()) {
    auto written = write_material_files(mesh, path);
    if (!written) return tl::unexpected(written.error());
    library = *written;
  }
  File file;
  if (auto status = open_for_writing(path, file); !status) return status;
  Writer out(file.get());
  // vt / vn values: the per-vertex arrays (index = vertex) or a corner
  // attribute's values (index per corner), so seams stay seams.
  const bool corner_texcoords = !mesh.corner_texcoords.empty();
  const bool corner_normals = !mesh.corner_normals.empty();
  const bool texcoords = corner_texcoords || !mesh.texcoords.empty();
  const bool normals = corner_normals || !mesh.normals.empty();
  out.text("# written by meshstream: " + std::to_string(mesh.vertex_count()) + " vertices, " +
           std::to_string(mesh.face_count()) + " triangles\n");
  if (!mesh.colors.empty() || !mesh.corner_colors.empty())
    out.text("# vertex colours are not stored in OBJ\n");
  for (const ExtraAttribute& e : mesh.extra_attributes)
    out.text("# not stored (OBJ has no such attribute): " + e.name + "\n");
  if (!library.empty()) out.text("mtllib " + library + "\n");
  for (const Vec3f& p : mesh.positions) {
    out.text("v "), out.numbers(p), out.put('\n');
  }
  for (const Vec2f& t : corner_texcoords ? mesh.corner_texcoords.values : mesh.texcoords) {
    out.text("vt "), out.numbers(t), out.put('\n');
  }
  for (const Vec3f& n : corner_normals ? mesh.corner_normals.values : mesh.normals) {
    out.text("vn "), out.numbers(n), out.put('\n');
  }
  const bool materials = !mesh.materials.empty();
  uint32_t current = 0xFFFFFFFFu;
  for (uint32_t f = 0; f < mesh.face_count(); ++f) {
    if (materials) {
      const uint32_t m = mesh.face_materials.empty() ? 0 : mesh.face_materials[f];
      if (m != current) {
        out.text("usemtl " + material_file_name(mesh, m) + "\n");
        current = m;
      }
    }
    out.text("f");
    for (uint32_t k = 0; k < 3; ++k) {
      const uint32_t c = 3 * f + k;
      const uint32_t v = mesh.triangles[f][k];
      out.put(' ');
      out.number(v + 1);  // OBJ counts from 1
      if (texcoords || normals) {
        out.put('/');
        if (texcoords) out.number((corner_texcoords ? mesh.corner_texcoords.corners[c] : v) + 1);
        if (normals)
          out.put('/'), out.number((corner_normals ? mesh.corner_normals.corners[c] : v) + 1);
      }
    }
    out.put('\n');
    out.maybe_flush();
  }
  if (!out.finish()) return make_error(ErrorCode::kIo, path + ": write failed (disk full?)");
  return {};
}

Status write_off(const Mesh& input, const std::string& path) {
  if (auto status = check_writable(input, path); !status) return status;
  // OFF is per vertex: seams are split (copies appended).
  SplitMesh split;
  if (has_corner_data(input)) split = split_seams(input);
  const Mesh& mesh = has_corner_data(input) ? split.mesh : input;
  File file;
  if (auto status = open_for_writing(path, file); !status) return status;
  Writer out(file.get());
  const bool normals = !mesh.normals.empty();
  const bool colors = !mesh.colors.empty();
  const bool texcoords = !mesh.texcoords.empty();
  // The keyword announces the per-vertex attributes, [ST][C][N]OFF; each
  // vertex line then holds x y z, the normal, the colour (four floats in
  // 0..1) and the texture coordinates, in that order.
  out.text(std::string(texcoords ? "ST" : "") + (colors ? "C" : "") + (normals ? "N" : "") +
           "OFF\n# written by meshstream\n");
  out.text(std::to_string(mesh.vertex_count()) + " " + std::to_string(mesh.face_count()) + " 0\n");
  for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    out.numbers(mesh.positions[v]);
    if (normals) out.put(' '), out.numbers(mesh.normals[v]);
    if (colors) {
      const Vec4f& c = mesh.colors[v];
      for (float x : {c.x, c.y, c.z, c.w}) {
        out.put(' '), out.number(std::clamp(std::isnan(x) ? 0.0f : x, 0.0f, 1.0f));
      }
    }
    if (texcoords) out.put(' '), out.numbers(mesh.texcoords[v]);
    out.put('\n');
    out.maybe_flush();
  }
  for (const Triangle& t : mesh.triangles) {
    out.triangle_line(t);
  }
  if (!out.finish()) return make_error(ErrorCode::kIo, path + ": write failed (disk full?)");
  return {};
}

Status write_stl(const Mesh& mesh, const std::string& path) {
  if (auto status = check_writable(mesh, path); !status) return status;
  File file;
  if (auto status = open_for_writing(path, file); !status) return status;
  Writer out(file.get());
  static_assert(std::endian::native == std::endian::little,
                "binary STL writer assumes little-endian");
  // 80-byte header (must not start with "solid", which marks ASCII STL),
  // the triangle count, then 50 bytes a triangle: the facet normal, three
  // corners, a zero attribute byte count.
  char header[80] = {};
  std::snprintf(header, sizeof header, "binary STL written by meshstream: %u triangles",
                mesh.face_count());
  out.raw(header, sizeof header);
  const uint32_t count = mesh.face_count();
  out.raw(&count, 4);
  for (const Triangle& t : mesh.triangles) {
    const Vec3f& a = mesh.positions[t[0]];
    const Vec3f& b = mesh.positions[t[1]];
    const Vec3f& c = mesh.positions[t[2]];
    const Vec3f n = cross(b - a, c - a);
    const float len = length(n);
    const Vec3f unit = len > 0 && std::isfinite(len) ? n / len : Vec3f{};
    uint8_t record[50] = {};
    std::memcpy(record, &unit, 12);
    std::memcpy(record + 12, &a, 12);
    std::memcpy(record + 24, &b, 12);
    std::memcpy(record + 36, &c, 12);
    out.raw(record, sizeof record);
  }
  if (!out.finish()) return make_error(ErrorCode::kIo, path + ": write failed (disk full?)");
  return {};
}

Status check_mesh_output_path(const std::string& path) {
  const std::string ext = lower_extension(path);
  if (ext == "ply" || ext == "obj" || ext == "off" || ext == "stl" || ext == "glb" || ext == "gltf")
    return {};
  return make_error(
      ErrorCode::kInvalidArgument,
      path + ": cannot write '." + ext + "' files (use .ply, .obj, .off, .stl, .glb or .gltf)");
}

std::vector<std::string> export_losses(const Mesh& mesh, const std::string& path) {
  const std::string ext = lower_extension(path);
  const bool stl = ext == "stl";
  const bool obj = ext == "obj";
  const bool off = ext == "off";
  const bool ply = ext == "ply";
  std::vector<std::string> lost;
  if (!stl && !obj && !off && !ply) return lost;  // glTF holds everything, other names fail
  const char* format = stl ? "STL" : obj ? "OBJ" : off ? "OFF" : "PLY";
  if (stl && (!mesh.normals.empty() || !mesh.corner_normals.empty())) lost.push_back("normals");
  if (stl && (!mesh.texcoords.empty() || !mesh.corner_texcoords.empty()))
    lost.push_back("texture coordinates");
  if ((stl || obj) && (!mesh.colors.empty() || !mesh.corner_colors.empty()))
    lost.push_back("vertex colours");
  if (!ply && !mesh.extra_attributes.empty()) {
    std::string names;
    for (const ExtraAttribute& e : mesh.extra_attributes)
      names += (names.empty() ? "" : ", ") + e.name;
    lost.push_back("extra attribute" + std::string(mesh.extra_attributes.size() > 1 ? "s " : " ") +
                   names + " (" + format + " has no such attribute)");
  }
  if (!obj && !mesh.materials.empty())
    lost.push_back(std::string("materials and textures (") + format +
                   " has none: use OBJ or glTF)");
  return lost;
}

Status write_mesh(const Mesh& mesh, const std::string& path) {
  if (auto writable = check_mesh_output_path(path); !writable) return writable;
  const std::string ext = lower_extension(path);
  if (ext == "ply") return write_ply(mesh, path, PlyEncoding::kBinary);
  if (ext == "obj") return write_obj(mesh, path);
  if (ext == "off") return write_off(mesh, path);
  if (ext == "glb" || ext == "gltf") return write_gltf(mesh, path);
  return write_stl(mesh, path);
}

}  // namespace meshstream

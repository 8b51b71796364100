// glTF 2.0 output, our own small writer (nlohmann-json): Draco's
// GltfEncoder writes from a draco::Mesh/Scene, which would mean building
// Draco's material and texture objects from ours and re-reading its choices
// (it also re-encodes nothing we need and adds its own extensions); a
// direct writer is about as long and writes exactly what the Mesh holds.
//
// Layout: one mesh, one node, one primitive per material used (faces in
// their material's order); glTF vertices are the corners' distinct value
// combinations within a primitive (seams split), per-vertex arrays as
// tightly packed float accessors (4-byte aligned), uint32 indices. Images
// are the textures' original bytes: a bufferView in a .glb, a file beside a
// .gltf (STEM_NAME.png), with STEM.bin for the buffer.
#include <cmath>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <unordered_map>
#include <vector>

#include "common/mesh/export.h"
#include "common/mesh/texture_files.h"

namespace meshstream {
namespace {

using Json = nlohmann::json;

constexpr int kFloat = 5126, kUint32 = 5125, kArrayBuffer = 34962, kElementArrayBuffer = 34963;

int gl_component_type(ExtraAttribute::ComponentType type) {
  switch (type) {
    case ExtraAttribute::ComponentType::kInt8:
      return 5120;
    case ExtraAttribute::ComponentType::kUint8:
      return 5121;
    case ExtraAttribute::ComponentType::kInt16:
      return 5122;
    case ExtraAttribute::ComponentType::kUint16:
      return 5123;
    case ExtraAttribute::ComponentType::kUint32:
      return 5125;
    case ExtraAttribute::ComponentType::kFloat32:
      return 5126;
  }
  return 5126;
}

const char* accessor_type(uint32_t components) {
  static const char* kTypes[] = {"SCALAR", "VEC2", "VEC3", "VEC4"};
  return kTypes[std::clamp<uint32_t>(components, 1, 4) - 1];
}

// Whether glTF allows `e` under its own name (glTF 2.0 spec 3.7.2.1);
// otherwise it is written as the application-specific "_NAME".
bool valid_semantic(const ExtraAttribute& e) {
  using T = ExtraAttribute::ComponentType;
  const bool f = e.component_type == T::kFloat32;
  const bool unorm =
      (e.component_type == T::kUint8 || e.component_type == T::kUint16) && e.normalized;
  auto starts = [&](const char* prefix) { return e.name.rfind(prefix, 0) == 0; };
  auto set_number = [&](size_t at) {
    if (e.name.size() <= at) return false;
    for (size_t i = at; i < e.name.size(); ++i) {
      if (!std::isdigit(static_cast<unsigned char>(e.name[i]))) return false;
    }
    return true;
  };
  if (e.name == "TANGENT") return f && e.components == 4;
  if (starts("TEXCOORD_") && set_number(9))
    return e.name != "TEXCOORD_0" && e.components == 2 && (f || unorm);
  if (starts("COLOR_") && set_number(6))
    return e.name != "COLOR_0" && (e.components == 3 || e.components == 4) && (f || unorm);
  if (starts("JOINTS_") && set_number(7))
    return e.components == 4 && !e.normalized &&
           (e.component_type == T::kUint8 || e.component_type == T::kUint16);
  if (starts("WEIGHTS_") && set_number(8)) return e.components == 4 && (f || unorm);
  return false;
}

class GltfBuilder {
 public:
  explicit GltfBuilder(const Mesh& mesh) : mesh_(mesh) {}

  Json build(bool binary, const std::vector<std::string>& image_files);
  const std::vector<uint8_t>& buffer() const { return buffer_; }

 private:
  // Appends `size` bytes as a bufferView; returns its index.
  int add_view(const void* data, size_t size, int target, size_t stride = 0);
  int add_accessor(int view, int component_type, size_t count, const char* type,
                   bool normalized = false, const Json& min = nullptr, const Json& max = nullptr);
  void add_primitive(uint32_t material, const std::vector<uint32_t>& faces, bool with_material);

  const Mesh& mesh_;
  std::vector<uint8_t> buffer_;
  Json views_ = Json::array(), accessors_ = Json::array(), primitives_ = Json::array();
};

int GltfBuilder::add_view(const void* data, size_t size, int target, size_t stride) {
  while (buffer_.size() % 4 != 0) buffer_.push_back(0);
  Json view = {{"buffer", 0}, {"byteOffset", buffer_.size()}, {"byteLength", size}};
  if (target != 0) view["target"] = target;
  if (stride != 0) view["byteStride"] = stride;
  const uint8_t* bytes = static_cast<const uint8_t*>(data);
  buffer_.insert(buffer_.end(), bytes, bytes + size);
  views_.push_back(view);
  return static_cast<int>(views_.size() - 1);
}

int GltfBuilder::add_accessor(int view, int component_type, size_t count, const char* type,
                              bool normalized, const Json& min, const Json& max) {
  Json accessor = {
      {"bufferView", view}, {"componentType", component_type}, {"count", count}, {"type", type}};
  if (normalized) accessor["normalized"] = true;
  if (!min.is_null()) accessor["min"] = min;
  if (!max.is_null()) accessor["max"] = max;
  accessors_.push_back(accessor);
  return static_cast<int>(accessors_.size() - 1);
}

// One primitive: its glTF vertices are the distinct (vertex, per-corner
// values) combinations of its faces' corners, in first-use order.
void GltfBuilder::add_primitive(uint32_t material, const std::vector<uint32_t>& faces,
                                bool with_material) {
  const Mesh& m = mesh_;
  const bool normals = !m.normals.empty() || !m.corner_normals.empty();
  const bool texcoords = !m.texcoords.empty() || !m.corner_texcoords.empty();
  const bool colors = !m.colors.empty() || !m.corner_colors.empty();
  std::vector<uint32_t> corner_of_vertex;  // a corner each glTF vertex comes from
  std::vector<uint32_t> indices;
  indices.reserve(3 * faces.size());
  std::unordered_map<std::string, uint32_t> index_of;
  std::string key;
  for (uint32_t f : faces) {
    for (uint32_t k = 0; k < 3; ++k) {
      const size_t c = 3 * static_cast<size_t>(f) + k;
      const uint32_t v = m.triangles[f][k];
      key.assign(reinterpret_cast<const char*>(&v), sizeof v);
      auto add = [&key](const void* p, size_t size) {
        key.append(static_cast<const char*>(p), size);
      };
      if (!m.corner_normals.empty()) add(&m.corner_normals.at_corner(c), sizeof(Vec3f));
      if (!m.corner_texcoords.empty()) add(&m.corner_texcoords.at_corner(c), sizeof(Vec2f));
      if (!m.corner_colors.empty()) add(&m.corner_colors.at_corner(c), sizeof(Vec4f));
      for (const ExtraAttribute& e : m.extra_attributes)
        add(e.bytes.data() + c * element_size(e), element_size(e));
      auto [it, added] = index_of.try_emplace(key, static_cast<uint32_t>(corner_of_vertex.size()));
      if (added) corner_of_vertex.push_back(static_cast<uint32_t>(c));
      indices.push_back(it->second);
    }
  }
  const size_t n = corner_of_vertex.size();
  auto vertex_of = [&](uint32_t c) { return m.triangles[c / 3][c % 3]; };

  Json attributes = Json::object();
  {
    std::vector<Vec3f> p(n);
    Vec3f lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
    for (size_t i = 0; i < n; ++i) {
      p[i] = m.positions[vertex_of(corner_of_vertex[i])];
      lo = {std::min(lo.x, p[i].x), std::min(lo.y, p[i].y), std::min(lo.z, p[i].z)};
      hi = {std::max(hi.x, p[i].x), std::max(hi.y, p[i].y), std::max(hi.z, p[i].z)};
    }
    const int view = add_view(p.data(), n * sizeof(Vec3f), kArrayBuffer);
    attributes["POSITION"] =
        add_accessor(view, kFloat, n, "VEC3", false, {lo.x, lo.y, lo.z}, {hi.x, hi.y, hi.z});
  }
  if (normals) {
    std::vector<Vec3f> values(n);
    for (size_t i = 0; i < n; ++i) {
      const uint32_t c = corner_of_vertex[i];
      Vec3f v = m.corner_normals.empty() ? m.normals[vertex_of(c)] : m.corner_normals.at_corner(c);
      // glTF requires unit normals: values that are not (zeros a file
      // left, sloppy lengths) are normalized, zeros become +z.
      const float len = length(v);
      if (!(std::fabs(len - 1.0f) <= 5e-4f))
        v = len > 0 && std::isfinite(len) ? v / len : Vec3f{0, 0, 1};
      values[i] = v;
    }
    attributes["NORMAL"] =
        add_accessor(add_view(values.data(), n * sizeof(Vec3f), kArrayBuffer), kFloat, n, "VEC3");
  }
  if (texcoords) {
    std::vector<Vec2f> values(n);
    for (size_t i = 0; i < n; ++i) {
      const uint32_t c = corner_of_vertex[i];
      values[i] =
          m.corner_texcoords.empty() ? m.texcoords[vertex_of(c)] : m.corner_texcoords.at_corner(c);
      values[i].y = 1.0f - values[i].y;  // glTF's v runs down the image (mesh.h)
    }
    attributes["TEXCOORD_0"] =
        add_accessor(add_view(values.data(), n * sizeof(Vec2f), kArrayBuffer), kFloat, n, "VEC2");
  }
  if (colors) {
    std::vector<Vec4f> values(n);
    for (size_t i = 0; i < n; ++i) {
      const uint32_t c = corner_of_vertex[i];
      Vec4f v = m.corner_colors.empty() ? m.colors[vertex_of(c)] : m.corner_colors.at_corner(c);
      for (float* x : {&v.x, &v.y, &v.z, &v.w})
        *x = std::clamp(std::isnan(*x) ? 0.0f : *x, 0.0f, 1.0f);
      values[i] = v;
    }
    attributes["COLOR_0"] =
        add_accessor(add_view(values.data(), n * sizeof(Vec4f), kArrayBuffer), kFloat, n, "VEC4");
  }
  for (const ExtraAttribute& e : m.extra_attributes) {
    const size_t size = element_size(e);
    const size_t stride = (size + 3) / 4 * 4;  // vertex attributes: 4-byte aligned elements
    std::vector<uint8_t> values(n * stride, 0);
    for (size_t i = 0; i < n; ++i)
      std::memcpy(values.data() + i * stride, e.bytes.data() + corner_of_vertex[i] * size, size);
    const int view =
        add_view(values.data(), values.size(), kArrayBuffer, stride != size ? stride : 0);
    const std::string name = valid_semantic(e) ? e.name : "_" + e.name;
    attributes[name] = add_accessor(view, gl_component_type(e.component_type), n,
                                    accessor_type(e.components), e.normalized);
  }
  const int index_view = add_view(indices.data(), indices.size() * 4, kElementArrayBuffer);
  Json primitive = {{"attributes", attributes},
                    {"indices", add_accessor(index_view, kUint32, indices.size(), "SCALAR")},
                    {"mode", 4}};
  if (with_material) primitive["material"] = material;
  primitives_.push_back(primitive);
}

Json GltfBuilder::build(bool binary, const std::vector<std::string>& image_files) {
  const Mesh& m = mesh_;
  const bool with_materials = !m.materials.empty();
  // Faces by material, in face order within each.
  const size_t groups = with_materials ? m.materials.size() : 1;
  std::vector<std::vector<uint32_t>> faces(groups);
  for (uint32_t f = 0; f < m.face_count(); ++f) {
    const uint32_t g = with_materials && !m.face_materials.empty() ? m.face_materials[f] : 0;
    faces[g].push_back(f);
  }
  for (uint32_t g = 0; g < groups; ++g) {
    if (!faces[g].empty()) add_primitive(g, faces[g], with_materials);
  }

  Json gltf = {{"asset", {{"version", "2.0"}, {"generator", "meshstream"}}},
               {"scene", 0},
               {"scenes", Json::array({{{"nodes", {0}}}})},
               {"nodes", Json::array({{{"mesh", 0}}})},
               {"meshes", Json::array({{{"primitives", primitives_}}})}};
  if (with_materials) {
    Json materials = Json::array();
    for (const Material& material : m.materials) {
      const Vec4f c = material.base_color;
      Json pbr = {{"baseColorFactor", {c.x, c.y, c.z, c.w}},
                  {"metallicFactor", material.metallic},
                  {"roughnessFactor", material.roughness}};
      auto valid = [&](int32_t t) { return t >= 0 && static_cast<size_t>(t) < m.textures.size(); };
      if (valid(material.base_color_texture))
        pbr["baseColorTexture"] = {{"index", material.base_color_texture}};
      if (valid(material.metallic_roughness_texture))
        pbr["metallicRoughnessTexture"] = {{"index", material.metallic_roughness_texture}};
      Json out = {{"name", material.name}, {"pbrMetallicRoughness", pbr}};
      if (valid(material.normal_texture))
        out["normalTexture"] = {{"index", material.normal_texture}};
      if (valid(material.occlusion_texture))
        out["occlusionTexture"] = {{"index", material.occlusion_texture}};
      if (valid(material.emissive_texture)) {
        out["emissiveTexture"] = {{"index", material.emissive_texture}};
        out["emissiveFactor"] = {1.0, 1.0, 1.0};
      }
      if (material.double_sided) out["doubleSided"] = true;
      materials.push_back(out);
    }
    gltf["materials"] = materials;
  }
  if (!m.textures.empty()) {
    Json images = Json::array(), textures = Json::array();
    for (size_t t = 0; t < m.textures.size(); ++t) {
      const Texture& texture = m.textures[t];
      Json image = {{"name", texture.name}};
      if (binary) {
        image["bufferView"] = add_view(texture.bytes.data(), texture.bytes.size(), 0);
        image["mimeType"] = texture.mime_type.empty() ? "image/png" : texture.mime_type;
      } else {
        image["uri"] = image_files[t];
      }
      images.push_back(image);
      textures.push_back({{"source", t}, {"sampler", 0}});
    }
    gltf["images"] = images;
    gltf["textures"] = textures;
    // Repeat wrapping and linear filtering: the defaults importers assume.
    gltf["samplers"] = Json::array({{{"magFilter", 9729}, {"minFilter", 9987}}});
  }
  while (buffer_.size() % 4 != 0) buffer_.push_back(0);
  gltf["buffers"] = Json::array({{{"byteLength", buffer_.size()}}});
  gltf["bufferViews"] = views_;
  gltf["accessors"] = accessors_;
  return gltf;
}

bool ends_with_glb(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".glb";
}

}  // namespace

Status write_gltf(const Mesh& mesh, const std::string& path) {
  if (auto status = validate_arrays(mesh); !status) {
    return make_error(ErrorCode::kInvalidMesh,
                      path + ": refusing to write: " + status.error().message);
  }
  if (auto status = check_attribute_counts(mesh); !status) {
    return make_error(ErrorCode::kInvalidMesh,
                      path + ": refusing to write: " + status.error().message);
  }
  for (const Texture& texture : mesh.textures) {
    if (texture.mime_type != "image/png" && texture.mime_type != "image/jpeg") {
      return make_error(
          ErrorCode::kUnsupported,
          path + ": texture " + texture.name + " is not PNG or JPEG (glTF carries only those)");
    }
  }
  const bool binary = ends_with_glb(path);
  const std::filesystem::path file(path);
  const std::string stem = file.stem().string().empty() ? "mesh" : file.stem().string();
  std::vector<std::string> image_files;
  if (!binary) image_files = texture_file_names(mesh, stem + "_");
  GltfBuilder builder(mesh);
  Json gltf = builder.build(binary, image_files);
  const std::vector<uint8_t>& buffer = builder.buffer();
  if (binary) {
    std::string json = gltf.dump();
    while (json.size() % 4 != 0) json.push_back(' ');
    const uint32_t total = static_cast<uint32_t>(12 + 8 + json.size() + 8 + buffer.size());
    std::vector<uint8_t> out;
    out.reserve(total);
    auto u32 = [&out](uint32_t x) {
      for (int i = 0; i < 4; ++i) out.push_back(static_cast<uint8_t>(x >> (8 * i)));
    };
    u32(0x46546C67u), u32(2), u32(total);
    u32(static_cast<uint32_t>(json.size())), u32(0x4E4F534Au);
    out.insert(out.end(), json.begin(), json.end());
    u32(static_cast<uint32_t>(buffer.size())), u32(0x004E4942u);
    out.insert(out.end(), buffer.begin(), buffer.end());
    return write_file_bytes(path, out.data(), out.size());
  }
  const std::string bin_name = stem + ".bin";
  gltf["buffers"][0]["uri"] = bin_name;
  const std::filesystem::path folder = file.parent_path();
  if (auto s = write_file_bytes((folder / bin_name).string(), buffer.data(), buffer.size()); !s)
    return s;
  for (size_t t = 0; t < mesh.textures.size(); ++t) {
    const Texture& texture = mesh.textures[t];
    if (auto s = write_file_bytes((folder / image_files[t]).string(), texture.bytes.data(),
                                  texture.bytes.size());
        !s) {
      return s;
    }
  }
  const std::string json = gltf.dump(1);
  return write_file_bytes(path, json.data(), json.size());
}

}  // namespace meshstream

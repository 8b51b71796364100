// glTF 2.0 (.gltf with external or embedded buffers and images, .glb)
// through Draco's scene reader, flattened into one Mesh: every mesh instance
// of the scene's node tree with its node's global transform applied
// (positions by the matrix, normals by its inverse transpose, tangents by
// its linear part; a mirroring transform reverses the winding, as glTF
// says), every primitive's material as a face material.
//
// Texture coordinates: Draco turns glTF's v (down the image) into OBJ's
// (up: 1 - v), the Mesh's convention (mesh.h); the writer turns it back.
// Both flips are exact on values that came from a flip.
//
// Draco splits nothing further and merges equal attribute values, so a
// point (glTF vertex) maps to a position value and to a value of each other
// attribute: the positions become our vertices, the other attributes
// corner attributes over them (clean_mesh welds positions across primitives
// and keeps an attribute per vertex where it has no seam). Images keep
// their original bytes (embedded, or the file beside a .gltf).
//
// Draco's Scene does not expose everything a glTF file can hold (cameras,
// morph targets, texture transforms are dropped or ignored), and we do not
// carry skins and animations: the file's JSON is read too
// (gltf_inventory) so that every such thing is named in a note.
#include <draco/io/scene_io.h>
#include <draco/material/material_library.h>
#include <draco/mesh/mesh.h>
#include <draco/scene/scene.h>
#include <draco/scene/scene_utils.h>
#include <draco/texture/texture_library.h>
#include <draco/texture/texture_transform.h>

#include <cstring>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <unordered_map>

#include "common/mesh/mesh_readers.h"
#include "common/mesh/texture_files.h"

namespace meshstream {
namespace {

using Json = nlohmann::json;

// ---- What the JSON holds that the Scene does not show.

// The JSON of a .gltf, or the JSON chunk of a .glb; kParse when neither.
Result<Json> read_gltf_json(const std::string& bytes) {
  std::string_view text = bytes;
  if (bytes.size() >= 4 && bytes.compare(0, 4, "glTF") == 0) {
    if (bytes.size() < 20) return make_error(ErrorCode::kParse, "truncated GLB header");
    uint32_t length = 0, chunk_length = 0, chunk_type = 0;
    std::memcpy(&length, bytes.data() + 8, 4);
    std::memcpy(&chunk_length, bytes.data() + 12, 4);
    std::memcpy(&chunk_type, bytes.data() + 16, 4);
    if (length > bytes.size()) {
      return make_error(ErrorCode::kParse, "truncated GLB: the header announces " +
                                               std::to_string(length) + " bytes, the file has " +
                                               std::to_string(bytes.size()));
    }
    if (chunk_type != 0x4E4F534Au || 20ull + chunk_length > bytes.size())
      return make_error(ErrorCode::kParse, "GLB without a valid JSON chunk");
    text = std::string_view(bytes).substr(20, chunk_length);
  }
  Json json = Json::parse(text, nullptr, false);
  if (json.is_discarded() || !json.is_object())
    return make_error(ErrorCode::kParse, "the glTF JSON does not parse");
  return json;
}

size_t array_size(const Json& json, const char* key) {
  auto it = json.find(key);
  return it != json.end() && it->is_array() ? it->size() : 0;
}

// Extensions whose content reaches the Mesh (geometry decoded by Draco) or
// that change nothing we carry.
bool extension_carried(const std::string& name) {
  static const std::set<std::string> kCarried = {"KHR_draco_mesh_compression",
                                                 "KHR_mesh_quantization"};
  return kCarried.count(name) != 0;
}

// Notes for what the file holds and the Mesh will not: counted from the JSON.
void gltf_inventory(const Json& json, std::vector<std::string>& notes) {
  auto count_note = [&](size_t n, const std::string& what) {
    if (n > 0) notes.push_back(std::to_string(n) + " " + what + " not carried");
  };
  count_note(array_size(json, "animations"), "animation(s)");
  count_note(array_size(json, "skins"), "skin(s) (joints and weights are kept as attributes)");
  count_note(array_size(json, "cameras"), "camera(s)");
  if (array_size(json, "scenes") > 1)
    notes.push_back(std::to_string(array_size(json, "scenes")) +
                    " scenes: only the default scene is read");
  size_t morph_primitives = 0, non_triangle_primitives = 0;
  if (auto meshes = json.find("meshes"); meshes != json.end() && meshes->is_array()) {
    for (const Json& mesh : *meshes) {
      auto primitives = mesh.find("primitives");
      if (primitives == mesh.end() || !primitives->is_array()) continue;
      for (const Json& primitive : *primitives) {
        if (array_size(primitive, "targets") > 0) ++morph_primitives;
        auto mode = primitive.find("mode");
        if (mode != primitive.end() && mode->is_number_integer() && *mode != 4 && *mode != 5 &&
            *mode != 6)
          ++non_triangle_primitives;
      }
    }
  }
  count_note(morph_primitives, "primitive(s) with morph targets: the targets are");
  count_note(non_triangle_primitives, "point or line primitive(s)");
  if (auto materials = json.find("materials"); materials != json.end() && materials->is_array()) {
    for (const Json& material : *materials) {
      const std::string name = material.value("name", std::string("(unnamed)"));
      const std::string alpha = material.value("alphaMode", std::string("OPAQUE"));
      if (alpha != "OPAQUE")
        notes.push_back("material " + name + ": alphaMode " + alpha + " not carried");
      if (auto e = material.find("emissiveFactor"); e != material.end() && e->is_array()) {
        for (const Json& x : *e) {
          if (x.is_number() && x.get<double>() != 0) {
            notes.push_back("material " + name + ": emissiveFactor not carried");
            break;
          }
        }
      }
      if (auto ext = material.find("extensions"); ext != material.end() && ext->is_object()) {
        for (auto it = ext->begin(); it != ext->end(); ++it)
          notes.push_back("material " + name + ": extension " + it.key() + " not carried");
      }
    }
  }
  if (auto used = json.find("extensionsUsed"); used != json.end() && used->is_array()) {
    for (const Json& name : *used) {
      if (name.is_string() && !extension_carried(name.get<std::string>()))
        notes.push_back("glTF extension " + name.get<std::string>() + " used: not carried");
    }
  }
}

// ---- The Scene to our Mesh.

using Matrix4 = Eigen::Matrix4d;

Vec3f transform_point(const Matrix4& m, const float* p) {
  const Eigen::Vector4d r = m * Eigen::Vector4d(p[0], p[1], p[2], 1.0);
  return {static_cast<float>(r[0]), static_cast<float>(r[1]), static_cast<float>(r[2])};
}

Vec3f transform_direction(const Eigen::Matrix3d& m, const float* d) {
  Eigen::Vector3d r = m * Eigen::Vector3d(d[0], d[1], d[2]);
  const double n = r.norm();
  if (n > 0) r /= n;
  return {static_cast<float>(r[0]), static_cast<float>(r[1]), static_cast<float>(r[2])};
}

bool is_identity(const Matrix4& m) { return m == Matrix4::Identity(); }

ExtraAttribute::ComponentType component_type_of(draco::DataType type, bool& ok) {
  ok = true;
  switch (type) {
    case draco::DT_INT8:
      return ExtraAttribute::ComponentType::kInt8;
    case draco::DT_UINT8:
      return ExtraAttribute::ComponentType::kUint8;
    case draco::DT_INT16:
      return ExtraAttribute::ComponentType::kInt16;
    case draco::DT_UINT16:
      return ExtraAttribute::ComponentType::kUint16;
    case draco::DT_UINT32:
      return ExtraAttribute::ComponentType::kUint32;
    case draco::DT_FLOAT32:
      return ExtraAttribute::ComponentType::kFloat32;
    default:
      ok = false;
      return ExtraAttribute::ComponentType::kFloat32;
  }
}

// The glTF semantic of a Draco attribute we carry as an extra attribute;
// `set` counts attributes of the same type in the primitive.
std::string semantic_of(draco::GeometryAttribute::Type type, int set) {
  switch (type) {
    case draco::GeometryAttribute::TANGENT:
      return set == 0 ? "TANGENT" : "";
    case draco::GeometryAttribute::TEX_COORD:
      return "TEXCOORD_" + std::to_string(set);
    case draco::GeometryAttribute::COLOR:
      return "COLOR_" + std::to_string(set);
    case draco::GeometryAttribute::JOINTS:
      return "JOINTS_" + std::to_string(set);
    case draco::GeometryAttribute::WEIGHTS:
      return "WEIGHTS_" + std::to_string(set);
    case draco::GeometryAttribute::GENERIC:
      return "_GENERIC_" + std::to_string(set);
    default:
      return "";
  }
}

class SceneFlattener {
 public:
  // `file_has_materials`: the JSON has a materials array (Draco adds a
  // default material to a file without one; we do not).
  SceneFlattener(const draco::Scene& scene, bool file_has_materials, RawMesh& raw)
      : scene_(scene), file_has_materials_(file_has_materials), raw_(raw), mesh_(raw.mesh) {}

  Status run();

 private:
  Status add_textures();
  void add_materials();
  Status add_instance(const draco::Mesh& dm, const Matrix4& transform, int material);
  void add_extra(const std::string& name, const draco::PointAttribute& attribute,
                 const draco::Mesh& dm, const Eigen::Matrix3d& linear, bool reverse);

  const draco::Scene& scene_;
  bool file_has_materials_;
  RawMesh& raw_;
  Mesh& mesh_;
  std::unordered_map<const draco::Texture*, int32_t> texture_index_;
  int32_t default_material_ = -1;
  // Extra attributes by name, and the faces each primitive added before a
  // name first appeared (filled with zeros then).
  std::map<std::string, size_t> extra_index_;
  std::set<std::string> extra_mismatch_;
};

Status SceneFlattener::add_textures() {
  const draco::TextureLibrary& library = scene_.GetMaterialLibrary().GetTextureLibrary();
  for (size_t t = 0; t < library.NumTextures(); ++t) {
    const draco::Texture* texture = library.GetTexture(static_cast<int>(t));
    const draco::SourceImage& image = texture->source_image();
    Texture ours;
    if (!image.encoded_data().empty()) {
      ours.bytes = image.encoded_data();
      ours.name = image.filename().empty()
                      ? "image" + std::to_string(t)
                      : std::filesystem::path(image.filename()).filename().string();
    } else if (!image.filename().empty()) {
      // An external image: Draco keeps its name; the bytes are the file's.
      auto read = read_texture_file(image.filename());
      if (!read) {
        return make_error(ErrorCode::kIo,
                          "image " + image.filename() + " cannot be read: " + read.error().message);
      }
      ours = std::move(*read);
    } else {
      return make_error(ErrorCode::kParse, "image " + std::to_string(t) + " has no data");
    }
    ours.mime_type = image_mime_type(ours.bytes);
    if (ours.mime_type.empty()) {
      raw_.notes.push_back("image " + ours.name + " is not PNG or JPEG: kept as bytes, type " +
                           image.mime_type());
      ours.mime_type = image.mime_type();
    }
    texture_index_[texture] = static_cast<int32_t>(mesh_.textures.size());
    mesh_.textures.push_back(std::move(ours));
  }
  return {};
}

void SceneFlattener::add_materials() {
  const draco::MaterialLibrary& library = scene_.GetMaterialLibrary();
  for (size_t m = 0; m < library.NumMaterials(); ++m) {
    const draco::Material* dm = library.GetMaterial(static_cast<int>(m));
    Material material;
    material.name = dm->GetName().empty() ? "material" + std::to_string(m) : dm->GetName();
    const draco::Vector4f c = dm->GetColorFactor();
    material.base_color = {c[0], c[1], c[2], c[3]};
    material.metallic = dm->GetMetallicFactor();
    material.roughness = dm->GetRoughnessFactor();
    material.double_sided = dm->GetDoubleSided();
    for (size_t k = 0; k < dm->NumTextureMaps(); ++k) {
      const draco::TextureMap* map = dm->GetTextureMapByIndex(static_cast<int>(k));
      auto found = texture_index_.find(map->texture());
      const int32_t index = found == texture_index_.end() ? -1 : found->second;
      int32_t* slot = nullptr;
      const char* what = "";
      switch (map->type()) {
        case draco::TextureMap::COLOR:
          slot = &material.base_color_texture;
          what = "base colour";
          break;
        case draco::TextureMap::NORMAL_TANGENT_SPACE:
          slot = &material.normal_texture;
          what = "normal";
          break;
        case draco::TextureMap::METALLIC_ROUGHNESS:
          slot = &material.metallic_roughness_texture;
          what = "metallic-roughness";
          break;
        case draco::TextureMap::AMBIENT_OCCLUSION:
          slot = &material.occlusion_texture;
          what = "occlusion";
          break;
        case draco::TextureMap::EMISSIVE:
          slot = &material.emissive_texture;
          what = "emissive";
          break;
        default:
          break;
      }
      if (slot == nullptr) {
        raw_.notes.push_back("material " + material.name + ": texture map of Draco type " +
                             std::to_string(static_cast<int>(map->type())) +
                             " (sheen, clearcoat, transmission, ...) not carried");
        continue;
      }
      *slot = index;
      if (map->tex_coord_index() != 0) {
        raw_.notes.push_back("material " + material.name + ": the " + what +
                             " texture reads UV set " + std::to_string(map->tex_coord_index()) +
                             " (kept as TEXCOORD_" + std::to_string(map->tex_coord_index()) +
                             "; our material records set 0 only)");
      }
      if (!draco::TextureTransform::IsDefault(map->texture_transform())) {
        raw_.notes.push_back("material " + material.name + ": the " + what +
                             " texture's KHR_texture_transform not carried");
      }
    }
    mesh_.materials.push_back(std::move(material));
  }
}

void SceneFlattener::add_extra(const std::string& name, const draco::PointAttribute& attribute,
                               const draco::Mesh& dm, const Eigen::Matrix3d& linear, bool reverse) {
  bool ok = false;
  const ExtraAttribute::ComponentType type = component_type_of(attribute.data_type(), ok);
  if (!ok || attribute.num_components() < 1 || attribute.num_components() > 4) {
    if (extra_mismatch_.insert(name).second)
      raw_.notes.push_back("attribute " + name + " of an unsupported type not carried");
    return;
  }
  const size_t faces_before = 3 * (mesh_.triangles.size() - dm.num_faces());
  auto found = extra_index_.find(name);
  if (found == extra_index_.end()) {
    ExtraAttribute extra;
    extra.name = name;
    extra.component_type = type;
    extra.components = attribute.num_components();
    extra.normalized = attribute.normalized();
    extra.bytes.assign(faces_before * element_size(extra), 0);  // earlier primitives had none
    found = extra_index_.emplace(name, mesh_.extra_attributes.size()).first;
    mesh_.extra_attributes.push_back(std::move(extra));
  }
  ExtraAttribute& extra = mesh_.extra_attributes[found->second];
  const size_t size = element_size(extra);
  if (extra.component_type != type || extra.components != attribute.num_components()) {
    if (extra_mismatch_.insert(name).second)
      raw_.notes.push_back("attribute " + name +
                           " has different types in different primitives: zeros where they differ");
    extra.bytes.resize(3 * mesh_.triangles.size() * size, 0);
    return;
  }
  extra.bytes.resize(faces_before * size);
  const bool tangent =
      name == "TANGENT" && type == ExtraAttribute::ComponentType::kFloat32 &&
      extra.components >= 3 &&
      linear != Eigen::Matrix3d::Identity();  // untouched bits when not transformed
  for (uint32_t f = 0; f < dm.num_faces(); ++f) {
    const auto& face = dm.face(draco::FaceIndex(f));
    for (int k = 0; k < 3; ++k) {
      const int corner = reverse && k > 0 ? 3 - k : k;
      const auto value = attribute.mapped_index(face[corner]);
      const uint8_t* bytes = attribute.GetAddress(value);
      const size_t at = extra.bytes.size();
      extra.bytes.insert(extra.bytes.end(), bytes, bytes + size);
      if (tangent) {
        float t[4];
        std::memcpy(t, bytes, size);
        const Vec3f d = transform_direction(linear, t);
        std::memcpy(extra.bytes.data() + at, &d, sizeof d);
      }
    }
  }
}

Status SceneFlattener::add_instance(const draco::Mesh& dm, const Matrix4& transform, int material) {
  const draco::PointAttribute* position = dm.GetNamedAttribute(draco::GeometryAttribute::POSITION);
  if (position == nullptr || position->num_components() != 3)
    return make_error(ErrorCode::kParse, "a primitive has no 3-D positions");
  const bool identity = is_identity(transform);
  const Eigen::Matrix3d linear = transform.topLeftCorner<3, 3>();
  const Eigen::Matrix3d normal_matrix = linear.inverse().transpose();
  const bool reverse = linear.determinant() < 0;  // mirrored: keep the faces outward

  const uint32_t base = mesh_.vertex_count();
  for (uint32_t v = 0; v < position->size(); ++v) {
    float p[3];
    if (!position->ConvertValue<float>(draco::AttributeValueIndex(v), 3, p))
      return make_error(ErrorCode::kParse, "a position could not be read");
    mesh_.positions.push_back(identity ? Vec3f{p[0], p[1], p[2]} : transform_point(transform, p));
  }
  const size_t corner_base = 3 * mesh_.triangles.size();
  for (uint32_t f = 0; f < dm.num_faces(); ++f) {
    const auto& face = dm.face(draco::FaceIndex(f));
    Triangle t;
    for (int k = 0; k < 3; ++k) {
      if (face[k].value() >= dm.num_points())
        return make_error(ErrorCode::kInvalidMesh, "a face refers to a vertex that does not exist");
      t[k] = base + position->mapped_index(face[k]).value();
    }
    if (reverse) std::swap(t[1], t[2]);
    mesh_.triangles.push_back(t);
  }
  raw_.vertices_in_file += dm.num_points();

  if (!file_has_materials_) {
    // No materials in the file at all: none in the mesh either.
  } else if (material < 0) {
    if (default_material_ < 0) {
      default_material_ = static_cast<int32_t>(mesh_.materials.size());
      mesh_.materials.push_back({.name = "(default material)"});
    }
    material = default_material_;
  }
  if (material >= 0)
    mesh_.face_materials.resize(mesh_.triangles.size(), static_cast<uint32_t>(material));

  // Corner attributes: the first of each kind; the rest are extra attributes.
  auto corners = [&](auto& target, const draco::PointAttribute& attribute, int n, float fill,
                     auto convert) {
    // Primitives without the kind get the fill value (one shared value).
    using V = typename std::remove_reference_t<decltype(target.values)>::value_type;
    const uint32_t value_base = static_cast<uint32_t>(target.values.size());
    if (target.corners.size() < corner_base) {
      V filler;
      float* x = &filler.x;
      for (size_t i = 0; i < sizeof(V) / sizeof(float); ++i) x[i] = fill;
      if constexpr (sizeof(V) == sizeof(Vec4f)) filler.w = 1.0f;
      target.values.push_back(filler);
      target.corners.resize(corner_base, value_base);
    }
    const uint32_t first = static_cast<uint32_t>(target.values.size());
    for (uint32_t v = 0; v < attribute.size(); ++v) {
      float value[4] = {fill, fill, fill, 1.0f};
      attribute.ConvertValue<float>(draco::AttributeValueIndex(v), static_cast<int8_t>(n), value);
      target.values.push_back(convert(value));
    }
    for (uint32_t f = 0; f < dm.num_faces(); ++f) {
      const auto& face = dm.face(draco::FaceIndex(f));
      for (int k = 0; k < 3; ++k) {
        const int corner = reverse && k > 0 ? 3 - k : k;
        target.corners.push_back(first + attribute.mapped_index(face[corner]).value());
      }
    }
  };
  std::map<int, int> seen;  // attribute type -> count so far in this primitive
  for (int a = 0; a < dm.num_attributes(); ++a) {
    const draco::PointAttribute& attribute = *dm.attribute(a);
    const auto type = attribute.attribute_type();
    if (type == draco::GeometryAttribute::POSITION) continue;
    const int set = seen[type]++;
    if (type == draco::GeometryAttribute::NORMAL && set == 0) {
      corners(mesh_.corner_normals, attribute, 3, 0.0f, [&](const float* v) {
        return identity ? Vec3f{v[0], v[1], v[2]} : transform_direction(normal_matrix, v);
      });
    } else if (type == draco::GeometryAttribute::TEX_COORD && set == 0) {
      corners(mesh_.corner_texcoords, attribute, 2, 0.0f, [](const float* v) {
        return Vec2f{v[0], v[1]};
      });
    } else if (type == draco::GeometryAttribute::COLOR && set == 0) {
      const int n = std::min<int>(4, attribute.num_components());
      corners(mesh_.corner_colors, attribute, n, 1.0f, [](const float* v) {
        return Vec4f{v[0], v[1], v[2], v[3]};
      });
    } else if (type == draco::GeometryAttribute::MATERIAL) {
      // Draco's per-face material index (from a merged primitive): ours is face_materials.
      continue;
    } else {
      const std::string name = semantic_of(type, set);
      if (name.empty()) {
        raw_.notes.push_back("an attribute of Draco type " + std::to_string(type) + " not carried");
        continue;
      }
      add_extra(name, attribute, dm, linear, reverse);
    }
  }
  // Kinds this primitive lacks but earlier ones had: the fill value.
  auto pad = [&](auto& target, float fill) {
    using V = typename std::remove_reference_t<decltype(target.values)>::value_type;
    if (target.corners.empty() || target.corners.size() == 3 * mesh_.triangles.size()) return;
    V filler;
    float* x = &filler.x;
    for (size_t i = 0; i < sizeof(V) / sizeof(float); ++i) x[i] = fill;
    if constexpr (sizeof(V) == sizeof(Vec4f)) filler.w = 1.0f;
    target.values.push_back(filler);
    target.corners.resize(3 * mesh_.triangles.size(),
                          static_cast<uint32_t>(target.values.size() - 1));
  };
  pad(mesh_.corner_normals, 0.0f);
  pad(mesh_.corner_texcoords, 0.0f);
  pad(mesh_.corner_colors, 1.0f);
  for (ExtraAttribute& extra : mesh_.extra_attributes)
    extra.bytes.resize(3 * mesh_.triangles.size() * element_size(extra), 0);
  return {};
}

Status SceneFlattener::run() {
  if (auto s = add_textures(); !s) return s;
  if (file_has_materials_) add_materials();
  const auto instances = draco::SceneUtils::ComputeAllInstances(scene_);
  if (instances.size() == 0) return make_error(ErrorCode::kInvalidMesh, "the scene has no mesh");
  for (auto i = draco::MeshInstanceIndex(0); i < instances.size(); ++i) {
    const auto& instance = instances[i];
    const int material = draco::SceneUtils::GetMeshInstanceMaterialIndex(scene_, instance);
    if (auto s = add_instance(scene_.GetMesh(instance.mesh_index), instance.transform,
                              material >= static_cast<int>(mesh_.materials.size()) ? -1 : material);
        !s) {
      return s;
    }
  }
  // Normals must be a unit vector, a filler of zeros for primitives without
  // one is a note, not a silent value.
  raw_.contents.normals.count = mesh_.corner_normals.values.size();
  raw_.contents.texcoords.count = mesh_.corner_texcoords.values.size();
  raw_.contents.colors.count = mesh_.corner_colors.values.size();
  return {};
}

}  // namespace

Result<RawMesh> read_gltf(const std::string& path) {
  auto bytes = read_file_bytes(path);
  if (!bytes) return tl::unexpected(bytes.error());
  auto json = read_gltf_json(*bytes);
  if (!json) return tl::unexpected(json.error());
  RawMesh raw;
  raw.contents.format = bytes->compare(0, 4, "glTF") == 0 ? "GLB" : "glTF";
  // Draco would refuse a missing buffer file with a vague message: name it.
  if (auto buffers = json->find("buffers"); buffers != json->end() && buffers->is_array()) {
    for (const Json& buffer : *buffers) {
      const std::string uri = buffer.value("uri", std::string());
      if (uri.empty() || uri.rfind("data:", 0) == 0) continue;
      const auto file = std::filesystem::path(path).parent_path() / uri;
      if (!std::filesystem::exists(file))
        return make_error(ErrorCode::kIo, "buffer file " + uri + " not found beside the glTF");
    }
  }
  if (auto images = json->find("images"); images != json->end() && images->is_array()) {
    for (const Json& image : *images) {
      const std::string uri = image.value("uri", std::string());
      if (uri.empty() || uri.rfind("data:", 0) == 0) continue;
      const auto file = std::filesystem::path(path).parent_path() / uri;
      if (!std::filesystem::exists(file))
        return make_error(ErrorCode::kIo, "image file " + uri + " not found beside the glTF");
    }
  }
  std::unique_ptr<draco::Scene> scene;
  try {
    auto read = draco::ReadSceneFromFile(path);
    if (!read.ok()) {
      return make_error(ErrorCode::kParse,
                        std::string("Draco could not read it: ") + read.status().error_msg());
    }
    scene = std::move(read).value();
  } catch (const std::exception& e) {
    return make_error(ErrorCode::kParse, std::string("Draco could not read it: ") + e.what());
  }
  SceneFlattener flattener(*scene, array_size(*json, "materials") > 0, raw);
  if (auto s = flattener.run(); !s) return tl::unexpected(s.error());
  gltf_inventory(*json, raw.notes);
  return raw;
}

}  // namespace meshstream

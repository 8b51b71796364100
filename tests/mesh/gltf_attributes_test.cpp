// Attributes end to end in common/mesh (issue 18): glTF import (seams,
// node transforms, materials, textures, extra attributes, what is not
// carried), hostile glTF files, cleaning that carries corner data, and
// round trips import -> export (GLB, glTF, OBJ, PLY) -> import that give the
// same welded mesh and attributes; our glTF passes the Khronos validator.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "common/mesh/corner_data.h"
#include "common/mesh/export.h"
#include "common/mesh/import.h"
#include "common/mesh/procedural.h"
#include "common/mesh/texture_files.h"
#include "common/mesh/topology.h"
#include "tests/gltf_validator.h"
#include "tests/test_meshes.h"

namespace meshstream {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

// A fresh folder under the temporary directory, removed at the end.
class TempDir {
 public:
  explicit TempDir(const std::string& name) {
    path_ =
        fs::temp_directory_path() / ("meshstream_attr_" + std::to_string(::getpid()) + "_" + name);
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() { fs::remove_all(path_); }
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

bool has_note(const CleanReport& report, const std::string& text) {
  for (const std::string& note : report.notes) {
    if (note.find(text) != std::string::npos) return true;
  }
  return false;
}

std::string notes_of(const CleanReport& report) {
  std::string all;
  for (const std::string& note : report.notes) all += "\n  " + note;
  return all;
}

ImportedMesh import_ok(const std::string& path) {
  auto imported = import_mesh(path);
  EXPECT_TRUE(imported) << path << ": " << (imported ? "" : imported.error().message);
  return imported ? std::move(*imported) : ImportedMesh{};
}

// What a mesh means independently of vertex and face order: for every face,
// the bytes of each corner's position, normal, texture coordinate, colour,
// extra attributes and the face's material name, rotated so the smallest
// corner comes first; sorted. Two meshes with equal signatures have the same
// welded surface and the same attribute values at every corner.
struct SignatureParts {
  bool normals = true, texcoords = true, colors = true, extras = true, materials = true;
  // Normals and float extra attributes rounded to 2^-16: Draco's glTF
  // reader moves some normals and tangents by an ulp.
  // Also: -0 and +0 positions compared as equal (Draco's glTF reader).
  bool round_directions = false;
  // Texture coordinates compared after a float v -> 1 - (1 - v): glTF's v
  // is 1 - ours, exact only on values that came from a glTF file.
  bool round_texcoords = false;
};

std::string rounded(const float* values, size_t n) {
  std::string out;
  for (size_t i = 0; i < n; ++i) out += std::to_string(std::lround(values[i] * 65536.0)) + ",";
  return out;
}

std::vector<std::string> signature(const Mesh& m, const SignatureParts& parts = {}) {
  std::vector<std::string> faces;
  faces.reserve(m.face_count());
  auto bytes = [](const void* p, size_t size) {
    return std::string(static_cast<const char*>(p), size);
  };
  for (uint32_t f = 0; f < m.face_count(); ++f) {
    std::string corner[3];
    for (uint32_t k = 0; k < 3; ++k) {
      const size_t c = 3 * f + k;
      const uint32_t v = m.triangles[f][k];
      std::string& s = corner[k];
      Vec3f position = m.positions[v];
      if (parts.round_directions) {
        // Draco's glTF reader turns -0 into +0.
        for (float* x : {&position.x, &position.y, &position.z}) *x += 0.0f;
      }
      s = bytes(&position, sizeof(Vec3f));
      if (parts.normals) {
        const Vec3f* n = !m.normals.empty()          ? &m.normals[v]
                         : !m.corner_normals.empty() ? &m.corner_normals.at_corner(c)
                                                     : nullptr;
        if (n != nullptr) s += parts.round_directions ? rounded(&n->x, 3) : bytes(n, sizeof(Vec3f));
      }
      if (parts.texcoords) {
        const Vec2f* t = !m.texcoords.empty()          ? &m.texcoords[v]
                         : !m.corner_texcoords.empty() ? &m.corner_texcoords.at_corner(c)
                                                       : nullptr;
        if (t != nullptr) {
          Vec2f value = *t;
          // Through glTF and back: v -> 1 - v -> 1 - (1 - v) in float, exact
          // on values that came from a glTF file, else within half an ulp.
          volatile float flipped = 1.0f - value.y;
          if (parts.round_texcoords) value.y = 1.0f - flipped;
          s += bytes(&value, sizeof(Vec2f));
        }
      }
      if (parts.colors) {
        if (!m.colors.empty()) s += bytes(&m.colors[v], sizeof(Vec4f));
        if (!m.corner_colors.empty()) s += bytes(&m.corner_colors.at_corner(c), sizeof(Vec4f));
      }
      if (parts.extras) {
        for (const ExtraAttribute& e : m.extra_attributes) {
          const uint8_t* p = e.bytes.data() + c * element_size(e);
          if (parts.round_directions &&
              e.component_type == ExtraAttribute::ComponentType::kFloat32) {
            float x[4];
            std::memcpy(x, p, element_size(e));
            s += e.name + rounded(x, e.components);
          } else {
            s += e.name + bytes(p, element_size(e));
          }
        }
      }
    }
    const uint32_t first = corner[0] <= corner[1] && corner[0] <= corner[2] ? 0
                           : corner[1] <= corner[2]                         ? 1
                                                                            : 2;
    std::string face =
        corner[first] + "|" + corner[(first + 1) % 3] + "|" + corner[(first + 2) % 3];
    if (parts.materials && !m.face_materials.empty()) {
      const Material& mat = m.materials[m.face_materials[f]];
      face += "|" + mat.name + bytes(&mat.base_color, sizeof(Vec4f));
      if (mat.base_color_texture >= 0) {
        const Texture& t = m.textures[mat.base_color_texture];
        face += bytes(t.bytes.data(), std::min<size_t>(t.bytes.size(), 64)) +
                std::to_string(t.bytes.size());
      }
    }
    faces.push_back(face);
  }
  std::sort(faces.begin(), faces.end());
  return faces;
}

// ---- Procedural meshes with seams through clean_mesh.

TEST(CornerData, CleaningCarriesCornerNormalsThroughFlipsDropsAndWelds) {
  Mesh cube = make_faceted_cube(2);
  cube.materials = {{.name = "a"}, {.name = "b"}};
  cube.face_materials.resize(cube.face_count());
  for (uint32_t f = 0; f < cube.face_count(); ++f) cube.face_materials[f] = f % 2;
  ExtraAttribute id{.name = "_CORNER_ID",
                    .component_type = ExtraAttribute::ComponentType::kUint32,
                    .components = 1};
  for (uint32_t c = 0; c < 3 * cube.face_count(); ++c) {
    const uint8_t* p = reinterpret_cast<const uint8_t*>(&c);
    id.bytes.insert(id.bytes.end(), p, p + 4);
  }
  cube.extra_attributes.push_back(id);
  const std::vector<std::string> expected = signature(cube);

  Mesh damaged = cube;
  // Flip three faces (corners and their data permuted consistently, as a
  // file with wrong winding would have them), append a duplicate and a
  // degenerate face, and unweld one vertex.
  for (uint32_t f : {0u, 5u, 17u}) reverse_face(damaged, f);
  auto append_face = [&](Triangle t, uint32_t source) {
    damaged.triangles.push_back(t);
    for (auto* attribute : {&damaged.corner_normals}) {
      for (uint32_t k = 0; k < 3; ++k)
        attribute->corners.push_back(attribute->corners[3 * source + k]);
    }
    for (uint32_t k = 0; k < 3; ++k)
      damaged.corner_texcoords.corners.push_back(damaged.corner_texcoords.corners[3 * source + k]);
    damaged.face_materials.push_back(damaged.face_materials[source]);
    ExtraAttribute& e = damaged.extra_attributes[0];
    std::vector<uint8_t> copy(e.bytes.begin() + 12 * source, e.bytes.begin() + 12 * source + 12);
    e.bytes.insert(e.bytes.end(), copy.begin(), copy.end());
  };
  append_face(damaged.triangles[3], 3);
  append_face({damaged.triangles[4][0], damaged.triangles[4][0], damaged.triangles[4][1]}, 4);
  damaged.positions.push_back(damaged.positions[damaged.triangles[7][0]]);
  damaged.colors.push_back(damaged.colors[damaged.triangles[7][0]]);
  damaged.triangles[7][0] = damaged.vertex_count() - 1;
  ASSERT_TRUE(check_attribute_counts(damaged));

  auto report = clean_mesh(damaged);
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_EQ(report->flipped_faces, 3u);
  EXPECT_EQ(report->duplicate_faces, 1u);
  EXPECT_EQ(report->degenerate_faces, 1u);
  EXPECT_EQ(report->welded_vertices, 1u);
  ASSERT_TRUE(check_attribute_counts(damaged));
  EXPECT_EQ(signature(damaged), expected);
  // Flat shading survived the flips: every corner normal is its face's.
  for (uint32_t f = 0; f < damaged.face_count(); ++f) {
    for (uint32_t k = 0; k < 3; ++k)
      EXPECT_GT(dot(damaged.corner_normals.at_corner(3 * f + k), face_normal(damaged, f)), 0.999f);
  }
}

TEST(CornerData, PerVertexValuesThatDisagreeAfterWeldingBecomeCornerValues) {
  // The sphere as a file would split it: one vertex per corner.
  const Mesh sphere = make_uv_sphere(12, 6);
  Mesh split;
  for (uint32_t c = 0; c < 3 * sphere.face_count(); ++c) {
    const uint32_t v = sphere.triangles[c / 3][c % 3];
    split.positions.push_back(sphere.positions[v]);
    split.normals.push_back(sphere.normals[v]);
    split.texcoords.push_back(sphere.corner_texcoords.at_corner(c));
    if (c % 3 == 2) split.triangles.push_back({c - 2, c - 1, c});
  }
  auto report = clean_mesh(split);
  ASSERT_TRUE(report) << report.error().message;
  EXPECT_EQ(split.vertex_count(), sphere.vertex_count());
  EXPECT_EQ(split.normals.size(), split.vertex_count()) << "seamless normals stay per vertex";
  ASSERT_FALSE(split.corner_texcoords.empty()) << "the UV seam is kept per corner";
  EXPECT_EQ(count_seam_vertices(split, split.corner_texcoords),
            count_seam_vertices(sphere, sphere.corner_texcoords));
  EXPECT_EQ(signature(split), signature(sphere));
}

// ---- Round trips through our writers.

struct Format {
  const char* extension;
  SignatureParts kept;
};

// PLY: per vertex, no materials or extras (colours are bytes: exact only
// for colours that were bytes). OBJ: no colours, no extras. glTF: all.
const Format kFormats[] = {
    {".glb", {.round_directions = true}},
    {".gltf", {.round_directions = true}},
    {".obj", {.colors = false, .extras = false}},
    {".ply", {.extras = false, .materials = false}},
};

void expect_round_trip(const Mesh& original, const std::string& label, bool byte_colors,
                       bool from_gltf = true) {
  TempDir dir("rt_" + label);
  for (const Format& format : kFormats) {
    SignatureParts parts = format.kept;
    if (std::string(format.extension) == ".ply" && !byte_colors) parts.colors = false;
    if (format.kept.round_directions && !from_gltf) {
      parts.round_texcoords = true;
    }
    const std::string path = dir.file("out" + std::string(format.extension));
    ASSERT_TRUE(write_mesh(original, path)) << label << format.extension;
    auto back = import_mesh(path);
    ASSERT_TRUE(back) << label << format.extension << ": " << back.error().message;
    EXPECT_EQ(back->mesh.vertex_count(), original.vertex_count()) << label << format.extension;
    EXPECT_EQ(back->mesh.face_count(), original.face_count()) << label << format.extension;
    EXPECT_TRUE(signature(back->mesh, parts) == signature(original, parts))
        << label << format.extension << ": attributes differ after the round trip";
    if (format.kept.round_directions && !original.textures.empty()) {  // glTF: every texture
      ASSERT_EQ(back->mesh.textures.size(), original.textures.size()) << label << format.extension;
      for (size_t t = 0; t < original.textures.size(); ++t)
        EXPECT_TRUE(back->mesh.textures[t].bytes == original.textures[t].bytes)
            << label << format.extension << ": texture " << t << " not byte-identical";
    }
  }
}

TEST(AttributeRoundTrip, ProceduralMeshesWithSeams) {
  Mesh cube = make_faceted_cube(3);
  // Byte-exact colours so the PLY (uchar colours) comparison is exact too.
  for (Vec4f& c : cube.colors)
    c = {std::round(c.x * 255) / 255, std::round(c.y * 255) / 255, std::round(c.z * 255) / 255,
         1.0f};
  for (Vec4f& c : cube.colors) {
    for (float* x : {&c.x, &c.y, &c.z}) *x = static_cast<float>(std::lround(*x * 255.0f)) / 255.0f;
  }
  // glTF's v is 1 - ours: exact on multiples of 2^-20 (any value that came
  // from a glTF file is exact too: the flip of a flip).
  auto snap = [](Mesh& m) {
    for (Vec2f& t : m.corner_texcoords.values) t.y = std::round(t.y * 1048576.0f) / 1048576.0f;
  };
  snap(cube);
  ASSERT_TRUE(clean_mesh(cube));
  expect_round_trip(cube, "cube", false);
  Mesh sphere = make_uv_sphere(24, 12);
  snap(sphere);
  ASSERT_TRUE(clean_mesh(sphere));
  expect_round_trip(sphere, "sphere", false);
}

const char* const kModels[] = {"Duck/Duck.glb",
                               "CesiumMilkTruck/CesiumMilkTruck.gltf",
                               "SheenCloth/SheenCloth.glb",
                               "SphereWithCircleTexture/sphere_with_circle_texture.gltf",
                               "test_pos_color.ply",
                               "usb/usb.obj"};

TEST(AttributeRoundTrip, EveryModel) {
  MESHSTREAM_REQUIRE_TEST_MODELS();
  for (const char* name : kModels) {
    const std::string path = testing::test_model(name);
    if (!fs::exists(path)) {
      ADD_FAILURE() << path << " missing from the models folder";
      continue;
    }
    const ImportedMesh imported = import_ok(path);
    const bool byte_colors = std::string(name).ends_with(".ply");
    const bool from_gltf = imported.contents.format == "GLB" || imported.contents.format == "glTF";
    expect_round_trip(imported.mesh, fs::path(name).stem().string(), byte_colors, from_gltf);
  }
}

// ---- glTF import facts.

TEST(GltfImport, DuckIsWeldedWithItsSeamsAndTexture) {
  MESHSTREAM_REQUIRE_TEST_MODELS();
  const ImportedMesh duck = import_ok(testing::test_model("Duck/Duck.glb"));
  const Mesh& m = duck.mesh;
  EXPECT_EQ(duck.contents.format, "GLB");
  EXPECT_EQ(m.vertex_count(), 2108u);  // 2399 glTF vertices on 2108 positions
  EXPECT_EQ(m.face_count(), 4212u);
  EXPECT_EQ(duck.report.vertices_in_file, 2399u);
  ASSERT_FALSE(m.corner_texcoords.empty());
  EXPECT_GT(count_seam_vertices(m, m.corner_texcoords), 0u);
  EXPECT_TRUE(!m.normals.empty() || !m.corner_normals.empty());
  ASSERT_EQ(m.materials.size(), 1u);
  ASSERT_EQ(m.textures.size(), 1u);
  EXPECT_EQ(m.textures[0].mime_type, "image/png");
  EXPECT_EQ(image_mime_type(m.textures[0].bytes), "image/png");
  EXPECT_EQ(m.materials[0].base_color_texture, 0);
  EXPECT_EQ(m.face_materials.size(), m.face_count());
  EXPECT_TRUE(has_note(duck.report, "camera")) << notes_of(duck.report);
}

TEST(GltfImport, MilkTruckAppliesNodeTransformsAndNamesTheAnimation) {
  MESHSTREAM_REQUIRE_TEST_MODELS();
  const std::string path = testing::test_model("CesiumMilkTruck/CesiumMilkTruck.gltf");
  const ImportedMesh truck = import_ok(path);
  const Mesh& m = truck.mesh;
  EXPECT_EQ(m.materials.size(), 4u);
  ASSERT_EQ(m.textures.size(), 1u);
  // The external PNG, byte for byte.
  std::ifstream png(testing::test_model("CesiumMilkTruck/CesiumMilkTruck.png"), std::ios::binary);
  const std::vector<uint8_t> file((std::istreambuf_iterator<char>(png)),
                                  std::istreambuf_iterator<char>());
  EXPECT_TRUE(m.textures[0].bytes == file);
  EXPECT_TRUE(has_note(truck.report, "animation")) << notes_of(truck.report);
  // The wheels mesh is instanced twice (front and back axle, x = -1.35 and
  // 1.43): both copies are there, so the truck is longer than one wheel.
  std::vector<uint32_t> per_material(m.materials.size(), 0);
  for (uint32_t id : m.face_materials) ++per_material[id];
  EXPECT_EQ(per_material[3], 2u * 768u) << "wheels: 768 triangles, two instances";
  const BoundingBox box = bounding_box(m);
  EXPECT_NEAR(box.max.x - box.min.x, 4.87, 0.05);
}

TEST(GltfImport, SheenClothCarriesTangentsAndMapsAndNamesSheen) {
  MESHSTREAM_REQUIRE_TEST_MODELS();
  const ImportedMesh cloth = import_ok(testing::test_model("SheenCloth/SheenCloth.glb"));
  const Mesh& m = cloth.mesh;
  ASSERT_EQ(m.extra_attributes.size(), 1u);
  EXPECT_EQ(m.extra_attributes[0].name, "TANGENT");
  EXPECT_EQ(m.extra_attributes[0].components, 4u);
  EXPECT_EQ(m.extra_attributes[0].bytes.size(), 3u * m.face_count() * 16u);
  ASSERT_EQ(m.materials.size(), 1u);
  EXPECT_GE(m.materials[0].base_color_texture, 0);
  EXPECT_GE(m.materials[0].normal_texture, 0);
  EXPECT_GE(m.materials[0].metallic_roughness_texture, 0);
  EXPECT_GE(m.materials[0].occlusion_texture, 0);
  EXPECT_TRUE(has_note(cloth.report, "KHR_materials_sheen")) << notes_of(cloth.report);
  EXPECT_TRUE(has_note(cloth.report, "KHR_texture_transform")) << notes_of(cloth.report);
}

TEST(GltfImport, PlyColoursAndObjTexturesAreKept) {
  MESHSTREAM_REQUIRE_TEST_MODELS();
  const ImportedMesh ply = import_ok(testing::test_model("test_pos_color.ply"));
  EXPECT_EQ(ply.mesh.colors.size(), ply.mesh.vertex_count());
  const ImportedMesh usb = import_ok(testing::test_model("usb/usb.obj"));
  EXPECT_TRUE(!usb.mesh.texcoords.empty() || !usb.mesh.corner_texcoords.empty());
  ASSERT_EQ(usb.mesh.materials.size(), 1u);
  ASSERT_EQ(usb.mesh.textures.size(), 1u);
  EXPECT_EQ(usb.mesh.textures[0].mime_type, "image/jpeg");
  EXPECT_EQ(usb.mesh.materials[0].base_color_texture, 0);
  EXPECT_FLOAT_EQ(usb.mesh.materials[0].base_color.x, 0.64f);
}

// ---- Hostile glTF files.

TEST(GltfImport, HostileFilesAreErrorsNamingTheReason) {
  MESHSTREAM_REQUIRE_TEST_MODELS();
  TempDir dir("hostile");
  // A truncated GLB.
  {
    std::ifstream in(testing::test_model("Duck/Duck.glb"), std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    for (size_t keep : {bytes.size() / 2, size_t{30}, size_t{10}}) {
      const std::string path = dir.file("truncated.glb");
      std::ofstream(path, std::ios::binary) << bytes.substr(0, keep);
      auto imported = import_mesh(path);
      ASSERT_FALSE(imported) << keep;
      EXPECT_THAT(imported.error().message, HasSubstr("truncated.glb"));
      EXPECT_THAT(imported.error().message, HasSubstr("truncated"));
    }
  }
  // A .gltf whose .bin is missing.
  {
    const fs::path truck = fs::path(testing::test_model("CesiumMilkTruck/CesiumMilkTruck.gltf"));
    fs::copy_file(truck, dir.path() / "truck.gltf");
    fs::copy_file(truck.parent_path() / "CesiumMilkTruck.png", dir.path() / "CesiumMilkTruck.png");
    auto imported = import_mesh(dir.file("truck.gltf"));
    ASSERT_FALSE(imported);
    EXPECT_THAT(imported.error().message, HasSubstr("truck.gltf"));
    EXPECT_THAT(imported.error().message, HasSubstr("CesiumMilkTruck0.bin"));
    // And with the .bin but without the image.
    fs::copy_file(truck.parent_path() / "CesiumMilkTruck0.bin",
                  dir.path() / "CesiumMilkTruck0.bin");
    fs::remove(dir.path() / "CesiumMilkTruck.png");
    imported = import_mesh(dir.file("truck.gltf"));
    ASSERT_FALSE(imported);
    EXPECT_THAT(imported.error().message, HasSubstr("CesiumMilkTruck.png"));
  }
  // A required extension nobody has.
  {
    Mesh m = make_icosahedron();
    ASSERT_TRUE(write_gltf(m, dir.file("ext.gltf")));
    std::ifstream in(dir.file("ext.gltf"));
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const size_t brace = text.find('{');
    text.insert(brace + 1,
                "\"extensionsRequired\":[\"EXT_nobody_has_this\"],"
                "\"extensionsUsed\":[\"EXT_nobody_has_this\"],");
    std::ofstream(dir.file("ext.gltf")) << text;
    auto imported = import_mesh(dir.file("ext.gltf"));
    ASSERT_FALSE(imported);
    EXPECT_THAT(imported.error().message, HasSubstr("ext.gltf"));
    EXPECT_THAT(imported.error().message, HasSubstr("EXT_nobody_has_this"));
  }
  // Not JSON at all.
  {
    std::ofstream(dir.file("garbage.gltf")) << "{ this is not json";
    auto imported = import_mesh(dir.file("garbage.gltf"));
    ASSERT_FALSE(imported);
    EXPECT_THAT(imported.error().message, HasSubstr("garbage.gltf"));
  }
}

// ---- The Khronos validator on our glTF output.

TEST(GltfExport, KhronosValidatorFindsNoErrors) {
  const std::string modules = testing::gltf_validator_modules();
  if (modules.empty()) {
    GTEST_SKIP() << "the Khronos gltf-validator is not installed (scripts/test installs it with "
                    "npm into build/gltf-validator; set MESHSTREAM_GLTF_VALIDATOR)";
  }
  TempDir dir("validate");
  std::vector<std::pair<std::string, Mesh>> meshes;
  meshes.emplace_back("cube", make_faceted_cube(2));
  meshes.emplace_back("sphere", make_uv_sphere(16, 8));
  meshes.emplace_back("icosphere", make_icosphere(2));
  if (!testing::test_model_dir().empty()) {
    for (const char* name : kModels) {
      auto imported = import_mesh(testing::test_model(name));
      ASSERT_TRUE(imported) << name;
      meshes.emplace_back(fs::path(name).stem().string(), std::move(imported->mesh));
    }
  }
  for (const auto& [name, mesh] : meshes) {
    for (const char* extension : {".glb", ".gltf"}) {
      const std::string path = dir.file(name + extension);
      ASSERT_TRUE(write_gltf(mesh, path)) << path;
      const auto [status, out] = testing::run_gltf_validator(modules, path);
      EXPECT_EQ(status, 0) << out;
      EXPECT_THAT(out, HasSubstr(": 0 errors")) << out;
    }
  }
  if (testing::test_model_dir().empty())
    GTEST_SKIP() << "procedural meshes validated; test models not found (MESHSTREAM_TEST_MODELS)";
}

// copy_face_data: the corner, extra and material data of the chosen faces,
// in their order, as keep_faces would keep them in place.
TEST(CornerData, CopyFaceDataTakesTheChosenFacesDataInOrder) {
  Mesh from = make_icosphere(1);
  const uint32_t F = from.face_count();
  from.corner_texcoords.values = {{0, 0}, {1, 0}, {0, 1}};
  from.face_materials.resize(F);
  ExtraAttribute extra;
  extra.name = "_FACE";
  extra.component_type = ExtraAttribute::ComponentType::kUint8;
  ExtraAttribute wrong = extra;
  wrong.name = "_SHORT";
  wrong.bytes = {1, 2, 3};
  for (uint32_t f = 0; f < F; ++f) {
    for (uint32_t k = 0; k < 3; ++k) {
      from.corner_texcoords.corners.push_back((f + k) % 3);
      extra.bytes.push_back(uint8_t(3 * f + k));
    }
    from.face_materials[f] = f % 4;
  }
  from.materials.resize(4);
  from.extra_attributes = {extra, wrong};
  const std::vector<uint32_t> faces = {7, 2, 19};
  Mesh to;
  to.corner_normals.values = {{0, 0, 1}};  // replaced: `from` has none
  to.corner_normals.corners = {0, 0, 0};
  copy_face_data(from, faces, to);
  EXPECT_TRUE(to.corner_normals.empty());
  EXPECT_EQ(to.corner_texcoords.values.size(), 3u);
  ASSERT_EQ(to.corner_texcoords.corners.size(), 9u);
  ASSERT_EQ(to.face_materials.size(), 3u);
  ASSERT_EQ(to.extra_attributes.size(), 2u);
  ASSERT_EQ(to.extra_attributes[0].bytes.size(), 9u);
  for (size_t i = 0; i < faces.size(); ++i) {
    EXPECT_EQ(to.face_materials[i], faces[i] % 4);
    for (uint32_t k = 0; k < 3; ++k) {
      EXPECT_EQ(to.corner_texcoords.corners[3 * i + k], (faces[i] + k) % 3);
      EXPECT_EQ(to.extra_attributes[0].bytes[3 * i + k], uint8_t(3 * faces[i] + k));
    }
  }
  EXPECT_EQ(to.extra_attributes[1].name, "_SHORT");
  EXPECT_TRUE(to.extra_attributes[1].bytes.empty()) << "an extra of the wrong size comes out empty";
}

}  // namespace
}  // namespace meshstream

// Extra attributes (tangents, a second UV set, custom ones: Mesh::
// extra_attributes, per corner) written to PLY as vertex properties of their
// own type, read back from the file byte for byte at every corner, in binary
// and ASCII; OBJ, which cannot hold them, names them in export_losses (the
// commands' warning) instead of dropping them silently.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "common/mesh/export.h"
#include "common/mesh/import.h"

namespace meshstream {
namespace {

using ::testing::Contains;
using ::testing::HasSubstr;
using Type = ExtraAttribute::ComponentType;

std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("meshstream_ply_extras_" + std::to_string(::getpid()) + "_" + name))
      .string();
}

// Extra attribute `name` whose corner c holds value(c, i) in component i.
template <typename T>
ExtraAttribute extra(const std::string& name, Type type, uint8_t components, size_t corners,
                     T (*value)(size_t, uint32_t)) {
  ExtraAttribute e;
  e.name = name;
  e.component_type = type;
  e.components = components;
  e.bytes.resize(corners * components * sizeof(T));
  for (size_t c = 0; c < corners; ++c)
    for (uint32_t i = 0; i < components; ++i) {
      const T v = value(c, i);
      std::memcpy(e.bytes.data() + (c * components + i) * sizeof(T), &v, sizeof(T));
    }
  return e;
}

// A square of four triangles around a centre vertex with per-vertex
// colours and four extra attributes; TANGENT differs at every corner (each
// vertex is split into one copy per face it touches), the others per vertex
// or per face.
Mesh square_with_extras() {
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5f, 0.5f, 0}};
  m.triangles = {{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}};
  m.colors.assign(5, {0.2f, 0.4f, 0.6f, 1.0f});
  const size_t corners = 12;
  m.extra_attributes.push_back(extra<float>("TANGENT", Type::kFloat32, 4, corners,
                                            [](size_t c, uint32_t i) { return 0.25f * c - i; }));
  m.extra_attributes.push_back(
      extra<uint16_t>("TEXCOORD_1", Type::kUint16, 2, corners,
                      [](size_t c, uint32_t i) { return uint16_t(60000 + 7 * (c / 3) + i); }));
  m.extra_attributes.push_back(extra<int8_t>(
      "x", Type::kInt8, 1, corners, [](size_t c, uint32_t) { return int8_t(-100 + int(c / 3)); }));
  m.extra_attributes.push_back(extra<uint32_t>("_ID", Type::kUint32, 1, corners,
                                               [](size_t, uint32_t) { return 4000000000u; }));
  return m;
}

struct PlyProperty {
  std::string type, name;
};

size_t type_size(const std::string& t) {
  if (t == "char" || t == "uchar") return 1;
  if (t == "short" || t == "ushort") return 2;
  return 4;  // int, uint, float
}

// One property's bytes from an ASCII token.
std::vector<uint8_t> bytes_of(const std::string& type, const std::string& token) {
  std::vector<uint8_t> out(type_size(type));
  if (type == "float") {
    const float f = std::strtof(token.c_str(), nullptr);
    std::memcpy(out.data(), &f, 4);
  } else {
    const long long v = std::strtoll(token.c_str(), nullptr, 10);
    std::memcpy(out.data(), &v, out.size());  // little-endian: the low bytes
  }
  return out;
}

// A PLY file as written (our own layout: vertex then face element, faces as
// uchar-count int lists): vertex properties, each vertex's bytes per
// property, the faces.
struct PlyFile {
  std::vector<std::string> comments;
  std::vector<PlyProperty> properties;
  std::vector<std::vector<std::vector<uint8_t>>> vertices;  // [vertex][property] bytes
  std::vector<std::array<uint32_t, 3>> faces;
};

PlyFile read_ply_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  PlyFile f;
  std::string line;
  bool binary = false;
  size_t vertex_count = 0, face_count = 0;
  std::string element;
  while (std::getline(in, line) && line != "end_header") {
    std::istringstream words(line);
    std::string word;
    words >> word;
    if (word == "format") {
      std::string format;
      words >> format;
      binary = format == "binary_little_endian";
    } else if (word == "comment") {
      f.comments.push_back(line);
    } else if (word == "element") {
      size_t count;
      words >> element >> count;
      (element == "vertex" ? vertex_count : face_count) = count;
    } else if (word == "property" && element == "vertex") {
      PlyProperty p;
      words >> p.type >> p.name;
      f.properties.push_back(p);
    }
  }
  f.vertices.resize(vertex_count);
  for (auto& vertex : f.vertices) {
    for (const PlyProperty& p : f.properties) {
      if (binary) {
        std::vector<uint8_t> b(type_size(p.type));
        in.read(reinterpret_cast<char*>(b.data()), std::streamsize(b.size()));
        vertex.push_back(b);
      } else {
        std::string token;
        in >> token;
        vertex.push_back(bytes_of(p.type, token));
      }
    }
  }
  f.faces.resize(face_count);
  for (auto& face : f.faces) {
    if (binary) {
      uint8_t n;
      in.read(reinterpret_cast<char*>(&n), 1);
      in.read(reinterpret_cast<char*>(face.data()), 12);
    } else {
      int n;
      in >> n >> face[0] >> face[1] >> face[2];
    }
  }
  return f;
}

TEST(PlyExtraAttributes, EveryCornerReadsBackByteForByteInBinaryAndAscii) {
  const Mesh mesh = square_with_extras();
  for (PlyEncoding encoding : {PlyEncoding::kBinary, PlyEncoding::kAscii}) {
    const std::string path = temp_path(encoding == PlyEncoding::kBinary ? "b.ply" : "a.ply");
    ASSERT_TRUE(write_ply(mesh, path, encoding));
    const PlyFile file = read_ply_file(path);
    std::vector<std::string> names, types;
    for (const PlyProperty& p : file.properties) names.push_back(p.name), types.push_back(p.type);
    const std::vector<std::string> expected_names{"x",
                                                  "y",
                                                  "z",
                                                  "red",
                                                  "green",
                                                  "blue",
                                                  "alpha",
                                                  "TANGENT_0",
                                                  "TANGENT_1",
                                                  "TANGENT_2",
                                                  "TANGENT_3",
                                                  "TEXCOORD_1_0",
                                                  "TEXCOORD_1_1",
                                                  "extra_x",
                                                  "_ID"};
    EXPECT_EQ(names, expected_names);
    EXPECT_EQ(types[7], "float");
    EXPECT_EQ(types[11], "ushort");
    EXPECT_EQ(types[13], "char");
    EXPECT_EQ(types[14], "uint");
    EXPECT_THAT(file.comments, Contains(HasSubstr("TANGENT: properties TANGENT_0..TANGENT_3")));
    for (const std::string& c : file.comments) EXPECT_THAT(c, Not(HasSubstr("not stored (PLY")));
    ASSERT_EQ(file.faces.size(), mesh.triangles.size());
    // TANGENT differs at every corner: one vertex per corner.
    EXPECT_EQ(file.vertices.size(), 12u);
    for (size_t f = 0; f < file.faces.size(); ++f) {
      for (int k = 0; k < 3; ++k) {
        const size_t corner = 3 * f + size_t(k);
        const auto& vertex = file.vertices.at(file.faces[f][k]);
        const Vec3f& p = mesh.positions[mesh.triangles[f][k]];
        EXPECT_EQ(std::memcmp(vertex[0].data(), &p.x, 4), 0) << "corner " << corner;
        size_t property = 7;
        for (const ExtraAttribute& e : mesh.extra_attributes) {
          const size_t size = component_size(e.component_type);
          for (uint32_t i = 0; i < e.components; ++i, ++property) {
            const uint8_t* want = e.bytes.data() + corner * element_size(e) + i * size;
            EXPECT_EQ(std::vector<uint8_t>(want, want + size), vertex[property])
                << e.name << "[" << i << "] at corner " << corner;
          }
        }
      }
    }
    // Our reader takes the file and lists the properties it does not keep.
    auto back = import_mesh(path);
    ASSERT_TRUE(back) << back.error().message;
    EXPECT_EQ(back->mesh.face_count(), mesh.face_count());
    EXPECT_THAT(back->contents.extra_properties, Contains("vertex TANGENT_0 (float)"));
    EXPECT_TRUE(export_losses(mesh, path).empty()) << "PLY stores every extra attribute";
    std::filesystem::remove(path);
  }
}

TEST(PlyExtraAttributes, FormatsWithoutThemNameTheExtrasThatAreNotStored) {
  const Mesh mesh = square_with_extras();
  const auto obj = export_losses(mesh, "out.OBJ");
  ASSERT_EQ(obj.size(), 2u);
  EXPECT_EQ(obj[0], "vertex colours");
  EXPECT_EQ(obj[1], "extra attributes TANGENT, TEXCOORD_1, x, _ID (OBJ has no such attribute)");
  const auto off = export_losses(mesh, "out.off");
  EXPECT_THAT(off, Contains(HasSubstr("TANGENT")));
  const auto stl = export_losses(mesh, "out.stl");
  EXPECT_THAT(stl, Contains("vertex colours"));
  EXPECT_THAT(stl, Contains(HasSubstr("(STL has no such attribute)")));
  EXPECT_TRUE(export_losses(mesh, "out.glb").empty());
  // The OBJ file itself still says so in a comment.
  const std::string path = temp_path("o.obj");
  ASSERT_TRUE(write_obj(mesh, path));
  std::ifstream in(path);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_THAT(text, HasSubstr("not stored (OBJ has no such attribute): TEXCOORD_1"));
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace meshstream

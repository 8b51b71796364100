// The OFF and PLY readers on small hand-written files: variants of the
// formats, and malformed input refused with the line and the problem.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include "common/mesh/import.h"
#include "common/mesh/mesh_readers.h"
#include "tests/mesh/temp_file.h"

namespace meshstream {
namespace {

using ::testing::HasSubstr;

using testing::TempFile;

const char* kTetraOff =
    "OFF\n"
    "# a tetrahedron\n"
    "4 4 6\n"
    "0 0 0\n1 0 0   # trailing comment\n0 1 0\n\n0 0 1\n"
    "3 0 2 1\n3 0 1 3\n3 1 2 3\n3 2 0 3\n";

TEST(OffReader, ReadsCommentsBlankLinesAndCounts) {
  TempFile file("tetra.off", kTetraOff);
  auto raw = read_off(file.path());
  ASSERT_TRUE(raw) << raw.error().message;
  EXPECT_EQ(raw->vertices_in_file, 4u);
  EXPECT_EQ(raw->mesh.face_count(), 4u);
  EXPECT_EQ(raw->mesh.positions[3], (Vec3f{0, 0, 1}));
  EXPECT_EQ(raw->mesh.triangles[0], (Triangle{0, 2, 1}));
}

TEST(OffReader, CountsOnTheKeywordLineAndHeaderless) {
  TempFile same_line("same.off", "OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  auto a = read_off(same_line.path());
  ASSERT_TRUE(a) << a.error().message;
  EXPECT_EQ(a->mesh.face_count(), 1u);
  TempFile headerless("headerless.off", "3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  auto b = read_off(headerless.path());
  ASSERT_TRUE(b) << b.error().message;
  EXPECT_EQ(b->mesh.face_count(), 1u);
}

TEST(OffReader, PolygonsAreFanTriangulated) {
  TempFile file("pentagon.off", "OFF\n5 1 0\n0 0 0\n1 0 0\n2 1 0\n1 2 0\n0 1 0\n5 0 1 2 3 4\n");
  auto raw = read_off(file.path());
  ASSERT_TRUE(raw) << raw.error().message;
  ASSERT_EQ(raw->mesh.face_count(), 3u);
  EXPECT_EQ(raw->mesh.triangles[0], (Triangle{0, 1, 2}));
  EXPECT_EQ(raw->mesh.triangles[1], (Triangle{0, 2, 3}));
  EXPECT_EQ(raw->mesh.triangles[2], (Triangle{0, 3, 4}));
}

TEST(OffReader, ColoursAndNormals) {
  TempFile coff("c.off",
                "COFF\n3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n0 1 0 0 0 255 255\n3 0 1 2\n");
  auto a = read_off(coff.path());
  ASSERT_TRUE(a) << a.error().message;
  ASSERT_EQ(a->mesh.colors.size(), 3u);
  EXPECT_EQ(a->mesh.colors[1], (Vec4f{0, 1, 0, 1}));
  TempFile noff("n.off", "NOFF\n3 1 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2 1 0 0\n");
  auto b = read_off(noff.path());
  ASSERT_TRUE(b) << b.error().message;
  ASSERT_EQ(b->mesh.normals.size(), 3u);
  EXPECT_EQ(b->mesh.normals[2], (Vec3f{0, 0, 1}));
}

struct BadOff {
  const char* name;
  const char* content;
  ErrorCode code;
  const char* message;
};

TEST(OffReader, MalformedFilesAreRefusedWithTheLine) {
  const BadOff cases[] = {
      {"index", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n", ErrorCode::kInvalidMesh,
       "line 6: face 0 refers to vertex 7"},
      {"short_face", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n", ErrorCode::kParse, "line 6"},
      {"missing_index", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1\n", ErrorCode::kParse,
       "announces 3 vertices but lists 2"},
      {"bad_number", "OFF\n3 1 0\n0 0 0\n1 x 0\n0 1 0\n3 0 1 2\n", ErrorCode::kParse,
       "line 4: vertex 1: 'x' is not a number"},
      {"too_few_coords", "OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n", ErrorCode::kParse, "line 4"},
      {"truncated", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", ErrorCode::kTruncated,
       "after 1 of 2 faces"},
      {"no_counts", "OFF\n", ErrorCode::kTruncated, "ends after its keyword"},
      {"lying_counts", "OFF\n4000000000 1 0\n0 0 0\n", ErrorCode::kParse, "cannot fit"},
      {"negative", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n", ErrorCode::kParse,
       "'-1' is not a vertex index"},
      {"four_d", "4OFF\n3 1 0\n", ErrorCode::kUnsupported, "4OFF"},
  };
  for (const BadOff& c : cases) {
    TempFile file(std::string(c.name) + ".off", c.content);
    auto imported = import_mesh(file.path());
    ASSERT_FALSE(imported) << c.name;
    EXPECT_EQ(imported.error().code, c.code) << c.name << ": " << imported.error().message;
    EXPECT_THAT(imported.error().message, HasSubstr(c.message)) << c.name;
    EXPECT_THAT(imported.error().message, HasSubstr(file.path())) << c.name;
  }
}

std::string binary_ply_triangle(bool big_endian) {
  std::string s = std::string("ply\nformat ") +
                  (big_endian ? "binary_big_endian" : "binary_little_endian") +
                  " 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                  "property uchar red\nproperty uchar green\nproperty uchar blue\n"
                  "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  auto put = [&](const void* p, size_t n) {
    std::string bytes(static_cast<const char*>(p), n);
    if (big_endian) std::reverse(bytes.begin(), bytes.end());
    s += bytes;
  };
  const float coords[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0.5f}};
  for (auto& c : coords) {
    for (float x : c) put(&x, 4);
    const unsigned char rgb[3] = {255, 0, 51};
    s.append(reinterpret_cast<const char*>(rgb), 3);
  }
  s += '\3';
  for (int32_t i : {0, 1, 2}) put(&i, 4);
  return s;
}

TEST(PlyReader, BinaryBothByteOrders) {
  for (bool big : {false, true}) {
    TempFile file(big ? "be.ply" : "le.ply", binary_ply_triangle(big));
    auto raw = read_ply(file.path());
    ASSERT_TRUE(raw) << raw.error().message;
    ASSERT_EQ(raw->mesh.vertex_count(), 3u);
    EXPECT_EQ(raw->mesh.positions[2], (Vec3f{0, 1, 0.5f}));
    EXPECT_EQ(raw->mesh.triangles[0], (Triangle{0, 1, 2}));
    ASSERT_EQ(raw->mesh.colors.size(), 3u);
    EXPECT_FLOAT_EQ(raw->mesh.colors[0].z, 0.2f);
  }
}

TEST(PlyReader, AsciiWithExtraPropertiesAndElements) {
  TempFile file("extra.ply",
                "ply\nformat ascii 1.0\ncomment hi\nelement vertex 4\nproperty float x\n"
                "property float y\nproperty float z\nproperty float confidence\n"
                "element face 1\nproperty uchar flags\nproperty list uchar uint vertex_index\n"
                "element edge 1\nproperty int a\nproperty int b\nend_header\n"
                "0 0 0 1\n1 0 0 1\n1 1 0 1\n0 1 0 .5\n7 4 0 1 2 3\n0 1\n");
  auto raw = read_ply(file.path());
  ASSERT_TRUE(raw) << raw.error().message;
  EXPECT_EQ(raw->mesh.vertex_count(), 4u);
  ASSERT_EQ(raw->mesh.face_count(), 2u);  // the quad, fan-triangulated
  EXPECT_EQ(raw->mesh.triangles[1], (Triangle{0, 2, 3}));
}

TEST(PlyReader, MalformedFilesAreRefused) {
  const BadOff cases[] = {
      {"magic", "plx\n", ErrorCode::kParse, "not a PLY file"},
      {"no_end", "ply\nformat ascii 1.0\nelement vertex 1\n", ErrorCode::kParse, "end_header"},
      {"bad_type", "ply\nformat ascii 1.0\nelement vertex 1\nproperty flot x\nend_header\n",
       ErrorCode::kParse, "unknown type 'flot'"},
      {"no_xyz", "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\n1\n",
       ErrorCode::kParse, "no x, y, z"},
      {"index",
       "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty "
       "float z\n"
       "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 "
       "0 1 3\n",
       ErrorCode::kInvalidMesh, "face 0 refers to vertex 3"},
      {"truncated_ascii",
       "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty "
       "float z\n"
       "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 "
       "0 1\n",
       ErrorCode::kTruncated, "face 0"},
      {"bad_number",
       "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty "
       "float z\n"
       "end_header\n0 zero 0\n",
       ErrorCode::kParse, "line 8, vertex 0: 'zero'"},
      {"lying_count",
       "ply\nformat binary_little_endian 1.0\nelement vertex 99999999\nproperty float x\n"
       "property float y\nproperty float z\nend_header\n",
       ErrorCode::kParse, "claims 99999999"},
  };
  for (const BadOff& c : cases) {
    TempFile file(std::string(c.name) + ".ply", c.content);
    auto imported = import_mesh(file.path());
    ASSERT_FALSE(imported) << c.name;
    EXPECT_EQ(imported.error().code, c.code) << c.name << ": " << imported.error().message;
    EXPECT_THAT(imported.error().message, HasSubstr(c.message)) << c.name;
  }
  // Binary truncated in the middle of the faces.
  std::string cut = binary_ply_triangle(false);
  cut.resize(cut.size() - 3);
  TempFile file("cut.ply", cut);
  auto imported = import_mesh(file.path());
  ASSERT_FALSE(imported);
  EXPECT_EQ(imported.error().code, ErrorCode::kTruncated) << imported.error().message;
}

// A list length of a float type that is NaN or not whole is refused by name
// (the fuzzer found a NaN length converted to an integer).
TEST(PlyReader, FloatListLengthMustBeAWholeNumber) {
  for (float length : {std::numeric_limits<float>::quiet_NaN(), 3.5f, -1.0f}) {
    std::string s =
        "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n"
        "property float y\nproperty float z\nelement face 1\n"
        "property list float int vertex_indices\nend_header\n";
    const float coords[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    s.append(reinterpret_cast<const char*>(coords), sizeof coords);
    s.append(reinterpret_cast<const char*>(&length), sizeof length);
    for (int32_t i : {0, 1, 2}) s.append(reinterpret_cast<const char*>(&i), sizeof i);
    TempFile file("float_length.ply", s);
    auto imported = import_mesh(file.path());
    ASSERT_FALSE(imported) << length;
    EXPECT_EQ(imported.error().code, ErrorCode::kParse) << imported.error().message;
    EXPECT_THAT(imported.error().message, HasSubstr("list length")) << length;
  }
}

}  // namespace
}  // namespace meshstream

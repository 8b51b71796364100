// Our OBJ reader (obj_reader.cpp): the same mesh as Draco's ObjDecoder on
// the real well-formed OBJ files, exact round trips of what write_obj
// writes, every corner form, and malformed input refused with the line and
// the token — including the face that corrupted Draco's heap.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "common/mesh/export.h"
#include "common/mesh/import.h"
#include "common/mesh/mesh_readers.h"
#include "common/mesh/procedural.h"
#include "tests/mesh/temp_file.h"
#include "tests/test_meshes.h"

namespace meshstream {
namespace {

using ::testing::HasSubstr;

using testing::TempFile;

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

// Positions, triangles and attributes identical, bit for bit.
void expect_same_mesh(const Mesh& ours, const Mesh& peer, const std::string& label) {
  EXPECT_EQ(ours.vertex_count(), peer.vertex_count()) << label;
  EXPECT_EQ(ours.face_count(), peer.face_count()) << label;
  EXPECT_TRUE(same_bits(ours.positions, peer.positions)) << label << ": positions differ";
  EXPECT_TRUE(ours.triangles == peer.triangles) << label << ": triangles differ";
  EXPECT_EQ(ours.normals.size(), peer.normals.size()) << label;
  EXPECT_TRUE(same_bits(ours.normals, peer.normals)) << label << ": normals differ";
  EXPECT_EQ(ours.texcoords.size(), peer.texcoords.size()) << label;
  EXPECT_TRUE(same_bits(ours.texcoords, peer.texcoords)) << label << ": texture coordinates differ";
  EXPECT_TRUE(same_bits(ours.colors, peer.colors)) << label << ": colours differ";
}

// Every OBJ of ../shared/meshes that Draco reads correctly (inf_nan.obj is
// refused by ours at the line, by the Draco path only later in clean_mesh).
const char* const kRealObjFiles[] = {"armadillo.obj",
                                     "skull.obj",
                                     "sphere.obj",
                                     "cube_att.obj",
                                     "cube_quads.obj",
                                     "octagon.obj",
                                     "suzanne.obj",
                                     "multiple_isolated_triangles.obj",
                                     "multiple_tetrahedrons.obj",
                                     "test_nm.obj",
                                     "non_manifold_wrap.obj",
                                     "deg_faces.obj",
                                     "degenerate_mesh.obj",
                                     "extra_vertex.obj",
                                     "eof_test.obj"};

TEST(ObjReader, SameMeshAsDracoOnTheRealFiles) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  for (const char* name : kRealObjFiles) {
    const std::string path = testing::test_mesh(name);
    auto ours = read_obj(path);
    auto peer = read_trusted_obj_with_draco(path);
    ASSERT_TRUE(ours) << name << ": " << ours.error().message;
    ASSERT_TRUE(peer) << name << ": " << peer.error().message;
    EXPECT_EQ(ours->vertices_in_file, peer->vertices_in_file) << name;
    expect_same_mesh(ours->mesh, peer->mesh, std::string(name) + " (as read)");

    // And after cleaning, both as the codec gets it and as `info` analyses it.
    ImportOptions analysis;
    analysis.drop_duplicate_faces = false;
    analysis.keep_nonmanifold = true;
    for (const ImportOptions& options : {ImportOptions{}, analysis}) {
      Mesh a = ours->mesh, b = peer->mesh;
      auto report_a = clean_mesh(a, options);
      auto report_b = clean_mesh(b, options);
      ASSERT_EQ(report_a.has_value(), report_b.has_value()) << name;
      if (!report_a) {
        EXPECT_EQ(report_a.error().message, report_b.error().message) << name;
        continue;
      }
      EXPECT_EQ(report_a->welded_vertices, report_b->welded_vertices) << name;
      EXPECT_EQ(report_a->degenerate_faces, report_b->degenerate_faces) << name;
      EXPECT_EQ(report_a->split_vertices, report_b->split_vertices) << name;
      expect_same_mesh(a, b, std::string(name) + " (cleaned)");
    }
  }
}

TEST(ObjReader, ArmadilloAndSkullMatchTheManifest) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  struct Row {
    const char* file;
    uint32_t in_file, vertices, faces;
  };
  for (const Row& row :
       {Row{"armadillo.obj", 49990, 49990, 99976}, Row{"skull.obj", 40062, 40062, 80016},
        Row{"suzanne.obj", 507, 505, 968}, Row{"test_nm.obj", 114, 97, 170}}) {
    ImportOptions analysis;
    analysis.drop_duplicate_faces = false;
    analysis.keep_nonmanifold = true;
    auto imported = import_mesh(testing::test_mesh(row.file), analysis);
    ASSERT_TRUE(imported) << imported.error().message;
    EXPECT_EQ(imported->report.vertices_in_file, row.in_file) << row.file;
    EXPECT_EQ(imported->mesh.vertex_count(), row.vertices) << row.file;
    EXPECT_EQ(imported->mesh.face_count(), row.faces) << row.file;
  }
}

// A mesh with every optional attribute write_obj stores (positions, normals,
// texture coordinates), on a few procedural shapes.
Mesh with_attributes(Mesh mesh, bool normals, bool texcoords) {
  if (normals) mesh.normals = compute_vertex_normals(mesh);
  if (texcoords) {
    mesh.texcoords.resize(mesh.vertex_count());
    for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
      const Vec3f& p = mesh.positions[v];
      mesh.texcoords[v] = {std::atan2(p.y, p.x) / 7.0f, p.z * 0.3f + 1.0f / 3.0f};
    }
  }
  return mesh;
}

TEST(ObjReader, ExactRoundTripOfOurExporter) {
  const struct {
    const char* name;
    Mesh mesh;
  } shapes[] = {{"icosphere", make_icosphere(3)},
                {"torus", make_torus(24, 12)},
                {"grid", make_open_grid(9)},
                {"components", make_multi_component(3)}};
  for (const auto& shape : shapes) {
    for (int variant = 0; variant < 4; ++variant) {
      const Mesh mesh = with_attributes(shape.mesh, variant & 1, variant & 2);
      const std::string label = std::string(shape.name) + " variant " + std::to_string(variant);
      TempFile file(std::string(shape.name) + std::to_string(variant) + ".obj", "");
      ASSERT_TRUE(write_obj(mesh, file.path())) << label;
      auto back = read_obj(file.path());
      ASSERT_TRUE(back) << label << ": " << back.error().message;
      EXPECT_EQ(back->vertices_in_file, mesh.vertex_count()) << label;
      EXPECT_TRUE(back->notes.empty()) << label << ": " << back->notes.front();
      expect_same_mesh(back->mesh, mesh, label);
      // Draco reads the same file to the same arrays.
      auto peer = read_trusted_obj_with_draco(file.path());
      ASSERT_TRUE(peer) << label << ": " << peer.error().message;
      expect_same_mesh(back->mesh, peer->mesh, label + " vs Draco");
    }
  }
}

Result<RawMesh> parse(const std::string& text) { return parse_obj_text(text); }

TEST(ObjReader, EveryCornerFormGivesTheSameTriangle) {
  const std::string header = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\n";
  for (const char* face :
       {"f 1 2 3\n", "f 1/1 2/2 3/3\n", "f 1//1 2//1 3//1\n", "f 1/1/1 2/2/1 3/3/1\n",
        "f -3 -2 -1\n", "f -3/-3/-1 -2/-2/-1 -1/-1/-1\n", "f\t1  2\t 3 \r\n"}) {
    auto raw = parse(header + face);
    ASSERT_TRUE(raw) << face << raw.error().message;
    ASSERT_EQ(raw->mesh.face_count(), 1u) << face;
    EXPECT_EQ(raw->mesh.triangles[0], (Triangle{0, 1, 2})) << face;
  }
  auto full = parse(header + "f 1/1/1 2/2/1 3/3/1\n");
  ASSERT_TRUE(full);
  ASSERT_EQ(full->mesh.texcoords.size(), 3u);
  EXPECT_EQ(full->mesh.texcoords[2].x, 0.0f);
  EXPECT_EQ(full->mesh.texcoords[2].y, 1.0f);
  ASSERT_EQ(full->mesh.normals.size(), 3u);
  EXPECT_EQ(full->mesh.normals[1], (Vec3f{0, 0, 1}));
}

TEST(ObjReader, RelativeIndicesCountFromTheElementsSoFar) {
  // Two triangles, each written right after its vertices with -1..-3.
  auto raw = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 1 1 0\nf -3 -1 -2\n");
  ASSERT_TRUE(raw) << raw.error().message;
  ASSERT_EQ(raw->mesh.face_count(), 2u);
  EXPECT_EQ(raw->mesh.triangles[0], (Triangle{0, 1, 2}));
  EXPECT_EQ(raw->mesh.triangles[1], (Triangle{1, 3, 2}));
}

TEST(ObjReader, PolygonsAreFanTriangulatedLikeDraco) {
  auto raw = parse("v 0 0 0\nv 1 0 0\nv 2 1 0\nv 1 2 0\nv 0 1 0\nf 1 2 3 4 5\n");
  ASSERT_TRUE(raw) << raw.error().message;
  ASSERT_EQ(raw->mesh.face_count(), 3u);
  EXPECT_EQ(raw->mesh.triangles[0], (Triangle{0, 1, 2}));
  EXPECT_EQ(raw->mesh.triangles[1], (Triangle{0, 2, 3}));
  EXPECT_EQ(raw->mesh.triangles[2], (Triangle{0, 3, 4}));
}

TEST(ObjReader, CommentsCrlfContinuationAndIgnoredLines) {
  auto raw = parse(
      "# header\r\nmtllib a.mtl\r\no thing\r\ng group\r\ns 1\r\nusemtl red\r\n"
      "v 0 0 0 # origin\r\nv 1 0 0 1.0\r\nv \\\r\n 0 1 0\r\nv 0 0 1\r\n"
      "l 1 2\r\np 3\r\nvp 0.5\r\nf 1 3 2\r\nf 1 2 \\\n 4\r\nzzz what is this\r\n");
  ASSERT_TRUE(raw) << raw.error().message;
  EXPECT_EQ(raw->vertices_in_file, 4u);
  ASSERT_EQ(raw->mesh.face_count(), 2u);
  EXPECT_EQ(raw->mesh.positions[2], (Vec3f{0, 1, 0}));
  EXPECT_EQ(raw->mesh.triangles[1], (Triangle{0, 1, 3}));
  ASSERT_EQ(raw->notes.size(), 2u);
  EXPECT_THAT(raw->notes[0], HasSubstr("1 line elements ('l') and 1 point elements ('p') skipped"));
  EXPECT_THAT(raw->notes[1], HasSubstr("line 18: 'zzz'"));  // line numbers count physical lines
}

TEST(ObjReader, VertexColoursWhenEveryVertexHasOne) {
  auto unit = parse("v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 0.5\nf 1 2 3\n");
  ASSERT_TRUE(unit) << unit.error().message;
  ASSERT_EQ(unit->mesh.colors.size(), 3u);
  EXPECT_EQ(unit->mesh.colors[2], (Vec4f{0, 0, 0.5f, 1}));
  auto bytes = parse("v 0 0 0 255 0 0\nv 1 0 0 0 255 0\nv 0 1 0 0 0 51\nf 1 2 3\n");
  ASSERT_TRUE(bytes) << bytes.error().message;
  ASSERT_EQ(bytes->mesh.colors.size(), 3u);
  EXPECT_FLOAT_EQ(bytes->mesh.colors[2].z, 0.2f);
  auto some = parse("v 0 0 0 1 0 0\nv 1 0 0\nv 0 1 0 0 0 1\nf 1 2 3\n");
  ASSERT_TRUE(some) << some.error().message;
  EXPECT_TRUE(some->mesh.colors.empty());
  ASSERT_EQ(some->notes.size(), 1u);
  EXPECT_THAT(some->notes[0], HasSubstr("only 2 of 3 vertices"));
}

TEST(ObjReader, PerFaceAttributesAreKeptPerCornerAndMissingOnesDroppedWithANote) {
  // Two triangles sharing vertices 2 and 3, with different normals there.
  auto raw = parse(
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 1\nvn 0 0 1\nvn 0 1 0\n"
      "f 1//1 2//1 3//1\nf 2//2 4//2 3//2\n");
  ASSERT_TRUE(raw) << raw.error().message;
  EXPECT_TRUE(raw->mesh.normals.empty());
  EXPECT_TRUE(raw->notes.empty());
  ASSERT_TRUE(check_attribute_counts(raw->mesh));
  ASSERT_EQ(raw->mesh.corner_normals.corners.size(), 6u);
  EXPECT_EQ(raw->mesh.corner_normals.at_corner(1).z, 1.0f);  // face 0 at vertex 2
  EXPECT_EQ(raw->mesh.corner_normals.at_corner(3).y, 1.0f);  // face 1 at vertex 2
  auto partial = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 1\nvn 0 0 1\nf 1//1 2//1 3//1\nf 2 4 3\n");
  ASSERT_TRUE(partial) << partial.error().message;
  EXPECT_TRUE(partial->mesh.normals.empty());
  ASSERT_EQ(partial->notes.size(), 1u);
  EXPECT_THAT(partial->notes[0], HasSubstr("some face corners have none"));
}

TEST(ObjReader, ByteOrderMarkIsSkipped) {
  auto raw = parse("\xEF\xBB\xBFv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  ASSERT_TRUE(raw) << raw.error().message;
  EXPECT_EQ(raw->vertices_in_file, 3u);
  EXPECT_TRUE(raw->notes.empty());
}

TEST(ObjReader, ForwardReferencesAreAllowed) {
  auto raw = parse("f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n");
  ASSERT_TRUE(raw) << raw.error().message;
  EXPECT_EQ(raw->mesh.triangles[0], (Triangle{0, 1, 2}));
}

struct BadObj {
  const char* name;
  const char* content;
  ErrorCode code;
  const char* message;
};

TEST(ObjReader, MalformedFilesAreRefusedWithLineAndToken) {
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  const BadObj cases[] = {
      // The face that corrupted Draco's heap (tests/fuzz/regressions/mesh_import/).
      {"draco_heap", "v  1.0  1.0  1.0\nvn  1.0  0.0  0.0\nf  1/1/3  4/2/3 8/4/3  7/3-3",
       ErrorCode::kParse, "line 3: face corner '7/3-3' is malformed"},
      {"letters", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n", ErrorCode::kParse,
       "line 4: face corner 'x'"},
      {"triple_slash", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3///\n", ErrorCode::kParse, "'3///'"},
      {"trailing_slash", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1 2 3/1/\n", ErrorCode::kParse,
       "'3/1/'"},
      {"empty_parts", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 /\n", ErrorCode::kParse, "'/'"},
      {"plus_sign", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 +3\n", ErrorCode::kParse, "'+3'"},
      {"zero", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", ErrorCode::kParse,
       "line 4: face corner '0' has index 0"},
      {"range", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 9\n", ErrorCode::kInvalidMesh,
       "line 5: a face refers to vertex 9 but the file has 3 'v' lines"},
      {"huge", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99999999999999999999\n", ErrorCode::kParse,
       "'99999999999999999999' is malformed"},
      {"beyond_uint32", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4294967296\n", ErrorCode::kInvalidMesh,
       "far beyond"},
      {"relative", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n", ErrorCode::kInvalidMesh,
       "line 4: face corner '-4': relative index -4 reaches before the first vertex (3 defined so "
       "far)"},
      // Found by fuzz_mesh_import: negating INT64_MIN was undefined behaviour.
      {"int64_min", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -9223372036854775808\n",
       ErrorCode::kInvalidMesh,
       "relative index -9223372036854775808 reaches before the first vertex"},
      {"texcoord_range", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/1\n",
       ErrorCode::kInvalidMesh,
       "line 5: a face refers to texture coordinate 2 but the file has 1 'vt' lines"},
      {"normal_missing", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//1 2//1 3//1\n", ErrorCode::kInvalidMesh,
       "refers to normal 1 but the file has 0 'vn' lines"},
      {"no_vertices", "f 1 2 3\n", ErrorCode::kInvalidMesh,
       "refers to vertex 3 but the file has 0 'v'"},
      {"two_corners", "v 0 0 0\nv 1 0 0\nf 1 2\n", ErrorCode::kParse,
       "line 3: a face needs at least 3 corners, found 2"},
      {"nan", "v 0 0 0\nv 1 nan 0\nv 0 1 0\nf 1 2 3\n", ErrorCode::kInvalidMesh,
       "line 2: vertex 1 has a non-finite coordinate (NaN/Inf): (1.000000, NaN, 0.000000)"},
      {"inf", "v 0 0 0\nv 1 0 0\nv 0 1 -inf\nf 1 2 3\n", ErrorCode::kInvalidMesh,
       "vertex 2 has a non-finite"},
      {"overflow", "v 0 0 0\nv 1 0 0\nv 0 1 1e39\nf 1 2 3\n", ErrorCode::kInvalidMesh,
       "(0.000000, 1.000000, Inf)"},
      {"bad_number", "v 0 0 0\nv 1 0,5 0\n", ErrorCode::kParse,
       "line 2: vertex 1: '0,5' is not a number"},
      {"two_numbers", "v 0 0\n", ErrorCode::kParse, "found 2 numbers"},
      {"five_numbers", "v 0 0 0 1 1\n", ErrorCode::kParse, "found 5 numbers"},
      {"many_numbers", "v 0 0 0 1 1 1 1 1 1\n", ErrorCode::kParse, "found more than 7 numbers"},
      {"bad_normal", "vn 0 0\n", ErrorCode::kParse, "'vn' needs three numbers, found 2"},
      {"bad_texcoord", "vt u v\n", ErrorCode::kParse, "line 1: 'vt' needs u [v [w]] ('u'"},
      {"control_bytes", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\x01\n", ErrorCode::kParse, "'3\\x01'"},
  };
  for (const BadObj& c : cases) {
    TempFile file(std::string(c.name) + ".obj", c.content);
    auto imported = import_mesh(file.path());
    ASSERT_FALSE(imported) << c.name;
    EXPECT_EQ(imported.error().code, c.code) << c.name << ": " << imported.error().message;
    EXPECT_THAT(imported.error().message, HasSubstr(c.message)) << c.name;
    EXPECT_THAT(imported.error().message, HasSubstr(file.path() + ": ")) << c.name;
  }
}

TEST(ObjReader, NonFiniteNormalsAreDroppedNotTrusted) {
  auto raw = parse("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 nan\nf 1//1 2//1 3//1\n");
  ASSERT_TRUE(raw) << raw.error().message;
  EXPECT_TRUE(raw->mesh.normals.empty());
  ASSERT_EQ(raw->notes.size(), 1u);
  EXPECT_THAT(raw->notes[0], HasSubstr("normals dropped: line 4: NaN or Inf"));
}

TEST(ObjReader, NumberSyntaxOfStrtofExceptHex) {
  auto raw = parse("v +1 -2.5e-3 .5\nv 1. 0x1 0\nv 1e-50 -0 7E+2\nf 1 2 3\n");
  // "0x1" is not a decimal number: from_chars stops after the '0'.
  ASSERT_FALSE(raw);
  EXPECT_THAT(raw.error().message, HasSubstr("'0x1' is not a number"));
  auto ok = parse("v +1 -2.5e-3 .5\nv 1. 1 0\nv 1e-50 -0 7E+2\nf 1 2 3\n");
  ASSERT_TRUE(ok) << ok.error().message;
  EXPECT_EQ(ok->mesh.positions[0], (Vec3f{1, -2.5e-3f, 0.5f}));
  EXPECT_EQ(ok->mesh.positions[2].x, 0.0f);
  EXPECT_TRUE(std::signbit(ok->mesh.positions[2].y));
  EXPECT_EQ(ok->mesh.positions[2].z, 700.0f);
  // Beyond double range: tiny values become 0, huge ones Inf (refused).
  const std::string tiny = "0." + std::string(400, '0') + "1";
  auto small =
      parse("v " + tiny + " 1000e-500 -1e-99999999999999999999\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  ASSERT_TRUE(small) << small.error().message;
  EXPECT_EQ(small->mesh.positions[0].x, 0.0f);
  EXPECT_EQ(small->mesh.positions[0].y, 0.0f);
  EXPECT_TRUE(std::signbit(small->mesh.positions[0].z));
  for (const std::string huge : {"1" + std::string(400, '0'), std::string("0.001e500"),
                                 std::string("1e99999999999999999999")}) {
    auto big = parse("v 0 0 " + huge + "\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    ASSERT_FALSE(big) << huge;
    EXPECT_THAT(big.error().message, HasSubstr("(0.000000, 0.000000, Inf)")) << huge;
  }
}

TEST(ObjReader, FuzzRegressionInputsAreRefusedCleanly) {
  const std::string dir =
      std::string(MESHSTREAM_SOURCE_DIR) + "/tests/fuzz/regressions/mesh_import";
  int obj_inputs = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    std::ifstream in(entry.path(), std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (bytes.empty() || bytes[0] % 4 != 0) continue;  // the fuzzer's first byte picks .obj
    ++obj_inputs;
    // Each is a broken file: refused, with the line of the problem.
    auto raw = parse(bytes.substr(1));
    ASSERT_FALSE(raw) << entry.path();
    EXPECT_THAT(raw.error().message, HasSubstr("line ")) << entry.path();
  }
  EXPECT_GT(obj_inputs, 0);
}

}  // namespace
}  // namespace meshstream

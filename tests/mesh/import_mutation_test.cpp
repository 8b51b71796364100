// Import never crashes, hangs or reads out of bounds on damaged files: small
// valid files in every format are truncated and have bytes overwritten, in a
// fixed pseudo-random pattern, and every result must be a mesh that passes
// validate_arrays and Adjacency::build, or an error with a message. Run
// under scripts/test --sanitize this is a small deterministic fuzzer.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "common/mesh/adjacency.h"
#include "common/mesh/export.h"
#include "common/mesh/import.h"
#include "common/mesh/procedural.h"

namespace meshstream {
namespace {

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void write_all(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

const char* kOff =
    "OFF\n# tetra\n4 4 6\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n4 2 0 3 1\n";
const char* kObj =
    "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nvn 0 0 1\nvt 0.5 0.5\nf 1/1/1 3/1/1 2/1/1\nf 1 2 4\nf 2 3 "
    "4\nf 3 1 4 2\n";

void check_every_mutation(const std::string& original, const std::string& extension,
                          uint32_t seed) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("meshstream_mutation_" + std::to_string(::getpid()) + extension))
                               .string();
  std::mt19937 random(seed);
  int accepted = 0, refused = 0;
  const char kInteresting[] = {'0', '9', '-', '.', ' ', '\n', 'e', '#', '\0', '\xff', '/', '3'};
  for (int trial = 0; trial < 200; ++trial) {
    std::string bytes = original;
    const int kind = trial % 3;
    if (kind == 0) {
      bytes.resize(random() % (bytes.size() + 1));  // truncation
    } else {
      const int edits = 1 + static_cast<int>(random() % 4);
      for (int e = 0; e < edits && !bytes.empty(); ++e) {
        const size_t at = random() % bytes.size();
        bytes[at] =
            kind == 1 ? kInteresting[random() % sizeof(kInteresting)] : static_cast<char>(random());
      }
    }
    write_all(path, bytes);
    auto imported = import_mesh(path);
    if (imported) {
      ++accepted;
      EXPECT_TRUE(validate_arrays(imported->mesh)) << "trial " << trial;
      EXPECT_TRUE(Adjacency::build(imported->mesh)) << "trial " << trial;
    } else {
      ++refused;
      EXPECT_FALSE(imported.error().message.empty());
      EXPECT_NE(imported.error().message.find(path), std::string::npos) << imported.error().message;
    }
  }
  std::filesystem::remove(path);
  // Both outcomes occur, so the mutations reach past the first check.
  EXPECT_GT(accepted, 0) << extension;
  EXPECT_GT(refused, 0) << extension;
}

TEST(ImportMutation, Off) { check_every_mutation(kOff, ".off", 1); }
TEST(ImportMutation, Obj) { check_every_mutation(kObj, ".obj", 2); }

TEST(ImportMutation, PlyBinaryAndAscii) {
  Mesh mesh = make_icosahedron();
  mesh.normals = compute_vertex_normals(mesh);
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("meshstream_mutation_src_" + std::to_string(::getpid()) + ".ply"))
                               .string();
  ASSERT_TRUE(write_ply(mesh, path, PlyEncoding::kBinary));
  const std::string binary = read_all(path);
  ASSERT_TRUE(write_ply(mesh, path, PlyEncoding::kAscii));
  const std::string ascii = read_all(path);
  std::filesystem::remove(path);
  check_every_mutation(binary, ".ply", 3);
  check_every_mutation(ascii, ".ply", 4);
}

TEST(ImportMutation, Stl) {
  // Binary STL: 80-byte header, count, then 50 bytes per triangle.
  const Mesh mesh = make_icosahedron();
  std::string bytes(80, ' ');
  const uint32_t count = mesh.face_count();
  bytes.append(reinterpret_cast<const char*>(&count), 4);
  for (const Triangle& t : mesh.triangles) {
    const Vec3f n = face_normal(mesh, static_cast<uint32_t>(&t - mesh.triangles.data()));
    bytes.append(reinterpret_cast<const char*>(&n), 12);
    for (uint32_t v : t) bytes.append(reinterpret_cast<const char*>(&mesh.positions[v]), 12);
    bytes.append(2, '\0');
  }
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("meshstream_stl_" + std::to_string(::getpid()) + ".stl"))
                               .string();
  write_all(path, bytes);
  auto imported = import_mesh(path);
  std::filesystem::remove(path);
  ASSERT_TRUE(imported) << imported.error().message;
  EXPECT_EQ(imported->mesh.vertex_count(), 12u);  // 60 corners welded
  EXPECT_EQ(imported->report.welded_vertices, 48u);
  EXPECT_EQ(imported->mesh.face_count(), 20u);
  check_every_mutation(bytes, ".stl", 5);
}

TEST(ImportMutation, AsciiStl) {
  std::string text = "solid tetra\n";
  const Mesh mesh = make_icosahedron();
  for (const Triangle& t : mesh.triangles) {
    text += "  facet normal 0 0 0\n    outer loop\n";
    for (uint32_t v : t) {
      const Vec3f& p = mesh.positions[v];
      text += "      vertex " + std::to_string(p.x) + " " + std::to_string(p.y) + " " +
              std::to_string(p.z) + "\n";
    }
    text += "    endloop\n  endfacet\n";
  }
  text += "endsolid tetra\n";
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("meshstream_ascii_" + std::to_string(::getpid()) + ".stl"))
                               .string();
  write_all(path, text);
  auto imported = import_mesh(path);
  std::filesystem::remove(path);
  ASSERT_TRUE(imported) << imported.error().message;
  EXPECT_EQ(imported->report.vertices_in_file, 60u);
  EXPECT_EQ(imported->mesh.vertex_count(), 12u);
  EXPECT_EQ(imported->mesh.face_count(), 20u);
  check_every_mutation(text, ".stl", 6);
}

}  // namespace
}  // namespace meshstream

// .drc files go through Draco's decoder: an icosahedron encoded with
// Draco's own encoder (no quantization, so positions are exact) imports
// with the same vertices and the same triangles up to Draco's reordering.
#include <draco/compression/encode.h>
#include <draco/mesh/triangle_soup_mesh_builder.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "common/mesh/import.h"
#include "common/mesh/procedural.h"

namespace meshstream {
namespace {

// Each triangle as its three positions, rotated to start at the smallest:
// comparable across any vertex renumbering.
std::vector<std::array<Vec3f, 3>> geometric_faces(const Mesh& mesh) {
  auto less = [](const Vec3f& a, const Vec3f& b) {
    return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z);
  };
  std::vector<std::array<Vec3f, 3>> faces;
  for (const Triangle& t : mesh.triangles) {
    std::array<Vec3f, 3> f = {mesh.positions[t[0]], mesh.positions[t[1]], mesh.positions[t[2]]};
    const int first = static_cast<int>(std::min_element(f.begin(), f.end(), less) - f.begin());
    std::rotate(f.begin(), f.begin() + first, f.end());
    faces.push_back(f);
  }
  std::sort(faces.begin(), faces.end(), [&](const auto& a, const auto& b) {
    return std::lexicographical_compare(a.begin(), a.end(), b.begin(), b.end(), less);
  });
  return faces;
}

TEST(ImportDrc, LosslessDracoFileImportsExactly) {
  const Mesh mesh = make_icosphere(2);
  draco::TriangleSoupMeshBuilder builder;
  builder.Start(static_cast<int>(mesh.face_count()));
  const int position =
      builder.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
  for (uint32_t f = 0; f < mesh.face_count(); ++f) {
    const Triangle& t = mesh.triangles[f];
    builder.SetAttributeValuesForFace(position, draco::FaceIndex(f), &mesh.positions[t[0]],
                                      &mesh.positions[t[1]], &mesh.positions[t[2]]);
  }
  std::unique_ptr<draco::Mesh> draco_mesh = builder.Finalize();
  ASSERT_NE(draco_mesh, nullptr);
  draco::Encoder encoder;  // no quantization set: positions stay exact floats
  draco::EncoderBuffer buffer;
  ASSERT_TRUE(encoder.EncodeMeshToBuffer(*draco_mesh, &buffer).ok());
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("meshstream_drc_" + std::to_string(::getpid()) + ".drc"))
                               .string();
  std::ofstream(path, std::ios::binary)
      .write(buffer.data(), static_cast<std::streamsize>(buffer.size()));
  auto imported = import_mesh(path);
  std::filesystem::remove(path);
  ASSERT_TRUE(imported) << imported.error().message;
  EXPECT_EQ(imported->mesh.vertex_count(), mesh.vertex_count());
  EXPECT_EQ(imported->mesh.face_count(), mesh.face_count());
  const auto expected = geometric_faces(mesh);
  const auto actual = geometric_faces(imported->mesh);
  EXPECT_TRUE(expected == actual) << "faces or their orientation changed";
}

TEST(ImportDrc, GarbageIsAParseError) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("meshstream_bad_" + std::to_string(::getpid()) + ".drc"))
                               .string();
  std::ofstream(path, std::ios::binary) << "DRACO this is not a mesh";
  auto imported = import_mesh(path);
  std::filesystem::remove(path);
  ASSERT_FALSE(imported);
  EXPECT_EQ(imported.error().code, ErrorCode::kParse);
}

}  // namespace
}  // namespace meshstream

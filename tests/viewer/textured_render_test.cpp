// The renderer shows a mesh's texture and colours (mesh_renderer.h): a
// procedural textured sphere (seamed texture coordinates per corner, a
// generated checker PNG) renders in the checker's colours, the same sphere
// without its texture renders grey, per-vertex colours show as such, and a
// sphere whose two materials use two textures shows each on its own faces.
#include <gtest/gtest.h>
#include <stb_image_write.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "client/viewer/offscreen.h"
#include "common/mesh/textured_sphere.h"
#include "tests/viewer/image_checks.h"
#include "tests/viewer/saturated_pixels.h"

namespace meshstream::client {
namespace {

OffscreenRequest request(SurfaceMode surface = SurfaceMode::kLit) {
  OffscreenRequest r;
  r.width = 256;
  r.height = 256;
  r.style.surface = surface;
  return r;
}

RgbaImage render_or_fail(const Mesh& mesh, const OffscreenRequest& r, const char* name) {
  auto image = render_offscreen(mesh, r);
  EXPECT_TRUE(image.has_value()) << (image ? "" : image.error().message);
  if (!image) return RgbaImage{};
  testing::keep_for_inspection(*image, std::string("textured_") + name);
  return *image;
}

TEST(TexturedRender, TheCheckerTextureShowsInItsColours) {
  const Mesh sphere = make_textured_uv_sphere(32, 64, 256);
  const RgbaImage lit = render_or_fail(sphere, request(), "lit");
  ASSERT_GT(lit.width, 0);
  const auto hues = testing::saturated_by_hue(lit);
  int total = 0, present = 0;
  for (int c : hues) {
    total += c;
    present += c > 200;
  }
  EXPECT_GT(total, 256 * 256 / 8) << "a textured sphere covers a good part of the picture";
  EXPECT_GE(present, 3) << "red " << hues[0] << ", green " << hues[1] << ", blue " << hues[2]
                        << ", yellow " << hues[3];

  // Without the texture the same sphere is grey.
  Mesh plain = sphere;
  plain.textures.clear();
  plain.materials.clear();
  plain.face_materials.clear();
  const auto grey = testing::saturated_by_hue(render_or_fail(plain, request(), "plain"));
  EXPECT_EQ(grey[0] + grey[1] + grey[2] + grey[3], 0);

  // The unlit texture mode shows the texture itself: more saturated pixels
  // than lit (no shading towards black at the rim).
  const auto flat =
      testing::saturated_by_hue(render_or_fail(sphere, request(SurfaceMode::kTexture), "flat"));
  EXPECT_GE(flat[0] + flat[1] + flat[2] + flat[3], total);
}

TEST(TexturedRender, VertexColoursShow) {
  Mesh sphere = make_textured_uv_sphere(16, 32, 16);
  sphere.textures.clear();
  sphere.materials.clear();
  sphere.face_materials.clear();
  sphere.corner_texcoords = {};
  sphere.colors.resize(sphere.vertex_count());
  for (uint32_t v = 0; v < sphere.vertex_count(); ++v)
    sphere.colors[v] =
        sphere.positions[v].z > 0 ? Vec4f{0.9f, 0.1f, 0.1f, 1} : Vec4f{0.1f, 0.2f, 0.9f, 1};
  const auto hues = testing::saturated_by_hue(render_or_fail(sphere, request(), "colors"));
  EXPECT_GT(hues[0], 500) << "red upper half";
  EXPECT_GT(hues[2], 500) << "blue lower half";
}

// A `side` x `side` PNG of one colour.
std::vector<uint8_t> solid_png(uint8_t r, uint8_t g, uint8_t b, int side = 8) {
  std::vector<uint8_t> rgb;
  for (int i = 0; i < side * side; ++i) rgb.insert(rgb.end(), {r, g, b});
  std::vector<uint8_t> png;
  stbi_write_png_to_func(
      [](void* context, void* data, int size) {
        auto* out = static_cast<std::vector<uint8_t>*>(context);
        out->insert(out->end(), static_cast<uint8_t*>(data), static_cast<uint8_t*>(data) + size);
      },
      &png, side, side, 3, rgb.data(), side * 3);
  return png;
}

TEST(TexturedRender, EachMaterialShowsItsOwnTexture) {
  // The upper half (z > 0) of the sphere uses material 0 (a red image),
  // the lower half material 1 (a blue one).
  Mesh sphere = make_textured_uv_sphere(16, 32, 16);
  sphere.textures.resize(2);
  sphere.textures[0].bytes = solid_png(220, 30, 30);
  sphere.textures[1] = sphere.textures[0];
  sphere.textures[1].name = "blue.png";
  sphere.textures[1].bytes = solid_png(30, 40, 220);
  sphere.materials.resize(2);
  sphere.materials[1].name = "blue";
  sphere.materials[1].base_color_texture = 1;
  for (uint32_t f = 0; f < sphere.face_count(); ++f) {
    float z = 0;
    for (uint32_t v : sphere.triangles[f]) z += sphere.positions[v].z;
    sphere.face_materials[f] = z > 0 ? 0 : 1;
  }
  const RgbaImage image = render_or_fail(sphere, request(SurfaceMode::kTexture), "two_materials");
  ASSERT_GT(image.width, 0);
  const auto hues = testing::saturated_by_hue(image);
  EXPECT_GT(hues[0], 1000) << "red faces (material 0)";
  EXPECT_GT(hues[2], 1000) << "blue faces (material 1): its own texture, not material 0's";
  EXPECT_LT(hues[1] + hues[3], (hues[0] + hues[2]) / 50) << "no other colour";
  // The two colours cover the two halves: their centres lie apart.
  double sum[2][2] = {{0, 0}, {0, 0}};
  int count[2] = {0, 0};
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const uint8_t* p = image.pixel(x, y);
      const int k = p[0] > 2 * p[2] + 40 ? 0 : p[2] > 2 * p[0] + 40 ? 1 : -1;
      if (k < 0) continue;
      sum[k][0] += x, sum[k][1] += y, ++count[k];
    }
  ASSERT_GT(count[0], 0);
  ASSERT_GT(count[1], 0);
  const double dx = sum[0][0] / count[0] - sum[1][0] / count[1];
  const double dy = sum[0][1] / count[0] - sum[1][1] / count[1];
  EXPECT_GT(std::hypot(dx, dy), 30.0) << "red and blue on separate halves of the sphere";
}

}  // namespace
}  // namespace meshstream::client

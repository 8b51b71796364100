// The renderer shows a mesh's texture and colours (mesh_renderer.h): a
// procedural textured sphere (seamed texture coordinates per corner, a
// generated checker PNG) renders in the checker's colours, the same sphere
// without its texture renders grey, and per-vertex colours show as such.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>

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

}  // namespace
}  // namespace meshstream::client

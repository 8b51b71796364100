// Procedural textured sphere: see textured_sphere.h.
#include "common/mesh/textured_sphere.h"

#include <stb_image_write.h>

#include <algorithm>
#include <cmath>

namespace meshstream {

namespace {

void append_bytes(void* context, void* data, int size) {
  auto* out = static_cast<std::vector<uint8_t>*>(context);
  const auto* p = static_cast<const uint8_t*>(data);
  out->insert(out->end(), p, p + size);
}

}  // namespace

std::vector<uint8_t> make_checker_png(uint32_t side, uint32_t cells) {
  side = std::max(side, 1u);
  cells = std::max(cells, 1u);
  std::vector<uint8_t> rgb(size_t(side) * side * 3);
  const uint8_t quadrant[4][3] = {{220, 40, 40}, {40, 190, 60}, {40, 70, 220}, {230, 200, 40}};
  for (uint32_t y = 0; y < side; ++y) {
    for (uint32_t x = 0; x < side; ++x) {
      const uint32_t q = (x * 2 / side) + 2 * (y * 2 / side);
      const uint32_t cx = x * cells / side, cy = y * cells / side;
      const bool dark = (cx + cy) % 2 == 1;
      const bool line = (x * cells) % side < std::max(1u, side / 128) ||
                        (y * cells) % side < std::max(1u, side / 128);
      uint8_t* p = &rgb[(size_t(y) * side + x) * 3];
      for (int c = 0; c < 3; ++c) {
        const int v = line ? 245 : dark ? quadrant[q][c] / 2 : quadrant[q][c];
        p[c] = uint8_t(v);
      }
    }
  }
  std::vector<uint8_t> png;
  stbi_write_png_to_func(append_bytes, &png, int(side), int(side), 3, rgb.data(), int(side) * 3);
  return png;
}

Mesh make_textured_uv_sphere(uint32_t rings, uint32_t segments, uint32_t texture_side) {
  rings = std::max(rings, 2u);
  segments = std::max(segments, 3u);
  Mesh m;
  const double pi = 3.14159265358979323846;
  // Vertex 0 the north pole, 1 the south pole, then ring r (1..rings-1),
  // segment s at 2 + (r - 1) * segments + s.
  m.positions.push_back({0, 0, 1});
  m.positions.push_back({0, 0, -1});
  for (uint32_t r = 1; r < rings; ++r) {
    const double theta = pi * r / rings;
    for (uint32_t s = 0; s < segments; ++s) {
      const double phi = 2 * pi * s / segments;
      m.positions.push_back({float(std::sin(theta) * std::cos(phi)),
                             float(std::sin(theta) * std::sin(phi)), float(std::cos(theta))});
    }
  }
  auto vertex = [&](uint32_t r, uint32_t s) -> uint32_t {
    if (r == 0) return 0;
    if (r == rings) return 1;
    return 2 + (r - 1) * segments + s % segments;
  };
  // UV grid (s, r) for s in 0..segments, r in 0..rings: u = s / segments
  // (s == segments is the seam's other side), v = 1 - r / rings.
  for (uint32_t r = 0; r <= rings; ++r) {
    for (uint32_t s = 0; s <= segments; ++s) {
      m.corner_texcoords.values.push_back(
          {float(s) / float(segments), 1.0f - float(r) / float(rings)});
    }
  }
  auto uv = [&](uint32_t r, uint32_t s) { return r * (segments + 1) + s; };
  auto add = [&](uint32_t r0, uint32_t s0, uint32_t r1, uint32_t s1, uint32_t r2, uint32_t s2) {
    m.triangles.push_back({vertex(r0, s0), vertex(r1, s1), vertex(r2, s2)});
    for (auto [r, s] : {std::pair{r0, s0}, std::pair{r1, s1}, std::pair{r2, s2}})
      m.corner_texcoords.corners.push_back(uv(r, s));
  };
  for (uint32_t r = 0; r < rings; ++r) {
    for (uint32_t s = 0; s < segments; ++s) {
      // Counter-clockwise from outside: r grows southwards, s eastwards.
      if (r > 0) add(r, s, r + 1, s, r, s + 1);
      if (r + 1 < rings) add(r, s + 1, r + 1, s, r + 1, s + 1);
    }
  }
  Material material;
  material.name = "checker";
  material.base_color_texture = 0;
  m.materials.push_back(material);
  m.face_materials.assign(m.triangles.size(), 0);
  Texture texture;
  texture.name = "checker.png";
  texture.mime_type = "image/png";
  texture.bytes = make_checker_png(texture_side);
  m.textures.push_back(std::move(texture));
  return m;
}

}  // namespace meshstream

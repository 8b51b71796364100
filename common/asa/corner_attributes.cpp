// Per-corner attributes through subdivision: see corner_attributes.h.
#include "common/asa/corner_attributes.h"

#include <array>

namespace meshstream::asa {

namespace {

using Weights = std::array<float, 3>;

// Barycentric coordinates of vertex p in the input face `corners`: an
// input vertex is one of the face's corners, a new vertex the mean of its
// parents'. A vertex outside the face (it cannot happen for a face's own
// descendants) counts as its first corner.
Weights barycentric(uint32_t p, const Triangle& corners, uint32_t input_vertices,
                    const std::vector<uint32_t>& parents) {
  if (p < input_vertices) {
    if (p == corners[1]) return {0, 1, 0};
    if (p == corners[2]) return {0, 0, 1};
    return {1, 0, 0};
  }
  const size_t at = 2 * size_t(p);
  if (at + 1 >= parents.size()) return {1, 0, 0};
  const Weights a = barycentric(parents[at], corners, input_vertices, parents);
  const Weights b = barycentric(parents[at + 1], corners, input_vertices, parents);
  return {0.5f * (a[0] + b[0]), 0.5f * (a[1] + b[1]), 0.5f * (a[2] + b[2])};
}

Vec2f weighted(const Vec2f& a, const Vec2f& b, const Vec2f& c, const Weights& w) {
  return {a.x * w[0] + b.x * w[1] + c.x * w[2], a.y * w[0] + b.y * w[1] + c.y * w[2]};
}
Vec3f weighted(const Vec3f& a, const Vec3f& b, const Vec3f& c, const Weights& w) {
  return a * w[0] + b * w[1] + c * w[2];
}
Vec4f weighted(const Vec4f& a, const Vec4f& b, const Vec4f& c, const Weights& w) {
  return {a.x * w[0] + b.x * w[1] + c.x * w[2], a.y * w[0] + b.y * w[1] + c.y * w[2],
          a.z * w[0] + b.z * w[1] + c.z * w[2], a.w * w[0] + b.w * w[1] + c.w * w[2]};
}

template <typename T>
T mix(const CornerAttribute<T>& attribute, uint32_t face, const Weights& w) {
  return weighted(attribute.at_corner(3 * size_t(face)), attribute.at_corner(3 * size_t(face) + 1),
                  attribute.at_corner(3 * size_t(face) + 2), w);
}

template <typename T>
void start(const CornerAttribute<T>& in, size_t corners, CornerAttribute<T>& out) {
  out.values.clear();
  out.corners.clear();
  if (in.empty()) return;
  out.values.resize(corners);
  out.corners.resize(corners);
  for (size_t c = 0; c < corners; ++c) out.corners[c] = uint32_t(c);
}

}  // namespace

void carry_corner_attributes(const Mesh& input, const std::vector<uint32_t>& source,
                             const std::vector<uint32_t>& parents, Mesh& out) {
  const size_t G = out.triangles.size();
  const size_t corners = 3 * G;
  start(input.corner_normals, corners, out.corner_normals);
  start(input.corner_colors, corners, out.corner_colors);
  start(input.corner_texcoords, corners, out.corner_texcoords);
  out.face_materials.clear();
  if (!input.face_materials.empty()) out.face_materials.resize(G);
  const uint32_t V = input.vertex_count();
  for (size_t g = 0; g < G; ++g) {
    const uint32_t s = g < source.size() ? source[g] : 0;
    if (s >= input.face_count()) continue;
    if (!input.face_materials.empty()) out.face_materials[g] = input.face_materials[s];
    const Triangle& corners_of_source = input.triangles[s];
    for (int k = 0; k < 3; ++k) {
      const size_t c = 3 * g + k;
      const Weights w = barycentric(out.triangles[g][k], corners_of_source, V, parents);
      if (!input.corner_normals.empty())
        out.corner_normals.values[c] = normalized(mix(input.corner_normals, s, w));
      if (!input.corner_colors.empty())
        out.corner_colors.values[c] = mix(input.corner_colors, s, w);
      if (!input.corner_texcoords.empty())
        out.corner_texcoords.values[c] = mix(input.corner_texcoords, s, w);
    }
  }
}

}  // namespace meshstream::asa

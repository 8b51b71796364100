// The renderer's cull (common/asa/display_cull.h): every face left out is
// outside the widened view cone or a back face of a closed component seen
// from outside; every vertex kept has its whole fan; open surfaces keep their
// back faces; attributes follow the faces; the region is valid for the
// camera it was made for and not for one far from it.
#include "common/asa/display_cull.h"

#include <cmath>
#include <map>

#include "common/mesh/procedural.h"
#include "tests/asa/asa_test_support.h"

namespace meshstream {
namespace {

struct Culled {
  std::shared_ptr<const Mesh> whole;
  CulledDisplay cull;
};

Culled cull_of(const Mesh& mesh, const AsaCamera& camera, float near_plane = 0) {
  Culled c;
  c.whole = std::make_shared<const Mesh>(mesh);
  const auto topo = analyze_display_topology(mesh);
  c.cull = cull_display(c.whole, nullptr, *topo, camera, near_plane);
  return c;
}

// The faces of `whole` kept by the cull, by their position triples.
std::vector<bool> kept_faces(const Mesh& whole, const Mesh& culled) {
  std::map<std::array<float, 9>, int> count;
  auto key = [](const Mesh& m, const Triangle& t) {
    std::array<float, 9> k{};
    for (int i = 0; i < 3; ++i) {
      k[3 * i] = m.positions[t[i]].x;
      k[3 * i + 1] = m.positions[t[i]].y;
      k[3 * i + 2] = m.positions[t[i]].z;
    }
    return k;
  };
  for (const Triangle& t : culled.triangles) ++count[key(culled, t)];
  std::vector<bool> kept(whole.face_count());
  for (uint32_t f = 0; f < whole.face_count(); ++f) {
    auto it = count.find(key(whole, whole.triangles[f]));
    kept[f] = it != count.end() && it->second-- > 0;
  }
  return kept;
}

// The face is seen by the camera: some vertex projects inside the image
// or the face straddles the eye's plane, and its front (outward for a
// closed mesh) turns towards the eye. A conservative "may be seen".
bool in_view(const Mesh& m, uint32_t f, const AsaCamera& c) {
  const Vec3f fw = normalized(c.target - c.eye);
  const Vec3f right = normalized(cross(fw, Vec3f{0, 1, 0}));
  const Vec3f up = cross(right, fw);
  const float ty = std::tan(c.fov_degrees * 3.14159265f / 360.0f);
  const float tx = ty * float(c.width) / float(c.height);
  // The face's bounding box in normalized image coordinates, or in view
  // when a vertex is behind the eye.
  float lo_x = 1e9f, hi_x = -1e9f, lo_y = 1e9f, hi_y = -1e9f;
  for (uint32_t v : m.triangles[f]) {
    const Vec3f r = m.positions[v] - c.eye;
    const float z = dot(r, fw);
    if (z <= 0) return true;
    const float x = dot(r, right) / (z * tx), y = dot(r, up) / (z * ty);
    lo_x = std::min(lo_x, x), hi_x = std::max(hi_x, x);
    lo_y = std::min(lo_y, y), hi_y = std::max(hi_y, y);
  }
  return hi_x >= -1 && lo_x <= 1 && hi_y >= -1 && lo_y <= 1;
}

bool faces_eye(const Mesh& m, uint32_t f, Vec3f eye) {
  const Triangle& t = m.triangles[f];
  const Vec3f a = m.positions[t[0]];
  return dot(cross(m.positions[t[1]] - a, m.positions[t[2]] - a), eye - a) >= 0;
}

TEST(DisplayCull, LeavesOutOnlyFacesOffScreenOrBehindAClosedSurface) {
  const Mesh torus = make_torus(48, 24);  // closed, wound outward
  AsaCamera camera = fit_camera(torus, 640, 480);
  const Culled c = cull_of(torus, camera);
  const Mesh& culled = *c.cull.mesh;
  ASSERT_NE(c.cull.mesh, c.whole) << "nothing was culled";
  EXPECT_GT(c.cull.back_culled, torus.face_count() / 4);
  EXPECT_LT(culled.face_count(), torus.face_count() * 3 / 4);
  const std::vector<bool> kept = kept_faces(torus, culled);
  for (uint32_t f = 0; f < torus.face_count(); ++f) {
    if (kept[f]) continue;
    EXPECT_FALSE(in_view(torus, f, camera) && faces_eye(torus, f, camera.eye)) << "face " << f;
  }
  // Every face the camera sees from the front is there.
  for (uint32_t f = 0; f < torus.face_count(); ++f)
    if (in_view(torus, f, camera) && faces_eye(torus, f, camera.eye)) {
      EXPECT_TRUE(kept[f]) << f;
    }
  EXPECT_TRUE(cull_valid_for(c.cull.region, camera, 0));
}

TEST(DisplayCull, KeepsTheWholeFanOfEveryVertexOfASeenFace) {
  const Mesh torus = make_torus(40, 20);
  const AsaCamera camera = fit_camera(torus, 640, 480);
  const Culled c = cull_of(torus, camera);
  const Mesh& culled = *c.cull.mesh;
  ASSERT_LT(culled.face_count(), torus.face_count());
  // Valence of each position in both meshes: a vertex of a face the camera
  // sees keeps all of its faces (so its shading normal is the same).
  using Key = std::array<float, 3>;
  auto key = [](Vec3f p) { return Key{p.x, p.y, p.z}; };
  std::map<Key, int> whole_valence, culled_valence;
  for (const Triangle& t : torus.triangles)
    for (uint32_t v : t) ++whole_valence[key(torus.positions[v])];
  for (const Triangle& t : culled.triangles)
    for (uint32_t v : t) ++culled_valence[key(culled.positions[v])];
  EXPECT_EQ(culled.vertex_count(), culled_valence.size()) << "unused vertices kept";
  uint32_t seen = 0;
  for (uint32_t f = 0; f < torus.face_count(); ++f) {
    if (!in_view(torus, f, camera) || !faces_eye(torus, f, camera.eye)) continue;
    ++seen;
    for (uint32_t v : torus.triangles[f]) {
      const Key p = key(torus.positions[v]);
      EXPECT_EQ(culled_valence[p], whole_valence[p]) << "face " << f;
    }
  }
  EXPECT_GT(seen, torus.face_count() / 4);
}

TEST(DisplayCull, OpenSurfacesKeepTheirBackFaces) {
  // Seen from below, every face of a height field turns away: all stay.
  const Mesh grid = make_open_grid(20);
  AsaCamera below;
  below.eye = {0.5f, 0.5f, -3};
  below.target = {0.5f, 0.5f, 0};
  below.width = 640;
  below.height = 480;
  const Culled c = cull_of(grid, below);
  EXPECT_EQ(c.cull.back_culled, 0u);
  EXPECT_EQ(c.cull.mesh->face_count(), grid.face_count());
  EXPECT_TRUE(c.cull.region.everything);
}

TEST(DisplayCull, AnEyeInsideOrANearPlaneCuttingTheSolidCullsNoBackFace) {
  const Mesh sphere = make_icosphere(3);
  AsaCamera inside;
  inside.eye = {0, 0, 0.2f};
  inside.target = {0, 0, -1};
  EXPECT_EQ(cull_of(sphere, inside).cull.back_culled, 0u);
  AsaCamera outside;
  outside.eye = {0, 0, 4};
  outside.target = {0, 0, 0};
  EXPECT_GT(cull_of(sphere, outside).cull.back_culled, 0u);
  // A near plane beyond the sphere's nearest point: its inside shows.
  EXPECT_EQ(cull_of(sphere, outside, 3.5f).cull.back_culled, 0u);
}

TEST(DisplayCull, ZoomedInLeavesOutWhatIsOffScreenAndCarriesAttributes) {
  Mesh sphere = make_uv_sphere(64, 32);  // corner texcoords, per-vertex normals
  sphere.face_materials.assign(sphere.face_count(), 0);
  sphere.materials.resize(1);
  AsaCamera close;
  close.eye = {0, 0, 1.6f};
  close.target = {0, 0, 1};
  close.fov_degrees = 20;
  close.width = 400;
  close.height = 300;
  auto whole = std::make_shared<const Mesh>(sphere);
  auto kinds =
      std::make_shared<const std::vector<FaceKind>>(sphere.face_count(), FaceKind::kTarget);
  const auto topo = analyze_display_topology(sphere);
  const CulledDisplay c = cull_display(whole, kinds, *topo, close);
  EXPECT_GT(c.frustum_culled, sphere.face_count() / 3);
  EXPECT_LT(c.mesh->face_count(), sphere.face_count() / 3);
  const Mesh& m = *c.mesh;
  ASSERT_TRUE(check_attribute_counts(m));
  ASSERT_TRUE(validate_arrays(m));
  EXPECT_EQ(m.normals.size(), m.vertex_count());
  EXPECT_EQ(m.corner_texcoords.corners.size(), 3 * size_t(m.face_count()));
  EXPECT_EQ(m.face_materials.size(), m.face_count());
  ASSERT_TRUE(c.face_kind);
  EXPECT_EQ(c.face_kind->size(), m.face_count());
  // Each kept corner keeps its texture coordinate.
  const std::vector<bool> kept = kept_faces(sphere, m);
  uint32_t j = 0;
  for (uint32_t f = 0; f < sphere.face_count(); ++f) {
    if (!kept[f]) continue;
    for (int k = 0; k < 3; ++k) {
      const Vec2f a = sphere.corner_texcoords.at_corner(3 * size_t(f) + k);
      const Vec2f b = m.corner_texcoords.at_corner(3 * size_t(j) + k);
      EXPECT_EQ(a.x, b.x);
      EXPECT_EQ(a.y, b.y);
    }
    ++j;
  }
}

TEST(DisplayCull, TheRegionHoldsNearTheCameraAndNotFarFromIt) {
  const Mesh torus = make_torus(32, 16);
  const AsaCamera camera = fit_camera(torus, 640, 480);
  const Culled c = cull_of(torus, camera);
  ASSERT_FALSE(c.cull.region.everything);
  const Vec3f offset = camera.eye - camera.target;
  auto turned = [&](float degrees) {
    const float a = degrees * 3.14159265f / 180.0f;
    AsaCamera t = camera;
    t.eye = camera.target + Vec3f{offset.x * std::cos(a) - offset.z * std::sin(a), offset.y,
                                  offset.x * std::sin(a) + offset.z * std::cos(a)};
    return t;
  };
  EXPECT_TRUE(cull_valid_for(c.cull.region, turned(0.4f), 0));
  EXPECT_FALSE(cull_valid_for(c.cull.region, turned(30), 0));
  EXPECT_FALSE(cull_valid_for(c.cull.region, camera, 1e6f)) << "a near plane cutting the model";
  // Every face a camera within the region sees from the front is kept.
  const AsaCamera moved = turned(0.4f);
  const std::vector<bool> kept = kept_faces(torus, *c.cull.mesh);
  for (uint32_t f = 0; f < torus.face_count(); ++f)
    if (in_view(torus, f, moved) && faces_eye(torus, f, moved.eye)) {
      EXPECT_TRUE(kept[f]) << f;
    }
}

TEST(DisplayCull, AnOpenComponentBesideAClosedOneKeepsItsFaces) {
  Mesh both = make_torus(24, 12);
  const Mesh grid = make_open_grid(8);
  const uint32_t base = both.vertex_count(), first_grid_face = both.face_count();
  for (Vec3f p : grid.positions) both.positions.push_back(p + Vec3f{0, 0, -0.5f});
  for (const Triangle& t : grid.triangles)
    both.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
  AsaCamera camera = fit_camera(both, 640, 480);
  const Culled c = cull_of(both, camera);
  const std::vector<bool> kept = kept_faces(both, *c.cull.mesh);
  for (uint32_t f = first_grid_face; f < both.face_count(); ++f)
    if (in_view(both, f, camera)) {
      EXPECT_TRUE(kept[f]) << "grid face " << f;
    }
  EXPECT_GT(c.cull.back_culled, 0u);
}

// A sphere with a hole around its +z pole, seen from +z: the far inside
// (back faces) shows through the hole and stays; back faces that no line
// through the hole reaches go.
TEST(DisplayCull, BackFacesSeenThroughAHoleStay) {
  const Mesh sphere = make_icosphere(4);
  Mesh holed;
  holed.positions = sphere.positions;
  for (const Triangle& t : sphere.triangles) {
    const Vec3f c =
        (sphere.positions[t[0]] + sphere.positions[t[1]] + sphere.positions[t[2]]) / 3.0f;
    if (c.z < 0.97f) holed.triangles.push_back(t);
  }
  ASSERT_LT(holed.face_count(), sphere.face_count());
  AsaCamera above;
  above.eye = {0, 0, 6};
  above.target = {0, 0, 0};
  above.fov_degrees = 30;
  above.width = 400;
  above.height = 400;
  const Culled c = cull_of(holed, above);
  EXPECT_GT(c.cull.back_culled, 0u) << "the holed sphere should still hide some back faces";
  const std::vector<bool> kept = kept_faces(holed, *c.cull.mesh);
  uint32_t far_inside = 0;
  for (uint32_t f = 0; f < holed.face_count(); ++f) {
    const Triangle& t = holed.triangles[f];
    const Vec3f centre =
        (holed.positions[t[0]] + holed.positions[t[1]] + holed.positions[t[2]]) / 3.0f;
    // Straight below the hole (within its cone from the eye): seen.
    if (centre.z < -0.9f && std::hypot(centre.x, centre.y) < 0.2f) {
      ++far_inside;
      EXPECT_TRUE(kept[f]) << "face " << f << " shows through the hole";
    }
  }
  EXPECT_GT(far_inside, 0u);
}

}  // namespace
}  // namespace meshstream

// Attributes in the stream (attribute_codec.h): exact at full rate (per
// vertex and per corner, seams, materials, extra attributes), valid at every
// prefix, 8-bit colours exact, damaged attribute records refused by name.
#include "common/codec/attribute_codec.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <tuple>

#include "common/codec/attribute_quantize.h"
#include "common/codec/byte_io.h"
#include "common/codec/container.h"
#include "common/codec/container_reseal.h"
#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "common/codec/quantize.h"
#include "common/mesh/import.h"
#include "common/mesh/procedural.h"
#include "common/mesh/textured_sphere.h"
#include "tests/codec/attribute_test_util.h"
#include "tests/test_meshes.h"

namespace meshstream {
namespace {

using testing::expected_mesh;
using testing::faces_of;

// A cube whose faces are n x n grids, welded along the cube's edges: normals
// per corner (the face's: seams on the cube's edges), texture coordinates
// per corner (one island per face), a material per cube face, colours per
// vertex and one extra attribute per corner.
Mesh faceted_cube(int n) {
  Mesh m;
  std::map<std::tuple<int, int, int>, uint32_t> ids;
  auto vertex = [&](int x, int y, int z) {
    auto key = std::tuple{x, y, z};
    auto it = ids.find(key);
    if (it != ids.end()) return it->second;
    const uint32_t id = m.vertex_count();
    m.positions.push_back({float(x) / n - 0.5f, float(y) / n - 0.5f, float(z) / n - 0.5f});
    ids.emplace(key, id);
    return id;
  };
  // Face f: axis a, side s; (u, v) span the other two axes, oriented outward.
  for (int f = 0; f < 6; ++f) {
    const int a = f / 2, s = f % 2;
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    Vec3f normal{0, 0, 0};
    (a == 0 ? normal.x : a == 1 ? normal.y : normal.z) = s ? 1.0f : -1.0f;
    auto at = [&](int i, int j) {
      int p[3];
      p[a] = s ? n : 0;
      p[b] = i;
      p[c] = j;
      return vertex(p[0], p[1], p[2]);
    };
    const uint32_t normal_index = uint32_t(m.corner_normals.values.size());
    m.corner_normals.values.push_back(normal);
    const uint32_t uv_base = uint32_t(m.corner_texcoords.values.size());
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i)
        m.corner_texcoords.values.push_back({float(f) * 1.1f + float(i) / n, float(j) / n});
    auto uv = [&](int i, int j) { return uv_base + uint32_t(j * (n + 1) + i); };
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        std::array<std::pair<int, int>, 3> t1{{{i, j}, {i + 1, j}, {i + 1, j + 1}}};
        std::array<std::pair<int, int>, 3> t2{{{i, j}, {i + 1, j + 1}, {i, j + 1}}};
        for (auto t : {t1, t2}) {
          if (!s) std::swap(t[1], t[2]);
          m.triangles.push_back({at(t[0].first, t[0].second), at(t[1].first, t[1].second),
                                 at(t[2].first, t[2].second)});
          for (int k = 0; k < 3; ++k) {
            m.corner_normals.corners.push_back(normal_index);
            m.corner_texcoords.corners.push_back(uv(t[k].first, t[k].second));
          }
          m.face_materials.push_back(uint32_t(f % 3));
        }
      }
    }
  }
  for (int k = 0; k < 3; ++k) {
    Material mat;
    mat.name = "mat" + std::to_string(k);
    mat.base_color = {0.2f * k, 0.5f, 1.0f - 0.3f * k, 1.0f};
    mat.base_color_texture = k == 1 ? 0 : -1;
    m.materials.push_back(mat);
  }
  // Materials refer to textures by index: a real (small) PNG for index 0,
  // carried by the texture records.
  m.textures.push_back(Texture{"t.png", "image/png", make_checker_png(16, 2)});
  for (const Vec3f& p : m.positions) {
    auto byte = [](float x) { return float(std::lround((x + 0.5f) * 255)) / 255.0f; };
    m.colors.push_back({byte(p.x), byte(p.y), byte(p.z), 1.0f});
  }
  ExtraAttribute tangent;
  tangent.name = "TANGENT";
  tangent.component_type = ExtraAttribute::ComponentType::kFloat32;
  tangent.components = 4;
  tangent.bytes.resize(3 * m.triangles.size() * 16);
  for (size_t i = 0; i < tangent.bytes.size(); ++i) tangent.bytes[i] = uint8_t((i * 7) / 16);
  m.extra_attributes.push_back(tangent);
  return m;
}

// A UV sphere: per-vertex normals, texture coordinates per corner with the
// seam meridian and the poles' fans split.
Mesh uv_sphere(int rings, int segments) {
  Mesh m;
  m.positions.push_back({0, 0, 1});
  for (int r = 1; r < rings; ++r) {
    const double th = M_PI * r / rings;
    for (int s = 0; s < segments; ++s) {
      const double ph = 2 * M_PI * s / segments;
      m.positions.push_back({float(std::sin(th) * std::cos(ph)), float(std::sin(th) * std::sin(ph)),
                             float(std::cos(th))});
    }
  }
  m.positions.push_back({0, 0, -1});
  const uint32_t south = m.vertex_count() - 1;
  auto id = [&](int r, int s) { return uint32_t(1 + (r - 1) * segments + (s % segments)); };
  auto uv = [&](int r, int s) {
    m.corner_texcoords.values.push_back({float(s) / segments, 1.0f - float(r) / rings});
    return uint32_t(m.corner_texcoords.values.size() - 1);
  };
  auto face = [&](uint32_t a, uint32_t b, uint32_t c, uint32_t ta, uint32_t tb, uint32_t tc) {
    m.triangles.push_back({a, b, c});
    for (uint32_t t : {ta, tb, tc}) m.corner_texcoords.corners.push_back(t);
  };
  for (int s = 0; s < segments; ++s) {
    face(0, id(1, s), id(1, s + 1), uv(0, s), uv(1, s), uv(1, s + 1));
    for (int r = 1; r + 1 < rings; ++r) {
      face(id(r, s), id(r + 1, s), id(r + 1, s + 1), uv(r, s), uv(r + 1, s), uv(r + 1, s + 1));
      face(id(r, s), id(r + 1, s + 1), id(r, s + 1), uv(r, s), uv(r + 1, s + 1), uv(r, s + 1));
    }
    face(id(rings - 1, s), south, id(rings - 1, s + 1), uv(rings - 1, s), uv(rings, s),
         uv(rings - 1, s + 1));
  }
  m.normals = m.positions;
  return m;
}

void expect_materials_equal(const Mesh& a, const Mesh& b) {
  ASSERT_EQ(a.materials.size(), b.materials.size());
  for (size_t i = 0; i < a.materials.size(); ++i) {
    EXPECT_EQ(a.materials[i].name, b.materials[i].name);
    EXPECT_EQ(a.materials[i].base_color, b.materials[i].base_color);
    EXPECT_EQ(a.materials[i].base_color_texture, b.materials[i].base_color_texture);
  }
}

// Every prefix: attribute arrays sized to the mesh and in range.
void expect_valid_prefixes(const std::vector<uint8_t>& stream) {
  IncrementalDecoder decoder;
  auto index = read_stream_index(stream);
  ASSERT_TRUE(index) << index.error().message;
  uint64_t at = 0;
  for (size_t i = 0; i < index->records.size(); ++i) {
    const uint64_t end = index->records[i].offset + index->records[i].size;
    auto fed = decoder.feed(std::span<const uint8_t>(stream.data() + at, end - at));
    ASSERT_TRUE(fed) << fed.error().message;
    at = end;
    const Mesh& m = decoder.mesh();
    ASSERT_TRUE(check_attribute_counts(m))
        << "record " << i << ": " << check_attribute_counts(m).error().message;
    ASSERT_TRUE(validate_arrays(m)) << "record " << i;
    if (i >= 1) {
      EXPECT_FALSE(m.colors.empty() && m.normals.empty() && m.corner_texcoords.empty())
          << "record " << i << " has no attributes";
    }
    // The one-shot decoder agrees on validity at this prefix.
    auto once = decode_hcs(std::span<const uint8_t>(stream.data(), end));
    ASSERT_TRUE(once) << once.error().message;
    EXPECT_TRUE(check_attribute_counts(*once)) << "record " << i;
  }
}

TEST(AttributeCodec, FacetedCubeRoundTripsExactlyWithSeamsMaterialsAndExtras) {
  const Mesh cube = faceted_cube(8);
  ASSERT_TRUE(check_attribute_counts(cube)) << check_attribute_counts(cube).error().message;
  EncodeOptions o;
  o.target_base_vertices = 40;
  EncodeReport report;
  auto stream = encode_hcs(cube, o, &report);
  ASSERT_TRUE(stream) << stream.error().message;
  EXPECT_GT(report.attribute_locked_vertices, 0u);
  EXPECT_GT(report.attribute_bytes["seams"], 0u);
  EXPECT_GT(report.attribute_bytes["extra"], 0u);
  EXPECT_TRUE(report.warnings.empty());  // everything travels, the image too
  auto decoded = decode_hcs(*stream);
  ASSERT_TRUE(decoded) << decoded.error().message;
  ASSERT_TRUE(check_attribute_counts(*decoded)) << check_attribute_counts(*decoded).error().message;
  Mesh expected = expected_mesh(cube, o);
  // The image travels in texture records: the decoded table keeps its index.
  ASSERT_EQ(decoded->textures.size(), cube.textures.size());
  EXPECT_TRUE(decoded->textures[0].bytes == cube.textures[0].bytes);
  expected.textures = cube.textures;
  EXPECT_TRUE(faces_of(*decoded) == faces_of(expected));
  expect_materials_equal(*decoded, expected);
  EXPECT_EQ(decoded->corner_normals.corners.size(), 3 * decoded->triangles.size());
  EXPECT_EQ(decoded->colors.size(), decoded->positions.size());
  // The seeds of tests/fuzz/corpus/hcs_decoder with seams came from here.
  if (const char* seeds = std::getenv("MESHSTREAM_WRITE_FUZZ_SEEDS")) {
    std::ofstream(std::string(seeds) + "/faceted_cube.hcs", std::ios::binary)
        .write(reinterpret_cast<const char*>(stream->data()), std::streamsize(stream->size()));
  }
  // The incremental decoder's complete mesh is the same.
  IncrementalDecoder inc;
  ASSERT_TRUE(inc.feed(*stream));
  EXPECT_TRUE(faces_of(inc.mesh()) == faces_of(expected));
  expect_valid_prefixes(*stream);
}

TEST(AttributeCodec, UvSphereRoundTripsExactly) {
  const Mesh sphere = uv_sphere(24, 32);
  ASSERT_TRUE(check_attribute_counts(sphere));
  for (int uv_bits : {12, 10}) {
    EncodeOptions o;
    o.quant_uv = uv_bits;
    o.quant_normal = 10;
    auto stream = encode_hcs(sphere, o);
    ASSERT_TRUE(stream) << stream.error().message;
    auto decoded = decode_hcs(*stream);
    ASSERT_TRUE(decoded) << decoded.error().message;
    EXPECT_TRUE(faces_of(*decoded) == faces_of(expected_mesh(sphere, o))) << uv_bits;
  }
  auto stream = encode_hcs(sphere, {});
  ASSERT_TRUE(stream);
  expect_valid_prefixes(*stream);
}

// Version 12: values records leave the normals out (part 3) and normals
// records after the last geometry record bring them, coded on the complete
// mesh; the round trip stays exact and every prefix valid.
TEST(AttributeCodec, NormalsComeInNormalsRecordsAfterTheGeometry) {
  Mesh sphere = uv_sphere(24, 32);
  sphere.normals.clear();  // per vertex, smooth: the geometric prediction's case
  for (const Vec3f& p : sphere.positions) {
    const float l = std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
    sphere.normals.push_back({p.x / l, p.y / l, p.z / l});
  }
  ASSERT_TRUE(check_attribute_counts(sphere)) << check_attribute_counts(sphere).error().message;
  EncodeOptions o;
  o.asa_guidance = false;
  auto stream = encode_hcs(sphere, o);
  ASSERT_TRUE(stream) << stream.error().message;
  auto index = read_stream_index(*stream);
  ASSERT_TRUE(index);
  size_t late_values = 0, old_values = 0, normals_records = 0, last_geometry = 0;
  size_t first_normals = index->records.size();
  for (size_t i = 0; i < index->records.size(); ++i) {
    const RecordEntry& r = index->records[i];
    const auto payload = record_payload(r, {stream->data() + r.offset, r.size});
    if (payload.empty() || payload[0] != kRecordAttributes) {
      if (payload.empty() || payload[0] != kRecordTexture) last_geometry = i;
      continue;
    }
    late_values += payload[1] == kAttributePartValuesLateNormals;
    old_values += payload[1] == kAttributePartValues;
    if (payload[1] == kAttributePartNormals) {
      ++normals_records;
      first_normals = std::min(first_normals, i);
    }
  }
  EXPECT_GT(late_values, 0u);
  EXPECT_EQ(old_values, 0u);
  EXPECT_GT(normals_records, 0u);
  EXPECT_GT(first_normals, last_geometry) << "normals records follow every geometry record";
  auto decoded = decode_hcs(*stream);
  ASSERT_TRUE(decoded) << decoded.error().message;
  EXPECT_TRUE(faces_of(*decoded) == faces_of(expected_mesh(sphere, o)));
  expect_valid_prefixes(*stream);
}

// The layout flags byte of channel `ch` in record 1's payload (the layout
// section: varint length, channel count, then per channel kind, flags,
// bits and for texture coordinates 16 bytes of grid).
uint8_t layout_flags(std::span<const uint8_t> payload, AttributeKind kind) {
  size_t pos = 2;
  uint32_t length = 0;
  if (!get_varint(payload, pos, length)) return 0xFF;
  const size_t end = pos + length;
  const uint32_t count = payload[pos++];
  for (uint32_t i = 0; i < count && pos + 3 <= end; ++i) {
    const uint8_t k = payload[pos], flags = payload[pos + 1];
    if (k == uint8_t(kind)) return flags;
    pos += 3 + (flags & kBaseCoarse ? 1 : 0) + (k == uint8_t(AttributeKind::kTexcoord) ? 16 : 0);
  }
  return 0xFF;
}

// Version 13: record 1 leaves the base's normals out (layout flag
// kBaseNormalsLate, no section for them); the normals records, after every
// geometry record, bring them from vertex 0, coded on the complete mesh.
// Until then each wedge shows its geometric normal (every prefix valid; on
// the cube's flat wedges the face's own normal), and the full-rate decode is
// exact.
void expect_base_normals_late(const Mesh& mesh, const EncodeOptions& o, bool flat_wedges) {
  EncodeReport report;
  auto stream = encode_hcs(mesh, o, &report);
  ASSERT_TRUE(stream) << stream.error().message;
  auto index = read_stream_index(*stream);
  ASSERT_TRUE(index);
  ASSERT_GT(index->records.size(), 1u);
  const RecordEntry& r = index->records[1];
  const auto payload = record_payload(r, {stream->data() + r.offset, r.size});
  ASSERT_GE(payload.size(), 8u);
  EXPECT_EQ(payload[0], kRecordAttributes);
  EXPECT_EQ(payload[1], kAttributePartBase);
  const uint8_t flags = layout_flags(payload, AttributeKind::kNormal);
  ASSERT_NE(flags, 0xFF) << "no normals in the layout";
  EXPECT_TRUE(flags & kBaseNormalsLate);
  EXPECT_FALSE(flags & kPredictBaseAlternative) << "record 1 codes no normals";
  auto parts = attribute_record_parts(payload, {}, {});
  ASSERT_TRUE(parts) << parts.error().message;
  EXPECT_EQ(parts->count("normals") ? parts->at("normals") : 0, 0u);
  EXPECT_GT(report.attribute_bytes["normals"], 0u) << "the normals travel later";
  // The first normals record starts at vertex 0 and follows every geometry
  // record.
  size_t last_geometry = 0, first_normals = 0;
  uint32_t first_count = 0;
  for (size_t i = 0; i < index->records.size(); ++i) {
    const RecordEntry& e = index->records[i];
    const auto p = record_payload(e, {stream->data() + e.offset, e.size});
    if (p.empty() || p[0] != kRecordAttributes) {
      if (!p.empty() && p[0] != kRecordTexture) last_geometry = i;
      continue;
    }
    if (p[1] == kAttributePartNormals && first_normals == 0) {
      first_normals = i;
      size_t pos = 2;
      ASSERT_TRUE(get_varint(p, pos, first_count));
    }
  }
  ASSERT_GT(first_normals, 0u) << "no normals record";
  EXPECT_GT(first_normals, last_geometry);
  EXPECT_GE(first_count, 1u);
  auto decoded = decode_hcs(*stream);
  ASSERT_TRUE(decoded) << decoded.error().message;
  Mesh expected = expected_mesh(mesh, o);
  expected.textures = mesh.textures;
  EXPECT_TRUE(faces_of(*decoded) == faces_of(expected));
  expect_valid_prefixes(*stream);
  if (!flat_wedges) return;
  // Record 1's prefix: every corner's normal is its wedge's geometric
  // normal on the base, which on flat wedges is the face's own.
  IncrementalDecoder inc;
  ASSERT_TRUE(inc.feed(std::span<const uint8_t>(*stream).subspan(0, r.offset + r.size)));
  const Mesh& first = inc.mesh();
  ASSERT_EQ(first.corner_normals.corners.size(), 3 * first.triangles.size());
  for (size_t f = 0; f < first.triangles.size(); ++f) {
    const Vec3f& a = first.positions[first.triangles[f][0]];
    const Vec3f& b = first.positions[first.triangles[f][1]];
    const Vec3f& c = first.positions[first.triangles[f][2]];
    const Vec3f u{b.x - a.x, b.y - a.y, b.z - a.z}, v{c.x - a.x, c.y - a.y, c.z - a.z};
    Vec3f g{u.y * v.z - u.z * v.y, u.z * v.x - u.x * v.z, u.x * v.y - u.y * v.x};
    const float l = std::sqrt(g.x * g.x + g.y * g.y + g.z * g.z);
    ASSERT_GT(l, 0);
    for (int k = 0; k < 3; ++k) {
      const Vec3f& n = first.corner_normals.values[first.corner_normals.corners[3 * f + k]];
      EXPECT_GT((n.x * g.x + n.y * g.y + n.z * g.z) / l, 0.98f) << "face " << f << " corner " << k;
    }
  }
}

TEST(AttributeCodec, BaseNormalsLateOnTheFacetedCube) {
  EncodeOptions o;
  o.target_base_vertices = 40;
  o.asa_guidance = false;
  expect_base_normals_late(faceted_cube(8), o, true);
}

// Draco's textured sphere: every vertex is a seam vertex and stays in the
// base (no geometry records with vertices), so its normals all travel in
// the normals records (version 12 coded them in record 1, from the
// neighbours' normals: 1 479 bytes; now 503 on the exact positions).
TEST(AttributeCodec, BaseNormalsLateOnDracosSphere) {
  std::filesystem::path file;
  if (!testing::test_mesh_dir().empty())
    file = std::filesystem::path(testing::test_mesh_dir()) / ".." / "models" /
           "SphereWithCircleTexture" / "sphere_with_circle_texture.gltf";
  if (file.empty() || !std::filesystem::exists(file))
    GTEST_SKIP() << "../shared/models/SphereWithCircleTexture not found (set "
                    "MESHSTREAM_TEST_MESHES)";
  auto imported = import_mesh(file.string());
  ASSERT_TRUE(imported) << imported.error().message;
  EncodeOptions o;
  o.asa_guidance = false;
  expect_base_normals_late(imported->mesh, o, false);
}

// Version 14: record 1 carries the base's 12-bit texture coordinates on an
// 8-bit grid (layout flag kBaseCoarse, shift 4), shown at the middle of the
// missing bits' range; the low-bits record brings the rest before the
// first values record, after which the base's values are exact.
// Where a stream's records are: its one low-bits record, its first values
// record and its last geometry record (0: none); layout flags of `kind`.
struct RecordPlaces {
  size_t low = 0, lows = 0, first_values = 0, last_geometry = 0;
  uint8_t flags = 0xFF;
};
RecordPlaces record_places(const std::vector<uint8_t>& stream, AttributeKind kind) {
  RecordPlaces out;
  auto index = read_stream_index(stream);
  if (!index || index->records.size() < 2) return out;
  for (size_t i = 1; i < index->records.size(); ++i) {
    const RecordEntry& e = index->records[i];
    const auto p = record_payload(e, {stream.data() + e.offset, e.size});
    if (i == 1) out.flags = layout_flags(p, kind);
    if (p.empty() || p[0] == kRecordTexture) continue;
    if (p[0] != kRecordAttributes) {
      out.last_geometry = i;
      continue;
    }
    if (p.size() > 1 && p[1] == kAttributePartLowBits) {
      out.low = i;
      ++out.lows;
    }
    if (p.size() > 1 && (p[1] == kAttributePartValues || p[1] == kAttributePartValuesLateNormals) &&
        out.first_values == 0)
      out.first_values = i;
  }
  return out;
}

// The mesh the client shows after record `last`.
Mesh decoded_through(const std::vector<uint8_t>& stream, size_t last) {
  auto index = read_stream_index(stream);
  EXPECT_TRUE(index);
  IncrementalDecoder d;
  if (!index) return {};
  const RecordEntry& e = index->records[last];
  EXPECT_TRUE(d.feed(std::span<const uint8_t>(stream).subspan(0, e.offset + e.size)));
  return d.mesh();
}

TEST(AttributeCodec, CoarseBaseTexcoordsThenTheirLowBits) {
  const Mesh cube = faceted_cube(8);
  EncodeOptions o;
  o.target_base_vertices = 40;
  o.asa_guidance = false;
  auto stream = encode_hcs(cube, o);
  ASSERT_TRUE(stream) << stream.error().message;
  const RecordPlaces at = record_places(*stream, AttributeKind::kTexcoord);
  ASSERT_NE(at.flags, 0xFF);
  EXPECT_TRUE(at.flags & kBaseCoarse);
  EXPECT_EQ(at.lows, 1u) << "one low-bits record";
  const size_t low = at.low;
  ASSERT_GT(low, 1u) << "no low-bits record";
  ASSERT_GT(at.first_values, 0u);
  EXPECT_LT(low, at.first_values) << "the values are predicted from the exact base";
  const std::vector<Vec2f> coarse = decoded_through(*stream, 1).corner_texcoords.values,
                           refined = decoded_through(*stream, low).corner_texcoords.values;
  auto whole = decode_hcs(*stream);
  ASSERT_TRUE(whole) << whole.error().message;
  ASSERT_FALSE(coarse.empty());
  ASSERT_GE(refined.size(), coarse.size());
  ASSERT_GE(whole->corner_texcoords.values.size(), coarse.size());
  // Half the coarse step: 2^3 steps of the 12-bit grid over the UV box.
  float lo = 1e9f, hi = -1e9f;
  for (const Vec2f& t : cube.corner_texcoords.values) {
    lo = std::min({lo, t.x, t.y});
    hi = std::max({hi, t.x, t.y});
  }
  const float half = 8 * (hi - lo) / 4095 * 1.01f;
  size_t differ = 0;
  for (size_t w = 0; w < coarse.size(); ++w) {
    EXPECT_LE(std::abs(coarse[w].x - refined[w].x), half) << w;
    EXPECT_LE(std::abs(coarse[w].y - refined[w].y), half) << w;
    differ += coarse[w].x != refined[w].x || coarse[w].y != refined[w].y;
    EXPECT_EQ(refined[w].x, whole->corner_texcoords.values[w].x) << "base wedge " << w;
    EXPECT_EQ(refined[w].y, whole->corner_texcoords.values[w].y) << "base wedge " << w;
  }
  EXPECT_GT(differ, 0u) << "record 1 carried them exactly";
  Mesh expected = expected_mesh(cube, o);
  expected.textures = cube.textures;
  EXPECT_TRUE(faces_of(*whole) == faces_of(expected));
  expect_valid_prefixes(*stream);
}

// Version 16 (kWedgeRepeat): a hard-edged cube (normals per face, so the
// vertices on its edges have two or three wedges) whose texture coordinates
// are per vertex, shared by those wedges: each is coded once, so the
// stream is smaller than with every wedge's value coded, and both decode
// exactly, at every prefix valid.
TEST(AttributeCodec, SharedTexcoordsOfHardEdgesAreCodedOnce) {
  Mesh cube = faceted_cube(6);
  cube.corner_texcoords.values.clear();
  cube.corner_texcoords.corners.clear();
  for (const Vec3f& p : cube.positions)
    cube.corner_texcoords.values.push_back({p.x + 0.3f * p.z, p.y + 0.7f * p.z});
  for (const auto& t : cube.triangles)
    for (uint32_t v : t) cube.corner_texcoords.corners.push_back(v);
  ASSERT_TRUE(check_attribute_counts(cube)) << check_attribute_counts(cube).error().message;
  EncodeOptions o;
  o.target_base_vertices = 40;
  std::vector<uint8_t> streams[2];
  for (bool repeat : {false, true}) {
    o.wedge_repeat = repeat;
    auto stream = encode_hcs(cube, o);
    ASSERT_TRUE(stream) << stream.error().message;
    const RecordPlaces at = record_places(*stream, AttributeKind::kTexcoord);
    ASSERT_NE(at.flags, 0xFF);
    EXPECT_EQ((at.flags & kWedgeRepeat) != 0, repeat);
    auto decoded = decode_hcs(*stream);
    ASSERT_TRUE(decoded) << decoded.error().message;
    Mesh expected = expected_mesh(cube, o);
    expected.textures = cube.textures;
    EXPECT_TRUE(faces_of(*decoded) == faces_of(expected)) << repeat;
    expect_valid_prefixes(*stream);
    streams[repeat] = std::move(*stream);
  }
  // 152 edge vertices of 2-3 wedges: far more than one bit per wedge saved.
  EXPECT_LT(streams[1].size() + 100, streams[0].size())
      << streams[1].size() << " vs " << streams[0].size();
}

// The faceted cube's face charts (UV per face, so every edge vertex has 2-3
// wedges) with smooth normals: each vertex's normal is the same in all its
// wedges, the case version 17 codes once.
Mesh smooth_cube_with_face_charts(int n) {
  Mesh cube = faceted_cube(n);
  cube.corner_normals.values.clear();
  cube.corner_normals.corners.clear();
  for (const Vec3f& p : cube.positions) cube.corner_normals.values.push_back(normalized(p));
  for (const auto& t : cube.triangles)
    for (uint32_t v : t) cube.corner_normals.corners.push_back(v);
  return cube;
}

// A normal repeated across the wedges that the texture coordinates split is
// coded once (version 17: kWedgeRepeat on the normals), exact at full rate
// and valid at every prefix either way.
TEST(AttributeCodec, SharedNormalsOfUvSeamsAreCodedOnce) {
  const Mesh cube = smooth_cube_with_face_charts(6);
  ASSERT_TRUE(check_attribute_counts(cube)) << check_attribute_counts(cube).error().message;
  EncodeOptions o;
  o.target_base_vertices = 40;
  std::vector<uint8_t> streams[2];
  for (bool repeat : {false, true}) {
    o.wedge_repeat = repeat;
    auto stream = encode_hcs(cube, o);
    ASSERT_TRUE(stream) << stream.error().message;
    const RecordPlaces at = record_places(*stream, AttributeKind::kNormal);
    ASSERT_NE(at.flags, 0xFF);
    EXPECT_EQ((at.flags & kWedgeRepeat) != 0, repeat);
    auto decoded = decode_hcs(*stream);
    ASSERT_TRUE(decoded) << decoded.error().message;
    Mesh expected = expected_mesh(cube, o);
    expected.textures = cube.textures;
    EXPECT_TRUE(faces_of(*decoded) == faces_of(expected)) << repeat;
    expect_valid_prefixes(*stream);
    streams[repeat] = std::move(*stream);
  }
  // 152 edge vertices of 2-3 wedges, one normal each.
  EXPECT_LT(streams[1].size() + 100, streams[0].size())
      << streams[1].size() << " vs " << streams[0].size();
}

// An icosphere of 2 562 vertices with smooth per-vertex colours that use
// all 8 bits (so the low bits are not a constant).
Mesh coloured_icosphere(uint32_t subdivisions) {
  Mesh m = make_icosphere(subdivisions);
  for (const Vec3f& p : m.positions)
    m.colors.push_back({0.5f + 0.45f * std::sin(3 * p.x + p.y), 0.5f + 0.45f * std::cos(2 * p.y),
                        0.5f + 0.45f * std::sin(2.5f * p.z + p.x), 1.0f});
  return m;
}

// Version 15, colours asked coarse (base_color_bits 4 of 8): record 1
// carries the base's colours on a 4-bit grid (layout flag kBaseCoarse),
// shown at the middle of the missing range (within half a coarse step, 8 of
// 255, and not exact); the low-bits record before the first values record
// makes them exact; the full-rate decode is exact and every prefix valid.
// The default (0) keeps them exact in record 1.
TEST(AttributeCodec, CoarseBaseColoursThenTheirLowBits) {
  const Mesh sphere = coloured_icosphere(4);
  EncodeOptions o;
  o.asa_guidance = false;
  auto plain = encode_hcs(sphere, o);
  ASSERT_TRUE(plain) << plain.error().message;
  const RecordPlaces plain_at = record_places(*plain, AttributeKind::kColor);
  ASSERT_NE(plain_at.flags, 0xFF);
  EXPECT_FALSE(plain_at.flags & kBaseCoarse);
  EXPECT_EQ(plain_at.lows, 0u);
  o.base_color_bits = 4;
  auto stream = encode_hcs(sphere, o);
  ASSERT_TRUE(stream) << stream.error().message;
  const RecordPlaces at = record_places(*stream, AttributeKind::kColor);
  EXPECT_TRUE(at.flags & kBaseCoarse);
  EXPECT_EQ(at.lows, 1u);
  ASSERT_GT(at.low, 1u) << "no low-bits record";
  ASSERT_GT(at.first_values, 0u);
  EXPECT_LT(at.low, at.first_values) << "the values are predicted from the exact base";
  const std::vector<Vec4f> coarse = decoded_through(*stream, 1).colors,
                           refined = decoded_through(*stream, at.low).colors;
  auto whole = decode_hcs(*stream);
  ASSERT_TRUE(whole) << whole.error().message;
  ASSERT_FALSE(coarse.empty());
  ASSERT_LT(coarse.size(), sphere.positions.size()) << "vertices beyond the base";
  ASSERT_GE(refined.size(), coarse.size());
  const float half = 8.0f / 255 * 1.01f;
  size_t differ = 0;
  for (size_t v = 0; v < coarse.size(); ++v) {
    const Vec4f c = coarse[v], r = refined[v];
    for (float d : {c.x - r.x, c.y - r.y, c.z - r.z, c.w - r.w}) EXPECT_LE(std::abs(d), half) << v;
    EXPECT_TRUE(r == whole->colors[v]) << "base vertex " << v;
    differ += coarse[v] != refined[v];
  }
  EXPECT_GT(differ, coarse.size() / 2) << "record 1 carried them exactly";
  EXPECT_TRUE(faces_of(*whole) == faces_of(expected_mesh(sphere, o)));
  expect_valid_prefixes(*stream);
  o.base_color_bits = 8;  // not coarser than the colours
  EXPECT_EQ(encode_hcs(sphere, o).error().code, ErrorCode::kInvalidArgument);
}

// Without a values record (every vertex in the base) the low-bits record of
// coarse colours follows the last geometry record (as version 14's UV:
// right after record 1 was measured and not kept, bench/REPORT.md): the
// colours are coarse until then and exact after it.
TEST(AttributeCodec, CoarseBaseColoursWithoutValuesRecordsExactAfterTheGeometry) {
  const Mesh sphere = coloured_icosphere(2);  // 162 vertices
  EncodeOptions o;
  o.asa_guidance = false;
  o.base_color_bits = 4;
  o.target_base_vertices = 1000;
  auto stream = encode_hcs(sphere, o);
  ASSERT_TRUE(stream) << stream.error().message;
  const RecordPlaces at = record_places(*stream, AttributeKind::kColor);
  EXPECT_TRUE(at.flags & kBaseCoarse);
  EXPECT_EQ(at.first_values, 0u) << "every vertex in the base";
  EXPECT_EQ(at.lows, 1u);
  ASSERT_GT(at.last_geometry, 1u) << "geometry records refine the base";
  EXPECT_EQ(at.low, at.last_geometry + 1);
  auto whole = decode_hcs(*stream);
  ASSERT_TRUE(whole) << whole.error().message;
  EXPECT_FALSE(decoded_through(*stream, at.last_geometry).colors == whole->colors);
  EXPECT_TRUE(decoded_through(*stream, at.low).colors == whole->colors);
  EXPECT_TRUE(faces_of(*whole) == faces_of(expected_mesh(sphere, o)));
  expect_valid_prefixes(*stream);
}

TEST(AttributeCodec, EightBitColoursComeBackExactly) {
  std::filesystem::path file;
  if (!testing::test_mesh_dir().empty())
    file = std::filesystem::path(testing::test_mesh_dir()) / ".." / "models" / "test_pos_color.ply";
  if (file.empty() || !std::filesystem::exists(file))
    GTEST_SKIP() << "../shared/models/test_pos_color.ply not found (set MESHSTREAM_TEST_MESHES)";
  auto imported = import_mesh(file.string());
  ASSERT_TRUE(imported) << imported.error().message;
  const Mesh& m = imported->mesh;
  ASSERT_EQ(m.colors.size(), m.positions.size());
  auto stream = encode_hcs(m, {});
  ASSERT_TRUE(stream) << stream.error().message;
  auto decoded = decode_hcs(*stream);
  ASSERT_TRUE(decoded);
  // The input's colours themselves (k / 255), not only their quantization.
  Mesh expected = *quantized_reference(m, 12);
  expected.colors = m.colors;
  EXPECT_TRUE(faces_of(*decoded) == faces_of(expected));
  expect_valid_prefixes(*stream);
}

TEST(AttributeCodec, MeshWithoutAttributesHasNoAttributeRecords) {
  Mesh plain = uv_sphere(10, 12);
  plain.corner_texcoords = {};
  plain.normals.clear();
  EncodeReport report;
  auto stream = encode_hcs(plain, {}, &report);
  ASSERT_TRUE(stream);
  EXPECT_TRUE(report.attribute_bytes.empty());
  auto index = read_stream_index(*stream);
  ASSERT_TRUE(index);
  for (const RecordEntry& r : index->records) EXPECT_NE((*stream)[r.offset], kRecordAttributes);
}

// EncodeOptions::measure_unlocked_seams (a measurement for bench/REPORT.md):
// false is the default stream byte for byte, seam vertices locked into the
// base; true decimates through the seams (a smaller base than the locked
// vertices) and writes the geometry alone, which decodes to the same
// positions and face count.
TEST(AttributeCodec, MeasureUnlockedSeamsOffChangesNothingOnRemovesTheLocks) {
  const Mesh cube = faceted_cube(8);
  EncodeOptions o;
  o.target_base_vertices = 40;
  o.asa_guidance = false;
  EncodeReport report;
  auto by_default = encode_hcs(cube, o, &report);
  ASSERT_TRUE(by_default) << by_default.error().message;
  EncodeOptions off = o;
  off.measure_unlocked_seams = false;
  auto locked = encode_hcs(cube, off);
  ASSERT_TRUE(locked) << locked.error().message;
  EXPECT_TRUE(*locked == *by_default) << "false must leave the stream unchanged";
  auto locked_index = read_stream_index(*locked);
  ASSERT_TRUE(locked_index);
  // Every vertex on the cube's edges is a seam vertex (normals, UV islands
  // and materials change there), locked into the base.
  const uint32_t locked_vertices = report.attribute_locked_vertices;
  EXPECT_EQ(locked_vertices, 12u * 7 + 8);
  EXPECT_GE(locked_index->header.base_vertex_count, locked_vertices);

  EncodeOptions on = o;
  on.measure_unlocked_seams = true;
  auto unlocked = encode_hcs(cube, on);
  ASSERT_TRUE(unlocked) << unlocked.error().message;
  auto index = read_stream_index(*unlocked);
  ASSERT_TRUE(index);
  EXPECT_LT(index->header.base_vertex_count, locked_vertices) << "seam vertices were decimated";
  for (const RecordEntry& r : index->records) EXPECT_NE((*unlocked)[r.offset], kRecordAttributes);
  auto a = decode_hcs(*locked);
  auto b = decode_hcs(*unlocked);
  ASSERT_TRUE(a && b);
  auto sorted = [](std::vector<Vec3f> p) {
    std::sort(p.begin(), p.end(), [](const Vec3f& x, const Vec3f& y) {
      return std::tie(x.x, x.y, x.z) < std::tie(y.x, y.y, y.z);
    });
    return p;
  };
  EXPECT_TRUE(sorted(a->positions) == sorted(b->positions));
  EXPECT_EQ(a->triangles.size(), b->triangles.size());
  EXPECT_TRUE(b->corner_normals.empty() && b->colors.empty());
}

TEST(AttributeCodec, BadQuantizationBitsAreRefused) {
  EncodeOptions o;
  o.quant_color = 1;
  auto stream = encode_hcs(faceted_cube(2), o);
  ASSERT_FALSE(stream);
  EXPECT_EQ(stream.error().code, ErrorCode::kInvalidArgument);
}

// A damaged attribute record (checksums resealed, as a hostile server would)
// is refused with a message naming it, and the mesh before it stays.
TEST(AttributeCodec, DamagedAttributeRecordsAreRefused) {
  EncodeOptions o;
  o.target_base_vertices = 40;
  auto stream = encode_hcs(faceted_cube(4), o);
  ASSERT_TRUE(stream);
  auto index = read_stream_index(*stream);
  ASSERT_TRUE(index);
  const RecordEntry& first = index->records[1];
  const RecordEntry& last = index->records.back();
  ASSERT_EQ((*stream)[first.offset], kRecordAttributes);
  ASSERT_EQ((*stream)[last.offset], kRecordAttributes);
  struct Damage {
    uint64_t at;
    uint8_t value;
    const char* expect;
  };
  // The layout section: a varint length, then the channel count and per
  // channel kind, per-corner flag, bits.
  size_t pos = first.offset + 2;
  uint32_t layout_length = 0;
  ASSERT_TRUE(get_varint(*stream, pos, layout_length));
  const uint64_t layout_at = pos;
  const Damage damages[] = {
      {first.offset + 1, 1, "before the mesh is complete"},  // base part claims to be the final
      {first.offset + 3, 0xFF, "attribute record"},          // layout length past the record
      {layout_at + 1, 9, "unknown attribute kind"},          // first channel's kind
      {layout_at + 3, 40, "quantization bits"},              // first channel's bits
      {layout_at + 2, 0x11, "unknown prediction flags"},     // normals: bit 4
      {layout_at + 2, 1, "attribute record"},           // normals without bit 3: a section missing
      {last.offset + 1, 0, "after a geometry record"},  // final part claims to be the base
      {last.offset + last.size - 6, 0xFF, "attribute record"},  // the zstd frame's end
  };
  // The low-bits record (version 14) claiming to be a values record.
  std::vector<Damage> all(std::begin(damages), std::end(damages));
  for (const RecordEntry& e : index->records)
    if ((*stream)[e.offset] == kRecordAttributes &&
        (*stream)[e.offset + 1] == kAttributePartLowBits) {
      all.push_back({e.offset + 1, kAttributePartValuesLateNormals, "before the base's low bits"});
      all.push_back({e.offset + 2, 7, "low-bits record for 7 vertices"});
    }
  EXPECT_EQ(all.size(), std::size(damages) + 2) << "one low-bits record";
  for (const Damage& d : all) {
    std::vector<uint8_t> bad = *stream;
    bad[d.at] = d.value;
    reseal_checksums(bad);
    IncrementalDecoder decoder;
    auto fed = decoder.feed(bad);
    ASSERT_FALSE(fed) << d.expect;
    EXPECT_NE(fed.error().message.find(d.expect), std::string::npos) << fed.error().message;
    EXPECT_NE(fed.error().message.find("record"), std::string::npos);
    EXPECT_TRUE(check_attribute_counts(decoder.mesh()));
  }
}

}  // namespace
}  // namespace meshstream

// The record table (record_table.h): its needs are earlier records and
// sufficient (any set closed under them replays to a manifold mesh, in any
// order that respects them; the whole set to the decoder's mesh exactly),
// and its spheres and cones hold what each record changes, checked against
// an independent record-by-record decode.
#include "common/codec/record_table.h"

#include <gtest/gtest.h>

#include <map>
#include <random>
#include <set>

#include "common/codec/container.h"
#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "common/mesh/import.h"
#include "tests/codec/codec_test_util.h"
#include "tests/test_meshes.h"

namespace meshstream {
namespace {

using namespace meshstream::testing;

std::vector<uint8_t> encode_fast(const Mesh& mesh) {
  EncodeOptions options;
  options.asa_guidance = false;
  options.plane_calibration = 1;  // one ordering: encode once
  auto bytes = encode_hcs(mesh, options);
  EXPECT_TRUE(bytes) << bytes.error().message;
  return bytes ? *bytes : std::vector<uint8_t>{};
}

struct Streams {
  std::vector<std::pair<std::string, std::vector<uint8_t>>> list;
};

const Streams& streams() {
  static const Streams s = [] {
    Streams out;
    out.list.push_back({"icosphere", encode_fast(icosphere(4, 0.1f))});
    out.list.push_back({"height field", encode_fast(height_field(36, 30))});
    out.list.push_back({"torus", encode_fast(torus(48, 20))});
    if (!test_mesh_dir().empty()) {
      auto imported = import_mesh(test_mesh("hemisphere.off"));
      if (imported) out.list.push_back({"hemisphere.off", encode_fast(imported->mesh)});
    }
    return out;
  }();
  return s;
}

TEST(RecordTable, NeedsAreEarlierRecordsAndEveryRecordIsListed) {
  for (const auto& [name, bytes] : streams().list) {
    SCOPED_TRACE(name);
    auto index = read_stream_index(bytes);
    ASSERT_TRUE(index);
    auto table = build_record_table(bytes);
    ASSERT_TRUE(table) << table.error().message;
    ASSERT_EQ(table->records.size(), index->records.size());
    EXPECT_EQ(table->total_bytes, bytes.size());
    uint64_t sum = table->prefix_bytes;
    size_t structure = 0, plane = 0;
    for (uint32_t r = 0; r < table->records.size(); ++r) {
      const RecordTableEntry& e = table->records[r];
      sum += e.bytes;
      EXPECT_EQ(e.bytes, index->records[r].size);
      EXPECT_EQ(e.kind == RecordKind::kBase, r == 0);
      for (size_t i = 0; i < e.needs.size(); ++i) {
        EXPECT_LT(e.needs[i], r) << "record " << r;
        if (i > 0) {
          EXPECT_LT(e.needs[i - 1], e.needs[i]);
        }
      }
      // Every record beyond the base builds on something.
      if (r > 0) {
        EXPECT_FALSE(e.needs.empty()) << "record " << r;
      }
      structure += e.kind == RecordKind::kStructure;
      plane += e.kind == RecordKind::kPlane;
      if (e.kind == RecordKind::kStructure) {
        EXPECT_GE(e.layer, 1u);
        EXPECT_GE(e.error, 0.f);
      }
    }
    EXPECT_EQ(sum, bytes.size());
    EXPECT_GT(structure, 3u);
    EXPECT_GT(plane, 0u);
  }
}

TEST(RecordTable, SpheresAndConesHoldWhatEachRecordChanged) {
  // An independent decode, record by record: the mesh after record r.
  for (const auto& [name, bytes] : streams().list) {
    SCOPED_TRACE(name);
    auto table = build_record_table(bytes);
    ASSERT_TRUE(table);
    auto index = read_stream_index(bytes);
    ASSERT_TRUE(index);
    IncrementalDecoder decoder;
    ASSERT_TRUE(decoder.feed(std::span(bytes).first(index->payload_offset)));
    for (uint32_t r = 0; r < index->records.size(); ++r) {
      const RecordEntry& rec = index->records[r];
      ASSERT_TRUE(decoder.feed(std::span(bytes).subspan(rec.offset, rec.size)));
      const RecordDelta& d = decoder.last_deltas().at(0);
      const Mesh& m = decoder.mesh();
      const RecordTableEntry& e = table->records[r];
      auto inside = [&](uint32_t v) {
        const double dist = length(to_double(m.positions[v]) - to_double(e.sphere.center));
        return dist <= double(e.sphere.radius) * (1 + 1e-5) + 1e-7;
      };
      std::set<uint32_t> changed(d.added_vertices.begin(), d.added_vertices.end());
      changed.insert(d.moved_vertices.begin(), d.moved_vertices.end());
      for (uint32_t f : d.touched_faces)
        for (uint32_t v : m.triangles[f]) changed.insert(v);
      for (uint32_t v : changed) ASSERT_TRUE(inside(v)) << "record " << r << " vertex " << v;
      if (e.kind == RecordKind::kStructure && e.cone.cos_half_angle > -1) {
        for (uint32_t f : d.touched_faces) {
          const Triangle& t = m.triangles[f];
          const Vec3d a = to_double(m.positions[t[0]]);
          const Vec3d n = cross(to_double(m.positions[t[1]]) - a, to_double(m.positions[t[2]]) - a);
          if (length(n) == 0) continue;
          EXPECT_GE(dot(to_double(e.cone.axis), n) / length(n), e.cone.cos_half_angle - 1e-5)
              << "record " << r << " face " << f;
        }
      }
    }
  }
}

// The set holding `seeds`, closed under needs, applied in a random order
// that respects the needs: each face write must find the slot as the
// decoder had it, and the faces must stay a manifold mesh.
struct Replay {
  std::map<uint32_t, Triangle> slots;
  std::string problem;
};

Replay replay(const RecordTable& table, const RecordTrace& trace, std::vector<uint32_t> set,
              std::mt19937& rng) {
  Replay out;
  std::set<uint32_t> pending(set.begin(), set.end()), done;
  while (!pending.empty() && out.problem.empty()) {
    std::vector<uint32_t> ready;
    for (uint32_t r : pending) {
      bool ok = true;
      for (uint32_t need : table.records[r].needs) ok = ok && done.count(need);
      if (ok) ready.push_back(r);
    }
    if (ready.empty()) {
      out.problem = "no record is ready: the set is not closed";
      break;
    }
    const uint32_t r = ready[rng() % ready.size()];
    for (const FaceWrite& w : trace.writes[r]) {
      auto at = out.slots.find(w.slot);
      if (w.appended ? at != out.slots.end() : (at == out.slots.end() || at->second != w.before)) {
        out.problem = "record " + std::to_string(r) + " finds slot " + std::to_string(w.slot) +
                      " not as the decoder had it";
        break;
      }
      out.slots[w.slot] = w.after;
    }
    pending.erase(r);
    done.insert(r);
  }
  if (!out.problem.empty()) return out;
  // Manifold: a directed edge at most once, an edge in at most two faces.
  std::set<std::pair<uint32_t, uint32_t>> directed;
  for (const auto& [slot, t] : out.slots) {
    for (int i = 0; i < 3; ++i) {
      if (t[i] == t[(i + 1) % 3]) out.problem = "a degenerate face";
      if (!directed.insert({t[i], t[(i + 1) % 3]}).second)
        out.problem = "directed edge twice: not manifold";
    }
  }
  return out;
}

TEST(RecordTable, ClosedSetsReplayToManifoldMeshesInAnyValidOrder) {
  std::mt19937 rng(17);
  for (const auto& [name, bytes] : streams().list) {
    SCOPED_TRACE(name);
    RecordTrace trace;
    auto table = build_record_table(bytes, &trace);
    ASSERT_TRUE(table);
    const uint32_t n = static_cast<uint32_t>(table->records.size());
    // Random closed sets: the closure of a few random records.
    for (int trial = 0; trial < 12; ++trial) {
      std::vector<uint32_t> seeds;
      for (int i = 0; i < 1 + trial % 4; ++i) seeds.push_back(1 + rng() % (n - 1));
      const std::vector<uint32_t> set = needs_closure(*table, seeds);
      for (uint32_t s : seeds) EXPECT_TRUE(std::binary_search(set.begin(), set.end(), s));
      for (uint32_t r : set)
        for (uint32_t need : table->records[r].needs)
          ASSERT_TRUE(std::binary_search(set.begin(), set.end(), need));
      Replay got = replay(*table, trace, set, rng);
      EXPECT_TRUE(got.problem.empty()) << got.problem;
    }
    // Every record, in random valid orders: exactly the decoder's faces.
    std::vector<uint32_t> all(n);
    for (uint32_t r = 0; r < n; ++r) all[r] = r;
    for (int trial = 0; trial < 3; ++trial) {
      Replay got = replay(*table, trace, all, rng);
      ASSERT_TRUE(got.problem.empty()) << got.problem;
      ASSERT_EQ(got.slots.size(), trace.faces.size());
      for (const auto& [slot, t] : got.slots) ASSERT_EQ(t, trace.faces[slot]) << "slot " << slot;
    }
    auto decoded = decode_hcs(bytes);
    ASSERT_TRUE(decoded);
    EXPECT_EQ(decoded->triangles, trace.faces);
    EXPECT_EQ(decoded->positions, trace.positions);
  }
}

TEST(RecordTable, SlotNeedsAreNecessary) {
  // Applying a record before the writer of a slot it rewrites is caught
  // (the replay above can fail): every slot need matters.
  std::mt19937 rng(3);
  const auto& [name, bytes] = streams().list.front();
  RecordTrace trace;
  auto table = build_record_table(bytes, &trace);
  ASSERT_TRUE(table);
  int checked = 0;
  for (uint32_t r = 1; r < table->records.size() && checked < 20; ++r) {
    for (const FaceWrite& w : trace.writes[r]) {
      if (w.appended) continue;
      // The slot's writer before r, dropped from r's needs.
      RecordTable cut = *table;
      uint32_t writer = 0;
      for (uint32_t q = r; q-- > 0;) {
        bool wrote = false;
        for (const FaceWrite& x : trace.writes[q]) wrote = wrote || x.slot == w.slot;
        if (wrote) {
          writer = q;
          break;
        }
      }
      if (writer == 0) continue;
      ASSERT_TRUE(std::binary_search(table->records[r].needs.begin(), table->records[r].needs.end(),
                                     writer));
      // r and its closure without `writer`'s: r cannot find its slot.
      std::vector<uint32_t> seeds;
      for (uint32_t need : table->records[r].needs)
        if (need != writer) seeds.push_back(need);
      std::vector<uint32_t> set = needs_closure(*table, seeds);
      if (std::binary_search(set.begin(), set.end(), writer)) continue;  // reached another way
      cut.records[r].needs = seeds;
      set.push_back(r);
      Replay got = replay(cut, trace, set, rng);
      EXPECT_FALSE(got.problem.empty()) << "record " << r << " without " << writer;
      ++checked;
      break;
    }
  }
  EXPECT_GT(checked, 0);
}

TEST(RecordTable, RefusesAStreamThatIsNotWhole) {
  const auto& bytes = streams().list.front().second;
  auto cut = build_record_table(std::span(bytes).first(bytes.size() - 10));
  ASSERT_FALSE(cut);
  EXPECT_EQ(cut.error().code, ErrorCode::kTruncated);
  std::vector<uint8_t> damaged = bytes;
  damaged[damaged.size() - 20] ^= 0x40;
  EXPECT_FALSE(build_record_table(damaged));
}

TEST(RecordTable, BoundingSphereHoldsItsPoints) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-3, 3);
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<Vec3f> points(1 + trial * 3);
    for (Vec3f& p : points) p = {u(rng), u(rng) * 0.1f, u(rng)};
    const BoundingSphere s = bounding_sphere(points);
    double diameter = 0;
    for (const Vec3f& p : points) {
      EXPECT_LE(length(to_double(p) - to_double(s.center)), s.radius);
      for (const Vec3f& q : points) diameter = std::max(diameter, length(to_double(p - q)));
    }
    // Ritter's sphere is within about 1.2x of the smallest (>= half the diameter).
    EXPECT_LE(s.radius, 0.6 * diameter * 1.2 + 1e-6);
  }
}

}  // namespace
}  // namespace meshstream

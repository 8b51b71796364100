// The client library in-process: the decoder hand-over (latest wins, the
// pipeline's mirror copies only what changed, the snapshot barrier), the
// display builder's two ASA paths, address parsing, the rate meter and the
// per-record reports.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <thread>

#include "client/connection.h"
#include "client/decoded_stream.h"
#include "client/display_builder.h"
#include "client/frame_mesh_pool.h"
#include "client/stream_client.h"
#include "common/asa/view.h"
#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "common/mesh/procedural.h"
#include "tests/asa/asa_test_support.h"

namespace meshstream::client {
namespace {

std::vector<uint8_t> demo_stream() {
  static const std::vector<uint8_t> bytes = [] {
    auto encoded = encode_hcs(make_demo_mesh(6000));
    return encoded ? *encoded : std::vector<uint8_t>{};
  }();
  return bytes;
}

bool same_mesh(const Mesh& a, const Mesh& b) {
  return a.triangles == b.triangles && a.positions.size() == b.positions.size() &&
         std::memcmp(a.positions.data(), b.positions.data(), sizeof(Vec3f) * a.positions.size()) ==
             0;
}

// The decoded mesh of the stream's first `bytes` bytes (a record boundary).
Mesh decode_prefix(const std::vector<uint8_t>& stream, uint64_t bytes) {
  auto m = decode_hcs(std::span<const uint8_t>(stream.data(), bytes));
  return m ? *m : Mesh{};
}

TEST(DecodedStream, UpdatesNotTakenAreMergedIntoOneTake) {
  const auto stream = demo_stream();
  ASSERT_FALSE(stream.empty());
  DecodedStream decoded;
  for (size_t at = 0; at < stream.size(); at += 100) {
    const size_t n = std::min<size_t>(100, stream.size() - at);
    ASSERT_TRUE(decoded.feed(std::span<const uint8_t>(stream.data() + at, n)));
  }
  ASSERT_TRUE(decoded.has_pending());
  Mesh mirror;
  MeshChanges changes;
  const TakenUpdate u = decoded.take(mirror, changes);
  EXPECT_EQ(u.updates, decoded.records_decoded());
  EXPECT_GT(u.updates, 5u);
  EXPECT_EQ(u.bytes_decoded, stream.size());
  EXPECT_TRUE(changes.full);  // the base mesh is among them
  EXPECT_TRUE(same_mesh(mirror, decode_prefix(stream, stream.size())));
  EXPECT_FALSE(decoded.has_pending());
}

TEST(DecodedStream, MirrorCopiesOnlyChangesAndStaysEqualToTheDecoder) {
  // Large enough that a late record touches a small part of the mesh.
  auto encoded = encode_hcs(make_demo_mesh(40000));
  ASSERT_TRUE(encoded);
  const std::vector<uint8_t>& stream = *encoded;
  DecodedStream decoded;
  Mesh mirror;
  uint32_t takes = 0, partial = 0;
  for (size_t at = 0; at < stream.size(); at += 1500) {
    const size_t n = std::min<size_t>(1500, stream.size() - at);
    ASSERT_TRUE(decoded.feed(std::span<const uint8_t>(stream.data() + at, n)));
    if (!decoded.has_pending()) continue;
    MeshChanges changes;
    const TakenUpdate u = decoded.take(mirror, changes);
    ++takes;
    if (!changes.full) {
      std::vector<uint32_t> unique = changes.faces;
      std::sort(unique.begin(), unique.end());
      unique.erase(std::unique(unique.begin(), unique.end()), unique.end());
      partial += unique.size() < mirror.triangles.size() / 2;
    }
    ASSERT_TRUE(same_mesh(mirror, decode_prefix(stream, u.bytes_decoded)))
        << "after " << u.records_decoded;
  }
  EXPECT_GT(takes, 3u);
  EXPECT_GT(partial, 1u) << "no take copied only a part of the mesh";
}

// The pipeline's take: meshes of a FrameMeshPool instead of a mirror. Each
// equals the decoder's mesh at that take, frames still held keep what they
// showed, and once a mesh is free again it is updated by the changes alone.
TEST(DecodedStream, PoolTakeGivesTheDecodedMeshAndKeepsHeldFramesIntact) {
  auto encoded = encode_hcs(make_demo_mesh(40000));
  ASSERT_TRUE(encoded);
  const std::vector<uint8_t>& stream = *encoded;
  DecodedStream decoded;
  FrameMeshPool pool;
  std::vector<std::pair<std::shared_ptr<const Mesh>, Mesh>> held;  // the last two frames
  uint32_t takes = 0;
  for (size_t at = 0; at < stream.size(); at += 1500) {
    const size_t n = std::min<size_t>(1500, stream.size() - at);
    ASSERT_TRUE(decoded.feed(std::span<const uint8_t>(stream.data() + at, n)));
    if (!decoded.has_pending()) continue;
    std::shared_ptr<const Mesh> mesh;
    MeshChanges changes;
    const TakenUpdate u = decoded.take(pool, mesh, changes);
    ++takes;
    ASSERT_TRUE(mesh);
    ASSERT_TRUE(same_mesh(*mesh, decode_prefix(stream, u.bytes_decoded)))
        << "after " << u.records_decoded;
    held.emplace_back(mesh, *mesh);
    if (held.size() > 2) held.erase(held.begin());
    for (const auto& [frame, shown] : held) ASSERT_TRUE(same_mesh(*frame, shown));
  }
  EXPECT_GT(takes, 5u);
  EXPECT_EQ(pool.stats().whole_copies + pool.stats().updates, takes);
  EXPECT_GT(pool.stats().updates, takes / 2) << "free meshes were copied whole";
}

TEST(DecodedStream, BarrierHoldsTheNetworkSideUntilThatRecordIsTaken) {
  const auto stream = demo_stream();
  DecodedStream decoded;
  decoded.set_barrier(2);  // record 2 must be shown as is
  // A feed applies every record it completes, so the pieces must be
  // shorter than any record (4 bytes: every record has a payload byte and a
  // 4-byte CRC trailer) for record 2 to complete alone whatever the layout.
  std::thread network([&] {
    for (size_t at = 0; at < stream.size(); at += 4) {
      const size_t n = std::min<size_t>(4, stream.size() - at);
      if (!decoded.feed(std::span<const uint8_t>(stream.data() + at, n))) return;
    }
  });
  Mesh mirror;
  std::vector<uint32_t> seen;
  while (seen.empty() || seen.back() < 3) {
    decoded.wait(0, true, std::chrono::milliseconds(50));
    if (!decoded.has_pending()) continue;
    MeshChanges changes;
    seen.push_back(decoded.take(mirror, changes).records_decoded);
    if (seen.size() > 1000) break;
  }
  network.join();
  EXPECT_NE(std::find(seen.begin(), seen.end(), 3u), seen.end())
      << "record 2 was never taken alone";
}

TEST(DisplayBuilder, IncrementalAndFullPathsGiveTheSameDisplayMesh) {
  const auto stream = demo_stream();
  IncrementalDecoder decoder;
  DisplayBuilder full, incremental;
  full.set_path(AsaPath::kFull);
  incremental.set_path(AsaPath::kIncremental);
  AsaOptions options;
  options.levels = 2;
  options.flatness = 0.8f;
  uint32_t region_updates = 0, updates = 0;
  for (size_t at = 0; at < stream.size(); at += 700) {
    const size_t n = std::min<size_t>(700, stream.size() - at);
    auto applied = decoder.feed(std::span<const uint8_t>(stream.data() + at, n));
    ASSERT_TRUE(applied);
    if (*applied == 0) continue;
    auto mesh = std::make_shared<const Mesh>(decoder.mesh());
    BuildReport rf, ri;
    auto a = full.build(mesh, {}, true, options, updates == 0, rf);
    auto b = incremental.build(mesh, {}, true, options, updates == 0, ri);
    ASSERT_TRUE(a && b);
    ++updates;
    region_updates += ri.incremental;
    EXPECT_FALSE(rf.incremental);
    ASSERT_EQ(a->mesh->face_count(), b->mesh->face_count());
    // The same faces (corner positions bit for bit, kinds); the incremental
    // path's in its own order, with unused vertex slots.
    ASSERT_TRUE(asa_test::face_set(*a->mesh, a->face_kind.get()) ==
                asa_test::face_set(*b->mesh, b->face_kind.get()))
        << "update " << updates;
  }
  EXPECT_GT(updates, 4u);
  EXPECT_GT(region_updates, 0u);
}

TEST(DisplayBuilder, WithoutAsaTheDisplayIsTheDecodedMesh) {
  auto mesh = std::make_shared<const Mesh>(make_icosphere(2));
  DisplayBuilder builder;
  BuildReport report;
  auto off = builder.build(mesh, {}, false, AsaOptions{}, true, report);
  ASSERT_TRUE(off);
  EXPECT_EQ(off->mesh.get(), mesh.get());
  AsaOptions zero;
  zero.levels = 0;
  auto none = builder.build(mesh, {}, true, zero, true, report);
  ASSERT_TRUE(none);
  EXPECT_EQ(none->mesh.get(), mesh.get());
  AsaOptions curved;
  curved.flatness = 0.999f;  // the icosphere's faces bend by about 15 degrees
  auto on = builder.build(mesh, {}, true, curved, true, report);
  ASSERT_TRUE(on);
  EXPECT_GT(on->mesh->face_count(), mesh->face_count());
}

// Camera moves as the viewer drives them (a new camera, no mesh change),
// while frames hold earlier displays for a while: each display has the
// faces of a full run at its camera, and a display a frame holds is never
// written into (the builder patches a free pooled copy only).
TEST(DisplayBuilder, CameraMovesPatchFreeCopiesAndLeaveHeldDisplaysAlone) {
  auto mesh = std::make_shared<const Mesh>(make_demo_mesh(40000));
  const AsaCamera fit = fit_camera(*mesh, 160, 120);
  AsaOptions options;
  options.view.enabled = true;
  options.view.camera = fit;
  options.view.facing_sign = facing_sign_of(*mesh);
  DisplayBuilder builder;
  builder.set_changes_exact(true);
  MeshChanges none;
  BuildReport report;
  ASSERT_TRUE(builder.build(mesh, none, true, options, true, report));
  struct Held {
    DisplayMesh display;
    std::vector<Triangle> triangles;  // as handed out
    std::vector<Vec3f> positions;
    int until = 0;
  };
  std::vector<Held> held;
  const Vec3f offset = fit.eye - fit.target;
  int incremental = 0;
  for (int step = 1; step <= 24; ++step) {
    const float a = 0.05f * static_cast<float>(step);
    options.view.camera.eye =
        fit.target + Vec3f{offset.x * std::cos(a) - offset.z * std::sin(a), offset.y,
                           offset.x * std::sin(a) + offset.z * std::cos(a)} *
                         (step % 5 == 0 ? 0.6f : 1.0f);
    auto display = builder.build(mesh, none, true, options, false, report);
    ASSERT_TRUE(display);
    incremental += report.incremental;
    auto full = subdivide(*mesh, options);
    ASSERT_TRUE(full);
    ASSERT_TRUE(asa_test::face_set(*display->mesh, display->face_kind.get()) ==
                asa_test::face_set(full->mesh, &full->face_kind))
        << "step " << step;
    // The unused vertex slots it reports (events count the others) are
    // those of the display: the rest are as many as a full run's.
    EXPECT_EQ(display->mesh->vertex_count() - report.unused_vertices, full->mesh.vertex_count())
        << "step " << step;
    for (const Held& h : held) {
      ASSERT_TRUE(h.display.mesh->triangles == h.triangles) << "a held display was written";
      ASSERT_TRUE(h.display.mesh->positions == h.positions) << "a held display was written";
    }
    std::erase_if(held, [&](const Held& h) { return h.until <= step; });
    // Frames hold a display for one to four steps.
    held.push_back(
        {*display, display->mesh->triangles, display->mesh->positions, step + 1 + step % 4});
  }
  EXPECT_GT(incremental, 12);
}

TEST(ParseHostPort, AcceptsHostPortAndRefusesTheRest) {
  auto a = parse_host_port("127.0.0.1:7878");
  ASSERT_TRUE(a);
  EXPECT_EQ(a->host, "127.0.0.1");
  EXPECT_EQ(a->port, 7878);
  auto b = parse_host_port("[::1]:9");
  ASSERT_TRUE(b);
  EXPECT_EQ(b->host, "::1");
  EXPECT_EQ(b->port, 9);
  for (const char* bad :
       {"127.0.0.1", ":7878", "host:", "host:0", "host:65536", "host:12x", "host:-1"}) {
    EXPECT_FALSE(parse_host_port(bad)) << bad;
  }
  // Each mistake gets its own reason: malformed, or a number out of range.
  auto reason = [](const char* text) { return parse_host_port(text).error().message; };
  EXPECT_NE(reason("127.0.0.1").find("no ':' before a port"), std::string::npos);
  EXPECT_NE(reason("host:").find("no port after"), std::string::npos);
  EXPECT_NE(reason(":7878").find("no host"), std::string::npos);
  EXPECT_NE(reason("host:12x").find("'12x' is not a number"), std::string::npos);
  for (const char* out_of_range :
       {"host:0", "host:65536", "host:-1", "host:99999999999999999999"}) {
    EXPECT_NE(reason(out_of_range).find("is out of range: a port is 1 to 65535"), std::string::npos)
        << reason(out_of_range);
    EXPECT_EQ(reason(out_of_range).find("not HOST:PORT"), std::string::npos) << out_of_range;
  }
}

// The rate is bytes over the time since the first byte (whose own bytes
// only start the clock), then over the last window: exact on a steady
// link from the start, and it falls during a pause.
TEST(RateMeter, ShowsTheTrueRateFromTheFirstByteAndFollowsAPause) {
  using namespace std::chrono;
  RateMeter meter(seconds(3));
  const auto t0 = steady_clock::now();
  EXPECT_EQ(meter.bytes_per_s(t0), 0);
  meter.add(5000, t0);  // the first read: starts the clock
  EXPECT_EQ(meter.bytes_per_s(t0), 0);
  for (int i = 1; i <= 50; ++i) {
    const auto t = t0 + milliseconds(100 * i);
    meter.add(2000, t);  // 20 kB/s
    EXPECT_NEAR(meter.bytes_per_s(t), 20000.0, 1e-6) << "after " << i * 100 << " ms";
  }
  // Nothing for 1.5 s: half the window is silent.
  EXPECT_NEAR(meter.bytes_per_s(t0 + milliseconds(6500)), 10000.0, 700.0);
  EXPECT_EQ(meter.bytes_per_s(t0 + seconds(9)), 0);
}

// One AppliedRecord per record, in order, with the index's counts and the
// bytes up to its end; the barriers set by set_barriers all hold.
TEST(DecodedStream, ReportsEveryRecordAndHoldsEveryBarrier) {
  const auto stream = demo_stream();
  DecodedStream decoded;
  std::vector<AppliedRecord> reported;
  decoded.on_record([&](const AppliedRecord& r) { reported.push_back(r); });
  decoded.set_barriers({5, 1, 9});
  std::thread network([&] {
    for (size_t at = 0; at < stream.size(); at += 4) {
      const size_t n = std::min<size_t>(4, stream.size() - at);
      if (!decoded.feed(std::span<const uint8_t>(stream.data() + at, n))) return;
    }
  });
  Mesh mirror;
  std::vector<uint32_t> seen;
  while (seen.empty() || seen.back() < decoded.records_decoded() || seen.back() < 10) {
    decoded.wait(0, true, std::chrono::milliseconds(50));
    if (!decoded.has_pending()) continue;
    MeshChanges changes;
    seen.push_back(decoded.take(mirror, changes).records_decoded);
    if (seen.size() > 5000) break;
  }
  network.join();
  for (uint32_t held : {2u, 6u, 10u}) {
    EXPECT_NE(std::find(seen.begin(), seen.end(), held), seen.end()) << held;
  }
  ASSERT_EQ(reported.size(), decoded.records_decoded());
  uint64_t end = 0;
  for (size_t i = 0; i < reported.size(); ++i) {
    EXPECT_EQ(reported[i].index, i);
    EXPECT_GT(reported[i].end_offset, end);
    EXPECT_EQ(reported[i].end_offset, end + reported[i].bytes);
    end = reported[i].end_offset;
    const Mesh at = decode_prefix(stream, reported[i].end_offset);
    if (i % 7 == 0 || i + 1 == reported.size()) {
      EXPECT_EQ(reported[i].vertices, at.vertex_count()) << i;
      EXPECT_EQ(reported[i].faces, at.face_count()) << i;
    }
  }
  EXPECT_EQ(end, stream.size());
}

}  // namespace
}  // namespace meshstream::client

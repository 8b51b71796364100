// The client library in-process: the decoder hand-over (latest wins, the
// pipeline's mirror copies only what changed, the snapshot barrier), the
// display builder's two ASA paths, and address parsing.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <thread>

#include "client/connection.h"
#include "client/decoded_stream.h"
#include "client/display_builder.h"
#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "common/mesh/procedural.h"

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
    ASSERT_EQ(a->mesh->vertex_count(), b->mesh->vertex_count());
    // Face for face, the same corner positions.
    for (uint32_t f = 0; f < a->mesh->face_count(); ++f) {
      for (int i = 0; i < 3; ++i) {
        ASSERT_EQ(std::memcmp(&a->mesh->positions[a->mesh->triangles[f][i]],
                              &b->mesh->positions[b->mesh->triangles[f][i]], sizeof(Vec3f)),
                  0)
            << "update " << updates << " face " << f;
      }
    }
    EXPECT_EQ(*a->face_kind, *b->face_kind);
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
}

}  // namespace
}  // namespace meshstream::client

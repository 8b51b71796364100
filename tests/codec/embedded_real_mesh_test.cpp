// The embedded stream on real meshes (skipped when ../shared/meshes is absent): the
// distance to the original along the record boundaries, the granularity
// bounds, the encoder's model at every prefix and the decoder controls.
// The distances run on every distinct real model; the other checks on a subset (time).
#include <gtest/gtest.h>

#include <algorithm>

#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "common/codec/rd_measure.h"
#include "common/mesh/import.h"
#include "tests/test_meshes.h"

namespace meshstream {
namespace {

struct Encoded {
  Mesh mesh;
  std::vector<uint8_t> bytes;
  StreamIndex index;
  EncodeReport report;
};

Encoded encode_real(const std::string& name) {
  Encoded e;
  auto imported = import_mesh(testing::test_mesh(name));
  EXPECT_TRUE(imported) << imported.error().message;
  if (!imported) return e;
  e.mesh = imported->mesh;
  auto bytes = encode_hcs(e.mesh, EncodeOptions{}, &e.report);
  EXPECT_TRUE(bytes) << bytes.error().message;
  if (!bytes) return e;
  e.bytes = std::move(*bytes);
  auto index = read_stream_index(e.bytes);
  EXPECT_TRUE(index);
  if (index) e.index = *index;
  return e;
}

uint64_t end_of(const StreamIndex& index, size_t i) {
  return index.records[i].offset + index.records[i].size;
}

class EmbeddedRealMesh : public ::testing::TestWithParam<const char*> {};
class EmbeddedRealMeshDistance : public ::testing::TestWithParam<const char*> {};

// Distance to the original after every record, on every distinct real model: the
// symmetric RMS as the encoder measures it (RdMeasure::relative_rms, 8000
// samples): fixed area samples on the original and fixed per-triangle
// quadrature points on the decoded prefix (surface_quadrature.h). Plain area sampling of the prefix
// moves every sample when one triangle changes; on CAD parts its RMS then jumps by 10-20 % between
// records that barely differ (crank.off, 8000 samples), which would hide or fake rises. With the
// quadrature a record's effect is measured, not the sampler's.
//
// A plane record only sharpens positions: at most 2 % above the previous
// RMS (a plane step can move a vertex whose true position was near the old
// interval's middle a little away; mask.off: +1.15 % once). A structure
// record may raise it more: the layered decimation's intermediate meshes
// are not nested, and on CAD
// creases a restored vertex's star can leave part of the original farther
// away than the fan it replaces (fandisk.off: +7.7 % over the best so far;
// every other model <= 0.2 %). Bound: 10 % over the best RMS seen so far.
// The worst rises are printed.
TEST_P(EmbeddedRealMeshDistance, RmsNeverRisesAlongRecordBoundaries) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  if (std::string(GetParam()) != "fandisk.off" && std::string(GetParam()) != "casting.off") {
    GTEST_SKIP()
        << "sanitizer build: distances after every record on the two small CAD parts only (time)";
  }
#endif
  const Encoded e = encode_real(GetParam());
  ASSERT_FALSE(e.bytes.empty());
  auto reference = quantized_reference(e.mesh, 12);
  ASSERT_TRUE(reference);
  RdMeasureOptions options;
  options.samples = 8000;
  auto measure = RdMeasure::prepare(*reference, options);
  ASSERT_TRUE(measure);
  IncrementalDecoder dec;
  uint64_t fed = 0;
  double previous = 0, best = 0, worst_plane = 0, worst_structure = 0;
  for (size_t i = 0; i < e.index.records.size(); ++i) {
    const uint64_t end = end_of(e.index, i);
    ASSERT_TRUE(dec.feed(std::span<const uint8_t>(e.bytes.data() + fed, end - fed)));
    fed = end;
    const double rms = measure->relative_rms(dec.mesh());
    if (i > 0) {
      const bool plane = e.report.records[i].plane;
      if (plane) {
        worst_plane = std::max(worst_plane, rms / previous - 1);
        EXPECT_LE(rms, previous * 1.02 + 1e-9)
            << "plane record " << i << " of " << e.index.records.size();
      } else {
        worst_structure = std::max(worst_structure, rms / best - 1);
      }
      EXPECT_LE(rms, best * 1.10 + 1e-9) << "record " << i << " of " << e.index.records.size();
    }
    previous = rms;
    best = i == 0 ? rms : std::min(best, rms);
  }
  EXPECT_LT(previous, 1e-5);  // the full stream: the quantized original itself
  std::printf(
      "%s: %zu records, worst RMS rise: plane records %.2f %% over the previous, structure records "
      "%.2f %% over the best so far\n",
      GetParam(), e.index.records.size(), 100 * worst_plane, 100 * worst_structure);
}

// At least min(n / 50, 200) record boundaries and no refinement record above
// 2 % of the stream; the decoder's mesh equals the encoder's model after every
// record; the full stream is exact.
TEST_P(EmbeddedRealMesh, GranularModelMatchingExactStream) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  const Encoded e = encode_real(GetParam());
  ASSERT_FALSE(e.bytes.empty());
  const uint32_t n = e.mesh.vertex_count();
  EXPECT_GE(e.index.records.size(), std::min<size_t>(n / 50, 200) + 1);
  for (size_t i = 1; i < e.index.records.size(); ++i)
    EXPECT_LE(e.index.records[i].size, 0.02 * e.bytes.size()) << "record " << i;
  ASSERT_EQ(e.report.records.size(), e.index.records.size());
  IncrementalDecoder dec;
  uint64_t fed = 0;
  for (size_t i = 0; i < e.index.records.size(); ++i) {
    const uint64_t end = end_of(e.index, i);
    ASSERT_TRUE(dec.feed(std::span<const uint8_t>(e.bytes.data() + fed, end - fed)));
    fed = end;
    ASSERT_EQ(position_hash(dec.mesh().positions), e.report.records[i].position_hash)
        << "record " << i;
  }
  auto reference = quantized_reference(e.mesh, 12);
  ASSERT_TRUE(reference);
  std::vector<Vec3f> got = dec.mesh().positions, want = reference->positions;
  auto less = [](Vec3f a, Vec3f b) { return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z); };
  std::sort(got.begin(), got.end(), less);
  std::sort(want.begin(), want.end(), less);
  EXPECT_TRUE(got == want);
}

// Points, percent of points, ratio and bytes select the largest record
// boundary within the budget, and decoding that prefix gives the index's
// counts there.
TEST_P(EmbeddedRealMesh, BudgetsSelectTheLargestBoundaryWithin) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  const Encoded e = encode_real(GetParam());
  ASSERT_FALSE(e.bytes.empty());
  const StreamIndex& index = e.index;
  const uint64_t total = e.bytes.size();
  using K = DecodeBudget::Kind;
  auto brute = [&](auto fits) {
    uint64_t best = end_of(index, 0);
    for (size_t i = 0; i < index.records.size(); ++i)
      if (fits(i)) best = end_of(index, i);
    return best;
  };
  for (double ratio : {2.0, 5.0, 20.0, 100.0}) {
    const uint64_t got = prefix_for_budget(index, {K::kRatio, ratio});
    EXPECT_EQ(got,
              brute([&](size_t i) { return double(end_of(index, i)) <= total / ratio + 1e-9; }));
    EXPECT_LE(got, std::max<double>(end_of(index, 0), total / ratio));
  }
  for (double fraction : {0.01, 0.1, 0.5}) {
    const double bytes = fraction * total;
    EXPECT_EQ(prefix_for_budget(index, {K::kBytes, bytes}),
              brute([&](size_t i) { return double(end_of(index, i)) <= bytes; }));
    const double points = fraction * e.mesh.vertex_count();
    EXPECT_EQ(prefix_for_budget(index, {K::kVertices, points}),
              brute([&](size_t i) { return index.records[i].vertices <= points; }));
    EXPECT_EQ(prefix_for_budget(index, {K::kPercentVertices, 100 * fraction}),
              brute([&](size_t i) { return index.records[i].vertices <= points + 1e-9; }));
    // The selected prefix decodes to the index's counts at that boundary.
    const uint64_t prefix = prefix_for_budget(index, {K::kBytes, bytes});
    auto mesh = decode_hcs(std::span<const uint8_t>(e.bytes.data(), prefix));
    ASSERT_TRUE(mesh);
    size_t record = 0;
    while (end_of(index, record) != prefix) ++record;
    EXPECT_EQ(mesh->vertex_count(), index.records[record].vertices);
  }
}

std::string test_name(const ::testing::TestParamInfo<const char*>& info) {
  std::string name = info.param;
  for (char& c : name)
    if (!isalnum(static_cast<unsigned char>(c))) c = '_';
  return name;
}

INSTANTIATE_TEST_SUITE_P(Shared, EmbeddedRealMesh,
                         ::testing::Values("fandisk.off", "casting.off", "hemisphere.off",
                                           "bunny.off"),
                         test_name);
// Distances after every record: every distinct real model of the manifest.
// Three are left out for CI's time (they were 103 of its 320 CPU seconds):
// bunny.stl is bun_zipper.ply's surface again (the same scan as an unwelded
// STL), bunny.off is it with its five holes filled (bun_zipper keeps the
// boundaries, the harder case), and dragon_res2.ply is the dragon that
// dragon_res3.ply measures at a quarter of the vertices, with non-manifold
// edges and duplicate faces of its own.
INSTANTIATE_TEST_SUITE_P(Shared, EmbeddedRealMeshDistance,
                         ::testing::Values("bun_zipper.ply", "armadillo.obj", "fandisk.off",
                                           "crank.off", "casting.off", "mask.off", "hemisphere.off",
                                           "skull.obj", "maneki-neko.off", "dragon_res3.ply"),
                         test_name);

}  // namespace
}  // namespace meshstream

// Issue II on real meshes (skipped when ../shared/meshes is absent): the
// distance to the original along the record boundaries, the granularity
// bounds, the encoder's model at every prefix and the decoder controls.
// A sensible subset (small meshes for the distances) keeps the suite fast.
#include <gtest/gtest.h>

#include <algorithm>

#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "common/mesh/import.h"
#include "common/metrics/distance.h"
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

uint64_t end_of(const StreamIndex& index, size_t i) { return index.records[i].offset + index.records[i].size; }

class EmbeddedRealMesh : public ::testing::TestWithParam<const char*> {};
class EmbeddedRealMeshDistance : public ::testing::TestWithParam<const char*> {};

// Distance to the original (symmetric RMS, 8000 area samples a side) after
// every record. A plane record only sharpens positions: it may not raise the
// RMS by more than 3 % (sampling noise: a vertex moving closer can still
// move a sampled point's nearest surface away). A structure record may raise
// it a little more: the layered decimation's intermediate triangulations are
// not nested, and on CAD creases a re-inserted vertex's new triangles can sit
// farther from some original points than the fan they replace; issue I's
// ordering (all positions exact) shows the same rises, up to 24 % on
// fandisk, so the bound is 25 % over the best RMS seen so far.
TEST_P(EmbeddedRealMeshDistance, RmsNeverRisesAlongRecordBoundaries) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  const Encoded e = encode_real(GetParam());
  ASSERT_FALSE(e.bytes.empty());
  DistanceOptions options;
  options.samples = 8000;
  options.threads = 1;
  auto original = PreparedSurface::prepare(e.mesh, options);
  ASSERT_TRUE(original);
  IncrementalDecoder dec;
  uint64_t fed = 0;
  double previous = 0, best = 0, worst_plane = 0, worst_structure = 0;
  for (size_t i = 0; i < e.index.records.size(); ++i) {
    const uint64_t end = end_of(e.index, i);
    ASSERT_TRUE(dec.feed(std::span<const uint8_t>(e.bytes.data() + fed, end - fed)));
    fed = end;
    auto shown = PreparedSurface::prepare(dec.mesh(), options);
    ASSERT_TRUE(shown);
    const double rms = surface_distance(*original, *shown).relative_rms();
    if (i > 0) {
      const bool plane = e.report.records[i].plane;
      const double rise = rms / previous - 1;
      (plane ? worst_plane : worst_structure) = std::max(plane ? worst_plane : worst_structure, rise);
      if (plane) {
        EXPECT_LE(rms, previous * 1.03 + 1e-7) << "plane record " << i << " of " << e.index.records.size();
      }
      EXPECT_LE(rms, best * 1.25 + 1e-7) << "record " << i << " of " << e.index.records.size();
    }
    previous = rms;
    best = i == 0 ? rms : std::min(best, rms);
  }
  EXPECT_LT(previous, 1e-4);
  std::printf("%s: %zu records, worst RMS rise: plane records %.1f %%, structure records %.1f %%\n", GetParam(),
              e.index.records.size(), 100 * worst_plane, 100 * worst_structure);
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
    ASSERT_EQ(position_hash(dec.mesh().positions), e.report.records[i].position_hash) << "record " << i;
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
    EXPECT_EQ(got, brute([&](size_t i) { return double(end_of(index, i)) <= total / ratio + 1e-9; }));
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
                         ::testing::Values("fandisk.off", "casting.off", "hemisphere.off", "bunny.off"), test_name);
// Distances after every record: the small meshes only (time).
INSTANTIATE_TEST_SUITE_P(Shared, EmbeddedRealMeshDistance,
                         ::testing::Values("fandisk.off", "casting.off", "hemisphere.off"), test_name);

}  // namespace
}  // namespace meshstream

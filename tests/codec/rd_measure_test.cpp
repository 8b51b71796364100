// The encoder's measured rate-distortion choice (rd_measure.h): the
// automatic stream is the best of the candidate balances by the measure, and
// the measure itself ranks streams the way their distances do.
#include "common/codec/rd_measure.h"

#include <gtest/gtest.h>

#include <optional>

#include "common/codec/encoder.h"
#include "common/mesh/procedural.h"

namespace meshstream {
namespace {

// The demo model and the measure of its quantized original, as the encoder
// prepares it.
class RdMeasureOnDemo : public ::testing::Test {
 protected:
  void SetUp() override {
    auto reference = quantized_reference(mesh, 12);
    ASSERT_TRUE(reference);
    auto prepared = RdMeasure::prepare(*reference);
    ASSERT_TRUE(prepared);
    measure = std::move(*prepared);
  }
  const Mesh mesh = make_demo_mesh(12000);
  std::optional<RdMeasure> measure;
};

TEST_F(RdMeasureOnDemo, AutomaticOrderingIsTheBestMeasuredCandidate) {
  EncodeOptions automatic;
  auto chosen = encode_hcs(mesh, automatic);
  ASSERT_TRUE(chosen);
  // Budgets relative to the first candidate's stream, as the encoder does.
  EncodeOptions first;
  first.plane_calibration = kOrderingCandidates[0].plane_calibration;
  first.distortion_estimate = kOrderingCandidates[0].distortion_estimate;
  auto default_stream = encode_hcs(mesh, first);
  ASSERT_TRUE(default_stream);
  const uint64_t reference_bytes = default_stream->size();
  auto chosen_curve = measure->curve(*chosen, reference_bytes);
  ASSERT_TRUE(chosen_curve);
  const double chosen_score = RdMeasure::score(*chosen_curve);
  bool equals_a_candidate = false;
  for (const RecordOrdering& candidate : kOrderingCandidates) {
    EncodeOptions fixed;
    fixed.plane_calibration = candidate.plane_calibration;
    fixed.distortion_estimate = candidate.distortion_estimate;
    auto stream = encode_hcs(mesh, fixed);
    ASSERT_TRUE(stream);
    auto curve = measure->curve(*stream, reference_bytes);
    ASSERT_TRUE(curve);
    EXPECT_LE(chosen_score, RdMeasure::score(*curve) + 1e-12)
        << "balance " << candidate.plane_calibration << ", estimate "
        << int(candidate.distortion_estimate);
    equals_a_candidate = equals_a_candidate || *stream == *chosen;
  }
  EXPECT_TRUE(equals_a_candidate);
}

// More of the stream is closer: the measured RMS falls along the budgets,
// and the prefixes grow.
TEST_F(RdMeasureOnDemo, CurveFallsAsTheBudgetGrows) {
  auto stream = encode_hcs(mesh, EncodeOptions{});
  ASSERT_TRUE(stream);
  auto curve = measure->curve(*stream, stream->size());
  ASSERT_TRUE(curve);
  ASSERT_EQ(curve->size(), RdMeasureOptions{}.budgets);
  for (size_t i = 1; i < curve->size(); ++i) {
    EXPECT_GE((*curve)[i].bytes, (*curve)[i - 1].bytes);
    EXPECT_GE((*curve)[i].vertices, (*curve)[i - 1].vertices);
    EXPECT_LE((*curve)[i].relative_rms, (*curve)[i - 1].relative_rms * 1.02) << "budget " << i;
  }
  EXPECT_LT(curve->back().relative_rms, curve->front().relative_rms);
}

// The encoder hands the measure a hierarchy built over other positions of
// the same triangles (grid units) and refitted: the curve is the same,
// number for number, as with the measure's own.
TEST_F(RdMeasureOnDemo, ARefittedHierarchyGivesTheSameCurve) {
  auto reference = quantized_reference(mesh, 12);
  ASSERT_TRUE(reference);
  Mesh elsewhere = *reference;
  for (Vec3f& p : elsewhere.positions) p = p * 4096.0f + Vec3f{7, -3, 11};
  TriangleBvh hierarchy = TriangleBvh::build(elsewhere, 2);
  ASSERT_TRUE(hierarchy.refit(*reference));
  auto given = RdMeasure::prepare(*reference, RdMeasureOptions{}, std::move(hierarchy));
  ASSERT_TRUE(given);
  EncodeOptions options;
  options.asa_guidance = false;
  auto stream = encode_hcs(mesh, options);
  ASSERT_TRUE(stream);
  auto own = measure->curve(*stream, stream->size());
  auto refitted = given->curve(*stream, stream->size());
  ASSERT_TRUE(own && refitted);
  ASSERT_EQ(own->size(), refitted->size());
  for (size_t i = 0; i < own->size(); ++i) {
    EXPECT_EQ((*own)[i].bytes, (*refitted)[i].bytes);
    EXPECT_EQ((*own)[i].relative_rms, (*refitted)[i].relative_rms) << "budget " << i;
  }
  // A hierarchy over another mesh is refused.
  TriangleBvh small = TriangleBvh::build(make_icosphere(1));
  auto wrong = RdMeasure::prepare(*reference, RdMeasureOptions{}, std::move(small));
  ASSERT_FALSE(wrong);
  EXPECT_EQ(wrong.error().code, ErrorCode::kInvalidArgument);
}

TEST(RdMeasure, GarbageStreamIsAnError) {
  auto measure = RdMeasure::prepare(make_icosphere(2));
  ASSERT_TRUE(measure);
  const std::vector<uint8_t> garbage(100, 0x5A);
  EXPECT_FALSE(measure->curve(garbage, garbage.size()));
  EXPECT_FALSE(RdMeasure::prepare(Mesh{}));
}

}  // namespace
}  // namespace meshstream

// The embedded stream. The decoder's mesh at every record boundary is the
// encoder's model bit for bit; plane records only move vertices; the
// granularity bounds hold; budgets pick the right boundary; the stream
// without bit planes stays available and exact.
#include <gtest/gtest.h>

#include <algorithm>

#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "tests/codec/codec_test_util.h"

namespace meshstream {
namespace {

using namespace meshstream::testing;

std::vector<Mesh> embedded_meshes() {
  return {icosphere(4, 0.2f), torus(40, 24), height_field(30, 24),
          combine({icosphere(3, 0.1f), tetrahedron(), height_field(8, 5)})};
}

TEST(EmbeddedStream, EveryPrefixEqualsTheEncoderModel) {
  int which = 0;
  for (const Mesh& mesh : embedded_meshes()) {
    ++which;
    // The automatic ordering, then each distortion estimate alone (a fixed
    // balance encodes once), with either base coder.
    for (DistortionEstimate estimate :
         {DistortionEstimate::kAutomatic, DistortionEstimate::kDisplacement,
          DistortionEstimate::kSurfaceDistance})
      for (bool draco : {true, false}) {
        SCOPED_TRACE("mesh " + std::to_string(which) + (draco ? ", Draco base" : ", own base") +
                     ", estimate " + std::to_string(int(estimate)));
        EncodeOptions options;
        options.allow_draco_base = draco;
        if (estimate != DistortionEstimate::kAutomatic) {
          options.plane_calibration = 1;
          options.distortion_estimate = estimate;
        }
        EncodeReport report;
        auto bytes = encode_hcs(mesh, options, &report);
        ASSERT_TRUE(bytes) << bytes.error().message;
        auto index = read_stream_index(*bytes);
        ASSERT_TRUE(index);
        ASSERT_EQ(report.records.size(), index->records.size());
        IncrementalDecoder dec;
        uint64_t fed = 0;
        size_t planes = 0, moving_planes = 0;
        std::vector<Vec3f> before;
        for (size_t i = 0; i < index->records.size(); ++i) {
          const uint64_t end = index->records[i].offset + index->records[i].size;
          auto r = dec.feed(std::span<const uint8_t>(bytes->data() + fed, end - fed));
          fed = end;
          ASSERT_TRUE(r) << "record " << i << ": " << r.error().message;
          ASSERT_EQ(dec.mesh().vertex_count(), report.records[i].vertices) << "record " << i;
          ASSERT_EQ(position_hash(dec.mesh().positions), report.records[i].position_hash)
              << "record " << i << (report.records[i].plane ? " (plane)" : " (structure)");
          if (report.records[i].plane) {
            ++planes;
            ASSERT_EQ(dec.last_deltas().size(), 1u);
            EXPECT_TRUE(dec.last_deltas()[0].added_vertices.empty());
            EXPECT_TRUE(dec.last_deltas()[0].touched_faces.empty());
            // Exactly the vertices whose positions changed are reported. A
            // plane record may move none: at shift 1 a vertex sits at the low
            // end of its interval, so a last plane of zero bits keeps it.
            std::vector<uint32_t> moved;
            for (uint32_t v = 0; v < before.size(); ++v)
              if (!(before[v] == dec.mesh().positions[v])) moved.push_back(v);
            std::vector<uint32_t> reported = dec.last_deltas()[0].moved_vertices;
            std::sort(reported.begin(), reported.end());
            EXPECT_EQ(reported, moved) << "record " << i;
            EXPECT_EQ(dec.last_deltas()[0].full_rebuild, !moved.empty());
            if (!moved.empty()) ++moving_planes;
          }
          before = dec.mesh().positions;
        }
        EXPECT_GT(moving_planes, 0u) << "an embedded stream refines positions in plane records";
        auto reference = quantized_reference(mesh, 12);
        ASSERT_TRUE(reference);
        EXPECT_EQ(sorted_positions(dec.mesh()), sorted_positions(*reference));
        EXPECT_EQ(canonical_faces(dec.mesh()), canonical_faces(*reference));
      }
  }
}

// The automatic ordering's candidates may run on threads: the stream (and
// the report) must not depend on it.
TEST(EmbeddedStream, CandidatesOnThreadsGiveTheSameStream) {
  for (const Mesh& mesh : embedded_meshes()) {
    EncodeOptions serial;
    serial.threads = 1;
    EncodeOptions threaded;
    threaded.threads = 0;
    EncodeReport serial_report, threaded_report;
    auto a = encode_hcs(mesh, serial, &serial_report);
    auto b = encode_hcs(mesh, threaded, &threaded_report);
    ASSERT_TRUE(a && b);
    EXPECT_EQ(*a, *b);
    ASSERT_EQ(serial_report.records.size(), threaded_report.records.size());
    for (size_t i = 0; i < serial_report.records.size(); ++i)
      EXPECT_EQ(serial_report.records[i].position_hash, threaded_report.records[i].position_hash)
          << i;
    EXPECT_EQ(serial_report.ordering.distortion_estimate,
              threaded_report.ordering.distortion_estimate);
  }
}

TEST(EmbeddedStream, UnknownDistortionEstimatesAreRefused) {
  for (int estimate : {-1, 3, 100}) {
    EncodeOptions options;
    options.distortion_estimate = static_cast<DistortionEstimate>(estimate);
    auto refused = encode_hcs(icosphere(2), options);
    ASSERT_FALSE(refused) << estimate;
    EXPECT_EQ(refused.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(refused.error().message.find("distortion estimate"), std::string::npos);
  }
}

// The base shift is automatic (quant bits - 8) unless given; a given one
// must be 0..kMaxBaseShift and stays below the quantization bits.
TEST(EmbeddedStream, BaseShiftIsAutomaticOrGiven) {
  const Mesh mesh = icosphere(2);
  auto shift_of = [&](std::optional<int> shift, int bits) -> int {
    EncodeOptions options;
    options.quant_bits = bits;
    options.base_shift = shift;
    options.plane_calibration = 1;
    EncodeReport report;
    auto bytes = encode_hcs(mesh, options, &report);
    if (!bytes) return -1;
    auto index = read_stream_index(*bytes);
    if (!index || index->header.extra.size() < 2) return -2;
    EXPECT_EQ(index->header.extra[1], report.base_shift);
    return index->header.extra[1];
  };
  EXPECT_EQ(shift_of(std::nullopt, 12), 4);
  EXPECT_EQ(shift_of(std::nullopt, 16), 8);
  EXPECT_EQ(shift_of(std::nullopt, 8), 0);
  EXPECT_EQ(shift_of(2, 12), 2);
  EXPECT_EQ(shift_of(0, 12), 0);
  EXPECT_EQ(shift_of(12, 10), 9);  // at most quant bits - 1
  for (int bad : {-1, kMaxBaseShift + 1}) {
    EncodeOptions options;
    options.base_shift = bad;
    auto refused = encode_hcs(mesh, options);
    ASSERT_FALSE(refused) << bad;
    EXPECT_EQ(refused.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(refused.error().message.find("base shift"), std::string::npos);
  }
}

}  // namespace
}  // namespace meshstream

// The encoder's ASA guidance (asa_guidance.h): choice bytes, the header
// block, what the encoder writes, and that damaged guidance is refused
// (never misapplied) while old streams read as "no guidance".
#include "common/codec/asa_guidance.h"

#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <string>

#include "common/codec/container_reseal.h"
#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "common/mesh/import.h"
#include "common/mesh/procedural.h"
#include "tests/codec/stream_samples.h"
#include "tests/test_meshes.h"

namespace meshstream {
namespace {

using testing::read_sample;

StreamHeader header_with(const AsaGuidance& g) {
  StreamHeader h;
  h.extra = {3, 4};
  append_asa_guidance(h.extra, g);
  return h;
}

TEST(AsaGuidance, EveryChoiceByteRoundTripsOrIsRefused) {
  int valid = 0, approximating = 0;
  for (int b = 0; b < 256; ++b) {
    const uint8_t byte = uint8_t(b);
    auto options = asa_choice_options(byte);
    if (!options) {
      EXPECT_EQ(options.error().code, ErrorCode::kCorrupt);
      continue;
    }
    ++valid;
    if (!*options) {
      EXPECT_EQ(byte, kAsaChoiceOff);
      continue;
    }
    EXPECT_GE((*options)->levels, 1);
    if (asa_choice_approximates(byte)) {
      // One Zorin level of the same flatness and crease, then the relaxation.
      ++approximating;
      EXPECT_EQ((*options)->levels, 1);
      EXPECT_EQ((*options)->rule, ButterflyRule::kZorin);
      const auto step = asa_choice_of(**options);
      ASSERT_TRUE(step) << b;
      EXPECT_EQ(approximating_choice(*step), std::optional<uint8_t>(byte)) << b;
      EXPECT_NE(asa_choice_label(byte).find("approximate"), std::string::npos);
      continue;
    }
    EXPECT_EQ(asa_choice_of(**options), std::optional<uint8_t>(byte)) << b;
  }
  // Off, and 3 levels x 4 flatness x 5 creases x 2 rules less the creases
  // below acos(t): 40 degrees is below acos(0.75) = 41.4; and the
  // approximating ones: 4 flatness x 5 creases, less the same one.
  EXPECT_EQ(approximating, 4 * 5 - 1);
  EXPECT_EQ(valid, 1 + 3 * (4 * 5 - 1) * 2 + approximating);
  EXPECT_FALSE(asa_choice_options(0x04));    // no levels, other bits set
  EXPECT_FALSE(asa_choice_options(0x51));    // crease index 5
  EXPECT_FALSE(asa_choice_options(0xd0));    // approximating, crease index 5
  EXPECT_FALSE(approximating_choice(0x02));  // two levels: no approximating form
  EXPECT_FALSE(approximating_choice(0x81));  // the projection rule: none either
  for (uint8_t c : AsaGuidanceOptions::default_candidates()) {
    auto o = asa_choice_options(c);
    ASSERT_TRUE(o && *o) << int(c);
  }
}

TEST(AsaGuidance, AnApproximatingChoiceRelaxesThePrefixThenSubdividesIt) {
  const Mesh prefix = make_icosphere(1);
  const uint8_t interpolating = *asa_choice_of(AsaOptions{});  // L1 t0.85
  const uint8_t approximating = *approximating_choice(interpolating);
  EXPECT_EQ(asa_choice_label(approximating), "L1 t0.85 approximate");
  Mesh relaxed = prefix;
  ASSERT_TRUE(relax_toward_smooth(relaxed, asa_choice_relax(AsaOptions{})));
  auto expected = subdivide(relaxed, AsaOptions{});
  ASSERT_TRUE(expected);
  std::vector<uint32_t> source;
  auto shown = apply_asa_choice(prefix, approximating, &source);
  ASSERT_TRUE(shown) << shown.error().message;
  EXPECT_EQ(shown->positions, expected->mesh.positions);
  EXPECT_EQ(shown->triangles, expected->mesh.triangles);
  EXPECT_EQ(source.size(), shown->face_count());
  auto plain = apply_asa_choice(prefix, interpolating);
  ASSERT_TRUE(plain);
  EXPECT_NE(plain->positions, shown->positions);
  auto off = apply_asa_choice(prefix, kAsaChoiceOff);
  ASSERT_TRUE(off);
  EXPECT_EQ(off->positions, prefix.positions);
  EXPECT_EQ(apply_asa_choice(prefix, 0xd0).error().code, ErrorCode::kCorrupt);
  // In a guidance block it reads like any other choice; a byte naming no
  // choice (here an approximating one with crease index 5) refuses the
  // whole guidance, so the client shows the decoded mesh (guided_asa.h).
  AsaGuidance g;
  g.groups = {{0, approximating}, {4, kAsaChoiceOff}};
  auto read = read_asa_guidance(header_with(g), 10);
  ASSERT_TRUE(read && *read);
  EXPECT_EQ((*read)->choice_for(1), approximating);
  g.groups.front().choice = 0xd0;
  EXPECT_EQ(read_asa_guidance(header_with(g), 10).error().code, ErrorCode::kCorrupt);
}

TEST(AsaGuidance, BlockRoundTripsAndPicksTheGroupOfAPrefix) {
  AsaGuidance g;
  g.groups = {{0, kAsaChoiceOff}, {7, 0x21}, {300, 0x01}, {999, kAsaChoiceOff}};
  const StreamHeader h = header_with(g);
  auto read = read_asa_guidance(h, 1000);
  ASSERT_TRUE(read && *read) << (read ? "absent" : read.error().message);
  ASSERT_EQ((*read)->groups.size(), g.groups.size());
  for (size_t i = 0; i < g.groups.size(); ++i) {
    EXPECT_EQ((*read)->groups[i].first_record, g.groups[i].first_record);
    EXPECT_EQ((*read)->groups[i].choice, g.groups[i].choice);
  }
  EXPECT_EQ(g.choice_for(1), kAsaChoiceOff);  // records 0..0
  EXPECT_EQ(g.choice_for(7), kAsaChoiceOff);  // last record 6
  EXPECT_EQ(g.choice_for(8), 0x21);
  EXPECT_EQ(g.choice_for(300), 0x21);
  EXPECT_EQ(g.choice_for(301), 0x01);
  EXPECT_EQ(g.choice_for(1000), kAsaChoiceOff);
  // Fewer records than the guidance names: refused.
  EXPECT_FALSE(read_asa_guidance(h, 999));
}

TEST(AsaGuidance, UnknownBlocksAreSkippedAndAbsentGuidanceIsNoGuidance) {
  StreamHeader h;
  h.extra = {3, 4};
  auto none = read_asa_guidance(h, 10);
  ASSERT_TRUE(none);
  EXPECT_FALSE(*none);
  h.extra.insert(h.extra.end(), {0x7f, 2, 9, 9});  // a block of some later feature
  AsaGuidance g;
  g.groups = {{0, 0x21}};
  append_asa_guidance(h.extra, g);
  auto read = read_asa_guidance(h, 10);
  ASSERT_TRUE(read && *read);
  EXPECT_EQ((*read)->groups.front().choice, 0x21);
}

TEST(AsaGuidance, DamagedBlocksAreRefused) {
  AsaGuidance g;
  g.groups = {{0, kAsaChoiceOff}, {5, 0x21}};
  const StreamHeader good = header_with(g);
  ASSERT_TRUE(read_asa_guidance(good, 10));
  // Layout: 3 4 | tag len | n | d0 c0 | d1 c1
  ASSERT_EQ(good.extra.size(), 9u);
  auto damaged = [&](size_t at, uint8_t value) {
    StreamHeader h = good;
    h.extra[at] = value;
    return read_asa_guidance(h, 10);
  };
  EXPECT_FALSE(damaged(3, 40));    // length past the header
  EXPECT_FALSE(damaged(4, 0));     // no groups
  EXPECT_FALSE(damaged(4, 11));    // more groups than records
  EXPECT_FALSE(damaged(5, 1));     // the first group not at record 0
  EXPECT_FALSE(damaged(7, 0));     // a group at the same record as the one before
  EXPECT_FALSE(damaged(7, 10));    // a group past the last record
  EXPECT_FALSE(damaged(8, 0x51));  // no such crease angle
  EXPECT_FALSE(damaged(8, 0x10));  // crease bits without levels
  EXPECT_FALSE(damaged(8, 0x1d));  // crease 40 below acos(0.75)
  StreamHeader cut = good;
  cut.extra.pop_back();
  cut.extra[3] -= 1;
  EXPECT_FALSE(read_asa_guidance(cut, 10));  // the last group cut short
  StreamHeader longer = good;
  longer.extra.push_back(0);
  longer.extra[3] += 1;
  EXPECT_FALSE(read_asa_guidance(longer, 10));  // bytes after the last group
  for (size_t at = 3; at < good.extra.size(); ++at) {
    // Whatever the byte, either refused or a valid reading: never a crash.
    for (int v = 0; v < 256; ++v) (void)damaged(at, uint8_t(v));
  }
}

TEST(AsaGuidance, EncoderWritesGuidanceThatChangesNoDecodedByte) {
  const Mesh mesh = make_demo_mesh(6000);
  EncodeOptions plain;
  plain.asa_guidance = false;
  auto unguided = encode_hcs(mesh, plain);
  auto guided = encode_hcs(mesh);
  ASSERT_TRUE(unguided && guided);
  auto ui = read_stream_index(*unguided);
  auto gi = read_stream_index(*guided);
  ASSERT_TRUE(ui && gi);
  auto none = read_asa_guidance(ui->header, uint32_t(ui->records.size()));
  ASSERT_TRUE(none);
  EXPECT_FALSE(*none);
  auto g = read_asa_guidance(gi->header, uint32_t(gi->records.size()));
  ASSERT_TRUE(g && *g) << (g ? "absent" : g.error().message);
  // Nothing is missing from the complete stream: no ASA there.
  EXPECT_EQ((*g)->choice_for(uint32_t(gi->records.size())), kAsaChoiceOff);
  // The same records behind a longer header; far under 0.5 % of the stream.
  ASSERT_EQ(gi->records.size(), ui->records.size());
  const size_t extra = guided->size() - unguided->size();
  EXPECT_EQ(extra, gi->header.extra.size() - ui->header.extra.size());
  EXPECT_LE(double(extra), 0.005 * double(unguided->size()));
  EXPECT_TRUE(std::equal(unguided->end() - std::ptrdiff_t(ui->total_bytes() - ui->payload_offset),
                         unguided->end(),
                         guided->end() - std::ptrdiff_t(gi->total_bytes() - gi->payload_offset)));
  // Every prefix decodes to the same mesh with or without guidance.
  for (size_t r = 0; r < gi->records.size(); r += std::max<size_t>(1, gi->records.size() / 5)) {
    auto a = decode_hcs(
        std::span<const uint8_t>(unguided->data(), ui->records[r].offset + ui->records[r].size));
    auto b = decode_hcs(
        std::span<const uint8_t>(guided->data(), gi->records[r].offset + gi->records[r].size));
    ASSERT_TRUE(a && b);
    EXPECT_EQ(a->positions, b->positions);
    EXPECT_EQ(a->triangles, b->triangles);
  }
  // Replacing the guidance keeps one block.
  AsaGuidance other;
  other.groups = {{0, 0x01}};
  auto replaced = with_asa_guidance(*guided, other);
  ASSERT_TRUE(replaced);
  auto ri = read_stream_index(*replaced);
  ASSERT_TRUE(ri);
  auto rg = read_asa_guidance(ri->header, uint32_t(ri->records.size()));
  ASSERT_TRUE(rg && *rg);
  ASSERT_EQ((*rg)->groups.size(), 1u);
  EXPECT_EQ((*rg)->groups[0].choice, 0x01);
}

// The encoder passes its own hierarchy over the original, refitted to the
// original's positions: the measurement finds the same distances and the
// same choices as with one built for it.
TEST(AsaGuidance, AGivenHierarchyMeasuresTheSame) {
  const Mesh mesh = make_demo_mesh(6000);
  EncodeOptions plain;
  plain.asa_guidance = false;
  auto stream = encode_hcs(mesh, plain);
  ASSERT_TRUE(stream);
  Mesh elsewhere = mesh;
  for (Vec3f& p : elsewhere.positions) p = p * 300.0f + Vec3f{-5, 2, 9};
  TriangleBvh hierarchy = TriangleBvh::build(elsewhere);
  ASSERT_TRUE(hierarchy.refit(mesh));
  AsaGuidanceOptions own, given;
  given.original_hierarchy = &hierarchy;
  AsaGuidanceReport own_report, given_report;
  auto a = measure_asa_guidance(mesh, *stream, own, &own_report);
  auto b = measure_asa_guidance(mesh, *stream, given, &given_report);
  ASSERT_TRUE(a && b);
  ASSERT_EQ(a->groups.size(), b->groups.size());
  for (size_t i = 0; i < a->groups.size(); ++i) EXPECT_EQ(a->groups[i].choice, b->groups[i].choice);
  ASSERT_EQ(own_report.groups.size(), given_report.groups.size());
  for (size_t i = 0; i < own_report.groups.size(); ++i) {
    EXPECT_EQ(own_report.groups[i].rms, given_report.groups[i].rms) << "group " << i;
    EXPECT_EQ(own_report.groups[i].normal, given_report.groups[i].normal) << "group " << i;
  }
}

TEST(AsaGuidance, DamagedGuidanceFailsTheHeaderChecksumOrIsRefused) {
  const Mesh mesh = make_demo_mesh(4000);
  auto guided = encode_hcs(mesh);
  ASSERT_TRUE(guided);
  auto index = read_stream_index(*guided);
  ASSERT_TRUE(index);
  const size_t extra_at = 12 + 48;  // the header's fixed fields, then extra
  const size_t choice_at = extra_at + index->header.extra.size() - 1;  // the last group's choice
  // A flipped bit in transit: the header's CRC-32 refuses the stream.
  std::vector<uint8_t> flipped = *guided;
  flipped[choice_at] ^= 0x40;
  auto refused = read_stream_index(flipped);
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().code, ErrorCode::kCorrupt);
  // A damaged choice behind a valid checksum (a hostile server): the
  // guidance is refused, so the client falls back to no ASA.
  std::vector<uint8_t> hostile = *guided;
  hostile[choice_at] = 0x51;
  reseal_checksums(hostile);
  auto hi = read_stream_index(hostile);
  ASSERT_TRUE(hi) << hi.error().message;
  auto hg = read_asa_guidance(hi->header, uint32_t(hi->records.size()));
  ASSERT_FALSE(hg);
  EXPECT_EQ(hg.error().code, ErrorCode::kCorrupt);
  EXPECT_NE(hg.error().message.find("ASA guidance"), std::string::npos);
  // The geometry still decodes.
  EXPECT_TRUE(decode_hcs(hostile));
}

TEST(AsaGuidance, OldStreamsHaveNoGuidanceAndStillDecode) {
  for (const char* name : {"container3_v8_icosphere3_own.hcs", "container2_grid8_own.hcs",
                           "issue1_components3_draco.hcs"}) {
    const std::vector<uint8_t> bytes = read_sample(name);
    auto index = read_stream_index(bytes);
    ASSERT_TRUE(index) << name;
    auto g = read_asa_guidance(index->header, uint32_t(index->records.size()));
    ASSERT_TRUE(g) << name << ": " << g.error().message;
    EXPECT_FALSE(*g) << name;
    EXPECT_TRUE(decode_hcs(bytes)) << name;
  }
}

// On real meshes: a CAD part gets no plain-worsening ASA where the fixed
// default was worst, a smooth scan gets ASA at its coarse prefixes.
TEST(AsaGuidance, RealMeshesGetTheirOwnChoice) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  AsaGuidanceReport report;
  for (const char* name : {"fandisk.off", "bunny.off"}) {
    auto imported = import_mesh(testing::test_mesh(name));
    ASSERT_TRUE(imported) << name;
    EncodeOptions plain;
    plain.asa_guidance = false;
    auto stream = encode_hcs(imported->mesh, plain);
    ASSERT_TRUE(stream);
    report = {};
    auto g = measure_asa_guidance(imported->mesh, *stream, {}, &report);
    ASSERT_TRUE(g) << g.error().message;
    ASSERT_FALSE(report.groups.empty());
    bool any_asa = false;
    for (const AsaGuidanceReport::Group& row : report.groups) {
      // Chosen only where it measured closer than no ASA by the margin.
      ASSERT_EQ(row.rms.size(), AsaGuidanceOptions::default_candidates().size() + 1);
      if (row.choice != kAsaChoiceOff) {
        any_asa = true;
        const auto& c = AsaGuidanceOptions::default_candidates();
        const size_t k = size_t(std::find(c.begin(), c.end(), row.choice) - c.begin());
        if (k < c.size()) {
          EXPECT_LT(row.rms[k + 1], row.rms[0] * 0.98) << name << " ratio " << row.ratio;
          // ... and in how the picture is shaded (the shading margin).
          EXPECT_LT(row.normal[k + 1], row.normal[0] * 0.98) << name << " ratio " << row.ratio;
        } else {  // the approximating form of a candidate: closer than that too
          ASSERT_TRUE(asa_choice_approximates(row.choice));
          EXPECT_LT(row.approximate_rms, row.rms[0] * 0.98 * 0.98) << name;
          EXPECT_LT(row.approximate_normal, row.normal[0] * 0.98) << name;
        }
      }
    }
    if (std::string(name) == "bunny.off") {
      EXPECT_TRUE(any_asa) << "a smooth scan gains from ASA";
    }
  }
}

}  // namespace
}  // namespace meshstream

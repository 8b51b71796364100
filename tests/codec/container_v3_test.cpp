// Container version 3: the range-coded record index and the per-record
// CRC-32 trailers (container.h, record_index_coder.h). Round trips of random
// record lists, and hostile indexes and records: clear errors, never a
// crash, a hang or a large allocation.
#include <gtest/gtest.h>

#include <chrono>
#include <random>

#include "common/codec/container.h"
#include "common/codec/container_reseal.h"
#include "common/codec/crc32.h"
#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "common/codec/record_index_coder.h"
#include "tests/codec/codec_test_util.h"
#include "tests/codec/container_test_util.h"

namespace meshstream {
namespace {

using namespace meshstream::testing;

struct RecordList {
  StreamHeader header;
  std::vector<std::vector<uint8_t>> payloads;
  std::vector<RecordCounts> counts;
};

// A base, then structure records (1..2 faces per vertex, so gaps 0..dv —
// boundary vertices add one face) and plane records (no vertices) in random
// runs, with payloads of random bytes and sizes (some empty).
RecordList random_records(std::mt19937& rng, size_t n) {
  RecordList l;
  uint32_t v = rng() % 1000, f = rng() % 2000;
  for (size_t i = 0; i < n; ++i) {
    if (i > 0) {
      const bool plane = rng() % 3 == 0;
      const uint32_t dv = plane ? 0 : 1 + rng() % 300;
      const uint32_t boundary = rng() % 4 == 0 ? rng() % (dv + 1) : 0;
      v += dv;
      f += 2 * dv - boundary;
    }
    std::vector<uint8_t> p(rng() % 5 == 0 ? rng() % 8 : rng() % 700);
    for (auto& b : p) b = uint8_t(rng());
    l.payloads.push_back(std::move(p));
    l.counts.push_back({v, f});
  }
  l.header.vertex_count = v;
  l.header.face_count = f;
  l.header.base_vertex_count = l.counts[0].vertices;
  l.header.base_face_count = l.counts[0].faces;
  l.header.bounds = {{-1, -2, -3}, {1, 2, 3}};
  l.header.layer_count = 3;
  l.header.extra = {2, 2};
  return l;
}

std::span<const uint8_t> bytes_of(const std::vector<uint8_t>& s, const RecordEntry& r) {
  return std::span<const uint8_t>(s).subspan(r.offset, r.size);
}

TEST(ContainerV3, RandomRecordListsRoundTrip) {
  std::mt19937 rng(17);
  for (size_t n : {1, 1, 2, 3, 10, 57, 300, 1000}) {
    const RecordList l = random_records(rng, n);
    auto written = write_container(l.header, l.payloads, l.counts);
    ASSERT_TRUE(written) << written.error().message;
    auto index = read_stream_index(written->bytes);
    ASSERT_TRUE(index) << "n " << n << ": " << index.error().message;
    EXPECT_EQ(index->version, 3);
    EXPECT_EQ(index->payload_offset, written->payload_offset);
    EXPECT_EQ(index->total_bytes(), written->bytes.size());
    EXPECT_EQ(index->header.vertex_count, l.header.vertex_count);
    ASSERT_EQ(index->records.size(), n);
    uint64_t at = index->payload_offset;
    for (size_t i = 0; i < n; ++i) {
      const RecordEntry& r = index->records[i];
      EXPECT_EQ(r.offset, at);
      EXPECT_EQ(r.offset, written->records[i].offset);
      EXPECT_EQ(r.size, l.payloads[i].size() + kRecordTrailerBytes);
      EXPECT_EQ(r.vertices, l.counts[i].vertices);
      EXPECT_EQ(r.faces, l.counts[i].faces);
      EXPECT_TRUE(r.crc_trailer);
      EXPECT_EQ(r.crc32, crc32(0, l.payloads[i].data(), l.payloads[i].size())) << "record " << i;
      EXPECT_TRUE(record_intact(r, bytes_of(written->bytes, r)));
      const auto payload = record_payload(r, bytes_of(written->bytes, r));
      EXPECT_TRUE(
          std::equal(payload.begin(), payload.end(), l.payloads[i].begin(), l.payloads[i].end()));
      at += r.size;
    }
  }
}

// Index entries alone, at the extremes of what the format holds: sizes up to
// 1 GiB, hundreds of millions of vertices in one record, big face gaps.
TEST(ContainerV3, ExtremeEntriesRoundTrip) {
  std::mt19937 rng(23);
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<RecordEntry> records(1 + rng() % 40);
    uint64_t v = 0, f = 0;
    for (size_t i = 0; i < records.size(); ++i) {
      const uint32_t shift = rng() % 31;
      records[i].size =
          std::max<uint32_t>(kRecordTrailerBytes, (rng() >> shift) % kMaxRecordBytes + 1);
      const uint64_t dv = i > 0 && rng() % 3 == 0 ? 0 : (rng() >> (rng() % 32)) % (1u << 26);
      v += dv;
      f += dv + rng() % (dv + 1);
      records[i].vertices = uint32_t(v);
      records[i].faces = uint32_t(f);
    }
    auto coded = encode_record_index(records);
    ASSERT_TRUE(coded) << coded.error().message;
    auto back = decode_record_index(*coded, uint32_t(records.size()), 100);
    ASSERT_TRUE(back) << "trial " << trial << ": " << back.error().message;
    uint64_t at = 100;
    for (size_t i = 0; i < records.size(); ++i) {
      EXPECT_EQ((*back)[i].size, records[i].size);
      EXPECT_EQ((*back)[i].vertices, records[i].vertices);
      EXPECT_EQ((*back)[i].faces, records[i].faces);
      EXPECT_EQ((*back)[i].offset, at);
      at += records[i].size;
    }
  }
}

TEST(ContainerV3, WriterRefusesWhatTheReaderWould) {
  std::mt19937 rng(3);
  RecordList l = random_records(rng, 5);
  EXPECT_FALSE(
      write_container(l.header, l.payloads, std::span(l.counts).first(4)));  // lengths differ
  EXPECT_FALSE(write_container(l.header, {}, {}));                           // no records
  RecordList bad = l;
  bad.header.vertex_count += 1;  // last counts differ from the header's
  EXPECT_FALSE(write_container(bad.header, bad.payloads, bad.counts));
  bad = l;
  bad.counts[2].vertices = bad.counts[1].vertices - 1;  // counts decrease
  EXPECT_FALSE(write_container(bad.header, bad.payloads, bad.counts));
  std::vector<RecordEntry> tiny(2);
  tiny[0].size = 3;  // smaller than a trailer
  EXPECT_FALSE(encode_record_index(tiny));
}

// The version-3 stream of a real encode: small enough to flip every byte.
const std::vector<uint8_t>& encoded_stream() {
  static const std::vector<uint8_t> bytes = [] {
    EncodeOptions opt;
    opt.target_base_vertices = 30;
    opt.record_bytes = 120;
    auto b = encode_hcs(combine({icosphere(3, 0.2f), height_field(12, 9), torus(16, 10)}), opt);
    return b ? *b : std::vector<uint8_t>{};
  }();
  return bytes;
}

TEST(ContainerV3, EncoderWritesVersionThree) {
  const auto& bytes = encoded_stream();
  auto index = read_stream_index(bytes);
  ASSERT_TRUE(index) << index.error().message;
  EXPECT_EQ(index->version, kContainerVersion);
  EXPECT_EQ(kContainerVersion, 3);
  EXPECT_GT(index->records.size(), 20u);
  // Compact: well under 2.5 bytes an entry (magic, header, count, length
  // and CRCs are 78 bytes here).
  const double per_entry = double(index->payload_offset - 78) / double(index->records.size());
  EXPECT_LT(per_entry, 2.5);
  for (const RecordEntry& r : index->records) EXPECT_TRUE(record_intact(r, bytes_of(bytes, r)));
}

TEST(ContainerV3, EveryShortPrefixIsTruncated) {
  const auto& bytes = encoded_stream();
  auto full = read_stream_index(bytes);
  ASSERT_TRUE(full);
  expect_every_short_prefix_truncated(bytes, full->payload_offset);
  // From the end of the index on, the records inside the span get their CRC.
  for (size_t n : {full->payload_offset, full->records[1].offset + full->records[1].size}) {
    auto index = read_stream_index(std::span(bytes).first(n));
    ASSERT_TRUE(index);
    for (const RecordEntry& r : index->records) {
      if (r.offset + r.size <= n) {
        EXPECT_EQ(r.crc32, crc32(0, bytes.data() + r.offset, r.size - kRecordTrailerBytes));
      } else {
        EXPECT_EQ(r.crc32, 0u);
      }
    }
  }
}

// Layout positions of the version-3 index in `s` (magic, header read as is).
struct IndexAt {
  size_t count_at = 0;
  size_t coded_at = 0;
  size_t length = 0;
};
IndexAt index_at(const std::vector<uint8_t>& s) {
  IndexAt a;
  const size_t header_size = s[8] | s[9] << 8 | s[10] << 16 | size_t(s[11]) << 24;
  a.count_at = 12 + header_size + 4;
  a.coded_at = a.count_at + 8;
  a.length = s[a.count_at + 4] | s[a.count_at + 5] << 8 | s[a.count_at + 6] << 16 |
             size_t(s[a.count_at + 7]) << 24;
  return a;
}
void put_u32(std::vector<uint8_t>& s, size_t at, uint32_t v) {
  for (int i = 0; i < 4; ++i) s[at + i] = uint8_t(v >> (8 * i));
}

// Any flipped bit in the coded index bytes fails the index checksum.
TEST(ContainerV3, FlippedIndexByteFailsTheChecksum) {
  const auto& bytes = encoded_stream();
  auto full = read_stream_index(bytes);
  ASSERT_TRUE(full);
  const IndexAt a = index_at(bytes);
  ASSERT_EQ(a.coded_at + a.length + 4, full->payload_offset);
  for (size_t i = a.coded_at; i < a.coded_at + a.length; ++i) {
    for (int bit = 0; bit < 8; ++bit) {
      std::vector<uint8_t> bad = bytes;
      bad[i] ^= uint8_t(1 << bit);
      auto index = read_stream_index(bad);
      ASSERT_FALSE(index);
      EXPECT_EQ(index.error().code, ErrorCode::kCorrupt) << "byte " << i;
    }
  }
  // Every bit of magic, header and index: always refused.
  for (size_t i = 0; i < full->payload_offset; ++i) {
    std::vector<uint8_t> bad = bytes;
    bad[i] ^= 0x04;
    EXPECT_FALSE(read_stream_index(bad)) << "byte " << i;
  }
}

// A flipped byte in a record's payload or in its trailer: record_intact is
// false and the decoder stops before applying it with a recoverable checksum
// error naming the record; resuming with good bytes finishes exactly.
TEST(ContainerV3, DamagedPayloadOrTrailerIsARecoverableChecksumError) {
  const auto& bytes = encoded_stream();
  auto index = read_stream_index(bytes);
  ASSERT_TRUE(index);
  auto whole = decode_hcs(bytes);
  ASSERT_TRUE(whole);
  std::mt19937 rng(29);
  for (int trial = 0; trial < 40; ++trial) {
    const uint32_t victim = uint32_t(rng() % index->records.size());
    const RecordEntry& r = index->records[victim];
    const bool in_trailer = trial % 2 == 1;
    const size_t at = in_trailer ? r.offset + r.size - 1 - rng() % kRecordTrailerBytes
                                 : r.offset + rng() % (r.size - kRecordTrailerBytes);
    std::vector<uint8_t> bad = bytes;
    bad[at] ^= uint8_t(1u << (rng() % 8));
    auto damaged = read_stream_index(bad);
    ASSERT_TRUE(damaged);  // the index does not cover record bytes
    EXPECT_FALSE(record_intact(damaged->records[victim], bytes_of(bad, r)));

    IncrementalDecoder dec;
    auto fed = dec.feed(bad);
    ASSERT_FALSE(fed) << "trial " << trial;
    EXPECT_EQ(fed.error().code, ErrorCode::kCorrupt);
    EXPECT_NE(fed.error().message.find("record " + std::to_string(victim) + " of"),
              std::string::npos)
        << fed.error().message;
    EXPECT_NE(fed.error().message.find("checksum"), std::string::npos) << fed.error().message;
    EXPECT_TRUE(dec.error_is_recoverable());
    EXPECT_EQ(dec.records_decoded(), victim);
    ASSERT_TRUE(dec.resume_at(dec.resume_offset()));
    const uint64_t from = dec.resume_offset();
    ASSERT_TRUE(dec.feed(std::span<const uint8_t>(bytes).subspan(from)));
    EXPECT_TRUE(dec.finished());
    EXPECT_EQ(dec.mesh().positions, whole->positions);
    EXPECT_EQ(dec.mesh().triangles, whole->triangles);
  }
}

// Garbage index bytes with valid checksums (a hostile server): a clear kParse
// naming the problem, or an index that obeys every rule; fast either way.
TEST(ContainerV3, ResealedGarbageIndexIsAClearParseError) {
  const auto& clean = encoded_stream();
  const IndexAt a = index_at(clean);
  std::mt19937 rng(31);
  int refused = 0;
  const auto start = std::chrono::steady_clock::now();
  for (int trial = 0; trial < 600; ++trial) {
    std::vector<uint8_t> s = clean;
    switch (trial % 3) {
      case 0:  // random coded bytes, same length
        for (size_t i = 0; i < a.length; ++i) s[a.coded_at + i] = uint8_t(rng());
        break;
      case 1:  // a few flipped bits
        for (int k = 0; k < 1 + trial % 4; ++k)
          s[a.coded_at + rng() % a.length] ^= uint8_t(1u << (rng() % 8));
        break;
      default:  // all zero or all 0xFF
        std::fill(s.begin() + a.coded_at, s.begin() + a.coded_at + a.length,
                  trial % 2 ? 0x00 : 0xFF);
        break;
    }
    reseal_checksums(s);
    auto index = read_stream_index(s);
    if (!index) {
      ++refused;
      EXPECT_EQ(index.error().code, ErrorCode::kParse) << index.error().message;
      EXPECT_NE(index.error().message.find("record"), std::string::npos) << index.error().message;
      continue;
    }
    // Accepted: then contiguous, counts ending at the header's.
    uint64_t at = index->payload_offset;
    for (const RecordEntry& r : index->records) {
      EXPECT_EQ(r.offset, at);
      EXPECT_GE(r.size, kRecordTrailerBytes);
      at += r.size;
    }
    EXPECT_EQ(index->records.back().vertices, index->header.vertex_count);
    (void)decode_hcs(s);  // no crash
  }
  EXPECT_GT(refused, 550);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 10.0);
}

// Counts and lengths a reader must refuse before allocating or waiting.
TEST(ContainerV3, ImplausibleCountAndLengthAreRefusedUpFront) {
  const auto& clean = encoded_stream();
  const IndexAt a = index_at(clean);
  struct Case {
    uint32_t count;
    uint32_t length;
  };
  // Too many records for the bytes; too many bytes a record; empty index;
  // the maximal count with a length that would need megabytes.
  for (Case c :
       {Case{kMaxRecords, 10}, Case{3, 49}, Case{1, 0}, Case{kMaxRecords, 1u << 30}, Case{0, 10}}) {
    std::vector<uint8_t> s = clean;
    put_u32(s, a.count_at, c.count);
    put_u32(s, a.count_at + 4, c.length);
    auto index = read_stream_index(s);
    ASSERT_FALSE(index);
    EXPECT_EQ(index.error().code, ErrorCode::kParse)
        << c.count << " / " << c.length << ": " << index.error().message;
  }
  // Coded bytes decoding to a huge count: 65536 zero bytes for 2^22 records.
  std::vector<uint8_t> s(clean.begin(), clean.begin() + a.coded_at);
  put_u32(s, a.count_at, kMaxRecords);
  put_u32(s, a.count_at + 4, kMaxRecords / kMaxRecordsPerIndexByte);
  s.resize(s.size() + kMaxRecords / kMaxRecordsPerIndexByte + 4, 0);
  reseal_checksums(s);
  const auto start = std::chrono::steady_clock::now();
  auto index = read_stream_index(s);
  ASSERT_FALSE(index);
  EXPECT_EQ(index.error().code, ErrorCode::kParse);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 2.0);
}

// Bytes after the last coded symbol (the decoder must use them all) and a
// record count one short of what the bytes code.
TEST(ContainerV3, TrailingOrMissingIndexBytesAreRefused) {
  const auto& clean = encoded_stream();
  const IndexAt a = index_at(clean);
  auto full = read_stream_index(clean);
  ASSERT_TRUE(full);
  // The decoder reads as many bytes as the encoder wrote before dropping up
  // to 4 trailing zeros, so up to that many extra zero bytes take the
  // dropped zeros' place (they decode the same symbols); 5 never fit. (Other
  // byte values would change the last symbols, which may then read all the
  // bytes and fail a count check instead: refused, but not as "trailing".)
  std::vector<uint8_t> longer = clean;
  longer.insert(longer.begin() + a.coded_at + a.length, 5, uint8_t(0));
  put_u32(longer, a.count_at + 4, uint32_t(a.length + 5));
  reseal_checksums(longer);
  auto index = read_stream_index(longer);
  ASSERT_FALSE(index);
  EXPECT_EQ(index.error().code, ErrorCode::kParse);
  EXPECT_NE(index.error().message.find("trailing"), std::string::npos) << index.error().message;

  // One record fewer: its few bits may lie inside the decoder's look-ahead,
  // so the bytes can be used up; then the index is refused (the counts stop
  // short of the header's) or, when the record dropped was a plane record,
  // it is the first records of the stream, exactly.
  std::vector<uint8_t> fewer = clean;
  put_u32(fewer, a.count_at, uint32_t(full->records.size() - 1));
  reseal_checksums(fewer);
  if (auto shorter = read_stream_index(fewer)) {
    ASSERT_EQ(shorter->records.size(), full->records.size() - 1);
    for (size_t i = 0; i < shorter->records.size(); ++i) {
      EXPECT_EQ(shorter->records[i].size, full->records[i].size);
      EXPECT_EQ(shorter->records[i].vertices, full->records[i].vertices);
    }
  } else {
    EXPECT_EQ(shorter.error().code, ErrorCode::kParse);
  }
}

// An index whose second record claims a gigabyte and two billion vertices
// (bytes that never come): the base still decodes, and the decoder reserves
// for the bytes it has, not for the index's claim (it threw bad_alloc).
TEST(ContainerV3, HugeClaimedRecordReservesNothingForIt) {
  const auto& clean = encoded_stream();
  auto index = read_stream_index(clean);
  ASSERT_TRUE(index);
  const RecordEntry& r0 = index->records[0];
  std::vector<RecordEntry> entries = {r0, r0};
  entries[1].size = kMaxRecordBytes;
  entries[1].vertices = r0.vertices + (1u << 31);
  entries[1].faces = r0.faces + (1u << 31) + 5;
  auto coded = encode_record_index(entries);
  ASSERT_TRUE(coded) << coded.error().message;
  // Header as the clean stream's, with the claimed totals.
  StreamHeader h = index->header;
  h.vertex_count = entries[1].vertices;
  h.face_count = entries[1].faces;
  std::vector<std::vector<uint8_t>> payloads(2);
  const auto base = record_payload(r0, bytes_of(clean, r0));
  payloads[0].assign(base.begin(), base.end());
  payloads[1] = {1};
  std::vector<RecordCounts> counts = {{r0.vertices, r0.faces},
                                      {entries[1].vertices, entries[1].faces}};
  auto shell = write_container(h, payloads, counts);
  ASSERT_TRUE(shell);
  const IndexAt a = index_at(shell->bytes);
  std::vector<uint8_t> s(shell->bytes.begin(), shell->bytes.begin() + a.coded_at);
  put_u32(s, a.count_at + 4, uint32_t(coded->size()));
  s.insert(s.end(), coded->begin(), coded->end());
  s.resize(s.size() + 4);
  put_u32(s, s.size() - 4, crc32(0, s.data() + a.count_at, s.size() - 4 - a.count_at));
  s.insert(s.end(), shell->bytes.begin() + shell->records[0].offset,
           shell->bytes.begin() + shell->records[0].offset + shell->records[0].size);
  auto claimed = read_stream_index(s);
  ASSERT_TRUE(claimed) << claimed.error().message;
  EXPECT_GT(claimed->total_bytes(), uint64_t(1) << 30);
  IncrementalDecoder dec;
  auto fed = dec.feed(s);
  ASSERT_TRUE(fed) << fed.error().message;
  EXPECT_EQ(dec.records_decoded(), 1u);
  EXPECT_EQ(dec.mesh().vertex_count(), r0.vertices);
}

// reseal_checksums makes damaged version-3 records pass: index CRC and
// every trailer.
TEST(ContainerV3, ResealFixesTrailers) {
  const auto& clean = encoded_stream();
  auto index = read_stream_index(clean);
  ASSERT_TRUE(index);
  std::vector<uint8_t> s = clean;
  for (const RecordEntry& r : index->records) s[r.offset] ^= 0x21;
  reseal_checksums(s);
  auto resealed = read_stream_index(s);
  ASSERT_TRUE(resealed);
  for (const RecordEntry& r : resealed->records) EXPECT_TRUE(record_intact(r, bytes_of(s, r)));
}

}  // namespace
}  // namespace meshstream

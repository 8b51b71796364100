// Texture records (texture_record.h, texture_stream.h): the images of a
// mesh travel in the stream, a small level first, the original bytes last;
// budgets, resume and checksums work for them; a record that lies about
// its image is refused with the record and texture named.
#include "common/codec/texture_record.h"

#include <gtest/gtest.h>
#include <stb_image.h>
#include <stb_image_write.h>

#include <cstdio>
#include <cstdlib>

#include "common/codec/container.h"
#include "common/codec/decoder.h"
#include "common/codec/encoder.h"
#include "common/codec/texture_stream.h"
#include "common/mesh/textured_sphere.h"

namespace meshstream {
namespace {

EncodeOptions quick_options() {
  EncodeOptions o;
  o.plane_calibration = 1.0;  // one ordering: the texture records do not depend on it
  return o;
}

// The sphere with a noisy 256-pixel image (a checker compresses so well
// that no middle level would pay), so the stream has all three levels.
std::vector<uint8_t> noisy_png(int side) {
  std::vector<uint8_t> rgb(size_t(side) * side * 3);
  uint32_t x = 12345;
  for (uint8_t& c : rgb) {
    x = x * 1103515245u + 12345u;
    c = uint8_t(x >> 24);
  }
  std::vector<uint8_t> png;
  stbi_write_png_to_func(
      [](void* ctx, void* data, int size) {
        auto* out = static_cast<std::vector<uint8_t>*>(ctx);
        out->insert(out->end(), static_cast<uint8_t*>(data), static_cast<uint8_t*>(data) + size);
      },
      &png, side, side, 3, rgb.data(), side * 3);
  return png;
}

Mesh textured_sphere() {
  Mesh m = make_textured_uv_sphere(24, 48, 256);
  m.textures[0].bytes = noisy_png(256);
  return m;
}

const std::vector<uint8_t>& textured_stream() {
  static const std::vector<uint8_t> stream = [] {
    auto s = encode_hcs(textured_sphere(), quick_options());
    EXPECT_TRUE(s) << s.error().message;
    return s ? *s : std::vector<uint8_t>{};
  }();
  return stream;
}

bool is_texture(const std::vector<uint8_t>& stream, const RecordEntry& r) {
  return stream[r.offset] == kRecordTexture;
}

// The stream's payloads and counts, to rewrite it with one record changed.
struct Records {
  StreamHeader header;
  std::vector<std::vector<uint8_t>> payloads;
  std::vector<RecordCounts> counts;
};
Records split(const std::vector<uint8_t>& stream) {
  auto index = read_stream_index(stream);
  EXPECT_TRUE(index);
  Records out;
  out.header = index->header;
  for (const RecordEntry& r : index->records) {
    auto p = record_payload(r, std::span(stream.data() + r.offset, r.size));
    out.payloads.emplace_back(p.begin(), p.end());
    out.counts.push_back({r.vertices, r.faces});
  }
  return out;
}

TEST(TextureRecords, PreviewFollowsTheBaseAndTheOriginalComesBackExactly) {
  const auto& stream = textured_stream();
  ASSERT_FALSE(stream.empty());
  auto index = read_stream_index(stream);
  ASSERT_TRUE(index);
  ASSERT_GE(index->records.size(), 3u);
  // The preview follows the base's attribute record (record 1: the texture
  // coordinates that map it), within 10 % of the first display's bytes
  // (header, index, base).
  ASSERT_FALSE(is_texture(stream, index->records[1]));
  EXPECT_EQ(stream[index->records[1].offset], kRecordAttributes);
  EXPECT_TRUE(is_texture(stream, index->records[2])) << "the preview is record 2";
  EXPECT_LE(index->records[2].size,
            0.10 * double(index->payload_offset + index->records[0].size) + 2);
  size_t textures = 0;
  for (const RecordEntry& r : index->records) textures += is_texture(stream, r);
  EXPECT_EQ(textures, 3u) << "preview, 128-pixel level and the original of a 256-pixel image";

  auto decoded = decode_hcs(stream);
  ASSERT_TRUE(decoded) << decoded.error().message;
  ASSERT_EQ(decoded->textures.size(), 1u);
  const Mesh original = textured_sphere();
  EXPECT_EQ(decoded->textures[0].bytes, original.textures[0].bytes);
  EXPECT_EQ(decoded->textures[0].name, "checker.png");
  EXPECT_EQ(decoded->textures[0].mime_type, "image/png");
  EXPECT_EQ(decoded->vertex_count(), original.vertex_count());
}

TEST(TextureRecords, EachLevelReplacesTheSmallerOneRecordByRecord) {
  const auto& stream = textured_stream();
  IncrementalDecoder decoder;
  auto index = read_stream_index(stream);
  ASSERT_TRUE(index);
  int last_width = 0;
  uint32_t levels_seen = 0;
  // Feed one record at a time.
  uint64_t at = 0;
  for (const RecordEntry& r : index->records) {
    const uint64_t end = r.offset + r.size;
    auto fed = decoder.feed(std::span(stream.data() + at, end - at));
    ASSERT_TRUE(fed) << fed.error().message;
    at = end;
    ASSERT_EQ(decoder.last_deltas().size(), 1u);
    const bool texture = is_texture(stream, r);
    EXPECT_EQ(decoder.last_deltas()[0].textures_changed, texture);
    if (!texture) continue;
    ++levels_seen;
    ASSERT_EQ(decoder.mesh().textures.size(), 1u);
    const Texture& t = decoder.mesh().textures[0];
    int w = 0, h = 0, n = 0;
    ASSERT_TRUE(stbi_info_from_memory(t.bytes.data(), int(t.bytes.size()), &w, &h, &n));
    EXPECT_GT(w, last_width) << "levels grow";
    if (levels_seen == 1) {
      EXPECT_LE(w, 32) << "the first level is a small preview";
      // Right after the base's attribute record (record 1).
      EXPECT_EQ(r.offset, index->records[1].offset + index->records[1].size);
    }
    last_width = w;
    EXPECT_EQ(decoder.textures_original()[0], w == 256);
  }
  EXPECT_EQ(last_width, 256);
  EXPECT_TRUE(decoder.finished());
}

TEST(TextureRecords, BudgetsAndResumeTreatThemAsAnyRecord) {
  const auto& stream = textured_stream();
  auto index = read_stream_index(stream);
  ASSERT_TRUE(index);
  // A byte budget that ends right after the preview shows the preview (it
  // follows the base, or the base's attribute record).
  size_t preview_at = 1;
  while (preview_at < index->records.size() &&
         stream[index->records[preview_at].offset] != kRecordTexture)
    ++preview_at;
  ASSERT_LT(preview_at, index->records.size());
  const RecordEntry& preview = index->records[preview_at];
  const uint64_t cut = prefix_for_budget(
      *index, Budget{Budget::Kind::kBytes, double(preview.offset + preview.size)});
  EXPECT_EQ(cut, preview.offset + preview.size);
  auto prefix = decode_hcs(std::span(stream.data(), cut));
  ASSERT_TRUE(prefix) << prefix.error().message;
  ASSERT_EQ(prefix->textures.size(), 1u);
  EXPECT_LT(prefix->textures[0].bytes.size(), 2000u);

  // A connection lost in the middle of the original's record: resume at the
  // last boundary and the image still comes back whole.
  size_t last_texture = 0;
  for (size_t i = 0; i < index->records.size(); ++i)
    if (is_texture(stream, index->records[i])) last_texture = i;
  const RecordEntry& full = index->records[last_texture];
  IncrementalDecoder decoder;
  const uint64_t broken = full.offset + full.size / 2;
  ASSERT_TRUE(decoder.feed(std::span(stream.data(), broken)));
  const uint64_t resume = decoder.resume_offset();
  EXPECT_EQ(resume, full.offset);
  ASSERT_TRUE(decoder.resume_at(resume));
  auto fed = decoder.feed(std::span(stream.data() + resume, stream.size() - resume));
  ASSERT_TRUE(fed) << fed.error().message;
  EXPECT_TRUE(decoder.finished());
  EXPECT_EQ(decoder.mesh().textures[0].bytes, textured_sphere().textures[0].bytes);

  // A flipped byte inside a texture record fails its checksum, recoverably.
  std::vector<uint8_t> damaged = stream;
  damaged[full.offset + full.size / 2] ^= 0x40;
  IncrementalDecoder d2;
  auto bad = d2.feed(damaged);
  ASSERT_FALSE(bad);
  EXPECT_TRUE(d2.error_is_recoverable());
  EXPECT_NE(bad.error().message.find("record " + std::to_string(last_texture)), std::string::npos)
      << bad.error().message;
}

// Rewrites the stream with texture record `which` (0 = the first) replaced
// by `change(payload)`, CRCs valid, and returns the decode error.
template <typename Change>
std::string refused(Change change, size_t which = 0) {
  Records r = split(textured_stream());
  size_t seen = 0, record = 0;
  for (size_t i = 1; i < r.payloads.size(); ++i) {
    if (r.payloads[i][0] != kRecordTexture) continue;
    if (seen++ == which) {
      change(r.payloads[i]);
      record = i;
      break;
    }
  }
  auto written = write_container(r.header, r.payloads, r.counts);
  EXPECT_TRUE(written);
  auto decoded = decode_hcs(written->bytes);
  if (decoded) return "decoded";
  EXPECT_NE(decoded.error().message.find("record " + std::to_string(record) + " of"),
            std::string::npos)
      << decoded.error().message;
  return decoded.error().message;
}

// Where the image bytes of a texture record start.
size_t image_start(const std::vector<uint8_t>& p) {
  auto level = read_texture_record(p);
  EXPECT_TRUE(level);
  return p.size() - level->bytes.size();
}

TEST(TextureRecords, RecordsThatLieAboutTheirImageAreRefusedByName) {
  // Wrong dimensions: the header says 17 pixels wide.
  std::string e = refused([](std::vector<uint8_t>& p) {
    TextureLevel level = *read_texture_record(p);
    level.width = 17;
    p = write_texture_record(level);
  });
  EXPECT_NE(e.find("texture 0 (\"checker.png\") level 0"), std::string::npos) << e;
  EXPECT_NE(e.find("17 x"), std::string::npos) << e;
  // Bad magic.
  e = refused([](std::vector<uint8_t>& p) { p[image_start(p) + 1] = 'X'; });
  EXPECT_NE(e.find("not a PNG or JPEG"), std::string::npos) << e;
  // Truncated image (the record is shorter, its CRC still right).
  e = refused([](std::vector<uint8_t>& p) { p.resize(p.size() - 20); }, 2);
  EXPECT_NE(e.find("truncated"), std::string::npos) << e;
  EXPECT_NE(e.find("texture 0"), std::string::npos) << e;
  // Declared JPEG, bytes PNG.
  e = refused([](std::vector<uint8_t>& p) {
    TextureLevel level = *read_texture_record(p);
    level.format = ImageFormat::kJpeg;
    p = write_texture_record(level);
  });
  EXPECT_NE(e.find("the record says JPEG but the bytes are PNG"), std::string::npos) << e;
  // An unknown image format.
  e = refused([](std::vector<uint8_t>& p) {
    const size_t format_at = 4;  // flag, level flags, texture 0, level 0: one byte each
    p[format_at] = 9;
  });
  EXPECT_NE(e.find("unknown image format 9"), std::string::npos) << e;
  // A level that goes back (the 128-pixel level's number rewritten to 0).
  e = refused(
      [](std::vector<uint8_t>& p) {
        TextureLevel level = *read_texture_record(p);
        level.level = 0;
        p = write_texture_record(level);
      },
      1);
  EXPECT_NE(e.find("level 0 came already"), std::string::npos) << e;
  // A texture index that skips one.
  e = refused([](std::vector<uint8_t>& p) {
    TextureLevel level = *read_texture_record(p);
    level.texture = 3;
    p = write_texture_record(level);
  });
  EXPECT_NE(e.find("texture 3"), std::string::npos) << e;
  EXPECT_NE(e.find("have not come yet"), std::string::npos) << e;
}

TEST(TextureRecords, AMeshWithoutTexturesKeepsItsStreamAndABadImageIsNamed) {
  Mesh plain = make_textured_uv_sphere(8, 12, 64);
  plain.textures.clear();
  plain.materials.clear();
  plain.face_materials.clear();
  auto a = encode_hcs(plain, quick_options());
  ASSERT_TRUE(a);
  auto same = add_texture_records(*a, {});
  ASSERT_TRUE(same);
  EXPECT_EQ(*same, *a);

  Mesh bad = make_textured_uv_sphere(8, 12, 64);
  bad.textures[0].name = "photo.bmp";
  bad.textures[0].bytes = {'B', 'M', 1, 2, 3, 4, 5, 6, 7, 8};
  auto refused_encode = encode_hcs(bad, quick_options());
  ASSERT_FALSE(refused_encode);
  EXPECT_NE(refused_encode.error().message.find("texture 0 (\"photo.bmp\")"), std::string::npos)
      << refused_encode.error().message;
}

TEST(TextureRecords, PreviewFitsItsShareOfTheFirstDisplay) {
  // The preview level's record fits the budget whenever a 1-pixel image
  // does (texture_levels' rule), larger budgets give larger previews, and
  // the original is the file's bytes.
  Texture t;
  t.name = "checker.png";
  t.mime_type = "image/png";
  t.bytes = make_checker_png(512);
  uint32_t last_width = 0;
  for (size_t budget : {100u, 200u, 400u, 1000u, 4000u}) {
    auto levels = texture_levels(t, 0, budget, TextureStreamOptions{});
    ASSERT_TRUE(levels);
    ASSERT_EQ(levels->size(), 2u) << "a checker's JPEG middle level does not pay";
    const TextureLevel& preview = levels->front();
    const size_t record = write_texture_record(preview).size() + 4;  // and its CRC trailer
    if (preview.width > 1) {
      EXPECT_LE(record + 2, budget) << preview.width;
    }
    EXPECT_GE(preview.width, last_width);
    last_width = preview.width;
    EXPECT_EQ(levels->back().bytes, t.bytes);
    EXPECT_TRUE(levels->back().original);
  }
}

}  // namespace
}  // namespace meshstream

namespace meshstream {
namespace {

// `meshstream info X.hcs --json` counts the texture records' bytes.
TEST(TextureRecords, InfoReportsTextureBytes) {
  const auto& stream = textured_stream();
  const std::string dir = ::testing::TempDir();
  const std::string path = dir + "/textured_sphere.hcs", out = dir + "/textured_info.json";
  {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    ASSERT_NE(f, nullptr);
    std::fwrite(stream.data(), 1, stream.size(), f);
    std::fclose(f);
  }
  const std::string tool = std::string(MESHSTREAM_BINARY_DIR) + "/tools/meshstream";
  ASSERT_EQ(std::system((tool + " info " + path + " --json > " + out).c_str()), 0);
  std::FILE* f = std::fopen(out.c_str(), "rb");
  ASSERT_NE(f, nullptr);
  std::string json;
  char buf[4096];
  for (size_t n; (n = std::fread(buf, 1, sizeof buf, f)) > 0;) json.append(buf, n);
  std::fclose(f);
  auto index = read_stream_index(stream);
  uint64_t texture_bytes = 0;
  for (const RecordEntry& r : index->records)
    if (is_texture(stream, r)) texture_bytes += r.size;
  EXPECT_NE(json.find("\"texture_bytes\":" + std::to_string(texture_bytes)), std::string::npos)
      << json.substr(0, 600);
  EXPECT_NE(json.find("\"name\":\"checker.png\""), std::string::npos);
  EXPECT_NE(json.find("\"kind\":\"texture\""), std::string::npos);
}

}  // namespace
}  // namespace meshstream

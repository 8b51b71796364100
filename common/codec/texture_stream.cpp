// Texture levels and their place in the stream: see texture_stream.h.
#include "common/codec/texture_stream.h"

#include <stb_image.h>
#include <stb_image_resize.h>
#include <stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <memory>

#include "common/codec/container.h"

namespace meshstream {

namespace {

struct Pixels {
  int width = 0, height = 0, channels = 0;
  std::vector<uint8_t> data;
};

void append_bytes(void* context, void* data, int size) {
  auto* out = static_cast<std::vector<uint8_t>*>(context);
  const auto* p = static_cast<const uint8_t*>(data);
  out->insert(out->end(), p, p + size);
}

std::vector<uint8_t> encode_png(const Pixels& p) {
  std::vector<uint8_t> out;
  stbi_write_png_to_func(append_bytes, &out, p.width, p.height, p.channels, p.data.data(),
                         p.width * p.channels);
  return out;
}

std::vector<uint8_t> encode_jpeg(const Pixels& p, int quality) {
  std::vector<uint8_t> out;
  stbi_write_jpg_to_func(append_bytes, &out, p.width, p.height, p.channels, p.data.data(), quality);
  return out;
}

// `source` scaled so that its long side is `side` pixels (sRGB-correct
// filtering; alpha, when there is one, kept apart).
Pixels scaled(const Pixels& source, int side) {
  Pixels out;
  const double scale = double(side) / double(std::max(source.width, source.height));
  out.width = std::max(1, int(std::lround(source.width * scale)));
  out.height = std::max(1, int(std::lround(source.height * scale)));
  out.channels = source.channels;
  out.data.resize(size_t(out.width) * out.height * out.channels);
  const int alpha = source.channels == 4 ? 3 : source.channels == 2 ? 1 : STBIR_ALPHA_CHANNEL_NONE;
  stbir_resize_uint8_srgb(source.data.data(), source.width, source.height, 0, out.data.data(),
                          out.width, out.height, 0, out.channels, alpha, 0);
  return out;
}

// The smaller of PNG and JPEG (JPEG only without alpha) for a derived level.
TextureLevel derived_level(const Pixels& p, uint32_t index, uint32_t level, const std::string& name,
                           bool prefer_jpeg) {
  TextureLevel t;
  t.texture = index;
  t.level = level;
  t.name = name;
  t.width = uint32_t(p.width);
  t.height = uint32_t(p.height);
  t.format = ImageFormat::kPng;
  t.bytes = encode_png(p);
  const bool opaque = p.channels == 1 || p.channels == 3;
  if (opaque) {
    std::vector<uint8_t> jpeg = encode_jpeg(p, prefer_jpeg ? 85 : 80);
    if (!jpeg.empty() && (prefer_jpeg || jpeg.size() < t.bytes.size())) {
      t.bytes = std::move(jpeg);
      t.format = ImageFormat::kJpeg;
    }
  }
  return t;
}

}  // namespace

Result<std::vector<TextureLevel>> texture_levels(const Texture& texture, uint32_t index,
                                                 size_t preview_bytes,
                                                 const TextureStreamOptions& options) {
  const std::string what = "texture " + std::to_string(index) + " (\"" + texture.name + "\")";
  auto facts = check_image(texture.bytes, what);
  if (!facts) {
    return make_error(ErrorCode::kInvalidMesh,
                      facts.error().message + ": it cannot be carried in the stream");
  }
  TextureLevel original;
  original.texture = index;
  original.original = true;
  original.format = facts->format;
  original.width = facts->width;
  original.height = facts->height;
  original.name = texture.name;
  original.bytes = texture.bytes;

  std::vector<TextureLevel> levels;
  const uint32_t long_side = std::max(facts->width, facts->height);
  constexpr int kPreviewSides[] = {32, 16, 8, 4, 2, 1};
  // What the preview adds to the first display besides its image: the
  // record's flags, varints, name and CRC trailer (12 + name), and the
  // index entries of the texture's records, which come before the base
  // (about 4 bytes each, for up to 3 levels).
  const size_t record_overhead = 24 + std::min<size_t>(texture.name.size(), kMaxTextureNameBytes);
  if (long_side > uint32_t(kPreviewSides[std::size(kPreviewSides) - 1])) {
    Pixels pixels;
    std::unique_ptr<uint8_t, void (*)(void*)> decoded(
        stbi_load_from_memory(texture.bytes.data(), int(texture.bytes.size()), &pixels.width,
                              &pixels.height, &pixels.channels, 0),
        stbi_image_free);
    if (!decoded) {
      return make_error(ErrorCode::kInvalidMesh, what + ": the image does not decode (" +
                                                     stbi_failure_reason() +
                                                     "): it cannot be carried in the stream");
    }
    pixels.data.assign(decoded.get(),
                       decoded.get() + size_t(pixels.width) * pixels.height * pixels.channels);
    // The preview: the largest side that fits, the smallest otherwise.
    TextureLevel preview;
    for (int side : kPreviewSides) {
      if (uint32_t(side) >= long_side) continue;
      preview = derived_level(scaled(pixels, side), index, 0, texture.name, false);
      if (preview.bytes.size() + record_overhead <= preview_bytes) break;
    }
    if (!preview.bytes.empty()) levels.push_back(std::move(preview));
    if (options.middle_side > 0 && long_side >= 2 * options.middle_side) {
      TextureLevel middle = derived_level(scaled(pixels, int(options.middle_side)), index,
                                          uint32_t(levels.size()), texture.name, true);
      // Only worth its bytes when well under the original's (a flat-coloured
      // PNG can be smaller than its own JPEG middle level).
      if (2 * middle.bytes.size() < texture.bytes.size()) levels.push_back(std::move(middle));
    }
  }
  original.level = uint32_t(levels.size());
  levels.push_back(std::move(original));
  return levels;
}

Result<std::vector<uint8_t>> add_texture_records(std::vector<uint8_t> stream,
                                                 const std::vector<Texture>& textures,
                                                 const TextureStreamOptions& options) {
  if (textures.empty()) return stream;
  if (textures.size() > kMaxStreamTextures) {
    return make_error(ErrorCode::kLimit, std::to_string(textures.size()) +
                                             " textures (a stream carries at most " +
                                             std::to_string(kMaxStreamTextures) + ")");
  }
  auto index = read_stream_index(stream);
  if (!index) return tl::unexpected(index.error());
  const std::vector<RecordEntry>& records = index->records;
  const uint64_t first_display = index->payload_offset + records[0].size;
  const size_t preview_bytes = size_t(
      std::max(1.0, options.preview_share * double(first_display) / double(textures.size())));

  std::vector<TextureLevel> previews;
  std::deque<TextureLevel> later;  // middle levels of every texture first, then the originals
  std::vector<TextureLevel> originals;
  for (uint32_t t = 0; t < textures.size(); ++t) {
    auto levels = texture_levels(textures[t], t, preview_bytes, options);
    if (!levels) return tl::unexpected(levels.error());
    for (TextureLevel& level : *levels) {
      if (level.level == 0)  // an image no larger than a preview goes whole, first
        previews.push_back(std::move(level));
      else if (!level.original)
        later.push_back(std::move(level));
      else
        originals.push_back(std::move(level));
    }
  }
  for (TextureLevel& o : originals) later.push_back(std::move(o));

  std::vector<std::vector<uint8_t>> payloads;
  std::vector<RecordCounts> counts;
  auto add = [&](std::vector<uint8_t> payload, RecordCounts c) {
    payloads.push_back(std::move(payload));
    counts.push_back(c);
  };
  uint64_t texture_bytes = 0;  // of the levels after the previews
  // The previews follow the base, or the base's attribute record where
  // there is one: its texture coordinates are what makes a preview visible.
  auto starts_with = [&](size_t i, uint8_t flag) {
    return i < records.size() && records[i].size > kRecordTrailerBytes &&
           stream[records[i].offset] == flag;
  };
  const size_t previews_after = starts_with(1, kRecordAttributes) ? 1 : 0;
  for (size_t i = 0; i < records.size(); ++i) {
    const RecordEntry& r = records[i];
    const std::span<const uint8_t> bytes(stream.data() + r.offset, r.size);
    const auto payload = record_payload(r, bytes);
    add(std::vector<uint8_t>(payload.begin(), payload.end()), {r.vertices, r.faces});
    if (i <= previews_after) {
      if (i == previews_after) {
        for (TextureLevel& p : previews) add(write_texture_record(p), {r.vertices, r.faces});
      }
      continue;
    }
    const double geometry = double(r.offset + r.size);
    while (!later.empty()) {
      std::vector<uint8_t> next = write_texture_record(later.front());
      const double after = double(texture_bytes + next.size());
      if (geometry < options.geometry_per_texture_byte * after) break;
      texture_bytes += next.size();
      add(std::move(next), {r.vertices, r.faces});
      later.pop_front();
    }
  }
  for (TextureLevel& rest : later) {
    add(write_texture_record(rest), {records.back().vertices, records.back().faces});
  }
  auto written = write_container(index->header, payloads, counts);
  if (!written) return tl::unexpected(written.error());
  return std::move(written->bytes);
}

}  // namespace meshstream

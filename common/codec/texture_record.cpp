// Texture records: see texture_record.h.
#include "common/codec/texture_record.h"

#include <stb_image.h>

#include <algorithm>
#include <cstring>

#include "common/codec/byte_io.h"

namespace meshstream {

namespace {

constexpr uint8_t kPngSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
// The last chunk of every PNG file: length 0, "IEND", its CRC-32.
constexpr uint8_t kPngEnd[12] = {0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xAE, 0x42, 0x60, 0x82};

uint32_t big_endian_u32(const uint8_t* p) {
  return uint32_t(p[0]) << 24 | uint32_t(p[1]) << 16 | uint32_t(p[2]) << 8 | uint32_t(p[3]);
}

Error parse_error(const std::string& what, const std::string& problem) {
  return Error{ErrorCode::kParse, what + ": " + problem};
}

}  // namespace

const char* mime_type_of(ImageFormat format) {
  return format == ImageFormat::kJpeg ? "image/jpeg" : "image/png";
}

Result<ImageFacts> check_image(std::span<const uint8_t> bytes, const std::string& what) {
  ImageFacts facts;
  if (bytes.size() >= 8 && std::memcmp(bytes.data(), kPngSignature, 8) == 0) {
    facts.format = ImageFormat::kPng;
    // Signature, IHDR (length 13, type, 13 bytes, CRC), IEND.
    if (bytes.size() < 8 + 25 + 12 || big_endian_u32(bytes.data() + 8) != 13 ||
        std::memcmp(bytes.data() + 12, "IHDR", 4) != 0) {
      return tl::unexpected(parse_error(what, "PNG image without an IHDR header chunk"));
    }
    facts.width = big_endian_u32(bytes.data() + 16);
    facts.height = big_endian_u32(bytes.data() + 20);
    // glTF buffer views are padded to 4 bytes: zeros after IEND are allowed
    // (its CRC ends in 0x82, so they cannot be part of it).
    size_t end = bytes.size();
    while (end > 8 + 25 + 12 && bytes[end - 1] == 0) --end;
    if (std::memcmp(bytes.data() + end - 12, kPngEnd, 12) != 0) {
      return tl::unexpected(
          parse_error(what, "PNG image is truncated (it does not end with an IEND chunk)"));
    }
  } else if (bytes.size() >= 3 && bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[2] == 0xFF) {
    facts.format = ImageFormat::kJpeg;
    // Some writers pad after the end-of-image marker; zero bytes only.
    size_t end = bytes.size();
    while (end > 0 && bytes[end - 1] == 0) --end;
    if (end < 4 || bytes[end - 2] != 0xFF || bytes[end - 1] != 0xD9) {
      return tl::unexpected(
          parse_error(what, "JPEG image is truncated (no end-of-image marker at its end)"));
    }
    int w = 0, h = 0, n = 0;
    if (bytes.size() > uint64_t(INT32_MAX) ||
        !stbi_info_from_memory(bytes.data(), int(bytes.size()), &w, &h, &n)) {
      return tl::unexpected(parse_error(what, "JPEG image has no readable frame header"));
    }
    facts.width = uint32_t(w);
    facts.height = uint32_t(h);
  } else {
    return tl::unexpected(parse_error(what, "not a PNG or JPEG image (unknown signature)"));
  }
  if (facts.width == 0 || facts.height == 0 || facts.width > kMaxTextureSide ||
      facts.height > kMaxTextureSide) {
    return tl::unexpected(parse_error(
        what, "image of " + std::to_string(facts.width) + " x " + std::to_string(facts.height) +
                  " pixels (1.." + std::to_string(kMaxTextureSide) + " a side allowed)"));
  }
  return facts;
}

std::vector<uint8_t> write_texture_record(const TextureLevel& level) {
  std::vector<uint8_t> out;
  out.reserve(level.bytes.size() + level.name.size() + 24);
  out.push_back(kRecordTexture);
  out.push_back(level.original ? kTextureLevelOriginal : 0);
  put_varint(out, level.texture);
  put_varint(out, level.level);
  out.push_back(static_cast<uint8_t>(level.format));
  put_varint(out, level.width);
  put_varint(out, level.height);
  const size_t name_bytes = std::min<size_t>(level.name.size(), kMaxTextureNameBytes);
  put_varint(out, static_cast<uint32_t>(name_bytes));
  out.insert(out.end(), level.name.begin(), level.name.begin() + name_bytes);
  out.insert(out.end(), level.bytes.begin(), level.bytes.end());
  return out;
}

Result<TextureLevel> read_texture_record(std::span<const uint8_t> payload) {
  TextureLevel t;
  auto fail = [&](const std::string& problem) -> Result<TextureLevel> {
    return make_error(ErrorCode::kParse, "texture record: " + problem);
  };
  if (payload.size() < 2 || payload[0] != kRecordTexture) return fail("not a texture record");
  if (payload[1] & ~kTextureLevelOriginal)
    return fail("unknown level flags " + std::to_string(payload[1]));
  t.original = payload[1] & kTextureLevelOriginal;
  size_t pos = 2;
  uint32_t name_bytes = 0;
  if (!get_varint(payload, pos, t.texture) || !get_varint(payload, pos, t.level) ||
      pos >= payload.size()) {
    return fail("header is cut short");
  }
  const uint8_t format = payload[pos++];
  if (!get_varint(payload, pos, t.width) || !get_varint(payload, pos, t.height) ||
      !get_varint(payload, pos, name_bytes)) {
    return fail("header is cut short");
  }
  if (t.texture >= kMaxStreamTextures) {
    return fail("texture index " + std::to_string(t.texture) + " (at most " +
                std::to_string(kMaxStreamTextures) + " textures)");
  }
  if (name_bytes > kMaxTextureNameBytes || name_bytes > payload.size() - pos) {
    return fail("texture " + std::to_string(t.texture) + ": name of " + std::to_string(name_bytes) +
                " bytes does not fit the record");
  }
  t.name.assign(reinterpret_cast<const char*>(payload.data() + pos), name_bytes);
  pos += name_bytes;
  const std::string what = "texture " + std::to_string(t.texture) + " (\"" + t.name + "\") level " +
                           std::to_string(t.level);
  if (format != uint8_t(ImageFormat::kPng) && format != uint8_t(ImageFormat::kJpeg)) {
    return make_error(ErrorCode::kParse, what + ": unknown image format " + std::to_string(format) +
                                             " (1 PNG, 2 JPEG)");
  }
  t.format = ImageFormat(format);
  const std::span<const uint8_t> image = payload.subspan(pos);
  auto facts = check_image(image, what);
  if (!facts) return tl::unexpected(facts.error());
  if (facts->format != t.format) {
    return make_error(ErrorCode::kParse, what + ": the record says " +
                                             (t.format == ImageFormat::kPng ? "PNG" : "JPEG") +
                                             " but the bytes are " +
                                             (facts->format == ImageFormat::kPng ? "PNG" : "JPEG"));
  }
  if (facts->width != t.width || facts->height != t.height) {
    return make_error(ErrorCode::kParse,
                      what + ": the record says " + std::to_string(t.width) + " x " +
                          std::to_string(t.height) + " pixels, the image is " +
                          std::to_string(facts->width) + " x " + std::to_string(facts->height));
  }
  t.bytes.assign(image.begin(), image.end());
  return t;
}

}  // namespace meshstream

// Texture records: an image of Mesh::textures travelling in the `.hcs`
// stream as a record of its own (docs/hcs-format.md, "Texture records").
// A texture comes as levels of a pyramid, smallest first, the last one the
// original file's bytes; each level replaces the one before it on the
// decoded mesh. The server serves them as any record (it never decodes);
// the decoder checks each one against what it claims to be before showing
// it.
//
// Payload (after the flag byte kRecordTexture):
//   u8     level flags: bit 0 = this level is the original image (the last)
//   varint texture index (into Mesh::textures; < kMaxStreamTextures)
//   varint level (0 = the smallest; increases by record for one texture)
//   u8     image format: 1 = PNG, 2 = JPEG
//   varint width, varint height (pixels; 1..kMaxTextureSide)
//   varint name length (<= kMaxTextureNameBytes), name bytes
//   the image file's bytes (the rest of the payload)
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "common/base/result.h"
#include "common/codec/stream_format.h"
#include "common/mesh/attributes.h"

namespace meshstream {

// The first payload byte is kRecordTexture (stream_format.h).
inline constexpr uint8_t kTextureLevelOriginal = 1;  // level flags bit 0

inline constexpr uint32_t kMaxStreamTextures = 1024;
inline constexpr uint32_t kMaxTextureSide = 16384;
inline constexpr uint32_t kMaxTextureNameBytes = 4096;

enum class ImageFormat : uint8_t { kPng = 1, kJpeg = 2 };

const char* mime_type_of(ImageFormat format);

// One level of one texture, as a texture record holds it.
struct TextureLevel {
  uint32_t texture = 0;  // index into Mesh::textures
  uint32_t level = 0;
  bool original = false;
  ImageFormat format = ImageFormat::kPng;
  uint32_t width = 0, height = 0;
  std::string name;
  std::vector<uint8_t> bytes;  // the PNG or JPEG file
};

// The payload of a texture record (without the CRC trailer).
std::vector<uint8_t> write_texture_record(const TextureLevel& level);

// Reads a texture record's payload and checks that its image is what the
// record says: the format's signature, the declared width and height (from
// the image's own header), and a whole file (PNG: an IEND chunk at its end;
// JPEG: an end-of-image marker). kParse naming the texture (index, name,
// level) and the problem otherwise. Never decodes pixels. O(size).
Result<TextureLevel> read_texture_record(std::span<const uint8_t> payload);

// Checks that `bytes` is a whole PNG or JPEG image and finds its format and
// size; kParse with `what` in front of the problem otherwise.
struct ImageFacts {
  ImageFormat format = ImageFormat::kPng;
  uint32_t width = 0, height = 0;
};
Result<ImageFacts> check_image(std::span<const uint8_t> bytes, const std::string& what);

}  // namespace meshstream

#include "common/mesh/texture_files.h"

#include <filesystem>

#include "common/mesh/mesh_readers.h"

namespace meshstream {

std::string image_mime_type(const std::vector<uint8_t>& bytes) {
  static const uint8_t kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  if (bytes.size() >= 8 && std::equal(kPng, kPng + 8, bytes.begin())) return "image/png";
  if (bytes.size() >= 3 && bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[2] == 0xFF)
    return "image/jpeg";
  return {};
}

Result<Texture> read_texture_file(const std::string& path) {
  auto bytes = read_file_bytes(path);
  if (!bytes) return tl::unexpected(std::move(bytes.error()).with_context(path));
  Texture texture;
  texture.name = std::filesystem::path(path).filename().string();
  texture.bytes.assign(bytes->begin(), bytes->end());
  texture.mime_type = image_mime_type(texture.bytes);
  if (texture.mime_type.empty()) {
    return make_error(ErrorCode::kUnsupported, path + ": not a PNG or JPEG image");
  }
  return texture;
}

std::string texture_extension(const Texture& texture) {
  if (texture.mime_type == "image/png") return ".png";
  if (texture.mime_type == "image/jpeg") return ".jpg";
  return ".bin";
}

}  // namespace meshstream

// Image files as textures (attributes.h): read byte for byte, never decoded
// or re-encoded, so export writes the same file back.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "common/base/result.h"
#include "common/mesh/attributes.h"

namespace meshstream {

// "image/png" or "image/jpeg" from the bytes' signature; "" for anything
// else (glTF carries only these two without extensions).
std::string image_mime_type(const std::vector<uint8_t>& bytes);

// The file's bytes as a Texture named by the file name (without folder).
// kIo when it cannot be read, kUnsupported when it is not PNG or JPEG.
Result<Texture> read_texture_file(const std::string& path);

// File extension for the texture's type: ".png", ".jpg" (".bin" otherwise).
std::string texture_extension(const Texture& texture);

}  // namespace meshstream

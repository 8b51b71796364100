// Puts a mesh's textures into an encoded `.hcs` stream as texture records
// (texture_record.h), interleaved with the geometry:
//
// - a preview of every texture (a small pyramid level made with stb) right
//   after the base record, sized so that the first display costs at most
//   `preview_share` more bytes than the base alone (header, index, base);
// - a middle level (`middle_side` pixels on the long side) and the original
//   bytes later, each after the first geometry record at whose end the
//   geometry so far has at least `geometry_per_texture_byte` times the
//   texture bytes sent so far (that level included): beyond the preview,
//   textures take at most 1 / (1 + geometry_per_texture_byte) of any prefix
//   that ends at a texture record, and whatever is left goes at the end.
//
// Texture records add no vertex or face: the index lists them with the
// counts of the record before them, so byte budgets, record budgets and
// resume work for them as for any record, and the server needs nothing new.
#pragma once

#include <cstdint>
#include <vector>

#include "common/base/result.h"
#include "common/codec/texture_record.h"
#include "common/mesh/attributes.h"

namespace meshstream {

struct TextureStreamOptions {
  double preview_share = 0.10;  // of the first display's bytes, for all previews together
  uint32_t middle_side = 128;   // long side of the middle level, pixels (0: none)
  double geometry_per_texture_byte = 1.0;
};

// The pyramid levels of `texture` (index `index`), smallest first, the
// last the original bytes: a preview whose record fits `preview_bytes` (the
// largest long side of 32, 16, 8, 4, 2, 1 pixels whose PNG or JPEG, with
// the record's own bytes, does; 1 pixel when none does), the middle level
// when the image is at least twice its size and the level under half the
// original's bytes, then the original. A 1-pixel image goes as its
// original alone. kInvalidMesh naming the texture when its bytes are not a
// whole PNG or JPEG image (check_image). O(pixels).
Result<std::vector<TextureLevel>> texture_levels(const Texture& texture, uint32_t index,
                                                 size_t preview_bytes,
                                                 const TextureStreamOptions& options);

// `stream` (a whole version-3 stream from the encoder) with the texture
// records of `textures` inserted as described above; unchanged when there
// are none. O(stream + texture bytes + pixels).
Result<std::vector<uint8_t>> add_texture_records(std::vector<uint8_t> stream,
                                                 const std::vector<Texture>& textures,
                                                 const TextureStreamOptions& options = {});

}  // namespace meshstream

// Binary STL: an 80-byte header, a triangle count, then 50 bytes a
// triangle (facet normal, three corners, an attribute byte count). Read
// here straight into the mesh's arrays, a fixed-size chunk at a time: no
// copy of the file and no intermediate mesh (Draco's StlDecoder, used
// before, built its own mesh that was then converted; at 6M triangles that
// was two extra copies of the mesh). The corners stay three per triangle in
// file order (vertex 3f + i is corner i of triangle f), as Draco gave them;
// clean_mesh welds them.
//
// The facet normals are not kept, as the ASCII reader does not keep them:
// they are one value per triangle, which the mesh could only hold as a
// per-corner attribute with a seam at every vertex. That blocked decimation
// at every vertex (bunny.stl streamed as a 34 756-vertex base, 395 KB,
// against 90 KB for the same surface from bun_zipper.ply) and carried
// nothing a reader cannot recompute from the corners: writers derive them
// from the winding (ours does, see write_stl).
#include <bit>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string_view>
#include <vector>

#include "common/mesh/mesh_readers.h"

namespace meshstream {
namespace {

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};

constexpr size_t kRecordBytes = 50;

}  // namespace

Result<RawMesh> read_stl(const std::string& path) {
  std::unique_ptr<std::FILE, FileCloser> file(std::fopen(path.c_str(), "rb"));
  if (!file) return make_error(ErrorCode::kIo, "cannot open the file for reading");
  char header[84] = {};
  const size_t got = std::fread(header, 1, sizeof header, file.get());
  uint32_t count = 0;
  std::memcpy(&count, header + 80, 4);
  uint64_t size = 0;
  if (std::fseek(file.get(), 0, SEEK_END) == 0) {
    const long end = std::ftell(file.get());
    if (end > 0) size = static_cast<uint64_t>(end);
  }
  // A binary STL has exactly 84 + 50 * count bytes; anything else starting
  // with "solid" is text. (A damaged count must not size an allocation.)
  if (got < 84 || size != 84 + kRecordBytes * count) {
    if (std::string_view(header, std::min<size_t>(got, 5)) == "solid") {
      file.reset();
      return read_ascii_stl(path);
    }
    return make_error(ErrorCode::kParse, "not a binary STL: " + std::to_string(size) +
                                             " bytes, but the header announces " +
                                             std::to_string(count) + " triangles (" +
                                             std::to_string(84 + 50ull * count) + " bytes)");
  }
  if (3ull * count > 0xFFFFFFFEull) {
    return make_error(ErrorCode::kInvalidMesh,
                      std::to_string(count) + " triangles: more corners than 32-bit indices hold");
  }
  if (std::fseek(file.get(), 84, SEEK_SET) != 0) return make_error(ErrorCode::kIo, "read failed");

  RawMesh raw;
  Mesh& mesh = raw.mesh;
  mesh.positions.resize(3 * static_cast<size_t>(count));
  mesh.triangles.resize(count);
  constexpr uint32_t kChunk = 8192;  // triangles per read: 400 KB
  std::vector<unsigned char> chunk(kChunk * kRecordBytes);
  for (uint32_t first = 0; first < count; first += kChunk) {
    const uint32_t n = std::min(kChunk, count - first);
    if (std::fread(chunk.data(), kRecordBytes, n, file.get()) != n)
      return make_error(ErrorCode::kIo, "read failed");
    for (uint32_t k = 0; k < n; ++k) {
      const uint32_t f = first + k;
      // Little-endian floats, as the format defines them (and export writes).
      static_assert(std::endian::native == std::endian::little && sizeof(Vec3f) == 12,
                    "binary STL reader assumes little-endian floats");
      std::memcpy(&mesh.positions[3 * static_cast<size_t>(f)], chunk.data() + k * kRecordBytes + 12,
                  36);
      mesh.triangles[f] = {3 * f, 3 * f + 1, 3 * f + 2};
    }
  }
  raw.vertices_in_file = 3 * count;
  raw.contents.normals.count = count;
  if (count > 0)
    raw.contents.normals.dropped = "STL normals are per facet, not per vertex (not read)";
  return raw;
}

}  // namespace meshstream

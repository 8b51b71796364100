// ASCII STL ("solid ... facet normal ... outer loop vertex x y z ...").
// Draco reads binary STL only; text STL is still common from CAD tools.
// Every facet has its own three corners, welded later by clean_mesh.
#include <cctype>
#include <charconv>
#include <string_view>

#include "common/mesh/mesh_readers.h"

namespace meshstream {

Result<RawMesh> read_ascii_stl(const std::string& path) {
  auto bytes = read_file_bytes(path);
  if (!bytes) return tl::unexpected(bytes.error());
  const std::string& text = *bytes;

  RawMesh raw;
  Mesh& mesh = raw.mesh;
  size_t pos = 0;
  uint32_t line = 1;
  auto next_token = [&](std::string_view& token) {
    while (pos < text.size() && std::isspace(static_cast<unsigned char>(text[pos]))) {
      line += text[pos] == '\n';
      ++pos;
    }
    const size_t start = pos;
    while (pos < text.size() && !std::isspace(static_cast<unsigned char>(text[pos]))) ++pos;
    token = std::string_view(text.data() + start, pos - start);
    return !token.empty();
  };
  std::string_view token;
  if (!next_token(token) || token != "solid") {
    return make_error(ErrorCode::kParse, "not an ASCII STL file (no 'solid' keyword)");
  }
  bool ended = false;
  uint64_t facet_normals = 0;
  while (next_token(token)) {
    if (token == "endsolid") {
      ended = true;
      break;
    }
    if (token == "normal") ++facet_normals;  // per facet: never a per-vertex attribute
    if (token != "vertex") continue;         // facet, normal, outer, loop, names: structure only
    Vec3f p;
    for (int i = 0; i < 3; ++i) {
      std::string_view number;
      if (!next_token(number))
        return make_error(ErrorCode::kTruncated,
                          "line " + std::to_string(line) + ": the file ends inside a vertex");
      const char* first = number.data() + (number[0] == '+' ? 1 : 0);
      auto [ptr, ec] = std::from_chars(first, number.data() + number.size(), p[i]);
      if (ec != std::errc() || ptr != number.data() + number.size()) {
        return make_error(ErrorCode::kParse, "line " + std::to_string(line) + ": '" +
                                                 std::string(number) + "' is not a number");
      }
    }
    mesh.positions.push_back(p);
  }
  if (!ended) return make_error(ErrorCode::kTruncated, "the file ends without 'endsolid'");
  if (mesh.positions.size() % 3 != 0) {
    return make_error(ErrorCode::kParse, std::to_string(mesh.positions.size()) +
                                             " vertices: not a whole number of triangles");
  }
  const uint32_t faces = static_cast<uint32_t>(mesh.positions.size() / 3);
  mesh.triangles.resize(faces);
  for (uint32_t f = 0; f < faces; ++f) mesh.triangles[f] = {3 * f, 3 * f + 1, 3 * f + 2};
  raw.vertices_in_file = static_cast<uint32_t>(mesh.positions.size());
  raw.contents.format = "STL (ascii)";
  raw.contents.normals.count = facet_normals;
  if (facet_normals > 0)
    raw.contents.normals.dropped = "STL normals are per facet, not per vertex (not read)";
  return raw;
}

}  // namespace meshstream

// OFF reader. Draco has none, and OFF is the common format of geometry
// processing data sets (the Princeton shape benchmark, pmp-library's data).
// Format: optional keyword line ([ST][C][N][4][n]OFF), then
// "vertices faces edges", then one vertex per line (x y z, then normal,
// colour, texture coordinates as the keyword announces), then one face per
// line ("n i0 ... i(n-1)" and an optional colour that we ignore).
#include <charconv>
#include <cstring>
#include <string_view>

#include "common/mesh/mesh_readers.h"

namespace meshstream {
namespace {

struct OffLayout {
  bool texcoords = false, colors = false, normals = false;
};

class LineReader {
 public:
  explicit LineReader(std::string text) : text_(std::move(text)) {}

  // Next line that has content after stripping a # comment; false at the end.
  bool next(std::string_view& line) {
    while (pos_ < text_.size()) {
      size_t end = text_.find('\n', pos_);
      if (end == std::string::npos) end = text_.size();
      std::string_view l(text_.data() + pos_, end - pos_);
      pos_ = end + 1;
      ++line_number_;
      if (size_t hash = l.find('#'); hash != std::string_view::npos) l = l.substr(0, hash);
      size_t a = l.find_first_not_of(" \t\r\f\v");
      if (a == std::string_view::npos) continue;
      size_t b = l.find_last_not_of(" \t\r\f\v");
      line = l.substr(a, b - a + 1);
      return true;
    }
    return false;
  }
  uint32_t line_number() const { return line_number_; }

 private:
  std::string text_;
  size_t pos_ = 0;
  uint32_t line_number_ = 0;
};

// Splits on blanks; `out` is reused to avoid allocation per line.
void split(std::string_view line, std::vector<std::string_view>& out) {
  out.clear();
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t' && line[j] != '\r') ++j;
    if (j > i) out.push_back(line.substr(i, j - i));
    i = j;
  }
}

bool parse_float(std::string_view token, float& value) {
  if (!token.empty() && token[0] == '+') token.remove_prefix(1);
  auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  return ec == std::errc() && ptr == token.data() + token.size();
}

bool parse_uint(std::string_view token, uint64_t& value) {
  auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  return ec == std::errc() && ptr == token.data() + token.size();
}

// Recognizes the keyword; false when the line is not a keyword line.
bool parse_keyword(std::string_view word, OffLayout& layout, bool& unsupported) {
  if (word.size() < 3 || word.substr(word.size() - 3) != "OFF") return false;
  std::string_view prefix = word.substr(0, word.size() - 3);
  if (prefix.substr(0, 2) == "ST") {
    layout.texcoords = true;
    prefix.remove_prefix(2);
  }
  if (!prefix.empty() && prefix[0] == 'C') {
    layout.colors = true;
    prefix.remove_prefix(1);
  }
  if (!prefix.empty() && prefix[0] == 'N') {
    layout.normals = true;
    prefix.remove_prefix(1);
  }
  // "4OFF" (homogeneous) and "nOFF" (any dimension) are not triangle meshes in 3-D.
  unsupported = !prefix.empty();
  return true;
}

std::string at_line(uint32_t line) { return "line " + std::to_string(line) + ": "; }

struct OffHeader {
  OffLayout layout;
  uint64_t vertex_count = 0, face_count = 0;
};

// The keyword line (optional) and the "vertices faces edges" counts; `tokens`
// is scratch. Counts that cannot fit in the file are refused.
Result<OffHeader> read_header(LineReader& reader, size_t file_size,
                              std::vector<std::string_view>& tokens) {
  std::string_view line;
  if (!reader.next(line)) return make_error(ErrorCode::kParse, "empty OFF file");
  split(line, tokens);
  OffHeader header;
  bool unsupported = false;
  size_t first_count = 0;
  if (parse_keyword(tokens[0], header.layout, unsupported)) {
    if (unsupported) {
      return make_error(ErrorCode::kUnsupported, at_line(reader.line_number()) + "OFF variant '" +
                                                     std::string(tokens[0]) +
                                                     "' is not supported (only 3-D [ST][C][N]OFF)");
    }
    first_count = 1;
    if (tokens.size() == 1) {
      if (!reader.next(line))
        return make_error(ErrorCode::kTruncated, "OFF file ends after its keyword");
      split(line, tokens);
      first_count = 0;
    }
  }
  uint64_t& vertex_count = header.vertex_count;
  uint64_t& face_count = header.face_count;
  if (tokens.size() < first_count + 2 || !parse_uint(tokens[first_count], vertex_count) ||
      !parse_uint(tokens[first_count + 1], face_count)) {
    return make_error(ErrorCode::kParse,
                      at_line(reader.line_number()) + "expected 'vertices faces edges' counts");
  }
  // Every vertex needs at least 6 bytes ("0 0 0\n"), every face 8: counts that
  // cannot fit in the file are lies, refused before allocating for them.
  if (vertex_count > file_size / 6 + 1 || face_count > file_size / 8 + 1) {
    return make_error(ErrorCode::kParse, at_line(reader.line_number()) + "counts (" +
                                             std::to_string(vertex_count) + " vertices, " +
                                             std::to_string(face_count) +
                                             " faces) cannot fit in a file of " +
                                             std::to_string(file_size) + " bytes");
  }
  return header;
}

// One line per vertex: x y z, then normal, colour (3 or 4 numbers) and
// texture coordinates as the keyword announces.
Status read_vertices(LineReader& reader, const OffHeader& header,
                     std::vector<std::string_view>& tokens, Mesh& mesh) {
  const OffLayout& layout = header.layout;
  const uint64_t vertex_count = header.vertex_count;
  mesh.positions.resize(vertex_count);
  if (layout.normals) mesh.normals.resize(vertex_count);
  if (layout.colors) mesh.colors.resize(vertex_count);
  if (layout.texcoords) mesh.texcoords.resize(vertex_count);
  const size_t needed = 3 + (layout.normals ? 3 : 0) + (layout.texcoords ? 2 : 0);
  bool colors_are_bytes = false;
  std::string_view line;
  for (uint64_t v = 0; v < vertex_count; ++v) {
    if (!reader.next(line)) {
      return make_error(ErrorCode::kTruncated, "file ends after " + std::to_string(v) + " of " +
                                                   std::to_string(vertex_count) + " vertices");
    }
    split(line, tokens);
    const size_t color_tokens = layout.colors ? (tokens.size() >= needed + 4 ? 4 : 3) : 0;
    if (tokens.size() < needed + color_tokens) {
      return make_error(ErrorCode::kParse, at_line(reader.line_number()) + "vertex " +
                                               std::to_string(v) + " needs " +
                                               std::to_string(needed + color_tokens) +
                                               " numbers, found " + std::to_string(tokens.size()));
    }
    float values[12];
    for (size_t k = 0; k < needed + color_tokens; ++k) {
      if (!parse_float(tokens[k], values[k])) {
        return make_error(ErrorCode::kParse, at_line(reader.line_number()) + "vertex " +
                                                 std::to_string(v) + ": '" +
                                                 std::string(tokens[k]) + "' is not a number");
      }
    }
    size_t k = 0;
    mesh.positions[v] = {values[0], values[1], values[2]};
    k = 3;
    if (layout.normals) {
      mesh.normals[v] = {values[k], values[k + 1], values[k + 2]};
      k += 3;
    }
    if (layout.colors) {
      Vec4f c{values[k], values[k + 1], values[k + 2], color_tokens == 4 ? values[k + 3] : -1.0f};
      if (c.x > 1 || c.y > 1 || c.z > 1 || c.w > 1) colors_are_bytes = true;
      mesh.colors[v] = c;
      k += color_tokens;
    }
    if (layout.texcoords) mesh.texcoords[v] = {values[k], values[k + 1]};
  }
  if (layout.colors) {
    // Colours are 0..255 integers or 0..1 floats; a missing alpha is opaque.
    const float scale = colors_are_bytes ? 1.0f / 255.0f : 1.0f;
    for (Vec4f& c : mesh.colors) {
      const bool opaque = c.w < 0;
      c = {c.x * scale, c.y * scale, c.z * scale, opaque ? 1.0f : c.w * scale};
    }
  }
  return {};
}

// One line per face: "n i0 ... i(n-1)", fan-triangulated; a trailing colour
// is skipped (counted in `face_colors`).
Status read_faces(LineReader& reader, const OffHeader& header,
                  std::vector<std::string_view>& tokens, Mesh& mesh, uint64_t& face_colors) {
  const uint64_t vertex_count = header.vertex_count, face_count = header.face_count;
  mesh.triangles.reserve(face_count * 2);
  std::string_view line;
  for (uint64_t f = 0; f < face_count; ++f) {
    if (!reader.next(line)) {
      return make_error(ErrorCode::kTruncated, "file ends after " + std::to_string(f) + " of " +
                                                   std::to_string(face_count) + " faces");
    }
    split(line, tokens);
    uint64_t corners = 0;
    if (tokens.empty() || !parse_uint(tokens[0], corners)) {
      return make_error(ErrorCode::kParse, at_line(reader.line_number()) + "face " +
                                               std::to_string(f) +
                                               " must start with its vertex count");
    }
    if (corners < 3) {
      return make_error(ErrorCode::kParse,
                        at_line(reader.line_number()) + "face " + std::to_string(f) + " has " +
                            std::to_string(corners) + " vertices; a polygon needs at least 3");
    }
    if (tokens.size() < corners + 1) {
      return make_error(ErrorCode::kParse, at_line(reader.line_number()) + "face " +
                                               std::to_string(f) + " announces " +
                                               std::to_string(corners) + " vertices but lists " +
                                               std::to_string(tokens.size() - 1));
    }
    if (tokens.size() > corners + 1) ++face_colors;
    uint32_t first = 0, previous = 0;
    for (uint64_t k = 0; k < corners; ++k) {
      uint64_t index = 0;
      if (!parse_uint(tokens[k + 1], index)) {
        return make_error(ErrorCode::kParse,
                          at_line(reader.line_number()) + "face " + std::to_string(f) + ": '" +
                              std::string(tokens[k + 1]) + "' is not a vertex index");
      }
      if (index >= vertex_count) {
        return make_error(ErrorCode::kInvalidMesh,
                          at_line(reader.line_number()) + "face " + std::to_string(f) +
                              " refers to vertex " + std::to_string(index) +
                              " but there are only " + std::to_string(vertex_count));
      }
      const uint32_t i = static_cast<uint32_t>(index);
      if (k == 0) first = i;
      if (k >= 2) mesh.triangles.push_back({first, previous, i});
      previous = i;
    }
  }
  return {};
}

}  // namespace

Result<RawMesh> read_off(const std::string& path) {
  auto bytes = read_file_bytes(path);
  if (!bytes) return tl::unexpected(bytes.error());
  const size_t file_size = bytes->size();
  LineReader reader(std::move(*bytes));
  std::vector<std::string_view> tokens;
  auto header = read_header(reader, file_size, tokens);
  if (!header) return tl::unexpected(header.error());
  RawMesh raw;
  if (auto ok = read_vertices(reader, *header, tokens, raw.mesh); !ok)
    return tl::unexpected(ok.error());
  uint64_t face_colors = 0;
  if (auto ok = read_faces(reader, *header, tokens, raw.mesh, face_colors); !ok)
    return tl::unexpected(ok.error());
  raw.vertices_in_file = static_cast<uint32_t>(header->vertex_count);
  raw.contents.format = "OFF";
  const OffLayout& layout = header->layout;
  if (layout.normals) raw.contents.normals.count = header->vertex_count;
  if (layout.colors) raw.contents.colors.count = header->vertex_count;
  if (layout.texcoords) raw.contents.texcoords.count = header->vertex_count;
  if (face_colors > 0) {
    raw.contents.extra_properties.push_back("face colour (on " + std::to_string(face_colors) +
                                            " faces)");
  }
  return raw;
}

}  // namespace meshstream

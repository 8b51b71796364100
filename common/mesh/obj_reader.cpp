// OBJ reader (Wavefront's polygonal subset). Our own rather than Draco's:
// Debian's Draco 1.5 ObjDecoder writes outside a heap block on a malformed
// face token such as `7/3-3` (found by tests/fuzz, input in
// tests/fuzz/regressions/mesh_import/), and dereferences a missing position
// attribute when there is no `v` line. Untrusted OBJ text must never reach it.
//
// What the mesh gets is what the Draco path gave (checked against it on the
// real OBJ files in tests/mesh/obj_reader_test.cpp): one vertex per `v` line,
// polygons fan-triangulated as (c0, c(k-1), ck), and normals / texture
// coordinates kept per vertex when every face corner of a vertex carries the
// same value, per corner otherwise (seams: per-face values, as in a cube
// with sharp edges; the Draco path dropped them). In addition: usemtl
// groups as face materials, and per-vertex colours of the common
// `v x y z r g b` extension, relative (negative) indices, `\` line
// continuation, and strict errors: every index is range-checked, malformed
// numbers and corner tokens are refused with the line and the token.
//
// Speed: the file is read once into memory, lines are found with memchr,
// numbers parsed with std::from_chars; no stream or allocation per token.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string_view>

#include "common/mesh/mesh_readers.h"

namespace meshstream {
namespace {

constexpr uint32_t kAbsent = 0xFFFFFFFFu;

struct Corner {
  uint32_t v = kAbsent, vt = kAbsent, vn = kAbsent;
};

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

std::string at_line(uint32_t line) { return "line " + std::to_string(line) + ": "; }

// A token for an error message: at most 40 characters, control bytes escaped
// (fuzzed files put anything on a line).
std::string quoted(std::string_view token) {
  std::string out = "'";
  for (size_t i = 0; i < token.size() && i < 40; ++i) {
    const unsigned char c = static_cast<unsigned char>(token[i]);
    if (c >= 0x20 && c < 0x7f) {
      out += static_cast<char>(c);
    } else {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02x", c);
      out += hex;
    }
  }
  if (token.size() > 40) out += "...";
  return out + "'";
}

// Splits the next blank-separated token off `rest`; empty at the end.
std::string_view next_token(std::string_view& rest) {
  size_t a = 0;
  while (a < rest.size() && is_blank(rest[a])) ++a;
  size_t b = a;
  while (b < rest.size() && !is_blank(rest[b])) ++b;
  std::string_view token = rest.substr(a, b - a);
  rest.remove_prefix(b);
  return token;
}

// A whole token as a float. from_chars takes no '+' and no blanks; "inf" and
// "nan" are accepted (the caller decides what a non-finite value means).
// Magnitudes beyond float range become +-Inf, below it 0, as strtof does.
bool parse_float(std::string_view token, float& value) {
  if (token.size() > 1 && token[0] == '+' && token[1] != '-' && token[1] != '+')
    token.remove_prefix(1);
  const char* end = token.data() + token.size();
  auto [ptr, ec] = std::from_chars(token.data(), end, value);
  if (ec == std::errc::result_out_of_range) {
    double wide = 0;
    auto [wide_ptr, wide_ec] = std::from_chars(token.data(), end, wide);
    if (wide_ptr != end) return false;
    if (wide_ec == std::errc::result_out_of_range) {
      // Beyond double range too: 0 or Inf by the decimal exponent of the
      // first non-zero digit ("0.<400 zeros>1" is tiny, "1e400" huge).
      const size_t e = token.find_first_of("eE");
      const std::string_view mantissa = token.substr(0, e);
      const size_t dot = std::min(mantissa.find('.'), mantissa.size());
      const size_t first = mantissa.find_first_of("123456789");
      int64_t magnitude = first == std::string_view::npos ? 0
                          : first < dot                   ? static_cast<int64_t>(dot - first) - 1
                                                          : -static_cast<int64_t>(first - dot);
      if (e != std::string_view::npos) {
        std::string_view exponent = token.substr(e + 1);
        if (!exponent.empty() && exponent[0] == '+') exponent.remove_prefix(1);
        int64_t value10 = 0;
        auto [eptr, eec] =
            std::from_chars(exponent.data(), exponent.data() + exponent.size(), value10);
        if (eec == std::errc::result_out_of_range)
          value10 = exponent[0] == '-' ? -(1ll << 40) : (1ll << 40);
        magnitude += std::clamp<int64_t>(value10, -(1ll << 40), 1ll << 40);
      }
      wide = magnitude < 0 ? 0.0 : HUGE_VAL;
      if (token[0] == '-') wide = -wide;
    } else if (wide_ec != std::errc()) {
      return false;
    }
    value = static_cast<float>(wide);
    return true;
  }
  return ec == std::errc() && ptr == end;
}

bool finite(const float* values, int n) {
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(values[i])) return false;
  }
  return true;
}

std::string describe(const float* values, int n) {
  std::string out = "(";
  for (int i = 0; i < n; ++i) {
    if (i) out += ", ";
    if (std::isnan(values[i]))
      out += "NaN";
    else if (std::isinf(values[i]))
      out += values[i] > 0 ? "Inf" : "-Inf";
    else
      out += std::to_string(values[i]);
  }
  return out + ")";
}

// Keywords of the OBJ format that carry nothing a triangle mesh keeps:
// grouping, smoothing, materials, and free-form geometry.
bool is_ignored_keyword(std::string_view k) {
  static const std::string_view kIgnored[] = {
      "o",         "g",      "s",      "usemtl", "mtllib",   "vp",       "cstype",
      "deg",       "bmat",   "step",   "curv",   "curv2",    "surf",     "parm",
      "trim",      "hole",   "scrv",   "sp",     "end",      "con",      "mg",
      "lod",       "usemap", "maplib", "bevel",  "c_interp", "d_interp", "shadow_obj",
      "trace_obj", "ctech",  "stech",  "call",   "csh"};
  return std::find(std::begin(kIgnored), std::end(kIgnored), k) != std::end(kIgnored);
}

// The largest positive index of one kind and the line that used it first:
// positive indices may refer to elements defined later in the file (Draco
// and most readers allow it), so they are checked once the file is read.
struct LargestIndex {
  uint64_t index = 0;  // 1-based, as written
  uint32_t line = 0;
};

class ObjParser {
 public:
  Result<RawMesh> parse(std::string_view text);

 private:
  Status parse_line(std::string_view line);
  Status parse_vertex(std::string_view rest);
  Status parse_normal(std::string_view rest);
  Status parse_texcoord(std::string_view rest);
  Status parse_face(std::string_view rest);
  Status parse_corner(const char*& p, const char* end, Corner& corner);
  void reserve_for(std::string_view text);
  void add_triangle(const Corner& a, const Corner& b, const Corner& c);
  Status resolve(int64_t written, std::string_view token, const char* what, size_t count,
                 LargestIndex& largest, uint32_t& out);
  Status check_largest(const LargestIndex& largest, const char* what, const char* keyword,
                       size_t count) const;
  void gather_attributes(RawMesh& raw);

  uint32_t line_ = 0;
  std::vector<Vec3f> positions_;
  std::vector<Vec3f> colors_;  // of the vertices that have one, in order
  std::vector<Vec3f> normals_;
  std::vector<Vec2f> texcoords_;
  // Triangles (fan-triangulated polygons) and, once any corner has one, the
  // texture coordinate / normal index of every triangle corner (kAbsent
  // where a corner has none).
  std::vector<Triangle> triangles_;
  std::vector<uint32_t> corner_vt_, corner_vn_;
  std::vector<Corner> polygon_;  // reused per face line
  LargestIndex largest_v_, largest_vt_, largest_vn_;
  uint32_t vertices_with_color_ = 0;
  uint32_t first_bad_normal_line_ = 0, first_bad_texcoord_line_ = 0;
  uint32_t line_elements_ = 0, point_elements_ = 0, unknown_lines_ = 0;
  std::string first_unknown_;
  std::vector<std::string> material_libraries_, materials_used_;  // mtllib and usemtl names
  // Once a usemtl line came: every triangle's index into materials_used_
  // (kAbsent before the first usemtl).
  std::vector<uint32_t> face_materials_;
  uint32_t current_material_ = kAbsent;
  bool any_usemtl_ = false;
  std::string joined_;  // a logical line made of continued physical lines
};

Status ObjParser::parse_vertex(std::string_view rest) {
  float values[7];
  int n = 0;
  const char* p = rest.data();
  const char* const end = p + rest.size();
  for (;;) {
    while (p != end && is_blank(*p)) ++p;
    if (p == end) break;
    if (n == 7) {
      n = 8;
      break;
    }
    // Fast path: a plain number followed by a blank; anything else (a '+',
    // out of float range, garbage) through parse_float on the whole token.
    auto [ptr, ec] = std::from_chars(p, end, values[n]);
    if (ec != std::errc() || (ptr != end && !is_blank(*ptr))) {
      std::string_view tail(p, static_cast<size_t>(end - p));
      const std::string_view token = next_token(tail);
      if (!parse_float(token, values[n])) {
        return make_error(ErrorCode::kParse, at_line(line_) + "vertex " +
                                                 std::to_string(positions_.size()) + ": " +
                                                 quoted(token) + " is not a number");
      }
      ptr = token.data() + token.size();
    }
    p = ptr;
    ++n;
  }
  if (n != 3 && n != 4 && n != 6) {
    return make_error(ErrorCode::kParse,
                      at_line(line_) + "vertex " + std::to_string(positions_.size()) +
                          ": 'v' needs x y z, x y z w or x y z r g b; found " +
                          (n == 8 ? std::string("more than 7") : std::to_string(n)) + " numbers");
  }
  if (!finite(values, 3)) {
    return make_error(ErrorCode::kInvalidMesh,
                      at_line(line_) + "vertex " + std::to_string(positions_.size()) +
                          " has a non-finite coordinate (NaN/Inf): " + describe(values, 3));
  }
  if (positions_.size() >= kAbsent - 1) {
    return make_error(ErrorCode::kLimit, at_line(line_) + "more than 4 billion vertices");
  }
  positions_.push_back({values[0], values[1], values[2]});
  // The fourth number (a rational weight) only matters to free-form
  // geometry; Draco ignores it too.
  if (n == 6) {
    if (!finite(values + 3, 3)) {
      return make_error(ErrorCode::kParse,
                        at_line(line_) + "vertex " + std::to_string(positions_.size() - 1) +
                            " has a non-finite colour " + describe(values + 3, 3));
    }
    if (vertices_with_color_ + 1 == positions_.size())
      colors_.push_back({values[3], values[4], values[5]});
    ++vertices_with_color_;
  }
  return {};
}

Status ObjParser::parse_normal(std::string_view rest) {
  float n[3];
  int count = 0;
  for (std::string_view token = next_token(rest); !token.empty(); token = next_token(rest)) {
    if (count == 3 || !parse_float(token, n[count])) {
      return make_error(ErrorCode::kParse, at_line(line_) + "'vn' needs three numbers (" +
                                               quoted(token) + " is one too many or not a number)");
    }
    ++count;
  }
  if (count != 3) {
    return make_error(ErrorCode::kParse,
                      at_line(line_) + "'vn' needs three numbers, found " + std::to_string(count));
  }
  if (!finite(n, 3) && first_bad_normal_line_ == 0) first_bad_normal_line_ = line_;
  normals_.push_back({n[0], n[1], n[2]});
  return {};
}

Status ObjParser::parse_texcoord(std::string_view rest) {
  float t[3] = {0, 0, 0};
  int count = 0;
  for (std::string_view token = next_token(rest); !token.empty(); token = next_token(rest)) {
    if (count == 3 || !parse_float(token, t[count])) {
      return make_error(ErrorCode::kParse, at_line(line_) + "'vt' needs u [v [w]] (" +
                                               quoted(token) + " is one too many or not a number)");
    }
    ++count;
  }
  if (count == 0) return make_error(ErrorCode::kParse, at_line(line_) + "'vt' without numbers");
  if (!finite(t, 2) && first_bad_texcoord_line_ == 0) first_bad_texcoord_line_ = line_;
  texcoords_.push_back({t[0], t[1]});
  return {};
}

// One written index to a 0-based one. Negative indices count back from the
// elements defined so far (-1 = the last one), as the OBJ format says.
Status ObjParser::resolve(int64_t written, std::string_view token, const char* what, size_t count,
                          LargestIndex& largest, uint32_t& out) {
  if (written > 0) {
    if (written >= static_cast<int64_t>(kAbsent)) {
      return make_error(ErrorCode::kInvalidMesh,
                        at_line(line_) + "face corner " + quoted(token) + " refers to " + what +
                            " " + std::to_string(written) + ", far beyond any file");
    }
    if (static_cast<uint64_t>(written) > largest.index)
      largest = {static_cast<uint64_t>(written), line_};
    out = static_cast<uint32_t>(written - 1);
    return {};
  }
  if (written == 0) {
    return make_error(ErrorCode::kParse, at_line(line_) + "face corner " + quoted(token) +
                                             " has index 0 (OBJ counts from 1, or back from -1)");
  }
  if (written < -static_cast<int64_t>(count)) {  // not -written: INT64_MIN has no negation
    return make_error(ErrorCode::kInvalidMesh, at_line(line_) + "face corner " + quoted(token) +
                                                   ": relative index " + std::to_string(written) +
                                                   " reaches before the first " + what + " (" +
                                                   std::to_string(count) + " defined so far)");
  }
  out = static_cast<uint32_t>(static_cast<int64_t>(count) + written);
  return {};
}

// `i`, `i/j`, `i//k` or `i/j/k`: each a non-zero signed integer, nothing
// else, starting at `p` (not a blank) and ending at a blank or `end`.
Status ObjParser::parse_corner(const char*& p, const char* end, Corner& corner) {
  const char* const start = p;
  auto token = [&] {
    const char* e = start;
    while (e != end && !is_blank(*e)) ++e;
    return std::string_view(start, static_cast<size_t>(e - start));
  };
  auto malformed = [&] {
    return make_error(ErrorCode::kParse, at_line(line_) + "face corner " + quoted(token()) +
                                             " is malformed (expected i, i/j, i//k or i/j/k with "
                                             "integer indices)");
  };
  auto number = [&](int64_t& value) {
    auto [ptr, ec] = std::from_chars(p, end, value);
    if (ec != std::errc() || ptr == p) return false;
    p = ptr;
    return true;
  };
  auto at_token_end = [&] { return p == end || is_blank(*p); };
  int64_t v = 0, vt = 0, vn = 0;
  bool has_vt = false, has_vn = false;
  if (!number(v)) return malformed();
  if (!at_token_end()) {
    if (*p++ != '/') return malformed();
    if (p != end && *p == '/') {
      ++p;
      if (!number(vn)) return malformed();
      has_vn = true;
    } else {
      if (!number(vt)) return malformed();
      has_vt = true;
      if (!at_token_end()) {
        if (*p++ != '/' || !number(vn)) return malformed();
        has_vn = true;
      }
    }
    if (!at_token_end()) return malformed();
  }
  corner = Corner{};
  // Resolution of positive indices cannot fail but the rare cases; the
  // token is only materialized for messages.
  if (v > 0 && v < static_cast<int64_t>(kAbsent)) {
    if (static_cast<uint64_t>(v) > largest_v_.index) largest_v_ = {static_cast<uint64_t>(v), line_};
    corner.v = static_cast<uint32_t>(v - 1);
  } else if (auto s = resolve(v, token(), "vertex", positions_.size(), largest_v_, corner.v); !s) {
    return s;
  }
  if (has_vt) {
    if (auto s =
            resolve(vt, token(), "texture coordinate", texcoords_.size(), largest_vt_, corner.vt);
        !s) {
      return s;
    }
  }
  if (has_vn) {
    if (auto s = resolve(vn, token(), "normal", normals_.size(), largest_vn_, corner.vn); !s)
      return s;
  }
  return {};
}

void ObjParser::add_triangle(const Corner& a, const Corner& b, const Corner& c) {
  auto attribute = [&](std::vector<uint32_t>& indices, uint32_t Corner::*member) {
    if (indices.empty()) {
      if (a.*member == kAbsent && b.*member == kAbsent && c.*member == kAbsent) return;
      indices.assign(3 * triangles_.size(), kAbsent);  // first corner with one: earlier had none
    }
    indices.push_back(a.*member);
    indices.push_back(b.*member);
    indices.push_back(c.*member);
  };
  attribute(corner_vt_, &Corner::vt);
  attribute(corner_vn_, &Corner::vn);
  triangles_.push_back({a.v, b.v, c.v});
  if (any_usemtl_) face_materials_.push_back(current_material_);
}

Status ObjParser::parse_face(std::string_view rest) {
  polygon_.clear();
  const char* p = rest.data();
  const char* const end = p + rest.size();
  for (;;) {
    while (p != end && is_blank(*p)) ++p;
    if (p == end) break;
    Corner corner;
    if (auto s = parse_corner(p, end, corner); !s) return s;
    polygon_.push_back(corner);
  }
  if (polygon_.size() < 3) {
    return make_error(ErrorCode::kParse, at_line(line_) +
                                             "a face needs at least 3 corners, found " +
                                             std::to_string(polygon_.size()));
  }
  // Fan from the first corner, as Draco and the manifest's tool triangulate.
  for (size_t k = 2; k < polygon_.size(); ++k)
    add_triangle(polygon_[0], polygon_[k - 1], polygon_[k]);
  return {};
}

Status ObjParser::parse_line(std::string_view line) {
  std::string_view rest = line;
  const std::string_view keyword = next_token(rest);
  if (keyword.empty()) return {};
  if (keyword == "v") return parse_vertex(rest);
  if (keyword == "f") return parse_face(rest);
  if (keyword == "vn") return parse_normal(rest);
  if (keyword == "vt") return parse_texcoord(rest);
  if (keyword == "mtllib") {
    // Names are separated by blanks (names with blanks are not portable).
    for (std::string_view name = next_token(rest); !name.empty(); name = next_token(rest))
      material_libraries_.emplace_back(name);
  } else if (keyword == "usemtl") {
    const std::string name(next_token(rest));
    if (!name.empty()) {
      auto it = std::find(materials_used_.begin(), materials_used_.end(), name);
      current_material_ = static_cast<uint32_t>(it - materials_used_.begin());
      if (it == materials_used_.end()) materials_used_.push_back(name);
      if (!any_usemtl_) face_materials_.assign(triangles_.size(), kAbsent);
      any_usemtl_ = true;
    }
  } else if (keyword == "l") {
    ++line_elements_;
  } else if (keyword == "p") {
    ++point_elements_;
  } else if (!is_ignored_keyword(keyword)) {
    if (unknown_lines_++ == 0) first_unknown_ = at_line(line_) + quoted(keyword);
  }
  return {};
}

Status ObjParser::check_largest(const LargestIndex& largest, const char* what, const char* keyword,
                                size_t count) const {
  if (largest.index <= count) return {};
  return make_error(ErrorCode::kInvalidMesh, at_line(largest.line) + "a face refers to " + what +
                                                 " " + std::to_string(largest.index) +
                                                 " but the file has " + std::to_string(count) +
                                                 " '" + keyword + "' lines");
}

// Per-corner values to per-vertex ones, the way the Draco path did it: kept
// when every corner of a vertex has the same value (bit for bit), else
// dropped with a note. Unreferenced vertices get zeros.
template <class V>
bool gather(const std::vector<Triangle>& triangles, const std::vector<uint32_t>& corner_index,
            const std::vector<V>& values, uint32_t vertex_count, std::vector<V>& out,
            bool& some_missing) {
  out.assign(vertex_count, V{});
  std::vector<uint8_t> set(vertex_count, 0);
  some_missing = false;
  for (size_t c = 0; c < corner_index.size(); ++c) {
    const uint32_t i = corner_index[c];
    const uint32_t v = triangles[c / 3][c % 3];
    if (i == kAbsent) {
      some_missing = true;
      return false;
    }
    if (!set[v]) {
      out[v] = values[i];
      set[v] = 1;
    } else if (std::memcmp(&out[v], &values[i], sizeof(V)) != 0) {
      return false;
    }
  }
  return true;
}

void ObjParser::gather_attributes(RawMesh& raw) {
  Mesh& mesh = raw.mesh;
  const uint32_t n = mesh.vertex_count();
  auto attribute = [&](auto& values, const std::vector<uint32_t>& corner_index, auto& target,
                       auto& corner, AttributeInFile& contents, const char* name,
                       const char* keyword, uint32_t bad_line) {
    contents.count = values.size();
    if (values.empty()) return;
    if (corner_index.empty()) {
      note_dropped(raw, contents, name,
                   std::string("the file has '") + keyword + "' lines but no face refers to them");
      return;
    }
    if (bad_line != 0) {
      note_dropped(raw, contents, name, at_line(bad_line) + "NaN or Inf");
      return;
    }
    bool some_missing = false;
    if (!gather(mesh.triangles, corner_index, values, n, target, some_missing)) {
      target.clear();
      if (some_missing) {
        note_dropped(raw, contents, name, "some face corners have none");
      } else {
        // Seams (per-face normals, UV island borders): kept per corner.
        corner.values = values;
        corner.corners = corner_index;
      }
    }
  };
  attribute(normals_, corner_vn_, mesh.normals, mesh.corner_normals, raw.contents.normals,
            "normals", "vn", first_bad_normal_line_);
  attribute(texcoords_, corner_vt_, mesh.texcoords, mesh.corner_texcoords, raw.contents.texcoords,
            "texture coordinates", "vt", first_bad_texcoord_line_);
  raw.contents.colors.count = vertices_with_color_;

  if (vertices_with_color_ == n && n > 0) {
    // 0..1 floats, or 0..255 integers when any value exceeds 1 (both occur).
    bool bytes = false;
    for (const Vec3f& c : colors_) bytes |= c.x > 1 || c.y > 1 || c.z > 1;
    const float scale = bytes ? 1.0f / 255.0f : 1.0f;
    mesh.colors.resize(n);
    for (uint32_t v = 0; v < n; ++v) {
      mesh.colors[v] = {colors_[v].x * scale, colors_[v].y * scale, colors_[v].z * scale, 1.0f};
    }
  } else if (vertices_with_color_ > 0) {
    note_dropped(raw, raw.contents.colors, "colors",
                 "only " + std::to_string(vertices_with_color_) + " of " + std::to_string(n) +
                     " vertices have one");
  }
}

// Counts `v` and `f` lines in one memchr pass so the arrays are allocated
// once (the reallocations cost more than the scan); a polygon counts as a
// triangle, vectors grow past that as usual.
void ObjParser::reserve_for(std::string_view text) {
  size_t vertices = 0, faces = 0;
  const char* p = text.data();
  const char* const end = p + text.size();
  while (p < end) {
    while (p < end && (*p == ' ' || *p == '\t')) ++p;
    if (end - p >= 2 && p[1] == ' ') {
      vertices += p[0] == 'v';
      faces += p[0] == 'f';
    }
    const void* nl = std::memchr(p, '\n', static_cast<size_t>(end - p));
    if (nl == nullptr) break;
    p = static_cast<const char*>(nl) + 1;
  }
  positions_.reserve(vertices);
  triangles_.reserve(faces);
}

Result<RawMesh> ObjParser::parse(std::string_view text) {
  reserve_for(text);
  // A UTF-8 byte order mark (some Windows tools write one) is not a keyword.
  size_t pos = text.substr(0, 3) == "\xEF\xBB\xBF" ? 3 : 0;
  while (pos < text.size()) {
    // One logical line: physical lines joined while they end in '\'.
    ++line_;
    const uint32_t first_line = line_;
    std::string_view line;
    bool continued = false;
    joined_.clear();
    for (;;) {
      const char* nl =
          static_cast<const char*>(std::memchr(text.data() + pos, '\n', text.size() - pos));
      const size_t end = nl ? static_cast<size_t>(nl - text.data()) : text.size();
      std::string_view physical = text.substr(pos, end - pos);
      pos = end + 1;
      if (const size_t hash = physical.find('#'); hash != std::string_view::npos) {
        physical = physical.substr(0, hash);
      }
      while (!physical.empty() &&
             (physical.back() == '\r' || physical.back() == ' ' || physical.back() == '\t')) {
        physical.remove_suffix(1);
      }
      bool continues = !physical.empty() && physical.back() == '\\';
      if (continues && pos >= text.size()) {  // a '\\' on the last line continues nothing
        physical.remove_suffix(1);
        continues = false;
      }
      if (!continues && !continued) {
        line = physical;
        break;
      }
      if (continues) physical.remove_suffix(1);
      joined_.append(physical.data(), physical.size());
      joined_ += ' ';
      continued = true;
      if (!continues) {
        line = joined_;
        break;
      }
      ++line_;
    }
    const uint32_t last_line = line_;
    line_ = first_line;  // errors name the line where the element starts
    if (auto s = parse_line(line); !s) return tl::unexpected(std::move(s).error());
    line_ = last_line;
  }

  if (auto s = check_largest(largest_v_, "vertex", "v", positions_.size()); !s)
    return tl::unexpected(s.error());
  if (auto s = check_largest(largest_vt_, "texture coordinate", "vt", texcoords_.size()); !s) {
    return tl::unexpected(s.error());
  }
  if (auto s = check_largest(largest_vn_, "normal", "vn", normals_.size()); !s)
    return tl::unexpected(s.error());

  RawMesh raw;
  raw.vertices_in_file = static_cast<uint32_t>(positions_.size());
  raw.mesh.positions = std::move(positions_);
  raw.mesh.triangles = std::move(triangles_);
  gather_attributes(raw);
  raw.contents.format = "OBJ";
  for (const std::string& name : material_libraries_)
    raw.contents.material_libraries.push_back({.name = name});
  raw.contents.materials_used = materials_used_;
  if (any_usemtl_ && !raw.mesh.triangles.empty()) {
    // Materials by usemtl name (read_obj fills them from the MTL files);
    // faces before the first usemtl get a default material of their own.
    for (const std::string& name : materials_used_) raw.mesh.materials.push_back({.name = name});
    const uint32_t none = static_cast<uint32_t>(raw.mesh.materials.size());
    bool any_none = false;
    for (uint32_t& m : face_materials_) {
      if (m == kAbsent) {
        m = none;
        any_none = true;
      }
    }
    if (any_none) raw.mesh.materials.push_back({.name = "(no usemtl)"});
    raw.mesh.face_materials = std::move(face_materials_);
  }
  if (line_elements_ + point_elements_ > 0) {
    raw.notes.push_back(std::to_string(line_elements_) + " line elements ('l') and " +
                        std::to_string(point_elements_) +
                        " point elements ('p') skipped: only faces are read");
  }
  if (unknown_lines_ > 0) {
    raw.notes.push_back(std::to_string(unknown_lines_) +
                        " lines with an unknown keyword ignored (first: " + first_unknown_ + ")");
  }
  return raw;
}

}  // namespace

Result<RawMesh> parse_obj_text(std::string_view text) { return ObjParser().parse(text); }

Result<RawMesh> read_obj(const std::string& path) {
  auto text = read_file_bytes(path);
  if (!text) return tl::unexpected(text.error());
  auto raw = parse_obj_text(*text);
  if (raw) apply_material_libraries(path, *raw);
  return raw;
}

}  // namespace meshstream

// PLY reader (Turk's format, as documented with the Stanford 3D Scanning
// Repository). Our own rather than Draco's: Draco's PlyDecoder merges
// vertices with equal positions (so a repaired mesh with deliberate vertex
// copies would not read back as written) and ignores texture coordinates.
#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string_view>

#include "common/mesh/mesh_readers.h"

namespace meshstream {
namespace {

enum class Scalar { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

bool parse_scalar_type(std::string_view name, Scalar& type) {
  static const struct {
    const char* name;
    Scalar type;
  } kTypes[] = {
      {"char", Scalar::kInt8},      {"int8", Scalar::kInt8},       {"uchar", Scalar::kUint8},
      {"uint8", Scalar::kUint8},    {"short", Scalar::kInt16},     {"int16", Scalar::kInt16},
      {"ushort", Scalar::kUint16},  {"uint16", Scalar::kUint16},   {"int", Scalar::kInt32},
      {"int32", Scalar::kInt32},    {"uint", Scalar::kUint32},     {"uint32", Scalar::kUint32},
      {"float", Scalar::kFloat32},  {"float32", Scalar::kFloat32}, {"double", Scalar::kFloat64},
      {"float64", Scalar::kFloat64}};
  for (const auto& t : kTypes) {
    if (name == t.name) {
      type = t.type;
      return true;
    }
  }
  return false;
}

size_t scalar_size(Scalar type) {
  switch (type) {
    case Scalar::kInt8:
    case Scalar::kUint8:
      return 1;
    case Scalar::kInt16:
    case Scalar::kUint16:
      return 2;
    case Scalar::kInt32:
    case Scalar::kUint32:
    case Scalar::kFloat32:
      return 4;
    case Scalar::kFloat64:
      return 8;
  }
  return 0;
}

// Largest value of an integer type, to scale colours to 0..1.
double integer_range(Scalar type) {
  switch (type) {
    case Scalar::kInt8:
      return 127;
    case Scalar::kUint8:
      return 255;
    case Scalar::kInt16:
      return 32767;
    case Scalar::kUint16:
      return 65535;
    case Scalar::kInt32:
      return 2147483647.0;
    case Scalar::kUint32:
      return 4294967295.0;
    default:
      return 1;
  }
}

struct Property {
  std::string name;
  Scalar type = Scalar::kFloat32;
  bool is_list = false;
  Scalar count_type = Scalar::kUint8;
};

struct Element {
  std::string name;
  uint64_t count = 0;
  std::vector<Property> properties;
};

enum class Encoding { kAscii, kBinaryLittle, kBinaryBig };

// Reads values one at a time from the body, in any of the three encodings.
// Numbers are returned as double (exact for every PLY type) except float32,
// which is returned bit-exact through `as_float`.
class BodyReader {
 public:
  BodyReader(const std::string& data, size_t pos, Encoding encoding)
      : data_(data), pos_(pos), encoding_(encoding) {}

  // Reads one scalar; false with `error_` set when malformed or truncated.
  bool read(Scalar type, double& value, float& as_float) {
    if (encoding_ == Encoding::kAscii) return read_ascii(type, value, as_float);
    const size_t size = scalar_size(type);
    if (data_.size() - pos_ < size) {
      error_ = "the file ends inside the data";
      truncated_ = true;
      return false;
    }
    unsigned char bytes[8];
    std::memcpy(bytes, data_.data() + pos_, size);
    pos_ += size;
    const bool swap =
        (encoding_ == Encoding::kBinaryBig) == (std::endian::native == std::endian::little);
    if (swap) std::reverse(bytes, bytes + size);
    switch (type) {
      case Scalar::kInt8:
        value = static_cast<int8_t>(bytes[0]);
        break;
      case Scalar::kUint8:
        value = bytes[0];
        break;
      case Scalar::kInt16: {
        int16_t x;
        std::memcpy(&x, bytes, 2);
        value = x;
        break;
      }
      case Scalar::kUint16: {
        uint16_t x;
        std::memcpy(&x, bytes, 2);
        value = x;
        break;
      }
      case Scalar::kInt32: {
        int32_t x;
        std::memcpy(&x, bytes, 4);
        value = x;
        break;
      }
      case Scalar::kUint32: {
        uint32_t x;
        std::memcpy(&x, bytes, 4);
        value = x;
        break;
      }
      case Scalar::kFloat32: {
        std::memcpy(&as_float, bytes, 4);
        value = as_float;
        return true;
      }
      case Scalar::kFloat64: {
        std::memcpy(&value, bytes, 8);
        break;
      }
    }
    as_float = static_cast<float>(value);
    return true;
  }

  // ASCII bodies are read as a stream of tokens (one element per line is the
  // rule, but only the order matters, as in most readers).
  const std::string& error() const { return error_; }
  bool truncated() const { return truncated_; }
  size_t position() const { return pos_; }
  // Line number of the current position (ASCII error messages).
  uint32_t line_at_position() const {
    return 1 + static_cast<uint32_t>(std::count(data_.begin(), data_.begin() + pos_, '\n'));
  }

 private:
  bool read_ascii(Scalar type, double& value, float& as_float) {
    while (pos_ < data_.size() && std::isspace(static_cast<unsigned char>(data_[pos_]))) ++pos_;
    if (pos_ >= data_.size()) {
      error_ = "the file ends inside the data";
      truncated_ = true;
      return false;
    }
    size_t end = pos_;
    while (end < data_.size() && !std::isspace(static_cast<unsigned char>(data_[end]))) ++end;
    std::string_view token(data_.data() + pos_, end - pos_);
    const char* first = token.data();
    if (!token.empty() && token[0] == '+') ++first;
    const char* last = token.data() + token.size();
    std::from_chars_result result{};
    if (type == Scalar::kFloat32) {
      result = std::from_chars(first, last, as_float);
      value = as_float;
    } else if (type == Scalar::kFloat64) {
      result = std::from_chars(first, last, value);
      as_float = static_cast<float>(value);
    } else {
      int64_t integer = 0;
      result = std::from_chars(first, last, integer);
      value = static_cast<double>(integer);
      as_float = static_cast<float>(value);
    }
    if (result.ec != std::errc() || result.ptr != last) {
      error_ = std::string("'") + std::string(token) + "' is not a valid number here";
      return false;
    }
    pos_ = end;
    return true;
  }

  const std::string& data_;
  size_t pos_;
  Encoding encoding_;
  std::string error_;
  bool truncated_ = false;
};

int find_property(const Element& element, std::initializer_list<const char*> names) {
  for (const char* name : names) {
    for (size_t i = 0; i < element.properties.size(); ++i) {
      if (!element.properties[i].is_list && element.properties[i].name == name)
        return static_cast<int>(i);
    }
  }
  return -1;
}

}  // namespace

Result<RawMesh> read_ply(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return make_error(ErrorCode::kIo, "cannot open the file for reading");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) return make_error(ErrorCode::kIo, "read failed");
  const std::string data = std::move(buffer).str();

  // Header.
  size_t pos = 0;
  uint32_t line_number = 0;
  auto next_line = [&](std::string_view& line) {
    if (pos >= data.size()) return false;
    size_t end = data.find('\n', pos);
    if (end == std::string::npos) end = data.size();
    line = std::string_view(data.data() + pos, end - pos);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    pos = end + 1;
    ++line_number;
    return true;
  };
  auto header_error = [&](const std::string& what) {
    return make_error(ErrorCode::kParse,
                      "PLY header line " + std::to_string(line_number) + ": " + what);
  };
  std::string_view line;
  if (!next_line(line) || line != "ply")
    return make_error(ErrorCode::kParse, "not a PLY file (no 'ply' magic)");
  Encoding encoding = Encoding::kAscii;
  bool have_format = false, have_end = false;
  std::vector<Element> elements;
  while (next_line(line)) {
    std::istringstream words{std::string(line)};
    std::string keyword;
    words >> keyword;
    if (keyword.empty() || keyword == "comment" || keyword == "obj_info") continue;
    if (keyword == "end_header") {
      have_end = true;
      break;
    }
    if (keyword == "format") {
      std::string name, version;
      words >> name >> version;
      if (name == "ascii")
        encoding = Encoding::kAscii;
      else if (name == "binary_little_endian")
        encoding = Encoding::kBinaryLittle;
      else if (name == "binary_big_endian")
        encoding = Encoding::kBinaryBig;
      else
        return header_error("unknown format '" + name + "'");
      have_format = true;
    } else if (keyword == "element") {
      Element element;
      if (!(words >> element.name >> element.count)) return header_error("malformed element line");
      elements.push_back(std::move(element));
    } else if (keyword == "property") {
      if (elements.empty()) return header_error("property before any element");
      Property property;
      std::string type;
      words >> type;
      if (type == "list") {
        std::string count_type, item_type;
        words >> count_type >> item_type >> property.name;
        property.is_list = true;
        if (!parse_scalar_type(count_type, property.count_type) ||
            !parse_scalar_type(item_type, property.type)) {
          return header_error("unknown list types '" + count_type + " " + item_type + "'");
        }
      } else {
        words >> property.name;
        if (!parse_scalar_type(type, property.type))
          return header_error("unknown type '" + type + "'");
      }
      if (property.name.empty()) return header_error("property without a name");
      elements.back().properties.push_back(std::move(property));
    } else {
      return header_error("unknown keyword '" + keyword + "'");
    }
  }
  if (!have_end) return make_error(ErrorCode::kParse, "PLY header has no end_header");
  if (!have_format) return make_error(ErrorCode::kParse, "PLY header has no format line");

  // Every element needs at least one byte (binary) or two (ASCII): counts
  // beyond the file size are lies, refused before allocating for them.
  const size_t body_size = data.size() - std::min(pos, data.size());
  for (const Element& e : elements) {
    if (e.count > body_size + 1) {
      return make_error(ErrorCode::kParse, "element '" + e.name + "' claims " +
                                               std::to_string(e.count) +
                                               " entries but the data has only " +
                                               std::to_string(body_size) + " bytes");
    }
  }

  RawMesh raw;
  Mesh& mesh = raw.mesh;
  BodyReader reader(data, std::min(pos, data.size()), encoding);
  auto body_error = [&](const std::string& where) {
    std::string at = encoding == Encoding::kAscii
                         ? "line " + std::to_string(reader.line_at_position())
                         : "byte " + std::to_string(reader.position());
    return make_error(reader.truncated() ? ErrorCode::kTruncated : ErrorCode::kParse,
                      at + ", " + where + ": " + reader.error());
  };
  bool have_vertices = false, have_faces = false;
  uint64_t vertex_count = 0;
  std::vector<double> values;
  std::vector<float> floats;
  for (const Element& element : elements) {
    const bool is_vertex = element.name == "vertex" && !have_vertices;
    const bool is_face = element.name == "face" && !have_faces;
    int x = -1, y = -1, z = -1, nx = -1, ny = -1, nz = -1, r = -1, g = -1, b = -1, a = -1, u = -1,
        v = -1;
    int indices = -1;
    if (is_vertex) {
      x = find_property(element, {"x"}), y = find_property(element, {"y"}),
      z = find_property(element, {"z"});
      if (x < 0 || y < 0 || z < 0)
        return make_error(ErrorCode::kParse, "PLY vertices have no x, y, z");
      nx = find_property(element, {"nx"}), ny = find_property(element, {"ny"}),
      nz = find_property(element, {"nz"});
      r = find_property(element, {"red", "r", "diffuse_red"});
      g = find_property(element, {"green", "g", "diffuse_green"});
      b = find_property(element, {"blue", "b", "diffuse_blue"});
      a = find_property(element, {"alpha", "a"});
      u = find_property(element, {"u", "s", "texture_u", "texture_s"});
      v = find_property(element, {"v", "t", "texture_v", "texture_t"});
      vertex_count = element.count;
      mesh.positions.resize(element.count);
      if (nx >= 0 && ny >= 0 && nz >= 0) mesh.normals.resize(element.count);
      if (r >= 0 && g >= 0 && b >= 0) mesh.colors.resize(element.count);
      if (u >= 0 && v >= 0) mesh.texcoords.resize(element.count);
      have_vertices = true;
    }
    if (is_face) {
      for (size_t i = 0; i < element.properties.size() && indices < 0; ++i) {
        const Property& p = element.properties[i];
        if (p.is_list && (p.name == "vertex_indices" || p.name == "vertex_index"))
          indices = static_cast<int>(i);
      }
      for (size_t i = 0; i < element.properties.size() && indices < 0; ++i) {
        if (element.properties[i].is_list) indices = static_cast<int>(i);
      }
      if (indices < 0) return make_error(ErrorCode::kParse, "PLY faces have no vertex index list");
      if (!have_vertices)
        return make_error(ErrorCode::kParse, "PLY faces come before the vertices");
      mesh.triangles.reserve(std::min<uint64_t>(element.count * 2, body_size));
      have_faces = true;
    }
    values.resize(element.properties.size());
    floats.resize(element.properties.size());
    std::vector<uint32_t> polygon;
    for (uint64_t k = 0; k < element.count; ++k) {
      const std::string where = element.name + " " + std::to_string(k);
      for (size_t p = 0; p < element.properties.size(); ++p) {
        const Property& property = element.properties[p];
        if (!property.is_list) {
          if (!reader.read(property.type, values[p], floats[p])) return body_error(where);
          continue;
        }
        double count_value = 0;
        float unused = 0;
        if (!reader.read(property.count_type, count_value, unused)) return body_error(where);
        if (count_value < 0 || count_value > 1e6) {
          return make_error(
              ErrorCode::kParse,
              where + ": list length " + std::to_string(count_value) + " is out of range");
        }
        const bool keep = is_face && static_cast<int>(p) == indices;
        polygon.clear();
        for (uint32_t i = 0; i < static_cast<uint32_t>(count_value); ++i) {
          double item = 0;
          if (!reader.read(property.type, item, unused)) return body_error(where);
          if (!keep) continue;
          if (item < 0 || item >= static_cast<double>(vertex_count) || item != std::floor(item)) {
            return make_error(ErrorCode::kInvalidMesh,
                              where + " refers to vertex " + std::to_string(item) +
                                  " but there are only " + std::to_string(vertex_count));
          }
          polygon.push_back(static_cast<uint32_t>(item));
        }
        if (keep) {
          if (polygon.size() < 3) {
            return make_error(ErrorCode::kParse, where + " has " + std::to_string(polygon.size()) +
                                                     " vertices; a polygon needs at least 3");
          }
          for (size_t i = 2; i < polygon.size(); ++i)
            mesh.triangles.push_back({polygon[0], polygon[i - 1], polygon[i]});
        }
      }
      if (is_vertex) {
        mesh.positions[k] = {floats[x], floats[y], floats[z]};
        if (!mesh.normals.empty()) mesh.normals[k] = {floats[nx], floats[ny], floats[nz]};
        if (!mesh.colors.empty()) {
          auto channel = [&](int index) {
            const Property& prop = element.properties[index];
            const bool integer = prop.type != Scalar::kFloat32 && prop.type != Scalar::kFloat64;
            return integer ? static_cast<float>(values[index] / integer_range(prop.type))
                           : floats[index];
          };
          mesh.colors[k] = {channel(r), channel(g), channel(b), a >= 0 ? channel(a) : 1.0f};
        }
        if (!mesh.texcoords.empty()) mesh.texcoords[k] = {floats[u], floats[v]};
      }
    }
  }
  if (!have_vertices) return make_error(ErrorCode::kParse, "PLY file has no vertex element");
  raw.vertices_in_file = static_cast<uint32_t>(vertex_count);
  return raw;
}

}  // namespace meshstream

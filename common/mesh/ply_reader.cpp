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

  // Binary, native byte order: `count` float32 values, true; false (nothing
  // read) when the data ends first.
  bool take_native(float* out, size_t count) {
    const size_t size = 4 * count;
    if (data_.size() - pos_ < size) return false;
    std::memcpy(out, data_.data() + pos_, size);
    pos_ += size;
    return true;
  }
  // The next `size` bytes without consuming them; false when fewer remain.
  bool peek(unsigned char* out, size_t size) const {
    if (data_.size() - pos_ < size) return false;
    std::memcpy(out, data_.data() + pos_, size);
    return true;
  }
  void skip(size_t size) { pos_ += size; }

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

struct Header {
  Encoding encoding = Encoding::kAscii;
  std::vector<Element> elements;
  size_t body_start = 0;  // first byte after end_header (may be data.size())
};

// One `property` line's words after the keyword; the error says what is wrong
// with them (the caller adds the line).
Result<Property> parse_property(std::istringstream& words) {
  Property property;
  std::string type;
  words >> type;
  if (type == "list") {
    std::string count_type, item_type;
    words >> count_type >> item_type >> property.name;
    property.is_list = true;
    if (!parse_scalar_type(count_type, property.count_type) ||
        !parse_scalar_type(item_type, property.type)) {
      return make_error(ErrorCode::kParse,
                        "unknown list types '" + count_type + " " + item_type + "'");
    }
  } else {
    words >> property.name;
    if (!parse_scalar_type(type, property.type)) {
      return make_error(ErrorCode::kParse, "unknown type '" + type + "'");
    }
  }
  if (property.name.empty()) {
    return make_error(ErrorCode::kParse, "property without a name");
  }
  return property;
}

// The header: magic, format, elements and their properties, end_header.
Result<Header> parse_header(const std::string& data) {
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
  Header header;
  bool have_format = false, have_end = false;
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
        header.encoding = Encoding::kAscii;
      else if (name == "binary_little_endian")
        header.encoding = Encoding::kBinaryLittle;
      else if (name == "binary_big_endian")
        header.encoding = Encoding::kBinaryBig;
      else
        return header_error("unknown format '" + name + "'");
      have_format = true;
    } else if (keyword == "element") {
      Element element;
      if (!(words >> element.name >> element.count)) return header_error("malformed element line");
      header.elements.push_back(std::move(element));
    } else if (keyword == "property") {
      if (header.elements.empty()) return header_error("property before any element");
      auto property = parse_property(words);
      if (!property) return header_error(property.error().message);
      header.elements.back().properties.push_back(std::move(*property));
    } else {
      return header_error("unknown keyword '" + keyword + "'");
    }
  }
  if (!have_end) return make_error(ErrorCode::kParse, "PLY header has no end_header");
  if (!have_format) return make_error(ErrorCode::kParse, "PLY header has no format line");
  header.body_start = std::min(pos, data.size());
  return header;
}

// Every element needs at least one byte (binary) or two (ASCII): counts
// beyond the file size are lies, refused before allocating for them.
Status check_counts(const Header& header, size_t body_size) {
  for (const Element& e : header.elements) {
    if (e.count > body_size + 1) {
      return make_error(ErrorCode::kParse, "element '" + e.name + "' claims " +
                                               std::to_string(e.count) +
                                               " entries but the data has only " +
                                               std::to_string(body_size) + " bytes");
    }
  }
  return {};
}

// Where the vertex element keeps what we read (-1: absent).
struct VertexLayout {
  int x = -1, y = -1, z = -1;
  int nx = -1, ny = -1, nz = -1;
  int r = -1, g = -1, b = -1, a = -1;
  int u = -1, v = -1;
  bool normals() const { return nx >= 0 && ny >= 0 && nz >= 0; }
  bool colors() const { return r >= 0 && g >= 0 && b >= 0; }
  bool texcoords() const { return u >= 0 && v >= 0; }
};

VertexLayout find_vertex_layout(const Element& e) {
  return {.x = find_property(e, {"x"}),
          .y = find_property(e, {"y"}),
          .z = find_property(e, {"z"}),
          .nx = find_property(e, {"nx"}),
          .ny = find_property(e, {"ny"}),
          .nz = find_property(e, {"nz"}),
          .r = find_property(e, {"red", "r", "diffuse_red"}),
          .g = find_property(e, {"green", "g", "diffuse_green"}),
          .b = find_property(e, {"blue", "b", "diffuse_blue"}),
          .a = find_property(e, {"alpha", "a"}),
          .u = find_property(e, {"u", "s", "texture_u", "texture_s"}),
          .v = find_property(e, {"v", "t", "texture_v", "texture_t"})};
}

// The face element's index list: "vertex_indices" or "vertex_index", else
// its first list; -1 when it has none.
int find_index_list(const Element& element) {
  for (size_t i = 0; i < element.properties.size(); ++i) {
    const Property& p = element.properties[i];
    if (p.is_list && (p.name == "vertex_indices" || p.name == "vertex_index"))
      return static_cast<int>(i);
  }
  for (size_t i = 0; i < element.properties.size(); ++i) {
    if (element.properties[i].is_list) return static_cast<int>(i);
  }
  return -1;
}

// Reads the body element by element into raw.mesh: the first "vertex"
// element's positions and attributes, the first "face" element's polygons
// (fan-triangulated); everything else is read and skipped.
class BodyParser {
 public:
  BodyParser(const std::string& data, const Header& header, RawMesh& raw)
      : header_(header),
        reader_(data, header.body_start, header.encoding),
        body_size_(data.size() - header.body_start),
        mesh_(raw.mesh) {}

  Status read_all() {
    for (const Element& element : header_.elements) {
      if (auto ok = read_element(element); !ok) return ok;
    }
    if (!have_vertices_) return make_error(ErrorCode::kParse, "PLY file has no vertex element");
    return {};
  }
  uint64_t vertex_count() const { return vertex_count_; }

 private:
  Status start_vertices(const Element& element) {
    layout_ = find_vertex_layout(element);
    if (layout_.x < 0 || layout_.y < 0 || layout_.z < 0)
      return make_error(ErrorCode::kParse, "PLY vertices have no x, y, z");
    vertex_count_ = element.count;
    mesh_.positions.resize(element.count);
    if (layout_.normals()) mesh_.normals.resize(element.count);
    if (layout_.colors()) mesh_.colors.resize(element.count);
    if (layout_.texcoords()) mesh_.texcoords.resize(element.count);
    have_vertices_ = true;
    return {};
  }

  Status start_faces(const Element& element) {
    indices_ = find_index_list(element);
    if (indices_ < 0) return make_error(ErrorCode::kParse, "PLY faces have no vertex index list");
    if (!have_vertices_) return make_error(ErrorCode::kParse, "PLY faces come before the vertices");
    // One triangle a face (polygons grow it): a guess of two left half the
    // array unused on triangle meshes, 12 bytes a face of address space.
    mesh_.triangles.reserve(std::min<uint64_t>(element.count, body_size_));
    have_faces_ = true;
    return {};
  }

  Status read_element(const Element& element) {
    const bool is_vertex = element.name == "vertex" && !have_vertices_;
    const bool is_face = element.name == "face" && !have_faces_;
    if (is_vertex) {
      if (auto ok = start_vertices(element); !ok) return ok;
    }
    indices_ = -1;
    if (is_face) {
      if (auto ok = start_faces(element); !ok) return ok;
    }
    values_.resize(element.properties.size());
    floats_.resize(element.properties.size());
    const bool fast_vertices = is_vertex && all_native_floats(element);
    const bool fast_faces = is_face && is_native_triangle_list(element);
    for (uint64_t k = 0; k < element.count; ++k) {
      // The common binary layouts, without a call per value: float32
      // vertices, faces with only a uchar-counted int32 list of 3. Anything
      // else (another count, the end of the data) takes the general path,
      // which gives the errors.
      if (fast_vertices && reader_.take_native(floats_.data(), element.properties.size())) {
        store_vertex(element, k);
        continue;
      }
      if (fast_faces && take_triangle()) continue;
      const Where where{element.name, k};
      for (size_t p = 0; p < element.properties.size(); ++p) {
        const Property& property = element.properties[p];
        if (!property.is_list) {
          if (!reader_.read(property.type, values_[p], floats_[p])) return body_error(where.str());
          continue;
        }
        const bool keep = is_face && static_cast<int>(p) == indices_;
        if (auto ok = read_list(property, keep, where); !ok) return ok;
      }
      if (is_vertex) store_vertex(element, k);
    }
    return {};
  }

  // An element and its index, named only when an error needs it (building
  // the string per element cost more than reading it).
  struct Where {
    const std::string& element;
    uint64_t k;
    std::string str() const { return element + " " + std::to_string(k); }
  };

  bool native_order() const {
    return (header_.encoding == Encoding::kBinaryLittle) ==
           (std::endian::native == std::endian::little);
  }
  bool all_native_floats(const Element& element) const {
    if (header_.encoding == Encoding::kAscii || !native_order()) return false;
    for (const Property& p : element.properties) {
      if (p.is_list || p.type != Scalar::kFloat32) return false;
    }
    return true;
  }
  bool is_native_triangle_list(const Element& element) const {
    if (header_.encoding == Encoding::kAscii || !native_order()) return false;
    if (element.properties.size() != 1 || indices_ != 0) return false;
    const Property& p = element.properties[0];
    return p.is_list && p.count_type == Scalar::kUint8 &&
           (p.type == Scalar::kInt32 || p.type == Scalar::kUint32);
  }
  // One face "3 a b c" with every index in range: appended, true. Otherwise
  // nothing read, false.
  bool take_triangle() {
    unsigned char record[13];
    if (!reader_.peek(record, sizeof record) || record[0] != 3) return false;
    int32_t index[3];
    std::memcpy(index, record + 1, sizeof index);
    for (int32_t i : index) {
      if (i < 0 || static_cast<uint64_t>(i) >= vertex_count_) return false;
    }
    mesh_.triangles.push_back({static_cast<uint32_t>(index[0]), static_cast<uint32_t>(index[1]),
                               static_cast<uint32_t>(index[2])});
    reader_.skip(sizeof record);
    return true;
  }

  // One list: its length, then its items; the face index list (`keep`)
  // becomes fan triangles.
  Status read_list(const Property& property, bool keep, const Where& at) {
    double count_value = 0;
    float unused = 0;
    if (!reader_.read(property.count_type, count_value, unused)) return body_error(at.str());
    // Written this way round so a NaN length (a float count type) is refused
    // too; a fractional one would be truncated in silence.
    if (!(count_value >= 0 && count_value <= 1e6) || count_value != std::floor(count_value)) {
      return make_error(ErrorCode::kParse, at.str() + ": list length " +
                                               std::to_string(count_value) +
                                               " is not a whole number from 0 to 1000000");
    }
    polygon_.clear();
    for (uint32_t i = 0; i < static_cast<uint32_t>(count_value); ++i) {
      double item = 0;
      if (!reader_.read(property.type, item, unused)) return body_error(at.str());
      if (!keep) continue;
      if (item < 0 || item >= static_cast<double>(vertex_count_) || item != std::floor(item)) {
        return make_error(ErrorCode::kInvalidMesh,
                          at.str() + " refers to vertex " + std::to_string(item) +
                              " but there are only " + std::to_string(vertex_count_));
      }
      polygon_.push_back(static_cast<uint32_t>(item));
    }
    if (!keep) return {};
    if (polygon_.size() < 3) {
      return make_error(ErrorCode::kParse, at.str() + " has " + std::to_string(polygon_.size()) +
                                               " vertices; a polygon needs at least 3");
    }
    for (size_t i = 2; i < polygon_.size(); ++i)
      mesh_.triangles.push_back({polygon_[0], polygon_[i - 1], polygon_[i]});
    return {};
  }

  void store_vertex(const Element& element, uint64_t k) {
    const VertexLayout& l = layout_;
    const float* f = floats_.data();
    mesh_.positions[k] = {f[l.x], f[l.y], f[l.z]};
    if (!mesh_.normals.empty()) mesh_.normals[k] = {f[l.nx], f[l.ny], f[l.nz]};
    if (!mesh_.colors.empty()) {
      auto channel = [&](int index) {
        const Property& prop = element.properties[index];
        const bool integer = prop.type != Scalar::kFloat32 && prop.type != Scalar::kFloat64;
        return integer ? static_cast<float>(values_[index] / integer_range(prop.type)) : f[index];
      };
      mesh_.colors[k] = {channel(l.r), channel(l.g), channel(l.b), l.a >= 0 ? channel(l.a) : 1.0f};
    }
    if (!mesh_.texcoords.empty()) mesh_.texcoords[k] = {f[l.u], f[l.v]};
  }

  tl::unexpected<Error> body_error(const std::string& where) const {
    std::string at = header_.encoding == Encoding::kAscii
                         ? "line " + std::to_string(reader_.line_at_position())
                         : "byte " + std::to_string(reader_.position());
    return make_error(reader_.truncated() ? ErrorCode::kTruncated : ErrorCode::kParse,
                      at + ", " + where + ": " + reader_.error());
  }

  const Header& header_;
  BodyReader reader_;
  size_t body_size_;
  Mesh& mesh_;
  VertexLayout layout_;
  bool have_vertices_ = false, have_faces_ = false;
  uint64_t vertex_count_ = 0;
  int indices_ = -1;
  std::vector<double> values_;
  std::vector<float> floats_;
  std::vector<uint32_t> polygon_;
};

const char* scalar_name(Scalar type) {
  switch (type) {
    case Scalar::kInt8:
      return "char";
    case Scalar::kUint8:
      return "uchar";
    case Scalar::kInt16:
      return "short";
    case Scalar::kUint16:
      return "ushort";
    case Scalar::kInt32:
      return "int";
    case Scalar::kUint32:
      return "uint";
    case Scalar::kFloat32:
      return "float";
    case Scalar::kFloat64:
      return "double";
  }
  return "?";
}

std::string describe_property(const Element& element, const Property& p) {
  return element.name + " " + p.name + " (" +
         (p.is_list ? std::string("list of ") + scalar_name(p.type) : scalar_name(p.type)) + ")";
}

// What the file holds as the header declares it: the attributes read, the
// properties and elements skipped.
FileContents describe_contents(const Header& header) {
  FileContents contents;
  contents.format = header.encoding == Encoding::kAscii          ? "PLY (ascii)"
                    : header.encoding == Encoding::kBinaryLittle ? "PLY (binary little-endian)"
                                                                 : "PLY (binary big-endian)";
  bool seen_vertex = false, seen_face = false;
  for (const Element& e : header.elements) {
    if (e.name == "vertex" && !seen_vertex) {
      seen_vertex = true;
      const VertexLayout l = find_vertex_layout(e);
      if (l.normals()) contents.normals.count = e.count;
      if (l.colors()) contents.colors.count = e.count;
      if (l.texcoords()) contents.texcoords.count = e.count;
      const int read[] = {l.x, l.y, l.z, l.nx, l.ny, l.nz, l.r, l.g, l.b, l.a, l.u, l.v};
      for (size_t i = 0; i < e.properties.size(); ++i) {
        if (std::find(std::begin(read), std::end(read), static_cast<int>(i)) == std::end(read))
          contents.extra_properties.push_back(describe_property(e, e.properties[i]));
      }
    } else if (e.name == "face" && !seen_face) {
      seen_face = true;
      const int indices = find_index_list(e);
      for (size_t i = 0; i < e.properties.size(); ++i) {
        if (static_cast<int>(i) != indices)
          contents.extra_properties.push_back(describe_property(e, e.properties[i]));
      }
    } else {
      contents.other_elements.push_back(e.name + " (" + std::to_string(e.count) + ")");
    }
  }
  return contents;
}

}  // namespace

Result<RawMesh> read_ply(const std::string& path) {
  auto data = read_file_bytes(path);
  if (!data) return tl::unexpected(data.error());
  auto header = parse_header(*data);
  if (!header) return tl::unexpected(header.error());
  if (auto ok = check_counts(*header, data->size() - header->body_start); !ok)
    return tl::unexpected(ok.error());
  RawMesh raw;
  raw.contents = describe_contents(*header);
  BodyParser body(*data, *header, raw);
  if (auto ok = body.read_all(); !ok) return tl::unexpected(ok.error());
  raw.vertices_in_file = static_cast<uint32_t>(body.vertex_count());
  return raw;
}

}  // namespace meshstream

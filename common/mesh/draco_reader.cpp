// .drc through Draco's io (PLY, OBJ and STL have their own
// readers: Draco's PLY reader merges equal positions and drops texture
// coordinates; its OBJ reader writes outside a heap block on malformed face
// tokens — see ply_reader.cpp, obj_reader.cpp; its STL reader builds a
// whole mesh of its own first — see stl_binary_reader.cpp).
//
// Draco's StlDecoder stays here, behind read_stl_with_draco, as the peer
// tests/mesh/stl_reader_test.cpp compares read_stl with.
//
// Draco's ObjDecoder is still here, behind read_trusted_obj_with_draco, as
// the peer tests/mesh/obj_reader_test.cpp and the benchmarks compare our OBJ
// reader with on well-formed files; nothing reads untrusted files with it.
// Two Draco habits would hide what a file holds, and are undone here:
//  - the OBJ reader merges equal attribute values by default: we turn that
//    off so `vertices_in_file` is the number of `v` lines;
//  - points (Draco's per-corner records) are not vertices: a vertex is the
//    position *value* a corner maps to (STL: each point, since an STL file
//    has no shared vertices and the reader merges them itself).
#include <draco/compression/decode.h>
#include <draco/io/obj_decoder.h>
#include <draco/io/stl_decoder.h>
#include <draco/mesh/mesh.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string_view>

#include "common/mesh/mesh_readers.h"

namespace meshstream {
namespace {

std::string lower_extension(const std::string& path) {
  const size_t dot = path.find_last_of('.');
  const size_t slash = path.find_last_of("/\\");
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return {};
  std::string ext = path.substr(dot + 1);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

Result<std::unique_ptr<draco::Mesh>> decode(const std::string& path, const std::string& ext) {
  auto fail = [](const draco::Status& status) {
    return make_error(ErrorCode::kParse,
                      std::string("Draco could not read it: ") + status.error_msg());
  };
  auto mesh = std::make_unique<draco::Mesh>();
  if (ext == "obj") {
    // Draco's ObjDecoder dereferences a missing position attribute when a
    // face comes with no `v` line at all (SEGV in MapPointToVertexIndices;
    // found by tests/fuzz, regression input regressions/mesh_import/).
    std::ifstream in(path, std::ios::binary);
    bool has_position = false;
    for (std::string line; !has_position && std::getline(in, line);) {
      const size_t at = line.find_first_not_of(" \t");
      has_position = at != std::string::npos && line.size() > at + 1 && line[at] == 'v' &&
                     (line[at + 1] == ' ' || line[at + 1] == '\t');
    }
    if (!has_position) return make_error(ErrorCode::kParse, "no vertex positions (no 'v' line)");
    draco::ObjDecoder decoder;
    decoder.set_deduplicate_input_values(false);
    if (auto status = decoder.DecodeFromFile(path, mesh.get()); !status.ok()) return fail(status);
    return mesh;
  }
  if (ext == "stl") {
    // Draco trusts the triangle count in the header (a damaged count makes it
    // allocate gigabytes); a binary STL has exactly 84 + 50 * count bytes.
    std::ifstream in(path, std::ios::binary);
    char header[84] = {};
    in.read(header, sizeof header);
    uint32_t count = 0;
    std::memcpy(&count, header + 80, 4);
    const uint64_t size = std::filesystem::file_size(path);
    if (in.gcount() < 84 || size != 84 + 50ull * count) {
      if (std::string_view(header, std::min<size_t>(in.gcount(), 5)) == "solid") {
        return make_error(ErrorCode::kUnsupported, "ASCII STL");  // read_with_draco hands it on
      }
      return make_error(ErrorCode::kParse, "not a binary STL: " + std::to_string(size) +
                                               " bytes, but the header announces " +
                                               std::to_string(count) + " triangles (" +
                                               std::to_string(84 + 50ull * count) + " bytes)");
    }
    draco::StlDecoder decoder;
    auto result = decoder.DecodeFromFile(path);
    if (!result.ok()) return fail(result.status());
    return std::move(result).value();
  }
  if (ext == "drc") {
    std::ifstream in(path, std::ios::binary);
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    draco::DecoderBuffer buffer;
    buffer.Init(bytes.data(), bytes.size());
    draco::Decoder decoder;
    auto result = decoder.DecodeMeshFromBuffer(&buffer);
    if (!result.ok()) return fail(result.status());
    return std::move(result).value();
  }
  return make_error(
      ErrorCode::kParse,
      "unknown mesh format '." + ext + "' (expected .obj, .ply, .stl, .off, .drc, .gltf or .glb)");
}

// Gathers one attribute per vertex from the corners. Returns false when two
// corners of one vertex disagree (e.g. per-face normals): then the attribute
// cannot be per-vertex and is dropped.
template <class V, int N>
bool gather(const draco::Mesh& dm, const draco::PointAttribute& attribute,
            const std::vector<uint32_t>& corner_vertex, uint32_t vertex_count, float fill,
            std::vector<V>& out) {
  static_assert(sizeof(V) == N * sizeof(float));
  out.assign(vertex_count, V{});
  std::vector<uint8_t> set(vertex_count, 0);
  for (uint32_t f = 0; f < dm.num_faces(); ++f) {
    const auto& face = dm.face(draco::FaceIndex(f));
    for (int i = 0; i < 3; ++i) {
      float value[N];
      for (float& x : value) x = fill;
      const auto index = attribute.mapped_index(face[i]);
      const int n = std::min<int>(N, attribute.num_components());
      if (!attribute.ConvertValue<float>(index, static_cast<int8_t>(n), value)) return false;
      const uint32_t v = corner_vertex[3 * f + i];
      V converted;
      std::memcpy(&converted, value, sizeof(V));
      if (!set[v]) {
        out[v] = converted;
        set[v] = 1;
      } else if (std::memcmp(&out[v], &converted, sizeof(V)) != 0) {
        return false;
      }
    }
  }
  return true;
}

// Draco's decode and the conversion of its mesh to ours.
Result<RawMesh> read_draco_mesh(const std::string& path, const std::string& ext) {
  Result<std::unique_ptr<draco::Mesh>> decoded = make_error(ErrorCode::kParse, "not decoded");
  try {
    decoded = decode(path, ext);
  } catch (const std::exception& e) {
    // Draco's parsers size vectors from counts in the file; a damaged file
    // can make that throw. Not a crash: a malformed file.
    return make_error(ErrorCode::kParse, std::string("Draco could not read it: ") + e.what());
  }
  if (!decoded) {
    if (decoded.error().code == ErrorCode::kUnsupported && ext == "stl")
      return read_ascii_stl(path);
    return tl::unexpected(std::move(decoded).error());
  }
  const draco::Mesh& dm = **decoded;
  const draco::PointAttribute* position = dm.GetNamedAttribute(draco::GeometryAttribute::POSITION);
  if (position == nullptr || position->num_components() != 3) {
    return make_error(ErrorCode::kParse, "the file has no 3-D vertex positions");
  }

  // Vertex of every corner, and the vertex positions.
  RawMesh raw;
  Mesh& mesh = raw.mesh;
  const bool per_point = ext == "stl";
  const uint32_t vertex_count =
      per_point ? dm.num_points() : static_cast<uint32_t>(position->size());
  mesh.positions.resize(vertex_count);
  for (uint32_t v = 0; v < vertex_count; ++v) {
    const auto index =
        per_point ? position->mapped_index(draco::PointIndex(v)) : draco::AttributeValueIndex(v);
    if (!position->ConvertValue<float>(index, 3, &mesh.positions[v].x)) {
      return make_error(ErrorCode::kParse, "vertex " + std::to_string(v) + " could not be read");
    }
  }
  std::vector<uint32_t> corner_vertex(static_cast<size_t>(dm.num_faces()) * 3);
  mesh.triangles.resize(dm.num_faces());
  for (uint32_t f = 0; f < dm.num_faces(); ++f) {
    const auto& face = dm.face(draco::FaceIndex(f));
    for (int i = 0; i < 3; ++i) {
      const uint32_t point = face[i].value();
      uint32_t v = 0;
      if (point >= dm.num_points()) {
        v = 0xFFFFFFFFu;  // out of range: clean_mesh reports it
      } else {
        v = per_point ? point : position->mapped_index(face[i]).value();
      }
      mesh.triangles[f][i] = v;
      corner_vertex[3 * f + i] = v;
      if (v >= vertex_count) {
        return make_error(ErrorCode::kInvalidMesh,
                          "face " + std::to_string(f) + " refers to a vertex that does not exist");
      }
    }
  }
  raw.vertices_in_file = vertex_count;

  auto optional = [&](draco::GeometryAttribute::Type type, const char* name, auto& target,
                      AttributeInFile& contents, auto tag, float fill) {
    const draco::PointAttribute* attribute = dm.GetNamedAttribute(type);
    if (attribute == nullptr) return;
    contents.count = attribute->size();
    using V = typename std::remove_reference_t<decltype(target)>::value_type;
    constexpr int N = decltype(tag)::value;
    if (!gather<V, N>(dm, *attribute, corner_vertex, vertex_count, fill, target)) {
      target.clear();
      note_dropped(raw, contents, name,
                   "they differ between corners of one vertex (per-face values)");
    }
  };
  optional(draco::GeometryAttribute::NORMAL, "normals", mesh.normals, raw.contents.normals,
           std::integral_constant<int, 3>{}, 0.0f);
  optional(draco::GeometryAttribute::COLOR, "colors", mesh.colors, raw.contents.colors,
           std::integral_constant<int, 4>{}, 1.0f);
  optional(draco::GeometryAttribute::TEX_COORD, "texture coordinates", mesh.texcoords,
           raw.contents.texcoords, std::integral_constant<int, 2>{}, 0.0f);
  return raw;
}

}  // namespace

Result<RawMesh> read_with_draco(const std::string& path) {
  const std::string ext = lower_extension(path);
  if (ext == "obj") return read_obj(path);
  if (ext == "stl") return read_stl(path);
  return read_draco_mesh(path, ext);
}

Result<RawMesh> read_stl_with_draco(const std::string& path) {
  return read_draco_mesh(path, "stl");
}

Result<RawMesh> read_trusted_obj_with_draco(const std::string& path) {
  return read_draco_mesh(path, "obj");
}

}  // namespace meshstream

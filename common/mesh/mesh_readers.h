// The format readers behind import_mesh: each returns the file's content as
// it is (positions, fan-triangulated faces, per-vertex attributes), before
// any cleaning. Errors name the problem; import_mesh adds the file name.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "common/base/result.h"
#include "common/mesh/file_contents.h"
#include "common/mesh/mesh.h"

namespace meshstream {

struct RawMesh {
  Mesh mesh;                       // indices may be anything: clean_mesh validates
  uint32_t vertices_in_file = 0;   // as the file counts them (STL: 3 per triangle)
  std::vector<std::string> notes;  // e.g. attributes that could not be kept
  FileContents contents;           // what the file holds, kept or not (format set by import)
};

// Records that the file's `name` (e.g. "normals") are not kept, and why: in
// the notes ("normals dropped: why") and in the attribute's contents entry.
inline void note_dropped(RawMesh& raw, AttributeInFile& attribute, const std::string& name,
                         const std::string& why) {
  attribute.dropped = why;
  raw.notes.push_back(name + " dropped: " + why);
}

// The whole file: kIo "cannot open the file for reading" or "read failed".
// One read into a buffer sized from the file length.
Result<std::string> read_file_bytes(const std::string& path);

// OFF, COFF, NOFF, STOFF and combinations ("CNOFF", ...), headerless counts
// too. Comments (#) anywhere; polygons are fan-triangulated (v0, vk, vk+1).
// Strict: wrong counts, malformed numbers, indices out of range and
// polygons with fewer than 3 vertices are kParse/kInvalidMesh errors with the
// line number. O(file size).
Result<RawMesh> read_off(const std::string& path);

// PLY, ASCII and binary (either byte order): vertex x y z, optional normals
// (nx ny nz), colours (red green blue [alpha]; integers scaled to 0..1) and
// texture coordinates (u v, s t, texture_u texture_v); faces from the
// "vertex_indices" (or "vertex_index") list, fan-triangulated; other
// elements and properties skipped. Vertices are kept exactly as the file has
// them (Draco's PLY reader merges equal positions and drops texture
// coordinates, which would break export/import round trips). Strict bounds
// and count checks. O(file size).
Result<RawMesh> read_ply(const std::string& path);

// ASCII STL: every "vertex x y z" of every facet, three per triangle (not
// welded here). Draco reads binary STL only. O(file size).
Result<RawMesh> read_ascii_stl(const std::string& path);

// STL: binary (exactly 84 + 50 * count bytes) read straight into the mesh's
// arrays in fixed-size chunks, three corners per triangle in file order (not
// welded here); anything else starting with "solid" goes to read_ascii_stl.
// Facet normals are counted in the contents, not kept (per facet, not per
// vertex; writers recompute them from the winding). O(file size), no copy
// of the file.
Result<RawMesh> read_stl(const std::string& path);

// OBJ: `v x y z [w]` (or `v x y z r g b`: per-vertex colours when every
// vertex has one; 0..255 values are scaled to 0..1), `vn`, `vt`, faces `f`
// with corners `i`, `i/j`, `i//k`, `i/j/k` (negative = relative to the
// elements so far; positive ones may point forward), polygons
// fan-triangulated (c0, c(k-1), ck). One vertex per `v` line; normals and
// texture coordinates are kept per vertex when all corners of a vertex agree,
// else per corner (seams); dropped with a note only when some corners have
// none. `usemtl` gives face_materials, `mtllib` the materials' colours and
// textures (apply_material_libraries). `#` comments, CRLF, `\`
// continuation; o/g/s and free-form lines are ignored, `l`/`p`
// elements skipped and counted in a note. Strict: malformed numbers or
// corner tokens (kParse), NaN/Inf positions and indices out of range
// (kInvalidMesh) are errors naming the line and the token. Never hands the
// text to Draco (its ObjDecoder corrupts the heap on malformed corners).
// O(file size), one read, no allocation per token.
Result<RawMesh> read_obj(const std::string& path);

// The materials of an OBJ read by parse_obj_text: its mtllib files beside
// `obj_path` give each used material its Kd colour (and d/Tr opacity) and
// map_Kd texture (the image file's bytes). Missing MTL or image files, maps
// other than map_Kd and materials no MTL defines are notes, never errors.
void apply_material_libraries(const std::string& obj_path, RawMesh& raw);

// read_obj on text already in memory (tests, fuzzing). Same rules, no
// material files (they are looked up beside a path).
Result<RawMesh> parse_obj_text(std::string_view text);

// glTF 2.0: .gltf (external or embedded buffers and images) and .glb,
// through Draco's scene reader (gltf_reader.cpp): every mesh instance of the
// default scene with its node transform, one face material per primitive,
// normals/texture coordinates/colours per corner (set 0; clean_mesh makes
// them per vertex where they have no seam), other attributes (TANGENT,
// TEXCOORD_1, JOINTS_0, ...) as extra attributes, images with their
// original bytes. What is not carried (animations, skins, cameras, morph
// targets, texture transforms, unknown extensions) is named in the notes.
// A file Draco refuses, a truncated GLB or a missing buffer/image file is
// an error naming the reason.
Result<RawMesh> read_gltf(const std::string& path);

// .drc through Draco's io (an .obj path goes to read_obj, .stl to read_stl).
// Positions are read per face corner through the point-to-value mapping, so
// Draco's own de-duplication does not hide what the file holds. Normals,
// colours and texture coordinates are kept when every vertex has one
// consistent value.
Result<RawMesh> read_with_draco(const std::string& path);

// Draco's ObjDecoder, kept ONLY as the peer that tests and benchmarks compare
// read_obj with, on well-formed files. Never call it on untrusted input:
// Debian's Draco 1.5 writes outside a heap block on malformed face tokens
// (tests/fuzz/regressions/mesh_import/obj-malformed-corner-heap-corruption).
Result<RawMesh> read_trusted_obj_with_draco(const std::string& path);

// Draco's StlDecoder (binary STL), kept ONLY as the peer tests compare
// read_stl with: the same positions in the same order and the same faces.
// It keeps facet normals when consistent per vertex (never, after welding,
// on a real mesh), which read_stl does not.
Result<RawMesh> read_stl_with_draco(const std::string& path);

}  // namespace meshstream

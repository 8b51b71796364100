// Writing meshes: PLY (binary little-endian or ASCII), OBJ and OFF with
// whatever optional attributes the mesh has, binary STL (positions only: the
// format has no per-vertex attributes). Chosen by the file's extension.
// Every writer refuses an invalid mesh (kInvalidMesh) and names the file on
// I/O errors (kIo). O(vertices + faces).
#pragma once

#include <string>
#include <vector>

#include "common/base/result.h"
#include "common/mesh/mesh.h"

namespace meshstream {

enum class PlyEncoding { kBinary, kAscii };

// Per-vertex formats (PLY, OFF) split seam vertices (per-corner values)
// into copies and say so in the header comment. PLY stores the extra
// attributes (tangents, a second UV set, custom ones) as vertex properties
// of their own type, named by ply_extra_property_names, and names what it
// cannot store (materials and textures). OBJ keeps seams (vt/vn per
// corner), writes usemtl groups and, beside the OBJ, STEM.mtl (Kd, d,
// map_Kd) and the texture images (STEM_NAME.png/.jpg, original bytes).
Status write_ply(const Mesh& mesh, const std::string& path,
                 PlyEncoding encoding = PlyEncoding::kBinary);
Status write_obj(const Mesh& mesh, const std::string& path);
// OFF text: the keyword ([ST][C][N]OFF) announces normals, colours (floats
// in 0..1) and texture coordinates when the mesh has them.
Status write_off(const Mesh& mesh, const std::string& path);
// Binary STL: 50 bytes a triangle (facet normal computed from the corners,
// zero when degenerate), the corners' floats as they are. Attributes are
// not written, and vertices no face uses are lost.
Status write_stl(const Mesh& mesh, const std::string& path);
// glTF 2.0: .glb (one file) or .gltf with STEM.bin and the images beside
// it (gltf_writer.cpp). One primitive per material, seams split into
// glTF vertices, positions/normals/UVs/colours as floats, extra attributes
// under their glTF semantic when glTF allows it (TANGENT, TEXCOORD_n,
// COLOR_n, JOINTS_n, WEIGHTS_n) and as "_NAME" otherwise; materials as
// pbrMetallicRoughness with the images' original bytes.
Status write_gltf(const Mesh& mesh, const std::string& path);

// Helpers the OBJ and glTF writers share: the name a material gets in a
// file (safe, unique), the file names of the textures written beside a
// file (PREFIX + the texture's safe name + its type's extension, unique),
// and writing the MTL file and images beside `obj_path` (returns the MTL's
// file name).
std::string material_file_name(const Mesh& mesh, uint32_t material);
std::vector<std::string> texture_file_names(const Mesh& mesh, const std::string& prefix);
Status write_file_bytes(const std::string& path, const void* data, size_t size);
Result<std::string> write_material_files(const Mesh& mesh, const std::string& obj_path);

// The PLY vertex properties of an extra attribute: its name made one safe
// token ("extra_" first when it is a name readers take for positions,
// normals, colours or texture coordinates), then "_i" per component when it
// has more than one (TANGENT -> TANGENT_0 .. TANGENT_3).
std::vector<std::string> ply_extra_property_names(const ExtraAttribute& e);

// What writing `mesh` to `path` (the format write_mesh picks by extension)
// cannot store, one phrase each ("extra attributes TANGENT, TEXCOORD_1 (OBJ has no such
// attribute)", "vertex colours"), for the commands' warnings: nothing is
// dropped without a word. Empty when the format holds everything.
std::vector<std::string> export_losses(const Mesh& mesh, const std::string& path);

// By extension (any case): .ply (binary), .obj, .off, .stl (binary), .glb, .gltf.
// kInvalidArgument for anything else (the same error as
// check_mesh_output_path).
Status write_mesh(const Mesh& mesh, const std::string& path);
// Whether write_mesh can write `path` (its extension only; the folder is not
// looked at), so a command can refuse a name before it does the work.
Status check_mesh_output_path(const std::string& path);

}  // namespace meshstream

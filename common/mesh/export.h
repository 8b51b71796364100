// Writing meshes: PLY (binary little-endian or ASCII), OBJ and OFF with
// whatever optional attributes the mesh has, binary STL (positions only: the
// format has no per-vertex attributes). Chosen by the file's extension.
// Every writer refuses an invalid mesh (kInvalidMesh) and names the file on
// I/O errors (kIo). O(vertices + faces).
#pragma once

#include <string>

#include "common/base/result.h"
#include "common/mesh/mesh.h"

namespace meshstream {

enum class PlyEncoding { kBinary, kAscii };

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
// By extension (any case): .ply (binary), .obj, .off, .stl (binary).
// kInvalidArgument for anything else (the same error as
// check_mesh_output_path).
Status write_mesh(const Mesh& mesh, const std::string& path);
// Whether write_mesh can write `path` (its extension only; the folder is not
// looked at), so a command can refuse a name before it does the work.
Status check_mesh_output_path(const std::string& path);

}  // namespace meshstream

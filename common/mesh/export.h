// Writing meshes: PLY (binary little-endian or ASCII) and OBJ, with whatever
// optional attributes the mesh has. Chosen by the file's extension.
#pragma once

#include <string>

#include "common/base/result.h"
#include "common/mesh/mesh.h"

namespace meshstream {

enum class PlyEncoding { kBinary, kAscii };

Status write_ply(const Mesh& mesh, const std::string& path,
                 PlyEncoding encoding = PlyEncoding::kBinary);
Status write_obj(const Mesh& mesh, const std::string& path);
// By extension: .ply (binary), .obj. kInvalidArgument for anything else.
Status write_mesh(const Mesh& mesh, const std::string& path);

}  // namespace meshstream

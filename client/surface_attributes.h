// Copying what a decoded mesh carries besides positions and triangles
// (normals, colours, texture coordinates per vertex or per corner,
// materials, textures, carried attributes) into the meshes the display
// pipeline hands out. Positions and triangles follow the records' changes
// (decoded_stream.h, frame_mesh_pool.h); these arrays are copied whole when
// a record may have changed them, and the textures (large, and changed only
// by texture records) only when one did.
#pragma once

#include "common/mesh/mesh.h"

namespace meshstream::client {

inline void copy_surface_attributes(const Mesh& from, Mesh& to, bool textures) {
  to.normals = from.normals;
  to.colors = from.colors;
  to.texcoords = from.texcoords;
  to.corner_normals = from.corner_normals;
  to.corner_colors = from.corner_colors;
  to.corner_texcoords = from.corner_texcoords;
  to.materials = from.materials;
  to.face_materials = from.face_materials;
  to.extra_attributes = from.extra_attributes;
  if (textures) to.textures = from.textures;
}

}  // namespace meshstream::client

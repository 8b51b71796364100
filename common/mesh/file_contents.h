// What a mesh file holds besides positions and faces, counted as the file
// has it, whether or not import keeps it: `meshstream info` reports it, so a
// file's texture coordinates or materials are never silently invisible.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace meshstream {

// One per-vertex attribute kind of the file.
struct AttributeInFile {
  // Values in the file: OBJ `vn`/`vt` lines or vertices with a colour; PLY,
  // OFF and Draco: vertices (or values) that carry one. 0: none in the file.
  uint64_t count = 0;
  // Why import did not keep them ("" when kept or absent), e.g. "they differ
  // between corners of one vertex (per-face values)".
  std::string dropped;
};

// An OBJ `mtllib` file, looked up beside the OBJ.
struct MaterialLibrary {
  std::string name;                    // as the mtllib line writes it
  bool found = false;                  // the file exists and could be read
  std::vector<std::string> materials;  // its `newmtl` names
  std::vector<std::string> textures;   // the files its map_* lines name, first use order
};

struct FileContents {
  std::string format;  // "OBJ", "PLY (ascii)", "OFF", "STL", "DRC", ...
  AttributeInFile normals, texcoords, colors;
  std::vector<MaterialLibrary> material_libraries;  // OBJ mtllib, in file order
  std::vector<std::string> materials_used;          // OBJ usemtl names, distinct, in file order
  // Data the readers skip: PLY properties other than positions, normals,
  // colours, texture coordinates and the face index list ("vertex
  // confidence (float)"), OFF face colours.
  std::vector<std::string> extra_properties;
  std::vector<std::string> other_elements;  // PLY elements besides vertex and face: "edge (120)"
};

// Reads the `mtllib` file `name` beside `obj_path`: its materials and the
// texture files they name. A missing or unreadable file gives found = false.
MaterialLibrary read_material_library(const std::string& obj_path, const std::string& name);

}  // namespace meshstream

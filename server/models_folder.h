// What a --models folder holds, decided before anything is loaded or
// encoded: the files the server serves and the name each is served under,
// every entry it skips and why, and the names two files would have shared.
// Pure file-system listing (no file is opened), so it costs a directory
// read and can be unit-tested on a temp folder.
#pragma once

#include <string>
#include <vector>

#include "common/base/result.h"

namespace meshstream::server {

struct ModelFile {
  std::string path;
  std::string name;  // the catalog name it is served under
};

struct SkippedEntry {
  std::string path;
  std::string reason;  // "'.txt' is not a model format (the server reads ...)"
};

// Files whose names without extension are the same: the first (in the
// naming order) is served under that name, the others under their file names.
struct NameClash {
  std::string name;              // the shared name ("bunny")
  std::vector<ModelFile> files;  // as served: {bunny.off, "bunny"}, {bunny.stl, "bunny.stl"}
};

struct FolderScan {
  std::vector<ModelFile> hcs;     // served as they are
  std::vector<ModelFile> meshes;  // imported and encoded
  std::vector<SkippedEntry> skipped;
  std::vector<NameClash> clashes;
};

// The extensions the server reads, for messages: ".hcs, .ply, .obj, .stl, .off, .drc, .gltf, .glb".
const char* served_extensions();

// Lists `dir` (not its subfolders). Naming rule: `.hcs` files first, then
// mesh files (.ply .obj .stl .off .drc .gltf .glb, any case), each group in byte order
// of file name; a file is served under its name without extension unless an
// earlier file took that name, then under its whole file name. Everything
// else (other extensions, no extension, subfolders, special files) is
// skipped with a reason. kIo when `dir` cannot be listed.
Result<FolderScan> scan_models_folder(const std::string& dir);

// "model name 'bunny' is claimed by 2 files: serving /m/bunny.off as 'bunny', /m/bunny.stl as
// 'bunny.stl'".
std::string describe(const NameClash& clash);

}  // namespace meshstream::server

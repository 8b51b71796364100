// Where models come from, as work for the encoder pool or the folder
// watcher: a `.hcs` file (checked and served as it is), a mesh file
// (imported and encoded, cached by content), the procedural demo models.
#pragma once

#include <string>
#include <vector>

#include "server/catalog.h"
#include "server/encoder_pool.h"
#include "server/models_folder.h"

namespace meshstream::server {

// Reads `file` (a `.hcs`) into memory and checks its index and CRCs
// (make_model). Read, not mapped: a file in a watched folder may be
// rewritten in place while sessions stream it. Errors name the file.
// O(file size).
Result<CatalogModel> load_hcs_file(const ModelFile& file);

// Imports and encodes `file` (cached in `cache_dir` by content hash and
// encoder version; empty = no cache) when the pool runs the task.
EncodeTask mesh_file_task(const ModelFile& file, const std::string& cache_dir);

// "demo" (trefoil, ~100k vertices), "demo-small" (~10k) and "torus", cached
// in `cache_dir` (empty = no cache). Empty when this build has no demo
// meshes.
std::vector<EncodeTask> demo_tasks(const std::string& cache_dir);

}  // namespace meshstream::server

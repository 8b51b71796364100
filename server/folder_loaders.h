// The two halves of models_folder_source (catalog.h), one per kind of file
// a models folder holds, after scan_models_folder has named them.
#pragma once

#include <string>
#include <vector>

#include "server/catalog.h"
#include "server/models_folder.h"

namespace meshstream::server {

// Maps each `.hcs` file and adds it under its name once its index and CRCs
// check out; a file that does not is one warning.
void add_hcs_files(const std::vector<ModelFile>& files, Catalog& catalog, const CatalogLog& log);

// Imports and encodes each mesh file (cached in `cache_dir`, empty = no
// cache) on `threads` threads and adds the successes; a failure is one
// warning naming the file.
void encode_mesh_files(const std::vector<ModelFile>& files, const std::string& cache_dir,
                       unsigned threads, Catalog& catalog, const CatalogLog& log);

}  // namespace meshstream::server

// Encoding meshes into catalog models with an on-disk cache: a stream is
// stored as `<cache>/<key>-q<bits>-e<kEncoderVersion>.hcs`, so the same input
// encoded by the same encoder version is mapped, not encoded, on the next
// start. Used by the mesh-folder and demo catalog sources.
#pragma once

#include <functional>
#include <string>

#include "common/base/result.h"
#include "common/codec/encode_progress.h"
#include "common/mesh/mesh.h"
#include "server/catalog.h"

namespace meshstream::server {

struct EncodeJob {
  std::string name;    // catalog name
  std::string source;  // "mesh" or "demo"
  std::string origin;  // for messages
  std::string key;     // identifies the input (content hash, demo parameters)
  // Produces the mesh to encode; called only on a cache miss.
  std::function<Result<Mesh>()> make_mesh;
};

struct EncodeOutcome {
  Result<CatalogModel> model = make_error(ErrorCode::kIo, "not run");
  bool from_cache = false;
  double seconds = 0;
};

// Maps the cached stream for `job` or makes, encodes, caches and maps it.
// `cache_dir` empty = no cache (the stream is kept in memory). A broken
// cache entry is re-encoded and replaced; writes are atomic (temp + rename)
// and a miss is encoded under the entry's lock (server/cache_lock.h), so
// threads and processes sharing `cache_dir` encode each entry once and never
// see it half-written. Cost: an encode on a miss, O(1) on a hit.
// `progress`, if set, gets the encoder's progress (encode_progress.h) on
// this thread; a cache hit reports nothing.
EncodeOutcome encode_cached(const EncodeJob& job, const std::string& cache_dir,
                            const EncodeProgressCallback& progress = {});

// Makes `dir` ready to hold cached streams: nothing to do when it is a
// folder; else creates it, only its last level unless `create_parents` (a
// mistyped --cache must not grow a tree of folders). True when it was
// created. kInvalidArgument when it exists as a file or (without
// `create_parents`) its parent is missing, kIo when creating fails; the
// message names `dir`.
Result<bool> prepare_cache_folder(const std::string& dir, bool create_parents);

// Whether this build has the mesh importer, encoder and demo meshes.
bool encoder_built();

}  // namespace meshstream::server

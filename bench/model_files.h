// The models the attribute benches read (../shared/models, see its MANIFEST.md).
#pragma once

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace meshstream::bench {

// ../models beside MESHSTREAM_TEST_MESHES (where the tests find the meshes),
// else the shared folder of this workplace.
inline std::string default_models_dir() {
  namespace fs = std::filesystem;
  if (const char* meshes = std::getenv("MESHSTREAM_TEST_MESHES"))
    if (fs::exists(fs::path(meshes) / ".." / "models"))
      return (fs::path(meshes) / ".." / "models").string();
  return "/work/shared/models";
}

// Every model file under dir that import reads with its attributes (PLY, OBJ,
// glTF, GLB), sorted so that tables come out in the same order each run.
inline std::vector<std::filesystem::path> model_files(const std::string& dir) {
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir)) {
    const std::string ext = e.path().extension().string();
    if (ext == ".ply" || ext == ".obj" || ext == ".glb" || ext == ".gltf")
      files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace meshstream::bench

// Finding the real test meshes (../shared/meshes, see its MANIFEST.md).
// Tests that need them call MESHSTREAM_REQUIRE_TEST_MESHES() and are
// reported as skipped, visibly, when the folder is absent.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <string>

namespace meshstream::testing {

// $MESHSTREAM_TEST_MESHES, else ../shared/meshes beside the repository;
// empty when neither exists.
inline std::string test_mesh_dir() {
  if (const char* env = std::getenv("MESHSTREAM_TEST_MESHES"); env && *env) {
    if (std::filesystem::is_directory(env)) return env;
  }
#ifdef MESHSTREAM_SOURCE_DIR
  std::filesystem::path shared =
      std::filesystem::path(MESHSTREAM_SOURCE_DIR) / ".." / "shared" / "meshes";
  if (std::filesystem::is_directory(shared)) return std::filesystem::canonical(shared).string();
#endif
  return {};
}

inline std::string test_mesh(const std::string& name) { return test_mesh_dir() + "/" + name; }

// The models with attributes (../shared/models, see its MANIFEST.md):
// $MESHSTREAM_TEST_MODELS, else ../shared/models beside the repository, else
// models/ beside $MESHSTREAM_TEST_MESHES; empty when none exists.
inline std::string test_model_dir() {
  if (const char* env = std::getenv("MESHSTREAM_TEST_MODELS"); env && *env) {
    if (std::filesystem::is_directory(env)) return env;
  }
#ifdef MESHSTREAM_SOURCE_DIR
  std::filesystem::path shared =
      std::filesystem::path(MESHSTREAM_SOURCE_DIR) / ".." / "shared" / "models";
  if (std::filesystem::is_directory(shared)) return std::filesystem::canonical(shared).string();
#endif
  if (const char* env = std::getenv("MESHSTREAM_TEST_MESHES"); env && *env) {
    std::filesystem::path beside = std::filesystem::path(env) / ".." / "models";
    if (std::filesystem::is_directory(beside)) return std::filesystem::canonical(beside).string();
  }
  return {};
}

inline std::string test_model(const std::string& name) { return test_model_dir() + "/" + name; }

// The node_modules folder holding the Khronos gltf-validator
// ($MESHSTREAM_GLTF_VALIDATOR, set by scripts/test; else build/gltf-validator).
inline std::string gltf_validator_modules() {
  if (const char* env = std::getenv("MESHSTREAM_GLTF_VALIDATOR"); env && *env) {
    if (std::filesystem::is_directory(env)) return env;
  }
#ifdef MESHSTREAM_BINARY_DIR
  std::filesystem::path local =
      std::filesystem::path(MESHSTREAM_BINARY_DIR) / "gltf-validator" / "node_modules";
  if (std::filesystem::is_directory(local / "gltf-validator")) return local.string();
#endif
  return {};
}

}  // namespace meshstream::testing

#define MESHSTREAM_REQUIRE_TEST_MESHES()                                               \
  do {                                                                                 \
    if (::meshstream::testing::test_mesh_dir().empty())                                \
      GTEST_SKIP() << "real test meshes not found (set MESHSTREAM_TEST_MESHES or put " \
                      "../shared/meshes beside the repository)";                       \
  } while (0)

#define MESHSTREAM_REQUIRE_TEST_MODELS()                                          \
  do {                                                                            \
    if (::meshstream::testing::test_model_dir().empty())                          \
      GTEST_SKIP() << "test models not found (set MESHSTREAM_TEST_MODELS or put " \
                      "../shared/models beside the repository)";                  \
  } while (0)

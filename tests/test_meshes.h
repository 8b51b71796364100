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

}  // namespace meshstream::testing

#define MESHSTREAM_REQUIRE_TEST_MESHES()                                               \
  do {                                                                                 \
    if (::meshstream::testing::test_mesh_dir().empty())                                \
      GTEST_SKIP() << "real test meshes not found (set MESHSTREAM_TEST_MESHES or put " \
                      "../shared/meshes beside the repository)";                       \
  } while (0)

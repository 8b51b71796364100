// `meshstream subdivide` follows its contract: output written with the
// expected counts, usage errors exit 2, bad data exits 1.
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>

#include "tests/asa/asa_test_support.h"

namespace meshstream {
namespace {

std::string tool() { return std::string(MESHSTREAM_BINARY_DIR) + "/tools/meshstream"; }

int run(const std::string& args) {
  const std::string command = tool() + " " + args + " > /dev/null 2>&1";
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(AsaTool, SubdivideCommand) {
  if (!std::filesystem::exists(tool())) GTEST_SKIP() << "meshstream tool not built";
  MESHSTREAM_REQUIRE_TEST_MESHES();
  const std::string in = ::meshstream::testing::test_mesh("fandisk.off");
  const std::string out = (std::filesystem::temp_directory_path() / "asa_tool_test.ply").string();
  ASSERT_EQ(run("subdivide " + in + " -o " + out + " --levels 2 --uniform"), 0);
  auto result = import_mesh(out);
  ASSERT_TRUE(result.has_value());
  EXPECT_EQ(result->mesh.face_count(), 16u * 12946u);
  ASSERT_EQ(run("subdivide " + in + " -o " + out +
                " --levels 2 --flatness 0.8 --rule projection --crease 45 "
                "--tension 0.01"),
            0);
  EXPECT_EQ(run("subdivide " + in + " -o " + out + " --rule bogus"), 2);
  EXPECT_EQ(run("subdivide " + in + " -o " + out + " --flatness 3"), 2);
  EXPECT_EQ(run("subdivide " + in), 2);
  EXPECT_EQ(run("subdivide /nonexistent/mesh.off -o " + out), 1);
  EXPECT_EQ(run("subdivide " + in + " -o /tmp/unsupported.xyz"), 2);  // a usage error, found first
  std::filesystem::remove(out);
}

}  // namespace
}  // namespace meshstream

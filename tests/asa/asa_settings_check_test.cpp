// The crease/flatness clash rule (common/asa/settings_check.h) says what
// ASA really does: below acos(t) a crease angle leaves ASA nothing to
// refine, at or above it ASA refines again; the programs refuse exactly the
// settings the rule flags.
#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/asa/settings_check.h"
#include "tests/asa/asa_test_support.h"

namespace meshstream {
namespace {

TEST(AsaSettingsCheck, ACreaseBelowTheFlatnessAngleLeavesNothingToRefine) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  const Mesh mesh = asa_test::load("fandisk.off");
  for (float t : {0.7f, 0.85f, 0.95f}) {
    const double limit = flatness_angle_degrees(t);
    AsaOptions below;
    below.flatness = t;
    below.crease_degrees = static_cast<float>(limit - 0.5);
    AsaOptions above = below;
    above.crease_degrees = static_cast<float>(limit + 5);
    EXPECT_FALSE(asa_settings_problem(below, "--crease", "--flatness").empty()) << t;
    EXPECT_TRUE(asa_settings_problem(above, "--crease", "--flatness").empty()) << t;
    auto cancelled = subdivide(mesh, below);
    auto refined = subdivide(mesh, above);
    ASSERT_TRUE(cancelled.has_value() && refined.has_value());
    // The flagged setting really changes nothing; the allowed one refines.
    EXPECT_EQ(cancelled->mesh.face_count(), mesh.face_count()) << "t " << t;
    EXPECT_GT(refined->mesh.face_count(), mesh.face_count()) << "t " << t;
  }
  // No clash without creases, without levels, or when --uniform ignores t.
  AsaOptions o;
  o.crease_degrees = 30;
  EXPECT_FALSE(asa_settings_problem(o, "--crease", "--flatness").empty());
  o.uniform = true;
  EXPECT_TRUE(asa_settings_problem(o, "--crease", "--flatness").empty());
  o.uniform = false;
  o.levels = 0;
  EXPECT_TRUE(asa_settings_problem(o, "--crease", "--flatness").empty());
  o.levels = 1;
  o.crease_degrees = 0;
  EXPECT_TRUE(asa_settings_problem(o, "--crease", "--flatness").empty());
}

TEST(AsaSettingsCheck, MessageNamesBothValuesAndTheRelation) {
  AsaOptions o;
  o.crease_degrees = 30;
  const std::string m = asa_settings_problem(o, "--crease", "--flatness");
  EXPECT_NE(m.find("--crease 30"), std::string::npos) << m;
  EXPECT_NE(m.find("acos(--flatness 0.85) = 31.8 degrees"), std::string::npos) << m;
  EXPECT_NE(m.find("ASA changes nothing"), std::string::npos) << m;
}

std::string tool() { return std::string(MESHSTREAM_BINARY_DIR) + "/tools/meshstream"; }

struct ToolRun {
  int status = -1;
  std::string err;
};
ToolRun run(const std::string& args) {
  const std::string err_file =
      (std::filesystem::temp_directory_path() / "asa_settings_check.err").string();
  const int s = std::system((tool() + " " + args + " > /dev/null 2> " + err_file).c_str());
  std::stringstream err;
  err << std::ifstream(err_file).rdbuf();
  std::filesystem::remove(err_file);
  return {WIFEXITED(s) ? WEXITSTATUS(s) : -1, err.str()};
}

TEST(AsaSettingsCheck, SubdivideRefusesCancellingSettingsAsAUsageError) {
  if (!std::filesystem::exists(tool())) GTEST_SKIP() << "meshstream tool not built";
  MESHSTREAM_REQUIRE_TEST_MESHES();
  const std::string in = ::meshstream::testing::test_mesh("fandisk.off");
  const std::string out = (std::filesystem::temp_directory_path() / "asa_settings.ply").string();
  std::filesystem::remove(out);
  const ToolRun clash = run("subdivide " + in + " -o " + out + " --crease 30");
  EXPECT_EQ(clash.status, 2) << clash.err;
  EXPECT_NE(clash.err.find("--crease 30 is below acos(--flatness 0.85) = 31.8"), std::string::npos)
      << clash.err;
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_EQ(run("subdivide " + in + " -o " + out + " --crease 30 --flatness 0.9").status, 0);
  EXPECT_EQ(run("subdivide " + in + " -o " + out + " --crease 30 --uniform").status, 0);
  std::filesystem::remove(out);
}

}  // namespace
}  // namespace meshstream

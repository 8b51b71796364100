// `meshstream encode`'s switches, through the real tool binary: what
// --no-bit-planes and --base-shift write, and that --issue1-order (the old
// name of --no-bit-planes, kept as a hidden alias) still gives the same bytes.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "common/codec/container.h"
#include "common/codec/stream_format.h"

namespace meshstream {
namespace {

namespace fs = std::filesystem;

std::string tool() { return std::string(MESHSTREAM_BINARY_DIR) + "/tools/meshstream"; }

std::vector<uint8_t> read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string read_text(const fs::path& path) {
  const std::vector<uint8_t> bytes = read_bytes(path);
  return {bytes.begin(), bytes.end()};
}

class EncodeCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    // Per process and test: other checkouts may run the same tests at once.
    dir_ = fs::temp_directory_path() /
           ("ms_encode_command_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    mesh_ = dir_ / "sphere.ply";
    ASSERT_EQ(shell(tool() + " generate icosphere --size 3 -o " + mesh_.string()), 0);
  }
  void TearDown() override { fs::remove_all(dir_); }

  int shell(const std::string& command) {
    return std::system((command + " >" + (dir_ / "out.txt").string() + " 2>&1").c_str());
  }

  // Encodes the sphere with `flags`; the stream's bytes (empty on failure).
  std::vector<uint8_t> encode(const std::string& flags, const std::string& name) {
    const fs::path out = dir_ / name;
    if (shell(tool() + " encode " + mesh_.string() + " -o " + out.string() + " " + flags) != 0)
      return {};
    return read_bytes(out);
  }

  // Plane records (bit planes of positions) in `stream`.
  static size_t plane_records(const std::vector<uint8_t>& stream, const StreamIndex& index) {
    size_t planes = 0;
    for (size_t i = 1; i < index.records.size(); ++i)
      planes += stream.at(index.records[i].offset) == kRecordPlane;
    return planes;
  }

  fs::path dir_, mesh_;
};

TEST_F(EncodeCommand, NoBitPlanesWritesExactPositionsAndTheOldNameTheSameBytes) {
  const std::vector<uint8_t> embedded = encode("", "default.hcs");
  const std::vector<uint8_t> exact = encode("--no-bit-planes", "exact.hcs");
  const std::vector<uint8_t> alias = encode("--issue1-order", "alias.hcs");
  ASSERT_FALSE(embedded.empty());
  ASSERT_FALSE(exact.empty());
  ASSERT_FALSE(alias.empty());
  EXPECT_EQ(alias, exact);

  auto embedded_index = read_stream_index(embedded);
  auto exact_index = read_stream_index(exact);
  ASSERT_TRUE(embedded_index && exact_index);
  // The default stream sends low bits later (an 8-bit base at 12 bits);
  // --no-bit-planes sends every position exact: base shift 0, no plane records.
  EXPECT_EQ(embedded_index->header.extra.at(1), 4);
  EXPECT_GT(plane_records(embedded, *embedded_index), 0u);
  EXPECT_EQ(exact_index->header.extra.at(1), 0);
  EXPECT_EQ(plane_records(exact, *exact_index), 0u);
  EXPECT_NE(exact, embedded);
}

TEST_F(EncodeCommand, BaseShiftIsAutomaticUnlessGiven) {
  const std::vector<uint8_t> automatic = encode("", "automatic.hcs");
  const std::vector<uint8_t> four = encode("--base-shift 4", "four.hcs");
  const std::vector<uint8_t> two = encode("--base-shift 2", "two.hcs");
  ASSERT_FALSE(automatic.empty());
  ASSERT_FALSE(two.empty());
  EXPECT_EQ(four, automatic);  // 12 bits: automatic is an 8-bit base
  auto index = read_stream_index(two);
  ASSERT_TRUE(index);
  EXPECT_EQ(index->header.extra.at(1), 2);
  EXPECT_TRUE(encode("--base-shift 13", "refused.hcs").empty());
}

TEST_F(EncodeCommand, HelpNamesTheFlagAfterWhatItDoes) {
  ASSERT_EQ(shell(tool() + " encode --help"), 0);
  const std::string help = read_text(dir_ / "out.txt");
  EXPECT_NE(help.find("--no-bit-planes"), std::string::npos) << help;
  EXPECT_EQ(help.find("--issue1-order"), std::string::npos) << help;
  EXPECT_EQ(help.find("issue I"), std::string::npos) << help;
}

// stderr is a file here, not a terminal: no bar and no carriage return
// unless --progress asks; then the bar names the stages and ends at 100 %
// (and is cleared). --no-progress wins. The stream is the same every way,
// and for every --threads.
TEST_F(EncodeCommand, ProgressBarOnlyWhenAskedOffATerminal) {
  const std::vector<uint8_t> plain = encode("", "plain.hcs");
  ASSERT_FALSE(plain.empty());
  const std::string quiet = read_text(dir_ / "out.txt");
  EXPECT_EQ(quiet.find('\r'), std::string::npos) << quiet;
  EXPECT_EQ(quiet.find("encode: "), std::string::npos) << quiet;

  EXPECT_EQ(encode("--progress", "bar.hcs"), plain);
  const std::string bar = read_text(dir_ / "out.txt");
  for (const char* part : {"\rencode: reading ", "encode: decimating [", "encode: coding records [",
                           "encode: measuring [", "] 100 %"})
    EXPECT_NE(bar.find(part), std::string::npos) << part << " in " << bar;

  EXPECT_EQ(encode("--progress --no-progress", "none.hcs"), plain);
  EXPECT_EQ(read_text(dir_ / "out.txt").find('\r'), std::string::npos);
  EXPECT_EQ(encode("--threads 1", "one.hcs"), plain);
  EXPECT_EQ(encode("--threads 3", "three.hcs"), plain);
}

}  // namespace
}  // namespace meshstream

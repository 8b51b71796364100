// The one budget rule (common/codec/budget.h) and the one set of budget
// options (common/cli/budget_options.h): what every program accepts, what it
// refuses and the message it refuses with.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "common/cli/budget_options.h"
#include "common/codec/budget.h"
#include "common/codec/decoder.h"

namespace meshstream {
namespace {

using Kind = Budget::Kind;

TEST(BudgetRule, AcceptsEveryNumberFormOfAValidValue) {
  const struct {
    Kind kind;
    const char* text;
    double value;
  } cases[] = {
      {Kind::kBytes, "0", 0},
      {Kind::kBytes, "10000", 10000},
      {Kind::kBytes, "1e4", 10000},
      {Kind::kBytes, "+250", 250},
      {Kind::kBytes, "10000.0", 10000},
      {Kind::kBytes, "9007199254740992", 9007199254740992.0},
      {Kind::kVertices, "0", 0},
      {Kind::kVertices, "4294967295", 4294967295.0},
      {Kind::kPercentVertices, "100", 100},
      {Kind::kPercentVertices, "0.5", 0.5},
      {Kind::kPercentVertices, "1e-3", 0.001},
      {Kind::kPercentBytes, "12.5", 12.5},
      {Kind::kRatio, "1", 1},
      {Kind::kRatio, "20", 20},
  };
  for (const auto& c : cases) {
    auto parsed = parse_budget(c.kind, c.text);
    ASSERT_TRUE(parsed) << c.text << ": " << parsed.error().message;
    EXPECT_EQ(parsed->kind, c.kind) << c.text;
    EXPECT_EQ(parsed->value, c.value) << c.text;
  }
}

TEST(BudgetRule, RefusesNamingTheTextAndTheReason) {
  const struct {
    Kind kind;
    const char* text;
    const char* message;
  } cases[] = {
      {Kind::kPercentVertices, "abc", "'abc' is not a number"},
      {Kind::kPercentVertices, "", "'' is not a number"},
      {Kind::kPercentVertices, "5%", "'5%' is not a number"},
      {Kind::kPercentVertices, " 5", "' 5' is not a number"},
      {Kind::kPercentVertices, "nan", "'nan' is not a number"},
      {Kind::kPercentVertices, "0", "'0' is out of range (0 < P <= 100)"},
      {Kind::kPercentVertices, "-0", "'-0' is out of range (0 < P <= 100)"},
      {Kind::kPercentVertices, "100.0001", "'100.0001' is out of range (0 < P <= 100)"},
      {Kind::kPercentBytes, "0", "'0' is out of range (0 < P <= 100)"},
      {Kind::kPercentBytes, "inf", "'inf' is not a finite number"},
      {Kind::kBytes, "-5", "'-5' is negative (a byte count is 0 or more)"},
      {Kind::kBytes, "1.5", "'1.5' is not a whole number (a byte count)"},
      {Kind::kBytes, "0x10", "'0x10' is not a number"},
      {Kind::kBytes, "1e999", "'1e999' is out of range"},
      {Kind::kBytes, "1e16", "'1e16' is too large (at most 9007199254740992)"},
      {Kind::kVertices, "-1", "'-1' is negative (a vertex count is 0 or more)"},
      {Kind::kVertices, "5e9", "'5e9' is too large (at most 4294967295)"},
      {Kind::kRatio, "0.5", "'0.5' is out of range (a ratio CR >= 1)"},
      {Kind::kRatio, "0", "'0' is out of range (a ratio CR >= 1)"},
  };
  for (const auto& c : cases) {
    auto parsed = parse_budget(c.kind, c.text);
    ASSERT_FALSE(parsed) << c.text;
    EXPECT_EQ(parsed.error().code, ErrorCode::kInvalidArgument) << c.text;
    EXPECT_EQ(parsed.error().message, c.message);
  }
}

TEST(BudgetRule, CheckNamesTheFieldAndTheValue) {
  EXPECT_TRUE(check_budget(Budget::all(), "budget"));
  EXPECT_TRUE(check_budget(Budget::bytes(0), "budget bytes"));
  auto bad = check_budget(Budget::percent_vertices(0), "budget percent_vertices");
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().message, "budget percent_vertices 0 is out of range (0 < P <= 100)");
  auto nan = check_budget(Budget::percent_bytes(std::nan("")), "budget percent");
  ASSERT_FALSE(nan);
  EXPECT_EQ(nan.error().message, "budget percent nan is not a number");
  EXPECT_FALSE(check_budget(Budget::bytes(std::numeric_limits<double>::infinity()), "b"));
}

// A stream index with records of 100 bytes after a 50-byte prefix.
StreamIndex hundred_byte_records(uint32_t count) {
  StreamIndex index;
  index.payload_offset = 50;
  index.header.vertex_count = 1000 * count;
  for (uint32_t i = 0; i < count; ++i) {
    RecordEntry r;
    r.offset = 50 + 100ull * i;
    r.size = 100;
    r.vertices = 1000 * (i + 1);
    index.records.push_back(r);
  }
  return index;
}

TEST(BudgetRule, PercentBytesEndsAtFloorOfThePercentOfTheStream) {
  const StreamIndex index = hundred_byte_records(10);  // 1050 bytes
  // 50 % of 1050 = 525: records ending at 150, 250, ..., 450 fit, 550 not.
  EXPECT_EQ(prefix_for_budget(index, Budget::percent_bytes(50)), 450u);
  EXPECT_EQ(prefix_for_budget(index, Budget::percent_bytes(100)), 1050u);
  // Below the base mesh: the base mesh.
  EXPECT_EQ(prefix_for_budget(index, Budget::percent_bytes(1)), 150u);
  // The same prefix as the byte budget of floor(total * P / 100).
  for (double p : {3.0, 14.2857, 33.3, 47.619, 66.7, 99.9}) {
    EXPECT_EQ(prefix_for_budget(index, Budget::percent_bytes(p)),
              prefix_for_budget(index, Budget::bytes(std::floor(1050 * p / 100))))
        << p;
  }
}

// Parses `args` with the shared options; the error message, or "" and the
// budget.
std::string parse_flags(std::vector<std::string> args, Budget& budget) {
  CLI::App app{"test"};
  cli::add_budget_options(
      app, budget,
      {Kind::kBytes, Kind::kVertices, Kind::kPercentVertices, Kind::kPercentBytes, Kind::kRatio});
  std::vector<const char*> argv{"test"};
  for (const std::string& a : args) argv.push_back(a.c_str());
  try {
    app.parse(static_cast<int>(argv.size()), argv.data());
  } catch (const CLI::ParseError& e) {
    return e.what();
  }
  return {};
}

TEST(BudgetOptions, EachFlagParsesIntoItsKind) {
  const struct {
    std::vector<std::string> args;
    Kind kind;
    double value;
  } cases[] = {
      {{"--bytes", "1e4"}, Kind::kBytes, 10000},
      {{"--vertices", "3000"}, Kind::kVertices, 3000},
      {{"--percent", "25"}, Kind::kPercentVertices, 25},
      {{"--percent-bytes", "50"}, Kind::kPercentBytes, 50},
      {{"--ratio", "20"}, Kind::kRatio, 20},
      {{"--bytes=-0"}, Kind::kBytes, 0},
  };
  for (const auto& c : cases) {
    Budget budget;
    EXPECT_EQ(parse_flags(c.args, budget), "") << c.args[0];
    EXPECT_EQ(budget.kind, c.kind) << c.args[0];
    EXPECT_EQ(budget.value, c.value) << c.args[0];
  }
  Budget none;
  EXPECT_EQ(parse_flags({}, none), "");
  EXPECT_EQ(none.kind, Kind::kAll);
}

TEST(BudgetOptions, BadValuesNameTheFlagAndTheValue) {
  Budget budget;
  EXPECT_EQ(parse_flags({"--percent", "abc"}, budget), "--percent: 'abc' is not a number");
  EXPECT_EQ(parse_flags({"--bytes", "-5"}, budget),
            "--bytes: '-5' is negative (a byte count is 0 or more)");
  EXPECT_EQ(parse_flags({"--percent-bytes", "0"}, budget),
            "--percent-bytes: '0' is out of range (0 < P <= 100)");
  EXPECT_NE(parse_flags({"--bytes", "10", "--vertices", "5"}, budget).find("excludes"),
            std::string::npos);
  EXPECT_EQ(std::string(cli::budget_flag(Kind::kPercentVertices)), "--percent");
}

}  // namespace
}  // namespace meshstream

// Where a decode or a stream stops: the one budget type of every program
// (`meshstream decode`, meshstream-client, the server's stream plan) and the
// one rule for which values are valid. prefix_for_budget
// (common/codec/decoder.h) turns a budget into a record boundary; the wire
// form is proto/meshstream.proto's Budget.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "common/base/result.h"

namespace meshstream {

struct Budget {
  enum class Kind {
    kAll,              // the whole stream
    kBytes,            // at most `value` stream bytes (container prefix included)
    kVertices,         // at most `value` decoded vertices
    kPercentVertices,  // at most `value` percent of the full mesh's vertices (HCS's
                       // "percentage of points"; wire Budget.percent_vertices)
    kPercentBytes,     // at most `value` percent of the stream's bytes (wire Budget.percent)
    kRatio,            // 1/`value` of the stream's bytes (compression ratio, >= 1)
  };
  Kind kind = Kind::kAll;
  double value = 0;

  static Budget all() { return {}; }
  static Budget bytes(double n) { return {Kind::kBytes, n}; }
  static Budget vertices(double n) { return {Kind::kVertices, n}; }
  static Budget percent_vertices(double p) { return {Kind::kPercentVertices, p}; }
  static Budget percent_bytes(double p) { return {Kind::kPercentBytes, p}; }
  static Budget ratio(double cr) { return {Kind::kRatio, cr}; }
};

// The largest byte budget (2^53: doubles hold every whole number up to it).
inline constexpr uint64_t kMaxBudgetBytes = uint64_t{1} << 53;

// The valid values of each kind:
//   kBytes, kVertices  a whole number >= 0 (at most 2^53 bytes, 2^32 - 1
//                      vertices); a budget below the base mesh gives the
//                      base mesh, so 0 is allowed
//   kPercent*          0 < P <= 100
//   kRatio             CR >= 1
// Never NaN or infinite.

// Empty when `budget` is valid, else why not, after the value, e.g.
// "is out of range (0 < P <= 100)". O(1).
std::string budget_problem(const Budget& budget);

// kInvalidArgument naming `what` and the value ("budget percent_vertices 0
// is out of range (0 < P <= 100)") when `budget` is invalid. For budgets
// that arrive as numbers (the wire).
Status check_budget(const Budget& budget, std::string_view what);

// Parses a budget value as typed on a command line: a decimal number
// ("2500", "1e4", "12.5"; a leading '+' is allowed), then the rule above.
// kInvalidArgument naming the text: "'abc' is not a number", "'-5' is
// negative (a count is 0 or more)". The one parser of every program's
// budget options (common/cli/budget_options.h).
Result<Budget> parse_budget(Budget::Kind kind, std::string_view text);

}  // namespace meshstream

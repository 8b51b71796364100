#include "common/codec/budget.h"

#include <charconv>
#include <cmath>
#include <cstdint>

namespace meshstream {
namespace {

// Shortest text that reads back as `value` ("0", "-5", "100.5", "nan").
std::string shown(double value) {
  char text[64];
  const auto end = std::to_chars(text, text + sizeof text, value).ptr;
  return std::string(text, end);
}

// Why `value` is no valid count, or empty. Doubles hold whole numbers
// exactly up to 2^53, which bounds byte counts.
std::string count_problem(double value, double most, const char* what) {
  if (value < 0) return std::string("is negative (") + what + " is 0 or more)";
  if (value != std::floor(value)) return std::string("is not a whole number (") + what + ")";
  if (value > most) return "is too large (at most " + shown(most) + ")";
  return {};
}

}  // namespace

std::string budget_problem(const Budget& budget) {
  const double v = budget.value;
  if (budget.kind == Budget::Kind::kAll) return {};
  if (std::isnan(v)) return "is not a number";
  if (!std::isfinite(v)) return "is not a finite number";
  switch (budget.kind) {
    case Budget::Kind::kAll:
      return {};
    case Budget::Kind::kBytes:
      return count_problem(v, double(kMaxBudgetBytes), "a byte count");
    case Budget::Kind::kVertices:
      return count_problem(v, double(UINT32_MAX), "a vertex count");
    case Budget::Kind::kPercentVertices:
    case Budget::Kind::kPercentBytes:
      return v > 0 && v <= 100 ? std::string() : "is out of range (0 < P <= 100)";
    case Budget::Kind::kRatio:
      return v >= 1 ? std::string() : "is out of range (a ratio CR >= 1)";
  }
  return {};
}

Status check_budget(const Budget& budget, std::string_view what) {
  const std::string problem = budget_problem(budget);
  if (problem.empty()) return {};
  return make_error(ErrorCode::kInvalidArgument,
                    std::string(what) + " " + shown(budget.value) + " " + problem);
}

Result<Budget> parse_budget(Budget::Kind kind, std::string_view text) {
  const std::string quoted = "'" + std::string(text) + "'";
  std::string_view digits = text;
  if (!digits.empty() && digits.front() == '+') digits.remove_prefix(1);
  double value = 0;
  // from_chars takes no leading whitespace, '+' or hex prefix and reads the
  // whole of a well-formed number; anything left over means it was not one.
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (digits.empty() || ec == std::errc::invalid_argument || end != digits.data() + digits.size()) {
    return make_error(ErrorCode::kInvalidArgument, quoted + " is not a number");
  }
  if (ec == std::errc::result_out_of_range) {
    return make_error(ErrorCode::kInvalidArgument, quoted + " is out of range");
  }
  Budget budget{kind, value};
  if (const std::string problem = budget_problem(budget); !problem.empty()) {
    return make_error(ErrorCode::kInvalidArgument, quoted + " " + problem);
  }
  return budget;
}

}  // namespace meshstream

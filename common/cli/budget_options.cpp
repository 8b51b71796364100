#include "common/cli/budget_options.h"

#include <vector>

namespace meshstream::cli {
namespace {

struct BudgetFlag {
  const char* name;
  const char* value_name;
  const char* help;
};

BudgetFlag flag_of(Budget::Kind kind) {
  switch (kind) {
    case Budget::Kind::kBytes:
      return {"--bytes", "N",
              "stop at the last record boundary within N stream bytes (a whole number >= 0)"};
    case Budget::Kind::kVertices:
      return {"--vertices", "N",
              "stop after the last record with at most N vertices (a whole number >= 0)"};
    case Budget::Kind::kPercentVertices:
      return {"--percent", "P",
              "stop after the last record with at most P percent of the full mesh's vertices "
              "(0 < P <= 100)"};
    case Budget::Kind::kPercentBytes:
      return {"--percent-bytes", "P",
              "stop at the last record boundary within P percent of the stream's bytes "
              "(0 < P <= 100)"};
    case Budget::Kind::kRatio:
      return {"--ratio", "CR",
              "stop at the last record boundary within 1/CR of the stream's bytes (CR >= 1)"};
    case Budget::Kind::kAll:
      break;
  }
  return {nullptr, nullptr, nullptr};
}

}  // namespace

const char* budget_flag(Budget::Kind kind) { return flag_of(kind).name; }

void add_budget_options(CLI::App& app, Budget& budget, std::initializer_list<Budget::Kind> kinds) {
  std::vector<CLI::Option*> added;
  for (const Budget::Kind kind : kinds) {
    const BudgetFlag flag = flag_of(kind);
    if (!flag.name) continue;
    const std::string name = flag.name;
    CLI::Option* option = app.add_option_function<std::string>(
        name,
        [&budget, kind, name](const std::string& text) {
          auto parsed = parse_budget(kind, text);
          if (!parsed) throw CLI::ValidationError(name, parsed.error().message);
          budget = *parsed;
        },
        flag.help);
    option->type_name(flag.value_name);
    for (CLI::Option* other : added) option->excludes(other);
    added.push_back(option);
  }
}

}  // namespace meshstream::cli

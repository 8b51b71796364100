// The budget options of every program's command line (`meshstream decode`,
// meshstream-client): the same flag names, help texts, parser and rule
// (parse_budget, common/codec/budget.h), so `--percent 0` or `--bytes -5`
// means the same everywhere. A bad value is a CLI11 ValidationError whose
// message names the flag and the value ("--percent: 'abc' is not a number"),
// which each program reports as a usage error (exit 2).
#pragma once

#include <CLI/CLI.hpp>
#include <initializer_list>

#include "common/codec/budget.h"

namespace meshstream::cli {

// The flag of each budget kind: --bytes N, --vertices N, --percent P
// (kPercentVertices), --percent-bytes P, --ratio CR. nullptr for kAll.
const char* budget_flag(Budget::Kind kind);

// Adds one option per kind in `kinds` to `app`, mutually exclusive; the one
// given on the command line is parsed into `budget` (which must outlive
// app.parse). `budget` is left as it is when none is given.
void add_budget_options(CLI::App& app, Budget& budget, std::initializer_list<Budget::Kind> kinds);

}  // namespace meshstream::cli

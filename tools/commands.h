// The subcommands of `meshstream`, one file each. Each add_* function
// registers its subcommand on `app`; when the subcommand runs, it stores its
// process exit code in `exit_code` (0 ok, 1 bad data or failure).
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "common/base/result.h"

namespace meshstream::tools {

void add_info_command(CLI::App& app, int& exit_code);
void add_encode_command(CLI::App& app, int& exit_code);
void add_decode_command(CLI::App& app, int& exit_code);
void add_subdivide_command(CLI::App& app, int& exit_code);
void add_compare_command(CLI::App& app, int& exit_code);
void add_generate_command(CLI::App& app, int& exit_code);

// `meshstream info` on a mesh file and on an .hcs stream (the command
// dispatches on the file's first bytes). `list_records`: --records, the
// per-record table (the summary alone by default).
int run_info_mesh(const std::string& path, bool json);
int run_info_hcs(const std::string& path, bool json, bool list_records);

// The -o check of the commands that write a mesh: a name write_mesh cannot
// write is a usage error (exit 2) before any input is read.
CLI::Validator mesh_output_validator();

// Prints "meshstream: <message>" to stderr and returns 1, the exit code for
// bad data and failures.
int report_failure(const Error& error);

}  // namespace meshstream::tools

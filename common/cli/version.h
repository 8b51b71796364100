// The --version line of every program, from one function so the three
// binaries cannot disagree: program, project version (CMake's
// project(VERSION)), the encoder version (kEncoderVersion, the bytes an
// encoder writes) and the protocol version (Hello.protocol_version).
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <string_view>

namespace meshstream::cli {

// "meshstream-client 0.1.0 (encoder version 8, protocol version 1)".
std::string version_line(std::string_view program);

// Adds --version to `app`: it prints version_line(program) on stdout and
// exits 0 (CLI11's CallForVersion, which app.exit() handles).
void add_version_flag(CLI::App& app, std::string_view program);

}  // namespace meshstream::cli

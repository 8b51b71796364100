// Reading the repository's files for the documentation tests: the tracked
// files (git ls-files, or a walk of the source tree when it is not a git
// checkout) and their text, and the output of a command.
#pragma once

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

namespace meshstream::docs_testing {

namespace fs = std::filesystem;

inline fs::path source_dir() { return fs::path(MESHSTREAM_SOURCE_DIR); }

// stdout and stderr of `command` (run by /bin/sh) and its exit status.
struct CommandOutput {
  std::string text;
  int status = -1;
};

inline CommandOutput run_command(const std::string& command) {
  CommandOutput out;
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return out;
  std::array<char, 4096> buffer;
  size_t n = 0;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    out.text.append(buffer.data(), n);
  out.status = ::pclose(pipe);
  return out;
}

inline std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// Paths relative to the source directory.
inline std::vector<std::string> tracked_files() {
  std::vector<std::string> files;
  const fs::path root = source_dir();
  CommandOutput listed = run_command("git -C '" + root.string() + "' ls-files");
  if (listed.status == 0 && !listed.text.empty()) {
    std::istringstream lines(listed.text);
    for (std::string line; std::getline(lines, line);) {
      if (!line.empty() && fs::is_regular_file(root / line)) files.push_back(line);
    }
    return files;
  }
  // Not a git checkout (an unpacked archive): every file but build output.
  for (auto it = fs::recursive_directory_iterator(root); it != fs::recursive_directory_iterator();
       ++it) {
    const std::string name = it->path().filename().string();
    if (it->is_directory() && (name == ".git" || name.rfind("build", 0) == 0)) {
      it.disable_recursion_pending();
      continue;
    }
    if (it->is_regular_file()) files.push_back(fs::relative(it->path(), root).string());
  }
  return files;
}

// True when the first 8 KiB hold a NUL byte (images, binary test data).
inline bool looks_binary(const std::string& text) {
  return text.substr(0, 8192).find('\0') != std::string::npos;
}

}  // namespace meshstream::docs_testing

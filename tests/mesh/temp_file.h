// A file with given content in the temporary folder, removed when the
// object goes out of scope. The process id in its name keeps tests that
// ctest runs in parallel processes apart.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace meshstream::testing {

class TempFile {
 public:
  TempFile(const std::string& name, const std::string& content) {
    path_ = (std::filesystem::temp_directory_path() /
             ("meshstream_test_" + std::to_string(::getpid()) + "_" + name))
                .string();
    std::ofstream(path_, std::ios::binary) << content;
  }
  ~TempFile() { std::filesystem::remove(path_); }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

}  // namespace meshstream::testing

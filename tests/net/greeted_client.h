// The network tests' handshake, with GoogleTest checks (net_harness.h stays
// free of GoogleTest: bench/load_bench uses it too).
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <string>

#include "tests/net/net_harness.h"

namespace meshstream::nettest {

// A client connected to `port` and past the handshake (Hello sent, the
// server's Hello read).
inline TestClient greeted_client(uint16_t port) {
  TestClient c;
  EXPECT_TRUE(c.connect(port));
  EXPECT_TRUE(c.hello());
  v1::ServerMessage m;
  EXPECT_EQ(c.read(m), ReadEnd::kMessage);
  EXPECT_TRUE(m.has_hello()) << m.DebugString();
  return c;
}

// A test program's models folder, <tmp>/<prefix><pid> (the pid keeps two
// test programs run side by side apart), removed when the program's tests end.
// Register it at namespace scope, before RUN_ALL_TESTS, as GoogleTest asks:
//   const ModelsFolder& folder = register_models_folder("ms_net_");
class ModelsFolder : public ::testing::Environment {
 public:
  explicit ModelsFolder(const std::string& prefix)
      : path_((std::filesystem::temp_directory_path() / (prefix + std::to_string(::getpid())))
                  .string()) {}
  // The folder, made if missing.
  const std::string& create() const {
    std::filesystem::create_directories(path_);
    return path_;
  }
  void TearDown() override {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }

 private:
  std::string path_;
};

inline const ModelsFolder& register_models_folder(const std::string& prefix) {
  return *static_cast<ModelsFolder*>(::testing::AddGlobalTestEnvironment(new ModelsFolder(prefix)));
}

}  // namespace meshstream::nettest

// The network tests' handshake, with GoogleTest checks (net_harness.h stays
// free of GoogleTest: bench/load_bench uses it too).
#pragma once

#include <gtest/gtest.h>

#include <cstdint>

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

}  // namespace meshstream::nettest

// The first connection of a client through a load balancer: HAProxy (TCP
// mode) accepts before it reaches a server, and closes the connection
// without a byte when that server has just died. The real meshstream-client
// tries such a peer 3 more times, then fails naming it; a peer that sends
// anything that is not the protocol still fails at once
// (tests/client/client_cli_test.cpp).
#include <gtest/gtest.h>

#include "tests/deploy/deploy_harness.h"

namespace meshstream::deploytest {
namespace {

// Accepts and closes every connection without writing; counts them.
class ClosingPeer {
 public:
  ClosingPeer() {
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a);
    ::listen(fd_, 16);
    socklen_t len = sizeof a;
    ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len);
    port_ = ntohs(a.sin_port);
    thread_ = std::thread([this] {
      while (!done_) {
        pollfd p{fd_, POLLIN, 0};
        if (::poll(&p, 1, 20) <= 0) continue;
        const int c = ::accept(fd_, nullptr, nullptr);
        if (c < 0) continue;
        ++connections_;
        ::close(c);
      }
    });
  }
  ~ClosingPeer() {
    done_ = true;
    thread_.join();
    ::close(fd_);
  }
  std::string address() const { return "127.0.0.1:" + std::to_string(port_); }
  int connections() const { return connections_; }

 private:
  int fd_ = -1;
  uint16_t port_ = 0;
  std::atomic<bool> done_{false};
  std::atomic<int> connections_{0};
  std::thread thread_;
};

TEST(FirstConnectionTest, APeerThatClosesWithoutAByteIsTriedThreeMoreTimes) {
  clienttest::TempDir tmp;
  ClosingPeer peer;
  const auto start = Clock::now();
  const auto runs = run_clients(1, peer.address(), "knot", tmp.path(), {}, {}, {}, 30s);
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  EXPECT_EQ(runs[0].exit_code, 1) << runs[0].stderr_text;
  EXPECT_EQ(peer.connections(), 4);
  EXPECT_LT(seconds, 5.0);
  EXPECT_NE(runs[0].stderr_text.find("no meshstream server at " + peer.address()),
            std::string::npos)
      << runs[0].stderr_text;
}

}  // namespace
}  // namespace meshstream::deploytest

// Ctrl-C while the real meshstream-client shows its window (under Xvfb):
// the window closes, the stream ends cleanly (done event with reason
// cancelled, final.ply of what arrived) and the client exits 130. The same
// without a window is in tests/client/client_cli_test.cpp.
#include <gtest/gtest.h>

#include "tests/client/client_harness.h"
#include "tests/viewer/xvfb_display.h"

namespace meshstream::clienttest {
namespace {

TEST(ClientInterrupt, CtrlCClosesTheWindowAndEndsTheStreamCleanly) {
  if (client::testing::XvfbDisplay::find_xvfb().empty()) {
    GTEST_SKIP() << "Xvfb is not installed (Debian package xvfb): window test skipped";
  }
  client::testing::XvfbDisplay xvfb;
  const std::string display = xvfb.start();
  ASSERT_FALSE(display.empty()) << "Xvfb did not start";
  TempDir dir;
  ASSERT_EQ(make_demo_model(dir.path(), /*with_asa_guidance=*/false), "");  // ASA not tested
  Server server;  // ~31 KB at 8 kB/s: about four seconds
  ASSERT_TRUE(server.start({"--models", dir / "models", "--cache", "none", "--rate", "8000",
                            "--max-chunk-bytes", "1024"},
                           dir.path()))
      << server.log();
  Child client;
  const std::string events = dir / "events.txt";
  ASSERT_TRUE(
      client.start({"/usr/bin/env", "DISPLAY=" + display, client_bin(), server.address(), "demo",
                    "--view", "--json", "--out", dir / "o", "--width", "320", "--height", "240"},
                   events, dir / "client.err"));
  const auto deadline = Clock::now() + 30s;
  while (Clock::now() < deadline &&
         of_kind(parse_events(read_text(events)), "refinement").size() < 3)
    std::this_thread::sleep_for(10ms);
  ASSERT_GE(of_kind(parse_events(read_text(events)), "refinement").size(), 3u)
      << read_text(dir / "client.err");
  client.signal(SIGINT);
  const auto status = client.wait(20s);
  ASSERT_TRUE(status) << "the window did not close after Ctrl-C";
  EXPECT_EQ(*status, 130) << read_text(dir / "client.err");
  const std::string text = read_text(events);
  ASSERT_FALSE(text.empty());
  EXPECT_EQ(text.back(), '\n');
  const auto parsed = parse_events(text);
  const auto& done = parsed.back();
  ASSERT_EQ(done["event"], "done") << text;
  EXPECT_EQ(done["reason"], "cancelled");
  EXPECT_LT(done["records"].get<int>(), done["records_total"].get<int>());
  ASSERT_EQ(run({tool_bin(), "decode", dir / "models/demo.hcs", "-o", dir / "prefix.ply", "--bytes",
                 std::to_string(done["bytes"].get<uint64_t>())},
                dir / "dec.out", dir / "dec.err"),
            0);
  EXPECT_TRUE(read_text(dir / "o/final.decoded.ply") == read_text(dir / "prefix.ply"))
      << "final.decoded.ply is not the mesh of what arrived";
  EXPECT_TRUE(fs::exists(dir / "o/final.ply"));
}

}  // namespace
}  // namespace meshstream::clienttest

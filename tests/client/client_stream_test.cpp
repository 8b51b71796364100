// meshstream-client against the real meshstream-server on loopback: the
// final decoded mesh equals `meshstream decode` of the same .hcs, every
// display mesh equals `meshstream subdivide` of the decoded mesh at its
// record, events are monotone, budgets stop on the right record boundary,
// a killed and restarted server still gives the identical final mesh, and a
// throttled stream shows several refinements before its end.
#include <gtest/gtest.h>

#include "tests/client/client_harness.h"
#include "tests/test_meshes.h"

namespace meshstream::clienttest {
namespace {

struct ClientRun {
  int status = -1;
  std::vector<nlohmann::json> events;
  std::string err;
};

class ClientStreamTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir();
    // The peer the client is checked against. Every test here names its ASA
    // settings (or --no-asa), so the stream needs no guidance.
    ASSERT_EQ(make_demo_model(dir_->path(), /*with_asa_guidance=*/false), "");
    server_ = new Server();
    ASSERT_TRUE(
        server_->start({"--models", *dir_ / "models", "--cache", *dir_ / "cache"}, dir_->path()))
        << server_->log();
  }
  static void TearDownTestSuite() {
    delete server_;
    delete dir_;
    server_ = nullptr;
    dir_ = nullptr;
  }
  static std::string hcs() { return *dir_ / "models/demo.hcs"; }

  // Runs meshstream-client with `args` after the address; events parsed.
  static ClientRun client(const std::string& address, const std::vector<std::string>& args) {
    static int n = 0;
    const std::string out = *dir_ / ("client" + std::to_string(++n) + ".out");
    const std::string err = *dir_ / ("client" + std::to_string(n) + ".err");
    std::vector<std::string> argv{client_bin(), address};
    argv.insert(argv.end(), args.begin(), args.end());
    ClientRun r;
    r.status = run(argv, out, err);
    r.events = parse_events(read_text(out));
    r.err = read_text(err);
    return r;
  }

  // `meshstream decode` of the first `bytes` of the stream (all when 0).
  static Mesh tool_decode(uint64_t bytes, const std::string& name) {
    std::vector<std::string> argv{tool_bin(), "decode", hcs(), "-o", *dir_ / name};
    if (bytes) {
      argv.push_back("--bytes");
      argv.push_back(std::to_string(bytes));
    }
    EXPECT_EQ(run(argv, *dir_ / "dec.out", *dir_ / "dec.err"), 0) << read_text(*dir_ / "dec.err");
    return load_ply(*dir_ / name);
  }

  static Mesh tool_subdivide(const std::string& in, const std::vector<std::string>& options,
                             const std::string& name) {
    std::vector<std::string> argv{tool_bin(), "subdivide", in, "-o", *dir_ / name};
    argv.insert(argv.end(), options.begin(), options.end());
    EXPECT_EQ(run(argv, *dir_ / "sub.out", *dir_ / "sub.err"), 0) << read_text(*dir_ / "sub.err");
    return load_ply(*dir_ / name);
  }

  static TempDir* dir_;
  static Server* server_;
};

TempDir* ClientStreamTest::dir_ = nullptr;
Server* ClientStreamTest::server_ = nullptr;

// Events: one header, a record event per decoded record, refinements with
// strictly increasing index and non-decreasing bytes/vertices/faces/elapsed,
// the last one final, then done.
void expect_monotone_events(const std::vector<nlohmann::json>& events) {
  ASSERT_GE(events.size(), 3u);
  EXPECT_EQ(events.front()["event"], "header");
  EXPECT_EQ(events.back()["event"], "done");
  const auto refinements = of_kind(events, "refinement");
  const auto records = of_kind(events, "record");
  ASSERT_EQ(refinements.size() + records.size() + 2, events.size())
      << "only header, records, refinements and done expected";
  EXPECT_EQ(static_cast<int64_t>(records.size()), events.back()["records"].get<int64_t>());
  for (size_t i = 1; i < refinements.size(); ++i) {
    const auto &a = refinements[i - 1], &b = refinements[i];
    EXPECT_LT(a["index"].get<int64_t>(), b["index"].get<int64_t>());
    EXPECT_LT(a["bytes"].get<int64_t>(), b["bytes"].get<int64_t>());
    // Bit-plane records sharpen positions without adding vertices or faces.
    EXPECT_LE(a["vertices"].get<int64_t>(), b["vertices"].get<int64_t>());
    EXPECT_LE(a["faces"].get<int64_t>(), b["faces"].get<int64_t>());
    EXPECT_LE(a["elapsed_ms"].get<double>(), b["elapsed_ms"].get<double>());
    EXPECT_FALSE(a["final"].get<bool>());
  }
  for (const auto& r : refinements) {
    for (const char* key : {"index", "bytes", "vertices", "faces", "display_vertices",
                            "display_faces", "decode_ms", "asa_ms", "elapsed_ms"}) {
      EXPECT_TRUE(r.contains(key)) << key;
    }
    EXPECT_GE(r["whole_display_faces"].get<int64_t>(), r["faces"].get<int64_t>());
    EXPECT_LE(r["display_faces"].get<int64_t>(), r["whole_display_faces"].get<int64_t>());
  }
  EXPECT_TRUE(refinements.back()["final"].get<bool>());
  const auto& done = events.back();
  EXPECT_EQ(done["records"], refinements.back()["index"].get<int64_t>() + 1);
  EXPECT_EQ(done["bytes"], refinements.back()["bytes"]);
  // Every record is accounted for: shown, or merged into a later frame.
  int64_t shown = 0;
  for (const auto& r : refinements) shown += 1 + r["coalesced"].get<int64_t>();
  EXPECT_EQ(shown, done["records"].get<int64_t>());
}

TEST_F(ClientStreamTest, FinalDecodedMeshEqualsOfflineDecode) {
  TempDir out;
  const ClientRun r = client(server_->address(), {"demo", "--json", "--out", out.path()});
  ASSERT_EQ(r.status, 0) << r.err;
  expect_monotone_events(r.events);
  const auto& done = r.events.back();
  EXPECT_EQ(done["reason"], "complete");
  EXPECT_EQ(done["records"], done["records_total"]);
  EXPECT_EQ(done["bytes"], fs::file_size(hcs()));

  // Byte for byte the same file as the offline decoder writes.
  tool_decode(0, "full.ply");
  EXPECT_EQ(read_text(out / "final.decoded.ply"), read_text(*dir_ / "full.ply"));
  const Mesh decoded = load_ply(out / "final.decoded.ply");
  EXPECT_EQ(decoded.vertex_count(), done["vertices"].get<uint32_t>());
  EXPECT_EQ(decoded.face_count(), done["faces"].get<uint32_t>());
}

TEST_F(ClientStreamTest, EachDisplayMeshEqualsOfflineSubdivideAtItsRecord) {
  TempDir out;
  const std::vector<std::string> asa{"--asa-levels", "2",          "--flatness", "0.8",
                                     "--rule",       "projection", "--crease",   "60"};
  // Whole-mesh ASA: what `meshstream subdivide` does without a camera; on
  // the complete mesh too (--asa-complete), so that the last saved record is
  // compared like the others (the default, the decoded mesh once the stream
  // is complete, is ClientCliTest.TheCompleteStreamIsShownAndSavedAsDecoded).
  std::vector<std::string> args{"demo", "--json", "--out", out.path(), "--out-every", "25"};
  args.insert(args.end(), {"--view-independent", "--asa-complete"});
  args.insert(args.end(), asa.begin(), asa.end());
  const ClientRun r = client(server_->address(), args);
  ASSERT_EQ(r.status, 0) << r.err;
  expect_monotone_events(r.events);
  // The display updates of the saved records (every 25th: each shown as is).
  std::vector<nlohmann::json> saved;
  for (const auto& e : of_kind(r.events, "refinement")) {
    if (e["index"].get<int64_t>() % 25 == 0) saved.push_back(e);
  }
  ASSERT_GE(saved.size(), 3u);
  // First, a middle and the last saved record (the checks run the tools).
  std::vector<size_t> picks{0, saved.size() / 2, saved.size() - 1};
  for (size_t pick : picks) {
    const auto& e = saved[pick];
    const int64_t index = e["index"];
    char name[32];
    std::snprintf(name, sizeof name, "%04lld.ply", static_cast<long long>(index));
    const Mesh display = load_ply(out / name);
    ASSERT_EQ(display.face_count(), e["whole_display_faces"].get<uint32_t>()) << name;
    ASSERT_EQ(display.vertex_count(), e["whole_display_vertices"].get<uint32_t>()) << name;
    const std::string prefix = "prefix" + std::to_string(index) + ".ply";
    const Mesh decoded = tool_decode(e["bytes"].get<uint64_t>(), prefix);
    EXPECT_EQ(decoded.vertex_count(), e["vertices"].get<uint32_t>());
    const Mesh expected = tool_subdivide(
        *dir_ / prefix,
        {"--levels", "2", "--flatness", "0.8", "--rule", "projection", "--crease", "60"},
        "sub" + std::to_string(index) + ".ply");
    EXPECT_TRUE(same_geometry(display, expected)) << "record " << index;
  }
}

// The incremental path (only the region a record changed is recomputed)
// gives the same triangles at the same positions as subdividing everything.
TEST_F(ClientStreamTest, IncrementalAsaEqualsOfflineSubdivideAtEachRecord) {
  TempDir out;
  Server paced;  // paced so that most records get their own display update
  ASSERT_TRUE(paced.start({"--models", *dir_ / "models", "--cache", *dir_ / "cache", "--rate",
                           "150000", "--max-chunk-bytes", "1024"},
                          out.path()))
      << paced.log();
  const std::vector<std::string> asa{"--levels", "1", "--flatness", "0.8", "--crease", "50"};
  const ClientRun r =
      client(paced.address(), {"demo", "--json", "--out", out / "o", "--out-every", "1",
                               "--asa-levels", "1", "--flatness", "0.8", "--crease", "50",
                               "--asa-path", "incremental", "--view-independent"});
  ASSERT_EQ(r.status, 0) << r.err;
  expect_monotone_events(r.events);
  std::vector<nlohmann::json> incremental;
  for (const auto& e : of_kind(r.events, "refinement")) {
    if (e["asa_path"] == "incremental") incremental.push_back(e);
  }
  ASSERT_GE(incremental.size(), 3u) << "the incremental path was never taken";
  for (size_t pick : {size_t(0), incremental.size() / 2, incremental.size() - 1}) {
    const auto& e = incremental[pick];
    const int64_t index = e["index"];
    char name[32];
    std::snprintf(name, sizeof name, "%04lld.ply", static_cast<long long>(index));
    const Mesh display = load_ply(out / ("o/" + std::string(name)));
    const std::string prefix = "iprefix" + std::to_string(index) + ".ply";
    tool_decode(e["bytes"].get<uint64_t>(), prefix);
    const Mesh expected =
        tool_subdivide(*dir_ / prefix, asa, "isub" + std::to_string(index) + ".ply");
    EXPECT_TRUE(same_geometry(display, expected)) << "record " << index;
  }
}

TEST_F(ClientStreamTest, NoAsaShowsTheDecodedMesh) {
  TempDir out;
  const ClientRun r =
      client(server_->address(), {"demo", "--json", "--no-asa", "--out", out.path()});
  ASSERT_EQ(r.status, 0) << r.err;
  for (const auto& e : of_kind(r.events, "refinement")) {
    EXPECT_EQ(e["display_faces"], e["faces"]);
    EXPECT_EQ(e["display_vertices"], e["vertices"]);
  }
  EXPECT_EQ(read_text(out / "final.ply"), read_text(out / "final.decoded.ply"));
}

TEST_F(ClientStreamTest, BudgetsStopOnTheLastRecordBoundaryWithinThem) {
  const uint64_t total = fs::file_size(hcs());
  {
    TempDir out;
    const uint64_t budget = total / 3;
    const ClientRun r = client(
        server_->address(),
        {"demo", "--json", "--bytes", std::to_string(budget), "--no-asa", "--out", out.path()});
    ASSERT_EQ(r.status, 0) << r.err;
    expect_monotone_events(r.events);
    const auto& done = r.events.back();
    EXPECT_EQ(done["reason"], "budget");
    EXPECT_LE(done["bytes"].get<uint64_t>(), budget);
    EXPECT_LT(done["records"].get<int64_t>(), done["records_total"].get<int64_t>());
    // The offline decoder with the same byte budget stops at the same record.
    EXPECT_EQ(read_text(out / "final.decoded.ply"), [&] {
      tool_decode(budget, "third.ply");
      return read_text(*dir_ / "third.ply");
    }());
  }
  {
    const ClientRun r =
        client(server_->address(), {"demo", "--json", "--vertices", "3000", "--no-asa"});
    ASSERT_EQ(r.status, 0) << r.err;
    const auto& done = r.events.back();
    EXPECT_LE(done["vertices"].get<uint32_t>(), 3000u);
    EXPECT_GT(done["vertices"].get<uint32_t>(), 300u);
    EXPECT_EQ(done["reason"], "budget");
  }
  {
    // --percent counts vertices (client_percent_test.cpp); --percent-bytes
    // is the wire's percent of the stream's bytes.
    const ClientRun r =
        client(server_->address(), {"demo", "--json", "--percent-bytes", "50", "--no-asa"});
    ASSERT_EQ(r.status, 0) << r.err;
    const auto& done = r.events.back();
    EXPECT_LE(done["bytes"].get<uint64_t>(), total / 2);
    EXPECT_GT(done["bytes"].get<uint64_t>(), total / 4);
  }
  {
    // A budget below the base mesh still delivers the base mesh.
    const ClientRun r = client(server_->address(), {"demo", "--json", "--bytes", "1", "--no-asa"});
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(r.events.back()["records"], 1);
  }
}

// --percent P is HCS's percentage of points, as `meshstream decode --percent
// P`: the client (over the wire's Budget.percent_vertices) ends on the same
// record with the same vertex count and the same decoded mesh, byte for byte.
TEST_F(ClientStreamTest, PercentMeansTheSameVerticesAsTheDecodeTool) {
  const Mesh full = load_ply([&] {
    tool_decode(0, "pfull.ply");
    return *dir_ / "pfull.ply";
  }());
  ASSERT_GT(full.vertex_count(), 0u);
  for (const char* p : {"12.5", "50", "80", "100"}) {
    TempDir out;
    const ClientRun r = client(server_->address(),
                               {"demo", "--json", "--percent", p, "--no-asa", "--out", out.path()});
    ASSERT_EQ(r.status, 0) << p << ": " << r.err;
    const auto& done = r.events.back();
    ASSERT_EQ(done["event"], "done") << p;

    const std::string name = std::string("pdec") + p + ".ply";
    ASSERT_EQ(run({tool_bin(), "decode", hcs(), "-o", *dir_ / name, "--percent", p},
                  *dir_ / "pdec.out", *dir_ / "pdec.err"),
              0)
        << read_text(*dir_ / "pdec.err");
    // "IN: decoded R of N records (...)"
    const std::string said = read_text(*dir_ / "pdec.out");
    const auto at = said.find("decoded ");
    ASSERT_NE(at, std::string::npos) << said;
    const int tool_records = std::stoi(said.substr(at + 8));
    const Mesh tool_mesh = load_ply(*dir_ / name);

    EXPECT_EQ(done["records"].get<int>(), tool_records) << p;
    EXPECT_EQ(done["vertices"].get<uint32_t>(), tool_mesh.vertex_count()) << p;
    EXPECT_EQ(done["faces"].get<uint32_t>(), tool_mesh.face_count()) << p;
    EXPECT_EQ(read_text(out / "final.decoded.ply"), read_text(*dir_ / name)) << p;
    EXPECT_LE(double(tool_mesh.vertex_count()),
              std::stod(p) / 100.0 * double(full.vertex_count()) + 1e-9)
        << p;
    EXPECT_EQ(done["reason"],
              tool_records == done["records_total"].get<int>() ? "complete" : "budget")
        << p;
  }
}

TEST_F(ClientStreamTest, KilledAndRestartedServerGivesTheIdenticalFinalMesh) {
  TempDir out;
  const uint16_t port = free_port();
  auto server = std::make_unique<Server>();
  // Throttled so the kill lands mid-stream.
  ASSERT_TRUE(server->start({"--models", *dir_ / "models", "--cache", *dir_ / "cache", "--rate",
                             "20000", "--max-chunk-bytes", "1024"},
                            out.path(), port))
      << server->log();
  Child c;
  const std::string events_path = out / "events.txt";
  ASSERT_TRUE(c.start({client_bin(), server->address(), "demo", "--json", "--out", out / "snaps"},
                      events_path, out / "client.err"));
  // Wait for a few refinements, then kill the server without warning.
  const auto deadline = Clock::now() + 20s;
  while (Clock::now() < deadline &&
         of_kind(parse_events(read_text(events_path)), "refinement").size() < 3) {
    std::this_thread::sleep_for(10ms);
  }
  ASSERT_GE(of_kind(parse_events(read_text(events_path)), "refinement").size(), 3u);
  server->kill_hard();
  std::this_thread::sleep_for(300ms);
  server = std::make_unique<Server>();
  ASSERT_TRUE(
      server->start({"--models", *dir_ / "models", "--cache", *dir_ / "cache"}, out.path(), port))
      << server->log();
  const auto status = c.wait(60s);
  ASSERT_TRUE(status.has_value());
  ASSERT_EQ(*status, 0) << read_text(out / "client.err");
  const auto events = parse_events(read_text(events_path));
  expect_monotone_events(events);
  EXPECT_GE(events.back()["reconnects"].get<int>(), 1);
  EXPECT_EQ(events.back()["reason"], "complete");
  EXPECT_EQ(of_kind(events, "header").size(), 1u);
  tool_decode(0, "full_for_resume.ply");
  EXPECT_EQ(read_text(out / "snaps/final.decoded.ply"), read_text(*dir_ / "full_for_resume.ply"));
}

TEST_F(ClientStreamTest, ThrottledStreamShowsSeveralRefinementsBeforeTheEnd) {
  TempDir out;
  Server slow;
  ASSERT_TRUE(slow.start({"--models", *dir_ / "models", "--cache", *dir_ / "cache", "--rate",
                          "40000", "--max-chunk-bytes", "2048"},
                         out.path()))
      << slow.log();
  const ClientRun r = client(slow.address(), {"demo", "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  expect_monotone_events(r.events);
  const auto refinements = of_kind(r.events, "refinement");
  ASSERT_GE(refinements.size(), 5u);
  const double end_ms = r.events.back()["elapsed_ms"].get<double>();
  // Progressive: the first display update comes long before the end, and
  // several arrive in the first half of the stream's time.
  EXPECT_LT(refinements.front()["elapsed_ms"].get<double>(), end_ms / 4);
  size_t early = 0;
  for (const auto& e : refinements) early += e["elapsed_ms"].get<double>() < end_ms / 2;
  EXPECT_GE(early, 3u);
}

// A real scanned mesh (with holes: boundary rules in ASA), encoded by the
// offline tool and served as .hcs.
TEST_F(ClientStreamTest, RealMeshFinalMeshesEqualOfflineDecodeAndSubdivide) {
  MESHSTREAM_REQUIRE_TEST_MESHES();
  const std::string input = meshstream::testing::test_mesh("bun_zipper.ply");
  if (!fs::exists(input)) GTEST_SKIP() << input << " not found";
  TempDir models, out;
  const std::string hcs = models / "bunny.hcs";
  ASSERT_EQ(run({tool_bin(), "encode", input, "-o", hcs, "--no-asa-guidance"}, out / "enc.out",
                out / "enc.err"),
            0)
      << read_text(out / "enc.err");
  Server server;
  ASSERT_TRUE(server.start({"--models", models.path(), "--cache", out / "cache"}, out.path()))
      << server.log();
  // --asa-complete: the complete mesh gets ASA too, so its boundary rules are checked here.
  // --asa on: the fixed settings `subdivide` applies (the default follows the guidance).
  const ClientRun r = client(server.address(), {"bunny", "--json", "--asa", "on", "--asa-complete",
                                                "--out", out / "snaps", "--view-independent"});
  ASSERT_EQ(r.status, 0) << r.err;
  expect_monotone_events(r.events);
  ASSERT_EQ(
      run({tool_bin(), "decode", hcs, "-o", out / "decoded.ply"}, out / "dec.out", out / "dec.err"),
      0);
  EXPECT_EQ(read_text(out / "snaps/final.decoded.ply"), read_text(out / "decoded.ply"));
  ASSERT_EQ(run({tool_bin(), "subdivide", out / "decoded.ply", "-o", out / "sub.ply"},
                out / "sub.out", out / "sub.err"),
            0);
  EXPECT_TRUE(same_geometry(load_ply(out / "snaps/final.ply"), load_ply(out / "sub.ply")));
}

TEST_F(ClientStreamTest, ListsTheCatalog) {
  const ClientRun r = client(server_->address(), {"--list", "--json"});
  ASSERT_EQ(r.status, 0) << r.err;
  ASSERT_EQ(r.events.size(), 1u);
  const auto& models = r.events[0]["models"];
  ASSERT_EQ(models.size(), 1u);
  EXPECT_EQ(models[0]["name"], "demo");
  EXPECT_EQ(models[0]["stream_bytes"].get<uint64_t>(), fs::file_size(hcs()));
}

TEST_F(ClientStreamTest, ServerErrorsExitOneWithTheirMessage) {
  const ClientRun r = client(server_->address(), {"no-such-model", "--json"});
  EXPECT_EQ(r.status, 1);
  const auto errors = of_kind(r.events, "error");
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(errors[0]["message"].get<std::string>().find("no-such-model"), std::string::npos)
      << errors[0]["message"];
  // Nobody listening: fails at once (client_cli_test.cpp has the details).
  const ClientRun gone = client("127.0.0.1:" + std::to_string(free_port()),
                                {"demo", "--json", "--reconnect-attempts", "1"});
  EXPECT_EQ(gone.status, 1);
  EXPECT_EQ(of_kind(gone.events, "error").size(), 1u);
}

TEST_F(ClientStreamTest, UsageErrorsExitTwo) {
  EXPECT_EQ(client("127.0.0.1", {"demo"}).status, 2);   // no port
  EXPECT_EQ(client(server_->address(), {}).status, 2);  // no model
  EXPECT_EQ(client(server_->address(), {"demo", "--bytes", "10", "--vertices", "5"}).status, 2);
  EXPECT_EQ(client(server_->address(), {"demo", "--rule", "loop"}).status, 2);
  EXPECT_EQ(client(server_->address(), {"demo", "--percent", "0"}).status, 2);
  EXPECT_EQ(client(server_->address(), {"demo", "--percent", "nan"}).status, 2);
  EXPECT_EQ(client(server_->address(), {"demo", "--percent", "101"}).status, 2);
  EXPECT_EQ(client(server_->address(), {"demo", "--percent-bytes", "0"}).status, 2);
  EXPECT_EQ(client(server_->address(), {"demo", "--percent", "5", "--percent-bytes", "5"}).status,
            2);
  EXPECT_EQ(client(server_->address(), {"demo", "--frobnicate"}).status, 2);
}

}  // namespace
}  // namespace meshstream::clienttest

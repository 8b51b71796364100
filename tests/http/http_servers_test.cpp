// The real meshstream-client binary streaming `meshstream encode` outputs
// from real web servers on loopback, started and stopped here: nginx with
// the configuration of docs/nginx.conf (range requests), and Python's
// http.server (no range support: 200 and the whole file). Every final mesh
// must be byte-identical to `meshstream decode` of the same file, and an
// HTTP run must give the same events and files as a TCP run through
// meshstream-server. Skipped, visibly, when nginx or python3 is absent
// (scripts/test installs nginx).
#include <gtest/gtest.h>

#include "tests/client/client_harness.h"
#include "tests/http/web_servers.h"
#include "tests/test_meshes.h"

namespace meshstream::clienttest {
namespace {

size_t count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

class HttpServersTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir();
    fs::create_directories(*dir_ / "www/models");
    fs::create_directories(*dir_ / "ref");
    // Every test here streams with --no-asa: no ASA guidance needed.
    ASSERT_EQ(make_demo_model(dir_->path(), /*with_asa_guidance=*/false), "");
    fs::copy_file(*dir_ / "models/demo.hcs", *dir_ / "www/models/demo.hcs");
    models_ = new std::vector<std::string>{"demo"};
    // A second procedural model, and real meshes when they are here.
    ASSERT_EQ(run({tool_bin(), "generate", "demo", "--size", "4000", "-o", *dir_ / "small.ply"},
                  *dir_ / "g.out", *dir_ / "g.err"),
              0)
        << read_text(*dir_ / "g.err");
    encode(*dir_ / "small.ply", "small");
    if (!meshstream::testing::test_mesh_dir().empty()) {
      for (const char* name : {"bunny.off", "fandisk.off", "hemisphere.off"}) {
        const std::string path = meshstream::testing::test_mesh(name);
        if (fs::exists(path)) encode(path, fs::path(name).stem().string());
      }
    }
    for (const std::string& m : *models_) {
      ASSERT_EQ(run({tool_bin(), "decode", hcs(m), "-o", *dir_ / ("ref/" + m + ".ply")},
                    *dir_ / "d.out", *dir_ / "d.err"),
                0)
          << read_text(*dir_ / "d.err");
    }
  }
  static void TearDownTestSuite() {
    delete models_;
    delete dir_;
  }
  static void encode(const std::string& mesh, const std::string& name) {
    ASSERT_EQ(run({tool_bin(), "encode", mesh, "-o", hcs(name), "--no-asa-guidance"},
                  *dir_ / "e.out", *dir_ / "e.err"),
              0)
        << read_text(*dir_ / "e.err");
    models_->push_back(name);
  }
  static std::string hcs(const std::string& model) {
    return *dir_ / ("www/models/" + model + ".hcs");
  }

  struct ClientRun {
    int status = -1;
    std::string out, err, out_dir;
  };
  static ClientRun client(const std::string& address, std::vector<std::string> args) {
    static int n = 0;
    ClientRun r;
    const std::string tag = "run" + std::to_string(++n);
    r.out_dir = *dir_ / tag;
    std::vector<std::string> argv{client_bin(), address, "--out", r.out_dir};
    argv.insert(argv.end(), args.begin(), args.end());
    r.status = run(argv, *dir_ / (tag + ".out"), *dir_ / (tag + ".err"));
    r.out = read_text(*dir_ / (tag + ".out"));
    r.err = read_text(*dir_ / (tag + ".err"));
    return r;
  }
  // Every model through `base` (http://127.0.0.1:PORT), byte-identical.
  static void stream_all(const std::string& base) {
    for (const std::string& m : *models_) {
      ClientRun r = client(base + "/models/" + m + ".hcs", {"--no-asa", "--quiet"});
      ASSERT_EQ(r.status, 0) << m << ": " << r.err;
      const std::string got = read_text(r.out_dir + "/final.decoded.ply");
      const std::string want = read_text(*dir_ / ("ref/" + m + ".ply"));
      ASSERT_FALSE(want.empty());
      EXPECT_TRUE(got == want) << m << ": the final mesh over HTTP differs from meshstream decode ("
                               << got.size() << " vs " << want.size() << " bytes)";
    }
  }

  static TempDir* dir_;
  static std::vector<std::string>* models_;
};
TempDir* HttpServersTest::dir_ = nullptr;
std::vector<std::string>* HttpServersTest::models_ = nullptr;

#define START_OR_SKIP(server)                                                      \
  do {                                                                             \
    const std::string why = (server).start(*dir_ / "www", *dir_ / "run-" #server); \
    if (why.find("not installed") != std::string::npos) GTEST_SKIP() << why;       \
    ASSERT_EQ(why, "");                                                            \
  } while (0)

TEST_F(HttpServersTest, EveryModelThroughNginxIsByteIdenticalToTheOfflineDecode) {
  Nginx nginx;
  START_OR_SKIP(nginx);
  const std::string base = "http://127.0.0.1:" + std::to_string(nginx.port());
  stream_all(base);
  // Many small range requests on one connection (the bytes per request).
  ClientRun r =
      client(base + "/models/demo.hcs", {"--no-asa", "--quiet", "--max-chunk-bytes", "2000"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(read_text(r.out_dir + "/final.decoded.ply") == read_text(*dir_ / "ref/demo.ply"));
  const std::string log = nginx.access_log();
  // Range requests only, every one answered 206.
  EXPECT_GE(count(log, "\" 206 "), models_->size() + 5) << log;
  EXPECT_EQ(count(log, "\" 206 "), count(log, "GET ")) << log;
}

TEST_F(HttpServersTest, ABudgetThroughNginxStopsWhereTheOfflineDecodeDoes) {
  Nginx nginx;
  START_OR_SKIP(nginx);
  const std::string url = "http://127.0.0.1:" + std::to_string(nginx.port()) + "/models/demo.hcs";
  for (const std::vector<std::string>& budget :
       {std::vector<std::string>{"--percent", "30"}, {"--bytes", "20000"}}) {
    ClientRun r = client(url, {"--no-asa", "--quiet", budget[0], budget[1]});
    ASSERT_EQ(r.status, 0) << r.err;
    const std::string ref = *dir_ / ("ref/demo" + budget[0] + ".ply");
    ASSERT_EQ(run({tool_bin(), "decode", hcs("demo"), "-o", ref, budget[0], budget[1]},
                  *dir_ / "d.out", *dir_ / "d.err"),
              0)
        << read_text(*dir_ / "d.err");
    EXPECT_TRUE(read_text(r.out_dir + "/final.decoded.ply") == read_text(ref)) << budget[0];
  }
}

TEST_F(HttpServersTest, OverHttpTheSameEventsAndFilesAsOverTcp) {
  Nginx nginx;
  START_OR_SKIP(nginx);
  Server server;
  ASSERT_TRUE(
      server.start({"--models", *dir_ / "www/models", "--cache", *dir_ / "cache"}, dir_->path()))
      << server.log();
  const std::vector<std::string> args{"--json", "--out-every", "16", "--percent", "80"};
  ClientRun tcp =
      client(server.address(), {"demo", "--json", "--out-every", "16", "--percent", "80"});
  ClientRun http =
      client("http://127.0.0.1:" + std::to_string(nginx.port()) + "/models/demo.hcs", args);
  ASSERT_EQ(tcp.status, 0) << tcp.err;
  ASSERT_EQ(http.status, 0) << http.err;
  // The same events, without the times, rates and transport counters.
  auto strip = [](const std::string& text) {
    std::vector<nlohmann::json> out;
    for (nlohmann::json e : parse_events(text)) {
      for (const char* k : {"elapsed_ms", "decode_ms", "asa_ms", "rate_bytes_per_s", "coalesced",
                            "display_updates", "reconnects", "bytes_received"})
        e.erase(k);
      if (e["event"] == "refinement" || e["event"] == "progress") continue;  // timing-dependent
      out.push_back(e);
    }
    return out;
  };
  const auto a = strip(tcp.out), b = strip(http.out);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i], b[i]) << "event " << i;
  // The same files (final.ply after ASA, NNNN.ply every 16th record).
  size_t files = 0;
  for (const auto& entry : fs::directory_iterator(tcp.out_dir)) {
    const std::string name = entry.path().filename().string();
    EXPECT_TRUE(read_text(entry.path().string()) == read_text(http.out_dir + "/" + name)) << name;
    ++files;
  }
  EXPECT_GE(files, 4u);
}

TEST_F(HttpServersTest, AServerWithoutRangeSupportStreamsEachModelWithOneRequest) {
  PythonHttp python;
  START_OR_SKIP(python);
  stream_all("http://127.0.0.1:" + std::to_string(python.port()));
  const std::string log = python.log();
  for (const std::string& m : *models_) {
    EXPECT_EQ(count(log, "GET /models/" + m + ".hcs "), 1u) << m << ":\n" << log;
  }
}

TEST_F(HttpServersTest, MissingFilesAndPagesAreClearErrors) {
  Nginx nginx;
  START_OR_SKIP(nginx);
  const std::string base = "http://127.0.0.1:" + std::to_string(nginx.port());
  std::ofstream(*dir_ / "www/models/page.hcs") << "<!DOCTYPE html><html><body>moved</body></html>";
  std::ofstream(*dir_ / "www/index.html") << "<html>home</html>";
  struct Case {
    std::string path, says;
  };
  for (const Case& c : {Case{"/models/nope.hcs", "HTTP 404 Not Found"},
                        Case{"/models/page.hcs", "HTML page"}, Case{"/index.html", "HTML page"}}) {
    ClientRun r = client(base + c.path, {"--no-asa", "--quiet"});
    EXPECT_EQ(r.status, 1) << c.path;
    EXPECT_NE(r.err.find(base + c.path), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << r.err;
  }
  fs::remove(*dir_ / "www/models/page.hcs");
}

TEST_F(HttpServersTest, RecordsTheStreamDoesNotHaveAreRefusedFromItsIndex) {
  Nginx nginx;
  START_OR_SKIP(nginx);
  // Checked when the index arrives, before any record is streamed, as over TCP.
  ClientRun r = client("http://127.0.0.1:" + std::to_string(nginx.port()) + "/models/demo.hcs",
                       {"--no-asa", "--quiet", "--out-at", "100000"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("--out-at 100000: model 'demo' has records 0 to "), std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(r.out_dir + "/final.ply"));
}

TEST_F(HttpServersTest, UrlUsageErrorsExitTwoNamingTheProblem) {
  struct Case {
    std::vector<std::string> args;
    std::string says;
  };
  for (const Case& c : {Case{{"https://h/m.hcs"}, "https is not supported"},
                        Case{{"http://h/m.hcs", "m"}, "the URL names the model already"},
                        Case{{"http://h/m.hcs", "--list"}, "--list needs a meshstream server"},
                        Case{{"http://h:0/m.hcs"}, "is not a port"},
                        Case{{"http://h/"}, "names a folder, not an .hcs file"}}) {
    const std::string out = *dir_ / "usage.out", err = *dir_ / "usage.err";
    std::vector<std::string> argv{client_bin()};
    argv.insert(argv.end(), c.args.begin(), c.args.end());
    EXPECT_EQ(run(argv, out, err), 2) << c.args[0];
    EXPECT_NE(read_text(err).find(c.says), std::string::npos) << read_text(err);
  }
}

}  // namespace
}  // namespace meshstream::clienttest

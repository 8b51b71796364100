// What a new user trips over, with the REAL meshstream-client against the
// real meshstream-server on loopback (issue 21): Ctrl-C ends cleanly, a
// first connection that cannot be made fails at once, --out is
// deterministic and keeps out of folders of earlier runs, a record event
// per decoded record, --snapshot mistakes found before streaming, the
// progress line's rate is the true rate, and each message names its cause.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <atomic>
#include <set>

#include "common/asa/approximate.h"
#include "common/asa/subdivide.h"
#include "common/asa/view.h"
#include "tests/client/client_harness.h"

namespace meshstream::clienttest {
namespace {

struct CliRun {
  int status = -1;
  std::string out, err;
  std::vector<nlohmann::json> events;
  double seconds = 0;
};

// The lines of `text` that are not empty.
std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty()) lines.push_back(line);
  }
  return lines;
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

std::set<std::string> files_in(const std::string& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

std::string ply_name(int64_t record) {
  char name[32];
  std::snprintf(name, sizeof name, "%04lld.ply", static_cast<long long>(record));
  return name;
}

class ClientCliTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new TempDir();
    ASSERT_EQ(make_demo_model(dir_->path()), "");
    fast_ = new Server();
    ASSERT_TRUE(
        fast_->start({"--models", *dir_ / "models", "--cache", *dir_ / "cache"}, dir_->path()))
        << fast_->log();
    fs::create_directories(*dir_ / "slow");
    slow_ = new Server();
    // ~31 KB at 10 kB/s: three seconds, time to act mid-stream.
    ASSERT_TRUE(slow_->start({"--models", *dir_ / "models", "--cache", *dir_ / "cache", "--rate",
                              "10000", "--max-chunk-bytes", "1024"},
                             *dir_ / "slow"))
        << slow_->log();
  }
  static void TearDownTestSuite() {
    delete fast_;
    delete slow_;
    delete dir_;
    fast_ = slow_ = nullptr;
    dir_ = nullptr;
  }
  static std::string hcs() { return *dir_ / "models/demo.hcs"; }

  // meshstream-client ADDRESS ARGS... to completion.
  static CliRun client(const std::string& address, const std::vector<std::string>& args,
                       const std::vector<std::string>& env_prefix = {}) {
    static int n = 0;
    const std::string out = *dir_ / ("c" + std::to_string(++n) + ".out");
    const std::string err = *dir_ / ("c" + std::to_string(n) + ".err");
    std::vector<std::string> argv = env_prefix;
    argv.push_back(client_bin());
    argv.push_back(address);
    argv.insert(argv.end(), args.begin(), args.end());
    CliRun r;
    const auto start = Clock::now();
    r.status = run(argv, out, err);
    r.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    r.out = read_text(out);
    r.err = read_text(err);
    r.events = parse_events(r.out);
    return r;
  }

  // `meshstream decode` of the stream's first `bytes` bytes (all when 0).
  static std::string tool_decode(uint64_t bytes, const std::string& name) {
    std::vector<std::string> argv{tool_bin(), "decode", hcs(), "-o", *dir_ / name};
    if (bytes) {
      argv.push_back("--bytes");
      argv.push_back(std::to_string(bytes));
    }
    EXPECT_EQ(run(argv, *dir_ / "dec.out", *dir_ / "dec.err"), 0) << read_text(*dir_ / "dec.err");
    return *dir_ / name;
  }

  static TempDir* dir_;
  static Server* fast_;
  static Server* slow_;
};

TempDir* ClientCliTest::dir_ = nullptr;
Server* ClientCliTest::fast_ = nullptr;
Server* ClientCliTest::slow_ = nullptr;

// Starts the client on the slow server, waits for `refinements` display
// updates, sends `sig`; the run's outcome.
CliRun interrupt_mid_stream(const std::string& address, const std::vector<std::string>& args,
                            const std::string& dir, int sig) {
  Child c;
  const std::string out = dir + "/events.txt", err = dir + "/client.err";
  std::vector<std::string> argv{client_bin(), address};
  argv.insert(argv.end(), args.begin(), args.end());
  CliRun r;
  if (!c.start(argv, out, err)) return r;
  const auto deadline = Clock::now() + 20s;
  while (Clock::now() < deadline && of_kind(parse_events(read_text(out)), "refinement").size() < 3)
    std::this_thread::sleep_for(10ms);
  const auto sent = Clock::now();
  c.signal(sig);
  const auto status = c.wait(20s);
  r.status = status ? *status : -1001;
  r.seconds = std::chrono::duration<double>(Clock::now() - sent).count();
  r.out = read_text(out);
  r.err = read_text(err);
  r.events = parse_events(r.out);
  return r;
}

// Row 1: Ctrl-C mid-stream is a clean end: every JSON line complete, a done
// event with reason cancelled, final.ply and final.decoded.ply of what had
// arrived (the offline decoder's mesh of that prefix, byte for byte), exit
// 130 (128 + SIGINT).
TEST_F(ClientCliTest, CtrlCMidStreamEndsCleanlyWithDoneFinalPlyAndExit130) {
  TempDir out;
  const CliRun r = interrupt_mid_stream(slow_->address(), {"demo", "--json", "--out", out / "o"},
                                        out.path(), SIGINT);
  ASSERT_EQ(r.status, 130) << r.err;
  EXPECT_LT(r.seconds, 3.0) << "the clean end took too long";
  ASSERT_FALSE(r.out.empty());
  EXPECT_EQ(r.out.back(), '\n') << "the last JSON line is cut short";
  for (const auto& e : r.events) ASSERT_TRUE(e.is_object()) << "a line that is not JSON";
  const auto& done = r.events.back();
  ASSERT_EQ(done["event"], "done") << r.out;
  EXPECT_EQ(done["reason"], "cancelled");
  EXPECT_LT(done["records"].get<int>(), done["records_total"].get<int>())
      << "the stream finished before the signal (not mid-stream)";
  EXPECT_GE(done["records"].get<int>(), 1);
  EXPECT_EQ(of_kind(r.events, "error").size(), 0u) << r.out;
  // What arrived, saved: the offline decode of the same prefix.
  ASSERT_TRUE(fs::exists(out / "o/final.ply"));
  const std::string expected = tool_decode(done["bytes"].get<uint64_t>(), "cancelled.ply");
  EXPECT_EQ(read_text(out / "o/final.decoded.ply"), read_text(expected));
  // --out keeps the whole display; the renderer is handed what the camera sees.
  EXPECT_EQ(load_ply(out / "o/final.ply").face_count(),
            done["whole_display_faces"].get<uint32_t>());
  EXPECT_LE(done["display_faces"].get<uint32_t>(), done["whole_display_faces"].get<uint32_t>());
}

// SIGTERM ends the same way (exit 143), and without --json the summary line
// still comes, saying "cancelled".
TEST_F(ClientCliTest, SigtermEndsCleanlyWithTheSummaryLine) {
  TempDir out;
  const CliRun r =
      interrupt_mid_stream(slow_->address(), {"demo", "--quiet", "--json"}, out.path(), SIGTERM);
  ASSERT_EQ(r.status, 143) << r.err;
  ASSERT_FALSE(r.events.empty());
  EXPECT_EQ(r.events.back()["reason"], "cancelled");
  TempDir text;
  Child c;
  ASSERT_TRUE(c.start({client_bin(), slow_->address(), "demo", "--quiet", "--no-asa"},
                      text / "out.txt", text / "err.txt"));
  std::this_thread::sleep_for(800ms);
  c.signal(SIGINT);
  const auto status = c.wait(20s);
  ASSERT_TRUE(status);
  EXPECT_EQ(*status, 130) << read_text(text / "err.txt");
  const auto summary = lines_of(read_text(text / "out.txt"));
  ASSERT_EQ(summary.size(), 1u) << read_text(text / "out.txt");
  EXPECT_TRUE(contains(summary[0], "demo: ")) << summary[0];
  EXPECT_TRUE(contains(summary[0], "(cancelled)")) << summary[0];
}

// A TCP listener that answers whatever it is sent with an HTTP error and
// closes: a peer that is not a meshstream server. Counts connections.
class HttpPeer {
 public:
  HttpPeer() {
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
        if (::poll(&p, 1, 50) <= 0) continue;
        const int c = ::accept(fd_, nullptr, nullptr);
        if (c < 0) continue;
        ++connections_;
        char buf[256];
        (void)::recv(c, buf, sizeof buf, 0);
        const char reply[] = "HTTP/1.0 400 Bad Request\r\nContent-Length: 0\r\n\r\n";
        (void)::send(c, reply, sizeof reply - 1, MSG_NOSIGNAL);
        ::close(c);
      }
    });
  }
  ~HttpPeer() {
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

// Row 2: nobody listening, a name that does not resolve, a peer that does
// not speak the protocol: exit 1 at once with one line naming the cause,
// no reconnecting (only a connection lost after a handshake is retried:
// ClientStreamTest.KilledAndRestartedServerGivesTheIdenticalFinalMesh).
TEST_F(ClientCliTest, AFirstConnectionThatCannotBeMadeFailsAtOnce) {
  const std::string refused = "127.0.0.1:" + std::to_string(free_port());
  const CliRun nobody = client(refused, {"demo", "--json"});
  EXPECT_EQ(nobody.status, 1);
  EXPECT_LT(nobody.seconds, 2.0);
  ASSERT_EQ(lines_of(nobody.err).size(), 1u) << nobody.err;
  EXPECT_TRUE(contains(nobody.err, "cannot connect to " + refused)) << nobody.err;
  EXPECT_FALSE(contains(nobody.err, "reconnecting")) << nobody.err;
  ASSERT_EQ(of_kind(nobody.events, "error").size(), 1u);

  const CliRun unresolved = client("no-such-host.invalid:7878", {"demo"});
  EXPECT_EQ(unresolved.status, 1);
  ASSERT_EQ(lines_of(unresolved.err).size(), 1u) << unresolved.err;
  EXPECT_TRUE(contains(unresolved.err, "cannot resolve no-such-host.invalid:7878"))
      << unresolved.err;

  HttpPeer http;
  const CliRun stranger = client(http.address(), {"demo"});
  EXPECT_EQ(stranger.status, 1);
  EXPECT_LT(stranger.seconds, 2.0);
  ASSERT_EQ(lines_of(stranger.err).size(), 1u) << stranger.err;
  EXPECT_TRUE(contains(stranger.err, "no meshstream server at " + http.address())) << stranger.err;
  EXPECT_EQ(http.connections(), 1) << "the client tried a peer that never spoke the protocol again";
}

// Row 7: --out writes final.ply and final.decoded.ply, and NNNN.ply only at
// the records asked for (--out-every N, --out-at LIST), the same files
// byte for byte on a fast and a throttled link.
TEST_F(ClientCliTest, OutWritesTheChosenRecordsWhateverTheTiming) {
  TempDir out;
  const CliRun plain = client(fast_->address(), {"demo", "--json", "--out", out / "plain"});
  ASSERT_EQ(plain.status, 0) << plain.err;
  EXPECT_EQ(files_in(out / "plain"), (std::set<std::string>{"final.ply", "final.decoded.ply"}));

  const std::vector<std::string> chosen{"--out-every", "40", "--out-at", "3,17"};
  std::vector<std::string> args{"demo", "--json", "--asa-levels", "1"};
  args.insert(args.end(), chosen.begin(), chosen.end());
  auto with_out = [&](const std::string& dir) {
    std::vector<std::string> a = args;
    a.push_back("--out");
    a.push_back(dir);
    return a;
  };
  const CliRun fast = client(fast_->address(), with_out(out / "fast"));
  ASSERT_EQ(fast.status, 0) << fast.err;
  const CliRun slow = client(slow_->address(), with_out(out / "slow"));
  ASSERT_EQ(slow.status, 0) << slow.err;
  const int records = fast.events.back()["records"].get<int>();
  std::set<std::string> expected{"final.ply", "final.decoded.ply", ply_name(3), ply_name(17)};
  for (int r = 0; r < records; r += 40) expected.insert(ply_name(r));
  EXPECT_EQ(files_in(out / "fast"), expected);
  EXPECT_EQ(files_in(out / "slow"), expected);
  // The same meshes: ASA's two paths (--asa-path auto picks the faster)
  // give the same triangles, not always in the same order.
  for (const std::string& name : expected) {
    EXPECT_TRUE(same_geometry(load_ply(out / ("fast/" + name)), load_ply(out / ("slow/" + name))))
        << name;
  }
  EXPECT_TRUE(read_text(out / "fast/final.decoded.ply") ==
              read_text(out / "slow/final.decoded.ply"));
  // NNNN.ply is the display mesh after record NNNN: ASA of that prefix,
  // view-dependent for the snapshot camera of that prefix at 1024 x 768.
  const std::string prefix =
      tool_decode(of_kind(fast.events, "record")[17]["bytes"].get<uint64_t>(), "prefix17.ply");
  const std::string camera = format_camera(fit_camera(load_ply(prefix), 1024, 768));
  ASSERT_EQ(run({tool_bin(), "subdivide", prefix, "-o", *dir_ / "sub17.ply", "--levels", "1",
                 "--camera", camera, "--width", "1024", "--height", "768"},
                *dir_ / "sub.out", *dir_ / "sub.err"),
            0)
      << read_text(*dir_ / "sub.err");
  EXPECT_TRUE(same_geometry(load_ply(out / "fast/0017.ply"), load_ply(*dir_ / "sub17.ply")));
}

// Issue 20: once every record has arrived nothing is missing, so the final
// display and final.ply are the decoded mesh (ASA of the complete mesh moved
// it away from the original); a prefix (a budget) is still post-processed,
// and --asa-complete asks for ASA on the complete mesh.
TEST_F(ClientCliTest, TheCompleteStreamIsShownAndSavedAsDecoded) {
  TempDir out;
  const CliRun full = client(fast_->address(), {"demo", "--json", "--out", out / "full"});
  ASSERT_EQ(full.status, 0) << full.err;
  const auto& done = full.events.back();
  ASSERT_EQ(done["records"], done["records_total"]) << "the stream did not complete";
  const Mesh decoded = load_ply(out / "full/final.decoded.ply");
  EXPECT_TRUE(same_geometry(load_ply(out / "full/final.ply"), decoded));
  EXPECT_EQ(done["whole_display_faces"].get<uint32_t>(), decoded.face_count());
  // Nothing is drawn (no --view, no --snapshot): nothing is culled.
  EXPECT_EQ(done["display_faces"].get<uint32_t>(), decoded.face_count());

  // The default (--asa auto) follows the stream's guidance and names the
  // setting it used in every refinement event.
  for (const auto& e : full.events) {
    if (e["event"] == "refinement") {
      EXPECT_TRUE(e.contains("asa")) << e.dump();
    }
  }
  // Fixed ASA (--asa on) post-processes every prefix.
  const CliRun part = client(fast_->address(), {"demo", "--json", "--asa", "on", "--percent-bytes",
                                                "30", "--out", out / "part"});
  ASSERT_EQ(part.status, 0) << part.err;
  EXPECT_LT(part.events.back()["records"].get<int>(),
            part.events.back()["records_total"].get<int>());
  EXPECT_GT(load_ply(out / "part/final.ply").face_count(),
            load_ply(out / "part/final.decoded.ply").face_count())
      << "the prefix was not post-processed";

  const CliRun asked = client(fast_->address(), {"demo", "--json", "--asa", "on", "--asa-complete",
                                                 "--out", out / "asked"});
  ASSERT_EQ(asked.status, 0) << asked.err;
  EXPECT_GT(load_ply(out / "asked/final.ply").face_count(), decoded.face_count())
      << "--asa-complete did not post-process the complete mesh";
}

// Issue 20, point 4: --approximate relaxes the decoded prefix before ASA
// (approximate.h): final.ply is ASA of the relaxed final.decoded.ply, and
// not the interpolating ASA of it.
TEST_F(ClientCliTest, ApproximateRelaxesTheDecodedPrefixBeforeAsa) {
  TempDir out;
  const CliRun run =
      client(fast_->address(), {"demo", "--json", "--approximate", "--view-independent",
                                "--percent-bytes", "30", "--out", out / "a"});
  ASSERT_EQ(run.status, 0) << run.err;
  const Mesh decoded = load_ply(out / "a/final.decoded.ply");
  Mesh relaxed = decoded;
  ASSERT_TRUE(relax_toward_smooth(relaxed));
  auto expected = subdivide(relaxed, AsaOptions{});
  ASSERT_TRUE(expected);
  auto interpolating = subdivide(decoded, AsaOptions{});
  ASSERT_TRUE(interpolating);
  const Mesh shown = load_ply(out / "a/final.ply");
  EXPECT_TRUE(same_geometry(shown, expected->mesh));
  EXPECT_FALSE(same_geometry(shown, interpolating->mesh));
  EXPECT_EQ(client(fast_->address(), {"demo", "--approximate", "--asa", "off"}).status, 2);
}

// Row 6: --out into a folder with files in it is refused (exit 1, naming
// the folder and --overwrite) before connecting; --overwrite deletes only
// the files this program writes.
TEST_F(ClientCliTest, OutRefusesAFolderOfAnEarlierRunUnlessOverwrite) {
  TempDir out;
  const std::string dir = out / "o";
  ASSERT_EQ(client(fast_->address(), {"demo", "--out", dir, "--out-every", "10", "--quiet"}).status,
            0);
  const auto first = files_in(dir);
  ASSERT_TRUE(first.count(ply_name(10)));
  std::ofstream(dir + "/notes.txt") << "mine\n";

  const CliRun refused = client(fast_->address(), {"demo", "--out", dir, "--quiet"});
  EXPECT_EQ(refused.status, 1);
  ASSERT_EQ(lines_of(refused.err).size(), 1u) << refused.err;
  EXPECT_TRUE(contains(refused.err, dir)) << refused.err;
  EXPECT_TRUE(contains(refused.err, "not empty")) << refused.err;
  EXPECT_TRUE(contains(refused.err, "--overwrite")) << refused.err;
  auto with_notes = first;
  with_notes.insert("notes.txt");
  EXPECT_EQ(files_in(dir), with_notes) << "a refused run touched the folder";

  const CliRun overwritten =
      client(fast_->address(), {"demo", "--out", dir, "--out-at", "5", "--overwrite", "--quiet"});
  ASSERT_EQ(overwritten.status, 0) << overwritten.err;
  EXPECT_EQ(files_in(dir),
            (std::set<std::string>{"notes.txt", ply_name(5), "final.ply", "final.decoded.ply"}));
  EXPECT_EQ(read_text(dir + "/notes.txt"), "mine\n");
}

// Row 8: a record event for every decoded record, in order, with its
// counts (the offline decoder's at that prefix), beside the refinements.
TEST_F(ClientCliTest, JsonHasARecordEventForEveryDecodedRecord) {
  const CliRun r = client(fast_->address(), {"demo", "--json", "--no-asa"});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto records = of_kind(r.events, "record");
  const auto& done = r.events.back();
  ASSERT_EQ(done["event"], "done");
  ASSERT_EQ(static_cast<int>(records.size()), done["records"].get<int>());
  EXPECT_LT(of_kind(r.events, "refinement").size(), records.size())
      << "every record had its own display update: the test shows nothing";
  uint64_t sum = 0;
  for (size_t i = 0; i < records.size(); ++i) {
    const auto& e = records[i];
    EXPECT_EQ(e["index"].get<size_t>(), i);
    for (const char* key :
         {"bytes", "record_bytes", "vertices", "faces", "decode_ms", "elapsed_ms"})
      ASSERT_TRUE(e.contains(key)) << key;
    sum += e["record_bytes"].get<uint64_t>();
    EXPECT_EQ(e["bytes"].get<uint64_t>(), sum) << i;
    if (i > 0) {
      EXPECT_LE(records[i - 1]["vertices"].get<uint32_t>(), e["vertices"].get<uint32_t>());
    }
  }
  EXPECT_EQ(records.back()["bytes"], done["bytes"]);
  EXPECT_EQ(records.back()["vertices"], done["vertices"]);
  EXPECT_EQ(records.back()["faces"], done["faces"]);
  // Every refinement comes after the record event of the record it shows.
  int64_t last_record = -1;
  for (const auto& e : r.events) {
    if (e["event"] == "record") last_record = e["index"];
    if (e["event"] == "refinement") {
      EXPECT_LE(e["index"].get<int64_t>(), last_record);
    }
  }
  const size_t mid = records.size() / 2;
  const Mesh at_mid = load_ply(tool_decode(records[mid]["bytes"].get<uint64_t>(), "mid.ply"));
  EXPECT_EQ(at_mid.vertex_count(), records[mid]["vertices"].get<uint32_t>());
  EXPECT_EQ(at_mid.face_count(), records[mid]["faces"].get<uint32_t>());
}

// Row 10: what can be checked before streaming is: the record of
// --snapshot-at against the header (before any record), the folder and
// the extension of --snapshot before connecting.
TEST_F(ClientCliTest, SnapshotMistakesAreFoundBeforeStreaming) {
  TempDir out;
  const CliRun beyond = client(
      slow_->address(), {"demo", "--json", "--snapshot", out / "s.png", "--snapshot-at", "5000"});
  EXPECT_EQ(beyond.status, 1);
  EXPECT_LT(beyond.seconds, 1.5) << "the stream (3 s) ran before the check";
  EXPECT_TRUE(of_kind(beyond.events, "record").empty()) << "records streamed before the check";
  const int records = [&] {
    const CliRun all = client(fast_->address(), {"demo", "--json", "--no-asa"});
    return all.events.back()["records_total"].get<int>();
  }();
  EXPECT_TRUE(contains(beyond.err, "--snapshot-at 5000")) << beyond.err;
  EXPECT_TRUE(contains(beyond.err, "records 0 to " + std::to_string(records - 1))) << beyond.err;
  EXPECT_FALSE(fs::exists(out / "s.png"));
  // Within a budget, the range is the budget's.
  const CliRun budget =
      client(fast_->address(), {"demo", "--bytes", "3000", "--out", out / "b", "--out-at", "200"});
  EXPECT_EQ(budget.status, 1);
  EXPECT_TRUE(contains(budget.err, "--out-at 200")) << budget.err;
  EXPECT_TRUE(contains(budget.err, "within the budget")) << budget.err;

  const CliRun folder = client(fast_->address(), {"demo", "--snapshot", "/nonexistent/x.png"});
  EXPECT_EQ(folder.status, 1);
  ASSERT_EQ(lines_of(folder.err).size(), 1u) << folder.err;
  EXPECT_TRUE(contains(folder.err, "/nonexistent does not exist")) << folder.err;

  const CliRun jpeg = client(fast_->address(), {"demo", "--snapshot", out / "x.jpg"});
  EXPECT_EQ(jpeg.status, 2);
  EXPECT_TRUE(contains(jpeg.err, "only PNG")) << jpeg.err;
  EXPECT_TRUE(contains(jpeg.err, ".jpg")) << jpeg.err;
  EXPECT_FALSE(fs::exists(out / "x.jpg"));
}

// Issue 20: a crease angle below acos(--flatness) leaves ASA nothing to
// refine; the client (and so its viewer) refuses it before connecting, naming
// both values and the relation. Without ASA, or with a lower t, it streams.
TEST_F(ClientCliTest, CreaseBelowTheFlatnessAngleIsAUsageError) {
  const CliRun clash = client(fast_->address(), {"demo", "--crease", "30"});
  EXPECT_EQ(clash.status, 2) << clash.err;
  ASSERT_EQ(lines_of(clash.err).size(), 1u) << clash.err;
  EXPECT_TRUE(contains(clash.err, "--crease 30 is below acos(--flatness 0.85) = 31.8 degrees"))
      << clash.err;
  const CliRun view =
      client(fast_->address(), {"demo", "--view", "--crease", "20", "--flatness", "0.9"});
  EXPECT_EQ(view.status, 2) << view.err;
  EXPECT_TRUE(contains(view.err, "--crease 20 is below acos(--flatness 0.9)")) << view.err;
  EXPECT_EQ(client(fast_->address(), {"demo", "--crease", "30", "--no-asa", "--json"}).status, 0);
  EXPECT_EQ(
      client(fast_->address(), {"demo", "--crease", "30", "--flatness", "0.9", "--json"}).status,
      0);
}

// Row 16: a malformed HOST:PORT and an out-of-range port each get their own
// reason (exit 2); an unknown model prints the server's own message.
TEST_F(ClientCliTest, AddressAndModelMessagesNameTheirCause) {
  const CliRun no_port = client("localhost", {"demo"});
  EXPECT_EQ(no_port.status, 2);
  EXPECT_TRUE(contains(no_port.err, "is not HOST:PORT")) << no_port.err;
  const CliRun word = client("localhost:http", {"demo"});
  EXPECT_EQ(word.status, 2);
  EXPECT_TRUE(contains(word.err, "'http' is not a number")) << word.err;
  const CliRun range = client("localhost:99999", {"demo"});
  EXPECT_EQ(range.status, 2);
  EXPECT_TRUE(contains(range.err, "port 99999")) << range.err;
  EXPECT_TRUE(contains(range.err, "out of range")) << range.err;
  EXPECT_FALSE(contains(range.err, "is not HOST:PORT")) << range.err;

  const CliRun unknown = client(fast_->address(), {"demoo"});
  EXPECT_EQ(unknown.status, 1);
  ASSERT_EQ(lines_of(unknown.err).size(), 1u) << unknown.err;
  EXPECT_TRUE(contains(unknown.err, "server " + fast_->address() + ": ")) << unknown.err;
  EXPECT_TRUE(contains(unknown.err, "'demoo'")) << unknown.err;
}

// Row 18: --view with no display: one "viewer:" prefix and where to turn.
TEST_F(ClientCliTest, ViewWithoutADisplaySaysWhatToUseInstead) {
  const CliRun r = client(fast_->address(), {"demo", "--view", "--quiet"},
                          {"/usr/bin/env", "-u", "DISPLAY", "-u", "WAYLAND_DISPLAY"});
  EXPECT_EQ(r.status, 1);
  ASSERT_EQ(lines_of(r.err).size(), 1u) << r.err;
  EXPECT_TRUE(contains(r.err, "meshstream-client: viewer: ")) << r.err;
  EXPECT_FALSE(contains(r.err, "viewer: viewer:")) << r.err;
  EXPECT_TRUE(contains(r.err, "--snapshot")) << r.err;
  EXPECT_TRUE(contains(r.err, "xvfb-run")) << r.err;
}

// Row 14: on a terminal, the progress line's rate is the link's rate (10
// kB/s here, measured over the time since the first byte), in kB.
TEST_F(ClientCliTest, ProgressLineShowsTheTrueRate) {
  const int master = ::posix_openpt(O_RDWR | O_NOCTTY);
  ASSERT_GE(master, 0);
  ASSERT_EQ(::grantpt(master), 0);
  ASSERT_EQ(::unlockpt(master), 0);
  const std::string terminal = ::ptsname(master);
  TempDir out;
  Child c;
  ASSERT_TRUE(
      c.start({client_bin(), slow_->address(), "demo", "--no-asa"}, out / "out.txt", terminal));
  std::string shown;
  std::optional<int> status;
  while (!(status = c.wait(10ms))) {
    pollfd p{master, POLLIN, 0};
    while (::poll(&p, 1, 0) > 0) {
      char buf[4096];
      const ssize_t n = ::read(master, buf, sizeof buf);
      if (n <= 0) break;
      shown.append(buf, static_cast<size_t>(n));
    }
  }
  ::close(master);
  ASSERT_EQ(*status, 0);
  // "\r\033[K12.3 kB / 31.0 kB (40%)  records ...  10.1 kB/s"
  // (bytes received, rate shown) per update; values in B, kB or MB.
  auto value_of = [](const std::string& text, size_t at) {
    size_t used = 0;
    const double v = std::stod(text.substr(at), &used);
    const std::string unit = text.substr(at + used, 3);
    return unit == " kB" ? v * 1e3 : unit == " MB" ? v * 1e6 : v;
  };
  std::vector<std::pair<double, double>> updates;
  std::istringstream in(shown);
  for (std::string update; std::getline(in, update, '\r');) {
    const auto start = update.find_first_of("0123456789");
    const auto per_s = update.rfind("/s");
    if (start == std::string::npos || per_s == std::string::npos) continue;
    const auto rate_at = update.rfind("  ", per_s) + 2;
    updates.emplace_back(value_of(update, start), value_of(update, rate_at));
  }
  EXPECT_FALSE(contains(shown, "KB")) << "one unit spelling: kB";
  EXPECT_TRUE(contains(shown, " kB/s")) << shown;
  size_t checked = 0;
  for (const auto& [received, rate] : updates) {
    // From 0.4 s of streaming on (the first 4 kB) the rate is the link's
    // within the pacing's jitter; the old meter (bytes of the last second)
    // showed 1, 2, 3 kB/s there, rising towards the link's rate.
    if (received < 4000) continue;
    ++checked;
    EXPECT_GT(rate, 7000.0) << "at " << received << " bytes";
    EXPECT_LT(rate, 13000.0) << "at " << received << " bytes";
  }
  EXPECT_GE(checked, 5u) << shown;
}

}  // namespace
}  // namespace meshstream::clienttest

// The server serves while it encodes (issue 15 point 5), through the real
// meshstream-server and meshstream-client binaries, real files in a temp
// folder and real sockets on loopback: a model still being encoded is
// listed with its state and refused with NOT_READY, `--wait` waits for it
// and then streams it; files added, changed and removed while the server
// runs are picked up (inotify and polling); a corrupt file dropped in is
// listed as failed with its reason while the others keep serving. Every
// wait polls with a generous deadline; nothing sleeps a fixed time to
// let the server catch up.
#include <gtest/gtest.h>

#include <cstdlib>
#include <functional>
#include <nlohmann/json.hpp>

#include "common/mesh/export.h"
#include "common/mesh/procedural.h"
#include "server/catalog.h"
#include "server/synthetic_stream.h"
#include "tests/net/greeted_client.h"
#include "tests/net/net_harness.h"

namespace meshstream::nettest {
namespace {

namespace fs = std::filesystem;

fs::path temp_root() {
  return fs::temp_directory_path() / ("ms_watch_" + std::to_string(::getpid()));
}

class CleanupWatchDirs : public ::testing::Environment {
 public:
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(temp_root(), ec);
  }
};
const auto* const cleanup_registration = ::testing::AddGlobalTestEnvironment(new CleanupWatchDirs);

std::string fresh_dir(const std::string& name) {
  const fs::path dir = temp_root() / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

std::string client_binary() {
  return std::string(MESHSTREAM_BINARY_DIR) + "/client/meshstream-client";
}

// A tetrahedron and a cube (as OFF), two small meshes that encode at once.
const char* const kTetraOff =
    "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
    "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
const char* const kCubeOff =
    "OFF\n8 12 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
    "3 0 2 1\n3 0 3 2\n3 4 5 6\n3 4 6 7\n3 0 1 5\n3 0 5 4\n"
    "3 1 2 6\n3 1 6 5\n3 2 3 7\n3 2 7 6\n3 3 0 4\n3 3 4 7\n";

void write_text(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

v1::ModelList list_models(uint16_t port) {
  TestClient c = greeted_client(port);
  v1::ServerMessage m;
  EXPECT_TRUE(c.list());
  EXPECT_EQ(c.read(m), ReadEnd::kMessage);
  return m.model_list();
}

std::optional<v1::ModelInfo> find_model(const v1::ModelList& list, const std::string& name) {
  for (const auto& m : list.models()) {
    if (m.name() == name) return m;
  }
  return std::nullopt;
}

// Polls ListModels until `done` holds for `name`'s entry (nullopt: not
// listed) or `timeout`; the last entry seen.
std::optional<v1::ModelInfo> poll_model(
    uint16_t port, const std::string& name,
    const std::function<bool(const std::optional<v1::ModelInfo>&)>& done,
    std::chrono::milliseconds timeout, bool* met = nullptr) {
  const auto deadline = Clock::now() + timeout;
  std::optional<v1::ModelInfo> seen;
  while (true) {
    seen = find_model(list_models(port), name);
    if (done(seen)) {
      if (met) *met = true;
      return seen;
    }
    if (Clock::now() >= deadline) {
      if (met) *met = false;
      return seen;
    }
    std::this_thread::sleep_for(50ms);
  }
}

bool is_ready(const std::optional<v1::ModelInfo>& m) {
  return m && m->state() == v1::ModelInfo::READY;
}

StreamResult stream_model(uint16_t port, const std::string& name) {
  TestClient c = greeted_client(port);
  EXPECT_TRUE(c.stream(name));
  return read_stream(c, 30000ms);
}

struct ClientRun {
  int status = -1;
  std::string out, err;
};

// Runs meshstream-client with `args` to its end (killed after `limit_s`).
ClientRun run_client(const std::vector<std::string>& args, const std::string& work,
                     int limit_s = 120) {
  std::string cmd = "timeout -s KILL " + std::to_string(limit_s) + " " + client_binary();
  for (const std::string& a : args) cmd += " '" + a + "'";
  cmd += " > " + work + "/client.out 2> " + work + "/client.err";
  const int raw = std::system(cmd.c_str());
  ClientRun r;
  if (WIFEXITED(raw) && WEXITSTATUS(raw) != 137) r.status = WEXITSTATUS(raw);
  const auto out = read_file(work + "/client.out");
  const auto err = read_file(work + "/client.err");
  r.out.assign(out.begin(), out.end());
  r.err.assign(err.begin(), err.end());
  return r;
}

std::vector<nlohmann::json> json_lines(const std::string& text) {
  std::vector<nlohmann::json> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty()) out.push_back(nlohmann::json::parse(line, nullptr, false));
  }
  return out;
}

// --------------------------------------------------- not ready, then --wait

TEST(ServeWhileEncoding, ListsAtOnceRefusesNotReadyAndWaitStreamsIt) {
  if (!server::demo_models_available()) GTEST_SKIP() << "this build has no encoder";
  const std::string work = fresh_dir("not_ready");
  const std::string models = fresh_dir("not_ready/models");
  // 50k vertices: an encode of seconds (one at least on an idle machine),
  // long enough to be seen encoding.
  ASSERT_TRUE(static_cast<bool>(write_ply(make_demo_mesh(100000), models + "/big.ply")));
  const std::vector<uint8_t> small = server::make_synthetic_hcs({});
  write_file(models + "/small.hcs", small);

  ServerProcess server;
  const auto started = Clock::now();
  ASSERT_TRUE(server.start({"--models", models, "--cache", "none", "--encoders", "1"},
                           work + "/log.txt", 20s, ServerProcess::Wait::kPort))
      << server.log();
  const double listening_s = std::chrono::duration<double>(Clock::now() - started).count();
  std::printf("[ measured ] 'listening on' %.3f s after start (a 50k-vertex mesh to encode)\n",
              listening_s);
  EXPECT_LT(listening_s, 5.0) << "the server must not encode before it listens";

  // Listed at once (the watcher's first scan) and not ready.
  bool met = false;
  const auto first = poll_model(
      server.port(), "big", [](const auto& m) { return m.has_value(); }, 10s, &met);
  ASSERT_TRUE(met) << server.log();
  ASSERT_NE(first->state(), v1::ModelInfo::READY)
      << "a 50k-vertex encode finished before the first ListModels";
  EXPECT_EQ(first->source(), "mesh");

  // A stream request gets NOT_READY naming the model and its progress; the
  // connection stays usable, and the .hcs beside it is served meanwhile.
  {
    TestClient c = greeted_client(server.port());
    ASSERT_TRUE(c.stream("big"));
    v1::ServerMessage m;
    ASSERT_EQ(c.read(m), ReadEnd::kMessage);
    ASSERT_TRUE(m.has_error()) << m.DebugString();
    EXPECT_EQ(m.error().code(), v1::Error::NOT_READY) << m.DebugString();
    EXPECT_FALSE(m.error().closing());
    EXPECT_EQ(m.error().model().name(), "big");
    EXPECT_TRUE(m.error().model().state() == v1::ModelInfo::ENCODING ||
                m.error().model().state() == v1::ModelInfo::QUEUED)
        << m.DebugString();
    EXPECT_NE(m.error().message().find("model 'big' is not ready: "), std::string::npos)
        << m.error().message();
    if (m.error().model().state() == v1::ModelInfo::ENCODING) {
      EXPECT_NE(m.error().message().find(" %"), std::string::npos) << m.error().message();
    }
    // (A .hcs is only read and checked: ready in milliseconds, never
    // behind the encode.)
    poll_model(server.port(), "small", is_ready, 10s, &met);
    ASSERT_TRUE(met) << server.log();
    EXPECT_FALSE(is_ready(find_model(list_models(server.port()), "big")))
        << "the .hcs waited for the encode";
    ASSERT_TRUE(c.stream("small"));
    const StreamResult r = read_stream(c);
    ASSERT_TRUE(r.ok) << r.problem;
    EXPECT_EQ(r.bytes, small);
  }

  // The client without --wait: exit 1, naming the model and NOT_READY.
  const ClientRun refused = run_client(
      {"127.0.0.1:" + std::to_string(server.port()), "big", "--no-asa", "--quiet"}, work);
  if (!is_ready(find_model(list_models(server.port()), "big"))) {
    EXPECT_EQ(refused.status, 1) << refused.err;
    EXPECT_NE(refused.err.find("model 'big' is not ready"), std::string::npos) << refused.err;
    EXPECT_NE(refused.err.find("[NOT_READY]"), std::string::npos) << refused.err;
    EXPECT_NE(refused.err.find("--wait"), std::string::npos) << refused.err;
  }

  // --list shows the state (text and JSON).
  const ClientRun listed =
      run_client({"127.0.0.1:" + std::to_string(server.port()), "--list", "--json"}, work);
  ASSERT_EQ(listed.status, 0) << listed.err;
  const auto events = json_lines(listed.out);
  ASSERT_EQ(events.size(), 1u) << listed.out;
  bool saw_small = false;
  for (const auto& model : events[0]["models"]) {
    if (model["name"] == "small") {
      saw_small = true;
      EXPECT_EQ(model["state"], "ready");
    }
    if (model["name"] == "big") {
      EXPECT_TRUE(model["state"] == "encoding" || model["state"] == "queued" ||
                  model["state"] == "ready")
          << model;
    }
  }
  EXPECT_TRUE(saw_small) << listed.out;

  // --wait: waits (reporting the state), then streams the whole model.
  const ClientRun waited = run_client(
      {"127.0.0.1:" + std::to_string(server.port()), "big", "--wait", "--no-asa", "--json"}, work);
  ASSERT_EQ(waited.status, 0) << waited.err << "\n" << server.log();
  std::printf(
      "[ measured ] --wait streamed the 50k-vertex model %.2f s after the server "
      "started\n",
      std::chrono::duration<double>(Clock::now() - started).count());
  bool done = false;
  for (const auto& e : json_lines(waited.out)) {
    if (e["event"] == "waiting") {
      EXPECT_EQ(e["model"], "big");
      EXPECT_TRUE(e["state"] == "encoding" || e["state"] == "queued") << e;
    }
    if (e["event"] == "done") {
      done = true;
      EXPECT_EQ(e["reason"], "complete") << e;
      EXPECT_GT(e["vertices"].get<uint32_t>(), 20000u) << e;
    }
  }
  EXPECT_TRUE(done) << waited.out;
  const auto ready = find_model(list_models(server.port()), "big");
  ASSERT_TRUE(is_ready(ready));
  EXPECT_GT(ready->vertices(), 20000u);
  // The log told how the encode went, and when it was done.
  EXPECT_NE(server.log().find("catalog: ready big: encoded " + models + "/big.ply"),
            std::string::npos)
      << server.log();

  // The file changes: while the new version is encoded, the old stream is
  // still served (listed as encoding, with the old stream's counts).
  const uint32_t old_vertices = ready->vertices();
  ASSERT_TRUE(static_cast<bool>(write_ply(make_demo_mesh(40000), models + "/big.ply")));
  const auto reencoding = poll_model(
      server.port(), "big", [](const auto& m) { return m && !is_ready(m); }, 20s, &met);
  ASSERT_TRUE(met) << server.log();
  EXPECT_EQ(reencoding->vertices(), old_vertices);
  const StreamResult old_stream = stream_model(server.port(), "big");
  ASSERT_TRUE(old_stream.ok) << old_stream.problem;
  EXPECT_EQ(old_stream.header.vertices(), old_vertices);
  const auto renewed = poll_model(
      server.port(), "big",
      [&](const auto& m) { return is_ready(m) && m->vertices() != old_vertices; }, 60s, &met);
  ASSERT_TRUE(met) << (renewed ? renewed->DebugString() : "not listed") << server.log();
  for (const char* line : {"catalog: ready big", "catalog: changed", "catalog: encoding big"}) {
    std::istringstream log(server.log());
    for (std::string l; std::getline(log, l);) {
      if (l.find(line) != std::string::npos) std::printf("[ server   ] %s\n", l.c_str());
    }
  }
  const StreamResult new_stream = stream_model(server.port(), "big");
  ASSERT_TRUE(new_stream.ok) << new_stream.problem;
  EXPECT_EQ(new_stream.header.vertices(), renewed->vertices());
}

// ------------------------------------------------ added, changed, removed

class FolderWatch : public ::testing::TestWithParam<std::string> {};

TEST_P(FolderWatch, FilesAddedChangedAndRemovedArePickedUp) {
  if (!server::mesh_encoding_available()) GTEST_SKIP() << "this build has no encoder";
  const std::string mode = GetParam();
  const std::string work = fresh_dir("watch_" + mode);
  const std::string models = fresh_dir("watch_" + mode + "/models");
  server::SyntheticStreamOptions slow;
  slow.payload_bytes = 400000;
  const std::vector<uint8_t> stay = server::make_synthetic_hcs(slow);
  write_file(models + "/stay.hcs", stay);
  ServerProcess server;
  // Paced, so a stream of stay.hcs lasts about 2 s.
  ASSERT_TRUE(
      server.start({"--models", models, "--cache", "none", "--watch", mode, "--rate", "200000"},
                   work + "/log.txt"))
      << server.log();
  ASSERT_TRUE(is_ready(find_model(list_models(server.port()), "stay")));

  // Added, written in three pieces with pauses (a copy in progress): it is
  // taken only once whole, so it is never reported failed on the way.
  const auto added = Clock::now();
  {
    const std::string text = kTetraOff;
    std::ofstream out(models + "/shape.off", std::ios::binary);
    for (size_t i = 0; i < 3; ++i) {
      out << text.substr(i * text.size() / 3, text.size() / 3 + (i == 2 ? text.size() % 3 : 0));
      out.flush();
      std::this_thread::sleep_for(300ms);
    }
  }
  bool met = false;
  poll_model(
      server.port(), "shape", [](const auto& m) { return m.has_value(); }, 20s, &met);
  ASSERT_TRUE(met) << server.log();
  const double listed_s = std::chrono::duration<double>(Clock::now() - added).count();
  auto shape = poll_model(server.port(), "shape", is_ready, 30s, &met);
  ASSERT_TRUE(met) << server.log();
  const double ready_s = std::chrono::duration<double>(Clock::now() - added).count();
  std::printf(
      "[ measured ] --watch %s: a file written over 0.9 s listed %.2f s, ready %.2f s "
      "after its first byte\n",
      mode.c_str(), listed_s, ready_s);
  EXPECT_EQ(shape->vertices(), 4u);
  EXPECT_EQ(server.log().find("failed shape"), std::string::npos) << server.log();
  const StreamResult tetra = stream_model(server.port(), "shape");
  ASSERT_TRUE(tetra.ok) << tetra.problem;
  EXPECT_EQ(tetra.header.vertices(), 4u);

  // Changed: re-encoded, the new stream served once ready.
  write_text(models + "/shape.off", kCubeOff);
  shape = poll_model(
      server.port(), "shape", [](const auto& m) { return is_ready(m) && m->vertices() == 8u; }, 30s,
      &met);
  ASSERT_TRUE(met) << (shape ? shape->DebugString() : "not listed") << server.log();
  const StreamResult cube = stream_model(server.port(), "shape");
  ASSERT_TRUE(cube.ok) << cube.problem;
  EXPECT_EQ(cube.header.vertices(), 8u);
  EXPECT_NE(server.log().find("changed " + models + "/shape.off: re-encoding shape"),
            std::string::npos)
      << server.log();

  // Removed while a stream of it runs: withdrawn from the list at once, the
  // running stream still finishes, byte for byte.
  TestClient streaming = greeted_client(server.port());
  ASSERT_TRUE(streaming.stream("stay"));
  v1::ServerMessage header;
  ASSERT_EQ(streaming.read(header), ReadEnd::kMessage);
  ASSERT_TRUE(header.has_header()) << header.DebugString();
  fs::remove(models + "/stay.hcs");
  fs::remove(models + "/shape.off");
  poll_model(
      server.port(), "stay", [](const auto& m) { return !m.has_value(); }, 20s, &met);
  ASSERT_TRUE(met) << server.log();
  poll_model(
      server.port(), "shape", [](const auto& m) { return !m.has_value(); }, 20s, &met);
  ASSERT_TRUE(met) << server.log();
  // The rest of the stream (the header was read above).
  std::vector<uint8_t> bytes;
  v1::StreamEnd end;
  const auto deadline = Clock::now() + 30s;
  while (Clock::now() < deadline) {
    v1::ServerMessage next;
    ASSERT_EQ(streaming.read(next, 30000ms), ReadEnd::kMessage);
    if (next.has_chunk()) {
      ASSERT_EQ(next.chunk().offset(), bytes.size());
      bytes.insert(bytes.end(), next.chunk().data().begin(), next.chunk().data().end());
      continue;
    }
    ASSERT_TRUE(next.has_end()) << next.DebugString();
    end = next.end();
    break;
  }
  EXPECT_EQ(end.reason(), v1::StreamEnd::COMPLETE);
  EXPECT_EQ(bytes, stay);
  TestClient c = greeted_client(server.port());
  ASSERT_TRUE(c.stream("shape"));
  v1::ServerMessage m;
  ASSERT_EQ(c.read(m), ReadEnd::kMessage);
  EXPECT_EQ(m.error().code(), v1::Error::UNKNOWN_MODEL) << m.DebugString();
}

INSTANTIATE_TEST_SUITE_P(InotifyAndPolling, FolderWatch, ::testing::Values("auto", "poll"));

// ------------------------------------------------------- a corrupt file

TEST(ServeWhileEncoding, ACorruptFileDroppedInIsFailedWithItsReasonAndTheOthersServe) {
  const std::string work = fresh_dir("corrupt");
  const std::string models = fresh_dir("corrupt/models");
  const std::vector<uint8_t> good = server::make_synthetic_hcs({});
  write_file(models + "/good.hcs", good);
  ServerProcess server;
  ASSERT_TRUE(server.start({"--models", models, "--cache", "none"}, work + "/log.txt"))
      << server.log();

  // A stream cut short, and a PLY whose header lies.
  write_file(models + "/cut.hcs", std::vector<uint8_t>(good.begin(), good.begin() + 5000));
  write_text(models + "/lies.ply",
             "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
             "end_header\n0\n");
  bool met = false;
  const auto failed = [](const auto& m) { return m && m->state() == v1::ModelInfo::FAILED; };
  const auto cut = poll_model(server.port(), "cut", failed, 30s, &met);
  ASSERT_TRUE(met) << (cut ? cut->DebugString() : "not listed") << server.log();
  EXPECT_NE(cut->reason().find(models + "/cut.hcs"), std::string::npos) << cut->reason();
  if (server::mesh_encoding_available()) {
    const auto lies = poll_model(server.port(), "lies", failed, 30s, &met);
    ASSERT_TRUE(met) << (lies ? lies->DebugString() : "not listed") << server.log();
    EXPECT_NE(lies->reason().find(models + "/lies.ply"), std::string::npos) << lies->reason();
  }

  // The others keep serving; the failed one says why it cannot be.
  const StreamResult r = stream_model(server.port(), "good");
  ASSERT_TRUE(r.ok) << r.problem;
  EXPECT_EQ(r.bytes, good);
  TestClient c = greeted_client(server.port());
  ASSERT_TRUE(c.stream("cut"));
  v1::ServerMessage m;
  ASSERT_EQ(c.read(m), ReadEnd::kMessage);
  ASSERT_TRUE(m.has_error()) << m.DebugString();
  EXPECT_EQ(m.error().code(), v1::Error::MODEL_FAILED);
  EXPECT_NE(m.error().message().find("model 'cut' cannot be served: " + models + "/cut.hcs"),
            std::string::npos)
      << m.error().message();
  // And the client: exit 1 naming the reason, with --wait too (waiting
  // cannot help a failed model).
  const ClientRun run = run_client(
      {"127.0.0.1:" + std::to_string(server.port()), "cut", "--wait", "--no-asa", "--quiet"}, work,
      30);
  EXPECT_EQ(run.status, 1) << run.err;
  EXPECT_NE(run.err.find("cannot be served: " + models + "/cut.hcs"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("[MODEL_FAILED]"), std::string::npos) << run.err;
  // The text --list names the state and the reason.
  const ClientRun listed =
      run_client({"127.0.0.1:" + std::to_string(server.port()), "--list"}, work);
  ASSERT_EQ(listed.status, 0) << listed.err;
  EXPECT_NE(listed.out.find("failed: " + models + "/cut.hcs"), std::string::npos) << listed.out;
  EXPECT_NE(listed.out.find("ready"), std::string::npos) << listed.out;
}

}  // namespace
}  // namespace meshstream::nettest

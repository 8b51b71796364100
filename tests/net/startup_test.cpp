// How the real meshstream-server binary starts, or refuses to (issue 21 rows
// 3, 12 and 13; issue 15 point 5): it binds first, so an unusable address
// fails at once; it warns about every file in --models it cannot use and
// about two files that want the same name; a missing folder, a folder with
// nothing to serve under --watch off and a cache path whose parent is
// missing are bad input (exit 1, one line naming them); an empty folder is
// served and watched.
// Real sockets on loopback, real files in a temp folder.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <cstdlib>

#include "server/catalog.h"
#include "server/models_folder.h"
#include "server/synthetic_stream.h"
#include "tests/net/greeted_client.h"
#include "tests/net/net_harness.h"

namespace meshstream::nettest {
namespace {

namespace fs = std::filesystem;

fs::path temp_root() {
  return fs::temp_directory_path() / ("ms_startup_" + std::to_string(::getpid()));
}

class CleanupStartupDirs : public ::testing::Environment {
 public:
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(temp_root(), ec);
  }
};
const auto* const cleanup_registration =
    ::testing::AddGlobalTestEnvironment(new CleanupStartupDirs);

std::string fresh_dir(const std::string& name) {
  const fs::path dir = temp_root() / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir.string();
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// A tetrahedron, the smallest closed mesh the importer accepts.
const char* const kTetraOff =
    "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n"
    "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";

// The same tetrahedron as a binary STL.
void write_tetra_stl(const std::string& path) {
  const float v[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  const int faces[4][3] = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  std::vector<uint8_t> bytes(80, 0);
  auto put = [&](const void* data, size_t n) {
    const auto* p = static_cast<const uint8_t*>(data);
    bytes.insert(bytes.end(), p, p + n);
  };
  const uint32_t count = 4;
  put(&count, 4);
  for (const auto& f : faces) {
    const float normal[3] = {0, 0, 0};
    put(normal, 12);
    for (int corner : f) put(v[corner], 12);
    const uint16_t attributes = 0;
    put(&attributes, 2);
  }
  write_file(path, bytes);
}

struct Exit {
  int status = -1;  // exit code, or -1 when it did not exit by itself
  double seconds = 0;
  std::string err;  // its stderr
};

// Runs the server with `args` until it exits (killed after `limit`).
Exit run_to_exit(const std::vector<std::string>& args, const std::string& work, int limit_s = 20) {
  std::string cmd = "timeout -s KILL " + std::to_string(limit_s) + " " + server_binary();
  for (const std::string& a : args) cmd += " '" + a + "'";
  cmd += " > " + work + "/out.txt 2> " + work + "/err.txt";
  const auto start = Clock::now();
  const int raw = std::system(cmd.c_str());
  Exit out;
  out.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  if (WIFEXITED(raw) && WEXITSTATUS(raw) != 137) out.status = WEXITSTATUS(raw);
  const std::vector<uint8_t> err = read_file(work + "/err.txt");
  out.err.assign(err.begin(), err.end());
  return out;
}

// The lines of `text` that contain `needle`.
std::vector<std::string> lines_with(const std::string& text, const std::string& needle) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (line.find(needle) != std::string::npos) out.push_back(line);
  }
  return out;
}

// The one line of stderr that starts with the program's name (its verdict).
std::vector<std::string> verdicts(const std::string& err) {
  std::vector<std::string> out;
  for (const std::string& line : lines_with(err, "meshstream-server: ")) {
    if (line.rfind("meshstream-server: ", 0) == 0) out.push_back(line);
  }
  return out;
}

bool folder_is_empty(const std::string& dir) { return fs::is_empty(dir); }

// A listening socket on 127.0.0.1 that holds a port for the test.
class HeldPort {
 public:
  HeldPort() {
    fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 ||
        ::listen(fd_, 4) != 0) {
      return;
    }
    socklen_t len = sizeof addr;
    ::getsockname(fd_, reinterpret_cast<sockaddr*>(&addr), &len);
    port_ = ntohs(addr.sin_port);
  }
  ~HeldPort() { ::close(fd_); }
  uint16_t port() const { return port_; }

 private:
  int fd_ = -1;
  uint16_t port_ = 0;
};

// ------------------------------------------------------------ row 3: bind first

TEST(ServerStartup, PortInUseFailsWithinASecondBeforeEncodingAnything) {
  if (!server::mesh_encoding_available()) GTEST_SKIP() << "this build has no encoder";
  const std::string work = fresh_dir("port_in_use");
  const std::string models = fresh_dir("port_in_use/models");
  const std::string cache = fresh_dir("port_in_use/cache");
  write_text(models + "/tetra.off", kTetraOff);
  HeldPort held;
  ASSERT_NE(held.port(), 0);
  const std::string address = "127.0.0.1:" + std::to_string(held.port());
  const Exit e = run_to_exit({"--models", models, "--cache", cache, "--listen", address}, work);
  EXPECT_EQ(e.status, 1) << e.err;
  EXPECT_LT(e.seconds, 1.0) << e.err;
  const auto verdict = verdicts(e.err);
  ASSERT_EQ(verdict.size(), 1u) << e.err;
  EXPECT_EQ(verdict[0],
            "meshstream-server: cannot listen on " + address + ": Address already in use")
      << e.err;
  // Nothing was encoded: no progress line, nothing in the cache.
  EXPECT_TRUE(lines_with(e.err, "encoded").empty()) << e.err;
  EXPECT_TRUE(folder_is_empty(cache)) << "the mesh was encoded before the bind failed";
}

TEST(ServerStartup, AnAddressThatIsNotLocalFailsAtOnceNamingIt) {
  const std::string work = fresh_dir("not_local");
  const std::string models = fresh_dir("not_local/models");
  write_file(models + "/small.hcs", server::make_synthetic_hcs({}));
  // 192.0.2.1 (TEST-NET-1) is no address of this machine.
  const Exit e =
      run_to_exit({"--models", models, "--cache", "none", "--listen", "192.0.2.1:7878"}, work);
  EXPECT_EQ(e.status, 1) << e.err;
  EXPECT_LT(e.seconds, 1.0) << e.err;
  const auto verdict = verdicts(e.err);
  ASSERT_EQ(verdict.size(), 1u) << e.err;
  EXPECT_EQ(verdict[0],
            "meshstream-server: cannot listen on 192.0.2.1:7878: Cannot assign "
            "requested address");
  EXPECT_TRUE(lines_with(e.err, "serving small").empty()) << e.err;
}

// A host name is resolved, as a user who writes --listen localhost:7878
// expects (it used to be refused: "'localhost' is not an IP address"); a
// name that does not resolve fails at once, naming it.
TEST(ServerStartup, AHostNameIsResolvedAndABadOneNamed) {
  const std::string work = fresh_dir("host_name");
  const std::string models = fresh_dir("host_name/models");
  write_file(models + "/small.hcs", server::make_synthetic_hcs({}));
  ServerProcess server;
  ASSERT_TRUE(server.start({"--models", models, "--cache", "none", "--listen", "localhost:0"},
                           work + "/log.txt"))
      << server.log();
  TestClient client = greeted_client(server.port());  // 127.0.0.1: the name's IPv4 address

  const Exit e = run_to_exit(
      {"--models", models, "--cache", "none", "--listen", "no-such-host.invalid:7878"}, work);
  EXPECT_EQ(e.status, 1) << e.err;
  EXPECT_NE(e.err.find("--listen: cannot resolve 'no-such-host.invalid'"), std::string::npos)
      << e.err;
}

// ------------------------------------------- row 12: clashes and skipped files

TEST(ModelsFolderScan, NamesHcsFirstThenMeshesInFileOrderAndSaysWhyItSkips) {
  const std::string dir = fresh_dir("scan");
  for (const char* name :
       {"bunny.stl", "bunny.off", "bunny.hcs", "Dragon.PLY", "notes.txt", "README", "scene.fbx"}) {
    write_text(dir + "/" + name, "x");
  }
  fs::create_directories(dir + "/old");
  const auto scan = server::scan_models_folder(dir);
  ASSERT_TRUE(scan) << scan.error().message;
  ASSERT_EQ(scan->hcs.size(), 1u);
  EXPECT_EQ(scan->hcs[0].name, "bunny");
  ASSERT_EQ(scan->meshes.size(), 3u);
  // Byte order: "Dragon.PLY" < "bunny.off" < "bunny.stl".
  EXPECT_EQ(scan->meshes[0].name, "Dragon");
  EXPECT_EQ(scan->meshes[1].name, "bunny.off");
  EXPECT_EQ(scan->meshes[2].name, "bunny.stl");
  ASSERT_EQ(scan->clashes.size(), 1u);
  EXPECT_EQ(server::describe(scan->clashes[0]),
            "model name 'bunny' is claimed by 3 files: serving " + dir + "/bunny.hcs as 'bunny', " +
                dir + "/bunny.off as 'bunny.off', " + dir + "/bunny.stl as 'bunny.stl'");
  ASSERT_EQ(scan->skipped.size(), 4u);
  EXPECT_EQ(scan->skipped[0].path, dir + "/README");
  EXPECT_NE(scan->skipped[0].reason.find("no file extension"), std::string::npos);
  EXPECT_EQ(scan->skipped[1].path, dir + "/notes.txt");
  EXPECT_NE(scan->skipped[1].reason.find("'.txt' is not a model format"), std::string::npos);
  EXPECT_EQ(scan->skipped[2].path, dir + "/old");
  EXPECT_NE(scan->skipped[2].reason.find("a folder"), std::string::npos);
  EXPECT_EQ(scan->skipped[3].path, dir + "/scene.fbx");
  EXPECT_NE(scan->skipped[3].reason.find("'.fbx' is not a model format"), std::string::npos);
}

TEST(ModelsFolderScan, AFolderThatCannotBeListedIsAnError) {
  const auto scan = server::scan_models_folder(temp_root().string() + "/no/such/folder");
  ASSERT_FALSE(scan);
  EXPECT_NE(scan.error().message.find("cannot list"), std::string::npos);
}

TEST(ServerStartup, WarnsOnceAboutAClashAndOncePerSkippedFile) {
  if (!server::mesh_encoding_available()) GTEST_SKIP() << "this build has no encoder";
  const std::string work = fresh_dir("clash");
  const std::string models = fresh_dir("clash/models");
  write_text(models + "/bunny.off", kTetraOff);
  write_tetra_stl(models + "/bunny.stl");
  write_text(models + "/notes.txt", "my models\n");
  write_text(models + "/README", "read me\n");
  write_text(models + "/scene.fbx", "Kaydara FBX");
  ServerProcess server;
  ASSERT_TRUE(server.start({"--models", models, "--cache", "none"}, work + "/log.txt"))
      << server.log();
  TestClient c = greeted_client(server.port());
  ASSERT_TRUE(c.list());
  v1::ServerMessage m;
  ASSERT_EQ(c.read(m), ReadEnd::kMessage);
  ASSERT_EQ(m.model_list().models_size(), 2) << m.DebugString() << server.log();
  EXPECT_EQ(m.model_list().models(0).name(), "bunny");
  EXPECT_EQ(m.model_list().models(1).name(), "bunny.stl");
  const std::string log = server.log();
  const auto clash = lines_with(log, "claimed by");
  ASSERT_EQ(clash.size(), 1u) << log;
  EXPECT_NE(clash[0].find(" warning "), std::string::npos) << clash[0];
  EXPECT_NE(clash[0].find("model name 'bunny' is claimed by 2 files: serving " + models +
                          "/bunny.off as 'bunny', " + models + "/bunny.stl as 'bunny.stl'"),
            std::string::npos)
      << clash[0];
  for (const char* skipped : {"/notes.txt", "/README", "/scene.fbx"}) {
    const auto lines = lines_with(log, models + skipped);
    ASSERT_EQ(lines.size(), 1u) << skipped << "\n" << log;
    EXPECT_NE(lines[0].find(" warning catalog: skipped " + models + skipped + ": "),
              std::string::npos)
        << lines[0];
  }
}

// ------------------------------------------- row 13: folders that cannot serve

TEST(ServerStartup, MissingModelsFolderExitsOneWithAHint) {
  const std::string work = fresh_dir("missing");
  const std::string missing = work + "/no-such-folder";
  Exit e = run_to_exit({"--models", missing, "--cache", "none", "--listen", "127.0.0.1:0"}, work);
  EXPECT_EQ(e.status, 1) << e.err;
  ASSERT_EQ(verdicts(e.err).size(), 1u) << e.err;
  EXPECT_EQ(verdicts(e.err)[0], "meshstream-server: --models " + missing +
                                    ": no such folder (give the folder that holds your models, "
                                    "or --demo for the built-in ones)");

  // A file given as the folder.
  write_text(work + "/README", "x");
  e = run_to_exit({"--models", work + "/README", "--cache", "none"}, work);
  EXPECT_EQ(e.status, 1) << e.err;
  ASSERT_EQ(verdicts(e.err).size(), 1u) << e.err;
  EXPECT_NE(verdicts(e.err)[0].find("README: is not a folder"), std::string::npos) << e.err;
}

// Issue 15 point 5: the server listens whatever the folder holds, an empty
// one too (files will come: it watches it), with one warning.
TEST(ServerStartup, AnEmptyFolderIsServedAndWatched) {
  const std::string work = fresh_dir("empty_watched");
  const std::string empty = fresh_dir("empty_watched/models");
  ServerProcess server;
  ASSERT_TRUE(server.start({"--models", empty, "--cache", "none"}, work + "/log.txt"))
      << server.log();
  TestClient c = greeted_client(server.port());
  ASSERT_TRUE(c.list());
  v1::ServerMessage m;
  ASSERT_EQ(c.read(m), ReadEnd::kMessage);
  EXPECT_EQ(m.model_list().models_size(), 0) << m.DebugString();
  EXPECT_EQ(lines_with(server.log(), "warning catalog: no model in " + empty + " yet").size(), 1u)
      << server.log();
}

// With --watch off nothing new will come: a folder with nothing the server
// can serve is still bad input (exit 1, one line), after one warning per
// file it could not use.
TEST(ServerStartup, WatchOffAndNothingToServeExitsOneWithAHint) {
  const std::string work = fresh_dir("empty");
  const std::string empty = fresh_dir("empty/models");
  Exit e = run_to_exit(
      {"--models", empty, "--cache", "none", "--watch", "off", "--listen", "127.0.0.1:0"}, work);
  EXPECT_EQ(e.status, 1) << e.err;
  ASSERT_EQ(verdicts(e.err).size(), 1u) << e.err;
  EXPECT_EQ(verdicts(e.err)[0], "meshstream-server: no model to serve in " + empty +
                                    " (the server reads files ending in " +
                                    server::served_extensions() + "; add some, or --demo)");

  // Only files it cannot use: the same verdict, after one warning each.
  write_text(empty + "/README", "x");
  write_file(empty + "/broken.hcs", std::vector<uint8_t>{'M', 'H', 'C', 'S', 1, 0});
  e = run_to_exit(
      {"--models", empty, "--cache", "none", "--watch", "off", "--listen", "127.0.0.1:0"}, work);
  EXPECT_EQ(e.status, 1) << e.err;
  EXPECT_EQ(lines_with(e.err, "warning catalog: skipped " + empty + "/README").size(), 1u) << e.err;
  EXPECT_EQ(lines_with(e.err, "warning catalog: failed broken: " + empty + "/broken.hcs").size(),
            1u)
      << e.err;
  ASSERT_EQ(verdicts(e.err).size(), 1u) << e.err;
  EXPECT_NE(verdicts(e.err)[0].find("no model to serve in " + empty), std::string::npos);
}

TEST(ServerStartup, CacheCreatesOnlyItsLastLevelAndSaysSo) {
  const std::string work = fresh_dir("cache");
  const std::string models = fresh_dir("cache/models");
  write_file(models + "/small.hcs", server::make_synthetic_hcs({}));

  // Parent missing: refused, nothing created.
  const std::string deep = work + "/nonexistent/deep/x";
  Exit e = run_to_exit({"--models", models, "--cache", deep, "--listen", "127.0.0.1:0"}, work);
  EXPECT_EQ(e.status, 1) << e.err;
  ASSERT_EQ(verdicts(e.err).size(), 1u) << e.err;
  EXPECT_EQ(verdicts(e.err)[0], "meshstream-server: --cache " + deep + ": its parent folder " +
                                    work + "/nonexistent/deep does not exist (the server " +
                                    "creates only the last level of a cache path)");
  EXPECT_FALSE(fs::exists(work + "/nonexistent"));

  // A file where the folder should be.
  write_text(work + "/afile", "x");
  e = run_to_exit({"--models", models, "--cache", work + "/afile", "--listen", "127.0.0.1:0"},
                  work);
  EXPECT_EQ(e.status, 1) << e.err;
  ASSERT_EQ(verdicts(e.err).size(), 1u) << e.err;
  EXPECT_NE(verdicts(e.err)[0].find("afile exists and is not a folder"), std::string::npos);

  // Parent present: the last level is created, and the log says so.
  const std::string fresh = work + "/newcache";
  ServerProcess server;
  ASSERT_TRUE(server.start({"--models", models, "--cache", fresh}, work + "/log.txt"))
      << server.log();
  EXPECT_TRUE(fs::is_directory(fresh));
  EXPECT_EQ(lines_with(server.log(), "info created cache folder " + fresh).size(), 1u)
      << server.log();
  server.kill_now();
  // Second start: it exists, nothing to say.
  ServerProcess again;
  ASSERT_TRUE(again.start({"--models", models, "--cache", fresh}, work + "/log2.txt"))
      << again.log();
  EXPECT_TRUE(lines_with(again.log(), "created cache folder").empty()) << again.log();
}

}  // namespace
}  // namespace meshstream::nettest

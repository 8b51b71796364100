#include "server/server_options.h"

#include <CLI/CLI.hpp>
#include <cstdlib>
#include <iostream>

#include "common/cli/version.h"

namespace meshstream::server {
namespace {

std::string default_cache_dir() {
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) {
    return std::string(xdg) + "/meshstream";
  }
  if (const char* home = std::getenv("HOME"); home && *home) {
    return std::string(home) + "/.cache/meshstream";
  }
  return {};
}

// "HOST:PORT" with a numeric port; false when malformed.
bool split_listen(const std::string& text, std::string& host, uint16_t& port) {
  const auto colon = text.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 == text.size()) return false;
  host = text.substr(0, colon);
  if (host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
  const std::string digits = text.substr(colon + 1);
  if (digits.size() > 5 || digits.find_first_not_of("0123456789") != std::string::npos)
    return false;
  const unsigned long value = std::stoul(digits);
  if (value > 65535) return false;
  port = static_cast<uint16_t>(value);
  return true;
}

}  // namespace

ParsedOptions parse_server_options(int argc, char** argv) {
  ServerOptions o;
  CLI::App app{"meshstream-server: streams progressive meshes (.hcs) to meshstream clients"};
  std::string listen = "127.0.0.1:7878";
  std::string cache;
  uint64_t handshake_ms = o.handshake_timeout.count();
  uint64_t idle_ms = o.idle_timeout.count();
  uint64_t stall_ms = o.stall_timeout.count();
  uint64_t hold_ms = o.first_chunk_hold.count();
  cli::add_version_flag(app, "meshstream-server");
  app.add_option("--models", o.models_dir,
                 "folder of models: .hcs served as-is, PLY/OBJ/STL/DRC/OFF encoded in the "
                 "background; other files are skipped with a warning. Watched while the server "
                 "runs: files added, changed or removed are picked up within seconds");
  app.add_option("--listen", listen,
                 "address to listen on, HOST:PORT (port 0 = any free port); the server listens "
                 "at once and encodes while it serves")
      ->capture_default_str();
  app.add_option("--encoders", o.encoders,
                 "models encoded at once in the background (0 = one per core less one, at "
                 "least one)")
      ->capture_default_str()
      ->check(CLI::Range(0u, 256u));
  app.add_option("--watch", o.watch,
                 "how --models is watched: auto (inotify, polling every second where it is "
                 "missing), poll (every second; for network file systems), off (read once)")
      ->capture_default_str()
      ->check(CLI::IsMember({"auto", "poll", "off"}));
  app.add_flag("--demo", o.demo, "also serve the procedural demo models");
  app.add_option("--cache", cache,
                 "cache folder for encoded meshes (default $XDG_CACHE_HOME/meshstream or "
                 "~/.cache/meshstream; 'none' disables); only its last level is created");
  app.add_option("--max-connections", o.max_connections, "clients served at once; more get 'busy'")
      ->capture_default_str()
      ->check(CLI::Range(1u, 1000000u));
  app.add_option("--rate", o.rate_bytes_per_s, "pacing per connection in bytes/s (0 = unlimited)")
      ->capture_default_str();
  app.add_option("--threads", o.threads, "io threads (0 = one per core)")
      ->capture_default_str()
      ->check(CLI::Range(0u, 1024u));
  app.add_option("--handshake-timeout-ms", handshake_ms, "time a client has to send Hello")
      ->capture_default_str()
      ->check(CLI::Range(uint64_t(1), uint64_t(86400000)));
  app.add_option("--idle-timeout-ms", idle_ms, "close a connection silent this long with no stream")
      ->capture_default_str()
      ->check(CLI::Range(uint64_t(1), uint64_t(86400000)));
  app.add_option("--stall-timeout-ms", stall_ms,
                 "close a connection that has not read our bytes for this long")
      ->capture_default_str()
      ->check(CLI::Range(uint64_t(1), uint64_t(86400000)));
  app.add_option("--max-frame-bytes", o.max_frame_bytes, "largest client frame accepted")
      ->capture_default_str()
      ->check(CLI::Range(64u, 16u << 20));
  app.add_option("--max-chunk-bytes", o.max_chunk_bytes, "default chunk size in bytes")
      ->capture_default_str()
      ->check(CLI::Range(1024u, 1u << 20));
  app.add_option("--first-chunk-hold-ms", hold_ms,
                 "longest time streams in bulk transfer wait while new streams' first chunks "
                 "go out (0 = no wait)")
      ->capture_default_str()
      ->check(CLI::Range(uint64_t(0), uint64_t(10000)));
  std::string metrics;
  app.add_option("--metrics", metrics,
                 "serve /metrics (Prometheus text format) and /healthz over HTTP on HOST:PORT "
                 "(port 0 = any free port, printed as 'metrics on HOST:PORT'; default: off)");
  app.add_option("--log-level", o.log_level, "trace, debug, info, warn, error or off")
      ->capture_default_str()
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help
    std::cerr << "meshstream-server: " << e.what() << " (see --help)\n";
    return 2;
  }
  if (o.models_dir.empty() && !o.demo) {
    std::cerr << "meshstream-server: --models DIR is required (or --demo) (see --help)\n";
    return 2;
  }
  if (!split_listen(listen, o.listen_host, o.listen_port)) {
    std::cerr << "meshstream-server: --listen expects HOST:PORT, got '" << listen
              << "' (see --help)\n";
    return 2;
  }
  if (!metrics.empty() && !split_listen(metrics, o.metrics_host, o.metrics_port)) {
    std::cerr << "meshstream-server: --metrics expects HOST:PORT, got '" << metrics
              << "' (see --help)\n";
    return 2;
  }
  o.cache_dir = cache == "none" ? std::string() : cache.empty() ? default_cache_dir() : cache;
  o.cache_dir_is_default = cache.empty();
  o.handshake_timeout = std::chrono::milliseconds(handshake_ms);
  o.idle_timeout = std::chrono::milliseconds(idle_ms);
  o.stall_timeout = std::chrono::milliseconds(stall_ms);
  o.first_chunk_hold = std::chrono::milliseconds(hold_ms);
  return o;
}

}  // namespace meshstream::server

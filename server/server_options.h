// The `meshstream-server` command line (contract in docs/design.md) and
// the settings it turns into.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <variant>

#include "proto/framing.h"

namespace meshstream::server {

struct ServerOptions {
  std::string models_dir;  // --models DIR (may be empty with --demo)
  std::string listen_host = "127.0.0.1";
  uint16_t listen_port = 7878;  // 0 = any free port (printed on stdout)
  bool demo = false;
  std::string cache_dir;             // default: $XDG_CACHE_HOME/meshstream or ~/.cache/meshstream
  bool cache_dir_is_default = true;  // no --cache given (its parents may be created)
  uint32_t max_connections = 1024;   // extra clients get Error{BUSY}
  uint64_t rate_bytes_per_s = 0;     // per connection; 0 = unlimited
  unsigned threads = 0;              // io threads; 0 = one per core
  unsigned encoders = 0;             // background encoders; 0 = one per core less one, >= 1
  std::string watch = "auto";        // --models folder: auto (inotify, else polling), poll, off
  std::chrono::milliseconds handshake_timeout{5000};
  std::chrono::milliseconds idle_timeout{60000};
  std::chrono::milliseconds stall_timeout{30000};
  uint32_t max_frame_bytes = proto::kDefaultMaxClientFrameBytes;  // client frames
  uint32_t max_chunk_bytes = 64 * 1024;                           // default Chunk.data size
  // Longest time bulk chunks wait for a burst of new streams' first chunks
  // (FirstChunkGate); zero = no hold (bulk only steps back once per chunk).
  std::chrono::milliseconds first_chunk_hold{50};
  std::string log_level = "info";
  // --metrics HOST:PORT: /metrics and /healthz over HTTP (port 0 = any free
  // port, printed on stdout after the "listening on" line); empty = off.
  std::string metrics_host;
  uint16_t metrics_port = 0;
};

// Outcome of parsing: options to run with, or an exit code to return now
// (0 after --help, 2 after a usage error, with the message already printed).
using ParsedOptions = std::variant<ServerOptions, int>;

// Parses argv. Usage errors print one line "meshstream-server: <reason>
// (see --help)" to stderr. Whether --models and --cache name usable folders
// is checked by main (bad input, exit 1), not here.
ParsedOptions parse_server_options(int argc, char** argv);

}  // namespace meshstream::server

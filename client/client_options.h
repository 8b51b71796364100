// The `meshstream-client` command line (contract in docs/design.md;
// every flag in docs/usage.md):
//   meshstream-client HOST:PORT [MODEL] | http://HOST[:PORT]/PATH/MODEL.hcs [--list] [--out DIR
//   [--out-every N] [--out-format ply|glb]
//     [--out-at LIST] [--overwrite]] [--asa-levels L]
//     [--flatness T] [--rule zorin|projection] [--crease DEG] [--approximate] [--no-asa]
//     [--asa-complete]
//     [--camera EX,EY,EZ,TX,TY,TZ[,FOV]] [--pixel-tolerance PX] [--view-independent]
//     [--max-display-faces N]
//     [--bytes N | --vertices N | --percent P | --percent-bytes P] [--json] [--view]
//     [--snapshot FILE.png] [--width W --height H] [--snapshot-at N]
//     [--exit-after N] [--exit-after-records N] [--wait]
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "client/display_builder.h"
#include "client/http_response.h"
#include "client/stream_client.h"
#include "common/asa/subdivide.h"

namespace meshstream::client {

struct ClientOptions {
  std::string host;
  uint16_t port = 0;
  std::string model;            // empty with --list; the file name without .hcs for a URL
  std::optional<HttpUrl> http;  // set: stream the .hcs file at this URL from a web server
  bool list = false;
  std::string out_dir;           // --out: final.ply, final.decoded.ply (+ NNNN.ply)
  uint32_t out_every = 0;        // --out-every: NNNN.ply at every N-th record (0 = none)
  std::vector<uint32_t> out_at;  // --out-at: NNNN.ply at these records
  bool overwrite = false;        // --overwrite: reuse a folder of an earlier run
  // --out-format: the files' format and extension, "ply" (default) or "glb"
  // (one file each: attributes, materials and textures inside).
  std::string out_format = "ply";
  bool asa_enabled = true;  // --no-asa (--asa off) turns it off
  // --asa auto (the default): follow the stream's ASA guidance (guided_asa.h);
  // --asa on, or any of --asa-levels, --flatness, --rule, --crease: the
  // fixed settings in `asa`.
  bool asa_guided = true;
  bool asa_complete = false;  // --asa-complete: ASA on the complete mesh too
  // --approximate: relax the decoded positions before ASA (approximate.h)
  bool approximate = false;
  AsaOptions asa;                     // levels, flatness, rule, crease
  AsaPath asa_path = AsaPath::kAuto;  // --asa-path (benchmarks and tests)
  // View-dependent ASA (common/asa/view.h): refine for this camera (default:
  // the snapshot camera, the viewer's framing at --width x --height).
  std::optional<AsaCamera> camera;         // --camera
  float pixel_tolerance = 2;               // --pixel-tolerance
  bool view_independent = false;           // --view-independent: the whole mesh
  uint64_t max_display_faces = 4'000'000;  // --max-display-faces
  Budget budget;
  bool json = false;
  bool view = false;
  std::string snapshot_png;
  int width = 1024;
  int height = 768;
  std::optional<uint32_t> snapshot_at;  // record index (0 = base mesh)
  // True when record `index` is saved as NNNN.ply (--out-every, --out-at).
  bool saves_record(uint32_t index) const;
  // The name --out gives a file: STEM.ply or STEM.glb by --out-format.
  std::string out_file(const std::string& stem) const;
  uint64_t exit_after_frames = 0;
  uint32_t exit_after_records = 0;
  uint32_t max_chunk_bytes = 0;
  ReconnectPolicy reconnect;
  bool quiet = false;  // no progress line
  bool wait = false;   // --wait: a model still being encoded is waited for
};

// Options to run with, or the exit code to return now (0 after --help, 2
// after a usage error, with a one-line reason already printed to stderr).
using ParsedClientOptions = std::variant<ClientOptions, int>;
ParsedClientOptions parse_client_options(int argc, char** argv);

}  // namespace meshstream::client

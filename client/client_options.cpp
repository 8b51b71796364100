#include "client/client_options.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <iostream>

#include "common/asa/settings_check.h"
#include "common/cli/budget_options.h"
#include "common/cli/version.h"

namespace meshstream::client {

bool ClientOptions::saves_record(uint32_t index) const {
  if (out_every > 0 && index % out_every == 0) return true;
  return std::find(out_at.begin(), out_at.end(), index) != out_at.end();
}

std::string ClientOptions::out_file(const std::string& stem) const {
  return stem + "." + out_format;
}

namespace {

// Lower-case extension with its dot ("" when there is none).
std::string extension_of(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

}  // namespace

ParsedClientOptions parse_client_options(int argc, char** argv) {
  ClientOptions o;
  CLI::App app{
      "meshstream-client: stream a model from a meshstream server, decode every refinement "
      "as it arrives and post-process it with ASA"};
  std::string address, rule = "zorin", path = "auto";
  int reconnect_attempts = o.reconnect.max_attempts;
  cli::add_version_flag(app, "meshstream-client");
  app.add_option("address", address,
                 "server address HOST:PORT, or the URL http://HOST[:PORT]/PATH/MODEL.hcs of an "
                 ".hcs file on a web server (HTTP/1.1 range requests; no MODEL then)")
      ->required();
  app.add_option("model", o.model, "model name to stream (see --list)");
  app.add_flag("--list", o.list, "list the server's models and exit");
  app.add_option("--out", o.out_dir,
                 "write final.ply (the last display mesh) and final.decoded.ply into DIR, a new "
                 "or empty folder (see --overwrite; .glb instead with --out-format glb)");
  app.add_option("--out-format", o.out_format,
                 "with --out: ply (binary PLY with colours, normals and texture coordinates, seam "
                 "vertices split) or glb (binary glTF: attributes, materials and textures in one "
                 "file)")
      ->check(CLI::IsMember({"ply", "glb"}))
      ->capture_default_str();
  app.add_option("--out-every", o.out_every,
                 "with --out: also write NNNN.ply, the display mesh after record NNNN, for every "
                 "N-th record (0, N, 2N, ...), whatever the timing (default: none)")
      ->check(CLI::PositiveNumber);
  app.add_option("--out-at", o.out_at,
                 "with --out: also write NNNN.ply after each of these records (e.g. 0,10,50; "
                 "default: none)")
      ->delimiter(',');
  app.add_flag("--overwrite", o.overwrite,
               "let --out use a folder that is not empty: first delete the files this program "
               "writes there (NNNN.ply, final.ply, final.decoded.ply, or the same .glb), "
               "nothing else");
  std::string asa_mode = "auto";
  app.add_option("--asa", asa_mode,
                 "auto: the post-processing the stream's encoder measured closest to the "
                 "original for each part of the stream (none where none helped, and for streams "
                 "without guidance); on: ASA with --asa-levels, --flatness, --rule, --crease, "
                 "--approximate (any of them implies on); off: the decoded mesh (as --no-asa)")
      ->check(CLI::IsMember({"auto", "on", "off"}))
      ->capture_default_str();
  app.add_option("--asa-levels", o.asa.levels,
                 "ASA subdivision levels (0 = none); view-dependent ASA goes only as deep as the "
                 "screen asks, up to this")
      ->check(CLI::Range(0, 8))
      ->capture_default_str();
  app.add_option("--flatness", o.asa.flatness, "ASA flatness t: an edge is flat when t < N1.N2")
      ->check(CLI::Range(-1.0, 1.0))
      ->capture_default_str();
  app.add_option("--rule", rule, "Butterfly rule: zorin or projection")
      ->check(CLI::IsMember({"zorin", "projection"}))
      ->capture_default_str();
  app.add_option("--crease", o.asa.crease_degrees,
                 "edges bending more than DEG degrees stay sharp (0 = off; the picture then "
                 "keeps edges above 60 degrees sharp); with ASA, DEG below acos(--flatness) "
                 "(31.8 at t = 0.85) is refused: every edge ASA refines would stay sharp")
      ->check(CLI::Range(0.0, 180.0))
      ->capture_default_str();
  app.add_flag("--approximate", o.approximate,
               "approximating instead of interpolating: relax the decoded positions (Taubin "
               "lambda|mu along the normals; boundaries and edges bending more than --crease, or "
               "60 degrees, stay) before ASA, for coarse prefixes whose positions carry large "
               "errors; implies --asa on");
  bool no_asa = false;
  app.add_flag("--no-asa", no_asa, "show the decoded mesh without ASA");
  std::string camera_text;
  app.add_option("--camera", camera_text,
                 "EX,EY,EZ,TX,TY,TZ[,FOV_DEG]: refine for this camera (eye, target, vertical "
                 "field of view, default 45) at --width x --height, and render --snapshot with it "
                 "(default: the snapshot camera, the model framed as the viewer starts)");
  app.add_option("--pixel-tolerance", o.pixel_tolerance,
                 "view-dependent ASA refines an edge only where its projected size exceeds PX "
                 "pixels (and it is in view and not back-facing)")
      ->capture_default_str();
  app.add_flag("--view-independent", o.view_independent,
               "refine the whole decoded mesh whatever the camera sees (ASA as before the camera)");
  app.add_option("--max-display-faces", o.max_display_faces,
                 "never show more faces: above it, the update raises the pixel tolerance (the "
                 "refinement event says so)")
      ->capture_default_str();
  app.add_flag("--asa-complete", o.asa_complete,
               "apply ASA to the complete mesh too (default: once every record of the stream "
               "has arrived, the display, --snapshot and final.ply are the decoded mesh)");
  app.add_option("--asa-path", path, "auto, full or incremental (how ASA is recomputed per update)")
      ->check(CLI::IsMember({"auto", "full", "incremental"}))
      ->capture_default_str();
  // The rule of every program's budgets: common/cli/budget_options.h.
  cli::add_budget_options(app, o.budget,
                          {Budget::Kind::kBytes, Budget::Kind::kVertices,
                           Budget::Kind::kPercentVertices, Budget::Kind::kPercentBytes});
  app.add_flag("--json", o.json, "print one JSON event per line on stdout");
  app.add_flag("--view", o.view, "open a window that shows the model as it refines");
  app.add_option("--snapshot", o.snapshot_png,
                 "render the final (or --snapshot-at) display mesh to FILE.png (PNG only)");
  app.add_option("--width", o.width, "snapshot/window width")
      ->check(CLI::Range(16, 16384))
      ->capture_default_str();
  app.add_option("--height", o.height, "snapshot/window height")
      ->check(CLI::Range(16, 16384))
      ->capture_default_str();
  app.add_option("--snapshot-at", o.snapshot_at,
                 "snapshot the display mesh after record N (0 = base mesh; checked against the "
                 "stream's records when its header arrives)");
  app.add_option("--exit-after", o.exit_after_frames,
                 "close the window after N frames (0 = when the user closes it)")
      ->capture_default_str();
  app.add_option("--exit-after-records", o.exit_after_records,
                 "close the window once a frame with N decoded records is drawn (0 = off)")
      ->capture_default_str();
  app.add_option("--max-chunk-bytes", o.max_chunk_bytes,
                 "largest chunk to ask the server for (0 = the server's --max-chunk-bytes); "
                 "over http://, the bytes of one range request, rounded up to whole records "
                 "(0 = 262144)")
      ->capture_default_str();
  uint64_t read_timeout_ms = static_cast<uint64_t>(o.reconnect.read_timeout.count());
  app.add_option("--read-timeout", read_timeout_ms,
                 "milliseconds of silence after which a connection counts as lost (and is "
                 "resumed)")
      ->check(CLI::Range(uint64_t{100}, uint64_t{3600000}))
      ->capture_default_str();
  app.add_option("--reconnect-attempts", reconnect_attempts,
                 "consecutive reconnects before giving up")
      ->check(CLI::Range(0, 1000))
      ->capture_default_str();
  app.add_flag("--quiet", o.quiet, "no progress line");
  app.add_flag("--wait", o.wait,
               "a model the server is still encoding (NOT_READY) is asked for again every half "
               "second until it is ready, then streamed; without it the client exits 1");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) {
      app.exit(e);
      return 0;
    }
    std::cerr << "meshstream-client: " << e.what() << " (see --help)\n";
    return 2;
  }
  auto usage = [](const std::string& why) {
    std::cerr << "meshstream-client: " << why << " (see --help)\n";
    return 2;
  };
  if (looks_like_http_url(address)) {
    auto url = parse_http_url(address);
    if (!url) return usage(url.error().message);
    if (o.list) return usage("--list needs a meshstream server (HOST:PORT), not a URL");
    if (o.wait) return usage("--wait needs a meshstream server (HOST:PORT), not a URL");
    if (!o.model.empty())
      return usage("the URL names the model already: no MODEL after " + address);
    o.http = *url;
    o.host = url->host;
    o.port = url->port;
    o.model = url->model;
  } else {
    auto hp = parse_host_port(address);
    if (!hp) return usage(hp.error().message);
    o.host = hp->host;
    o.port = hp->port;
  }
  if (!o.list && o.model.empty()) return usage("name a MODEL to stream, or use --list");
  if (o.list && !o.model.empty()) return usage("--list takes no MODEL");
  if (o.list && o.wait) return usage("--wait is for streaming a MODEL, not --list");
  if (o.snapshot_at && o.snapshot_png.empty())
    return usage("--snapshot-at needs --snapshot FILE.png");
  if (!o.snapshot_png.empty() && extension_of(o.snapshot_png) != ".png") {
    const std::string ext = extension_of(o.snapshot_png);
    return usage("--snapshot " + o.snapshot_png +
                 ": only PNG is written, so the name must end in " +
                 (ext.empty() ? std::string(".png") : ".png, not " + ext));
  }
  if (o.out_dir.empty() &&
      (o.out_every || !o.out_at.empty() || o.overwrite || app.count("--out-format")))
    return usage("--out-every, --out-at, --out-format and --overwrite need --out DIR");
  if (!camera_text.empty()) {
    AsaCamera camera;
    if (auto parsed = parse_camera(camera_text, camera); !parsed)
      return usage(parsed.error().message);
    o.camera = camera;
  }
  if (!std::isfinite(o.pixel_tolerance) || o.pixel_tolerance <= 0)
    return usage("--pixel-tolerance " + app.get_option("--pixel-tolerance")->results().front() +
                 ": must be above 0 pixels");
  if (o.max_display_faces == 0) return usage("--max-display-faces 0: must be at least 1");
  if (o.view_independent && o.camera)
    return usage("--view-independent refines the whole mesh: it takes no --camera");
  if (o.camera) {
    o.camera->width = o.width;
    o.camera->height = o.height;
  }
  o.asa.rule = rule == "projection" ? ButterflyRule::kProjection : ButterflyRule::kZorin;
  const bool fixed_settings = app.count("--asa-levels") + app.count("--flatness") +
                                  app.count("--rule") + app.count("--crease") +
                                  app.count("--approximate") >
                              0;
  if (no_asa && app.count("--asa") && asa_mode != "off")
    return usage("--no-asa contradicts --asa " + asa_mode);
  if (asa_mode == "off" && fixed_settings)
    return usage("--asa off takes no --asa-levels, --flatness, --rule, --crease or --approximate");
  o.asa_enabled = !no_asa && asa_mode != "off";
  o.asa_guided = o.asa_enabled && asa_mode == "auto" && !fixed_settings;
  if (o.asa_enabled) {
    if (std::string clash = asa_settings_problem(o.asa, "--crease", "--flatness"); !clash.empty())
      return usage(clash);
  }
  o.asa_path = path == "full"          ? AsaPath::kFull
               : path == "incremental" ? AsaPath::kIncremental
                                       : AsaPath::kAuto;
  o.reconnect.max_attempts = reconnect_attempts;
  o.reconnect.read_timeout = Millis(read_timeout_ms);
  return o;
}

}  // namespace meshstream::client

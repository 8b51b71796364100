#include "client/client_options.h"

#include <CLI/CLI.hpp>
#include <iostream>

#include "common/cli/budget_options.h"
#include "common/cli/version.h"

namespace meshstream::client {

ParsedClientOptions parse_client_options(int argc, char** argv) {
  ClientOptions o;
  CLI::App app{
      "meshstream-client: stream a model from a meshstream server, decode every refinement "
      "as it arrives and post-process it with ASA"};
  std::string address, rule = "zorin", path = "auto";
  int reconnect_attempts = o.reconnect.max_attempts;
  cli::add_version_flag(app, "meshstream-client");
  app.add_option("address", address, "server address HOST:PORT")->required();
  app.add_option("model", o.model, "model name to stream (see --list)");
  app.add_flag("--list", o.list, "list the server's models and exit");
  app.add_option("--out", o.out_dir,
                 "write NNNN.ply per display update (NNNN = record index) and final.ply");
  app.add_option("--asa-levels", o.asa.levels, "ASA subdivision levels (0 = none)")
      ->check(CLI::Range(0, 8))
      ->capture_default_str();
  app.add_option("--flatness", o.asa.flatness, "ASA flatness t: an edge is flat when t < N1.N2")
      ->check(CLI::Range(-1.0, 1.0))
      ->capture_default_str();
  app.add_option("--rule", rule, "Butterfly rule: zorin or projection")
      ->check(CLI::IsMember({"zorin", "projection"}))
      ->capture_default_str();
  app.add_option("--crease", o.asa.crease_degrees,
                 "edges bending more than DEG degrees stay sharp (0 = off)")
      ->check(CLI::Range(0.0, 180.0))
      ->capture_default_str();
  bool no_asa = false;
  app.add_flag("--no-asa", no_asa, "show the decoded mesh without ASA");
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
                 "render the final (or --snapshot-at) display mesh to a PNG");
  app.add_option("--width", o.width, "snapshot/window width")
      ->check(CLI::Range(16, 16384))
      ->capture_default_str();
  app.add_option("--height", o.height, "snapshot/window height")
      ->check(CLI::Range(16, 16384))
      ->capture_default_str();
  app.add_option("--snapshot-at", o.snapshot_at,
                 "snapshot the display mesh after record N (0 = base mesh)");
  app.add_option("--exit-after", o.exit_after_frames, "close the window after N frames (tests)");
  app.add_option("--exit-after-records", o.exit_after_records,
                 "close the window once a frame with N decoded records is drawn (tests)");
  app.add_option("--max-chunk-bytes", o.max_chunk_bytes, "largest chunk to ask the server for");
  app.add_option("--reconnect-attempts", reconnect_attempts,
                 "consecutive reconnects before giving up")
      ->check(CLI::Range(0, 1000))
      ->capture_default_str();
  app.add_flag("--quiet", o.quiet, "no progress line");
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
  auto hp = parse_host_port(address);
  if (!hp) return usage(hp.error().message);
  o.host = hp->host;
  o.port = hp->port;
  if (!o.list && o.model.empty()) return usage("name a MODEL to stream, or use --list");
  if (o.list && !o.model.empty()) return usage("--list takes no MODEL");
  if (o.snapshot_at && o.snapshot_png.empty())
    return usage("--snapshot-at needs --snapshot FILE.png");
  o.asa.rule = rule == "projection" ? ButterflyRule::kProjection : ButterflyRule::kZorin;
  o.asa_enabled = !no_asa;
  o.asa_path = path == "full"          ? AsaPath::kFull
               : path == "incremental" ? AsaPath::kIncremental
                                       : AsaPath::kAuto;
  o.reconnect.max_attempts = reconnect_attempts;
  return o;
}

}  // namespace meshstream::client

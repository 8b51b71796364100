#include "client/client_app.h"

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <thread>

#include "client/decoded_stream.h"
#include "client/display_pipeline.h"
#include "client/event_log.h"
#include "client/stream_client.h"
#include "common/mesh/export.h"

namespace meshstream::client {

using Clock = std::chrono::steady_clock;

namespace {

int run_list(const ClientOptions& o) {
  auto models = list_models(o.host, o.port, o.reconnect.connect_timeout);
  if (!models) {
    EventLog(o.json, false).error(models.error().message);
    return 1;
  }
  if (o.json) {
    nlohmann::json list = nlohmann::json::array();
    for (const auto& m : *models) {
      list.push_back({{"name", m.name()},
                      {"vertices", m.vertices()},
                      {"faces", m.faces()},
                      {"stream_bytes", m.stream_bytes()},
                      {"records", m.records()},
                      {"source", m.source()}});
    }
    std::cout << nlohmann::json{{"event", "models"}, {"models", list}}.dump() << std::endl;
    return 0;
  }
  std::printf("%-24s %10s %10s %12s %8s  %s\n", "model", "vertices", "faces", "bytes", "records",
              "source");
  for (const auto& m : *models) {
    std::printf("%-24s %10u %10u %12llu %8u  %s\n", m.name().c_str(), m.vertices(), m.faces(),
                static_cast<unsigned long long>(m.stream_bytes()), m.records(), m.source().c_str());
  }
  return 0;
}

std::string record_file(const std::string& dir, uint32_t record) {
  char name[32];
  std::snprintf(name, sizeof name, "%04u.ply", record);
  return (std::filesystem::path(dir) / name).string();
}

}  // namespace

int run_client(const ClientOptions& o, const ViewerHooks& hooks) {
  if (o.list) return run_list(o);

  if (!o.out_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(o.out_dir, ec);
    if (ec) {
      std::cerr << "meshstream-client: cannot create " << o.out_dir << ": " << ec.message() << "\n";
      return 1;
    }
  }
  const bool progress = !o.json && !o.quiet && ::isatty(2);
  EventLog log(o.json, progress);

  StreamTarget target;
  target.host = o.host;
  target.port = o.port;
  target.model = o.model;
  target.budget = o.budget;
  target.max_chunk_bytes = o.max_chunk_bytes;
  target.reconnect = o.reconnect;

  DecodedStream decoded;
  decoded.set_barrier(o.snapshot_at);
  StreamClient client(target);
  client.on_retry([&](const Error& e, int attempt) { log.reconnecting(e, attempt); });
  LatestFrameMailbox mailbox;

  const auto t0 = Clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  };
  std::mutex file_mutex;
  std::optional<Error> file_error;  // first failure writing a file
  auto keep_error = [&](const Status& s) {
    if (s) return;
    std::lock_guard lock(file_mutex);
    if (!file_error) file_error = s.error();
  };
  uint32_t display_updates = 0, coalesced = 0;
  bool snapshot_done = false;
  std::optional<DisplayFrame> final_frame;
  // The newest frame shown: what the summary reports when the stream is
  // cancelled (window closed) before a final frame.
  std::optional<DisplayFrame> last_frame;

  PipelineSettings settings;
  settings.asa_enabled = o.asa_enabled;
  settings.asa = o.asa;
  settings.path = o.asa_path;
  // Runs on the pipeline thread after each published frame.
  auto observer = [&](const DisplayFrame& frame, const FrameInfo& info) {
    if (info.new_records) {
      last_frame = frame;
      ++display_updates;
      coalesced += frame.coalesced_updates;
      log.refinement(frame, info, elapsed(), client.rate_bytes_per_s());
      if (!o.out_dir.empty())
        keep_error(write_mesh(*frame.display, record_file(o.out_dir, frame.records_decoded - 1)));
      if (o.snapshot_at && !snapshot_done && frame.records_decoded == *o.snapshot_at + 1 &&
          hooks.snapshot) {
        keep_error(hooks.snapshot(*frame.display, frame.face_kind.get(), o, o.snapshot_png));
        snapshot_done = true;
      }
    }
    if (frame.final && !final_frame) {
      final_frame = frame;
      if (!o.out_dir.empty()) {
        keep_error(
            write_mesh(*frame.display, (std::filesystem::path(o.out_dir) / "final.ply").string()));
        keep_error(write_mesh(*frame.decoded,
                              (std::filesystem::path(o.out_dir) / "final.decoded.ply").string()));
      }
      if (!o.snapshot_png.empty() && !o.snapshot_at && hooks.snapshot) {
        keep_error(hooks.snapshot(*frame.display, frame.face_kind.get(), o, o.snapshot_png));
        snapshot_done = true;
      }
    }
  };
  DisplayPipeline pipeline(decoded, &client, mailbox, settings, observer);

  StreamFacts facts;
  std::thread network([&] {
    client.run(decoded, [&](const StreamFacts& f) {
      facts = f;
      pipeline.set_totals(f.total_bytes, f.records_total, f.end_record);
      log.header(f, elapsed());
    });
  });
  pipeline.start();

  Status viewer_status;
  if (o.view && hooks.run_view) {
    viewer_status = hooks.run_view(o, mailbox, pipeline);
    // The window closed: stop streaming if it still runs.
    client.stop();
    decoded.stop();
  }
  Status pipeline_status = pipeline.wait_finished();
  // The last record may be shown before the server's StreamEnd arrives:
  // let the network thread finish the conversation (it stops by itself).
  if (!pipeline_status) client.stop();
  network.join();
  pipeline.stop();
  mailbox.close();

  const std::optional<StreamOutcome> outcome = decoded.outcome();
  if (outcome && !outcome->ok) {
    log.error(outcome->error.message);
    return 1;
  }
  if (!pipeline_status) {
    log.error("post-processing failed: " + pipeline_status.error().message);
    return 1;
  }
  if (!viewer_status) {
    log.error("viewer: " + viewer_status.error().message);
    return 1;
  }
  if (file_error) {
    log.error(file_error->message);
    return 1;
  }
  if (o.snapshot_at && !snapshot_done) {
    log.error("--snapshot-at " + std::to_string(*o.snapshot_at) +
              ": the stream ended before that record");
    return 1;
  }
  DoneSummary s;
  s.model = o.model;
  s.reason = outcome ? outcome->reason : "cancelled";
  s.records_total = facts.records_total;
  s.bytes_total = facts.total_bytes;
  s.elapsed_ms = elapsed();
  s.reconnects = client.reconnects();
  s.display_updates = display_updates;
  s.coalesced = coalesced;
  if (const auto& shown = final_frame ? final_frame : last_frame) {
    s.records = shown->records_decoded;
    s.bytes = shown->bytes_received;
    s.vertices = shown->decoded->vertex_count();
    s.faces = shown->decoded->face_count();
    s.display_vertices = shown->display->vertex_count();
    s.display_faces = shown->display->face_count();
  }
  log.done(s);
  return 0;
}

}  // namespace meshstream::client

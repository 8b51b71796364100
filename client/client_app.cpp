#include "client/client_app.h"

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <regex>
#include <thread>

#include "client/decoded_stream.h"
#include "client/display_pipeline.h"
#include "client/event_log.h"
#include "client/interrupt_watch.h"
#include "client/stream_client.h"
#include "client/stream_source.h"
#include "common/mesh/export.h"
#include "common/mesh/import.h"

namespace meshstream::client {

using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

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
      nlohmann::json entry{{"name", m.name()},
                           {"vertices", m.vertices()},
                           {"faces", m.faces()},
                           {"stream_bytes", m.stream_bytes()},
                           {"records", m.records()},
                           {"source", m.source()},
                           {"state", model_state_name(m.state())}};
      if (m.state() == v1::ModelInfo::ENCODING) {
        entry["percent"] = m.percent();
        entry["stage"] = m.stage();
      }
      if (m.state() == v1::ModelInfo::FAILED) entry["reason"] = m.reason();
      list.push_back(std::move(entry));
    }
    std::cout << nlohmann::json{{"event", "models"}, {"models", list}}.dump() << std::endl;
    return 0;
  }
  std::printf("%-24s %10s %10s %12s %8s  %-6s  %s\n", "model", "vertices", "faces", "bytes",
              "records", "source", "state");
  for (const auto& m : *models) {
    std::string state = model_state_name(m.state());
    if (m.state() == v1::ModelInfo::ENCODING) {
      char percent[32];
      std::snprintf(percent, sizeof percent, " %.0f %%", m.percent());
      state += percent;
    }
    if (m.state() == v1::ModelInfo::FAILED) state += ": " + m.reason();
    std::printf("%-24s %10u %10u %12llu %8u  %-6s  %s\n", m.name().c_str(), m.vertices(), m.faces(),
                static_cast<unsigned long long>(m.stream_bytes()), m.records(), m.source().c_str(),
                state.c_str());
  }
  return 0;
}

std::string record_file(const ClientOptions& o, uint32_t record) {
  char stem[32];
  std::snprintf(stem, sizeof stem, "%04u", record);
  return (fs::path(o.out_dir) / o.out_file(stem)).string();
}

// The files --out writes: NNNN.ply (four digits or more), final.ply and
// final.decoded.ply, or the same names ending in .glb (an earlier run may
// have used the other --out-format). --overwrite deletes these and nothing
// else.
bool written_by_this_program(const std::string& name) {
  static const std::regex pattern(R"((\d{4,}|final|final\.decoded)\.(ply|glb))");
  return std::regex_match(name, pattern);
}

// --out DIR: created when missing; a folder with anything in it is refused
// (its old snapshots would sit beside the new ones) unless --overwrite,
// which first deletes what an earlier run of this program wrote there.
Status prepare_out_dir(const ClientOptions& o) {
  const fs::path dir(o.out_dir);
  std::error_code ec;
  if (!fs::exists(dir, ec)) {
    fs::create_directories(dir, ec);
    if (ec)
      return make_error(ErrorCode::kIo, "cannot create --out " + o.out_dir + ": " + ec.message());
    return {};
  }
  if (!fs::is_directory(dir, ec)) {
    return make_error(ErrorCode::kIo, "--out " + o.out_dir + " exists and is not a folder");
  }
  std::vector<std::string> entries;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    entries.push_back(entry.path().filename().string());
  }
  if (ec) return make_error(ErrorCode::kIo, "cannot list --out " + o.out_dir + ": " + ec.message());
  if (entries.empty()) return {};
  if (!o.overwrite) {
    return make_error(ErrorCode::kIo,
                      "--out " + o.out_dir + " is not empty (" + std::to_string(entries.size()) +
                          " entries, e.g. " + entries.front() +
                          "): use a new folder, or --overwrite to replace an earlier run's files");
  }
  for (const std::string& name : entries) {
    const fs::path path = dir / name;
    if (!written_by_this_program(name) || !fs::is_regular_file(path, ec)) continue;
    if (!fs::remove(path, ec) && ec) {
      return make_error(ErrorCode::kIo, "cannot delete " + path.string() + ": " + ec.message());
    }
  }
  return {};
}

// --snapshot FILE.png: its folder must exist and be writable, known before
// a single byte is streamed.
Status check_snapshot_folder(const ClientOptions& o) {
  fs::path folder = fs::path(o.snapshot_png).parent_path();
  if (folder.empty()) folder = ".";
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) {
    return make_error(ErrorCode::kIo, "--snapshot " + o.snapshot_png + ": the folder " +
                                          folder.string() + " does not exist");
  }
  if (::access(folder.c_str(), W_OK) != 0) {
    return make_error(ErrorCode::kIo, "--snapshot " + o.snapshot_png + ": the folder " +
                                          folder.string() + " is not writable");
  }
  return {};
}

// "--snapshot-at 5000": a record the stream (within the budget) does not have.
Status check_record_exists(const std::string& flag, uint32_t record, const StreamFacts& f) {
  if (record < f.end_record) return {};
  const std::string range = f.end_record == 0
                                ? "no records"
                                : "records 0 to " + std::to_string(f.end_record - 1) +
                                      (f.end_record < f.records_total ? " within the budget" : "");
  return make_error(ErrorCode::kInvalidArgument,
                    flag + " " + std::to_string(record) + ": model '" + f.model + "' has " + range);
}

// The viewer's error, with one "viewer:" prefix, and where to turn when
// there is no display to open a window on.
std::string viewer_failure(const Error& e) {
  std::string message = e.message.rfind("viewer: ", 0) == 0 ? e.message : "viewer: " + e.message;
  if (e.code == ErrorCode::kUnsupported && message.find("xvfb-run") == std::string::npos) {
    message +=
        "; without a display, render with --snapshot FILE.png, or run the window under xvfb-run";
  }
  return message;
}

// One streaming run: the network thread (StreamClient into DecodedStream),
// the display pipeline thread (ASA, events, files), the viewer or nothing
// on this thread; then the report.
class StreamingRun {
 public:
  StreamingRun(const ClientOptions& o, const ViewerHooks& hooks)
      : o_(o),
        hooks_(hooks),
        log_(o.json, !o.json && !o.quiet && ::isatty(2)),
        client_(make_stream_source(o)),
        pipeline_(
            decoded_, client_.get(), mailbox_, settings_of(o),
            [this](const DisplayFrame& frame, const FrameInfo& info) { on_frame(frame, info); }) {}

  // The phases: stream (until the end, an error, the window closing or
  // Ctrl-C), then report. The exit code.
  int run() {
    InterruptWatch interrupts([this](int) {
      interrupted_ = true;
      client_->stop();
      mailbox_.close();  // closes the window, if one is open
    });
    stream();
    interrupted_by_ = interrupts.signal();
    return report();
  }

 private:
  static PipelineSettings settings_of(const ClientOptions& o) {
    PipelineSettings settings;
    settings.asa_enabled = o.asa_enabled;
    settings.asa_on_complete = o.asa_complete;
    settings.asa_guided = o.asa_guided;
    settings.asa = o.asa;
    settings.approximate = o.approximate;
    settings.path = o.asa_path;
    settings.view.dependent = !o.view_independent;
    settings.view.camera = o.camera;
    settings.view.width = o.width;
    settings.view.height = o.height;
    settings.view.pixel_tolerance = o.pixel_tolerance;
    settings.view.max_display_faces = o.max_display_faces;
    settings.view.cull_for_renderer = o.view || !o.snapshot_png.empty();
    // Records that must each be shown (barriers, check_header) keep every
    // run of ASA; otherwise the final frame need not wait for a stale one.
    settings.drop_stale_asa_at_end = o.out_at.empty() && !o.snapshot_at && o.out_every == 0;
    return settings;
  }

  double elapsed() const {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0_).count();
  }

  // Network thread, first header, before any record: refuse records the
  // stream does not have, and set the records to be shown exactly.
  Status check_header(const StreamFacts& f) {
    if (o_.snapshot_at) {
      if (Status s = check_record_exists("--snapshot-at", *o_.snapshot_at, f); !s) return s;
    }
    for (uint32_t r : o_.out_at) {
      if (Status s = check_record_exists("--out-at", r, f); !s) return s;
    }
    std::vector<uint32_t> barriers = o_.out_at;
    if (o_.snapshot_at) barriers.push_back(*o_.snapshot_at);
    for (uint64_t r = 0; o_.out_every > 0 && r < f.end_record; r += o_.out_every) {
      barriers.push_back(static_cast<uint32_t>(r));
    }
    decoded_.set_barriers(std::move(barriers));
    return {};
  }

  void on_header(const StreamFacts& f) {
    facts_ = f;
    pipeline_.set_totals(f.total_bytes, f.records_total, f.end_record);
    log_.header(f, elapsed());
  }

  void keep_error(const Status& s) {
    if (s) return;
    std::lock_guard lock(file_mutex_);
    if (!file_error_) file_error_ = s.error();
  }

  // A display mesh to a file without the vertex slots no face uses (ASA's
  // incremental path keeps some, IncrementalSubdivider::result()).
  static Status write_display(const Mesh& display, const std::string& path) {
    Mesh compact = display;  // (writing costs more than the copy)
    drop_unreferenced(compact);
    return write_mesh(compact, path);
  }

  Status snapshot(const DisplayFrame& frame) const {
    const Mesh& drawn = frame.drawn ? *frame.drawn : *frame.display;
    const auto* kinds = frame.drawn ? frame.drawn_face_kind.get() : frame.face_kind.get();
    return hooks_.snapshot(drawn, kinds, *frame.display, frame.camera ? &*frame.camera : nullptr,
                           o_, o_.snapshot_png);
  }

  // Pipeline thread, after each published frame: events and files.
  void on_frame(const DisplayFrame& frame, const FrameInfo& info) {
    if (!info.guidance_warning.empty()) log_.note("warning: " + info.guidance_warning);
    if (!info.new_records && (info.rerun || info.rest_cull))
      log_.view_update(frame, info, elapsed());
    if (info.new_records) {
      last_frame_ = frame;
      ++display_updates_;
      coalesced_ += frame.coalesced_updates;
      log_.refinement(frame, info, elapsed(), client_->rate_bytes_per_s());
      const uint32_t record = frame.records_decoded - 1;
      if (!o_.out_dir.empty() && o_.saves_record(record))
        keep_error(write_display(*frame.display, record_file(o_, record)));
      if (o_.snapshot_at && !snapshot_done_ && record == *o_.snapshot_at && hooks_.snapshot) {
        keep_error(snapshot(frame));
        snapshot_done_ = true;
      }
    }
    if (frame.final && !final_frame_) {
      final_frame_ = frame;
      if (!o_.out_dir.empty()) {
        const fs::path dir(o_.out_dir);
        keep_error(write_display(*frame.display, (dir / o_.out_file("final")).string()));
        keep_error(write_mesh(*frame.decoded, (dir / o_.out_file("final.decoded")).string()));
        for (const std::string& lost : export_losses(*frame.display, o_.out_file("final")))
          log_.note("warning: " + o_.out_file("final") + ": not stored: " + lost);
      }
      if (!o_.snapshot_png.empty() && !o_.snapshot_at && hooks_.snapshot) {
        keep_error(snapshot(frame));
        snapshot_done_ = true;
      }
    }
  }

  void stream() {
    decoded_.on_record([this](const AppliedRecord& r) { log_.record(r, elapsed()); });
    client_->on_retry([this](const Error& e, int attempt) { log_.reconnecting(e, attempt); });
    client_->on_waiting([this](const v1::ModelInfo& m) { log_.waiting(m, elapsed()); });
    client_->check_header([this](const StreamFacts& f) { return check_header(f); });
    std::thread network(
        [this] { client_->run(decoded_, [this](const StreamFacts& f) { on_header(f); }); });
    pipeline_.start();
    if (o_.view && hooks_.run_view) {
      viewer_status_ = hooks_.run_view(o_, mailbox_, pipeline_);
      // The window closed: stop streaming if it still runs. After Ctrl-C the
      // pipeline still shows (and saves) what arrived.
      client_->stop();
      if (!interrupted_) decoded_.stop();
    }
    pipeline_status_ = pipeline_.wait_finished();
    // The last record may be shown before the server's StreamEnd arrives:
    // let the network thread finish the conversation (it stops by itself).
    if (!pipeline_status_) client_->stop();
    network.join();
    pipeline_.stop();
    mailbox_.close();
  }

  DoneSummary summary() const {
    const std::optional<StreamOutcome> outcome = decoded_.outcome();
    DoneSummary s;
    s.model = o_.model;
    s.reason = outcome ? outcome->reason : "cancelled";
    s.records_total = facts_.records_total;
    s.bytes_total = facts_.total_bytes;
    s.elapsed_ms = elapsed();
    s.reconnects = client_->reconnects();
    s.display_updates = display_updates_;
    s.coalesced = coalesced_;
    if (const auto& shown = final_frame_ ? final_frame_ : last_frame_) {
      s.records = shown->records_decoded;
      s.bytes = shown->bytes_received;
      s.vertices = shown->decoded->vertex_count();
      s.faces = shown->decoded->face_count();
      const Mesh& drawn = shown->drawn ? *shown->drawn : *shown->display;
      s.display_vertices = drawn_vertices(*shown);
      s.display_faces = drawn.face_count();
      s.whole_display_vertices = whole_display_vertices(*shown);
      s.whole_display_faces = shown->display->face_count();
    }
    return s;
  }

  // The first failure wins; a run ended by a signal exits 128 + signal.
  int report() {
    const std::optional<StreamOutcome> outcome = decoded_.outcome();
    if (outcome && !outcome->ok) {
      log_.error(outcome->error.message);
      return 1;
    }
    if (!pipeline_status_) {
      log_.error("post-processing failed: " + pipeline_status_.error().message);
      return 1;
    }
    if (!viewer_status_) {
      log_.error(viewer_failure(viewer_status_.error()));
      return 1;
    }
    if (file_error_) {
      log_.error(file_error_->message);
      return 1;
    }
    if (o_.snapshot_at && !snapshot_done_) {
      const std::string why = interrupted_by_ ? ": cancelled before that record"
                                              : ": the stream ended before that record";
      if (!interrupted_by_) {
        log_.error("--snapshot-at " + std::to_string(*o_.snapshot_at) + why);
        return 1;
      }
      log_.note("--snapshot-at " + std::to_string(*o_.snapshot_at) + why);
    }
    log_.done(summary());
    return interrupted_by_ ? 128 + interrupted_by_ : 0;
  }

  const ClientOptions& o_;
  const ViewerHooks& hooks_;
  const Clock::time_point t0_ = Clock::now();
  EventLog log_;
  DecodedStream decoded_;
  std::unique_ptr<StreamSource> client_;  // a meshstream server or a web server
  LatestFrameMailbox mailbox_;
  DisplayPipeline pipeline_;

  StreamFacts facts_;
  std::atomic<bool> interrupted_{false};  // set by the signal watcher
  int interrupted_by_ = 0;
  Status pipeline_status_, viewer_status_;
  std::mutex file_mutex_;
  std::optional<Error> file_error_;  // first failure writing a file
  // Pipeline thread only (read after it stopped):
  uint32_t display_updates_ = 0, coalesced_ = 0;
  bool snapshot_done_ = false;
  std::optional<DisplayFrame> final_frame_;
  // The newest frame shown: what the summary reports when the stream is
  // cancelled (window closed, Ctrl-C) before a final frame.
  std::optional<DisplayFrame> last_frame_;
};

}  // namespace

int run_client(const ClientOptions& o, const ViewerHooks& hooks) {
  if (o.list) return run_list(o);
  // What can be checked before connecting is checked before connecting.
  if (!o.out_dir.empty()) {
    if (Status s = prepare_out_dir(o); !s) {
      EventLog(o.json, false).error(s.error().message);
      return 1;
    }
  }
  if (!o.snapshot_png.empty()) {
    if (Status s = check_snapshot_folder(o); !s) {
      EventLog(o.json, false).error(s.error().message);
      return 1;
    }
  }
  return StreamingRun(o, hooks).run();
}

}  // namespace meshstream::client

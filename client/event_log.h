// What the client tells its user while streaming: JSON event lines on stdout
// (--json; contract in docs/design.md: header, a record event per
// decoded record, refinement per display update, done or error; the fields
// in docs/usage.md), or a progress line on a terminal. Thread-safe:
// the header comes from the network thread, refinements from the pipeline.
#pragma once

#include <cstdint>
#include <cstdio>
#include <mutex>
#include <string>

#include "client/display_frame.h"
#include "client/display_pipeline.h"
#include "client/stream_client.h"

namespace meshstream::client {

struct DoneSummary {
  std::string model;
  std::string reason;  // complete, budget, cancelled
  uint32_t records = 0, records_total = 0;
  uint64_t bytes = 0, bytes_total = 0;
  uint32_t vertices = 0, faces = 0, display_vertices = 0, display_faces = 0;
  uint32_t whole_display_vertices = 0, whole_display_faces = 0;  // display_* before the cull
  double elapsed_ms = 0;
  int reconnects = 0;
  uint32_t display_updates = 0;
  uint32_t coalesced = 0;  // decoder updates merged into later frames, in total
};

// "950 B", "12.3 kB", "1.25 MB": SI units (1 kB = 1000 bytes), the one
// spelling the client's progress line, summary and viewer panel use.
std::string human_bytes(double bytes);

class EventLog {
 public:
  // json: event lines on stdout; progress: a progress line on stderr
  // (meant for a terminal).
  EventLog(bool json, bool progress) : json_(json), progress_(progress) {}

  void header(const StreamFacts& facts, double elapsed_ms);
  void record(const AppliedRecord& record, double elapsed_ms);
  void refinement(const DisplayFrame& frame, const FrameInfo& info, double elapsed_ms, double rate);
  // A re-run of ASA without new records (camera or options changed), or
  // the cull owed since camera-only re-runs once the camera rests: a
  // "view" event with --json, nothing otherwise.
  void view_update(const DisplayFrame& frame, const FrameInfo& info, double elapsed_ms);
  void reconnecting(const Error& error, int attempt);
  // --wait: the model is not ready yet. One line (or `waiting` event) each
  // time its state or whole percent changes.
  void waiting(const v1::ModelInfo& model, double elapsed_ms);
  void done(const DoneSummary& summary);
  void error(const std::string& message);
  void note(const std::string& line);  // stderr, human readers only

 private:
  void line(const std::string& text);  // one stdout line, flushed
  void clear_progress();

  std::mutex mutex_;
  bool json_, progress_;
  bool progress_shown_ = false;
  std::string last_waiting_;  // the state last reported by waiting()
};

}  // namespace meshstream::client

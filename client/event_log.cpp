#include "client/event_log.h"

#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>

namespace meshstream::client {

namespace {

double round3(double x) { return std::round(x * 1000.0) / 1000.0; }

// pixel_tolerance: the one used (null when ASA refines the whole mesh or
// is off); budget_limited: --max-display-faces raised it (or cut levels).
void add_view_fields(nlohmann::json& j, const DisplayFrame& fr) {
  if (fr.pixel_tolerance > 0)
    j["pixel_tolerance"] = round3(fr.pixel_tolerance);
  else
    j["pixel_tolerance"] = nullptr;
  j["budget_limited"] = fr.budget_limited;
}

}  // namespace

std::string human_bytes(double b) {
  char buf[32];
  if (b >= 1e6)
    std::snprintf(buf, sizeof buf, "%.2f MB", b / 1e6);
  else if (b >= 1e3)
    std::snprintf(buf, sizeof buf, "%.1f kB", b / 1e3);
  else
    std::snprintf(buf, sizeof buf, "%.0f B", b);
  return buf;
}

void EventLog::line(const std::string& text) {
  std::fwrite(text.data(), 1, text.size(), stdout);
  std::fputc('\n', stdout);
  std::fflush(stdout);
}

void EventLog::clear_progress() {
  if (progress_shown_) {
    std::fputs("\r\033[K", stderr);
    progress_shown_ = false;
  }
}

void EventLog::header(const StreamFacts& f, double elapsed_ms) {
  std::lock_guard lock(mutex_);
  if (!json_) return;
  nlohmann::json j{{"event", "header"},
                   {"model", f.model},
                   {"total_bytes", f.total_bytes},
                   {"records", f.records_total},
                   {"vertices", f.vertices},
                   {"faces", f.faces},
                   {"base_vertices", f.base_vertices},
                   {"base_faces", f.base_faces},
                   {"quant_bits", f.quant_bits},
                   {"start_offset", f.start_offset},
                   {"end_offset", f.end_offset},
                   {"end_record", f.end_record},
                   {"elapsed_ms", round3(elapsed_ms)}};
  line(j.dump());
}

void EventLog::record(const AppliedRecord& r, double elapsed_ms) {
  std::lock_guard lock(mutex_);
  if (!json_) return;
  nlohmann::json j{{"event", "record"},
                   {"index", r.index},
                   {"bytes", r.end_offset},
                   {"record_bytes", r.bytes},
                   {"vertices", r.vertices},
                   {"faces", r.faces},
                   {"decode_ms", round3(r.decode_ms)},
                   {"elapsed_ms", round3(elapsed_ms)}};
  line(j.dump());
}

namespace {
// What the renderer is handed (the culled display in view-dependent mode).
const Mesh& drawn_of(const DisplayFrame& fr) { return fr.drawn ? *fr.drawn : *fr.display; }
}  // namespace

void EventLog::refinement(const DisplayFrame& fr, const FrameInfo& info, double elapsed_ms,
                          double rate) {
  std::lock_guard lock(mutex_);
  if (json_) {
    nlohmann::json j{{"event", "refinement"},
                     {"index", fr.records_decoded - 1},
                     {"bytes", fr.bytes_received},
                     {"vertices", fr.decoded->vertex_count()},
                     {"faces", fr.decoded->face_count()},
                     {"display_vertices", drawn_vertices(fr)},
                     {"display_faces", drawn_of(fr).face_count()},
                     {"cull_ms", round3(fr.cull_ms)},
                     {"whole_display_vertices", whole_display_vertices(fr)},
                     {"whole_display_faces", fr.display->face_count()},
                     {"decode_ms", round3(fr.decode_ms)},
                     {"asa_ms", round3(fr.asa_ms)},
                     {"elapsed_ms", round3(elapsed_ms)},
                     {"coalesced", fr.coalesced_updates},
                     {"asa_path", info.build.incremental ? "incremental" : "full"},
                     {"final", fr.final}};
    add_view_fields(j, fr);
    if (!info.asa_guided.empty()) j["asa"] = info.asa_guided;
    line(j.dump());
    return;
  }
  if (!progress_) return;
  const double pct =
      fr.bytes_total ? 100.0 * double(fr.bytes_received) / double(fr.bytes_total) : 0;
  std::fprintf(stderr, "\r\033[K%s / %s (%.0f%%)  records %u/%u  vertices %u (display %u)  %s/s",
               human_bytes(double(fr.bytes_received)).c_str(),
               human_bytes(double(fr.bytes_total)).c_str(), pct, fr.records_decoded,
               fr.records_total, fr.decoded->vertex_count(), whole_display_vertices(fr),
               human_bytes(rate).c_str());
  std::fflush(stderr);
  progress_shown_ = true;
}

void EventLog::view_update(const DisplayFrame& fr, const FrameInfo& info, double elapsed_ms) {
  std::lock_guard lock(mutex_);
  if (!json_) return;
  nlohmann::json j{{"event", "view"},
                   {"display_vertices", drawn_vertices(fr)},
                   {"display_faces", drawn_of(fr).face_count()},
                   {"cull_ms", round3(fr.cull_ms)},
                   {"whole_display_vertices", whole_display_vertices(fr)},
                   {"whole_display_faces", fr.display->face_count()},
                   {"asa_ms", round3(fr.asa_ms)},
                   {"region_faces", info.build.region_faces},
                   {"asa_path", info.rest_cull           ? "none"
                                : info.build.incremental ? "incremental"
                                                         : "full"},
                   {"elapsed_ms", round3(elapsed_ms)}};
  add_view_fields(j, fr);
  line(j.dump());
}

void EventLog::reconnecting(const Error& error, int attempt) {
  std::lock_guard lock(mutex_);
  clear_progress();
  std::fprintf(stderr, "meshstream-client: %s; reconnecting (attempt %d)\n", error.message.c_str(),
               attempt);
  std::fflush(stderr);
}

void EventLog::waiting(const v1::ModelInfo& model, double elapsed_ms) {
  std::lock_guard lock(mutex_);
  const std::string state = model_state_name(model.state());
  char percent[32];
  std::snprintf(percent, sizeof percent, "%.0f %%", model.percent());
  std::string text = state;
  if (model.state() == v1::ModelInfo::ENCODING) {
    text += std::string(", ") + percent + (model.stage().empty() ? "" : " (" + model.stage() + ")");
  }
  if (text == last_waiting_) return;
  last_waiting_ = text;
  if (json_) {
    nlohmann::json j{{"event", "waiting"},     {"model", model.name()},
                     {"state", state},         {"percent", round3(model.percent())},
                     {"stage", model.stage()}, {"elapsed_ms", round3(elapsed_ms)}};
    line(j.dump());
    return;
  }
  clear_progress();
  std::fprintf(stderr, "meshstream-client: waiting for '%s': %s\n", model.name().c_str(),
               text.c_str());
  std::fflush(stderr);
}

void EventLog::done(const DoneSummary& s) {
  std::lock_guard lock(mutex_);
  if (json_) {
    nlohmann::json j{{"event", "done"},
                     {"model", s.model},
                     {"reason", s.reason},
                     {"records", s.records},
                     {"records_total", s.records_total},
                     {"bytes", s.bytes},
                     {"total_bytes", s.bytes_total},
                     {"vertices", s.vertices},
                     {"faces", s.faces},
                     {"display_vertices", s.display_vertices},
                     {"display_faces", s.display_faces},
                     {"whole_display_vertices", s.whole_display_vertices},
                     {"whole_display_faces", s.whole_display_faces},
                     {"elapsed_ms", round3(s.elapsed_ms)},
                     {"reconnects", s.reconnects},
                     {"display_updates", s.display_updates},
                     {"coalesced", s.coalesced}};
    line(j.dump());
    return;
  }
  clear_progress();
  char buf[512];
  std::snprintf(
      buf, sizeof buf,
      "%s: %u/%u records, %s of %s (%s), %u vertices, %u faces; display %u vertices, %u faces; "
      "%.1f ms, %u display updates (%u updates coalesced), %d reconnects",
      s.model.c_str(), s.records, s.records_total, human_bytes(double(s.bytes)).c_str(),
      human_bytes(double(s.bytes_total)).c_str(), s.reason.c_str(), s.vertices, s.faces,
      s.display_vertices, s.display_faces, s.elapsed_ms, s.display_updates, s.coalesced,
      s.reconnects);
  line(buf);
}

void EventLog::error(const std::string& message) {
  std::lock_guard lock(mutex_);
  clear_progress();
  if (json_) line(nlohmann::json{{"event", "error"}, {"message", message}}.dump());
  std::fprintf(stderr, "meshstream-client: %s\n", message.c_str());
  std::fflush(stderr);
}

void EventLog::note(const std::string& text) {
  std::lock_guard lock(mutex_);
  clear_progress();
  std::fprintf(stderr, "meshstream-client: %s\n", text.c_str());
  std::fflush(stderr);
}

}  // namespace meshstream::client

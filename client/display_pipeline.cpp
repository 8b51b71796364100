#include "client/display_pipeline.h"

#include <chrono>

namespace meshstream::client {

using Clock = std::chrono::steady_clock;

DisplayPipeline::DisplayPipeline(DecodedStream& decoded, StreamSource* client,
                                 LatestFrameMailbox& mailbox, PipelineSettings settings,
                                 FrameObserver observer)
    : decoded_(decoded),
      client_(client),
      mailbox_(mailbox),
      observer_(std::move(observer)),
      settings_(std::move(settings)) {
  builder_.set_path(settings_.path);
}

DisplayPipeline::~DisplayPipeline() { stop(); }

void DisplayPipeline::start() {
  thread_ = std::thread([this] { loop(); });
}

void DisplayPipeline::stop() {
  decoded_.stop();
  if (thread_.joinable()) thread_.join();
  mark_finished(std::nullopt);
}

Status DisplayPipeline::wait_finished() {
  std::unique_lock lock(mutex_);
  finished_changed_.wait(lock, [&] { return finished_; });
  if (error_) return tl::unexpected(*error_);
  return {};
}

void DisplayPipeline::set_totals(uint64_t bytes_total, uint32_t records_total,
                                 uint32_t end_record) {
  std::lock_guard lock(mutex_);
  bytes_total_ = bytes_total;
  records_total_ = records_total;
  end_record_ = end_record;
}

void DisplayPipeline::mark_finished(std::optional<Error> error) {
  {
    std::lock_guard lock(mutex_);
    if (finished_) return;
    finished_ = true;
    error_ = std::move(error);
  }
  finished_changed_.notify_all();
}

void DisplayPipeline::publish(DisplayFrame frame, const FrameInfo& info) {
  frame.sequence = ++sequence_;
  if (observer_) observer_(frame, info);
  mailbox_.publish(std::move(frame));
}

void DisplayPipeline::loop() {
  const auto started = Clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double, std::milli>(Clock::now() - started).count();
  };
  Mesh mirror;
  MeshChanges changes;
  uint64_t seen_pokes = 0;
  bool outcome_seen = false;
  std::optional<DisplayFrame> last;  // the newest published frame
  while (decoded_.wait(seen_pokes, outcome_seen, std::chrono::milliseconds(200))) {
    const uint64_t pokes = decoded_.pokes();
    const bool rerun = pokes != seen_pokes;
    seen_pokes = pokes;
    PipelineSettings settings;
    uint64_t bytes_total;
    uint32_t records_total, end_record;
    {
      std::lock_guard lock(mutex_);
      settings = settings_;
      bytes_total = bytes_total_;
      records_total = records_total_;
      end_record = end_record_;
    }
    const bool pending = decoded_.has_pending();
    if (!pending && !(rerun && last) && (outcome_seen || !decoded_.outcome())) continue;

    if (!pending && !(rerun && last)) {
      // The stream ended with nothing new: the last frame is the final one.
      outcome_seen = true;
      const StreamOutcome outcome = *decoded_.outcome();
      if (!outcome.ok) {
        mark_finished(std::nullopt);  // the stream's error is reported by its owner
        continue;
      }
      if (last && !last->final) {
        DisplayFrame frame = *last;
        frame.final = true;
        frame.coalesced_updates = 0;
        FrameInfo info;
        info.elapsed_ms = elapsed();
        publish(frame, info);
        last = frame;
      }
      mark_finished(std::nullopt);
      continue;
    }

    DisplayFrame frame;
    FrameInfo info;
    if (pending) {
      const TakenUpdate u = decoded_.take(mirror, changes);
      frame.records_decoded = u.records_decoded;
      frame.bytes_received = u.bytes_decoded;
      frame.decode_ms = u.decode_ms;
      frame.coalesced_updates = u.updates > 0 ? u.updates - 1 : 0;
      // Final once the last record the server will send is in (the end
      // frame itself may still be on its way), or the stream ended well.
      frame.final =
          (end_record > 0 && u.records_decoded >= end_record) ||
          (u.ended && decoded_.outcome() && decoded_.outcome()->ok && !decoded_.has_pending());
      info.new_records = true;
      frame.decoded = std::make_shared<const Mesh>(mirror);
    } else {
      frame = *last;
      frame.decode_ms = 0;
      frame.coalesced_updates = 0;
    }
    info.rerun = rerun;
    frame.records_total = records_total;
    frame.bytes_total = bytes_total;
    // Nothing is missing once every record is in: show the decoded mesh.
    const bool complete = records_total > 0 && frame.records_decoded >= records_total;
    const bool asa_now = settings.asa_enabled && (!complete || settings.asa_on_complete);
    auto display =
        builder_.build(frame.decoded, changes, asa_now, settings.asa, rerun || !last, info.build);
    changes.clear();
    if (!display) {
      decoded_.stop();
      if (client_) client_->stop();
      mark_finished(display.error());
      break;
    }
    frame.display = display->mesh;
    frame.face_kind = display->face_kind;
    frame.asa_ms = info.build.asa_ms;
    info.elapsed_ms = elapsed();
    publish(frame, info);
    last = frame;
    if (frame.final) {
      outcome_seen = true;
      mark_finished(std::nullopt);
    }
  }
  mark_finished(std::nullopt);  // stopped
}

void DisplayPipeline::set_asa(bool asa_enabled, const AsaOptions& options) {
  {
    std::lock_guard lock(mutex_);
    settings_.asa_enabled = asa_enabled;
    settings_.asa = options;
    // A change made while streaming (the viewer's panel) is an explicit
    // request: it applies to the complete mesh too.
    settings_.asa_on_complete = true;
  }
  decoded_.poke();
}

AsaOptions DisplayPipeline::asa_options() const {
  std::lock_guard lock(mutex_);
  return settings_.asa;
}

bool DisplayPipeline::asa_enabled() const {
  std::lock_guard lock(mutex_);
  return settings_.asa_enabled;
}

void DisplayPipeline::pause() {
  if (client_) client_->pause();
}
void DisplayPipeline::resume() {
  if (client_) client_->resume();
}
bool DisplayPipeline::paused() const { return client_ && client_->paused(); }
double DisplayPipeline::current_rate_bytes_per_s() const {
  return client_ ? client_->rate_bytes_per_s() : 0;
}

}  // namespace meshstream::client

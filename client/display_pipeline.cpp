#include "client/display_pipeline.h"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>

#include "client/frame_mesh_pool.h"
#include "common/asa/approximate.h"

namespace meshstream::client {

using Clock = std::chrono::steady_clock;

namespace {

// What the view options need of one decoded mesh, each O(V) or O(F): the
// snapshot camera fitted on it and its facing sign.
struct MeshViewFacts {
  std::shared_ptr<const Mesh> mesh;
  std::optional<AsaCamera> fit;
  float facing_sign = 0;  // 0: not computed yet (else +1 or -1)
};

// The camera and tolerance of this update into the ASA options. The
// snapshot camera is fitted on this very mesh, so the display of a record
// does not depend on which updates were merged before it (--out files are
// the same on any link); it is snapped (fit_camera) so that records that
// barely move the framing do not move the camera. O(V + F): the fit and
// the facing sign.
// `facts` keeps both for the mesh they were computed on: a re-run without
// new records (the viewer's camera moved, the tolerance changed) reuses
// them instead of two more passes over a mesh that did not change.
// Without ASA and without a renderer (--no-asa with no --view or
// --snapshot) nothing reads the camera: `need_camera` false leaves it
// unset and skips the fit, four passes over every vertex per update (a
// third of the client's time on dragon_x2).
AsaOptions options_with_view(const PipelineSettings& settings,
                             const std::shared_ptr<const Mesh>& decoded, MeshViewFacts& facts,
                             bool need_camera, std::optional<AsaCamera>& camera) {
  if (facts.mesh != decoded) {
    facts.mesh = decoded;
    facts.fit.reset();
    facts.facing_sign = 0;
  }
  if (settings.view.camera) {
    camera = *settings.view.camera;
  } else if (!need_camera) {
    camera.reset();
    AsaOptions options = settings.asa;
    options.view.enabled = settings.view.dependent;
    options.view.pixel_tolerance = settings.view.pixel_tolerance;
    return options;
  } else {
    if (!facts.fit || facts.fit->width != settings.view.width ||
        facts.fit->height != settings.view.height)
      facts.fit = fit_camera(*decoded, settings.view.width, settings.view.height, /*snap=*/true);
    camera = *facts.fit;
  }
  AsaOptions options = settings.asa;
  options.view.enabled = settings.view.dependent;
  options.view.camera = *camera;
  options.view.pixel_tolerance = settings.view.pixel_tolerance;
  if (options.view.enabled && settings.asa_enabled) {
    if (facts.facing_sign == 0) facts.facing_sign = facing_sign_of(*decoded);
    options.view.facing_sign = facts.facing_sign;
  }
  return options;
}

// The topologies of the newest ASA input and display mesh (held, so a
// pool cannot reuse them while they are cached): camera moves on an
// unchanged decoded mesh analyse it once, and a re-run that shows the same
// display (the complete mesh without ASA) reuses all of it.
struct TopologyCache {
  std::shared_ptr<const Mesh> source_mesh, display_mesh;
  std::shared_ptr<const SourceTopology> source;
  std::shared_ptr<const DisplayTopology> display;
};

// View-dependent mode: the renderer gets the faces the frame's camera can
// see (display_cull.h); else the display mesh itself. `source`: the mesh
// ASA refined (its vertices are the display's first ones). O(V + F) of the
// display mesh, plus O(V + F) of the source when it changed.
void cull_for_renderer(DisplayFrame& frame, const std::shared_ptr<const Mesh>& source, bool cull,
                       TopologyCache& cache) {
  frame.drawn = frame.display;
  frame.drawn_face_kind = frame.face_kind;
  frame.cull = {};
  frame.topology.reset();
  if (!cull || !frame.camera || !frame.display || !source) return;
  if (cache.source_mesh != source) {
    cache.source_mesh = source;
    cache.source = analyze_source_topology(*source);
    cache.display_mesh.reset();
  }
  if (cache.display_mesh != frame.display) {
    cache.display_mesh = frame.display;
    cache.display = analyze_display_topology(*frame.display, *cache.source);
  }
  CulledDisplay culled =
      cull_display(frame.display, frame.face_kind, *cache.display, *frame.camera);
  frame.drawn = std::move(culled.mesh);
  frame.drawn_face_kind = std::move(culled.face_kind);
  frame.cull = culled.region;
  frame.topology = cache.display;
}

// Times cull_for_renderer into frame.cull_ms (0 when it culled nothing).
void timed_cull_for_renderer(DisplayFrame& frame, const std::shared_ptr<const Mesh>& source,
                             bool cull, TopologyCache& cache) {
  const auto start = Clock::now();
  cull_for_renderer(frame, source, cull, cache);
  frame.cull_ms =
      frame.topology ? std::chrono::duration<double, std::milli>(Clock::now() - start).count() : 0;
}

// The whole display as what the renderer draws, for any camera (a
// camera-only re-run: the cull is owed until the camera rests).
void draw_whole_display(DisplayFrame& frame) {
  frame.drawn = frame.display;
  frame.drawn_face_kind = frame.face_kind;
  frame.cull = {};
  frame.topology.reset();
  frame.cull_ms = 0;
}

// While the viewer's camera moves, each re-run's display is drawn whole:
// the window leaves a cull's region within a frame of an orbit (its eye
// margin is 0.6 degrees) and then draws the whole display anyway, so a
// cull per re-run would cost O(V + F) on this thread for nothing. The
// camera rests when no new camera came for twice the time between the last
// two camera re-runs (a slow renderer, llvmpipe under Xvfb, sends them
// seconds apart: an orbit there must not count as resting at every frame),
// at least kRestMin and at most kRestMax (a gap longer than that starts a
// new move).
struct OwedCull {
  static constexpr Clock::duration kRestMin = std::chrono::milliseconds(200);
  static constexpr Clock::duration kRestMax = std::chrono::seconds(10);
  bool owed = false;
  std::shared_ptr<const Mesh> source;  // the mesh ASA refined for the owed frame
  std::optional<Clock::time_point> last_rerun;
  Clock::duration interval{};  // between the last two camera-only re-runs; 0: none

  void camera_rerun(const std::shared_ptr<const Mesh>& refined) {
    const auto now = Clock::now();
    interval = last_rerun && now - *last_rerun <= kRestMax ? now - *last_rerun : Clock::duration{};
    last_rerun = now;
    source = refined;
    owed = true;
  }
  void paid() {
    owed = false;
    source.reset();
  }
  Clock::time_point rest_at() const {
    return last_rerun.value_or(Clock::time_point{}) + std::clamp(2 * interval, kRestMin, kRestMax);
  }
  // How long the pipeline may wait for news before the cull falls due.
  std::chrono::milliseconds wait_for(std::chrono::milliseconds idle) const {
    if (!owed) return idle;
    const auto left =
        std::chrono::ceil<std::chrono::milliseconds>(rest_at() - Clock::now()).count();
    return std::chrono::milliseconds(std::clamp<long long>(left, 1, idle.count()));
  }
};

// The options differ in more than the camera and tolerance.
bool asa_settings_changed(const PipelineSettings& a, const PipelineSettings& b) {
  const AsaOptions &x = a.asa, &y = b.asa;
  return a.asa_enabled != b.asa_enabled || a.approximate != b.approximate ||
         a.view.dependent != b.view.dependent || x.levels != y.levels || x.flatness != y.flatness ||
         x.uniform != y.uniform || x.rule != y.rule || x.tension != y.tension ||
         x.crease_degrees != y.crease_degrees;
}

}  // namespace

DisplayPipeline::DisplayPipeline(DecodedStream& decoded, StreamSource* client,
                                 LatestFrameMailbox& mailbox, PipelineSettings settings,
                                 FrameObserver observer)
    : decoded_(decoded),
      client_(client),
      mailbox_(mailbox),
      observer_(std::move(observer)),
      settings_(std::move(settings)) {
  builder_ = new_builder();
}

std::shared_ptr<DisplayBuilder> DisplayPipeline::new_builder() const {
  auto builder = std::make_shared<DisplayBuilder>();
  builder->set_path(settings_.path);
  builder->set_max_faces(settings_.view.max_display_faces);
  builder->set_changes_exact(true);  // decoded_stream's changes come from the record deltas
  return builder;
}

bool DisplayPipeline::complete_without_asa_waiting(const PipelineSettings& settings) const {
  uint32_t records_total;
  {
    std::lock_guard lock(mutex_);
    records_total = records_total_;
  }
  return settings.drop_stale_asa_at_end && !settings.asa_on_complete && records_total > 0 &&
         decoded_.records_decoded() >= records_total && decoded_.has_pending();
}

namespace {

// One run of the display builder on its own thread, with everything it
// reads and writes owned here, so that the pipeline can stop waiting for it.
struct BuildJob {
  std::shared_ptr<DisplayBuilder> builder;
  std::shared_ptr<const Mesh> mesh;
  MeshChanges changes;
  bool asa_enabled = false, options_changed = false;
  AsaOptions options;
  BuildReport report;
  std::optional<Result<DisplayMesh>> result;
  std::mutex mutex;
  std::condition_variable done;
};

}  // namespace

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
  FrameMeshPool frame_meshes;  // frames' copies of the decoded mesh: only the changes, where free
  MeshChanges changes;
  uint64_t seen_pokes = 0;
  bool outcome_seen = false;
  std::optional<DisplayFrame> last;      // the newest published frame
  std::optional<PipelineSettings> used;  // the settings of the last build
  bool fresh_builder = false;            // the builder was replaced: its first build is a full one
  MeshViewFacts view_facts;              // of the newest decoded mesh (it holds it, as `last` does)
  TopologyCache topology;                // of the newest display mesh
  OwedCull owed;                         // `last` was published uncull'd (camera-only re-run)
  constexpr std::chrono::milliseconds kIdleWait(200);
  while (decoded_.wait(seen_pokes, outcome_seen, owed.wait_for(kIdleWait))) {
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
    if (owed.owed && last && !pending && !rerun && Clock::now() >= owed.rest_at()) {
      // The camera rests: the newest display again, culled for its camera.
      DisplayFrame frame = *last;
      frame.decode_ms = 0;
      frame.asa_ms = 0;
      frame.coalesced_updates = 0;
      timed_cull_for_renderer(frame, owed.source, true, topology);
      owed.paid();
      FrameInfo info;
      info.rest_cull = true;
      info.elapsed_ms = elapsed();
      publish(frame, info);
      last = frame;
    }
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
      const TakenUpdate u = decoded_.take(frame_meshes, frame.decoded, changes);
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
    } else {
      frame = *last;
      frame.decode_ms = 0;
      frame.coalesced_updates = 0;
    }
    info.rerun = rerun;
    frame.records_total = records_total;
    frame.bytes_total = bytes_total;
    // Nothing is missing once every record is in: show the decoded mesh
    // (unless asked for ASA there too). A change of that counts as an
    // options change. A new camera or tolerance alone is none: the builder
    // redoes only what the views may refine.
    const bool complete = records_total > 0 && frame.records_decoded >= records_total;
    PipelineSettings effective = settings;
    if (settings.asa_guided) {
      guided_.update(decoded_);
      info.guidance_warning = guided_.take_warning();
      info.asa_guided = guided_.label_for(frame.records_decoded);
      const std::optional<AsaOptions> chosen = guided_.options_for(frame.records_decoded);
      effective.asa_enabled = chosen.has_value();
      effective.approximate = guided_.approximates_for(frame.records_decoded);
      if (chosen) {
        effective.asa.levels = chosen->levels;
        effective.asa.flatness = chosen->flatness;
        effective.asa.crease_degrees = chosen->crease_degrees;
        effective.asa.rule = chosen->rule;
      }
    }
    effective.asa_enabled = effective.asa_enabled && (!complete || settings.asa_on_complete);
    const bool options_changed = !used || fresh_builder || asa_settings_changed(effective, *used);
    fresh_builder = false;
    used = effective;
    // The camera is read by ASA, by the renderer's cull and by snapshots
    // (which come with cull_for_renderer).
    const bool need_camera = effective.asa_enabled || settings.view.cull_for_renderer;
    const AsaOptions options =
        options_with_view(effective, frame.decoded, view_facts, need_camera, frame.camera);
    // Approximating: ASA runs on the relaxed positions. Relaxing moves the
    // neighbours of every changed vertex too, so the decoder's changes do
    // not describe the builder's input: a full update each time.
    std::shared_ptr<const Mesh> asa_input = frame.decoded;
    const bool approximate = effective.asa_enabled && effective.approximate;
    if (approximate) {
      auto relaxed = std::make_shared<Mesh>(*frame.decoded);
      if (auto s = relax_toward_smooth(*relaxed, asa_choice_relax(options)); !s) {
        decoded_.stop();
        if (client_) client_->stop();
        mark_finished(s.error());
        break;
      }
      asa_input = std::move(relaxed);
    }
    const bool full_update = options_changed || !last || approximate;
    std::optional<Result<DisplayMesh>> built;
    if (effective.asa_enabled && !complete && settings.drop_stale_asa_at_end &&
        !settings.asa_on_complete && records_total > 0) {
      // ASA on a prefix: on a thread of its own, so that if the last record
      // arrives meanwhile the final frame (the decoded mesh) need not wait
      // for a result it would replace at once.
      auto job = std::make_shared<BuildJob>();
      job->builder = builder_;
      job->mesh = asa_input;
      job->changes = std::move(changes);
      job->asa_enabled = effective.asa_enabled;
      job->options_changed = full_update;
      job->options = options;
      std::thread([job] {
        auto r = job->builder->build(job->mesh, job->changes, job->asa_enabled, job->options,
                                     job->options_changed, job->report);
        std::lock_guard lock(job->mutex);
        job->result = std::move(r);
        job->done.notify_all();
      }).detach();
      bool dropped = false;
      {
        std::unique_lock lock(job->mutex);
        while (!job->result) {
          if (job->done.wait_for(lock, std::chrono::milliseconds(5)) == std::cv_status::timeout &&
              !job->result && complete_without_asa_waiting(settings)) {
            dropped = true;
            break;
          }
        }
        if (!dropped) {
          built = std::move(*job->result);
          info.build = job->report;
        }
      }
      changes.clear();
      if (dropped) {
        // The old builder stays with the job; the next build starts afresh
        // (options_changed), and the final update is taken at once.
        builder_ = new_builder();
        fresh_builder = true;
        continue;
      }
    } else {
      built = builder_->build(asa_input, changes, effective.asa_enabled, options, full_update,
                              info.build);
      changes.clear();
    }
    auto& display = *built;
    if (!display) {
      decoded_.stop();
      if (client_) client_->stop();
      mark_finished(display.error());
      break;
    }
    frame.display = display->mesh;
    frame.face_kind = display->face_kind;
    frame.display_unused_vertices = info.build.unused_vertices;
    frame.asa_ms = info.build.asa_ms;
    frame.pixel_tolerance = effective.asa_enabled ? info.build.pixel_tolerance : 0;
    frame.budget_limited = info.build.budget_limited;
    // Runs with ASA and a renderer hand it what the camera sees (--no-asa
    // and --view-independent draw the whole mesh, as before); a camera-only
    // re-run owes its cull until the camera rests (OwedCull).
    const std::shared_ptr<const Mesh>& refined = effective.asa_enabled ? asa_input : frame.decoded;
    const bool cull = settings.view.cull_for_renderer && settings.view.dependent &&
                      (settings.asa_enabled || settings.asa_guided);
    if (cull && !pending && !options_changed) {
      draw_whole_display(frame);
      owed.camera_rerun(refined);
    } else {
      timed_cull_for_renderer(frame, refined, cull, topology);
      owed.paid();
    }
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
    settings_.asa_guided = false;
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

void DisplayPipeline::set_view_camera(const AsaCamera& camera) {
  {
    std::lock_guard lock(mutex_);
    settings_.view.camera = camera;
  }
  decoded_.poke();
}

void DisplayPipeline::set_pixel_tolerance(float pixels) {
  if (!(pixels > 0)) return;
  {
    std::lock_guard lock(mutex_);
    settings_.view.pixel_tolerance = pixels;
  }
  decoded_.poke();
}

float DisplayPipeline::pixel_tolerance() const {
  std::lock_guard lock(mutex_);
  return settings_.view.dependent ? settings_.view.pixel_tolerance : 0;
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

// The display pipeline: its own thread takes the newest decoded mesh from
// the DecodedStream whenever it is free, runs ASA (DisplayBuilder) and
// publishes a DisplayFrame into the LatestFrameMailbox. The network thread
// never waits for it; when ASA falls behind, the updates that arrived
// meanwhile are merged into the next frame (DisplayFrame::coalesced_updates).
// It also implements the StreamControls a viewer steers the stream with.
#pragma once

#include <atomic>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>

#include "client/decoded_stream.h"
#include "client/display_builder.h"
#include "client/display_frame.h"
#include "client/guided_asa.h"
#include "client/stream_source.h"

namespace meshstream::client {

// Why a frame was published.
struct FrameInfo {
  bool new_records = false;  // it shows records the previous frame did not
  bool rerun = false;        // ASA options changed
  // The camera came to rest after camera-only re-runs (which draw the
  // whole display): the same display again, now culled for the renderer.
  bool rest_cull = false;
  BuildReport build;
  // --asa auto: the setting the stream's guidance chose for this frame
  // ("" when not guided), and once, why the guidance was refused.
  std::string asa_guided;
  std::string guidance_warning;
  double elapsed_ms = 0;  // since the pipeline started
};

using FrameObserver = std::function<void(const DisplayFrame&, const FrameInfo&)>;

// Where view-dependent ASA's camera comes from, and its limits.
struct ViewSettings {
  bool dependent = true;            // false: --view-independent (the whole mesh)
  std::optional<AsaCamera> camera;  // --camera or the viewer's; else the snapshot camera
  int width = 1024, height = 768;   // the snapshot camera's image (--width, --height)
  float pixel_tolerance = 2;
  uint64_t max_display_faces = 4'000'000;
  // A renderer is asked for (--view, --snapshot): hand it only the faces
  // the camera can show (display_cull.h). A run that draws nothing skips
  // the cull's O(F) passes (on dragon_x2 they cost more than ASA).
  bool cull_for_renderer = false;
};

struct PipelineSettings {
  bool asa_enabled = true;
  AsaOptions asa;  // asa.view is filled per update from `view`
  // With ASA: relax the decoded positions first (approximate.h;
  // --approximate, or the guidance's approximating choices).
  bool approximate = false;
  // ASA is for a partly received model: once every record of the stream is
  // decoded, the display is the decoded mesh itself (it is then closer to
  // the original than its ASA: crank 0.118 % against 4.08 % of the diagonal),
  // unless this asks for ASA there too (--asa-complete, or any set_asa()).
  bool asa_on_complete = false;
  // --asa auto: asa_enabled and asa come from the stream's guidance, per
  // frame (guided_asa.h); any set_asa() ends it (an explicit choice).
  bool asa_guided = false;
  AsaPath path = AsaPath::kAuto;
  ViewSettings view;
  // When the last record arrives while ASA still runs on an older prefix
  // and the complete mesh is shown as decoded (no asa_on_complete), publish
  // the final frame at once and drop that run's result (it would be
  // replaced at once). Off when particular records must each be shown
  // (--out-every, --out-at, --snapshot-at).
  bool drop_stale_asa_at_end = true;
};

class DisplayPipeline : public StreamControls {
 public:
  // `client` may be null (no pause/rate). The observer runs on the
  // pipeline thread after each publish (events, snapshot files).
  DisplayPipeline(DecodedStream& decoded, StreamSource* client, LatestFrameMailbox& mailbox,
                  PipelineSettings settings, FrameObserver observer);
  ~DisplayPipeline() override;

  void start();
  // Stops the thread (after the frame in progress) and joins it.
  void stop();
  // Blocks until the stream ended and its last state is published (or the
  // stream failed). The error, if the pipeline (ASA) failed.
  Status wait_finished();
  // From the stream header: totals, and the record count after which the
  // stream is complete (StreamHeader.end_record: the budget's last record).
  void set_totals(uint64_t bytes_total, uint32_t records_total, uint32_t end_record);

  // StreamControls
  void set_asa(bool asa_enabled, const AsaOptions& options) override;
  AsaOptions asa_options() const override;
  bool asa_enabled() const override;
  void pause() override;
  void resume() override;
  bool paused() const override;
  double current_rate_bytes_per_s() const override;
  void set_view_camera(const AsaCamera& camera) override;
  void set_pixel_tolerance(float pixels) override;
  float pixel_tolerance() const override;

 private:
  void loop();
  std::shared_ptr<DisplayBuilder> new_builder() const;
  // The stream's last record is decoded and waiting, and the complete mesh
  // is shown without ASA: what runs now on an older prefix can be dropped.
  bool complete_without_asa_waiting(const PipelineSettings& settings) const;
  void publish(DisplayFrame frame, const FrameInfo& info);
  void mark_finished(std::optional<Error> error);

  DecodedStream& decoded_;
  StreamSource* client_;
  LatestFrameMailbox& mailbox_;
  FrameObserver observer_;
  // Shared with a run of ASA that was dropped at the end (it owns the old
  // builder and finishes on its own thread; the pipeline takes a new one).
  std::shared_ptr<DisplayBuilder> builder_;
  GuidedAsa guided_;  // the pipeline thread's

  mutable std::mutex mutex_;  // guards settings_, finished_, error_, totals
  std::condition_variable finished_changed_;
  PipelineSettings settings_;
  bool finished_ = false;
  std::optional<Error> error_;
  uint64_t bytes_total_ = 0;
  uint32_t records_total_ = 0;
  uint32_t end_record_ = 0;
  uint64_t sequence_ = 0;
  std::thread thread_;
};

}  // namespace meshstream::client

// What the client's display pipeline publishes after each update, and the
// hand-over point between the pipeline (network + decode + ASA threads) and
// whoever shows the result (the viewer's render thread, snapshot writers,
// the JSON event printer).
#pragma once

#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "common/asa/display_cull.h"
#include "common/asa/subdivide.h"
#include "common/mesh/mesh.h"

namespace meshstream::client {

struct DisplayFrame {
  uint64_t sequence = 0;         // increases by one per published frame
  uint32_t records_decoded = 0;  // records applied to `decoded`
  uint32_t records_total = 0;
  uint64_t bytes_received = 0;  // stream bytes so far
  uint64_t bytes_total = 0;
  std::shared_ptr<const Mesh> decoded;                     // the decoder's mesh at this record
  std::shared_ptr<const Mesh> display;                     // after ASA (== decoded when ASA is off)
  std::shared_ptr<const std::vector<FaceKind>> face_kind;  // per display face; may be null
  // Vertex slots of `display` no face uses (ASA's incremental path keeps
  // some, IncrementalSubdivider::result()); events count the others.
  uint32_t display_unused_vertices = 0;
  // What the renderer draws (view-dependent mode, display_cull.h): the
  // display's faces the camera (within the cull's margins) can see, with
  // a skirt; the display itself otherwise. --out files keep `display`.
  std::shared_ptr<const Mesh> drawn;
  std::shared_ptr<const std::vector<FaceKind>> drawn_face_kind;  // per drawn face; may be null
  CullRegion cull;  // the cameras `drawn` is complete for
  // Of `display`, for the viewer to cull again when its camera leaves
  // `cull` (null: no culling, `drawn` is `display`).
  std::shared_ptr<const DisplayTopology> topology;
  double decode_ms = 0;
  double asa_ms = 0;
  // The renderer's cull for this frame (display_cull.h, with the topology
  // passes it needed); 0 when none ran: no renderer, no view-dependent ASA,
  // or a camera-only re-run, whose cull is left to the frame published
  // once the camera rests (FrameInfo::rest_cull).
  double cull_ms = 0;
  uint32_t coalesced_updates = 0;  // decoder updates merged into this frame
  bool final = false;              // the stream is complete (or its budget reached)
  // The camera the display was refined for (view-dependent ASA) and that
  // snapshots render with: --camera, the viewer's, or the snapshot camera.
  std::optional<AsaCamera> camera;
  float pixel_tolerance = 0;    // the tolerance used; 0: view-independent or no ASA
  bool budget_limited = false;  // --max-display-faces cut this update
};

// The vertices faces use: of the whole display, and of what is drawn.
inline uint32_t whole_display_vertices(const DisplayFrame& f) {
  return f.display->vertex_count() - f.display_unused_vertices;
}
inline uint32_t drawn_vertices(const DisplayFrame& f) {
  return f.drawn && f.drawn != f.display ? f.drawn->vertex_count() : whole_display_vertices(f);
}

// Latest-wins mailbox: the producer never waits for the consumer, and a
// consumer that falls behind sees only the newest frame.
class LatestFrameMailbox {
 public:
  void publish(DisplayFrame frame) {
    {
      std::lock_guard lock(mutex_);
      latest_ = std::move(frame);
    }
    changed_.notify_all();
  }
  // The newest frame if its sequence is above `seen`, else nullopt. Never blocks.
  std::optional<DisplayFrame> take_newer(uint64_t seen) const {
    std::lock_guard lock(mutex_);
    if (latest_ && latest_->sequence > seen) return latest_;
    return std::nullopt;
  }
  // Blocks until a frame newer than `seen` exists or `closed()`.
  std::optional<DisplayFrame> wait_newer(uint64_t seen) const {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return closed_ || (latest_ && latest_->sequence > seen); });
    if (latest_ && latest_->sequence > seen) return latest_;
    return std::nullopt;
  }
  void close() {
    {
      std::lock_guard lock(mutex_);
      closed_ = true;
    }
    changed_.notify_all();
  }
  bool closed() const {
    std::lock_guard lock(mutex_);
    return closed_;
  }

 private:
  mutable std::mutex mutex_;
  mutable std::condition_variable changed_;
  std::optional<DisplayFrame> latest_;
  bool closed_ = false;
};

// What a viewer may ask of a running stream. The client implements it; the
// viewer calls it from its render thread (implementations are thread-safe).
class StreamControls {
 public:
  virtual ~StreamControls() = default;
  // Re-runs ASA on the current decoded mesh with new options, and uses them
  // for every later update. options.levels == 0 or asa_enabled false: no ASA.
  virtual void set_asa(bool asa_enabled, const AsaOptions& options) = 0;
  virtual AsaOptions asa_options() const = 0;
  virtual bool asa_enabled() const = 0;
  virtual void pause() = 0;  // stop reading from the network (the server paces down)
  virtual void resume() = 0;
  virtual bool paused() const = 0;
  virtual double current_rate_bytes_per_s() const = 0;
  // View-dependent ASA: refine for this camera from now on (the viewer's,
  // as it orbits and zooms; re-runs ASA for what the move changed), and
  // with this pixel tolerance (> 0). pixel_tolerance() is 0 when ASA
  // refines the whole mesh (--view-independent).
  virtual void set_view_camera(const AsaCamera& camera) { (void)camera; }
  virtual void set_pixel_tolerance(float pixels) { (void)pixels; }
  virtual float pixel_tolerance() const { return 0; }
};

}  // namespace meshstream::client

// Per-vertex distance from a displayed mesh to a reference surface (the
// final decoded mesh), for the viewer's distance colouring, computed off the
// render thread.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "common/mesh/mesh.h"
#include "common/metrics/bvh.h"

namespace meshstream::client {

// Exact distance of every vertex of `mesh` to the surface in `reference`
// (closest point through the hierarchy, the previous answer as hint).
// Precondition: !reference.empty(). O(V log F).
std::vector<float> vertex_distances(const Mesh& mesh, const TriangleBvh& reference);

// One background thread: set the reference once (its hierarchy is built
// there), then ask for the distances of any mesh; the newest request wins.
class DistanceWorker {
 public:
  DistanceWorker();
  ~DistanceWorker();  // finishes the job in progress, then joins
  DistanceWorker(const DistanceWorker&) = delete;
  DistanceWorker& operator=(const DistanceWorker&) = delete;

  void set_reference(std::shared_ptr<const Mesh> reference);
  // True from the moment set_reference was called (requests made while the
  // hierarchy is still being built are answered once it is ready).
  bool has_reference() const;
  // Distances of `mesh`, reported with `tag` by take_result.
  void request(std::shared_ptr<const Mesh> mesh, uint64_t tag);

  struct Answer {
    uint64_t tag = 0;
    std::vector<float> distances;
    float max = 0;
    float p98 = 0;  // 98th percentile: the colour ramp's default top, robust to a few outliers
    float reference_diagonal = 0;
  };
  // The newest finished answer not yet taken. Never blocks.
  std::optional<Answer> take_result();

 private:
  void run();
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::shared_ptr<const Mesh> reference_;  // pending: hierarchy not built yet
  std::shared_ptr<const Mesh> job_;
  uint64_t job_tag_ = 0;
  bool reference_given_ = false;  // set_reference was called (the build may be running)
  bool has_reference_ = false;    // the hierarchy is built and not empty
  std::optional<Answer> answer_;
  std::thread thread_;
};

}  // namespace meshstream::client

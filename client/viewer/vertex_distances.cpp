#include "client/viewer/vertex_distances.h"

#include <algorithm>
#include <cmath>

namespace meshstream::client {

std::vector<float> vertex_distances(const Mesh& mesh, const TriangleBvh& reference) {
  std::vector<float> distances(mesh.vertex_count());
  uint32_t hint = TriangleBvh::kNoHint;
  for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    ClosestHit hit = reference.closest(to_double(mesh.positions[v]), hint);
    hint = hit.triangle;
    distances[v] = static_cast<float>(std::sqrt(hit.squared_distance));
  }
  return distances;
}

DistanceWorker::DistanceWorker() : thread_([this] { run(); }) {}

DistanceWorker::~DistanceWorker() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  thread_.join();
}

void DistanceWorker::set_reference(std::shared_ptr<const Mesh> reference) {
  {
    std::lock_guard lock(mutex_);
    reference_ = std::move(reference);
    reference_given_ = true;
  }
  wake_.notify_all();
}

bool DistanceWorker::has_reference() const {
  std::lock_guard lock(mutex_);
  return reference_given_;
}

void DistanceWorker::request(std::shared_ptr<const Mesh> mesh, uint64_t tag) {
  {
    std::lock_guard lock(mutex_);
    job_ = std::move(mesh);
    job_tag_ = tag;
  }
  wake_.notify_all();
}

std::optional<DistanceWorker::Answer> DistanceWorker::take_result() {
  std::lock_guard lock(mutex_);
  std::optional<Answer> answer = std::move(answer_);
  answer_.reset();
  return answer;
}

void DistanceWorker::run() {
  TriangleBvh bvh;
  float diagonal = 0;
  std::unique_lock lock(mutex_);
  while (true) {
    wake_.wait(lock, [&] { return stop_ || reference_ || (job_ && has_reference_); });
    if (stop_) return;
    if (reference_) {
      std::shared_ptr<const Mesh> reference = std::move(reference_);
      lock.unlock();
      bvh = reference->empty() ? TriangleBvh{} : TriangleBvh::build(*reference);
      diagonal = bounding_box(*reference).diagonal();
      lock.lock();
      has_reference_ = !bvh.empty();
      continue;
    }
    std::shared_ptr<const Mesh> job = std::move(job_);
    uint64_t tag = job_tag_;
    lock.unlock();
    Answer answer;
    answer.tag = tag;
    answer.distances = vertex_distances(*job, bvh);
    for (float d : answer.distances) answer.max = std::max(answer.max, d);
    if (!answer.distances.empty()) {
      std::vector<float> sorted = answer.distances;
      auto nth = sorted.begin() + static_cast<std::ptrdiff_t>((sorted.size() - 1) * 98 / 100);
      std::nth_element(sorted.begin(), nth, sorted.end());
      answer.p98 = *nth;
    }
    answer.reference_diagonal = diagonal;
    lock.lock();
    answer_ = std::move(answer);
  }
}

}  // namespace meshstream::client

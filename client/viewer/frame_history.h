// The frames the viewer has received, thinned to a bounded number so a long
// stream can be scrubbed back through (and compared against the final mesh)
// without keeping every intermediate mesh alive.
#pragma once

#include <cstddef>
#include <vector>

#include "client/display_frame.h"

namespace meshstream::client {

class FrameHistory {
 public:
  explicit FrameHistory(size_t capacity = 24) : capacity_(capacity < 4 ? 4 : capacity) {}

  // Appends; when full, drops every second frame of the older ones (the
  // first and the newest always stay), so the kept frames stay spread over
  // the whole stream. O(capacity) when thinning, O(1) otherwise.
  void add(const DisplayFrame& frame) {
    frames_.push_back(frame);
    if (frames_.size() <= capacity_) return;
    std::vector<DisplayFrame> kept;
    kept.reserve(capacity_);
    for (size_t i = 0; i + 1 < frames_.size(); ++i) {
      if (i % 2 == 0) kept.push_back(std::move(frames_[i]));
    }
    kept.push_back(std::move(frames_.back()));
    frames_ = std::move(kept);
  }

  size_t size() const { return frames_.size(); }
  bool empty() const { return frames_.empty(); }
  const DisplayFrame& operator[](size_t i) const { return frames_[i]; }
  const DisplayFrame& newest() const { return frames_.back(); }

 private:
  size_t capacity_;
  std::vector<DisplayFrame> frames_;
};

}  // namespace meshstream::client

// The frames the viewer has received, thinned to a bounded number so a long
// stream can be scrubbed back through (and compared against the final mesh)
// without keeping every intermediate mesh alive.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "client/display_frame.h"

namespace meshstream::client {

class FrameHistory {
 public:
  explicit FrameHistory(size_t capacity = 24) : capacity_(capacity < 4 ? 4 : capacity) {}

  // Appends. Keeps the frames whose arrival number is a multiple of a stride,
  // plus the newest; when more than `capacity` are kept the stride doubles,
  // so the kept frames stay evenly spread over the whole stream (the first
  // frame always stays). Amortized O(1); O(capacity) when the stride doubles.
  void add(const DisplayFrame& frame) {
    uint64_t ordinal = received_++;
    // The previous newest stays only if it is on the stride.
    if (!entries_.empty() && entries_.back().ordinal % stride_ != 0) entries_.pop_back();
    entries_.push_back({ordinal, frame});
    while (entries_.size() > capacity_) {
      stride_ *= 2;
      std::vector<Entry> kept;
      kept.reserve(capacity_);
      for (size_t i = 0; i < entries_.size(); ++i) {
        if (entries_[i].ordinal % stride_ == 0 || i + 1 == entries_.size()) {
          kept.push_back(std::move(entries_[i]));
        }
      }
      entries_ = std::move(kept);
    }
  }

  size_t size() const { return entries_.size(); }
  bool empty() const { return entries_.empty(); }
  const DisplayFrame& operator[](size_t i) const { return entries_[i].frame; }
  const DisplayFrame& newest() const { return entries_.back().frame; }

 private:
  struct Entry {
    uint64_t ordinal;
    DisplayFrame frame;
  };
  size_t capacity_;
  uint64_t received_ = 0;
  uint64_t stride_ = 1;
  std::vector<Entry> entries_;
};

}  // namespace meshstream::client

// Closure with a worklist: every face's action and every edge's split flag
// only ever grow (keep -> bisect -> red, pair -> opened), so the loop ends
// after O(F) pushes.
#include "common/asa/closure.h"

namespace meshstream::asa {
namespace {

struct Closer {
  const LevelView& m;
  ClosureBuffers& b;
  uint32_t split_edges = 0;

  uint8_t green(uint32_t f) const { return m.green ? m.green[f] : static_cast<uint8_t>(kNotGreen); }

  void split(uint32_t c) {
    if (b.edge_split[c]) return;
    b.edge_split[c] = 1;
    ++split_edges;
    const uint32_t o = m.opposite[c];
    if (o != kNone) {
      b.edge_split[o] = 1;
      b.worklist.push_back(o / 3);
    }
  }

  void make_red(uint32_t f) {
    if (green(f) != kNotGreen) {
      open_pair(f);
      return;
    }
    if (b.action[f] == kRed) return;
    b.action[f] = kRed;
    for (uint32_t i = 0; i < 3; ++i) split(3 * f + i);
  }

  // The parent (A, B, C) of a green pair is split 1-to-4: M already exists
  // on BC, so only AB and CA get new vertices.
  void open_pair(uint32_t f) {
    const uint32_t first = green(f) == kGreenFirst ? f : f - 1;
    const uint32_t second = first + 1;
    if (b.action[first] == kOpened) return;
    b.action[first] = b.action[second] = kOpened;
    split(3 * first + 2);   // AB
    split(3 * second + 1);  // CA
  }

  void evaluate(uint32_t f) {
    const uint8_t action = b.action[f];
    if (action == kRed || action == kOpened) return;
    const uint8_t kind = green(f);
    if (kind != kNotGreen) {
      const uint32_t first = kind == kGreenFirst ? f : f - 1;
      const uint32_t second = first + 1;
      if (b.edge_split[3 * first] || b.edge_split[3 * first + 2] || b.edge_split[3 * second] ||
          b.edge_split[3 * second + 1]) {
        open_pair(f);
      }
      return;
    }
    const int count = b.edge_split[3 * f] + b.edge_split[3 * f + 1] + b.edge_split[3 * f + 2];
    if (count >= 2) {
      make_red(f);
    } else if (count == 1) {
      b.action[f] = kBisect;
    }
  }
};

}  // namespace

uint32_t close_targets(const LevelView& m, const uint8_t* target, ClosureBuffers& b) {
  b.action.assign(m.face_count, kKeep);
  b.edge_split.assign(3 * static_cast<size_t>(m.face_count), 0);
  b.worklist.clear();
  Closer closer{m, b};
  for (uint32_t f = 0; f < m.face_count; ++f) {
    if (target[f]) closer.make_red(f);
  }
  while (!b.worklist.empty()) {
    const uint32_t f = b.worklist.back();
    b.worklist.pop_back();
    closer.evaluate(f);
  }
  return closer.split_edges;
}

}  // namespace meshstream::asa

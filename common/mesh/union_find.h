// Disjoint sets over 0..n-1 with path halving and union by rank: the
// workhorse of component, fan and boundary-loop counting. Near O(1) per call;
// 5 bytes per element (ranks stay below 32, so one byte holds them: import
// builds these over every corner of big meshes). Callers use the sets, never
// which element is a root.
#pragma once

#include <cstdint>
#include <numeric>
#include <vector>

namespace meshstream {

class UnionFind {
 public:
  explicit UnionFind(uint32_t n) : parent_(n), rank_(n, 0) {
    std::iota(parent_.begin(), parent_.end(), 0u);
  }

  uint32_t find(uint32_t x) {
    while (parent_[x] != x) {
      parent_[x] = parent_[parent_[x]];
      x = parent_[x];
    }
    return x;
  }

  // Returns true when a and b were in different sets.
  bool unite(uint32_t a, uint32_t b) {
    a = find(a);
    b = find(b);
    if (a == b) return false;
    if (rank_[a] < rank_[b]) std::swap(a, b);
    parent_[b] = a;
    if (rank_[a] == rank_[b]) ++rank_[a];
    return true;
  }

 private:
  std::vector<uint32_t> parent_;
  std::vector<uint8_t> rank_;
};

}  // namespace meshstream

// A bounding-volume hierarchy over the triangles of a mesh, for exact
// closest-point queries (surface distances, see distance.h).
//
// Built top-down with the binned surface-area heuristic (I. Wald, "On fast
// construction of SAH-based bounding volume hierarchies", IEEE RT 2007),
// stored as one flat array of nodes in depth-first order (a node's left child
// is the next node), queried with an explicit stack, nearer child first,
// pruning every box farther than the best squared distance found so far.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "common/base/result.h"
#include "common/mesh/mesh.h"
#include "common/mesh/vec.h"

namespace meshstream {

struct ClosestHit {
  double squared_distance = 0;
  Vec3d point{};          // on the surface
  uint32_t triangle = 0;  // index into the mesh's triangles
  uint32_t slot = 0;      // its place in the hierarchy (TriangleBvh::closest_from_slot's hint)
};

class TriangleBvh {
 public:
  static constexpr uint32_t kNoHint = 0xffffffffu;
  // Nodes pack their first slot or right child into 29 bits; a tree has
  // fewer than 2 nodes a triangle, so 2^28 triangles keep every index in range.
  static constexpr uint32_t kCountShift = 29;
  static constexpr uint32_t kFirstMask = (1u << kCountShift) - 1;
  static constexpr uint32_t kMaxTriangles = 1u << 28;

  TriangleBvh() = default;

  // Builds the hierarchy over every triangle of `mesh` (degenerate ones too).
  // Precondition: every index is in range (validate first; distance.cpp
  // does) and fewer than kMaxTriangles triangles (checked: more aborts,
  // 2^28 triangles would need over 20 GB here alone). A mesh without triangles gives an empty
  // hierarchy. Deterministic; O(F log F) time, about 44 bytes per triangle kept and 12 per vertex
  // (the build itself needs about 60 more a triangle while it runs). `threads` (0 = one per core)
  // build the top subtrees side by side; the tree is the same for every count.
  static TriangleBvh build(const Mesh& mesh, unsigned threads = 1);

  // The same tree over new positions of the same triangles (`mesh` has
  // the triangles it was built over, in the same order; its positions may
  // differ, e.g. the grid units of a quantized mesh and their dequantized
  // values): corners and bounds are recomputed bottom-up, the topology is
  // kept. Queries stay exact (closest()), so every squared distance is the
  // one a fresh build over `mesh` gives; only the triangle named on a tie
  // may differ. O(F), a small fraction of a build. kInvalidArgument when
  // the triangle count differs.
  Status refit(const Mesh& mesh);

  bool empty() const { return triangles_.empty(); }
  uint32_t triangle_count() const { return static_cast<uint32_t>(triangles_.size()); }
  uint32_t node_count() const { return static_cast<uint32_t>(nodes_.size()); }
  uint32_t depth() const { return depth_; }

  // The closest surface point to `query`. Exact with respect to
  // closest_point_on_triangle: the squared distance equals the minimum over
  // all triangles computed by brute force, bit for bit (ties may name another
  // triangle). `hint` (a triangle index, e.g. the previous query's answer)
  // only speeds the search up. Precondition: !empty(). O(log F) typical.
  ClosestHit closest(Vec3d query, uint32_t hint = kNoHint) const;
  // closest() with the hint a slot (an earlier hit's `slot`) instead of a
  // triangle: the same search, without the triangle-to-slot map.
  ClosestHit closest_from_slot(Vec3d query, uint32_t slot_hint = kNoHint) const;
  // Frees the triangle-to-slot map (4 bytes a triangle) while only
  // closest_from_slot() is used: closest() then searches without its hint
  // (the same distances, more slowly) until restore_triangle_hints().
  void drop_triangle_hints() { std::vector<uint32_t>().swap(slot_of_); }
  void restore_triangle_hints();

  struct Node {
    // Bounds, inflated a hair so rounding never escapes them, then rounded
    // outwards to floats (half the memory; a looser box only prunes less,
    // so every distance is the same).
    Vec3f lo, hi;
    // One word, so a node is 28 bytes instead of 32 (issue 15's encoder
    // memory): the top 3 bits hold count (leaf: its 1..4 triangles;
    // inner: 0), the low 29 bits first (leaf: its first slot in
    // triangles_; inner: its right child). Hence build()'s limit of
    // kMaxTriangles triangles.
    uint32_t packed = 0;
    uint32_t first() const { return packed & kFirstMask; }
    uint32_t count() const { return packed >> kCountShift; }
    void set(uint32_t first, uint32_t count) { packed = count << kCountShift | first; }
  };
  static_assert(sizeof(Node) == 28, "a node is two float boxes and one word");
  // The nodes in depth-first order (the root first, a node's left child
  // next): for inspecting the tree's shape.
  const std::vector<Node>& nodes() const { return nodes_; }

 private:
  // A triangle in leaf order: its corners as indices into points_, which
  // holds each corner point once, as the mesh holds it (floats, which
  // doubles represent exactly: queries widen them, so results are those of
  // double corners). 16 bytes a triangle and 12 a point instead of 40 a
  // triangle with the corners copied in (issue 15's encoder memory).
  struct Slot {
    std::array<uint32_t, 3> corners;
    uint32_t triangle;
  };
  // Nodes of one subtree in depth-first order (its root first); the top
  // subtrees each get their own, appended in order after the build.
  struct Builder {
    std::vector<Node> nodes;
    uint32_t depth = 0;
  };
  uint32_t build_node(Builder& out, std::vector<uint32_t>& refs, uint32_t begin, uint32_t end,
                      uint32_t depth, const Mesh& mesh, const std::vector<Vec3d>& centroids,
                      uint32_t spawn_levels) const;

  std::vector<Node> nodes_;
  std::vector<Slot> triangles_;    // in leaf order
  std::vector<Vec3f> points_;      // the corners' points, in the order the leaves first use them
  std::vector<uint32_t> slot_of_;  // triangle index -> slot (empty after drop_triangle_hints)
  double inflate_ = 0;
  uint32_t depth_ = 0;
};

}  // namespace meshstream

#include "common/metrics/bvh.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <future>
#include <limits>
#include <string>
#include <thread>

#include "common/metrics/closest_point.h"

namespace meshstream {
namespace {

constexpr uint32_t kMaxLeafTriangles = 4;
constexpr uint32_t kBins = 16;
// Beyond this depth splits are by median count, so the depth (and the query
// stack) stays bounded even on pathological inputs.
constexpr uint32_t kSahDepthLimit = 40;
constexpr uint32_t kStackSize = 128;  // > kSahDepthLimit + log2(2^32) + 1

struct Box {
  Vec3d lo{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
           std::numeric_limits<double>::infinity()};
  Vec3d hi{-std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
           -std::numeric_limits<double>::infinity()};
  void grow(Vec3d p) {
    for (int i = 0; i < 3; ++i) {
      lo[i] = std::min(lo[i], p[i]);
      hi[i] = std::max(hi[i], p[i]);
    }
  }
  void grow(const Box& b) {
    // An empty box (an empty SAH bin) is inverted: growing by its corners
    // would span everything, every split cost would be inf or NaN and the
    // build would fall back to median splits without a word.
    if (!b.valid()) return;
    grow(b.lo);
    grow(b.hi);
  }
  bool valid() const { return lo.x <= hi.x; }
  double half_area() const {
    if (!valid()) return 0;
    const Vec3d e = hi - lo;
    return e.x * e.y + e.y * e.z + e.z * e.x;
  }
};

// A subtree this large is worth a thread of its own.
constexpr uint32_t kSpawnTriangles = 1u << 15;

// Rounded outwards to floats: a node's stored bounds.
float round_down(double x) {
  float f = static_cast<float>(x);
  return double(f) > x ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
}
float round_up(double x) {
  float f = static_cast<float>(x);
  return double(f) < x ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
}

// A computed closest point may stray from its triangle by a few units in
// the last place of the largest coordinate; boxes grown by far more than
// that keep squared_distance_to_box a true lower bound after rounding.
double inflation_for(const Mesh& mesh) {
  double max_abs = 0;
  for (const Triangle& t : mesh.triangles)
    for (uint32_t v : t)
      for (int i = 0; i < 3; ++i)
        max_abs = std::max(max_abs, std::abs(double(mesh.positions[v][i])));
  return 1e-12 * max_abs;
}

}  // namespace

TriangleBvh TriangleBvh::build(const Mesh& mesh, unsigned threads) {
  TriangleBvh bvh;
  const uint32_t n = mesh.face_count();
  if (n == 0) return bvh;
  if (n >= kMaxTriangles) std::abort();  // the nodes' 29-bit indices (bvh.h)
  // Corner bounds are read from the mesh as needed (no copy of the corners:
  // it was the largest array of the build).
  std::vector<Vec3d> centroids(n);
  for (uint32_t f = 0; f < n; ++f) {
    std::array<Vec3d, 3> c;
    for (int k = 0; k < 3; ++k) c[k] = to_double(mesh.positions[mesh.triangles[f][k]]);
    centroids[f] = (c[0] + c[1] + c[2]) * (1.0 / 3.0);
  }
  bvh.inflate_ = inflation_for(mesh);

  std::vector<uint32_t> refs(n);
  for (uint32_t f = 0; f < n; ++f) refs[f] = f;
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  // Two levels of subtrees on their own threads for two or more threads
  // (four subtrees keep two cores busy when the splits are uneven).
  const uint32_t spawn_levels = threads > 1 ? 2 : 0;
  Builder out;
  out.nodes.reserve(2 * n / kMaxLeafTriangles + 1);
  bvh.build_node(out, refs, 0, n, 0, mesh, centroids, spawn_levels);
  std::vector<Vec3d>().swap(centroids);  // freed (`= {}` would keep the capacity)
  bvh.nodes_ = std::move(out.nodes);
  bvh.depth_ = out.depth;
  // Leaves hold 1..kMaxLeafTriangles triangles, so the reserve above is
  // often outgrown (doubling the array): keep only what the tree uses.
  bvh.nodes_.shrink_to_fit();

  // The corners' points numbered in the order the leaves first use them,
  // so a leaf's points lie together as its copied corners did.
  constexpr uint32_t kUnused = 0xffffffffu;
  std::vector<uint32_t> point_of(mesh.vertex_count(), kUnused);
  bvh.triangles_.resize(n);
  bvh.slot_of_.resize(n);
  for (uint32_t s = 0; s < n; ++s) {
    const Triangle& t = mesh.triangles[refs[s]];
    Slot& slot = bvh.triangles_[s];
    for (int k = 0; k < 3; ++k) {
      uint32_t& p = point_of[t[k]];
      if (p == kUnused) {
        p = static_cast<uint32_t>(bvh.points_.size());
        bvh.points_.push_back(mesh.positions[t[k]]);
      }
      slot.corners[k] = p;
    }
    slot.triangle = refs[s];
    bvh.slot_of_[refs[s]] = s;
  }
  bvh.points_.shrink_to_fit();
  return bvh;
}

uint32_t TriangleBvh::build_node(Builder& out, std::vector<uint32_t>& refs, uint32_t begin,
                                 uint32_t end, uint32_t depth, const Mesh& mesh,
                                 const std::vector<Vec3d>& centroids, uint32_t spawn_levels) const {
  std::vector<Node>& nodes_ = out.nodes;
  out.depth = std::max(out.depth, depth + 1);
  const uint32_t index = static_cast<uint32_t>(nodes_.size());
  nodes_.emplace_back();
  auto grow_by_corners = [&](Box& box, uint32_t f) {
    for (uint32_t v : mesh.triangles[f]) box.grow(to_double(mesh.positions[v]));
  };

  Box centroid_bounds;
  for (uint32_t i = begin; i < end; ++i) centroid_bounds.grow(centroids[refs[i]]);
  const uint32_t count = end - begin;
  const Vec3d extent = centroid_bounds.hi - centroid_bounds.lo;
  int axis = 0;
  if (extent.y > extent[axis]) axis = 1;
  if (extent.z > extent[axis]) axis = 2;
  const bool binned = count > kMaxLeafTriangles && depth < kSahDepthLimit && extent[axis] > 0;

  // Binned SAH along the widest centroid axis. The node's bounds are its
  // bins' union (min and max are exact: the same box as from the corners
  // directly), so the corners are read once a level, not twice.
  Box bounds;
  Box bin_box[kBins];
  uint32_t bin_count[kBins] = {};
  const double scale = binned ? kBins / extent[axis] : 0;
  auto bin_of = [&](uint32_t f) {
    const double t = (centroids[f][axis] - centroid_bounds.lo[axis]) * scale;
    return std::min<uint32_t>(kBins - 1, static_cast<uint32_t>(std::max(0.0, t)));
  };
  if (binned) {
    for (uint32_t i = begin; i < end; ++i) {
      const uint32_t b = bin_of(refs[i]);
      ++bin_count[b];
      grow_by_corners(bin_box[b], refs[i]);
    }
    for (uint32_t b = 0; b < kBins; ++b)
      if (bin_count[b] > 0) bounds.grow(bin_box[b]);
  } else {
    for (uint32_t i = begin; i < end; ++i) grow_by_corners(bounds, refs[i]);
  }
  const Vec3d pad{inflate_, inflate_, inflate_};
  const Vec3d lo = bounds.lo - pad, hi = bounds.hi + pad;
  nodes_[index].lo = {round_down(lo.x), round_down(lo.y), round_down(lo.z)};
  nodes_[index].hi = {round_up(hi.x), round_up(hi.y), round_up(hi.z)};

  auto make_leaf = [&] {
    nodes_[index].set(begin, count);
    return index;
  };
  if (count <= kMaxLeafTriangles) return make_leaf();

  uint32_t mid = begin;
  if (binned) {
    double right_area[kBins];
    uint32_t right_count[kBins];
    Box acc;
    uint32_t acc_count = 0;
    for (uint32_t b = kBins - 1; b > 0; --b) {
      acc.grow(bin_box[b]);
      acc_count += bin_count[b];
      right_area[b] = acc.half_area();
      right_count[b] = acc_count;
    }
    double best_cost = std::numeric_limits<double>::infinity();
    uint32_t best_split = 0;
    Box left;
    uint32_t left_count = 0;
    for (uint32_t b = 1; b < kBins; ++b) {
      left.grow(bin_box[b - 1]);
      left_count += bin_count[b - 1];
      if (left_count == 0 || right_count[b] == 0) continue;
      const double cost = left.half_area() * left_count + right_area[b] * right_count[b];
      if (cost < best_cost) {
        best_cost = cost;
        best_split = b;
      }
    }
    if (best_split > 0) {
      auto* split = std::partition(refs.data() + begin, refs.data() + end,
                                   [&](uint32_t f) { return bin_of(f) < best_split; });
      mid = static_cast<uint32_t>(split - refs.data());
    }
  }
  if (mid <= begin || mid >= end) {
    // Median split by count (ties in centroid broken by index, so the
    // result does not depend on the standard library's nth_element).
    mid = begin + count / 2;
    std::sort(refs.begin() + begin, refs.begin() + end, [&](uint32_t x, uint32_t y) {
      if (centroids[x][axis] != centroids[y][axis]) return centroids[x][axis] < centroids[y][axis];
      return x < y;
    });
  }

  uint32_t right = 0;
  if (spawn_levels > 0 && count >= kSpawnTriangles) {
    // The right subtree on its own thread into its own array (the two
    // halves of refs are disjoint), appended after the left one: the
    // nodes, their order and their indices are those of the serial build.
    Builder right_out;
    auto right_done = std::async(std::launch::async, [&] {
      build_node(right_out, refs, mid, end, depth + 1, mesh, centroids, spawn_levels - 1);
    });
    build_node(out, refs, begin, mid, depth + 1, mesh, centroids, spawn_levels - 1);
    right_done.get();
    right = static_cast<uint32_t>(nodes_.size());
    for (Node node : right_out.nodes) {
      if (node.count() == 0) node.set(node.first() + right, 0);  // an inner node's right child
      nodes_.push_back(node);
    }
    out.depth = std::max(out.depth, right_out.depth);
  } else {
    build_node(out, refs, begin, mid, depth + 1, mesh, centroids, 0);
    right = build_node(out, refs, mid, end, depth + 1, mesh, centroids, 0);
  }
  nodes_[index].set(right, 0);
  return index;
}

Status TriangleBvh::refit(const Mesh& mesh) {
  if (mesh.face_count() != triangles_.size())
    return make_error(ErrorCode::kInvalidArgument,
                      "hierarchy refit: " + std::to_string(mesh.face_count()) +
                          " triangles, the hierarchy has " + std::to_string(triangles_.size()));
  if (triangles_.empty()) return {};
  inflate_ = inflation_for(mesh);
  for (const Slot& s : triangles_) {
    const Triangle& t = mesh.triangles[s.triangle];
    for (int k = 0; k < 3; ++k) points_[s.corners[k]] = mesh.positions[t[k]];
  }
  // Children follow their parent in the array, so going backwards meets
  // both children before the parent. A leaf's box is its corners' (padded
  // and rounded outwards as in the build); an inner box is its children's
  // union (they are padded and rounded already: a looser box only prunes
  // less).
  const Vec3d pad{inflate_, inflate_, inflate_};
  for (size_t i = nodes_.size(); i-- > 0;) {
    Node& node = nodes_[i];
    if (node.count() > 0) {
      Box box;
      for (uint32_t s = node.first(), e = s + node.count(); s < e; ++s)
        for (uint32_t c : triangles_[s].corners) box.grow(to_double(points_[c]));
      const Vec3d lo = box.lo - pad, hi = box.hi + pad;
      node.lo = {round_down(lo.x), round_down(lo.y), round_down(lo.z)};
      node.hi = {round_up(hi.x), round_up(hi.y), round_up(hi.z)};
    } else {
      const Node& l = nodes_[i + 1];
      const Node& r = nodes_[node.first()];
      for (int k = 0; k < 3; ++k) {
        node.lo[k] = std::min(l.lo[k], r.lo[k]);
        node.hi[k] = std::max(l.hi[k], r.hi[k]);
      }
    }
  }
  return {};
}

void TriangleBvh::restore_triangle_hints() {
  if (slot_of_.size() == triangles_.size()) return;
  slot_of_.resize(triangles_.size());
  for (uint32_t s = 0; s < triangles_.size(); ++s) slot_of_[triangles_[s].triangle] = s;
}

ClosestHit TriangleBvh::closest(Vec3d query, uint32_t hint) const {
  return closest_from_slot(query, hint < slot_of_.size() ? slot_of_[hint] : kNoHint);
}

ClosestHit TriangleBvh::closest_from_slot(Vec3d query, uint32_t slot_hint) const {
  ClosestHit best;
  best.squared_distance = std::numeric_limits<double>::infinity();
  auto test_slot = [&](uint32_t s) {
    const Slot& t = triangles_[s];
    const Vec3d q = closest_point_on_triangle(query, to_double(points_[t.corners[0]]),
                                              to_double(points_[t.corners[1]]),
                                              to_double(points_[t.corners[2]]));
    const double d2 = squared_length(query - q);
    if (d2 < best.squared_distance) {
      best.squared_distance = d2;
      best.point = q;
      best.triangle = t.triangle;
      best.slot = s;
    }
  };
  if (slot_hint < triangles_.size()) test_slot(slot_hint);

  struct Entry {
    uint32_t node;
    double d2;
  };
  Entry stack[kStackSize];
  uint32_t top = 0;
  auto box_d2 = [&](const Node& n) {
    return squared_distance_to_box(query, vec3_cast<double>(n.lo), vec3_cast<double>(n.hi));
  };
  stack[top++] = {0, box_d2(nodes_[0])};
  while (top > 0) {
    const Entry e = stack[--top];
    // Every triangle below lies at least e.d2 away (closest_point.h), so a
    // box farther than the best so far cannot hold a strictly better one.
    if (e.d2 > best.squared_distance) continue;
    const Node& node = nodes_[e.node];
    if (node.count() > 0) {
      for (uint32_t s = node.first(), end = s + node.count(); s < end; ++s) test_slot(s);
      continue;
    }
    const uint32_t left = e.node + 1;
    const uint32_t right = node.first();
    const double dl = box_d2(nodes_[left]);
    const double dr = box_d2(nodes_[right]);
    // Push the farther child first so the nearer one is searched first.
    if (dl <= dr) {
      if (dr <= best.squared_distance) stack[top++] = {right, dr};
      if (dl <= best.squared_distance) stack[top++] = {left, dl};
    } else {
      if (dl <= best.squared_distance) stack[top++] = {left, dl};
      if (dr <= best.squared_distance) stack[top++] = {right, dr};
    }
  }
  return best;
}

}  // namespace meshstream

// Layered decimation: see decimate.h for the rules and their reasons.
#include "common/codec/decimate.h"

#include <algorithm>
#include <cmath>
#include <thread>

#include "common/base/parallel_blocks.h"

namespace meshstream {
namespace {

constexpr double kMinFanCosine = 0.2;
// Each layer considers only the cheapest DecimateOptions::candidate_share
// of its candidates (default half): the independent set is then drawn from
// the least important vertices, so the coarse meshes keep the shape.
// Weights in the removal cost and apex choice (see decimate.h). Measured
// with bench/decimation_bench on all 13 real models (RMS at the LOD chain's
// cumulative bytes, docs/hcs-format.md "Layers"): a prediction weight of
// 0.25 kept flat CAD vertices whose ring average lies far off in the plane
// (zero error, long thin fans) for the coarse meshes; with the area-weighted
// error below, 0.05 gives -8 % / -12 % RMS at the chain's 1/16 / 1/4 points
// (geometric means; 0.025 and 0.1 less) for a stream 2 % larger. Valence
// 0.15 or 0.35, shape 3, area power 0.5 or 1.5 did not pay.
constexpr double kValenceWeight = 0.25;
constexpr double kPredictionWeight = 0.05;
constexpr double kShapeWeight = 10.0;
// An upper bound of best_apex's shape term min(area2 / s) over a fan: the
// equilateral triangle's sqrt(3) / 6 = 0.28868, rounded up so that the
// floating-point quotient of any triangle stays below it.
constexpr double kMaxShape = 0.2887;

// Edge vectors and their cross products in 64 bits: exact for 20-bit grids.
Vec3l sub(Vec3i a, Vec3i b) { return vec3_cast<int64_t>(a) - vec3_cast<int64_t>(b); }
double norm(Vec3l a) { return length(vec3_cast<double>(a)); }

// Plane quadric (Garland & Heckbert 1997): sum of w (n.p + d)^2 over planes,
// in grid units; `weight` is the summed plane weight (area).
struct Quadric {
  double a00 = 0, a01 = 0, a02 = 0, a03 = 0, a11 = 0, a12 = 0, a13 = 0, a22 = 0, a23 = 0, a33 = 0;
  double weight = 0;
  void add_plane(const Vec3d& n, double d, double w) {
    a00 += w * n.x * n.x;
    a01 += w * n.x * n.y;
    a02 += w * n.x * n.z;
    a03 += w * n.x * d;
    a11 += w * n.y * n.y;
    a12 += w * n.y * n.z;
    a13 += w * n.y * d;
    a22 += w * n.z * n.z;
    a23 += w * n.z * d;
    a33 += w * d * d;
    weight += w;
  }
  void add(const Quadric& o) {
    a00 += o.a00;
    a01 += o.a01;
    a02 += o.a02;
    a03 += o.a03;
    a11 += o.a11;
    a12 += o.a12;
    a13 += o.a13;
    a22 += o.a22;
    a23 += o.a23;
    a33 += o.a33;
    weight += o.weight;
  }
  // Mean squared distance of p from the planes.
  double mean_error(Vec3i q) const {
    const double x = q.x, y = q.y, z = q.z;
    const double e = a00 * x * x + 2 * a01 * x * y + 2 * a02 * x * z + 2 * a03 * x + a11 * y * y +
                     2 * a12 * y * z + 2 * a13 * y + a22 * z * z + 2 * a23 * z + a33;
    return weight > 0 ? std::max(0.0, e) / weight : 0.0;
  }
};

// decimate_layers' per-layer vertex marks, one byte a vertex: removed or
// in a removed vertex's ring (so not removable in this layer); got a new
// edge or face in this layer; and in the high bits the index into the
// vertex's ring of the apex that priced it at the layer's start
// (LayerBuilder::planned_apex). One byte, not two: the decimation's arrays
// are part of the encoder's peak.
constexpr uint8_t kBlocked = 1;
constexpr uint8_t kTouched = 2;
constexpr int kApexShift = 4;
static_assert(kMaxRemovalValence <= (1u << (8 - kApexShift)));
uint32_t planned_apex_of(uint8_t mark) { return mark >> kApexShift; }

struct Candidate {
  double cost;
  uint32_t vertex;
};

// The error quadrics of every vertex, shared by the layer builders of
// every thread (the workers only read them).
struct QuadricField {
  std::vector<Quadric> quadrics;
  double mean_weight = 0;  // of the initial quadrics: the cost's area unit
};

class LayerBuilder {
 public:
  LayerBuilder(EditableMesh& mesh, QuadricField& field)
      : quadrics(field.quadrics), mean_weight(field.mean_weight), m_(mesh) {}
  std::vector<Quadric>& quadrics;
  double& mean_weight;

  // Every face's plane, weighted by area, into its vertices' quadrics; every
  // boundary edge's perpendicular plane too, so boundaries keep their shape.
  void init_quadrics() {
    const auto& p = m_.positions();
    quadrics.assign(m_.vertex_count(), Quadric{});
    for (uint32_t f = 0; f < m_.face_slot_count(); ++f) {
      if (m_.face_dead(f)) continue;
      const Triangle& t = m_.faces()[f];
      const Vec3l n = cross(sub(p[t[1]], p[t[0]]), sub(p[t[2]], p[t[0]]));
      const double len = norm(n);
      if (len == 0) continue;
      const Vec3d u = vec3_cast<double>(n) / len;
      const Vec3d p0 = to_double(p[t[0]]);
      for (uint32_t v : t) quadrics[v].add_plane(u, -dot(u, p0), 0.5 * len);
      for (int i = 0; i < 3; ++i) {
        if (m_.opposite(3 * f + i) != kNone) continue;
        const uint32_t a = t[(i + 1) % 3], b = t[(i + 2) % 3];
        const Vec3d pa = to_double(p[a]);
        const Vec3d e = to_double(p[b]) - pa;
        const Vec3d side = normalized(cross(e, u));
        const double w = 2.0 * dot(e, e);
        quadrics[a].add_plane(side, -dot(side, pa), w);
        quadrics[b].add_plane(side, -dot(side, pa), w);
      }
    }
  }

  // Importance of removing v (lower first), or a negative value when v
  // cannot be removed at all. The error is that of the apex the removal
  // would use now (best_apex): the least error over all ring vertices, valid
  // or not, called vertices cheap whose only zero-error collapse makes an
  // existing edge or a flipped triangle (crank at 1/4 of its vertices: RMS
  // per vertex 4.6x meshopt's, 1.7x with this).
  // `apex` gets the index into v's ring of the apex that priced it.
  double cost(uint32_t v, uint8_t& apex) {
    if (m_.is_isolated(v)) return -1;
    double error = 0;
    const uint32_t a = best_apex(v, error);
    if (a == kNone) return -1;
    apex = static_cast<uint8_t>(a);
    const size_t k = ring_.size();
    const auto& p = m_.positions();
    Vec3d centroid{};
    for (uint32_t r : ring_) centroid += to_double(p[r]);
    centroid = centroid / double(k);
    const Vec3d d = to_double(p[v]) - centroid;
    // The squared distance times the area it spreads over (the quadric's
    // plane weight: original area now represented around v), relative to
    // the mean star: a removal's share of the squared surface RMS. The
    // mean error alone ranked a vertex carrying a large CAD face as cheap as
    // a small one (RMS at the chain's 1/16 bytes: fandisk 2.9x -> 2.1x the
    // chain's, crank 2.5x -> 2.0x; with the prediction weight 0.05 too,
    // 1.1x and 2.1x).
    if (mean_weight > 0) error *= quadrics[v].weight / mean_weight;
    return std::log1p(std::sqrt(error) + kPredictionWeight * length(d)) +
           kValenceWeight * double(k);
  }

  // The best valid apex of v's fan (index into ring_, which holds v's ring
  // afterwards) and its quadric error (mean squared, grid units), or kNone.
  uint32_t best_apex(uint32_t v, double& error) {
    m_.star(v, ring_, corners_);
    const uint32_t k = static_cast<uint32_t>(ring_.size());
    const bool boundary = m_.is_boundary(v);
    if (k < 3 || k > kMaxRemovalValence || corners_.size() != (boundary ? k - 1 : k)) return kNone;
    const auto& p = m_.positions();
    if (boundary) {
      // The new boundary edge (ring[k-1], ring[0]) must not exist yet.
      m_.star(ring_[k - 1], apex_ring_, apex_corners_);
      if (std::find(apex_ring_.begin(), apex_ring_.end(), ring_[0]) != apex_ring_.end())
        return kNone;
    }
    // The ring twice over, so ring[(a + j) % k] is wrapped[a + j]: a
    // division by the variable k costs tens of cycles, and this runs for
    // every fan triangle of every apex of every live vertex of every layer.
    // q: the ring's positions the same way, in 64 bits; edge2[i]: the
    // squared length of ring edge (R_i, R_i+1).
    uint32_t wrapped[2 * kMaxRemovalValence];
    Vec3l q[2 * kMaxRemovalValence];
    int64_t edge2[2 * kMaxRemovalValence];
    for (uint32_t i = 0; i < k; ++i) {
      wrapped[i] = wrapped[i + k] = ring_[i];
      q[i] = q[i + k] = vec3_cast<int64_t>(p[ring_[i]]);
    }
    for (uint32_t i = 0; i + 1 < 2 * k; ++i) edge2[i] = squared_length(q[i + 1] - q[i]);
    Vec3l star_normal{0, 0, 0};
    bool folded_star = false;
    for (uint32_t i = 0; i < corners_.size(); ++i) {
      const Vec3l n = cross(sub(p[ring_[i]], p[v]), sub(p[wrapped[i + 1]], p[v]));
      if (n.x == 0 && n.y == 0 && n.z == 0) folded_star = true;
      star_normal += n;
    }
    // A star with no area at all (folded flat on the grid) has no normal: it
    // takes only fans that have no area either (nothing there can turn).
    const double snl = norm(star_normal);
    const bool flat_star = snl == 0;
    const Vec3d sn = flat_star ? Vec3d{} : vec3_cast<double>(star_normal) / snl;

    const Quadric& quadric = quadrics[v];
    double best_quality = -1;
    uint32_t best_apex = kNone;
    for (uint32_t a = 0; a < k; ++a) {
      const uint32_t apex = ring_[a];
      // The quadric term first: an apex whose score could not beat the best
      // one even with the best possible shape term (worst <= kMaxShape)
      // would be skipped below anyway, so its fan need not be checked. The
      // same apex wins, so the same removals are made.
      const double apex_error = std::sqrt(quadric.mean_error(p[apex]));
      if (best_apex != kNone && kShapeWeight * kMaxShape - apex_error <= best_quality) continue;
      bool ok = true;
      double worst = 1e300;
      // Fan triangle j is (A, B, C) = (R_a, R_a+j, R_a+j+1): its B - A is
      // the previous one's C - A, and its C - B a ring edge, so each step
      // computes one new difference. All exact integers (20-bit grids:
      // squared lengths below 2^53), so the values are those of computing
      // each triangle on its own.
      const Vec3l A = q[a];
      Vec3l ba = q[a + 1] - A;
      int64_t ba2 = squared_length(ba);
      for (uint32_t j = 1; j + 1 < k; ++j) {
        const Vec3l ca = q[a + j + 1] - A;
        const int64_t ca2 = squared_length(ca);
        const Vec3l n = cross(ba, ca);
        const int64_t s = ba2 + edge2[a + j] + ca2;
        ba = ca;
        ba2 = ca2;
        if (n.x == 0 && n.y == 0 && n.z == 0) {
          // Folded flat on the grid: it covers nothing and faces no way, so
          // it cannot turn over. Dense scans have many such triangles at 12
          // bits, and refusing every fan that makes one left their vertices
          // for the base (dragon_x1 at 9 bits: 15 943 base vertices, 477
          // with this); the quadric error still prices the flattening.
          // Only where v's star is folded already: a flat fan in a star with
          // area (three ring vertices on a straight CAD crease) made worse
          // coarse meshes (casting: RMS over the LOD chain's, geometric mean
          // from its 1/64 to 1/4 point, 0.76 -> 0.86; 0.76 with this rule).
          if (!folded_star) {
            ok = false;
            break;
          }
          worst = 0;
          continue;
        }
        // A triangle facing away from the star's normal fails whatever its
        // area (which is positive here): no square root needed for it.
        const double facing = flat_star ? 0.0 : dot(vec3_cast<double>(n), sn);
        if (facing <= 0) {
          ok = false;
          break;
        }
        const double area2 = norm(n);
        if (facing <= kMinFanCosine * area2) {
          ok = false;
          break;
        }
        worst = std::min(worst, area2 / double(s));  // 2*sqrt(3)*this = 1 for equilateral
      }
      if (!ok) continue;
      // The fan from `apex` is the half-edge collapse of v into it: least
      // quadric error wins, triangle shape (worst in [0, 0.29]) breaks
      // near-ties worth up to ~3 grid steps. The first best in ring order.
      const double score = kShapeWeight * worst - apex_error;
      if (best_apex != kNone && score <= best_quality) continue;
      // Only an apex that would win pays for its star (the edge checks).
      if (!apex_edges_ok(v, a)) continue;
      best_quality = score;
      best_apex = a;
    }
    if (best_apex != kNone) error = quadrics[v].mean_error(p[ring_[best_apex]]);
    return best_apex;
  }

  // Whether the fan from apex a of v's ring (ring_, corners_ hold v's star)
  // makes no existing edge (or, for an interior valence-3 v, no existing
  // face) on the mesh as it is now.
  bool apex_edges_ok(uint32_t v, uint32_t a) {
    const uint32_t k = static_cast<uint32_t>(ring_.size());
    const bool boundary = m_.is_boundary(v);
    m_.star(ring_[a], apex_ring_, apex_corners_);
    if (k == 3 && !boundary) {
      const uint32_t b = ring_[(a + 1) % k], c = ring_[(a + 2) % k];
      for (uint32_t corner : apex_corners_) {
        const uint32_t x = m_.vertex(EditableMesh::next(corner));
        const uint32_t y = m_.vertex(EditableMesh::prev(corner));
        if ((x == b && y == c) || (x == c && y == b)) return false;
      }
      return true;
    }
    for (uint32_t j = 2; j + 2 <= k; ++j) {
      const uint32_t w = ring_[(a + j) % k];
      if (std::find(apex_ring_.begin(), apex_ring_.end(), w) != apex_ring_.end()) return false;
    }
    return true;
  }

  // best_apex(v) now, given `planned`, the apex it gave at the layer's
  // start, and `marks` (kTouched: a vertex that got a new edge or face in
  // this layer since then). While v is not blocked, its star, its ring's
  // positions and its quadric are those of the layer's start: the removals
  // since only add edges and faces among its ring vertices (what they
  // delete holds a removed vertex, never in v's ring). So the apexes valid
  // now are a subset of those valid then, and the planned apex, the first
  // best of those, is still the first best while it stays valid. Only a
  // touched vertex can have a new edge, so its checks are redone only where
  // one could have changed; else best_apex runs again. Returns the same as
  // best_apex (ring_, corners_ hold v's star).
  uint32_t planned_apex(uint32_t v, uint32_t planned, const std::vector<uint8_t>& marks) {
    m_.star(v, ring_, corners_);
    const uint32_t k = static_cast<uint32_t>(ring_.size());
    const bool boundary = m_.is_boundary(v);
    if (planned >= k) {
      double error = 0;
      return best_apex(v, error);
    }
    if (boundary && (marks[ring_[k - 1]] & kTouched) && (marks[ring_[0]] & kTouched)) {
      // The new boundary edge (ring[k-1], ring[0]) may exist now.
      m_.star(ring_[k - 1], apex_ring_, apex_corners_);
      if (std::find(apex_ring_.begin(), apex_ring_.end(), ring_[0]) != apex_ring_.end())
        return kNone;
    }
    const bool recheck = (k == 3 && !boundary) || (marks[ring_[planned]] & kTouched);
    if (!recheck || apex_edges_ok(v, planned)) return planned;
    double error = 0;
    return best_apex(v, error);
  }

  // Tries to remove v, whose layer-start apex is `planned` (see
  // planned_apex); returns true, fills `removal`, appends its ring (apex
  // first) to `ring_pool` and marks the vertices that get new edges or
  // faces kTouched in `marks` on success.
  bool try_remove(uint32_t v, uint32_t planned, std::vector<uint8_t>& marks, Removal& removal,
                  std::vector<uint32_t>& ring_pool) {
    const uint32_t best_apex = planned_apex(v, planned, marks);
    if (best_apex == kNone) return false;
    const uint32_t k = static_cast<uint32_t>(ring_.size());
    const bool boundary = m_.is_boundary(v);
    // New edges join the apex to R_a+2 .. R_a+k-2; a boundary vertex's also
    // (ring[k-1], ring[0]); a new face holds the apex.
    marks[ring_[best_apex]] |= kTouched;
    for (uint32_t j = 2; j + 2 <= k; ++j) marks[ring_[(best_apex + j) % k]] |= kTouched;
    if (boundary) {
      marks[ring_[k - 1]] |= kTouched;
      marks[ring_[0]] |= kTouched;
    }
    removal.vertex = v;
    removal.ring_first = static_cast<uint32_t>(ring_pool.size());
    removal.ring_size = static_cast<uint16_t>(k);
    for (uint32_t i = 0; i < k; ++i) ring_pool.push_back(ring_[(best_apex + i) % k]);
    removal.open_edge =
        boundary ? static_cast<uint16_t>((2 * k - 1 - best_apex) % k) : Removal::kInterior;
    m_.remove_vertex(v, ring_, corners_, best_apex);
    if (!quadrics.empty()) quadrics[ring_[best_apex]].add(quadrics[v]);
    return true;
  }

 private:
  EditableMesh& m_;
  std::vector<uint32_t> ring_, corners_, apex_ring_, apex_corners_;
};

}  // namespace

uint32_t base_target(uint32_t vertices, const DecimateOptions& options) {
  if (options.max_base_share <= 0 || options.max_base_share >= 1) return options.target_vertices;
  const auto share = static_cast<uint32_t>(options.max_base_share * double(vertices));
  return std::min(options.target_vertices, std::max(kMinBaseTarget, share));
}

namespace {

// The removal cost of every live vertex (cost[v]; negative: not
// removable) and the apex it was priced with (in marks[v], whose flags it
// clears), on `threads` threads over blocks of vertex ids handed out one
// at a time (a thread that gets less of a core under load takes fewer).
// The costs only read the mesh and the quadrics, so every thread sees the
// same state and the result does not depend on the thread count. (Keeping
// the costs of vertices no removal touched does not pay: a layer removes
// about 15 % of the vertices, and their 2-rings, which a cost reads, cover
// nearly the whole mesh.)
void update_costs(EditableMesh& mesh, QuadricField& field, const std::vector<uint8_t>& alive,
                  std::vector<double>& cost, std::vector<uint8_t>& marks, unsigned threads) {
  const uint32_t n = mesh.vertex_count();
  constexpr uint32_t kBlock = 4096;
  for_each_block((n + kBlock - 1) / kBlock, threads, [&](size_t b) {
    LayerBuilder builder(mesh, field);
    const uint32_t first = static_cast<uint32_t>(b) * kBlock;
    const uint32_t last = std::min(n, first + kBlock);
    for (uint32_t v = first; v < last; ++v) {
      uint8_t apex = 0;
      if (alive[v]) cost[v] = builder.cost(v, apex);
      marks[v] = static_cast<uint8_t>(apex << kApexShift);  // and no flags yet
    }
  });
}

bool cheaper(const Candidate& a, const Candidate& b) {
  return a.cost < b.cost || (a.cost == b.cost && a.vertex < b.vertex);
}

// Sorts the `m` cheapest candidates into candidates[0, m) (the rest stay
// unsorted behind them): the same as a full sort's first m, since no two
// candidates tie (vertex ids differ). Two selections split them into
// halves that sort on their own threads; a full sort was 5 % of the
// decimation, all of it on one core.
void sort_cheapest(std::vector<Candidate>& candidates, size_t m, unsigned threads) {
  const auto begin = candidates.begin();
  if (m < candidates.size()) std::nth_element(begin, begin + m, candidates.end(), cheaper);
  constexpr size_t kMinHalf = 8192;
  if (threads < 2 || m < 2 * kMinHalf) {
    std::sort(begin, begin + m, cheaper);
    return;
  }
  const size_t half = m / 2;
  std::nth_element(begin, begin + half, begin + m, cheaper);
  for_each_block(2, threads, [&](size_t b) {
    if (b == 0)
      std::sort(begin, begin + half, cheaper);
    else
      std::sort(begin + half, begin + m, cheaper);
  });
}

}  // namespace

DecimationResult decimate_layers(EditableMesh mesh, const DecimateOptions& options) {
  DecimationResult result;
  const uint32_t n = mesh.vertex_count();
  std::vector<uint8_t> alive(n, 1), marks(n, 0);
  uint32_t alive_count = n;
  QuadricField field;
  LayerBuilder builder(mesh, field);
  builder.init_quadrics();
  for (const Quadric& q : field.quadrics) field.mean_weight += q.weight / n;
  const uint32_t target = base_target(n, options);
  const unsigned threads =
      options.threads > 0 ? options.threads : std::max(1u, std::thread::hardware_concurrency());
  std::vector<double> cost(n, -1);
  std::vector<Candidate> candidates;
  std::vector<uint8_t> layer_locked;
  while (alive_count > target && result.layers.size() < options.max_layers) {
    update_costs(mesh, field, alive, cost, marks, threads);
    if (options.layer_locks) {
      layer_locked.assign(n, 0);
      options.layer_locks(static_cast<uint32_t>(result.layers.size()), mesh, layer_locked);
    }
    candidates.clear();
    for (uint32_t v = 0; v < n; ++v) {
      const bool locked = (v < options.locked.size() && options.locked[v] != 0) ||
                          (v < layer_locked.size() && layer_locked[v] != 0);
      if (alive[v] && cost[v] >= 0 && !locked) candidates.push_back({cost[v], v});
    }
    DecimationLayer layer;
    // The cheapest share first; all candidates when none of those is removable.
    const size_t share = static_cast<size_t>(options.candidate_share * double(candidates.size()));
    const size_t first = std::min(std::max<size_t>(share, 1), candidates.size());
    sort_cheapest(candidates, first, threads);
    for (size_t limit : {first, candidates.size()}) {
      if (limit > first) std::sort(candidates.begin() + first, candidates.end(), cheaper);
      for (size_t i = 0; i < limit && i < candidates.size(); ++i) {
        if (alive_count - layer.removals.size() <= target) break;
        const uint32_t v = candidates[i].vertex;
        if (marks[v] & kBlocked) continue;
        Removal r;
        if (!builder.try_remove(v, planned_apex_of(marks[v]), marks, r, layer.rings)) continue;
        marks[v] |= kBlocked;
        for (uint32_t u : layer.ring(r)) marks[u] |= kBlocked;
        alive[v] = 0;
        layer.removals.push_back(r);
      }
      if (!layer.removals.empty()) break;
    }
    if (layer.removals.empty()) break;
    alive_count -= static_cast<uint32_t>(layer.removals.size());
    // Kept until the encode ends: no growth slack.
    layer.removals.shrink_to_fit();
    layer.rings.shrink_to_fit();
    result.layers.push_back(std::move(layer));
    if (options.progress) options.progress(double(n - alive_count) / double(n - target));
  }
  std::vector<uint32_t> new_id(n, kNone);
  for (uint32_t v = 0; v < n; ++v) {
    if (alive[v]) {
      new_id[v] = static_cast<uint32_t>(result.base_vertices.size());
      result.base_vertices.push_back(v);
    }
  }
  for (uint32_t f = 0; f < mesh.face_slot_count(); ++f) {
    if (!mesh.face_dead(f)) result.base_faces.push_back(mesh.faces()[f]);
  }
  return result;
}

}  // namespace meshstream

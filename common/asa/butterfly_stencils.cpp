// Modified Butterfly stencils.
//
// Method: D. Zorin, P. Schröder, W. Sweldens, "Interpolating Subdivision for
// Meshes with Arbitrary Topology", SIGGRAPH 1996, pp. 189-192 (ten-point
// regular stencil with tension w, extraordinary weights for K = 3, 4, >= 5,
// averaging when both endpoints are extraordinary). Boundary curve rule: the
// four-point scheme of Dyn, Levin and Gregory (1987).
//
// Deliberate choices (documented in docs/algorithms.md section 2):
// * Interior edges touching the boundary follow OpenMesh's ModifiedButterFlyT
//   (OpenMesh 9, Tools/Subdivider/Uniform/ModifiedButterFlyT.hh) exactly, so the
//   comparison test covers meshes with boundaries: when each endpoint is either
//   regular (interior, valence 6) or on a boundary, the regular stencil is used
//   and a wing vertex across a boundary edge is replaced by its reflection
//   e + b - o; otherwise only the interior extraordinary endpoint(s) give the
//   point. A boundary vertex is never an extraordinary centre.
// * Creases (our extension; docs/algorithms.md section 5 notes no published rule for
//   Butterfly): a crease edge is a boundary for both of its sides. Crease edges
//   get the curve four-point rule along the crease; a vertex with a number of
//   feature edges other than two is a corner and the curve is extended past it
//   by reflection (2a - b), so a crease between two corners stays a straight
//   line and a crease never bends across a corner. Interior stencils treat
//   crease vertices like boundary vertices and reflect wings across crease
//   edges, so no stencil reaches across a crease.
// * The ten-point stencil's two far vertices d (weight w) are the neighbours
//   of each endpoint straight across from the other endpoint (the ones that
//   give quadratic precision); a missing one is reflected (2a - b).
// * Projection placement (Cheang 1998): the plane through the edge midpoint
//   with the averaged unit normal of the edge's two triangles; only the normal
//   component of the Butterfly offset is kept. Curve-rule edges (boundary,
//   crease) keep the full curve point: a normal offset alone would
//   straighten a curved boundary.
// * The offset bound (issue 20, no spikes; butterfly_rules.h, bound_offset):
//   after the rule (and the projection), a point farther from the edge's
//   midpoint than L (1/8 + sigma) (L / 8 for an irregular stencil) is pulled
//   back to that distance. AsaOptions::bound_offsets turns it off.
#include "common/asa/butterfly_stencils.h"

#include <cmath>
#include <numbers>

#include "common/asa/butterfly_rules.h"

namespace meshstream::asa {

void ButterflyWeights::configure(float tension, bool bound_offsets) {
  tension_ = tension;
  bound_offsets_ = bound_offsets;
  table_.clear();
  offset_.clear();
}

void ButterflyWeights::add_valences(const uint32_t* valence, const uint8_t* vertex_features,
                                    uint32_t vertex_count) {
  // Which valences below 63 occur, as bits (branch-free: most vertices
  // repeat a handful of valences); 63 stands for "63 or more".
  uint64_t seen = 0;
  for (uint32_t v = 0; v < vertex_count; ++v) {
    const uint32_t K = valence[v] < 63 ? valence[v] : 63;
    seen |= static_cast<uint64_t>(vertex_features[v] == 0) << K;
  }
  for (uint32_t K = 3; K < 63; ++K)
    if (K != 6 && (seen >> K & 1)) add(K);
  if (seen >> 63 & 1) {
    for (uint32_t v = 0; v < vertex_count; ++v) {
      const uint32_t K = valence[v];
      if (vertex_features[v] == 0 && K >= 63 && (K >= offset_.size() || offset_[K] == kNone))
        add(K);
    }
  }
}

void ButterflyWeights::add_valences(const uint32_t* valence, const uint8_t* vertex_features,
                                    const std::vector<uint32_t>& list) {
  for (const uint32_t v : list) {
    const uint32_t K = valence[v];
    if (vertex_features[v] == 0 && K >= 3 && K != 6 && (K >= offset_.size() || offset_[K] == kNone))
      add(K);
  }
}

void ButterflyWeights::add_valences(const uint32_t* valence, const uint8_t* vertex_features,
                                    uint32_t first, uint32_t count) {
  add_valences(valence + first, vertex_features + first, count);
}

void ButterflyWeights::add(uint32_t K) {
  if (K < 3) return;
  if (K >= offset_.size()) offset_.resize(K + 1, kNone);
  if (offset_[K] != kNone) return;
  offset_[K] = static_cast<uint32_t>(table_.size());
  std::vector<double> s(K + 1, 0.0);
  if (K == 3) {
    s = {5.0 / 12, -1.0 / 12, -1.0 / 12, 3.0 / 4};
  } else if (K == 4) {
    s = {3.0 / 8, 0.0, -1.0 / 8, 0.0, 3.0 / 4};
  } else {
    double sum = 0;
    for (uint32_t j = 0; j < K; ++j) {
      double x = 2.0 * std::numbers::pi * j / K;
      s[j] = (0.25 + std::cos(x) + 0.5 * std::cos(2.0 * x)) / K;
      sum += s[j];
    }
    s[K] = 1.0 - sum;  // 3/4 up to rounding, as OpenMesh does
  }
  for (double w : s) table_.push_back(static_cast<float>(w));
}

uint32_t other_feature_neighbor_at_next(const LevelView& m, uint32_t c) {
  const uint32_t a = m.corner_vertex[next_corner(c)];
  if (m.vertex_features[a] != 2) return kNone;
  return rules::walk_to_feature_ccw(m, next_corner(c), rules::walk_limit(m));
}

Vec3f butterfly_point(const LevelView& m, uint32_t c, const ButterflyWeights& wt,
                      EdgePlacement placement) {
  return rules::edge_point(m, c, wt, placement);
}

}  // namespace meshstream::asa

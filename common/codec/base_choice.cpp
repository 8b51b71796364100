// Base coder choice: see base_choice.h.
#include "common/codec/base_choice.h"

#include <algorithm>
#include <unordered_map>

namespace meshstream {
namespace {

uint64_t position_key(Vec3i p) {
  return uint64_t(uint32_t(p.x)) | uint64_t(uint32_t(p.y)) << 21 | uint64_t(uint32_t(p.z)) << 42;
}

}  // namespace

ChosenBase code_base_own(const DecimationResult& dec, const std::vector<Vec3i>& q) {
  ChosenBase out;
  std::unordered_map<uint32_t, uint32_t> id;
  for (const Triangle& t : dec.base_faces) {
    for (uint32_t v : t) {
      if (id.emplace(v, static_cast<uint32_t>(out.to_input.size())).second)
        out.to_input.push_back(v);
    }
  }
  for (uint32_t v : dec.base_vertices) {
    if (id.emplace(v, static_cast<uint32_t>(out.to_input.size())).second) out.to_input.push_back(v);
  }
  BaseMesh base;
  for (uint32_t v : out.to_input) base.positions.push_back(q[v]);
  for (const Triangle& t : dec.base_faces) base.faces.push_back({id[t[0]], id[t[1]], id[t[2]]});
  out.bytes = encode_base_own(base);
  out.decoded = std::move(base);
  out.coder = kBaseCoderOwn;
  return out;
}

std::optional<ChosenBase> code_base_traversal(const DecimationResult& dec,
                                              const std::vector<Vec3i>& q, int bits) {
  BaseMesh base;
  std::unordered_map<uint32_t, uint32_t> id;
  for (uint32_t v : dec.base_vertices) {
    id.emplace(v, static_cast<uint32_t>(base.positions.size()));
    base.positions.push_back(q[v]);
  }
  for (const Triangle& t : dec.base_faces) base.faces.push_back({id[t[0]], id[t[1]], id[t[2]]});
  auto coded = encode_base_traversal(base, bits);
  if (!coded) return std::nullopt;
  // The decoder's picture must be the encoder's: checked here (the base is
  // small) rather than trusted.
  auto decoded = decode_base_traversal(coded->bytes, static_cast<uint32_t>(base.positions.size()),
                                       static_cast<uint32_t>(base.faces.size()), bits);
  if (!decoded || decoded->positions != coded->decoded.positions ||
      decoded->faces != coded->decoded.faces) {
    return std::nullopt;
  }
  ChosenBase out;
  out.coder = kBaseCoderTraversal;
  out.bytes = std::move(coded->bytes);
  out.decoded = std::move(coded->decoded);
  out.to_input.reserve(coded->to_base.size());
  for (uint32_t b : coded->to_base) out.to_input.push_back(dec.base_vertices[b]);
  return out;
}

std::optional<ChosenBase> code_base_draco(const DecimationResult& dec, const std::vector<Vec3i>& q,
                                          int bits) {
  BaseMesh base;
  std::unordered_map<uint32_t, uint32_t> id;
  for (uint32_t v : dec.base_vertices) {
    id.emplace(v, static_cast<uint32_t>(base.positions.size()));
    base.positions.push_back(q[v]);
  }
  for (const Triangle& t : dec.base_faces) base.faces.push_back({id[t[0]], id[t[1]], id[t[2]]});
  auto bytes = encode_base_draco(base);
  if (!bytes) return std::nullopt;
  auto decoded = decode_base_draco(*bytes, static_cast<uint32_t>(base.positions.size()),
                                   static_cast<uint32_t>(base.faces.size()), bits);
  if (!decoded) return std::nullopt;
  // Map Draco's vertices back to ours (base ids): by position where it is
  // unique; vertices sharing a grid point are resolved through faces whose
  // other two corners are already mapped (a directed edge names one face in
  // a manifold mesh). Then the oriented faces must match id for id.
  const uint32_t n = static_cast<uint32_t>(base.positions.size());
  if (decoded->positions.size() != n || decoded->faces.size() != base.faces.size())
    return std::nullopt;
  std::unordered_map<uint64_t, std::vector<uint32_t>> by_position;
  for (uint32_t v = 0; v < n; ++v) by_position[position_key(base.positions[v])].push_back(v);
  std::vector<uint32_t> map(n, kNone);  // decoded -> base
  std::vector<uint8_t> taken(n, 0);
  for (uint32_t d = 0; d < n; ++d) {
    auto it = by_position.find(position_key(decoded->positions[d]));
    if (it == by_position.end()) return std::nullopt;
    if (it->second.size() == 1) {
      map[d] = it->second[0];
      if (taken[map[d]]++) return std::nullopt;
    }
  }
  auto edge_key = [](uint32_t a, uint32_t b) { return uint64_t(a) << 32 | b; };
  std::unordered_map<uint64_t, uint32_t> third;  // directed edge -> opposite vertex (base ids)
  for (const Triangle& t : base.faces)
    for (int i = 0; i < 3; ++i) third[edge_key(t[i], t[(i + 1) % 3])] = t[(i + 2) % 3];
  for (bool progress = true; progress;) {
    progress = false;
    for (const Triangle& t : decoded->faces) {
      for (int i = 0; i < 3; ++i) {
        const uint32_t a = t[i], b = t[(i + 1) % 3], c = t[(i + 2) % 3];
        if (map[c] != kNone || map[a] == kNone || map[b] == kNone) continue;
        auto it = third.find(edge_key(map[a], map[b]));
        if (it == third.end() || taken[it->second] ||
            !(base.positions[it->second] == decoded->positions[c])) {
          continue;
        }
        map[c] = it->second;
        taken[it->second] = 1;
        progress = true;
      }
    }
  }
  for (uint32_t d = 0; d < n; ++d)
    if (map[d] == kNone) return std::nullopt;
  auto oriented = [](Triangle t) {
    while (t[0] > t[1] || t[0] > t[2]) std::rotate(t.begin(), t.begin() + 1, t.end());
    return t;
  };
  std::vector<Triangle> ours, theirs;
  for (const Triangle& t : base.faces) ours.push_back(oriented(t));
  for (const Triangle& t : decoded->faces)
    theirs.push_back(oriented({map[t[0]], map[t[1]], map[t[2]]}));
  std::sort(ours.begin(), ours.end());
  std::sort(theirs.begin(), theirs.end());
  if (ours != theirs) return std::nullopt;
  ChosenBase out;
  out.to_input.resize(n);
  for (uint32_t d = 0; d < n; ++d) out.to_input[d] = dec.base_vertices[map[d]];
  out.coder = kBaseCoderDraco;
  out.bytes = std::move(*bytes);
  out.decoded = std::move(*decoded);
  return out;
}

ChosenBase choose_base(const DecimationResult& dec, const std::vector<Vec3i>& positions, int bits,
                       bool allow_draco) {
  auto traversal = code_base_traversal(dec, positions, bits);
  ChosenBase base = traversal ? std::move(*traversal) : code_base_own(dec, positions);
  if (allow_draco) {
    if (auto draco = code_base_draco(dec, positions, bits);
        draco && draco->bytes.size() < base.bytes.size()) {
      base = std::move(*draco);
    }
  }
  return base;
}

}  // namespace meshstream

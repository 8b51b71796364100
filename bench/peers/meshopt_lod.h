// meshoptimizer's simplifier as the LOD-chain peer of the codec benchmark:
// what a user would build instead of a progressive stream.
// Header-only so each bench executable can include it.
#pragma once

#include <meshoptimizer.h>

#include <cstdint>
#include <vector>

#include "common/mesh/mesh.h"

namespace meshstream::bench {

// meshopt_simplify (edge collapses under a quadric error, topology kept) down
// to about `fraction` of the triangles, with no error limit, then compacted to
// the vertices it still uses. fraction >= 1 returns the mesh unchanged.
inline Mesh simplify_lod(const Mesh& mesh, double fraction) {
  if (fraction >= 1) return mesh;
  std::vector<uint32_t> indices;
  indices.reserve(3 * mesh.triangles.size());
  for (const Triangle& t : mesh.triangles) indices.insert(indices.end(), t.begin(), t.end());
  const size_t target = static_cast<size_t>(static_cast<double>(indices.size()) * fraction) / 3 * 3;
  std::vector<uint32_t> lod(indices.size());
  const size_t kept = meshopt_simplify(lod.data(), indices.data(), indices.size(),
                                       &mesh.positions[0].x, mesh.positions.size(), sizeof(Vec3f),
                                       target, /*target_error=*/1.0f, /*options=*/0, nullptr);
  lod.resize(kept);
  std::vector<uint32_t> remap(mesh.positions.size(), UINT32_MAX);
  Mesh out;
  for (uint32_t& v : lod) {
    if (remap[v] == UINT32_MAX) {
      remap[v] = out.vertex_count();
      out.positions.push_back(mesh.positions[v]);
    }
    v = remap[v];
  }
  for (size_t i = 0; i < lod.size(); i += 3)
    out.triangles.push_back({lod[i], lod[i + 1], lod[i + 2]});
  return out;
}

}  // namespace meshstream::bench

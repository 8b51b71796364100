// The real meshes every codec benchmark runs on (../shared/meshes, see its
// MANIFEST.md) and the `--meshes a,b` list parsing they share.
#pragma once

#include <sstream>
#include <string>
#include <vector>

namespace meshstream::bench {

inline const std::vector<std::string> kRealMeshes = {
    "bun_zipper.ply",  "bunny.off",       "bunny.stl",      "armadillo.obj",  "fandisk.off",
    "crank.off",       "casting.off",     "mask.off",       "hemisphere.off", "skull.obj",
    "maneki-neko.off", "dragon_res2.ply", "dragon_res3.ply"};

// "a,b,,c" -> {"a", "b", "c"}.
inline std::vector<std::string> split_commas(const std::string& list) {
  std::vector<std::string> out;
  std::stringstream in(list);
  for (std::string item; std::getline(in, item, ',');) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

}  // namespace meshstream::bench

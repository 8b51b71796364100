#include "common/mesh/file_contents.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace meshstream {

MaterialLibrary read_material_library(const std::string& obj_path, const std::string& name) {
  MaterialLibrary library;
  library.name = name;
  const std::filesystem::path path = std::filesystem::path(obj_path).parent_path() / name;
  std::ifstream in(path);
  if (!in) return library;
  library.found = true;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    std::string rest;
    std::getline(words >> std::ws, rest);
    while (!rest.empty() && (rest.back() == '\r' || rest.back() == ' ')) rest.pop_back();
    if (rest.empty()) continue;
    if (keyword == "newmtl") {
      library.materials.push_back(rest);
    } else if (keyword.rfind("map_", 0) == 0 || keyword == "bump" || keyword == "disp" ||
               keyword == "decal" || keyword == "refl") {
      // Options (-bm 1, -o u v, ...) come before the file name, the last word.
      const std::string file = rest.substr(rest.find_last_of(' ') + 1);
      auto& t = library.textures;
      if (std::find(t.begin(), t.end(), file) == t.end()) t.push_back(file);
    }
  }
  return library;
}

}  // namespace meshstream

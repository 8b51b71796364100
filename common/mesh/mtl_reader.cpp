// OBJ materials: the MTL files an OBJ names (`mtllib`, looked up beside the
// OBJ), their `Kd` (base colour), `d` / `Tr` (opacity) and `map_Kd` (base
// colour texture, read byte for byte). A missing MTL or image file is a
// note, not an error: the geometry is still good.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "common/mesh/mesh_readers.h"
#include "common/mesh/texture_files.h"

namespace meshstream {
namespace {

struct MtlEntry {
  Vec4f base_color{1, 1, 1, 1};
  std::string map_kd;                   // file name, "" for none
  std::vector<std::string> other_maps;  // "map_Ks x.png", for the note
};

// Parses one MTL file into `entries` (by newmtl name; a later definition of
// a name wins, as in most viewers).
void parse_mtl(std::istream& in, std::map<std::string, MtlEntry>& entries) {
  MtlEntry* current = nullptr;
  std::string line;
  while (std::getline(in, line)) {
    if (const size_t hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    std::istringstream words(line);
    std::string keyword;
    if (!(words >> keyword)) continue;
    std::string rest;
    std::getline(words >> std::ws, rest);
    while (!rest.empty() && (rest.back() == '\r' || rest.back() == ' ' || rest.back() == '\t'))
      rest.pop_back();
    if (keyword == "newmtl") {
      current = &(entries[rest] = MtlEntry{});
      continue;
    }
    if (current == nullptr) continue;
    std::istringstream values(rest);
    if (keyword == "Kd") {
      float r = 1, g = 1, b = 1;
      if (values >> r >> g >> b) current->base_color = {r, g, b, current->base_color.w};
    } else if (keyword == "d") {
      float d = 1;
      if (values >> d) current->base_color.w = d;
    } else if (keyword == "Tr") {
      float tr = 0;
      if (values >> tr) current->base_color.w = 1 - tr;
    } else if (keyword == "map_Kd") {
      // Options (-bm 1, -o u v, ...) come before the file name, the last word.
      current->map_kd = rest.substr(rest.find_last_of(" \t") + 1);
    } else if (keyword.rfind("map_", 0) == 0 || keyword == "bump" || keyword == "disp" ||
               keyword == "norm") {
      current->other_maps.push_back(keyword + " " + rest.substr(rest.find_last_of(" \t") + 1));
    }
  }
}

}  // namespace

void apply_material_libraries(const std::string& obj_path, RawMesh& raw) {
  const std::filesystem::path folder = std::filesystem::path(obj_path).parent_path();
  std::map<std::string, MtlEntry> entries;
  for (MaterialLibrary& library : raw.contents.material_libraries) {
    library = read_material_library(obj_path, library.name);
    if (!library.found) {
      raw.notes.push_back("material library " + library.name +
                          " not found beside the OBJ: its materials get default values");
      continue;
    }
    std::ifstream in(folder / library.name);
    parse_mtl(in, entries);
  }
  Mesh& mesh = raw.mesh;
  std::map<std::string, int32_t> texture_of_file;
  for (Material& material : mesh.materials) {
    auto it = entries.find(material.name);
    if (it == entries.end()) {
      if (material.name != "(no usemtl)" && !raw.contents.material_libraries.empty())
        raw.notes.push_back("material " + material.name + " is not defined in any mtllib file");
      continue;
    }
    const MtlEntry& entry = it->second;
    material.base_color = entry.base_color;
    for (const std::string& map : entry.other_maps)
      raw.notes.push_back("material " + material.name + ": " + map +
                          " not kept (only Kd and map_Kd are carried from MTL files)");
    if (entry.map_kd.empty()) continue;
    auto known = texture_of_file.find(entry.map_kd);
    if (known != texture_of_file.end()) {
      material.base_color_texture = known->second;
      continue;
    }
    auto texture = read_texture_file((folder / entry.map_kd).string());
    if (!texture) {
      raw.notes.push_back("material " + material.name + ": texture " + entry.map_kd +
                          " not kept: " + texture.error().message);
      texture_of_file[entry.map_kd] = -1;
      continue;
    }
    texture->name = entry.map_kd;
    material.base_color_texture = static_cast<int32_t>(mesh.textures.size());
    texture_of_file[entry.map_kd] = material.base_color_texture;
    mesh.textures.push_back(std::move(*texture));
  }
}

}  // namespace meshstream

#include "server/models_folder.h"

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>

namespace meshstream::server {
namespace {

namespace fs = std::filesystem;

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

bool is_mesh_extension(const std::string& ext) {
  return ext == ".ply" || ext == ".obj" || ext == ".stl" || ext == ".drc" || ext == ".off" ||
         ext == ".gltf" || ext == ".glb";
}

// Why an entry that is neither .hcs nor a mesh file is skipped.
std::string skip_reason(const fs::directory_entry& entry, std::error_code& ec) {
  if (entry.is_directory(ec)) return "a folder (subfolders are not searched)";
  if (!entry.is_regular_file(ec)) return "not a regular file";
  const std::string ext = entry.path().extension().string();
  if (ext.empty()) {
    return std::string("no file extension (the server reads ") + served_extensions() + ")";
  }
  return "'" + ext + "' is not a model format the server reads (it reads " + served_extensions() +
         ")";
}

}  // namespace

const char* served_extensions() { return ".hcs, .ply, .obj, .stl, .off, .drc, .gltf, .glb"; }

Result<FolderScan> scan_models_folder(const std::string& dir) {
  std::error_code ec;
  std::vector<fs::path> hcs, meshes;
  FolderScan scan;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const fs::directory_entry& entry = *it;
    std::error_code entry_ec;
    const std::string ext = lower(entry.path().extension().string());
    if (entry.is_regular_file(entry_ec) && ext == ".hcs") {
      hcs.push_back(entry.path());
    } else if (entry.is_regular_file(entry_ec) && is_mesh_extension(ext)) {
      meshes.push_back(entry.path());
    } else {
      scan.skipped.push_back({entry.path().string(), skip_reason(entry, entry_ec)});
    }
  }
  if (ec) return make_error(ErrorCode::kIo, "cannot list " + dir + ": " + ec.message());
  std::sort(hcs.begin(), hcs.end());
  std::sort(meshes.begin(), meshes.end());
  std::sort(scan.skipped.begin(), scan.skipped.end(),
            [](const SkippedEntry& a, const SkippedEntry& b) { return a.path < b.path; });

  std::set<std::string> taken;
  std::map<std::string, NameClash> clashes;  // by the shared name
  auto assign = [&](const std::vector<fs::path>& paths, std::vector<ModelFile>& out) {
    for (const fs::path& path : paths) {
      const std::string stem = path.stem().string();
      std::string name = taken.count(stem) ? path.filename().string() : stem;
      if (taken.count(name)) {
        scan.skipped.push_back(
            {path.string(), "model name '" + name + "' is taken by another file"});
        continue;
      }
      taken.insert(name);
      const ModelFile file{path.string(), name};
      out.push_back(file);
      NameClash& clash = clashes[stem];
      clash.name = stem;
      clash.files.push_back(file);
    }
  };
  assign(hcs, scan.hcs);
  assign(meshes, scan.meshes);
  for (auto& [name, clash] : clashes) {
    if (clash.files.size() > 1) scan.clashes.push_back(std::move(clash));
  }
  return scan;
}

std::string describe(const NameClash& clash) {
  std::string text = "model name '" + clash.name + "' is claimed by " +
                     std::to_string(clash.files.size()) + " files: serving ";
  for (size_t i = 0; i < clash.files.size(); ++i) {
    if (i) text += ", ";
    text += clash.files[i].path + " as '" + clash.files[i].name + "'";
  }
  return text;
}

}  // namespace meshstream::server

#include "common/mesh/import.h"

#include <cctype>
#include <filesystem>
#include <fstream>

#include "common/mesh/mesh_readers.h"

namespace meshstream {
namespace {

bool has_extension(const std::string& path, const char* wanted) {
  const size_t n = std::char_traits<char>::length(wanted);
  if (path.size() < n) return false;
  std::string ext = path.substr(path.size() - n);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == wanted;
}

// The format's name from the extension, for readers that do not set one.
std::string format_name(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  if (!ext.empty()) ext.erase(0, 1);
  for (char& c : ext) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return ext;
}

Result<RawMesh> read_by_format(const std::string& path) {
  if (has_extension(path, ".off")) return read_off(path);
  if (has_extension(path, ".ply")) return read_ply(path);
  // Never Draco's ObjDecoder: it corrupts the heap on malformed face tokens.
  if (has_extension(path, ".obj")) return read_obj(path);
  if (has_extension(path, ".gltf") || has_extension(path, ".glb")) return read_gltf(path);
  return read_with_draco(path);
}

}  // namespace

Result<ImportedMesh> import_mesh(const std::string& path, const ImportOptions& options) {
  // Checked first so an unreadable file is kIo, not whatever a parser makes of it.
  {
    std::ifstream probe(path, std::ios::binary);
    if (!probe) return make_error(ErrorCode::kIo, path + ": cannot open the file for reading");
    char byte;
    probe.read(&byte, 1);
    if (probe.bad()) return make_error(ErrorCode::kIo, path + ": cannot read the file");
    if (probe.gcount() == 0) return make_error(ErrorCode::kParse, path + ": the file is empty");
  }
  Result<RawMesh> raw = read_by_format(path);
  if (!raw) return tl::unexpected(std::move(raw.error()).with_context(path));

  ImportedMesh imported;
  imported.mesh = std::move(raw->mesh);
  auto report = clean_mesh(imported.mesh, options);
  if (!report) return tl::unexpected(std::move(report.error()).with_context(path));
  imported.report = std::move(*report);
  imported.report.vertices_in_file = raw->vertices_in_file;
  imported.report.notes.insert(imported.report.notes.begin(), raw->notes.begin(), raw->notes.end());
  imported.contents = std::move(raw->contents);
  if (imported.contents.format.empty()) imported.contents.format = format_name(path);
  return imported;
}

}  // namespace meshstream
